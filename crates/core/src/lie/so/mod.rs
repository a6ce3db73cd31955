//! SO(n) and so(n) for any n ≥ 2 (000 §3, 001 §2).
//!
//! Coordinates on so(n) use the basis e_ij (i < j, +1 at (i, j), −1 at (j, i)) in the order
//! (1,2), (1,3), …, (1,n), (2,3), …, (n−1,n); the pairing ⟨ξ, η⟩ = ½ tr(ξᵀη) = Σ_{i<j} ξ_ij η_ij
//! (001 (2.8)) makes this basis orthonormal.

use crate::check;
use crate::error::{Error, Result};
use crate::lie::{so3, MatrixLieGroup};
use crate::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::{Matrix3, Vector3};

/// Dimension n(n−1)/2 of so(n).
pub fn dim(n: usize) -> usize {
    n * (n.saturating_sub(1)) / 2
}

/// The n with n(n−1)/2 = `d`, if there is one with n ≥ 2.
pub fn n_from_dim(d: usize) -> Option<usize> {
    let n = ((1.0 + (1.0 + 8.0 * d as f64).sqrt()) / 2.0).round() as usize;
    (n >= 2 && dim(n) == d).then_some(n)
}

/// Skew-symmetric matrix with coordinates `c` in the e_ij basis (the inverse of [`vee_n`]).
pub fn hat_n(c: &[f64]) -> Result<Mat> {
    let n = n_from_dim(c.len()).ok_or_else(|| {
        Error::shape(
            "so(n) coordinates",
            "a vector of length n(n−1)/2 for some n ≥ 2 (1, 3, 6, 10, …)",
            format!("({},)", c.len()),
        )
    })?;
    check::finite_slice("so(n) coordinates", c)?;
    Ok(hat_n_unchecked(n, c))
}

/// [`hat_n`] for a known n and valid `c` (length n(n−1)/2); for inner loops.
pub fn hat_n_unchecked(n: usize, c: &[f64]) -> Mat {
    let mut m = Mat::zeros(n, n);
    let mut k = 0;
    for i in 0..n {
        for j in i + 1..n {
            m[(i, j)] = c[k];
            m[(j, i)] = -c[k];
            k += 1;
        }
    }
    m
}

pub use super::SKEW_TOL;

/// Coordinates of a skew-symmetric matrix in the e_ij basis (upper triangle, row by row).
///
/// Errors if `xi` is not square, not finite, or not skew-symmetric to [`SKEW_TOL`] (relative).
pub fn vee_n(xi: &Mat) -> Result<Vec<f64>> {
    check_algebra("xi", xi)?;
    Ok(vee_n_unchecked(xi))
}

/// [`vee_n`] without checks: reads the upper triangle.
pub fn vee_n_unchecked(xi: &Mat) -> Vec<f64> {
    let n = xi.nrows();
    let mut c = Vec::with_capacity(dim(n));
    for i in 0..n {
        for j in i + 1..n {
            c.push(xi[(i, j)]);
        }
    }
    c
}

/// Relative skew defect ‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F).
pub fn skew_defect(xi: &Mat) -> f64 {
    let n = xi.nrows();
    if xi.ncols() != n {
        return f64::INFINITY;
    }
    let (mut sym, mut all) = (0.0, 0.0);
    for j in 0..n {
        for i in 0..n {
            let x = xi[(i, j)];
            let d = x + xi[(j, i)];
            sym += d * d;
            all += x * x;
        }
    }
    sym.sqrt() / all.sqrt().max(1.0)
}

/// Lie bracket [ξ, η] = ξη − ηξ. Unchecked (see [`ad`]); never panics: operands of different
/// or non-square shapes give a matrix of NaN.
pub fn bracket(xi: &Mat, eta: &Mat) -> Mat {
    let n = xi.nrows();
    if xi.ncols() != n || eta.nrows() != n || eta.ncols() != n {
        return nan_mat(n, xi.ncols());
    }
    xi * eta - eta * xi
}

/// Pairing ⟨ξ, η⟩ = ½ tr(ξᵀη) on so(n) (001 (2.8)). Unchecked; NaN for operands of different
/// shapes.
pub fn pairing(xi: &Mat, eta: &Mat) -> f64 {
    if xi.nrows() != eta.nrows() || xi.ncols() != eta.ncols() {
        return f64::NAN;
    }
    let mut s = 0.0;
    for j in 0..xi.ncols() {
        for i in 0..xi.nrows() {
            s += xi[(i, j)] * eta[(i, j)];
        }
    }
    0.5 * s
}

// ---------------------------------------------------------------------------------------------
// Validation

/// Checks that `xi` is a finite n×n skew-symmetric matrix with n ≥ 2 (skew to [`SKEW_TOL`],
/// relative); returns n.
pub fn check_algebra(what: &str, xi: &Mat) -> Result<usize> {
    let n = check::square(what, xi, 2)?;
    check_skew(what, xi, n)?;
    Ok(n)
}

/// [`check_algebra`] for a second argument that must have the same size n.
pub fn check_algebra_of(what: &str, xi: &Mat, n: usize) -> Result<()> {
    check::square_of(what, xi, n)?;
    check_skew(what, xi, n)
}

fn check_skew(what: &str, xi: &Mat, n: usize) -> Result<()> {
    let defect = skew_defect(xi);
    if defect > SKEW_TOL {
        return Err(Error::NotInGroup {
            what: what.into(),
            group: format!("so({n})"),
            defect_name: "‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F)".into(),
            defect,
            tol: SKEW_TOL,
        });
    }
    Ok(())
}

/// Tolerance on the orthogonality defect ‖RᵀR − I‖_F (absolute) for accepting a matrix as a
/// rotation in every function that takes an element of SO(n).
pub const ROTATION_TOL: f64 = 1e-10;

