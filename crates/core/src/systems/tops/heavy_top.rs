//! The heavy top (000 §5.2): a rigid body with a fixed point in a uniform gravity field.
//!
//! State (M, Γ) ∈ se(3)* with M the body angular momentum and Γ = Rᵀe₃ the upward vertical seen
//! in the body; χ the unit vector from the fixed point to the centre of mass (body frame), m the
//! mass, l the distance, g gravity. Euler–Poisson equations
//!
//! Ṁ = M × Ω + mgl Γ × χ,   Γ̇ = Γ × Ω,   Ω = I⁻¹M,   Ṙ = R hat(Ω),
//!
//! Hamiltonian H = ½ M·I⁻¹M + mgl Γ·χ (the potential mgl e₃·Rχ is the height of the centre of
//! mass; the plus sign is the one for which dH/dt = mgl[Ω·(Γ × χ) + χ·(Γ × Ω)] = 0 along the
//! equations — checked numerically in the tests). Casimirs |Γ|², M·Γ; for the Lagrange top
//! (I₁ = I₂, χ = e₃) also M₃ is conserved. 000 §5.2 writes the potential term of the reduced
//! Lagrangian with Γ = R⁻¹e₃ and obtains IΩ̇ = IΩ × Ω + gΓ × X_b: the same equations with
//! mgl χ = g X_b (mass absorbed in X_b).

use super::methods::exact::{relative_attitude, ExactSplitting, FreeFlow, FreeTangent};
use super::methods::lgvi::Lgvi;
use super::top::TopWork;
use super::top::{self, top_kinds, Top};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Composition, Rk4, Splitting};
use crate::integrate::problem::Split;
use crate::integrate::space::Space;
use crate::integrate::tangent::{SplitTangent, Tangent};
use crate::integrate::{Catalog, Entry, Integrator, Problem, Properties, Stepper};
use nalgebra::{Matrix3, Vector3};

/// A heavy top with inertia I, weight parameter mgl ≥ 0 and centre-of-mass direction χ.
/// State z = (M, Γ), or (M, Γ, R) with Γ = Rᵀe₃ for the top that carries its attitude
/// ([`HeavyTop::with_attitude`]).
#[derive(Clone, Debug, PartialEq)]
pub struct HeavyTop {
    pub(crate) top: Top,
    mgl: f64,
    /// Unit χ in the user's body frame.
    chi: Vector3<f64>,
}

impl HeavyTop {
    /// A top with principal moments, mgl ≥ 0 and χ ≠ 0 (normalised to a unit vector).
    pub fn new(moments: [f64; 3], mgl: f64, chi: [f64; 3]) -> Result<Self> {
        top::check_moments(&moments)?;
        Self::build(moments, None, mgl, chi)
    }

    /// A top with a symmetric positive-definite inertia matrix (row-major), diagonalised once.
    pub fn from_matrix(inertia: &[f64; 9], mgl: f64, chi: [f64; 3]) -> Result<Self> {
        let (moments, q) = top::principal_frame(inertia)?;
        Self::build(moments, Some(q), mgl, chi)
    }

    fn build(
        moments: [f64; 3],
        frame: Option<Matrix3<f64>>,
        mgl: f64,
        chi: [f64; 3],
    ) -> Result<Self> {
        if !(mgl.is_finite() && mgl >= 0.0) {
            return Err(Error::invalid(
                "mgl",
                format!("expected a finite number ≥ 0, got {mgl}"),
            ));
        }
        check::finite_slice("chi", &chi)?;
        let chi = Vector3::from(chi);
        let norm = chi.norm();
        if norm == 0.0 {
            return Err(Error::invalid(
                "chi",
                "the centre-of-mass direction must be non-zero",
            ));
        }
        let chi = chi / norm;
        let c = top::to_frame(&frame, chi.as_slice()) * mgl;
        Ok(HeavyTop {
            top: Top::new(moments, frame, Some(c.into())),
            mgl,
            chi,
        })
    }

    /// The same top carrying its attitude R ∈ SO(3) along: state (M, Γ, R row-major).
    pub fn with_attitude(&self) -> Self {
        let mut t = self.clone();
        t.top.set_lifted(true);
        t
    }

