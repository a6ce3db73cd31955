//! Pseudo-rigid body dynamics on T*GL⁺(n) (001 §3–§5): potentials, Verlet, the Riemann-ellipsoid
//! and Lagrangian forms, Dedekind's reciprocity.

mod common;

use common::{dist, Rng};
use lieflow::integrate::methods::{Composition, Verlet};
use lieflow::integrate::{integrate as drive, integrate_with, Run, System};
use lieflow::lie::so3;
use lieflow::pseudo_rigid::dynamics::{adjoint_motion, FullBody};
use lieflow::pseudo_rigid::potential::{
    self, Harmonic, Potential, SaintVenantKirchhoff, Sum, Volumetric, Zero,
};
use lieflow::pseudo_rigid::PseudoRigidBody;
use lieflow::{Error, Mat};
use nalgebra::Vector3;
use proptest::prelude::*;
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// Helpers (L, Γ, Q, N and SVD coordinates are computed inline here, per DESIGN.md).

/// A point of GL⁺(n) near the identity with well separated singular values.
fn gl_plus(rng: &mut Rng, n: usize) -> Mat {
    loop {
        let x = Mat::from_fn(n, n, |i, j| {
            (if i == j { 1.0 + 0.25 * i as f64 } else { 0.0 }) + 0.3 * rng.uniform()
        });
        if x.as_ref().determinant() > 0.2 {
            return x;
        }
    }
}

fn det(x: &Mat) -> f64 {
    x.as_ref().determinant()
}

/// A rotation in SO(n): the Q factor of a QR decomposition, with the sign of det fixed.
fn rotation(m: &Mat) -> Mat {
    let mut q = m.qr().compute_Q();
    if det(&q) < 0.0 {
        for i in 0..q.nrows() {
            q[(i, 0)] = -q[(i, 0)];
        }
    }
    q
}

/// Angular momentum L = PXᵀ − XPᵀ (001 (7.3)).
fn ang_mom(x: &Mat, p: &Mat) -> Mat {
    p * x.transpose() - x * p.transpose()
}

/// Circulation Γ = PᵀX − XᵀP (001 (7.3)).
fn circulation(x: &Mat, p: &Mat) -> Mat {
    p.transpose() * x - x.transpose() * p
}

fn rel(a: &Mat, b: &Mat) -> f64 {
    dist(a, b) / b.norm_l2().max(1e-300)
}

fn svk() -> SaintVenantKirchhoff {
    SaintVenantKirchhoff::new(0.7, 1.3).unwrap()
}

/// Elastic body with a gas inside: SVK + polytropic volumetric term.
fn elastic_gas() -> Arc<dyn Potential> {
    Arc::new(Sum::new(vec![
        Arc::new(svk()),
        Arc::new(Volumetric::polytropic(0.4, 1.4).unwrap()),
    ]))
}

fn all_potentials() -> Vec<(&'static str, Arc<dyn Potential>)> {
    vec![
        ("harmonic", Arc::new(Harmonic::new(2.0).unwrap())),
        ("svk", Arc::new(svk())),
        (
            "svk λ=0",
            Arc::new(SaintVenantKirchhoff::new(0.0, 0.5).unwrap()),
        ),
        (
            "polytropic",
            Arc::new(Volumetric::polytropic(0.5, 1.4).unwrap()),
        ),
        (
            "isothermal",
            Arc::new(Volumetric::polytropic(0.5, 1.0).unwrap()),
        ),
        ("sum", elastic_gas()),
    ]
}

/// The catalog name of Verlet of order 2, 4 or 6 ([`PseudoRigidBody`]).
fn verlet(order: usize) -> &'static str {
    match order {
        2 => "verlet",
        4 => "verlet4",
        6 => "verlet6",
        _ => panic!("Verlet has orders 2, 4 and 6, got {order}"),
    }
}

/// The pseudo-rigid body of the driver with potential `pot` in n dimensions; `check_det`: stop
/// when det X ≤ 0 (always on for a volumetric potential).
fn body_of(pot: Arc<dyn Potential>, n: usize, check_det: bool) -> PseudoRigidBody {
    PseudoRigidBody::new(n, pot, check_det).unwrap()
}

/// Runs `steps` steps of `method` and returns the final (X, P).
fn integrate(
    pot: Arc<dyn Potential>,
    method: &str,
    check_det: bool,
    x0: &Mat,
    p0: &Mat,
    dt: f64,
    steps: usize,
) -> (Mat, Mat) {
    let b = body_of(pot, x0.nrows(), check_det);
    let traj = drive(&b, method, &b.state(x0, p0).unwrap(), dt, steps, steps).unwrap();
    b.split(&traj.final_state).unwrap()
}

