//! The tangent Euler top on a three-dimensional space form (002 §V): a rigid body whose centre x
//! moves on ℝ³, S³(r) or H³(r) ([`SpaceForm`]) and whose axes are an orthonormal frame tangent
//! there, with L = ½ m g(ẋ, ẋ) + ½ ω·𝕀ω, ω the angular velocity relative to parallel transport
//! and 𝕀 the body's inertia tensor (for a mass distribution with Euler tensor E, 𝕀 = tr(E)1 − E;
//! 002 writes the rotational energy through E).
//!
//! # A left-invariant system on the frame bundle (derived again)
//! The frame bundle is the isometry group G (SE(3), SO(4), SO⁺(1,3); [`super::space_form`]) and
//! g⁻¹ġ = ξ(Ω, v) with Ω = ω and v the body velocity, so L = ℓ(ξ) = ½ m|v|² + ½ Ω·𝕀Ω is
//! left-invariant: the isometries act on frames and keep it. Its momenta μ = (Π, P) = (𝕀Ω, m v)
//! obey the Lie–Poisson (Euler–Poincaré) equations of the bracket of g_κ:
//!
//! Π̇ = Π × Ω (the P × v term vanishes, P ∥ v),  Ṗ = P × Ω + (κ/m) Π × P,  ġ = g ξ̂,
//!
//! i.e. the spin obeys the free Euler equations exactly and, in space, is parallel transported,
//! while the centre feels the force m Dẋ/dt = κ s × ẋ (s the spin vector): the form (122) takes
//! for constant curvature, orthogonal to ẋ, so T = |P|²/2m is conserved and so is H − T, the
//! integral 002 §V names.
//!
//! # Integrals (measured in the tests)
//! The Casimirs of g_κ* C₁ = Π·P and C₂ = |P|² + κ|Π|²; T and H − T; the six Killing momenta
//! J = Ad*_{g⁻¹}μ (the spatial momentum: on S³ and H³ the bivector K = g M gᵀ =
//! m(ẋxᵀ − xẋᵀ) + eΠ̂eᵀ, M = [[0, −ℓPᵀ], [ℓP, Π̂]]; on ℝ³ p = mẋ and L = m x × ẋ + RΠ). H, T, C₁, C₂
//! and any one Cartan pair of the Killing momenta (a rotation and the translation or boost along
//! its axis) are six integrals in involution, independent at generic points: the top on each space
//! form is Liouville integrable, as 002 §V claims for n = 3 (its list of integrals holds as stated
//! only on ℝ³ and with the spin RΠ for "the angular momentum"; on S³ and H³ the sixth integral is
//! Π·P). For n > 3 the counting argument of §V is not the obstruction: the same reduction makes the
//! top on a space form integrable exactly when the n-dimensional free rigid body is (Manakov's,
//! for an inertia from a mass distribution), see the user guide.
//!
//! # The exact flow
//! H = C₂/2m + ½Π·(𝕀⁻¹ − κ/m)Π. T = C₂/2m − (κ/2m)|Π|² Poisson-commutes with the rotational energy
//! E = ½Π·𝕀⁻¹Π (|Π|² is a Casimir of so(3)), and both flows are exact:
//! - T over τ: g ← g exp(τ ξ_C) diag(1, exp(−τκ′Π̂)), P ← exp(τκ′Π̂) P, Π fixed, with
//!   ξ_C = (κ′Π, P/m), κ′ = κ/m (the Casimir's flow exp(τξ_C), then the rotation |Π|² generates);
//! - E over τ: the free rigid body with the physical 𝕀 (elliptic functions,
//!   [`crate::systems::tops`]), its relative attitude S(τ) acting on Π and P (SᵀΠ, SᵀP) and on the
//!   frame (g ← g diag(1, S)).
//!
//! Method `exact` composes the two. `splitting`, `splitting4`, `splitting6` split E further into
//! the three axis rotations (the rigid body's Lie–Poisson splitting, T as the outer flow): their
//! error is exactly that rigid-body splitting's, since T commutes with every piece. All of them
//! are left-equivariant, so the Killing momenta, C₁, C₂ and T are kept to round-off. `rk4`
//! integrates the Lie–Poisson field as a baseline.
//!
//! On S³ the top is the left-invariant rigid body on SO(4) with ℓ(ξ) = ½⟨ξ, 𝕁ξ⟩,
//! ⟨A, B⟩ = ½tr(AᵀB) and 𝕁 = diag(m r², m r², m r², 𝕀) in the e_ij coordinates of (Ω, v)
//! ([`FrameTop::group_inertia`]): M = 𝕁ξ and Ṁ = [M, ξ].
//!
//! State z = (g row-major, 16 values; Π; P), 22 values; [`SpaceTop::state`] makes it from
//! (x, R, ẋ, ω) with R the frame relative to the reference field Ê(x). The kernels work in the
//! principal axes of 𝕀 (`to_internal`).
//!
//! # Tangent lift
//! (Issue 26.) Every method above is lifted: the splittings through their flows' tangent maps,
//! `exact` through the free body's closed-form tangent map and that of T's flow (its own
//! stepper), `rk4` through the field's derivative (`tangent.rs`).

