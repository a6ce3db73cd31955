//! The relativistic tangent top in 1+2 Minkowski space-time (002 (87)–(96), any I) and, for the
//! symmetric top, on the static space-time −dt² + g over a surface (002 (97)–(111)): the type,
//! its Legendre map and the kernels of both Lagrangians.

use std::sync::Arc;

use nalgebra::Vector3;

use super::lift::{self, inner, mul, DerivsT, GeoT, M2, V2};
use super::{energy, lagrangian, legendre_inverse, space, state, velocities, Derivs, Legendre};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::space::Space;
use crate::integrate::Problem;
use crate::numerics::dual::{Dual, Real};
use crate::systems::tangent_top::classical::TangentTop;
use crate::systems::tangent_top::surface::{self, inverse, Plane, Surface};

/// The relativistic tangent Euler top in 1+2 Minkowski space-time, 002 (87)–(96) (module docs):
/// L = −m/γ + ½θ̇²(𝕀γ + γ³ẋᵀK(θ)ẋ), K(θ) = R(θ) J I Jᵀ R(θ)ᵀ, physical sign (−L of 002 (90));
/// or, built by [`RelativisticTangentTop::on_surface`] (the symmetric top) or
/// [`RelativisticTangentTop::on_surface_with_moments`] (any I), the top on the static space-time
/// −dt² + g over a [`Surface`], 002 (97)–(103): L = −m/γ + ½s²(𝕀γ + γ³uᵀK(θ)u), v² = g(ẋ, ẋ),
/// s = θ̇ + α·ẋ, u the components of ẋ in the surface's orthonormal frame (for the symmetric top
/// L = −m/γ + ½𝕀s²(γ + ½γ³v²)). State z = (x¹, x², θ, p₁, p₂, p_θ); speeds v < 1 (c = 1).
#[derive(Clone, Debug)]
pub struct RelativisticTangentTop {
    mass: f64,
    /// The second-moment tensor I = ∫ξξᵀdm as (I₁₁, I₁₂, I₂₂).
    moments: [f64; 3],
    /// The spatial slice: None for the Minkowski plane in Cartesian coordinates (the closed-form
    /// kernel of 002 (90)); a surface for [`RelativisticTangentTop::on_surface`] and
    /// [`RelativisticTangentTop::on_surface_with_moments`] (the kernel of 002 (102)).
    surface: Option<Arc<dyn Surface>>,
}

/// Equal masses and moments on the same space-time: both Minkowski, or the same surface object.
impl PartialEq for RelativisticTangentTop {
    fn eq(&self, other: &Self) -> bool {
        self.mass == other.mass
            && self.moments == other.moments
            && match (&self.surface, &other.surface) {
                (None, None) => true,
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                _ => false,
            }
    }
}

impl RelativisticTangentTop {
    /// A top of mass m > 0 with second-moment tensor I = ∫ξξᵀ dm = [[i11, i12], [i12, i22]]
    /// (`moments` = (i11, i12, i22), positive semidefinite with 𝕀 = tr I > 0).
    pub fn new(mass: f64, moments: [f64; 3]) -> Result<Self> {
        check::positive("mass", mass)?;
        check::finite_slice("moments", &moments)?;
        let [a, b, c] = moments;
        if a < 0.0 || c < 0.0 || a * c - b * b < -1e-14 * (a + c).powi(2) || a + c <= 0.0 {
            return Err(Error::invalid(
                "moments",
                format!(
                    "expected a positive semidefinite second-moment tensor \
                     [[I11, I12], [I12, I22]] with positive trace, got ({a}, {b}, {c})"
                ),
            ));
        }
        Ok(RelativisticTangentTop {
            mass,
            moments,
            surface: None,
        })
    }

    /// The symmetric top, I = (𝕀/2)·Id (the seed's "2I = 𝕀" of 002 (93)); `inertia` = 𝕀 > 0.
    pub fn symmetric(mass: f64, inertia: f64) -> Result<Self> {
        check::positive("inertia", inertia)?;
        Self::new(mass, [0.5 * inertia, 0.0, 0.5 * inertia])
    }

    /// The symmetric top (I = (𝕀/2)·Id, `inertia` = 𝕀 > 0) of mass m > 0 on the static space-time
    /// ds² = −dt² + g over `surface` (002 (97)–(103), module docs); z = (x¹, x², θ, p₁, p₂, p_θ)
    /// in the surface's chart. On [`Plane`] it is the same top as
    /// [`RelativisticTangentTop::symmetric`], with the Killing momenta of SE(2) as invariants.
    pub fn on_surface(surface: Arc<dyn Surface>, mass: f64, inertia: f64) -> Result<Self> {
        let top = Self::symmetric(mass, inertia)?;
        Ok(RelativisticTangentTop {
            surface: Some(surface),
            ..top
        })
    }

