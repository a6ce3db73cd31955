//! Jacobi elliptic functions sn, cn, dn, the complete integral K, the incomplete integral F and
//! Carlson's symmetric integrals R_F, R_D and R_J.
//!
//! Conventions follow Abramowitz & Stegun ch. 16–17 and scipy: the *parameter* `m = k²` (not the
//! modulus k), `0 ≤ m < 1`; near m = 1 the complementary parameter m₁ = 1 − m (or the
//! complementary modulus k′ = √m₁) is the argument instead ([`ellipj_complement`],
//! [`ellipj_kprime`], [`ellipk_complement`]), down to m₁ = 0 (the homoclinic limit sn = tanh,
//! cn = dn = sech). sn, cn, dn are computed by the descending Landen (Gauss) transformation
//! (A&S 16.12) written in k′ only, with 1 − cn and 1 − dn carried along and the reflection about
//! u = K (A&S 16.8), so that every step is a sum or product of positive terms; K(m) =
//! π / (2 AGM(1, √(1−m))) (A&S 17.6); F(φ | m) by Carlson's symmetric integral R_F (Carlson 1995,
//! "Numerical computation of real or complex elliptic integrals"):
//! F(φ | m) = sin φ · R_F(cos²φ, 1 − m sin²φ, 1).
//!
//! Carlson's symmetric integrals themselves (Carlson 1995; DLMF 19.16.1, 19.16.5),
//! R_F(x, y, z) = ½ ∫₀^∞ dt / √((t+x)(t+y)(t+z)) ([`carlson_rf`]) and
//! R_D(x, y, z) = 3/2 ∫₀^∞ dt (t+x)^{−1/2}(t+y)^{−1/2}(t+z)^{−3/2} ([`carlson_rd`]), are computed
//! by the duplication theorem with Carlson's fifth-order series, in a form that overflows for no
//! finite argument; they give the incomplete integral of the second kind
//! E(φ | m) = sin φ R_F − (m/3) sin³φ R_D(cos²φ, 1 − m sin²φ, 1) and the index symbols of a
//! homogeneous ellipsoid ([`crate::pseudo_rigid::gravity`]).
//!
//! These serve the exact solution of the free rigid body ([`crate::systems::tops::rigid_body`]), the
//! pendulum ([`crate::systems::pendulum`]) and the self-gravity of an ellipsoid.

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

/// Jacobi elliptic functions (sn, cn, dn)(u | m), 0 ≤ m < 1, by the descending Landen (Gauss)
/// transformation A&S 16.12 in complementary form with k′ = √(1 − m) (exact enough: 1 − m is
/// exact for m ≥ ½), see [`ellipj_complement`], which this is. The argument is first reduced
/// modulo the real period 4K, so that large |u| loses no accuracy beyond that of the reduction.
/// Near m = 1, where 1 − m is not representable as a difference, use [`ellipj_complement`].
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
    ellipj_kprime_unchecked(u, (1.0 - m).sqrt(), m)
}

/// Largest number of descending Landen (Gauss) levels in [`ellipj_complement`]: m₁ → 4√m₁/(1+√m₁)²
/// takes the least positive m₁ (5e-324) to a bottom parameter μ < 1e-10 in 12 levels.
const LANDEN_MAX: usize = 24;

/// The bottom of the Landen descent: below this μ the first-order expansions in μ (A&S 16.13) are
/// exact to O(μ²) < 1e-20.
const LANDEN_BOTTOM: f64 = 1e-10;

fn check_m1(m1: f64) -> Result<()> {
    if m1.is_finite() && (0.0..=1.0).contains(&m1) {
        Ok(())
    } else {
        Err(Error::invalid(
            "m1",
            format!(
                "the complementary parameter m₁ = 1 − m must satisfy 0 ≤ m₁ ≤ 1, got {}",
                crate::error::fmt_num(m1)
            ),
        ))
    }
}

/// AGM(1, k′) for 0 < k′ ≤ 1: positive terms only, so it is accurate to a few ulp for every k′
/// down to the least subnormal (about 14 steps there).
fn agm_kprime(kp: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, kp);
    for _ in 0..2 * AGM_MAX {
        if a - b <= f64::EPSILON * a {
            break;
        }
        let an = 0.5 * (a + b);
        b = a.sqrt() * b.sqrt();
        a = an;
    }
    0.5 * (a + b)
}

/// K = π / (2 AGM(1, k′)), +∞ at k′ = 0.
pub(crate) fn ellipk_kprime(kp: f64) -> f64 {
    if kp == 0.0 {
        f64::INFINITY
    } else {
        std::f64::consts::FRAC_PI_2 / agm_kprime(kp)
    }
}

fn check_kp(kp: f64) -> Result<()> {
    if kp.is_finite() && (0.0..=1.0).contains(&kp) {
        Ok(())
    } else {
        Err(Error::invalid(
            "kp",
            format!(
                "the complementary modulus k′ = √(1 − m) must satisfy 0 ≤ k′ ≤ 1, got {}",
                crate::error::fmt_num(kp)
            ),
        ))
    }
}

fn check_u(u: f64, function: &str) -> Result<()> {
    if u.is_finite() {
        Ok(())
    } else {
        Err(Error::NonFinite {
            what: "u".into(),
            location: format!("the argument u of {function} (u = {u})"),
        })
    }
}

/// K(m) from the complementary parameter m₁ = 1 − m: K = π / (2 AGM(1, √m₁)) (A&S 17.6), with
/// relative accuracy of a few ulp for every 0 < m₁ ≤ 1 (m = 1 − m₁ need not be representable);
/// K = +∞ at m₁ = 0 (the logarithmic singularity K ≈ ½ ln(16/m₁)).
pub fn ellipk_complement(m1: f64) -> Result<f64> {
    check_m1(m1)?;
    Ok(ellipk_kprime(m1.sqrt()))
}

/// Jacobi (sn, cn, dn)(u | m) from the complementary parameter m₁ = 1 − m, 0 ≤ m₁ ≤ 1: accurate
/// as m → 1, where m itself cannot carry m₁ (m₁ < 2⁻⁵³ rounds m to 1).
///
/// * m₁ = 0 (m = 1, the homoclinic limit): sn = tanh u, cn = dn = sech u (A&S 16.6), exactly.
/// * m₁ > 0: u is reduced modulo 4K (K from m₁, [`ellipk_complement`]) and by the symmetries
///   sn(2K − x) = sn x, cn(2K − x) = −cn x (A&S 16.8) to 0 ≤ x ≤ K. For x ≤ K/2 the descending
///   Landen (Gauss) transformation is applied in terms of the complementary modulus
///   k′ = √m₁ only (A&S 16.12 with r = √μ = (1 − k′)/(1 + k′) = (1 − m₁)/(1 + k′)²,
///   1 − r = 2k′/(1 + k′), and the next complementary parameter 1 − μ = 4k′/(1 + k′)², so
///   nothing is a difference of nearly equal numbers), down to μ < 1e-10 where A&S 16.13 holds to
///   O(μ²); on the way up sn ← (1 + r) sn / (1 + r sn²), and cn, dn together with their
///   complements 1 − cn, 1 − dn by sums of positive terms (see `landen`). For K/2 < x ≤ K the
///   reflection x = K − w (A&S 16.8.2): sn = cd w, cn = k′ sd w, dn = k′ nd w, so cn and dn
///   (both of order k′ near x = K) keep their relative accuracy.
///
/// Accuracy: ≤ 1e-14 relative against mpmath for m₁ from 0.5 down to 1e-300 (tested), up to the
/// conditioning of the reduction of u (an absolute error of about ulp(K) in x).
pub fn ellipj_complement(u: f64, m1: f64) -> Result<(f64, f64, f64)> {
    check_m1(m1)?;
    check_u(u, "ellipj_complement")?;
    Ok(ellipj_kprime_unchecked(u, m1.sqrt(), 1.0 - m1))
}

/// [`ellipj_complement`] with the complementary modulus k′ = √(1 − m), 0 ≤ k′ ≤ 1, itself: it
/// reaches m₁ = k′² below the least positive double (k′ ≥ 5e-324).
pub fn ellipj_kprime(u: f64, kp: f64) -> Result<(f64, f64, f64)> {
    check_kp(kp)?;
    check_u(u, "ellipj_kprime")?;
    Ok(ellipj_kprime_unchecked(u, kp, (1.0 - kp) * (1.0 + kp)))
}

/// (sn, cn, dn)(u | m) from both k′ = √(1 − m) and m = 1 − k′² (each as accurately as the caller
/// knows it: k′ carries the parameter near m = 1, m near m = 0); no validation (0 ≤ k′ ≤ 1,
/// m = 1 − k′² and u finite are the caller's duty). See [`ellipj_complement`].
pub fn ellipj_kprime_unchecked(u: f64, kp: f64, m: f64) -> (f64, f64, f64) {
    if kp == 0.0 {
        let sech = 1.0 / u.cosh();
        return (u.tanh(), sech, sech);
    }
    let k = ellipk_kprime(kp);
    let k4 = 4.0 * k;
    let r = u - k4 * (u / k4).round(); // |r| ≤ 2K
    let sg = if r < 0.0 { -1.0 } else { 1.0 }; // sn odd, cn and dn even
    let mut x = r.abs();
    let mut cs = 1.0;
    if x > k {
        x = (2.0 * k - x).max(0.0); // exact (Sterbenz): K < x ≤ 2K
        cs = -1.0;
    }
    let (sn, cn, dn) = if x > 0.5 * k {
        let (s, c, d) = landen((k - x).max(0.0), kp, m);
        (c / d, kp * s / d, kp / d)
    } else {
        landen(x, kp, m)
    };
    (sg * sn, cs * cn, dn)
}