/// Orthogonality defect ‖RᵀR − I‖_F of a square matrix.
pub fn orthogonality_defect(r: &Mat) -> f64 {
    let n = r.ncols();
    let g = r.transpose() * r;
    let mut s = 0.0;
    for j in 0..n {
        for i in 0..n {
            let d = g[(i, j)] - if i == j { 1.0 } else { 0.0 };
            s += d * d;
        }
    }
    s.sqrt()
}

/// Whether `r` is in SO(n): ‖RᵀR − I‖_F ≤ `tol` and det R > 0.
///
/// Errors on a non-square or non-finite `r` and on a `tol` that is not a finite positive number.
pub fn is_rotation(r: &Mat, tol: f64) -> Result<bool> {
    check::square("R", r, 2)?;
    check::positive("tol", tol)?;
    Ok(orthogonality_defect(r) <= tol && r.determinant() > 0.0)
}

/// Checks that `r` is a finite n×n rotation (‖RᵀR − I‖_F ≤ [`ROTATION_TOL`], det R > 0);
/// returns n. The error message carries both the orthogonality defect and the determinant.
pub fn check_rotation(what: &str, r: &Mat) -> Result<usize> {
    let n = check::square(what, r, 2)?;
    rotation_error(what, r, n)?;
    Ok(n)
}

/// [`check_rotation`] for a given size n ≥ 1 (SO(1) = {1} is allowed: the SVD coordinates of
/// GL⁺(1) use it).
pub fn check_rotation_of(what: &str, r: &Mat, n: usize) -> Result<()> {
    check::square_of(what, r, n)?;
    rotation_error(what, r, n)
}

fn rotation_error(what: &str, r: &Mat, n: usize) -> Result<()> {
    let defect = orthogonality_defect(r);
    let det = r.determinant();
    // NaN (an overflow of RᵀR or det R for a huge matrix) is a defect too.
    if defect.is_nan() || defect > ROTATION_TOL || det.is_nan() || det <= 0.0 {
        return Err(Error::NotInGroup {
            what: what.into(),
            group: format!("SO({n})"),
            defect_name: format!("‖RᵀR − I‖_F (det R = {det:.6})"),
            defect,
            tol: ROTATION_TOL,
        });
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// so(3) coordinates

/// The e_ij coordinates c of `so3::hat(w)`: c = (−w3, w2, −w1), so that
/// `hat_n(&so3_to_e_ij(w)) = so3::hat(w)` (DESIGN.md: the physics hat map differs from the e_ij
/// basis at n = 3 in order and sign).
pub fn so3_to_e_ij(w: &Vector3<f64>) -> [f64; 3] {
    [-w.z, w.y, -w.x]
}

/// Inverse of [`so3_to_e_ij`]: w = (−c3, c2, −c1).
pub fn e_ij_to_so3(c: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(-c[2], c[1], -c[0])
}

fn to_matrix3(m: &Mat) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[(i, j)])
}

fn from_matrix3(m: &Matrix3<f64>) -> Mat {
    Mat::from_fn(3, 3, |i, j| m[(i, j)])
}

fn nan_mat(r: usize, c: usize) -> Mat {
    Mat::from_fn(r, c, |_, _| f64::NAN)
}

/// The norm |ξ| = √⟨ξ, ξ⟩ of the pairing (001 (2.8)), i.e. the Euclidean norm of the e_ij
/// coordinates; |ξ|² = Σ θ_j² over the rotation angles θ_j of exp ξ.
pub fn norm(xi: &Mat) -> f64 {
    pairing(xi, xi).sqrt()
}

// ---------------------------------------------------------------------------------------------
// exp and log

/// Exponential map so(n) → SO(n) (000 §3).
///
/// n = 2: exp [[0, a], [−a, 0]] = [[cos a, sin a], [−sin a, cos a]]. n = 3: Rodrigues through
/// [`so3::exp`] (w = [`e_ij_to_so3`] of the coordinates). n > 3: scaling and squaring with
/// diagonal Padé approximants of degree m = 3, 5, 7, 9 or 13 chosen from ‖ξᵖ‖₁^{1/p} (Higham
/// 2005, Al-Mohy & Higham 2009, as scipy's expm): r = (V − U)⁻¹ (V + U) with U, V the odd and even parts of the Padé numerator,
/// on ξ/2ˢ with ‖ξ/2ˢ‖₁ ≤ θ₁₃ = 5.37 when m = 13, then s squarings. For skew ξ, V is
/// symmetric and U skew, so r is orthogonal up to rounding (diagonal Padé approximants map
/// so(n) into SO(n)); after squarings, one Newton–Schulz step R ← R (3I − RᵀR)/2 squares the
/// accumulated O(2ˢ ε) orthogonality defect away, so ‖RᵀR − I‖ stays at round-off for |ξ| up to
/// 10³ and beyond. (A spectral route, exp ξ = cos √S + ξ sinc √S with S = ξᵀξ through a
/// symmetric eigendecomposition, was measured 4× slower at n = 50 and not kept.)
///
/// Errors if `xi` is not a finite skew n×n matrix with n ≥ 2.
pub fn exp(xi: &Mat) -> Result<Mat> {
    check_algebra("xi", xi)?;
    check_exp_norm("exp", xi)?;
    Ok(exp_unchecked(xi))
}

/// Largest |ξ| accepted by [`exp`] and [`dexp`]: the one rule of all exponentials,
/// [`super::EXP_MAX_NORM`] ≈ 2.25e14 (see [`super::ANGLE_ROUNDING_TOL`]).
pub use super::EXP_MAX_NORM;

