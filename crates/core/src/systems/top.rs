//! Shared machinery of the bodies on SO(3): principal frames, the exact sub-flows of the
//! Lie–Poisson splitting, and the Euler(–Poisson) vector field for the RK4 baseline.
//!
//! **Splitting** (McLachlan, "Explicit Lie–Poisson integration and the Euler equations", Phys.
//! Rev. Lett. 71 (1993); Touma & Wisdom, "Lie–Poisson integrators for rigid body dynamics in the
//! solar system", Astron. J. 107 (1994); Dullweber, Leimkuhler & McLachlan, J. Chem. Phys. 107
//! (1997)). With I_r the middle principal moment,
//!
//! T = ½ Σ M_i²/I_i = ½|M|²/I_r + ½ a_p M_p² + ½ a_q M_q²,   a_i = 1/I_i − 1/I_r,
//!
//! where {p, q, r} = {1, 2, 3}. Each piece has an exact flow:
//! * ½ a_k M_k²: Ṁ = M × (a_k M_k e_k), a rotation of M (and of Γ, Γ̇ = Γ × Ω) about e_k by the
//!   angle −a_k M_k t (M_k is constant along it), and R ↦ R exp(t a_k M_k ê_k);
//! * ½|M|²/I_r: M is fixed (|M|² is a Casimir of so(3)*), Γ ↦ exp(−t M̂/I_r) Γ and
//!   R ↦ R exp(t M̂/I_r); on the free body it commutes with everything and only moves R;
//! * the heavy-top potential V = Γ·c (c = mgl χ): the kick M ↦ M + t Γ × c, Γ and R fixed.
//!
//! Every sub-flow is the exact flow of a Hamiltonian on T*SO(3) (reduced: on so(3)* or se(3)*),
//! so the composed method is symplectic on T*SO(3) with R ∈ SO(3), Poisson on the reduced space,
//! and keeps |M|² (free body), |Γ|² and M·Γ (heavy top) to round-off, and R M (free body). For the
//! Lagrange top (I₁ = I₂, χ = e₃) I_r = I₁ = I₂ and every piece keeps M₃. Only two sub-flows act on
//! the free body's M (two `sin_cos` per Strang step), fewer than the three-axis splitting.

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::rk::{Rk4, VectorField};
use crate::integrate::splitting::{run_sequence, Composition};
use crate::integrate::{Method, State, Stepper};
use nalgebra::{Matrix3, Vector3};

/// Checks principal moments: finite and > 0.
pub(crate) fn check_moments(moments: &[f64; 3]) -> Result<()> {
    for (i, &m) in moments.iter().enumerate() {
        if !(m.is_finite() && m > 0.0) {
            return Err(Error::invalid(
                "inertia",
                format!(
                    "principal moment I[{i}] = {m} must be finite and > 0 (non-positive inertia)"
                ),
            ));
        }
    }
    Ok(())
}

/// Diagonalises a symmetric positive-definite inertia matrix (row-major): I = Q diag Qᵀ, Q ∈ SO(3).
pub(crate) fn principal_frame(inertia: &[f64; 9]) -> Result<([f64; 3], Matrix3<f64>)> {
    check::finite_slice("inertia", inertia)?;
    let a = Matrix3::from_row_slice(inertia);
    let asym = (a - a.transpose()).abs().max();
    if asym > 1e-12 * a.abs().max().max(f64::MIN_POSITIVE) {
        return Err(Error::invalid(
            "inertia",
            format!("the inertia matrix is not symmetric (max |I − Iᵀ| = {asym:.3e})"),
        ));
    }
    let eig = a.symmetric_eigen();
    let moments = [eig.eigenvalues[0], eig.eigenvalues[1], eig.eigenvalues[2]];
    if moments.iter().any(|&m| m <= 0.0) {
        return Err(Error::invalid(
            "inertia",
            format!("the inertia matrix is not positive definite (eigenvalues {moments:?})"),
        ));
    }
    let mut q = eig.eigenvectors;
    if q.determinant() < 0.0 {
        let c = -q.column(2);
        q.set_column(2, &c);
    }
    Ok((moments, q))
}