/// (sn, cn, dn)(x | m) with k′ = √(1 − m) by the descending Landen transformation in
/// complementary form; see [`ellipj_complement`]. Relative accuracy for 0 ≤ x ≤ K/2, where
/// cn, dn ≥ √(k′/2).
pub(crate) fn landen(x: f64, kp: f64, m: f64) -> (f64, f64, f64) {
    let mut r = [0.0; LANDEN_MAX];
    let mut omr = [0.0; LANDEN_MAX];
    let mut s = kp; // √(1 − μ) at the current level
    let mut mu = m;
    let mut v = x;
    let mut n = 0;
    while mu > LANDEN_BOTTOM && n < LANDEN_MAX {
        let rj = mu / ((1.0 + s) * (1.0 + s)); // (1 − k′)/(1 + k′), as (1 − k′²)/(1 + k′)²
        r[n] = rj;
        omr[n] = 2.0 * s / (1.0 + s);
        v /= 1.0 + rj;
        mu = rj * rj;
        s = 2.0 * s.sqrt() / (1.0 + s); // √(4k′/(1 + k′)²)
        n += 1;
    }
    // A&S 16.13 at the bottom parameter μ < 1e-10, with the complements c = 1 − cn, d = 1 − dn
    // (1 − cos v = 2 sin²(v/2)).
    let (sv, cv) = v.sin_cos();
    let q = 0.25 * mu * (v - sv * cv);
    let sh = (0.5 * v).sin();
    let (mut sn, mut cn, mut dn) = (sv - q * cv, cv + q * sv, 1.0 - 0.5 * mu * sv * sv);
    let (mut c, mut d) = (2.0 * sh * sh - q * sv, 0.5 * mu * sv * sv);
    // Going up, each level is close to a doubling of the argument when r ≈ 1 (m → 1), which
    // would double the relative error of cn and dn near 1 at every level. So the complements are
    // carried along by their own sums of positive terms,
    //   1 − dn' = 2r sn² / (1 + r sn²),  1 − cn' = (r sn² + c + d·cn) / (1 + r sn²)
    // (from 1 − cn·dn = c + d·cn), and cn, dn are taken as 1 − c, 1 − d where c, d ≤ ½ and
    // from the products where they are small.
    for j in (0..n).rev() {
        let s2 = sn * sn;
        let den = 1.0 + r[j] * s2;
        let c_up = (r[j] * s2 + c + d * cn) / den;
        let d_up = 2.0 * r[j] * s2 / den;
        let cn_up = if c_up <= 0.5 {
            1.0 - c_up
        } else {
            cn * dn / den
        };
        let dn_up = if d_up <= 0.5 {
            1.0 - d_up
        } else {
            (omr[j] + r[j] * cn * cn) / den
        };
        sn = (1.0 + r[j]) * sn / den;
        (cn, dn, c, d) = (cn_up, dn_up, c_up, d_up);
    }
    (sn, cn, dn)
}

/// The u ∈ [−K, K] with sn u = `sn`, cn u = `cn` ≥ 0 and dn u = `dn` ≥ 0 (the incomplete integral
/// F(φ | m) with sin φ = sn, cos φ = cn, 1 − m sin²φ = dn²): u = sn · R_F(cn², dn², 1)
/// (Carlson 1995, (4.5)). The parameter enters only through dn, so near m = 1 no m or 1 − m is
/// formed; valid at m = 1 (dn = cn: u = artanh sn). The first duplication step is taken with
/// the square roots cn, dn, 1 themselves (λ = cn·dn + cn + dn), so cn² and dn² may underflow.
/// Not both cn and dn may vanish (that is u = ±K at m = 1, infinite).
pub(crate) fn ellipf_from_jacobi(sn: f64, cn: f64, dn: f64) -> f64 {
    let lambda = cn * dn + cn + dn;
    let x = 0.25 * (cn * cn + lambda);
    let y = 0.25 * (dn * dn + lambda);
    let z = 0.25 * (1.0 + lambda);
    sn * rf_kernel(x, y, z)
}

/// Largest number of duplication steps of [`rf_kernel`] and [`rd_kernel`]. Each step takes the
/// arguments to (x + λ)/4, λ = √x√y + √x√z + √y√z: an extreme spread (ratio 2⁻²¹⁰⁰, the widest
/// two finite doubles can have) is halved in the exponent per step, and from a spread of order one
/// the relative deviations 1 − x/μ shrink by 4 per step, so every argument converges in fewer
/// than 30 steps; the cap only bounds the loop for arguments outside the domain (two zeros).
const CARLSON_MAX: usize = 64;

/// The duplication stops when every |1 − x/μ| < CARLSON_TOL: the neglected sixth-order terms of
/// Carlson's series are then below 1e-18 relative.
const CARLSON_TOL: f64 = 1e-3;

/// The power of four 4^k by which [`carlson_rf`] and [`carlson_rd`] divide arguments whose
/// largest entry m is below 1e-100 (k < 0, m/4^k ∈ [1, 4); exact), so that no argument is
/// subnormal where the others are too; k = 0 otherwise (the kernels overflow for no finite
/// argument, so large arguments need no scaling).
fn carlson_scale(m: f64) -> i32 {
    let e = crate::check::pow2_exponent(m);
    if e < 0 {
        e.div_euclid(2)
    } else {
        0
    }
}

fn check_carlson(function: &str, args: [(&str, f64); 3]) -> Result<()> {
    for (what, v) in args {
        if !v.is_finite() {
            return Err(Error::NonFinite {
                what: what.into(),
                location: format!("the argument {what} of {function} ({what} = {v})"),
            });
        }
        if v < 0.0 {
            return Err(Error::invalid(
                what,
                format!(
                    "the arguments of {function} must be ≥ 0, got {what} = {}",
                    crate::error::fmt_num(v)
                ),
            ));
        }
    }
    Ok(())
}

/// Carlson's symmetric elliptic integral of the first kind
/// R_F(x, y, z) = ½ ∫₀^∞ dt / √((t+x)(t+y)(t+z)) (Carlson 1995 (2.1), DLMF 19.16.1), for finite
/// x, y, z ≥ 0 of which at most one is zero.
///
/// By the duplication theorem R_F(x, y, z) = R_F((x+λ)/4, (y+λ)/4, (z+λ)/4),
/// λ = √x√y + √x√z + √y√z, until the arguments agree to 1e-3, then Carlson's
/// fifth-order series R_F = μ^{−1/2}(1 − E₂/10 + E₃/14 + E₂²/24 − 3E₂E₃/44) (Carlson 1995 §2).
/// Every step is a sum or product of positive terms; it is written on quarters (x/4 + λ/4), so it
/// overflows for no finite argument, and arguments below 1e-100 are first scaled by an exact power
/// of four (R_F is homogeneous of degree −1/2). Relative error ≤ 1e-15 measured against mpmath
/// (40 digits) for argument ratios from 1 to 1e-6 and at coincident arguments
/// (`tests/carlson.rs`). Special values: R_F(x, x, x) = x^{−1/2}, R_F(0, 1 − m, 1) = K(m),
/// F(φ | m) = sin φ R_F(cos²φ, 1 − m sin²φ, 1).
///
/// Errors: [`Error::NonFinite`] for a NaN or infinite argument, [`Error::InvalidArgument`] for a
/// negative one or more than one zero (R_F = ∞ there).
pub fn carlson_rf(x: f64, y: f64, z: f64) -> Result<f64> {
    check_carlson("carlson_rf", [("x", x), ("y", y), ("z", z)])?;
    if [x, y, z].iter().filter(|&&v| v == 0.0).count() > 1 {
        return Err(Error::invalid(
            "x, y, z",
            format!(
                "R_F(x, y, z) needs at most one zero argument (it is infinite otherwise), got \
                 ({}, {}, {})",
                crate::error::fmt_num(x),
                crate::error::fmt_num(y),
                crate::error::fmt_num(z)
            ),
        ));
    }
    let k = carlson_scale(x.max(y).max(z));
    let s = |v: f64| crate::check::ldexp(v, -2 * k);
    let r = rf_kernel(s(x), s(y), s(z));
    carlson_result("carlson_rf", "R_F(x, y, z)", r, -k)
}

