//! What the bodies on SO(3) share ([`crate::systems::RigidBody`], [`crate::systems::HeavyTop`]): principal frames,
//! the state layout (M, [Γ], [R]), the exact sub-flows of the Lie–Poisson splitting (the
//! [`Split`] kind), and the Euler(–Poisson) vector field (the [`VectorField`] kind).
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
use crate::integrate::methods::{Composition, Processed, ProcessedSplitting, Splitting};
use crate::integrate::problem::Split;
use crate::integrate::space::{Block, Space};
use crate::integrate::Entry;
use crate::numerics::simd::{fma, neg};
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

/// How far from SO(3) an attitude read by an observable may be (‖RᵀR − I‖_F and |det R − 1|).
/// Initial states are held to [`crate::lie::so3::ROTATION_TOL`]; computed attitudes drift off
/// SO(3) under methods that do not keep it (rk4: about 4e-5 after 10⁵ steps of 0.05), and
/// observables still read them, while a matrix that is no rotation (0, 2I, a reflection) is
/// refused.
pub(crate) const OBSERVED_ROTATION_TOL: f64 = 1e-3;

/// An attitude (row-major) read by an observable: finite and a rotation to
/// [`OBSERVED_ROTATION_TOL`] (`Error::NonFinite`, `Error::NotInGroup` naming the defect).
pub(crate) fn observed_attitude(what: &str, r: &[f64]) -> Result<Matrix3<f64>> {
    check::len_of(what, r, 9)?;
    let m = Matrix3::from_row_slice(r);
    let (orth, det) = crate::lie::so3::rotation_defect(&m);
    let defect = [("‖RᵀR − I‖_F", orth), ("|det R − 1|", (det - 1.0).abs())]
        .into_iter()
        .find(|&(_, d)| d.is_nan() || d > OBSERVED_ROTATION_TOL);
    match defect {
        Some((name, d)) => Err(Error::NotInGroup {
            what: what.into(),
            group: "SO(3)".into(),
            defect_name: name.into(),
            defect: d,
            tol: OBSERVED_ROTATION_TOL,
        }),
        None => Ok(m),
    }
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

/// Rotates v about e_k by the angle −θ: the flow of v̇ = v × (θ/t) e_k over time t. NaN beyond
/// the angle range of every exponential ([`crate::numerics::angle::angle_sin_cos`]), which the driver's
/// finiteness guard reports with the step.
#[inline]
pub(crate) fn rotate_axis(v: &mut Vector3<f64>, k: usize, theta: f64) {
    let (s, cm1) = crate::numerics::simd::angle_sin_cosm1(theta);
    rotate_axis_sc(v, k, s, cm1);
}

/// v ↦ v + ((cos θ − 1)v + sin θ Jv) in the plane (i, j) ⊥ e_k, from `s` = sin θ and
/// `cm1` = cos θ − 1: orthogonal to O(θ²ε), where (cos θ)v + sin θ Jv with cos θ rounded is off
/// by up to an ulp of 1 and, at the same angle every step (a symmetric body), biases |v|² the
/// same way every step ([`crate::numerics::simd`], "Rotations").
#[inline]
pub(crate) fn rotate_axis_sc(v: &mut Vector3<f64>, k: usize, s: f64, cm1: f64) {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let (vi, vj) = (v[i], v[j]);
    v[i] = vi + (cm1 * vi + s * vj);
    v[j] = vj + (cm1 * vj - s * vi);
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

/// A body on SO(3): principal moments, the principal frame of an inertia given as a matrix, the
/// gravity vector c = mgl χ of a heavy top (principal frame), and whether the state carries the
/// attitude R. State layout (flat): M (3), then Γ (3) for a heavy top, then R (9, row-major)
/// when lifted.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Top {
    pub(crate) moments: [f64; 3],
    pub(crate) frame: Option<Matrix3<f64>>,
    pub(crate) c: Option<Vector3<f64>>,
    pub(crate) lifted: bool,
    axes: [usize; 2],
    coef: [f64; 2],
    inv_ir: f64,
    kinds: [Flow; 4],
    flows: usize,
}

/// The working form of a body's state for the flows: registers for M, Γ and R.
#[derive(Clone, Copy, Debug)]
pub struct TopWork {
    pub(crate) m: Vector3<f64>,
    pub(crate) g: Option<Vector3<f64>>,
    pub(crate) r: Option<Matrix3<f64>>,
}

impl Top {
    pub(crate) fn new(moments: [f64; 3], frame: Option<Matrix3<f64>>, c: Option<[f64; 3]>) -> Self {
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| moments[a].total_cmp(&moments[b]));
        let r = idx[1];
        let axes = [(r + 1) % 3, (r + 2) % 3];
        let mut top = Top {
            moments,
            frame,
            c: c.map(Vector3::from),
            lifted: false,
            axes,
            coef: axes.map(|k| 1.0 / moments[k] - 1.0 / moments[r]),
            inv_ir: 1.0 / moments[r],
            kinds: [Flow::Axis(0); 4],
            flows: 0,
        };
        top.set_lifted(false);
        top
    }

    /// The same body with or without the attitude; the flows follow (the Casimir flow moves only
    /// R and Γ, so the free body without attitude has two flows).
    pub(crate) fn set_lifted(&mut self, lifted: bool) {
        self.lifted = lifted;
        let (kinds, flows): (&[Flow], usize) = match (self.c.is_some(), lifted) {
            (true, _) => (
                &[Flow::Kick, Flow::Axis(0), Flow::Axis(1), Flow::Casimir],
                4,
            ),
            (false, true) => (&[Flow::Axis(0), Flow::Axis(1), Flow::Casimir], 3),
            (false, false) => (&[Flow::Axis(0), Flow::Axis(1)], 2),
        };
        self.kinds[..kinds.len()].copy_from_slice(kinds);
        self.flows = flows;
    }

    /// The space: `M: ℝ³` (and `Gamma: ℝ³` for a heavy top), then `R: SO(3)` when lifted.
    pub(crate) fn space(&self) -> Space {
        let mut s = Space::new([("M", Block::Real(3))]);
        if self.c.is_some() {
            s = s.with("Gamma", Block::Real(3));
        }
        if self.lifted {
            s = s.with("R", Block::SO3);
        }
        s
    }

    /// Offset of R in the state.
    fn r_at(&self) -> usize {
        if self.c.is_some() {
            6
        } else {
            3
        }
    }

    /// Kinetic energy ½ M·I⁻¹M of a body momentum given in the user frame (000 §3–§4).
    /// |Ω| = |I⁻¹M|, the rate of rotation (scale-safe).
    pub(crate) fn rate(&self, m: &[f64]) -> f64 {
        let m = to_frame(&self.frame, m);
        let w: Vec<f64> = (0..3).map(|i| m[i] / self.moments[i]).collect();
        crate::lie::scaled_norm(w.iter())
    }

    pub(crate) fn kinetic_energy(&self, m: &[f64]) -> f64 {
        let m = to_frame(&self.frame, m);
        0.5 * (0..3).map(|i| m[i] * m[i] / self.moments[i]).sum::<f64>()
    }

    /// The attitude R of a lifted state.
    pub(crate) fn attitude(&self, z: &[f64]) -> Option<Matrix3<f64>> {
        let at = self.r_at();
        self.lifted.then(|| Matrix3::from_row_slice(&z[at..at + 9]))
    }

    fn map_frame(&self, z: &mut [f64], inverse: bool) {
        if let Some(q) = &self.frame {
            let qm = if inverse { *q } else { q.transpose() };
            let at = self.r_at();
            for v in z[..at].chunks_exact_mut(3) {
                let w = qm * Vector3::from_column_slice(v);
                v.copy_from_slice(w.as_slice());
            }
            if let Some(r) = self.attitude(z) {
                let r = r * if inverse { q.transpose() } else { *q };
                z[at..at + 9].copy_from_slice(&row_major(&r));
            }
        }
    }

    /// A tangent vector (δM, δΓ, ξ with δR = Rξ̂): every block is a body vector, v ↦ Qᵀv
    /// (inverse: v ↦ Qv), since δ(RQ) = RQ (Qᵀξ)^.
    pub(crate) fn tangent_frame(&self, dz: &mut [f64], inverse: bool) {
        if let Some(q) = &self.frame {
            let qm = if inverse { *q } else { q.transpose() };
            for v in dz.chunks_exact_mut(3) {
                let w = qm * Vector3::from_column_slice(v);
                v.copy_from_slice(w.as_slice());
            }
        }
    }

    /// The index of ξ (the attitude's left-trivialised direction) in a tangent vector.
    pub(crate) fn xi_at(&self) -> usize {
        if self.c.is_some() {
            6
        } else {
            3
        }
    }

    /// Body vectors v ↦ Qᵀv, R ↦ RQ (user frame → principal frame).
    pub(crate) fn to_internal(&self, z: &mut [f64]) {
        self.map_frame(z, false);
    }

    /// Inverse of [`Top::to_internal`].
    pub(crate) fn to_user(&self, z: &mut [f64]) {
        self.map_frame(z, true);
    }

    pub(crate) fn load(&self, z: &[f64]) -> TopWork {
        TopWork {
            m: Vector3::from_column_slice(&z[..3]),
            g: self.c.map(|_| Vector3::from_column_slice(&z[3..6])),
            r: self.attitude(z),
        }
    }

    pub(crate) fn store(&self, w: &TopWork, z: &mut [f64]) {
        z[..3].copy_from_slice(w.m.as_slice());
        if let Some(g) = &w.g {
            z[3..6].copy_from_slice(g.as_slice());
        }
        if let Some(r) = &w.r {
            let at = self.r_at();
            z[at..at + 9].copy_from_slice(&row_major(r));
        }
    }

    pub(crate) fn flows(&self) -> usize {
        self.flows
    }

    /// The exact flow i over time τ (module docs): one body through the batch kernel
    /// ([`TopLanes`]), so that a body gives the same bits alone and in a batch. NaN where an
    /// angle is lost to rounding (see `rotate_axis`).
    pub(crate) fn flow(&self, i: usize, tau: f64, b: &mut TopWork) {
        let kernel = self.kernel();
        let d = crate::integrate::problem::SplitLanes::dim(&kernel);
        let mut z = [0.0; 15];
        self.store(b, &mut z);
        let program = crate::integrate::problem::Program {
            outer: i,
            fused: 0.0,
            inner: &[],
            steps: 1,
        };
        crate::integrate::problem::SplitLanes::run(&kernel, &mut z[..d], &[tau], &program);
        *b = self.load(&z[..d]);
    }

    /// The exact flow of the heavy-top potential V = Γ·c over time τ: M ↦ M + τ Γ × c (the
    /// identity for a free body).
    pub(crate) fn kick(&self, tau: f64, b: &mut TopWork) {
        if let Some(i) = self.kick_index() {
            self.flow(i, tau, b);
        }
    }

    /// The index of the gravity kick among the flows (a heavy top's).
    pub(crate) fn kick_index(&self) -> Option<usize> {
        self.kinds[..self.flows]
            .iter()
            .position(|&k| k == Flow::Kick)
    }

    /// The kernel of the flows ([`TopLanes`]) for this body.
    fn kernel(&self) -> TopLanes {
        TopLanes {
            kinds: self.kinds,
            axes: self.axes,
            coef: self.coef,
            inv_ir: self.inv_ir,
            c: self.c.map(Into::into),
            lifted: self.lifted,
        }
    }

    /// The flows on many bodies at once: [`TopLanes`].
    pub(crate) fn lanes(
        &self,
    ) -> Option<std::sync::Arc<dyn crate::integrate::problem::SplitLanes>> {
        Some(std::sync::Arc::new(self.kernel()))
    }

    /// The Euler–Poisson field on (M, [Γ], [R]): Ṁ = M × Ω + Γ × c, Γ̇ = Γ × Ω, Ṙ = R hat(Ω),
    /// Ω = I⁻¹M (principal frame).
    pub(crate) fn field(&self, y: &[f64], dy: &mut [f64]) {
        let m = Vector3::from_column_slice(&y[..3]);
        let w = Vector3::from_fn(|i, _| m[i] / self.moments[i]);
        let mut dm = m.cross(&w);
        if let Some(c) = &self.c {
            let g = Vector3::from_column_slice(&y[3..6]);
            dm += g.cross(c);
            dy[3..6].copy_from_slice(g.cross(&w).as_slice());
        }
        dy[..3].copy_from_slice(dm.as_slice());
        if let Some(r) = self.attitude(y) {
            let at = self.r_at();
            dy[at..at + 9].copy_from_slice(&row_major(&(r * crate::lie::so3::hat(&w))));
        }
    }
}