mod riemannian;
mod tangent;

pub use riemannian::RiemannianFrameTop;

use super::space_form::SpaceForm;
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Composition, Rk4, Splitting};
use crate::integrate::problem::{indexed_names, Split, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::{Catalog, Clock, Entry, Integrator, Problem, Properties, Stepper};
use crate::lie::so3;
use crate::systems::tops::methods::exact::relative_attitude;
use crate::systems::tops::top;
use nalgebra::{Matrix3, Matrix4, Vector3};

/// The body a top carries: mass, inertia tensor and its principal axes (shared by [`FrameTop`]
/// and [`RiemannianFrameTop`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    mass: f64,
    /// Principal moments (the kernels' frame).
    moments: [f64; 3],
    /// 𝕀 = V diag(moments) Vᵀ in the user's body frame (None: diagonal already).
    axes: Option<Matrix3<f64>>,
    /// 𝕀 and 𝕀⁻¹ in the user's body frame.
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
}

impl Body {
    /// Mass m > 0 and the inertia tensor 𝕀 (3×3 row-major, symmetric positive definite).
    pub fn new(mass: f64, inertia: &[f64; 9]) -> Result<Self> {
        check::positive("mass", mass)?;
        let (moments, q) = top::principal_frame(inertia)?;
        let a = Matrix3::from_row_slice(inertia);
        let a = (a + a.transpose()) * 0.5;
        let inv = a
            .try_inverse()
            .ok_or_else(|| Error::invalid("inertia", "the inertia tensor is singular"))?;
        let diagonal = (0..3).all(|i| (0..3).all(|j| i == j || inertia[3 * i + j] == 0.0));
        Ok(Body {
            mass,
            moments,
            axes: (!diagonal).then_some(q),
            inertia: a,
            inertia_inv: inv,
        })
    }

    /// The mass m.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// The inertia tensor 𝕀 (user body frame).
    pub fn inertia(&self) -> Matrix3<f64> {
        self.inertia
    }

    /// The principal moments (the kernels' frame).
    pub(crate) fn moments(&self) -> &[f64; 3] {
        &self.moments
    }

    /// The principal axes V (𝕀 = V diag(moments) Vᵀ), None when 𝕀 is diagonal.
    pub(crate) fn axes(&self) -> Option<&Matrix3<f64>> {
        self.axes.as_ref()
    }
}

/// What both tops give (the binding reads either through it): the state from (x, R, ẋ, ω) and
/// back, and the two conserved energies. Points and velocities are ambient components on a space
/// form, chart components on a Riemannian chart.
pub trait SpaceTop: Problem {
    /// The body.
    fn body(&self) -> &Body;

    /// The number of components of a point (and of a velocity).
    fn point_dim(&self) -> usize;

    /// The flat state of the body at x with frame Ê(x)R, velocity ẋ and angular velocity ω
    /// relative to parallel transport (body frame). Checked: x in the space, ẋ tangent, R ∈
    /// SO(3), all finite.
    fn state(
        &self,
        x: &[f64],
        r: &Matrix3<f64>,
        xdot: &[f64],
        omega: &Vector3<f64>,
    ) -> Result<Vec<f64>>;

    /// x: the centre's point.
    fn position(&self, z: &[f64]) -> Result<Vec<f64>>;

    /// R: the body frame relative to the reference frame Ê(x).
    fn frame(&self, z: &[f64]) -> Result<Matrix3<f64>>;

    /// ẋ.
    fn velocity(&self, z: &[f64]) -> Result<Vec<f64>>;

    /// Π = 𝕀ω (user body frame).
    fn spin(&self, z: &[f64]) -> Result<Vector3<f64>>;