/// v ↦ Qᵀ v (user body frame → principal frame).
pub(crate) fn to_frame(frame: &Option<Matrix3<f64>>, v: &[f64]) -> Vector3<f64> {
    let v = Vector3::from_column_slice(v);
    match frame {
        Some(q) => q.transpose() * v,
        None => v,
    }
}

/// v ↦ Q v (principal frame → user body frame).
pub(crate) fn from_frame(frame: &Option<Matrix3<f64>>, v: &Vector3<f64>) -> Vector3<f64> {
    match frame {
        Some(q) => q * v,
        None => *v,
    }
}

/// Kinetic energy ½ M·I⁻¹M of a body momentum given in the user frame (000 §3–§4).
pub(crate) fn kinetic_energy(frame: &Option<Matrix3<f64>>, moments: &[f64; 3], m: &[f64]) -> f64 {
    let m = to_frame(frame, m);
    0.5 * (0..3).map(|i| m[i] * m[i] / moments[i]).sum::<f64>()
}

/// Row-major copy of a 3×3 matrix.
pub(crate) fn row_major(r: &Matrix3<f64>) -> [f64; 9] {
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = r[(i, j)];
        }
    }
    out
}

fn map_state(frame: &Option<Matrix3<f64>>, state: &mut State, inverse: bool) {
    if let Some(q) = frame {
        let qm = if inverse { *q } else { q.transpose() };
        for v in state.z.chunks_exact_mut(3) {
            let w = qm * Vector3::from_column_slice(v);
            v.copy_from_slice(w.as_slice());
        }
        if let Some(r) = state.attitude.as_mut() {
            let rm = Matrix3::from_row_slice(r);
            *r = row_major(&(rm * if inverse { q.transpose() } else { *q }));
        }
    }
}

/// Body vectors v ↦ Qᵀv, R ↦ RQ.
pub(crate) fn state_to_frame(frame: &Option<Matrix3<f64>>, state: &mut State) {
    map_state(frame, state, false);
}

/// Inverse of [`state_to_frame`].
pub(crate) fn state_from_frame(frame: &Option<Matrix3<f64>>, state: &mut State) {
    map_state(frame, state, true);
}

/// Rotates v about e_k by the angle −θ: the flow of v̇ = v × (θ/t) e_k over time t.
#[inline]
pub(crate) fn rotate_axis(v: &mut Vector3<f64>, k: usize, theta: f64) {
    let (s, c) = theta.sin_cos();
    rotate_axis_sc(v, k, s, c);
}

#[inline]
fn rotate_axis_sc(v: &mut Vector3<f64>, k: usize, s: f64, c: f64) {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let (vi, vj) = (v[i], v[j]);
    v[i] = c * vi + s * vj;
    v[j] = c * vj - s * vi;
}

/// Steps between two re-projections of an attitude onto SO(3).
pub(crate) const REORTHONORMALIZE_EVERY: usize = 256;

/// Chunk sizes ≤ [`REORTHONORMALIZE_EVERY`] summing to `steps`.
pub(crate) fn chunks(steps: usize) -> impl Iterator<Item = usize> {
    let n = REORTHONORMALIZE_EVERY;
    (0..steps.div_ceil(n)).map(move |c| n.min(steps - c * n))
}

