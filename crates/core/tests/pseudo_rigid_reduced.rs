//! The reduced pseudo-rigid body (001 §7) and the `PseudoRigidBody` system of the driver.

mod common;

use common::order;
use lieflow::integrate::methods::composition::{run_sequence, Composition};
use lieflow::integrate::methods::Verlet;
use lieflow::integrate::{integrate, integrate_batch, integrate_with, Problem, Run};
use lieflow::lie::so::spectral_invariants;
use lieflow::pseudo_rigid::dynamics::FullBody;
use lieflow::pseudo_rigid::momentum;
use lieflow::pseudo_rigid::potential::{
    self, Harmonic, Potential, SaintVenantKirchhoff, Sum, Volumetric, Workspace, Zero,
};
use lieflow::pseudo_rigid::reduced::{
    momenta_of_velocities, reconstruct, reduce, ReducedState, ReducedWork,
};
use lieflow::pseudo_rigid::PseudoRigidBody;
use lieflow::{Error, Mat};
use nalgebra::Matrix3;
use std::sync::Arc;

fn elastic_gas() -> Arc<dyn Potential> {
    Arc::new(Sum::new(vec![
        Arc::new(SaintVenantKirchhoff::new(0.7, 1.3).unwrap()),
        Arc::new(Volumetric::polytropic(0.4, 1.4).unwrap()),
    ]))
}

/// A spinning, deforming body: distinct singular values, nonzero L and Γ.
fn initial(n: usize) -> (Mat, Mat) {
    let x = Mat::from_fn(n, n, |i, j| {
        if i == j {
            1.0 + 0.25 * i as f64
        } else {
            0.05 * ((i + 2 * j) as f64).sin()
        }
    });
    let p = Mat::from_fn(n, n, |i, j| {
        0.3 * ((3 * i + j) as f64).cos() + if i < j { 0.4 } else { -0.2 }
    });
    (x, p)
}

fn rel(a: &Mat, b: &Mat) -> f64 {
    (a - b).norm_l2() / b.norm_l2().max(1e-300)
}

fn body(n: usize) -> PseudoRigidBody {
    PseudoRigidBody::new(n, elastic_gas(), true).unwrap()
}

fn final_xp(b: &PseudoRigidBody, m: &str, dt: f64, steps: usize) -> (Mat, Mat) {
    let n = b.n();
    let (x0, p0) = initial(n);
    let traj = integrate(b, m, &b.state(&x0, &p0).unwrap(), dt, steps, steps).unwrap();
    b.split(traj.state(1)).unwrap()
}

#[test]
fn reduce_and_reconstruct_are_inverse() {
    for n in 2..=6 {
        let (x, p) = initial(n);
        let (red, r, s) = reduce(&x, &p).unwrap();
        let (x2, p2) = reconstruct(&r, &s, &red).unwrap();
        assert!(rel(&x2, &x) < 1e-12 && rel(&p2, &p) < 1e-12, "n = {n}");
        // p_Ω, p_Λ are RᵀLR, SᵀΓS: same spectra as L, Γ.
        let (l, g) = momentum::momentum_map(&x, &p).unwrap();
        let (sl, so) = (spectral_invariants(&l), spectral_invariants(&red.p_omega));
        let (sg, sn) = (spectral_invariants(&g), spectral_invariants(&red.p_lambda));
        for (u, v) in sl.iter().zip(&so).chain(sg.iter().zip(&sn)) {
            assert!((u - v).abs() < 1e-12 * u.abs().max(1.0));
        }
    }
}

#[test]
fn pair_formula_is_the_bi_inertia_inverse() {
    for n in 2..=6 {
        let (x, p) = initial(n);
        let (red, _, _) = reduce(&x, &p).unwrap();
        let (po, pl) = momenta_of_velocities(&red).unwrap();
        assert!(rel(&po, &red.p_omega) < 1e-12 && rel(&pl, &red.p_lambda) < 1e-12);
    }
}

