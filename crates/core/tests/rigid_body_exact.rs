//! The exact flow (M(t), R(t)) of the free rigid body (`systems::exact_flow`), the method
//! `exact`, and the heavy top's `exact_splitting*`: against an independent reference (classical
//! RK4 on the 12-dimensional (M, R) equations with Richardson extrapolation), by finite
//! differences of Ṙ = R hat(Ω), the group property, SO(3) and R M to round-off, large times
//! against 50-digit values, chunking, and the orders and work of the heavy-top splittings.
//! Measured values are printed (run with `--nocapture`).
#![allow(clippy::excessive_precision)] // mpmath reference values keep their digits

use lieflow::integrate::{integrate, integrate_with, Problem, Run, System};
use lieflow::lie::so3;
use lieflow::systems::{Exact, HeavyTop, RigidBody};
use nalgebra::{Matrix3, Vector3};

mod common;
use common::distance as dist;

fn rows(r: &Matrix3<f64>) -> [f64; 9] {
    std::array::from_fn(|k| r[(k / 3, k % 3)])
}

fn r0() -> Matrix3<f64> {
    so3::exp_unchecked(&Vector3::new(0.4, -0.2, 0.1))
}

/// (M, R) after time t of Ṁ = M × Ω, Ṙ = R hat(Ω), Ω = J⁻¹M (J the inertia matrix of the user
/// frame) by classical RK4 with n steps.
fn rk4(j: &Matrix3<f64>, m0: Vector3<f64>, r0: Matrix3<f64>, t: f64, n: usize) -> [f64; 12] {
    let jinv = j.try_inverse().unwrap();
    let f = |m: &Vector3<f64>, r: &Matrix3<f64>| {
        let w = jinv * m;
        (m.cross(&w), r * so3::hat(&w))
    };
    let h = t / n as f64;
    let (mut m, mut r) = (m0, r0);
    for _ in 0..n {
        let (k1m, k1r) = f(&m, &r);
        let (k2m, k2r) = f(&(m + k1m * (h / 2.0)), &(r + k1r * (h / 2.0)));
        let (k3m, k3r) = f(&(m + k2m * (h / 2.0)), &(r + k2r * (h / 2.0)));
        let (k4m, k4r) = f(&(m + k3m * h), &(r + k3r * h));
        m += (k1m + (k2m + k3m) * 2.0 + k4m) * (h / 6.0);
        r += (k1r + (k2r + k3r) * 2.0 + k4r) * (h / 6.0);
    }
    let mut out = [0.0; 12];
    out[..3].copy_from_slice(m.as_slice());
    out[3..].copy_from_slice(&rows(&r));
    out
}

/// RK4 at steps h and h/2 (h ≈ `h`), Richardson-extrapolated: error O(h⁵) ~ 1e-15.
fn reference(j: &Matrix3<f64>, m0: Vector3<f64>, r0: Matrix3<f64>, t: f64, h: f64) -> [f64; 12] {
    let n = ((t.abs() / h).ceil() as usize).max(1);
    let a = rk4(j, m0, r0, t, n);
    let b = rk4(j, m0, r0, t, 2 * n);
    std::array::from_fn(|k| b[k] + (b[k] - a[k]) / 15.0)
}

fn exact(body: &RigidBody, m0: &[f64; 3], r0: &Matrix3<f64>, t: f64) -> [f64; 12] {
    let (m, r) = body.exact_motion(m0, &rows(r0), t).unwrap();
    let mut out = [0.0; 12];
    out[..3].copy_from_slice(&m);
    out[3..].copy_from_slice(&r);
    out
}

/// A body: its name, the inertia matrix of the user frame, and the body.
fn body(name: &'static str, j: [f64; 9]) -> (&'static str, Matrix3<f64>, RigidBody) {
    let jm = Matrix3::from_row_slice(&j);
    let diagonal = (0..3).all(|a| (0..3).all(|b| a == b || j[3 * a + b] == 0.0));
    let b = if diagonal {
        RigidBody::new([j[0], j[4], j[8]]).unwrap()
    } else {
        RigidBody::from_matrix(&j).unwrap()
    };
    (name, jm, b)
}

fn diag(a: f64, b: f64, c: f64) -> [f64; 9] {
    [a, 0.0, 0.0, 0.0, b, 0.0, 0.0, 0.0, c]
}

