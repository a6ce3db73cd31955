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
//! pendulum ([`crate::systems::test_problems::pendulum`]) and the self-gravity of an ellipsoid.

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
#[rustfmt::skip]
mod tables;

#[cfg(test)]
mod tests {
    use super::*;

    use super::tables::{K_M1, SNCNDN_M, SNCNDN_M1};

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
