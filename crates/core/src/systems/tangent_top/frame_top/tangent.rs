//! The tangent lift of [`FrameTop`] (issue 26): the tangent maps of its exact flows (the
//! splittings and `exact`) and the derivative of its Lie–Poisson field (`rk4`), principal frame.
//! A direction is (δg, δΠ, δP) with δg ambient (16 values: g is a
//! [`crate::integrate::space::Block::Matrix`], so the
//! directions need not be tangent to the frame group, and the maps below are the derivatives of
//! the flows as they act on any 4×4 matrix).
//!
//! - **Axis flow** ½Π_k²/I_k over τ: Π, P and the rows of g's frame block turn about e_k by
//!   θ = τΠ_k/I_k (`top::rotate_axis_sc`: v_i' = cos θ v_i + sin θ v_j, v_j' = cos θ v_j −
//!   sin θ v_i), so δv' = Rot(θ)δv + δθ (v_j', −v_i') with δθ = τδΠ_k/I_k.
//! - **Flow of T** (module docs of [`super`]): g₁ = g(1 + A), A = expm1(X),
//!   X = ξ̂(τκ′Π, τP/m); then the frame block's rows and P turn by T = exp(φ̂), φ = τκ′Π. So
//!   δg₁ = δg(1 + A) + g DA\[δX\] ([`expm1_tangent`]), and each turned vector v' = Tv varies by
//!   Tδv + w × v' with w = J_l(φ)δφ; δΠ' = δΠ.
//! - **Free rigid body** over τ (`exact`): Π' = S(τ)ᵀΠ, P' = SᵀP, g' = g diag(1, S), with S the
//!   relative attitude of the elliptic solution. With δS = Sη̂ (left-trivialised),
//!   δ(Sᵀv) = v' × η + Sᵀδv; δΠ' = Dφ_τ δΠ is the momentum's exact tangent map
//!   ([`crate::systems::tops::methods::exact`], "Tangent map"), and η follows from it in closed
//!   form ([`FreeTangent`]).
//! - **Field**: δġ = δg ξ̂(Ω, v) + g ξ̂(δΩ, δv), δΠ̇ = δΠ × Ω + Π × δΩ,
//!   δṖ = δP × Ω + P × δΩ + κ′(δΠ × P + Π × δP), Ω = 𝕀⁻¹Π, v = P/m.
//!
//! `exact` composes the flow of T and the free body's as the plain method does (the base state
//! is the plain run's bit for bit); no parameters (the free body's attitude along a moment of
//! inertia needs ∫M_q² dt, an integral of the second kind not formed here).

use nalgebra::{Matrix4, Vector3};

use super::{unflat, write, Exact, FrameTop, FrameWork};
use crate::error::Result;
use crate::integrate::methods::{Composition, Rk4, Splitting};
use crate::integrate::problem::Split;
use crate::integrate::tangent::{SplitTangent, Tangent, VectorFieldTangent};
use crate::integrate::{Catalog, Clock, Entry, Integrator, Properties, Stepper};
use crate::lie::so3;
use crate::systems::tangent_top::space_form::{expm1, expm1_tangent};
use crate::systems::tops::methods::exact::FreeTangent;

/// The frame block's row `row` (columns 1–3) of g.
fn frame_row(g: &Matrix4<f64>, row: usize) -> Vector3<f64> {
    Vector3::new(g[(row, 1)], g[(row, 2)], g[(row, 3)])
}

fn set_frame_row(g: &mut Matrix4<f64>, row: usize, v: &Vector3<f64>) {
    for c in 0..3 {
        g[(row, c + 1)] = v[c];
    }
}

impl FrameTop {
    /// The axis flow's tangent map (module docs).
    fn axis_tangent(
        &self,
        k: usize,
        tau: f64,
        before: &FrameWork,
        after: &FrameWork,
        dirs: &mut [f64],
    ) {
        let moments = self.body.moments();
        let (s, cm1) = crate::numerics::simd::angle_sin_cosm1(tau * before.pi[k] / moments[k]);
        let c = 1.0 + cm1;
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let tc = tau / moments[k];
        for dy in dirs.chunks_exact_mut(22) {
            let (mut dg, mut dpi, mut dp) = unflat(dy);
            let dtheta = tc * dpi[k];
            let turn = |v: &mut Vector3<f64>, a: &Vector3<f64>| {
                let (vi, vj) = (v[i], v[j]);
                v[i] = c * vi + s * vj + dtheta * a[j];
                v[j] = c * vj - s * vi - dtheta * a[i];
            };
            turn(&mut dpi, &after.pi);
            turn(&mut dp, &after.p);
            for row in 0..4 {
                let mut v = frame_row(&dg, row);
                turn(&mut v, &frame_row(&after.g, row));
                set_frame_row(&mut dg, row, &v);
            }
            write(&dg, &dpi, &dp, dy);
        }
    }

