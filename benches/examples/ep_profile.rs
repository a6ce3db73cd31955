use lieflow::integrate::integrate;
use lieflow::systems::user::{EulerPoincare, Lagrangian};
use lieflow::systems::{Algebra, Side};
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
    let z0 = [1.0, 0.5, -0.3, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let m = std::env::args().nth(1).unwrap_or("variational".into());
    let t = std::time::Instant::now();
    let r = if m == "lgvi" {
        let body = lieflow::systems::RigidBody::new([1.0, 2.0, 3.0])
            .unwrap()
            .with_attitude();
        integrate(
            &body,
            &m,
            &z0,
            0.01,
            std::env::var("N")
                .map(|n| n.parse().unwrap())
                .unwrap_or(2_000_000),
            std::env::var("N")
                .map(|n| n.parse().unwrap())
                .unwrap_or(2_000_000),
        )
        .unwrap()
    } else {
        integrate(
            &ep,
            &m,
            &z0,
            0.01,
            std::env::var("N")
                .map(|n| n.parse().unwrap())
                .unwrap_or(2_000_000),
            std::env::var("N")
                .map(|n| n.parse().unwrap())
                .unwrap_or(2_000_000),
        )
        .unwrap()
    };
    eprintln!(
        "{} ns/step {:?}",
        t.elapsed().as_nanos() as f64 / 2e6,
        &r.state(1)[..3]
    );
}
