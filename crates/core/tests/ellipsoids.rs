//! The fluid ellipsoids (EFE ch. 5–7) as relative equilibria of the incompressible
//! pseudo-rigid body with self-gravity: defining equations, closed forms, EFE's printed values,
//! Dedekind's theorem, stability in the co-moving frame, a long run of the full dynamics, and the
//! continuation of the Maclaurin–Jacobi diagram.

use lieflow::analysis::continuation::{End, Kind, Options};
use lieflow::integrate::{integrate, Problem};
use lieflow::pseudo_rigid::ellipsoids::{self, EllipsoidFamily, Fluid};
use lieflow::pseudo_rigid::gravity::index_symbols;
use std::f64::consts::PI;

fn fluid() -> Fluid {
    Fluid::new(1.0, 1.0).unwrap()
}

/// EFE ch. 5 (32): Ω²/(πGρ) of the Maclaurin spheroid.
fn maclaurin_closed(e: f64) -> f64 {
    let s = (1.0 - e * e).sqrt();
    2.0 * s * (3.0 - 2.0 * e * e) * e.asin() / e.powi(3) - 6.0 * (1.0 - e * e) / (e * e)
}

#[test]
fn maclaurin_against_the_closed_form() {
    let fl = fluid();
    // (The closed form cancels terms of size 6/e²: its own error is ~1e-15·10/e².)
    for &e in &[0.1, 0.3, 0.6, 0.81267, 0.9, 0.95, 0.99] {
        let m = fl.maclaurin(e).unwrap();
        let q = fl.quantities(&m).unwrap();
        let exact = maclaurin_closed(e);
        assert!(
            (q.omega2_over_pi_g_rho - exact).abs() <= 1e-12 * exact + 1e-14 / (e * e),
            "e = {e}: {} vs {exact}",
            q.omega2_over_pi_g_rho
        );
        assert!((q.e - e).abs() < 1e-15);
        let r = fl.residuals(&m).unwrap();
        assert!(r.iter().all(|x| x.abs() < 1e-13), "{r:?}");
        assert_eq!(q.f, 0.0);
    }
    // EFE Table I: Ω²/(πGρ) = 0.37423 at e = 0.81267, the maximum 0.449331 at e = 0.92995.
    let q = fl.quantities(&fl.maclaurin(0.81267).unwrap()).unwrap();
    assert!((q.omega2_over_pi_g_rho - 0.37423).abs() < 5e-6);
    let q = fl.quantities(&fl.maclaurin(0.92995).unwrap()).unwrap();
    assert!((q.omega2_over_pi_g_rho - 0.449331).abs() < 2e-6);
}

#[test]
fn jacobi_satisfies_efe_39() {
    let fl = fluid();
    for &r in &[0.95, 0.8, 0.6, 0.432232, 0.3, 0.1] {
        let j = fl.jacobi(r).unwrap();
        let a = j.a;
        let (ai, aij) = index_symbols(&a).unwrap();
        // EFE §39 (4): a₁²a₂²A₁₂ = a₃²A₃; (5): Ω²/(πGρ) = 2B₁₂, B₁₂ = A₂ − a₁²A₁₂.
        let lhs = a[0] * a[0] * a[1] * a[1] * aij[0][1];
        let rhs = a[2] * a[2] * ai[2];
        assert!((lhs - rhs).abs() <= 1e-12 * rhs, "r = {r}: {lhs} vs {rhs}");
        let q = fl.quantities(&j).unwrap();
        let b12 = ai[1] - a[0] * a[0] * aij[0][1];
        assert!((q.omega2_over_pi_g_rho - 2.0 * b12).abs() <= 1e-12 * b12);
        let res = fl.residuals(&j).unwrap();
        assert!(res.iter().all(|x| x.abs() < 1e-12), "{res:?}");
        let re = fl.relative_equilibrium(&j).unwrap();
        assert!(re.residuals.motion < 1e-12, "{:?}", re.residuals);
        assert!(re.residuals.commutator < 1e-12);
    }
    // EFE Table VI at Poincaré's pear-shaped point: a₂ = 0.432232, a₃ = 0.345069,
    // Ω²/(πGρ) = 0.284030.
    let j = fl.jacobi(0.432232).unwrap();
    assert!((j.a[2] - 0.345069).abs() < 2e-6, "{:?}", j.a);
    let q = fl.quantities(&j).unwrap();
    assert!((q.omega2_over_pi_g_rho - 0.284030).abs() < 2e-6);
}

