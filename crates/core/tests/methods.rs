//! The implicit and Lie-group methods on their test problems: `Gauss(s)` (pendulum, Hénon–Heiles),
//! `Rattle` (particle on a sphere), `NonholonomicRattle` (vertical rolling disk) and `Rkmk4`
//! (free rigid body on so(3)* and so(n)*). Observed orders against exact solutions or independent
//! references, symplecticity of the one-step map, constraints, reversibility, energy, invariants
//! and error paths. Measured values are printed (run with `--nocapture`).

use lieflow::integrate::methods::{
    Gauss, NonholonomicRattle, Rattle, Rk4, Rkmk4, Verlet, IMPLICIT_MIDPOINT,
};
use lieflow::integrate::problem::{Canonical, GroupField, Separable, VectorField, Violation};
use lieflow::integrate::{integrate, integrate_with, Block, Integrator, Problem, Space, System};
use lieflow::lie::{so, so3};
use lieflow::systems::{
    GeneralizedRigidBody, Pendulum, RigidBody, RollingDisk, SphereParticle, SphericalPendulum,
};
use lieflow::{Error, Mat};
use nalgebra::{Matrix3, Vector3};

mod common;
use common::distance as dist;

// ---------------------------------------------------------------------------------------------
// Helpers

/// The state after `steps` steps of `method` from z0.
fn run<P: Problem, M: Integrator<P>>(p: &P, m: &M, z0: &[f64], dt: f64, steps: usize) -> Vec<f64> {
    integrate_with(p, m, z0, dt, steps, steps)
        .unwrap()
        .final_state
}

/// Every state of a run of `steps` steps (the initial one first).
fn trajectory<P: Problem, M: Integrator<P>>(
    p: &P,
    m: &M,
    z0: &[f64],
    dt: f64,
    steps: usize,
    every: usize,
) -> Vec<Vec<f64>> {
    let t = integrate_with(p, m, z0, dt, steps, every).unwrap();
    (0..t.len()).map(|k| t.state(k).to_vec()).collect()
}

fn norm(a: &[f64]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Errors at T of runs with dt, dt/2, dt/4 against `exact`, and the observed orders
/// log₂(e_k/e_{k+1}).
fn orders<P: Problem, M: Integrator<P>>(
    p: &P,
    m: &M,
    z0: &[f64],
    t_end: f64,
    dt: f64,
    exact: &[f64],
) -> ([f64; 3], [f64; 2]) {
    let e = [1.0, 2.0, 4.0].map(|k| {
        let h = dt / k;
        let n = (t_end / h).round() as usize;
        assert!(
            (n as f64 * h - t_end).abs() < 1e-12,
            "T = {t_end} is not a multiple of {h}"
        );
        dist(&run(p, m, z0, h, n), exact)
    });
    (e, [(e[0] / e[1]).log2(), (e[1] / e[2]).log2()])
}

fn assert_order(what: &str, e: [f64; 3], o: [f64; 2], nominal: f64) {
    eprintln!(
        "order {what}: errors {:.3e} {:.3e} {:.3e}, observed {:.3} {:.3} (nominal {nominal})",
        e[0], e[1], e[2], o[0], o[1]
    );
    assert!(
        (o[1] - nominal).abs() <= 0.2,
        "{what}: observed order {o:?}, nominal {nominal}, errors {e:?}"
    );
}

/// ω(u, v) = Σ u_q·v_p − u_p·v_q for vectors (q, p) of T*ℝᵈ.
fn omega(u: &[f64], v: &[f64]) -> f64 {
    let d = u.len() / 2;
    (0..d).map(|i| u[i] * v[d + i] - u[d + i] * v[i]).sum()
}

/// The derivative d/dε map(curve(ε)) at 0 by the fourth-order central difference with step δ.
fn derivative(map: &dyn Fn(f64) -> Vec<f64>, delta: f64) -> Vec<f64> {
    let (a, b, c, d) = (map(delta), map(-delta), map(2.0 * delta), map(-2.0 * delta));
    (0..a.len())
        .map(|i| (8.0 * (a[i] - b[i]) - (c[i] - d[i])) / (12.0 * delta))
        .collect()
}

/// max_{a,b} |ω(J v_a, J v_b) − ω(v_a, v_b)| for the images J v of the vectors v.
fn symplectic_defect(vs: &[Vec<f64>], jvs: &[Vec<f64>]) -> f64 {
    let mut defect = 0.0f64;
    for a in 0..vs.len() {
        for b in 0..vs.len() {
            defect = defect.max((omega(&jvs[a], &jvs[b]) - omega(&vs[a], &vs[b])).abs());
        }
    }
    defect
}

/// The defect of JᵀΩJ = Ω for the one-step map of `m` at z (a canonical problem on T*ℝᵈ).
fn canonical_defect<P: Problem, M: Integrator<P>>(p: &P, m: &M, z: &[f64], h: f64) -> f64 {
    let n = z.len();
    let basis: Vec<Vec<f64>> = (0..n)
        .map(|j| (0..n).map(|i| f64::from(u8::from(i == j))).collect())
        .collect();
    let images: Vec<Vec<f64>> = basis
        .iter()
        .map(|e| {
            let map = |eps: f64| {
                let zz: Vec<f64> = z.iter().zip(e).map(|(x, v)| x + eps * v).collect();
                run(p, m, &zz, h, 1)
            };
            derivative(&map, 1e-3)
        })
        .collect();
    symplectic_defect(&basis, &images)
}

/// Forward n steps, momenta negated, forward n steps, momenta negated: the distance to z0.
fn reversibility<P: Problem, M: Integrator<P>>(p: &P, m: &M, z0: &[f64], h: f64, n: usize) -> f64 {
    let d = z0.len() / 2;
    let mut z = run(p, m, z0, h, n);
    z[d..].iter_mut().for_each(|x| *x = -*x);
    let mut z = run(p, m, &z, h, n);
    z[d..].iter_mut().for_each(|x| *x = -*x);
    dist(&z, z0) / norm(z0)
}

/// max |E − E₀| over the saved states, and the maxima over the first and the last tenth.
fn energy_errors<P: Problem>(p: &P, states: &[Vec<f64>]) -> (f64, f64, f64) {
    let e0 = p.energy(&states[0]).unwrap();
    let err: Vec<f64> = states
        .iter()
        .map(|z| (p.energy(z).unwrap() - e0).abs())
        .collect();
    let tenth = err.len() / 10;
    let max = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(*x));
    (
        max(&err),
        max(&err[..tenth]),
        max(&err[err.len() - tenth..]),
    )
}

