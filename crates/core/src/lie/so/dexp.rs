//! The derivative of exp on so(n) and its inverse (000 §3).

use super::exp::{check_exp_norm, exp_unchecked};
use super::{
    bracket, check_algebra, check_algebra_of, dim, from_matrix3, hat_n_unchecked, norm, to_matrix3,
    vee_n_unchecked,
};
use crate::check;
use crate::error::{Error, Result};
use crate::lie::so3;
use crate::Mat;

/// A result of `what` if it is finite; otherwise an overflow error naming ξ, η (the maps are
/// linear in η, so a huge η can take the result past the f64 range).
fn representable(what: &str, m: Mat) -> Result<Mat> {
    if (0..m.nrows()).all(|i| (0..m.ncols()).all(|j| m[(i, j)].is_finite())) {
        Ok(m)
    } else {
        Err(check::overflow_error(
            "xi, eta",
            &format!("{what}(xi, eta)"),
        ))
    }
}

/// Right-trivialized derivative of exp (000 §3): dexp_ξ η = Σ_{k≥0} ad_ξᵏ η / (k+1)!
/// = ∫₀¹ Ad_{exp(sξ)} η ds, so that
///
///   d/dt exp(ξ + tη)|₀ = dexp_ξ(η) · exp ξ   and   exp(−ξ) · d/dt exp(ξ + tη)|₀ = dexp_{−ξ}(η)
///
/// (the second is the left-trivialized form). Defined for every ξ: the series is summed at
/// ξ/2ˢ with |ξ|/2ˢ ≤ ½ (terms fall at least like 0.71ᵏ/(k+1)!, truncated when below 10⁻¹⁷ of
/// the sum) and doubled back s times with dexp_{2y} = ½ (dexp_y + Ad_{exp y} dexp_y), which
/// avoids the cancellation of the raw series for large |ξ|. n = 3: closed form
/// (see `dexp3`).
pub fn dexp(xi: &Mat, eta: &Mat) -> Result<Mat> {
    representable("dexp", dexp_raw(xi, eta)?)
}

fn dexp_raw(xi: &Mat, eta: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    check_algebra_of("eta", eta, n)?;
    check_exp_norm("dexp", xi)?;
    if n == 3 {
        return Ok(dexp3(xi, eta, false));
    }
    let nx = norm(xi);
    let mut s = 0;
    while nx * 0.5f64.powi(s) > 0.5 {
        s += 1;
    }
    let y = xi * faer::Scale(0.5f64.powi(s));
    let mut term = eta.clone();
    let mut sum = eta.clone();
    for k in 1..64 {
        term = bracket(&y, &term) * faer::Scale(1.0 / (k + 1) as f64);
        sum += &term;
        if term.norm_l2() <= 1e-17 * sum.norm_l2() {
            break;
        }
    }
    for level in (1..=s).rev() {
        let r = exp_unchecked(&(xi * faer::Scale(0.5f64.powi(level))));
        let conj = &r * &sum * r.transpose();
        sum = (&sum + &conj) * faer::Scale(0.5);
    }
    Ok(sum)
}

/// Closed forms at n = 3 through w = vee(ξ), v = vee(η) (physics convention, where ad_ξ is
/// w × ·): with X = ad_ξ and θ = |w|,
///
///   dexp_ξ = (eˣ − 1)/X = I + (1 − cos θ)/θ² X + (θ − sin θ)/θ³ X²,
///   dexp⁻¹_ξ = X/(eˣ − 1) = I − X/2 + (1 − (θ/2) cot(θ/2))/θ² X²
///
/// (from X³ = −θ² X), with Taylor coefficients for θ < 10⁻³.
fn dexp3(xi: &Mat, eta: &Mat, inverse: bool) -> Mat {
    let w = so3::vee_unchecked(&to_matrix3(xi));
    let v = so3::vee_unchecked(&to_matrix3(eta));
    let t2 = w.norm_squared();
    let (a, b) = if inverse {
        let c = if t2 < 1e-6 {
            1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
        } else {
            let t = t2.sqrt();
            (1.0 - 0.5 * t / (0.5 * t).tan()) / t2
        };
        (-0.5, c)
    } else if t2 < 1e-6 {
        (
            0.5 - t2 / 24.0 + t2 * t2 / 720.0,
            1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0,
        )
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let wv = w.cross(&v);
    from_matrix3(&so3::hat(&(v + wv * a + w.cross(&wv) * b)))
}

/// Coefficients b_k = B_k / k! of z / (eᶻ − 1) = Σ b_k zᵏ (B_1 = −½), from
/// b_2m = (−1)^{m+1} 2 ζ(2m) / (2π)^{2m} (odd b_k = 0 for k ≥ 3), computed once: the series
/// dexp⁻¹_u = Σ b_k ad_uᵏ of [`dexp_inv`] and of the RKMK kernels of the so(n) rigid body and
/// of user Lie–Poisson systems.
pub(crate) fn bernoulli_coefficients() -> &'static [f64] {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut b = vec![0.0; DEXP_INV_MAX_TERMS + 1];
        b[0] = 1.0;
        b[1] = -0.5;
        // ζ(2), ζ(4), ζ(6) in closed form; from ζ(8) on the direct sum converges fast.
        let pi2 = std::f64::consts::PI * std::f64::consts::PI;
        let small = [pi2 / 6.0, pi2 * pi2 / 90.0, pi2 * pi2 * pi2 / 945.0];
        for m in 1..=DEXP_INV_MAX_TERMS / 2 {
            let p = 2 * m as i32;
            let zeta = if m <= 3 { small[m - 1] } else { zeta_direct(p) };
            let sign = if m % 2 == 1 { 1.0 } else { -1.0 };
            b[2 * m] = sign * 2.0 * zeta / two_pi.powi(p);
        }
        b
    })
}