/// A parameter of a top as the kernels see it: a principal moment I_k, or the gravity vector
/// c = mgl χ (principal frame) moving along dc (∂c/∂mgl = χ, ∂c/∂χ_j = mgl e_j).
#[derive(Clone, Copy, Debug)]
pub(crate) enum TopParam {
    Moment(usize),
    Gravity(Vector3<f64>),
}

impl Top {
    /// The reference axis r of the splittings (the middle moment; `axes` are the other two).
    fn reference_axis(&self) -> usize {
        (self.axes[0] + 2) % 3
    }

    /// dy += ∂φ_i,τ/∂θ at the state `before` flow i (its result `after`; flat, principal frame,
    /// without the attitude): Axis(a) through θ = τ·coef·M_k with coef = 1/I_k − 1/I_r;
    /// Casimir through v = τM/I_r; Kick through c (module docs of [`Top::flow_tangent`]).
    pub(crate) fn flow_parameter(
        &self,
        i: usize,
        tau: f64,
        before: &TopWork,
        after: &TopWork,
        p: TopParam,
        dy: &mut [f64],
    ) {
        let r = self.reference_axis();
        match (self.kinds[i], p) {
            (Flow::Axis(a), TopParam::Moment(q)) => {
                let k = self.axes[a];
                let dcoef = if q == k {
                    -1.0 / (self.moments[k] * self.moments[k])
                } else if q == r {
                    self.inv_ir * self.inv_ir
                } else {
                    0.0
                };
                let dtheta = tau * dcoef * before.m[k];
                let (ii, jj) = ((k + 1) % 3, (k + 2) % 3);
                dy[ii] += dtheta * after.m[jj];
                dy[jj] -= dtheta * after.m[ii];
                if let Some(g1) = after.g {
                    dy[3 + ii] += dtheta * g1[jj];
                    dy[3 + jj] -= dtheta * g1[ii];
                }
                if self.lifted {
                    dy[self.xi_at() + k] += dtheta;
                }
            }
            (Flow::Casimir, TopParam::Moment(q)) if q == r => {
                let v = before.m * (tau * self.inv_ir);
                let dv = before.m * (-tau * self.inv_ir * self.inv_ir);
                if let Some(g1) = after.g {
                    let jl = crate::lie::so3::jacobian_left(&-v)
                        .unwrap_or_else(|_| Matrix3::from_element(f64::NAN));
                    let d = -(jl * dv).cross(&g1);
                    for c in 0..3 {
                        dy[3 + c] += d[c];
                    }
                }
                if self.lifted {
                    let jr = crate::lie::so3::jacobian_right(&v)
                        .unwrap_or_else(|_| Matrix3::from_element(f64::NAN));
                    let d = jr * dv;
                    let x = self.xi_at();
                    for c in 0..3 {
                        dy[x + c] += d[c];
                    }
                }
            }
            (Flow::Kick, TopParam::Gravity(dc)) => {
                if let Some(g) = before.g {
                    let d = g.cross(&dc) * tau;
                    for c in 0..3 {
                        dy[c] += d[c];
                    }
                }
            }
            _ => {}
        }
    }