    /// Whether the state carries the attitude.
    pub fn has_attitude(&self) -> bool {
        self.top.lifted
    }

    /// The principal moments.
    pub fn moments(&self) -> [f64; 3] {
        self.top.moments
    }

    /// mgl.
    pub fn mgl(&self) -> f64 {
        self.mgl
    }

    /// The unit vector χ (user body frame).
    pub fn chi(&self) -> [f64; 3] {
        self.chi.into()
    }

    /// A state (M, Γ).
    pub fn state(&self, m: [f64; 3], gamma: [f64; 3]) -> Vec<f64> {
        [m, gamma].concat()
    }

    /// The state (M, Rᵀe₃, R) of the top with attitude (R row-major).
    pub fn state_with_attitude(&self, m: [f64; 3], r: [f64; 9]) -> Vec<f64> {
        [&m[..], &r[6..9], &r[..]].concat()
    }
}

impl HeavyTop {
    /// Parameter m (`I1`, `I2`, `I3`, `mgl`, `chi1`, `chi2`, `chi3`) as the kernels see it:
    /// ∂c/∂mgl = χ, ∂c/∂χ_j = mgl e_j (principal frame).
    pub(crate) fn top_parameter(&self, m: usize) -> top::TopParam {
        match m {
            0..=2 => top::TopParam::Moment(m),
            3 => top::TopParam::Gravity(top::to_frame(&self.top.frame, self.chi.as_slice())),
            _ => {
                let mut e = Vector3::zeros();
                e[m - 4] = self.mgl;
                top::TopParam::Gravity(top::to_frame(&self.top.frame, e.as_slice()))
            }
        }
    }
}

impl Problem for HeavyTop {
    fn name(&self) -> &'static str {
        "HeavyTop"
    }

    /// The principal moments I1, I2, I3 (as for `RigidBody`), mgl, and the components of the
    /// unit vector χ (body frame; a derivative along them, not along an unnormalised χ).
    fn parameters(&self) -> Vec<&'static str> {
        vec!["I1", "I2", "I3", "mgl", "chi1", "chi2", "chi3"]
    }
    fn space(&self) -> Space {
        self.top.space()
    }
    /// H = ½ M·I⁻¹M + mgl Γ·χ.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let t = self.top.kinetic_energy(&z[..3]);
        Ok(t + self.mgl * Vector3::from_column_slice(&z[3..6]).dot(&self.chi))
    }
    /// The larger of |Ω| and the small-swing pendulum frequency √(mgl|Γ|/I_min).
    fn rate(&self, z: &[f64]) -> Option<f64> {
        let gamma = Vector3::from_column_slice(&z[3..6]).norm();
        let smallest = self
            .top
            .moments
            .iter()
            .fold(f64::INFINITY, |m, &i| m.min(i));
        Some(
            self.top
                .rate(&z[..3])
                .max((self.mgl * gamma / smallest).sqrt()),
        )
    }
    /// [|Γ|², M·Γ].
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let m = Vector3::from_column_slice(&z[..3]);
        let g = Vector3::from_column_slice(&z[3..6]);
        Ok(vec![g.norm_squared(), m.dot(&g)])
    }
    fn invariant_names(&self) -> Vec<String> {
        vec!["|Γ|²".into(), "M·Γ".into()]
    }
    /// Γ ≠ 0 (the vertical seen in the body; its length is a Casimir, and scaling it scales
    /// mgl), and with the attitude Γ must equal Rᵀe₃ (to 1e-9).
    fn check_state(&self, z: &[f64]) -> Result<()> {
        if z[3..6].iter().all(|&g| g == 0.0) {
            return Err(Error::invalid(
                "state (Gamma)",
                "Γ = 0 has no direction: expected the vertical seen in the body, Rᵀe₃ (a unit \
                 vector; its length only scales mgl)",
            ));
        }
        if self.top.lifted {
            let d = (0..3)
                .map(|i| (z[12 + i] - z[3 + i]).powi(2))
                .sum::<f64>()
                .sqrt();
            if d > 1e-9 {
                return Err(Error::invalid(
                    "state",
                    format!("Γ must equal Rᵀe₃ (third row of R) when the attitude is given; |Γ − Rᵀe₃| = {d:.3e}"),
                ));
            }
        }
        Ok(())
    }
    fn to_internal(&self, z: &mut [f64]) {
        self.top.to_internal(z)
    }
    fn to_user(&self, z: &mut [f64]) {
        self.top.to_user(z)
    }
    fn tangent_to_internal(&self, dz: &mut [f64]) {
        self.top.tangent_frame(dz, false)
    }
    fn tangent_to_user(&self, dz: &mut [f64]) {
        self.top.tangent_frame(dz, true)
    }
}

