//! Work–precision of the free rigid body with its attitude, from Rust: every catalogued method of
//! `RigidBody::with_attitude()` at T = 100 (I = (1, 2, 3), M₀ = (1, 0.5, −0.3), R₀ = 1), error
//! against a reference, wall time of the whole `integrate` call (best of repeats).
//!
//! The reference is the method `exact` when the catalog has it, else `splitting6` with 2¹⁶ steps.
//! Prints CSV `rust,method,steps,seconds,error` (read by
//! `benches/python/rigid_body_work_precision.py`, which draws the figure):
//!
//!     cargo run --release -p lieflow-benches --example rigid_body_work_precision

use std::time::Instant;

use lieflow::integrate::{integrate, System};
use lieflow::systems::RigidBody;

const T: f64 = 100.0;

/// The final state of a run of `steps` steps, and its best wall time over repeats (at least 3,
/// more while under ~0.2 s in all).
fn run(
    body: &RigidBody,
    method: &str,
    z0: &[f64],
    steps: usize,
) -> lieflow::Result<(Vec<f64>, f64)> {
    let (mut best, mut spent, mut n, mut last) = (f64::INFINITY, 0.0, 0, Vec::new());
    while n < 3 || (spent < 0.2 && n < 1000) {
        let t0 = Instant::now();
        let traj = integrate(body, method, z0, T / steps as f64, steps, steps)?;
        let dt = t0.elapsed().as_secs_f64();
        last = traj.state(traj.len() - 1).to_vec();
        best = best.min(dt);
        spent += dt;
        n += 1;
    }
    Ok((last, best))
}

fn main() -> lieflow::Result<()> {
    let body = RigidBody::new([1.0, 2.0, 3.0])?.with_attitude();
    let mut z0 = vec![1.0, 0.5, -0.3];
    z0.extend([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    let methods: Vec<&str> = body.methods().into_iter().map(|(name, _)| name).collect();
    let reference = if methods.contains(&"exact") {
        run(&body, "exact", &z0, 1)?.0
    } else {
        run(&body, "splitting6", &z0, 1 << 16)?.0
    };
    println!("rust,method,steps,seconds,error");
    for method in methods {
        for k in 0..12 {
            let steps = 25usize << k;
            if method == "exact" && k > 6 {
                break;
            }
            // A step too large for a method's iteration (isospectral, lgvi) is skipped.
            let Ok((z, sec)) = run(&body, method, &z0, steps) else {
                continue;
            };
            let err = z
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            println!("rust,{method},{steps},{sec:.9e},{err:.3e}");
            if sec > 0.05 || err < 1e-14 {
                break;
            }
        }
    }
    Ok(())
}
