//! The curvature of the constraint distribution (003 §2.2): the closed form and its check by the
//! commutator of the exact flows of two constrained fields.

use nalgebra::{Matrix3, Vector3};

use super::{arr, finite1, RollingSpheres};
use crate::check;
use crate::error::Result;
use crate::lie::so3;

impl RollingSpheres {
    /// 003 §2.2's closed form of the curvature, Δ(X, X̃) = α₁α₂ u × ((z₁Ω₁ − z₂Ω₂) × (z₁Ω̃₁ −
    /// z₂Ω̃₂)), at the configuration of `z` (its velocities are ignored).
    pub fn curvature(
        &self,
        z: &[f64],
        omega: [[f64; 3]; 2],
        omega_tilde: [[f64; 3]; 2],
    ) -> Result<[f64; 3]> {
        let l = self.observed(z)?;
        check::finite_slice("omega", omega.as_flattened())?;
        check::finite_slice("omega_tilde", omega_tilde.as_flattened())?;
        let v = |o: [[f64; 3]; 2]| l.z[0] * Vector3::from(o[0]) - l.z[1] * Vector3::from(o[1]);
        let d = l.u.cross(&v(omega).cross(&v(omega_tilde))) * (self.alpha[0] * self.alpha[1]);
        finite1("the curvature", arr(&d))
    }

    /// The curvature Δ(X, X̃) = −ν[X, X̃] (003 §2.2) computed numerically from the Lie bracket of
    /// the constrained fields X = (Ω₁, Ω₂, (α₁z₁Ω₁ + α₂z₂Ω₂) × u), X̃ likewise (Ω_k constant in
    /// the left trivialization), with ν(Ω₁, Ω₂, v) = v − (α₁z₁Ω₁ + α₂z₂Ω₂) × u.
    ///
    /// How: the flow of X is exact, φ_t(z₁, z₂, u) = (z₁exp(tΩ̂₁), z₂exp(tΩ̂₂), exp(t b̂)u) with
    /// b = α₁z₁Ω₁ + α₂z₂Ω₂ (constant along the flow, as z_k exp(tΩ̂_k)Ω_k = z_kΩ_k). The flow
    /// commutator C(s) = φ̃_{−s} ∘ φ_{−s} ∘ φ̃_s ∘ φ_s(q) = q + s²[X, X̃] + O(s³) (for
    /// [X, Y] = XY − YX as derivations) is read in the chart of q — vee(log(z_k⁻¹ z_k(s))) on
    /// SO(3) (left trivialization), u(s) − u on S² — divided by s², symmetrized in ±s (odd
    /// orders cancel) and Richardson-extrapolated from s and 2s: error O(s⁴) + O(ε/s²).
    /// s ≈ 5e-3 gives ~1e-10 relative.
    pub fn curvature_by_brackets(
        &self,
        z: &[f64],
        omega: [[f64; 3]; 2],
        omega_tilde: [[f64; 3]; 2],
        s: f64,
    ) -> Result<[f64; 3]> {
        let l = self.observed(z)?;
        check::finite_slice("omega", omega.as_flattened())?;
        check::finite_slice("omega_tilde", omega_tilde.as_flattened())?;
        check::positive("s", s)?;
        let o = omega.map(Vector3::from);
        let ot = omega_tilde.map(Vector3::from);
        let flow = |q: &mut ([Matrix3<f64>; 2], Vector3<f64>), om: &[Vector3<f64>; 2], t: f64| {
            let b = (q.0[0] * om[0]) * self.alpha[0] + (q.0[1] * om[1]) * self.alpha[1];
            q.1 = so3::exp_unchecked(&(b * t)) * q.1;
            for (zi, oi) in q.0.iter_mut().zip(om) {
                *zi *= so3::exp_unchecked(&(oi * t));
            }
        };
        // The bracket estimate (components in the chart of q: Ω₁, Ω₂, u̇).
        let d = |h: f64| -> [Vector3<f64>; 3] {
            let mut q = (l.z, l.u);
            flow(&mut q, &o, h);
            flow(&mut q, &ot, h);
            flow(&mut q, &o, -h);
            flow(&mut q, &ot, -h);
            let h2 = h * h;
            [
                so3::log_unchecked(&(l.z[0].transpose() * q.0[0])) / h2,
                so3::log_unchecked(&(l.z[1].transpose() * q.0[1])) / h2,
                (q.1 - l.u) / h2,
            ]
        };
        let sym = |h: f64| {
            let (p, m) = (d(h), d(-h));
            [0, 1, 2].map(|i| (p[i] + m[i]) * 0.5)
        };
        let (d1, d2) = (sym(s), sym(2.0 * s));
        let br = [0, 1, 2].map(|i| (d1[i] * 4.0 - d2[i]) / 3.0);
        let nu =
            br[2] - (l.z[0] * br[0] * self.alpha[0] + l.z[1] * br[1] * self.alpha[1]).cross(&l.u);
        finite1("the curvature", arr(&(-nu)))
    }
}