#[test]
fn reduced_hamiltonian_equals_the_full_one() {
    for n in 2..=6 {
        let (x, p) = initial(n);
        let full = FullBody::new(n, elastic_gas()).unwrap();
        let (red, _, _) = reduce(&x, &p).unwrap();
        let (h, hr) = (
            full.hamiltonian(&x, &p).unwrap(),
            red.hamiltonian(&full).unwrap(),
        );
        assert!((h - hr).abs() < 1e-12 * h.abs(), "n = {n}: {h} vs {hr}");
    }
}

#[test]
fn reduced_field_matches_the_lagrangian_form() {
    for n in 2..=6 {
        let (x, p) = initial(n);
        let full = FullBody::new(n, elastic_gas()).unwrap();
        let (red, _, _) = reduce(&x, &p).unwrap();
        let (o, l) = red.velocities().unwrap();
        let lag = full.lagrange_vector_field(&red.a, &o, &l).unwrap();
        let f = red.vector_field(&full).unwrap();
        assert_eq!(f.a_dot, red.p_a);
        for i in 0..n {
            assert!(
                (f.p_a_dot[i] - lag.a_ddot[i]).abs() < 1e-10 * lag.a_ddot[i].abs().max(1.0),
                "n = {n}, i = {i}: {} vs {}",
                f.p_a_dot[i],
                lag.a_ddot[i]
            );
        }
        assert!((&f.p_omega_dot - &lag.p_omega_dot).norm_l2() < 1e-10);
        assert!((&f.p_lambda_dot - &lag.p_lambda_dot).norm_l2() < 1e-10);
    }
}

/// The reduced field's exact derivative (`vector_field_tangent`: D²U and the pair formulas'
/// second derivatives) against fourth-order central differences of the field, n = 2…5, along a
/// direction in every block at once and along each a_l alone.
#[test]
fn reduced_field_tangent_matches_differences() {
    for n in 2..=5 {
        let (x, p) = initial(n);
        let full = FullBody::new(n, elastic_gas()).unwrap();
        let (red, _, _) = reduce(&x, &p).unwrap();
        let skew = |k: f64| {
            Mat::from_fn(n, n, |i, j| match i.cmp(&j) {
                std::cmp::Ordering::Less => (k + (i + 3 * j) as f64).sin(),
                std::cmp::Ordering::Greater => -(k + (j + 3 * i) as f64).sin(),
                _ => 0.0,
            })
        };
        let mut dirs = vec![ReducedState {
            a: (0..n).map(|i| (0.3 * i as f64).cos()).collect(),
            p_a: (0..n).map(|i| (0.7 * i as f64).sin()).collect(),
            p_omega: skew(0.2),
            p_lambda: skew(1.1),
        }];
        for l in 0..n {
            let mut a = vec![0.0; n];
            a[l] = 1.0;
            dirs.push(ReducedState {
                a,
                p_a: vec![0.0; n],
                p_omega: Mat::zeros(n, n),
                p_lambda: Mat::zeros(n, n),
            });
        }
        for d in &dirs {
            let t = red.vector_field_tangent(&full, d).unwrap();
            // Small against the gaps a_i − a_j (K has (a_i − a_j)⁻² terms).
            let h = 2e-4;
            let at = |s: f64| {
                let z = ReducedState {
                    a: red.a.iter().zip(&d.a).map(|(x, y)| x + s * y).collect(),
                    p_a: red.p_a.iter().zip(&d.p_a).map(|(x, y)| x + s * y).collect(),
                    p_omega: &red.p_omega + &d.p_omega * faer::Scale(s),
                    p_lambda: &red.p_lambda + &d.p_lambda * faer::Scale(s),
                };
                let f = z.vector_field(&full).unwrap();
                let mut v = f.a_dot;
                v.extend(f.p_a_dot);
                v.extend((0..n * n).map(|k| f.p_omega_dot[(k / n, k % n)]));
                v.extend((0..n * n).map(|k| f.p_lambda_dot[(k / n, k % n)]));
                v
            };
            let (a, b, a2, b2) = (at(h), at(-h), at(2.0 * h), at(-2.0 * h));
            let mut exact = t.a_dot.clone();
            exact.extend(&t.p_a_dot);
            exact.extend((0..n * n).map(|k| t.p_omega_dot[(k / n, k % n)]));
            exact.extend((0..n * n).map(|k| t.p_lambda_dot[(k / n, k % n)]));
            let scale = exact.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let err = (0..exact.len())
                .map(|k| (exact[k] - (8.0 * (a[k] - b[k]) - (a2[k] - b2[k])) / (12.0 * h)).abs())
                .fold(0.0f64, f64::max)
                / scale;
            eprintln!("n = {n}: δ(field) vs differences {err:.1e}");
            assert!(err < 1e-9, "n = {n}: {err:e}");
        }
        // A direction of the wrong size, or not skew, is a typed error.
        let mut bad = dirs[0].clone();
        bad.a.push(0.0);
        let e = red.vector_field_tangent(&full, &bad).unwrap_err();
        assert!(matches!(e, Error::Shape { .. }), "{e}");
        let mut bad = dirs[0].clone();
        bad.p_omega[(0, 1)] += 1.0;
        assert!(red.vector_field_tangent(&full, &bad).is_err());
    }
}