    /// The top of mass m > 0 with any second-moment tensor I = [[i11, i12], [i12, i22]]
    /// (`moments` = (i11, i12, i22), as [`RelativisticTangentTop::new`]) on the static space-time
    /// ds² = −dt² + g over `surface`: L = −m/γ + ½s²(𝕀γ + γ³uᵀK(θ)u) (002 (102), physical sign,
    /// module docs), u the components of ẋ in the surface's orthonormal frame. An anisotropic
    /// body's L depends on θ (p_θ is not conserved); the energy and the Killing momenta are. On
    /// [`Plane`] it is the same top as [`RelativisticTangentTop::new`].
    pub fn on_surface_with_moments(
        surface: Arc<dyn Surface>,
        mass: f64,
        moments: [f64; 3],
    ) -> Result<Self> {
        let top = Self::new(mass, moments)?;
        Ok(RelativisticTangentTop {
            surface: Some(surface),
            ..top
        })
    }

    /// The second-moment tensor I = ∫ξξᵀdm as (I₁₁, I₁₂, I₂₂).
    pub fn moments(&self) -> [f64; 3] {
        self.moments
    }

    /// The spatial slice: the surface of [`RelativisticTangentTop::on_surface`], else [`Plane`].
    pub fn surface(&self) -> Arc<dyn Surface> {
        self.surface.clone().unwrap_or_else(|| Arc::new(Plane))
    }

    /// Whether the top lives on a surface ([`RelativisticTangentTop::on_surface`]) rather than
    /// in the Minkowski plane of [`RelativisticTangentTop::new`].
    pub fn is_on_surface(&self) -> bool {
        self.surface.is_some()
    }

    /// The non-relativistic limit: the classical (intrinsic) [`TangentTop`] of the same mass and
    /// Euler tensor on the same surface (the Plane for a Minkowski top). As all velocities scale
    /// by ε → 0, L + m → the classical L up to O(ε⁴) (module docs).
    pub fn classical_limit(&self) -> Result<TangentTop> {
        let [a, b, c] = self.moments;
        TangentTop::with_tensor(self.surface(), self.mass, [a, b, b, c])
    }

    /// The momenta J = p_A X^A of the Killing fields of the surface lifted to (x, θ), in the order
    /// of [`Surface::killing`] (on the Minkowski plane: p_x, p_y and x p_y − y p_x + p_θ, the
    /// last conserved for any I). Errors: wrong length, non-finite, x outside the chart.
    pub fn killing_momenta(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        check::finite_slice("state", z)?;
        self.check_point(&z[..3])?;
        Ok(surface::killing_momenta(&*self.surface(), z, false))
    }

    /// The speed v = √g(ẋ, ẋ) and the covariant spin rate s = θ̇ + α·ẋ of a state (both constant
    /// along a motion of the symmetric top, module docs). Errors: as
    /// [`RelativisticTangentTop::velocities`].
    pub fn speed_and_spin(&self, z: &[f64]) -> Result<(f64, f64)> {
        let v = self.velocities(z)?;
        let surface = self.surface();
        let x = [z[0], z[1]];
        let (g, a) = (surface.metric(x), surface.connection(x));
        let xd = [v[0], v[1]];
        Ok((
            surface::inner(&g, xd, xd).sqrt(),
            v[2] + a[0] * xd[0] + a[1] * xd[1],
        ))
    }

    /// The mass m.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// 𝕀 = tr I.
    pub fn inertia(&self) -> f64 {
        self.moments[0] + self.moments[2]
    }

    /// Whether I = (𝕀/2)·Id (then θ is cyclic and p_θ is conserved).
    pub fn is_symmetric(&self) -> bool {
        self.moments[1] == 0.0 && self.moments[0] == self.moments[2]
    }

    /// K(θ) = R(θ) J I Jᵀ R(θ)ᵀ and its first θ-derivative K' = JK − KJ, as (K₁₁, K₁₂, K₂₂).
    fn k(&self, theta: f64) -> ([f64; 3], [f64; 3]) {
        k_of(self.moments, theta)
    }

