//! Pseudo-rigid body dynamics (001 §3, §7): Störmer–Verlet steps per second on T*GL⁺(n) with a
//! Saint Venant–Kirchhoff potential, n = 3 and n = 10, and the reduced-space splitting at n = 3.
//!
//! Run: `CARGO_TARGET_DIR=… cargo bench -p lieflow-benches --bench pseudo_rigid_dynamics`;
//! results in docs/bench-pr5.md. Each measured iteration runs `STEPS` steps in place, so the
//! time per step is the reported time divided by `STEPS`.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use lieflow::integrate::splitting::Composition;
use lieflow::integrate::verlet::{Verlet, VerletOrder, VerletScratch};
use lieflow::pseudo_rigid::potential::{Potential, SaintVenantKirchhoff};
use lieflow::pseudo_rigid::reduced::ReducedSplitting;
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

fn verlet(c: &mut Criterion) {
    let svk: Arc<dyn Potential> = Arc::new(SaintVenantKirchhoff::new(0.7, 1.3).unwrap());
    let mut g = c.benchmark_group("pseudo_rigid_verlet_svk");
    g.measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(STEPS as u64));
    for n in [3, 10] {
        let (x0, p0) = initial(n);
        let (mut x, mut p) = (x0.clone(), p0.clone());
        let mut scratch = VerletScratch::new(n);
        let method = Verlet::new(VerletOrder::Two).with_check_det(false);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                method
                    .run(&*svk, &mut x, &mut p, 0.0, 1e-4, STEPS, &mut scratch)
                    .unwrap();
                black_box(&x);
            })
        });
        let (mut x, mut p) = (x0.clone(), p0.clone());
        let checked = Verlet::new(VerletOrder::Two);
        g.bench_with_input(BenchmarkId::new("check_det", n), &n, |b, _| {
            b.iter(|| {
                checked
                    .run(&*svk, &mut x, &mut p, 0.0, 1e-4, STEPS, &mut scratch)
                    .unwrap();
                black_box(&x);
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("pseudo_rigid_reduced_svk");
    g.measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(STEPS as u64));
    for n in [3, 10] {
        let (x0, p0) = initial(n);
        let mut split = ReducedSplitting::new(&x0, &p0, &Composition::strang()).unwrap();
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                split.run(&*svk, 0.0, 1e-5, STEPS).unwrap();
                black_box(&split.state);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, verlet);
criterion_main!(benches);
