use std::fmt;
use std::sync::Arc;

use super::*;
use crate::check;
use crate::error::{fmt_num, Error, Result};
use crate::integrate::hooks;
use crate::integrate::methods::{canonical_catalog, Verlet};
use crate::integrate::problem::{Canonical, Separable, Violation};
use crate::integrate::space::Space;
use crate::integrate::tangent::{
    separable_field_tangent, SeparableTangent, Tangent, VectorFieldTangent,
};
use crate::integrate::Problem;
use crate::Mat;

/// The constant kinetic mass M of a [`UserSeparable`] (T = ½ pᵀM⁻¹p).
#[derive(Clone, Debug, PartialEq)]
pub enum KineticMass {
    /// M = m·I (m > 0); the number of degrees of freedom is given separately.
    Scalar(f64),
    /// M = diag(m) (every m_i > 0).
    Diagonal(Vec<f64>),
    /// A symmetric positive-definite matrix.
    Matrix(Mat),
}

/// M⁻¹ in the form the kernels use.
#[derive(Clone, Debug, PartialEq)]
enum InverseMass {
    Scalar(f64),
    Diagonal(Vec<f64>),
    /// Row-major d×d.
    Dense(Vec<f64>),
}

impl InverseMass {
    fn apply(&self, p: &[f64], v: &mut [f64]) {
        match self {
            InverseMass::Scalar(w) => {
                for (vi, pi) in v.iter_mut().zip(p) {
                    *vi = w * pi;
                }
            }
            InverseMass::Diagonal(w) => {
                for ((vi, pi), wi) in v.iter_mut().zip(p).zip(w) {
                    *vi = wi * pi;
                }
            }
            InverseMass::Dense(w) => {
                let d = p.len();
                for (i, vi) in v.iter_mut().enumerate() {
                    *vi = (0..d).map(|j| w[i * d + j] * p[j]).sum();
                }
            }
        }
    }

    /// ½ pᵀM⁻¹p.
    fn kinetic(&self, p: &[f64]) -> f64 {
        let t = match self {
            InverseMass::Scalar(w) => w * p.iter().map(|x| x * x).sum::<f64>(),
            InverseMass::Diagonal(w) => p.iter().zip(w).map(|(x, wi)| wi * x * x).sum(),
            InverseMass::Dense(w) => {
                let d = p.len();
                (0..d)
                    .map(|i| p[i] * (0..d).map(|j| w[i * d + j] * p[j]).sum::<f64>())
                    .sum()
            }
        };
        0.5 * t
    }
}

/// A separable system H = ½ pᵀM⁻¹p + U(q) with U and ∇U given by functions (module docs); state
/// z = (q, p).
#[derive(Clone)]
pub struct UserSeparable {
    dof: usize,
    inverse: Arc<InverseMass>,
    u: ScalarFn,
    gradient: Option<GradientFn>,
    /// D²U(q)\[v\], for the tangent lift (sensitivities); none: no lift.
    hessian: Option<HessianProductFn>,
}

/// The Hessian product of a potential: (q, v, D²U(q)\[v\] out).
pub type HessianProductFn = Arc<dyn Fn(&[f64], &[f64], &mut [f64]) -> Result<()> + Send + Sync>;

impl fmt::Debug for UserSeparable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UserSeparable")
            .field("dof", &self.dof)
            .field("inverse_mass", &self.inverse)
            .field("gradient", &self.gradient.is_some())
            .field("hessian", &self.hessian.is_some())
            .finish()
    }
}