const DEXP_INV_MAX_TERMS: usize = 400;

/// ζ(p) = Σ_{j≥1} j⁻ᵖ by direct summation for p ≥ 8, smallest terms first, up to the J with
/// J⁻ᵖ < 10⁻²⁰ (at most ~320 terms; the dropped tail is below 10⁻²⁰ · J/(p − 1)).
fn zeta_direct(p: i32) -> f64 {
    let last = (1e20f64.powf(1.0 / p as f64)).ceil() as i32;
    (2..=last).rev().map(|j| f64::from(j).powi(-p)).sum::<f64>() + 1.0
}

/// Inverse of [`dexp`] (same right-trivialized convention): dexp⁻¹_ξ η = Σ_k B_k/k! ad_ξᵏ η with
/// the Bernoulli numbers B_0 = 1, B_1 = −½, B_2 = 1/6, … (000 §3).
///
/// Domain |ξ| < π (|ξ| the pairing norm, [`norm`]): the eigenvalues of ad_ξ are ±i(θ_j ± θ_k)
/// and ±iθ_j, of modulus ≤ √2|ξ| < 2π, inside the radius of convergence 2π; the terms then fall
/// at least like (√2|ξ|/2π)ᵏ ≤ 0.71ᵏ and the sum is truncated when a bound of the tail is below
/// 10⁻¹⁷ of the sum. n = 3: closed form (see `dexp3`). Outside the domain →
/// [`Error::InvalidArgument`].
pub fn dexp_inv(xi: &Mat, eta: &Mat) -> Result<Mat> {
    representable("dexp_inv", dexp_inv_raw(xi, eta)?)
}

fn dexp_inv_raw(xi: &Mat, eta: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    check_algebra_of("eta", eta, n)?;
    let nx = norm(xi);
    let pi = std::f64::consts::PI;
    if n == 3 && nx < pi {
        return Ok(dexp3(xi, eta, true));
    }
    if nx >= pi {
        return Err(Error::invalid(
            "xi",
            format!(
                "dexp⁻¹ needs |ξ| < π (where its Bernoulli series converges), got |ξ| = {}",
                crate::error::fmt_num(nx)
            ),
        ));
    }
    let b = bernoulli_coefficients();
    let two_pi = 2.0 * pi;
    let tail = 4.0 / (1.0 - std::f64::consts::SQRT_2 * nx / two_pi);
    let mut p = bracket(xi, eta);
    let mut sum = eta - &p * faer::Scale(0.5);
    let mut pn = p.norm_l2();
    for (k, &bk) in b.iter().enumerate().skip(2) {
        if tail * pn / two_pi.powi(k as i32 - 1) <= 1e-17 * sum.norm_l2() || pn == 0.0 {
            return Ok(sum);
        }
        p = bracket(xi, &p);
        pn = p.norm_l2();
        if bk != 0.0 {
            sum += &p * faer::Scale(bk);
        }
    }
    Err(Error::NotConverged {
        what: "dexp⁻¹ Bernoulli series".into(),
        iterations: DEXP_INV_MAX_TERMS,
        residual: pn,
        tol: 1e-17,
    })
}

/// The dim × dim matrix, in e_ij coordinates, of the linear map η ↦ `map`(`xi`, η), column k from
/// the k-th basis element.
fn coordinate_matrix(xi: &Mat, map: fn(&Mat, &Mat) -> Result<Mat>) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    let d = dim(n);
    let mut m = Mat::zeros(d, d);
    let mut e = vec![0.0; d];
    for k in 0..d {
        e[k] = 1.0;
        let col = vee_n_unchecked(&map(xi, &hat_n_unchecked(n, &e))?);
        e[k] = 0.0;
        for (i, c) in col.into_iter().enumerate() {
            m[(i, k)] = c;
        }
    }
    Ok(m)
}