top_kinds!(HeavyTop; ;
    "exact_splitting" => || ExactSplitting(Composition::strang()),
    "exact_splitting4" => || ExactSplitting(Composition::suzuki4()),
    "exact_splitting6" => || ExactSplitting(Composition::yoshida6()));

impl Catalog for HeavyTop {
    fn kind_catalog() -> Vec<Entry<Self>> {
        let mut catalog = top::splittings();
        catalog.extend([
            Entry::new("lgvi", || Lgvi),
            Entry::new("rk4", || Rk4),
            Entry::new("exact_splitting", || ExactSplitting(Composition::strang())),
            Entry::new(
                "exact_splitting4",
                || ExactSplitting(Composition::suzuki4()),
            ),
            Entry::new("exact_splitting6", || {
                ExactSplitting(Composition::yoshida6())
            }),
        ]);
        catalog
    }

    fn lifted(&self) -> Option<Self> {
        Some(self.with_attitude())
    }

    /// The tangent lift of the splittings and lgvi (and, without the attitude, rk4); with the attitude
    /// its directions are left-trivialised (δR = Rξ̂).
    fn tangent(&self) -> Option<std::sync::Arc<dyn crate::integrate::tangent::TangentSystem>> {
        Some(crate::integrate::tangent::Tangent::split(self.clone()).into_system())
    }

    /// With the attitude, `rk4` on the field lift (ambient directions).
    fn tangent_for(
        &self,
        method: &str,
    ) -> Option<std::sync::Arc<dyn crate::integrate::tangent::TangentSystem>> {
        crate::integrate::tangent::Tangent::routed(self, method, || self.tangent())
    }
}

impl Integrator<HeavyTop> for ExactSplitting {
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, problem: &HeavyTop, dt: f64) -> Result<Box<dyn Stepper>> {
        Splitting(self.0.clone()).stepper(&FreeKick(problem.clone()), dt)
    }
}

/// The exact splittings on the tangent lift: the same composition of the lifted flows
/// (`FreeKick`'s [`SplitTangent`]).
impl Integrator<Tangent<HeavyTop>> for ExactSplitting {
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, lift: &Tangent<HeavyTop>, dt: f64) -> Result<Box<dyn Stepper>> {
        Splitting(self.0.clone()).stepper(&Tangent::split(FreeKick(lift.problem().clone())), dt)
    }
}

/// The heavy top as a [`Split`] problem of two flows: 0 the kick of V, 1 the exact free flow.
#[derive(Clone, Debug)]
struct FreeKick(HeavyTop);

impl Problem for FreeKick {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn space(&self) -> Space {
        self.0.space()
    }
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.0.energy(z)
    }
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.0.invariants(z)
    }
    fn invariant_names(&self) -> Vec<String> {
        self.0.invariant_names()
    }
    fn parameters(&self) -> Vec<&'static str> {
        self.0.parameters()
    }
}

/// The kick's tangent map is the top's; the free flow's (δM, δΓ, ξ) ↦ (δM(τ), S(τ)ᵀδΓ − σ × Γ(τ),
/// S(τ)ᵀξ + σ) with δM(τ) and σ (δS = Sσ̂) from the exact flow's tangent map
/// ([`FreeTangent`]; Γ(τ) = S(τ)ᵀΓ₀, R(τ) = R S(τ)); the moments' columns add ∂M(τ)/∂I_q and
/// their σ.
impl SplitTangent for FreeKick {
    fn flow_tangent(
        &self,
        i: usize,
        tau: f64,
        before: &TopWork,
        after: &TopWork,
        dirs: &mut [f64],
    ) {
        let top = &self.0.top;
        if i == 0 {
            if let Some(k) = top.kick_index() {
                top.flow_tangent(k, tau, before, after, dirs);
            }
            return;
        }
        let flow = FreeFlow::new(&top.moments, &before.m);
        let ft = FreeTangent::of(&flow, &top.moments, tau);
        let e = top.xi_at() + if top.lifted { 3 } else { 0 };
        for dy in dirs.chunks_exact_mut(e) {
            let (dm, sigma) = ft.apply(&Vector3::from_column_slice(&dy[..3]), None);
            self.free_direction(&ft.s, after, dm, sigma, false, dy);
        }
    }

