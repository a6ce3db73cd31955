//! The pseudo-rigid body as a system of the integration driver ([`crate::integrate`]).
//!
//! State layout: z = (X row-major, P row-major), length 2n². The body is three problem kinds:
//! - [`Separable`] (H = ½ tr(PᵀP) + U(X), 001 (3.22)): methods `verlet`, `verlet4`, `verlet6`
//!   ([`Verlet`] on all of T*GL⁺(n), or on all n×n matrices with `check_det` off); the force has
//!   a stack-matrix fast path at n = 3 ([`Potential::gradient3`]);
//! - [`Split`] with the flows of the reduced system on the principal stratum (001 §7,
//!   [`super::reduced`]): method `reduced`, a [`Splitting`] whose working state is the reduced
//!   one, so a run reduces (X, P) once and reconstructs only when a state is read;
//! - [`Constrained`]: the **incompressible** body ([`PseudoRigidBody::incompressible`]), a fluid
//!   or elastic ellipsoid that keeps its volume: the holonomic constraint det X = det X₀ (a level
//!   set, [`Constrained::level_set`]) whose multiplier is the pressure. G = ∂ det/∂X = cof X =
//!   det(X) X⁻ᵀ, so the hidden constraint is ⟨cof X, P⟩ = det(X) tr(X⁻¹P) = 0 (the motion keeps
//!   the volume) and the constraint force is −λ cof X. Methods `rattle` (the default, order 2),
//!   `rattle4`, `rattle6` ([`Rattle`] and its Suzuki / Yoshida compositions): symplectic on
//!   T*{det X = det X₀}, equivariant under SO(n)×SO(n), so L and Γ are kept to round-off as det X
//!   is. Verlet and the reduced flows ignore the constraint and are not offered. For a body that
//!   is not incompressible, the constraint set is empty (m = 0).
//!
//! ```
//! use std::sync::Arc;
//! use lieflow::integrate::{integrate, Problem};
//! use lieflow::pseudo_rigid::potential::Harmonic;
//! use lieflow::pseudo_rigid::system::PseudoRigidBody;
//! use lieflow::Mat;
//! let body = PseudoRigidBody::new(3, Arc::new(Harmonic::new(1.0)?), true)?;
//! let x0 = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + 0.2 * i as f64 } else { 0.0 });
//! let p0 = Mat::from_fn(3, 3, |i, j| 0.1 * (i as f64 - j as f64));
//! let traj = integrate(&body, "verlet4", &body.state(&x0, &p0)?, 1e-2, 100, 10)?;
//! let (e0, e1) = (body.energy(traj.state(0))?, body.energy(traj.state(10))?);
//! assert!((e1 - e0).abs() < 1e-8);
//! # Ok::<(), lieflow::Error>(())
//! ```
//!
//! The incompressible body, from a momentum projected onto the hidden constraint:
//!
//! ```
//! use std::sync::Arc;
//! use lieflow::integrate::integrate;
//! use lieflow::pseudo_rigid::potential::SaintVenantKirchhoff;
//! use lieflow::pseudo_rigid::system::PseudoRigidBody;
//! use lieflow::Mat;
//! let body = PseudoRigidBody::incompressible(3, Arc::new(SaintVenantKirchhoff::new(1.0, 2.0)?))?;
//! let x0 = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + 0.2 * i as f64 } else { 0.05 });
//! let p0 = body.project_momentum(&x0, &Mat::from_fn(3, 3, |i, j| 0.1 * (i + 2 * j) as f64))?;
//! let traj = integrate(&body, "rattle4", &body.state(&x0, &p0)?, 1e-2, 100, 100)?;
//! let (d0, d1) = (x0.determinant(), body.split(traj.state(1))?.0.determinant());
//! assert!((d1 - d0).abs() < 1e-13 * d0);
//! # Ok::<(), lieflow::Error>(())
//! ```

use std::sync::Arc;