    /// out += ∂f/∂θ (z): a moment through Ω_k = M_k/I_k (∂Ṁ = M × ∂Ω, ∂Γ̇ = Γ × ∂Ω,
    /// ∂Ṙ = R(∂Ω)^), the gravity vector through Ṁ ∋ Γ × c.
    pub(crate) fn field_parameter(&self, y: &[f64], p: TopParam, out: &mut [f64]) {
        let m = Vector3::from_column_slice(&y[..3]);
        let g = self.c.map(|_| Vector3::from_column_slice(&y[3..6]));
        let mut dw = Vector3::zeros();
        let (dm, dg) = match p {
            TopParam::Moment(k) => {
                dw[k] = -m[k] / (self.moments[k] * self.moments[k]);
                (m.cross(&dw), g.map(|g| g.cross(&dw)))
            }
            TopParam::Gravity(dc) => (g.map_or(Vector3::zeros(), |g| g.cross(&dc)), None),
        };
        for c in 0..3 {
            out[c] += dm[c];
            if let Some(dg) = dg {
                out[3 + c] += dg[c];
            }
        }
        if let Some(r) = self.attitude(y) {
            let at = self.r_at();
            let dr = row_major(&(r * crate::lie::so3::hat(&dw)));
            out[at..at + 9]
                .iter_mut()
                .zip(dr)
                .for_each(|(o, x)| *o += x);
        }
    }