    fn flow_parameter(
        &self,
        i: usize,
        tau: f64,
        before: &TopWork,
        after: &TopWork,
        m: usize,
        dz: &mut [f64],
    ) {
        let top = &self.0.top;
        match (i, self.0.top_parameter(m)) {
            (0, p) => {
                if let Some(k) = top.kick_index() {
                    top.flow_parameter(k, tau, before, after, p, dz);
                }
            }
            (_, top::TopParam::Moment(q)) => {
                let flow = FreeFlow::new(&top.moments, &before.m);
                let ft = FreeTangent::of(&flow, &top.moments, tau);
                let (dm, sigma) = ft.apply(&Vector3::zeros(), Some(q));
                self.free_direction(&ft.s, after, dm, sigma, true, dz);
            }
            _ => {}
        }
    }
}

impl FreeKick {
    /// dy ← (δM, SᵀδΓ − σ × Γ′, Sᵀξ + σ) for a direction dy (δM from the tangent map), or with
    /// `add` (a moment's column, whose own δM₀, δΓ, ξ are carried by the state part)
    /// dy += (δM, −σ × Γ′, σ).
    fn free_direction(
        &self,
        s: &Matrix3<f64>,
        after: &TopWork,
        dm: Vector3<f64>,
        sigma: Vector3<f64>,
        add: bool,
        dy: &mut [f64],
    ) {
        let top = &self.0.top;
        let x = top.lifted.then(|| top.xi_at());
        let part = |at: usize| match add {
            true => Vector3::zeros(),
            false => s.transpose() * Vector3::from_column_slice(&dy[at..at + 3]),
        };
        let dg = part(3) - sigma.cross(&after.g.unwrap_or_else(Vector3::zeros));
        let xi = x.map(|x| part(x) + sigma);
        let keep = if add { 1.0 } else { 0.0 };
        let blocks = [(0, Some(dm)), (3, Some(dg)), (x.unwrap_or(0), xi)];
        for (at, v) in blocks {
            if let Some(v) = v {
                for c in 0..3 {
                    dy[at + c] = keep * dy[at + c] + v[c];
                }
            }
        }
    }
}

impl Split for FreeKick {
    type Work = TopWork;
    fn load(&self, z: &[f64]) -> Result<TopWork> {
        Ok(self.0.top.load(z))
    }
    fn store(&self, w: &TopWork, z: &mut [f64]) {
        self.0.top.store(w, z)
    }
    fn flows(&self) -> usize {
        2
    }
    #[inline]
    fn flow(&self, i: usize, tau: f64, w: &mut TopWork) {
        if i == 0 {
            self.0.top.kick(tau, w);
            return;
        }
        // M(τ) = S(τ)ᵀM₀ (R M conserved) rather than the elliptic formula for M: a rotation of
        // M₀, so |M| and M·Γ keep their values to the rounding of an orthogonal product, with no
        // bias from the amplitudes' rounding repeated in every step; R S row by row (rows
        // r ↦ Sᵀr). The closed forms act by increments (`Relative`).
        let s = relative_attitude(&self.0.top.moments, &w.m, tau);
        s.apply_momentum(&mut w.m);
        if let Some(g) = w.g.as_mut() {
            s.apply(g);
        }
        if let Some(r) = w.r.as_mut() {
            for i in 0..3 {
                let mut row = Vector3::new(r[(i, 0)], r[(i, 1)], r[(i, 2)]);
                s.apply(&mut row);
                for j in 0..3 {
                    r[(i, j)] = row[j];
                }
            }
        }
    }
}
