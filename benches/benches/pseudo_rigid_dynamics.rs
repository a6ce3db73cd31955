//! Pseudo-rigid body dynamics (001 §3, §7): Störmer–Verlet steps per second on T*GL⁺(n) with a
//! Saint Venant–Kirchhoff potential, n = 3 and n = 10, the reduced-space splitting, and the body
//! reduced by its right SO(n) action (`RightReduced`, 001 §3.2: its Verlet, plain and carrying X).
//!
//! Run: `CARGO_TARGET_DIR=… cargo bench -p lieflow-benches --bench pseudo_rigid_dynamics`;
//! results in docs/bench-pr5.md. Each measured iteration advances one driver run
//! (`lieflow::integrate::Run`, built once) by `STEPS` steps, so the time per step is the
//! reported time divided by `STEPS`.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use lieflow::integrate::{Run, System};
use lieflow::pseudo_rigid::potential::{Potential, SaintVenantKirchhoff};
use lieflow::pseudo_rigid::{PseudoRigidBody, RightReduced};
use lieflow::Mat;

const STEPS: usize = 1000;

/// A spinning, deforming initial state with distinct singular values.
fn initial(n: usize) -> (Mat, Mat) {
    let x = Mat::from_fn(n, n, |i, j| {
        if i == j {
            1.0 + 0.05 * i as f64 / n as f64
        } else {
            0.005 * ((i + 2 * j) as f64).sin()
        }
    });
    let p = Mat::from_fn(n, n, |i, j| 0.02 * ((3 * i + j) as f64).cos());
    (x, p)
}

/// A run of `method` on the body, started once at z₀ and advanced in place by every measured
/// iteration (one state saved per `STEPS` steps, into a reserved buffer).
fn bench_run<S: System>(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    id: BenchmarkId,
    body: &S,
    z0: &[f64],
    method: &str,
    dt: f64,
) {
    let mut run = Run::new(body, method, z0, dt, STEPS, 0.0).unwrap();
    let mut out = Vec::with_capacity(z0.len());
    g.bench_function(id, |b| {
        b.iter(|| {
            out.clear();
            run.advance(body, STEPS as u64, &mut out).unwrap();
            black_box(&out);
        })
    });
}

fn verlet(c: &mut Criterion) {
    let svk: Arc<dyn Potential> = Arc::new(SaintVenantKirchhoff::new(0.7, 1.3).unwrap());
    let mut g = c.benchmark_group("pseudo_rigid_verlet_svk");
    g.measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(STEPS as u64));
    for n in [3, 10] {
        let (x0, p0) = initial(n);
        let free = PseudoRigidBody::new(n, svk.clone(), false).unwrap();
        let z0 = free.state(&x0, &p0).unwrap();
        bench_run(
            &mut g,
            BenchmarkId::from_parameter(n),
            &free,
            &z0,
            "verlet",
            1e-4,
        );
        let checked = PseudoRigidBody::new(n, svk.clone(), true).unwrap();
        let id = BenchmarkId::new("check_det", n);
        bench_run(&mut g, id, &checked, &z0, "verlet", 1e-4);
    }
    g.finish();
    let mut g = c.benchmark_group("pseudo_rigid_reduced_svk");
    g.measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(STEPS as u64));
    for n in [3, 10] {
        let (x0, p0) = initial(n);
        let body = PseudoRigidBody::new(n, svk.clone(), false).unwrap();
        let z0 = body.state(&x0, &p0).unwrap();
        bench_run(
            &mut g,
            BenchmarkId::from_parameter(n),
            &body,
            &z0,
            "reduced",
            1e-5,
        );
    }
    g.finish();
    let mut g = c.benchmark_group("pseudo_rigid_right_reduced_svk");
    g.measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(STEPS as u64));
    for n in [3, 10] {
        let (x0, p0) = initial(n);
        let body = RightReduced::new(n, svk.clone()).unwrap();
        let z0 = body.reduce(&x0, &p0).unwrap();
        bench_run(
            &mut g,
            BenchmarkId::from_parameter(n),
            &body,
            &z0,
            "verlet",
            1e-4,
        );
        let lifted = body.reconstructing();
        let z0 = lifted.reduce(&x0, &p0).unwrap();
        let id = BenchmarkId::new("reconstructing", n);
        bench_run(&mut g, id, &lifted, &z0, "verlet", 1e-4);
    }
    g.finish();
}

criterion_group!(benches, verlet);
criterion_main!(benches);
