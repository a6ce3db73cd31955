//! The incompressible pseudo-rigid body (det X = det X₀, the pressure as multiplier) integrated by
//! RATTLE and its symmetric compositions (`rattle`, `rattle4`, `rattle6`): the volume and the
//! hidden constraint ⟨cof X, P⟩ = 0 to round-off, L and Γ to round-off (equivariance), bounded
//! energy error, the observed orders 2, 4, 6; the constraint kernels (cof X, D² det) against
//! finite differences; the index-1 constrained field against RATTLE trajectories and the exact
//! centripetal force of the particle on a sphere; the compressible body unchanged. Measured values
//! are printed (run with `--nocapture`).

use std::sync::Arc;

use faer::linalg::solvers::DenseSolveCore;
use lieflow::integrate::methods::rattle::{constrained_field, constrained_field_into, FieldWork};
use lieflow::integrate::methods::{Composition, Rattle, Splitting, Verlet};
use lieflow::integrate::problem::{Constrained, Separable};
use lieflow::integrate::{check_state, integrate, integrate_with, Problem, System};
use lieflow::pseudo_rigid::potential::{Harmonic, Potential, SaintVenantKirchhoff};
use lieflow::pseudo_rigid::PseudoRigidBody;
use lieflow::systems::{SphereParticle, SphericalPendulum};
use lieflow::{Error, Mat};

mod common;
use common::distance as dist;

// ---------------------------------------------------------------------------------------------
// Helpers

/// A deterministic generator of values in [−1, 1) (xorshift64*).
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }

    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        2.0 * (u as f64 / (1u64 << 53) as f64) - 1.0
    }

    fn mat(&mut self, n: usize, scale: f64) -> Mat {
        Mat::from_fn(n, n, |_, _| scale * self.next())
    }
}

fn svk() -> Arc<dyn Potential> {
    Arc::new(SaintVenantKirchhoff::new(1.0, 2.0).unwrap())
}

fn harmonic() -> Arc<dyn Potential> {
    Arc::new(Harmonic::new(1.5).unwrap())
}

/// A non-trivial state of the incompressible body: X₀ = diag(1.4, 1.15, 0.9, …) + a random
/// perturbation (det X₀ ≠ 1), P₀ random, projected onto ⟨cof X₀, P₀⟩ = 0.
fn state(body: &PseudoRigidBody, seed: u64, p_scale: f64) -> Vec<f64> {
    let n = body.n();
    let mut rng = Rng::new(seed);
    let x = Mat::from_fn(
        n,
        n,
        |i, j| if i == j { 1.4 - 0.25 * i as f64 } else { 0.0 },
    ) + rng.mat(n, 0.15);
    let p = body.project_momentum(&x, &rng.mat(n, p_scale)).unwrap();
    body.state(&x, &p).unwrap()
}

