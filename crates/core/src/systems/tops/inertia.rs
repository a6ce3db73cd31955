//! The inertia of a body (000 §3.1): the mass matrix J = Σ m_k x_k x_kᵀ of point masses (any
//! dimension n; the inertia of the generalized rigid body on so(n), whose kinetic energy is
//! ½⟨Ω, JΩ + ΩJ⟩), the inertia tensor 𝕀 = Σ m_k (|x_k|² 1 − x_k x_kᵀ) = tr(J) 1 − J in three
//! dimensions (the kinetic energy ½ Σ m_k |ω × x_k|² = ½⟨ω, 𝕀ω⟩), those of homogeneous solids,
//! and the spatial inertia 𝕁 = R 𝕀 Rᵀ of (4.1).
//!
//! **Homogeneous solids** with semi-axes a_i, in their principal frame: the ellipsoid
//! Σ (x_i/a_i)² ≤ 1 in ℝⁿ has ∫ x_i² dm = m a_i²/(n + 2) (scale the unit ball, whose second
//! moment is the (n+2)-th part of its volume per axis); the box |x_i| ≤ a_i has ∫ x_i² dm =
//! m a_i²/3. So the solid ellipsoid's 𝕀 = (m/5) diag(b² + c², a² + c², a² + b²) and the box's
//! (m/3) diag(b² + c², …) (the textbook m(L_y² + L_z²)/12 with L = 2a).

use nalgebra::Matrix3;

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so3;

/// A homogeneous solid of [`mass_matrix_of`] and [`inertia_of`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solid {
    /// The solid ellipsoid Σ (x_i/a_i)² ≤ 1.
    Ellipsoid,
    /// The box |x_i| ≤ a_i.
    Box,
}

/// J = Σ m_k x_k x_kᵀ (n×n, row-major) of point masses `masses` (k) at `positions` (k·n,
/// row-major).
///
/// Errors: no mass, sizes that do not match, a non-finite entry, a negative mass, all masses
/// zero; a result beyond the f64 range.
pub fn mass_matrix(masses: &[f64], positions: &[f64]) -> Result<(usize, Vec<f64>)> {
    let k = masses.len();
    if k == 0 || positions.len() % k != 0 || positions.is_empty() {
        return Err(Error::shape(
            "positions",
            format!("({k}, n): one position per mass"),
            format!("{} values for {k} masses", positions.len()),
        ));
    }
    check::finite_slice("masses", masses)?;
    check::finite_slice("positions", positions)?;
    if let Some(i) = masses.iter().position(|m| *m < 0.0) {
        return Err(Error::invalid(
            "masses",
            format!("masses must be non-negative, got {} at {i}", masses[i]),
        ));
    }
    if masses.iter().all(|m| *m == 0.0) {
        return Err(Error::invalid("masses", "all masses are zero"));
    }
    let n = positions.len() / k;
    check::array_size("the mass matrix", &[n, n])?;
    let mut j = vec![0.0; n * n];
    for (m, x) in masses.iter().zip(positions.chunks_exact(n)) {
        for a in 0..n {
            for b in 0..n {
                j[a * n + b] += m * x[a] * x[b];
            }
        }
    }
    finite(j, "positions", "the mass matrix Σ m x xᵀ").map(|j| (n, j))
}

/// J (n×n, row-major, diagonal) of a homogeneous solid of mass `mass` with semi-axes
/// `semi_axes` (n) in its principal frame (module docs).
///
/// Errors: no axis, a mass or an axis that is not positive and finite.
pub fn mass_matrix_of(solid: Solid, mass: f64, semi_axes: &[f64]) -> Result<Vec<f64>> {
    let n = semi_axes.len();
    if n == 0 {
        return Err(Error::shape(
            "semi_axes",
            "(n,) with n ≥ 1",
            "no semi-axis".to_string(),
        ));
    }
    check::positive("mass", mass)?;
    for &a in semi_axes {
        check::positive("semi_axes", a)?;
    }
    check::array_size("the mass matrix", &[n, n])?;
    let factor = match solid {
        Solid::Ellipsoid => mass / (n + 2) as f64,
        Solid::Box => mass / 3.0,
    };
    let mut j = vec![0.0; n * n];
    for (i, a) in semi_axes.iter().enumerate() {
        j[i * n + i] = factor * a * a;
    }
    finite(j, "semi_axes", "the mass matrix")
}