/// [`norm`] without overflow: finite for every finite ξ (1e300 stays 1e300).
fn scaled_norm(xi: &Mat) -> f64 {
    let n = xi.nrows().min(xi.ncols());
    let upper: Vec<f64> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .map(|(i, j)| 0.5 * (xi[(i, j)] - xi[(j, i)]))
        .collect();
    super::scaled_norm(upper.iter())
}

fn check_exp_norm(map: &str, xi: &Mat) -> Result<()> {
    super::check_exp_norm("xi", map, scaled_norm(xi))
}

/// [`exp`] without validation, for inner loops on known-good input. Never panics: a non-square
/// or non-finite input gives a matrix of NaN.
pub fn exp_unchecked(xi: &Mat) -> Mat {
    let (n, c) = (xi.nrows(), xi.ncols());
    if n != c {
        return nan_mat(n, c);
    }
    match n {
        0 | 1 => Mat::identity(n, n),
        2 => {
            let (s, c) = super::angle_sin_cos(0.5 * (xi[(0, 1)] - xi[(1, 0)]));
            Mat::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => s,
                (1, 0) => -s,
                _ => c,
            })
        }
        3 => from_matrix3(&so3::exp(&so3::vee(&to_matrix3(xi)))),
        _ => exp_pade(xi),
    }
}

/// Coefficients b_0, …, b_m of the diagonal Padé approximants of exp of degree m = 3, 5, 7, 9, 13
/// with their thresholds θ_m on ‖A‖₁ below which the approximation error is under the unit
/// round-off (Higham 2005, Tables 2.3 and 10.2; the same as scipy's expm).
const PADE: [(f64, &[f64]); 5] = [
    (1.495585217958292e-2, &[120.0, 60.0, 12.0, 1.0]),
    (
        2.53939833006323e-1,
        &[30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0],
    ),
    (
        9.504178996162932e-1,
        &[
            17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0,
        ],
    ),
    (
        2.097847961257068,
        &[
            17643225600.0,
            8821612800.0,
            2075673600.0,
            302702400.0,
            30270240.0,
            2162160.0,
            110880.0,
            3960.0,
            90.0,
            1.0,
        ],
    ),
    (
        5.371920351148152,
        &[
            64764752532480000.0,
            32382376266240000.0,
            7771770303897600.0,
            1187353796428800.0,
            129060195264000.0,
            10559470521600.0,
            670442572800.0,
            33522128640.0,
            1323241920.0,
            40840800.0,
            960960.0,
            16380.0,
            182.0,
            1.0,
        ],
    ),
];

