//! Integrators on the free rigid body: elliptic functions and the exact solution, observed orders,
//! long-run preservation (Casimir, spatial momentum, SO(3), energy).

#![allow(clippy::excessive_precision)] // reference values are quoted as printed by mpmath

mod common;

use common::order;
use lieflow::integrate::methods::{Composition, Processed, Splitting};
use lieflow::integrate::{integrate, integrate_with, Problem, Trajectory};
use lieflow::numerics::elliptic::{ellipf, ellipj, ellipk};
use lieflow::systems::RigidBody;
use nalgebra::{Matrix3, Vector3};

const M0: [f64; 3] = [1.0, 0.5, -0.3];

fn body() -> RigidBody {
    RigidBody::new([1.0, 2.0, 3.0]).unwrap()
}

fn identity() -> [f64; 9] {
    [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
}

// Reference values: mpmath 1.3 (mp.dps = 30), `ellipfun('sn'|'cn'|'dn', u, m=m)`, `ellipk(m)`,
// `ellipf(phi, m)`, printed to 17 significant digits.
#[test]
fn elliptic_functions_match_mpmath() {
    let snd = [
        (0.3, 0.0, 0.29552020666133956, 0.95533648912560602, 1.0),
        (
            0.7,
            0.5,
            0.62434009096621735,
            0.78115264245363431,
            0.89727349532132494,
        ),
        (
            2.5,
            0.9,
            0.99969453845058613,
            0.024714971010898663,
            0.31709580068626356,
        ),
        (
            -1.3,
            0.3,
            -0.9396511313083225,
            0.34213411322314773,
            0.85738948292435738,
        ),
        (
            10.0,
            0.99,
            -0.99142074486068205,
            -0.1307092447376634,
            0.16405504440062638,
        ),
        (
            50.0,
            0.2,
            -0.20941879610043375,
            -0.97782604170672656,
            0.9956047175299889,
        ),
    ];
    for (u, m, sn, cn, dn) in snd {
        let (s, c, d) = ellipj(u, m).unwrap();
        assert!((s - sn).abs() < 1e-14, "sn({u}|{m}) = {s}, mpmath {sn}");
        assert!((c - cn).abs() < 1e-14, "cn({u}|{m}) = {c}, mpmath {cn}");
        assert!((d - dn).abs() < 1e-14, "dn({u}|{m}) = {d}, mpmath {dn}");
    }
    let kk = [
        (0.0, std::f64::consts::FRAC_PI_2),
        (0.5, 1.8540746773013719),
        (0.9, 2.5780921133481733),
        (0.999, 4.8411325605502966),
    ];
    for (m, k) in kk {
        assert!((ellipk(m).unwrap() - k).abs() < 1e-14 * k, "K({m})");
    }
    let ff = [
        (0.5, 0.3, 0.50614021196235529),
        (1.2, 0.8, 1.48849568894933),
        (-2.8, 0.6, -3.5535251509020493),
        (4.0, 0.95, 6.7958507204742785),
    ];
    for (phi, m, f) in ff {
        assert!(
            (ellipf(phi, m).unwrap() - f).abs() < 1e-13 * f.abs(),
            "F({phi}|{m})"
        );
    }
    assert!(ellipj(1.0, 1.0).is_err());
    assert!(ellipj(f64::NAN, 0.5).is_err());
    assert!(ellipk(-0.1).is_err());
}

/// Euler's equation Ṁ = M × I⁻¹M.
fn euler_rhs(i: [f64; 3], m: &[f64; 3]) -> Vector3<f64> {
    let m = Vector3::from(*m);
    m.cross(&Vector3::new(m.x / i[0], m.y / i[1], m.z / i[2]))
}

#[test]
fn exact_solution_solves_euler_equation() {
    // Both sides of the separatrix, all orderings of the moments, both signs of the dn component.
    let cases: [([f64; 3], [f64; 3]); 6] = [
        ([1.0, 2.0, 3.0], M0),
        ([1.0, 2.0, 3.0], [0.2, 0.5, -1.0]),
        ([3.0, 1.0, 2.0], [0.4, -0.9, 0.3]),
        ([2.0, 3.0, 1.0], [-0.7, 0.1, 0.6]),
        ([3.0, 2.0, 1.0], [0.1, -0.2, 1.1]),
        ([1.5, 1.5, 4.0], [0.3, 0.4, 1.0]),
    ];
    for (inertia, m0) in cases {
        let b = RigidBody::new(inertia).unwrap();
        let h0 = b.energy(&m0).unwrap();
        let c0 = b.invariants(&m0).unwrap()[0];
        let e0 = b.exact_momentum(&m0, 0.0).unwrap();
        assert!(
            (Vector3::from(e0) - Vector3::from(m0)).norm() < 1e-13,
            "{inertia:?}: M(0)"
        );
        for t in [0.37, 2.0, 7.5, 31.0] {
            let m = b.exact_momentum(&m0, t).unwrap();
            let dt = 1e-4;
            let mp = b.exact_momentum(&m0, t + dt).unwrap();
            let mm = b.exact_momentum(&m0, t - dt).unwrap();
            let fd = (Vector3::from(mp) - Vector3::from(mm)) / (2.0 * dt);
            let rhs = euler_rhs(inertia, &m);
            assert!(
                (fd - rhs).norm() < 1e-7,
                "{inertia:?} t={t}: dM/dt {fd} vs M×Ω {rhs}"
            );
            assert!((b.energy(&m).unwrap() - h0).abs() < 1e-13);
            assert!((b.invariants(&m).unwrap()[0] - c0).abs() < 1e-13);
        }
    }
}

/// Issue 16: near the separatrix, M₀ = (ε, 1, ε), I = (1, 2, 3), the exact solution was off by
/// 9e-9 (ε = 1e-4) to 6e-7 (ε = 1e-6) at t = 30 and refused ε ≤ 1e-7 and the separatrix itself;
/// now it is within round-off of a 40-digit reference (the problem's own amplification
/// e^{t/√12} ≈ 6e3 at t = 30 would allow 1e-10). Cases: ε = 1e-4 … 1e-8; a float state within
/// round-off of the separatrix of I = (1, 2, 3); exactly on the separatrix of I = (2, 3, 6)
/// (M₁² = M₃², the heteroclinic orbit: sn = tanh, cn = dn = sech), far from and near the
/// unstable axis.
#[test]
fn exact_solution_near_the_separatrix_matches_mpmath() {
    // (I, M0, [M(10), M(20), M(30)]) from a 40-digit Taylor integration of Euler's equations
    // (mpmath, order 40, step 0.05; two step sizes agree to 1e-40).
    type Case = ([f64; 3], [f64; 3], [[f64; 3]; 3]);
    let cases: [Case; 8] = [
        // eps=0.0001
        (
            [1.0, 2.0, 3.0],
            [0.0001, 1.0, 0.0001],
            [
                [
                    0.000383407476790428,
                    0.999999725997376,
                    -0.000648848117648813,
                ],
                [0.00679745892233486, 0.999907604835965, -0.0117726948232972],
                [0.120127898686097, 0.970709633118499, -0.208067575869504],
            ],
        ),
        // eps=1e-05
        (
            [1.0, 2.0, 3.0],
            [1e-05, 1.0, 1e-05],
            [
                [
                    3.83407517924273e-05,
                    0.999999997259974,
                    -6.48848190567373e-05,
                ],
                [
                    0.000679776936571828,
                    0.999999076006206,
                    -0.00117732325658034,
                ],
                [0.0121895211987925, 0.999702787178158, -0.0211128652997985],
            ],
        ),
        // eps=1e-06
        (
            [1.0, 2.0, 3.0],
            [1e-06, 1.0, 1e-06],
            [
                [3.83407518335611e-06, 0.9999999999726, -6.48848191296559e-06],
                [
                    6.79777247029519e-05,
                    0.999999990760058,
                    -0.000117732379434763,
                ],
                [0.00121913147764148, 0.999997027434462, -0.00211159718680645],
            ],
        ),
        // eps=1e-07
        (
            [1.0, 2.0, 3.0],
            [1e-07, 1.0, 1e-07],
            [
                [
                    3.83407518339724e-07,
                    0.999999999999726,
                    -6.48848191303851e-07,
                ],
                [
                    6.79777250134098e-06,
                    0.999999999907601,
                    -1.1773237997253e-05,
                ],
                [
                    0.000121913327148565,
                    0.999999970274301,
                    -0.000211160029383639,
                ],
            ],
        ),
        // eps=1e-08
        (
            [1.0, 2.0, 3.0],
            [1e-08, 1.0, 1e-08],
            [
                [
                    3.83407518339766e-08,
                    0.999999999999997,
                    -6.48848191303924e-08,
                ],
                [
                    6.79777250165144e-07,
                    0.999999999999076,
                    -1.17732379977908e-06,
                ],
                [
                    1.21913328942412e-05,
                    0.999999999702743,
                    -2.11160032490674e-05,
                ],
            ],
        ),
        // sep123
        (
            [1.0, 2.0, 3.0],
            [0.1, 1.0, 0.17320508075688773],
            [
                [0.00531737530241253, 1.01974845039332, 0.00920996418669026],
                [0.00028001464918734, 1.01980374894741, 0.000484999599252996],
                [1.47452604815566e-05, 1.01980390229216, 2.55395402669246e-05],
            ],
        ),
        // sep236
        (
            [2.0, 3.0, 6.0],
            [0.1, 1.0, 0.1],
            [
                [0.018665687276377, 1.00960545969057, 0.018665687276377],
                [0.00346807972121433, 1.00993858469022, 0.00346807972121433],
                [0.000644265684559941, 1.00995008284739, 0.000644265684559941],
            ],
        ),
        // sep236b
        (
            [2.0, 3.0, 6.0],
            [1e-06, 1.0, -1e-06],
            [
                [
                    5.29449005040729e-06,
                    0.999999999972968,
                    -5.29449005040729e-06,
                ],
                [
                    2.80316248836204e-05,
                    0.999999999215228,
                    -2.80316248836204e-05,
                ],
                [
                    0.000148413157468884,
                    0.999999977974534,
                    -0.000148413157468884,
                ],
            ],
        ),
    ];
    for (inertia, m0, want) in cases {
        let b = RigidBody::new(inertia).unwrap();
        // M(0) = M₀ componentwise to 1e-14 relative (the phase u₀ ≈ K carries an absolute
        // error of a few ulp(K), K ≈ ½ ln(16/(1 − m)) ≈ 20 here).
        let at0 = b.exact_momentum(&m0, 0.0).unwrap();
        for k in 0..3 {
            assert!(
                (at0[k] - m0[k]).abs() <= 1e-14 * m0[k].abs(),
                "{m0:?}: M(0) = {at0:?}"
            );
        }
        for (j, t) in [10.0, 20.0, 30.0].into_iter().enumerate() {
            let got = b.exact_momentum(&m0, t).unwrap();
            let err = (0..3)
                .map(|k| (got[k] - want[j][k]).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "{inertia:?} {m0:?} t = {t}: error {err:e}");
        }
    }
}

/// Within 1e-170 of the unstable middle axis (1 − m ~ 1e-340 is no double; k′ = √(1 − m) is):
/// the small components follow the linearization about the steady rotation, exact there to
/// O(1e-340): M₁ = M₁⁰ cosh σt − M₃⁰ sinh σt /(6σ), M₃ = M₃⁰ cosh σt − M₁⁰ sinh σt /(2σ),
/// σ = 1/√12 for I = (1, 2, 3), M₂ = 1.
#[test]
fn exact_solution_tiny_deviation_from_the_unstable_axis() {
    let b = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let sigma = 1.0 / 12f64.sqrt();
    for m0 in [
        [1e-170, 1.0, 1e-170],
        [1e-170, 1.0, 0.0],
        [0.0, 1.0, -3e-200],
    ] {
        for t in [0.0, 1.0, 30.0, 300.0] {
            let got = b.exact_momentum(&m0, t).unwrap();
            let (c, s) = ((sigma * t).cosh(), (sigma * t).sinh());
            let want = [
                m0[0] * c - m0[2] * s / (6.0 * sigma),
                1.0,
                m0[2] * c - m0[0] * s / (2.0 * sigma),
            ];
            let scale = want[0].abs().max(want[2].abs());
            for k in 0..3 {
                let tol = 1e-12 * if k == 1 { 1.0 } else { scale };
                assert!(
                    (got[k] - want[k]).abs() <= tol,
                    "{m0:?} t = {t}: {got:?} vs {want:?}"
                );
            }
        }
    }
    // Exactly on the axis: the unstable steady rotation is kept.
    assert_eq!(
        b.exact_momentum(&[0.0, 2.0, 0.0], 50.0).unwrap(),
        [0.0, 2.0, 0.0]
    );
}

/// The solution is homogeneous: M(t; cM₀) = c M(t/c; M₀) for any scale c (no square of a
/// component overflows or underflows).
#[test]
fn exact_solution_is_scale_free() {
    let b = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let m0 = [1e-6, 1.0, 1e-6];
    for t in [0.0, 7.0, 30.0] {
        let want = b.exact_momentum(&m0, t).unwrap();
        for c in [1e-300, 1e-200, 1e200, 1e300] {
            let got = b.exact_momentum(&m0.map(|x| c * x), t / c).unwrap();
            for k in 0..3 {
                assert!((got[k] / c - want[k]).abs() < 1e-15, "c = {c:e}, t = {t}");
            }
        }
    }
}

fn err_at(b: &RigidBody, method: &str, dt: f64, t_end: f64) -> f64 {
    let steps = (t_end / dt).round() as usize;
    let traj = integrate(b, method, &M0, dt, steps, steps).unwrap();
    let exact = Vector3::from(b.exact_momentum(&M0, t_end).unwrap());
    (Vector3::from_column_slice(traj.final_state.as_slice()) - exact).norm()
}

fn observed_order(b: &RigidBody, method: &str, dts: [f64; 3]) -> (f64, f64) {
    let e: Vec<f64> = dts.iter().map(|&dt| err_at(b, method, dt, 10.0)).collect();
    let p1 = (e[0] / e[1]).ln() / (dts[0] / dts[1]).ln();
    let p2 = (e[1] / e[2]).ln() / (dts[1] / dts[2]).ln();
    eprintln!("{method}: errors {e:?}, orders {p1:.3} {p2:.3}");
    (p1, p2)
}

#[test]
fn observed_orders_match_nominal() {
    let b = body();
    let cases = [
        ("splitting", [0.04, 0.02, 0.01]),
        ("splitting4", [0.1, 0.05, 0.025]),
        ("splitting6", [0.2, 0.1, 0.05]),
        ("splitting8", [1.0, 0.5, 0.25]),
        ("isospectral", [0.04, 0.02, 0.01]),
        ("lgvi", [0.04, 0.02, 0.01]),
        ("rk4", [0.1, 0.05, 0.025]),
    ];
    for (method, dts) in cases {
        let (p1, p2) = observed_order(&b, method, dts);
        let p = order(&b, method) as f64;
        assert!(
            (p1 - p).abs() < 0.2 && (p2 - p).abs() < 0.2,
            "{method}: orders {p1}, {p2}, nominal {p}"
        );
    }
}

/// The processed compositions (BCM06) reach their effective orders 6, 8, 10 only after the
/// processor: their kernels alone are of order 4. Errors at T = 4 against the exact solution,
/// between 1e-10 and 1e-13. Their leading error constants are small (what the coefficients were
/// optimised for), so the observed orders settle late: processed6 7.1 from 8 to 16 steps, 6.3
/// from 10 to 20, 5.9 from 12 to 24; processed8 8.95, 8.7, 8.3 from 6, 8, 10 steps doubled
/// (order 8 is checked to ±0.5; `scripts/processed_orders.py` shows the same in 40 digits).
#[test]
fn processed_compositions_reach_their_effective_orders() {
    let b = body();
    let exact = Vector3::from(b.exact_momentum(&M0, 4.0).unwrap());
    let error = |method: &str, n: usize| {
        let z = integrate(&b, method, &M0, 4.0 / n as f64, n, n)
            .unwrap()
            .final_state;
        (Vector3::from_column_slice(&z) - exact).norm()
    };
    for (method, [n1, n2], order, tol) in [
        ("processed6", [12, 24], 6.0, 0.3),
        ("processed8", [10, 20], 8.0, 0.5),
        ("processed10", [6, 12], 10.0, 0.3),
    ] {
        let (e1, e2) = (error(method, n1), error(method, n2));
        let observed = (e1 / e2).ln() / (n2 as f64 / n1 as f64).ln();
        eprintln!("{method}: errors {e1:.2e} {e2:.2e}, order {observed:.2}");
        assert!((observed - order).abs() < tol, "{method}: order {observed}");
    }
    // At the same number of Strang stages over T = 10 (processed6: 26 steps of 11 stages,
    // splitting6: 41 steps of 7) the processed method is far more accurate (its doc says so).
    let exact10 = Vector3::from(b.exact_momentum(&M0, 10.0).unwrap());
    let at10 = |method: &str, n: usize| {
        let z = integrate(&b, method, &M0, 10.0 / n as f64, n, n)
            .unwrap()
            .final_state;
        (Vector3::from_column_slice(&z) - exact10).norm()
    };
    let ratio = at10("splitting6", 41) / at10("processed6", 26);
    eprintln!("splitting6 / processed6 at 287 / 286 stages: {ratio:.1}");
    assert!(ratio > 10.0, "splitting6 / processed6 = {ratio}");
    // Without the processor (the kernel run as a plain composition) the order is 4.
    let kernel = Splitting(Processed::bcm6().kernel().clone());
    let plain = |n: usize| {
        let z = integrate_with(&b, &kernel, &M0, 4.0 / n as f64, n, n)
            .unwrap()
            .final_state;
        (Vector3::from_column_slice(&z) - exact).norm()
    };
    let observed = (plain(8) / plain(32)).ln() / 4f64.ln();
    assert!(
        (observed - 4.0).abs() < 0.1,
        "kernel alone: order {observed}"
    );
}

/// Kahan–Li's sixth-order composition: order 6, and at the same step an error more than five
/// times smaller than Yoshida's (6.7 measured; its doc says so).
#[test]
fn kahan_li6_has_order_6_and_a_smaller_error_than_yoshida6() {
    let b = body();
    let exact = Vector3::from(b.exact_momentum(&M0, 10.0).unwrap());
    let error = |c: Composition, n: usize| {
        let z = integrate_with(&b, &Splitting(c), &M0, 10.0 / n as f64, n, n)
            .unwrap()
            .final_state;
        (Vector3::from_column_slice(&z) - exact).norm()
    };
    let e = [25, 50, 100].map(|n| error(Composition::kahan_li6(), n));
    for k in 0..2 {
        let observed = (e[k] / e[k + 1]).log2();
        assert!((observed - 6.0).abs() < 0.2, "kahan_li6: order {observed}");
    }
    let ratio = error(Composition::yoshida6(), 50) / e[1];
    eprintln!("kahan_li6: errors {e:?}, yoshida6/kahan_li6 at 50 steps {ratio:.1}");
    assert!(ratio > 5.0, "yoshida6/kahan_li6 = {ratio}");
}

#[test]
fn processed_compositions_check_their_weights() {
    let k = Composition::suzuki4();
    assert!(Processed::new(k.clone(), vec![0.3, -0.2], 6).is_err()); // sum ≠ 0
    assert!(Processed::new(k.clone(), vec![0.3, f64::NAN], 6).is_err());
    assert!(Processed::new(k.clone(), vec![0.3, -0.3], 5).is_err()); // odd
    assert!(Processed::new(k.clone(), vec![0.3, -0.3], 2).is_err()); // below the kernel's
    let p = Processed::new(k, vec![0.3, -0.3], 6).unwrap();
    assert_eq!((p.order(), p.processor()), (6, &[0.3, -0.3][..]));
    // P⁻¹ is P's flows reversed with negated times, for every built-in pair.
    for p in [Processed::bcm6(), Processed::bcm8(), Processed::bcm10()] {
        assert!(p.processor().iter().sum::<f64>().abs() < 1e-15);
        assert_eq!(p.kernel().order(), 4);
        let (pre, post) = p.sequences(3);
        assert_eq!(pre.len(), post.len());
        for (a, b) in pre.iter().zip(post.iter().rev()) {
            assert_eq!((a.0, a.1), (b.0, -b.1));
        }
    }
}

/// Max relative energy error over the first and the last tenth of the saved samples.
fn energy_tenths<S: Problem>(s: &S, traj: &Trajectory) -> (f64, f64) {
    let h0 = s.energy(traj.state(0)).unwrap();
    let n = traj.len();
    let rel = |k: usize| ((s.energy(traj.state(k)).unwrap() - h0) / h0).abs();
    let first = (1..n / 10).map(rel).fold(0.0, f64::max);
    let last = (n - n / 10..n).map(rel).fold(0.0, f64::max);
    (first, last)
}

/// R M of sample k of a run of the body with attitude (state (M, R)).
fn spatial(traj: &Trajectory, k: usize) -> Vector3<f64> {
    let z = traj.state(k);
    let r = Matrix3::from_row_slice(&z[3..12]);
    r * Vector3::from_column_slice(&z[..3])
}

fn orth_defect(traj: &Trajectory, k: usize) -> f64 {
    let r = Matrix3::from_row_slice(&traj.state(k)[3..12]);
    (r.transpose() * r - Matrix3::identity()).norm()
}

#[test]
fn geometric_methods_preserve_structure_over_a_million_steps() {
    let b = body().with_attitude();
    let state0 = b.state_with_attitude(M0, identity());
    let c0 = b.invariants(&state0).unwrap()[0];
    let rm0 = Vector3::from(M0);
    for method in ["splitting", "isospectral", "lgvi"] {
        let traj = integrate(&b, method, &state0, 0.01, 1_000_000, 100).unwrap();
        let mut casimir = 0.0f64;
        let mut rm = 0.0f64;
        let mut orth = 0.0f64;
        for k in 0..traj.len() {
            casimir = casimir.max(((b.invariants(traj.state(k)).unwrap()[0] - c0) / c0).abs());
            rm = rm.max((spatial(&traj, k) - rm0).norm() / rm0.norm());
            orth = orth.max(orth_defect(&traj, k));
        }
        let (first, last) = energy_tenths(&b, &traj);
        eprintln!("{method}: |M|² drift {casimir:.2e}, RM drift {rm:.2e}, ‖RᵀR−I‖ {orth:.2e}, energy first {first:.2e} last {last:.2e}");
        assert!(casimir < 1e-12, "{method}: |M|² drift {casimir:e}");
        assert!(rm < 1e-12, "{method}: RM drift {rm:e}");
        assert!(orth < 1e-13, "{method}: ‖RᵀR − I‖ = {orth:e}");
        // Bounded: no growth, or at round-off level (the free-body LGVI is the Moser–Veselov
        // discretisation, which conserves the energy exactly).
        assert!(
            last <= 2.0 * first || last < 1e-13,
            "{method}: energy error grows: {first:e} → {last:e}"
        );
    }
}

#[test]
fn rk4_energy_drifts() {
    let b = body();
    let traj = integrate(&b, "rk4", &M0, 0.01, 1_000_000, 100).unwrap();
    let (first, last) = energy_tenths(&b, &traj);
    eprintln!("Rk4: energy first {first:.2e} last {last:.2e}");
    assert!(
        last > 2.0 * first,
        "RK4 energy error should drift: {first:e} → {last:e}"
    );
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

    /// For random inertias and momenta the exact solution keeps H and |M|², and the sixth-order
    /// splitting follows it (so the two routes agree on every branch of the elliptic formulas).
    #[test]
    fn exact_solution_and_splitting_agree(
        i1 in 0.5f64..3.0, i2 in 0.5f64..3.0, i3 in 0.5f64..3.0,
        m1 in -1.0f64..1.0, m2 in -1.0f64..1.0, m3 in -1.0f64..1.0,
    ) {
        let b = RigidBody::new([i1, i2, i3]).unwrap();
        let m0 = [m1, m2, m3];
        let (h0, c0) = (b.energy(&m0).unwrap(), b.invariants(&m0).unwrap()[0]);
        // No state is skipped or refused: near the separatrix (k → 1) the solution is computed
        // from the complementary modulus (exact_solution_near_the_separatrix_matches_mpmath).
        let exact = b.exact_momentum(&m0, 1.0).unwrap();
        proptest::prop_assert!((b.energy(&exact).unwrap() - h0).abs() < 1e-12 * h0.max(1e-3));
        proptest::prop_assert!((b.invariants(&exact).unwrap()[0] - c0).abs() < 1e-12 * c0.max(1e-3));
        let z = integrate(&b, "splitting6", &m0, 0.01, 100, 100).unwrap().final_state;
        let err = (0..3).map(|k| (z[k] - exact[k]).abs()).fold(0.0, f64::max);
        proptest::prop_assert!(err < 1e-8, "error {err:e} for I = {:?}, M0 = {m0:?}", [i1, i2, i3]);
    }
}

/// The generic composition on a symmetric base step that is not a flow (Störmer–Verlet for the
/// harmonic oscillator q̈ = −q, exact solution cos t): observed orders 2, 4, 4, 6; and the
/// flattened sequences give every flow a total time of exactly one step per step.
#[test]
fn compositions_lift_the_order_of_any_symmetric_step() {
    use lieflow::integrate::methods::composition::{run_sequence, Composition};
    let verlet = |h: f64, y: &mut [f64; 2]| {
        y[1] -= 0.5 * h * y[0];
        y[0] += h * y[1];
        y[1] -= 0.5 * h * y[0];
    };
    let err = |c: &Composition, n: usize| {
        let h = 10.0 / n as f64;
        let mut y = [1.0, 0.0];
        for _ in 0..n {
            c.compose(h, &mut y, |hh, y| verlet(hh, y));
        }
        (y[0] - 10f64.cos()).abs()
    };
    for (c, n) in [
        (Composition::strang(), 400),
        (Composition::triple_jump4(), 100),
        (Composition::suzuki4(), 100),
        (Composition::yoshida6(), 50),
    ] {
        let p = (err(&c, n) / err(&c, 2 * n)).log2();
        assert!(
            (p - c.order() as f64).abs() < 0.2,
            "{:?}: order {p}",
            c.gammas()
        );
        assert!((c.gammas().iter().sum::<f64>() - 1.0).abs() < 1e-14);
        for flows in 1..=4 {
            let mut total = [0.0; 4];
            run_sequence(&c.sequence(flows), 0.5, 7, &mut total, |i, tau, t| {
                t[i] += tau
            });
            for (i, t) in total.iter().take(flows).enumerate() {
                assert!(
                    (t - 3.5).abs() < 1e-12,
                    "flow {i} of {flows}: total time {t}"
                );
            }
        }
    }
}
