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

use super::rigid_body::LgviStepper;
use super::top::{self, TopField, TopRk4, TopSplitting};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::variational::Lgvi;
use crate::integrate::{Method, State, Stepper, System};
use nalgebra::{Matrix3, Vector3};

/// A heavy top with inertia I, weight parameter mgl ≥ 0 and centre-of-mass direction χ.
#[derive(Clone, Debug, PartialEq)]
pub struct HeavyTop {
    moments: [f64; 3],
    frame: Option<Matrix3<f64>>,
    mgl: f64,
    /// Unit χ in the user's body frame.
    chi: Vector3<f64>,
    /// c = mgl χ in the principal frame.
    c: [f64; 3],
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
            moments,
            frame,
            mgl,
            chi,
            c: c.into(),
        })
    }

    /// The principal moments.
    pub fn moments(&self) -> [f64; 3] {
        self.moments
    }

    /// mgl.
    pub fn mgl(&self) -> f64 {
        self.mgl
    }

    /// The unit vector χ (user body frame).
    pub fn chi(&self) -> [f64; 3] {
        self.chi.into()
    }

    /// A state (M, Γ) without attitude.
    pub fn state(&self, m: [f64; 3], gamma: [f64; 3]) -> State {
        State::new([m, gamma].concat())
    }

    /// A state (M, Rᵀe₃) with attitude R (row-major).
    pub fn state_with_attitude(&self, m: [f64; 3], r: [f64; 9]) -> State {
        State::with_attitude([m, [r[6], r[7], r[8]]].concat(), r)
    }

    fn fields(&self) -> (TopField, TopField) {
        (
            TopField::new(self.moments, Some(self.c), false),
            TopField::new(self.moments, Some(self.c), true),
        )
    }
}

const TOP_METHODS: [Method; 5] = [
    Method::Splitting,
    Method::Splitting4,
    Method::Splitting6,
    Method::Lgvi,
    Method::Rk4,
];

impl System for HeavyTop {
    fn name(&self) -> &'static str {
        "HeavyTop"
    }
    fn dim(&self) -> usize {
        6
    }
    fn has_attitude(&self) -> bool {
        true
    }
    fn methods(&self) -> &'static [Method] {
        &TOP_METHODS
    }
    /// H = ½ M·I⁻¹M + mgl Γ·χ.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        check::len_of("state", z, 6)?;
        let t = top::kinetic_energy(&self.frame, &self.moments, &z[..3]);
        Ok(t + self.mgl * Vector3::from_column_slice(&z[3..]).dot(&self.chi))
    }
    /// [|Γ|², M·Γ].
    fn casimirs(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        let m = Vector3::from_column_slice(&z[..3]);
        let g = Vector3::from_column_slice(&z[3..]);
        Ok(vec![g.norm_squared(), m.dot(&g)])
    }
    /// With an attitude, Γ must equal Rᵀe₃ (to 1e-9).
    fn check_constraints(&self, state: &State) -> Result<()> {
        if let Some(r) = &state.attitude {
            let d = (0..3)
                .map(|i| (r[6 + i] - state.z[3 + i]).powi(2))
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
    fn to_internal(&self, state: &mut State) {
        top::state_to_frame(&self.frame, state);
    }
    fn to_user(&self, state: &mut State) {
        top::state_from_frame(&self.frame, state);
    }
    fn stepper<'a>(&'a self, method: Method, dt: f64) -> Result<Box<dyn Stepper + 'a>> {
        self.check_method(method)?;
        Ok(match method {
            Method::Lgvi => Box::new(LgviStepper(Lgvi::new(self.moments, dt, Some(self.c)))),
            Method::Rk4 => {
                let (p, f) = self.fields();
                Box::new(TopRk4::new(p, f, dt))
            }
            _ => Box::new(TopSplitting::new(self.moments, Some(self.c), method, dt)),
        })
    }
}