// ---------------------------------------------------------------------------------------------
// A two-degree-of-freedom canonical test problem

/// The Hénon–Heiles system H = ½|p|² + ½|q|² + q₁²q₂ − q₂³/3 (bounded motion for H < 1/6).
#[derive(Clone)]
struct HenonHeiles;

impl Problem for HenonHeiles {
    fn name(&self) -> &'static str {
        "HenonHeiles"
    }
    fn space(&self) -> Space {
        Space::new([("q", Block::Real(2)), ("p", Block::Real(2))])
    }
    fn energy(&self, z: &[f64]) -> lieflow::Result<f64> {
        Ok(self.hamiltonian(&z[..2], &z[2..]))
    }
    fn invariants(&self, _z: &[f64]) -> lieflow::Result<Vec<f64>> {
        Ok(Vec::new())
    }
    fn invariant_names(&self) -> Vec<String> {
        Vec::new()
    }
}

impl Canonical for HenonHeiles {
    fn dof(&self) -> usize {
        2
    }
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        0.5 * (p[0] * p[0] + p[1] * p[1] + q[0] * q[0] + q[1] * q[1]) + q[0] * q[0] * q[1]
            - q[1].powi(3) / 3.0
    }
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        hq[0] = q[0] + 2.0 * q[0] * q[1];
        hq[1] = q[1] + q[0] * q[0] - q[1] * q[1];
        hp.copy_from_slice(p);
    }
}

impl Separable for HenonHeiles {
    type Scratch = ();
    fn scratch(&self) {}
    fn dof(&self) -> usize {
        2
    }
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        v.copy_from_slice(p);
    }
    fn force(&self, q: &[f64], f: &mut [f64], _s: &mut ()) -> std::result::Result<(), Violation> {
        f[0] = -(q[0] + 2.0 * q[0] * q[1]);
        f[1] = -(q[1] + q[0] * q[0] - q[1] * q[1]);
        Ok(())
    }
}

impl VectorField for HenonHeiles {
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        dz[..2].copy_from_slice(&z[2..]);
        dz[2] = -(z[0] + 2.0 * z[0] * z[1]);
        dz[3] = -(z[1] + z[0] * z[0] - z[1] * z[1]);
    }
}

const HH0: [f64; 4] = [0.1, -0.2, 0.3, 0.25];

fn pendulum() -> Pendulum {
    Pendulum::new(1.3, 0.8, 9.81).unwrap()
}

const AMPLITUDE: f64 = 2.0;

// ---------------------------------------------------------------------------------------------
// Gauss–Legendre

#[test]
fn pendulum_exact_solution_solves_the_equations() {
    let pend = pendulum();
    let t = 0.37;
    let z = pend.exact(AMPLITUDE, t).unwrap();
    let eps = 1e-5;
    let (a, b) = (
        pend.exact(AMPLITUDE, t + eps).unwrap(),
        pend.exact(AMPLITUDE, t - eps).unwrap(),
    );
    let mut f = [0.0; 2];
    pend.field(&z, &mut f);
    for i in 0..2 {
        let fd = (a[i] - b[i]) / (2.0 * eps);
        assert!(
            (fd - f[i]).abs() < 1e-7 * f[i].abs().max(1.0),
            "{fd} vs {}",
            f[i]
        );
    }
    let z0 = [AMPLITUDE, 0.0];
    assert_eq!(pend.exact(AMPLITUDE, 0.0).unwrap()[0], AMPLITUDE);
    assert!((pend.energy(&z).unwrap() - pend.energy(&z0).unwrap()).abs() < 1e-13);
    assert!(pend.exact(3.2, 1.0).is_err());
}