fn norm_1(a: &Mat) -> f64 {
    (0..a.ncols())
        .map(|j| (0..a.nrows()).map(|i| a[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// out = Σ_k c_k P_k + c0 I (or out += …), over n×n matrices P_k, in fused passes.
fn lin_comb(out: &mut Mat, terms: &[(f64, &Mat)], c0: f64, add: bool) {
    if !add {
        out.fill(0.0);
    }
    for &(c, p) in terms {
        faer::zip!(&mut *out, p).for_each(|faer::unzip!(o, x)| *o += c * *x);
    }
    for i in 0..out.nrows() {
        out[(i, i)] += c0;
    }
}

/// dst = a b (sequential faer product; no allocation).
fn mul_into(dst: &mut Mat, a: &Mat, b: &Mat) {
    crate::linalg::mul(
        dst.as_mut(),
        faer::Accum::Replace,
        a.as_ref(),
        b.as_ref(),
        1.0,
    );
}

/// The storage of the Padé exponential of so(n) for one size n ([`exp_into`]), allocated once:
/// a caller that computes many exponentials of one size (a batch, a time loop) keeps one and
/// allocates nothing per call. ([`exp`] and [`exp_unchecked`] keep one per thread.)
pub struct ExpWork {
    a2: Mat,
    a4: Mat,
    a6: Mat,
    x: Mat,
    u: Mat,
    v: Mat,
    t: Mat,
    lu: crate::linalg::DenseLu,
}

impl ExpWork {
    /// Storage for n×n exponentials.
    pub fn new(n: usize) -> Self {
        let z = || Mat::zeros(n, n);
        ExpWork {
            a2: z(),
            a4: z(),
            a6: z(),
            x: z(),
            u: z(),
            v: z(),
            t: z(),
            lu: crate::linalg::DenseLu::new(n),
        }
    }

    /// The size n it was made for.
    pub fn n(&self) -> usize {
        self.a2.nrows()
    }
}

thread_local! {
    /// The [`ExpWork`] of [`exp_unchecked`] on this thread (the size of its last call).
    static EXP_WORK: std::cell::RefCell<Option<ExpWork>> = const { std::cell::RefCell::new(None) };
}

/// [`exp_unchecked`] for n > 3 with this thread's storage: one allocation, the result.
fn exp_pade(xi: &Mat) -> Mat {
    let n = xi.nrows();
    let mut out = Mat::zeros(n, n);
    EXP_WORK.with(|cell| match cell.try_borrow_mut() {
        Ok(mut slot) => {
            let work = match slot.as_mut() {
                Some(w) if w.n() == n => w,
                _ => slot.insert(ExpWork::new(n)),
            };
            exp_into(xi, &mut out, work);
        }
        // Re-entered on this thread (cannot happen from lieflow itself): own storage.
        Err(_) => exp_into(xi, &mut out, &mut ExpWork::new(n)),
    });
    out
}

/// exp(ξ) of a skew n×n ξ (n = `work.n()` > 3, unchecked as [`exp_unchecked`]) into `out`
/// (n×n), with no allocation: scaling and squaring with diagonal Padé approximants
/// r_m = (V − U)⁻¹ (V + U), U the odd and V the even part of the numerator (Higham 2005). The
/// degree m and the scaling s follow Al-Mohy & Higham 2009 (as scipy's expm): with
/// d_p = ‖ξᵖ‖₁^{1/p} from the exact powers ξ², ξ⁴, ξ⁶ (and the bounds
/// d₈ ≤ min(d₄, (‖ξ²‖‖ξ⁶‖)^{1/8}), d₁₀ ≤ (‖ξ⁴‖‖ξ⁶‖)^{1/10}), the lowest m ∈ {3, 5, 7, 9} with
/// max(d's) ≤ θ_m, else m = 13 on ξ/2ˢ. For skew ξ, V is symmetric and U skew, so r_m is
/// orthogonal up to rounding (diagonal Padé approximants map so(n) into SO(n)); after s ≥ 1
/// squarings one Newton–Schulz step removes the accumulated defect. A wrongly sized `out` or
/// `work` gives NaN.
pub fn exp_into(xi: &Mat, out: &mut Mat, work: &mut ExpWork) {
    let n = work.n();
    if xi.nrows() != n || xi.ncols() != n || out.nrows() != n || out.ncols() != n {
        out.fill(f64::NAN);
        return;
    }
    let ExpWork {
        a2,
        a4,
        a6,
        x,
        u,
        v,
        t,
        lu,
    } = work;
    mul_into(a2, xi, xi);
    mul_into(a4, a2, a2);
    mul_into(a6, a4, a2);
    let (n2, n4, n6) = (norm_1(a2), norm_1(a4), norm_1(a6));
    let (d4, d6) = (n4.powf(0.25), n6.powf(1.0 / 6.0));
    let d8 = d4.min((n2 * n6).powf(0.125));
    let d10 = (n4 * n6).powf(0.1);
    let eta1 = d4.max(d6);
    let eta3 = d6.max(d8);
    let theta = |m: usize| PADE[m].0;
    let degree = if eta1 <= theta(0) {
        0
    } else if eta1 <= theta(1) {
        1
    } else if eta3 <= theta(2) {
        2
    } else if eta3 <= theta(3) {
        3
    } else {
        4
    };
    let b = PADE[degree].1;
    let mut squarings = 0;
    if degree < 4 {
        // U = ξ (b₁ I + b₃ ξ² + …), V = b₀ I + b₂ ξ² + … over the even powers ξ², ξ⁴, ξ⁶, ξ⁸.
        if degree == 3 {
            mul_into(x, a4, a4);
        }
        let pows: [&Mat; 4] = [a2, a4, a6, x];
        let odd: [(f64, &Mat); 4] =
            std::array::from_fn(|k| (b.get(2 * k + 3).copied().unwrap_or(0.0), pows[k]));
        let even: [(f64, &Mat); 4] =
            std::array::from_fn(|k| (b.get(2 * k + 2).copied().unwrap_or(0.0), pows[k]));
        lin_comb(t, &odd[..=degree], b[1], false);
        mul_into(u, xi, t);
        lin_comb(v, &even[..=degree], b[0], false);
    } else {
        let eta5 = eta3.min(d8.max(d10));
        if !eta5.is_finite() {
            out.fill(f64::NAN);
            return;
        }
        squarings = (eta5 / theta(4)).log2().ceil().max(0.0) as i32;
        // Degree 13 on ξ/2ˢ (Higham 2005, (10.35)), the powers scaled in place.
        let s = squarings;
        faer::zip!(&mut *x, xi).for_each(|faer::unzip!(o, a)| *o = *a * 0.5f64.powi(s));
        *a2 *= faer::Scale(0.25f64.powi(s));
        *a4 *= faer::Scale(0.0625f64.powi(s));
        *a6 *= faer::Scale(0.015625f64.powi(s));
        let terms = |c: [usize; 3]| [(b[c[0]], &*a6), (b[c[1]], &*a4), (b[c[2]], &*a2)];
        lin_comb(t, &terms([13, 11, 9]), 0.0, false);
        mul_into(v, a6, t);
        lin_comb(v, &terms([7, 5, 3]), b[1], true);
        mul_into(u, x, v);
        lin_comb(t, &terms([12, 10, 8]), 0.0, false);
        mul_into(v, a6, t);
        lin_comb(v, &terms([6, 4, 2]), b[0], true);
    }
    // r = (V − U)⁻¹ (V + U)
    let m = lu.matrix();
    faer::zip!(&mut *m, &*v, &*u).for_each(|faer::unzip!(o, p, q)| *o = *p - *q);
    faer::zip!(&mut *out, &*v, &*u).for_each(|faer::unzip!(o, p, q)| *o = *p + *q);
    if !lu.factor() {
        out.fill(f64::NAN);
        return;
    }
    lu.solve_columns(out.as_mut());
    for _ in 0..squarings {
        mul_into(t, out, out);
        std::mem::swap(out, t);
    }
    if squarings > 0 {
        orthogonalize_in(out, t, u);
    }
}

/// Newton–Schulz steps toward the orthogonal polar factor, R ← R (3I − RᵀR)/2, each squaring
/// the orthogonality defect δ = ‖RᵀR − I‖_F, until a step starts from δ ≤ 1e-8 (so it ends at
/// round-off). One step after the usual few squarings (δ ~ 1e-14); up to four after the ~45
/// squarings of |ξ| near [`EXP_MAX_NORM`], where the defect doubles with every squaring
/// (2⁴⁵ ε ≈ 1e-2). `g` and `p` are n×n scratch.
fn orthogonalize_in(r: &mut Mat, g: &mut Mat, p: &mut Mat) {
    let n = r.nrows();
    for _ in 0..8 {
        crate::linalg::mul(
            g.as_mut(),
            faer::Accum::Replace,
            r.transpose(),
            r.as_ref(),
            1.0,
        );
        let mut defect = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let gij = g[(i, j)];
                let e = gij - if i == j { 1.0 } else { 0.0 };
                defect += e * e;
                g[(i, j)] = if i == j { 1.5 - 0.5 * gij } else { -0.5 * gij };
            }
        }
        mul_into(p, r, g);
        std::mem::swap(r, p);
        if defect.sqrt() <= 1e-8 {
            break;
        }
    }
}

/// [`orthogonalize_in`] with its own scratch.
fn orthogonalize(mut r: Mat) -> Mat {
    let n = r.nrows();
    let (mut g, mut p) = (Mat::zeros(n, n), Mat::zeros(n, n));
    orthogonalize_in(&mut r, &mut g, &mut p);
    r
}

/// Rotations whose largest angle is within this distance of π are refused by [`log`], for every
/// n (the same tolerance as [`so3::LOG_PI_TOL`]): at π the logarithm is not unique, and within
/// round-off of π a rounding-level change of R decides between the candidates ±θJ. Below it the
/// logarithm is unique and computed to a backward error at round-off (exp(log R) = R); its
/// forward condition number grows like 1/(π − θ), which is the problem's, not the method's.
pub const LOG_PI_TOL: f64 = so3::LOG_PI_TOL;

fn check_angle(what: &str, angle: f64) -> Result<()> {
    let distance = std::f64::consts::PI - angle;
    if distance < LOG_PI_TOL {
        return Err(Error::NoUniqueLog {
            what: what.into(),
            angle,
            distance,
        });
    }
    Ok(())
}

/// Principal logarithm SO(n) → so(n): the ξ with exp ξ = R and all rotation angles in [0, π).
///
/// With C = (R + Rᵀ)/2 = cos √S and A = (R − Rᵀ)/2 = ξ sinc √S (S = ξᵀξ, see [`exp`]), C and A
/// commute and ξ = g(C) A with g(cos θ) = θ / sin θ. The method never resolves individual
/// rotation planes, so clustered or equal angles cost nothing (a plane split is ill-conditioned
/// for close angles, the logarithm is not):
///
/// - C = U diag(λ) Uᵀ (symmetric eigendecomposition, ascending λ = cos θ). The eigenvalues are
///   split once, at the midpoint of the widest gap among those in [−3/4, −1/4] (with the window's
///   ends as extra points; a gap of at least 1/(2(n + 1))), into an obtuse block V_o (the m
///   smallest) and an acute block V_a. Each block is an invariant subspace of R known to
///   ε / gap, independent of the clustering inside it.
/// - Acute block (angles below the split, at most 0.77π): ξ_a = g_a(C) A with g_a = θ / sin θ
///   on λ above the split and 0 below. g is smooth there (g(1) = 1, g ≤ 3.7), so g_a(C) is a
///   well-conditioned function of C; near θ = 0 the result keeps the relative accuracy of A.
/// - Obtuse block: −R_o = −V_oᵀ R V_o (m even: −1 eigenvalues and rotation pairs come in pairs)
///   has the acute angles π − θ_k, so η = log(−R_o) = ½{g(−Λ_o), −V_oᵀ A V_o} by the same formula
///   (in the eigenbasis, entrywise). With J the complex structure of the block, η = −Σ (π − θ_k)
///   J_k, so J = −polar(η) (an SVD of the m×m η, made exactly a complex structure by
///   Newton–Schulz steps; m = 2 in closed form) and ξ_o = π J + η. The polar factor is only as
///   accurate as ε / (π − θ) — the forward conditioning of the problem — but its error between
///   planes of equal π − θ commutes with η, so exp(ξ_o) = R_o to round-off. The singular
///   values of η are the π − θ_k: the smallest decides the refusal within [`LOG_PI_TOL`] of π.
///
/// Chosen over inverse scaling and squaring with Padé (Higham's logm) because it works in the
/// real symmetric eigenbasis that the structure provides (one eigendecomposition and two or
/// three n×n products, as the previous plane-by-plane version), is exactly skew, and handles
/// angles near π without square roots of a near −I matrix. n = 2: θ = atan2(R₁₂, R₁₁).
/// n = 3 with tr R ≥ 1: ξ = (θ / |A|) A, θ = atan2(|A|, (tr R − 1)/2).
///
/// Errors: `R` not a finite n×n rotation (‖RᵀR − I‖_F > [`ROTATION_TOL`] or det R ≤ 0) →
/// [`Error::NotInGroup`]; a rotation angle within [`LOG_PI_TOL`] of π → [`Error::NoUniqueLog`]
/// (carrying the angle).
pub fn log(r: &Mat) -> Result<Mat> {
    check_rotation("R", r)?;
    log_rotation(r)
}

/// [`log`] for an R already known to be a (finite, square) rotation.
fn log_rotation(r: &Mat) -> Result<Mat> {
    let n = r.nrows();
    let a = (r - r.transpose()) * faer::Scale(0.5);
    match n {
        2 => {
            let angle = a[(0, 1)].atan2(0.5 * (r[(0, 0)] + r[(1, 1)]));
            check_angle("R", angle.abs())?;
            Ok(Mat::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => angle,
                (1, 0) => -angle,
                _ => 0.0,
            }))
        }
        3 => {
            let cos = 0.5 * (r[(0, 0)] + r[(1, 1)] + r[(2, 2)] - 1.0);
            if cos < 0.0 {
                return log_spectral(r, &a);
            }
            let s = norm(&a);
            let angle = s.atan2(cos);
            let f = if s > 0.0 { angle / s } else { 1.0 };
            Ok(a * faer::Scale(f))
        }
        _ => log_spectral(r, &a),
    }
}