    /// The tangent map of flow i over τ on one direction dy = (δM, δΓ, ξ) (principal frame; ξ
    /// the left-trivialised direction of the attitude when lifted), from the states before and
    /// after it: Axis(a) turns M and Γ about e_k by
    /// θ = τ·coef·M_k (v_i' = cos θ v_i + sin θ v_j, v_j' = cos θ v_j − sin θ v_i), so
    /// δv' = Rot(θ)δv + δθ (v_j', −v_i') with δθ = τ·coef·δM_k; Casimir turns Γ by exp(−v̂),
    /// v = τM/I_r, so δΓ' = exp(−v̂)δΓ − (J_l(−v)δv) × Γ'; Kick: δM' = δM + τ δΓ × c.
    pub(crate) fn flow_tangent(
        &self,
        i: usize,
        tau: f64,
        before: &TopWork,
        after: &TopWork,
        dirs: &mut [f64],
    ) {
        let heavy = self.c.is_some();
        let e = 3 + if heavy { 3 } else { 0 } + if self.lifted { 3 } else { 0 };
        let x = self.xi_at();
        match self.kinds[i] {
            Flow::Axis(a) => {
                // One (sin θ, cos θ) for every direction.
                let k = self.axes[a];
                let tc = tau * self.coef[a];
                let (s, c) = (tc * before.m[k]).sin_cos();
                let (ii, jj) = ((k + 1) % 3, (k + 2) % 3);
                let g1 = after.g.unwrap_or_else(Vector3::zeros);
                for dy in dirs.chunks_exact_mut(e) {
                    let dtheta = tc * dy[k];
                    let mut turn = |at: usize, after: &Vector3<f64>| {
                        let (vi, vj) = (dy[at + ii], dy[at + jj]);
                        dy[at + ii] = c * vi + s * vj + dtheta * after[jj];
                        dy[at + jj] = c * vj - s * vi - dtheta * after[ii];
                    };
                    turn(0, &after.m);
                    if heavy {
                        turn(3, &g1);
                    }
                    if self.lifted {
                        // R' = R Rot(θ)ᵀ with Rot(θ) = exp(−θê_k): ξ' = Rot ξ + δθ e_k.
                        let (xi, xj) = (dy[x + ii], dy[x + jj]);
                        dy[x + ii] = c * xi + s * xj;
                        dy[x + jj] = c * xj - s * xi;
                        dy[x + k] += dtheta;
                    }
                }
            }
            Flow::Casimir => {
                // One exp(−v̂), J_l(−v), J_r(v) for every direction.
                let t = tau * self.inv_ir;
                let v = before.m * t;
                let ex = crate::lie::so3::exp_unchecked(&-v);
                let nan = |_| Matrix3::from_element(f64::NAN);
                let jl = heavy.then(|| crate::lie::so3::jacobian_left(&-v).unwrap_or_else(nan));
                let jr = self
                    .lifted
                    .then(|| crate::lie::so3::jacobian_right(&v).unwrap_or_else(nan));
                let g1 = after.g.unwrap_or_else(Vector3::zeros);
                for dy in dirs.chunks_exact_mut(e) {
                    let dv = Vector3::new(dy[0], dy[1], dy[2]) * t;
                    if let Some(jl) = &jl {
                        let dg = Vector3::new(dy[3], dy[4], dy[5]);
                        dy[3..6].copy_from_slice((ex * dg - (jl * dv).cross(&g1)).as_slice());
                    }
                    if let Some(jr) = &jr {
                        // R' = R exp(v̂): ξ' = exp(−v̂)ξ + J_r(v)δv.
                        let xi = Vector3::from_column_slice(&dy[x..x + 3]);
                        dy[x..x + 3].copy_from_slice((ex * xi + jr * dv).as_slice());
                    }
                }
            }
            Flow::Kick => {
                if let Some(c) = self.c {
                    for dy in dirs.chunks_exact_mut(e) {
                        let dm = Vector3::new(dy[3], dy[4], dy[5]).cross(&c) * tau;
                        for q in 0..3 {
                            dy[q] += dm[q];
                        }
                    }
                }
            }
        }
    }

    /// The derivative of [`Top::field`] along dy (ambient: the attitude's δR a 3×3 matrix):
    /// δṀ = δM × Ω + M × δΩ (+ δΓ × c), δΓ̇ = δΓ × Ω + Γ × δΩ, δṘ = δR Ω̂ + R(δΩ)^,
    /// δΩ = I⁻¹δM (principal frame).
    pub(crate) fn field_tangent(&self, y: &[f64], dy: &[f64], out: &mut [f64]) {
        let m = Vector3::from_column_slice(&y[..3]);
        let dm = Vector3::from_column_slice(&dy[..3]);
        let w = Vector3::from_fn(|i, _| m[i] / self.moments[i]);
        let dw = Vector3::from_fn(|i, _| dm[i] / self.moments[i]);
        let mut ddm = dm.cross(&w) + m.cross(&dw);
        if let Some(c) = &self.c {
            let g = Vector3::from_column_slice(&y[3..6]);
            let dg = Vector3::from_column_slice(&dy[3..6]);
            ddm += dg.cross(c);
            out[3..6].copy_from_slice((dg.cross(&w) + g.cross(&dw)).as_slice());
        }
        out[..3].copy_from_slice(ddm.as_slice());
        if let Some(r) = self.attitude(y) {
            let at = self.r_at();
            let dr = Matrix3::from_row_slice(&dy[at..at + 9]);
            let hat = crate::lie::so3::hat;
            out[at..at + 9].copy_from_slice(&row_major(&(dr * hat(&w) + r * hat(&dw))));
        }
    }
}

/// The flows of the free rigid body (M) and of the heavy top (M, Γ), with or without the attitude
/// R, on a block of bodies, in SIMD lanes ([`crate::numerics::simd`]); [`Top::flow`] is this
/// kernel on one body. Flow `Axis(a)` rotates M (and Γ) about e_k, k = `axes[a]`, by the angle
/// −τ·`coef[a]`·M_k (and the columns i, j of R by the same angle); `Casimir` turns Γ and the rows
/// of R by exp(−τ M̂/I_r) ([`Turn`]); `Kick` adds τ Γ × c to M ([`kick_lanes`]).
///
/// Each group of [`group`] vectors of bodies is loaded into registers once and stepped through
/// the whole program there (the vectors interleaved, so that the latency of one sin/cos is hidden
/// behind the others), then stored. One body runs in one scalar lane, inside the same dispatch.
#[derive(Clone, Copy, Debug)]
struct TopLanes {
    kinds: [Flow; 4],
    axes: [usize; 2],
    coef: [f64; 2],
    inv_ir: f64,
    /// c = mgl χ of a heavy top (then the block holds M and Γ).
    c: Option<[f64; 3]>,
    /// Whether the block also holds R (row-major, after M and Γ).
    lifted: bool,
}