/// Bodies and initial momenta covering the cases of the solution: both sides of the
/// separatrix, both polar axes (ν of the s axis below and above 1), near the separatrix, near
/// a steady rotation, symmetric bodies (both kinds), a nearly symmetric body, a sphere, steady
/// rotations, M = 0, and an inertia given as a matrix.
fn cases() -> Vec<(&'static str, Matrix3<f64>, RigidBody, [f64; 3])> {
    let b123 = body("I = (1, 2, 3)", diag(1.0, 2.0, 3.0));
    let thin = body("I = (1, 2.9, 3)", diag(1.0, 2.9, 3.0));
    let perm = body("I = (3, 1, 2)", diag(3.0, 1.0, 2.0));
    let near_sym = body("I = (1, 1 + 1e-7, 3)", diag(1.0, 1.0 + 1e-7, 3.0));
    // √((I₂ − I₁)/I₁) = 0.5, √((I₃ − I₂)/I₃) = 0.6: M = (±0.6, ±1, ±0.5) lies exactly on the
    // separatrix (the branch k′ = 0, checked in the unit tests of `exact_flow`).
    let sep = body("I = (1, 1.25, 1.953125)", diag(1.0, 1.25, 1.953125));
    let matrix = body(
        "matrix inertia",
        [2.0, 0.3, 0.0, 0.3, 1.0, 0.1, 0.0, 0.1, 3.0],
    );
    let with =
        |b: &(&'static str, Matrix3<f64>, RigidBody), m: [f64; 3]| (b.0, b.1, b.2.clone(), m);
    let mut out = vec![
        with(&b123, [1.0, 0.5, -0.3]),
        with(&b123, [0.2, 1.0, 0.9]),  // about the major axis
        with(&b123, [-0.9, 1.0, 0.2]), // about the minor axis
        with(&b123, [1e-7, 1.0, -1e-7]),
        // e₂ = M₁² − M₃²/3: near the separatrix (k′ ~ 1e-5, 1e-8) and on it (up to rounding).
        with(&b123, [0.3, -1.0, 0.3 * 3f64.sqrt() * (1.0 + 1e-9)]),
        with(&b123, [0.3, -1.0, 0.3 * 3f64.sqrt() * (1.0 - 1e-15)]),
        with(&b123, [0.3, -1.0, 0.3 * 3f64.sqrt()]),
        with(&b123, [1e-6, 2e-6, 1.0]), // near a steady rotation
        with(&sep, [0.6, 1.0, 0.5]),
        with(&sep, [-0.6, 1.0, -0.5]),
        with(&thin, [0.05, 0.3, 1.0]), // polar axis p (h/g = 57)
        with(&thin, [1.0, 0.3, 0.1]),
        with(&perm, [0.7, -0.4, 0.5]),
        with(&near_sym, [0.6, -0.2, 0.7]),
        with(&matrix, [1.0, 0.5, -0.3]),
        with(&matrix, [-0.2, 1.1, 0.4]),
    ];
    for (name, j, m) in [
        (
            "symmetric I = (1, 1, 3)",
            diag(1.0, 1.0, 3.0),
            [0.6, -0.2, 0.7],
        ),
        (
            "symmetric I = (1, 3, 3)",
            diag(1.0, 3.0, 3.0),
            [0.6, -0.2, 0.7],
        ),
        ("sphere", diag(2.0, 2.0, 2.0), [0.6, -0.2, 0.7]),
        ("steady about e1", diag(1.0, 2.0, 3.0), [1.3, 0.0, 0.0]),
        (
            "steady about e2 (unstable)",
            diag(1.0, 2.0, 3.0),
            [0.0, -1.3, 0.0],
        ),
        ("steady about e3", diag(1.0, 2.0, 3.0), [0.0, 0.0, 1.3]),
        ("M = 0", diag(1.0, 2.0, 3.0), [0.0, 0.0, 0.0]),
    ] {
        let b = body(name, j);
        out.push(with(&b, m));
    }
    out
}

#[test]
fn exact_motion_against_rk4_with_richardson() {
    let r0 = r0();
    let mut worst = 0.0f64;
    for (name, j, b, m0) in cases() {
        for t in [0.3, 2.0, 11.0, -3.7] {
            let want = reference(&j, Vector3::from(m0), r0, t, 2e-3);
            let got = exact(&b, &m0, &r0, t);
            let e = dist(&got, &want) / (1.0 + Vector3::from(m0).norm());
            worst = worst.max(e);
            assert!(e < 5e-13, "{name}, M0 = {m0:?}, t = {t}: error {e:e}");
        }
    }
    eprintln!("exact motion vs RK4 (Richardson): max relative error {worst:.2e}");
}

/// Ṙ = R hat(Ω) and Ṁ = M × Ω at the computed motion, by fourth-order central differences in
/// t (a check of the precession rate φ̇ independent of the reference integrator).
#[test]
fn the_motion_solves_the_equations() {
    let r0 = r0();
    let delta = 1e-3;
    let mut worst = 0.0f64;
    for (name, j, b, m0) in cases() {
        let jinv = j.try_inverse().unwrap();
        for t in [0.7, 130.0] {
            let at = |s: f64| exact(&b, &m0, &r0, t + s);
            let (a, bm, c, d) = (at(delta), at(-delta), at(2.0 * delta), at(-2.0 * delta));
            let fd: Vec<f64> = (0..12)
                .map(|k| (8.0 * (a[k] - bm[k]) - (c[k] - d[k])) / (12.0 * delta))
                .collect();
            let z = at(0.0);
            let m = Vector3::from_column_slice(&z[..3]);
            let r = Matrix3::from_row_slice(&z[3..]);
            let w = jinv * m;
            let mut want = m.cross(&w).as_slice().to_vec();
            want.extend(rows(&(r * so3::hat(&w))));
            let e = dist(&fd, &want) / (1.0 + m.norm() * w.norm());
            worst = worst.max(e);
            assert!(e < 1e-10, "{name}, M0 = {m0:?}, t = {t}: {e:e}");
        }
    }
    eprintln!("finite differences of (M, R) vs (M × Ω, R hat(Ω)): max relative defect {worst:.2e}");
}

/// R(t) ∈ SO(3) and R(t)M(t) = R₀M₀ to round-off at every t, and |M|, H conserved.
#[test]
fn rotation_and_spatial_momentum_to_round_off() {
    let r0 = r0();
    let (mut orth, mut spatial, mut casimir) = (0.0f64, 0.0f64, 0.0f64);
    for (name, j, b, m0) in cases() {
        let m0v = Vector3::from(m0);
        let s0 = r0 * m0v;
        let scale = m0v.norm().max(1.0);
        for t in [0.1, 1.0, 10.0, 1e2, 1e4, 1e6, -1e5] {
            let z = exact(&b, &m0, &r0, t);
            let m = Vector3::from_column_slice(&z[..3]);
            let r = Matrix3::from_row_slice(&z[3..]);
            let o = (r.transpose() * r - Matrix3::identity()).norm();
            let s = (r * m - s0).norm() / scale;
            let c = (m.norm() - m0v.norm()).abs() / scale
                + (m.dot(&(j.try_inverse().unwrap() * m))
                    - m0v.dot(&(j.try_inverse().unwrap() * m0v)))
                .abs()
                    / (scale * scale);
            (orth, spatial, casimir) = (orth.max(o), spatial.max(s), casimir.max(c));
            assert!(
                o < 2e-15 && s < 2e-15 && c < 2e-15 && (r.determinant() - 1.0).abs() < 2e-15,
                "{name}, M0 = {m0:?}, t = {t}: ‖RᵀR − I‖ {o:e}, |RM − R₀M₀| {s:e}, |M|, H {c:e}"
            );
        }
    }
    eprintln!(
        "max ‖RᵀR − I‖ {orth:.2e}, relative |RM − R₀M₀| {spatial:.2e}, relative |M|, H error \
         {casimir:.2e}"
    );
}

/// Φ_t ∘ Φ_s = Φ_{t+s}, to a few ε(1 + rate·(|s| + |t|)) plus the conditioning: near the
/// unstable axis a perturbation of the state at s grows until s + t, so the defect is compared
/// with the effect of changes of 1e-13·|M| in each component of M(s) (finite differences).
#[test]
fn group_property() {
    let r0 = r0();
    let mut worst = 0.0f64;
    for (name, _, b, m0) in cases() {
        for (s, t) in [(0.7, 1.9), (3.3, -1.2), (1e3, 2.5), (-40.0, 77.0)] {
            let z = exact(&b, &m0, &r0, s);
            let m: [f64; 3] = z[..3].try_into().unwrap();
            let r = Matrix3::from_row_slice(&z[3..]);
            let two = exact(&b, &m, &r, t);
            let one = exact(&b, &m0, &r0, s + t);
            let rate = 1.0 + Vector3::from(m0).norm();
            let h = 1e-13 * Vector3::from(m).norm().max(1e-300);
            let sensitivity = (0..3)
                .map(|k| {
                    let mut bumped = m;
                    bumped[k] += h;
                    dist(&exact(&b, &bumped, &r, t), &two) / 1e-13
                })
                .fold(0.0, f64::max);
            let tol = 1e-15 * rate * (1.0 + rate * (s.abs() + t.abs())) + 4e-16 * sensitivity;
            let e = dist(&two, &one);
            worst = worst.max(e / tol);
            assert!(
                e < tol,
                "{name}, M0 = {m0:?}, s = {s}, t = {t}: {e:e} (tolerance {tol:e})"
            );
        }
    }
    eprintln!("group property: max defect / tolerance {worst:.2e}");
}

// (I, M0, R0 (rows), t, (M, R rows)(t)) by the closed form in mpmath at 50 digits (polar axis s
// always, Π(n; φ | m) by mpmath.ellippi, exact reduction), itself checked against
// mpmath.odefun (Taylor series) at t = 2.5 to 5e-26. The inputs are doubles; a change of 2⁻⁵²
// in one component of M0 moves these motions by up to 2.9e-12, 2.5e-12, 1.0e-12 at t = 1e4 and
// 3.0e-10, 2.6e-10, 1.0e-10 at t = 1e6 (50-digit values too): the conditioning of the problem,
// the phase error ε·ω·t that any double computation makes.
type Large = ([f64; 3], [f64; 3], [[f64; 3]; 3], f64, [f64; 12]);
const LARGE_T: &[Large] = &[
    (
        [1.0, 2.0, 3.0],
        [1.0, 0.5, -0.3],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        10000.0,
        [
            0.9901280253104839,
            0.573224191725233,
            -0.17623994869414528,
            0.5258689061668703,
            0.8494679872011067,
            0.043197595388629134,
            0.528788027108759,
            -0.2867259414089318,
            -0.7988563430990506,
            -0.6662170186307804,
            0.4429360825713594,
            -0.599968758222503,
        ],
    ),
    (
        [1.0, 2.0, 3.0],
        [1.0, 0.5, -0.3],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        1000000.0,
        [
            1.0200398639976793,
            0.2967738253660248,
            0.45983037354356243,
            0.5583018225906422,
            0.6480834257729665,
            0.517964234412322,
            0.8063414284026241,
            -0.27696703154517877,
            -0.5225923500001389,
            -0.19522442401908324,
            0.7094202821145077,
            -0.6772077137710331,
        ],
    ),
    (
        [1.0, 2.0, 3.0],
        [-0.9, 1.0, 0.2],
        [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        10000.0,
        [
            -0.8941591950297273,
            1.020743521054707,
            0.09253106596505539,
            -0.8304153632500515,
            -0.511471522762401,
            -0.2209235294879106,
            0.26358522319358957,
            -0.7100077718739175,
            0.6530021393476599,
            -0.4908494215054863,
            0.4840308309206613,
            0.7244176972755315,
        ],
    ),
    (
        [1.0, 2.0, 3.0],
        [-0.9, 1.0, 0.2],
        [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        1000000.0,
        [
            -0.9052836796096233,
            0.9807373948870534,
            -0.2619458373454654,
            -0.8316549839648595,
            -0.4982859366150485,
            0.24507368895512446,
            0.4281140435867937,
            -0.29427919995527774,
            0.8544694951590996,
            -0.353650043588537,
            0.8155433022503131,
            0.4580619705066994,
        ],
    ),
    (
        [1.0, 2.9, 3.0],
        [0.05, 0.3, 1.0],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        10000.0,
        [
            0.032058076142731415,
            0.4187985503002086,
            0.9571207102661975,
            -0.6817864523669733,
            0.6948038172265142,
            -0.22894298184552717,
            -0.6798604516600883,
            -0.48623390290214297,
            0.54896844894501,
            0.2701055342591066,
            0.5299285303095258,
            0.8038773246749709,
        ],
    ),
    (
        [1.0, 2.9, 3.0],
        [0.05, 0.3, 1.0],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        1000000.0,
        [
            0.046337090934523074,
            0.33236529935613446,
            0.9898920051135037,
            0.9993301617709184,
            0.03565570306880966,
            -0.008240061503349333,
            -0.03589250555871213,
            0.9988857911429462,
            -0.03064154528492702,
            0.007138334513590791,
            0.030916776859810133,
            0.9994964717741492,
        ],
    ),
];

/// Large times: within twice the conditioning (the effect of one ulp of M0, above) of the
/// 50-digit values: no digits lost beyond the phase's own rounding. And t = 1e4 against 10⁴
/// composed steps of size 1: those keep |M| and H to round-off, but each step's rounding
/// (~ε) changes the frequency by ~εω, so their phase drifts by ~ε·t per step taken
/// (≲ ε·n·t/2 = 5e-9 in all); a single evaluation has only its own ε·ω·t.
#[test]
fn large_times() {
    for &(inertia, m0, r, t, want) in LARGE_T {
        let b = RigidBody::new(inertia).unwrap();
        let r0 = Matrix3::from_fn(|i, j| r[i][j]);
        let got = exact(&b, &m0, &r0, t);
        let e = dist(&got, &want);
        let bound = 6e-16 * t;
        eprintln!(
            "I = {inertia:?}, M0 = {m0:?}, t = {t:e}: error {e:.2e} (ε·t = {:.1e})",
            f64::EPSILON * t
        );
        assert!(e < bound, "t = {t}: error {e:e} > {bound:e}");
    }
    // 10⁴ steps of the exact flow over dt = 1, each from the last, against one evaluation.
    let b = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let r0 = r0();
    let (mut m, mut r) = ([1.0, 0.5, -0.3], r0);
    for _ in 0..10_000 {
        let z = exact(&b, &m, &r, 1.0);
        m = z[..3].try_into().unwrap();
        r = Matrix3::from_row_slice(&z[3..]);
    }
    let mut composed = m.to_vec();
    composed.extend(rows(&r));
    let e = dist(&composed, &exact(&b, &[1.0, 0.5, -0.3], &r0, 1e4));
    let (mv, m0v): (Vector3<f64>, Vector3<f64>) = (Vector3::from(m), Vector3::new(1.0, 0.5, -0.3));
    let energy = |v: Vector3<f64>| 0.5 * (v[0] * v[0] + v[1] * v[1] / 2.0 + v[2] * v[2] / 3.0);
    let dm = (mv.norm() / m0v.norm() - 1.0).abs();
    let dh = (energy(mv) / energy(m0v) - 1.0).abs();
    eprintln!(
        "10⁴ composed steps of dt = 1 vs one evaluation at t = 1e4: {e:.2e}; relative drift of \
         |M| {dm:.2e}, H {dh:.2e}"
    );
    assert!(e < 1e-9 && dm < 5e-14 && dh < 5e-14, "{e:e} {dm:e} {dh:e}");
}

/// The method `exact`: every saved state is the exact motion at its grid time (one step of
/// dt = 100 included), the run does not depend on how it is cut into chunks, and it claims
/// exactness.
#[test]
fn the_exact_method() {
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let lifted = body.with_attitude();
    let r0 = r0();
    let m0 = [1.0, 0.5, -0.3];
    let z0 = lifted.state_with_attitude(m0, rows(&r0));
    let (_, p) = lifted
        .methods()
        .into_iter()
        .find(|(n, _)| *n == "exact")
        .unwrap();
    assert!(p.exact && p.invariants && p.manifold && p.symplectic && p.symmetric);
    assert_eq!(
        p,
        <Exact as lieflow::integrate::Integrator<RigidBody>>::properties(&Exact)
    );
    let traj = integrate(&lifted, "exact", &z0, 0.05, 10_000, 500).unwrap();
    let mut worst = 0.0f64;
    for k in 0..traj.len() {
        let e = dist(traj.state(k), &exact(&body, &m0, &r0, traj.t[k]));
        worst = worst.max(e);
    }
    eprintln!("exact method, dt = 0.05, 10⁴ steps: max distance to the exact motion {worst:.2e}");
    assert!(worst < 1e-12, "{worst:e}");
    // Without the attitude: the momentum of the same motion.
    let m = integrate(&body, "exact", &m0, 0.05, 10_000, 10_000)
        .unwrap()
        .final_state;
    assert!(dist(&m, &traj.final_state[..3]) < 1e-13);
    // T = 100 in one step and in 100 steps, against the reference integrator.
    let j = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0));
    let want = reference(&j, Vector3::from(m0), r0, 100.0, 2e-3);
    for steps in [1, 100] {
        let z = integrate(&lifted, "exact", &z0, 100.0 / steps as f64, steps, steps).unwrap();
        let e = dist(&z.final_state, &want);
        eprintln!("exact method, T = 100 in {steps} step(s): error {e:.2e}");
        assert!(e < 1e-12, "{steps} steps: {e:e}");
    }
    // Chunking: a run cut into calls gives the states of one call, bit for bit (also across the
    // retractions of R every 256 steps, where the reference state is renewed).
    let one = integrate(&lifted, "exact", &z0, 0.05, 1000, 1000)
        .unwrap()
        .final_state;
    let mut run = Run::new(&lifted, "exact", &z0, 0.05, 1, 0.0).unwrap();
    let mut out = Vec::new();
    for n in [1, 37, 300, 2, 660] {
        run.advance(&lifted, n, &mut out).unwrap();
    }
    assert_eq!(run.state(&lifted), one);
    // A matrix inertia: the user frame.
    let mb = RigidBody::from_matrix(&[2.0, 0.3, 0.0, 0.3, 1.0, 0.1, 0.0, 0.1, 3.0]).unwrap();
    let z = integrate(&mb.with_attitude(), "exact", &z0, 0.1, 100, 100)
        .unwrap()
        .final_state;
    assert!(dist(&z, &exact(&mb, &m0, &r0, 10.0)) < 1e-13);
    // The method value itself.
    let z = integrate_with(&lifted, &Exact, &z0, 0.1, 100, 100)
        .unwrap()
        .final_state;
    assert!(dist(&z, &exact(&body, &m0, &r0, 10.0)) < 1e-13);
}

#[test]
fn typed_errors() {
    let b = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let id = rows(&Matrix3::identity());
    let err = |r: lieflow::Result<([f64; 3], [f64; 9])>| r.unwrap_err();
    assert!(matches!(
        err(b.exact_motion(&[f64::NAN, 0.0, 1.0], &id, 1.0)),
        lieflow::Error::NonFinite { .. }
    ));
    assert!(matches!(
        err(b.exact_motion(&[1.0, 0.0, 1.0], &id, f64::INFINITY)),
        lieflow::Error::NonFinite { .. }
    ));
    let mut twice = id;
    twice[0] = 2.0;
    assert!(matches!(
        err(b.exact_motion(&[1.0, 0.0, 1.0], &twice, 1.0)),
        lieflow::Error::NotInGroup { .. }
    ));
    assert!(matches!(
        err(b.exact_motion(&[1.0, 0.0], &id, 1.0)),
        lieflow::Error::Shape { .. }
    ));
    // A phase beyond the angle range of the rotations: refused, not a meaningless rotation.
    assert!(matches!(
        err(b.exact_motion(&[1.0, 0.5, -0.3], &id, 1e15)),
        lieflow::Error::InvalidArgument { .. }
    ));
    // Huge and tiny momenta: finite results.
    for s in [1e-300, 1e300] {
        let (m, r) = b
            .exact_motion(&[s, 0.5 * s, -0.3 * s], &id, 1e-300 / s.min(1.0) * 1e-3)
            .unwrap();
        assert!(m.iter().chain(&r).all(|x| x.is_finite()));
    }
}

// ---------------------------------------------------------------------------------------------
// The heavy top: exact_splitting, exact_splitting4, exact_splitting6

/// A fast-spinning asymmetric top (a gyroscope): I = (1, 2, 3), mgl = 1, χ = e₃,
/// M₀ = (40, 80, 400), |M| ≈ 410: the kinetic energy 2.8e4 against a potential of order 1;
/// T = 0.1 is about two turns.
fn fast_top() -> (HeavyTop, Vec<f64>) {
    let top = HeavyTop::new([1.0, 2.0, 3.0], 1.0, [0.0, 0.0, 1.0]).unwrap();
    let r = so3::exp_unchecked(&Vector3::new(0.3, 0.0, 0.0));
    let z = top.state_with_attitude([40.0, 80.0, 400.0], rows(&r));
    (top.with_attitude(), z)
}

const T_TOP: f64 = 0.1;

fn run_top(top: &HeavyTop, method: &str, z0: &[f64], t: f64, n: usize) -> Vec<f64> {
    integrate(top, method, z0, t / n as f64, n, n)
        .unwrap()
        .final_state
}

#[test]
fn exact_splittings_have_orders_2_4_6() {
    let (top, z0) = fast_top();
    let reference = run_top(&top, "exact_splitting6", &z0, T_TOP, 4000);
    for (name, nominal, n) in [
        ("exact_splitting", 2.0, 50),
        ("exact_splitting4", 4.0, 25),
        ("exact_splitting6", 6.0, 10),
    ] {
        let e = [n, 2 * n, 4 * n].map(|k| dist(&run_top(&top, name, &z0, T_TOP, k), &reference));
        let o = [(e[0] / e[1]).log2(), (e[1] / e[2]).log2()];
        eprintln!(
            "{name}: errors {:.2e} {:.2e} {:.2e}, observed orders {:.2} {:.2}",
            e[0], e[1], e[2], o[0], o[1]
        );
        assert!((o[1] - nominal).abs() < 0.25, "{name}: {o:?}");
    }
}

/// |Γ| = 1, M·Γ, R ∈ SO(3) and Γ = Rᵀe₃ kept to round-off over 10⁴ steps of the fast top, as
/// by the Lie–Poisson splittings (printed alongside).
#[test]
fn exact_splittings_keep_the_casimirs() {
    let (top, z0) = fast_top();
    let c0 = top.invariants(&z0).unwrap();
    let drift = |name: &str| {
        let traj = integrate(&top, name, &z0, 1e-3, 10_000, 100).unwrap();
        let (mut dc, mut dr) = (0.0f64, 0.0f64);
        for k in 0..traj.len() {
            let z = traj.state(k);
            let c = top.invariants(z).unwrap();
            dc = dc
                .max((c[0] - c0[0]).abs())
                .max((c[1] - c0[1]).abs() / c0[1].abs());
            let r = Matrix3::from_row_slice(&z[6..15]);
            dr = dr
                .max((r.transpose() * r - Matrix3::identity()).norm())
                .max(dist(&z[3..6], &z[12..15]));
        }
        (dc, dr)
    };
    for (exact, plain) in [
        ("exact_splitting", "splitting"),
        ("exact_splitting4", "splitting4"),
        ("exact_splitting6", "splitting6"),
    ] {
        let ((dc, dr), (pc, pr)) = (drift(exact), drift(plain));
        eprintln!(
            "10⁴ steps: relative drift of |Γ|², M·Γ {dc:.2e} ({plain}: {pc:.2e}); ‖RᵀR − I‖, \
             |Γ − Rᵀe₃| {dr:.2e} ({plain}: {pr:.2e}) [{exact}]"
        );
        assert!(dc < 5e-13 && dr < 5e-13, "{exact}: {dc:e} {dr:e}");
    }
}

/// Per-step cost of exact_splitting* over splitting* on a heavy top, rounded up from the
/// criterion bench `heavy_top` of benches/integrators.rs: 0.505/0.102, 2.62/0.496, 3.70/0.733 µs
/// (ratios 5.0, 5.3, 5.0; docs/benchmarks.md).
const COST_RATIO: usize = 6;

/// At equal work the exact splittings beat the Lie–Poisson splittings on the fast top. Work is
/// counted, not timed: splitting* gets [`COST_RATIO`] times as many steps.
#[test]
fn exact_splittings_beat_the_splittings_at_equal_work() {
    let (top, z0) = fast_top();
    let reference = run_top(&top, "exact_splitting6", &z0, T_TOP, 4000);
    for (exact, plain, n) in [
        ("exact_splitting", "splitting", 50),
        ("exact_splitting4", "splitting4", 25),
        ("exact_splitting6", "splitting6", 12),
    ] {
        for k in [n, 2 * n] {
            let e = dist(&run_top(&top, exact, &z0, T_TOP, k), &reference);
            let p = dist(
                &run_top(&top, plain, &z0, T_TOP, COST_RATIO * k),
                &reference,
            );
            eprintln!(
                "{exact} ({k} steps) {e:.2e} vs {plain} ({} steps) {p:.2e}: {:.1}× smaller",
                COST_RATIO * k,
                p / e
            );
            assert!(2.0 * e < p, "{exact}: {e:e} vs {plain}: {p:e}");
        }
    }
}