/// The window of cos θ in which [`log`] splits the spectrum of C into its acute and obtuse
/// blocks (θ from 0.58π to 0.77π).
const LOG_SPLIT_WINDOW: (f64, f64) = (-0.75, -0.25);

/// g(λ) = θ / sin θ at λ = cos θ for the acute range λ ≥ −0.75 (clamped to λ ≤ 1): smooth,
/// g(1) = 1, computed as atan2(s, λ) / s with s = √((1 − λ)(1 + λ)) (both relatively accurate).
fn theta_over_sin(lambda: f64) -> f64 {
    let l = lambda.min(1.0);
    let s = ((1.0 - l) * (1.0 + l)).sqrt();
    if s > 0.0 {
        s.atan2(l) / s
    } else {
        1.0
    }
}

/// The number m of eigenvalues (ascending `lam`) below the midpoint of the widest gap in
/// [`LOG_SPLIT_WINDOW`] (0 when all are above the window's upper end).
fn log_split(lam: &[f64]) -> usize {
    let (lo, hi) = LOG_SPLIT_WINDOW;
    if !lam.first().is_some_and(|&l| l < hi) {
        return 0;
    }
    let (mut best_gap, mut best_m, mut prev) = (-1.0, 0, lo);
    for j in 0..=lam.len() {
        if j < lam.len() && lam[j] < lo {
            continue;
        }
        let next = if j < lam.len() { lam[j].min(hi) } else { hi };
        if next - prev > best_gap {
            (best_gap, best_m) = (next - prev, j);
        }
        if j == lam.len() || lam[j] >= hi {
            break;
        }
        prev = lam[j];
    }
    best_m
}

