//! Integrator benchmarks: ns per step for every method and system, batch throughput on 1 and 2
//! threads, and (with `--bench`) a work–precision table for the free rigid body to T = 100.
//!
//! `cargo bench -p lieflow-benches --bench integrators` (results in docs/bench-integ.md).

use criterion::{BatchSize, Criterion};
use lieflow::integrate::{integrate, integrate_batch, Properties, System};
use lieflow::systems::user::{EulerPoincare, Lagrangian};
use lieflow::systems::{
    Algebra, FrameTop, GeneralizedRigidBody, HeavyTop, RigidBody, Side, SpaceForm, SpaceTop,
    SphericalPendulum,
};
use std::hint::black_box;
use std::time::Instant;

const M0: [f64; 3] = [1.0, 0.5, -0.3];
const I3: [f64; 9] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
/// Steps per timed run of the per-step benchmarks (the figure reported is time / STEPS).
const STEPS: usize = 1000;

fn per_step<S: System>(
    c: &mut Criterion,
    group: &str,
    sys: &S,
    state: &[f64],
    methods: Vec<(&str, Properties)>,
) {
    let mut g = c.benchmark_group(group);
    g.throughput(criterion::Throughput::Elements(STEPS as u64));
    for (m, _) in methods {
        g.bench_function(m, |b| {
            b.iter_batched(
                || state.to_vec(),
                |s| integrate(sys, m, black_box(&s), 0.01, STEPS, STEPS).unwrap(),
                BatchSize::SmallInput,
            )
        });
    }
    g.finish();
}

fn steps(c: &mut Criterion) {
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    per_step(c, "rigid_body", &body, &M0, body.methods());
    let lifted = body.with_attitude();
    per_step(
        c,
        "rigid_body_attitude",
        &lifted,
        &lifted.state_with_attitude(M0, I3),
        lifted.methods(),
    );
    let top = HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap();
    per_step(
        c,
        "heavy_top",
        &top,
        &top.state(M0, [0.0, 0.0, 1.0]),
        top.methods(),
    );
    // The same body from its Lagrangian ℓ = ½⟨Ω, 𝕀Ω⟩ (issue 24: the native quadratic path of
    // the discrete Euler–Poincaré method against the built-in lgvi above).
    let ep = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Quadratic(vec![1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0]),
        Side::Left,
        None,
    )
    .unwrap()
    .with_attitude()
    .unwrap();
    per_step(
        c,
        "euler_poincare_attitude",
        &ep,
        &lifted.state_with_attitude(M0, I3),
        ep.methods(),
    );
    // The tangent top on S³ (issue 25): exact flow, axis splittings, rk4.
    let ft = FrameTop::new(
        SpaceForm::sphere(1.7).unwrap(),
        1.3,
        &[1.0, 0.1, 0.0, 0.1, 2.0, 0.0, 0.0, 0.0, 3.0],
    )
    .unwrap();
    let r = nalgebra::Matrix3::identity();
    let zf = ft
        .state(
            &[1.7, 0.0, 0.0, 0.0],
            &r,
            &[0.0, 0.5, 0.0, -0.4],
            &nalgebra::Vector3::new(0.8, -0.6, 1.1),
        )
        .unwrap();
    per_step(c, "frame_top_s3", &ft, &zf, ft.methods());
    let pend = SphericalPendulum::new(1.0, 1.0, 9.81).unwrap();
    let s = pend.state_from_spherical(1.0, 0.0, 0.3, 1.2).unwrap();
    per_step(c, "spherical_pendulum", &pend, &s, pend.methods());
    for n in [4, 5] {
        let j: Vec<f64> = (0..n).map(|i| 0.5 + 0.37 * i as f64).collect();
        let z: Vec<f64> = (0..n * (n - 1) / 2)
            .map(|k| ((k as f64 + 1.0) * 1.7).sin())
            .collect();
        let b = GeneralizedRigidBody::new(&j).unwrap();
        per_step(c, &format!("so{n}_body"), &b, &z, b.methods());
    }
}

