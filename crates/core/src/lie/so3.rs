//! Fixed-size SO(3) and so(3) ≅ R³ on nalgebra types: the fast path of rigid-body loops.
//!
//! Physics hat map (000 §3.3, corrected): hat(w) x = w × x and [hat u, hat v] = hat(u × v).

use nalgebra::{Matrix3, Vector3};

/// hat(w) = [[0, −w3, w2], [w3, 0, −w1], [−w2, w1, 0]], so hat(w) x = w × x.
#[inline]
pub fn hat(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// Inverse of [`hat`] on skew matrices (reads the skew part, so it is exact on so(3)).
#[inline]
pub fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        0.5 * (m[(2, 1)] - m[(1, 2)]),
        0.5 * (m[(0, 2)] - m[(2, 0)]),
        0.5 * (m[(1, 0)] - m[(0, 1)]),
    )
}

/// Rodrigues' formula exp(hat w) = I + sinθ/θ hat w + (1 − cosθ)/θ² hat² w, θ = |w|, with Taylor
/// coefficients for small θ.
#[inline]
pub fn exp(w: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = w.norm_squared();
    let (a, b) = if t2 < 1e-8 {
        (
            1.0 - t2 / 6.0 * (1.0 - t2 / 20.0),
            0.5 - t2 / 24.0 * (1.0 - t2 / 30.0),
        )
    } else {
        let t = t2.sqrt();
        let (s, c) = t.sin_cos();
        (s / t, (1.0 - c) / t2)
    };
    let k = hat(w);
    Matrix3::identity() + k * a + k * k * b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hat_is_cross_product() {
        let u = Vector3::new(0.3, -1.2, 2.0);
        let v = Vector3::new(-0.7, 0.4, 1.1);
        assert!((hat(&u) * v - u.cross(&v)).norm() < 1e-15);
        assert_eq!(vee(&hat(&u)), u);
    }

    #[test]
    fn exp_rotates_about_axis() {
        let r = exp(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
        let w = Vector3::new(1e-6, -2e-6, 3e-7);
        let r = exp(&w);
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-15);
    }
}