    /// T = ½ m g(ẋ, ẋ), the translational energy (conserved).
    fn translational_energy(&self, z: &[f64]) -> Result<f64>;

    /// ω = 𝕀⁻¹Π, the angular velocity relative to parallel transport (body frame).
    fn angular_velocity(&self, z: &[f64]) -> Result<Vector3<f64>> {
        Ok(self.body().inertia_inv * self.spin(z)?)
    }

    /// H − T = ½ Π·𝕀⁻¹Π, the rotational energy (conserved: 002 §V's "H − T").
    fn rotational_energy(&self, z: &[f64]) -> Result<f64> {
        let pi = self.spin(z)?;
        Ok(0.5 * pi.dot(&(self.body().inertia_inv * pi)))
    }
}

/// The tangent Euler top on a three-dimensional space form (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameTop {
    space: SpaceForm,
    body: Body,
}

/// The working state of the kernels (principal frame): the frame g and the momenta (Π, P).
#[derive(Clone, Copy, Debug)]
pub struct FrameWork {
    g: Matrix4<f64>,
    pi: Vector3<f64>,
    p: Vector3<f64>,
}

impl FrameTop {
    /// A top of mass m > 0 with the inertia tensor 𝕀 (3×3 row-major, symmetric positive
    /// definite) on `space`.
    pub fn new(space: SpaceForm, mass: f64, inertia: &[f64; 9]) -> Result<Self> {
        Ok(FrameTop {
            space,
            body: Body::new(mass, inertia)?,
        })
    }

    /// The space form.
    pub fn space(&self) -> SpaceForm {
        self.space
    }

    fn split(&self, z: &[f64]) -> Result<(Matrix4<f64>, Vector3<f64>, Vector3<f64>)> {
        check::len_of("state", z, 22)?;
        check::finite_slice("state", z)?;
        Ok(unflat(z))
    }

    /// (C₁, C₂) = (Π·P, |P|² + κ|Π|²), the Casimirs of g_κ*.
    pub fn casimirs(&self, z: &[f64]) -> Result<[f64; 2]> {
        let (_, pi, p) = self.split(z)?;
        Ok([
            pi.dot(&p),
            p.norm_squared() + self.space.curvature() * pi.norm_squared(),
        ])
    }

    /// The six Killing momenta (J_Π, J_P) = Ad*_{g⁻¹}(Π, P) (module docs): on S³ and H³ the
    /// momenta of the rotations about the axes of the base point's tangent space and of the
    /// translations (boosts) along them, K = [[0, −ℓJ_Pᵀ], [ℓJ_P, Ĵ_Π]] = g M gᵀ; on ℝ³ the total
    /// angular momentum about the origin L = x × p + RΠ and the momentum p = mẋ.
    pub fn killing_momenta(&self, z: &[f64]) -> Result<[f64; 6]> {
        let (g, pi, p) = self.split(z)?;
        let (jp, jq) = match self.space {
            SpaceForm::Euclidean => {
                let r = g.fixed_view::<3, 3>(1, 1).into_owned();
                let x = g.fixed_view::<3, 1>(1, 0).into_owned();
                let lin = r * p;
                (x.cross(&lin) + r * pi, lin)
            }
            _ => {
                let k = g * self.body_bivector(&pi, &p) * g.transpose();
                let l = self.space.length();
                (
                    Vector3::new(k[(3, 2)], k[(1, 3)], k[(2, 1)]),
                    Vector3::new(k[(1, 0)], k[(2, 0)], k[(3, 0)]) / l,
                )
            }
        };
        Ok([jp[0], jp[1], jp[2], jq[0], jq[1], jq[2]])
    }

    /// M = [[0, −ℓPᵀ], [ℓP, Π̂]]: on S³ the so(4) body momentum of the frame g (module docs).
    fn body_bivector(&self, pi: &Vector3<f64>, p: &Vector3<f64>) -> Matrix4<f64> {
        let l = self.space.length();
        let mut m = Matrix4::zeros();
        m.fixed_view_mut::<3, 3>(1, 1).copy_from(&so3::hat(pi));
        for i in 0..3 {
            m[(i + 1, 0)] = l * p[i];
            m[(0, i + 1)] = -l * p[i];
        }
        m
    }