/// Left Jacobian J_l(ξ) of exp on so(n): the matrix of [`dexp`]_ξ in e_ij coordinates, so that
/// exp(ξ + δ) = exp(J_l(ξ) δ) exp(ξ) to first order (dim(n) evaluations of [`dexp`]).
pub fn jacobian_left(xi: &Mat) -> Result<Mat> {
    coordinate_matrix(xi, dexp)
}

/// Right Jacobian J_r(ξ) = J_l(−ξ) (the matrix of dexp_{−ξ}): exp(ξ + δ) = exp(ξ) exp(J_r(ξ) δ)
/// to first order.
pub fn jacobian_right(xi: &Mat) -> Result<Mat> {
    check_algebra("xi", xi)?;
    coordinate_matrix(&-xi, dexp)
}

/// J_l(ξ)⁻¹, the matrix of [`dexp_inv`]_ξ (its domain |ξ| < π).
pub fn jacobian_left_inv(xi: &Mat) -> Result<Mat> {
    coordinate_matrix(xi, dexp_inv)
}

/// J_r(ξ)⁻¹ = J_l(−ξ)⁻¹, the matrix of dexp⁻¹_{−ξ} (domain |ξ| < π).
pub fn jacobian_right_inv(xi: &Mat) -> Result<Mat> {
    check_algebra("xi", xi)?;
    coordinate_matrix(&-xi, dexp_inv)
}

/// p ← a·b for dense row-major n×n matrices.
fn product(n: usize, a: &[f64], b: &[f64], p: &mut [f64]) {
    for i in 0..n {
        for j in 0..n {
            p[i * n + j] = (0..n).map(|k| a[i * n + k] * b[k * n + j]).sum();
        }
    }
}

/// c ← c + s[a, b] for skew dense n×n matrices a, b (row-major; [a, b] = ab − (ab)ᵀ since
/// ba = (ab)ᵀ), through the product buffer `p`.
fn add_bracket(n: usize, a: &[f64], b: &[f64], s: f64, p: &mut [f64], c: &mut [f64]) {
    product(n, a, b, p);
    for i in 0..n {
        for j in 0..n {
            c[i * n + j] += s * (p[i * n + j] - p[j * n + i]);
        }
    }
}

/// b ← s[a, b] in place (skew dense n×n, through `p`).
fn bracket_in_place(n: usize, a: &[f64], b: &mut [f64], s: f64, p: &mut [f64]) {
    product(n, a, b, p);
    for i in 0..n {
        for j in 0..n {
            b[i * n + j] = s * (p[i * n + j] - p[j * n + i]);
        }
    }
}

