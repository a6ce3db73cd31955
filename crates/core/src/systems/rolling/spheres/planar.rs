//! The holonomic subsystem T𝒬₀ (003 §2.4): the planar motion about e₃, where the spheres are the
//! rolling disks of 003 §1.

use nalgebra::Vector3;

use super::{local, RollingSpheres, STATE_DIM};
use crate::check;
use crate::error::{Error, Result};

impl RollingSpheres {
    /// The state of the planar motion (003 §2.4 ↔ §1): z_k the rotation by θ_k about e₃,
    /// u = (cos φ, sin φ, 0), Ω_k = θ̇_k e₃. Then (10) gives u̇ = φ̇ e₃ × u with
    /// φ̇ = α₁θ̇₁ + α₂θ̇₂, i.e. 003 §1's R φ̇ = r₁θ̇₁ + r₂θ̇₂ (u = e^{iφ}, z_k = e^{iθ_k}).
    ///
    /// The correspondence with the disks of 003 §1: the plane ⊥ e₃ is ℂ (x + iy); disk k has
    /// radius r_k, mass m_k, centre of mass γ_k,x + iγ_k,y, and 003 §1's moment of inertia
    /// ∫|p|²dρ_k about the disk's centre equals e₃ᵀJ_k⁰e₃ + m_k|γ_k|² = (I_k)₁₁ + (I_k)₂₂ +
    /// m_k|γ_k|². For this state to stay planar the bodies must be planar-symmetric
    /// ([`RollingSpheres::is_planar`]). Errors: non-finite input.
    pub fn planar_state(&self, theta: [f64; 2], phi: f64, theta_dot: [f64; 2]) -> Result<Vec<f64>> {
        check::finite_slice(
            "planar state",
            &[theta[0], theta[1], phi, theta_dot[0], theta_dot[1]],
        )?;
        let rot = |t: f64| {
            let (s, c) = t.sin_cos();
            [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
        };
        let (s, c) = phi.sin_cos();
        self.state(
            rot(theta[0]),
            rot(theta[1]),
            [c, s, 0.0],
            [0.0, 0.0, theta_dot[0]],
            [0.0, 0.0, theta_dot[1]],
        )
    }

    /// The planar coordinates (θ₁, θ₂, φ, θ̇₁, θ̇₂) of a state in T𝒬₀ (the inverse of
    /// [`RollingSpheres::planar_state`], angles in (−π, π]). Errors: a state off T𝒬₀ by more
    /// than `tol` (in z_ke₃ − e₃, u₃ and the in-plane parts of Ω_k), a state of the wrong
    /// length.
    pub fn to_planar(&self, z: &[f64], tol: f64) -> Result<[f64; 5]> {
        check::len_of("state", z, STATE_DIM)?;
        check::finite_slice("state", z)?;
        let l = local(z);
        let e3 = Vector3::z();
        let off = (l.z[0] * e3 - e3)
            .norm()
            .max((l.z[1] * e3 - e3).norm())
            .max(l.u[2].abs())
            .max(l.omega[0].xy().norm())
            .max(l.omega[1].xy().norm());
        if off > tol {
            return Err(Error::invalid(
                "state",
                format!("not in T𝒬₀ (planar motion about e₃): defect {off:.3e} > {tol:.1e}"),
            ));
        }
        Ok([
            l.z[0][(1, 0)].atan2(l.z[0][(0, 0)]),
            l.z[1][(1, 0)].atan2(l.z[1][(0, 0)]),
            l.u[1].atan2(l.u[0]),
            l.omega[0][2],
            l.omega[1][2],
        ])
    }

    /// Whether T𝒬₀ is invariant for these bodies (003 §2.4): γ_k·e₃ = 0 and e₃ an eigenvector of
    /// I_k (both to `tol`, relative to r_k and ‖I_k‖).
    pub fn is_planar(&self, tol: f64) -> bool {
        (0..2).all(|i| {
            let a = self.inertias[i];
            let col = Vector3::new(a[(0, 2)], a[(1, 2)], 0.0);
            self.gammas[i][2].abs() <= tol * self.radii[i]
                && col.norm() <= tol * a.norm().max(f64::MIN_POSITIVE)
        })
    }
}