/// Frames (X_k, P_k), k = 0..=frames, every `every` steps (det X checked).
fn frames(
    pot: Arc<dyn Potential>,
    method: &str,
    x0: &Mat,
    p0: &Mat,
    dt: f64,
    every: usize,
    frames: usize,
) -> Vec<(Mat, Mat)> {
    let b = body_of(pot, x0.nrows(), true);
    let z0 = b.state(x0, p0).unwrap();
    let traj = drive(&b, method, &z0, dt, every * frames, every).unwrap();
    assert_eq!(traj.len(), frames + 1);
    (0..traj.len())
        .map(|k| b.split(traj.state(k)).unwrap())
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Potentials

#[test]
fn gradients_match_central_finite_differences() {
    let mut rng = Rng(1);
    for (name, pot) in all_potentials() {
        for n in 2..=6 {
            let x = gl_plus(&mut rng, n);
            let g = potential::gradient(&*pot, &x).unwrap();
            let h = 1e-5;
            let mut fd = Mat::zeros(n, n);
            for i in 0..n {
                for j in 0..n {
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[(i, j)] += h;
                    xm[(i, j)] -= h;
                    fd[(i, j)] = (potential::value(&*pot, &xp).unwrap()
                        - potential::value(&*pot, &xm).unwrap())
                        / (2.0 * h);
                }
            }
            let err = dist(&g, &fd) / g.norm_l2().max(1.0);
            assert!(err < 1e-8, "{name}, n = {n}: FD error {err:.2e}");
        }
    }
}

#[test]
fn closed_form_values() {
    // At X = aI: E = ½(a² − 1)I, tr E = n e, tr E² = n e²; det = aⁿ.
    let (n, a) = (3usize, 1.2f64);
    let x = Mat::identity(n, n) * faer::Scale(a);
    let e = 0.5 * (a * a - 1.0);
    let s = svk();
    let u = potential::value(&s, &x).unwrap();
    let nf = n as f64;
    let expect = 0.5 * s.lambda() * (nf * e).powi(2) + s.mu() * nf * e * e;
    assert!((u - expect).abs() < 1e-14);
    let h = Harmonic::new(3.0).unwrap();
    assert!((potential::value(&h, &x).unwrap() - 1.5 * nf * a * a).abs() < 1e-14);
    let v = Volumetric::polytropic(0.5, 1.4).unwrap();
    let d = a.powi(3);
    let expect = 0.5 * (d.powf(-0.4) - 1.0) / 0.4;
    assert!((potential::value(&v, &x).unwrap() - expect).abs() < 1e-14);
    let v1 = Volumetric::polytropic(0.5, 1.0).unwrap();
    assert!((potential::value(&v1, &x).unwrap() + 0.5 * d.ln()).abs() < 1e-14);
    // The polytropic family is continuous at γ = 1.
    let v_near = Volumetric::polytropic(0.5, 1.0 + 1e-7).unwrap();
    let gap = potential::value(&v_near, &x).unwrap() - potential::value(&v1, &x).unwrap();
    assert!(gap.abs() < 1e-7);
    assert_eq!(potential::value(&Zero, &x).unwrap(), 0.0);
    assert_eq!(potential::value(&Sum::new(vec![]), &x).unwrap(), 0.0);
}

fn invariance_case(n: usize, xs: &[f64]) {
    let nn = n * n;
    let x0 = Mat::from_fn(n, n, |i, j| {
        (if i == j { 1.0 } else { 0.0 }) + 0.3 * xs[i * n + j]
    });
    let x = if det(&x0) > 0.0 {
        x0
    } else {
        Mat::from_fn(n, n, |i, j| if i == 0 { -x0[(i, j)] } else { x0[(i, j)] })
    };
    let g = rotation(&Mat::from_fn(n, n, |i, j| xs[nn + i * n + j]));
    let h = rotation(&Mat::from_fn(n, n, |i, j| xs[2 * nn + i * n + j]));
    let y = &g * &x * h.transpose();
    for (name, pot) in all_potentials() {
        let (ux, uy) = (
            potential::value(&*pot, &x).unwrap(),
            potential::value(&*pot, &y).unwrap(),
        );
        assert!(
            (ux - uy).abs() <= 1e-11 * ux.abs().max(1.0),
            "{name}: U(X) = {ux}, U(gXhᵀ) = {uy}"
        );
        // Equivariance of the gradient: ∂U/∂X(gXhᵀ) = g ∂U/∂X(X) hᵀ.
        let gx = potential::gradient(&*pot, &x).unwrap();
        let gy = potential::gradient(&*pot, &y).unwrap();
        let err = dist(&gy, &(&g * &gx * h.transpose())) / gx.norm_l2().max(1.0);
        assert!(err < 1e-11, "{name}: gradient equivariance {err:.2e}");
        // Transposition invariance (used by Dedekind's reciprocity).
        let ut = potential::value(&*pot, &x.transpose().to_owned()).unwrap();
        assert!((ux - ut).abs() <= 1e-11 * ux.abs().max(1.0));
    }
}

proptest! {
    #[test]
    fn potentials_are_bi_invariant(
        (n, xs) in (2usize..=6).prop_flat_map(|n| {
            (Just(n), proptest::collection::vec(-1.0f64..1.0, 3 * n * n))
        })
    ) {
        invariance_case(n, &xs);
    }
}

#[test]
fn constructors_and_checked_evaluations_reject_bad_input() {
    for k in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            Harmonic::new(k),
            Err(Error::InvalidArgument { .. })
        ));
    }
    for (l, m) in [
        (-0.1, 1.0),
        (1.0, 0.0),
        (f64::NAN, 1.0),
        (1.0, f64::INFINITY),
    ] {
        assert!(matches!(
            SaintVenantKirchhoff::new(l, m),
            Err(Error::InvalidArgument { .. })
        ));
    }
    for (k, g) in [
        (0.0, 1.4),
        (1.0, 0.9),
        (1.0, f64::NAN),
        (f64::INFINITY, 1.4),
    ] {
        assert!(matches!(
            Volumetric::polytropic(k, g),
            Err(Error::InvalidArgument { .. })
        ));
    }
    let v = Volumetric::polytropic(1.0, 1.4).unwrap();
    let mut flip = Mat::identity(3, 3);
    flip[(0, 0)] = -1.0;
    assert!(matches!(
        potential::value(&v, &flip),
        Err(Error::NotInGroup { .. })
    ));
    assert!(matches!(
        potential::gradient(elastic_gas().as_ref(), &flip),
        Err(Error::NotInGroup { .. })
    ));
    // The raw kernel is +∞ outside GL⁺(n).
    let mut ws = potential::Workspace::new(3);
    assert_eq!(v.value(flip.as_ref(), &mut ws), f64::INFINITY);
    // Elastic potentials are defined on all matrices.
    assert!(potential::value(&svk(), &flip).is_ok());
    let mut nan = Mat::identity(3, 3);
    nan[(1, 2)] = f64::NAN;
    assert!(matches!(
        potential::gradient(&svk(), &nan),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        potential::value(&svk(), &Mat::zeros(2, 3)),
        Err(Error::Shape { .. })
    ));
}