#[test]
fn bifurcation_point() {
    let fl = fluid();
    let b = fl.maclaurin_jacobi_bifurcation().unwrap();
    let q = fl.quantities(&b).unwrap();
    // EFE: e = 0.81267, Ω²/(πGρ) = 0.37423; the defining equation a₁⁴A₁₁ = a₃²A₃.
    assert!((q.e - 0.81267).abs() < 5e-6, "{}", q.e);
    assert!((q.omega2_over_pi_g_rho - 0.37423).abs() < 5e-6);
    let (ai, aij) = index_symbols(&b.a).unwrap();
    let (l, r) = (aij[0][0], b.a[2] * b.a[2] * ai[2]);
    assert!((l - r).abs() <= 1e-12 * r, "{l} vs {r}");
    // The Jacobi ellipsoids approach it as a₂/a₁ → 1.
    let j = fl.jacobi(1.0 - 1e-6).unwrap();
    assert!((j.a[2] - b.a[2]).abs() < 1e-5);
}

#[test]
fn dedekind_is_the_adjoint_of_jacobi() {
    let fl = fluid();
    for &r in &[0.9, 0.5, 0.2] {
        let (j, d) = (fl.jacobi(r).unwrap(), fl.dedekind(r).unwrap());
        let (qj, qd) = (fl.quantities(&j).unwrap(), fl.quantities(&d).unwrap());
        assert_eq!(qd.omega3, 0.0);
        assert!(qd.f.is_infinite());
        // Dedekind's theorem: the circulation of one is the angular momentum of the other.
        assert!((qj.angular_momentum - qd.circulation).abs() < 1e-13);
        assert!((qj.circulation - qd.angular_momentum).abs() < 1e-13);
        assert!((qj.energy - qd.energy).abs() < 1e-13);
        let re = fl.relative_equilibrium(&d).unwrap();
        assert!(re.residuals.motion < 1e-12);
        // The same figure on its own ray (f = ∞) as a Riemann S-type ellipsoid.
        let s = fl.riemann_s(r, f64::INFINITY).unwrap();
        assert!((s.a[2] - d.a[2]).abs() < 1e-12 && (s.mu - d.mu).abs() < 1e-12);
    }
}

#[test]
fn riemann_s_type() {
    let fl = fluid();
    for &(r, f) in &[(0.5, 0.0), (0.5, -2.0), (0.7, -1.0), (0.6, 1.0), (0.4, 3.0)] {
        let s = fl.riemann_s(r, f).unwrap();
        let q = fl.quantities(&s).unwrap();
        assert!((q.f - f).abs() < 1e-12 * (1.0 + f.abs()), "f = {}", q.f);
        assert!((q.a2_over_a1 - r).abs() < 1e-15);
        let res = fl.residuals(&s).unwrap();
        assert!(res.iter().all(|x| x.abs() < 1e-12), "{res:?}");
        let re = fl.relative_equilibrium(&s).unwrap();
        assert!(re.residuals.motion < 1e-12, "{:?}", re.residuals);
    }
    // f = 0 is Jacobi's.
    let (s, j) = (fl.riemann_s(0.5, 0.0).unwrap(), fl.jacobi(0.5).unwrap());
    assert!((s.a[2] - j.a[2]).abs() < 1e-13);
    // Irrotational (f = −2): the inertial-frame vorticity ζ + 2Ω vanishes.
    let s = fl.riemann_s(0.5, -2.0).unwrap();
    let q = fl.quantities(&s).unwrap();
    assert!((q.zeta + 2.0 * q.omega3).abs() < 1e-12);
}

#[test]
fn stability_in_the_comoving_frame() {
    let fl = fluid();
    // Maclaurin: spectrally stable below e = 0.95289 (EFE §33), unstable above.
    for &(e, stable) in &[(0.5, true), (0.9, true), (0.96, false), (0.99, false)] {
        let s = fl.stability(&fl.maclaurin(e).unwrap()).unwrap();
        assert_eq!(s.spectral.stable, stable, "e = {e}: {:?}", s.spectral);
        assert!(s.residual < 1e-10);
    }
    // Energy–momentum: definite on the Maclaurin sequence before the bifurcation.
    let s = fl.stability(&fl.maclaurin(0.5).unwrap()).unwrap();
    assert!(s.energy_momentum.stable, "{:?}", s.energy_momentum);
    // Jacobi ellipsoids: spectrally stable (to second-harmonic perturbations, EFE §40).
    for &r in &[0.8, 0.5] {
        let s = fl.stability(&fl.jacobi(r).unwrap()).unwrap();
        assert!(s.spectral.stable, "r = {r}: {:?}", s.spectral);
    }
}