    /// The tangent map of the flow of T (module docs).
    fn t_tangent(&self, tau: f64, before: &FrameWork, after: &FrameWork, dirs: &mut [f64]) {
        let (kp, m) = (self.space.curvature() / self.body.mass, self.body.mass);
        let phi = before.pi * (tau * kp);
        let x = self.space.hat(&phi, &(before.p * (tau / m)));
        let a = expm1(&x);
        let (t, jl) = so3::exp_and_jacobian_left(&phi);
        for dy in dirs.chunks_exact_mut(22) {
            let (dg, dpi, dp) = unflat(dy);
            let dx = self.space.hat(&(dpi * (tau * kp)), &(dp * (tau / m)));
            let mut g1 = dg + dg * a + before.g * expm1_tangent(&x, &dx);
            let w = jl * (dpi * (tau * kp));
            for row in 0..4 {
                let v = t * frame_row(&g1, row) + w.cross(&frame_row(&after.g, row));
                set_frame_row(&mut g1, row, &v);
            }
            write(&g1, &dpi, &(t * dp + w.cross(&after.p)), dy);
        }
    }

    /// The tangent map of the free rigid body's exact flow (module docs).
    fn rotation_tangent(&self, tau: f64, before: &FrameWork, after: &FrameWork, dirs: &mut [f64]) {
        let free = FreeTangent::new(self.body.moments(), &before.pi, tau);
        for dy in dirs.chunks_exact_mut(22) {
            let (mut dg, dpi, dp) = unflat(dy);
            let (dpi1, eta) = free.apply(&dpi, None);
            for row in 0..4 {
                let v = frame_row(&after.g, row).cross(&eta) + free.turn(&frame_row(&dg, row));
                set_frame_row(&mut dg, row, &v);
            }
            write(&dg, &dpi1, &(after.p.cross(&eta) + free.turn(&dp)), dy);
        }
    }
}

/// Flows 0–2 (the axis rotations) and 3 (T): module docs.
impl SplitTangent for FrameTop {
    fn flow_tangent(
        &self,
        i: usize,
        tau: f64,
        before: &FrameWork,
        after: &FrameWork,
        dirs: &mut [f64],
    ) {
        match i {
            3 => self.t_tangent(tau, before, after, dirs),
            k => self.axis_tangent(k, tau, before, after, dirs),
        }
    }
}

/// The field's derivative (module docs), principal frame.
impl VectorFieldTangent for FrameTop {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        let (g, pi, p) = unflat(z);
        let (dg, dpi, dp) = unflat(dz);
        let inv = Vector3::from_fn(|k, _| 1.0 / self.body.moments()[k]);
        let (omega, domega) = (pi.component_mul(&inv), dpi.component_mul(&inv));
        let m = self.body.mass;
        let (v, dv) = (p / m, dp / m);
        let kp = self.space.curvature() / m;
        let dgd = dg * self.space.hat(&omega, &v) + g * self.space.hat(&domega, &dv);
        let dpid = dpi.cross(&omega) + pi.cross(&domega);
        let dpd = dp.cross(&omega) + p.cross(&domega) + (dpi.cross(&p) + pi.cross(&dp)) * kp;
        write(&dgd, &dpid, &dpd, out);
    }
}

/// `exact` on the lift: each step the flow of T and the free body's, as [`Exact`], with their
/// tangent maps on the directions.
impl Integrator<Tangent<FrameTop>> for Exact {
    fn properties(&self) -> Properties {
        Properties::exact()
    }

    fn stepper(&self, lift: &Tangent<FrameTop>, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Box::new(ExactTangentStepper {
            top: lift.problem().clone(),
            dt,
            w: FrameWork {
                g: Matrix4::identity(),
                pi: Vector3::zeros(),
                p: Vector3::zeros(),
            },
            dirs: Vec::new(),
        }))
    }
}

struct ExactTangentStepper {
    top: FrameTop,
    dt: f64,
    w: FrameWork,
    dirs: Vec<f64>,
}