/// Makes a square matrix exactly skew in place: X ← (X − Xᵀ)/2.
fn skew_in_place(x: &mut Mat) {
    let n = x.nrows();
    for j in 0..n {
        x[(j, j)] = 0.0;
        for i in j + 1..n {
            let v = 0.5 * (x[(i, j)] - x[(j, i)]);
            x[(i, j)] = v;
            x[(j, i)] = -v;
        }
    }
}

/// The spectral logarithm (n ≥ 3; n = 3 only for angles > π/2), see [`log`].
fn log_spectral(r: &Mat, a: &Mat) -> Result<Mat> {
    let n = r.nrows();
    let not_converged = |what: &str| Error::NotConverged {
        what: format!("{what} in so::log"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    };
    let c = Mat::from_fn(n, n, |i, j| 0.5 * (r[(i, j)] + r[(j, i)]));
    let eig = c
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|_| not_converged("symmetric eigendecomposition"))?;
    let (u, lam) = (eig.U(), eig.S().column_vector());
    let lam: Vec<f64> = (0..n).map(|j| lam[j]).collect();
    let m = log_split(&lam);
    if m % 2 == 1 {
        // Unreachable for a rotation to ROTATION_TOL: the pairs of eigenvalues of C agree to
        // ~1e-10, far below the split gap ≥ 1/(2(n + 1)).
        return Err(not_converged("the acute/obtuse split of the spectrum"));
    }
    // Acute block: ξ = U diag(g_a) (Uᵀ A).
    let mut w = u.transpose() * a;
    let obtuse_a = (m > 0).then(|| -(w.subrows(0, m) * u.subcols(0, m)));
    for (i, &l) in lam.iter().enumerate() {
        let g = if i < m { 0.0 } else { theta_over_sin(l) };
        for j in 0..n {
            w[(i, j)] *= g;
        }
    }
    let mut xi = u * &w;
    // Obtuse block: η = log(−R_o) entrywise in the eigenbasis, then ξ_o = π J + η.
    if let Some(an) = obtuse_a {
        let g: Vec<f64> = lam[..m].iter().map(|&l| theta_over_sin(-l)).collect();
        let mut eta = Mat::from_fn(m, m, |k, l| 0.5 * (g[k] + g[l]) * an[(k, l)]);
        skew_in_place(&mut eta);
        let pi = std::f64::consts::PI;
        // The singular values of η are the π − θ_k (η's 2×2 form when m = 2).
        let svd = if m == 2 {
            None
        } else {
            Some(
                eta.svd()
                    .map_err(|_| not_converged("SVD of the obtuse block"))?,
            )
        };
        let sigma_min = match &svd {
            None => eta[(0, 1)].abs(),
            Some(svd) => {
                let s = svd.S().column_vector();
                (0..m).map(|k| s[k]).fold(f64::INFINITY, f64::min)
            }
        };
        check_angle("R", pi - sigma_min)?;
        let xo = match svd {
            None => {
                let x = eta[(0, 1)];
                let t = x - pi.copysign(x);
                Mat::from_fn(2, 2, |k, l| [[0.0, t], [-t, 0.0]][k][l])
            }
            Some(svd) => {
                // The SVD's backward error is relative to ‖η‖, not to each σ: with angles both
                // near and far from π its polar factor UVᵀ has a symmetric part ~ε‖η‖/σ_min.
                // Its skew part commutes with η to round-off; Newton–Schulz steps (odd
                // polynomials in J, so they keep the commutation) make it a complex structure
                // again (J² = −I).
                let mut j = svd.U() * svd.V().transpose();
                skew_in_place(&mut j);
                let mut j = orthogonalize(j);
                skew_in_place(&mut j);
                let mut xo = j * faer::Scale(-pi);
                xo += &eta;
                xo
            }
        };
        let vo = u.subcols(0, m);
        xi += vo * xo * vo.transpose();
    }
    skew_in_place(&mut xi);
    Ok(xi)
}

// ---------------------------------------------------------------------------------------------
// Cayley map