#[test]
fn reduced_field_is_the_derivative_of_the_reduced_full_flow() {
    // Frames can flip signs between SVDs, so follow the frames with the reduced integrator and
    // compare d/dt of the sign-free quantities a, p_a with central differences of the full flow.
    let n = 3;
    let b = body(n);
    let full = b.full();
    let (x0, p0) = initial(n);
    let (red0, _, _) = reduce(&x0, &p0).unwrap();
    let f = red0.vector_field(full).unwrap();
    let h = 1e-3;
    let fwd = final_xp(&b, "verlet6", h / 20.0, 20);
    let (xm, pm) = {
        // Backward in time: the motion of (X, −P) reversed.
        let s = b.state(&x0, &(-&p0)).unwrap();
        let traj = integrate(&b, "verlet6", &s, h / 20.0, 20, 20).unwrap();
        let (x, p) = b.split(traj.state(1)).unwrap();
        (x, -p)
    };
    let (rp, _, _) = reduce(&fwd.0, &fwd.1).unwrap();
    let (rm, _, _) = reduce(&xm, &pm).unwrap();
    for i in 0..n {
        let da = (rp.a[i] - rm.a[i]) / (2.0 * h);
        let dpa = (rp.p_a[i] - rm.p_a[i]) / (2.0 * h);
        assert!((da - f.a_dot[i]).abs() < 5e-5, "ȧ_{i}");
        assert!(
            (dpa - f.p_a_dot[i]).abs() < 5e-5,
            "ṗ_a{i}: {dpa} vs {}",
            f.p_a_dot[i]
        );
    }
}

#[test]
fn full_and_reduced_flows_agree_to_second_order() {
    for n in [2, 3, 4] {
        let b = body(n);
        let t = 0.5;
        let (xr, pr) = final_xp(&b, "verlet6", t / 400.0, 400);
        let err = |steps: usize| {
            let (x, p) = final_xp(&b, "reduced", t / steps as f64, steps);
            rel(&x, &xr).max(rel(&p, &pr))
        };
        let (e1, e2) = (err(200), err(400));
        let order = (e1 / e2).log2();
        assert!(e2 < 1e-3, "n = {n}: error {e2}");
        assert!((order - 2.0).abs() < 0.2, "n = {n}: observed order {order}");
    }
}

#[test]
fn reduced_method_keeps_the_coadjoint_orbits_and_momenta() {
    for n in [3, 5] {
        let (x, p) = initial(n);
        let pot = elastic_gas();
        // The kernel of method "reduced": the Strang step of the reduced flows, checked after
        // every step, on the reduced working state.
        let seq = Composition::strang().sequence(ReducedWork::flows(n));
        let mut split = ReducedWork::new(&x, &p).unwrap();
        let (so, sl) = (
            spectral_invariants(&split.state.p_omega),
            spectral_invariants(&split.state.p_lambda),
        );
        for _ in 0..10_000 {
            run_sequence(&seq, 1e-3, 1, &mut split, |i, tau, w| w.flow(i, tau, &*pot));
            split.check_step().unwrap();
        }
        let (so2, sl2) = (
            spectral_invariants(&split.state.p_omega),
            spectral_invariants(&split.state.p_lambda),
        );
        for (u, v) in so.iter().zip(&so2).chain(sl.iter().zip(&sl2)) {
            assert!((u - v).abs() <= 1e-12 * u.abs(), "n = {n}: {u} vs {v}");
        }
        let (l0, g0) = momentum::momentum_map(&x, &p).unwrap();
        let (x1, p1) = split.full_state();
        let (l1, g1) = momentum::momentum_map(&x1, &p1).unwrap();
        assert!(rel(&l1, &l0) < 1e-12 && rel(&g1, &g0) < 1e-12, "n = {n}");
        // The entries themselves changed (the body rotates): the test is not vacuous.
        assert!((&split.state.p_omega - &reduce(&x, &p).unwrap().0.p_omega).norm_l2() > 1e-3);
        // The driver's method "reduced" is this kernel: the same final state, bit for bit.
        let b = body(n);
        let traj = integrate(
            &b,
            "reduced",
            &b.state(&x, &p).unwrap(),
            1e-3,
            10_000,
            10_000,
        )
        .unwrap();
        assert_eq!(traj.final_state, b.state(&x1, &p1).unwrap(), "n = {n}");
    }
}

