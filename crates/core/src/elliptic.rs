//! Jacobi elliptic functions sn, cn, dn, the complete integral K and the incomplete integral F.
//!
//! Conventions follow Abramowitz & Stegun ch. 16–17 and scipy: the *parameter* `m = k²` (not the
//! modulus k), `0 ≤ m < 1`. sn, cn, dn are computed by the descending Landen transformation (the
//! arithmetic–geometric mean, A&S 16.4), K(m) = π / (2 AGM(1, √(1−m))) (A&S 17.6), and
//! F(φ | m) by Carlson's symmetric integral R_F (Carlson 1995, "Numerical computation of real or
//! complex elliptic integrals"): F(φ | m) = sin φ · R_F(cos²φ, 1 − m sin²φ, 1).
//!
//! These serve the exact solution of the free rigid body ([`crate::systems::rigid_body`]).

use crate::error::{Error, Result};

/// Maximal number of AGM steps; convergence is quadratic, 0 ≤ m ≤ 1 − 1e-16 needs < 10.
const AGM_MAX: usize = 16;

fn check_m(m: f64) -> Result<()> {
    if m.is_finite() && (0.0..1.0).contains(&m) {
        Ok(())
    } else {
        Err(Error::invalid(
            "m",
            format!(
                "the elliptic parameter m = k² must satisfy 0 ≤ m < 1, got {}",
                crate::error::fmt_num(m)
            ),
        ))
    }
}

/// AGM sequence of (1, √(1−m)): returns (a_n, c_n) for n = 0..=N and N.
fn agm(m: f64) -> ([f64; AGM_MAX + 1], [f64; AGM_MAX + 1], usize) {
    let mut a = [0.0; AGM_MAX + 1];
    let mut c = [0.0; AGM_MAX + 1];
    a[0] = 1.0;
    c[0] = m.sqrt();
    let mut b = (1.0 - m).sqrt();
    let mut n = 0;
    while n < AGM_MAX && c[n].abs() > f64::EPSILON * a[n] {
        let (an, bn) = (a[n], b);
        a[n + 1] = 0.5 * (an + bn);
        c[n + 1] = 0.5 * (an - bn);
        b = (an * bn).sqrt();
        n += 1;
    }
    (a, c, n)
}

/// Complete elliptic integral of the first kind K(m) = ∫₀^{π/2} dθ / √(1 − m sin²θ), A&S 17.6.
pub fn ellipk(m: f64) -> Result<f64> {
    check_m(m)?;
    let (a, _, n) = agm(m);
    Ok(std::f64::consts::FRAC_PI_2 / a[n])
}

/// Jacobi elliptic functions (sn, cn, dn)(u | m) by the descending Landen transformation,
/// A&S 16.4. The argument is first reduced modulo the real period 4K, so that large |u| loses
/// no accuracy beyond that of the reduction.
pub fn ellipj(u: f64, m: f64) -> Result<(f64, f64, f64)> {
    check_m(m)?;
    if !u.is_finite() {
        return Err(Error::NonFinite {
            what: "u".into(),
            location: format!("the argument u of ellipj (u = {u})"),
        });
    }
    Ok(ellipj_unchecked(u, m))
}

/// [`ellipj`] without validation (0 ≤ m < 1 and u finite are the caller's duty).
pub fn ellipj_unchecked(u: f64, m: f64) -> (f64, f64, f64) {
    let (a, c, n) = agm(m);
    let k4 = 4.0 * std::f64::consts::FRAC_PI_2 / a[n];
    let u = u - k4 * (u / k4).round();
    let mut phi = (1u64 << n) as f64 * a[n] * u;
    for j in (1..=n).rev() {
        phi = 0.5 * (phi + (c[j] / a[j] * phi.sin()).asin());
    }
    let (sn, cn) = phi.sin_cos();
    // dn > 0 for real u and 0 ≤ m < 1 (A&S 16.9), so this root is exact and stable.
    let dn = (1.0 - m * sn * sn).sqrt();
    (sn, cn, dn)
}

/// Carlson's symmetric elliptic integral R_F(x, y, z) for x, y, z ≥ 0 (at most one zero), by the
/// duplication theorem (Carlson 1995, algorithm for R_F with its fifth-order series).
fn carlson_rf(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    loop {
        let mu = (x + y + z) / 3.0;
        let (dx, dy, dz) = (1.0 - x / mu, 1.0 - y / mu, 1.0 - z / mu);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-3 {
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 + (e2 / 24.0 - 0.1 - 3.0 * e3 / 44.0) * e2 + e3 / 14.0) / mu.sqrt();
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * (sy + sz) + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
}

/// Incomplete elliptic integral of the first kind F(φ | m) = ∫₀^φ dθ / √(1 − m sin²θ) for any
/// real φ (A&S 17.2.6), using F(φ + jπ | m) = F(φ | m) + 2jK(m) (A&S 17.4.3). It inverts the
/// amplitude: sn(F(φ | m) | m) = sin φ, cn(F(φ | m) | m) = cos φ.
pub fn ellipf(phi: f64, m: f64) -> Result<f64> {
    check_m(m)?;
    if !phi.is_finite() {
        return Err(Error::NonFinite {
            what: "phi".into(),
            location: format!("the argument phi of ellipf (phi = {phi})"),
        });
    }
    Ok(ellipf_unchecked(phi, m))
}

/// [`ellipf`] without validation.
pub fn ellipf_unchecked(phi: f64, m: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let j = (phi / pi).round();
    let r = phi - j * pi; // |r| ≤ π/2
    let (s, c) = r.sin_cos();
    let f = s * carlson_rf(c * c, 1.0 - m * s * s, 1.0);
    if j == 0.0 {
        f
    } else {
        let (a, _, n) = agm(m);
        f + j * 2.0 * std::f64::consts::FRAC_PI_2 / a[n]
    }
}