/// Vectors of bodies stepped together by [`TopLanes`] in a batch: 8 with AVX-512's 32
/// registers, 4 with AVX2's 16 (measured best of 1, 2, 4, 8, 16 on AVX-512).
const fn group(lanes: usize) -> usize {
    if lanes >= 8 {
        8
    } else {
        4
    }
}

impl crate::integrate::problem::SplitLanes for TopLanes {
    fn dim(&self) -> usize {
        3 + if self.c.is_some() { 3 } else { 0 } + if self.lifted { 9 } else { 0 }
    }

    fn run(
        &self,
        block: &mut [f64],
        first: &[f64],
        program: &crate::integrate::problem::Program<'_>,
    ) {
        fn go<const D: usize>(
            lanes: &TopLanes,
            block: &mut [f64],
            first: &[f64],
            program: &crate::integrate::problem::Program<'_>,
        ) {
            pulp::Arch::new().dispatch(LanesRun::<D> {
                lanes,
                block,
                first,
                program,
            });
        }
        // dim() is 3 + 3·[heavy top] + 9·[attitude]: one of these four.
        match self.dim() {
            3 => go::<3>(self, block, first, program),
            6 => go::<6>(self, block, first, program),
            12 => go::<12>(self, block, first, program),
            _ => go::<15>(self, block, first, program),
        }
    }
}

/// A run of [`TopLanes`] on a block of D components: M, then Γ (heavy top), then the rows of R
/// (with attitude): 3, 6, 12 or 15.
struct LanesRun<'a, const D: usize> {
    lanes: &'a TopLanes,
    block: &'a mut [f64],
    first: &'a [f64],
    program: &'a crate::integrate::problem::Program<'a>,
}

impl<const D: usize> pulp::WithSimd for LanesRun<'_, D> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        match self.first.len() {
            0 => {}
            // One body (a single run, a flow of `Top::flow`): one lane, compiled inside this
            // dispatch (its fused multiply-adds are the machine's).
            1 => self.steps::<pulp::Scalar, 1>(pulp::Scalar::new()),
            _ if group(S::F64_LANES) == 8 => self.steps::<S, 8>(simd),
            _ => self.steps::<S, 4>(simd),
        }
    }
}

impl<const D: usize> LanesRun<'_, D> {
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // the group's vectors index several arrays
    fn steps<S: pulp::Simd, const G: usize>(self, simd: S) {
        let n = self.first.len();
        let lanes = S::F64_LANES;
        let mut chunks = self.block.chunks_exact_mut(n);
        let mut rows: [&mut [f64]; D] = std::array::from_fn(|_| chunks.next().unwrap_or_default());
        let (p, top) = (self.program, self.lanes);
        let mut start = 0;
        while start < n {
            // Loads G vectors of bodies (zeros past the end: lanes of no body).
            let part = |j: usize| {
                let lo = (start + j * lanes).min(n);
                lo..(lo + lanes).min(n)
            };
            let mut z = [[simd.splat_f64s(0.0); G]; D];
            let mut tau = [simd.splat_f64s(0.0); G];
            for j in 0..G {
                for (c, row) in rows.iter().enumerate() {
                    z[c][j] = simd.partial_load_f64s(&row[part(j)]);
                }
                tau[j] = simd.partial_load_f64s(&self.first[part(j)]);
            }
            // The first outer flow, with each body's own time; every time scaled as its flow
            // uses it (τ·factor).
            let outer = simd.splat_f64s(top.factor(p.outer));
            for t in &mut tau {
                *t = simd.mul_f64s(*t, outer);
            }
            top.apply(simd, p.outer, tau, &mut z);
            for &(i, t) in p.inner {
                top.apply(simd, i, [simd.splat_f64s(t * top.factor(i)); G], &mut z);
            }
            let fused = [simd.splat_f64s(p.fused * top.factor(p.outer)); G];
            for _ in 1..p.steps {
                top.apply(simd, p.outer, fused, &mut z);
                for &(i, t) in p.inner {
                    top.apply(simd, i, [simd.splat_f64s(t * top.factor(i)); G], &mut z);
                }
            }
            for j in 0..G {
                let range = part(j);
                for (c, row) in rows.iter_mut().enumerate() {
                    simd.partial_store_f64s(&mut row[range.clone()], z[c][j]);
                }
            }
            start += G * lanes;
        }
    }
}

impl TopLanes {
    /// The factor by which flow i scales its time: a_k for an axis flow (the angle is
    /// τ a_k M_k), 1/I_r for the Casimir flow, 1 for the kick.
    fn factor(&self, i: usize) -> f64 {
        match self.kinds[i] {
            Flow::Axis(a) => self.coef[a],
            Flow::Casimir => self.inv_ir,
            Flow::Kick => 1.0,
        }
    }

    /// Flow i over the scaled times `tau` (τ·[`TopLanes::factor`]) on a group (the block's rows
    /// as in [`LanesRun`]).
    #[inline(always)]
    fn apply<S: pulp::Simd, const D: usize, const G: usize>(
        &self,
        simd: S,
        i: usize,
        tau: [S::f64s; G],
        z: &mut [[S::f64s; G]; D],
    ) {
        match self.kinds[i] {
            Flow::Axis(a) => rotate(simd, z, self.axes[a], tau),
            Flow::Casimir => {
                // Every block after M (Γ, the rows of R) turns with the same exp(−v̂).
                for g in 0..G {
                    let turn = Turn::new(simd, tau[g], [z[0][g], z[1][g], z[2][g]]);
                    for base in (3..D).step_by(3) {
                        let mut x = [z[base][g], z[base + 1][g], z[base + 2][g]];
                        turn.apply(&mut x);
                        for (c, xc) in x.into_iter().enumerate() {
                            z[base + c][g] = xc;
                        }
                    }
                }
            }
            Flow::Kick => {
                if let Some(c) = self.c {
                    for g in 0..G {
                        let mut m = [z[0][g], z[1][g], z[2][g]];
                        let v = [z[3 % D][g], z[4 % D][g], z[5 % D][g]];
                        kick_lanes(simd, tau[g], &mut m, v, c);
                        for k in 0..3 {
                            z[k][g] = m[k];
                        }
                    }
                }
            }
        }
    }
}