fn norm(a: &[f64]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn mat_dist(a: &Mat, b: &Mat) -> f64 {
    (a - b).norm_l2()
}

/// det X, and |⟨cof X, P⟩|/(‖cof X‖‖P‖) with cof X = det(X) X⁻ᵀ (an independent route: faer's
/// determinant and inverse).
fn volume_and_rate(body: &PseudoRigidBody, z: &[f64]) -> (f64, f64) {
    let (x, p) = body.split(z).unwrap();
    let d = x.determinant();
    let cof = x.partial_piv_lu().inverse().transpose().to_owned() * faer::Scale(d);
    let inner: f64 = (0..x.nrows())
        .flat_map(|i| (0..x.nrows()).map(move |j| (i, j)))
        .map(|(i, j)| cof[(i, j)] * p[(i, j)])
        .sum();
    (d, inner.abs() / (cof.norm_l2() * p.norm_l2()))
}

// ---------------------------------------------------------------------------------------------
// The body, its catalog and its states

#[test]
fn the_incompressible_body_has_its_catalog_and_claims() {
    let body = PseudoRigidBody::incompressible(3, svk()).unwrap();
    assert!(body.is_incompressible() && body.check_det());
    assert_eq!(body.constraints(), 1);
    assert!(body.level_set());
    let methods = body.methods();
    let names: Vec<&str> = methods.iter().map(|m| m.0).collect();
    assert_eq!(names, ["rattle", "rattle4", "rattle6"]);
    for ((_, p), order) in methods.iter().zip([2, 4, 6]) {
        assert_eq!(p.order, order);
        assert!(p.symplectic && p.symmetric && p.invariants && p.manifold);
    }
    // Verlet and the reduced flows would ignore the constraint: not offered.
    for m in ["verlet", "verlet4", "reduced"] {
        let z0 = state(&body, 7, 0.5);
        let e = integrate(&body, m, &z0, 0.01, 1, 1).unwrap_err();
        assert!(matches!(e, Error::UnsupportedMethod { .. }), "{e}");
    }
    // The default is the first entry, `rattle`.
    assert_eq!(body.invariant_count(), 2 + 1);
    let z0 = state(&body, 7, 0.5);
    let inv = body.invariants(&z0).unwrap();
    assert_eq!(inv.len(), 3);
    let (d0, _) = volume_and_rate(&body, &z0);
    assert!((inv[2] - d0).abs() < 1e-14 * d0);
    // Compositions and Rattle as values.
    assert_eq!(Rattle::new(), Rattle(Composition::strang()));
    assert_eq!(Rattle::default(), Rattle::new());
}

#[test]
fn the_compressible_body_is_unchanged() {
    for n in [2, 3, 4] {
        let body = PseudoRigidBody::new(n, svk(), true).unwrap();
        assert!(!body.is_incompressible());
        assert_eq!(body.constraints(), 0);
        assert!(!body.level_set());
        assert_eq!(body.invariant_count(), 2 * (n / 2));
        let names: Vec<&str> = body.methods().iter().map(|m| m.0).collect();
        assert_eq!(names, ["verlet", "verlet4", "verlet6", "reduced"]);
        // The same results as the methods taken as values (bit for bit), and a momentum that
        // does not keep the volume is fine.
        let mut rng = Rng::new(11 + n as u64);
        let x = Mat::from_fn(
            n,
            n,
            |i, j| if i == j { 1.6 - 0.35 * i as f64 } else { 0.0 },
        ) + rng.mat(n, 0.05);
        let p = rng.mat(n, 0.2);
        let z0 = body.state(&x, &p).unwrap();
        check_state(&body, &z0).unwrap();
        let by_name = |m: &str| integrate(&body, m, &z0, 0.01, 50, 50).unwrap().final_state;
        let with = |m: &dyn lieflow::integrate::Integrator<PseudoRigidBody>| {
            integrate_with(&body, m, &z0, 0.01, 50, 50)
                .unwrap()
                .final_state
        };
        assert_eq!(by_name("verlet"), with(&Verlet::strang()));
        assert_eq!(by_name("verlet4"), with(&Verlet(Composition::suzuki4())));
        assert_eq!(by_name("verlet6"), with(&Verlet(Composition::yoshida6())));
        if n == 3 {
            assert_eq!(by_name("reduced"), with(&Splitting::strang()));
        }
        // RATTLE with no constraint (m = 0) is Störmer–Verlet (up to round-off: the drift is
        // formed through the velocity).
        let r = with(&Rattle::new());
        let v = with(&Verlet::strang());
        assert!(dist(&r, &v) < 1e-12 * norm(&v), "{:e}", dist(&r, &v));
    }
}

#[test]
fn states_must_keep_the_volume_to_be_integrated() {
    let body = PseudoRigidBody::incompressible(3, harmonic()).unwrap();
    let mut rng = Rng::new(3);
    let x = Mat::from_fn(3, 3, |i, j| if i == j { 1.2 } else { 0.0 }) + rng.mat(3, 0.2);
    let p = rng.mat(3, 0.5);
    let z = body.state(&x, &p).unwrap();
    let e = integrate(&body, "rattle", &z, 0.01, 1, 1).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { .. }), "{e}");
    let msg = e.to_string();
    eprintln!("unprojected momentum: {msg}");
    assert!(
        msg.contains("⟨cof X, P⟩") && msg.contains("project_momentum"),
        "{msg}"
    );
    // Projected: accepted, and the projection is orthogonal (P − P' ∥ cof X) and idempotent.
    let pp = body.project_momentum(&x, &p).unwrap();
    let zp = body.state(&x, &pp).unwrap();
    check_state(&body, &zp).unwrap();
    let (_, rate) = volume_and_rate(&body, &zp);
    assert!(rate < 1e-15, "{rate:e}");
    let again = body.project_momentum(&x, &pp).unwrap();
    assert!(mat_dist(&again, &pp) < 1e-15 * pp.norm_l2());
    let cof = x.partial_piv_lu().inverse().transpose().to_owned();
    let diff = &p - &pp;
    let k = diff[(0, 0)] / cof[(0, 0)];
    assert!(mat_dist(&diff, &(&cof * faer::Scale(k))) < 1e-14 * diff.norm_l2());
    // P = 0 is a state (at rest), and a state just inside the tolerance is accepted.
    check_state(&body, &body.state(&x, &Mat::zeros(3, 3)).unwrap()).unwrap();
    // det X ≤ 0 is refused as for the compressible body (check_det is on).
    let flip = Mat::from_fn(3, 3, |i, j| {
        if i == j {
            1.0 - 2.0 * f64::from(u8::from(i == 0))
        } else {
            0.0
        }
    });
    let zf = body.state(&flip, &Mat::zeros(3, 3)).unwrap();
    assert!(matches!(
        check_state(&body, &zf).unwrap_err(),
        Error::NotInGroup { .. }
    ));
    assert!(body.project_momentum(&flip, &p).is_err());
    // At extreme scales the projection and the check still hold (cof X scaled to unit size).
    for s in [1e-120, 1e150] {
        let xs = &x * faer::Scale(s);
        let ps = body.project_momentum(&xs, &(&p * faer::Scale(s))).unwrap();
        let zs = body.state(&xs, &ps).unwrap();
        check_state(&body, &zs).unwrap();
        assert!(mat_dist(&(&ps * faer::Scale(1.0 / s)), &pp) < 1e-14 * pp.norm_l2());
    }
    // The compressible body does not ask for it.
    let free = PseudoRigidBody::new(3, harmonic(), true).unwrap();
    check_state(&free, &z).unwrap();
}

