//! SIMD lanes for the batch paths, and the lane-wise (sin θ, cos θ) of the exact rotation flows.
//!
//! **Why `pulp`.** The batch kernels are written once, generic over [`pulp::Simd`], and run
//! through [`pulp::Arch::dispatch`], which picks the widest instruction set of the machine at run
//! time (AVX2 on x86-64 v3 processors, SSE2/scalar below it; NEON on aarch64). The wheel and the
//! crate are built for the baseline target (no `-C target-cpu`), so compile-time SIMD (`wide`,
//! which follows the compile-time target features) would run 2-lane SSE2 code on every machine.
//! pulp is already in the build (faer uses it), so it costs no new dependency.
//!
//! **Reproducibility.** The same generic kernel runs with `S = pulp::Scalar` (one lane) for the
//! single-member steppers and with the dispatched vector type for batches, and it uses only
//! operations that IEEE 754 rounds correctly and identically in every lane and instruction set:
//! `+`, `−`, `×`, the fused multiply-add a·b + c rounded once ([`fma`]), comparisons, selects
//! and bit operations. The fused multiply-add is never replaced by a multiply and an add (which
//! round twice, a different last bit): under the dispatched instruction sets (x86-64 v3 and v4,
//! NEON) it is the hardware instruction, and the one-lane kernels run inside the same dispatch
//! (`pulp::Arch::dispatch`), so that `pulp::Scalar`'s `f64::mul_add` compiles to it too; on a
//! machine without FMA it is the platform's correctly rounded `fma` (slower, the same bits). A
//! member's result is therefore the same bits whatever lane, block, batch size, instruction set,
//! machine or thread computes it. Lanes that need the slow path (below) are taken one by
//! one by the same scalar function, again independent of their neighbours.
//!
//! **sin/cos** ([`sin_cos_lanes`], scalar [`lane_sin_cos`]): the angle x is reduced to
//! r = x − kπ/2, |r| ≲ π/4, k = round(2x/π) (rounding by adding and subtracting 1.5·2⁵², whose
//! low mantissa bits then hold k mod 4), by a three-part Cody–Waite reduction: π/2 = C₁ + C₂ + C₃
//! with C₁, C₂ of 33 significant bits, so that k·C₁ and k·C₂ are exact for |k| ≤ 2¹⁹, C₃ the
//! rounded rest (π/2 − C₁ − C₂ − C₃ ≈ 1e-37); the result is a double-double r = r_hi + r_lo with
//! an absolute error below 2⁻⁹⁸. sin r and cos r are the Taylor polynomials through r¹⁷ and r¹⁶
//! (their remainders are about 1e-19 and 3e-18 of the result at |r| = π/4), coefficients 1/n!
//! correctly rounded, evaluated by Horner's rule in z = r² with the first-order correction for
//! r_lo; cos r = w + ((1 − w) − z/2) + (z²Q(z) − r·r_lo) with w = 1 − z/2 keeps the rounding error
//! of w. The quadrant k mod 4 swaps and negates the pair.
//!
//! The range: the flows of the rigid bodies rotate by θ = τ·a_k·M_k per sub-step
//! (a_k = 1/I_k − 1/I_r), |θ| ≪ 1 whenever the step resolves the motion; the fast path covers
//! |θ| ≤ [`FAST_MAX`] = 2¹⁹·π/2 ≈ 8.2e5 rad. Lanes beyond it, and lanes within 2⁻⁴⁰ of a
//! non-zero multiple of π/2 (where the reduction loses more bits than the three parts carry),
//! take the platform's `sin_cos` (an exact reduction), so every finite angle gets a correct
//! value; beyond [`crate::numerics::angle::EXP_MAX_NORM`] the flows' rule of [`crate::numerics::angle::angle_sin_cos`]
//! applies (NaN: the angle is lost to rounding), and a non-finite angle gives NaN. The error
//! against libm is at most 2 ulp (tests: a large random sample over the fast range, angles near
//! multiples of π/2, tiny and huge angles).
//!
//! **Rotations** ([`sin_cosm1_lanes`], scalar [`angle_sin_cosm1`]): the rotation flows take
//! (sin θ, cos θ − 1) and apply v + ((cos θ − 1)v + sin θ·Jv), not (cos θ)v + sin θ·Jv. A rotation
//! by (c, s) rounded scales |v|² by c² + s² = 1 + δ with |δ| up to about an ulp of 1, and for a
//! symmetric body the angle, hence δ, is the same at every step: the Casimirs then drift linearly
//! (Brouwer's law broken; measured on the Lagrange top: δ = 0.15 ulp, |Γ|² off by 2.9e-11 after
//! 10⁶ steps, all of it δ). With cos θ − 1 carried to its own relative precision (the polynomial
//! without the 1: −r²/2 + r⁴Q(r²)) the defect (1 + (c − 1))² + s² − 1 is O(θ²ε), below the
//! rounding of the product itself for the angles of a step, and the errors random-walk.