#[test]
fn gauss_observed_orders_on_the_pendulum() {
    let pend = pendulum();
    let t_end = 3.0;
    let exact = pend.exact(AMPLITUDE, t_end).unwrap();
    let z0 = [AMPLITUDE, 0.0];
    for (s, dt) in [(1, 0.02), (2, 0.1), (3, 0.2)] {
        let (e, o) = orders(&pend, &Gauss(s), &z0, t_end, dt, &exact);
        assert_order(&format!("Gauss({s}) pendulum"), e, o, 2.0 * s as f64);
    }
    let (e, o) = orders(&pend, &Verlet::strang(), &z0, t_end, 0.02, &exact);
    assert_order("Verlet pendulum", e, o, 2.0);
    let (e, o) = orders(&pend, &Rk4, &z0, t_end, 0.02, &exact);
    assert_order("RK4 pendulum", e, o, 4.0);
}

#[test]
fn gauss_observed_orders_on_henon_heiles() {
    let hh = HenonHeiles;
    let t_end = 5.0;
    let exact = run(&hh, &Gauss(3), &HH0, 1e-3, 5000);
    for (s, dt) in [(1, 0.05), (2, 0.2), (3, 0.25)] {
        let (e, o) = orders(&hh, &Gauss(s), &HH0, t_end, dt, &exact);
        assert_order(&format!("Gauss({s}) Hénon–Heiles"), e, o, 2.0 * s as f64);
    }
}

#[test]
fn catalogued_pendulum_methods() {
    let pend = pendulum();
    let names: Vec<_> = pend.methods().iter().map(|(n, _)| *n).collect();
    assert_eq!(names, ["midpoint", "gauss4", "gauss6", "verlet", "rk4"]);
    let exact = pend.exact(AMPLITUDE, 1.0).unwrap();
    for (name, tol) in [
        ("midpoint", 1e-3),
        ("gauss4", 1e-7),
        ("gauss6", 1e-11),
        ("verlet", 1e-3),
        ("rk4", 1e-6),
    ] {
        let z = integrate(&pend, name, &[AMPLITUDE, 0.0], 0.01, 100, 100)
            .unwrap()
            .final_state;
        assert!(dist(&z, &exact) < tol, "{name}: {}", dist(&z, &exact));
    }
    assert_eq!(
        <Gauss as Integrator<Pendulum>>::properties(&Gauss(3)),
        lieflow::integrate::Properties::geometric(6)
    );
    assert_eq!(IMPLICIT_MIDPOINT, Gauss(1));
}

#[test]
fn symplecticity_of_gauss_and_verlet() {
    let hh = HenonHeiles;
    let h = 0.1;
    for s in 1..=3 {
        let d = canonical_defect(&hh, &Gauss(s), &HH0, h);
        eprintln!("symplecticity defect Gauss({s}) Hénon–Heiles: {d:.2e}");
        assert!(d < 1e-10, "Gauss({s}): {d:e}");
    }
    let d = canonical_defect(&hh, &Verlet::strang(), &HH0, h);
    eprintln!("symplecticity defect Verlet Hénon–Heiles: {d:.2e}");
    assert!(d < 1e-10, "Verlet: {d:e}");
    // The test sees a non-symplectic method.
    let d = canonical_defect(&hh, &Rk4, &HH0, h);
    eprintln!("symplecticity defect RK4 Hénon–Heiles (control): {d:.2e}");
    assert!(d > 1e-8, "RK4: {d:e}");
    // One degree of freedom: area preservation, det J = 1, at a large amplitude and step.
    let pend = pendulum();
    for s in 1..=3 {
        let d = canonical_defect(&pend, &Gauss(s), &[2.5, 1.0], 0.2);
        eprintln!("symplecticity defect Gauss({s}) pendulum (det J − 1): {d:.2e}");
        assert!(d < 1e-10, "Gauss({s}) pendulum: {d:e}");
    }
    let d = canonical_defect(&pend, &Rk4, &[2.5, 1.0], 0.2);
    assert!(d > 1e-6, "RK4 pendulum: {d:e}");
}

#[test]
fn gauss_is_reversible() {
    let (pend, hh) = (pendulum(), HenonHeiles);
    for s in 1..=3 {
        for n in [1, 100] {
            let r1 = reversibility(&pend, &Gauss(s), &[2.5, 1.0], 0.1, n);
            let r2 = reversibility(&hh, &Gauss(s), &HH0, 0.1, n);
            eprintln!(
                "reversibility Gauss({s}), {n} steps: pendulum {r1:.2e}, Hénon–Heiles {r2:.2e}"
            );
            assert!(r1 < 1e-13 && r2 < 1e-13, "Gauss({s}): {r1:e} {r2:e}");
        }
    }
    // The test sees a non-symmetric method.
    let r = reversibility(&hh, &Rk4, &HH0, 0.1, 100);
    assert!(r > 1e-8, "RK4: {r:e}");
}