/// The turn exp(−v̂) for v = t M (Rodrigues: exp(−v̂) x = x − A v × x + B v × (v × x), θ = |v|,
/// A = sin θ/θ, B = (1 − cos θ)/θ²): the flow of ½|M|²/I_r over τ = t I_r on Γ, and on the rows
/// of R (R exp(v̂) has the rows exp(−v̂) r). For θ ≤ [`crate::numerics::simd::SMALL_MAX`] (the usual step)
/// A and B are polynomials in θ² ([`crate::numerics::simd::sinc_versinc_small`]: no square root, no
/// division); a lane beyond it takes sin θ/θ and (1 − cos θ)/θ², chosen per lane, so a body
/// gives the same bits in any vector.
struct Turn<S: pulp::Simd> {
    simd: S,
    v: [S::f64s; 3],
    a: S::f64s,
    b: S::f64s,
}

impl<S: pulp::Simd> Turn<S> {
    #[inline(always)]
    fn new(simd: S, t: S::f64s, m: [S::f64s; 3]) -> Self {
        let v = [
            simd.mul_f64s(m[0], t),
            simd.mul_f64s(m[1], t),
            simd.mul_f64s(m[2], t),
        ];
        let th2 = fma(
            simd,
            v[2],
            v[2],
            fma(simd, v[1], v[1], simd.mul_f64s(v[0], v[0])),
        );
        let small_max = crate::numerics::simd::SMALL_MAX * crate::numerics::simd::SMALL_MAX;
        let small = simd.less_than_or_equal_f64s(th2, simd.splat_f64s(small_max));
        let (mut a, mut b) = crate::numerics::simd::sinc_versinc_small(simd, th2);
        if simd.first_true_m64s(simd.not_m64s(small)) < S::F64_LANES {
            // 1 − cos θ as −(cos θ − 1): no cancellation near multiples of 2π.
            let th = simd.sqrt_f64s(th2);
            let (s, cm1) = crate::numerics::simd::sin_cosm1_lanes(simd, th);
            let versin = simd.xor_f64s(cm1, simd.splat_f64s(-0.0));
            a = simd.select_f64s(small, a, simd.div_f64s(s, th));
            b = simd.select_f64s(small, b, simd.div_f64s(versin, th2));
        }
        Turn { simd, v, a, b }
    }

    /// x ↦ exp(−v̂) x = x + (B v × (v × x) − A v × x): the increment formed first and added to
    /// x once. Adding A v × x and then B v × (v × x) rounds x twice, and at a relative
    /// equilibrium (a steady precession) the second addend is the same to far below an ulp of x
    /// at every step, so its rounding onto x is the same every step: a bias (|Γ|² of the Lagrange
    /// top's steady precession drifted by 0.6 ulp per step with `splitting4`). The increment as a
    /// whole varies from step to step by many of its own ulps, and its one rounding onto x is
    /// unbiased.
    #[inline(always)]
    fn apply(&self, x: &mut [S::f64s; 3]) {
        let simd = self.simd;
        let w = cross(simd, self.v, *x);
        let u = cross(simd, self.v, w);
        for k in 0..3 {
            let d = fma(simd, self.b, u[k], neg(simd, simd.mul_f64s(self.a, w[k])));
            x[k] = simd.add_f64s(x[k], d);
        }
    }
}

/// M ↦ M + τ Γ × c: the flow of the heavy-top potential Γ·c.
#[inline(always)]
fn kick_lanes<S: pulp::Simd>(
    simd: S,
    tau: S::f64s,
    m: &mut [S::f64s; 3],
    g: [S::f64s; 3],
    c: [f64; 3],
) {
    let c = [
        simd.splat_f64s(c[0]),
        simd.splat_f64s(c[1]),
        simd.splat_f64s(c[2]),
    ];
    let gc = cross(simd, g, c);
    for k in 0..3 {
        m[k] = fma(simd, gc[k], tau, m[k]);
    }
}

/// a × b, each component a_i b_j − a_j b_i with one fused multiply-add.
#[inline(always)]
fn cross<S: pulp::Simd>(simd: S, a: [S::f64s; 3], b: [S::f64s; 3]) -> [S::f64s; 3] {
    [
        fma(simd, a[1], b[2], neg(simd, simd.mul_f64s(a[2], b[1]))),
        fma(simd, a[2], b[0], neg(simd, simd.mul_f64s(a[0], b[2]))),
        fma(simd, a[0], b[1], neg(simd, simd.mul_f64s(a[1], b[0]))),
    ]
}

/// The rotation of every body of a group about e_k by the angle −tc·M_k (tc = τ·a per lane):
/// V_i ← V_i + ((c − 1)V_i + s V_j), V_j ← V_j + ((c − 1)V_j − s V_i) with (i, j, k) cyclic for
/// V = M, Γ and the rows of R (c − 1 carried to its own precision: no bias per step), each
/// increment (c − 1)V_i + s V_j with one fused multiply-add.
#[inline(always)]
fn rotate<S: pulp::Simd, const D: usize, const G: usize>(
    simd: S,
    z: &mut [[S::f64s; G]; D],
    k: usize,
    tc: [S::f64s; G],
) {
    match k {
        0 => rotate_about::<S, D, G, 0, 1, 2>(simd, z, tc),
        1 => rotate_about::<S, D, G, 1, 2, 0>(simd, z, tc),
        _ => rotate_about::<S, D, G, 2, 0, 1>(simd, z, tc),
    }
}

#[inline(always)]
fn rotate_about<
    S: pulp::Simd,
    const D: usize,
    const G: usize,
    const K: usize,
    const I: usize,
    const J: usize,
>(
    simd: S,
    z: &mut [[S::f64s; G]; D],
    tc: [S::f64s; G],
) {
    for g in 0..G {
        let angle = simd.mul_f64s(tc[g], z[K][g]);
        let (s, cm1) = crate::numerics::simd::sin_cosm1_step(simd, angle);
        for base in (0..D).step_by(3) {
            let (vi, vj) = (z[base + I][g], z[base + J][g]);
            let di = fma(simd, cm1, vi, simd.mul_f64s(s, vj));
            let dj = fma(simd, cm1, vj, neg(simd, simd.mul_f64s(s, vi)));
            z[base + I][g] = simd.add_f64s(vi, di);
            z[base + J][g] = simd.add_f64s(vj, dj);
        }
    }
}