#[test]
fn reduced_energy_error_is_bounded() {
    let b = body(3);
    let (x0, p0) = initial(3);
    let traj = integrate(
        &b,
        "reduced",
        &b.state(&x0, &p0).unwrap(),
        1e-3,
        20_000,
        1000,
    )
    .unwrap();
    let e0 = b.energy(traj.state(0)).unwrap();
    let worst = (0..traj.len())
        .map(|k| (b.energy(traj.state(k)).unwrap() - e0).abs() / e0.abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-3, "energy error {worst}");
}

#[test]
fn system_free_body_and_orders() {
    let n = 3;
    let b = PseudoRigidBody::new(n, Arc::new(Zero), true).unwrap();
    let (x0, p0) = initial(n);
    let traj = integrate(&b, "verlet", &b.state(&x0, &p0).unwrap(), 0.01, 50, 50).unwrap();
    let (x, p) = b.split(traj.state(1)).unwrap();
    assert!(rel(&x, &(&x0 + &p0 * faer::Scale(0.5))) < 1e-13 && rel(&p, &p0) < 1e-15);
    // Harmonic: orders 2, 4, 6 through the driver.
    let k = 1.5f64;
    let hb = PseudoRigidBody::new(n, Arc::new(Harmonic::new(k).unwrap()), true).unwrap();
    let w = k.sqrt();
    let t = 1.0;
    let exact = &x0 * faer::Scale((w * t).cos()) + &p0 * faer::Scale((w * t).sin() / w);
    for (m, s1) in [("verlet", 100), ("verlet4", 40), ("verlet6", 20)] {
        let order = order(&hb, m) as f64;
        let err = |steps: usize| rel(&final_xp(&hb, m, t / steps as f64, steps).0, &exact);
        let order_obs = (err(s1) / err(2 * s1)).log2();
        assert!((order_obs - order).abs() < 0.2, "{m}: {order_obs}");
    }
    assert_eq!(
        ["verlet", "verlet4", "verlet6", "reduced"].map(|m| order(&hb, m)),
        [2, 4, 6, 2]
    );
}

#[test]
fn system_invariants_and_batches() {
    for n in 2..=6 {
        let b = body(n);
        let (x0, p0) = initial(n);
        let s0 = b.state(&x0, &p0).unwrap();
        let c0 = b.invariants(&s0).unwrap();
        assert_eq!(c0.len(), 2 * (n / 2));
        assert_eq!(b.invariant_count(), c0.len());
        for m in ["verlet", "reduced"] {
            let trajs =
                integrate_batch(&b, m, &[s0.clone(), s0.clone()], 1e-3, 400, 200, None).unwrap();
            assert_eq!(trajs[0], trajs[1]);
            let c1 = b.invariants(trajs[0].state(2)).unwrap();
            for (u, v) in c0.iter().zip(&c1) {
                assert!((u - v).abs() < 1e-11 * u.abs().max(1.0), "n = {n}, {m}");
            }
            let (l0, _) = b.momenta(&s0).unwrap();
            let (l1, _) = b.momenta(trajs[0].state(2)).unwrap();
            assert!(rel(&l1, &l0) < 1e-12);
            let a = b.singular_values(trajs[0].state(2)).unwrap();
            assert!(a.windows(2).all(|w| w[0] >= w[1]) && a[n - 1] > 0.0);
        }
    }
}

