//! SO(3)/so(3) fast path and SE(3): time per call of the hot kernels (exp, log, Ad, Jacobians,
//! Cayley, SE(3) exp/log/Ad), with nalgebra's own `Rotation3` exp/log as a peer baseline.
//! Results and the command that produced them: docs/bench-so3.md.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use lieflow::lie::se3::{self, SE3};
use lieflow::lie::so3::{self, SO3};
use lieflow::lie::MatrixLieGroup;
use nalgebra::{Rotation3, Vector3, Vector6};

fn so3_kernels(c: &mut Criterion) {
    let w = Vector3::new(0.3, -1.1, 0.7);
    let tiny = Vector3::new(1e-5, -2e-5, 3e-6);
    let near_pi = Vector3::new(0.0, 0.6, 0.8) * (std::f64::consts::PI - 1e-6);
    let r = so3::exp_unchecked(&w);
    let r_pi = so3::exp_unchecked(&near_pi);
    let g = SO3::exp_unchecked(&w);
    let v = Vector3::new(1.0, 2.0, -0.5);

    let mut grp = c.benchmark_group("so3");
    grp.bench_function("exp", |b| b.iter(|| so3::exp_unchecked(black_box(&w))));
    grp.bench_function("exp tiny angle (series)", |b| {
        b.iter(|| so3::exp_unchecked(black_box(&tiny)))
    });
    grp.bench_function("nalgebra Rotation3::new (peer)", |b| {
        b.iter(|| Rotation3::new(black_box(w)))
    });
    grp.bench_function("log", |b| b.iter(|| so3::log_unchecked(black_box(&r))));
    grp.bench_function("log near pi", |b| {
        b.iter(|| so3::log_unchecked(black_box(&r_pi)))
    });
    let rot = Rotation3::from_matrix_unchecked(r);
    grp.bench_function("nalgebra Rotation3::scaled_axis (peer)", |b| {
        b.iter(|| black_box(&rot).scaled_axis())
    });
    grp.bench_function("Ad", |b| b.iter(|| black_box(&g).adjoint(black_box(&v))));
    grp.bench_function("jacobian_right", |b| {
        b.iter(|| so3::jacobian_right_unchecked(black_box(&w)))
    });
    grp.bench_function("jacobian_right_inv", |b| {
        b.iter(|| so3::jacobian_right_inv(black_box(&w)))
    });
    grp.bench_function("cayley", |b| b.iter(|| so3::cayley(black_box(&w))));
    grp.bench_function("cayley_inv", |b| b.iter(|| so3::cayley_inv(black_box(&r))));
    grp.finish();
}

fn se3_kernels(c: &mut Criterion) {
    let xi = Vector6::new(0.3, -1.1, 0.7, 1.0, 2.0, -0.5);
    let g = se3::exp_unchecked(&xi);
    let h = se3::exp_unchecked(&(xi * 0.5));
    let mut grp = c.benchmark_group("se3");
    grp.bench_function("exp", |b| b.iter(|| se3::exp_unchecked(black_box(&xi))));
    grp.bench_function("log", |b| b.iter(|| se3::log_unchecked(black_box(&g))));
    grp.bench_function("Ad matrix", |b| b.iter(|| black_box(&g).adjoint_matrix()));
    grp.bench_function("Ad on a vector", |b| {
        b.iter(|| black_box(&g).adjoint(black_box(&xi)))
    });
    grp.bench_function("compose", |b| {
        b.iter(|| SE3::compose(black_box(&g), black_box(&h)))
    });
    grp.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = so3_kernels, se3_kernels
}
criterion_main!(benches);
