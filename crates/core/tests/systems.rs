//! The other Lie–Poisson systems (heavy top, spherical pendulum, the so(n) body), inertia given as
//! a matrix, the batch driver, chunked integration and every error path of the driver.

mod common;

use common::order;
use lieflow::integrate::{check_state, integrate, integrate_batch, Problem, System, Trajectory};
use lieflow::lie::so3;
use lieflow::systems::{GeneralizedRigidBody, HeavyTop, RigidBody, SphericalPendulum};
use lieflow::{Error, Mat};
use nalgebra::{Matrix3, Vector3};

const M0: [f64; 3] = [1.0, 0.5, -0.3];

fn row_major(r: &Matrix3<f64>) -> [f64; 9] {
    let mut o = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            o[3 * i + j] = r[(i, j)];
        }
    }
    o
}

fn max_rel_drift<S: Problem>(s: &S, traj: &Trajectory, k: usize) -> f64 {
    let c0 = s.invariants(traj.state(0)).unwrap()[k];
    (0..traj.len())
        .map(|i| ((s.invariants(traj.state(i)).unwrap()[k] - c0) / c0).abs())
        .fold(0.0, f64::max)
}

fn energy_tenths<S: Problem>(s: &S, traj: &Trajectory) -> (f64, f64) {
    let h0 = s.energy(traj.state(0)).unwrap();
    let n = traj.len();
    let rel = |k: usize| ((s.energy(traj.state(k)).unwrap() - h0) / h0).abs();
    (
        (1..n / 10).map(rel).fold(0.0, f64::max),
        (n - n / 10..n).map(rel).fold(0.0, f64::max),
    )
}

// ---------------------------------------------------------------- heavy top

/// Errors at t = 2 against `reference` for the step sizes `dts` and the observed order
/// log₂(e₀/e₁) (`dts[1] = dts[0]/2`).
fn observed_order<S: System>(
    sys: &S,
    method: &str,
    s0: &[f64],
    reference: &[f64],
    dts: [f64; 2],
) -> ([f64; 2], f64) {
    let e = dts.map(|dt| {
        let n = (2.0 / dt) as usize;
        let z = integrate(sys, method, s0, dt, n, n).unwrap().final_state;
        z.iter()
            .zip(reference)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
    });
    (e, (e[0] / e[1]).log2())
}

fn top() -> HeavyTop {
    HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap()
}

/// A state (M, Γ, R) of the top with attitude, `top().with_attitude()`.
fn top_state() -> Vec<f64> {
    let r = so3::exp_unchecked(&Vector3::new(0.4, -0.2, 0.1));
    top().state_with_attitude(M0, row_major(&r))
}

#[test]
fn heavy_top_energy_sign_is_the_conserved_one() {
    // RK4 at a small step conserves H = ½M·I⁻¹M + mgl Γ·χ; with the opposite sign of the
    // potential the "energy" changes at O(1).
    let t = top().with_attitude();
    let s0 = top_state();
    let traj = integrate(&t, "rk4", &s0, 1e-3, 10_000, 10_000).unwrap();
    let (a, b) = (traj.state(0), traj.state(1));
    assert!((t.energy(b).unwrap() - t.energy(a).unwrap()).abs() < 1e-10);
    let pot = |z: &[f64]| 0.7 * Vector3::from_column_slice(&z[3..6]).dot(&Vector3::from(t.chi()));
    let wrong = |z: &[f64]| t.energy(z).unwrap() - 2.0 * pot(z);
    assert!((wrong(b) - wrong(a)).abs() > 1e-3);
}