// ---------------------------------------------------------------------------------------------
// Verlet: exact solutions, orders, invariants

#[test]
fn free_body_moves_on_straight_lines() {
    let mut rng = Rng(2);
    for n in 2..=6 {
        let x0 = gl_plus(&mut rng, n);
        let p0 = rng.mat(n, 0.1);
        for order in [2, 4, 6] {
            let (x, p) = integrate(Arc::new(Zero), verlet(order), true, &x0, &p0, 1e-2, 100);
            let exact = &x0 + &p0 * faer::Scale(1.0);
            // Round-off only: 100 × (1, 3 or 7) additions of ~1e-3 to entries of size ~1.
            let err = rel(&x, &exact);
            assert!(err < 1e-13, "n = {n}, order {order}: {err:.2e}");
            assert_eq!(dist(&p, &p0), 0.0);
        }
    }
}

/// X(t) = X₀ cos ωt + (P₀/ω) sin ωt, P(t) = −ωX₀ sin ωt + P₀ cos ωt.
fn harmonic_exact(x0: &Mat, p0: &Mat, omega: f64, t: f64) -> (Mat, Mat) {
    let (s, c) = (omega * t).sin_cos();
    (
        x0 * faer::Scale(c) + p0 * faer::Scale(s / omega),
        x0 * faer::Scale(-omega * s) + p0 * faer::Scale(c),
    )
}

#[test]
fn harmonic_oscillator_orders_2_4_6_through_det_zero() {
    // n = 3 (odd): X(t + π/ω) = −X(t), so det X changes sign before T; check_det is off.
    let mut rng = Rng(3);
    let (n, omega) = (3, 1.3);
    let pot: Arc<dyn Potential> = Arc::new(Harmonic::new(omega * omega).unwrap());
    let x0 = gl_plus(&mut rng, n);
    let p0 = rng.mat(n, 1.0);
    let t_end = std::f64::consts::PI / omega + 0.4;
    let (xe, pe) = harmonic_exact(&x0, &p0, omega, t_end);
    assert!(
        det(&xe) < 0.0,
        "the exact solution must have crossed det X = 0"
    );
    for (order, coarse) in [(2usize, 400usize), (4, 80), (6, 40)] {
        let err = |steps: usize| {
            let (x, p) = integrate(
                pot.clone(),
                verlet(order),
                false,
                &x0,
                &p0,
                t_end / steps as f64,
                steps,
            );
            dist(&x, &xe) + dist(&p, &pe)
        };
        let (e1, e2) = (err(coarse), err(2 * coarse));
        let observed = (e1 / e2).log2();
        eprintln!(
            "harmonic n = 3, order {order}: errors {e1:.3e}, {e2:.3e}, observed {observed:.3}"
        );
        assert!(
            (observed - order as f64).abs() < 0.2,
            "order {order}: errors {e1:.3e}, {e2:.3e}, observed {observed:.3}"
        );
    }
}

#[test]
fn harmonic_oscillator_for_n_2_to_6() {
    let mut rng = Rng(4);
    let omega = 0.9;
    let pot: Arc<dyn Potential> = Arc::new(Harmonic::new(omega * omega).unwrap());
    for n in 2..=6 {
        let x0 = gl_plus(&mut rng, n);
        let p0 = rng.mat(n, 0.5);
        let steps = 200;
        let t_end = 2.0;
        let (x, p) = integrate(
            pot.clone(),
            verlet(6),
            false,
            &x0,
            &p0,
            t_end / steps as f64,
            steps,
        );
        let (xe, pe) = harmonic_exact(&x0, &p0, omega, t_end);
        assert!(dist(&x, &xe) + dist(&p, &pe) < 1e-10, "n = {n}");
    }
}

#[test]
fn leaving_gl_plus_stops_with_the_time_of_exit() {
    let mut rng = Rng(5);
    let (n, omega) = (3, 1.3);
    let pot: Arc<dyn Potential> = Arc::new(Harmonic::new(omega * omega).unwrap());
    let x0 = gl_plus(&mut rng, n);
    let p0 = rng.mat(n, 1.0);
    // First root t* of det X(t) for the exact motion, by scanning and bisection.
    let d = |t: f64| det(&harmonic_exact(&x0, &p0, omega, t).0);
    let mut t_hi = 0.0;
    while d(t_hi) > 0.0 {
        t_hi += 1e-3;
    }
    let mut t_lo = t_hi - 1e-3;
    for _ in 0..60 {
        let mid = 0.5 * (t_lo + t_hi);
        if d(mid) > 0.0 {
            t_lo = mid
        } else {
            t_hi = mid
        }
    }
    let dt = 1e-3;
    let b = body_of(pot.clone(), n, true);
    let z0 = b.state(&x0, &p0).unwrap();
    for order in [2, 4, 6] {
        let steps = (10.0 / dt) as usize;
        let mut run = Run::new(&b, verlet(order), &z0, dt, steps, 0.0).unwrap();
        match run.advance(&b, steps as u64, &mut Vec::new()) {
            Err(Error::LeftDomain { t, message, .. }) => {
                // t is the time at the end of the step in which det X ≤ 0 was found.
                assert!(
                    t >= t_lo - 1e-6 && t <= t_lo + dt + 1e-6,
                    "t = {t}, t* = {t_lo}"
                );
                assert!(message.contains("check_det"), "{message}");
                let k = (t / dt).round();
                assert!(message.contains(&format!("found in step {k}")), "{message}");
                // The run is left at the first state found outside GL⁺(n).
                let (x, _) = b.split(&run.state(&b)).unwrap();
                assert!(det(&x) <= 0.0);
            }
            other => panic!("expected LeftDomain, got {other:?}"),
        }
    }
    // X(t + π/ω) = −X(t) with check_det off.
    let half = std::f64::consts::PI / omega;
    let (x, _) = integrate(pot, verlet(6), false, &x0, &p0, half / 200.0, 200);
    assert!(dist(&x, &(-&x0)) < 1e-9);
}