    /// m and I = (I₁₁, I₁₂, I₂₂) over [`Real`], the parameter (0: the mass, 1: the inertia 𝕀
    /// with I scaled) moved at unit rate.
    fn constants<T: Real>(&self, parameter: Option<usize>) -> (T, [T; 3]) {
        let tr = self.inertia();
        let rate = f64::from(u8::from(parameter == Some(1))) / tr;
        (
            T::with(self.mass, f64::from(u8::from(parameter == Some(0)))),
            self.moments.map(|i| T::with(i, i * rate)),
        )
    }

    /// L(q, q̇) of 002 (90) (physical sign, module docs), q = (x, y, θ), q̇ = (ẋ, ẏ, θ̇).
    /// Errors: non-finite input, |ẋ| ≥ 1.
    pub fn lagrangian(&self, q: [f64; 3], qdot: [f64; 3]) -> Result<f64> {
        lagrangian(self, q, qdot)
    }

    /// The canonical state (x, y, θ, p_x, p_y, p_θ) with p = ∂L/∂q̇ at the given position, angle
    /// and velocities. Errors: non-finite input, |ẋ| ≥ 1, a Legendre map that is not invertible
    /// there (∂²L/∂q̇² not positive definite).
    pub fn state(
        &self,
        x: [f64; 2],
        theta: f64,
        xdot: [f64; 2],
        thetadot: f64,
    ) -> Result<Vec<f64>> {
        state(self, [x[0], x[1], theta], [xdot[0], xdot[1], thetadot])
    }

    /// The velocities (ẋ, ẏ, θ̇) of a state (the inverse Legendre map). Errors: wrong length,
    /// non-finite, or momenta outside the range of the Legendre map.
    pub fn velocities(&self, z: &[f64]) -> Result<[f64; 3]> {
        velocities(self, z)
    }

    fn symmetric_only(&self, what: &str) -> Result<f64> {
        if self.is_symmetric() {
            Ok(0.5 * self.inertia())
        } else {
            Err(Error::invalid(
                what,
                "002 (94)–(96) hold for the symmetric top only (I = (𝕀/2)·Id)",
            ))
        }
    }

    /// |p| as a function of the speed v and J = p_θ for the symmetric top, 002 (94) (module docs;
    /// the seed's J is half of this one; on a surface |p| = |p_x − p_θ α|_{g⁻¹}). Errors: not
    /// symmetric, v ∉ [0, 1), non-finite J.
    pub fn momentum_94(&self, v: f64, j: f64) -> Result<f64> {
        let i0 = self.symmetric_only("momentum_94")?;
        check_speed(v)?;
        check::finite_slice("J", &[j])?;
        let (m, s) = (self.mass, v * v);
        let g = 1.0 / (1.0 - s).sqrt();
        Ok(m * g * v * (1.0 + j * j * (1.0 - s) * (4.0 - s) / (2.0 * i0 * m * (2.0 - s).powi(2))))
    }

    /// θ̇ of the symmetric top from v and J = p_θ, 002 (95): θ̇ = J/(2I₀γ(1 + ½v²γ²)) (on a
    /// surface: the covariant spin rate s = θ̇ + α·ẋ).
    pub fn spin_rate_95(&self, v: f64, j: f64) -> Result<f64> {
        let i0 = self.symmetric_only("spin_rate_95")?;
        check_speed(v)?;
        check::finite_slice("J", &[j])?;
        let g2 = 1.0 / (1.0 - v * v);
        Ok(j / (2.0 * i0 * g2.sqrt() * (1.0 + 0.5 * v * v * g2)))
    }

    /// The energy of the symmetric top from v and θ̇, 002 (96) (physical sign):
    /// E = mγ + I₀θ̇²(γ + (5/2)v²γ³ + (3/2)v⁴γ⁵) (on a surface with θ̇ → s = θ̇ + α·ẋ).
    pub fn energy_96(&self, v: f64, thetadot: f64) -> Result<f64> {
        let i0 = self.symmetric_only("energy_96")?;
        check_speed(v)?;
        check::finite_slice("thetadot", &[thetadot])?;
        let s = v * v;
        let g = 1.0 / (1.0 - s).sqrt();
        let (g3, g5) = (g * g * g, g.powi(5));
        Ok(self.mass * g + i0 * thetadot * thetadot * (g + 2.5 * s * g3 + 1.5 * s * s * g5))
    }
}