#[test]
fn gauss_energy_stays_bounded_over_1e5_steps() {
    let pend = pendulum();
    let hh = HenonHeiles;
    for s in 1..=3 {
        let h = 0.05 * s as f64;
        let states = trajectory(&pend, &Gauss(s), &[AMPLITUDE, 0.0], h, 100_000, 100);
        let (max, first, last) = energy_errors(&pend, &states);
        let e0 = pend.energy(&states[0]).unwrap().abs();
        eprintln!(
            "energy Gauss({s}) pendulum, h = {h:.2}, 1e5 steps: max |ΔE|/|E| {:.2e}, first tenth \
             {:.2e}, last tenth {:.2e}",
            max / e0,
            first / e0,
            last / e0
        );
        assert!(
            last <= 2.0 * first + 1e-13 * e0,
            "drift: {first:e} → {last:e}"
        );
        let states = trajectory(&hh, &Gauss(s), &HH0, 0.1, 100_000, 100);
        let (max, first, last) = energy_errors(&hh, &states);
        let e0 = hh.energy(&HH0).unwrap();
        eprintln!(
            "energy Gauss({s}) Hénon–Heiles, h = 0.1, 1e5 steps: max |ΔE|/E {:.2e}, first tenth \
             {:.2e}, last tenth {:.2e}",
            max / e0,
            first / e0,
            last / e0
        );
        assert!(
            last <= 2.0 * first + 1e-13 * e0,
            "drift: {first:e} → {last:e}"
        );
    }
}

#[test]
fn gauss6_energy_error_stays_at_round_off() {
    // h = 0.02: the truncation error of Gauss(3) (~1e-17) is below round-off, so what remains is
    // rounding; iterating the stage equations to round-off and the compensated update keep it
    // from drifting.
    let hh = HenonHeiles;
    let states = trajectory(&hh, &Gauss(3), &HH0, 0.02, 100_000, 100);
    let (max, first, last) = energy_errors(&hh, &states);
    let e0 = hh.energy(&HH0).unwrap();
    eprintln!(
        "energy Gauss(3) Hénon–Heiles, h = 0.02, 1e5 steps (round-off regime): max |ΔE|/E \
         {:.2e}, first tenth {:.2e}, last tenth {:.2e}",
        max / e0,
        first / e0,
        last / e0
    );
    assert!(max < 2e-14 * e0, "{max:e}");
}

#[test]
fn gauss_errors() {
    let pend = pendulum();
    for s in [0, 4] {
        let e = integrate_with(&pend, &Gauss(s), &[1.0, 0.0], 0.1, 1, 1).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument { .. }), "{e}");
    }
    // A step far beyond the period: the stage equations have no nearby solution.
    let e = integrate_with(&pend, &Gauss(2), &[3.0, 20.0], 50.0, 3, 1).unwrap_err();
    match &e {
        Error::NotConverged { what, .. } => {
            assert!(
                what.contains("in step") && what.contains("reduce dt"),
                "{e}"
            )
        }
        _ => panic!("expected NotConverged, got {e}"),
    }
    eprintln!("Gauss non-convergence: {e}");
}

// ---------------------------------------------------------------------------------------------
// RATTLE

fn particle() -> SphereParticle {
    SphereParticle::new(0.7, 1.3, 9.81).unwrap()
}

fn spherical() -> SphericalPendulum {
    SphericalPendulum::new(0.7, 1.3, 9.81).unwrap()
}

fn particle_state() -> Vec<f64> {
    let z = spherical()
        .state_from_spherical(1.1, 0.3, 0.4, 1.7)
        .unwrap();
    particle().from_spherical(&z).unwrap()
}

/// (| |q| − l |/l, |q·p|/(l|p|)).
fn sphere_residuals(z: &[f64], l: f64) -> (f64, f64) {
    let q = &z[..3];
    let p = &z[3..];
    let qp: f64 = (0..3).map(|i| q[i] * p[i]).sum();
    ((norm(q) - l).abs() / l, qp.abs() / (l * norm(p)))
}

#[test]
fn rattle_agrees_with_the_spherical_pendulum_and_has_order_2() {
    let (part, sph) = (particle(), spherical());
    let z0 = particle_state();
    let u0 = part.to_spherical(&z0).unwrap();
    assert!(dist(&part.from_spherical(&u0).unwrap(), &z0) < 1e-14);
    assert!((part.energy(&z0).unwrap() - sph.energy(&u0).unwrap()).abs() < 1e-12);
    let t_end = 2.0;
    let reference = integrate(&sph, "splitting6", &u0, 1e-3, 2000, 2000)
        .unwrap()
        .final_state;
    let exact = part.from_spherical(&reference).unwrap();
    let (e, o) = orders(&part, &Rattle::new(), &z0, t_end, 0.02, &exact);
    assert_order("RATTLE sphere particle", e, o, 2.0);
    // Through the catalog, in the spherical pendulum's coordinates.
    let z = integrate(&part, "rattle", &z0, 0.005, 400, 400)
        .unwrap()
        .final_state;
    let err = dist(&part.to_spherical(&z).unwrap(), &reference);
    eprintln!("RATTLE vs SphericalPendulum (u, L) at t = 2, h = 0.005: {err:.2e}");
    assert!(err < 1e-3, "{err:e}");
}