use super::dynamics::FullBody;
use super::momentum::momentum_map_scaled;
use super::potential::{self, Potential, Workspace};
use super::reduced::ReducedWork;
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Rattle, Splitting, Verlet};
use crate::integrate::problem::{Constrained, Separable, Split, Symmetric, Violation};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{SeparableTangent, SplitTangent, Tangent, TangentSystem};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::gl;
use crate::lie::so::{self, spectral_invariants, spectral_names};
use crate::numerics::linalg;
use crate::Mat;
use faer::{Accum, MatMut, MatRef};
use nalgebra::Matrix3;

/// Relative tolerance of the hidden constraint ⟨cof X, P⟩ = 0 of an incompressible body's state,
/// relative to ‖cof X‖_F ‖P‖_F.
pub const VOLUME_RATE_TOL: f64 = 1e-10;

/// A generalized pseudo-rigid body H = ½ tr(PᵀP) + U(X) (001 (3.22)) for the integration
/// driver, with state z = (X, P) row-major; optionally incompressible (det X = det X₀).
#[derive(Debug, Clone)]
pub struct PseudoRigidBody {
    body: FullBody,
    /// Whether det X > 0 is enforced (asked for, or required by the potential).
    check_det: bool,
    /// Whether the volume is held: det X = det X₀ (a holonomic constraint, RATTLE).
    incompressible: bool,
}

impl PseudoRigidBody {
    /// A body in n ≥ 2 dimensions with potential U. `check_det`: stop with
    /// [`Error::LeftDomain`] when det X ≤ 0 (always on for potentials defined only on GL⁺(n)).
    pub fn new(n: usize, potential: Arc<dyn Potential>, check_det: bool) -> Result<Self> {
        Ok(PseudoRigidBody {
            check_det: check_det || potential.needs_positive_det(),
            body: FullBody::new(n, potential)?,
            incompressible: false,
        })
    }

    /// The incompressible body in n ≥ 2 dimensions with potential U: H = ½ tr(PᵀP) + U(X) on
    /// T*{det X = det X₀} (the volume of the ellipsoid X(ball) is that of the initial state; the
    /// pressure is the multiplier of the constraint). det X > 0 is checked. Its states must
    /// satisfy the hidden constraint ⟨cof X, P⟩ = 0 ([`PseudoRigidBody::project_momentum`]);
    /// methods `rattle` (default), `rattle4`, `rattle6`.
    pub fn incompressible(n: usize, potential: Arc<dyn Potential>) -> Result<Self> {
        let mut body = Self::new(n, potential, true)?;
        body.incompressible = true;
        Ok(body)
    }

    /// Whether the body is incompressible (det X = det X₀ held by RATTLE).
    pub fn is_incompressible(&self) -> bool {
        self.incompressible
    }

    /// The projection of a momentum P onto the hidden constraint of the incompressible body at
    /// X ∈ GL⁺(n): P − κ cof X with κ = ⟨cof X, P⟩/‖cof X‖_F² (the orthogonal projection onto
    /// {⟨cof X, P⟩ = 0} = {tr(X⁻¹P) = 0}, the velocities that keep det X). Checked: n×n,
    /// finite, det X > 0. Computed from cof X scaled to unit size, so it holds at every scale.
    pub fn project_momentum(&self, x: &Mat, p: &Mat) -> Result<Mat> {
        let n = self.n();
        check::square_of("X", x, n)?;
        check::square_of("P", p, n)?;
        check::finite_mat("X", x)?;
        check::finite_mat("P", p)?;
        gl::check_gl_plus("X", x)?;
        let c = unit_cofactor(x);
        let c2 = linalg::frob2(c.as_ref());
        let mut out = p.clone();
        // Twice: the second pass removes the round-off of the first.
        for _ in 0..2 {
            let k = linalg::inner(c.as_ref(), out.as_ref()) / c2;
            linalg::axpy(out.as_mut(), -k, c.as_ref());
        }
        check::finite_mat("P", &out)
            .map_err(|_| check::overflow_error("P", "the projected momentum"))?;
        Ok(out)
    }