impl RelativisticTangentTop {
    /// F(θ) = 𝕀γ + γ³uᵀK(θ)u, the spin's moment of inertia about a centre that moves uniformly
    /// in a straight line with velocity u (002 (91), module docs "Prescribed centre motion"):
    /// with ẋ = u held fixed, L = −m/γ + ½F(θ)θ̇². u are Cartesian components in the Minkowski
    /// plane (the components in the orthonormal frame Ê, θ measured from Ê₁). Errors:
    /// non-finite input, |u| ≥ 1.
    pub fn prescribed_inertia(&self, theta: f64, velocity: [f64; 2]) -> Result<f64> {
        check::finite_slice("theta", &[theta])?;
        check::finite_slice("velocity", &velocity)?;
        let speed2 = velocity[0] * velocity[0] + velocity[1] * velocity[1];
        if speed2.is_nan() || speed2 >= 1.0 {
            return Err(superluminal([velocity[0], velocity[1], 0.0], speed2.sqrt()));
        }
        let g = 1.0 / (1.0 - speed2).sqrt();
        let (k, _) = self.k(theta);
        let u = velocity;
        let p = k[0] * u[0] * u[0] + 2.0 * k[1] * u[0] * u[1] + k[2] * u[1] * u[1];
        let f = self.inertia() * g + g * g * g * p;
        if !f.is_finite() {
            return Err(check::overflow_error("velocity", "F(θ)"));
        }
        Ok(f)
    }

    /// The spin rate |θ̇| = √(2E/F(θ)) at the angle θ of the spin with the conserved spin energy
    /// E = ½F(θ)θ̇² ≥ 0 (002 (92), physical sign: the seed's θ̇² = E/F with its F = ½ of this
    /// one), the centre moving with the fixed velocity u ([`RelativisticTangentTop::prescribed_inertia`]).
    /// Errors: as `prescribed_inertia`, E < 0.
    pub fn prescribed_spin_rate(&self, theta: f64, energy: f64, velocity: [f64; 2]) -> Result<f64> {
        let f = self.prescribed_inertia(theta, velocity)?;
        check_spin_energy(energy)?;
        let rate = (2.0 * energy / f).sqrt();
        if !rate.is_finite() {
            return Err(check::overflow_error("energy", "the spin rate"));
        }
        Ok(rate)
    }

    /// The effective potential V(θ) = −E/F(θ) of the spin with the fixed centre velocity u and
    /// spin energy E = ½F(θ)θ̇² ≥ 0: ½θ̇² + V(θ) = 0 and θ̈ = −V′(θ) (module docs; the seed's
    /// V_eff = E/F of 002 (92) is θ̇² itself). Errors: as
    /// [`RelativisticTangentTop::prescribed_spin_rate`].
    pub fn prescribed_potential(&self, theta: f64, energy: f64, velocity: [f64; 2]) -> Result<f64> {
        let f = self.prescribed_inertia(theta, velocity)?;
        check_spin_energy(energy)?;
        let v = -energy / f;
        if !v.is_finite() {
            return Err(check::overflow_error("energy", "the effective potential"));
        }
        Ok(v)
    }
}

fn check_spin_energy(energy: f64) -> Result<()> {
    if energy.is_finite() && energy >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            "energy",
            format!("expected a finite spin energy E = F θ̇²/2 ≥ 0, got {energy}"),
        ))
    }
}

fn check_speed(v: f64) -> Result<()> {
    if v.is_finite() && (0.0..1.0).contains(&v) {
        Ok(())
    } else {
        Err(Error::invalid(
            "v",
            format!("expected a speed 0 ≤ v < 1 (c = 1), got {v}"),
        ))
    }
}

fn superluminal(v: [f64; 3], speed: f64) -> Error {
    Error::invalid(
        "velocity",
        format!(
            "expected a speed |ẋ| < 1 (c = 1), got |({}, {})| = {speed}",
            v[0], v[1],
        ),
    )
}

impl Problem for RelativisticTangentTop {
    fn calls_out(&self) -> bool {
        self.surface.as_ref().is_some_and(|s| s.calls_out())
    }
    fn name(&self) -> &'static str {
        "RelativisticTangentTop"
    }
    /// The mass m and the inertia 𝕀 (I scaled with it): the sensitivities of a tangent run (the
    /// potential's and the surface's constants are not parameters here).
    fn parameters(&self) -> Vec<&'static str> {
        vec!["mass", "inertia"]
    }
    fn space(&self) -> Space {
        space()
    }
    /// E = H = p·q̇ − L (002 (96) for the symmetric top, with the physical sign).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        energy(self, z)
    }
    /// Minkowski: (p_x, p_y), and p_θ for the symmetric top: momenta of cyclic coordinates,
    /// linear, so kept exactly by the Gauss methods. On a surface: p_θ (symmetric top only) and
    /// the Killing momenta of the affine generators ([`Surface::killing_is_affine`]; quadratic in
    /// z, so also kept by the Gauss methods); [`RelativisticTangentTop::killing_momenta`] gives
    /// all.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        let Some(surface) = &self.surface else {
            let mut out = vec![z[3], z[4]];
            if self.is_symmetric() {
                out.push(z[5]);
            }
            return Ok(out);
        };
        check::finite_slice("state", z)?;
        self.check_point(&z[..3])?;
        let affine = surface::killing_momenta(&**surface, z, true);
        let spin = self.is_symmetric().then_some(z[5]);
        Ok(spin.into_iter().chain(affine).collect())
    }
    fn invariant_names(&self) -> Vec<String> {
        let spin = self.is_symmetric().then(|| "p_θ".to_string());
        match &self.surface {
            None => ["p_x".to_string(), "p_y".to_string()]
                .into_iter()
                .chain(spin)
                .collect(),
            Some(surface) => spin
                .into_iter()
                .chain(surface::killing_momentum_names(&**surface, true))
                .collect(),
        }
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.velocities(z).map(|_| ())
    }
}

