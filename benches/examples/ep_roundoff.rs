//! Round-off of the discrete Euler–Poincaré method over long runs (issue 24): the free rigid body
//! from ℓ = ½⟨Ω, 𝕀Ω⟩ with its attitude, dt = 0.01, 10⁷ steps; the drift of |M|² and of the
//! Noether momentum R M at 10³ … 10⁷ steps, in units of ε. A random walk grows like √N (×3.2
//! per decade), a systematic drift like N (×10).
//!
//! `cargo run --release -p lieflow-benches --example ep_roundoff [variational | lgvi | …]` (lgvi:
//! the built-in `RigidBody`'s, for comparison; another name: a method of the EulerPoincare
//! system).

use lieflow::integrate::{Run, System};
use lieflow::systems::user::{EulerPoincare, Lagrangian};
use lieflow::systems::{Algebra, RigidBody, Side};

fn main() {
    let ep = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Quadratic(vec![1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0]),
        Side::Left,
        None,
    )
    .unwrap()
    .with_attitude()
    .unwrap();
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap().with_attitude();
    let method = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "variational".into());
    let sys: &dyn System = if method == "lgvi" { &body } else { &ep };
    let z0 = [1.0, 0.5, -0.3, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let inv0 = sys.invariants(&z0).unwrap();
    let mut run = Run::new(sys, &method, &z0, 0.01, 10_000_000, 0.0).unwrap();
    let mut out = Vec::new();
    let t = std::time::Instant::now();
    let (mut done, eps) = (0usize, f64::EPSILON);
    println!("| steps | Δ|M|² / ε | max Δ(R M) / ε | ns/step |");
    println!("|---|---|---|---|");
    for decade in 3..=7 {
        let target = 10usize.pow(decade);
        run.advance(sys, (target - done) as u64, &mut out).unwrap();
        out.clear();
        done = target;
        let inv = sys.invariants(&run.state(sys)).unwrap();
        let noether = (1..4)
            .map(|k| (inv[k] - inv0[k]).abs())
            .fold(0.0f64, f64::max);
        println!(
            "| 10^{decade} | {:.1} | {:.1} | {:.0} |",
            (inv[0] - inv0[0]).abs() / eps,
            noether / eps,
            t.elapsed().as_nanos() as f64 / done as f64
        );
    }
}