fn frobenius(a: &[f64]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The most terms of the series of [`dexp_series_dense`].
const DEXP_SERIES_MAX_TERMS: usize = 64;

/// dexp_u w = Σ_{k≥0} ad_uᵏ w/(k+1)! (000 §3: the series of [`dexp`], unscaled) on dense skew
/// n×n matrices (row-major) into `value`, and with `du` also its derivative in u,
///
///   D_u(dexp_u w)\[du\] = Σ_{k≥1} 1/(k+1)! Σ_{i+j=k−1} ad_uⁱ ad_du ad_uʲ w,
///
/// the series differentiated term by term, into `deriv`: the derivative of T_k = ad_uᵏ w is
/// D_k = ad_du T_{k−1} + ad_u D_{k−1} (D_0 = 0), which is that inner sum, so one pass carries
/// both (three brackets a term, no allocation; `work`: three n×n buffers). Truncated as
/// [`dexp`]'s series, once the terms of both sums are below 10⁻¹⁷ of their sums (at most 64
/// terms). For the domain of dexp⁻¹ (|u| < π: ‖ad_u‖ ≤ √2|u|, the terms fall like
/// ‖ad_u‖ᵏ/(k+1)! with little cancellation); it loses accuracy for large |u|, where [`dexp`]
/// scales.
pub(crate) fn dexp_series_dense(
    n: usize,
    u: &[f64],
    w: &[f64],
    du: Option<&[f64]>,
    value: &mut [f64],
    mut deriv: Option<&mut [f64]>,
    work: [&mut [f64]; 3],
) {
    let [t, d, p] = work;
    value.copy_from_slice(w);
    t.copy_from_slice(w);
    d.fill(0.0);
    if let Some(out) = deriv.as_deref_mut() {
        out.fill(0.0);
    }
    for k in 1..DEXP_SERIES_MAX_TERMS {
        let inv = 1.0 / (k + 1) as f64;
        // With t = T_{k−1}/k! and d = D_{k−1}/k!: d ← (ad_u d + ad_du t)/(k + 1) (before t
        // moves on), t ← ad_u t/(k + 1).
        let mut small = true;
        if let (Some(du), Some(out)) = (du, deriv.as_deref_mut()) {
            bracket_in_place(n, u, d, inv, p);
            add_bracket(n, du, t, inv, p, d);
            out.iter_mut().zip(d.iter()).for_each(|(o, x)| *o += x);
            let dn = frobenius(d);
            small = dn <= 1e-17 * frobenius(out);
        }
        bracket_in_place(n, u, t, inv, p);
        value.iter_mut().zip(t.iter()).for_each(|(v, x)| *v += x);
        let tn = frobenius(t);
        if small && tn <= 1e-17 * frobenius(value) {
            return;
        }
    }
}

/// D_ξ(dexp_ξ η)\[δ\], the derivative of [`dexp`] in ξ along δ: the series of dexp differentiated
/// term by term, Σ_{k≥1} 1/(k+1)! Σ_{i+j=k−1} ad_ξⁱ ad_δ ad_ξʲ η (see `dexp_series_dense`;
/// the derivative RKMK's tangent lift needs of dexp⁻¹: D(dexp⁻¹_ξ v)\[δ\] =
/// −dexp⁻¹_ξ D_ξ(dexp_ξ w)\[δ\] at w = dexp⁻¹_ξ v). Domain |ξ| < π (that of [`dexp_inv`]);
/// outside it → [`Error::InvalidArgument`].
pub fn dexp_derivative(xi: &Mat, delta: &Mat, eta: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    check_algebra_of("delta", delta, n)?;
    check_algebra_of("eta", eta, n)?;
    let nx = norm(xi);
    if nx >= std::f64::consts::PI {
        return Err(Error::invalid(
            "xi",
            format!(
                "the derivative of dexp is summed for |ξ| < π, got |ξ| = {}",
                crate::error::fmt_num(nx)
            ),
        ));
    }
    let dense = |m: &Mat| -> Vec<f64> { (0..n * n).map(|k| m[(k / n, k % n)]).collect() };
    let (u, du, w) = (dense(xi), dense(delta), dense(eta));
    let [mut value, mut out, mut t, mut d, mut p] = std::array::from_fn(|_| vec![0.0; n * n]);
    dexp_series_dense(
        n,
        &u,
        &w,
        Some(&du),
        &mut value,
        Some(&mut out),
        [&mut t, &mut d, &mut p],
    );
    representable("dexp_derivative", Mat::from_fn(n, n, |i, j| out[i * n + j]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skew(n: usize, seed: f64, scale: f64) -> Mat {
        let c: Vec<f64> = (0..dim(n))
            .map(|k| scale * ((k as f64 + 1.0) * seed).sin())
            .collect();
        hat_n_unchecked(n, &c)
    }

    /// The dense series is dexp (n = 3: its closed form; n = 4, 5: the scaled series), and its
    /// derivative is the central difference of dexp (step 1e-5, to ~1e-10), at |ξ| up to 1.5.
    #[test]
    fn dexp_derivative_is_the_derivative_of_dexp() {
        for n in [3, 4, 5] {
            for scale in [0.05, 0.4, 1.0] {
                let (xi, delta, eta) = (skew(n, 1.3, scale), skew(n, 0.7, 1.0), skew(n, 2.1, 1.0));
                let dense =
                    |m: &Mat| -> Vec<f64> { (0..n * n).map(|k| m[(k / n, k % n)]).collect() };
                let [mut value, mut t, mut d, mut p] = std::array::from_fn(|_| vec![0.0; n * n]);
                dexp_series_dense(
                    n,
                    &dense(&xi),
                    &dense(&eta),
                    None,
                    &mut value,
                    None,
                    [&mut t, &mut d, &mut p],
                );
                let exact = dexp(&xi, &eta).unwrap();
                let e1 = (0..n * n)
                    .map(|k| (value[k] - exact[(k / n, k % n)]).abs())
                    .fold(0.0f64, f64::max);
                assert!(e1 < 1e-15, "n = {n}, |ξ| ~ {scale}: dexp {e1:e}");
                let der = dexp_derivative(&xi, &delta, &eta).unwrap();
                let h = 1e-5;
                let at = |s: f64| dexp(&(&xi + &delta * faer::Scale(s)), &eta).unwrap();
                let fd = (at(h) - at(-h)) * faer::Scale(0.5 / h);
                let e2 = (&der - &fd).norm_l2() / der.norm_l2().max(1.0);
                eprintln!(
                    "so({n}) |ξ| = {:.2}: D dexp vs differences {e2:.1e}",
                    norm(&xi)
                );
                assert!(e2 < 1e-9, "n = {n}: {e2:e}");
            }
        }
        let big = skew(4, 1.3, 3.0);
        assert!(dexp_derivative(&big, &big, &big).is_err());
    }
}