use pulp::Simd;

/// The largest |θ| reduced by the fast path: 2¹⁹·π/2 (|k| ≤ 2¹⁹, so k·C₁ and k·C₂ are exact).
pub const FAST_MAX: f64 = 524_288.0 * std::f64::consts::FRAC_PI_2;

/// Below this |r| (for k ≠ 0) the three-part reduction is not accurate enough (its absolute error
/// is below 2⁻⁹⁸): such lanes take the exact slow path.
const TINY: f64 = 1.0 / 1_099_511_627_776.0; // 2⁻⁴⁰

/// 1.5·2⁵²: x + MAGIC − MAGIC rounds x to the nearest integer (|x| < 2⁵¹), and the low bits of
/// x + MAGIC are that integer modulo 2⁵¹.
const MAGIC: f64 = 6_755_399_441_055_744.0;

/// 2/π, correctly rounded.
const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
/// π/2 to 33 significant bits (0x1.921fb544p0; the bits are tested).
const C1: f64 = 1.570_796_326_734_125_6;
/// The next 33 bits of π/2 (0x1.0b4611a6p-34).
const C2: f64 = 6.077_100_506_303_966e-11;
/// π/2 − C₁ − C₂, rounded (0x1.3198a2e037073p-69).
const C3: f64 = 2.022_266_248_795_950_6e-21;