#[test]
fn system_errors() {
    let n = 3;
    let b = body(n);
    let (x0, p0) = initial(n);
    let s0 = b.state(&x0, &p0).unwrap();
    assert!(matches!(
        integrate(&b, "splitting", &s0, 0.1, 1, 1),
        Err(Error::UnsupportedMethod { .. })
    ));
    assert!(matches!(
        integrate(&b, "verlet", &[1.0; 5], 0.1, 1, 1),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        b.state(&x0, &Mat::zeros(2, 2)),
        Err(Error::Shape { .. })
    ));
    let mut bad = s0.clone();
    bad[3] = f64::NAN;
    assert!(matches!(
        integrate(&b, "verlet", &bad, 0.1, 1, 1),
        Err(Error::NonFinite { .. })
    ));
    let neg = b.state(&(-&x0), &p0).unwrap();
    for m in ["verlet", "reduced"] {
        assert!(matches!(
            integrate(&b, m, &neg, 0.1, 1, 1),
            Err(Error::NotInGroup { .. })
        ));
    }
    assert!(matches!(
        PseudoRigidBody::new(1, Arc::new(Zero), true),
        Err(Error::InvalidArgument { .. })
    ));
    // Degenerate stratum for the reduced method only.
    let eye = b.state(&Mat::identity(n, n), &p0).unwrap();
    assert!(matches!(
        integrate(&b, "reduced", &eye, 0.1, 1, 1),
        Err(Error::DegenerateStratum { .. })
    ));
    assert!(integrate(&b, "verlet", &eye, 0.1, 1, 1).is_ok());
    assert!(matches!(
        ReducedState {
            a: vec![1.0, -1.0],
            p_a: vec![0.0; 2],
            p_omega: Mat::zeros(2, 2),
            p_lambda: Mat::zeros(2, 2)
        }
        .validate(),
        Err(Error::InvalidArgument { .. })
    ));
}

#[test]
fn leaving_gl_plus_names_the_time_for_both_methods() {
    // Harmonic k = 1 with P₀ = −X₀: X(t) = X₀ (cos t − sin t), det X = 0 at t = π/4.
    let n = 3;
    let x0 = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + 0.5 * i as f64 } else { 0.0 });
    let p0 = -&x0;
    for check in [true, false] {
        let b = PseudoRigidBody::new(n, Arc::new(Harmonic::new(1.0).unwrap()), check).unwrap();
        let s0 = b.state(&x0, &p0).unwrap();
        for m in ["verlet", "reduced"] {
            let r = integrate(&b, m, &s0, 1e-3, 2000, 100);
            if !check && m == "verlet" {
                assert!(r.is_ok());
                continue;
            }
            match r {
                Err(Error::LeftDomain { t, .. }) => {
                    assert!(
                        (t - std::f64::consts::FRAC_PI_4).abs() < 2e-3,
                        "{m}: t = {t}"
                    )
                }
                other => panic!("{m}: expected LeftDomain, got {other:?}"),
            }
        }
    }
}

#[test]
fn reduced_method_stops_at_an_unresolved_near_collision_of_semi_axes() {
    // This motion has an avoided crossing a₁ ≈ a₂ (gap ≈ 5e-5) near t = 2.3 (found with Verlet);
    // the reduced step cannot resolve it and must stop there instead of returning bad data.
    let b = body(3);
    let x0 = Mat::from_fn(3, 3, |i, j| {
        [[1.2, 0.05, 0.0], [0.0, 1.0, 0.03], [0.02, 0.0, 0.85]][i][j]
    });
    let p0 = Mat::from_fn(3, 3, |i, j| {
        [[0.0, 0.4, -0.1], [-0.2, 0.05, 0.3], [0.15, -0.25, 0.0]][i][j]
    });
    let s0 = b.state(&x0, &p0).unwrap();
    for dt in [1e-3, 2.5e-4] {
        match integrate(&b, "reduced", &s0, dt, (6.0 / dt) as usize, 100) {
            Err(Error::LeftDomain { t, .. }) => assert!((t - 2.3).abs() < 0.05, "t = {t}"),
            other => panic!("dt = {dt}: expected LeftDomain, got {other:?}"),
        }
    }
    assert!(integrate(&b, "verlet4", &s0, 1e-3, 6000, 100).is_ok());
}