/// Carlson's symmetric elliptic integral of the second kind
/// R_D(x, y, z) = 3/2 ∫₀^∞ dt (t+x)^{−1/2}(t+y)^{−1/2}(t+z)^{−3/2} (Carlson 1995 (2.4),
/// DLMF 19.16.5), symmetric in x and y only, for finite x, y ≥ 0 with x + y > 0 and z > 0.
///
/// By the duplication theorem R_D(x, y, z) = ¼ R_D((x+λ)/4, (y+λ)/4, (z+λ)/4) + 3/(√z (z + λ))
/// (Carlson 1995 (2.29)), until the arguments agree to 1e-3, then Carlson's
/// fifth-order series μ^{−3/2}(1 − 3E₂/14 + E₃/6 + 9E₂²/88 − 3E₄/22 − 9E₂E₃/52 + 3E₅/26) with
/// μ = (x + y + 3z)/5 (Carlson 1995 §2); all terms are positive, written on quarters like
/// [`carlson_rf`] (no overflow for finite arguments), and arguments below 1e-100 are first scaled
/// by an exact power of four (R_D is homogeneous of degree −3/2). Relative error ≤ 1e-15 measured
/// against mpmath (40 digits) for argument ratios from 1 to 1e-6 and at coincident arguments
/// (`tests/carlson.rs`). Special values: R_D(x, x, x) = x^{−3/2},
/// R_D(x, y, z) + R_D(y, z, x) + R_D(z, x, y) = 3/√(xyz) (DLMF 19.21.12), and
/// E(φ | m) = sin φ R_F(c, Δ, 1) − (m/3) sin³φ R_D(c, Δ, 1) with c = cos²φ, Δ = 1 − m sin²φ.
///
/// Errors: [`Error::NonFinite`] for a NaN or infinite argument, [`Error::InvalidArgument`] for a
/// negative one, x = y = 0 or z = 0 (R_D = ∞ there), and the overflow error
/// ([`Error::InvalidArgument`]) where R_D exceeds the f64 range (arguments near the least
/// doubles: R_D(x, x, x) = x^{−3/2}).
pub fn carlson_rd(x: f64, y: f64, z: f64) -> Result<f64> {
    check_carlson("carlson_rd", [("x", x), ("y", y), ("z", z)])?;
    if z == 0.0 || (x == 0.0 && y == 0.0) {
        return Err(Error::invalid(
            if z == 0.0 { "z" } else { "x, y" },
            format!(
                "R_D(x, y, z) needs z > 0 and x + y > 0 (it is infinite otherwise), got ({}, {}, \
                 {})",
                crate::error::fmt_num(x),
                crate::error::fmt_num(y),
                crate::error::fmt_num(z)
            ),
        ));
    }
    let k = carlson_scale(x.max(y).max(z));
    let s = |v: f64| crate::check::ldexp(v, -2 * k);
    let r = rd_kernel(s(x), s(y), s(z));
    carlson_result("carlson_rd", "R_D(x, y, z)", r, -3 * k)
}

/// r·2^e, or the error of a kernel that did not converge (NaN: not reached in the domain) or of a
/// result beyond the f64 range.
fn carlson_result(function: &str, quantity: &str, r: f64, e: i32) -> Result<f64> {
    if r.is_nan() {
        return Err(Error::NotConverged {
            what: format!("the duplication of {function}"),
            iterations: CARLSON_MAX,
            residual: f64::NAN,
            tol: CARLSON_TOL,
        });
    }
    crate::check::unscale("x, y, z", quantity, r, e)
}

/// [`carlson_rf`] without validation or scaling: x, y, z finite and ≥ 0, at most one zero (NaN
/// otherwise, after [`CARLSON_MAX`] steps). Accurate for normal arguments; the scaling of
/// [`carlson_rf`] keeps subnormal arguments from being the largest.
pub(crate) fn rf_kernel(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    for _ in 0..CARLSON_MAX {
        // μ = (x + y + z)/3 on quarters (no overflow).
        let mu = (0.25 * x + 0.25 * y + 0.25 * z) / 0.75;
        let (dx, dy) = (1.0 - x / mu, 1.0 - y / mu);
        let dz = -(dx + dy);
        if dx.abs().max(dy.abs()).max(dz.abs()) < CARLSON_TOL {
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 + (e2 / 24.0 - 0.1 - 3.0 * e3 / 44.0) * e2 + e3 / 14.0) / mu.sqrt();
        }
        // λ/4 from the halved square roots: the same rounding as λ/4, no overflow.
        let (sx, sy, sz) = (0.5 * x.sqrt(), 0.5 * y.sqrt(), 0.5 * z.sqrt());
        let lam = sx * (sy + sz) + sy * sz;
        x = 0.25 * x + lam;
        y = 0.25 * y + lam;
        z = 0.25 * z + lam;
    }
    f64::NAN
}

/// [`carlson_rd`] without validation or scaling: x, y ≥ 0 with x + y > 0 and z > 0, finite (NaN
/// otherwise, after [`CARLSON_MAX`] steps); +∞ or 0 where the result leaves the f64 range.
pub(crate) fn rd_kernel(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    // R_D = 3 Σ_k 4^{−k} / (√z_k (z_k + λ_k)) + 4^{−n} R_D(x_n, y_n, z_n).
    let (mut sum, mut fac) = (0.0, 1.0);
    for _ in 0..CARLSON_MAX {
        // μ = (x + y + 3z)/5 on eighths (no overflow).
        let mu = (0.125 * x + 0.125 * y + 0.375 * z) / 0.625;
        let (dx, dy) = (1.0 - x / mu, 1.0 - y / mu);
        let dz = -(dx + dy) / 3.0; // X + Y + 3Z = 0
        if dx.abs().max(dy.abs()).max(dz.abs()) < CARLSON_TOL {
            let (xy, z2) = (dx * dy, dz * dz);
            let e2 = xy - 6.0 * z2;
            let e3 = (3.0 * xy - 8.0 * z2) * dz;
            let e4 = 3.0 * (xy - z2) * z2;
            let e5 = xy * z2 * dz;
            let series = 1.0
                + e2 * (-3.0 / 14.0 + 9.0 / 88.0 * e2 - 9.0 / 52.0 * e3)
                + e3 / 6.0
                + (-3.0 / 22.0) * e4
                + 3.0 / 26.0 * e5;
            // μ^{−3/2} as (1/√μ)/μ: underflows only where the result does.
            return 3.0 * sum + fac * series / mu.sqrt() / mu;
        }
        let (sx, sy, sz) = (0.5 * x.sqrt(), 0.5 * y.sqrt(), 0.5 * z.sqrt());
        let lam = sx * (sy + sz) + sy * sz; // λ/4
                                            // 4^{−k}/(√z (z + λ)) = 4^{−k}/(8 (√z/2)(z/4 + λ/4)).
        sum += 0.125 * fac / (sz * (0.25 * z + lam));
        fac *= 0.25;
        x = 0.25 * x + lam;
        y = 0.25 * y + lam;
        z = 0.25 * z + lam;
    }
    f64::NAN
}

/// Carlson's symmetric elliptic integral of the third kind
/// R_J(x, y, z, p) = 3/2 ∫₀^∞ dt (t+x)^{−1/2}(t+y)^{−1/2}(t+z)^{−1/2}(t+p)^{−1} (Carlson 1995
/// (2.5), DLMF 19.16.2), for finite x, y, z ≥ 0 of which at most one is zero and p > 0.
///
/// By the duplication theorem (DLMF 19.26.20, divided by 4^{3/2} by homogeneity)
/// R_J(x, y, z, p) = ¼ R_J(x′, y′, z′, p′) + 6 R_C(1, 1 + e)/d with x′ = (x + λ)/4, …,
/// λ = √x√y + √x√z + √y√z, d = (√p + √x)(√p + √y)(√p + √z) and
/// e = (p − x)(p − y)(p − z)/d² = Π_i (√p − √x_i)/(√p + √x_i), a product of ratios in (−1, 1)
/// formed from the square roots (no difference of the arguments, no overflow), and
/// 1 + e = 2√p(p + λ)/d; R_C(1, 1 + e) = atan(√e)/√e (e > 0) or atanh(√−e)/√−e (e < 0), by its
/// Taylor series for |e| < 10⁻² (after the first step e shrinks by about 64 per step). The
/// steps stop when the arguments agree to 1e-3 (as in [`carlson_rf`]); the remainder is
/// Carlson's fifth-order series μ^{−3/2}(1 − 3E₂/14 + E₃/6 + 9E₂²/88 − 3E₄/22 − 9E₂E₃/52 +
/// 3E₅/26) with μ = (x + y + z + 2p)/5, the deviations X = 1 − x/μ, …, P = 1 − p/μ and
/// E₂ = XY + XZ + YZ − 3P², E₃ = XYZ + 2E₂P + 4P³, E₄ = (2XYZ + E₂P + 3P³)P, E₅ = XYZP²
/// (Carlson 1995 §2; at p = z these are the E₂…E₅ of [`carlson_rd`]).
/// Arguments below 1e-100 are first scaled by an exact power of four (R_J is homogeneous of degree
/// −3/2); the kernel overflows for no finite argument (a term whose d overflows is below the
/// least double). Relative error ≤ 2e-15 against mpmath (`tests/carlson.rs`). Special values:
/// R_J(x, y, z, z) = R_D(x, y, z), R_J(x, x, x, x) = x^{−3/2}, and the incomplete integral of the
/// third kind Π(n; φ | m) = s R_F(c, Δ, 1) + (n/3) s³ R_J(c, Δ, 1, 1 − n s²) with s = sin φ,
/// c = cos²φ, Δ = 1 − m s² (DLMF 19.25.14; n < 1).
///
/// Errors: [`Error::NonFinite`] for a NaN or infinite argument, [`Error::InvalidArgument`] for a
/// negative one, p = 0 (the Cauchy principal value for p < 0 is not provided) or more than one
/// zero among x, y, z (R_J = ∞ there).
pub fn carlson_rj(x: f64, y: f64, z: f64, p: f64) -> Result<f64> {
    check_carlson("carlson_rj", [("x", x), ("y", y), ("z", z)])?;
    check_carlson("carlson_rj", [("p", p), ("p", p), ("p", p)])?;
    if p == 0.0 || [x, y, z].iter().filter(|&&v| v == 0.0).count() > 1 {
        return Err(Error::invalid(
            if p == 0.0 { "p" } else { "x, y, z" },
            format!(
                "R_J(x, y, z, p) needs p > 0 and at most one zero among x, y, z (it is infinite \
                 otherwise), got ({}, {}, {}, {})",
                crate::error::fmt_num(x),
                crate::error::fmt_num(y),
                crate::error::fmt_num(z),
                crate::error::fmt_num(p)
            ),
        ));
    }
    let k = carlson_scale(x.max(y).max(z).max(p));
    let s = |v: f64| crate::check::ldexp(v, -2 * k).sqrt();
    let r = rj_from_roots(s(x), s(y), s(z), s(p));
    carlson_result("carlson_rj", "R_J(x, y, z, p)", r, -3 * k)
}