    /// |⟨cof X, P⟩| / (‖cof X‖_F ‖P‖_F) (0 for P = 0): the relative violation of the hidden
    /// constraint of the incompressible body, scale-free.
    fn volume_rate(x: &Mat, p: &Mat) -> f64 {
        let c = unit_cofactor(x);
        let e = check::pow2_floor(check::max_abs(p));
        let p = check::ldexp_mat(p, -e);
        let pn = linalg::frob2(p.as_ref()).sqrt();
        if pn == 0.0 {
            return 0.0;
        }
        linalg::inner(c.as_ref(), p.as_ref()).abs() / (linalg::frob2(c.as_ref()).sqrt() * pn)
    }

    /// The underlying [`FullBody`] (vector fields, Hamiltonian).
    pub fn full(&self) -> &FullBody {
        &self.body
    }

    /// The dimension n.
    pub fn n(&self) -> usize {
        self.body.n()
    }

    /// Whether det X > 0 is enforced.
    pub fn check_det(&self) -> bool {
        self.check_det
    }

    /// The flat state z = (X, P) row-major (checked: n×n, finite).
    pub fn state(&self, x: &Mat, p: &Mat) -> Result<Vec<f64>> {
        let n = self.n();
        check::square_of("X", x, n)?;
        check::square_of("P", p, n)?;
        check::finite_mat("X", x)?;
        check::finite_mat("P", p)?;
        let mut z = vec![0.0; 2 * n * n];
        write_back(n, x, p, &mut z);
        Ok(z)
    }

    /// (X, P) from a flat state (checked length).
    pub fn split(&self, z: &[f64]) -> Result<(Mat, Mat)> {
        let n = self.n();
        check::len_of("state", z, 2 * n * n)?;
        Ok(split_unchecked(n, z))
    }

    /// L = PXᵀ − XPᵀ and Γ = PᵀX − XᵀP (001 (7.3)) of a flat state.
    pub fn momenta(&self, z: &[f64]) -> Result<(Mat, Mat)> {
        let (x, p) = self.split(z)?;
        check::finite_slice("state", z)?;
        let (l, g) = momentum_map_scaled(&x, &p);
        Ok((l?, g?))
    }

    /// Singular values a₁ ≥ … ≥ aₙ of X (the semi-axes of the ellipsoid X(ball)).
    pub fn singular_values(&self, z: &[f64]) -> Result<Vec<f64>> {
        let (x, _) = self.split(z)?;
        check::finite_mat("X", &x)?;
        let s = x.singular_values().map_err(|e| Error::NotConverged {
            what: format!("SVD of X ({e:?})"),
            iterations: 0,
            residual: f64::NAN,
            tol: 0.0,
        })?;
        Ok(s)
    }
}

/// cof X divided by a positive number so that its largest |entry| is 1 (X ∈ GL⁺(n) finite): the
/// direction of ∂ det/∂X at every scale of X (X is scaled by a power of two first, which scales
/// cof X by a positive power).
fn unit_cofactor(x: &Mat) -> Mat {
    let n = x.nrows();
    let x = check::ldexp_mat(x, -check::pow2_floor(check::max_abs(x)));
    let mut c = Mat::zeros(n, n);
    potential::det_cofactor(x.as_ref(), c.as_mut(), &mut Workspace::new(n));
    let m = check::max_abs(&c);
    if m > 0.0 && m.is_finite() {
        c *= faer::Scale(1.0 / m);
    }
    c
}

fn split_unchecked(n: usize, z: &[f64]) -> (Mat, Mat) {
    let nn = n * n;
    (
        Mat::from_fn(n, n, |i, j| z[i * n + j]),
        Mat::from_fn(n, n, |i, j| z[nn + i * n + j]),
    )
}

fn write_back(n: usize, x: &Mat, p: &Mat, z: &mut [f64]) {
    let nn = n * n;
    for i in 0..n {
        for j in 0..n {
            z[i * n + j] = x[(i, j)];
            z[nn + i * n + j] = p[(i, j)];
        }
    }
}

