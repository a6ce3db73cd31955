//! Riemann-ellipsoid variables (001 §3.1, §9): the quadrupole moment Q = XXᵀ and the shear
//! tensor N = XẊᵀ (001 (3.4)), N = ½(−L + Q̇) (3.10), and the Poisson brackets (9.1) of
//! functions of (Q, N).

use crate::error::Result;
use crate::lie::gl;
use crate::{check, Mat};

/// (Q, N) = (XXᵀ, XVᵀ) for a velocity (or momentum) V at X (001 (3.4)).
pub fn riemann_variables(x: &Mat, v: &Mat) -> Result<(Mat, Mat)> {
    let n = gl::check_gl_plus("X", x)?;
    check::square_of("V", v, n)?;
    // Scale-aware: X and V divided by powers of two, the products multiplied back once.
    let (ex, ev) = (check::pow2_exponent_mat(x), check::pow2_exponent_mat(v));
    let (xs, vs) = (check::ldexp_mat(x, -ex), check::ldexp_mat(v, -ev));
    Ok((
        check::unscale_mat("X", "Q = XXᵀ", &(&xs * xs.transpose()), 2 * ex)?,
        check::unscale_mat("X, V", "N = XVᵀ", &(&xs * vs.transpose()), ex + ev)?,
    ))
}

/// The symmetric/skew split of N (001 (3.10)): returns (Q̇, L) with Q̇ = N + Nᵀ = ẊXᵀ + XẊᵀ and
/// L = Nᵀ − N = ẊXᵀ − XẊᵀ, so that N = ½(−L + Q̇). L agrees with the angular momentum (2.29).
pub fn split_shear(n_mat: &Mat) -> Result<(Mat, Mat)> {
    check::square("N", n_mat, 1)?;
    Ok((n_mat + n_mat.transpose(), n_mat.transpose() - n_mat))
}

/// Poisson bracket {f, g} of two functions of (Q, N), given their gradients
/// (∂f/∂Q, ∂f/∂N), (∂g/∂Q, ∂g/∂N) (entries Q_ij, N_ij taken as coordinates), from the structure
/// functions of 001 (9.1):
/// {Q_ij, Q_kl} = 0, {Q_ij, N_kl} = δ_il Q_jk + δ_jl Q_ik, {N_ij, N_kl} = δ_il N_kj − δ_jk N_il.
/// (9.1) checked against the canonical bracket on T*GL⁺(n) with {X_ab, P_ab} = 1 and N = XPᵀ:
/// correct as printed. O(n⁴).
pub fn poisson_bracket(q: &Mat, n_mat: &Mat, df: (&Mat, &Mat), dg: (&Mat, &Mat)) -> Result<f64> {
    let n = check::square("Q", q, 1)?;
    for (what, m) in [
        ("N", n_mat),
        ("dfdQ", df.0),
        ("dfdN", df.1),
        ("dgdQ", dg.0),
        ("dgdN", dg.1),
    ] {
        check::square_of(what, m, n)?;
    }
    let delta = |a: usize, b: usize| if a == b { 1.0 } else { 0.0 };
    let qn =
        |i: usize, j: usize, k: usize, l: usize| delta(i, l) * q[(j, k)] + delta(j, l) * q[(i, k)];
    let nn = |i: usize, j: usize, k: usize, l: usize| {
        delta(i, l) * n_mat[(k, j)] - delta(j, k) * n_mat[(i, l)]
    };
    let mut s = 0.0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                for l in 0..n {
                    let c = qn(i, j, k, l);
                    s += c * (df.0[(i, j)] * dg.1[(k, l)] - dg.0[(i, j)] * df.1[(k, l)]);
                    s += nn(i, j, k, l) * df.1[(i, j)] * dg.1[(k, l)];
                }
            }
        }
    }
    if !s.is_finite() {
        return Err(check::overflow_error(
            "Q, N, dfdQ, dfdN, dgdQ, dgdN",
            "the Poisson bracket {f, g}",
        ));
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::super::momentum::momentum_map_unchecked;
    use super::*;

    #[test]
    fn shear_split_gives_angular_momentum() {
        let x = Mat::from_fn(3, 3, |i, j| {
            if i == j {
                2.0 + i as f64
            } else {
                0.1 * (i + 2 * j) as f64
            }
        });
        let v = Mat::from_fn(3, 3, |i, j| (i as f64 - j as f64 * 0.3).sin());
        let (_, n) = riemann_variables(&x, &v).unwrap();
        let (qdot, l) = split_shear(&n).unwrap();
        let (l2, _) = momentum_map_unchecked(&x, &v);
        assert!((&l - &l2).norm_l2() < 1e-13);
        let qd = &v * x.transpose() + &x * v.transpose();
        assert!((&qdot - &qd).norm_l2() < 1e-13);
        let half = (qdot - l) * faer::Scale(0.5);
        assert!((&half - &n).norm_l2() < 1e-13);
    }
}