#[test]
fn jacobi_stays_on_its_relative_equilibrium_for_100_periods() {
    let fl = fluid();
    let j = fl.jacobi(0.6).unwrap();
    let body = fl.body().unwrap();
    let (z0, _) = Fluid::state(&j);
    let q = fl.quantities(&j).unwrap();
    let period = 2.0 * PI / q.omega3;
    let per = 200;
    let steps = 100 * per;
    let dt = period / per as f64;
    let traj = integrate(&body, "rattle6", &z0, dt, steps, per).unwrap();
    let re = fl.relative_equilibrium(&j).unwrap();
    let det0 = j.a.iter().product::<f64>();
    let mut worst_det = 0.0f64;
    let mut worst_x = 0.0f64;
    let mut worst_axes = 0.0f64;
    for k in 0..traj.len() {
        let z = traj.state(k);
        let (x, _) = body.split(z).unwrap();
        let d = x[(0, 0)] * (x[(1, 1)] * x[(2, 2)] - x[(1, 2)] * x[(2, 1)])
            - x[(0, 1)] * (x[(1, 0)] * x[(2, 2)] - x[(1, 2)] * x[(2, 0)])
            + x[(0, 2)] * (x[(1, 0)] * x[(2, 1)] - x[(1, 1)] * x[(2, 0)]);
        worst_det = worst_det.max((d / det0 - 1.0).abs());
        let sv = body.singular_values(z).unwrap();
        for (s, a) in sv.iter().zip(&j.a) {
            worst_axes = worst_axes.max((s - a).abs());
        }
        let t = traj.t[k];
        let (xe, _) = &re.motion(&[t]).unwrap()[0];
        worst_x = worst_x.max((&x - xe).norm_l2());
    }
    eprintln!("det drift {worst_det:.2e}, axes {worst_axes:.2e}, X {worst_x:.2e}");
    assert!(worst_det < 1e-13, "det X drift {worst_det:.2e}");
    assert!(worst_axes < 1e-8, "semi-axes moved by {worst_axes:.2e}");
    assert!(
        worst_x < 1e-6,
        "X(t) left e^{{tΩ}}A e^{{−tΛ}} by {worst_x:.2e}"
    );
    let _ = body.energy(&z0).unwrap();
}

