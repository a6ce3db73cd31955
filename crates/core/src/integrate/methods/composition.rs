//! Symmetric compositions of a symmetric second-order step, and the flattened flow sequences of
//! splitting methods.
//!
//! One piece of code serves every splitting and every composed method of lieflow. A Hamiltonian H = H₁ + … + H_n whose
//! pieces have exact flows φ_i (rotations about body axes, momentum kicks, …) gets the palindromic
//! Strang step S_h = φ₁(h/2)…φ_{n−1}(h/2) φ_n(h) φ_{n−1}(h/2)…φ₁(h/2), second order and symmetric
//! (S_h⁻¹ = S_{−h}); the composition S_{γ_s h}…S_{γ₁ h} with palindromic weights γ lifts it to
//! order 4 or 6 (Yoshida 1990, "Construction of higher order symplectic integrators", Phys. Lett.
//! A 150; Suzuki 1990, Phys. Lett. A 146; Hairer, Lubich & Wanner, *Geometric Numerical
//! Integration*, §II.4 and §V.3). Each φ_i is the exact flow of a Hamiltonian, so the method is a
//! Poisson map that keeps every Casimir of the bracket.
//!
//! [`Composition::sequence`] flattens the composition into the list of sub-flows with their
//! fractions of h, merging adjacent occurrences of the same exact flow (φ(a)φ(b) = φ(a + b));
//! [`run_sequence`] also merges the first and last flow of consecutive steps ("first same as
//! last"), so the Strang step of an n-flow splitting costs 2n − 2 flow evaluations.
//! [`Composition::compose`] composes any symmetric base step (not necessarily a flow), e.g. an
//! implicit or Störmer–Verlet step.

#![allow(clippy::excessive_precision)] // the coefficients with the digits they are published with

use crate::error::{Error, Result};

/// A flattened sequence of exact flows: (flow index, fraction of h), in the order applied.
pub type Sequence = Vec<(usize, f64)>;

/// Weights of a symmetric composition of a symmetric second-order method.
#[derive(Clone, Debug, PartialEq)]
pub struct Composition {
    gammas: Vec<f64>,
    order: u32,
}

impl Composition {
    /// The base method itself: Strang splitting, order 2.
    pub fn strang() -> Self {
        Composition {
            gammas: vec![1.0],
            order: 2,
        }
    }

    /// Yoshida's / Suzuki's "triple jump" γ = (w₁, w₀, w₁), w₁ = 1/(2 − 2^{1/3}),
    /// w₀ = 1 − 2w₁: order 4 with 3 stages (Yoshida 1990 eq. (4.10)).
    pub fn triple_jump4() -> Self {
        let w1 = 1.0 / (2.0 - 2f64.cbrt());
        Composition {
            gammas: vec![w1, 1.0 - 2.0 * w1, w1],
            order: 4,
        }
    }

    /// Suzuki's 5-stage fractal γ = (p, p, 1 − 4p, p, p), p = 1/(4 − 4^{1/3}) (Suzuki 1990):
    /// order 4 with a much smaller error constant than the triple jump (HLW §V.3.2).
    pub fn suzuki4() -> Self {
        let p = 1.0 / (4.0 - 4f64.cbrt());
        Composition {
            gammas: vec![p, p, 1.0 - 4.0 * p, p, p],
            order: 4,
        }
    }

    /// Yoshida's 7-stage sixth-order composition, "solution A" (Yoshida 1990, Table 1):
    /// γ = (w₃, w₂, w₁, w₀, w₁, w₂, w₃), w₀ = 1 − 2(w₁ + w₂ + w₃).
    pub fn yoshida6() -> Self {
        let (w1, w2, w3) = (
            -1.177_679_984_178_87,
            0.235_573_213_359_357,
            0.784_513_610_477_56,
        );
        let w0 = 1.0 - 2.0 * (w1 + w2 + w3);
        Composition {
            gammas: vec![w3, w2, w1, w0, w1, w2, w3],
            order: 6,
        }
    }