/// `v`, or the overflow error of `quantity` at this scale of `what` where an entry is not finite
/// (finite input whose result exceeds the f64 range).
fn finite(v: Vec<f64>, what: &str, quantity: &str) -> Result<Vec<f64>> {
    match v.iter().all(|x| x.is_finite()) {
        true => Ok(v),
        false => Err(check::overflow_error(what, quantity)),
    }
}

/// 𝕀 = tr(J) 1 − J of a three-dimensional mass matrix J (3×3, row-major; `what` names the
/// arguments it came from).
///
/// Errors: a result beyond the f64 range.
pub fn from_mass_matrix(j: &[f64], what: &str) -> Result<Matrix3<f64>> {
    let j = Matrix3::from_row_slice(j);
    let i = Matrix3::identity() * j.trace() - j;
    finite(i.as_slice().to_vec(), what, "the inertia tensor").map(|_| i)
}

/// 𝕀 = Σ m_k (|x_k|² 1 − x_k x_kᵀ) of point masses at positions (k, 3) (row-major).
///
/// Errors: those of [`mass_matrix`]; positions not in three dimensions.
pub fn inertia_tensor(masses: &[f64], positions: &[f64]) -> Result<Matrix3<f64>> {
    let (n, j) = mass_matrix(masses, positions)?;
    if n != 3 {
        return Err(Error::shape(
            "positions",
            format!(
                "({}, 3): the inertia tensor is three-dimensional",
                masses.len()
            ),
            format!("({}, {n})", masses.len()),
        ));
    }
    from_mass_matrix(&j, "positions")
}

/// 𝕀 of a homogeneous solid (module docs): semi-axes (a, b, c).
///
/// Errors: those of [`mass_matrix_of`].
pub fn inertia_of(solid: Solid, mass: f64, semi_axes: [f64; 3]) -> Result<Matrix3<f64>> {
    from_mass_matrix(&mass_matrix_of(solid, mass, &semi_axes)?, "semi_axes")
}

