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

use crate::error::{Error, Result};

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
    pub fn sequence(&self, n_flows: usize) -> Vec<(usize, f64)> {
        assert!(n_flows >= 1, "a splitting needs at least one flow");
        let mut seq: Vec<(usize, f64)> = Vec::new();
        for &g in &self.gammas {
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
