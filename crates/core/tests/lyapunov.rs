//! Lyapunov exponents by repeated QR (`lieflow::analysis::lyapunov`): a linear saddle's exactly,
//! the symplectic pairing λ_i + λ_(e+1−i) = 0 on Hénon–Heiles and the heavy tops, zero
//! exponents for the integrable tops (Lagrange, Kovalevskaya) against a clearly positive one for
//! a generic top at the same energy, the base states of the plain run bit for bit, and the
//! errors.

use std::sync::Arc;

use lieflow::analysis::lyapunov::{lyapunov, Lyapunov, LyapunovRun};
use lieflow::integrate::{integrate, Problem, System};
use lieflow::systems::{HeavyTop, KineticMass, UserCanonical, UserSeparable};
use lieflow::Error;

mod common;
use common::henon_heiles;

/// The saddle H = p q (q̇ = q, ṗ = −p) with its derivatives.
fn saddle() -> UserCanonical {
    let h = Arc::new(|q: &[f64], p: &[f64]| -> lieflow::Result<f64> { Ok(q[0] * p[0]) });
    let g = Arc::new(
        |q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]| -> lieflow::Result<()> {
            hq[0] = p[0];
            hp[0] = q[0];
            Ok(())
        },
    );
    let hess = Arc::new(
        |_: &[f64], _: &[f64], dq: &[f64], dp: &[f64], hq: &mut [f64], hp: &mut [f64]| {
            hq[0] = dp[0];
            hp[0] = dq[0];
            Ok(())
        },
    );
    UserCanonical::new(1, h, Some(g))
        .unwrap()
        .with_hessian(hess)
}

/// A Hénon–Heiles state (x = 0, y, p_y) with p_x ≥ 0 from the energy `e`.
fn hh_state(e: f64, y: f64, py: f64) -> [f64; 4] {
    let u = 0.5 * y * y - y * y * y / 3.0;
    let px = (2.0 * (e - u) - py * py).sqrt();
    [0.0, y, px, py]
}

/// λ_i + λ_(e+1−i), the largest in magnitude.
fn pairing(l: &Lyapunov) -> f64 {
    let x = &l.exponents;
    let e = x.len();
    (0..e / 2).fold(0.0f64, |m, i| m.max((x[i] + x[e - 1 - i]).abs()))
}