/// One Newton step of the polar decomposition, R ↦ R(3I − RᵀR)/2: for R = Q(I + E), E symmetric,
/// the result is Q(I + O(E²)). Every attitude-carrying stepper applies it every
/// [`REORTHONORMALIZE_EVERY`] steps, a change at round-off level (‖RᵀR − I‖ ~ 1e-15) that keeps
/// the rounding errors of many products of rotations from accumulating (without it ‖RᵀR − I‖
/// reaches ~6e-12 after 10⁶ steps).
#[inline]
pub(crate) fn reorthonormalize(r: &mut Matrix3<f64>) {
    *r = *r * (Matrix3::identity() * 3.0 - r.transpose() * *r) * 0.5;
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Flow {
    /// ½ a M_k² for the a-th non-reference axis.
    Axis(usize),
    /// ½ |M|² / I_r.
    Casimir,
    /// Γ·c.
    Kick,
}

/// The Lie–Poisson splitting of a rigid body or heavy top (see the module docs).
pub(crate) struct TopSplitting {
    h: f64,
    axes: [usize; 2],
    coef: [f64; 2],
    inv_ir: f64,
    c: Option<Vector3<f64>>,
    plain: (Vec<(usize, f64)>, Vec<Flow>),
    full: (Vec<(usize, f64)>, Vec<Flow>),
}

struct Body {
    m: Vector3<f64>,
    g: Option<Vector3<f64>>,
    r: Option<Matrix3<f64>>,
}

impl TopSplitting {
    /// `moments`: principal moments; `c = mgl χ` for the heavy top (principal frame).
    pub(crate) fn new(moments: [f64; 3], c: Option<[f64; 3]>, method: Method, h: f64) -> Self {
        let comp = Composition::for_method(method).unwrap_or_else(Composition::strang);
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| moments[a].total_cmp(&moments[b]));
        let r = idx[1];
        let axes = [(r + 1) % 3, (r + 2) % 3];
        let coef = axes.map(|k| 1.0 / moments[k] - 1.0 / moments[r]);
        let with = |flows: Vec<Flow>| (comp.sequence(flows.len()), flows);
        let full = if c.is_some() {
            vec![Flow::Kick, Flow::Axis(0), Flow::Axis(1), Flow::Casimir]
        } else {
            vec![Flow::Axis(0), Flow::Axis(1), Flow::Casimir]
        };
        let plain = if c.is_some() {
            full.clone()
        } else {
            vec![Flow::Axis(0), Flow::Axis(1)]
        };
        TopSplitting {
            h,
            axes,
            coef,
            inv_ir: 1.0 / moments[r],
            c: c.map(Vector3::from),
            plain: with(plain),
            full: with(full),
        }
    }
}

impl Stepper for TopSplitting {
    fn run(&mut self, state: &mut State, steps: usize) -> Result<()> {
        let mut b = Body {
            m: Vector3::from_column_slice(&state.z[..3]),
            g: (state.z.len() == 6).then(|| Vector3::from_column_slice(&state.z[3..6])),
            r: state.attitude.map(|r| Matrix3::from_row_slice(&r)),
        };
        let (seq, flows) = if b.r.is_some() {
            (&self.full.0, &self.full.1)
        } else {
            (&self.plain.0, &self.plain.1)
        };
        let (axes, coef, inv_ir, c) = (self.axes, self.coef, self.inv_ir, self.c);
        let mut flow = |i: usize, tau: f64, b: &mut Body| match flows[i] {
            Flow::Axis(a) => {
                let k = axes[a];
                let (s, co) = (tau * coef[a] * b.m[k]).sin_cos();
                rotate_axis_sc(&mut b.m, k, s, co);
                if let Some(g) = b.g.as_mut() {
                    rotate_axis_sc(g, k, s, co);
                }
                if let Some(r) = b.r.as_mut() {
                    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                    let (ci, cj) = (r.column(i).into_owned(), r.column(j).into_owned());
                    r.set_column(i, &(ci * co + cj * s));
                    r.set_column(j, &(cj * co - ci * s));
                }
            }
            Flow::Casimir => {
                if b.g.is_some() || b.r.is_some() {
                    let e = crate::lie::so3::exp(&(b.m * (tau * inv_ir)));
                    if let Some(g) = b.g.as_mut() {
                        *g = e.transpose() * *g;
                    }
                    if let Some(r) = b.r.as_mut() {
                        *r *= e;
                    }
                }
            }
            Flow::Kick => {
                if let (Some(g), Some(c)) = (b.g, c) {
                    b.m += g.cross(&c) * tau;
                }
            }
        };
        if b.r.is_some() {
            for k in chunks(steps) {
                run_sequence(seq, self.h, k, &mut b, &mut flow);
                if let Some(r) = b.r.as_mut() {
                    reorthonormalize(r);
                }
            }
        } else {
            run_sequence(seq, self.h, steps, &mut b, &mut flow);
        }
        state.z[..3].copy_from_slice(b.m.as_slice());
        if let Some(g) = b.g {
            state.z[3..6].copy_from_slice(g.as_slice());
        }
        if let Some(r) = b.r {
            state.attitude = Some(row_major(&r));
        }
        Ok(())
    }
}