/// K(θ) = R(θ) J I Jᵀ R(θ)ᵀ and K′ = JK − KJ as (K₁₁, K₁₂, K₂₂) for I = (I₁₁, I₁₂, I₂₂), over
/// [`Real`].
fn k_of<T: Real>(moments: [T; 3], theta: T) -> ([T; 3], [T; 3]) {
    let k = |x: f64| T::from(x);
    let [a, b, c] = moments;
    // J I Jᵀ = [[c, −b], [−b, a]]; rotate by θ.
    let (s, co) = theta.sin_cos();
    let (p, q, r) = (c, -b, a);
    // R M Rᵀ for symmetric M = [[p, q], [q, r]].
    let k11 = co * co * p - k(2.0) * co * s * q + s * s * r;
    let k12 = co * s * (p - r) + (co * co - s * s) * q;
    let k22 = s * s * p + k(2.0) * co * s * q + co * co * r;
    // K' = JK − KJ = [[−2K12, K11 − K22], [K11 − K22, 2K12]].
    ([k11, k12, k22], [k(-2.0) * k12, k11 - k22, k(2.0) * k12])
}

impl Legendre for RelativisticTangentTop {
    /// Derivatives of L at (q, q̇); None where v ≥ 1, x is outside the chart or the input is not
    /// finite.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs> {
        let (q, v) = ([q[0], q[1], q[2]], [v[0], v[1], v[2]]);
        let c = self.constants(None);
        match &self.surface {
            None => self.minkowski_derivs(q, v, c)?.finite(),
            Some(surface) => self
                .curved_derivs(&self.local(&**surface, q)?, q[2], v, c)?
                .finite(),
        }
    }

    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        match &self.surface {
            None => self.minkowski_solve(q, p),
            Some(surface) => {
                self.curved_solve(&self.local(&**surface, [q[0], q[1], q[2]])?, q[2], p)
            }
        }
    }

    fn derivs_dual(
        &self,
        q: [Dual; 3],
        v: [Dual; 3],
        parameter: Option<usize>,
    ) -> Option<DerivsT<Dual>> {
        let c = self.constants(parameter);
        match &self.surface {
            None => self.minkowski_derivs(q, v, c),
            Some(surface) => self.curved_derivs(&self.local(&**surface, q)?, q[2], v, c),
        }
    }

    /// In the Minkowski plane; on a surface with second derivatives.
    fn has_hessian(&self) -> bool {
        match &self.surface {
            None => true,
            Some(s) => s.has_second_derivatives(),
        }
    }

    fn undefined(&self, q: [f64; 3], v: [f64; 3]) -> Error {
        match &self.surface {
            None => superluminal(v, v[0].hypot(v[1])),
            Some(surface) => {
                let x = [q[0], q[1]];
                if let Err(e) = surface.check(x) {
                    return e.at_start();
                }
                let speed = surface::inner(&surface.metric(x), [v[0], v[1]], [v[0], v[1]]);
                superluminal(v, speed.sqrt())
            }
        }
    }

    fn check_point(&self, q: &[f64]) -> Result<()> {
        match &self.surface {
            None => Ok(()),
            Some(surface) => surface.check([q[0], q[1]]).map_err(|e| e.at_start()),
        }
    }
}

/// What the kernel of a top on a surface needs at one point x: the geometry (g, ∂g, α, ∂α) and,
/// for an anisotropic body, the orthonormal frame `e[a][i]` = e_a^i (for u = e g ẋ); over
/// [`Real`] (f64, or [`Dual`] along a direction for the tangent lift).
struct Local<T> {
    geo: GeoT<T>,
    frame: Option<M2<T>>,
}

