//! Brouwer's law for the invariants (issue 29, part 6): over 10⁶ steps the round-off of the
//! invariants random-walks (error ∝ √N, slope ½ of log error against log N) instead of drifting
//! (∝ N, slope 1), in the resonant cases where every step repeats the same rounding: the Lagrange
//! top (the rotation about its axis is the same at every step), its steady precession, the
//! symmetric free body with its attitude, the conical pendulum, and the particle on a sphere
//! under RATTLE.
//!
//! The error at N steps is the largest |I(t) − I(0)| up to N (‖RᵀR − I‖_F itself), RMS over
//! 32 nearby initial states (8 or 16 for the costlier methods); the slope is the least-squares
//! slope of log₁₀ error against log₁₀ N over N = 10⁴ … 10⁶ by half decades and must be ≤ 0.6.
//! Before the rotations were applied by increments (`simd::sin_cosm1_lanes`, `so3::Rodrigues`)
//! and RATTLE corrected q by its total multiplier, every case but RKMK4 failed (slopes 0.9–1.3;
//! the Lagrange top's |Γ|² and M·Γ 1.3 with `splitting` and `splitting4`). The steppers run bare
//! (no retraction of R every 256 steps). `crates/core/examples/roundoff_slopes.rs` prints the
//! table of every method and system up to 10⁷ steps (docs/benchmarks.md).

use lieflow::integrate::{Clock, System};
use lieflow::lie::so3;
use lieflow::systems::{HeavyTop, RigidBody, SphereParticle, SphericalPendulum};
use nalgebra::{Matrix3, Vector3};

/// The step counts at which the errors are taken: 10⁴ … 10⁶ by half decades (from the period of
/// the motion on, ~6·10³ steps for the Lagrange top: below it the rounding errors are correlated
/// with the motion and even unbiased round-off grows faster than √N).
const CHECKPOINTS: [u64; 5] = [10_000, 31_623, 100_000, 316_228, 1_000_000];
/// Initial states per method (the RMS averages the walks: with 16 the slope of a pure random walk
/// still scatters by about ±0.1 over two decades, so the cheap splittings take 32, the costlier
/// methods 16 or 8).
const SEEDS: usize = 32;

/// A bare-stepper run of `method` from each state: the invariants' errors (and ‖RᵀR − I‖_F for
/// the attitude at `attitude`) at the [`CHECKPOINTS`], RMS over the states.
fn errors(
    system: &dyn System,
    method: &str,
    dt: f64,
    states: &[Vec<f64>],
    attitude: Option<usize>,
) -> Vec<[f64; 5]> {
    let measure = |z: &[f64]| {
        let mut q = system.invariants(z).unwrap();
        if let Some(at) = attitude {
            let r = Matrix3::from_row_slice(&z[at..at + 9]);
            q.push((r.transpose() * r - Matrix3::identity()).norm());
        }
        q
    };
    let mut sum: Vec<[f64; 5]> = Vec::new();
    for z0 in states {
        let (mut stepper, _) = system.stepper(method, dt).unwrap();
        let mut z = z0.clone();
        system.to_internal(&mut z);
        stepper.set(&z).unwrap();
        let q0 = measure(z0);
        let n = q0.len();
        sum.resize(n, [0.0; 5]);
        let mut worst = vec![0.0f64; n];
        let mut done = 0u64;
        for (d, &target) in CHECKPOINTS.iter().enumerate() {
            let stride = (target / 2000).max(1);
            while done < target {
                let k = stride.min(target - done);
                stepper
                    .advance(k as usize, Clock { t0: 0.0, dt, done })
                    .unwrap();
                done += k;
                stepper.get(&mut z);
                system.to_user(&mut z);
                let q = measure(&z);
                for i in 0..n {
                    let err = if attitude.is_some() && i == n - 1 {
                        q[i]
                    } else {
                        (q[i] - q0[i]).abs()
                    };
                    worst[i] = worst[i].max(err);
                }
            }
            for i in 0..n {
                sum[i][d] += worst[i] * worst[i];
            }
        }
    }
    sum.iter()
        .map(|s| s.map(|x| (x / states.len() as f64).sqrt()))
        .collect()
}

/// Least-squares slope of log₁₀ error on log₁₀ N (an error of exactly 0 counts as 1e-17).
fn slope(errs: &[f64; 5]) -> f64 {
    let xs = CHECKPOINTS.map(|n| (n as f64).log10());
    let ys = errs.map(|e| e.max(1e-17).log10());
    let (mx, my) = (xs.iter().sum::<f64>() / 5.0, ys.iter().sum::<f64>() / 5.0);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    sxy / sxx
}

fn check(name: &str, system: &dyn System, methods: &[&str], dt: f64, states: &[Vec<f64>]) {
    check_with(name, system, methods, dt, states, None)
}