/// 𝕁 = R 𝕀 Rᵀ (000 (4.1)): the inertia in the spatial frame of a body at attitude R, with
/// R 𝕀 Ω = 𝕁 ω for the spatial angular velocity ω = RΩ.
///
/// Errors: R not a rotation, 𝕀 not finite.
pub fn spatial_inertia(r: &Matrix3<f64>, inertia: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    so3::check_rotation("R", r)?;
    check::finite_slice("inertia", inertia.as_slice())?;
    let j = r * inertia * r.transpose();
    finite(j.as_slice().to_vec(), "inertia", "R 𝕀 Rᵀ").map(|_| j)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn cross(a: Vector3<f64>, b: Vector3<f64>) -> Vector3<f64> {
        a.cross(&b)
    }

    #[test]
    fn the_kinetic_energy_and_momentum_of_point_masses_are_those_of_the_inertia_tensor() {
        // ½ Σ m |ω × x|² = ½⟨ω, 𝕀ω⟩ and Σ m x × (ω × x) = 𝕀ω for any ω; in space, with x_s = R x
        // and ω_s = R Ω, Σ m x_s × (ω_s × x_s) = 𝕁 ω_s = R 𝕀 Ω (4.1).
        let masses = [1.0, 0.5, 2.0, 0.3];
        let xs = [
            [0.3, -0.2, 0.5],
            [1.0, 0.4, -0.7],
            [-0.6, 0.8, 0.1],
            [0.2, 0.0, -1.1],
        ];
        let flat: Vec<f64> = xs.iter().flatten().copied().collect();
        let i = inertia_tensor(&masses, &flat).unwrap();
        let r = so3::exp(&Vector3::new(0.3, -0.5, 0.8)).unwrap();
        let jj = spatial_inertia(&r, &i).unwrap();
        for w in [Vector3::new(0.7, -0.1, 0.4), Vector3::new(-1.0, 2.0, 0.5)] {
            let energy: f64 = masses
                .iter()
                .zip(&xs)
                .map(|(m, x)| 0.5 * m * cross(w, Vector3::from(*x)).norm_squared())
                .sum();
            assert!((energy - 0.5 * w.dot(&(i * w))).abs() < 1e-14);
            let momentum: Vector3<f64> = masses
                .iter()
                .zip(&xs)
                .map(|(m, x)| *m * cross(Vector3::from(*x), cross(w, Vector3::from(*x))))
                .sum();
            assert!((momentum - i * w).norm() < 1e-14);
            let ws = r * w;
            let spatial: Vector3<f64> = masses
                .iter()
                .zip(&xs)
                .map(|(m, x)| {
                    let xs = r * Vector3::from(*x);
                    *m * cross(xs, cross(ws, xs))
                })
                .sum();
            assert!((spatial - jj * ws).norm() < 1e-14);
            assert!((spatial - r * (i * w)).norm() < 1e-14);
        }
    }

    #[test]
    fn the_solids_against_their_mass_sampled_on_a_grid() {
        // The homogeneous ellipsoid and box by the midpoint rule on a 120³ grid of their
        // bounding box: the second moments to the rule's accuracy (≈ 1e-4 for the ellipsoid's
        // jagged boundary).
        let (a, mass) = ([1.0, 0.7, 0.4], 2.5);
        let k = 120;
        for solid in [Solid::Ellipsoid, Solid::Box] {
            let (mut masses, mut points) = (Vec::new(), Vec::new());
            for p in 0..k {
                for q in 0..k {
                    for s in 0..k {
                        let x = [p, q, s]
                            .iter()
                            .zip(&a)
                            .map(|(i, ai)| ai * (-1.0 + (2 * i + 1) as f64 / k as f64))
                            .collect::<Vec<_>>();
                        let inside = match solid {
                            Solid::Ellipsoid => {
                                x.iter()
                                    .zip(&a)
                                    .map(|(x, ai)| (x / ai).powi(2))
                                    .sum::<f64>()
                                    <= 1.0
                            }
                            Solid::Box => true,
                        };
                        if inside {
                            masses.push(1.0);
                            points.extend(x);
                        }
                    }
                }
            }
            let total = masses.len() as f64;
            masses.iter_mut().for_each(|m| *m = mass / total);
            let sampled = inertia_tensor(&masses, &points).unwrap();
            let exact = inertia_of(solid, mass, a).unwrap();
            let err = (sampled - exact).amax() / exact.amax();
            assert!(err < 2e-3, "{solid:?}: {err:e}");
            // J in n = 2 and 4: the disc's and the 4-ball's second moments m a²/(n + 2).
            let j2 = mass_matrix_of(solid, mass, &[1.0, 2.0]).unwrap();
            let j4 = mass_matrix_of(solid, mass, &[1.0; 4]).unwrap();
            let want = |n: f64| match solid {
                Solid::Ellipsoid => mass / (n + 2.0),
                Solid::Box => mass / 3.0,
            };
            assert!((j2[3] - 4.0 * want(2.0)).abs() < 1e-15 && (j4[5] - want(4.0)).abs() < 1e-15);
        }
        assert!(inertia_of(Solid::Box, -1.0, a).is_err());
        assert!(inertia_of(Solid::Box, 1.0, [1.0, 0.0, 1.0]).is_err());
        assert!(mass_matrix(&[1.0, -1.0], &[0.0; 6]).is_err());
        assert!(mass_matrix(&[1.0, 1.0], &[0.0; 5]).is_err());
        assert!(inertia_tensor(&[1.0], &[0.0, 1.0]).is_err());
        assert!(spatial_inertia(&Matrix3::identity().scale(2.0), &Matrix3::identity()).is_err());
        // Finite input whose inertia exceeds the f64 range is an overflow error, not ∞.
        let e = inertia_tensor(&[1.0], &[1e300, 0.0, 0.0]).unwrap_err();
        assert!(e.to_string().contains("overflow"), "{e}");
        assert!(inertia_of(Solid::Ellipsoid, 1.0, [f64::MAX, 1.0, 1.0]).is_err());
    }
}