#[test]
fn rattle_keeps_constraints_momentum_and_energy_over_1e5_steps() {
    let part = particle();
    let z0 = particle_state();
    let states = trajectory(&part, &Rattle::new(), &z0, 0.02, 100_000, 1);
    let (mut rq, mut rp, mut rl) = (0.0f64, 0.0f64, 0.0f64);
    let l0 = part.invariants(&z0).unwrap()[0];
    for z in &states[1..] {
        let (a, b) = sphere_residuals(z, 1.3);
        rq = rq.max(a);
        rp = rp.max(b);
        rl = rl.max((part.invariants(z).unwrap()[0] - l0).abs() / l0.abs());
    }
    eprintln!(
        "RATTLE 1e5 steps: max | |q| − l |/l {rq:.2e}, max |q·p|/(l|p|) {rp:.2e}, max relative \
         drift of (q × p)₃ {rl:.2e}"
    );
    assert!(
        rq < 1e-15 && rp < 1e-14 && rl < 1e-11,
        "{rq:e} {rp:e} {rl:e}"
    );
    let (max, first, last) = energy_errors(&part, &states);
    let e0 = part.energy(&z0).unwrap().abs();
    eprintln!(
        "energy RATTLE, h = 0.02, 1e5 steps: max |ΔE|/|E| {:.2e}, first tenth {:.2e}, last tenth \
         {:.2e}",
        max / e0,
        first / e0,
        last / e0
    );
    assert!(
        max < 1e-2 * e0 && last <= 2.0 * first,
        "{first:e} → {last:e}"
    );
}

#[test]
fn rattle_is_symplectic_on_the_constrained_phase_space() {
    let part = particle();
    let (z, l) = (particle_state(), 1.3);
    let (q, p) = (
        Vector3::from_column_slice(&z[..3]),
        Vector3::from_column_slice(&z[3..]),
    );
    // An orthonormal basis e1, e2 of the tangent plane q⊥.
    let e1 = q.cross(&Vector3::z()).normalize();
    let e2 = q.cross(&e1).normalize();
    let tangent = |dq: Vector3<f64>, dp: Vector3<f64>| -> Vec<f64> {
        [dq.as_slice(), dp.as_slice()].concat()
    };
    // Tangent vectors to {|q| = l, q·p = 0}: q·δq = 0 and δq·p + q·δp = 0.
    let vs = [
        tangent(e1, -q * (e1.dot(&p) / (l * l))),
        tangent(e2, -q * (e2.dot(&p) / (l * l))),
        tangent(Vector3::zeros(), e1),
        tangent(Vector3::zeros(), e2),
    ];
    // A curve on the manifold through z with velocity v: radial projection of q, then of p.
    let on_manifold = |v: &[f64], eps: f64| -> Vec<f64> {
        let qe = (q + Vector3::from_column_slice(&v[..3]) * eps).normalize() * l;
        let pe = p + Vector3::from_column_slice(&v[3..]) * eps;
        let pe = pe - qe * (qe.dot(&pe) / (l * l));
        [qe.as_slice(), pe.as_slice()].concat()
    };
    for h in [0.05, 0.2] {
        let images: Vec<Vec<f64>> = vs
            .iter()
            .map(|v| {
                derivative(
                    &|eps| run(&part, &Rattle::new(), &on_manifold(v, eps), h, 1),
                    1e-3,
                )
            })
            .collect();
        let d = symplectic_defect(&vs, &images);
        eprintln!("symplecticity defect RATTLE on T*S², h = {h}: {d:.2e}");
        assert!(d < 1e-10, "{d:e}");
    }
}

#[test]
fn rattle_is_reversible() {
    let part = particle();
    let z0 = particle_state();
    for n in [1, 100] {
        let r = reversibility(&part, &Rattle::new(), &z0, 0.05, n);
        eprintln!("reversibility RATTLE, {n} steps: {r:.2e}");
        assert!(r < 1e-13, "{r:e}");
    }
}

#[test]
fn sphere_particle_checks_states() {
    let part = particle();
    let mut z = particle_state();
    assert!(lieflow::integrate::check_state(&part, &z).is_ok());
    z[0] += 1e-6;
    let e = integrate(&part, "rattle", &z, 0.01, 1, 1).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { .. }), "{e}");
    let mut z = particle_state();
    z[3] += 1e-3;
    assert!(lieflow::integrate::check_state(&part, &z).is_err());
}

// ---------------------------------------------------------------------------------------------
// The nonholonomic RATTLE on the vertical rolling disk

fn disk() -> RollingDisk {
    RollingDisk::new(1.2, 0.4, 0.1, 0.05).unwrap()
}

fn loaded_disk() -> RollingDisk {
    disk().with_potential(0.3, 0.8).unwrap()
}

fn disk_state(d: &RollingDisk) -> Vec<f64> {
    d.state([0.1, -0.3, 0.2, 0.5], 2.0, 1.5).unwrap()
}

/// The reduced equations of the loaded disk (module docs of `rolling_disk`), integrated by
/// classical RK4 with `steps` steps to t: an independent reference.
fn disk_reference(z0: &[f64], t: f64, steps: usize) -> Vec<f64> {
    let (m, r, i, j, k, g) = (1.2, 0.4, 0.1, 0.05, 0.3, 0.8);
    let f = |y: &[f64; 6]| -> [f64; 6] {
        let (s, c) = y[3].sin_cos();
        [
            r * c * y[4],
            r * s * y[4],
            y[4],
            y[5],
            -m * g * r * c / (i + m * r * r),
            -k / j * y[3].sin(),
        ]
    };
    let mut y = [z0[0], z0[1], z0[2], z0[3], z0[6] / i, z0[7] / j];
    let h = t / steps as f64;
    for _ in 0..steps {
        let k1 = f(&y);
        let k2 = f(&std::array::from_fn(|a| y[a] + 0.5 * h * k1[a]));
        let k3 = f(&std::array::from_fn(|a| y[a] + 0.5 * h * k2[a]));
        let k4 = f(&std::array::from_fn(|a| y[a] + h * k3[a]));
        for a in 0..6 {
            y[a] += h / 6.0 * (k1[a] + 2.0 * (k2[a] + k3[a]) + k4[a]);
        }
    }
    loaded_disk()
        .state([y[0], y[1], y[2], y[3]], y[4], y[5])
        .unwrap()
}