/// Cayley map cay(ξ) = (I − ξ/2)⁻¹ (I + ξ/2), so(n) → SO(n), a second-order approximation of
/// exp (cay ξ = exp ξ + O(|ξ|³)). I − ξ/2 is always invertible (eigenvalues 1 − iθ/2).
///
/// Defined for every ξ (its angles 2 atan(θ_j/2) tend to π): both factors are scaled by
/// c = 1/max(1, max |ξ_ij|), cay ξ = (cI − cξ/2)⁻¹ (cI + cξ/2), so the solve sees entries of
/// order one and the result is finite and orthogonal for every finite ξ.
///
/// For n = 3 the closed form of [`super::so3::cayley`] is used, accurate for every finite ξ. For
/// n ≥ 4 the solve mixes the scales of the rotation planes: with a zero angle (always present
/// for odd n) beside a huge one it loses accuracy like ε·|ξ|², so the result is checked, and a
/// rotation that is not orthogonal to 1e-12 is refused with [`Error::InvalidArgument`] naming the
/// scale (never a NaN or a wrong rotation).
pub fn cayley(xi: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    if n == 3 {
        let w = nalgebra::Vector3::new(xi[(2, 1)], xi[(0, 2)], xi[(1, 0)]);
        let r = super::so3::cayley(&w);
        return Ok(Mat::from_fn(3, 3, |i, j| r[(i, j)]));
    }
    let m = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .fold(1.0f64, |m, (i, j)| m.max(xi[(i, j)].abs()));
    let c = 1.0 / m;
    let half = xi * faer::Scale(0.5 * c);
    let minus = Mat::identity(n, n) * faer::Scale(c) - &half;
    let plus = Mat::identity(n, n) * faer::Scale(c) + &half;
    let r = minus.partial_piv_lu().solve(&plus);
    let defect = (r.transpose() * &r - Mat::identity(n, n)).norm_max();
    if defect.is_nan() || defect > 1e-12 {
        return Err(Error::invalid(
            "xi",
            format!(
                "the Cayley map of a ξ with entries up to {} lost its accuracy (orthogonality \
                 defect {}): a zero angle beside a huge one; scale ξ down",
                crate::error::fmt_num(m),
                crate::error::fmt_num(defect)
            ),
        ));
    }
    Ok(r)
}

/// [`cayley_inv`] refuses rotations with σ_min(I + R) below this (an eigenvalue −1 of R, i.e. a
/// rotation angle π, is not in the image of the Cayley map; near it ξ grows like 2 tan(θ/2)).
pub const CAYLEY_TOL: f64 = 1e-8;

/// Inverse Cayley map ξ = 2 (I + R)⁻¹ (R − I), the exact inverse of [`cayley`]
/// (from (I − ξ/2) R = I + ξ/2).
///
/// Errors: `R` not a rotation → [`Error::NotInGroup`]; I + R singular (smallest singular value
/// below [`CAYLEY_TOL`]) → [`Error::InvalidArgument`].
pub fn cayley_inv(r: &Mat) -> Result<Mat> {
    let n = check_rotation("R", r)?;
    let plus = r + Mat::identity(n, n);
    let smin = plus
        .singular_values()
        .map_err(|_| Error::NotConverged {
            what: "SVD of I + R in so::cayley_inv".into(),
            iterations: 0,
            residual: f64::NAN,
            tol: 0.0,
        })?
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    if smin < CAYLEY_TOL {
        return Err(Error::invalid(
            "R",
            format!(
                "I + R is singular (smallest singular value {smin:.3e} < {CAYLEY_TOL:.0e}): R has \
                 an eigenvalue −1 (a rotation by π), outside the image of the Cayley map"
            ),
        ));
    }
    let minus = r - Mat::identity(n, n);
    let xi = plus.partial_piv_lu().solve(&minus) * faer::Scale(2.0);
    Ok((&xi - xi.transpose()) * faer::Scale(0.5))
}

// ---------------------------------------------------------------------------------------------
// dexp and its inverse

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
    let w = so3::vee(&to_matrix3(xi));
    let v = so3::vee(&to_matrix3(eta));
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

// ---------------------------------------------------------------------------------------------
// Adjoint and coadjoint actions

/// Adjoint action Ad_g ξ = g ξ gᵀ (= g ξ g⁻¹ on SO(n)).
pub fn adjoint(g: &Mat, xi: &Mat) -> Result<Mat> {
    let n = check_rotation("g", g)?;
    check_algebra_of("xi", xi, n)?;
    Ok(g * xi * g.transpose())
}

/// ad_ξ η = [ξ, η] = ξη − ηξ.
pub fn ad(xi: &Mat, eta: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    check_algebra_of("eta", eta, n)?;
    Ok(bracket(xi, eta))
}

/// Coadjoint action ad*_ξ μ = [μ, ξ] with so(n)* ≅ so(n) through the pairing ½ tr(ξᵀη)
/// (000 §3.3): from ⟨ad*_ξ μ, η⟩ = ⟨μ, [ξ, η]⟩ = ½ tr(μᵀξη − ξμᵀη) for skew μ, ξ.
pub fn ad_star(xi: &Mat, mu: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    check_algebra_of("mu", mu, n)?;
    Ok(bracket(mu, xi))
}

// ---------------------------------------------------------------------------------------------
// Projection

