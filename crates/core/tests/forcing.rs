//! Open systems (issue 15): external torques and forces, Rayleigh damping and double-bracket
//! dissipation (`lieflow::integrate::forcing`). Checked against independent references (an RK4
//! written here on the forced equations, at a step 100× smaller), by observed orders, by the
//! energy balance of the dissipation, the Casimirs, the limit rotation about the major axis, and
//! the conformal symplecticity of damped Störmer–Verlet-type steps.

use std::sync::Arc;

use lieflow::integrate::forcing::{momentum_block, Dissipation, ForceFn, Forced};
use lieflow::integrate::{integrate, Block, Clock, Problem, Run, Space, System};
use lieflow::systems::{
    Algebra, GeneralizedRigidBody, LieHamiltonian, LiePoisson, Pendulum, RigidBody,
};
use lieflow::Error;
use nalgebra::{Matrix3, Vector3};

mod common;
use common::distance as dist;

const I: [f64; 3] = [1.0, 2.0, 3.0];
const M0: [f64; 3] = [1.0, 0.5, -0.3];

/// The torque of the tests: a constant body torque plus a time-dependent one and, when
/// `damped`, the momentum-dependent −0.2 M.
fn torque(damped: bool) -> ForceFn {
    Arc::new(move |t: f64, z: &[f64], out: &mut [f64]| {
        out[0] = 0.3 + 0.1 * t.sin();
        out[1] = -0.2;
        out[2] = 0.25 * (2.0 * t).cos();
        if damped {
            for i in 0..3 {
                out[i] -= 0.2 * z[i];
            }
        }
        Ok(())
    })
}

