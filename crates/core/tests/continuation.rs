//! Pseudo-arclength continuation on families with known geometry: a pitchfork (branch point,
//! switching), a circle (folds), a monitored verdict (its change located).

use lieflow::analysis::continuation::{
    follow, switch_direction, End, Family, Indicator, Kind, Options,
};
use lieflow::{Mat, Result};

/// F(x, λ) = x(λ − x²): the branches x = 0 and λ = x² cross at the pitchfork (0, 0).
struct Pitchfork;

impl Family for Pitchfork {
    fn unknowns(&self) -> usize {
        2
    }
    fn residual(&self, u: &[f64]) -> Result<Vec<f64>> {
        Ok(vec![u[0] * (u[1] - u[0] * u[0])])
    }
}

/// F(x, λ) = x² + λ² − 1 with an analytic Jacobian.
struct Circle;

impl Family for Circle {
    fn unknowns(&self) -> usize {
        2
    }
    fn residual(&self, u: &[f64]) -> Result<Vec<f64>> {
        Ok(vec![u[0] * u[0] + u[1] * u[1] - 1.0])
    }
    fn jacobian(&self, u: &[f64]) -> Result<Mat> {
        Ok(Mat::from_fn(1, 2, |_, j| 2.0 * u[j]))
    }
}

fn lambda(u: &[f64]) -> Result<f64> {
    Ok(u[1])
}

fn x(u: &[f64]) -> Result<f64> {
    Ok(u[0])
}

#[test]
fn pitchfork_branch_point_located_and_switched() {
    let opts = Options::default();
    let b = follow(&Pitchfork, &[0.0, -1.0], &lambda, 1.0, None, None, &opts).unwrap();
    assert_eq!(b.end, End::Reached);
    assert!((b.points.last().unwrap().parameter - 1.0).abs() < 1e-12);
    // The trivial branch stays at x = 0.
    assert!(b.points.iter().all(|p| p.u[0].abs() < 1e-12));
    let bp: Vec<_> = b
        .special
        .iter()
        .filter(|s| s.kind == Kind::Branch)
        .collect();
    assert_eq!(bp.len(), 1, "{:?}", b.special);
    assert!(
        bp[0].point.parameter.abs() < 1e-10,
        "λ* = {}",
        bp[0].point.parameter
    );
    // Switching: the other branch λ = x², followed in λ up to 0.25 (x = ±0.5).
    let dir = switch_direction(&Pitchfork, &bp[0].point).unwrap();
    assert!(dir[0].abs() > 0.999, "{dir:?}");
    let other = follow(
        &Pitchfork,
        &bp[0].point.u,
        &lambda,
        0.25,
        None,
        Some(&dir),
        &opts,
    )
    .unwrap();
    assert_eq!(other.end, End::Reached);
    let last = other.points.last().unwrap();
    assert!((last.u[1] - last.u[0] * last.u[0]).abs() < 1e-12);
    assert!((last.u[0].abs() - 0.5).abs() < 1e-10, "{:?}", last.u);
    // Not a branch point: switching refuses with a typed error.
    assert!(switch_direction(&Pitchfork, &b.points[0]).is_err());
}

#[test]
fn circle_folds_located() {
    let opts = Options::default();
    // From (0, 1) towards +x, around the fold at x = 1 and down to x = −0.5.
    let b = follow(
        &Circle,
        &[0.0, 1.0],
        &x,
        -0.5,
        None,
        Some(&[1.0, 0.0]),
        &opts,
    )
    .unwrap();
    assert_eq!(b.end, End::Reached);
    let folds: Vec<_> = b.special.iter().filter(|s| s.kind == Kind::Fold).collect();
    assert_eq!(folds.len(), 1, "{:?}", b.special);
    assert!((folds[0].point.parameter - 1.0).abs() < 1e-10);
    assert!(folds[0].point.u[1].abs() < 1e-5);
    let last = b.points.last().unwrap();
    assert!(
        (last.u[0] + 0.5).abs() < 1e-11 && last.u[1] < 0.0,
        "{:?}",
        last.u
    );
    for p in &b.points {
        assert!((p.u[0].hypot(p.u[1]) - 1.0).abs() < 1e-13);
    }
    // No branch points on a regular curve.
    assert!(b.special.iter().all(|s| s.kind != Kind::Branch));
}

#[test]
fn monitor_change_located() {
    let opts = Options::default();
    // A verdict with a smooth margin (0.3 − λ) and one without (NaN: bisection).
    let monitor = |u: &[f64]| -> Result<Vec<Indicator>> {
        Ok(vec![
            Indicator {
                stable: u[1] < 0.3,
                margin: 0.3 - u[1],
            },
            Indicator {
                stable: u[1] < 0.6,
                margin: f64::NAN,
            },
        ])
    };
    let b = follow(
        &Pitchfork,
        &[0.0, -1.0],
        &lambda,
        1.0,
        Some(&monitor),
        None,
        &opts,
    )
    .unwrap();
    let st: Vec<_> = b
        .special
        .iter()
        .filter(|s| s.kind == Kind::Stability)
        .collect();
    assert_eq!(st.len(), 2);
    assert_eq!(st[0].verdict, Some(0));
    assert!((st[0].point.parameter - 0.3).abs() < 1e-12);
    assert_eq!(st[1].verdict, Some(1));
    assert!((st[1].point.parameter - 0.6).abs() < 1e-10);
    assert_eq!(st[1].point.stable, vec![false, false]);
    // Special points come in the order met: the branch point (λ = 0) before λ = 0.3.
    let kinds: Vec<_> = b.special.iter().map(|s| s.kind).collect();
    assert_eq!(kinds, vec![Kind::Branch, Kind::Stability, Kind::Stability]);
}

#[test]
fn bad_start_is_a_typed_error() {
    let opts = Options::default();
    assert!(follow(&Circle, &[0.0], &x, 0.0, None, None, &opts).is_err());
    assert!(follow(&Circle, &[f64::NAN, 1.0], &x, 0.0, None, None, &opts).is_err());
}