#[test]
fn rolling_disk_without_potential_against_the_exact_solution() {
    let d = disk();
    let z0 = disk_state(&d);
    let t_end = 4.0;
    let exact = d.exact(&z0, t_end).unwrap();
    let (e, o) = orders(&d, &NonholonomicRattle, &z0, t_end, 0.05, &exact);
    assert_order("nonholonomic RATTLE free disk", e, o, 2.0);
    // θ̇ and φ̇ (so the energy) are kept at every step end, and the contact points lie exactly
    // on a circle: with φ̄ the midpoint heading and γ = cos(φ̇h/2), the method's θ̇_{n+1/2} is
    // θ̇(I + mR²)/(I + mR²γ), and x_{n+1} − x_n = hR cos φ̄ θ̇_{n+1/2} is the chord of the circle
    // of radius ρ' = hRθ̇_{n+1/2}/(2 sin(φ̇h/2)) = ρ + O(h²), ρ = Rθ̇/φ̇.
    let (m, r, i, wt, wp) = (1.2, 0.4, 0.1, 2.0, 1.5);
    let h = 0.05;
    let states = trajectory(&d, &NonholonomicRattle, &z0, h, 2000, 1);
    let e0 = d.energy(&z0).unwrap();
    let half = 0.5 * wp * h;
    let wt_half = wt * (i + m * r * r) / (i + m * r * r * half.cos());
    let rho = h * r * wt_half / (2.0 * half.sin());
    let rho_exact = r * wt / wp;
    let centre = [z0[0] - rho * z0[3].sin(), z0[1] + rho * z0[3].cos()];
    let (mut de, mut dr, mut dw) = (0.0f64, 0.0f64, 0.0f64);
    for z in &states {
        de = de.max((d.energy(z).unwrap() - e0).abs() / e0);
        dr = dr.max(((z[0] - centre[0]).hypot(z[1] - centre[1]) - rho).abs() / rho);
        dw = dw.max((z[6] - z0[6]).abs() / z0[6]);
        assert_eq!(z[7], z0[7]);
    }
    eprintln!(
        "free disk, h = {h}, 2000 steps: max |ΔE|/E {de:.2e}, max relative change of θ̇ {dw:.2e}, \
         max relative distance to the discrete circle {dr:.2e} (its radius differs from Rθ̇/φ̇ by \
         {:.2e})",
        (rho - rho_exact).abs() / rho_exact
    );
    assert!(
        de < 2e-12 && dw < 1e-12 && dr < 1e-12,
        "{de:e} {dw:e} {dr:e}"
    );
    assert!(loaded_disk().exact(&z0, 1.0).is_err());
}

#[test]
fn rolling_disk_with_potential_has_order_2() {
    let d = loaded_disk();
    let z0 = disk_state(&d);
    let t_end = 3.0;
    let reference = disk_reference(&z0, t_end, 30_000);
    // The reference is exact to ~1e-13: a second RK4 run with half the step agrees.
    assert!(dist(&reference, &disk_reference(&z0, t_end, 60_000)) < 1e-12);
    let (e, o) = orders(&d, &NonholonomicRattle, &z0, t_end, 0.04, &reference);
    assert_order("nonholonomic RATTLE loaded disk", e, o, 2.0);
    let z = integrate(&d, "nonholonomic", &z0, 0.005, 600, 600)
        .unwrap()
        .final_state;
    assert!(dist(&z, &reference) < 1e-3);
}

#[test]
fn rolling_disk_constraints_over_1e5_steps() {
    let d = loaded_disk();
    let z0 = disk_state(&d);
    let states = trajectory(&d, &NonholonomicRattle, &z0, 0.01, 100_000, 1);
    let worst = states
        .iter()
        .map(|z| d.constraint_residual(z).unwrap())
        .fold(0.0f64, f64::max);
    eprintln!("loaded disk, h = 0.01, 1e5 steps: max relative constraint residual {worst:.2e}");
    assert!(worst <= 1e-14, "{worst:e}");
}

#[test]
fn rolling_disk_energy_stays_bounded_over_1e5_steps() {
    // On the tilted plane without spring, φ̇ is constant and θ̇, x, y oscillate (bounded motion:
    // ẋ = R cos φ θ̇ averages to zero); with the spring alone, φ swings like a pendulum.
    for (name, k, g) in [("tilted plane", 0.0, 0.8), ("spring", 0.3, 0.0)] {
        let d = disk().with_potential(k, g).unwrap();
        let z0 = disk_state(&d);
        let states = trajectory(&d, &NonholonomicRattle, &z0, 0.01, 100_000, 10);
        let (max, first, last) = energy_errors(&d, &states);
        let e0 = d.energy(&z0).unwrap().abs();
        eprintln!(
            "energy nonholonomic RATTLE, {name}, h = 0.01, 1e5 steps: max |ΔE|/|E| {:.2e}, first \
             tenth {:.2e}, last tenth {:.2e}",
            max / e0,
            first / e0,
            last / e0
        );
        assert!(
            max < 1e-3 * e0 && last <= 2.0 * first + 1e-13 * e0,
            "{first:e} → {last:e}"
        );
        // Without the spring the turning momentum J φ̇ is kept exactly.
        if k == 0.0 {
            assert!(states.iter().all(|z| z[7] == z0[7]));
        }
    }
}