/// The largest exponent's running estimate at the segment ending nearest `t`.
fn largest_at(l: &Lyapunov, t: f64) -> f64 {
    let e = l.exponents.len();
    let k = l
        .times
        .iter()
        .position(|&s| s >= t - 1e-9)
        .unwrap_or(l.times.len() - 1);
    l.running[k * e..(k + 1) * e]
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The saddle's exponents are those of the method's one-step map exactly: J = diag(R(h)ⁿ,
/// R(−h)ⁿ) (R the method's stability function), whose QR is itself, so every segment's estimate
/// is log R(±h)/h to round-off, within the method's error of ±1.
#[test]
fn a_saddle_has_its_exponents_exactly() {
    let sys = saddle();
    let h: f64 = 0.01;
    let rk4 = |h: f64| 1.0 + h + h * h / 2.0 + h.powi(3) / 6.0 + h.powi(4) / 24.0;
    let pade = |h: f64| (1.0 + h / 2.0 + h * h / 12.0) / (1.0 - h / 2.0 + h * h / 12.0);
    for (method, r) in [("rk4", &rk4 as &dyn Fn(f64) -> f64), ("gauss4", &pade)] {
        let l = lyapunov(&sys, method, &[0.3, -0.7], h, 1000, 7).unwrap();
        let (up, down) = (r(h).ln() / h, r(-h).ln() / h);
        assert_eq!(l.times.len(), 143);
        assert!((l.times[0] - 0.07).abs() < 1e-15 && (l.times[142] - 10.0).abs() < 1e-12);
        for k in 0..l.times.len() {
            let row = &l.running[2 * k..2 * k + 2];
            assert!((row[0] - up).abs() < 1e-12, "{method}: {row:?} {up}");
            assert!((row[1] - down).abs() < 1e-12, "{method}: {row:?} {down}");
        }
        eprintln!(
            "saddle {method}: exponents {:?}, exact ±1 within {:.1e}",
            l.exponents,
            (l.exponents[0] - 1.0)
                .abs()
                .max((l.exponents[1] + 1.0).abs())
        );
        assert!((l.exponents[0] - 1.0).abs() < 1e-8 && (l.exponents[1] + 1.0).abs() < 1e-8);
    }
}

/// Hénon–Heiles at E = 1/6: an orbit of the chaotic sea has a clearly positive largest exponent,
/// one on a torus at low energy ≈ 0; the exponents pair, λ₁ + λ₄ ≈ 0 ≈ λ₂ + λ₃, and their sum
/// (log det J / t, a symplectic map) vanishes to round-off.
#[test]
fn henon_heiles_pairs_its_exponents() {
    let sys = henon_heiles();
    let chaotic = hh_state(1.0 / 6.0, -0.1, 0.1);
    let l = lyapunov(&sys, "verlet", &chaotic, 0.02, 100_000, 10).unwrap();
    let sum: f64 = l.exponents.iter().sum();
    eprintln!(
        "Hénon–Heiles E = 1/6, t = 2000: {:?}, pairing {:.1e}, sum {sum:.1e}",
        l.exponents,
        pairing(&l)
    );
    assert!(l.exponents[0] > 0.03, "{:?}", l.exponents);
    assert!(pairing(&l) < 0.1 * l.exponents[0], "{:?}", l.exponents);
    assert!(sum.abs() < 1e-12, "{sum:e}");
    let regular = hh_state(0.01, 0.05, 0.0);
    let l = lyapunov(&sys, "verlet", &regular, 0.02, 100_000, 10).unwrap();
    eprintln!(
        "Hénon–Heiles E = 0.01, t = 2000: {:?}, pairing {:.1e}",
        l.exponents,
        pairing(&l)
    );
    assert!(l.exponents[0] < 0.01, "{:?}", l.exponents);
}

/// A heavy top (mgl = 1) at energy `e`: Γ = (0.6, 0, 0.8), M along (0.8, 0.5, −0.6) (so
/// M·Γ = 0) scaled to the energy.
fn top_state(top: &HeavyTop, inertia: [f64; 3], chi: [f64; 3], e: f64) -> [f64; 6] {
    let gamma = [0.6, 0.0, 0.8];
    let d = [0.8, 0.5, -0.6];
    let n = (chi[0] * chi[0] + chi[1] * chi[1] + chi[2] * chi[2]).sqrt();
    let potential: f64 = (0..3).map(|i| gamma[i] * chi[i] / n).sum();
    let kinetic: f64 = (0..3).map(|i| d[i] * d[i] / inertia[i]).sum::<f64>() / 2.0;
    let s = ((e - potential) / kinetic).sqrt();
    let z = [s * d[0], s * d[1], s * d[2], gamma[0], gamma[1], gamma[2]];
    assert!((top.energy(&z).unwrap() - e).abs() < 1e-12);
    z
}

/// The integrable tops (Lagrange: I₁ = I₂, centre of mass on the axis; Kovalevskaya:
/// I = (2, 2, 1), centre of mass in the equatorial plane) have all exponents ≈ 0, the largest
/// decaying roughly like log t / t; a generic top (I = (1, 2, 3), centre of mass off every axis)
/// at the same energy has a clearly positive one. The spectrum pairs (λ, 0, 0, 0, 0, −λ): the
/// two Casimirs give two zeros, the energy and the flow direction two more.
#[test]
fn integrable_tops_have_zero_exponents_and_a_generic_one_does_not() {
    let e = 2.0;
    let tops = [
        ("Lagrange", [1.0, 1.0, 2.0], [0.0, 0.0, 1.0]),
        ("Kovalevskaya", [2.0, 2.0, 1.0], [1.0, 0.0, 0.0]),
        ("generic", [1.0, 2.0, 3.0], [1.0, 1.0, 1.0]),
    ];
    for (name, inertia, chi) in tops {
        let top = HeavyTop::new(inertia, 1.0, chi).unwrap();
        let z0 = top_state(&top, inertia, chi, e);
        let l = lyapunov(&top, "splitting", &z0, 0.01, 200_000, 10).unwrap();
        let at: Vec<f64> = [10.0, 100.0, 1000.0, 2000.0]
            .iter()
            .map(|&t| largest_at(&l, t))
            .collect();
        let sum: f64 = l.exponents.iter().sum();
        eprintln!(
            "{name} top, E = {e}: λ₁(t = 10, 100, 1000, 2000) = {at:.4?}; at t = 2000 {:.4?}, \
             pairing {:.1e}, sum {sum:.1e}",
            l.exponents,
            pairing(&l)
        );
        assert!(sum.abs() < 1e-10, "{sum:e}");
        match name {
            "generic" => {
                assert!(l.exponents[0] > 0.08, "{:?}", l.exponents);
                assert!(pairing(&l) < 0.05 * l.exponents[0], "{:?}", l.exponents);
                assert!(l.exponents[1..5].iter().all(|x| x.abs() < 0.02));
            }
            _ => {
                assert!(l.exponents[0] < 0.01, "{:?}", l.exponents);
                assert!(at[2] < 0.5 * at[1] && at[3] < at[2], "{at:?}");
            }
        }
    }
}

/// The base states are the plain run's, bit for bit (a last segment shorter than the others, a
/// splitting whose consecutive steps fuse, a processed one, RK4), and the computation resumes:
/// segments in chunks give what one call gives.
#[test]
fn the_base_states_are_the_plain_runs_and_chunks_change_nothing() {
    let top = HeavyTop::new([1.0, 2.0, 3.0], 1.0, [1.0, 1.0, 1.0]).unwrap();
    let z0 = [0.3, -0.5, 0.9, 0.6, 0.0, 0.8];
    for method in ["splitting", "splitting4", "processed6", "rk4", "lgvi"] {
        let l = lyapunov(&top, method, &z0, 0.01, 1005, 10).unwrap();
        let plain = integrate(&top, method, &z0, 0.01, 1005, 1005).unwrap();
        assert_eq!(l.state, plain.state(1), "{method}");
        assert_eq!(l.times.len(), 101);
        assert!((l.times[100] - 10.05).abs() < 1e-12);
        let mut run = LyapunovRun::new(&top, method, &z0, 0.01, 1005, 10).unwrap();
        let mut chunks = 0;
        while run.segments_done() < run.segments() {
            assert!(run.advance(&top, 7).unwrap() <= 7);
            chunks += 1;
        }
        assert_eq!(chunks, 15);
        assert_eq!(run.finish(), l, "{method}");
    }
}

/// Bad input: typed errors, before any step.
#[test]
fn bad_input_is_refused() {
    let top = HeavyTop::new([1.0, 2.0, 3.0], 1.0, [1.0, 1.0, 1.0]).unwrap();
    let z0 = [0.3, -0.5, 0.9, 0.6, 0.0, 0.8];
    let invalid = |r: lieflow::Result<Lyapunov>, what: &str| match r {
        Err(Error::InvalidArgument { what: w, .. }) if w == what => {}
        other => panic!("{what}: {other:?}"),
    };
    invalid(lyapunov(&top, "splitting", &z0, 0.01, 0, 10), "steps");
    invalid(
        lyapunov(&top, "splitting", &z0, 0.01, 10, 0),
        "renormalise_every",
    );
    invalid(lyapunov(&top, "splitting", &z0, 0.0, 10, 1), "dt");
    invalid(lyapunov(&top, "splitting", &z0, -0.1, 10, 1), "dt");
    assert!(matches!(
        lyapunov(&top, "splitting", &z0, f64::NAN, 10, 1),
        Err(Error::InvalidArgument { .. } | Error::NonFinite { .. })
    ));
    assert!(matches!(
        lyapunov(&top, "splitting", &z0[..5], 0.01, 10, 1),
        Err(Error::Shape { .. })
    ));
    let mut nan = z0;
    nan[2] = f64::NAN;
    assert!(matches!(
        lyapunov(&top, "splitting", &nan, 0.01, 10, 1),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        lyapunov(&top, "splittin", &z0, 0.01, 10, 1),
        Err(Error::UnsupportedMethod { .. })
    ));
    // A system without the derivatives its lift needs (no Hessian): no tangent maps.
    let u = Arc::new(|q: &[f64]| -> lieflow::Result<f64> { Ok(0.5 * q[0] * q[0]) });
    let bare = UserSeparable::new(KineticMass::Scalar(1.0), Some(1), u, None).unwrap();
    assert!(bare.tangent_for("verlet").is_none());
    invalid(
        lyapunov(&bare, "verlet", &[1.0, 0.0], 0.01, 10, 1),
        "method",
    );
}