/// Euler–Poisson vector field on y = (M, [Γ], [R row-major]): Ṁ = M × Ω + Γ × c, Γ̇ = Γ × Ω,
/// Ṙ = R hat(Ω), Ω = I⁻¹M (principal frame).
pub(crate) struct TopField {
    inv_i: Vector3<f64>,
    c: Option<Vector3<f64>>,
    attitude: bool,
}

impl TopField {
    pub(crate) fn new(moments: [f64; 3], c: Option<[f64; 3]>, attitude: bool) -> Self {
        TopField {
            inv_i: Vector3::from(moments.map(|i| 1.0 / i)),
            c: c.map(Vector3::from),
            attitude,
        }
    }

    /// Length of y.
    pub(crate) fn len(&self) -> usize {
        3 + if self.c.is_some() { 3 } else { 0 } + if self.attitude { 9 } else { 0 }
    }
}

impl VectorField for TopField {
    fn eval(&self, y: &[f64], dy: &mut [f64]) {
        let m = Vector3::from_column_slice(&y[..3]);
        let w = m.component_mul(&self.inv_i);
        let mut dm = m.cross(&w);
        let mut off = 3;
        if let Some(c) = &self.c {
            let g = Vector3::from_column_slice(&y[3..6]);
            dm += g.cross(c);
            dy[3..6].copy_from_slice(g.cross(&w).as_slice());
            off = 6;
        }
        dy[..3].copy_from_slice(dm.as_slice());
        if self.attitude {
            let r = Matrix3::from_row_slice(&y[off..off + 9]);
            dy[off..off + 9].copy_from_slice(&row_major(&(r * crate::lie::so3::hat(&w))));
        }
    }
}

/// RK4 on a rigid-body / heavy-top state, with or without attitude.
pub(crate) struct TopRk4 {
    plain: (TopField, Rk4),
    full: (TopField, Rk4),
    y: Vec<f64>,
}

impl TopRk4 {
    pub(crate) fn new(plain: TopField, full: TopField, h: f64) -> Self {
        let (np, nf) = (plain.len(), full.len());
        TopRk4 {
            plain: (plain, Rk4::new(h, np)),
            full: (full, Rk4::new(h, nf)),
            y: vec![0.0; nf],
        }
    }
}

impl Stepper for TopRk4 {
    fn run(&mut self, state: &mut State, steps: usize) -> Result<()> {
        let d = state.z.len();
        let (field, rk) = if state.attitude.is_some() {
            (&self.full.0, &mut self.full.1)
        } else {
            (&self.plain.0, &mut self.plain.1)
        };
        let y = &mut self.y[..field.len()];
        y[..d].copy_from_slice(&state.z);
        if let Some(r) = &state.attitude {
            y[d..].copy_from_slice(r);
        }
        rk.run(field, y, steps)?;
        state.z.copy_from_slice(&y[..d]);
        if let Some(r) = state.attitude.as_mut() {
            r.copy_from_slice(&y[d..]);
        }
        Ok(())
    }
}