    /// On S³: the so(4) body momentum M = [[0, −rPᵀ], [rP, Π̂]] of g ∈ SO(4) (whose first column
    /// is x/r), with Ṁ = [M, ξ] for ξ = g⁻¹ġ and the pairing ⟨M, ξ⟩ = ½ tr(Mᵀξ). An error on the
    /// other spaces.
    pub fn group_momentum(&self, z: &[f64]) -> Result<Matrix4<f64>> {
        self.sphere_only("group_momentum")?;
        let (_, pi, p) = self.split(z)?;
        Ok(self.body_bivector(&pi, &p))
    }

    /// On S³: 𝕁, the 6×6 inertia of the left-invariant SO(4) top in so(4)'s e_ij coordinates
    /// (01, 02, 03, 12, 13, 23) (ℓ(ξ) = ½⟨ξ, 𝕁ξ⟩, M = 𝕁ξ): diag(m r², m r², m r²) on the
    /// translations and 𝕀 (user body frame) on the rotations, read through
    /// (ξ₁₂, ξ₁₃, ξ₂₃) = (−Ω₃, Ω₂, −Ω₁) (row-major). An error on the other spaces.
    pub fn group_inertia(&self) -> Result<[f64; 36]> {
        self.sphere_only("group_inertia")?;
        let mr2 = self.body.mass * self.space.length().powi(2);
        // The rotation coordinates c = (ξ₁₂, ξ₁₃, ξ₂₃) = B Ω with B = [[0,0,−1],[0,1,0],[−1,0,0]]
        // (B = B⁻¹ = Bᵀ): 𝕁_rot = B 𝕀 B.
        let b = Matrix3::new(0.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0);
        let rot = b * self.body.inertia * b;
        let mut j = [0.0; 36];
        for i in 0..3 {
            j[6 * i + i] = mr2;
            for k in 0..3 {
                j[6 * (i + 3) + k + 3] = rot[(i, k)];
            }
        }
        Ok(j)
    }

    fn sphere_only(&self, what: &str) -> Result<()> {
        match self.space {
            SpaceForm::Sphere { .. } => Ok(()),
            _ => Err(Error::invalid(
                "space",
                format!(
                    "{what} is the SO(4) form of the top on the 3-sphere; this top moves on {}",
                    self.space.name()
                ),
            )),
        }
    }

    // The exact flows (principal frame).

    /// T over τ (module docs).
    /// Both factors by increments (g + g(exp ξ̂ − 1), then rows turned by `so3::Rodrigues`).
    fn flow_t(&self, tau: f64, w: &mut FrameWork) {
        let kp = self.space.curvature() / self.body.mass;
        let d = self
            .space
            .expm1(&(w.pi * (tau * kp)), &(w.p * (tau / self.body.mass)));
        w.g += w.g * d;
        // g ← g diag(1, exp(−τκ′Π̂)): each row r of the frame block becomes exp(τκ′Π̂)r; and
        // P ← exp(τκ′Π̂)P.
        let turn = so3::Rodrigues::exp(&(w.pi * (tau * kp)));
        for row in 0..4 {
            let mut v = Vector3::new(w.g[(row, 1)], w.g[(row, 2)], w.g[(row, 3)]);
            turn.apply(&mut v);
            for c in 0..3 {
                w.g[(row, c + 1)] = v[c];
            }
        }
        turn.apply(&mut w.p);
    }

    /// ½Π_k²/I_k over τ: the rotation about e_k by θ = τΠ_k/I_k (Π, P by Sᵀ, the frame by S).
    fn flow_axis(&self, k: usize, tau: f64, w: &mut FrameWork) {
        // One (sin θ, cos θ − 1) for the six vectors the rotation turns.
        let (s, cm1) = crate::numerics::simd::angle_sin_cosm1(tau * w.pi[k] / self.body.moments[k]);
        top::rotate_axis_sc(&mut w.pi, k, s, cm1);
        top::rotate_axis_sc(&mut w.p, k, s, cm1);
        for row in 0..4 {
            let mut v = Vector3::new(w.g[(row, 1)], w.g[(row, 2)], w.g[(row, 3)]);
            top::rotate_axis_sc(&mut v, k, s, cm1);
            for c in 0..3 {
                w.g[(row, c + 1)] = v[c];
            }
        }
    }