    /// Kahan & Li's 9-stage sixth-order composition s9odr6a (W. Kahan & R.-C. Li, "Composition
    /// constants for raising the orders of unconventional schemes for ordinary differential
    /// equations", Math. Comp. 66 (1997); HLW §V.3.2 (3.12)): two stages more than
    /// [`Composition::yoshida6`] and, on the free rigid body, an error 6.7 times smaller at the
    /// same step (`tests/integrators.rs`; at order 6 that is 1.5 times at the same cost).
    pub fn kahan_li6() -> Self {
        Composition::palindrome(
            &[
                0.392_161_444_007_314_139_28,
                0.332_599_136_789_359_438_60,
                -0.706_246_172_557_639_359_81,
                0.082_213_596_293_550_800_23,
            ],
            6,
        )
    }

    /// Kahan & Li's 15-stage eighth-order composition s15odr8 (Kahan & Li 1997; HLW §V.3.2
    /// (3.13)).
    pub fn kahan_li8() -> Self {
        Composition::palindrome(
            &[
                0.741_670_364_350_612_953_45,
                -0.409_100_825_800_031_593_99,
                0.190_754_710_296_238_379_95,
                -0.573_862_471_116_082_266_66,
                0.299_064_181_303_655_923_84,
                0.334_624_918_245_298_183_78,
                0.315_293_092_396_766_596_63,
            ],
            8,
        )
    }

    /// The palindrome (w₁, …, w_k, w₀, w_k, …, w₁) with the middle weight w₀ = 1 − 2Σw_i
    /// (computed, so the weights sum to 1 to round-off).
    fn palindrome(outer: &[f64], order: u32) -> Self {
        let middle = 1.0 - 2.0 * outer.iter().sum::<f64>();
        let mut gammas = outer.to_vec();
        gammas.push(middle);
        gammas.extend(outer.iter().rev());
        Composition { gammas, order }
    }

    /// A composition with user weights γ and the order the user claims for it. The weights must
    /// be finite, sum to 1 (to 1e-12) and be palindromic (γ_i = γ_{s+1−i}, so the composition of
    /// a symmetric step is symmetric, and its order even); the claim is the user's (the generic
    /// order tests measure it).
    pub fn new(gammas: Vec<f64>, order: u32) -> Result<Self> {
        let bad = |m: String| Err(Error::invalid("composition", m));
        if gammas.is_empty() || gammas.iter().any(|g| !g.is_finite()) {
            return bad(format!("expected finite weights, got {gammas:?}"));
        }
        let sum: f64 = gammas.iter().sum();
        if (sum - 1.0).abs() > 1e-12 {
            return bad(format!("the weights must sum to 1, got {sum}"));
        }
        if gammas
            .iter()
            .zip(gammas.iter().rev())
            .any(|(a, b)| (a - b).abs() > 1e-14)
        {
            return bad(format!("the weights must be palindromic, got {gammas:?}"));
        }
        if order < 2 || order % 2 == 1 {
            return bad(format!(
                "the order of a symmetric composition is even ≥ 2, got {order}"
            ));
        }
        Ok(Composition { gammas, order })
    }

    /// The weights γ (they sum to 1).
    pub fn gammas(&self) -> &[f64] {
        &self.gammas
    }

    /// The order of the composed method.
    pub fn order(&self) -> u32 {
        self.order
    }

    /// Applies one composed step of size h: `base(γ_i h, state)` for every weight.
    pub fn compose<T: ?Sized>(&self, h: f64, state: &mut T, mut base: impl FnMut(f64, &mut T)) {
        for &g in &self.gammas {
            base(g * h, state);
        }
    }

    /// The composed step of the palindromic Strang splitting of `n_flows` exact flows, flattened:
    /// a list of (flow index, fraction of h). Flow 0 is the outermost, flow n−1 the middle one.
    /// Adjacent occurrences of flow 0 between stages are merged. The list is palindromic, starts
    /// and ends with flow 0.
    pub fn sequence(&self, n_flows: usize) -> Sequence {
        flatten(&self.gammas, n_flows)
    }
}