/// The Lie–Poisson splittings the SO(3) bodies share (the first entries of their catalogs, in
/// this order): symmetric compositions of the sub-flows (Strang, Suzuki 4, Yoshida 6,
/// Kahan–Li 8) and the processed ones (Blanes–Casas–Murua, effective orders 6, 8, 10).
pub(crate) fn splittings<P: Split + Clone + 'static>() -> Vec<Entry<P>> {
    vec![
        Entry::new("splitting", Splitting::strang),
        Entry::new("splitting4", || Splitting(Composition::suzuki4())),
        Entry::new("splitting6", || Splitting(Composition::yoshida6())),
        Entry::new("splitting8", || Splitting(Composition::kahan_li8())),
        Entry::new("processed6", || ProcessedSplitting(Processed::bcm6())),
        Entry::new("processed8", || ProcessedSplitting(Processed::bcm8())),
        Entry::new("processed10", || ProcessedSplitting(Processed::bcm10())),
    ]
}

/// The problem kinds of a body on SO(3) with a field `top: Top`: [`Split`] (the Lie–Poisson
/// splitting), [`VectorField`] (RK4) and the [`super::methods::lgvi::Lgvi`] method, each with
/// its tangent lift.
macro_rules! top_kinds {
    ($t:ty) => {
        $crate::systems::tops::top::top_kinds!($t;);
    };
    // Further methods of the lift without the attitude (name => constructor); after a second
    // `;`, further methods of the lift with and without it.
    ($t:ty; $($name:literal => $make:expr),* $(; $($both:literal => $bmake:expr),*)?) => {
        impl $crate::integrate::problem::Split for $t {
            type Work = $crate::systems::tops::top::TopWork;
            fn load(&self, z: &[f64]) -> $crate::Result<Self::Work> {
                Ok(self.top.load(z))
            }
            fn store(&self, w: &Self::Work, z: &mut [f64]) {
                self.top.store(w, z)
            }
            fn flows(&self) -> usize {
                self.top.flows()
            }
            #[inline]
            fn flow(&self, i: usize, tau: f64, w: &mut Self::Work) {
                self.top.flow(i, tau, w)
            }
            fn lanes(&self) -> Option<std::sync::Arc<dyn $crate::integrate::problem::SplitLanes>> {
                self.top.lanes()
            }
        }

        impl $crate::integrate::problem::VectorField for $t {
            fn field(&self, z: &[f64], dz: &mut [f64]) {
                self.top.field(z, dz)
            }
        }

        impl $crate::integrate::tangent::VectorFieldTangent for $t {
            fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
                self.top.field_tangent(z, dz, out)
            }
            fn field_parameter(&self, z: &[f64], m: usize, out: &mut [f64]) {
                self.top.field_parameter(z, self.top_parameter(m), out)
            }
        }

        impl $crate::integrate::tangent::SplitTangent for $t {
            fn flow_tangent(
                &self,
                i: usize,
                tau: f64,
                before: &Self::Work,
                after: &Self::Work,
                dirs: &mut [f64],
            ) {
                self.top.flow_tangent(i, tau, before, after, dirs)
            }
            fn flow_parameter(
                &self,
                i: usize,
                tau: f64,
                before: &Self::Work,
                after: &Self::Work,
                m: usize,
                dz: &mut [f64],
            ) {
                self.top
                    .flow_parameter(i, tau, before, after, self.top_parameter(m), dz)
            }
        }

        impl $crate::integrate::tangent::Tangent<$t> {
            /// The methods of the tangent lift with the attitude: the splittings, `lgvi` and the
            /// further methods of both lifts.
            fn attitude_catalog() -> Vec<$crate::integrate::Entry<Self>> {
                let mut c = $crate::systems::tops::top::splittings();
                c.push($crate::integrate::Entry::new("lgvi", || {
                    $crate::systems::tops::methods::lgvi::Lgvi
                }));
                $($(c.push($crate::integrate::Entry::new($both, $bmake));)*)?
                c
            }

            fn rk4() -> $crate::integrate::Entry<Self> {
                $crate::integrate::Entry::new("rk4", || $crate::integrate::methods::Rk4)
            }
        }

        /// The splittings, `lgvi`, and (without the attitude) `rk4` and the further methods on
        /// the tangent lift; with the attitude, `rk4` alone on the field lift (its directions
        /// ambient).
        impl $crate::integrate::Catalog for $crate::integrate::tangent::Tangent<$t> {
            fn kind_catalog() -> Vec<$crate::integrate::Entry<Self>> {
                let mut c = Self::attitude_catalog();
                c.push(Self::rk4());
                $(c.push($crate::integrate::Entry::new($name, $make));)*
                c
            }

            fn catalog(&self) -> Vec<$crate::integrate::Entry<Self>> {
                match (self.ambient(), self.problem().top.lifted) {
                    (true, _) => vec![Self::rk4()],
                    (false, true) => Self::attitude_catalog(),
                    (false, false) => Self::kind_catalog(),
                }
            }
        }

        /// The LGVI on the tangent lift (module docs of `methods::lgvi`, "Tangent map").
        impl $crate::integrate::Integrator<$crate::integrate::tangent::Tangent<$t>>
            for $crate::systems::tops::methods::lgvi::Lgvi
        {
            fn properties(&self) -> $crate::integrate::Properties {
                $crate::integrate::Properties::geometric(2)
            }
            fn stepper(
                &self,
                lift: &$crate::integrate::tangent::Tangent<$t>,
                dt: f64,
            ) -> $crate::Result<Box<dyn $crate::integrate::Stepper>> {
                use $crate::integrate::Problem;
                let p = lift.problem();
                let params = (0..p.parameters().len()).map(|m| p.top_parameter(m)).collect();
                Ok(self.tangent_stepper_for(&p.top, params, dt))
            }
        }

        impl $crate::integrate::Integrator<$t> for $crate::systems::tops::methods::lgvi::Lgvi {
            fn properties(&self) -> $crate::integrate::Properties {
                $crate::integrate::Properties::geometric(2)
            }
            fn stepper(
                &self,
                problem: &$t,
                dt: f64,
            ) -> $crate::Result<Box<dyn $crate::integrate::Stepper>> {
                Ok(self.stepper_for(&problem.top, dt))
            }
        }
    };
}
pub(crate) use top_kinds;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The kernel gives the same bits whatever runs it: the best instruction set of the machine,
    /// AVX2 where the machine has it, the portable scalar lanes outside any dispatch (libm's
    /// `fma`), and each member alone; with angles on both sides of the small-angle path in one
    /// vector. The free body (3 components) and the heavy top with attitude (15).
    /// The kernel's run on D components with the lanes `simd` (outside any dispatch).
    fn with<const D: usize>(
        k: &TopLanes,
        block: &mut [f64],
        first: &[f64],
        program: &crate::integrate::problem::Program<'_>,
        simd: impl pulp::Simd,
    ) {
        pulp::WithSimd::with_simd(Run::<D>(k, block, first, program), simd)
    }

    /// [`LanesRun`] from its parts, for a chosen instruction set.
    struct Run<'a, const D: usize>(
        &'a TopLanes,
        &'a mut [f64],
        &'a [f64],
        &'a crate::integrate::problem::Program<'a>,
    );

    impl<const D: usize> pulp::WithSimd for Run<'_, D> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, simd: S) {
            let run = LanesRun::<D> {
                lanes: self.0,
                block: self.1,
                first: self.2,
                program: self.3,
            };
            run.with_simd(simd)
        }
    }

    #[test]
    fn the_kernel_gives_the_same_bits_on_every_instruction_set() {
        use crate::integrate::problem::{Program, SplitLanes};
        for heavy in [false, true] {
            let mut top = Top::new([1.0, 2.0, 3.0], None, heavy.then_some([0.14, -0.21, 0.7]));
            top.set_lifted(heavy);
            let kernel = top.kernel();
            let (d, n) = (kernel.dim(), 37);
            let block: Vec<f64> = (0..d * n)
                .map(|i| (0.37 * (7 * (i / n) + 13 * (i % n)) as f64).sin())
                .collect();
            // Member 5 turns by about 1.5 rad in its first flow: the reduction path.
            let mut first: Vec<f64> = (0..n).map(|j| 0.005 + 1e-4 * j as f64).collect();
            first[5] = 3.0;
            let inner: Vec<(usize, f64)> = (1..top.flows())
                .chain((1..top.flows() - 1).rev())
                .map(|i| (i, 0.005))
                .collect();
            let program = Program {
                outer: 0,
                fused: 0.01,
                inner: &inner,
                steps: 50,
            };
            let go = |run: &dyn Fn(&mut [f64], &[f64])| {
                let mut b = block.clone();
                run(&mut b, &first);
                b.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            };
            let best = go(&|b, f| kernel.run(b, f, &program));
            let alone = go(&|b, f| {
                for j in 0..n {
                    let mut z: Vec<f64> = (0..d).map(|c| b[c * n + j]).collect();
                    kernel.run(&mut z, &f[j..j + 1], &program);
                    for (c, v) in z.into_iter().enumerate() {
                        b[c * n + j] = v;
                    }
                }
            });
            assert_eq!(best, alone, "heavy = {heavy}: a member alone");
            let scalar = go(&|b, f| match d {
                3 => with::<3>(&kernel, b, f, &program, pulp::Scalar::new()),
                _ => with::<15>(&kernel, b, f, &program, pulp::Scalar::new()),
            });
            assert_eq!(best, scalar, "heavy = {heavy}: portable scalar lanes");
            #[cfg(target_arch = "x86_64")]
            if let Some(v3) = pulp::x86::V3::try_new() {
                let avx2 = go(&|b, f| match d {
                    3 => pulp::Simd::vectorize(v3, Run::<3>(&kernel, b, f, &program)),
                    _ => pulp::Simd::vectorize(v3, Run::<15>(&kernel, b, f, &program)),
                });
                assert_eq!(best, avx2, "heavy = {heavy}: AVX2");
            }
            assert!(best.iter().all(|&x| f64::from_bits(x).is_finite()));
        }
    }

    proptest! {
        /// The Rodrigues turn of the lanes is exp(−t M̂) Γ (so3::exp), at angles up to 5 rad
        /// (the polynomials below 0.78, sin θ/θ beyond).
        #[test]
        fn the_turn_is_the_exponential(
            m in prop::array::uniform3(-2.0f64..2.0),
            g in prop::array::uniform3(-1.0f64..1.0),
            t in prop_oneof![-1e-6f64..1e-6, -0.2f64..0.2, -1.5f64..1.5],
        ) {
            let mut v = g;
            Turn::new(pulp::Scalar::new(), t, m).apply(&mut v);
            let e = crate::lie::so3::exp_unchecked(&(Vector3::from(m) * t));
            let want = e.transpose() * Vector3::from(g);
            // Both sides round: a few ulps per radian of turn.
            let turn = Vector3::from(m).norm() * t.abs();
            let bound = 8.0 * f64::EPSILON * (1.0 + turn) * (1.0 + want.norm());
            prop_assert!((Vector3::from(v) - want).norm() < bound);
        }

        /// The kick is M + τ Γ × c.
        #[test]
        fn kick_lanes_is_the_cross_product(
            m in prop::array::uniform3(-2.0f64..2.0),
            g in prop::array::uniform3(-1.0f64..1.0),
            c in prop::array::uniform3(-1.0f64..1.0),
            tau in -1.0f64..1.0,
        ) {
            let mut out = m;
            kick_lanes(pulp::Scalar::new(), tau, &mut out, g, c);
            let want = Vector3::from(m) + Vector3::from(g).cross(&Vector3::from(c)) * tau;
            prop_assert!((Vector3::from(out) - want).norm() < 1e-15);
        }
    }
}
