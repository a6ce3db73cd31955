//! 003 §2.4 across the two systems: spheres whose centres of mass and contact point lie in the
//! plane ⊥ e₃, spinning about e₃, stay in that plane and move as the rolling disks of 003 §1 with
//! the same parameters (disk moment about the centre (I_k)₁₁ + (I_k)₂₂ + m_k|γ_k|²). The
//! difference of the two computed motions is the integrators' error: it falls by 2⁴ as the
//! step halves.

use lieflow::integrate::integrate;
use lieflow::systems::{RollingDisks, RollingSpheres};

const R: [f64; 2] = [1.0, 0.7];
const GAMMA: [[f64; 2]; 2] = [[0.3, 0.1], [-0.2, 0.25]];
const M: [f64; 2] = [1.0, 1.5];

/// Second moments about the centres of mass with e₃ as an eigenvector (planar-symmetric bodies).
fn moments() -> [[[f64; 3]; 3]; 2] {
    [
        [[0.30, 0.05, 0.0], [0.05, 0.20, 0.0], [0.0, 0.0, 0.4]],
        [[0.15, -0.03, 0.0], [-0.03, 0.25, 0.0], [0.0, 0.0, 0.3]],
    ]
}

fn wrap(d: f64) -> f64 {
    (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

#[test]
fn planar_spheres_are_the_rolling_disks() {
    let i = moments();
    let spheres = RollingSpheres::new(
        R[0],
        R[1],
        [GAMMA[0][0], GAMMA[0][1], 0.0],
        [GAMMA[1][0], GAMMA[1][1], 0.0],
        M[0],
        M[1],
        i[0],
        i[1],
    )
    .unwrap();
    assert!(spheres.is_planar(1e-14));
    let disk_moment =
        |k: usize| i[k][0][0] + i[k][1][1] + M[k] * (GAMMA[k][0].powi(2) + GAMMA[k][1].powi(2));
    let (theta, phi, thetadot) = ([0.3, -1.1], 0.5, [0.7, 0.2]);
    let c = (R[0] + R[1]) * phi - R[0] * theta[0] - R[1] * theta[1];
    let disks = RollingDisks::new(R, GAMMA, M, [disk_moment(0), disk_moment(1)])
        .unwrap()
        .with_rolling_constant(c)
        .unwrap();
    let z_disks = disks.state(theta, thetadot).unwrap();
    let z_spheres = spheres.planar_state(theta, phi, thetadot).unwrap();
    let t_end = 5.0;
    let gap = |dt: f64| {
        let steps = (t_end / dt).round() as usize;
        let a = integrate(&disks, "gauss6", &z_disks, dt, steps, steps / 10).unwrap();
        let b = integrate(&spheres, "midpoint4", &z_spheres, dt, steps, steps / 10).unwrap();
        let mut worst: f64 = 0.0;
        for k in 0..a.len() {
            let zd = a.state(k);
            // stays in T𝒬₀ to round-off, and its planar coordinates are the disks'
            let p = spheres.to_planar(b.state(k), 1e-13).unwrap();
            let v = disks.velocities(zd).unwrap();
            let phi_d = disks.phi([zd[0], zd[1]]);
            worst = worst
                .max(wrap(p[0] - zd[0]).abs())
                .max(wrap(p[1] - zd[1]).abs())
                .max(wrap(p[2] - phi_d).abs())
                .max((p[3] - v[0]).abs())
                .max((p[4] - v[1]).abs());
        }
        worst
    };
    let (coarse, fine) = (gap(0.02), gap(0.01));
    eprintln!(
        "planar spheres vs disks to t = {t_end}: {coarse:.2e} (dt = 0.02), {fine:.2e} (dt = 0.01), ratio {:.1}",
        coarse / fine
    );
    assert!(fine < 1e-7, "the two systems disagree: {fine}");
    assert!(
        (coarse / fine).log2() > 3.5,
        "not the integrators' order-4 error"
    );
}