/// The Strang steps S_{w₁h}, …, S_{w_s h} (in this order) of an `n_flows`-flow splitting as one
/// list of (flow index, fraction of h), adjacent occurrences of flow 0 merged.
fn flatten(weights: &[f64], n_flows: usize) -> Sequence {
    assert!(n_flows >= 1, "a splitting needs at least one flow");
    let mut seq = Sequence::new();
    for &g in weights {
        let mut stage: Vec<(usize, f64)> = (0..n_flows - 1).map(|i| (i, 0.5 * g)).collect();
        stage.push((n_flows - 1, g));
        stage.extend((0..n_flows - 1).rev().map(|i| (i, 0.5 * g)));
        for (i, c) in stage {
            match seq.last_mut() {
                Some(last) if last.0 == i => last.1 += c,
                _ => seq.push((i, c)),
            }
        }
    }
    seq
}

/// A processed composition ψ_h = P⁻¹ ∘ K_h ∘ P: the kernel K_h, a symmetric [`Composition`] of
/// the symmetric step S, runs every step; the processor P = S_{p_m h} ∘ … ∘ S_{p₁ h} (weights
/// summing to 0, so P = id + O(h³)) is applied once when a state is set, its inverse
/// P⁻¹ = S_{−p₁ h} ∘ … ∘ S_{−p_m h} once per state read. N steps cost N kernels and one
/// processor pair, and ψ_h^N = P⁻¹ K_h^N P has the *effective* order of the pair, higher than
/// the kernel's own: the kernel only has to satisfy the conditions a conjugation cannot remove
/// (J. C. Butcher's effective order; S. Blanes, F. Casas & A. Murua, "Composition methods for
/// differential equations with processing", SIAM J. Sci. Comput. 27 (2006) 1817, cited BCM06).
/// With a Poisson S the processed map is Poisson too (a conjugate of one by another).
#[derive(Clone, Debug, PartialEq)]
pub struct Processed {
    kernel: Composition,
    processor: Vec<f64>,
    order: u32,
}

impl Processed {
    /// Effective order 6 with an 11-stage kernel and a 12-stage processor (BCM06; weights as
    /// tabulated by Blanes, Casas & Murua, "Splitting methods for differential equations", Acta
    /// Numerica 2024, arXiv:2401.01722, Table 8.1). On the free rigid body over T = 10, at the same
    /// number of Strang stages, its error is 70 times smaller than [`Composition::yoshida6`]'s
    /// (about 2× fewer stages for the same error at order 6; `tests/integrators.rs`).
    pub fn bcm6() -> Self {
        let (a1, a5) = (0.170_576_886_500_922_215_7, -0.423_366_140_892_658_048);
        Processed::antisymmetric(
            Composition::palindrome(&[a1, a1, a1, a1, a5], 4),
            6,
            &[
                -0.206_219_531_391_26,
                0.236_513_874_832_03,
                0.090_869_822_762_41,
                0.246_873_069_776_59,
                -0.1,
            ],
        )
    }

    /// Effective order 8 with a 13-stage kernel and a 20-stage processor (BCM06).
    pub fn bcm8() -> Self {
        let outer = [
            0.168,
            0.168,
            0.585_550_530_805_562,
            -0.460_090_457_516_872,
            0.172_863_148_729_731,
            0.179_664_539_695_039,
        ];
        Processed::antisymmetric(
            Composition::palindrome(&outer, 4),
            8,
            &[
                -0.008_488_123_494_574_411,
                -0.337_188_967_354_338,
                0.333_987_768_164_597,
                0.588_351_189_003_849,
                0.162_324_207_599_241,
                -0.511_744_926_116_413,
                0.236_885_952_363_384,
                0.598_212_975_943_381,
                -0.543_415_765_371_656,
            ],
        )
    }

