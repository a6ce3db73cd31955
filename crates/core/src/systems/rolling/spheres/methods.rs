//! The system as a problem of the driver, in the momentum chart (z₁, z₂, u, P₁, P₂), P = Mω:
//! the Lie-group field on SO(3)² × S² × ℝ⁶, the flat field of the RK4 baseline, and the catalog.

use nalgebra::{Matrix3, Vector3, Vector6};

use super::{arr, local, put_rows, Kin, RollingSpheres, STATE_DIM};
use crate::check;
use crate::error::Result;
use crate::integrate::methods::{Composition, LieMidpoint, Rk4, Rkmk4};
use crate::integrate::problem::{GroupField, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::so3::{self, hat};

impl Problem for RollingSpheres {
    fn name(&self) -> &'static str {
        "RollingSpheres"
    }
    fn space(&self) -> Space {
        Space::new([
            ("z1", Block::SO3),
            ("z2", Block::SO3),
            ("u", Block::Sphere),
            ("Omega1", Block::Real(3)),
            ("Omega2", Block::Real(3)),
        ])
    }
    /// The kinetic energy of the two bodies, eR²·L (L of (8)) = eR²(½Ω₁ᵀK₁Ω₁ + ½Ω₂ᵀK₂Ω₂ +
    /// ½|w|²).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let l = local(z);
        let k = self.kin(&l);
        let w = self.w(&k);
        Ok(self.scale()
            * 0.5
            * (l.omega[0].dot(&(self.k[0] * l.omega[0]))
                + l.omega[1].dot(&(self.k[1] * l.omega[1]))
                + w.norm_squared()))
    }
    /// The total angular momentum eR²·J ([`RollingSpheres::angular_momentum`]): in the internal
    /// frame it is the sum P₁ + P₂ of two state blocks whose rates ṡ₁ × w and ṡ₂ × w cancel
    /// identically (ṡ₁ + ṡ₂ = w), so every method that updates the blocks by linear combinations
    /// of field values keeps P₁ + P₂ to round-off; the methods that also keep SO(3) and S² (all
    /// but RK4) keep J to round-off (measured ~1e-14 relative over 10⁵ steps).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        // Not [`RollingSpheres::angular_momentum`]: a run's states are read as they are (RK4
        // leaves SO(3) and S² slowly; the driver's finiteness guard covers the rest).
        check::len_of("state", z, STATE_DIM)?;
        Ok(arr(&(self.noether(&local(z)) * self.scale())).to_vec())
    }
    fn invariant_names(&self) -> Vec<String> {
        vec!["J₁".into(), "J₂".into(), "J₃".into()]
    }
    /// (z₁, z₂, u, Ω₁, Ω₂) ↦ (z₁, z₂, u, P₁, P₂), the spatial momenta P = Mω (rescaled units).
    fn to_internal(&self, z: &mut [f64]) {
        let l = local(z);
        let k = self.kin(&l);
        let p = self.mass_matrix(&l.z, &k)
            * Vector6::from_iterator(k.w[0].iter().chain(k.w[1].iter()).copied());
        z[21..27].copy_from_slice(p.as_slice());
    }
    /// (z₁, z₂, u, P₁, P₂) ↦ (z₁, z₂, u, Ω₁, Ω₂), Ω_k = z_kᵀ(M⁻¹P)_k.
    fn to_user(&self, z: &mut [f64]) {
        let l = local(z);
        let w = self.omegas_from_momenta(&l.z, &l.u, &z[21..27]);
        for i in 0..2 {
            let o = l.z[i].transpose() * w[i];
            z[21 + 3 * i..24 + 3 * i].copy_from_slice(o.as_slice());
        }
    }
    /// The chart's tangent map at z, δP = M δω + DM\[δz\]ω (`tangent.rs`).
    fn tangent_to_internal_at(&self, z: &[f64], dz: &mut [f64]) {
        self.chart_tangent(z, dz, false)
    }
    /// Its inverse at the internal state z.
    fn tangent_to_user_at(&self, z: &[f64], dz: &mut [f64]) {
        self.chart_tangent_inverse(z, dz, false)
    }
    /// The chart's tangent map on an ambient direction (δz_k a 3×3 matrix).
    fn ambient_to_internal_at(&self, z: &[f64], dz: &mut [f64]) {
        self.chart_tangent(z, dz, true)
    }
    /// The derivative of [`Problem::to_user`] at the internal state z (off SO(3) too), ambient.
    fn ambient_to_user_at(&self, z: &[f64], dz: &mut [f64]) {
        self.chart_tangent_inverse(z, dz, true)
    }
}

impl RollingSpheres {
    /// The field of an internal state (z₁, z₂, u, P₁, P₂): the spatial ω = M⁻¹P, the kinematics
    /// and the momentum rates ṡ_k × w.
    fn internal_field(&self, z: &[f64]) -> (Kin, [Vector3<f64>; 2]) {
        let l = local(z);
        let w = self.omegas_from_momenta(&l.z, &l.u, &z[21..27]);
        let k = self.kin_spatial(&l.z, &l.u, w);
        let ww = self.w(&k);
        let sd = self.sdot(&k);
        let rates = [sd[0].cross(&ww), sd[1].cross(&ww)];
        (k, rates)
    }