// ---------------------------------------------------------------------------------------------
// Long runs: volume, hidden constraint, momenta, energy

#[test]
fn rattle4_keeps_volume_momenta_and_energy_over_1e4_steps() {
    for (pot, name) in [(svk(), "SaintVenantKirchhoff"), (harmonic(), "Harmonic")] {
        let body = PseudoRigidBody::incompressible(3, pot).unwrap();
        let z0 = state(&body, 42, 0.8);
        let (d0, r0) = volume_and_rate(&body, &z0);
        let (l0, g0) = body.momenta(&z0).unwrap();
        let h0 = body.energy(&z0).unwrap();
        assert!((d0 - 1.0).abs() > 0.05 && r0 < 1e-15, "{d0} {r0:e}");
        let (dt, steps) = (0.01, 10_000);
        let traj = integrate(&body, "rattle4", &z0, dt, steps, 10).unwrap();
        let (mut dd, mut rate, mut dl, mut dg) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let energy_err: Vec<f64> = (0..traj.len())
            .map(|k| (body.energy(traj.state(k)).unwrap() - h0).abs())
            .collect();
        for k in 1..traj.len() {
            let z = traj.state(k);
            let (d, r) = volume_and_rate(&body, z);
            dd = dd.max((d - d0).abs() / d0);
            rate = rate.max(r);
            let (l, g) = body.momenta(z).unwrap();
            dl = dl.max(mat_dist(&l, &l0) / l0.norm_l2());
            dg = dg.max(mat_dist(&g, &g0) / g0.norm_l2());
        }
        let m = energy_err.len();
        let first = energy_err[1..m / 10].iter().fold(0.0f64, |a, &b| a.max(b));
        let last = energy_err[m - m / 10..]
            .iter()
            .fold(0.0f64, |a, &b| a.max(b));
        // The semi-axes move: the run is not trivial.
        let (s0, s1) = (
            body.singular_values(&z0).unwrap(),
            body.singular_values(&traj.final_state).unwrap(),
        );
        eprintln!(
            "{name} n = 3, rattle4, h = {dt}, 1e4 steps: det X0 = {d0:.4}, max |Δdet|/det \
             {dd:.2e}, max |⟨cof X, P⟩|/(‖cof‖‖P‖) {rate:.2e}, max ‖ΔL‖/‖L‖ {dl:.2e}, \
             max ‖ΔΓ‖/‖Γ‖ {dg:.2e}, |ΔH|/|H| first tenth {:.2e}, last tenth {:.2e}; \
             semi-axes {s0:.3?} → {s1:.3?}",
            first / h0.abs(),
            last / h0.abs()
        );
        assert!(dd <= 1e-13, "{name}: det drift {dd:e}");
        assert!(rate < 1e-13, "{name}: hidden constraint {rate:e}");
        assert!(dl < 1e-12 && dg < 1e-12, "{name}: L {dl:e}, Γ {dg:e}");
        assert!(
            last <= 2.0 * first.max(1e-13 * h0.abs()),
            "{name}: energy error {first:e} → {last:e}"
        );
        assert!(first < 1e-5 * h0.abs(), "{name}: energy error {first:e}");
        assert!(dist(&s0, &s1) > 1e-2);
        check_state(&body, &traj.final_state).unwrap();
        // The invariants the catalog claims (spectral invariants of L and Γ, det X).
        let i0 = body.invariants(&z0).unwrap();
        let i1 = body.invariants(&traj.final_state).unwrap();
        assert!(dist(&i0, &i1) < 1e-12 * norm(&i0), "{:e}", dist(&i0, &i1));
    }
}