/// Asserts slope ≤ 0.6 for every method and quantity (all of them reported).
fn check_with(
    name: &str,
    system: &dyn System,
    methods: &[&str],
    dt: f64,
    states: &[Vec<f64>],
    attitude: Option<usize>,
) {
    let mut biased = Vec::new();
    for m in methods {
        for (i, e) in errors(system, m, dt, states, attitude).iter().enumerate() {
            let s = slope(e);
            let e = e.map(|x| format!("{x:.1e}")).join(", ");
            println!("{name} {m} quantity {i}: errors [{e}], slope {s:.2}");
            if s > 0.6 {
                biased.push(format!("{m}, quantity {i}: slope {s:.2} (errors [{e}])"));
            }
        }
    }
    assert!(
        biased.is_empty(),
        "{name}: round-off growing faster than a random walk (slope > 0.6 over 10⁴…10⁶ \
         steps; a biased rounding):\n{}",
        biased.join("\n")
    );
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    Vector3::from(v).normalize().into()
}

/// Seed k of a family of nearby vectors (seed 0 is v).
fn nudge(v: [f64; 3], k: usize) -> [f64; 3] {
    let k = k as f64;
    [
        v[0] + 0.01 * (1.3 * k).sin(),
        v[1] + 0.01 * (2.1 * k).sin(),
        v[2] + 0.01 * (0.7 * k).sin(),
    ]
}

fn lagrange_top() -> HeavyTop {
    HeavyTop::new([1.0, 1.0, 0.5], 1.0, [0.0, 0.0, 1.0]).unwrap()
}

/// The Lagrange top of the issue: M₀ = (0.1, 0.2, 0.9), Γ₀ ∝ (0.2, 0.1, 0.97), dt = 1e-3. Before:
/// |Γ|² off by 2.9e-11 after 10⁶ `splitting` steps, exactly linear (c² + s² − 1 = 0.15 ulp of
/// the same axis rotation at every step).
#[test]
fn the_lagrange_top_random_walks() {
    let top = lagrange_top();
    let states: Vec<_> = (0..SEEDS)
        .map(|k| top.state(nudge([0.1, 0.2, 0.9], k), unit(nudge([0.2, 0.1, 0.97], k))))
        .collect();
    check("Lagrange top", &top, &["splitting"], 1e-3, &states);
    check(
        "Lagrange top",
        &top,
        &["splitting4"],
        1e-3,
        &states[..SEEDS / 4],
    );
}

/// Its steady precession (a relative equilibrium: M and Γ turn rigidly about e₃), where the
/// Rodrigues turn of Γ added a second-order increment that is the same at every step.
#[test]
fn the_steady_precession_random_walks() {
    let top = lagrange_top();
    let states: Vec<_> = (0..SEEDS)
        .map(|k| {
            let (beta, m3) = (0.3 + 0.01 * k as f64, 3.0);
            let (sb, cb) = f64::sin_cos(beta);
            let disc = (sb * m3).powi(2) - 4.0 * cb * sb * sb;
            let a = (sb * m3 + disc.sqrt()) / (2.0 * cb);
            top.state([a, 0.0, m3], [sb, 0.0, cb])
        })
        .collect();
    check(
        "steady precession",
        &top,
        &["splitting", "exact_splitting"],
        1e-3,
        &states[..SEEDS / 2],
    );
}

/// The symmetric free body I = (1, 1, 2) with its attitude (|M|², R M and RᵀR), and RKMK4's
/// |M|² (its increment of M₃ is the same at every step: compensated summation).
#[test]
fn the_symmetric_body_random_walks() {
    let body = RigidBody::new([1.0, 1.0, 2.0]).unwrap();
    let lifted = body.with_attitude();
    let states: Vec<_> = (0..SEEDS)
        .map(|k| {
            let r = so3::exp_unchecked(&Vector3::new(0.4, -0.2, 0.1 + 0.01 * k as f64));
            let rows: Vec<f64> = (0..9).map(|i| r[(i / 3, i % 3)]).collect();
            [&nudge([0.6, 0.3, 0.8], k)[..], &rows].concat()
        })
        .collect();
    check_with(
        "symmetric body",
        &lifted,
        &["splitting"],
        1e-2,
        &states,
        Some(3),
    );
    check_with(
        "symmetric body",
        &lifted,
        &["lgvi"],
        1e-2,
        &states[..SEEDS / 2],
        Some(3),
    );
    check_with(
        "symmetric body",
        &lifted,
        &["rkmk4"],
        1e-2,
        &states[..SEEDS / 4],
        Some(3),
    );
}

/// The conical pendulum (q turned about L by the same angle at every step).
#[test]
fn the_conical_pendulum_random_walks() {
    let pend = SphericalPendulum::new(1.0, 1.0, 9.81).unwrap();
    let states: Vec<_> = (0..SEEDS)
        .map(|k| {
            let th = 0.8 + 0.01 * k as f64;
            pend.state_from_spherical(th, 0.1, 0.0, (9.81 / th.cos()).sqrt())
                .unwrap()
        })
        .collect();
    check(
        "conical pendulum",
        &pend,
        &["splitting4"],
        1e-3,
        &states[..SEEDS / 4],
    );
}