#[test]
fn volumetric_potentials_are_always_checked() {
    // A collapsing body with a gas, with a step so large that X jumps past det X = 0.
    let pot = elastic_gas();
    let x0 = Mat::identity(3, 3);
    let p0 = Mat::identity(3, 3) * faer::Scale(-3.0);
    let b = body_of(pot, 3, false);
    assert!(b.check_det());
    let mut run = Run::new(&b, "verlet", &b.state(&x0, &p0).unwrap(), 1.0, 10, 5.0).unwrap();
    let res = run.advance(&b, 10, &mut Vec::new());
    assert!(
        matches!(res, Err(Error::LeftDomain { t, .. }) if t == 6.0),
        "{res:?}"
    );
}

/// The flat state (X, P) row-major of any X, P (no checks: for states of the wrong shape).
fn flat(x: &Mat, p: &Mat) -> Vec<f64> {
    let row_major = |m: &Mat| {
        (0..m.nrows())
            .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
            .collect::<Vec<f64>>()
    };
    [row_major(x), row_major(p)].concat()
}

#[test]
fn run_rejects_bad_input_and_changes_nothing() {
    let pot: Arc<dyn Potential> = Arc::new(svk());
    let b = body_of(pot.clone(), 3, true);
    let x0 = Mat::identity(3, 3);
    let p0 = Mat::zeros(3, 3);
    let mut bad_det = x0.clone();
    bad_det[(2, 2)] = -1.0;
    let mut nan = x0.clone();
    nan[(0, 1)] = f64::NAN;
    type Case = (Mat, Mat, f64, usize, fn(&Error) -> bool);
    let cases: Vec<Case> = vec![
        (x0.clone(), p0.clone(), 0.0, 10, |e| {
            matches!(e, Error::InvalidArgument { .. })
        }),
        (x0.clone(), p0.clone(), -0.1, 10, |e| {
            matches!(e, Error::InvalidArgument { .. })
        }),
        (x0.clone(), p0.clone(), f64::NAN, 10, |e| {
            matches!(e, Error::InvalidArgument { .. })
        }),
        (x0.clone(), p0.clone(), 0.1, 0, |e| {
            matches!(e, Error::InvalidArgument { .. })
        }),
        (Mat::identity(2, 2), p0.clone(), 0.1, 10, |e| {
            matches!(e, Error::Shape { .. })
        }),
        (x0.clone(), Mat::zeros(3, 2), 0.1, 10, |e| {
            matches!(e, Error::Shape { .. })
        }),
        (nan, p0.clone(), 0.1, 10, |e| {
            matches!(e, Error::NonFinite { .. })
        }),
        (bad_det.clone(), p0.clone(), 0.1, 10, |e| {
            matches!(e, Error::NotInGroup { .. })
        }),
    ];
    for (x_in, p_in, dt, steps, ok) in cases {
        // The driver takes the state by reference: it validates before any work and cannot
        // change the caller's data; check that anyway, bit for bit.
        let z = flat(&x_in, &p_in);
        let before: Vec<u64> = z.iter().map(|v| v.to_bits()).collect();
        for method in ["verlet", "verlet4", "verlet6"] {
            let err = drive(&b, method, &z, dt, steps, 1).unwrap_err();
            assert!(ok(&err), "{method}: {err:?}");
            let err = Run::new(&b, method, &z, dt, 1, 0.0)
                .and_then(|mut run| run.advance(&b, steps as u64, &mut Vec::new()));
            if steps > 0 {
                assert!(ok(&err.unwrap_err()), "{method}");
            }
        }
        let err = integrate_with(&b, &Verlet::strang(), &z, dt, steps, 1).unwrap_err();
        assert!(ok(&err), "{err:?}");
        assert_eq!(
            z.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            before,
            "state changed"
        );
    }
    // (X, P) of the wrong shape are rejected by the state builder too.
    assert!(matches!(
        b.state(&Mat::identity(2, 2), &p0),
        Err(Error::Shape { .. })
    ));
    // The same det X₀ ≤ 0 is fine with check_det off for an elastic potential.
    let free = body_of(pot, 3, false);
    drive(
        &free,
        "verlet",
        &free.state(&bad_det, &p0).unwrap(),
        0.1,
        10,
        10,
    )
    .unwrap();
    // Methods are the body's catalog (orders 2, 4, 6) or values with any valid composition.
    assert!(matches!(
        drive(&b, "verlet3", &flat(&x0, &p0), 0.1, 10, 1),
        Err(Error::UnsupportedMethod { .. })
    ));
    assert!(Composition::new(vec![1.0], 3).is_err());
    let orders: Vec<(&str, u32)> = b.methods().into_iter().map(|(m, p)| (m, p.order)).collect();
    assert_eq!(
        orders,
        [
            ("verlet", 2),
            ("verlet4", 4),
            ("verlet6", 6),
            ("reduced", 2)
        ]
    );
}

