//! The exponential so(n) → SO(n): closed forms for n ≤ 3, scaling and squaring with diagonal
//! Padé approximants above (000 §3).

use super::{check_algebra, from_matrix3, nan_mat, to_matrix3};
use crate::error::Result;
use crate::lie::so3;
use crate::Mat;

/// Exponential map so(n) → SO(n) (000 §3).
///
/// n = 2: exp [[0, a], [−a, 0]] = [[cos a, sin a], [−sin a, cos a]]. n = 3: Rodrigues through
/// [`so3::exp`] (w = [`e_ij_to_so3`](super::e_ij_to_so3) of the coordinates). n > 3: scaling and squaring with
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

/// [`norm`] without overflow: finite for every finite ξ (1e300 stays 1e300).
fn scaled_norm(xi: &Mat) -> f64 {
    let n = xi.nrows().min(xi.ncols());
    let upper: Vec<f64> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .map(|(i, j)| 0.5 * (xi[(i, j)] - xi[(j, i)]))
        .collect();
    crate::lie::scaled_norm(upper.iter())
}

pub(super) fn check_exp_norm(map: &str, xi: &Mat) -> Result<()> {
    crate::lie::check_exp_norm("xi", map, scaled_norm(xi))
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
            let (s, c) = crate::numerics::angle::angle_sin_cos(0.5 * (xi[(0, 1)] - xi[(1, 0)]));
            Mat::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => s,
                (1, 0) => -s,
                _ => c,
            })
        }
        3 => from_matrix3(&so3::exp_unchecked(&so3::vee_unchecked(&to_matrix3(xi)))),
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
    crate::numerics::linalg::mul(
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
    lu: crate::numerics::linalg::DenseLu,
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
            lu: crate::numerics::linalg::DenseLu::new(n),
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
/// squarings of |ξ| near [`crate::numerics::angle::EXP_MAX_NORM`], where the defect doubles with every squaring
/// (2⁴⁵ ε ≈ 1e-2). `g` and `p` are n×n scratch.
fn orthogonalize_in(r: &mut Mat, g: &mut Mat, p: &mut Mat) {
    let n = r.nrows();
    for _ in 0..8 {
        crate::numerics::linalg::mul(
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
pub(super) fn orthogonalize(mut r: Mat) -> Mat {
    let n = r.nrows();
    let (mut g, mut p) = (Mat::zeros(n, n), Mat::zeros(n, n));
    orthogonalize_in(&mut r, &mut g, &mut p);
    r
}