/// The body's part of L on a surface at (x, θ, ẋ): P = uᵀK(θ)u with u the frame components of ẋ
/// (module docs, "Anisotropic top"), ∂P/∂ẋ = 2k, ∂²P/∂ẋ² = 2N, ∂P/∂x^k and ∂P/∂θ.
struct BodyTerm<T> {
    p: T,
    k: V2<T>,
    n: M2<T>,
    px: V2<T>,
    ptheta: T,
}

impl RelativisticTangentTop {
    /// The geometry at x (and the frame, for an anisotropic body); None outside the chart.
    fn local<T: Real>(&self, surface: &dyn Surface, q: [T; 3]) -> Option<Local<T>> {
        let x = [q[0], q[1]];
        if !(surface.contains([x[0].re(), x[1].re()]) && q[2].is_finite()) {
            return None;
        }
        let geo = lift::geometry(surface, x);
        let frame = (!self.is_symmetric()).then(|| lift::frame(surface, x));
        Some(Local { geo, frame })
    }

    /// P = uᵀK(θ)u and its derivatives (module docs, "Anisotropic top"). Symmetric top:
    /// P = (𝕀/2) g(ẋ, ẋ). Otherwise with the coframe F = e g (u = Fẋ), N = FᵀKF, k = Nẋ,
    /// ∂_k u = p_k − α_k J u, (p_k)_a = ½ e_a^l ẋ^i (∂_k g_il + ∂_i g_kl − ∂_l g_ik),
    /// ∂P/∂x^k = 2 (∂_k u)·Ku and ∂P/∂θ = uᵀK′u.
    fn body_term<T: Real>(local: &Local<T>, theta: T, xd: V2<T>, moments: [T; 3]) -> BodyTerm<T> {
        let c = |x: f64| T::from(x);
        let geo = &local.geo;
        let g = &geo.g;
        let Some(e) = &local.frame else {
            let h = c(0.5) * (moments[0] + moments[2]);
            let gx = [
                g[0][0] * xd[0] + g[0][1] * xd[1],
                g[1][0] * xd[0] + g[1][1] * xd[1],
            ];
            return BodyTerm {
                p: h * (gx[0] * xd[0] + gx[1] * xd[1]),
                k: [h * gx[0], h * gx[1]],
                n: g.map(|r| r.map(|v| h * v)),
                px: std::array::from_fn(|k| h * inner(&geo.dg[k], xd, xd)),
                ptheta: c(0.0),
            };
        };
        let f = mul(e, g);
        let u = [
            f[0][0] * xd[0] + f[0][1] * xd[1],
            f[1][0] * xd[0] + f[1][1] * xd[1],
        ];
        let (kk, kp) = k_of(moments, theta);
        let km = [[kk[0], kk[1]], [kk[1], kk[2]]];
        let ku = [
            km[0][0] * u[0] + km[0][1] * u[1],
            km[1][0] * u[0] + km[1][1] * u[1],
        ];
        let kpm = [[kp[0], kp[1]], [kp[1], kp[2]]];
        // N = Fᵀ K F, k = Fᵀ K u.
        let ft = [[f[0][0], f[1][0]], [f[0][1], f[1][1]]];
        let n = mul(&ft, &mul(&km, &f));
        let k = [
            ft[0][0] * ku[0] + ft[0][1] * ku[1],
            ft[1][0] * ku[0] + ft[1][1] * ku[1],
        ];
        let dg = &geo.dg;
        let px = std::array::from_fn(|kx| {
            // ∂_k u = p_k − α_k J u, J u = (−u₂, u₁).
            let du: [T; 2] = std::array::from_fn(|a| {
                let mut pa = c(0.0);
                for i in 0..2 {
                    for l in 0..2 {
                        pa += e[a][l] * xd[i] * (dg[kx][i][l] + dg[i][kx][l] - dg[l][i][kx]);
                    }
                }
                let ju = if a == 0 { -u[1] } else { u[0] };
                c(0.5) * pa - geo.alpha[kx] * ju
            });
            c(2.0) * (du[0] * ku[0] + du[1] * ku[1])
        });
        BodyTerm {
            p: u[0] * ku[0] + u[1] * ku[1],
            k,
            n,
            px,
            ptheta: inner(&kpm, u, u),
        }
    }