/// Delegates to a potential but hides its n = 3 fast path, so Verlet takes the general loop.
#[derive(Debug)]
struct General(Arc<dyn Potential>);

impl Potential for General {
    fn value(&self, x: faer::MatRef<'_, f64>, ws: &mut Workspace) -> f64 {
        self.0.value(x, ws)
    }
    fn add_gradient(
        &self,
        x: faer::MatRef<'_, f64>,
        out: faer::MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        self.0.add_gradient(x, out, ws)
    }
    fn add_hessian(
        &self,
        x: faer::MatRef<'_, f64>,
        v: faer::MatRef<'_, f64>,
        out: faer::MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        self.0.add_hessian(x, v, out, ws)
    }
    fn needs_positive_det(&self) -> bool {
        self.0.needs_positive_det()
    }
}

fn potentials3() -> Vec<Arc<dyn Potential>> {
    vec![
        Arc::new(Zero),
        Arc::new(Harmonic::new(1.7).unwrap()),
        Arc::new(SaintVenantKirchhoff::new(0.7, 1.3).unwrap()),
        Arc::new(Volumetric::polytropic(0.4, 1.4).unwrap()),
        Arc::new(Volumetric::polytropic(0.4, 1.0).unwrap()),
        elastic_gas(),
    ]
}

#[test]
fn fixed_size_gradients_match_the_general_kernels() {
    let (x, _) = initial(3);
    let x3 = Matrix3::from_fn(|i, j| x[(i, j)]);
    for pot in potentials3() {
        let g = potential::gradient(&*pot, &x).unwrap();
        let g3 = pot
            .gradient3(&x3)
            .expect("built-ins have the n = 3 fast path");
        let err = (0..9)
            .map(|k| (g[(k / 3, k % 3)] - g3[(k / 3, k % 3)]).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-13 * g.norm_l2().max(1.0), "{pot:?}: {err}");
    }
    assert!(General(elastic_gas()).gradient3(&x3).is_none());
}

#[test]
fn verlet_fast_path_matches_the_general_loop() {
    let (x0, p0) = initial(3);
    for pot in potentials3() {
        for v in [Verlet::strang(), Verlet(Composition::yoshida6())] {
            let run = |pot: Arc<dyn Potential>| {
                let b = PseudoRigidBody::new(3, pot, false).unwrap();
                let traj =
                    integrate_with(&b, &v, &b.state(&x0, &p0).unwrap(), 1e-2, 200, 200).unwrap();
                b.split(&traj.final_state).unwrap()
            };
            let (xf, pf) = run(pot.clone());
            let (xg, pg) = run(Arc::new(General(pot.clone())));
            assert!(
                rel(&xf, &xg) < 1e-12 && rel(&pf, &pg) < 1e-12,
                "{pot:?} order {}",
                v.0.order()
            );
        }
    }
    // The exit error and the state left at the exit agree too (a run started at t0 = 1).
    let h: Arc<dyn Potential> = Arc::new(Harmonic::new(1.0).unwrap());
    let x = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + 0.5 * i as f64 } else { 0.0 });
    let exit = |pot: Arc<dyn Potential>| {
        let b = PseudoRigidBody::new(3, pot, true).unwrap();
        let z0 = b.state(&x, &(-&x)).unwrap();
        let mut run = Run::new(&b, "verlet", &z0, 1e-3, 2000, 1.0).unwrap();
        let e = run.advance(&b, 2000, &mut Vec::new());
        match e {
            Err(Error::LeftDomain { t, .. }) => (t, b.split(&run.state(&b)).unwrap().0),
            other => panic!("expected LeftDomain, got {other:?}"),
        }
    };
    let ((tf, xf), (tg, xg)) = (exit(h.clone()), exit(Arc::new(General(h.clone()))));
    assert_eq!(tf, tg);
    assert!((tf - 1.0 - std::f64::consts::FRAC_PI_4).abs() < 2e-3);
    assert!(rel(&xf, &xg) < 1e-12);
}
