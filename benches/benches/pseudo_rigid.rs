//! Pseudo-rigid geometry (001): the closed-form inverse of the bi-inertia tensor (7.6)–(7.9)
//! against a dense LU solve of the n(n−1) system, and the bi-connection (6.18).
//!
//! Run: `CARGO_TARGET_DIR=… cargo bench -p lieflow-benches --bench pseudo_rigid`; results in
//! docs/bench-prb.md.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use faer::linalg::solvers::Solve;
use lieflow::lie::so;
use lieflow::pseudo_rigid::{connection, BiInertia};
use lieflow::Mat;

/// Deterministic pseudo-random numbers in [−1, 1) (xorshift), so runs are comparable.
fn uniform(seed: u64, len: usize) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..len)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

/// A configuration X ∈ GL⁺(n) with (generically) distinct singular values, and λ, γ ∈ so(n).
fn inputs(n: usize) -> (Mat, Mat, Mat) {
    let v = uniform(n as u64, n * n);
    let mut x = Mat::from_fn(n, n, |i, j| v[i * n + j]);
    if x.determinant() < 0.0 {
        for j in 0..n {
            x[(0, j)] = -x[(0, j)];
        }
    }
    let d = so::dim(n);
    let c = uniform(n as u64 + 1000, 2 * d);
    (
        x,
        so::hat_n_unchecked(n, &c[..d]),
        so::hat_n_unchecked(n, &c[d..]),
    )
}

fn bi_inertia_solve(c: &mut Criterion) {
    let mut g = c.benchmark_group("bi_inertia_solve");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(1));
    for n in [3usize, 10, 30, 100, 300] {
        let (x, lam, gam) = inputs(n);
        g.bench_with_input(BenchmarkId::new("closed_form", n), &n, |b, _| {
            b.iter(|| {
                let bi = BiInertia::new(black_box(&x)).unwrap();
                bi.solve(black_box(&lam), black_box(&gam)).unwrap()
            })
        });
        g.bench_with_input(BenchmarkId::new("svd_only", n), &n, |b, _| {
            b.iter(|| lieflow::lie::gl::svd_coordinates(black_box(&x)).unwrap())
        });
    }
    for n in [3usize, 10, 30] {
        let (x, lam, gam) = inputs(n);
        let m = BiInertia::new(&x).unwrap().matrix();
        let mut rhs = so::vee_n_unchecked(&lam);
        rhs.extend(so::vee_n_unchecked(&gam));
        let rhs = Mat::from_fn(rhs.len(), 1, |i, _| rhs[i]);
        g.bench_with_input(BenchmarkId::new("dense_lu", n), &n, |b, _| {
            b.iter(|| black_box(&m).partial_piv_lu().solve(black_box(&rhs)))
        });
        g.bench_with_input(BenchmarkId::new("dense_build_lu", n), &n, |b, _| {
            b.iter(|| {
                let m = BiInertia::new(black_box(&x)).unwrap().matrix();
                m.partial_piv_lu().solve(black_box(&rhs))
            })
        });
    }
    g.finish();
}

fn bi_connection(c: &mut Criterion) {
    let mut g = c.benchmark_group("bi_connection");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(1));
    for n in [3usize, 10, 30, 100, 300] {
        let (x, lam, _) = inputs(n);
        let y = &lam * &x + &x;
        g.bench_with_input(BenchmarkId::new("evaluate", n), &n, |b, _| {
            b.iter(|| {
                let bi = BiInertia::new(black_box(&x)).unwrap();
                connection::bi_connection(&bi, black_box(&y)).unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bi_inertia_solve, bi_connection);
criterion_main!(benches);