/// Nearest rotation to M in the Frobenius norm: R = U D Vᵀ from the SVD M = U Σ Vᵀ with
/// D = diag(1, …, 1, sign det(UVᵀ)) (the sign fix acts on the smallest singular value). For
/// det M > 0 this is the orthogonal polar factor of M. It is unique when the two smallest
/// singular values (of M with det M < 0: the smallest one) are not both zero/tied.
///
/// Scale-free (the nearest rotation to cM is that of M): the SVD is taken of M/c with c a power
/// of two near max |M_ij| ([`check::pow2_exponent_mat`]), so M at 1e300 or 1e-300 is projected
/// like M at 1.
pub fn project_to_so(m: &Mat) -> Result<Mat> {
    check::square("M", m, 2)?;
    let m = check::ldexp_mat(m, -check::pow2_exponent_mat(m));
    let svd = m.svd().map_err(|e| Error::NotConverged {
        what: format!("the SVD of M in so::project_to_so (faer: {e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let (u, v) = (svd.U(), svd.V());
    let mut r = u * v.transpose();
    if r.determinant() < 0.0 {
        let s = svd.S().column_vector();
        let jmin = (0..s.nrows())
            .min_by(|&a, &b| s[a].total_cmp(&s[b]))
            .unwrap_or(0);
        let n = r.nrows();
        // R − 2 u_j v_jᵀ flips the sign of the j-th singular direction.
        r = Mat::from_fn(n, n, |i, k| r[(i, k)] - 2.0 * u[(i, jmin)] * v[(k, jmin)]);
    }
    Ok(r)
}

// ---------------------------------------------------------------------------------------------
// The group element type

/// An element of SO(n) (n ≥ 2), validated on construction; implements [`MatrixLieGroup`] with
/// the skew matrices as algebra and the e_ij coordinates.
#[derive(Clone, Debug)]
pub struct SOn(Mat);

impl SOn {
    /// Wraps `r` after checking it is a rotation ([`check_rotation`]).
    pub fn new(r: Mat) -> Result<Self> {
        check_rotation("R", &r)?;
        Ok(Self(r))
    }

    /// The identity of SO(n); errors for n < 2.
    pub fn identity(n: usize) -> Result<Self> {
        if n < 2 {
            return Err(Error::invalid("n", format!("SO(n) needs n ≥ 2, got {n}")));
        }
        Ok(Self(Mat::identity(n, n)))
    }

    /// exp ξ as a group element (validates ξ, see [`exp`]).
    pub fn exp_checked(xi: &Mat) -> Result<Self> {
        exp(xi).map(Self)
    }

    /// The size n.
    pub fn n(&self) -> usize {
        self.0.nrows()
    }

    /// The rotation matrix.
    pub fn as_mat(&self) -> &Mat {
        &self.0
    }

    /// The rotation matrix, by value.
    pub fn into_mat(self) -> Mat {
        self.0
    }
}

impl MatrixLieGroup for SOn {
    type Algebra = Mat;

    fn dim(&self) -> usize {
        dim(self.n())
    }
    fn identity_like(&self) -> Self {
        Self(Mat::identity(self.n(), self.n()))
    }
    fn compose(&self, other: &Self) -> Self {
        Self(&self.0 * &other.0)
    }
    fn inverse(&self) -> Self {
        Self(self.0.transpose().to_owned())
    }
    /// [`exp_unchecked`] (NaN for invalid input; use [`SOn::exp_checked`] to validate).
    fn exp(xi: &Mat) -> Self {
        Self(exp_unchecked(xi))
    }
    fn log(&self) -> Result<Mat> {
        log_rotation(&self.0)
    }
    fn adjoint(&self, xi: &Mat) -> Mat {
        &self.0 * xi * self.0.transpose()
    }
    fn ad(xi: &Mat, eta: &Mat) -> Mat {
        bracket(xi, eta)
    }
    fn ad_star(xi: &Mat, mu: &Mat) -> Mat {
        bracket(mu, xi)
    }
    fn pairing(mu: &Mat, xi: &Mat) -> f64 {
        pairing(mu, xi)
    }
    fn matrix(&self) -> Mat {
        self.0.clone()
    }
    fn algebra_matrix(xi: &Mat) -> Mat {
        xi.clone()
    }
    fn coords(xi: &Mat) -> Vec<f64> {
        vee_n_unchecked(xi)
    }
    fn algebra_from_coords(&self, c: &[f64]) -> Mat {
        hat_n_unchecked(self.n(), c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hat_vee_roundtrip_and_basis_order() {
        let c = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let m = hat_n(&c).unwrap();
        assert_eq!(m.nrows(), 4);
        assert_eq!(m[(0, 1)], 1.0);
        assert_eq!(m[(0, 3)], 3.0);
        assert_eq!(m[(1, 2)], 4.0);
        assert_eq!(m[(3, 2)], -6.0);
        assert_eq!(vee_n(&m).unwrap(), c.to_vec());
        assert!(hat_n(&[1.0, 2.0]).is_err());
        assert_eq!(n_from_dim(1), Some(2));
        assert_eq!(n_from_dim(45), Some(10));
        assert_eq!(n_from_dim(0), None);
    }

    #[test]
    fn pairing_is_sum_over_upper_triangle() {
        let a = hat_n(&[1.0, 2.0, 3.0]).unwrap();
        let b = hat_n(&[4.0, 5.0, 6.0]).unwrap();
        assert!((pairing(&a, &b) - 32.0).abs() < 1e-14);
    }

    #[test]
    fn bernoulli_coefficients_match_known_values() {
        // z/(eᶻ − 1) = 1 − z/2 + z²/12 − z⁴/720 + z⁶/30240 − z⁸/1209600 + …
        let b = bernoulli_coefficients();
        let known = [
            1.0,
            -0.5,
            1.0 / 12.0,
            0.0,
            -1.0 / 720.0,
            0.0,
            1.0 / 30240.0,
            0.0,
        ];
        for (k, v) in known.iter().enumerate() {
            assert!((b[k] - v).abs() <= 1e-15 * v.abs(), "b_{k}");
        }
        assert!((b[8] + 1.0 / 1_209_600.0).abs() < 1e-15 / 1_209_600.0);
        // B_10 = 5/66.
        assert!((b[10] - 5.0 / 66.0 / 3_628_800.0).abs() < 1e-15 * b[10]);
    }

    #[test]
    fn vee_rejects_non_skew() {
        let mut m = hat_n(&[1.0, 2.0, 3.0]).unwrap();
        m[(0, 0)] = 0.1;
        assert!(matches!(vee_n(&m), Err(Error::NotInGroup { .. })));
    }
}