    /// The spatial angular velocities ω from the momenta P = Mω of an internal state (NaN if M
    /// is not positive definite, which valid bodies exclude).
    pub(super) fn omegas_from_momenta(
        &self,
        z: &[Matrix3<f64>; 2],
        u: &Vector3<f64>,
        p: &[f64],
    ) -> [Vector3<f64>; 2] {
        // M depends on the configuration only (s_k), not on ω.
        let k = self.kin_spatial(z, u, [Vector3::zeros(); 2]);
        match self.mass_matrix(z, &k).cholesky() {
            Some(c) => {
                let x = c.solve(&Vector6::from_column_slice(p));
                [x.fixed_rows::<3>(0).into(), x.fixed_rows::<3>(3).into()]
            }
            None => [Vector3::repeat(f64::NAN); 2],
        }
    }
}

/// ż = (ω̂₁z₁, ω̂₂z₂, u̇, Ṗ₁, Ṗ₂) on the flat 27 values of the internal frame (for the RK4
/// baseline).
impl VectorField for RollingSpheres {
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let (k, rates) = self.internal_field(z);
        for i in 0..2 {
            let zi = Matrix3::from_row_slice(&z[9 * i..9 * i + 9]);
            put_rows(&(hat(&k.w[i]) * zi), &mut dz[9 * i..9 * i + 9]);
        }
        dz[18..21].copy_from_slice(k.udot.as_slice());
        dz[21..24].copy_from_slice(rates[0].as_slice());
        dz[24..27].copy_from_slice(rates[1].as_slice());
    }
}

/// g = so(3) × so(3) × so(3) × ℝ³ × ℝ³ acting on the left on the internal state:
/// z_k ↦ exp(ξ̂_k)z_k, u ↦ exp(ξ̂_u)u, P_k ↦ P_k + ξ_{P_k}; ξ(z) = (ω₁, ω₂, α₁ω₁ + α₂ω₂,
/// ṡ₁ × w, ṡ₂ × w) with ω = M⁻¹P (ż_k = z_kΩ̂_k = ω̂_kz_k and (10)). dexp⁻¹ is J_l⁻¹ on each
/// so(3) factor (as for [`crate::systems::RigidBody`]) and the identity on ℝ⁶.
impl GroupField for RollingSpheres {
    type Scratch = ();
    fn scratch(&self) {}
    fn algebra_dim(&self) -> usize {
        15
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut ()) {
        let (k, rates) = self.internal_field(z);
        let b = k.w[0] * self.alpha[0] + k.w[1] * self.alpha[1];
        xi[0..3].copy_from_slice(k.w[0].as_slice());
        xi[3..6].copy_from_slice(k.w[1].as_slice());
        xi[6..9].copy_from_slice(b.as_slice());
        xi[9..12].copy_from_slice(rates[0].as_slice());
        xi[12..15].copy_from_slice(rates[1].as_slice());
    }
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut ()) {
        let mut dz = [0.0; STATE_DIM];
        self.act_increment(xi, z, &mut dz, s);
        z.iter_mut().zip(dz).for_each(|(zi, d)| *zi += d);
    }
    /// The increments (exp(ξ̂_k) − I)z_k, (exp(ξ̂_u) − I)u and ξ_P (`so3::Rodrigues`: no bias per
    /// step from a rotation matrix rounded to an ulp of 1).
    fn act_increment(&self, xi: &[f64], z: &[f64], dz: &mut [f64], _s: &mut ()) -> bool {
        for i in 0..2 {
            let g = so3::Rodrigues::exp(&Vector3::from_column_slice(&xi[3 * i..3 * i + 3]));
            let d = g.left_increment(&Matrix3::from_row_slice(&z[9 * i..9 * i + 9]));
            put_rows(&d, &mut dz[9 * i..9 * i + 9]);
        }
        let g = so3::Rodrigues::exp(&Vector3::from_column_slice(&xi[6..9]));
        let d = g.increment(&Vector3::from_column_slice(&z[18..21]));
        dz[18..21].copy_from_slice(d.as_slice());
        dz[21..27].copy_from_slice(&xi[9..15]);
        true
    }
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], _s: &mut ()) {
        for i in 0..3 {
            let r = 3 * i..3 * i + 3;
            match so3::jacobian_left_inv(&Vector3::from_column_slice(&u[r.clone()])) {
                Ok(j) => out[r.clone()]
                    .copy_from_slice((j * Vector3::from_column_slice(&v[r])).as_slice()),
                Err(_) => out[r].fill(f64::NAN),
            }
        }
        out[9..15].copy_from_slice(&v[9..15]);
    }
}

impl Catalog for RollingSpheres {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("midpoint", LieMidpoint::new),
            Entry::new("midpoint4", || LieMidpoint(Composition::suzuki4())),
            Entry::new("rkmk4", || Rkmk4),
            Entry::new("rk4", || Rk4),
        ]
    }

    /// The lift of the Lie-group methods (`tangent.rs`).
    fn tangent(&self) -> Option<std::sync::Arc<dyn crate::integrate::tangent::TangentSystem>> {
        Some(self.lift())
    }

    /// `rk4` on the field lift (ambient directions), the others on [`Catalog::tangent`]'s.
    fn tangent_for(
        &self,
        method: &str,
    ) -> Option<std::sync::Arc<dyn crate::integrate::tangent::TangentSystem>> {
        self.lift_for(method)
    }
}