    /// Effective order 10 with a 23-stage kernel and a 24-stage processor (BCM06).
    pub fn bcm10() -> Self {
        let a1 = 0.121_657_748_919_383;
        let outer = [
            a1,
            a1,
            a1,
            a1,
            a1,
            -0.511_318_780_154_828,
            -0.172_858_614_884_985,
            0.123_016_258_833_066,
            0.441_503_951_671_565,
            -0.327_071_324_165_477,
            0.070_952_700_957_766,
        ];
        Processed::antisymmetric(
            Composition::palindrome(&outer, 4),
            10,
            &[
                0.472_714_208_057_822_1,
                0.013_447_506_131_911_08,
                -0.463_710_471_298_707_8,
                -0.304_559_092_256_524_7,
                -0.538_294_582_183_432,
                -0.189_979_553_319_973_2,
                0.154_825_647_255_348_9,
                -0.359_414_803_315_607_2,
                0.343_034_566_967_739_2,
                0.533_403_028_369_592_2,
                0.009_116_042_043_427_756,
            ],
        )
    }

    /// The processor of weights (−g₀, −g₁, …, −g_k, g₀, …, g_k) with g₀ = −Σ_{i≥1} g_i, for the
    /// tabulated g₁ … g_k: the form (and sign) in which BCM06's processors are listed.
    fn antisymmetric(kernel: Composition, order: u32, g: &[f64]) -> Self {
        let mut half = vec![-g.iter().sum::<f64>()];
        half.extend_from_slice(g);
        let mut processor: Vec<f64> = half.iter().map(|x| -x).collect();
        processor.extend_from_slice(&half);
        Processed {
            kernel,
            processor,
            order,
        }
    }

    /// A processed composition with the user's kernel, processor weights p₁, …, p_m (applied in
    /// this order; finite, summing to 0 to 1e-12) and the effective order the user claims for
    /// the pair (even, at least the kernel's order; the generic order tests measure it).
    pub fn new(kernel: Composition, processor: Vec<f64>, order: u32) -> Result<Self> {
        let sum: f64 = processor.iter().sum();
        if processor.iter().any(|p| !p.is_finite()) || sum.abs() > 1e-12 {
            return Err(Error::invalid(
                "processor",
                format!("expected finite weights summing to 0, got {processor:?} (sum {sum})"),
            ));
        }
        if order % 2 == 1 || order < kernel.order {
            return Err(Error::invalid(
                "processed composition",
                format!(
                    "the effective order is even and at least the kernel's {}, got {order}",
                    kernel.order
                ),
            ));
        }
        Ok(Processed {
            kernel,
            processor,
            order,
        })
    }

    /// The kernel (a symmetric composition of order 4 for the built-in pairs).
    pub fn kernel(&self) -> &Composition {
        &self.kernel
    }

    /// The processor weights p₁, …, p_m.
    pub fn processor(&self) -> &[f64] {
        &self.processor
    }

    /// The effective order of ψ_h.
    pub fn order(&self) -> u32 {
        self.order
    }

    /// The processor P and its inverse P⁻¹ of an `n_flows`-flow splitting as flattened lists of
    /// (flow index, fraction of h), like [`Composition::sequence`]: P = flatten(p), and P⁻¹ the
    /// same flows in reverse order with negated times (φ_i(τ)⁻¹ = φ_i(−τ)).
    pub fn sequences(&self, n_flows: usize) -> (Sequence, Sequence) {
        let p = flatten(&self.processor, n_flows);
        let inverse = p.iter().rev().map(|&(i, c)| (i, -c)).collect();
        (p, inverse)
    }
}

/// Runs `steps` composed steps of size `h` given by a flattened `seq` (from
/// [`Composition::sequence`]), calling `flow(i, τ, state)` for the exact flow i over time τ.
/// The last flow of a step and the first of the next are merged (they are the same exact flow).
pub fn run_sequence<T: ?Sized>(
    seq: &[(usize, f64)],
    h: f64,
    steps: usize,
    state: &mut T,
    mut flow: impl FnMut(usize, f64, &mut T),
) {
    let m = seq.len();
    if m == 1 {
        flow(seq[0].0, seq[0].1 * h * steps as f64, state);
        return;
    }
    let (first, c0) = seq[0];
    let cm = seq[m - 1].1;
    flow(first, c0 * h, state);
    for step in 0..steps {
        for &(i, c) in &seq[1..m - 1] {
            flow(i, c * h, state);
        }
        let c = if step + 1 < steps { cm + c0 } else { cm };
        flow(first, c * h, state);
    }
}