    /// The top on a surface (module docs, "Derivatives"): L, ∂L/∂q̇, ∂L/∂q, ∂²L/∂q̇² at the local
    /// data of x, the angle θ and q̇ = (ẋ, θ̇), with the constants m, I; None where
    /// g(ẋ, ẋ) ≥ 1 or a value is not finite.
    fn curved_derivs<T: Real>(
        &self,
        local: &Local<T>,
        theta: T,
        v: [T; 3],
        (m, moments): (T, [T; 3]),
    ) -> Option<DerivsT<T>> {
        let c = |x: f64| T::from(x);
        let tr = moments[0] + moments[2];
        let geo = &local.geo;
        let (xd, w) = ([v[0], v[1]], v[2]);
        let g = &geo.g;
        let n = [
            g[0][0] * xd[0] + g[0][1] * xd[1],
            g[1][0] * xd[0] + g[1][1] * xd[1],
        ];
        let qq = n[0] * xd[0] + n[1] * xd[1];
        if !(qq.is_finite() && qq.re() < 1.0 && w.is_finite()) {
            return None;
        }
        let body = Self::body_term(local, theta, xd, moments);
        let pp = body.p;
        if !pp.is_finite() {
            return None;
        }
        let a = geo.alpha;
        let s = w + a[0] * xd[0] + a[1] * xd[1];
        let g1 = c(1.0) / (c(1.0) - qq).sqrt();
        let g3 = g1 * g1 * g1;
        let g5 = g3 * g1 * g1;
        let g7 = g5 * g1 * g1;
        let s2 = s * s;
        let l = -m / g1 + c(0.5) * s2 * (tr * g1 + g3 * pp);
        let l_q = c(0.5) * m * g1 + c(0.25) * s2 * (tr * g3 + c(3.0) * g5 * pp); // ∂L/∂Q
        let l_s = s * (tr * g1 + g3 * pp); // ∂L/∂s = p_θ
        let l_p = c(0.5) * s2 * g3; // ∂L/∂P
        let l_qq = c(0.25) * m * g3 + c(0.375) * s2 * (tr * g5 + c(5.0) * g7 * pp);
        let l_qs = s * (c(0.5) * tr * g3 + c(1.5) * g5 * pp);
        let l_qp = c(0.75) * s2 * g5;
        let l_ss = tr * g1 + g3 * pp;
        let l_sp = s * g3;
        let k = body.k;
        let lv = [
            c(2.0) * l_q * n[0] + l_s * a[0] + c(2.0) * l_p * k[0],
            c(2.0) * l_q * n[1] + l_s * a[1] + c(2.0) * l_p * k[1],
            l_s,
        ];
        let mut lq = [c(0.0); 3];
        for (kx, lqk) in lq.iter_mut().enumerate().take(2) {
            let da = geo.dalpha[kx];
            *lqk = l_q * inner(&geo.dg[kx], xd, xd)
                + l_s * (da[0] * xd[0] + da[1] * xd[1])
                + l_p * body.px[kx];
        }
        lq[2] = l_p * body.ptheta;
        let mut hess = [[c(0.0); 3]; 3];
        for i in 0..2 {
            for j in 0..2 {
                hess[i][j] = c(2.0) * l_q * g[i][j]
                    + c(2.0) * l_p * body.n[i][j]
                    + c(4.0) * l_qq * n[i] * n[j]
                    + c(4.0) * l_qp * (n[i] * k[j] + k[i] * n[j])
                    + c(2.0) * l_qs * (n[i] * a[j] + a[i] * n[j])
                    + c(2.0) * l_sp * (k[i] * a[j] + a[i] * k[j])
                    + l_ss * a[i] * a[j];
            }
            let h = c(2.0) * l_qs * n[i] + c(2.0) * l_sp * k[i] + l_ss * a[i];
            hess[i][2] = h;
            hess[2][i] = h;
        }
        hess[2][2] = l_ss;
        let finite = l.is_finite() && lq.iter().all(|x| x.is_finite());
        finite.then_some(DerivsT { l, lv, lq, hess })
    }