// Taylor coefficients: sin r = r + r³·P(r²), P = −1/3! + z/5! − … + z⁷/17!;
// cos r = 1 − r²/2 + r⁴·Q(r²), Q = 1/4! − z/6! + … + z⁶/16!.
const S: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5_040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];
const C: [f64; 7] = [
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// (sin x, cos x) in every lane by the fast path (module docs), and the mask of the lanes that
/// must be recomputed by [`slow_sin_cos`] (|x| > [`FAST_MAX`], non-finite, or too close to a
/// non-zero multiple of π/2).
#[inline(always)]
pub fn sin_cos_fast<S: Simd>(simd: S, x: S::f64s) -> (S::f64s, S::f64s, S::m64s) {
    let ([s, c, _], slow) = fast(simd, x);
    (s, c, slow)
}

/// (sin x, cos x − 1) in every lane by the fast path, and the mask of the lanes that must be
/// recomputed by [`slow_sin_cosm1`] (as [`sin_cos_fast`]). For k ≡ 0 (mod 4) cos x − 1 is
/// cos r − 1 = −r²/2 + r⁴Q(r²) − r·r_lo, to the relative accuracy of the polynomials (no
/// cancellation at small r); elsewhere |x| ≥ π/4 and cos x − 1 ≤ −0.29 is the rounded difference.
#[inline(always)]
pub fn sin_cosm1_fast<S: Simd>(simd: S, x: S::f64s) -> (S::f64s, S::f64s, S::m64s) {
    let ([s, _, cm1], slow) = fast(simd, x);
    (s, cm1, slow)
}

/// sin x, cos x and cos x − 1 by the fast path, and the slow lanes.
#[inline(always)]
fn fast<S: Simd>(simd: S, x: S::f64s) -> ([S::f64s; 3], S::m64s) {
    let ax = simd.abs_f64s(x);
    // k = round(2x/π) and its low bits.
    let t = simd.add_f64s(
        simd.mul_f64s(x, splat(simd, TWO_OVER_PI)),
        splat(simd, MAGIC),
    );
    let k = simd.sub_f64s(t, splat(simd, MAGIC));
    let bits = simd.transmute_u64s_f64s(t);
    // r = x − k·C₁ (exact) − k·C₂ (exact product, exact two-sum) − k·C₃.
    let a = simd.sub_f64s(x, simd.mul_f64s(k, splat(simd, C1)));
    let b = simd.mul_f64s(k, splat(simd, C2));
    let r1 = simd.sub_f64s(a, b);
    // Two-sum of a and −b: r1 + e1 = a − b exactly.
    let bb = simd.sub_f64s(r1, a);
    let e1 = simd.sub_f64s(
        simd.sub_f64s(a, simd.sub_f64s(r1, bb)),
        simd.add_f64s(b, bb),
    );
    let tail = simd.sub_f64s(e1, simd.mul_f64s(k, splat(simd, C3)));
    let r = simd.add_f64s(r1, tail);
    let r_lo = simd.add_f64s(simd.sub_f64s(r1, r), tail);
    let (sin_r, cos_r, cosm1_r) = sin_cos_reduced(simd, r, r_lo);
    // Quadrant k mod 4: odd k swaps, k ∈ {2, 3} negates sin, k ∈ {1, 2} negates cos.
    let odd = simd.equal_u64s(simd.and_u64s(bits, simd.splat_u64s(1)), simd.splat_u64s(1));
    let neg_s = simd.equal_u64s(simd.and_u64s(bits, simd.splat_u64s(2)), simd.splat_u64s(2));
    let neg_c = simd.equal_u64s(
        simd.and_u64s(simd.add_u64s(bits, simd.splat_u64s(1)), simd.splat_u64s(2)),
        simd.splat_u64s(2),
    );
    let s = simd.select_f64s(odd, cos_r, sin_r);
    let c = simd.select_f64s(odd, sin_r, cos_r);
    let sign = splat(simd, -0.0);
    let s = simd.select_f64s(neg_s, simd.xor_f64s(s, sign), s);
    let c = simd.select_f64s(neg_c, simd.xor_f64s(c, sign), c);
    let quad0 = simd.equal_u64s(simd.and_u64s(bits, simd.splat_u64s(3)), simd.splat_u64s(0));
    let cm1 = simd.select_f64s(quad0, cosm1_r, simd.sub_f64s(c, splat(simd, 1.0)));
    // Lanes for the slow path: |x| beyond the fast range (or NaN), or deep cancellation.
    let in_range = simd.less_than_or_equal_f64s(ax, splat(simd, FAST_MAX));
    let cancel = simd.and_m64s(
        simd.less_than_f64s(simd.abs_f64s(r), splat(simd, TINY)),
        simd.greater_than_f64s(ax, splat(simd, 0.5)),
    );
    let slow = simd.or_m64s(simd.not_m64s(in_range), cancel);
    ([s, c, cm1], slow)
}

/// a·b + c rounded once (a fused multiply-add: the hardware's under the dispatched instruction
/// sets, the correctly rounded `fma` of the platform's libm on a scalar path without them; the
/// same bits either way).
#[inline(always)]
pub fn fma<S: Simd>(simd: S, a: S::f64s, b: S::f64s, c: S::f64s) -> S::f64s {
    simd.mul_add_f64s(a, b, c)
}

// The kernels' small helpers are functions, not closures: a closure that LLVM does not inline
// is compiled outside the dispatched instruction set, and its intrinsics become calls.

/// v in every lane.
#[inline(always)]
pub fn splat<S: Simd>(simd: S, v: f64) -> S::f64s {
    simd.splat_f64s(v)
}

/// −x (exact: the sign bit).
#[inline(always)]
pub fn neg<S: Simd>(simd: S, x: S::f64s) -> S::f64s {
    simd.xor_f64s(x, simd.splat_f64s(-0.0))
}

/// a + b z.
#[inline(always)]
fn pair<S: Simd>(simd: S, z: S::f64s, a: f64, b: f64) -> S::f64s {
    fma(simd, splat(simd, b), z, splat(simd, a))
}

/// P(z) and Q(z) of the Taylor polynomials (sin r = r + r³P(r²), cos r = 1 − r²/2 + r⁴Q(r²)),
/// by Estrin's scheme in fused multiply-adds (pairs, then z², z⁴: a chain of 3 instead of
/// Horner's 7, for the one-body path, which waits on it), and z².
#[inline(always)]
fn taylor_pq<S: Simd>(simd: S, z: S::f64s) -> (S::f64s, S::f64s, S::f64s) {
    let z2 = simd.mul_f64s(z, z);
    let z4 = simd.mul_f64s(z2, z2);
    let p = fma(
        simd,
        cubic(simd, z, z2, [S[4], S[5], S[6], S[7]]),
        z4,
        cubic(simd, z, z2, [S[0], S[1], S[2], S[3]]),
    );
    let q = fma(
        simd,
        fma(simd, splat(simd, C[6]), z2, pair(simd, z, C[4], C[5])),
        z4,
        cubic(simd, z, z2, [C[0], C[1], C[2], C[3]]),
    );
    (p, q, z2)
}

/// c₀ + c₁z + (c₂ + c₃z)z² (Estrin's pairs).
#[inline(always)]
fn cubic<S: Simd>(simd: S, z: S::f64s, z2: S::f64s, c: [f64; 4]) -> S::f64s {
    fma(
        simd,
        pair(simd, z, c[2], c[3]),
        z2,
        pair(simd, z, c[0], c[1]),
    )
}

/// (sin θ/θ, (1 − cos θ)/θ²) from z = θ² for θ ≤ [`SMALL_MAX`]: 1 + z P(z) and ½ − z Q(z), the
/// polynomials of [`sin_cos_small`] (no square root, no division, no cancellation at small θ).
#[inline(always)]
pub fn sinc_versinc_small<S: Simd>(simd: S, z: S::f64s) -> (S::f64s, S::f64s) {
    let (p, q, _) = taylor_pq(simd, z);
    let minus_z = simd.xor_f64s(z, simd.splat_f64s(-0.0));
    (
        fma(simd, z, p, simd.splat_f64s(1.0)),
        fma(simd, minus_z, q, simd.splat_f64s(0.5)),
    )
}

/// (sin, cos, cos − 1) of r + r_lo, |r| ≲ π/4, |r_lo| ≤ ulp(r)/2: the polynomials (module
/// docs); cos − 1 = (z²Q − r·r_lo) − z/2 without the 1 (no cancellation).
#[inline(always)]
fn sin_cos_reduced<S: Simd>(simd: S, r: S::f64s, r_lo: S::f64s) -> (S::f64s, S::f64s, S::f64s) {
    let z = simd.mul_f64s(r, r);
    let (p, q, z2) = taylor_pq(simd, z);
    let hz = simd.mul_f64s(splat(simd, 0.5), z);
    // sin(r + r_lo) ≈ (r + r³P) + r_lo·(1 − z/2): r + r³P in one rounding (as the small path
    // without r_lo), then the correction of r_lo (≤ 1 ulp of sin in all).
    let lo = fma(simd, neg(simd, hz), r_lo, r_lo);
    let sin_r = simd.add_f64s(fma(simd, simd.mul_f64s(r, z), p, r), lo);
    // cos(r + r_lo) ≈ w + (((1 − w) − z/2) + (z²Q − r·r_lo)), w = 1 − z/2; cos − 1 as
    // z²Q − (r·r_lo + z/2), one rounding after the product (for r_lo = 0: z²Q − z/2).
    let one = splat(simd, 1.0);
    let w = simd.sub_f64s(one, hz);
    let r_rlo = simd.mul_f64s(r, r_lo);
    let tail = fma(simd, z2, q, neg(simd, r_rlo));
    let cos_corr = simd.add_f64s(simd.sub_f64s(simd.sub_f64s(one, w), hz), tail);
    let cos_r = simd.add_f64s(w, cos_corr);
    let cosm1 = fma(simd, z2, q, neg(simd, simd.add_f64s(r_rlo, hz)));
    (sin_r, cos_r, cosm1)
}

/// The largest |x| for which k = round(2x/π) is 0 whatever the rounding of 2x/π
/// (0.78·2/π < 0.4966 < ½): there the reduction is the identity.
pub const SMALL_MAX: f64 = 0.78;

/// [`sin_cos_fast`] for lanes that all have |x| ≤ [`SMALL_MAX`] (k = 0): the same bits, without
/// the reduction, the quadrant and the slow-lane mask. For k = 0 the reduction computes
/// r = x + (+0) and r_lo = +0 exactly (x − 0·C₁ = x, the two-sum error and k·C₃ are +0), and
/// the quadrant leaves the pair as it is, so the operations below are the same ones.
#[inline(always)]
pub fn sin_cos_small<S: Simd>(simd: S, x: S::f64s) -> (S::f64s, S::f64s) {
    let zero = simd.splat_f64s(0.0);
    let (s, c, _) = sin_cos_reduced(simd, simd.add_f64s(x, zero), zero);
    (s, c)
}

/// [`sin_cosm1_fast`] for lanes that all have |x| ≤ [`SMALL_MAX`]: the same bits (as
/// [`sin_cos_small`]), without the reduction and the terms of r_lo = +0. The reduction gives
/// r = x + (+0) (x but for the sign of a zero, which z = r² and r + r³P then do not show) and
/// r_lo = +0, whose correction adds +0 to sin and turns −(r·r_lo + z/2) into −z/2. Three
/// operations fewer on the chain of the one-body steppers, which wait on it.
#[inline(always)]
pub fn sin_cosm1_small<S: Simd>(simd: S, x: S::f64s) -> (S::f64s, S::f64s) {
    sin_cosm1_poly(simd, x, simd.mul_f64s(x, x))
}

/// [`sin_cosm1_small`] of x given z = x².
#[inline(always)]
fn sin_cosm1_poly<S: Simd>(simd: S, x: S::f64s, z: S::f64s) -> (S::f64s, S::f64s) {
    let (p, q, z2) = taylor_pq(simd, z);
    let minus_hz = simd.mul_f64s(simd.splat_f64s(-0.5), z);
    let sin = fma(simd, simd.mul_f64s(x, z), p, x);
    (sin, fma(simd, z2, q, minus_hz))
}

/// (sin x, cos x − 1) of the rotation angles of a step: [`sin_cosm1_small`] when every lane
/// has x² ≤ [`SMALL_MAX`]² (the usual step: the test reuses the square the polynomials take,
/// one comparison; x² ≤ fl(0.78²) bounds |x| by 0.78 + 1e-16, far inside the range where the
/// reduction is the identity), else [`sin_cosm1_lanes`]: the same bits either way.
#[inline(always)]
pub fn sin_cosm1_step<S: Simd>(simd: S, x: S::f64s) -> (S::f64s, S::f64s) {
    let z = simd.mul_f64s(x, x);
    let small = simd.less_than_or_equal_f64s(z, simd.splat_f64s(SMALL_MAX * SMALL_MAX));
    if simd.first_true_m64s(simd.not_m64s(small)) >= S::F64_LANES {
        sin_cosm1_poly(simd, x, z)
    } else {
        sin_cosm1_lanes(simd, x)
    }
}

/// Whether every lane of `x` has |x| ≤ [`SMALL_MAX`] (so [`sin_cos_small`] applies; false for
/// NaN lanes).
#[inline(always)]
pub fn all_small<S: Simd>(simd: S, x: S::f64s) -> bool {
    let big =
        simd.not_m64s(simd.less_than_or_equal_f64s(simd.abs_f64s(x), simd.splat_f64s(SMALL_MAX)));
    simd.first_true_m64s(big) >= S::F64_LANES
}

/// The slow path of one lane: the platform's `sin_cos` (exact argument reduction) for
/// |x| ≤ [`crate::numerics::angle::EXP_MAX_NORM`], NaN beyond it and for a non-finite x (the rule of
/// [`crate::numerics::angle::angle_sin_cos`]).
#[cold]
#[inline(never)]
pub fn slow_sin_cos(x: f64) -> (f64, f64) {
    crate::numerics::angle::angle_sin_cos(x)
}

/// The slow path of [`sin_cosm1_lanes`] for one lane: sin x and cos x − 1 = −2 sin²(x/2) by the
/// platform's `sin` (exact argument reductions; no cancellation near multiples of 2π), NaN where
/// [`slow_sin_cos`] is.
#[cold]
#[inline(never)]
pub fn slow_sin_cosm1(x: f64) -> (f64, f64) {
    let (s, _) = crate::numerics::angle::angle_sin_cos(x);
    if s.is_nan() {
        return (f64::NAN, f64::NAN);
    }
    let h = (0.5 * x).sin();
    (s, -2.0 * (h * h))
}

/// (sin θ, cos θ) of the rotation angles θ in every lane (module docs): the fast path, and the
/// slow path for the lanes that need it, each lane independent of the others.
#[inline(always)]
pub fn sin_cos_lanes<S: Simd>(simd: S, x: S::f64s) -> (S::f64s, S::f64s) {
    let (mut s, mut c, slow) = sin_cos_fast(simd, x);
    if simd.first_true_m64s(slow) < S::F64_LANES {
        fix_slow(simd, x, slow, [&mut s, &mut c], slow_sin_cos);
    }
    (s, c)
}

/// (sin θ, cos θ − 1) of the rotation angles θ in every lane: [`sin_cosm1_fast`], and
/// [`slow_sin_cosm1`] for the lanes that need it. The form of the rotation flows: a rotation
/// applied as v + ((cos θ − 1)v + sin θ·Jv) is orthogonal to O(θ²ε) where (cos θ, sin θ) rounded
/// is off by up to ε (module docs, "Rotations").
#[inline(always)]
pub fn sin_cosm1_lanes<S: Simd>(simd: S, x: S::f64s) -> (S::f64s, S::f64s) {
    let (mut s, mut cm1, slow) = sin_cosm1_fast(simd, x);
    if simd.first_true_m64s(slow) < S::F64_LANES {
        fix_slow(simd, x, slow, [&mut s, &mut cm1], slow_sin_cosm1);
    }
    (s, cm1)
}

/// Overwrites the lanes of `slow` with `f`.
#[cold]
#[inline(never)]
fn fix_slow<S: Simd>(
    simd: S,
    x: S::f64s,
    slow: S::m64s,
    [s, c]: [&mut S::f64s; 2],
    f: fn(f64) -> (f64, f64),
) {
    let slow = simd.select_u64s(slow, simd.splat_u64s(1), simd.splat_u64s(0));
    let flags: &[u64] = pulp::bytemuck::cast_slice(std::slice::from_ref(&slow));
    let xs: &[f64] = pulp::bytemuck::cast_slice(std::slice::from_ref(&x));
    let ss: &mut [f64] = pulp::bytemuck::cast_slice_mut(std::slice::from_mut(s));
    let cs: &mut [f64] = pulp::bytemuck::cast_slice_mut(std::slice::from_mut(c));
    for (i, &flag) in flags.iter().enumerate() {
        if flag != 0 {
            (ss[i], cs[i]) = f(xs[i]);
        }
    }
}

/// (sin θ, cos θ) of a rotation angle: one lane of [`sin_cos_lanes`], bit for bit what every
/// lane of a batch computes for the same θ (for |θ| ≤ [`SMALL_MAX`], the usual angle of a
/// step, by [`sin_cos_small`]: the same bits without the reduction). NaN beyond
/// [`crate::numerics::angle::EXP_MAX_NORM`] and for a non-finite θ. Dispatched, so that its fused
/// multiply-adds are the hardware's where the machine has them.
#[inline]
pub fn lane_sin_cos(theta: f64) -> (f64, f64) {
    pulp::Arch::new().dispatch(|| {
        let s = pulp::Scalar::new();
        if all_small(s, theta) {
            sin_cos_small(s, theta)
        } else {
            sin_cos_lanes(s, theta)
        }
    })
}

/// (sin θ, cos θ − 1) of a rotation angle: one lane of [`sin_cosm1_lanes`], bit for bit (as
/// [`lane_sin_cos`]).
#[inline]
pub fn angle_sin_cosm1(theta: f64) -> (f64, f64) {
    pulp::Arch::new().dispatch(|| {
        let s = pulp::Scalar::new();
        if all_small(s, theta) {
            sin_cosm1_small(s, theta)
        } else {
            sin_cosm1_lanes(s, theta)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// |a − b| in units of the spacing of doubles at b (±0 equal; NaN against NaN is 0).
    fn ulps(a: f64, b: f64) -> f64 {
        if a.is_nan() && b.is_nan() {
            return 0.0;
        }
        if a == b {
            return 0.0;
        }
        let e = b.abs().max(f64::MIN_POSITIVE);
        let ulp = f64::from_bits(e.to_bits() + 1) - e;
        (a - b).abs() / ulp
    }

    fn check(x: f64) -> f64 {
        let (s, c) = lane_sin_cos(x);
        let (s0, c0) = crate::numerics::angle::angle_sin_cos(x);
        let u = ulps(s, s0).max(ulps(c, c0));
        assert!(
            u <= 2.0,
            "x = {x:e}: ({s:e}, {c:e}) vs libm ({s0:e}, {c0:e}): {u} ulp"
        );
        u
    }

    /// A deterministic sample (SplitMix64) of angles: uniform on [−4π, 4π], log-uniform
    /// magnitudes from 2⁻⁶⁰ to FAST_MAX·4, and doubles next to multiples of π/2.
    fn sample(n: usize) -> Vec<f64> {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let unit = |v: u64| (v >> 11) as f64 / (1u64 << 53) as f64;
        let mut out = Vec::with_capacity(3 * n);
        for _ in 0..n {
            let sign = if next() & 1 == 0 { 1.0 } else { -1.0 };
            out.push(sign * 4.0 * std::f64::consts::PI * unit(next()));
            let e = -60.0 + unit(next()) * (60.0 + (FAST_MAX * 4.0).log2());
            out.push(sign * e.exp2());
            let k = (next() % 2_000_000) as f64 - 1_000_000.0;
            let base = k * std::f64::consts::FRAC_PI_2;
            let step = (next() % 64) as i64 - 32;
            let bits = (base.to_bits() as i64 + step) as u64;
            out.push(f64::from_bits(bits));
        }
        out
    }

    #[test]
    fn within_two_ulp_of_libm_on_a_large_sample() {
        let n = if cfg!(debug_assertions) {
            30_000
        } else {
            1_000_000
        };
        let worst = sample(n).into_iter().map(check).fold(0.0, f64::max);
        println!("worst error against libm: {worst} ulp");
        assert!(worst <= 2.0, "worst {worst} ulp");
    }

    #[test]
    fn special_angles() {
        for x in [
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            5e-324,
            1e-300,
            1e-8,
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI,
            1.5 * std::f64::consts::PI,
            FAST_MAX,
            FAST_MAX * 1.000_001,
            1e10,
            crate::numerics::angle::EXP_MAX_NORM,
            6381956970095103.0 * 2f64.powi(-5),
        ] {
            check(x);
            check(-x);
        }
        let nan = |(s, c): (f64, f64)| s.is_nan() && c.is_nan();
        assert!(nan(lane_sin_cos(f64::NAN)));
        assert!(nan(lane_sin_cos(f64::INFINITY)));
        assert!(nan(lane_sin_cos(-f64::INFINITY)));
        assert!(nan(lane_sin_cos(
            crate::numerics::angle::EXP_MAX_NORM * 2.0
        )));
    }

    /// Every lane of the dispatched SIMD kernel gives the bits of the scalar kernel, whatever
    /// its neighbours (slow lanes included).
    #[test]
    fn lanes_match_the_scalar_kernel_bit_for_bit() {
        struct Run<'a>(&'a [f64], &'a mut Vec<(f64, f64)>);
        impl pulp::WithSimd for Run<'_> {
            type Output = ();
            fn with_simd<S: Simd>(self, simd: S) {
                for chunk in self.0.chunks(S::F64_LANES) {
                    let x = simd.partial_load_f64s(chunk);
                    let (s, c) = sin_cos_lanes(simd, x);
                    let mut sv = vec![0.0; S::F64_LANES];
                    let mut cv = vec![0.0; S::F64_LANES];
                    simd.partial_store_f64s(&mut sv, s);
                    simd.partial_store_f64s(&mut cv, c);
                    self.1.extend(sv.into_iter().zip(cv).take(chunk.len()));
                }
            }
        }
        let mut xs = sample(2000);
        xs.extend([f64::NAN, 1e12, -3e300, 0.0, FAST_MAX * 2.0, 1e-310]);
        let mut got = Vec::new();
        pulp::Arch::new().dispatch(Run(&xs, &mut got));
        for (x, (s, c)) in xs.iter().zip(got) {
            let (s0, c0) = lane_sin_cos(*x);
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                (s0.to_bits(), c0.to_bits()),
                "x = {x:e}"
            );
        }
    }

    #[test]
    fn reduction_constants() {
        assert_eq!(C1.to_bits(), 0x3FF9_21FB_5440_0000);
        assert_eq!(C2.to_bits(), 0x3DD0_B461_1A60_0000);
        assert_eq!(C3.to_bits(), 0x3BA3_198A_2E03_7073);
        // C₁ and C₂ carry 33 significant bits: k·C₁, k·C₂ are exact for |k| ≤ 2¹⁹.
        assert_eq!(C1.to_bits() & 0xF_FFFF, 0);
        assert_eq!(C2.to_bits() & 0xF_FFFF, 0);
        // C₁ + C₂ + C₃ is π/2 to far beyond double precision.
        assert_eq!(C1 + (C2 + C3), std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn the_small_path_gives_the_bits_of_the_full_path() {
        let simd = pulp::Scalar::new();
        let mut xs: Vec<f64> = sample(20_000)
            .into_iter()
            .filter(|x| x.abs() <= SMALL_MAX)
            .collect();
        xs.extend([0.0, -0.0, SMALL_MAX, -SMALL_MAX, 5e-324, -5e-324, 1e-200]);
        for x in xs {
            let (s, c, slow) = sin_cos_fast(simd, x);
            assert!(!slow);
            let (s1, c1) = sin_cos_small(simd, x);
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                (s1.to_bits(), c1.to_bits()),
                "x = {x:e}"
            );
        }
    }

    /// a·b exactly, as a pair (the test's reference arithmetic: `mul_add` is the correctly
    /// rounded fused multiply-add of the platform or of libm).
    fn two_prod(a: f64, b: f64) -> (f64, f64) {
        let p = a * b;
        (p, a.mul_add(b, -p))
    }

    /// cos x − 1 = −2 sin²(x/2) from the platform's `sin` (exact reduction), squared exactly.
    fn cosm1_reference(x: f64) -> f64 {
        let (p, e) = two_prod((0.5 * x).sin(), (0.5 * x).sin());
        -2.0 * (p + e)
    }

    /// (sin x, cos x − 1): sin the bits of [`lane_sin_cos`], cos x − 1 within 5 ulp of itself
    /// (4 ulp of the reference's rounding, and cos x − 1 = c − 1 off the first quadrant).
    fn check_cosm1(x: f64) -> f64 {
        let (s, cm1) = angle_sin_cosm1(x);
        let (s0, _) = lane_sin_cos(x);
        assert_eq!(s.to_bits(), s0.to_bits(), "x = {x:e}");
        let want = cosm1_reference(x);
        // Below the normal range cos x − 1 = −x²/2 underflows: absolute comparison there.
        let u = if want.abs() < 1e-290 {
            if (cm1 - want).abs() <= 1e-300 {
                0.0
            } else {
                f64::INFINITY
            }
        } else {
            ulps(cm1, want)
        };
        assert!(
            u <= 5.0,
            "x = {x:e}: cos x − 1 = {cm1:e}, want {want:e}: {u} ulp"
        );
        u
    }

    #[test]
    fn cosm1_within_five_ulp_on_a_large_sample() {
        let n = if cfg!(debug_assertions) {
            20_000
        } else {
            300_000
        };
        let worst = sample(n).into_iter().map(check_cosm1).fold(0.0, f64::max);
        println!("worst error of cos x − 1: {worst} ulp");
        for x in [
            0.0,
            -0.0,
            1e-8,
            1e-150,
            SMALL_MAX,
            2.0 * std::f64::consts::PI,
            FAST_MAX * 2.0,
        ] {
            check_cosm1(x);
            check_cosm1(-x);
        }
        let nan = |(s, c): (f64, f64)| s.is_nan() && c.is_nan();
        assert!(nan(angle_sin_cosm1(f64::NAN)));
        assert!(nan(angle_sin_cosm1(f64::INFINITY)));
        assert!(nan(angle_sin_cosm1(
            crate::numerics::angle::EXP_MAX_NORM * 2.0
        )));
    }

    /// The rotation (1 + (c − 1), s) is orthogonal to O(θ²ε): (1 + m)² + s² − 1 = 2m + m² + s²
    /// evaluated exactly is below 2θ²ε at the angles of a step, where (c, s) rounded is off by up
    /// to an ulp of 1 at any angle (the bias that made the Casimirs of symmetric bodies drift).
    #[test]
    fn the_rotation_is_orthogonal_to_second_order_in_the_angle() {
        let mut worst = 0.0f64;
        let mut worst_cs = 0.0f64;
        for x in sample(20_000).into_iter().filter(|x| x.abs() <= SMALL_MAX) {
            let (s, m) = angle_sin_cosm1(x);
            let (s2, s2e) = two_prod(s, s);
            let (m2, m2e) = two_prod(m, m);
            let defect = ((2.0 * m + s2) + m2) + (s2e + m2e);
            if x != 0.0 {
                worst = worst.max(defect.abs() / (x * x * f64::EPSILON));
            }
            let (s, c) = lane_sin_cos(x);
            let (c2, c2e) = two_prod(c, c);
            let (s2, s2e) = two_prod(s, s);
            worst_cs = worst_cs.max((((c2 - 1.0) + s2) + (c2e + s2e)).abs() / f64::EPSILON);
        }
        println!("(1 + m)² + s² − 1 ≤ {worst:.3} θ²ε; c² + s² − 1 up to {worst_cs:.3} ε");
        assert!(worst <= 2.0, "{worst} θ²ε");
    }

    /// The lanes of [`sin_cosm1_lanes`] give the bits of the scalar kernel, and the small path
    /// the bits of the full one.
    #[test]
    fn cosm1_lanes_and_small_path_match_the_scalar_kernel_bit_for_bit() {
        struct Run<'a>(&'a [f64], &'a mut Vec<(f64, f64)>);
        impl pulp::WithSimd for Run<'_> {
            type Output = ();
            fn with_simd<S: Simd>(self, simd: S) {
                for chunk in self.0.chunks(S::F64_LANES) {
                    let x = simd.partial_load_f64s(chunk);
                    let (s, c) = sin_cosm1_lanes(simd, x);
                    let mut sv = vec![0.0; S::F64_LANES];
                    let mut cv = vec![0.0; S::F64_LANES];
                    simd.partial_store_f64s(&mut sv, s);
                    simd.partial_store_f64s(&mut cv, c);
                    self.1.extend(sv.into_iter().zip(cv).take(chunk.len()));
                }
            }
        }
        let mut xs = sample(2000);
        xs.extend([f64::NAN, 1e12, -3e300, 0.0, FAST_MAX * 2.0, 1e-310]);
        let mut got = Vec::new();
        pulp::Arch::new().dispatch(Run(&xs, &mut got));
        let bits = |(a, b): (f64, f64)| (a.to_bits(), b.to_bits());
        for (x, sc) in xs.iter().zip(got) {
            assert_eq!(bits(sc), bits(angle_sin_cosm1(*x)), "x = {x:e}");
            // Outside a dispatch the fused multiply-adds are libm's `fma`: the same bits.
            let outside = sin_cosm1_lanes(pulp::Scalar::new(), *x);
            assert_eq!(bits(sc), bits(outside), "x = {x:e}");
        }
        let simd = pulp::Scalar::new();
        let mut xs: Vec<f64> = sample(20_000)
            .into_iter()
            .filter(|x| x.abs() <= SMALL_MAX)
            .collect();
        xs.extend([
            0.0, -0.0, SMALL_MAX, -SMALL_MAX, 5e-324, -5e-324, 1e-200, -1e-160,
        ]);
        for x in xs {
            let (s, c, slow) = sin_cosm1_fast(simd, x);
            assert!(!slow);
            assert_eq!(bits((s, c)), bits(sin_cosm1_small(simd, x)), "x = {x:e}");
        }
    }

    proptest! {
        #[test]
        fn within_two_ulp_anywhere_in_the_fast_range(x in -FAST_MAX..FAST_MAX) {
            check(x);
        }

        #[test]
        fn within_two_ulp_for_small_angles(e in -80.0f64..1.0, negative: bool) {
            let x = e.exp2();
            check(if negative { -x } else { x });
        }

        #[test]
        fn pythagoras_to_round_off(x in -100.0f64..100.0) {
            let (s, c) = lane_sin_cos(x);
            prop_assert!((s * s + c * c - 1.0).abs() <= 4.0 * f64::EPSILON);
        }
    }
}