#[test]
fn continuation_maclaurin_to_jacobi() {
    let fl = fluid();
    let start = fl.maclaurin(0.3).unwrap();
    let family = EllipsoidFamily::of(&fl, &start).unwrap();
    let u0 = family.unknowns_of(&start);
    let opts = Options::default();
    let b = match ellipsoids::follow(&family, &u0, "e", 0.99, true, None, &opts) {
        Ok(b) => b,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(b.end, End::Reached);
    let bif = fl
        .quantities(&fl.maclaurin_jacobi_bifurcation().unwrap())
        .unwrap();
    let branch: Vec<_> = b
        .special
        .iter()
        .filter(|s| s.kind == Kind::Branch)
        .collect();
    assert!(!branch.is_empty(), "{:?}", b.special);
    let e_branch = family.parameter("e", &branch[0].point.u).unwrap();
    assert!((e_branch - bif.e).abs() < 1e-10, "{e_branch} vs {}", bif.e);
    // The spectral stability is lost at e = 0.95289 (EFE §33).
    let lost: Vec<_> = b
        .special
        .iter()
        .filter(|s| s.kind == Kind::Stability && s.verdict == Some(0))
        .collect();
    assert_eq!(lost.len(), 1, "{:?}", b.special);
    let e_lost = lost[0].point.parameter;
    eprintln!("spectral stability lost at e = {e_lost:.12}");
    assert!((e_lost - 0.95289).abs() < 5e-6, "{e_lost}");
    // The energy–momentum verdict changes at the bifurcation (secular instability): with the
    // exact Hessian (issue 26) located to 1e-11 (it was 7e-9 by nested differences).
    let em: Vec<_> = b
        .special
        .iter()
        .filter(|s| s.kind == Kind::Stability && s.verdict == Some(1))
        .collect();
    assert_eq!(em.len(), 1, "{:?}", b.special);
    let e_em = em[0].point.parameter;
    assert!((e_em - bif.e).abs() < 1e-11, "{e_em} vs {}", bif.e);
    // Switch onto the Jacobi branch and follow it to a₂/a₁ = 0.3.
    let dir = family
        .switch_direction(&branch[0].point, ellipsoids::Sense::Splitting)
        .unwrap();
    assert!(dir[0] > dir[1]);
    let jb = ellipsoids::follow(
        &family,
        &branch[0].point.u,
        "a2_over_a1",
        0.3,
        false,
        Some(&dir),
        &opts,
    )
    .unwrap();
    assert_eq!(jb.end, End::Reached);
    for p in jb.points.iter().skip(1) {
        let f = family.figure(&p.u).unwrap();
        let (ai, aij) = index_symbols(&f.a).unwrap();
        let (l, r) = (
            f.a[0].powi(2) * f.a[1].powi(2) * aij[0][1],
            f.a[2].powi(2) * ai[2],
        );
        assert!((l - r).abs() < 1e-10 * r, "{:?}: {l} vs {r}", f.a);
        assert!(f.a[0] > f.a[1]);
    }
    // The end point is the Jacobi ellipsoid with a₂/a₁ = 0.3 (scaled).
    let last = family.figure(&jb.points.last().unwrap().u).unwrap();
    let j = fl.jacobi(0.3).unwrap();
    assert!((last.a[2] / last.a[0] - j.a[2]).abs() < 1e-10);
}

#[test]
fn every_kind_of_figure_stays_on_its_relative_equilibrium() {
    let fl = fluid();
    let body = fl.body().unwrap();
    let figures = [
        ("Maclaurin", fl.maclaurin(0.7).unwrap()),
        ("Dedekind", fl.dedekind(0.6).unwrap()),
        ("S-type f = -2", fl.riemann_s(0.6, -2.0).unwrap()),
        ("S-type f = 1", fl.riemann_s(0.6, 1.0).unwrap()),
    ];
    for (name, fig) in figures {
        let (z0, _) = Fluid::state(&fig);
        let period = 2.0 * PI / fig.omega.abs().max(fig.mu.abs());
        let per = 200;
        let traj = integrate(&body, "rattle6", &z0, period / per as f64, 10 * per, per).unwrap();
        let re = fl.relative_equilibrium(&fig).unwrap();
        let mut worst = 0.0f64;
        for k in 0..traj.len() {
            let (x, _) = body.split(traj.state(k)).unwrap();
            let (xe, _) = &re.motion(&[traj.t[k]]).unwrap()[0];
            worst = worst.max((&x - xe).norm_l2());
        }
        let st = fl.stability(&fig).unwrap();
        eprintln!(
            "{name}: max |X − X_exact| over 10 periods = {worst:.2e} (spectrally stable: {}, \
             max Re λ = {:.1e})",
            st.spectral.stable, st.spectral.max_real_part
        );
        // rattle6 at 200 steps per period: the phase error of an order-6 method.
        assert!(worst < 5e-8, "{name}: {worst:.2e}");
    }
}

#[test]
fn comoving_refuses_a_state_that_is_not_a_relative_equilibrium() {
    use lieflow::analysis::comoving;
    let fl = fluid();
    let j = fl.jacobi(0.6).unwrap();
    let (z, xi) = Fluid::state(&j);
    let body = fl.body().unwrap();
    // The right velocities at the wrong speed: the co-moving field does not vanish.
    let slow: Vec<f64> = xi.iter().map(|x| 0.9 * x).collect();
    let e = comoving::stability(&body, &z, &slow).unwrap_err();
    assert!(matches!(e, lieflow::Error::InvalidArgument { .. }), "{e}");
    assert!(e.to_string().contains("does not vanish"), "{e}");
    // Wrong lengths and non-finite input.
    assert!(comoving::stability(&body, &z[..17], &xi).is_err());
    assert!(comoving::stability(&body, &z, &xi[..5]).is_err());
    let mut bad = z.clone();
    bad[0] = f64::NAN;
    assert!(comoving::stability(&body, &bad, &xi).is_err());
}

#[test]
fn switching_senses() {
    let fl = fluid();
    let start = fl.maclaurin(0.8).unwrap();
    let family = EllipsoidFamily::of(&fl, &start).unwrap();
    let u0 = family.unknowns_of(&start);
    let b = ellipsoids::follow(&family, &u0, "e", 0.82, false, None, &Options::default()).unwrap();
    let bp = &b
        .special
        .iter()
        .find(|s| s.kind == Kind::Branch)
        .unwrap()
        .point;
    let split = family
        .switch_direction(bp, ellipsoids::Sense::Splitting)
        .unwrap();
    let join = family
        .switch_direction(bp, ellipsoids::Sense::Joining)
        .unwrap();
    assert!(split[0] > split[1]);
    assert!(split.iter().zip(&join).all(|(a, b)| a == &-b));
    // Towards a smaller a₂/a₁ is the splitting sense; towards a larger one the other.
    let down = family
        .switch_direction(bp, ellipsoids::Sense::Towards("a2_over_a1", 0.5))
        .unwrap();
    let up = family
        .switch_direction(bp, ellipsoids::Sense::Towards("a2_over_a1", 1.5))
        .unwrap();
    assert_eq!(down, split);
    assert_eq!(up, join);
}