#[test]
fn every_method_keeps_the_volume_at_n_2_3_4() {
    for n in [2, 3, 4] {
        let body = PseudoRigidBody::incompressible(n, harmonic()).unwrap();
        let z0 = state(&body, 5 + n as u64, 0.6);
        let (d0, _) = volume_and_rate(&body, &z0);
        for (m, _) in body.methods() {
            let traj = integrate(&body, m, &z0, 0.02, 2000, 100).unwrap();
            let (mut dd, mut rate) = (0.0f64, 0.0f64);
            for k in 0..traj.len() {
                let (d, r) = volume_and_rate(&body, traj.state(k));
                dd = dd.max((d - d0).abs() / d0);
                rate = rate.max(r);
            }
            let h0 = body.energy(&z0).unwrap();
            let h1 = body.energy(&traj.final_state).unwrap();
            eprintln!(
                "n = {n} {m}: det X0 = {d0:.4}, max |Δdet|/det {dd:.2e}, hidden constraint \
                 {rate:.2e}, |ΔH|/|H| at the end {:.2e}",
                (h1 - h0).abs() / h0.abs()
            );
            assert!(dd <= 1e-13 && rate < 1e-13, "n = {n} {m}: {dd:e} {rate:e}");
            assert!((h1 - h0).abs() < 1e-3 * h0.abs(), "n = {n} {m}");
        }
    }
}