#[test]
fn nonholonomic_rattle_is_reversible() {
    for d in [disk(), loaded_disk()] {
        let z0 = disk_state(&d);
        for n in [1, 100] {
            let r = reversibility(&d, &NonholonomicRattle, &z0, 0.05, n);
            eprintln!("reversibility nonholonomic RATTLE, {n} steps: {r:.2e}");
            assert!(r < 1e-13, "{r:e}");
        }
    }
}

#[test]
fn rolling_disk_checks_states() {
    let d = disk();
    let mut z = disk_state(&d);
    z[4] += 1e-3;
    let e = integrate(&d, "nonholonomic", &z, 0.01, 1, 1).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { .. }), "{e}");
    let props = d.methods()[0].1;
    assert!(props.symmetric && !props.symplectic && props.order == 2);
}

// ---------------------------------------------------------------------------------------------
// RKMK4

const M0: [f64; 3] = [1.0, 0.5, -0.3];

fn body() -> RigidBody {
    RigidBody::new([1.0, 2.0, 3.0]).unwrap()
}

#[test]
fn so3_dexp_inv_is_the_inverse_left_jacobian() {
    // For the left action, d/dt exp(u + t J_l⁻¹(u) v)·exp(−u) at t = 0 must be hat(v).
    let u = Vector3::new(0.4, -0.7, 0.9);
    let v = Vector3::new(0.3, 0.2, -0.5);
    let mut out = [0.0; 3];
    body().dexp_inv(u.as_slice(), v.as_slice(), &mut out, &mut ());
    let w = Vector3::from(out);
    let eps = 1e-6;
    let d = (so3::exp_unchecked(&(u + w * eps)) - so3::exp_unchecked(&(u - w * eps))) / (2.0 * eps);
    let lhs = d * so3::exp_unchecked(&u).transpose();
    assert!(
        (lhs - so3::hat(&v)).norm() < 1e-9,
        "{}",
        (lhs - so3::hat(&v)).norm()
    );
    // The right Jacobian would be the wrong one here.
    let wr = so3::jacobian_right_inv(&u).unwrap() * v;
    let d =
        (so3::exp_unchecked(&(u + wr * eps)) - so3::exp_unchecked(&(u - wr * eps))) / (2.0 * eps);
    assert!((d * so3::exp_unchecked(&u).transpose() - so3::hat(&v)).norm() > 1e-2);
}

#[test]
fn son_kernels_agree_with_lie_so() {
    let gb = GeneralizedRigidBody::new(&[0.4, 0.9, 1.3, 2.2]).unwrap();
    let mut s = gb.scratch();
    let u = [0.3, -0.2, 0.5, 0.1, -0.4, 0.25];
    let v = [0.7, 0.1, -0.3, 0.2, 0.6, -0.5];
    let mut out = [0.0; 6];
    gb.dexp_inv(&u, &v, &mut out, &mut s);
    let want = so::vee_n(&so::dexp_inv(&so::hat_n(&u).unwrap(), &so::hat_n(&v).unwrap()).unwrap())
        .unwrap();
    assert!(dist(&out, &want) < 1e-15, "{}", dist(&out, &want));
    for scale in [1.0, 10.0] {
        let xi: Vec<f64> = u.iter().map(|x| x * scale).collect();
        let mut z = v.to_vec();
        gb.act(&xi, &mut z, &mut s);
        let g = so::exp(&so::hat_n(&xi).unwrap()).unwrap();
        let want = so::vee_n(&(&g * so::hat_n(&v).unwrap() * g.transpose())).unwrap();
        assert!(dist(&z, &want) < 1e-13, "{}", dist(&z, &want));
    }
    // Beyond |u| = π/2 the kernel reports non-finite values.
    let big: Vec<f64> = u.iter().map(|x| x * 4.0).collect();
    gb.dexp_inv(&big, &v, &mut out, &mut s);
    assert!(out.iter().all(|x| x.is_nan()));
}

#[test]
fn rkmk4_has_order_4_on_the_rigid_body() {
    let b = body();
    let t_end = 5.0;
    let exact = b.exact_momentum(&M0, t_end).unwrap();
    let (e, o) = orders(&b, &Rkmk4, &M0, t_end, 0.1, &exact);
    assert_order("RKMK4 rigid body", e, o, 4.0);
    // so(4): against a fine RK4 run.
    let gb = GeneralizedRigidBody::new(&[0.4, 0.9, 1.3, 2.2]).unwrap();
    let m0 = [0.7, -0.2, 0.4, 0.5, -0.6, 0.3];
    let reference = run(&gb, &Rk4, &m0, 1e-4, 50_000);
    let (e, o) = orders(&gb, &Rkmk4, &m0, t_end, 0.1, &reference);
    assert_order("RKMK4 so(4) body", e, o, 4.0);
}