#[test]
fn heavy_top_geometric_methods_keep_casimirs_and_bounded_energy() {
    let t = top().with_attitude();
    let s0 = top_state();
    for method in ["splitting", "splitting4", "lgvi"] {
        let traj = integrate(&t, method, &s0, 0.01, 1_000_000, 100).unwrap();
        let g2 = max_rel_drift(&t, &traj, 0);
        let c0 = t.invariants(traj.state(0)).unwrap()[1];
        let mg = (0..traj.len())
            .map(|k| (t.invariants(traj.state(k)).unwrap()[1] - c0).abs())
            .fold(0.0, f64::max);
        let gamma_r = (0..traj.len())
            .map(|k| {
                // Sample k is (M, Γ, R): R occupies [6..15], its third row Rᵀe₃ is [12..15].
                let z = traj.state(k);
                let a = &z[6..15];
                (0..3)
                    .map(|i| (a[6 + i] - z[3 + i]).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        let (first, last) = energy_tenths(&t, &traj);
        eprintln!("{method}: |Γ|² {g2:.2e}, M·Γ {mg:.2e}, Γ−Rᵀe₃ {gamma_r:.2e}, energy {first:.2e} → {last:.2e}");
        assert!(
            g2 < 1e-12 && mg < 1e-12,
            "{method}: Casimirs drift {g2:e} {mg:e}"
        );
        assert!(gamma_r < 1e-12, "{method}: Γ ≠ Rᵀe₃ ({gamma_r:e})");
        assert!(last <= 2.0 * first, "{method}: energy {first:e} → {last:e}");
    }
}

#[test]
fn lagrange_top_keeps_m3() {
    let t = HeavyTop::new([1.0, 1.0, 2.0], 1.3, [0.0, 0.0, 1.0]).unwrap();
    let s0 = t.state([0.3, -0.4, 2.0], [0.1, 0.6, (1.0f64 - 0.37).sqrt()]);
    for method in ["splitting", "splitting6", "lgvi"] {
        let traj = integrate(&t, method, &s0, 0.01, 200_000, 100).unwrap();
        let d = (0..traj.len())
            .map(|k| (traj.state(k)[2] - 2.0).abs())
            .fold(0.0, f64::max);
        eprintln!("{method}: M₃ drift {d:.2e}");
        assert!(d < 1e-12, "{method}: M₃ drift {d:e}");
    }
}

#[test]
fn heavy_top_orders_and_zero_gravity_limit() {
    let t = top();
    let s0 = t.state(M0, [0.1, 0.2, (0.95f64).sqrt()]);
    let reference = integrate(&t, "splitting6", &s0, 1e-3, 2000, 2000)
        .unwrap()
        .final_state;
    for (method, dts) in [
        ("splitting", [0.02, 0.01]),
        ("splitting4", [0.1, 0.05]),
        ("lgvi", [0.02, 0.01]),
        ("rk4", [0.1, 0.05]),
    ] {
        let (e, p) = observed_order(&t, method, &s0, &reference, dts);
        eprintln!("heavy top {method}: errors {e:?}, order {p:.3}");
        assert!(
            (p - order(&t, method) as f64).abs() < 0.2,
            "{method}: order {p}"
        );
    }
    // mgl = 0: M follows the free rigid body.
    let free = HeavyTop::new([1.0, 2.0, 3.0], 0.0, [0.0, 0.0, 1.0]).unwrap();
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let a = integrate(&free, "splitting4", &s0, 0.01, 500, 500)
        .unwrap()
        .final_state;
    let exact = body.exact_momentum(&M0, 5.0).unwrap();
    assert!((0..3).all(|i| (a[i] - exact[i]).abs() < 1e-8));
}

// ---------------------------------------------------------------- spherical pendulum

/// 000 §5.1.1 (θ from the downward vertical): θ̈ = sinθ cosθ φ̇² − (g/l) sinθ,
/// φ̈ = −2 φ̇ θ̇ cosθ / sinθ, integrated here with a small-step RK4 as an independent reference.
fn spherical_reference(y0: [f64; 4], g_over_l: f64, t: f64, n: usize) -> [f64; 4] {
    let f = |y: [f64; 4]| {
        let (s, c) = y[0].sin_cos();
        [
            y[2],
            y[3],
            s * c * y[3] * y[3] - g_over_l * s,
            -2.0 * y[3] * y[2] * c / s,
        ]
    };
    let h = t / n as f64;
    let mut y = y0;
    let add = |y: [f64; 4], k: [f64; 4], a: f64| [0, 1, 2, 3].map(|i| y[i] + a * k[i]);
    for _ in 0..n {
        let k1 = f(y);
        let k2 = f(add(y, k1, h / 2.0));
        let k3 = f(add(y, k2, h / 2.0));
        let k4 = f(add(y, k3, h));
        y = [0, 1, 2, 3].map(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    y
}

#[test]
fn spherical_pendulum_matches_spherical_coordinates() {
    let p = SphericalPendulum::new(0.8, 1.5, 9.81).unwrap();
    let y0 = [1.0, 0.3, 0.2, 1.5];
    let s0 = p.state_from_spherical(y0[0], y0[1], y0[2], y0[3]).unwrap();
    let y = spherical_reference(y0, 9.81 / 1.5, 3.0, 300_000);
    let expected = p.state_from_spherical(y[0], y[1], y[2], y[3]).unwrap();
    for method in ["splitting4", "splitting6", "rk4"] {
        let z = integrate(&p, method, &s0, 1e-3, 3000, 3000)
            .unwrap()
            .final_state;
        let err = z
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        eprintln!("pendulum {method}: max error vs spherical coordinates {err:.2e}");
        assert!(err < 1e-8, "{method}: {err:e}");
    }
}

#[test]
fn spherical_pendulum_keeps_energy_and_vertical_momentum() {
    let p = SphericalPendulum::new(1.0, 1.0, 9.81).unwrap();
    let s0 = p.state_from_spherical(2.0, 0.0, 0.5, 1.2).unwrap();
    let l3 = p.vertical_momentum(&s0).unwrap();
    let traj = integrate(&p, "splitting", &s0, 0.01, 1_000_000, 100).unwrap();
    let dl3 = (0..traj.len())
        .map(|k| (p.vertical_momentum(traj.state(k)).unwrap() - l3).abs() / l3.abs())
        .fold(0.0, f64::max);
    let dq = max_rel_drift(&p, &traj, 0);
    let ql = (0..traj.len())
        .map(|k| p.invariants(traj.state(k)).unwrap()[1].abs())
        .fold(0.0, f64::max);
    let (first, last) = energy_tenths(&p, &traj);
    eprintln!(
        "pendulum: L₃ {dl3:.2e}, |q|² {dq:.2e}, q·L {ql:.2e}, energy {first:.2e} → {last:.2e}"
    );
    assert!(dl3 < 1e-12 && dq < 1e-12 && ql < 1e-12);
    assert!(last <= 2.0 * first);
}

// ---------------------------------------------------------------- so(n)

/// The so(3) body as a generalized rigid body: J_i = (I_j + I_k − I_i)/2, coordinates
/// c = (−M₃, M₂, −M₁). Its isospectral trajectory matches the exact elliptic solution of
/// Ṁ = M × Ω — this fixes the sign of Ṁ = [M, Ω].
#[test]
fn son_body_reduces_to_euler_top() {
    let i = [1.0, 2.0, 3.0];
    let j = [
        (i[1] + i[2] - i[0]) / 2.0,
        (i[0] + i[2] - i[1]) / 2.0,
        (i[0] + i[1] - i[2]) / 2.0,
    ];
    let grb = GeneralizedRigidBody::new(&j).unwrap();
    let body = RigidBody::new(i).unwrap();
    let c = |m: [f64; 3]| vec![-m[2], m[1], -m[0]];
    assert!((grb.energy(&c(M0)).unwrap() - body.energy(&M0).unwrap()).abs() < 1e-15);
    assert!((grb.invariants(&c(M0)).unwrap()[0] - body.invariants(&M0).unwrap()[0]).abs() < 1e-15);
    let exact = c(body.exact_momentum(&M0, 2.0).unwrap());
    for method in ["isospectral", "rk4"] {
        let z = integrate(&grb, method, &c(M0), 1e-3, 2000, 2000)
            .unwrap()
            .final_state;
        let err = z
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-5, "{method}: {err:e}");
    }
}

fn son_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let d = n * (n - 1) / 2;
    let j: Vec<f64> = (0..n).map(|i| 0.5 + 0.37 * i as f64).collect();
    let z: Vec<f64> = (0..d).map(|k| ((k as f64 + 1.0) * 1.7).sin()).collect();
    (j, z)
}

#[test]
fn isospectral_keeps_the_spectrum_on_so4_so5() {
    for n in [4, 5] {
        let (j, z) = son_state(n);
        let b = GeneralizedRigidBody::new(&j).unwrap();
        let traj = integrate(&b, "isospectral", &z, 0.01, 1_000_000, 1000).unwrap();
        let drift = (0..n / 2)
            .map(|k| max_rel_drift(&b, &traj, k))
            .fold(0.0, f64::max);
        let (first, last) = energy_tenths(&b, &traj);
        eprintln!("so({n}): Casimir drift {drift:.2e}, energy {first:.2e} → {last:.2e}");
        assert!(drift < 1e-12, "so({n}): spectrum drift {drift:e}");
        assert!(last <= 2.0 * first);
    }
}

#[test]
fn son_orders_and_matrix_mass() {
    let (j, z) = son_state(4);
    let b = GeneralizedRigidBody::new(&j).unwrap();
    let s0 = z.clone();
    let reference = integrate(&b, "rk4", &s0, 1e-3, 2000, 2000)
        .unwrap()
        .final_state;
    for (method, dts) in [("isospectral", [0.02, 0.01]), ("rk4", [0.1, 0.05])] {
        let (_, p) = observed_order(&b, method, &s0, &reference, dts);
        assert!(
            (p - order(&b, method) as f64).abs() < 0.2,
            "so(4) {method}: order {p}"
        );
    }
    // J given as a full matrix Q diag Qᵀ: the trajectory is the conjugate by Q.
    let q = Mat::from_fn(4, 4, |a, c| {
        let t = 0.3f64;
        match (a, c) {
            (0, 0) | (1, 1) => t.cos(),
            (0, 1) => -t.sin(),
            (1, 0) => t.sin(),
            (2, 2) | (3, 3) => 1.0,
            _ => 0.0,
        }
    });
    let jd = Mat::from_fn(4, 4, |a, c| if a == c { j[a] } else { 0.0 });
    let jm = &q * &jd * q.transpose();
    let bm = GeneralizedRigidBody::from_matrix(&jm).unwrap();
    let m0 = lieflow::lie::so::hat_n(&z).unwrap();
    let zu = lieflow::lie::so::vee_n(&(&q * &m0 * q.transpose())).unwrap();
    assert!((bm.energy(&zu).unwrap() - b.energy(&z).unwrap()).abs() < 1e-13);
    let a = integrate(&b, "isospectral", &s0, 0.01, 100, 100)
        .unwrap()
        .final_state;
    let bz = integrate(&bm, "isospectral", &zu, 0.01, 100, 100)
        .unwrap()
        .final_state;
    let back =
        lieflow::lie::so::vee_n(&(q.transpose() * lieflow::lie::so::hat_n(&bz).unwrap() * &q))
            .unwrap();
    let spec_a = b.invariants(&a).unwrap();
    let spec_b = bm.invariants(&back).unwrap();
    assert!((spec_a[0] - spec_b[0]).abs() < 1e-12);
    // Eigen-order of the matrix route may permute axes; compare energies (frame-independent).
    assert!((b.energy(&a).unwrap() - bm.energy(&bz).unwrap()).abs() < 1e-12);
}

#[test]
fn son_mass_matrix_with_a_zero_eigenvalue_is_accepted() {
    // J = Q diag(0, 1, 2) Qᵀ is PSD with J_i + J_j > 0; round-off in its eigen-decomposition can
    // make the zero eigenvalue slightly negative, which must not be rejected.
    let (c, s) = (0.7f64.cos(), 0.7f64.sin());
    let q = Mat::from_fn(3, 3, |a, b| match (a, b) {
        (0, 0) | (2, 2) => c,
        (0, 2) => -s,
        (2, 0) => s,
        (1, 1) => 1.0,
        _ => 0.0,
    });
    let d = Mat::from_fn(3, 3, |a, b| if a == b { [0.0, 1.0, 2.0][a] } else { 0.0 });
    let j = &q * &d * q.transpose();
    let body = GeneralizedRigidBody::from_matrix(&j).unwrap();
    let mut p = body.principal().to_vec();
    p.sort_by(f64::total_cmp);
    for (got, want) in p.iter().zip([0.0, 1.0, 2.0]) {
        assert!((got - want).abs() < 1e-14, "{p:?}");
    }
    // A truly negative eigenvalue is still an error.
    let bad = Mat::from_fn(3, 3, |a, b| if a == b { [-0.1, 1.0, 2.0][a] } else { 0.0 });
    assert!(matches!(
        GeneralizedRigidBody::from_matrix(&bad),
        Err(Error::InvalidArgument { .. })
    ));
}

// ---------------------------------------------------------------- inertia matrix

#[test]
fn inertia_matrix_is_diagonalised_once() {
    let q = so3::exp_unchecked(&Vector3::new(0.3, -0.8, 0.5));
    let i = q * Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)) * q.transpose();
    let body_m = RigidBody::from_matrix(&row_major(&i)).unwrap();
    let body_p = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let mu = q * Vector3::from(M0);
    let mu_s = [mu.x, mu.y, mu.z];
    assert!((body_m.energy(&mu_s).unwrap() - body_p.energy(&M0).unwrap()).abs() < 1e-14);
    let exact_p = Vector3::from(body_p.exact_momentum(&M0, 7.0).unwrap());
    let exact_m = Vector3::from(body_m.exact_momentum(&mu_s, 7.0).unwrap());
    assert!((q * exact_p - exact_m).norm() < 1e-12);
    // Attitude in the user frame: R_user = R_p Qᵀ keeps R M.
    let s0 = body_m.state_with_attitude(mu_s, row_major(&q.transpose()));
    let traj = integrate(&body_m.with_attitude(), "splitting6", &s0, 0.01, 700, 700).unwrap();
    let m_end = Vector3::from_column_slice(&traj.final_state[..3]);
    assert!((m_end - exact_m).norm() < 1e-9);
    let rm = RigidBody::spatial_momentum(&traj.final_state).unwrap();
    assert!((Vector3::from(rm) - Vector3::from(M0)).norm() < 1e-13);
    let w = body_m.angular_velocity(&mu_s).unwrap();
    let w_expected = q * Vector3::new(M0[0] / 1.0, M0[1] / 2.0, M0[2] / 3.0);
    assert!((Vector3::from(w) - w_expected).norm() < 1e-14);
}

// ---------------------------------------------------------------- driver

#[test]
fn batch_equals_single_runs_on_any_pool() {
    let b = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let states: Vec<Vec<f64>> = (0..8)
        .map(|k| vec![1.0, 0.1 * k as f64, -0.3 + 0.05 * k as f64])
        .collect();
    let single: Vec<_> = states
        .iter()
        .map(|s| integrate(&b, "splitting4", s, 0.01, 500, 50).unwrap())
        .collect();
    for threads in [None, Some(1), Some(2)] {
        let batch = integrate_batch(&b, "splitting4", &states, 0.01, 500, 50, threads).unwrap();
        assert_eq!(batch, single);
    }
    assert!(integrate_batch(&b, "splitting4", &states, 0.01, 500, 50, Some(0)).is_err());
    let mut bad = states.clone();
    bad[5][1] = f64::NAN;
    assert!(matches!(
        integrate_batch(&b, "splitting4", &bad, 0.01, 500, 50, None),
        Err(Error::NonFinite { .. })
    ));
}

#[test]
fn chunks_continue_the_run() {
    let b = RigidBody::new([1.0, 2.0, 3.0]).unwrap().with_attitude();
    let s0 = b.state_with_attitude(M0, [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    let whole = integrate(&b, "splitting", &s0, 0.01, 1000, 100).unwrap();
    let a = integrate(&b, "splitting", &s0, 0.01, 500, 100).unwrap();
    let c = integrate(&b, "splitting", &a.final_state, 0.01, 500, 100).unwrap();
    assert_eq!(whole.len(), 11);
    assert_eq!(a.len() + c.len() - 1, whole.len());
    assert_eq!(whole.final_state.len(), 12);
    for (x, y) in whole.final_state.iter().zip(&c.final_state) {
        assert!((x - y).abs() < 1e-14);
    }
    // steps not a multiple of save_every: samples at 0, 3, 6, 9; final state at 10. Systems also
    // work as trait objects (what a binding holds).
    let sys: &dyn System = &b;
    let t = integrate(sys, "rk4", &s0, 0.1, 10, 3).unwrap();
    assert_eq!(t.t.len(), 4);
    assert!((t.t[3] - 0.9).abs() < 1e-15);
    // Four samples of (M, R): the attitudes travel in the state.
    assert_eq!(t.dim, 12);
    assert_eq!(t.states.len(), 4 * 12);
}

#[test]
fn bad_input_gets_typed_errors() {
    let b = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let s0 = M0.to_vec();
    for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            integrate(&b, "splitting", &s0, dt, 10, 1),
            Err(Error::InvalidArgument { .. })
        ));
    }
    assert!(matches!(
        integrate(&b, "splitting", &s0, 0.1, 0, 1),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(matches!(
        integrate(&b, "splitting", &s0, 0.1, 10, 0),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(matches!(
        integrate(&b, "splitting", &[1.0, 2.0], 0.1, 10, 1),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        integrate(&b, "splitting", &[1.0, f64::NAN, 0.0], 0.1, 10, 1),
        Err(Error::NonFinite { .. })
    ));
    // The kernels do not check lengths; the driver checks a state once.
    assert!(matches!(
        check_state(&b, &[1.0, 2.0]),
        Err(Error::Shape { .. })
    ));
    let lifted = b.with_attitude();
    let skewed = b.state_with_attitude(M0, [1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    assert!(matches!(
        integrate(&lifted, "splitting", &skewed, 0.1, 10, 1),
        Err(Error::NotInGroup { .. })
    ));
    let reflection = b.state_with_attitude(M0, [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    assert!(matches!(
        integrate(&lifted, "splitting", &reflection, 0.1, 10, 1),
        Err(Error::NotInGroup { .. })
    ));
    // A state (M, R) is not a state of the body without attitude, and vice versa.
    assert!(matches!(
        integrate(&b, "splitting", &reflection, 0.1, 10, 1),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        integrate(&lifted, "splitting", &s0, 0.1, 10, 1),
        Err(Error::Shape { .. })
    ));
    for bad in [[1.0, 0.0, 2.0], [1.0, -2.0, 3.0], [1.0, f64::NAN, 1.0]] {
        assert!(matches!(
            RigidBody::new(bad),
            Err(Error::InvalidArgument { .. })
        ));
    }
    assert!(RigidBody::from_matrix(&[1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]).is_err());
    assert!(RigidBody::from_matrix(&[1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0]).is_err());
    let t = top();
    match integrate(&t, "isospectral", &t.state(M0, [0.0, 0.0, 1.0]), 0.1, 10, 1) {
        Err(Error::UnsupportedMethod { supported, .. }) => {
            assert_eq!(
                supported,
                "splitting, splitting4, splitting6, splitting8, processed6, processed8, \
                 processed10, lgvi, rk4, exact_splitting, exact_splitting4, exact_splitting6"
            )
        }
        other => panic!("expected UnsupportedMethod, got {other:?}"),
    }
    // Methods are named by the system's catalog: an unknown name is rejected, a known one runs.
    assert!(matches!(
        integrate(&b, "verlet8", &s0, 0.1, 10, 1),
        Err(Error::UnsupportedMethod { .. })
    ));
    let names: Vec<&str> = b.methods().into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        [
            "splitting",
            "splitting4",
            "splitting6",
            "splitting8",
            "processed6",
            "processed8",
            "processed10",
            "isospectral",
            "lgvi",
            "dmv",
            "dmv4",
            "dmv6",
            "dmv8",
            "dmv10",
            "rk4",
            "rkmk4",
            "exact"
        ]
    );
    assert_eq!(order(&b, "splitting6"), 6);
    assert!(integrate(&b, "splitting6", &s0, 0.1, 10, 1).is_ok());
    let inconsistent = [
        &M0[..],
        &[0.0, 1.0, 0.0],
        &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    ]
    .concat();
    assert!(matches!(
        integrate(&t.with_attitude(), "splitting", &inconsistent, 0.1, 10, 1),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(HeavyTop::new([1.0, 2.0, 3.0], -1.0, [0.0, 0.0, 1.0]).is_err());
    assert!(HeavyTop::new([1.0, 2.0, 3.0], 1.0, [0.0, 0.0, 0.0]).is_err());
    assert!(matches!(
        GeneralizedRigidBody::new(&[1.0]),
        Err(Error::Shape { .. })
    ));
    assert!(GeneralizedRigidBody::new(&[1.0, -0.5, 2.0]).is_err());
    assert!(GeneralizedRigidBody::new(&[0.0, 0.0, 2.0]).is_err());
    // The so(n) body carries no attitude: it has no lifted form, and a state with an attitude
    // appended has the wrong length.
    let g = GeneralizedRigidBody::new(&[1.0, 2.0, 3.0]).unwrap();
    assert!(g.lift().is_none());
    let with_r = [
        &[0.1, 0.2, 0.3][..],
        &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    ]
    .concat();
    assert!(matches!(
        integrate(&g, "isospectral", &with_r, 0.1, 10, 1),
        Err(Error::Shape { .. })
    ));
    let p = SphericalPendulum::new(1.0, 1.0, 9.81).unwrap();
    let off = [0.0, 0.0, -1.1, 0.0, 0.0, 0.0];
    assert!(matches!(
        integrate(&p, "splitting", &off, 0.1, 10, 1),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(SphericalPendulum::new(0.0, 1.0, 9.81).is_err());
    // The implicit solvers report failure instead of returning garbage.
    let big = [100.0, 50.0, -30.0];
    let r = integrate(&b, "isospectral", &big, 10.0, 10, 1);
    assert!(matches!(r, Err(Error::NotConverged { .. })));
    assert!(b
        .exact_momentum(&[1.0, 0.0, 1.0 / 3f64.sqrt() * 0.0 + 1.0], f64::NAN)
        .is_err());
}

/// 000 Theorem 4.11 (Noether with a broken symmetry) for the built-in heavy top with attitude:
/// gravity breaks SO(3) down to the rotations about the vertical, so the spatial angular momentum
/// s = R M obeys ṡ = mgl e₃ × Rχ (checked by central differences along the run) and only its
/// vertical component e₃·s is conserved (to round-off by lgvi, which is equivariant under that
/// subgroup), while the horizontal ones move.
#[test]
fn heavy_top_noether_with_symmetry_breaking_theorem_4_11() {
    let (mgl, chi) = (0.8, [0.1, 0.2, 1.0]);
    let top = lieflow::systems::HeavyTop::new([1.0, 1.4, 2.1], mgl, chi)
        .unwrap()
        .with_attitude();
    let r0 = lieflow::lie::so3::exp_unchecked(&Vector3::new(0.5, -0.3, 0.2));
    let r0: [f64; 9] = std::array::from_fn(|k| r0[(k / 3, k % 3)]);
    let z0 = top.state_with_attitude([0.4, -0.9, 1.3], r0);
    let chi = Vector3::from(chi).normalize();
    let spatial = |z: &[f64]| {
        let r = nalgebra::Matrix3::from_row_slice(&z[6..15]);
        (r * Vector3::new(z[0], z[1], z[2]), r * chi)
    };
    let dt = 1e-3;
    let t = lieflow::integrate::integrate(&top, "splitting6", &z0, dt, 4000, 1).unwrap();
    let mut worst = 0.0f64;
    for k in 1..t.len() - 1 {
        let (sp, _) = spatial(t.state(k + 1));
        let (sm, _) = spatial(t.state(k - 1));
        let (_, rchi) = spatial(t.state(k));
        let rate = (sp - sm) / (2.0 * dt);
        let expected = mgl * Vector3::z().cross(&rchi);
        worst = worst.max((rate - expected).norm());
    }
    assert!(worst < 1e-5, "ṡ − mgl e₃ × Rχ: {worst}");
    let long = lieflow::integrate::integrate(&top, "lgvi", &z0, 0.01, 100_000, 1000).unwrap();
    let (s0, _) = spatial(&z0);
    let mut horizontal = 0.0f64;
    for k in 0..long.len() {
        let (s, _) = spatial(long.state(k));
        assert!(
            (s.z - s0.z).abs() < 1e-12,
            "e₃·RM drifted by {}",
            s.z - s0.z
        );
        horizontal = horizontal.max((s.xy() - s0.xy()).norm());
    }
    assert!(
        horizontal > 0.1,
        "the horizontal components should move: {horizontal}"
    );
}

/// The rate of rotation the driver's bindings warn by: |I⁻¹M| in the principal frame, the
/// same for an inertia given as a rotated matrix; the heavy top's includes √(mgl|Γ|/I_min).
#[test]
fn rates_are_the_angular_velocity_and_the_pendulum_frequency() {
    let m = [1.0, 0.5, -0.3];
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let omega = (1.0f64 + 0.0625 + 0.01).sqrt();
    assert!((body.rate(&m).unwrap() - omega).abs() <= 1e-15);
    let q = so3::exp_unchecked(&Vector3::new(0.3, -0.2, 0.5));
    let i = q * Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)) * q.transpose();
    let rotated = RigidBody::from_matrix(&row_major(&i)).unwrap();
    let mq = q * Vector3::from(m);
    assert!((rotated.rate(mq.as_slice()).unwrap() - omega).abs() <= 1e-14);
    // A huge momentum: a finite rate, not an overflow.
    assert!(body.rate(&[1e300, 1e300, 0.0]).unwrap().is_finite());
    let top = HeavyTop::new([1.0, 1.0, 0.5], 50.0, [0.0, 0.0, 1.0]).unwrap();
    let z = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    assert!((top.rate(&z).unwrap() - 10.0).abs() <= 1e-14);
    let pendulum = SphericalPendulum::new(1.0, 1.0, 9.81).unwrap();
    assert_eq!(pendulum.rate(&[0.0, 0.0, -1.0, 0.0, 0.0, 0.0]), None);
}