/// The forced Euler equations with the attitude, Ṁ = M × Ω + τ(t, M), Ṙ = R Ω̂, by RK4 with a
/// step of `h` from t = 0 to `t_end` (the reference).
fn reference(m0: [f64; 3], t_end: f64, h: f64, damped: bool) -> Vec<f64> {
    let tau = torque(damped);
    let field = |t: f64, y: &[f64]| -> Vec<f64> {
        let m = Vector3::from_column_slice(&y[..3]);
        let w = Vector3::new(m[0] / I[0], m[1] / I[1], m[2] / I[2]);
        let mut f = [0.0; 3];
        tau(t, y, &mut f).unwrap();
        let dm = m.cross(&w) + Vector3::from(f);
        let r = Matrix3::from_row_slice(&y[3..12]);
        let dr = r * Matrix3::new(0.0, -w[2], w[1], w[2], 0.0, -w[0], -w[1], w[0], 0.0);
        let mut out = dm.as_slice().to_vec();
        for i in 0..3 {
            for j in 0..3 {
                out.push(dr[(i, j)]);
            }
        }
        out
    };
    let mut y: Vec<f64> = m0.to_vec();
    y.extend([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    let n = (t_end / h).round() as usize;
    for k in 0..n {
        let t = k as f64 * h;
        let add = |a: &[f64], b: &[f64], s: f64| {
            a.iter().zip(b).map(|(x, y)| x + s * y).collect::<Vec<_>>()
        };
        let k1 = field(t, &y);
        let k2 = field(t + h / 2.0, &add(&y, &k1, h / 2.0));
        let k3 = field(t + h / 2.0, &add(&y, &k2, h / 2.0));
        let k4 = field(t + h, &add(&y, &k3, h));
        for i in 0..y.len() {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    y
}

fn forced_body(damped: bool) -> Forced {
    let body = RigidBody::new(I).unwrap().with_attitude();
    Forced::new(Arc::new(body))
        .with_force("M", torque(damped), damped)
        .unwrap()
}

fn lifted_state() -> Vec<f64> {
    let mut z = M0.to_vec();
    z.extend([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    z
}

fn final_error(sys: &Forced, method: &str, dt: f64, t_end: f64, reference: &[f64]) -> f64 {
    let steps = (t_end / dt).round() as usize;
    let traj = integrate(sys, method, &lifted_state(), dt, steps, steps).unwrap();
    dist(&traj.final_state, reference)
}

/// The forced rigid body with attitude agrees with the reference, and the observed orders of
/// the kicked Strang splitting and its compositions are 2, 4 and 6, for a torque that depends
/// on the time only and for one that depends on M too (implicit kicks).
#[test]
fn torque_against_reference_with_orders() {
    for damped in [false, true] {
        let sys = forced_body(damped);
        let t_end = 4.0;
        let r = reference(M0, t_end, 1e-4, damped);
        for (method, order, dt) in [
            ("splitting", 2.0, 0.02),
            ("splitting4", 4.0, 0.08),
            ("splitting6", 6.0, 0.16),
        ] {
            let e1 = final_error(&sys, method, dt, t_end, &r);
            let e2 = final_error(&sys, method, dt / 2.0, t_end, &r);
            let p = (e1 / e2).log2();
            assert!(
                (p - order).abs() < 0.3,
                "{method} damped={damped}: observed order {p} (errors {e1:e}, {e2:e})"
            );
        }
        let e = final_error(&sys, "splitting6", 0.01, t_end, &r);
        assert!(e < 1e-10, "damped={damped}: splitting6 error {e:e}");
    }
}

/// The attitude stays in SO(3) to round-off under the forced splitting (the kicks touch only M).
#[test]
fn attitude_stays_a_rotation() {
    let sys = forced_body(true);
    let traj = integrate(&sys, "splitting4", &lifted_state(), 0.05, 20_000, 20_000).unwrap();
    let r = Matrix3::from_row_slice(&traj.final_state[3..12]);
    let defect = (r.transpose() * r - Matrix3::identity()).norm();
    assert!(defect < 1e-13, "‖RᵀR − I‖ = {defect:e}");
}

/// The names of the forced methods follow the free system's symmetric second-order methods.
#[test]
fn catalog_of_the_forced_systems() {
    let names = |s: &Forced| s.methods().into_iter().map(|(n, _)| n).collect::<Vec<_>>();
    let body = forced_body(false);
    assert_eq!(names(&body)[..3], ["splitting", "splitting4", "splitting6"]);
    assert!(names(&body).contains(&"lgvi4"));
    let pend = Forced::new(Arc::new(Pendulum::new(1.0, 1.0, 9.81).unwrap()));
    assert_eq!(names(&pend)[..3], ["midpoint", "midpoint4", "midpoint6"]);
    for (_, p) in body.methods() {
        assert!(p.symmetric && !p.symplectic && !p.invariants);
    }
    let err = integrate(&body, "rk4", &lifted_state(), 0.1, 1, 1).unwrap_err();
    assert!(matches!(err, Error::UnsupportedMethod { .. }), "{err}");
}

/// A run cut into calls gives the same states, bit for bit, as one call (the time of a kick
/// comes from the run's clock).
#[test]
fn chunking_does_not_change_the_states() {
    let sys = forced_body(true);
    let z0 = lifted_state();
    let one = integrate(&sys, "splitting4", &z0, 0.01, 100, 100)
        .unwrap()
        .final_state;
    let mut run = Run::new(&sys, "splitting4", &z0, 0.01, 100, 0.0).unwrap();
    let mut out = Vec::new();
    run.advance(&sys, 37, &mut out).unwrap();
    run.advance(&sys, 63, &mut out).unwrap();
    assert_eq!(run.state(&sys), one);
}

/// Double-bracket dissipation of the rigid body: |M| kept to round-off, the energy decreasing
/// at every step, and the body ends rotating about its major axis with H = |M|²/(2 I₃).
#[test]
fn double_bracket_goes_to_the_major_axis() {
    let body = RigidBody::new(I).unwrap();
    let sys = Forced::new(Arc::new(body.clone()))
        .with_dissipation(&Dissipation::DoubleBracket(0.5))
        .unwrap();
    for (method, _) in sys.methods() {
        let traj = integrate(&sys, method, &M0, 0.05, 4000, 1).unwrap();
        let c0 = sys.invariants(&M0).unwrap()[0];
        let mut e_prev = f64::INFINITY;
        let mut worst = 0.0f64;
        for k in 0..traj.len() {
            let z = traj.state(k);
            let dc = (sys.invariants(z).unwrap()[0] - c0).abs() / c0;
            // Round-off of ~10⁵ group actions (4000 steps of up to 7 stages).
            assert!(
                dc < 2000.0 * f64::EPSILON,
                "{method}: relative |M|² drift {dc:e} at sample {k}"
            );
            worst = worst.max(dc);
            let e = sys.energy(z).unwrap();
            assert!(
                e <= e_prev + 1e-15,
                "{method}: the energy rose at sample {k}: {e} > {e_prev}"
            );
            e_prev = e;
        }
        let m = &traj.final_state;
        assert!(
            m[0].abs() < 1e-8 && m[1].abs() < 1e-8,
            "{method}: not about the major axis: {m:?}"
        );
        assert!(
            (e_prev - c0 / (2.0 * I[2])).abs() < 1e-12,
            "{method}: final energy {e_prev}"
        );
    }
}

/// The dissipative field is BKMR's: dH/dt = −α|M × Ω|², checked on the first step's energy.
#[test]
fn double_bracket_energy_rate() {
    let alpha = 0.3;
    let body = RigidBody::new(I).unwrap();
    let sys = Forced::new(Arc::new(body))
        .with_dissipation(&Dissipation::DoubleBracket(alpha))
        .unwrap();
    let m = Vector3::from(M0);
    let w = Vector3::new(M0[0] / I[0], M0[1] / I[1], M0[2] / I[2]);
    let rate = -alpha * m.cross(&w).norm_squared();
    // One step of the sixth-order method: (E(h) − E(0))/h = dH/dt + O(h).
    let h = 1e-5;
    let e0 = sys.energy(&M0).unwrap();
    let e1 = sys
        .energy(
            &integrate(&sys, "splitting6", &M0, h, 1, 1)
                .unwrap()
                .final_state,
        )
        .unwrap();
    let measured = (e1 - e0) / h;
    assert!(
        (measured - rate).abs() < 1e-3 * rate.abs(),
        "dH/dt = {measured}, expected {rate}"
    );
}

/// The same dissipation for the generalized rigid body on so(4)* and a user Lie–Poisson system
/// on so(3)*: energy decreasing, Casimirs kept.
#[test]
fn double_bracket_on_other_algebras() {
    let body = GeneralizedRigidBody::new(&[1.0, 1.5, 2.2, 3.1]).unwrap();
    let m0 = [0.3, -0.2, 0.5, 0.1, 0.4, -0.3];
    let quadratic = |algebra, diag: &[f64]| {
        let d = diag.len();
        let a = (0..d * d)
            .map(|k| {
                if k % (d + 1) == 0 {
                    diag[k / (d + 1)]
                } else {
                    0.0
                }
            })
            .collect();
        Arc::new(LiePoisson::new(algebra, LieHamiltonian::Quadratic(a), None).unwrap())
            as Arc<dyn System>
    };
    let so3 = quadratic(Algebra::So3, &[1.0, 0.5, 1.0 / 3.0]);
    // Kirchhoff's body: H = ½ M·AM + ½ Γ·BΓ on se(3)*, Casimirs |Γ|², M·Γ.
    let se3 = quadratic(Algebra::Se3, &[1.0, 0.5, 0.25, 1.0, 0.8, 0.6]);
    let cases: Vec<(Arc<dyn System>, Vec<f64>)> = vec![
        (Arc::new(body), m0.to_vec()),
        (so3, M0.to_vec()),
        (se3, vec![0.3, -0.5, 0.8, 1.0, 0.4, -0.6]),
    ];
    for (free, z0) in cases {
        let sys = Forced::new(free.clone())
            .with_dissipation(&Dissipation::DoubleBracket(1.0))
            .unwrap();
        let method = sys.methods()[0].0;
        let traj = integrate(&sys, method, &z0, 0.02, 2000, 100).unwrap();
        let c0 = sys.invariants(&z0).unwrap();
        let (e0, e1) = (
            sys.energy(&z0).unwrap(),
            sys.energy(&traj.final_state).unwrap(),
        );
        assert!(
            e1 < e0 * 0.999,
            "{}: the energy did not decrease ({e0} → {e1})",
            free.name()
        );
        for k in 0..traj.len() {
            let c = sys.invariants(traj.state(k)).unwrap();
            let d = dist(&c, &c0);
            assert!(d < 1e-13, "{}: Casimir drift {d:e}", free.name());
        }
    }
}

/// Rayleigh damping of the pendulum: the energy decreases, the motion agrees with an RK4
/// reference, and the map contracts area by the constant factor ((1 − a)/(1 + a))², a = cτ/2m,
/// per Strang step (conformal symplecticity), measured by a finite-difference Jacobian.
#[test]
fn rayleigh_damping_of_the_pendulum() {
    let (m, l, g, c) = (1.0, 1.0, 9.81, 0.4);
    let pend = Pendulum::new(m, l, g).unwrap();
    let sys = Forced::new(Arc::new(pend.clone()))
        .with_dissipation(&Dissipation::Rayleigh(vec![c]))
        .unwrap();
    let z0 = [1.0, 0.0];
    // H = p²/(2ml²) − mgl cos q: q̇ = p/(ml²), ṗ = −mgl sin q − c p/(ml²).
    let f = |z: [f64; 2]| {
        [
            z[1] / (m * l * l),
            -m * g * l * z[0].sin() - c * z[1] / (m * l * l),
        ]
    };
    let (mut y, h) = (z0, 1e-4);
    for _ in 0..20_000 {
        let k1 = f(y);
        let k2 = f([y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]]);
        let k3 = f([y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]]);
        let k4 = f([y[0] + h * k3[0], y[1] + h * k3[1]]);
        for i in 0..2 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    let traj = integrate(&sys, "midpoint4", &z0, 0.01, 200, 1).unwrap();
    let e = dist(&traj.final_state, &y);
    assert!(e < 1e-7, "midpoint4 against RK4: {e:e}");
    let energies: Vec<f64> = (0..traj.len())
        .map(|k| sys.energy(traj.state(k)).unwrap())
        .collect();
    assert!(
        energies.windows(2).all(|w| w[1] <= w[0] + 1e-12),
        "the energy rose"
    );
    // Conformal symplecticity: det of the one-step map.
    let dt = 0.1;
    let step = |z: [f64; 2]| {
        integrate(&sys, "midpoint", &z, dt, 1, 1)
            .unwrap()
            .final_state
    };
    let d = 1e-6;
    let col = |i: usize| {
        let (mut a, mut b) = ([0.7, 0.3], [0.7, 0.3]);
        a[i] += d;
        b[i] -= d;
        let (fa, fb) = (step(a), step(b));
        [(fa[0] - fb[0]) / (2.0 * d), (fa[1] - fb[1]) / (2.0 * d)]
    };
    let (c0, c1) = (col(0), col(1));
    let det = c0[0] * c1[1] - c0[1] * c1[0];
    let a = c * (dt / 2.0) / (2.0 * m * l * l);
    let expected = ((1.0 - a) / (1.0 + a)).powi(2);
    assert!(
        (det - expected).abs() < 1e-8,
        "det = {det}, expected {expected}"
    );
}

/// Bad input: typed errors that name what was wrong.
#[test]
fn errors() {
    let body: Arc<dyn System> = Arc::new(RigidBody::new(I).unwrap().with_attitude());
    let f: ForceFn = Arc::new(|_, _, out: &mut [f64]| {
        out.fill(0.0);
        Ok(())
    });
    let e = Forced::new(body.clone())
        .with_force("R", f.clone(), false)
        .unwrap_err();
    assert!(e.to_string().contains("curved block R"), "{e}");
    let e = Forced::new(body.clone())
        .with_force("P", f.clone(), false)
        .unwrap_err();
    assert!(e.to_string().contains("the blocks are M, R"), "{e}");
    let e = Forced::new(body.clone())
        .with_dissipation(&Dissipation::DoubleBracket(1.0))
        .unwrap_err();
    assert!(e.to_string().contains("attitude"), "{e}");
    let e = Forced::new(body.clone())
        .with_dissipation(&Dissipation::Rayleigh(vec![1.0]))
        .unwrap_err();
    assert!(e.to_string().contains("no Rayleigh damping"), "{e}");
    let free: Arc<dyn System> = Arc::new(RigidBody::new(I).unwrap());
    let e = Forced::new(free.clone())
        .with_dissipation(&Dissipation::DoubleBracket(-1.0))
        .unwrap_err();
    assert!(e.to_string().contains("≥ 0"), "{e}");
    let pend: Arc<dyn System> = Arc::new(Pendulum::new(1.0, 1.0, 1.0).unwrap());
    for bad in [
        vec![-1.0],
        vec![f64::NAN],
        vec![1.0, 2.0],
        vec![1.0, 2.0, 0.0, 1.0],
    ] {
        assert!(
            Forced::new(pend.clone())
                .with_dissipation(&Dissipation::Rayleigh(bad.clone()))
                .is_err(),
            "{bad:?}"
        );
    }
    // A force that turns non-finite is refused, with the step named.
    let blow: ForceFn = Arc::new(|t, _, out: &mut [f64]| {
        out.fill(if t > 0.25 { f64::NAN } else { 0.1 });
        Ok(())
    });
    let sys = Forced::new(free).with_force("M", blow, false).unwrap();
    let e = integrate(&sys, "splitting", &M0, 0.1, 10, 1).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, Error::NonFinite { .. })
            && msg.contains("step 3")
            && msg.contains("force on M"),
        "{msg}"
    );
}

/// The forced methods are symmetric, Φ_{−h} ∘ Φ_h = id, with a time-dependent and
/// momentum-dependent torque and with dissipation (the step back starts at t + h).
#[test]
fn forced_methods_are_symmetric() {
    let free: Arc<dyn System> = Arc::new(RigidBody::new(I).unwrap());
    let systems = [
        Forced::new(free.clone())
            .with_force("M", torque(true), true)
            .unwrap(),
        Forced::new(free)
            .with_dissipation(&Dissipation::DoubleBracket(0.7))
            .unwrap(),
    ];
    let h = 0.1;
    for sys in &systems {
        for (name, p) in sys.methods() {
            assert!(p.symmetric);
            let mut z = M0.to_vec();
            for (dt, t0) in [(h, 0.3), (-h, 0.3 + h)] {
                let (mut stepper, _) = sys.stepper(name, dt).unwrap();
                stepper.set(&z).unwrap();
                stepper.advance(1, Clock { t0, dt, done: 0 }).unwrap();
                stepper.get(&mut z);
            }
            let defect = dist(&z, &M0);
            assert!(
                defect < 1e-14,
                "{:?} {name}: Φ_−h ∘ Φ_h defect {defect:e}",
                sys.terms()
            );
        }
    }
}

/// An implicit kick whose fixed-point iteration cannot converge (h·|∂F/∂M|/2 > 1) stops with
/// a ConvergenceError naming the step instead of returning a wrong state.
#[test]
fn an_implicit_kick_that_does_not_converge_is_an_error() {
    let stiff: ForceFn = Arc::new(|_, z: &[f64], out: &mut [f64]| {
        for i in 0..3 {
            out[i] = -100.0 * z[i];
        }
        Ok(())
    });
    let free: Arc<dyn System> = Arc::new(RigidBody::new(I).unwrap());
    let sys = Forced::new(free).with_force("M", stiff, true).unwrap();
    let e = integrate(&sys, "splitting", &M0, 0.1, 5, 1).unwrap_err();
    assert!(matches!(e, Error::NotConverged { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("implicit midpoint kick of the force on M in step 1"),
        "{msg}"
    );
    // The same force with a step inside the contraction range runs.
    assert!(integrate(&sys, "splitting", &M0, 0.005, 5, 1).is_ok());
}

/// The default block of a force: the first of M, P, p, L, mu the state has.
#[test]
fn the_default_block_is_the_momentum() {
    let block = |s: &dyn System| momentum_block(s.name(), &s.space());
    assert_eq!(block(&RigidBody::new(I).unwrap()).unwrap(), "M");
    assert_eq!(block(&Pendulum::new(1.0, 1.0, 1.0).unwrap()).unwrap(), "p");
    let other = Space::new([("u", Block::Sphere), ("w", Block::Real(3))]);
    let e = momentum_block("Some", &other).unwrap_err();
    assert!(
        e.to_string()
            .contains("none of the momentum blocks M, P, p, L, mu (its blocks are u, w)"),
        "{e}"
    );
}