impl UserSeparable {
    /// The system with mass `mass`, potential `u` and its gradient (or `None` for finite
    /// differences); `dof` is needed for a scalar mass and must agree with a vector or matrix.
    ///
    /// Errors: a non-finite, non-positive or non-symmetric mass, or one that is not positive
    /// definite ([`Error::InvalidArgument`]); a mass of the wrong shape or a `dof` that disagrees
    /// ([`Error::Shape`]); a scalar mass without `dof`.
    pub fn new(
        mass: KineticMass,
        dof: Option<usize>,
        u: ScalarFn,
        gradient: Option<GradientFn>,
    ) -> Result<Self> {
        let (d, inverse) = match mass {
            KineticMass::Scalar(m) => {
                check::positive("mass", m)?;
                let d = dof.ok_or_else(|| {
                    Error::invalid(
                        "dof",
                        "a scalar mass needs the number of degrees of freedom (dof)",
                    )
                })?;
                (d, InverseMass::Scalar(1.0 / m))
            }
            KineticMass::Diagonal(m) => {
                for (i, &mi) in m.iter().enumerate() {
                    check::positive(&format!("mass[{i}]"), mi)?;
                }
                (
                    m.len(),
                    InverseMass::Diagonal(m.iter().map(|x| 1.0 / x).collect()),
                )
            }
            KineticMass::Matrix(m) => {
                let d = check::square("mass", &m, 1)?;
                (d, InverseMass::Dense(spd_inverse("mass", &m)?))
            }
        };
        if let Some(k) = dof {
            if k != d {
                return Err(Error::shape(
                    "mass",
                    format!("a scalar, ({k},) or ({k}, {k}) for dof = {k}"),
                    format!("a mass of {d} degrees of freedom"),
                ));
            }
        }
        check_dof("dof", d)?;
        if let InverseMass::Diagonal(w) | InverseMass::Dense(w) = &inverse {
            // 1/m of a subnormal mass overflows.
            check::finite_slice("the inverse of mass", w)?;
        }
        if let InverseMass::Scalar(w) = inverse {
            check::finite_slice("the inverse of mass", &[w])?;
        }
        Ok(UserSeparable {
            dof: d,
            inverse: Arc::new(inverse),
            u,
            gradient,
            hessian: None,
        })
    }

    /// Whether ∇U is computed by finite differences.
    pub fn finite_differences(&self) -> bool {
        self.gradient.is_none()
    }

    /// The same system with the Hessian product D²U(q)\[v\] (with an exact gradient, it makes
    /// its Verlet methods' Jacobians exact: the tangent lift, [`crate::integrate::tangent`]).
    pub fn with_hessian(mut self, hessian: HessianProductFn) -> Self {
        self.hessian = Some(hessian);
        self
    }

    /// U(q), checked finite.
    pub fn potential(&self, q: &[f64]) -> Result<f64> {
        finite_value("the potential U(q)", (self.u)(q)?)
    }

    /// ∇U(q), checked finite.
    pub fn potential_gradient(&self, q: &[f64], out: &mut [f64]) -> Result<()> {
        match &self.gradient {
            Some(g) => g(q, out)?,
            None => fd_gradient(&|y| self.potential(y), q, out)?,
        }
        finite_entries("the gradient of U", "dU/dq", out)
    }

    /// The velocity M⁻¹p.
    pub fn velocity_of(&self, p: &[f64]) -> Vec<f64> {
        let mut v = vec![0.0; p.len()];
        self.inverse.apply(p, &mut v);
        v
    }
}

/// The inverse of a symmetric positive-definite matrix (row-major), by its eigendecomposition.
fn spd_inverse(what: &str, m: &Mat) -> Result<Vec<f64>> {
    check::finite_mat(what, m)?;
    let d = m.nrows();
    let scale = check::max_abs(m);
    let asym = (0..d)
        .flat_map(|a| (0..d).map(move |b| (a, b)))
        .fold(0.0f64, |s, (a, b)| s.max((m[(a, b)] - m[(b, a)]).abs()));
    if asym > 1e-12 * scale {
        return Err(Error::invalid(
            what,
            format!("not symmetric (max |M − Mᵀ| = {asym:.3e})"),
        ));
    }
    let eig = m
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| Error::invalid(what, format!("eigendecomposition failed: {e:?}")))?;
    let vals: Vec<f64> = (0..d).map(|i| eig.S()[i]).collect();
    let (lo, hi) = vals.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    if !(lo > 0.0 && lo > 1e-14 * hi) {
        return Err(Error::invalid(
            what,
            format!(
                "not positive definite (eigenvalues from {} to {}; the smallest must be > 1e-14 of \
                 the largest)",
                fmt_num(lo),
                fmt_num(hi)
            ),
        ));
    }
    let u = eig.U();
    let mut inv = vec![0.0; d * d];
    for i in 0..d {
        for j in 0..d {
            inv[i * d + j] = (0..d).map(|k| u[(i, k)] * u[(j, k)] / vals[k]).sum();
        }
    }
    // Exactly symmetric.
    for i in 0..d {
        for j in i + 1..d {
            let s = 0.5 * (inv[i * d + j] + inv[j * d + i]);
            inv[i * d + j] = s;
            inv[j * d + i] = s;
        }
    }
    Ok(inv)
}