    /// The free rigid body's exact flow over τ (E = ½Π·𝕀⁻¹Π).
    fn flow_rotation(&self, tau: f64, w: &mut FrameWork) {
        let rel = relative_attitude(&self.body.moments, &w.pi, tau);
        rel.apply_momentum(&mut w.pi);
        rel.apply(&mut w.p);
        for row in 0..4 {
            let mut v = Vector3::new(w.g[(row, 1)], w.g[(row, 2)], w.g[(row, 3)]);
            rel.apply(&mut v);
            for c in 0..3 {
                w.g[(row, c + 1)] = v[c];
            }
        }
    }
}

impl SpaceTop for FrameTop {
    fn body(&self) -> &Body {
        &self.body
    }

    /// 3 on ℝ³, 4 on S³ and H³ (ambient components).
    fn point_dim(&self) -> usize {
        self.space.ambient_dim()
    }

    /// The state (g, Π, P); x and ẋ ambient, ẋ tangent at x.
    fn state(
        &self,
        x: &[f64],
        r: &Matrix3<f64>,
        xdot: &[f64],
        omega: &Vector3<f64>,
    ) -> Result<Vec<f64>> {
        self.space.check_point(x)?;
        self.space.check_tangent(x, xdot)?;
        check::finite_slice("omega", omega.as_slice())?;
        so3::check_rotation("R", r)?;
        let mut d = Matrix4::identity();
        d.fixed_view_mut::<3, 3>(1, 1).copy_from(r);
        let g = self.space.reference(x) * d;
        let v = self.space.body(&g, xdot);
        Ok(flat(
            &g,
            &(self.body.inertia * omega),
            &(v * self.body.mass),
        ))
    }

    /// Ambient components.
    fn position(&self, z: &[f64]) -> Result<Vec<f64>> {
        Ok(self.space.position(&self.split(z)?.0))
    }

    fn frame(&self, z: &[f64]) -> Result<Matrix3<f64>> {
        Ok(self.space.relative_frame(&self.split(z)?.0))
    }

    /// ẋ = Σ v_i e_i (ambient components), v = P/m.
    fn velocity(&self, z: &[f64]) -> Result<Vec<f64>> {
        let (g, _, p) = self.split(z)?;
        Ok(self.space.ambient(&g, &(p / self.body.mass)))
    }

    fn spin(&self, z: &[f64]) -> Result<Vector3<f64>> {
        Ok(self.split(z)?.1)
    }

    /// |P|²/2m.
    fn translational_energy(&self, z: &[f64]) -> Result<f64> {
        Ok(self.split(z)?.2.norm_squared() / (2.0 * self.body.mass))
    }
}

/// g ← g diag(1, S).
fn turn_frame(g: &mut Matrix4<f64>, s: &Matrix3<f64>) {
    let block = g.fixed_view::<4, 3>(0, 1) * s;
    g.fixed_view_mut::<4, 3>(0, 1).copy_from(&block);
}

fn flat(g: &Matrix4<f64>, pi: &Vector3<f64>, p: &Vector3<f64>) -> Vec<f64> {
    let mut z = vec![0.0; 22];
    write(g, pi, p, &mut z);
    z
}

fn write(g: &Matrix4<f64>, pi: &Vector3<f64>, p: &Vector3<f64>, z: &mut [f64]) {
    for i in 0..4 {
        for j in 0..4 {
            z[4 * i + j] = g[(i, j)];
        }
    }
    z[16..19].copy_from_slice(pi.as_slice());
    z[19..22].copy_from_slice(p.as_slice());
}

fn unflat(z: &[f64]) -> (Matrix4<f64>, Vector3<f64>, Vector3<f64>) {
    (
        Matrix4::from_row_slice(&z[..16]),
        Vector3::from_column_slice(&z[16..19]),
        Vector3::from_column_slice(&z[19..22]),
    )
}