#[test]
fn rkmk4_on_so3_and_on_son_with_n_3_agree() {
    // J_i + J_j = I_k for {i, j, k} = {1, 2, 3}: J = (I₂ + I₃ − I₁, I₁ + I₃ − I₂, I₁ + I₂ − I₃)/2,
    // and the e_ij coordinates of hat(M) are (−M₃, M₂, −M₁).
    let b = body();
    let gb = GeneralizedRigidBody::new(&[2.0, 1.0, 0.0]).unwrap();
    let c0 = [-M0[2], M0[1], -M0[0]];
    let m = run(&b, &Rkmk4, &M0, 0.1, 50);
    let c = run(&gb, &Rkmk4, &c0, 0.1, 50);
    let err = dist(&[-c[2], c[1], -c[0]], &m);
    assert!(err < 1e-14, "{err:e}");
}

#[test]
fn rkmk4_keeps_the_orbit_over_1e4_steps() {
    let b = body();
    let states = trajectory(&b, &Rkmk4, &M0, 0.05, 10_000, 10);
    let c0 = norm(&M0).powi(2);
    let drift = states
        .iter()
        .map(|z| (norm(z).powi(2) - c0).abs() / c0)
        .fold(0.0f64, f64::max);
    let (_, _, last) = energy_errors(&b, &states);
    eprintln!(
        "RKMK4 rigid body, h = 0.05, 1e4 steps: max relative drift of |M|² {drift:.2e}; energy \
         error in the last tenth {last:.2e}"
    );
    assert!(drift < 1e-13, "{drift:e}");
    // The lifted body: R ∈ SO(3) and the spatial momentum R M, through the catalog.
    let lifted = b.with_attitude();
    let r0 = so3::exp_unchecked(&Vector3::new(0.3, -0.5, 0.2));
    let mut z0 = M0.to_vec();
    for i in 0..3 {
        for j in 0..3 {
            z0.push(r0[(i, j)]);
        }
    }
    let traj = integrate(&lifted, "rkmk4", &z0, 0.05, 10_000, 10).unwrap();
    let s0 = RigidBody::spatial_momentum(&z0).unwrap();
    let (mut dr, mut ds) = (0.0f64, 0.0f64);
    for k in 0..traj.len() {
        let z = traj.state(k);
        let r = Matrix3::from_row_slice(&z[3..]);
        dr = dr.max((r.transpose() * r - Matrix3::identity()).norm());
        let s = RigidBody::spatial_momentum(z).unwrap();
        ds = ds.max(dist(&s, &s0) / norm(&s0));
    }
    eprintln!(
        "RKMK4 lifted rigid body, 1e4 steps: max ‖RᵀR − I‖ {dr:.2e}, max relative drift of R M \
         {ds:.2e}"
    );
    assert!(dr < 1e-13 && ds < 1e-13, "{dr:e} {ds:e}");
    // so(4): the spectrum (C₁, C₂).
    let gb = GeneralizedRigidBody::new(&[0.4, 0.9, 1.3, 2.2]).unwrap();
    let m0 = [0.7, -0.2, 0.4, 0.5, -0.6, 0.3];
    let traj = integrate(&gb, "rkmk4", &m0, 0.05, 10_000, 10).unwrap();
    let i0 = gb.invariants(&m0).unwrap();
    let mut dc = 0.0f64;
    for k in 0..traj.len() {
        let c = gb.invariants(traj.state(k)).unwrap();
        for (a, b) in c.iter().zip(&i0) {
            dc = dc.max((a - b).abs() / b.abs());
        }
    }
    eprintln!("RKMK4 so(4) body, h = 0.05, 1e4 steps: max relative drift of C₁, C₂ {dc:.2e}");
    assert!(dc < 1e-13, "{dc:e}");
}

#[test]
fn rkmk4_catalog_entries_and_errors() {
    let b = body();
    let names: Vec<_> = b.methods().iter().map(|(n, _)| *n).collect();
    assert!(names.contains(&"rkmk4"));
    let gb = GeneralizedRigidBody::from_matrix(&Mat::from_fn(4, 4, |i, j| {
        if i == j {
            1.0 + i as f64
        } else {
            0.1
        }
    }))
    .unwrap();
    let (name, props) = *gb.methods().last().unwrap();
    assert_eq!(name, "rkmk4");
    assert!(props.invariants && props.manifold && !props.symplectic && props.order == 4);
    // A user frame (non-diagonal J): RKMK4 and the isospectral midpoint agree to O(h²).
    let m0 = [0.7, -0.2, 0.4, 0.5, -0.6, 0.3];
    let a = integrate(&gb, "rkmk4", &m0, 0.01, 100, 100)
        .unwrap()
        .final_state;
    let c = integrate(&gb, "isospectral", &m0, 0.01, 100, 100)
        .unwrap()
        .final_state;
    assert!(dist(&a, &c) < 1e-4, "{}", dist(&a, &c));
    // A step so large that |u| ≥ π/2 in so(4): a typed error naming the step.
    let e = integrate(&gb, "rkmk4", &m0, 10.0, 5, 1).unwrap_err();
    match &e {
        Error::LeftDomain { message, .. } => assert!(message.contains("step 1"), "{e}"),
        _ => panic!("expected LeftDomain, got {e}"),
    }
}