    /// The inverse Legendre map of the top on a surface: from a free particle of mass
    /// m + 𝕀 s² (exact at low speed for the symmetric top) carrying π = p_x − p_θ α at spin
    /// s = p_θ/𝕀, slower than light; failing that, from rest.
    fn curved_solve(
        &self,
        local: &Local<f64>,
        theta: f64,
        p: &[f64],
    ) -> Option<(Vector3<f64>, Derivs)> {
        let tr = self.inertia();
        let geo = &local.geo;
        let s = p[2] / tr;
        let a = geo.alpha;
        let pi = [p[0] - p[2] * a[0], p[1] - p[2] * a[1]];
        let gi = inverse(&geo.g);
        let up = [
            gi[0][0] * pi[0] + gi[0][1] * pi[1],
            gi[1][0] * pi[0] + gi[1][1] * pi[1],
        ];
        let mm = self.mass + tr * s * s;
        let e = (mm * mm + up[0] * pi[0] + up[1] * pi[1]).sqrt();
        let xd = [up[0] / e, up[1] / e];
        let guess = Vector3::new(xd[0], xd[1], s - a[0] * xd[0] - a[1] * xd[1]);
        let c = self.constants(None);
        let derivs = |v: &Vector3<f64>| {
            self.curved_derivs(local, theta, [v[0], v[1], v[2]], c)?
                .finite()
        };
        legendre_inverse(p, guess, derivs)
            .or_else(|| legendre_inverse(p, Vector3::new(0.0, 0.0, s), derivs))
    }

    /// Derivatives of the Minkowski L (002 (90)) at (q, q̇) with the constants m, I; None where
    /// |ẋ| ≥ 1 or the input is not finite.
    fn minkowski_derivs<T: Real>(
        &self,
        q: [T; 3],
        v: [T; 3],
        (m, moments): (T, [T; 3]),
    ) -> Option<DerivsT<T>> {
        let c = |x: f64| T::from(x);
        let (u, w) = ([v[0], v[1]], v[2]);
        let s = u[0] * u[0] + u[1] * u[1];
        if !(s.is_finite() && s.re() < 1.0 && w.is_finite() && q[2].is_finite()) {
            return None;
        }
        let tr = moments[0] + moments[2];
        let g = c(1.0) / (c(1.0) - s).sqrt();
        let (g3, g5) = (g * g * g, g * g * g * g * g);
        let g7 = g5 * g * g;
        let (k, kp) = k_of(moments, q[2]);
        let ku = [k[0] * u[0] + k[1] * u[1], k[1] * u[0] + k[2] * u[1]];
        let qk = u[0] * ku[0] + u[1] * ku[1];
        let qkp = kp[0] * u[0] * u[0] + c(2.0) * kp[1] * u[0] * u[1] + kp[2] * u[1] * u[1];
        let w2 = w * w;
        let l = -m / g + c(0.5) * w2 * (tr * g + g3 * qk);
        let a_s = m * g + c(0.5) * w2 * tr * g3 + c(1.5) * w2 * g5 * qk;
        let b_s = m * g3 + c(1.5) * w2 * tr * g5 + c(7.5) * w2 * g7 * qk;
        let lv = [
            a_s * u[0] + w2 * g3 * ku[0],
            a_s * u[1] + w2 * g3 * ku[1],
            w * (tr * g + g3 * qk),
        ];
        let lq = [c(0.0), c(0.0), c(0.5) * w2 * g3 * qkp];
        let mut hess = [[c(0.0); 3]; 3];
        let kk = [[k[0], k[1]], [k[1], k[2]]];
        for i in 0..2 {
            for j in 0..2 {
                let delta = c(if i == j { 1.0 } else { 0.0 });
                hess[i][j] = a_s * delta
                    + b_s * u[i] * u[j]
                    + c(3.0) * w2 * g5 * (u[i] * ku[j] + ku[i] * u[j])
                    + w2 * g3 * kk[i][j];
            }
            let huw = w * ((tr * g3 + c(3.0) * g5 * qk) * u[i] + c(2.0) * g3 * ku[i]);
            hess[i][2] = huw;
            hess[2][i] = huw;
        }
        hess[2][2] = tr * g + g3 * qk;
        Some(DerivsT { l, lv, lq, hess })
    }

    fn minkowski_solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        // Start from a free particle of the mass the spin adds to at low speed
        // (p ≈ (m + ω²(𝕀/2 + K))ẋ, bounded by m + ω²𝕀·3/2; u = p/√(M² + |p|²) is slower than light)
        // with the spin of a top at rest; failing that, from rest.
        let tr = self.inertia();
        let w = p[2] / tr;
        let mm = self.mass + 1.5 * w * w * tr;
        let e = (mm * mm + p[0] * p[0] + p[1] * p[1]).sqrt();
        let guess = Vector3::new(p[0] / e, p[1] / e, w);
        let q = [q[0], q[1], q[2]];
        let c = self.constants(None);
        let derivs = |v: &Vector3<f64>| self.minkowski_derivs(q, [v[0], v[1], v[2]], c)?.finite();
        legendre_inverse(p, guess, derivs)
            .or_else(|| legendre_inverse(p, Vector3::new(0.0, 0.0, w), derivs))
    }
}