impl Problem for UserSeparable {
    /// H (or U) is a user function.
    fn calls_out(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "Separable"
    }
    fn space(&self) -> Space {
        qp_space(self.dof)
    }
    /// ½ pᵀM⁻¹p + U(q).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let d = self.dof;
        let h = self.inverse.kinetic(&z[d..]) + self.potential(&z[..d])?;
        finite_value("the energy", h)
    }
    /// None.
    fn invariants(&self, _z: &[f64]) -> Result<Vec<f64>> {
        Ok(Vec::new())
    }
    fn invariant_names(&self) -> Vec<String> {
        Vec::new()
    }
}

impl Separable for UserSeparable {
    type Scratch = ();
    fn scratch(&self) {}
    fn dof(&self) -> usize {
        self.dof
    }
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        self.inverse.apply(p, v);
    }
    /// f = −∇U(q); a failure of the functions is recorded (the method's step then stops the run)
    /// and reported as a violation.
    fn force(&self, q: &[f64], f: &mut [f64], _s: &mut ()) -> std::result::Result<(), Violation> {
        if hooks::call(|| self.potential_gradient(q, f)) {
            f.iter_mut().for_each(|x| *x = -*x);
            Ok(())
        } else {
            f.fill(f64::NAN);
            Err(Violation {
                what: "the gradient of U".into(),
                message: "the function failed".into(),
            })
        }
    }
}

/// v′ = M⁻¹ (linear), f′(q)\[dq\] = −D²U(q)\[dq\] from the Hessian callable (a failure recorded
/// as for the force; NaN).
impl SeparableTangent for UserSeparable {
    fn velocity_tangent(&self, _p: &[f64], dp: &[f64], dv: &mut [f64]) {
        self.inverse.apply(dp, dv);
    }

    fn force_tangent(&self, q: &[f64], dq: &[f64], df: &mut [f64], _s: &mut ()) {
        let ok = match &self.hessian {
            Some(h) => hooks::call(|| h(q, dq, df)),
            None => false,
        };
        if ok {
            df.iter_mut().for_each(|x| *x = -*x);
        } else {
            df.fill(f64::NAN);
        }
    }
}

impl VectorFieldTangent for UserSeparable {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        separable_field_tangent(self, z, dz, out, &mut ());
    }
}

/// verlet (default), verlet4, verlet6, then gauss4, gauss6, midpoint, rk4: for the system and
/// its tangent lift.
fn methods<P: Separable + crate::integrate::problem::VectorField + Clone + 'static>(
) -> Vec<crate::integrate::Entry<P>> {
    let mut entries = Verlet::family();
    entries.extend(canonical_catalog());
    entries
}

impl Canonical for UserSeparable {
    fn dof(&self) -> usize {
        self.dof
    }
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        let mut u = f64::NAN;
        hooks::call(|| self.potential(q).map(|v| u = v));
        u + self.inverse.kinetic(p)
    }
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        self.inverse.apply(p, hp);
        if !hooks::call(|| self.potential_gradient(q, hq)) {
            hq.fill(f64::NAN);
        }
    }
}

// The tangent lift (every method) where a gradient and a Hessian are given.
crate::integrate::methods::canonical_system!(UserSeparable, methods(), |s: &UserSeparable| (s
    .hessian
    .is_some()
    && s.gradient.is_some())
.then(|| Tangent::separable(s.clone()).into_system()));