#[test]
fn verlet_preserves_angular_momentum_and_circulation() {
    let mut rng = Rng(6);
    let pot = svk();
    let x0 = gl_plus(&mut rng, 3);
    let p0 = rng.mat(3, 0.8);
    let (l0, g0) = (ang_mom(&x0, &p0), circulation(&x0, &p0));
    // SVK is defined on all n×n matrices (and does not keep det X > 0): check_det off.
    let (x, p) = integrate(Arc::new(pot), verlet(2), false, &x0, &p0, 1e-2, 100_000);
    let (dl, dg) = (rel(&ang_mom(&x, &p), &l0), rel(&circulation(&x, &p), &g0));
    eprintln!("SVK n = 3, 1e5 Verlet steps: L drift {dl:.2e}, Γ drift {dg:.2e}");
    assert!(
        dl < 1e-12 && dg < 1e-12,
        "L drift {dl:.2e}, Γ drift {dg:.2e}"
    );
    // The motion is not trivial: X has moved far from X₀.
    assert!(dist(&x, &x0) > 0.1);
    for n in 2..=6 {
        // Moderate strain: SVK lets a singular value collapse at finite energy, and the gas
        // barrier alone makes strongly strained large-n bodies stiff near det X = 0.
        let x0 = &Mat::identity(n, n) + rng.mat(n, 0.2);
        let p0 = rng.mat(n, 0.4);
        let (l0, g0) = (ang_mom(&x0, &p0), circulation(&x0, &p0));
        for order in [4, 6] {
            let (x, p) = integrate(elastic_gas(), verlet(order), true, &x0, &p0, 1e-2, 3_000);
            let (dl, dg) = (rel(&ang_mom(&x, &p), &l0), rel(&circulation(&x, &p), &g0));
            assert!(
                dl < 1e-12 && dg < 1e-12,
                "n = {n}, order {order}: {dl:.2e} {dg:.2e}"
            );
        }
    }
}

#[test]
fn energy_error_is_bounded_over_a_million_steps() {
    let mut rng = Rng(7);
    let pot = elastic_gas();
    let body = FullBody::new(3, pot.clone()).unwrap();
    let x0 = gl_plus(&mut rng, 3);
    let p0 = rng.mat(3, 0.8);
    let h0 = body.hamiltonian(&x0, &p0).unwrap();
    let (dt, chunk, chunks) = (1e-2, 100, 10_000);
    let b = body_of(pot, 3, true);
    // One run resumed chunk by chunk (the run owns the clock).
    let mut run = Run::new(&b, "verlet", &b.state(&x0, &p0).unwrap(), dt, chunk, 0.0).unwrap();
    let mut saved = Vec::with_capacity(9 * 2 * 2);
    let mut errs = Vec::with_capacity(chunks);
    for k in 0..chunks {
        saved.clear();
        assert_eq!(run.advance(&b, chunk as u64, &mut saved).unwrap(), 1);
        assert_eq!(run.steps_done(), ((k + 1) * chunk) as u64);
        let (x, p) = b.split(&run.state(&b)).unwrap();
        assert_eq!(b.split(&saved).unwrap(), (x.clone(), p.clone()));
        errs.push((body.hamiltonian(&x, &p).unwrap() - h0).abs() / h0.abs());
    }
    assert!((run.time() - (chunks * chunk) as f64 * dt).abs() < 1e-9);
    let tenth = chunks / 10;
    let first = errs[..tenth].iter().cloned().fold(0.0, f64::max);
    let last = errs[chunks - tenth..].iter().cloned().fold(0.0, f64::max);
    eprintln!("1e6 steps: max rel. energy error first tenth {first:.3e}, last tenth {last:.3e}");
    assert!(
        last <= 2.0 * first,
        "first tenth {first:.3e}, last tenth {last:.3e}"
    );
    assert!(first < 1e-3, "{first:.3e}");
}

// ---------------------------------------------------------------------------------------------
// Hamilton's equations, Riemann-ellipsoid form (001 (3.20)), Lagrangian form (Prop. 4.2, (5.5))

#[test]
fn hamiltonian_and_vector_field() {
    let mut rng = Rng(8);
    let body = FullBody::new(4, elastic_gas()).unwrap();
    let x = gl_plus(&mut rng, 4);
    let p = rng.mat(4, 0.5);
    let h = body.hamiltonian(&x, &p).unwrap();
    let u = potential::value(body.potential(), &x).unwrap();
    assert!((h - 0.5 * p.norm_l2().powi(2) - u).abs() < 1e-13);
    let (xd, pd) = body.vector_field(&x, &p).unwrap();
    assert_eq!(dist(&xd, &p), 0.0);
    assert!(dist(&pd, &-potential::gradient(body.potential(), &x).unwrap()) < 1e-15);
    assert!(FullBody::new(1, elastic_gas()).is_err());
    assert!(matches!(
        body.hamiltonian(&Mat::identity(3, 3), &p),
        Err(Error::Shape { .. })
    ));
    let mut flip = Mat::identity(4, 4);
    flip[(0, 0)] = -1.0;
    assert!(matches!(
        body.vector_field(&flip, &p),
        Err(Error::NotInGroup { .. })
    ));
}

/// Symmetric square root of an SPD matrix (eigen-decomposition).
fn sqrt_spd(q: &Mat) -> Mat {
    let eig = q.self_adjoint_eigen(faer::Side::Lower).unwrap();
    let n = q.nrows();
    let d = Mat::from_fn(n, n, |i, j| if i == j { eig.S()[i].sqrt() } else { 0.0 });
    eig.U() * d * eig.U().transpose()
}

#[test]
fn riemann_force_is_two_q_du_dq() {
    // (3.20a) has −2Q ∂U/∂Q for U = V(Q); the code uses X(∂U/∂X)ᵀ. Compare with finite
    // differences of V(Q) = U(Q^{1/2}) over symmetric perturbations.
    let mut rng = Rng(9);
    for (name, pot) in all_potentials() {
        let n = 3;
        let x = gl_plus(&mut rng, n);
        let q = &x * x.transpose();
        let v = |q: &Mat| potential::value(&*pot, &sqrt_spd(q)).unwrap();
        let h = 1e-6;
        let mut gq = Mat::zeros(n, n);
        for i in 0..n {
            for j in i..n {
                let mut dq = Mat::zeros(n, n);
                dq[(i, j)] = h;
                dq[(j, i)] = h;
                let dv = (v(&(&q + &dq)) - v(&(&q - &dq))) / (2.0 * h);
                // ⟨G, dQ⟩ = G_ii h (i = j) or 2 G_ij h (i ≠ j) for symmetric G.
                let g = if i == j { dv } else { 0.5 * dv };
                gq[(i, j)] = g;
                gq[(j, i)] = g;
            }
        }
        let force = &x * potential::gradient(&*pot, &x).unwrap().transpose();
        let err = dist(&(&q * &gq * faer::Scale(2.0)), &force) / force.norm_l2().max(1.0);
        assert!(err < 1e-7, "{name}: {err:.2e}");
    }
}