#[test]
fn rattle_is_equivariant_under_the_two_sided_rotations() {
    // Φ_h(g X hᵀ, g P hᵀ) = g Φ_h(X, P) hᵀ for rotations g, h (the reason L and Γ are kept).
    let body = PseudoRigidBody::incompressible(3, svk()).unwrap();
    let z0 = state(&body, 9, 0.7);
    let rot = |w: [f64; 3]| {
        let r = lieflow::lie::so3::exp_unchecked(&nalgebra::Vector3::from(w));
        Mat::from_fn(3, 3, |i, j| r[(i, j)])
    };
    let (g, h) = (rot([0.3, -0.5, 0.9]), rot([-1.1, 0.2, 0.4]));
    let act = |z: &[f64]| {
        let (x, p) = body.split(z).unwrap();
        body.state(&(&g * &x * h.transpose()), &(&g * &p * h.transpose()))
            .unwrap()
    };
    for m in ["rattle", "rattle4"] {
        let a = act(&integrate(&body, m, &z0, 0.05, 20, 20).unwrap().final_state);
        let b = integrate(&body, m, &act(&z0), 0.05, 20, 20)
            .unwrap()
            .final_state;
        let err = dist(&a, &b) / norm(&a);
        eprintln!("{m}: equivariance defect after 20 steps {err:.2e}");
        assert!(err < 1e-13, "{m}: {err:e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Orders

#[test]
fn observed_orders_are_2_4_6() {
    for n in [3, 2] {
        let body = PseudoRigidBody::incompressible(n, svk()).unwrap();
        let z0 = state(&body, 21, 0.8);
        let t_end = 1.0;
        let end = |m: &str, steps: usize| {
            integrate(&body, m, &z0, t_end / steps as f64, steps, steps)
                .unwrap()
                .final_state
        };
        let reference = end("rattle6", 2560);
        for (m, p, base) in [
            ("rattle", 2.0, 20),
            ("rattle4", 4.0, 10),
            ("rattle6", 6.0, 10),
        ] {
            let e: Vec<f64> = [base, 2 * base, 4 * base]
                .iter()
                .map(|&k| dist(&end(m, k), &reference))
                .collect();
            let orders = [(e[0] / e[1]).log2(), (e[1] / e[2]).log2()];
            eprintln!(
                "n = {n} {m}: errors {:.2e} {:.2e} {:.2e} (steps {base}, ×2, ×4), observed \
                 orders {:.2} {:.2}",
                e[0], e[1], e[2], orders[0], orders[1]
            );
            assert!(
                e[2] > 1e-11,
                "{m}: errors at round-off, the test says nothing"
            );
            assert!(
                (orders[1] - p).abs() < 0.3,
                "n = {n} {m}: observed order {:.2}, nominal {p}",
                orders[1]
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The constraint kernels

#[test]
fn cofactor_and_curvature_of_det_match_finite_differences() {
    for n in [2, 3, 4, 5] {
        let body = PseudoRigidBody::incompressible(n, harmonic()).unwrap();
        let mut s = body.scratch();
        let mut rng = Rng::new(100 + n as u64);
        let x = Mat::from_fn(n, n, |i, j| if i == j { 1.3 } else { 0.0 }) + rng.mat(n, 0.3);
        let vm = rng.mat(n, 1.0);
        let q = body.state(&x, &vm).unwrap();
        let (q, v) = q.split_at(n * n);
        let g = |eps: f64| {
            let qe: Vec<f64> = q.iter().zip(v).map(|(a, b)| a + eps * b).collect();
            let mut out = [0.0];
            body.constraint(&qe, &mut out, &mut body.scratch());
            out[0]
        };
        let d = x.determinant();
        assert!((g(0.0) - d).abs() < 1e-14 * d.abs().max(1.0), "n = {n}");
        // G·V = d/dε det(X + εV): the polynomial det(X + εV) of degree n is differentiated
        // exactly enough by the 4th-order central difference at ε = 1e-3.
        let e = 1e-3;
        let d1 = (8.0 * (g(e) - g(-e)) - (g(2.0 * e) - g(-2.0 * e))) / (12.0 * e);
        let d2 =
            (16.0 * (g(e) + g(-e)) - (g(2.0 * e) + g(-2.0 * e)) - 30.0 * g(0.0)) / (12.0 * e * e);
        let mut jac = vec![0.0; n * n];
        body.constraint_jacobian(q, &mut jac, &mut s);
        let gv: f64 = jac.iter().zip(v).map(|(a, b)| a * b).sum();
        let mut curv = [0.0];
        body.constraint_curvature(q, v, &mut curv, &mut s);
        // Independent routes: cof X = det(X) X⁻ᵀ by faer; D² det[V, V] = 2 det(X) e₂(X⁻¹V).
        let cof = x.partial_piv_lu().inverse().transpose().to_owned() * faer::Scale(d);
        let jac_err = (0..n * n)
            .map(|k| (jac[k] - cof[(k / n, k % n)]).abs())
            .fold(0.0, f64::max);
        let b = x.partial_piv_lu().inverse() * &vm;
        let tr: f64 = (0..n).map(|i| b[(i, i)]).sum();
        let tr2: f64 = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| b[(i, j)] * b[(j, i)])
            .sum();
        let e2 = 2.0 * d * 0.5 * (tr * tr - tr2);
        eprintln!(
            "n = {n}: |G − det X·X⁻ᵀ| {jac_err:.1e}, G·V {gv:.6} vs FD {d1:.6}, D²det[V,V] \
             {:.6} vs FD {d2:.6} vs 2 det e₂(X⁻¹V) {e2:.6}",
            curv[0]
        );
        assert!(jac_err < 1e-13 * cof.norm_l2(), "n = {n}: {jac_err:e}");
        assert!((gv - d1).abs() < 1e-8 * gv.abs().max(1.0), "n = {n}");
        assert!(
            (curv[0] - d2).abs() < 1e-5 * curv[0].abs().max(1.0),
            "n = {n}"
        );
        assert!((curv[0] - e2).abs() < 1e-12 * e2.abs().max(1.0), "n = {n}");
    }
}

/// D³ det(X)\[U, V, ·\] at n = 3 (closed form) against central differences of the closed-form
/// D² det(X)\[U, ·\] along V (exact for a cubic up to round-off), and symmetric in (U, V).
#[test]
fn third_derivative_of_det_matches_differences_of_the_second() {
    let body = PseudoRigidBody::incompressible(3, harmonic()).unwrap();
    let mut s = body.scratch();
    let mut rng = Rng::new(7);
    let x = Mat::from_fn(3, 3, |i, j| if i == j { 1.3 } else { 0.0 }) + rng.mat(3, 0.3);
    let flat = |m: &Mat| (0..9).map(|k| m[(k / 3, k % 3)]).collect::<Vec<f64>>();
    let (q, u, v) = (flat(&x), flat(&rng.mat(3, 1.0)), flat(&rng.mat(3, 1.0)));
    let (mut third, mut swapped) = ([0.0; 9], [0.0; 9]);
    assert!(body.constraint_third(&q, &u, &v, &mut third, &mut s));
    assert!(body.constraint_third(&q, &v, &u, &mut swapped, &mut s));
    let h = 1e-3;
    let second = |sign: f64| {
        let qe: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a + sign * h * b).collect();
        let mut rows = [0.0; 9];
        assert!(body.constraint_second(&qe, &u, &mut rows, &mut body.scratch()));
        rows
    };
    let (up, down) = (second(1.0), second(-1.0));
    let fd: Vec<f64> = (0..9).map(|k| (up[k] - down[k]) / (2.0 * h)).collect();
    let err = dist(&third, &fd);
    eprintln!("D³det[U, V, ·] vs differences of D²det[U, ·] {err:.1e}");
    assert!(err < 1e-12 * norm(&fd), "{err:e}");
    assert!(dist(&third, &swapped) < 1e-14 * norm(&fd));
    let compressible = PseudoRigidBody::new(3, harmonic(), true).unwrap();
    assert!(!compressible.constraint_third(&q, &u, &v, &mut third, &mut s));
}

/// The derivative of the index-1 field (`constrained_field_tangent`: the multiplier's
/// derivative through D²g and D³g) against central differences of the field, for the
/// incompressible body (n = 3 with D³ det in closed form; n = 4 by differences of the curvature)
/// and the particle on a sphere; directions in every coordinate, off the constraint too.
#[test]
fn the_constrained_fields_derivative_matches_differences() {
    use lieflow::integrate::methods::rattle::constrained_field_tangent;
    fn check<P: Constrained + lieflow::integrate::tangent::SeparableTangent>(
        name: &str,
        problem: &P,
        z: &[f64],
        tol: f64,
    ) {
        let nz = z.len();
        let mut dirs = vec![0.0; nz * nz];
        for j in 0..nz {
            dirs[j * nz + j] = 1.0;
        }
        let mut out = vec![0.0; nz * nz];
        constrained_field_tangent(problem, z, &dirs, &mut out).unwrap();
        let mut worst = 0.0f64;
        let scale = out.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for j in 0..nz {
            let h = 1e-4 * z[j].abs().max(1.0);
            let field = |sign: f64| {
                let mut zs = z.to_vec();
                zs[j] += sign * h;
                let mut dz = vec![0.0; nz];
                constrained_field(problem, &zs, &mut dz, &mut problem.scratch()).unwrap();
                dz
            };
            let (a, b, a2, b2) = (field(1.0), field(-1.0), field(2.0), field(-2.0));
            for i in 0..nz {
                let fd = (8.0 * (a[i] - b[i]) - (a2[i] - b2[i])) / (12.0 * h);
                worst = worst.max((out[j * nz + i] - fd).abs() / scale);
            }
        }
        eprintln!("{name}: DF vs differences {worst:.1e}");
        assert!(worst < tol, "{name}: {worst:e}");
    }
    for n in [3, 4] {
        let body = PseudoRigidBody::incompressible(n, svk()).unwrap();
        check(
            &format!("incompressible n = {n}"),
            &body,
            &state(&body, 3, 0.5),
            1e-9,
        );
    }
    let part = SphereParticle::new(0.7, 1.3, 9.81).unwrap();
    check(
        "sphere particle",
        &part,
        &[0.3, -0.4, 1.1, 0.5, 0.2, 0.1],
        1e-10,
    );
}

// ---------------------------------------------------------------------------------------------
// The index-1 constrained field

/// Along a RATTLE trajectory of step h: the field's (q̇, ṗ) against central differences of the
/// trajectory, and λ against the multiplier of the trajectory's momentum change
/// (f − ṗ = Gᵀλ, least squares). Returns the largest relative errors (of ż, of λ).
fn field_vs_rattle<P: Constrained + System>(problem: &P, z0: &[f64], h: f64) -> (f64, f64) {
    let d = problem.dof();
    let m = problem.constraints();
    let traj = integrate(problem, "rattle", z0, h, 40, 1).unwrap();
    let mut s = problem.scratch();
    let mut w = FieldWork::new(problem);
    let (mut ez, mut el) = (0.0f64, 0.0f64);
    let (mut dz, mut lambda) = (vec![0.0; 2 * d], vec![0.0; m]);
    let (mut f, mut jac) = (vec![0.0; d], vec![0.0; m * d]);
    for k in 1..traj.len() - 1 {
        let z = traj.state(k);
        constrained_field_into(problem, z, &mut dz, &mut lambda, &mut s, &mut w).unwrap();
        let fd: Vec<f64> = (0..2 * d)
            .map(|i| (traj.state(k + 1)[i] - traj.state(k - 1)[i]) / (2.0 * h))
            .collect();
        ez = ez.max(dist(&dz, &fd) / norm(&fd));
        // The trajectory's multiplier (m = 1 here): λ = G·(f − ṗ)/|G|².
        assert_eq!(m, 1);
        problem.force(&z[..d], &mut f, &mut s).unwrap();
        problem.constraint_jacobian(&z[..d], &mut jac, &mut s);
        let lam_fd = (0..d).map(|i| jac[i] * (f[i] - fd[d + i])).sum::<f64>()
            / jac.iter().map(|x| x * x).sum::<f64>();
        el = el.max((lambda[0] - lam_fd).abs() / lambda[0].abs());
        // The allocating form agrees.
        let mut dz2 = vec![0.0; 2 * d];
        let l2 = constrained_field(problem, z, &mut dz2, &mut s).unwrap();
        assert_eq!((dz2, l2), (dz.clone(), lambda.clone()));
    }
    (ez, el)
}

#[test]
fn the_constrained_field_matches_rattle_trajectories() {
    let body = PseudoRigidBody::incompressible(3, svk()).unwrap();
    let z0 = state(&body, 77, 0.8);
    let part = SphereParticle::new(0.7, 1.3, 9.81).unwrap();
    let pend = SphericalPendulum::new(0.7, 1.3, 9.81).unwrap();
    let zp = part
        .from_spherical(&pend.state_from_spherical(1.1, 0.3, 0.4, 1.7).unwrap())
        .unwrap();
    for (name, errs) in [
        (
            "incompressible body",
            [1e-2, 5e-3].map(|h| field_vs_rattle(&body, &z0, h)),
        ),
        (
            "sphere particle",
            [1e-2, 5e-3].map(|h| field_vs_rattle(&part, &zp, h)),
        ),
    ] {
        eprintln!(
            "{name}: constrained field vs RATTLE central differences: ż {:.2e} → {:.2e}, λ \
             {:.2e} → {:.2e} (h = 1e-2 → 5e-3)",
            errs[0].0, errs[1].0, errs[0].1, errs[1].1
        );
        // Both errors are O(h²) (central differences of a symmetric method): a quarter on halving.
        assert!(errs[0].0 < 1e-3 && errs[0].1 < 1e-3, "{name}: {errs:?}");
        assert!(errs[1].0 < 0.3 * errs[0].0 && errs[1].1 < 0.3 * errs[0].1);
    }
    // A state off T*{g = c} is refused where G M⁻¹Gᵀ is singular: X = 0 has cof X = 0.
    let mut dz = vec![0.0; 18];
    let mut s = body.scratch();
    let mut zero = z0.clone();
    zero[..9].fill(0.0);
    let e = constrained_field(&body, &zero, &mut dz, &mut s).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { .. }), "{e}");
    // Its derivative refuses it alike, and leaves the output alone.
    let (dirs, mut out) = (vec![1.0; 18], vec![7.0; 18]);
    let e = lieflow::integrate::methods::rattle::constrained_field_tangent(
        &body, &zero, &dirs, &mut out,
    )
    .unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { .. }), "{e}");
    assert!(out.iter().all(|&x| x == 7.0));
}

#[test]
fn the_constrained_field_of_the_sphere_particle_is_the_centripetal_force() {
    // λ = (q·f + |p|²/m)/l²: with g = 0 the force −λq = −(m|v|²/l) q/l points to the centre with
    // the magnitude m v²/l; with gravity it also cancels the radial part of −m g e₃.
    let (m, l) = (0.7, 1.3);
    for gravity in [0.0, 9.81] {
        let part = SphereParticle::new(m, l, gravity).unwrap();
        let pend = SphericalPendulum::new(m, l, gravity).unwrap();
        let z = part
            .from_spherical(&pend.state_from_spherical(1.1, 0.3, 0.4, 1.7).unwrap())
            .unwrap();
        let (q, p) = z.split_at(3);
        let mut dz = vec![0.0; 6];
        let lambda = constrained_field(&part, &z, &mut dz, &mut ()).unwrap();
        let p2: f64 = p.iter().map(|x| x * x).sum();
        let f = [0.0, 0.0, -m * gravity];
        let qf: f64 = q.iter().zip(&f).map(|(a, b)| a * b).sum();
        let exact = (qf + p2 / m) / (l * l);
        let pdot: Vec<f64> = (0..3).map(|i| f[i] - exact * q[i]).collect();
        let vel: Vec<f64> = p.iter().map(|x| x / m).collect();
        eprintln!(
            "sphere particle, g = {gravity}: λ {:.15} vs exact {exact:.15}",
            lambda[0]
        );
        assert!((lambda[0] - exact).abs() < 1e-14 * exact.abs());
        assert!(dist(&dz[3..], &pdot) < 1e-14 * norm(&pdot));
        assert!(dist(&dz[..3], &vel) < 1e-15 * norm(&vel));
        if gravity == 0.0 {
            // |ṗ| = m v²/l, towards the centre.
            let v2 = p2 / (m * m);
            assert!((norm(&dz[3..]) - m * v2 / l).abs() < 1e-14 * m * v2 / l);
            let radial: f64 = (0..3).map(|i| dz[3 + i] * q[i]).sum::<f64>() / l;
            assert!((radial + m * v2 / l).abs() < 1e-14 * m * v2 / l);
        }
        // The field is tangent to T*S²: d/dt (q·p) = |p|²/m + q·ṗ = 0.
        let qpdot: f64 = (0..3).map(|i| q[i] * dz[3 + i]).sum();
        assert!((p2 / m + qpdot).abs() < 1e-13 * p2 / m);
    }
}
