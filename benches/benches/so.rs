//! so(n)/SO(n) for n = 3, 10, 50: exp (Rodrigues at n = 3, Padé(13) above) and log.
//! Run: `cargo bench -p lieflow-benches --bench so`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use lieflow::lie::so;
use lieflow::Mat;
use std::hint::black_box;

/// A deterministic skew matrix with |ξ| = 1.5 (inside the injectivity radius, so log applies).
fn sample(n: usize) -> Mat {
    let c: Vec<f64> = (0..so::dim(n))
        .map(|k| ((k * 7919 % 101) as f64 / 50.0) - 1.0)
        .collect();
    let xi = so::hat_n(&c).expect("valid coordinates");
    let scale = 1.5 / so::norm(&xi);
    xi * faer::Scale(scale)
}

fn bench_so(c: &mut Criterion) {
    let mut g = c.benchmark_group("so_n");
    for n in [3, 10, 50] {
        let xi = sample(n);
        let r = so::exp(&xi).expect("exp");
        g.bench_with_input(BenchmarkId::new("exp", n), &xi, |b, xi| {
            b.iter(|| so::exp(black_box(xi)))
        });
        g.bench_with_input(BenchmarkId::new("log", n), &r, |b, r| {
            b.iter(|| so::log(black_box(r)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_so);
criterion_main!(benches);