/// R_C(1, y) for y = 1 + e, −1 < e < 1, given both e and y (each to its own relative accuracy):
/// the Taylor series Σ_k (−e)^k/(2k + 1) for |e| < 10⁻² (eight terms: the remainder is below
/// e⁸/17 < 10⁻¹⁷), atan(√e)/√e for e > 0, and for e < 0 atanh(s)/s = ln((1 + s)/√y)/s with
/// s = √(−e) (as (1 + s)/(1 − s) = (1 + s)²/y, accurate as y → 0 where atanh(s) is not).
#[inline]
fn rc_one(e: f64, y: f64) -> f64 {
    if e.abs() < 1e-2 {
        const C: [f64; 8] = [
            1.0,
            1.0 / 3.0,
            1.0 / 5.0,
            1.0 / 7.0,
            1.0 / 9.0,
            1.0 / 11.0,
            1.0 / 13.0,
            1.0 / 15.0,
        ];
        C.iter().rev().fold(0.0, |s, &c| c - e * s)
    } else if e > 0.0 {
        let r = e.sqrt();
        r.atan() / r
    } else {
        let r = (-e).sqrt();
        ((1.0 + r) / y.sqrt()).ln() / r
    }
}

/// [`carlson_rj`] from the square roots √x, √y, √z, √p of its arguments, without validation or
/// scaling (x, y, z ≥ 0 with at most one zero and p > 0, finite; NaN otherwise).
/// The first duplication step uses the roots themselves, so x, y, z may be squares that
/// underflow (cn², dn² near a separatrix): only their roots enter λ, d and e. With the roots
/// r_i and r_p, 1 + e = (d² + δ)/d² = 2r_p(p + λ)/d (the odd powers of Π(r_p ± r_i) cancel), a
/// product of positive terms, so R_C(1, 1 + e) keeps its accuracy as 1 + e → 0 (p ≪ x, y or z).
pub(crate) fn rj_from_roots(sx: f64, sy: f64, sz: f64, sp: f64) -> f64 {
    let (mut rx, mut ry, mut rz, mut rp) = (sx, sy, sz, sp);
    let (mut x, mut y, mut z, mut p) = (sx * sx, sy * sy, sz * sz, sp * sp);
    // R_J = 6 Σ_k 4^{−k} R_C(1, 1 + e_k)/d_k + 4^{−n} R_J(x_n, y_n, z_n, p_n).
    let (mut sum, mut fac) = (0.0, 1.0);
    for _ in 0..CARLSON_MAX {
        // μ = (x + y + z + 2p)/5 on eighths (no overflow).
        let mu = (0.125 * x + 0.125 * y + 0.125 * z + 0.25 * p) / 0.625;
        let (dx, dy, dz) = (1.0 - x / mu, 1.0 - y / mu, 1.0 - z / mu);
        let dp = -0.5 * (dx + dy + dz); // X + Y + Z + 2P = 0
        if dx.abs().max(dy.abs()).max(dz.abs()).max(dp.abs()) < CARLSON_TOL {
            let xyz = dx * dy * dz;
            let (p2, p3) = (dp * dp, dp * dp * dp);
            let e2 = dx * dy + dx * dz + dy * dz - 3.0 * p2;
            let e3 = xyz + 2.0 * e2 * dp + 4.0 * p3;
            let e4 = (2.0 * xyz + e2 * dp + 3.0 * p3) * dp;
            let e5 = xyz * p2;
            let series = 1.0
                + e2 * (-3.0 / 14.0 + 9.0 / 88.0 * e2 - 9.0 / 52.0 * e3)
                + e3 / 6.0
                + (-3.0 / 22.0) * e4
                + 3.0 / 26.0 * e5;
            return 6.0 * sum + fac * series / mu.sqrt() / mu;
        }
        // λ/4 from the halved roots (no overflow).
        let (hx, hy, hz) = (0.5 * rx, 0.5 * ry, 0.5 * rz);
        let lam = hx * (hy + hz) + hy * hz;
        let (ax, ay, az) = (rp + rx, rp + ry, rp + rz);
        let d = ax * ay * az;
        let (e, one_e, inv) = if d <= 1e300 {
            // One division per step.
            let inv = 1.0 / d;
            let e = (rp - rx) * (rp - ry) * (rp - rz) * inv;
            (e, 8.0 * rp * (0.25 * p + lam) * inv, inv)
        } else {
            // Huge arguments: ratios, no overflow (the term itself may underflow).
            let e = (rp - rx) / ax * ((rp - ry) / ay) * ((rp - rz) / az);
            let one_e = 8.0 * (rp / ax) * ((0.25 * p + lam) / ay) / az;
            (e, one_e, 1.0 / ax / ay / az)
        };
        sum += fac * rc_one(e, one_e) * inv;
        fac *= 0.25;
        x = 0.25 * x + lam;
        y = 0.25 * y + lam;
        z = 0.25 * z + lam;
        p = 0.25 * p + lam;
        (rx, ry, rz, rp) = (x.sqrt(), y.sqrt(), z.sqrt(), p.sqrt());
    }
    f64::NAN
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
    let f = s * rf_kernel(c * c, 1.0 - m * s * s, 1.0);
    if j == 0.0 {
        f
    } else {
        let (a, _, n) = agm(m);
        f + j * 2.0 * std::f64::consts::FRAC_PI_2 / a[n]
    }
}

#[cfg(test)]
#[allow(clippy::approx_constant, clippy::excessive_precision)] // mpmath reference values
mod tests {
    use super::*;