#[test]
fn riemann_equations_follow_from_hamilton_equations() {
    // Chain rule at random (X, P): Q̇ = PXᵀ + XPᵀ, Ṅ = PPᵀ + X Ṗᵀ.
    let mut rng = Rng(10);
    for n in 2..=6 {
        let body = FullBody::new(n, elastic_gas()).unwrap();
        let x = gl_plus(&mut rng, n);
        let p = rng.mat(n, 0.7);
        let (_, pd) = body.vector_field(&x, &p).unwrap();
        let q = &x * x.transpose();
        let nn = &x * p.transpose();
        let (qd, nd) = body.riemann_vector_field(&q, &nn).unwrap();
        let qd_ref = &p * x.transpose() + &x * p.transpose();
        let nd_ref = &p * p.transpose() + &x * pd.transpose();
        assert!(rel(&qd, &qd_ref) < 1e-12, "n = {n}");
        assert!(
            rel(&nd, &nd_ref) < 1e-10,
            "n = {n}: {:.2e}",
            rel(&nd, &nd_ref)
        );
    }
}

/// Five-point central differences: first and second derivative at the middle sample.
fn d1(f: [&Mat; 5], h: f64) -> Mat {
    (f[0] - f[1] * faer::Scale(8.0) + f[3] * faer::Scale(8.0) - f[4])
        * faer::Scale(1.0 / (12.0 * h))
}

#[test]
fn full_trajectories_satisfy_the_riemann_equations() {
    let mut rng = Rng(11);
    for n in [2, 3, 5] {
        let body = FullBody::new(n, elastic_gas()).unwrap();
        let x0 = gl_plus(&mut rng, n);
        let p0 = rng.mat(n, 0.7);
        let h = 1e-3;
        let fr = frames(body.potential_arc(), verlet(6), &x0, &p0, h, 1, 600);
        for c in [2, 300, 598] {
            let qn: Vec<(Mat, Mat)> = (c - 2..=c + 2)
                .map(|k| {
                    let (x, p) = &fr[k];
                    (x * x.transpose(), x * p.transpose())
                })
                .collect();
            let qd_fd = d1([&qn[0].0, &qn[1].0, &qn[2].0, &qn[3].0, &qn[4].0], h);
            let nd_fd = d1([&qn[0].1, &qn[1].1, &qn[2].1, &qn[3].1, &qn[4].1], h);
            let (qd, nd) = body.riemann_vector_field(&qn[2].0, &qn[2].1).unwrap();
            assert!(rel(&qd_fd, &qd) < 1e-8, "n = {n}: {:.2e}", rel(&qd_fd, &qd));
            assert!(rel(&nd_fd, &nd) < 1e-8, "n = {n}: {:.2e}", rel(&nd_fd, &nd));
        }
    }
    let body = FullBody::new(3, elastic_gas()).unwrap();
    let mut not_spd = Mat::identity(3, 3);
    not_spd[(1, 1)] = -1.0;
    assert!(matches!(
        body.riemann_vector_field(&not_spd, &Mat::zeros(3, 3)),
        Err(Error::NotInGroup { .. })
    ));
    let mut asym = Mat::identity(3, 3);
    asym[(0, 1)] = 0.5;
    assert!(matches!(
        body.riemann_vector_field(&asym, &Mat::zeros(3, 3)),
        Err(Error::NotInGroup { .. })
    ));
}

/// SVD coordinates of the frames k = c−2..=c+2, with the column signs of every frame aligned
/// with the middle one (so that R(t), S(t) are continuous): (U_k, a_k, V_k), X_k = U_k A_k V_kᵀ.
fn aligned_svds(fr: &[(Mat, Mat)], c: usize) -> Vec<(Mat, Vec<f64>, Mat)> {
    let svd = |x: &Mat| {
        let s = x.svd().unwrap();
        let a: Vec<f64> = (0..x.nrows()).map(|i| s.S()[i]).collect();
        (s.U().to_owned(), a, s.V().to_owned())
    };
    let mid = svd(&fr[c].0);
    assert!(
        mid.1.windows(2).all(|w| w[0] > w[1] + 1e-3),
        "principal stratum"
    );
    (c - 2..=c + 2)
        .map(|k| {
            let (mut u, a, mut v) = svd(&fr[k].0);
            for j in 0..u.ncols() {
                let dot: f64 = (0..u.nrows()).map(|i| u[(i, j)] * mid.0[(i, j)]).sum();
                if dot < 0.0 {
                    for i in 0..u.nrows() {
                        u[(i, j)] = -u[(i, j)];
                        v[(i, j)] = -v[(i, j)];
                    }
                }
            }
            (u, a, v)
        })
        .collect()
}