/// The exact free flow with the attitude: a run to T = 100 in one step (dt = 100) and in 100
/// steps (dt = 1, one evaluation: the method evaluates at the end of each chunk), the cost of
/// one evaluated step (every step saved, dt = 0.01), and `RigidBody::exact_motion` itself.
fn exact(c: &mut Criterion) {
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let lifted = body.with_attitude();
    let z = lifted.state_with_attitude(M0, I3);
    let mut g = c.benchmark_group("exact");
    for (name, dt, n) in [("T100_dt100", 100.0, 1), ("T100_dt1", 1.0, 100)] {
        g.bench_function(name, |b| {
            b.iter(|| integrate(&lifted, "exact", black_box(&z), dt, n, n).unwrap())
        });
    }
    g.throughput(criterion::Throughput::Elements(STEPS as u64));
    g.bench_function("every_step_saved", |b| {
        b.iter(|| integrate(&lifted, "exact", black_box(&z), 0.01, STEPS, 1).unwrap())
    });
    g.throughput(criterion::Throughput::Elements(1));
    g.bench_function("exact_motion", |b| {
        b.iter(|| {
            body.exact_motion(black_box(&M0), &I3, black_box(100.0))
                .unwrap()
        })
    });
    g.finish();
}

/// One criterion group: `integrate_batch` of `states` (10⁴ members × 1000 steps) with each of
/// `methods` on 1 and 2 threads.
fn batch_group<S: System>(
    c: &mut Criterion,
    name: &str,
    system: &S,
    states: &[Vec<f64>],
    methods: &[&str],
) {
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    g.throughput(criterion::Throughput::Elements(states.len() as u64 * 1000));
    for &method in methods {
        for threads in [1, 2] {
            g.bench_function(format!("{method}_{threads}_threads"), |b| {
                b.iter(|| {
                    integrate_batch(system, method, states, 0.01, 1000, 1000, Some(threads))
                        .unwrap()
                })
            });
        }
    }
    g.finish();
}

/// Batches in SIMD lanes (issue 14): the free body (splitting4 runs five Strang stages per
/// step), the body with its attitude (R's columns rotated, its rows turned) and the heavy top
/// (the kick, two axis rotations and the Rodrigues turn of Γ).
fn batch(c: &mut Criterion) {
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let states: Vec<Vec<f64>> = (0..10_000)
        .map(|k| {
            let a = k as f64 * 1e-4;
            vec![1.0 - a, 0.5 + a, -0.3 + 0.5 * a]
        })
        .collect();
    let methods = ["splitting", "splitting4"];
    batch_group(c, "batch_rigid_body_1e4x1e3", &body, &states, &methods);
    let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let with_r: Vec<Vec<f64>> = states
        .iter()
        .map(|m| m.iter().chain(&identity).copied().collect())
        .collect();
    let lifted = body.with_attitude();
    batch_group(
        c,
        "batch_rigid_body_attitude_1e4x1e3",
        &lifted,
        &with_r,
        &["splitting"],
    );
    let top = HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap();
    let tops: Vec<Vec<f64>> = states
        .iter()
        .map(|m| top.state([m[0], m[1], m[2]], [0.0, 0.6, 0.8]))
        .collect();
    batch_group(c, "batch_heavy_top_1e4x1e3", &top, &tops, &["splitting"]);
}

/// Error at T = 100 against the exact solution and the best of 7 wall times, for each method
/// over a range of steps; printed as a markdown table.
fn work_precision() {
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let exact = body.exact_momentum(&M0, 100.0).unwrap();
    let s0 = M0;
    println!("| method | dt | steps | error at T=100 | time (µs) |");
    println!("|---|---|---|---|---|");
    let grid: [(&str, &[usize]); 8] = [
        ("splitting", &[10_000, 20_000, 50_000, 100_000]),
        ("splitting4", &[1000, 1250, 2000, 4000]),
        ("splitting6", &[300, 400, 500, 1000]),
        ("lgvi", &[10_000, 100_000]),
        ("dmv", &[10_000, 100_000]),
        ("dmv10", &[200, 250, 400, 500]),
        ("isospectral", &[10_000, 100_000]),
        ("rk4", &[2000, 4000, 5000, 10_000]),
    ];
    for (m, ns) in grid {
        for &n in ns {
            let dt = 100.0 / n as f64;
            let mut best = f64::INFINITY;
            let mut err = 0.0;
            for _ in 0..7 {
                let t0 = Instant::now();
                let traj = integrate(&body, m, black_box(&s0), dt, n, n).unwrap();
                best = best.min(t0.elapsed().as_secs_f64());
                let z = &traj.final_state;
                err = (0..3)
                    .map(|i| (z[i] - exact[i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
            }
            println!("| {m} | {dt} | {n} | {err:.2e} | {:.1} |", best * 1e6);
        }
    }
}

fn main() {
    if std::env::args().any(|a| a == "--bench") && std::env::var_os("SKIP_WORK_PRECISION").is_none()
    {
        work_precision();
    }
    let mut c = Criterion::default().configure_from_args();
    steps(&mut c);
    exact(&mut c);
    batch(&mut c);
    c.final_summary();
}