    // generated by mpmath (mp.dps = 420): (u, m1, sn, cn, dn)
    const SNCNDN_M1: &[(f64, f64, f64, f64, f64)] = &[
        (
            0.05562224031904116,
            0.5,
            0.05557925539922523,
            0.9984542785572446,
            0.9992274381664236,
        ),
        (
            0.5562224031904116,
            0.5,
            0.5165541651141227,
            0.8562545150264912,
            0.9309059551058989,
        ),
        (
            0.9270373386506859,
            0.5,
            0.7653668647301796,
            0.6435942529055826,
            0.8408964152537145,
        ),
        (
            1.2978522741109602,
            0.5,
            0.9198077532215213,
            0.3923693376317485,
            0.7595899213106955,
        ),
        (
            1.7984524369823307,
            0.5,
            0.9992262426153972,
            0.03933085390269843,
            0.7076534872622036,
        ),
        (
            1.8540746773013719,
            0.5,
            1.0,
            2.98456382067177e-17,
            0.7071067811865476,
        ),
        (
            2.5957045482219203,
            0.5,
            0.8538797904916137,
            -0.5204702713796417,
            0.7971478229883081,
        ),
        (
            5.3768165641739785,
            0.5,
            -0.9913692808281386,
            -0.13109900468843885,
            0.7131573981353272,
        ),
        (
            -6.118446435094527,
            0.5,
            0.9198077532215214,
            0.39236933763174825,
            0.7595899213106954,
        ),
        (
            14.090967547490425,
            0.5,
            -0.65291562790516,
            0.7574306455624902,
            0.8870459917155397,
        ),
        (
            0.5,
            0.5,
            0.4707504736556573,
            0.8822663948904403,
            0.9429724257773857,
        ),
        (
            3.0,
            0.5,
            0.6300289982420332,
            -0.776571607370589,
            0.8952830450126206,
        ),
        (
            0.07734276340044519,
            0.1,
            0.07719658695487966,
            0.9970158910280807,
            0.9973147037250909,
        ),
        (
            0.7734276340044519,
            0.1,
            0.6539423976332011,
            0.7565443414484972,
            0.7842980342446144,
        ),
        (
            1.2890460566740867,
            0.1,
            0.8716346291009541,
            0.4901561724104289,
            0.5623413251903491,
        ),
        (
            1.8046644793437212,
            0.1,
            0.9646133337273404,
            0.26366857301435587,
            0.40319846819635125,
        ),
        (
            2.500749349947728,
            0.1,
            0.9997003827418827,
            0.024477433397588032,
            0.3170792176588684,
        ),
        (
            2.5780921133481733,
            0.1,
            1.0,
            -5.690966659509484e-17,
            0.31622776601683794,
        ),
        (
            3.6093289586874424,
            0.1,
            0.9289337738867205,
            -0.37024592331661843,
            0.47262441680399647,
        ),
        (
            7.476467128709702,
            0.1,
            -0.9966119298357238,
            -0.08224756111347263,
            0.32571182842844837,
        ),
        (
            -8.50770397404897,
            0.1,
            0.9646133337273405,
            0.26366857301435553,
            0.403198468196351,
        ),
        (
            19.593500061446115,
            0.1,
            -0.7833829784341518,
            0.6215393061582165,
            0.6690889314505759,
        ),
        (
            0.5,
            0.1,
            0.4638403680117277,
            0.8859187959416738,
            0.8979793436947593,
        ),
        (
            3.0,
            0.1,
            0.9906305999378325,
            -0.1365687170138534,
            0.3417395397376911,
        ),
        (
            0.11086912088969623,
            0.01,
            0.11041932619837352,
            0.9938850901396484,
            0.9939464254565626,
        ),
        (
            1.1086912088969623,
            0.01,
            0.8046254533720189,
            0.5937826873409775,
            0.5992095634984596,
        ),
        (
            1.8478186814949373,
            0.01,
            0.9534625892455924,
            0.30151134457776363,
            0.31622776601683794,
        ),
        (
            2.586946154092912,
            0.01,
            0.9909432751276576,
            0.13428114342405484,
            0.16688652199767023,
        ),
        (
            3.5847682421001785,
            0.01,
            0.9999382911238038,
            0.0111091828865578,
            0.100609044349715,
        ),
        (3.6956373629898747, 0.01, 1.0, 3.962169442181278e-19, 0.1),
        (
            5.173892308185824,
            0.01,
            0.9786949006055207,
            -0.20531997352607975,
            0.22745269533127674,
        ),
        (
            10.717348352670637,
            0.01,
            -0.9992858688121729,
            -0.03778561091607406,
            0.10683386573731161,
        ),
        (
            -12.195603297866585,
            0.01,
            0.9909432751276576,
            0.13428114342405453,
            0.16688652199766998,
        ),
        (
            28.086843958723048,
            0.01,
            -0.9026930774640353,
            0.4302850309951641,
            0.4396518575185646,
        ),
        (
            0.5,
            0.01,
            0.4622893992991469,
            0.8867291081810915,
            0.8879333455742484,
        ),
        (
            3.0,
            0.01,
            0.9971703129000018,
            0.07517557496230041,
            0.12487935538031626,
        ),
        (
            0.1797476802152099,
            0.0001,
            0.17783663346321615,
            0.9840600244895987,
            0.9840616313957626,
        ),
        (
            1.7974768021520988,
            0.0001,
            0.9465630754513628,
            0.3225187501402946,
            0.3226576240500735,
        ),
        (
            2.995794670253498,
            0.0001,
            0.9950371902099892,
            0.09950371902099893,
            0.1,
        ),
        (
            4.194112538354897,
            0.0001,
            0.9995695935895277,
            0.029336454647185567,
            0.03099260409370676,
        ),
        (
            5.811841660291786,
            0.0001,
            0.999998367067557,
            0.0018071696709786225,
            0.010161965146244255,
        ),
        (5.991589340506996, 0.0001, 1.0, 1.6985172479488416e-18, 0.01),
        (
            8.388225076709794,
            0.0001,
            0.99851740816377,
            -0.054433313273282005,
            0.055341569324946584,
        ),
        (
            17.375609087470288,
            0.0001,
            -0.9999797973467879,
            -0.0063564847421399475,
            0.01184908679127764,
        ),
        (
            -19.772244823673088,
            0.0001,
            0.9995695935895277,
            0.029336454647185546,
            0.03099260409370674,
        ),
        (
            45.53607898785317,
            0.0001,
            -0.9835881767947054,
            0.180428097783209,
            0.18069599619200272,
        ),
        (
            0.5,
            0.0001,
            0.4621188795931607,
            0.8868179864682277,
            0.8868300268424888,
        ),
        (
            3.0,
            0.0001,
            0.9950788601994242,
            0.09908613416727281,
            0.09958453784607511,
        ),
        (
            0.3178990427126298,
            1e-08,
            0.30760599089599183,
            0.9515138224770542,
            0.9515138229742695,
        ),
        (
            3.178990427126298,
            1e-08,
            0.9965402735036513,
            0.08311127050688093,
            0.08311133025161553,
        ),
        (
            5.29831737854383,
            1e-08,
            0.9999500037496876,
            0.009999500037496877,
            0.010000000000000002,
        ),
        (
            7.4176443299613615,
            1e-08,
            0.9999992811481369,
            0.0011990426220909647,
            0.001203205383637284,
        ),
        (
            10.27873571437503,
            1e-08,
            0.9999999994774481,
            3.232806328913532e-05,
            0.0001050956881397867,
        ),
        (10.59663475708766, 1e-08, 1.0, 3.038578467040901e-20, 0.0001),
        (
            14.835288659922723,
            1e-08,
            0.9999939968955706,
            -0.0034649924706318,
            0.0034664351575463426,
        ),
        (
            30.730240795554213,
            1e-08,
            -0.9999999919429443,
            -0.00012694136927740994,
            0.0001615986109868604,
        ),
        (
            -34.96889469838928,
            1e-08,
            0.9999992811481369,
            0.001199042622090962,
            0.0012032053836372814,
        ),
        (
            80.53442415386621,
            1e-08,
            -0.999583812519498,
            0.028847907185530375,
            0.028848080363569385,
        ),
        (
            0.5,
            1e-08,
            0.46211715743224296,
            0.8868188838803239,
            0.8868188850843594,
        ),
        (
            3.0,
            1e-08,
            0.9950547561003718,
            0.0993279032398735,
            0.09932795308154371,
        ),
        (
            0.45605414757263146,
            1e-12,
            0.42686278267927236,
            0.9043164074389607,
            0.9043164074390614,
        ),
        (
            4.560541475726314,
            1e-12,
            0.9997813514916599,
            0.02091050476458959,
            0.02091050478849056,
        ),
        (
            7.600902459543858,
            1e-12,
            0.999999500000375,
            0.000999999500000375,
            0.0009999999999999998,
        ),
        (
            10.6412634433614,
            1e-12,
            0.9999999988569873,
            4.781239676442222e-05,
            4.782285315993021e-05,
        ),
        (
            14.745750771515084,
            1e-12,
            0.9999999999998886,
            4.7202812994193834e-07,
            1.1058076484887688e-06,
        ),
        (
            15.201804919087715,
            1e-12,
            1.0,
            -1.7779607517770807e-22,
            1e-06,
        ),
        (
            21.2825268867228,
            1e-12,
            0.9999999760914378,
            -0.00021867126891200026,
            0.0002186735554371779,
        ),
        (
            44.08523426535437,
            1e-12,
            -0.9999999999976299,
            -2.1771890522402107e-06,
            2.3958614670280684e-06,
        ),
        (
            -50.16595623298946,
            1e-12,
            0.9999999988569873,
            4.781239676442209e-05,
            4.782285315993008e-05,
        ),
        (
            115.53371738506662,
            1e-12,
            -0.9999895436593919,
            0.004573026555918924,
            0.004573026665253416,
        ),
        (
            0.5,
            1e-12,
            0.462117157260027,
            0.8868188839700649,
            0.8868188839701854,
        ),
        (
            3.0,
            1e-12,
            0.9950547536869718,
            0.09932792741701525,
            0.09932792742199942,
        ),
        (
            0.5942092531521677,
            1e-16,
            0.5329161920558901,
            0.8461680283753633,
            0.8461680283753633,
        ),
        (
            5.942092531521677,
            1e-16,
            0.9999862027985674,
            0.00525301937006959,
            0.005253019370079107,
        ),
        (
            9.903487552536129,
            1e-16,
            0.999999995,
            9.999999949999993e-05,
            9.999999999999992e-05,
        ),
        (
            13.86488257355058,
            1e-16,
            0.9999999999981881,
            1.9036408060751328e-06,
            1.9036670713531767e-06,
        ),
        (
            19.21276585192009,
            1e-16,
            1.0,
            6.297994892091175e-09,
            1.1817983739234308e-08,
        ),
        (
            19.806975105072258,
            1e-16,
            1.0,
            -1.4316431630891157e-23,
            1e-08,
        ),
        (
            27.72976514710116,
            1e-16,
            0.9999999999048174,
            -1.3797294802006346e-05,
            1.3797298425904663e-05,
        ),
        (
            57.440227804709544,
            1e-16,
            -0.9999999999999993,
            -3.5549118353154175e-08,
            3.6928848014615385e-08,
        ),
        (
            -65.36301784673844,
            1e-16,
            0.9999999999981881,
            1.9036408060751266e-06,
            1.9036670713531706e-06,
        ),
        (
            150.53301079854916,
            1e-16,
            -0.9999997373472541,
            0.0007247795684605226,
            0.0007247795685295091,
        ),
        (
            0.5,
            1e-16,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-16,
            0.9950547536867305,
            0.09932792741943297,
            0.09932792741943347,
        ),
        (
            0.6287480295470783,
            1e-17,
            0.5571895343193899,
            0.830385345996027,
            0.830385345996027,
        ),
        (
            6.287480295470783,
            1e-17,
            0.999993084994987,
            0.0037188657153580853,
            0.0037188657153594297,
        ),
        (
            10.47913382578464,
            1e-17,
            0.9999999984188612,
            5.623413243012092e-05,
            5.6234132519034893e-05,
        ),
        (
            14.670787356098494,
            1e-17,
            0.9999999999996385,
            8.503280395261273e-07,
            8.503339195894441e-07,
        ),
        (
            20.3295196220222,
            1e-17,
            1.0,
            2.1218919931015505e-09,
            3.808205040486722e-09,
        ),
        (
            20.95826765156928,
            1e-17,
            1.0,
            -2.1326855018648403e-24,
            3.1622776601683795e-09,
        ),
        (
            29.341574712196987,
            1e-17,
            0.9999999999760912,
            -6.915028560198317e-06,
            6.9150292832610914e-06,
        ),
        (
            60.77897618955091,
            1e-17,
            -0.9999999999999999,
            -1.266364611947161e-08,
            1.3052506772233768e-08,
        ),
        (
            -69.16228325017862,
            1e-17,
            0.9999999999996385,
            8.503280395261236e-07,
            8.503339195894403e-07,
        ),
        (
            159.28283415192652,
            1e-17,
            -0.9999998954360502,
            0.0004573050280130493,
            0.00045730502802398296,
        ),
        (
            0.5,
            1e-17,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-17,
            0.9950547536867305,
            0.09932792741943318,
            0.09932792741943323,
        ),
        (
            0.7323643587318104,
            1e-20,
            0.6245097091349008,
            0.7810170441137899,
            0.7810170441137899,
        ),
        (
            7.323643587318104,
            1e-20,
            0.9999991294498156,
            0.001319507336423965,
            0.001319507336423969,
        ),
        (
            12.206072645530174,
            1e-20,
            0.99999999995,
            9.999999999499997e-06,
            9.999999999999997e-06,
        ),
        (
            17.088501703742242,
            1e-20,
            0.9999999999999971,
            7.578579533782211e-08,
            7.578586131321764e-08,
        ),
        (
            23.679780932328537,
            1e-20,
            1.0,
            7.996108584845596e-11,
            1.2803817887670906e-10,
        ),
        (
            24.412145291060348,
            1e-20,
            1.0,
            -5.425811579939814e-26,
            1e-10,
        ),
        (
            34.177003407484484,
            1e-20,
            0.9999999999996211,
            -8.705505604242115e-07,
            8.705505661677032e-07,
        ),
        (
            70.795221344075,
            1e-20,
            -1.0,
            -5.699964246820396e-10,
            5.787019303150008e-10,
        ),
        (
            -80.56007946049914,
            1e-20,
            0.9999999999999971,
            7.578579533782146e-08,
            7.5785861313217e-08,
        ),
        (
            185.53230421205862,
            1e-20,
            -0.9999999934024605,
            0.00011486983512075013,
            0.00011486983512079366,
        ),
        (
            0.5,
            1e-20,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-20,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
        (
            1.0777521226809172,
            1e-30,
            0.7923640175131755,
            0.6100485749105395,
            0.6100485749105395,
        ),
        (
            10.777521226809172,
            1e-30,
            0.9999999991294495,
            4.1726503868363245e-05,
            4.1726503868363245e-05,
        ),
        (
            17.96253537801529,
            1e-30,
            0.9999999999999994,
            3.162277660168374e-08,
            3.162277660168375e-08,
        ),
        (
            25.1475495292214,
            1e-30,
            1.0,
            2.396558317668319e-11,
            2.3965583197546442e-11,
        ),
        (
            34.84731863334966,
            1e-30,
            1.0,
            1.2988539767171355e-15,
            1.6392137300650934e-15,
        ),
        (
            35.92507075603058,
            1e-30,
            1.0,
            -2.5852877943251388e-30,
            1e-15,
        ),
        (
            50.2950990584428,
            1e-30,
            1.0,
            -8.705505632958327e-10,
            8.70550563296407e-10,
        ),
        (
            104.18270519248867,
            1e-30,
            -1.0,
            -1.8148751118404678e-14,
            1.817628034438826e-14,
        ),
        (
            -118.55273349490089,
            1e-30,
            1.0,
            2.3965583176682928e-11,
            2.396558319754618e-11,
        ),
        (
            273.03053774583236,
            1e-30,
            -0.9999999999993402,
            1.1486983549966396e-06,
            1.1486983549966396e-06,
        ),
        (
            0.5,
            1e-30,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-30,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
        (
            2.113915414528238,
            1e-60,
            0.9712512881027652,
            0.23805658016261474,
            0.23805658016261474,
        ),
        (
            21.139154145282376,
            1e-60,
            1.0,
            1.3195079107728974e-09,
            1.3195079107728974e-09,
        ),
        (
            35.23192357547063,
            1e-60,
            1.0,
            9.999999999999993e-16,
            9.999999999999993e-16,
        ),
        (
            49.32469300565888,
            1e-60,
            1.0,
            7.5785828325520155e-22,
            7.5785828325520155e-22,
        ),
        (
            68.34993173641303,
            1e-60,
            1.0,
            4.079917839025106e-30,
            4.200682036669199e-30,
        ),
        (
            70.46384715094126,
            1e-60,
            1.0,
            -1.3440785525506694e-45,
            9.999999999999999e-31,
        ),
        (
            98.64938601131776,
            1e-60,
            1.0,
            -8.705505632961184e-19,
            8.705505632961184e-19,
        ),
        (
            204.34515673772964,
            1e-60,
            -1.0,
            -5.743487422232466e-28,
            5.7434961277381e-28,
        ),
        (
            -232.53069559810615,
            1e-60,
            1.0,
            7.578582832551895e-22,
            7.578582832551895e-22,
        ),
        (
            535.5252383471535,
            1e-60,
            -1.0,
            1.1486983549969423e-12,
            1.1486983549969423e-12,
        ),
        (
            0.5,
            1e-60,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-60,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
        (
            3.495466470324665,
            1e-100,
            0.9981613166324784,
            0.06061341417967723,
            0.06061341417967723,
        ),
        (
            34.95466470324665,
            1e-100,
            1.0,
            1.3195079107728981e-15,
            1.3195079107728981e-15,
        ),
        (
            58.257774505411085,
            1e-100,
            1.0,
            1.0000000000000024e-25,
            1.0000000000000024e-25,
        ),
        (
            81.56088430757552,
            1e-100,
            1.0,
            7.578582832552006e-36,
            7.578582832552006e-36,
        ),
        (
            113.02008254049751,
            1e-100,
            1.0,
            1.6467663637517797e-49,
            1.649799823246523e-49,
        ),
        (116.51554901082217, 1e-100, 1.0, 4.9477708191416e-65, 1e-50),
        (
            163.12176861515104,
            1e-100,
            1.0,
            -8.705505632961206e-31,
            8.705505632961206e-31,
        ),
        (
            337.8950921313843,
            1e-100,
            -1.0,
            -5.743491774550088e-46,
            5.743491775420639e-46,
        ),
        (
            -384.50131173571316,
            1e-100,
            1.0,
            7.578582832551856e-36,
            7.578582832551856e-36,
        ),
        (
            885.5181724822485,
            1e-100,
            -1.0,
            1.1486983549969722e-20,
            1.1486983549969722e-20,
        ),
        (
            0.5,
            1e-100,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-100,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
        (
            5.222405290070199,
            1e-150,
            0.9999418039164266,
            0.010788363192000749,
            0.010788363192000749,
        ),
        (
            52.22405290070199,
            1e-150,
            1.0,
            4.172650388652589e-23,
            4.172650388652589e-23,
        ),
        (
            87.04008816783666,
            1e-150,
            1.0,
            3.162277660168383e-38,
            3.162277660168383e-38,
        ),
        (
            121.85612343497131,
            1e-150,
            1.0,
            2.3965583187115067e-53,
            2.3965583187115067e-53,
        ),
        (
            168.8577710456031,
            1e-150,
            1.0,
            9.268707273943745e-74,
            9.269246707799814e-74,
        ),
        (
            174.08017633567331,
            1e-150,
            1.0,
            2.192263790571567e-90,
            1e-75,
        ),
        (
            243.71224686994262,
            1e-150,
            1.0,
            -8.705505632961017e-46,
            8.705505632961017e-46,
        ),
        (
            504.8325113734526,
            1e-150,
            -1.0,
            -1.8162515731397225e-68,
            1.8162515731397252e-68,
        ),
        (
            -574.4645819077219,
            1e-150,
            1.0,
            2.3965583187114515e-53,
            2.3965583187114515e-53,
        ),
        (
            1323.0093401511172,
            1e-150,
            -1.0,
            1.1486983549969766e-30,
            1.1486983549969766e-30,
        ),
        (
            0.5,
            1e-150,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-150,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
        (
            6.949344109815733,
            1e-200,
            0.9999981596263923,
            0.0019185264732461615,
            0.0019185264732461615,
        ),
        (
            69.49344109815733,
            1e-200,
            1.0,
            1.3195079107728996e-30,
            1.3195079107728996e-30,
        ),
        (
            115.82240183026222,
            1e-200,
            1.0,
            1.0000000000000068e-50,
            1.0000000000000068e-50,
        ),
        (
            162.1513625623671,
            1e-200,
            1.0,
            7.57858283255217e-71,
            7.57858283255217e-71,
        ),
        (
            224.6954595507087,
            1e-200,
            1.0,
            5.212324007885116e-98,
            5.21233360052631e-98,
        ),
        (
            231.64480366052445,
            1e-200,
            1.0,
            1.3652860754334868e-114,
            1e-100,
        ),
        (
            324.3027251247342,
            1e-200,
            1.0,
            -8.705505632960827e-61,
            8.705505632960827e-61,
        ),
        (
            671.7699306155209,
            1e-200,
            -1.0,
            -5.743491774985157e-91,
            5.743491774985157e-91,
        ),
        (
            -764.4278520797307,
            1e-200,
            1.0,
            7.578582832551542e-71,
            7.578582832551542e-71,
        ),
        (
            1760.5005078199858,
            1e-200,
            -1.0,
            1.148698354996981e-40,
            1.148698354996981e-40,
        ),
        (
            0.5,
            1e-200,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-200,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
        (
            8.676282929561268,
            1e-250,
            0.9999999418022246,
            0.0003411679165094406,
            0.0003411679165094406,
        ),
        (
            86.76282929561268,
            1e-250,
            1.0,
            4.172650388652594e-38,
            4.172650388652594e-38,
        ),
        (
            144.6047154926878,
            1e-250,
            1.0,
            3.162277660168374e-63,
            3.162277660168374e-63,
        ),
        (
            202.4466016897629,
            1e-250,
            1.0,
            2.3965583187115246e-88,
            2.3965583187115246e-88,
        ),
        (
            280.5331480558143,
            1e-250,
            1.0,
            2.9311078017928994e-122,
            2.9311079723768624e-122,
        ),
        (
            289.2094309853756,
            1e-250,
            1.0,
            -3.3562988976497843e-140,
            1e-125,
        ),
        (
            404.8932033795258,
            1e-250,
            1.0,
            -8.705505632960886e-76,
            8.705505632960886e-76,
        ),
        (
            838.7073498575892,
            1e-250,
            -1.0,
            -1.8162515731397617e-113,
            1.8162515731397617e-113,
        ),
        (
            -954.3911222517395,
            1e-250,
            1.0,
            2.3965583187114886e-88,
            2.3965583187114886e-88,
        ),
        (
            2197.9916754888545,
            1e-250,
            -1.0,
            1.148698354996986e-50,
            1.148698354996986e-50,
        ),
        (
            0.5,
            1e-250,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-250,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
        (
            10.403221749306802,
            1e-300,
            0.9999999981596247,
            6.0669189839040556e-05,
            6.0669189839040556e-05,
        ),
        (
            104.03221749306802,
            1e-300,
            1.0,
            1.3195079107729013e-45,
            1.3195079107729013e-45,
        ),
        (
            173.38702915511337,
            1e-300,
            1.0,
            1.000000000000004e-75,
            1.000000000000004e-75,
        ),
        (
            242.7418408171587,
            1e-300,
            1.0,
            7.57858283255212e-106,
            7.57858283255212e-106,
        ),
        (
            336.37083656091994,
            1e-300,
            1.0,
            1.6482830919824263e-146,
            1.6482830950158859e-146,
        ),
        (
            346.77405831022674,
            1e-300,
            1.0,
            8.106670740906309e-165,
            1e-150,
        ),
        (
            485.4836816343174,
            1e-300,
            1.0,
            -8.705505632960944e-91,
            8.705505632960944e-91,
        ),
        (
            1005.6447690996575,
            1e-300,
            -1.0,
            -5.743491774985277e-136,
            5.743491774985277e-136,
        ),
        (
            -1144.354392423748,
            1e-300,
            1.0,
            7.578582832550796e-106,
            7.578582832550796e-106,
        ),
        (
            2635.482843157723,
            1e-300,
            -1.0,
            1.1486983549967292e-60,
            1.1486983549967292e-60,
        ),
        (
            0.5,
            1e-300,
            0.46211715726000974,
            0.8868188839700739,
            0.8868188839700739,
        ),
        (
            3.0,
            1e-300,
            0.9950547536867305,
            0.0993279274194332,
            0.0993279274194332,
        ),
    ];
    // (m1, K(1 − m1))
    const K_M1: &[(f64, f64)] = &[
        (0.5, 1.8540746773013719),
        (0.1, 2.5780921133481733),
        (0.01, 3.6956373629898747),
        (0.0001, 5.991589340506996),
        (1e-08, 10.59663475708766),
        (1e-12, 15.201804919087715),
        (1e-16, 19.806975105072258),
        (1e-17, 20.95826765156928),
        (1e-20, 24.412145291060348),
        (1e-30, 35.92507075603058),
        (1e-60, 70.46384715094126),
        (1e-100, 116.51554901082217),
        (1e-150, 174.08017633567331),
        (1e-200, 231.64480366052445),
        (1e-250, 289.2094309853756),
        (1e-300, 346.77405831022674),
    ];

    // generated by mpmath (mp.dps = 60): (u, m, sn, cn, dn) at u = f·K(m)
    const SNCNDN_M: &[(f64, f64, f64, f64, f64)] = &[
        (
            0.047123889803846894,
            0.0,
            0.04710645070964266,
            0.99888987496197,
            1.0,
        ),
        (
            0.6283185307179587,
            0.0,
            0.5877852522924732,
            0.8090169943749473,
            1.0,
        ),
        (
            1.2566370614359175,
            0.0,
            0.9510565162951536,
            0.3090169943749473,
            1.0,
        ),
        (
            1.5550883635269477,
            0.0,
            0.9998766324816606,
            0.015707317311820648,
            1.0,
        ),
        (
            2.670353755551324,
            0.0,
            0.45399049973954686,
            -0.8910065241883678,
            1.0,
        ),
        (
            -4.084070449666731,
            0.0,
            0.8090169943749473,
            -0.5877852522924732,
            1.0,
        ),
        (
            20.891591146372125,
            0.0,
            0.8910065241883678,
            -0.45399049973954686,
            1.0,
        ),
        (
            0.047123889803846894,
            1e-300,
            0.04710645070964266,
            0.99888987496197,
            1.0,
        ),
        (
            0.6283185307179587,
            1e-300,
            0.5877852522924732,
            0.8090169943749473,
            1.0,
        ),
        (
            1.2566370614359175,
            1e-300,
            0.9510565162951536,
            0.3090169943749473,
            1.0,
        ),
        (
            1.5550883635269477,
            1e-300,
            0.9998766324816606,
            0.015707317311820648,
            1.0,
        ),
        (
            2.670353755551324,
            1e-300,
            0.45399049973954686,
            -0.8910065241883678,
            1.0,
        ),
        (
            -4.084070449666731,
            1e-300,
            0.8090169943749473,
            -0.5877852522924732,
            1.0,
        ),
        (
            20.891591146372125,
            1e-300,
            0.8910065241883678,
            -0.45399049973954686,
            1.0,
        ),
        (
            0.047123889803846894,
            1e-20,
            0.04710645070964266,
            0.99888987496197,
            1.0,
        ),
        (
            0.6283185307179587,
            1e-20,
            0.5877852522924732,
            0.8090169943749473,
            1.0,
        ),
        (
            1.2566370614359175,
            1e-20,
            0.9510565162951536,
            0.3090169943749473,
            1.0,
        ),
        (
            1.5550883635269477,
            1e-20,
            0.9998766324816606,
            0.015707317311820648,
            1.0,
        ),
        (
            2.670353755551324,
            1e-20,
            0.45399049973954686,
            -0.8910065241883678,
            1.0,
        ),
        (
            -4.084070449666731,
            1e-20,
            0.8090169943749473,
            -0.5877852522924732,
            1.0,
        ),
        (
            20.891591146372125,
            1e-20,
            0.8910065241883678,
            -0.45399049973954686,
            1.0,
        ),
        (
            0.04712388992165662,
            1e-08,
            0.04710645082714746,
            0.9988898749564286,
            0.9999999999889049,
        ),
        (
            0.628318532288755,
            1e-08,
            0.5877852532542492,
            0.8090169936761762,
            0.9999999982725425,
        ),
        (
            1.25663706457751,
            1e-08,
            0.9510565165221981,
            0.30901699367617613,
            0.9999999954774575,
        ),
        (
            1.5550883674146685,
            1e-08,
            0.9998766324822773,
            0.015707317272562162,
            0.9999999950012336,
        ),
        (
            2.6703537622272084,
            1e-08,
            0.45399050064059626,
            -0.8910065237292603,
            0.9999999989694631,
        ),
        (
            -4.084070459876908,
            1e-08,
            0.8090169950737189,
            -0.5877852513306967,
            0.9999999967274575,
        ),
        (
            20.891591198601105,
            1e-08,
            0.8910065246474744,
            -0.45399049883849946,
            0.9999999960305369,
        ),
        (
            0.047242366845520675,
            0.01,
            0.04722462044158755,
            0.9988842952134886,
            0.9999888491139496,
        ),
        (
            0.6298982246069424,
            0.01,
            0.5887516362981962,
            0.808313992676235,
            0.998265353053767,
        ),
        (
            1.259796449213885,
            0.01,
            0.9512843285090715,
            0.3083149790928832,
            0.9954650075534199,
        ),
        (
            1.5589981059021825,
            0.01,
            0.9998772511424495,
            0.015667885875860526,
            0.9949886707025755,
        ),
        (
            2.6770674545795052,
            0.01,
            0.45489618327715053,
            -0.8905444752733471,
            0.9989648115045889,
        ),
        (
            -4.094338459945126,
            0.01,
            0.809718568518424,
            -0.586818404445936,
            0.9967163881455772,
        ),
        (
            20.944115968180835,
            0.01,
            0.8914673119787421,
            -0.45308501594446504,
            0.9960185040031806,
        ),
        (
            0.04837324046160658,
            0.1,
            0.048352493921458135,
            0.9988303341066366,
            0.9998830949831873,
        ),
        (
            0.6449765394880878,
            0.1,
            0.5978915247543005,
            0.801577023514882,
            0.9819636309266743,
        ),
        (
            1.2899530789761755,
            0.1,
            0.9534075280148607,
            0.30168540820628453,
            0.9534680951937822,
        ),
        (
            1.596316935233017,
            0.1,
            0.9998830027478958,
            0.015296431474413317,
            0.9486956298421455,
        ),
        (
            2.741150292824373,
            0.1,
            0.46349368811693753,
            -0.8861002206724469,
            0.9892003639847571,
        ),
        (
            -4.19234750667257,
            0.1,
            0.8163001136390741,
            -0.5776280156578582,
            0.9661083854554227,
        ),
        (
            21.44546993797892,
            0.1,
            0.8957742565955021,
            -0.4445092588695713,
            0.9590405873173865,
        ),
        (
            0.05141668344536373,
            0.3,
            0.05138724798948072,
            0.9986788025907367,
            0.9996038241339518,
        ),
        (
            0.6855557792715165,
            0.3,
            0.6217373645420177,
            0.7832257972847589,
            0.9402301818489469,
        ),
        (
            1.371111558543033,
            0.3,
            0.9586863439706601,
            0.2844652771150973,
            0.8510441517132062,
        ),
        (
            1.6967505536970031,
            0.3,
            0.9998971891454488,
            0.014339147081699314,
            0.8366968885693965,
        ),
        (
            2.9136120619039447,
            0.3,
            0.4862043543811625,
            -0.8738451383287528,
            0.9638887890904423,
        ),
        (
            -4.456112565264857,
            0.3,
            0.8330149493228973,
            -0.5532504805280974,
            0.8898459576024219,
        ),
        (
            22.79472966077792,
            0.3,
            0.9065829463099598,
            -0.42202767854721634,
            0.8680047283500164,
        ),
        (
            0.055370819951241705,
            0.49,
            0.05532869725812542,
            0.9984681944156852,
            0.9992497086700912,
        ),
        (
            0.7382775993498895,
            0.49,
            0.6511086602972131,
            0.7589845271716468,
            0.8900944787594879,
        ),
        (
            1.476555198699779,
            0.49,
            0.9646932791353,
            0.26337592371206264,
            0.7375566214357236,
        ),
        (
            1.8272370583909763,
            0.49,
            0.9999131284728959,
            0.013180876584882402,
            0.7142024435681367,
        ),
        (
            3.13767979723703,
            0.49,
            0.5147736354459925,
            -0.857326136455501,
            0.9328204388210847,
        ),
        (
            -4.798804395774281,
            0.49,
            0.8527010843044808,
            -0.5223991393809554,
            0.8023225173237517,
        ),
        (
            24.547730178383823,
            0.49,
            0.9190687733418504,
            -0.3940971832783208,
            0.7655737515323224,
        ),
        (
            0.0646954694249893,
            0.75,
            0.06461660477065244,
            0.9979101634856282,
            0.9984330327022113,
        ),
        (
            0.8626062589998573,
            0.75,
            0.7134240605908759,
            0.7007325522408862,
            0.7863012033104869,
        ),
        (
            1.7252125179997146,
            0.75,
            0.9757547334069768,
            0.21886685503721126,
            0.5347214463395028,
        ),
        (
            2.1349504910246466,
            0.75,
            0.9999418618078112,
            0.01078299607383045,
            0.5000871971499032,
        ),
        (
            3.6660766007493932,
            0.75,
            0.5779035012607279,
            -0.8161051055045495,
            0.8657486109852813,
        ),
        (
            -5.606940683499072,
            0.75,
            0.891175734299605,
            -0.45365825308877605,
            0.6358886364346119,
        ),
        (
            28.681658111745257,
            0.75,
            0.9426582903503197,
            -0.3337594157979854,
            0.5775348567189338,
        ),
        (
            0.1452339768165089,
            0.999,
            0.14422188579599732,
            0.9895453742287144,
            0.9895558840256516,
        ),
        (
            1.9364530242201188,
            0.999,
            0.9594527038220982,
            0.2818696669180013,
            0.28349789879174864,
        ),
        (
            3.8729060484402376,
            0.999,
            0.9993655039901033,
            0.03561726315435881,
            0.047616392609817045,
        ),
        (
            4.792721234944794,
            0.999,
            0.9999988272571818,
            0.0015314973917539283,
            0.03165980320179974,
        ),
        (
            8.229925352935505,
            0.999,
            0.8963070507950354,
            -0.4434339530246933,
            0.4443388763369809,
        ),
        (
            -12.586944657430772,
            0.999,
            0.9942566351260919,
            -0.10702216362857488,
            0.1115450122786031,
        ),
        (
            64.38706305531895,
            0.999,
            0.9979634388065534,
            -0.06378851625017398,
            0.0711681517997574,
        ),
    ];

    /// Relative error with an allowance for the conditioning of the argument: an absolute error
    /// of a few ulp(|u| + K) in the reduced argument moves f by |f'| times that.
    fn rel_err(got: f64, want: f64, deriv: f64, u: f64, k: f64) -> f64 {
        let cond = 4.0 * f64::EPSILON * (u.abs() + k) * deriv.abs();
        (got - want).abs() / (want.abs() + cond / 1e-14).max(f64::MIN_POSITIVE)
    }

    #[test]
    fn ellipj_complement_matches_mpmath_down_to_1e_minus_300() {
        let mut worst = 0.0f64;
        for &(u, m1, sn, cn, dn) in SNCNDN_M1 {
            let k = ellipk_complement(m1).unwrap();
            let (s, c, d) = ellipj_complement(u, m1).unwrap();
            let m = 1.0 - m1;
            let e = [
                rel_err(s, sn, cn * dn, u, k),
                rel_err(c, cn, sn * dn, u, k),
                rel_err(d, dn, m * sn * cn, u, k),
            ];
            let e = e.iter().fold(0.0f64, |a, &b| a.max(b));
            worst = worst.max(e);
            assert!(e < 1e-14, "m1 = {m1:e}, u = {u}: rel. error {e:e}");
        }
        assert!(worst < 1e-14);
    }

    #[test]
    fn ellipk_complement_matches_mpmath() {
        for &(m1, k) in K_M1 {
            let got = ellipk_complement(m1).unwrap();
            assert!(
                (got - k).abs() <= 4.0 * f64::EPSILON * k,
                "K(1 − {m1:e}) = {got} vs {k}"
            );
        }
        assert_eq!(ellipk_complement(0.0).unwrap(), f64::INFINITY);
        assert!(ellipk_complement(-1e-300).is_err());
        assert!(ellipk_complement(1.5).is_err());
        assert!(ellipk_complement(f64::NAN).is_err());
    }

    #[test]
    fn ellipj_matches_mpmath_for_every_m() {
        for &(u, m, sn, cn, dn) in SNCNDN_M {
            let k = ellipk(m).unwrap();
            let (s, c, d) = ellipj(u, m).unwrap();
            let e = [
                rel_err(s, sn, cn * dn, u, k),
                rel_err(c, cn, sn * dn, u, k),
                rel_err(d, dn, m * sn * cn, u, k),
            ];
            let e = e.iter().fold(0.0f64, |a, &b| a.max(b));
            assert!(e < 1e-14, "m = {m:e}, u = {u}: rel. error {e:e}");
        }
    }

    #[test]
    fn kprime_form_agrees_and_reaches_the_homoclinic_limit() {
        // m₁ = 0: sn = tanh, cn = dn = sech exactly, also where cosh overflows.
        for u in [0.0, 0.3, -2.0, 20.0, 800.0] {
            let (s, c, d) = ellipj_complement(u, 0.0).unwrap();
            assert_eq!((s, c, d), (u.tanh(), 1.0 / u.cosh(), 1.0 / u.cosh()));
            assert_eq!(ellipj_kprime(u, 0.0).unwrap(), (s, c, d));
        }
        // k′ = √m₁ is the same function, and carries m₁ below the least double (k′ = 1e-170).
        for &(u, m1, ..) in SNCNDN_M1.iter().step_by(5) {
            let a = ellipj_complement(u, m1).unwrap();
            let b = ellipj_kprime(u, m1.sqrt()).unwrap();
            assert!((a.0 - b.0).abs() + (a.1 - b.1).abs() + (a.2 - b.2).abs() < 1e-13);
        }
        // sn(K | m) = 1, cn(K | m) = 0, dn(K | m) = k′ and sn(K/2 | m)² = 1/(1 + k′) (A&S 16.5),
        // here with k′ = 1e-170, K = ln(4/k′) + O(k′²).
        let kp: f64 = 1e-170;
        let k = (4.0f64).ln() - kp.ln();
        let (s, c, d) = ellipj_kprime(k, kp).unwrap();
        // Near u = K the only error is that of K itself (a few ulp of 393, 6e-14 each) in the
        // reduced argument: cn ≈ k′(K − u), and d ln dn / du ≈ 1 at K/2.
        assert!((s - 1.0).abs() < 1e-15 && c.abs() < 1e-12 * kp && (d - kp).abs() < 1e-14 * kp);
        let (s, _, d) = ellipj_kprime(0.5 * k, kp).unwrap();
        assert!((s * s * (1.0 + kp) - 1.0).abs() < 1e-15);
        assert!(
            (d - kp.sqrt()).abs() < 1e-12 * kp.sqrt(),
            "dn(K/2) = √k′: {d:e}"
        );
        assert!(ellipj_kprime(0.3, -1e-3).is_err());
        assert!(ellipj_kprime(0.3, 1.5).is_err());
        assert!(ellipj_complement(0.3, f64::NAN).is_err());
        assert!(ellipj_complement(f64::INFINITY, 0.5).is_err());
    }
}