#[test]
fn full_trajectories_satisfy_the_lagrangian_form() {
    let mut rng = Rng(12);
    for n in [2, 3, 4] {
        let body = FullBody::new(n, elastic_gas()).unwrap();
        let x0 = gl_plus(&mut rng, n);
        let p0 = rng.mat(n, 0.6);
        let h = 1e-3;
        let fr = frames(body.potential_arc(), verlet(6), &x0, &p0, h, 1, 300);
        for c in [2, 150, 298] {
            let svds = aligned_svds(&fr, c);
            let (u, a, v) = &svds[2];
            let p = &fr[c].1;
            // Body velocities from M = RᵀẊS = ΩA + Ȧ − AΛ (off-diagonal 2×2 solves).
            let m = u.transpose() * p * v;
            let mut omega = Mat::zeros(n, n);
            let mut lambda = Mat::zeros(n, n);
            for i in 0..n {
                for j in i + 1..n {
                    let den = a[j] * a[j] - a[i] * a[i];
                    omega[(i, j)] = (a[j] * m[(i, j)] + a[i] * m[(j, i)]) / den;
                    lambda[(i, j)] = (a[i] * m[(i, j)] + a[j] * m[(j, i)]) / den;
                    omega[(j, i)] = -omega[(i, j)];
                    lambda[(j, i)] = -lambda[(i, j)];
                }
            }
            let rates = body.lagrange_vector_field(a, &omega, &lambda).unwrap();
            // (4.15): p_Ω = RᵀLR, p_Λ = SᵀΓS.
            let body_l = |k: usize| {
                let (xk, pk) = &fr[c - 2 + k];
                svds[k].0.transpose() * ang_mom(xk, pk) * &svds[k].0
            };
            let body_g = |k: usize| {
                let (xk, pk) = &fr[c - 2 + k];
                svds[k].2.transpose() * circulation(xk, pk) * &svds[k].2
            };
            assert!(rel(&rates.p_omega, &body_l(2)) < 1e-10, "n = {n}");
            assert!(rel(&rates.p_lambda, &body_g(2)) < 1e-10, "n = {n}");
            // (4.11b, c) by central differences along the trajectory.
            let ls: Vec<Mat> = (0..5).map(body_l).collect();
            let gs: Vec<Mat> = (0..5).map(body_g).collect();
            let scale = rates.p_omega.norm_l2() + rates.p_lambda.norm_l2();
            let e_l = dist(
                &d1([&ls[0], &ls[1], &ls[2], &ls[3], &ls[4]], h),
                &rates.p_omega_dot,
            );
            let e_g = dist(
                &d1([&gs[0], &gs[1], &gs[2], &gs[3], &gs[4]], h),
                &rates.p_lambda_dot,
            );
            assert!(
                e_l < 1e-7 * scale && e_g < 1e-7 * scale,
                "n = {n}: {e_l:.2e} {e_g:.2e}"
            );
            // (4.11a): ä = E − ∂U/∂A.
            for i in 0..n {
                let f: Vec<f64> = svds.iter().map(|s| s.1[i]).collect();
                let add = (-f[0] + 16.0 * f[1] - 30.0 * f[2] + 16.0 * f[3] - f[4]) / (12.0 * h * h);
                assert!(
                    (add - rates.a_ddot[i]).abs() < 1e-5 * (1.0 + rates.a_ddot[i].abs()),
                    "n = {n}, i = {i}: FD {add}, (4.11a) {}",
                    rates.a_ddot[i]
                );
            }
        }
    }
}

fn to_mat(m: &nalgebra::Matrix3<f64>) -> Mat {
    Mat::from_fn(3, 3, |i, j| m[(i, j)])
}

fn vee(m: &Mat) -> Vector3<f64> {
    Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

#[test]
fn vector_equations_5_5_agree_with_prop_4_2() {
    let mut rng = Rng(13);
    let body = FullBody::new(3, elastic_gas()).unwrap();
    for _ in 0..20 {
        let a = Vector3::new(
            1.5 + 0.2 * rng.uniform(),
            1.0 + 0.2 * rng.uniform(),
            0.6 + 0.1 * rng.uniform(),
        );
        let w = Vector3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let l = Vector3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let v = body.lagrange_vector_field_3d(&a, &w, &l).unwrap();
        let r = body
            .lagrange_vector_field(a.as_slice(), &to_mat(&so3::hat(&w)), &to_mat(&so3::hat(&l)))
            .unwrap();
        let close = |x: Vector3<f64>, y: Vector3<f64>| (x - y).norm() < 1e-13 * (1.0 + y.norm());
        assert!(close(v.m, vee(&r.p_omega)));
        assert!(close(v.c, vee(&r.p_lambda)));
        assert!(close(v.e, Vector3::from_column_slice(&r.e)));
        assert!(close(v.a_ddot, Vector3::from_column_slice(&r.a_ddot)));
        assert!(close(v.m_dot, vee(&r.p_omega_dot)));
        assert!(close(v.c_dot, vee(&r.p_lambda_dot)));
    }
    let body2 = FullBody::new(2, elastic_gas()).unwrap();
    let z = Vector3::zeros();
    assert!(body2
        .lagrange_vector_field_3d(&Vector3::new(1.0, 1.0, 1.0), &z, &z)
        .is_err());
    assert!(body
        .lagrange_vector_field_3d(&Vector3::new(1.0, 0.0, 1.0), &z, &z)
        .is_err());
    let sym = Mat::identity(3, 3);
    assert!(matches!(
        body.lagrange_vector_field(&[1.0, 2.0, 3.0], &sym, &Mat::zeros(3, 3)),
        Err(Error::NotInGroup { .. })
    ));
    assert!(matches!(
        body.lagrange_vector_field(&[1.0, 2.0], &Mat::zeros(3, 3), &Mat::zeros(3, 3)),
        Err(Error::Shape { .. })
    ));
}

// ---------------------------------------------------------------------------------------------
// Dedekind's reciprocity

fn stack(frames: &[(Mat, Mat)]) -> (Vec<f64>, Vec<f64>) {
    let n = frames[0].0.nrows();
    let (mut xs, mut ps) = (Vec::new(), Vec::new());
    for (x, p) in frames {
        for i in 0..n {
            for j in 0..n {
                xs.push(x[(i, j)]);
                ps.push(p[(i, j)]);
            }
        }
    }
    (xs, ps)
}

#[test]
fn dedekind_adjoint_motion_is_a_motion_and_swaps_l_and_gamma() {
    let mut rng = Rng(14);
    for n in [2, 3, 4] {
        let pot = elastic_gas();
        let x0 = gl_plus(&mut rng, n);
        let p0 = rng.mat(n, 0.7);
        let direct = frames(pot.clone(), verlet(4), &x0, &p0, 1e-2, 50, 8);
        let xt = x0.transpose().to_owned();
        let pt = p0.transpose().to_owned();
        let adjoint = frames(pot.clone(), verlet(4), &xt, &pt, 1e-2, 50, 8);
        let (xs, ps) = stack(&direct);
        let (axs, aps) = adjoint_motion(n, &xs, &ps).unwrap();
        let (bxs, bps) = stack(&adjoint);
        let err = axs
            .iter()
            .zip(&bxs)
            .chain(aps.iter().zip(&bps))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-11, "n = {n}: {err:.2e}");
        for ((x, p), (y, q)) in direct.iter().zip(&adjoint) {
            assert!(rel(&ang_mom(y, q), &circulation(x, p)) < 1e-11);
            assert!(rel(&circulation(y, q), &ang_mom(x, p)) < 1e-11);
        }
        // The motion is genuinely different from its adjoint (L ≠ Γ).
        assert!(dist(&ang_mom(&x0, &p0), &circulation(&x0, &p0)) > 0.1);
    }
    assert!(matches!(
        adjoint_motion(3, &[0.0; 10], &[0.0; 10]),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        adjoint_motion(3, &[0.0; 9], &[0.0; 18]),
        Err(Error::Shape { .. })
    ));
    assert!(adjoint_motion(1, &[0.0], &[0.0]).is_err());
    let mut bad = [0.0; 9];
    bad[4] = f64::INFINITY;
    assert!(matches!(
        adjoint_motion(3, &bad, &[0.0; 9]),
        Err(Error::NonFinite { .. })
    ));
}