/// The particle on a sphere with RATTLE: its vertical angular momentum (q × p)₃, which drifted
/// when the multiplier's last, ulp-sized corrections reached p but were rounded away from q.
#[test]
fn rattle_keeps_the_vertical_momentum_of_the_sphere_particle() {
    let pend = SphericalPendulum::new(1.0, 1.0, 9.81).unwrap();
    let particle = SphereParticle::new(1.0, 1.0, 9.81).unwrap();
    let states: Vec<_> = (0..SEEDS / 4)
        .map(|k| {
            let s = pend
                .state_from_spherical(0.8 + 0.01 * k as f64, 0.1, 0.3, 1.2)
                .unwrap();
            particle.from_spherical(&s).unwrap()
        })
        .collect();
    check(
        "particle on a sphere",
        &particle,
        &["rattle"],
        1e-3,
        &states,
    );
}

/// The free body's `exact` composed with itself (each step a one-step run from the previous
/// final state, as continuations of runs and `Trajectory.concatenate` compose it: the stepper
/// `set` at every step): |M|² and H random-walk, without and with the attitude, within
/// 3 ε√N relative (RMS over 8 nearby states, 10⁵ steps). Before M(t) was evaluated relative to
/// its base point (M₀ + amp·((cn, sn, dn)(u) − (cn, sn, dn)(u₀))), each evaluation of the elliptic
/// formula from a fresh M₀ returned |M|² about ½ ulp low, so both fell linearly: I = (1, 2, 3),
/// M₀ ≈ (0.3, −0.8, 1.1), dt = 0.1, mean relative drift of |M|² −7.6e-13 after 10⁴ steps and
/// −7.6e-12 after 10⁵ (34 and 108 ε√N), of H −6.4e-13 and −6.5e-12.
#[test]
fn the_composed_exact_flow_random_walks() {
    const N: [u64; 3] = [1_000, 10_000, 100_000];
    const RUNS: usize = 8;
    let plain = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let lifted = plain.with_attitude();
    let attitude: Vec<f64> = (0..9).map(|i| if i % 4 == 0 { 1.0 } else { 0.0 }).collect();
    // (name, system, inertia, M₀, dt, steps (a prefix of N))
    type Case<'a> = (&'a str, &'a RigidBody, [f64; 3], [f64; 3], f64, usize);
    let cases: [Case; 3] = [
        ("M", &plain, [1.0, 2.0, 3.0], [0.3, -0.8, 1.1], 0.1, 3),
        // Close to the separatrix (k′ ≈ 0.02) with longer steps.
        (
            "M near the separatrix",
            &plain,
            [1.0, 2.0, 3.0],
            [0.02, 1.0, 0.03],
            0.5,
            3,
        ),
        ("(M, R)", &lifted, [1.0, 2.0, 3.0], [0.3, -0.8, 1.1], 0.1, 2),
    ];
    let mut fails = Vec::new();
    for (name, body, inertia, m0, dt, checkpoints) in cases {
        let invariants = |z: &[f64]| {
            let c: f64 = z[..3].iter().map(|x| x * x).sum();
            let h: f64 = 0.5 * (0..3).map(|i| z[i] * z[i] / inertia[i]).sum::<f64>();
            [c, h]
        };
        // [checkpoint][quantity]: the sums of the signed relative errors and of their squares.
        let mut sum = [[0.0f64; 2]; 3];
        let mut sq = [[0.0f64; 2]; 3];
        for k in 0..RUNS {
            let mut z = nudge(m0, k).to_vec();
            if std::ptr::eq(body, &lifted) {
                z.extend_from_slice(&attitude);
            }
            let q0 = invariants(&z);
            let (mut stepper, _) = body.stepper("exact", dt).unwrap();
            let mut done = 0u64;
            for (d, &n) in N[..checkpoints].iter().enumerate() {
                while done < n {
                    stepper.set(&z).unwrap();
                    stepper.advance(1, Clock { t0: 0.0, dt, done }).unwrap();
                    stepper.get(&mut z);
                    done += 1;
                }
                let q = invariants(&z);
                for i in 0..2 {
                    let e = q[i] / q0[i] - 1.0;
                    sum[d][i] += e;
                    sq[d][i] += e * e;
                }
            }
        }
        for (d, &n) in N[..checkpoints].iter().enumerate() {
            let walk = f64::EPSILON * (n as f64).sqrt();
            for (i, q) in ["|M|²", "H"].iter().enumerate() {
                let mean = sum[d][i] / RUNS as f64;
                let rms = (sq[d][i] / RUNS as f64).sqrt();
                println!(
                    "{name}, N = {n:6}: {q} relative error mean {mean:+.2e}, rms {rms:.2e} \
                     ({:.2} ε√N)",
                    rms / walk
                );
                if rms > 3.0 * walk {
                    fails.push(format!(
                        "{name}, N = {n}: {q} rms {rms:.2e} > 3 ε√N = {:.2e}",
                        3.0 * walk
                    ));
                }
            }
        }
    }
    assert!(fails.is_empty(), "linear drift:\n{}", fails.join("\n"));
}