impl Problem for FrameTop {
    fn name(&self) -> &'static str {
        "FrameTop"
    }

    fn space(&self) -> Space {
        Space::new([
            ("g", Block::Matrix(4)),
            ("Pi", Block::Real(3)),
            ("P", Block::Real(3)),
        ])
    }

    /// H = |P|²/2m + ½Π·𝕀⁻¹Π.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        Ok(self.translational_energy(z)? + self.rotational_energy(z)?)
    }

    /// C₁, C₂, T, then the six Killing momenta.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let mut c = self.casimirs(z)?.to_vec();
        c.push(self.translational_energy(z)?);
        c.extend(self.killing_momenta(z)?);
        Ok(c)
    }

    fn invariant_names(&self) -> Vec<String> {
        let mut names = vec!["Π·P".to_string(), "|P|² + κ|Π|²".into(), "T".into()];
        let (angular, linear) = match self.space {
            SpaceForm::Euclidean => ("L", "p"),
            _ => ("J_Π", "J_P"),
        };
        names.extend(indexed_names(angular, 3));
        names.extend(indexed_names(linear, 3));
        names
    }

    /// g in the space's frame group.
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.space.check_frame("g", &unflat(z).0)
    }

    /// The principal frame of 𝕀: g ← g diag(1, V), Π ← VᵀΠ, P ← VᵀP.
    fn to_internal(&self, z: &mut [f64]) {
        if let Some(v) = &self.body.axes {
            let (mut g, pi, p) = unflat(z);
            turn_frame(&mut g, v);
            write(&g, &(v.transpose() * pi), &(v.transpose() * p), z);
        }
    }

    fn to_user(&self, z: &mut [f64]) {
        if let Some(v) = &self.body.axes {
            let (mut g, pi, p) = unflat(z);
            turn_frame(&mut g, &v.transpose());
            write(&g, &(v * pi), &(v * p), z);
        }
    }
}

/// Flows: 0–2 the axis rotations ½Π_k²/I_k, 3 the translational energy T (the middle flow: T
/// commutes with the others, so it is applied once per Strang step, over the whole step).
impl Split for FrameTop {
    type Work = FrameWork;

    fn load(&self, z: &[f64]) -> Result<FrameWork> {
        let (g, pi, p) = unflat(z);
        Ok(FrameWork { g, pi, p })
    }

    fn store(&self, w: &FrameWork, z: &mut [f64]) {
        write(&w.g, &w.pi, &w.p, z);
    }

    fn flows(&self) -> usize {
        4
    }

    fn flow(&self, i: usize, tau: f64, w: &mut FrameWork) {
        match i {
            3 => self.flow_t(tau, w),
            k => self.flow_axis(k, tau, w),
        }
    }
}

/// The Lie–Poisson field (module docs), principal frame: the baseline `rk4`.
impl VectorField for FrameTop {
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let (g, pi, p) = unflat(z);
        let omega = Vector3::from_fn(|k, _| pi[k] / self.body.moments[k]);
        let v = p / self.body.mass;
        let gd = g * self.space.hat(&omega, &v);
        let kp = self.space.curvature() / self.body.mass;
        write(
            &gd,
            &pi.cross(&omega),
            &(p.cross(&omega) + pi.cross(&p) * kp),
            dz,
        );
    }
}

/// The exact flow as a method (`exact`): each step the exact flow of T, then the free rigid
/// body's (they commute), from the state of the step before.
#[derive(Clone, Copy, Debug, Default)]
pub struct Exact;

struct ExactStepper {
    top: FrameTop,
    dt: f64,
    w: FrameWork,
}

impl Integrator<FrameTop> for Exact {
    fn properties(&self) -> Properties {
        Properties::exact()
    }

    fn stepper(&self, problem: &FrameTop, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Box::new(ExactStepper {
            top: problem.clone(),
            dt,
            w: FrameWork {
                g: Matrix4::identity(),
                pi: Vector3::zeros(),
                p: Vector3::zeros(),
            },
        }))
    }
}

impl Stepper for ExactStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.w = self.top.load(z)?;
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        self.top.store(&self.w, z);
    }

    fn advance(&mut self, steps: usize, _clock: Clock) -> Result<()> {
        for _ in 0..steps {
            self.top.flow_t(self.dt, &mut self.w);
            self.top.flow_rotation(self.dt, &mut self.w);
        }
        Ok(())
    }
}

/// `exact` (default), `splitting`, `splitting4`, `splitting6` (T and the axis rotations, Strang,
/// Suzuki 4, Yoshida 6), `rk4` (the Lie–Poisson field, a baseline that keeps nothing).
impl Catalog for FrameTop {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("exact", || Exact),
            Entry::new("splitting", Splitting::strang),
            Entry::new("splitting4", || Splitting(Composition::suzuki4())),
            Entry::new("splitting6", || Splitting(Composition::yoshida6())),
            Entry::new("rk4", || Rk4),
        ]
    }

    /// The lift of every method (module docs, "Tangent lift").
    fn tangent(&self) -> Option<std::sync::Arc<dyn crate::integrate::tangent::TangentSystem>> {
        Some(crate::integrate::tangent::Tangent::split(self.clone()).into_system())
    }
}