impl Problem for PseudoRigidBody {
    fn calls_out(&self) -> bool {
        self.body.potential().calls_out()
    }
    /// The potential's constants ([`Potential::parameters`]).
    fn parameters(&self) -> Vec<&'static str> {
        self.body.potential().parameters()
    }
    fn name(&self) -> &'static str {
        "PseudoRigidBody"
    }

    fn space(&self) -> Space {
        let n = self.n();
        Space::new([("X", Block::Matrix(n)), ("P", Block::Matrix(n))])
    }

    /// H = ½ tr(PᵀP) + U(X) (001 (3.22)).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let (x, p) = self.split(z)?;
        self.body.hamiltonian(&x, &p)
    }

    /// The spectral invariants ½tr((LᵀL)^k) then ½tr((ΓᵀΓ)^k), k = 1…⌊n/2⌋: they fix the
    /// coadjoint orbits of p_Ω = RᵀLR and p_Λ = SᵀΓS (the Casimirs of the reduced space, 001 §7);
    /// for the incompressible body then det X (the volume, held by the constraint).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let (l, g) = self.momenta(z)?;
        let mut c = spectral_invariants(&l);
        c.extend(spectral_invariants(&g));
        if self.incompressible {
            let (x, _) = split_unchecked(self.n(), z);
            c.push(x.determinant());
        }
        Ok(c)
    }

    fn invariant_names(&self) -> Vec<String> {
        let mut names = spectral_names("L", self.n());
        names.extend(spectral_names("Γ", self.n()));
        if self.incompressible {
            names.push("det X".into());
        }
        names
    }

    fn symmetry(&self) -> Option<&dyn Symmetric> {
        Some(self)
    }

    /// For the incompressible body, P onto the hidden constraint ⟨cof X, P⟩ = 0 (along
    /// cof X, the nearest such P); the free body has no constraint.
    fn project(&self, z: &mut [f64]) -> Result<()> {
        if self.incompressible {
            let (x, mut p) = self.split(z)?;
            let c = unit_cofactor(&x);
            let c2 = linalg::frob2(c.as_ref());
            if c2 > 0.0 {
                let k = linalg::inner(c.as_ref(), p.as_ref()) / c2;
                p -= &c * faer::Scale(k);
                write_back(self.n(), &x, &p, z);
            }
        }
        Ok(())
    }

    /// det X > 0 when checked; for the incompressible body also the hidden constraint
    /// ⟨cof X, P⟩ = 0 to [`VOLUME_RATE_TOL`] relative to ‖cof X‖_F ‖P‖_F.
    fn check_state(&self, z: &[f64]) -> Result<()> {
        if self.check_det() {
            let (x, p) = split_unchecked(self.n(), z);
            gl::check_gl_plus("X0", &x)?;
            if self.incompressible {
                let r = Self::volume_rate(&x, &p);
                if r.is_nan() || r > VOLUME_RATE_TOL {
                    return Err(Error::invalid(
                        "state",
                        format!(
                            "an incompressible pseudo-rigid body keeps its volume det X, so its \
                             momentum must satisfy the hidden constraint ⟨cof X, P⟩ = \
                             det(X) tr(X⁻¹P) = 0; got |⟨cof X, P⟩|/(‖cof X‖‖P‖) = {r:.3e} \
                             (tolerance {VOLUME_RATE_TOL:.0e}); project P first with \
                             project_momentum(X, P) (P − κ cof X, κ = ⟨cof X, P⟩/‖cof X‖²)"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The 3×3 matrix of 9 row-major values (the n = 3 fast path), built without bounds checks.
#[inline]
fn mat3(q: &[f64]) -> Option<Matrix3<f64>> {
    let q: &[f64; 9] = q.try_into().ok()?;
    Some(Matrix3::new(
        q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8],
    ))
}

/// Scratch of the force and the constraint kernels: the potential's workspace, and two n×n
/// matrices for the curvature of det at n > 3.
#[derive(Debug)]
pub struct ForceScratch {
    ws: Workspace,
    cof: Mat,
    prod: Mat,
}

impl Separable for PseudoRigidBody {
    type Scratch = ForceScratch;

    fn scratch(&self) -> ForceScratch {
        let n = self.n();
        ForceScratch {
            ws: Workspace::new(n),
            cof: Mat::zeros(n, n),
            prod: Mat::zeros(n, n),
        }
    }

    fn dof(&self) -> usize {
        self.n() * self.n()
    }

    /// v = P (T = ½ tr(PᵀP)).
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        v.copy_from_slice(p);
    }

    /// X ← X + hP.
    fn drift(&self, q: &mut [f64], p: &[f64], h: f64, _v: &mut [f64]) {
        for (x, p) in q.iter_mut().zip(p) {
            *x += h * p;
        }
    }

    /// f = −∂U/∂X, on stack matrices at n = 3 when the potential has
    /// [`Potential::gradient3`]; a violation where det X ≤ 0 and det X is checked.
    #[inline]
    fn force(
        &self,
        q: &[f64],
        f: &mut [f64],
        s: &mut ForceScratch,
    ) -> std::result::Result<(), Violation> {
        let pot = self.body.potential();
        let check = self.check_det;
        if let (Some(x), 9) = (mat3(q), f.len()) {
            if check {
                let d = x.determinant();
                if d.is_nan() || d <= 0.0 {
                    return Err(self.left_gl_plus(d));
                }
            }
            if let Some(g) = pot.gradient3(&x) {
                // The column-major values of gᵀ are the row-major values of g; one contiguous
                // copy (vector stores, which the next kick's vector loads read back at once).
                for (fk, gk) in f.iter_mut().zip(g.transpose().as_slice()) {
                    *fk = -gk;
                }
                return Ok(());
            }
        }
        self.force_dense(q, f, s, check)
    }
}

/// The tangent lift ([`crate::integrate::tangent`]): v′ = identity, f′(X)\[V\] = −D²U(X)\[V\] (the
/// potential's Hessian, analytic for every built-in potential).
impl SeparableTangent for PseudoRigidBody {
    fn velocity_tangent(&self, _p: &[f64], dp: &[f64], dv: &mut [f64]) {
        dv.copy_from_slice(dp);
    }

    /// On stack matrices at n = 3 where the potential has [`Potential::hessian3`].
    fn force_tangent(&self, q: &[f64], dq: &[f64], df: &mut [f64], s: &mut ForceScratch) {
        let pot = self.body.potential();
        if let (Some(x), Some(v)) = (mat3(q), mat3(dq)) {
            if let Some(h) = pot.hessian3(&x, &v) {
                // Row-major values of −h are the column-major values of −hᵀ.
                for (fk, hk) in df.iter_mut().zip(h.transpose().as_slice()) {
                    *fk = -hk;
                }
                return;
            }
        }
        let n = s.ws.n();
        df.fill(0.0);
        self.body.potential().add_hessian(
            MatRef::from_row_major_slice(q, n, n),
            MatRef::from_row_major_slice(dq, n, n),
            MatMut::from_row_major_slice_mut(df, n, n),
            &mut s.ws,
        );
        df.iter_mut().for_each(|v| *v = -*v);
    }

    fn force_parameter(&self, q: &[f64], m: usize, df: &mut [f64], s: &mut ForceScratch) {
        self.add_force_parameter(q, m, df, s);
    }
}

impl PseudoRigidBody {
    /// d(force)/dθ_m = −∂(∂U/∂X)/∂θ_m added to `df` (the potential's constants).
    fn add_force_parameter(&self, q: &[f64], m: usize, df: &mut [f64], s: &mut ForceScratch) {
        let n = s.ws.n();
        for v in df.iter_mut() {
            *v = -*v;
        }
        self.body.potential().add_parameter_gradient(
            MatRef::from_row_major_slice(q, n, n),
            m,
            MatMut::from_row_major_slice_mut(df, n, n),
            &mut s.ws,
        );
        for v in df.iter_mut() {
            *v = -*v;
        }
    }
}

/// The tangent maps of the reduced flows, in the reduced coordinates while a run is loaded
/// ([`ReducedWork::tangent_in`]): the lift of method `reduced`.
impl SplitTangent for PseudoRigidBody {
    fn flow_tangent(
        &self,
        i: usize,
        tau: f64,
        before: &ReducedWork,
        _after: &ReducedWork,
        dirs: &mut [f64],
    ) {
        before.flow_tangent(i, tau, self.body.potential(), dirs);
    }

    fn directions_in(&self, w: &ReducedWork, dirs: &mut [f64]) {
        w.tangent_in(dirs);
    }

    fn directions_out(&self, w: &ReducedWork, dirs: &mut [f64]) {
        w.tangent_out(dirs);
    }

    fn flow_parameter(
        &self,
        i: usize,
        tau: f64,
        before: &ReducedWork,
        _after: &ReducedWork,
        m: usize,
        dz: &mut [f64],
    ) {
        before.flow_parameter(i, tau, self.body.potential(), m, dz);
    }
}

/// The methods of [`PseudoRigidBody`]'s catalog on its lift: Verlet's and the reduced flows for
/// the free body, RATTLE's for the incompressible one.
impl Catalog for Tangent<PseudoRigidBody> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        let mut catalog = Verlet::family();
        catalog.push(Entry::new("reduced", Splitting::strang));
        catalog
    }

    fn catalog(&self) -> Vec<Entry<Self>> {
        match self.problem().incompressible {
            true => Rattle::family(),
            false => Self::kind_catalog(),
        }
    }
}

impl PseudoRigidBody {
    /// [`Separable::force`] for any n, on views of the row-major slices (no copies).
    #[inline(never)]
    fn force_dense(
        &self,
        q: &[f64],
        f: &mut [f64],
        s: &mut ForceScratch,
        check: bool,
    ) -> std::result::Result<(), Violation> {
        let pot = self.body.potential();
        let n = s.ws.n();
        let x = MatRef::from_row_major_slice(q, n, n);
        if check {
            let d = potential::det(x, &mut s.ws);
            if d.is_nan() || d <= 0.0 {
                return Err(self.left_gl_plus(d));
            }
        }
        f.fill(0.0);
        pot.add_gradient(x, MatMut::from_row_major_slice_mut(f, n, n), &mut s.ws);
        f.iter_mut().for_each(|v| *v = -*v);
        Ok(())
    }

    /// The violation det X = d ≤ 0, with the advice that fits the potential.
    #[cold]
    fn left_gl_plus(&self, d: f64) -> Violation {
        let n = self.n();
        let advice = if self.body.potential().needs_positive_det() {
            "a volumetric potential is defined only for det X > 0, so the motion ends here"
        } else {
            "the equations extend to all n×n matrices: construct the body with check_det = false \
             to continue through det X = 0"
        };
        Violation {
            what: format!("X (pseudo-rigid body in GL+({n}))"),
            message: format!("det X = {d:.3e} ≤ 0: the motion left GL+({n}); {advice}"),
        }
    }
}

/// The incompressible body: g(X) = det X on the level set det X = det X₀ (m = 1; m = 0 for a body
/// that is not incompressible, where these kernels write nothing). No allocation.
impl Constrained for PseudoRigidBody {
    fn constraints(&self) -> usize {
        usize::from(self.incompressible)
    }

    /// det X = det X₀: the volume of the initial state.
    fn level_set(&self) -> bool {
        self.incompressible
    }

    /// g(X) = det X (closed forms for n ≤ 3, an LU above).
    fn constraint(&self, q: &[f64], g: &mut [f64], s: &mut ForceScratch) {
        if self.incompressible {
            let n = s.ws.n();
            g[0] = potential::det(MatRef::from_row_major_slice(q, n, n), &mut s.ws);
        }
    }

    /// G(X) = cof X = det(X) X⁻ᵀ row-major (closed forms for n ≤ 3: at n = 3 the columns of
    /// cof X are cross products of those of X; an LU inverse above, for X ∈ GL⁺(n)).
    fn constraint_jacobian(&self, q: &[f64], jac: &mut [f64], s: &mut ForceScratch) {
        if self.incompressible {
            let n = s.ws.n();
            potential::det_cofactor(
                MatRef::from_row_major_slice(q, n, n),
                MatMut::from_row_major_slice_mut(jac, n, n),
                &mut s.ws,
            );
        }
    }

    /// D cof(X)\[U\] at n = 3 (columns (cof X)_i = x_{i+1} × x_{i+2}, cyclic, so their
    /// derivatives u_{i+1} × x_{i+2} + x_{i+1} × u_{i+2}); polarisation elsewhere.
    fn constraint_second(
        &self,
        q: &[f64],
        u: &[f64],
        rows: &mut [f64],
        _s: &mut ForceScratch,
    ) -> bool {
        let (Some(x), Some(v), true) = (mat3(q), mat3(u), self.incompressible) else {
            return false;
        };
        for i in 0..3 {
            let (a, b) = ((i + 1) % 3, (i + 2) % 3);
            let col = v.column(a).cross(&x.column(b)) + x.column(a).cross(&v.column(b));
            for r in 0..3 {
                rows[r * 3 + i] = col[r];
            }
        }
        true
    }

    /// D³ det(X)\[U, V, ·\] at n = 3 (det is cubic: constant in X): the mixed determinant is
    /// linear in W, and its coefficient in column c is u_a × v_b + v_a × u_b with
    /// (c, a, b) cyclic (det = x_c · (x_a × x_b)).
    fn constraint_third(
        &self,
        _q: &[f64],
        u: &[f64],
        v: &[f64],
        rows: &mut [f64],
        _s: &mut ForceScratch,
    ) -> bool {
        let (Some(u), Some(v), true) = (mat3(u), mat3(v), self.incompressible) else {
            return false;
        };
        for c in 0..3 {
            let (a, b) = ((c + 1) % 3, (c + 2) % 3);
            let col = u.column(a).cross(&v.column(b)) + v.column(a).cross(&u.column(b));
            for r in 0..3 {
                rows[r * 3 + c] = col[r];
            }
        }
        true
    }

    /// D² det(X)[V, V] = d²/dε² det(X + εV) at ε = 0: 2 det V at n = 2; 2⟨X, cof V⟩ at n = 3
    /// (det(X + εV) = det X + ε⟨cof X, V⟩ + ε²⟨X, cof V⟩ + ε³ det V); 2 det(X) e₂(X⁻¹V) with
    /// e₂(B) = ½((tr B)² − tr B²) above, i.e. (⟨C, V⟩² − tr((CᵀV)²))/det X with C = cof X.
    fn constraint_curvature(&self, q: &[f64], v: &[f64], out: &mut [f64], s: &mut ForceScratch) {
        if !self.incompressible {
            return;
        }
        let n = s.ws.n();
        out[0] = match n {
            2 => 2.0 * (v[0] * v[3] - v[1] * v[2]),
            3 => {
                // ⟨X, cof V⟩ = Σ_i x_i · (v_{i+1} × v_{i+2}) over the columns (cyclic).
                let (x, w) = (mat3(q).unwrap_or_default(), mat3(v).unwrap_or_default());
                let mut t = 0.0;
                for i in 0..3 {
                    let (a, b) = ((i + 1) % 3, (i + 2) % 3);
                    t += x.column(i).dot(&w.column(a).cross(&w.column(b)));
                }
                2.0 * t
            }
            _ => {
                let (x, w) = (
                    MatRef::from_row_major_slice(q, n, n),
                    MatRef::from_row_major_slice(v, n, n),
                );
                let d = potential::det_cofactor(x, s.cof.as_mut(), &mut s.ws);
                let tr = linalg::inner(s.cof.as_ref(), w);
                linalg::mul(s.prod.as_mut(), Accum::Replace, s.cof.transpose(), w, 1.0);
                let m = &s.prod;
                let mut tr2 = 0.0;
                for i in 0..n {
                    for j in 0..n {
                        tr2 += m[(i, j)] * m[(j, i)];
                    }
                }
                (tr * tr - tr2) / d
            }
        };
    }
}

/// The flows of the reduced system on the principal stratum (001 §7, [`super::reduced`]).
impl Split for PseudoRigidBody {
    type Work = ReducedWork;

    fn load(&self, z: &[f64]) -> Result<ReducedWork> {
        let (x, p) = split_unchecked(self.n(), z);
        ReducedWork::new(&x, &p)
    }

    fn store(&self, w: &ReducedWork, z: &mut [f64]) {
        let (x, p) = w.full_state();
        write_back(self.n(), &x, &p, z);
    }

    fn flows(&self) -> usize {
        ReducedWork::flows(self.n())
    }

    fn flow(&self, i: usize, tau: f64, w: &mut ReducedWork) {
        w.flow(i, tau, self.body.potential());
    }

    const CHECKED: bool = true;

    fn check_step(&self, w: &mut ReducedWork) -> std::result::Result<(), Violation> {
        w.check_step()
    }
}

/// The two-sided action (X, P) ↦ (gXhᵀ, gPhᵀ) of SO(n)×SO(n), the cotangent lift of X ↦ gXhᵀ
/// (001 (6.1)); an element of the algebra is ξ ⊕ η in e_ij coordinates, ξ block first.
impl Symmetric for PseudoRigidBody {
    fn symmetry_dim(&self) -> usize {
        2 * so::dim(self.n())
    }

    /// J = L ⊕ Γ (001 (7.3)) in e_ij coordinates: ⟨J, ξ ⊕ η⟩ = tr(Pᵀ(ξX − Xη)).
    fn momentum_map(&self, z: &[f64]) -> Result<Vec<f64>> {
        let (l, g) = self.momenta(z)?;
        let mut j = so::vee_n_unchecked(&l);
        j.extend(so::vee_n_unchecked(&g));
        Ok(j)
    }

    /// (ξX − Xη, ξP − Pη), the velocity of t ↦ (e^{tξ} X e^{−tη}, e^{tξ} P e^{−tη}).
    fn generator(&self, xi: &[f64], z: &[f64]) -> Result<Vec<f64>> {
        let n = self.n();
        let d = so::dim(n);
        check::len_of("xi ⊕ eta", xi, 2 * d)?;
        check::finite_slice("xi ⊕ eta", xi)?;
        let (x, p) = self.split(z)?;
        let (a, b) = (
            so::hat_n_unchecked(n, &xi[..d]),
            so::hat_n_unchecked(n, &xi[d..]),
        );
        let mut out = vec![0.0; 2 * n * n];
        write_back(n, &(&a * &x - &x * &b), &(&a * &p - &p * &b), &mut out);
        Ok(out)
    }

    /// (e^ξ X e^{−η}, e^ξ P e^{−η}).
    fn act(&self, xi: &[f64], z: &[f64]) -> Result<Vec<f64>> {
        let n = self.n();
        let d = so::dim(n);
        check::len_of("xi ⊕ eta", xi, 2 * d)?;
        check::finite_slice("xi ⊕ eta", xi)?;
        let (x, p) = self.split(z)?;
        let g = so::exp(&so::hat_n_unchecked(n, &xi[..d]))?;
        let h = so::exp(&so::hat_n_unchecked(n, &xi[d..]))?;
        let mut out = vec![0.0; 2 * n * n];
        write_back(
            n,
            &(&g * &x * h.transpose()),
            &(&g * &p * h.transpose()),
            &mut out,
        );
        Ok(out)
    }
}

/// `verlet` (default), `verlet4`, `verlet6`, `reduced`; for the incompressible body `rattle`
/// (default, as `verlet` is for the free one), `rattle4`, `rattle6` only (Verlet and the reduced
/// flows would ignore the constraint).
impl Catalog for PseudoRigidBody {
    /// The free body's.
    fn kind_catalog() -> Vec<Entry<Self>> {
        let mut catalog = Verlet::family();
        catalog.push(Entry::new("reduced", Splitting::strang));
        catalog
    }

    fn catalog(&self) -> Vec<Entry<Self>> {
        match self.incompressible {
            true => Rattle::family(),
            false => Self::kind_catalog(),
        }
    }

    /// The tangent lift of the Verlet methods and the reduced flows (the free body) or of
    /// RATTLE's (the incompressible one).
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        Some(Tangent::separable(self.clone()).into_system())
    }
}