// ---------------------------------------------------------------------------------------------
// No allocation per step: a global allocator that counts this thread's allocations.

struct CountingAlloc;

thread_local! {
    static ALLOCS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

unsafe impl std::alloc::GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

/// Allocations made on this thread by `f`.
fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCS.with(|c| c.get());
    f();
    ALLOCS.with(|c| c.get()) - before
}

/// Allocations of `Run::advance` by `steps` steps of a run built (and its output reserved)
/// beforehand; save_every = steps, so exactly one state is saved.
fn advance_allocations<S: System>(
    sys: &S,
    method: &str,
    z0: &[f64],
    dt: f64,
    steps: usize,
) -> usize {
    let mut run = Run::new(sys, method, z0, dt, steps, 0.0).unwrap();
    let mut out = Vec::with_capacity(z0.len());
    let count = allocations(|| {
        assert_eq!(run.advance(sys, steps as u64, &mut out).unwrap(), 1);
    });
    assert_eq!(out.len(), z0.len());
    count
}

#[test]
fn verlet_steps_do_not_allocate() {
    // The counter sees this thread's allocations (so a count of 0 below means something).
    assert!(allocations(|| drop(std::hint::black_box(vec![0u8; 16]))) > 0);
    let mut rng = Rng(15);
    for n in [2, 3, 4, 7] {
        let pot = elastic_gas();
        let x0 = &Mat::identity(n, n) + rng.mat(n, 0.1);
        let p0 = rng.mat(n, 0.1);
        let b = body_of(pot, n, true);
        let z0 = b.state(&x0, &p0).unwrap();
        let count = |steps: usize| advance_allocations(&b, "verlet6", &z0, 1e-3, steps);
        let (few, many) = (count(1), count(1000));
        assert_eq!(
            few, many,
            "n = {n}: allocations grow with the number of steps"
        );
        assert_eq!(many, 0, "n = {n}: the step loop allocates");
    }
    // The same for the rigid body's splitting, with and without the attitude (the attitude run
    // crosses the driver's retractions, every 256 steps).
    let body = lieflow::systems::RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let m0 = [1.0, 0.5, -0.3];
    let lifted = body.with_attitude();
    let z0 = lifted.state_with_attitude(m0, [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    for steps in [1, 1000] {
        assert_eq!(advance_allocations(&body, "splitting", &m0, 1e-2, steps), 0);
        assert_eq!(
            advance_allocations(&lifted, "splitting", &z0, 1e-2, steps),
            0
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Timing (not a test: run with `--ignored --nocapture`; numbers go to docs/bench-pot.md).

#[test]
#[ignore]
fn bench_verlet_steps_per_second() {
    let mut rng = Rng(99);
    let cases: Vec<(&str, usize, Arc<dyn Potential>, usize)> = vec![
        ("SVK", 3, Arc::new(svk()), 4_000_000),
        ("SVK + polytropic gas", 3, elastic_gas(), 2_000_000),
        ("SVK", 10, Arc::new(svk()), 400_000),
        ("SVK + polytropic gas", 10, elastic_gas(), 200_000),
    ];
    for (name, n, pot, steps) in cases {
        for check_det in [true, false] {
            if pot.needs_positive_det() && !check_det {
                continue;
            }
            let x0 = &Mat::identity(n, n) + rng.mat(n, 0.1);
            let p0 = rng.mat(n, 0.1);
            let b = body_of(pot.clone(), n, check_det);
            let mut run =
                Run::new(&b, "verlet", &b.state(&x0, &p0).unwrap(), 1e-3, steps, 0.0).unwrap();
            let mut out = Vec::with_capacity(2 * n * n);
            let start = std::time::Instant::now();
            run.advance(&b, steps as u64, &mut out).unwrap();
            let secs = start.elapsed().as_secs_f64();
            eprintln!(
                "{name:>22}, n = {n:>2}, check_det = {check_det:>5}: {:>6.1} ns/step, {:.3e} steps/s",
                secs / steps as f64 * 1e9,
                steps as f64 / secs
            );
        }
    }
}