impl Stepper for ExactTangentStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.w = self.top.load(&z[..22])?;
        self.dirs.clear();
        self.dirs.extend_from_slice(&z[22..]);
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        // Nothing before `set`.
        if z.len() == 22 + self.dirs.len() {
            self.top.store(&self.w, &mut z[..22]);
            z[22..].copy_from_slice(&self.dirs);
        }
    }

    fn advance(&mut self, steps: usize, _clock: Clock) -> Result<()> {
        for _ in 0..steps {
            let before = self.w;
            self.top.flow_t(self.dt, &mut self.w);
            self.top
                .t_tangent(self.dt, &before, &self.w, &mut self.dirs);
            let before = self.w;
            self.top.flow_rotation(self.dt, &mut self.w);
            self.top
                .rotation_tangent(self.dt, &before, &self.w, &mut self.dirs);
        }
        Ok(())
    }
}

/// Every method of [`FrameTop`]'s catalog on the lift.
impl Catalog for Tangent<FrameTop> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("exact", || Exact),
            Entry::new("splitting", Splitting::strang),
            Entry::new("splitting4", || Splitting(Composition::suzuki4())),
            Entry::new("splitting6", || Splitting(Composition::yoshida6())),
            Entry::new("rk4", || Rk4),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::space_form::SpaceForm;
    use super::*;
    use crate::integrate::problem::VectorField;
    use crate::integrate::Problem;
    use crate::systems::tangent_top::frame_top::SpaceTop;
    use crate::systems::tops::methods::exact::relative_attitude;
    use nalgebra::Matrix3;

    fn tops() -> Vec<FrameTop> {
        let inertia = [2.0, 0.3, -0.1, 0.3, 3.1, 0.2, -0.1, 0.2, 4.2];
        [
            SpaceForm::sphere(1.0).unwrap(),
            SpaceForm::hyperbolic(1.5).unwrap(),
            SpaceForm::Euclidean,
        ]
        .into_iter()
        .map(|s| FrameTop::new(s, 1.3, &inertia).unwrap())
        .collect()
    }

    /// An internal state of the top and a direction (off the frame group).
    fn state(top: &FrameTop) -> (Vec<f64>, Vec<f64>) {
        let x: Vec<f64> = match top.space {
            SpaceForm::Euclidean => vec![0.3, -0.2, 0.5],
            SpaceForm::Sphere { .. } => vec![0.8, 0.0, 0.6, 0.0],
            SpaceForm::Hyperbolic { radius } => {
                let v = [0.3, -0.2, 0.5];
                let n2: f64 = v.iter().map(|a| a * a).sum();
                vec![(radius * radius + n2).sqrt(), v[0], v[1], v[2]]
            }
        };
        let xdot: Vec<f64> = match top.space {
            SpaceForm::Euclidean => vec![0.4, 0.1, -0.3],
            SpaceForm::Sphere { .. } => vec![0.0, 0.5, 0.0, -0.4],
            SpaceForm::Hyperbolic { radius } => {
                // Tangent: x₀ẋ₀ = x⃗·ẋ⃗.
                let v = [0.4, 0.1, -0.3];
                let dot = x[1] * v[0] + x[2] * v[1] + x[3] * v[2];
                let _ = radius;
                vec![dot / x[0], v[0], v[1], v[2]]
            }
        };
        let r = so3::exp_unchecked(&Vector3::new(0.4, -0.7, 0.3));
        let mut z = top
            .state(&x, &r, &xdot, &Vector3::new(0.7, -0.4, 1.1))
            .unwrap();
        top.to_internal(&mut z);
        let dz = (0..22).map(|k| ((k as f64) * 0.77).sin()).collect();
        (z, dz)
    }

    fn worst(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    }

    fn moved(z: &[f64], dz: &[f64], s: f64) -> Vec<f64> {
        z.iter().zip(dz).map(|(a, b)| a + s * b).collect()
    }

    /// D expm1 against central differences, below and above the scaling switch.
    #[test]
    fn expm1_tangent_is_the_derivative() {
        let top = &tops()[0];
        let dx = top
            .space
            .hat(&Vector3::new(0.3, -0.5, 0.2), &Vector3::new(0.1, 0.4, -0.7));
        for c in [1e-3, 0.3, 2.5] {
            let x = top
                .space
                .hat(&Vector3::new(0.7, 0.2, -0.4), &Vector3::new(-0.3, 0.8, 0.5))
                * c;
            let h = 1e-6;
            let fd = (expm1(&(x + dx * h)) - expm1(&(x - dx * h))) / (2.0 * h);
            let err = (expm1_tangent(&x, &dx) - fd).amax();
            assert!(err < 1e-9, "scale {c}: {err:e}");
        }
    }

    /// Each flow's tangent map and the field's derivative against central differences.
    #[test]
    fn flow_tangents_and_field_tangent_are_their_derivatives() {
        for top in tops() {
            let (z, dz) = state(&top);
            let h = 1e-6;
            for i in 0..5 {
                let tau = 0.37;
                let flow = |s: f64| {
                    let mut w = top.load(&moved(&z, &dz, s)).unwrap();
                    match i {
                        4 => top.flow_rotation(tau, &mut w),
                        i => top.flow(i, tau, &mut w),
                    }
                    let mut out = vec![0.0; 22];
                    top.store(&w, &mut out);
                    out
                };
                let (p, q) = (flow(h), flow(-h));
                let fd: Vec<f64> = p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect();
                let before = top.load(&z).unwrap();
                let mut after = before;
                match i {
                    4 => top.flow_rotation(tau, &mut after),
                    i => top.flow(i, tau, &mut after),
                }
                let mut d = dz.clone();
                match i {
                    4 => top.rotation_tangent(tau, &before, &after, &mut d),
                    i => top.flow_tangent(i, tau, &before, &after, &mut d),
                }
                let err = worst(&d, &fd);
                eprintln!(
                    "{}: flow {i}: tangent vs differences {err:.1e}",
                    top.space.name()
                );
                assert!(err < 1e-8, "{} flow {i}: {err:e}", top.space.name());
            }
            let field = |s: f64| {
                let mut out = vec![0.0; 22];
                top.field(&moved(&z, &dz, s), &mut out);
                out
            };
            let (p, q) = (field(h), field(-h));
            let fd: Vec<f64> = p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect();
            let mut d = vec![0.0; 22];
            top.field_tangent(&z, &dz, &mut d);
            let err = worst(&d, &fd);
            assert!(err < 1e-8, "{} field: {err:e}", top.space.name());
        }
    }

    /// The free body's tangent: η read off central differences of S (a run of the flow with
    /// the attitude), δΠ' of the momentum, also along τ, and at rest; for three distinct
    /// moments (the elliptic flow), a symmetric body and a spherical one (the closed forms).
    #[test]
    fn free_tangent_is_the_flows_derivative() {
        let dpi = Vector3::new(0.3, -0.8, 0.45);
        let bodies = [[1.3, 2.1, 3.4], [1.3, 1.3, 3.4], [2.0, 2.0, 2.0]];
        for (moments, pi0) in bodies
            .iter()
            .flat_map(|m| [(*m, Vector3::new(0.7, -0.4, 1.1)), (*m, Vector3::zeros())])
        {
            for dtau in [0.0, 0.7] {
                let tau = 0.9;
                let at = |s: f64| {
                    let pi = pi0 + dpi * s;
                    let rel = relative_attitude(&moments, &pi, tau + dtau * s);
                    // S from Sᵀ applied to the basis.
                    let st = Matrix3::from_fn(|r, c| {
                        let mut e = Vector3::zeros();
                        e[c] = 1.0;
                        rel.apply(&mut e);
                        e[r]
                    });
                    let mut m = pi;
                    rel.apply_momentum(&mut m);
                    (st.transpose(), m)
                };
                let h = 1e-6;
                let ((sp, mp), (sq, mq)) = (at(h), at(-h));
                let s0 = at(0.0).0;
                let eta_fd = so3::vee_unchecked(&(s0.transpose() * (sp - sq) / (2.0 * h)));
                let dm_fd = (mp - mq) / (2.0 * h);
                let (dm, eta) = FreeTangent::new(&moments, &pi0, tau).apply_timed(&dpi, dtau);
                let err = (eta - eta_fd).amax().max((dm - dm_fd).amax());
                eprintln!(
                    "I = {moments:?}, |Π₀| = {:.1}, δτ = {dtau}: {err:.1e}",
                    pi0.norm()
                );
                assert!(
                    err < 1e-8,
                    "I = {moments:?}, Π₀ = {pi0:?}, δτ = {dtau}: {err:e}"
                );
            }
        }
    }
}
