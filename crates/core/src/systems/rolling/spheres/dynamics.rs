//! The Lagrangian (8), the momenta and the Noether momentum (003 §2.1), and the equations of
//! motion of Lagrange–d'Alembert as the 6 × 6 system of the mass matrix (003 §2.3).

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::{arr, finite1, finite2, Kin, Local, RollingSpheres};
use crate::error::Result;
use crate::lie::so3::hat;

impl RollingSpheres {
    /// The constrained mass matrix M = diag(K₁^s, K₂^s) + SᵀS, S = [ŝ₁ ŝ₂] (spatial; module docs).
    pub(super) fn mass_matrix(&self, z: &[Matrix3<f64>; 2], k: &Kin) -> Matrix6<f64> {
        let sh = [hat(&k.s[0]), hat(&k.s[1])];
        let mut m = Matrix6::zeros();
        for i in 0..2 {
            for j in 0..2 {
                let mut b = -sh[i] * sh[j];
                if i == j {
                    b += z[i] * self.k[i] * z[i].transpose();
                }
                m.fixed_view_mut::<3, 3>(3 * i, 3 * j).copy_from(&b);
            }
        }
        m
    }

    /// The spatial momenta eR²·(P₁, P₂), P_k = ∂L_c/∂ω_k = K_k^sω_k + s_k × w of the constrained
    /// Lagrangian L_c(ω) = L with u̇ from (10) (physical units). P₁ + P₂ is the total angular
    /// momentum, and Ṗ_k = ṡ_k × w (module docs).
    pub fn spatial_momenta(&self, z: &[f64]) -> Result<[[f64; 3]; 2]> {
        let l = self.observed(z)?;
        let k = self.kin(&l);
        let w = self.w(&k);
        let sc = self.scale();
        finite2(
            "the spatial momenta",
            [0, 1].map(|i| arr(&((l.z[i] * self.k[i] * l.omega[i] + k.s[i].cross(&w)) * sc))),
        )
    }

    /// The rates eR²·(Ṗ₁, Ṗ₂) = eR²·(ṡ₁ × w, ṡ₂ × w) of [`RollingSpheres::spatial_momenta`]
    /// (physical units; they sum to zero).
    pub fn momentum_rates(&self, z: &[f64]) -> Result<[[f64; 3]; 2]> {
        let k = self.kin(&self.observed(z)?);
        let w = self.w(&k);
        let sd = self.sdot(&k);
        finite2(
            "the momentum rates",
            [0, 1].map(|i| arr(&(sd[i].cross(&w) * self.scale()))),
        )
    }

    /// L of (8), evaluated literally (with u̇ from (10)).
    pub fn lagrangian(&self, z: &[f64]) -> Result<f64> {
        let l = self.observed(z)?;
        let ud = self.kin(&l).udot;
        let [a1, a2] = self.alpha;
        let b1 = l.z[0] * l.omega[0].cross(&self.e[0]);
        let b2 = l.z[1] * l.omega[1].cross(&self.e[1]);
        let v = 0.5 * l.omega[0].dot(&(self.j[0] * l.omega[0]))
            + 0.5 * l.omega[1].dot(&(self.j[1] * l.omega[1]))
            + 0.5 * ud.norm_squared()
            - ud.dot(&(b1 * a1 - b2 * a2))
            - a1 * a2 * b1.dot(&b2);
        Ok(finite1("the Lagrangian", [v])?[0])
    }

    /// The body momenta p_k = ∂L/∂Ω_k of (8) (003 §2.3): p₁ = J₁Ω₁ − α₁e₁ × z₁ᵀ(u̇ + α₂b₂),
    /// p₂ = J₂Ω₂ + α₂e₂ × z₂ᵀ(u̇ − α₁b₁), rescaled.
    fn momenta(&self, l: &Local, k: &Kin) -> [Vector3<f64>; 2] {
        let [a1, a2] = self.alpha;
        let b1 = k.w[0].cross(&k.eps[0]);
        let b2 = k.w[1].cross(&k.eps[1]);
        [
            self.j[0] * l.omega[0]
                - self.e[0].cross(&(l.z[0].transpose() * (k.udot + b2 * a2))) * a1,
            self.j[1] * l.omega[1]
                + self.e[1].cross(&(l.z[1].transpose() * (k.udot - b1 * a1))) * a2,
        ]
    }

    /// The Noether momentum of the diagonal SO(3) symmetry of L (003 §2.1),
    /// J = z₁p₁ + z₂p₂ + u × ∂L/∂u̇ (rescaled units; conserved).
    pub fn noether_momentum(&self, z: &[f64]) -> Result<[f64; 3]> {
        let l = self.observed(z)?;
        finite1("the Noether momentum", arr(&self.noether(&l)))
    }

    pub(super) fn noether(&self, l: &Local) -> Vector3<f64> {
        let k = self.kin(l);
        let p = self.momenta(l, &k);
        l.z[0] * p[0] + l.z[1] * p[1] + l.u.cross(&self.w(&k))
    }

    /// The total angular momentum about the centre of mass (physical units), eR²·J
    /// ([`RollingSpheres::noether_momentum`]).
    pub fn angular_momentum(&self, z: &[f64]) -> Result<[f64; 3]> {
        let j = self.noether(&self.observed(z)?) * self.scale();
        finite1("the angular momentum", arr(&j))
    }

    /// The body momenta eR²·p_k = eR²·∂L/∂Ω_k (physical units); p_k·e_k/|e_k| is the Noether
    /// quantity of the material rotation of body k about e_k (not conserved, 003 §2.1).
    pub fn body_momenta(&self, z: &[f64]) -> Result<[[f64; 3]; 2]> {
        let l = self.observed(z)?;
        let p = self.momenta(&l, &self.kin(&l));
        finite2(
            "the body momenta",
            [arr(&(p[0] * self.scale())), arr(&(p[1] * self.scale()))],
        )
    }

    /// Ω̇_k from the 6 × 6 system of the module docs (spatial ω̇_k, then Ω̇_k = z_kᵀω̇_k); NaN if
    /// the system is not positive definite (it always is for valid bodies).
    fn accel(&self, l: &Local) -> [Vector3<f64>; 2] {
        let k = self.kin(l);
        let sd = self.sdot(&k);
        let acc = k.w[0].cross(&sd[0]) + k.w[1].cross(&sd[1]);
        let m = self.mass_matrix(&l.z, &k);
        let mut f = Vector6::zeros();
        for i in 0..2 {
            let ks = l.z[i] * self.k[i] * l.z[i].transpose();
            let fi = (ks * k.w[i]).cross(&k.w[i]) - k.s[i].cross(&acc);
            f.fixed_rows_mut::<3>(3 * i).copy_from(&fi);
        }
        match m.cholesky() {
            Some(c) => {
                let x = c.solve(&f);
                [
                    l.z[0].transpose() * x.fixed_rows::<3>(0),
                    l.z[1].transpose() * x.fixed_rows::<3>(3),
                ]
            }
            None => [Vector3::repeat(f64::NAN); 2],
        }
    }

    /// The body angular accelerations (Ω̇₁, Ω̇₂) of the Lagrange–d'Alembert equations (module
    /// docs).
    pub fn accelerations(&self, z: &[f64]) -> Result<[[f64; 3]; 2]> {
        let a = self.accel(&self.observed(z)?);
        finite2("the accelerations", [arr(&a[0]), arr(&a[1])])
    }
}
