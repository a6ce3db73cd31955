//! User-defined systems (issue 15): Lie–Poisson systems against the built-in rigid bodies (same
//! method, and the exact solution), Casimirs of the orbit-preserving methods, so(n) by structure
//! constants against the built-in algebra, structure constants against the brackets of
//! `lieflow::lie`, canonical and separable systems against closed forms and the pendulum, the
//! observed orders of the Gauss methods, finite-difference gradients, and failures of the
//! functions located at their step.

// Index loops mirror the index notation of the formulas they check.
#![allow(clippy::needless_range_loop)]

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use lieflow::integrate::{integrate, Problem, Run, System, Trajectory};
use lieflow::lie::{se3, so};
use lieflow::systems::user::{CanonicalFn, CanonicalGradientFn, GradientFn, ScalarFn};
use lieflow::systems::{
    Algebra, GeneralizedRigidBody, KineticMass, LieHamiltonian, LiePoisson, Pendulum, RigidBody,
    Side, UserCanonical, UserSeparable,
};
use lieflow::{Error, Mat};
use nalgebra::Vector6;

mod common;
use common::distance as dist;

const INERTIA: [f64; 3] = [1.0, 2.0, 3.0];
const M0: [f64; 3] = [1.0, 0.5, -0.3];

fn max_dist(a: &Trajectory, b: &Trajectory) -> f64 {
    (0..a.len())
        .map(|k| dist(a.state(k), b.state(k)))
        .fold(0.0, f64::max)
}

fn diag(v: &[f64]) -> Vec<f64> {
    let d = v.len();
    let mut a = vec![0.0; d * d];
    for i in 0..d {
        a[i * d + i] = v[i];
    }
    a
}

/// The rigid body as a Lie–Poisson system on so(3)* with H = ½ M·I⁻¹M (quadratic form).
fn rigid_quadratic() -> LiePoisson {
    let a = diag(&INERTIA.map(|i| 1.0 / i));
    LiePoisson::new(Algebra::So3, LieHamiltonian::Quadratic(a), None).unwrap()
}

/// The same with H and ∇H as functions.
fn rigid_functions(gradient: bool) -> LiePoisson {
    let value: ScalarFn =
        Arc::new(|m: &[f64]| Ok(0.5 * (0..3).map(|i| m[i] * m[i] / INERTIA[i]).sum::<f64>()));
    let grad: GradientFn = Arc::new(|m: &[f64], out: &mut [f64]| {
        for i in 0..3 {
            out[i] = m[i] / INERTIA[i];
        }
        Ok(())
    });
    LiePoisson::new(
        Algebra::So3,
        LieHamiltonian::Function {
            value,
            gradient: gradient.then_some(grad),
        },
        None,
    )
    .unwrap()
}

fn max_invariant_drift<S: Problem>(s: &S, traj: &Trajectory) -> f64 {
    let c0 = s.invariants(traj.state(0)).unwrap();
    (0..traj.len())
        .flat_map(|k| {
            let c = s.invariants(traj.state(k)).unwrap();
            c.iter()
                .zip(&c0)
                .map(|(x, y)| ((x - y) / y.abs().max(1e-300)).abs())
                .collect::<Vec<_>>()
        })
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------------------------
// Lie–Poisson on so(3)*: the rigid body

#[test]
fn so3_quadratic_reproduces_the_rigid_body_with_the_same_method() {
    let body = RigidBody::new(INERTIA).unwrap();
    let lp = rigid_quadratic();
    for method in ["rkmk4", "rk4"] {
        let a = integrate(&body, method, &M0, 0.01, 5000, 50).unwrap();
        let b = integrate(&lp, method, &M0, 0.01, 5000, 50).unwrap();
        let d = max_dist(&a, &b);
        assert!(d < 1e-13, "{method}: {d:e}");
    }
    // Energies agree (H = ½ M·I⁻¹M both).
    let (e1, e2) = (body.energy(&M0).unwrap(), lp.energy(&M0).unwrap());
    assert!((e1 - e2).abs() < 1e-15);
}

#[test]
fn so3_function_path_equals_the_quadratic_path_and_the_exact_solution() {
    let body = RigidBody::new(INERTIA).unwrap();
    let q = rigid_quadratic();
    let f = rigid_functions(true);
    let t_end = 5.0;
    let exact = body.exact_momentum(&M0, t_end).unwrap();
    for method in ["rkmk4", "midpoint", "midpoint4", "rk4"] {
        let a = integrate(&q, method, &M0, 0.005, 1000, 1000).unwrap();
        let b = integrate(&f, method, &M0, 0.005, 1000, 1000).unwrap();
        assert!(max_dist(&a, &b) < 1e-14, "{method}");
        let err = dist(&a.final_state, &exact);
        let tol = if method == "midpoint" { 1e-4 } else { 1e-8 };
        assert!(err < tol, "{method}: {err:e}");
    }
}

#[test]
fn so3_orbit_methods_keep_the_casimir_to_round_off() {
    let lp = rigid_functions(true);
    for method in ["rkmk4", "midpoint", "midpoint4"] {
        let traj = integrate(&lp, method, &M0, 0.05, 20_000, 100).unwrap();
        let drift = max_invariant_drift(&lp, &traj);
        // Round-off of 20 000 group actions (a random walk, measured ≤ 3.3e-14).
        assert!(drift < 1.5e-13, "{method}: |M|² drift {drift:e}");
    }
    let traj = integrate(&lp, "rk4", &M0, 0.05, 20_000, 100).unwrap();
    assert!(
        max_invariant_drift(&lp, &traj) > 1e-9,
        "rk4 does not keep |M|"
    );
}

#[test]
fn so3_observed_orders() {
    let body = RigidBody::new(INERTIA).unwrap();
    let lp = rigid_quadratic();
    let exact = body.exact_momentum(&M0, 2.0).unwrap();
    for (method, order) in [("rkmk4", 4.0), ("midpoint", 2.0), ("midpoint4", 4.0)] {
        let e: Vec<f64> = [0.04f64, 0.02]
            .iter()
            .map(|&dt| {
                let n = (2.0 / dt).round() as usize;
                dist(
                    &integrate(&lp, method, &M0, dt, n, n).unwrap().final_state,
                    &exact,
                )
            })
            .collect();
        let p = (e[0] / e[1]).log2();
        assert!((p - order).abs() < 0.2, "{method}: observed order {p}");
    }
}

#[test]
fn finite_difference_gradient_is_accurate_to_1e_12() {
    let exact = rigid_functions(true);
    let fd = rigid_functions(false);
    let mut g1 = [0.0; 3];
    let mut g2 = [0.0; 3];
    for m in [M0, [3.0, -0.1, 2.0], [1e-3, 2e-3, -5e-4], [1e5, -2e5, 3e4]] {
        exact.eval_gradient(&m, &mut g1).unwrap();
        fd.eval_gradient(&m, &mut g2).unwrap();
        let scale = g1.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let err = dist(&g1, &g2) / scale;
        assert!(err < 1e-11, "{m:?}: {err:e}");
    }
    // And the runs agree to that level.
    let a = integrate(&exact, "rkmk4", &M0, 0.01, 500, 500).unwrap();
    let b = integrate(&fd, "rkmk4", &M0, 0.01, 500, 500).unwrap();
    assert!(max_dist(&a, &b) < 1e-10);
}

// ---------------------------------------------------------------------------------------------
// se(3)*: Kirchhoff's equations

/// A Kirchhoff body: H = ½ M·AM + M·BP + ½ P·CP (A, C diagonal, B symmetric here).
fn kirchhoff() -> Vec<f64> {
    let a = [1.0, 0.7, 0.4];
    let c = [2.0, 1.5, 1.2];
    let b = [[0.1, 0.02, 0.0], [0.02, -0.05, 0.03], [0.0, 0.03, 0.08]];
    let mut h = vec![0.0; 36];
    for i in 0..3 {
        h[i * 6 + i] = a[i];
        h[(3 + i) * 6 + 3 + i] = c[i];
        for j in 0..3 {
            h[i * 6 + 3 + j] = b[i][j];
            h[(3 + j) * 6 + i] = b[i][j];
        }
    }
    h
}

#[test]
fn se3_casimirs_are_kept_and_the_field_is_kirchhoffs() {
    let h = kirchhoff();
    let lp = LiePoisson::new(Algebra::Se3, LieHamiltonian::Quadratic(h.clone()), None).unwrap();
    let z0 = [0.3, -0.5, 0.8, 1.0, 0.4, -0.6];
    // Ṁ = M × Ω + Γ × V, Γ̇ = Γ × Ω with (Ω, V) = ∇H.
    let mut g = [0.0; 6];
    lp.eval_gradient(&z0, &mut g).unwrap();
    let cross = |a: &[f64], b: &[f64]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let (m, gam, om, v) = (&z0[..3], &z0[3..], &g[..3], &g[3..]);
    let (a, b, c) = (cross(m, om), cross(gam, v), cross(gam, om));
    let want = [a[0] + b[0], a[1] + b[1], a[2] + b[2], c[0], c[1], c[2]];
    let mut dz = [0.0; 6];
    lieflow::integrate::problem::VectorField::field(&lp, &z0, &mut dz);
    assert!(dist(&dz, &want) < 1e-15, "{dz:?} vs {want:?}");
    for method in ["rkmk4", "midpoint", "midpoint4"] {
        let traj = integrate(&lp, method, &z0, 0.02, 20_000, 100).unwrap();
        let drift = max_invariant_drift(&lp, &traj);
        // Round-off of 20 000 group actions (a random walk, measured ≤ 8e-14).
        assert!(drift < 3e-13, "{method}: Casimir drift {drift:e}");
    }
    // The function path gives the same motion.
    let hq = h.clone();
    let value: ScalarFn = Arc::new(move |z: &[f64]| {
        Ok(0.5
            * (0..6)
                .map(|i| z[i] * (0..6).map(|j| hq[i * 6 + j] * z[j]).sum::<f64>())
                .sum::<f64>())
    });
    let f = LiePoisson::new(
        Algebra::Se3,
        LieHamiltonian::Function {
            value,
            gradient: None,
        },
        None,
    )
    .unwrap();
    let a = integrate(&lp, "rkmk4", &z0, 0.01, 300, 300).unwrap();
    let b = integrate(&f, "rkmk4", &z0, 0.01, 300, 300).unwrap();
    assert!(max_dist(&a, &b) < 1e-10);
}

#[test]
fn se3_structure_constants_are_those_of_ad_matrix() {
    let lp = LiePoisson::new(
        Algebra::Se3,
        LieHamiltonian::Quadratic(diag(&[1.0; 6])),
        None,
    )
    .unwrap();
    let c = lp.structure_constants().unwrap();
    let xi = [0.3, -0.2, 0.5, 0.1, 0.7, -0.4];
    let ad = se3::ad_matrix(&Vector6::from_column_slice(&xi));
    for k in 0..6 {
        for j in 0..6 {
            let v: f64 = (0..6).map(|i| xi[i] * c[(i * 6 + j) * 6 + k]).sum();
            assert!((v - ad[(k, j)]).abs() < 1e-15, "({k}, {j})");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// so(n)*

#[test]
fn so_n_structure_constants_are_the_brackets_of_hat_n() {
    for n in [2, 3, 4, 5] {
        let lp = LiePoisson::new(
            Algebra::So(n),
            LieHamiltonian::Quadratic(diag(&vec![1.0; so::dim(n)])),
            None,
        )
        .unwrap();
        let d = so::dim(n);
        let c = lp.structure_constants().unwrap();
        for i in 0..d {
            for j in 0..d {
                let mut ei = vec![0.0; d];
                let mut ej = vec![0.0; d];
                ei[i] = 1.0;
                ej[j] = 1.0;
                let b = so::vee_n(&so::bracket(
                    &so::hat_n(&ei).unwrap(),
                    &so::hat_n(&ej).unwrap(),
                ))
                .unwrap();
                for k in 0..d {
                    assert_eq!(c[(i * d + j) * d + k], b[k], "n = {n}, [e{i}, e{j}]_{k}");
                }
            }
        }
    }
}

#[test]
fn so_n_by_structure_constants_equals_the_built_in_algebra_and_the_generalized_body() {
    let j = [1.0, 2.0, 3.0, 4.5];
    let n = j.len();
    let d = so::dim(n);
    // Ω_ij = M_ij / (J_i + J_j): A = diag(1/(J_i + J_j)) in e_ij coordinates.
    let mut w = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            w.push(1.0 / (j[a] + j[b]));
        }
    }
    let a = diag(&w);
    let builtin =
        LiePoisson::new(Algebra::So(n), LieHamiltonian::Quadratic(a.clone()), None).unwrap();
    let c = builtin.structure_constants().unwrap();
    let generic =
        LiePoisson::new(Algebra::Constants(c), LieHamiltonian::Quadratic(a), None).unwrap();
    let body = GeneralizedRigidBody::new(&j).unwrap();
    let z0 = [0.3, -0.2, 0.5, 0.1, 0.4, -0.6];
    assert_eq!(z0.len(), d);
    assert!((body.energy(&z0).unwrap() - builtin.energy(&z0).unwrap()).abs() < 1e-15);
    for method in ["rkmk4", "rk4"] {
        let x = integrate(&body, method, &z0, 0.01, 2000, 100).unwrap();
        let y = integrate(&builtin, method, &z0, 0.01, 2000, 100).unwrap();
        assert!(max_dist(&x, &y) < 1e-12, "{method}: {:e}", max_dist(&x, &y));
    }
    for method in ["rkmk4", "midpoint", "midpoint4", "rk4"] {
        let x = integrate(&builtin, method, &z0, 0.01, 2000, 100).unwrap();
        let y = integrate(&generic, method, &z0, 0.01, 2000, 100).unwrap();
        assert!(max_dist(&x, &y) < 1e-12, "{method}: {:e}", max_dist(&x, &y));
    }
    // The orbit: the built-in Casimirs along the generic run.
    let y = integrate(&generic, "midpoint4", &z0, 0.02, 10_000, 100).unwrap();
    assert!(max_invariant_drift(&builtin, &y) < 3e-13);
}

#[test]
fn structure_constants_are_validated() {
    let q = || LieHamiltonian::Quadratic(diag(&[1.0; 3]));
    let at = |i: usize, j: usize, k: usize| (i * 3 + j) * 3 + k;
    // so(3) constants with one sign flipped break antisymmetry.
    let lp = LiePoisson::new(Algebra::So3, q(), None).unwrap();
    let mut c = lp.structure_constants().unwrap();
    c[at(0, 1, 2)] = -1.0; // [e0, e1]_2 = −1, but [e1, e0]_2 = −1 too
    let e = LiePoisson::new(Algebra::Constants(c), q(), None).unwrap_err();
    assert!(e.to_string().contains("antisymmetric"), "{e}");
    // Antisymmetric but not Jacobi: start from [e0, e1] = e2, [e1, e2] = e0, [e2, e0] = 2 e1.
    let mut c = vec![0.0; 27];
    for (i, j, k, v) in [(0, 1, 2, 1.0), (1, 2, 0, 1.0), (2, 0, 1, 2.0)] {
        c[at(i, j, k)] = v;
        c[at(j, i, k)] = -v;
    }
    // That one is a Lie algebra (so(3) with e1 rescaled); [e0, e1] = e2 + e0 breaks Jacobi.
    c[at(0, 1, 0)] = 1.0;
    c[at(1, 0, 0)] = -1.0;
    let e = LiePoisson::new(Algebra::Constants(c), q(), None).unwrap_err();
    assert!(e.to_string().contains("Jacobi"), "{e}");
    assert!(matches!(
        LiePoisson::new(Algebra::Constants(vec![0.0; 26]), q(), None),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        LiePoisson::new(Algebra::So3, LieHamiltonian::Quadratic(vec![1.0; 4]), None),
        Err(Error::Shape { .. })
    ));
    let mut a = diag(&[1.0; 3]);
    a[1] = 0.5;
    assert!(matches!(
        LiePoisson::new(Algebra::So3, LieHamiltonian::Quadratic(a), None),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(LiePoisson::new(Algebra::So(1), q(), None).is_err());
    // An abelian algebra: every state is an equilibrium.
    let lp = LiePoisson::new(
        Algebra::Constants(vec![0.0; 8]),
        LieHamiltonian::Quadratic(diag(&[1.0, 2.0])),
        None,
    )
    .unwrap();
    let t = integrate(&lp, "rkmk4", &[0.3, 0.4], 0.1, 10, 10).unwrap();
    assert_eq!(t.final_state, vec![0.3, 0.4]);
}

// ---------------------------------------------------------------------------------------------
// canonical and separable systems

fn oscillator(gradient: bool) -> UserCanonical {
    let h: CanonicalFn = Arc::new(|q: &[f64], p: &[f64]| Ok(0.5 * (p[0] * p[0] + q[0] * q[0])));
    let g: CanonicalGradientFn =
        Arc::new(|q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]| {
            hq[0] = q[0];
            hp[0] = p[0];
            Ok(())
        });
    UserCanonical::new(1, h, gradient.then_some(g)).unwrap()
}

#[test]
fn canonical_oscillator_against_its_closed_form_and_the_gauss_orders() {
    let sys = oscillator(true);
    let z0 = [1.0, 0.0];
    let t_end: f64 = 4.0;
    let exact = [t_end.cos(), -t_end.sin()];
    for (method, order) in [
        ("midpoint", 2.0),
        ("gauss4", 4.0),
        ("gauss6", 6.0),
        ("rk4", 4.0),
    ] {
        let e: Vec<f64> = [0.2, 0.1]
            .iter()
            .map(|&dt| {
                let n = (t_end / dt).round() as usize;
                dist(
                    &integrate(&sys, method, &z0, dt, n, n).unwrap().final_state,
                    &exact,
                )
            })
            .collect();
        let p = (e[0] / e[1]).log2();
        assert!(
            (p - order).abs() < 0.15,
            "{method}: observed order {p} ({e:?})"
        );
    }
    // Symplectic and quadratic-invariant keeping: the Gauss methods keep H = ½(q² + p²) exactly.
    let traj = integrate(&sys, "gauss4", &z0, 0.1, 100_000, 1000).unwrap();
    let h = |z: &[f64]| sys.energy(z).unwrap();
    let drift = (0..traj.len())
        .map(|k| (h(traj.state(k)) - 0.5).abs())
        .fold(0.0, f64::max);
    assert!(drift < 1e-13, "{drift:e}");
}

fn pendulum_user(gradient: bool, mass: KineticMass) -> UserSeparable {
    let (m, l, g) = (1.5, 0.8, 9.81);
    let u: ScalarFn = Arc::new(move |q: &[f64]| Ok(-m * g * l * q[0].cos()));
    let du: GradientFn = Arc::new(move |q: &[f64], out: &mut [f64]| {
        out[0] = m * g * l * q[0].sin();
        Ok(())
    });
    UserSeparable::new(mass, Some(1), u, gradient.then_some(du)).unwrap()
}

#[test]
fn separable_pendulum_equals_the_built_in_pendulum() {
    let (m, l, g) = (1.5, 0.8, 9.81);
    let pend = Pendulum::new(m, l, g).unwrap();
    let z0 = [1.2, 0.0];
    for mass in [
        KineticMass::Scalar(m * l * l),
        KineticMass::Diagonal(vec![m * l * l]),
        KineticMass::Matrix(Mat::from_fn(1, 1, |_, _| m * l * l)),
    ] {
        let user = pendulum_user(true, mass.clone());
        for method in ["verlet", "gauss4", "gauss6", "midpoint", "rk4"] {
            let a = integrate(&pend, method, &z0, 0.01, 2000, 100).unwrap();
            let b = integrate(&user, method, &z0, 0.01, 2000, 100).unwrap();
            let d = max_dist(&a, &b);
            assert!(d < 1e-12, "{mass:?} {method}: {d:e}");
        }
        assert!((pend.energy(&z0).unwrap() - user.energy(&z0).unwrap()).abs() < 1e-14);
    }
    // verlet4/verlet6 against the exact solution: orders 4 and 6.
    let user = pendulum_user(true, KineticMass::Scalar(m * l * l));
    let t_end: f64 = 2.0;
    let exact = pend.exact(1.2, t_end).unwrap();
    for (method, order) in [("verlet", 2.0), ("verlet4", 4.0), ("verlet6", 6.0)] {
        let e: Vec<f64> = [0.05, 0.025]
            .iter()
            .map(|&dt| {
                let n = (t_end / dt).round() as usize;
                dist(
                    &integrate(&user, method, &z0, dt, n, n).unwrap().final_state,
                    &exact,
                )
            })
            .collect();
        let p = (e[0] / e[1]).log2();
        assert!(
            (p - order).abs() < 0.3,
            "{method}: observed order {p} ({e:?})"
        );
    }
    // Without the gradient (finite differences) the run agrees to ~1e-10.
    let fd = pendulum_user(false, KineticMass::Scalar(m * l * l));
    let a = integrate(&user, "verlet4", &z0, 0.01, 1000, 1000).unwrap();
    let b = integrate(&fd, "verlet4", &z0, 0.01, 1000, 1000).unwrap();
    assert!(max_dist(&a, &b) < 1e-9, "{:e}", max_dist(&a, &b));
}

#[test]
fn separable_with_a_dense_mass_matrix() {
    // Two uncoupled oscillators in rotated coordinates: M = Qᵀ diag(1, 4) Q, U = ½ qᵀKq with
    // K = Qᵀ diag(1, 4) Q: frequencies 1 and 1 (ω² = k/m), so the motion is 2π-periodic.
    let (c, s) = (0.6f64, 0.8f64);
    let q = [[c, -s], [s, c]];
    let sym =
        |a: f64, b: f64| Mat::from_fn(2, 2, |i, j| a * q[0][i] * q[0][j] + b * q[1][i] * q[1][j]);
    let m = sym(1.0, 4.0);
    let k = sym(1.0, 4.0);
    let kk = [[k[(0, 0)], k[(0, 1)]], [k[(1, 0)], k[(1, 1)]]];
    let u: ScalarFn = Arc::new(move |x: &[f64]| {
        Ok(0.5
            * (0..2)
                .map(|i| x[i] * (0..2).map(|j| kk[i][j] * x[j]).sum::<f64>())
                .sum::<f64>())
    });
    let du: GradientFn = Arc::new(move |x: &[f64], out: &mut [f64]| {
        for i in 0..2 {
            out[i] = (0..2).map(|j| kk[i][j] * x[j]).sum();
        }
        Ok(())
    });
    let sys = UserSeparable::new(KineticMass::Matrix(m), None, u, Some(du)).unwrap();
    let z0 = [0.3, -0.2, 0.1, 0.4];
    let period = 2.0 * std::f64::consts::PI;
    let n = 4000;
    let t = integrate(&sys, "verlet6", &z0, period / n as f64, n, n).unwrap();
    assert!(dist(&t.final_state, &z0) < 1e-9, "{:?}", t.final_state);
    // Bad masses.
    let bad =
        |mass| UserSeparable::new(mass, Some(2), Arc::new(|_: &[f64]| Ok(0.0)), None).unwrap_err();
    assert!(matches!(
        bad(KineticMass::Scalar(-1.0)),
        Error::InvalidArgument { .. }
    ));
    assert!(matches!(
        bad(KineticMass::Diagonal(vec![1.0, 0.0])),
        Error::InvalidArgument { .. }
    ));
    assert!(matches!(
        bad(KineticMass::Matrix(Mat::from_fn(2, 2, |i, j| if i == j {
            1.0
        } else {
            2.0
        }))),
        Error::InvalidArgument { .. }
    ));
    assert!(matches!(
        bad(KineticMass::Matrix(Mat::from_fn(2, 2, |i, j| (i + 2 * j)
            as f64
            + 1.0))),
        Error::InvalidArgument { .. }
    ));
    assert!(matches!(
        bad(KineticMass::Diagonal(vec![1.0; 3])),
        Error::Shape { .. }
    ));
    assert!(UserSeparable::new(
        KineticMass::Scalar(1.0),
        None,
        Arc::new(|_: &[f64]| Ok(0.0)),
        None
    )
    .is_err());
}

// ---------------------------------------------------------------------------------------------
// failures of the functions

#[test]
fn a_failing_function_stops_the_run_at_its_step() {
    // H fails once it has been called `limit` times: the error names the step it failed in.
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = calls.clone();
    let grad: CanonicalGradientFn = Arc::new(
        move |q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]| {
            if q[0] < -0.5 {
                return Err(Error::invalid("gradient", "q below −0.5"));
            }
            counter.fetch_add(1, Ordering::Relaxed);
            hq[0] = q[0];
            hp[0] = p[0];
            Ok(())
        },
    );
    let h: CanonicalFn = Arc::new(|q: &[f64], p: &[f64]| Ok(0.5 * (p[0] * p[0] + q[0] * q[0])));
    let sys = UserCanonical::new(1, h, Some(grad)).unwrap();
    // q = cos t crosses −0.5 at t = 2π/3 ≈ 2.094: step 210 of dt = 0.01 (t = 2.10).
    let e = integrate(&sys, "gauss4", &[1.0, 0.0], 0.01, 1000, 10).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("q below −0.5 (in step 210 of gauss4"), "{msg}");
    for method in ["midpoint", "gauss6", "rk4"] {
        let e = integrate(&sys, method, &[1.0, 0.0], 0.01, 1000, 10).unwrap_err();
        assert!(e.to_string().contains(&format!("of {method}")), "{e}");
    }
    assert!(calls.load(Ordering::Relaxed) > 0);
}

/// A harmonic oscillator whose gradient fails exactly once, at its `fail_at`-th call (counted
/// over every run of the system), and counts its calls.
fn fails_once(fail_at: usize) -> (UserCanonical, Arc<AtomicUsize>) {
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = calls.clone();
    let grad: CanonicalGradientFn = Arc::new(
        move |q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]| {
            if counter.fetch_add(1, Ordering::SeqCst) + 1 == fail_at {
                return Err(Error::invalid("gradient", "transient failure"));
            }
            hq[0] = q[0];
            hp[0] = p[0];
            Ok(())
        },
    );
    let h: CanonicalFn = Arc::new(|q: &[f64], p: &[f64]| Ok(0.5 * (p[0] * p[0] + q[0] * q[0])));
    (UserCanonical::new(1, h, Some(grad)).unwrap(), calls)
}

#[test]
fn a_transient_failure_ends_the_run_at_its_step_without_replaying_steps() {
    // rk4 calls the gradient 4 times a step: call 998 is in step 250. With save_every = 10 a
    // chunk holds 10 steps; the run must end in step 250 (not replay the chunk, in which the
    // function would pass, and go on) and call the function no more.
    let (sys, calls) = fails_once(998);
    let mut run = Run::new(&sys, "rk4", &[1.0, 0.0], 0.01, 10, 0.0).unwrap();
    let mut out = Vec::new();
    let e = run.advance(&sys, 2000, &mut out).unwrap_err();
    assert!(
        e.to_string()
            .contains("transient failure (in step 250 of rk4"),
        "{e}"
    );
    assert_eq!(
        calls.load(Ordering::SeqCst),
        998,
        "steps were taken again or went on"
    );
    // The partial run belongs together: 24 saved states (steps 10..240), checked state at 249,
    // equal bit for bit to a fresh run of 249 steps.
    assert_eq!(run.steps_done(), 249);
    assert_eq!(out.len(), 24 * 2);
    let (fresh, _) = fails_once(usize::MAX);
    let traj = integrate(&fresh, "rk4", &[1.0, 0.0], 0.01, 249, 10).unwrap();
    assert_eq!(run.checked_state(&sys), traj.final_state);
    assert_eq!(&out[..], &traj.states[2..]);
}

#[test]
fn failures_stay_with_the_run_of_their_thread() {
    // One system, two threads: the run whose function fails gets the error, the other none.
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = calls.clone();
    let grad: CanonicalGradientFn = Arc::new(
        move |q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]| {
            counter.fetch_add(1, Ordering::Relaxed);
            if p[0] > 10.0 {
                return Err(Error::invalid("gradient", "fast"));
            }
            hq[0] = q[0];
            hp[0] = p[0];
            Ok(())
        },
    );
    let h: CanonicalFn = Arc::new(|q: &[f64], p: &[f64]| Ok(0.5 * (p[0] * p[0] + q[0] * q[0])));
    let sys = UserCanonical::new(1, h, Some(grad)).unwrap();
    std::thread::scope(|s| {
        for _ in 0..4 {
            let good = s.spawn(|| integrate(&sys, "rk4", &[1.0, 0.0], 0.01, 5000, 7));
            let bad = s.spawn(|| integrate(&sys, "rk4", &[20.0, 0.0], 0.01, 5000, 7));
            assert!(good.join().unwrap().is_ok());
            let e = bad.join().unwrap().unwrap_err();
            assert!(e.to_string().contains("fast (in step"), "{e}");
        }
    });
}

#[test]
fn non_finite_values_are_typed_errors_naming_the_step() {
    // H = ln q is NaN at q < 0: the energy is a NonFinite error.
    let h: CanonicalFn = Arc::new(|q: &[f64], _p: &[f64]| Ok(q[0].ln()));
    let sys = UserCanonical::new(1, h, None).unwrap();
    assert!(matches!(
        sys.energy(&[-1.0, 0.0]),
        Err(Error::NonFinite { .. })
    ));
    // A gradient returning NaN at the 3rd step.
    let grad: GradientFn = Arc::new(|m: &[f64], out: &mut [f64]| {
        for i in 0..3 {
            out[i] = if m[2] < -0.31 {
                f64::NAN
            } else {
                m[i] / INERTIA[i]
            };
        }
        Ok(())
    });
    let lp = LiePoisson::new(
        Algebra::So3,
        LieHamiltonian::Function {
            value: Arc::new(|_: &[f64]| Ok(0.0)),
            gradient: Some(grad),
        },
        None,
    )
    .unwrap();
    for method in ["rkmk4", "midpoint", "midpoint4", "rk4"] {
        let e = integrate(&lp, method, &M0, 0.05, 100, 100).unwrap_err();
        assert!(matches!(e, Error::NonFinite { .. }), "{method}: {e}");
        let msg = e.to_string();
        assert!(msg.contains("dH/dmu[0] = NaN, in step"), "{msg}");
        assert!(msg.contains(&format!("of {method} (t = ")), "{msg}");
    }
    // A Separable potential whose gradient fails at the initial state: named there.
    let du: GradientFn = Arc::new(|_: &[f64], _: &mut [f64]| Err(Error::invalid("U", "no")));
    let sep = UserSeparable::new(
        KineticMass::Scalar(1.0),
        Some(1),
        Arc::new(|_: &[f64]| Ok(0.0)),
        Some(du),
    )
    .unwrap();
    let e = integrate(&sep, "verlet", &[0.0, 1.0], 0.1, 10, 1).unwrap_err();
    assert!(
        e.to_string().contains("at the initial state of verlet"),
        "{e}"
    );
    // In the parallel batch driver each member's stepper has its own fault: the member that
    // fails is the one named.
    let states = vec![vec![1.5, 0.0, 0.2], M0.to_vec(), vec![1.5, 0.0, 0.2]];
    let e = lieflow::integrate::integrate_batch(&lp, "rkmk4", &states, 0.05, 3, 3, Some(2))
        .unwrap_err();
    assert!(e.to_string().contains("batch member 1"), "{e}");
}

#[test]
fn catalogs_and_names() {
    let names = |s: &dyn System| s.methods().into_iter().map(|(n, _)| n).collect::<Vec<_>>();
    assert_eq!(
        names(&oscillator(true)),
        ["gauss4", "gauss6", "midpoint", "rk4"]
    );
    assert_eq!(
        names(&pendulum_user(true, KineticMass::Scalar(1.0))),
        ["verlet", "verlet4", "verlet6", "gauss4", "gauss6", "midpoint", "rk4"]
    );
    assert_eq!(
        names(&rigid_quadratic()),
        ["rkmk4", "midpoint", "midpoint4", "rk4"]
    );
    let props = rigid_quadratic().methods();
    assert!(props[0].1.invariants && props[2].1.symmetric && !props[3].1.invariants);
    assert_eq!(rigid_quadratic().name(), "LiePoisson");
    assert_eq!(oscillator(true).name(), "Canonical");
    assert!(UserCanonical::new(0, Arc::new(|_: &[f64], _: &[f64]| Ok(0.0)), None).is_err());
}

/// H(μ) = Σ ½ a_i μ_i² + ⅓ b_i μ_i³ (odd: H(−μ) ≠ H(μ)), with its gradient; `mirror`: H(−μ).
fn cubic_hamiltonian(d: usize, mirror: bool) -> LieHamiltonian {
    let s = if mirror { -1.0 } else { 1.0 };
    let a = move |i: usize| 1.0 + 0.5 * i as f64;
    let b = move |i: usize| s * (0.2 - 0.07 * i as f64);
    let value: ScalarFn = Arc::new(move |m: &[f64]| {
        Ok((0..d)
            .map(|i| 0.5 * a(i) * m[i] * m[i] + b(i) * m[i] * m[i] * m[i] / 3.0)
            .sum())
    });
    let gradient: GradientFn = Arc::new(move |m: &[f64], out: &mut [f64]| {
        for i in 0..d {
            out[i] = a(i) * m[i] + b(i) * m[i] * m[i];
        }
        Ok(())
    });
    LieHamiltonian::Function {
        value,
        gradient: Some(gradient),
    }
}

#[test]
fn a_right_invariant_system_is_the_left_one_of_the_inverse_motion() {
    // The right system of H from μ₀ is, bit for bit, the negated left system of H̃(μ) = H(−μ)
    // from −μ₀ (the mirror g ↦ g⁻¹: module docs of systems::user, "Left and right"), on every
    // kind of algebra and with every method; and it is not the left system of H itself.
    let so3_constants = LiePoisson::new(Algebra::So3, rigid_quadratic_h(), None)
        .unwrap()
        .structure_constants()
        .unwrap();
    let algebras = [
        (Algebra::So3, vec![1.0, 0.5, -0.3]),
        (Algebra::Se3, vec![1.0, 0.5, -0.3, 0.2, -0.1, 0.4]),
        (Algebra::So(4), vec![0.3, -0.2, 0.5, 0.1, 0.4, -0.6]),
        (Algebra::Constants(so3_constants), vec![1.0, 0.5, -0.3]),
    ];
    for (algebra, mu0) in algebras {
        let d = mu0.len();
        let right = LiePoisson::new(algebra.clone(), cubic_hamiltonian(d, false), None)
            .unwrap()
            .with_side(Side::Right);
        let mirror = LiePoisson::new(algebra.clone(), cubic_hamiltonian(d, true), None).unwrap();
        let left = LiePoisson::new(algebra.clone(), cubic_hamiltonian(d, false), None).unwrap();
        let minus: Vec<f64> = mu0.iter().map(|x| -x).collect();
        for method in ["rkmk4", "midpoint", "rk4"] {
            let r = integrate(&right, method, &mu0, 0.01, 300, 30).unwrap();
            let m = integrate(&mirror, method, &minus, 0.01, 300, 30).unwrap();
            let l = integrate(&left, method, &mu0, 0.01, 300, 30).unwrap();
            for k in 0..r.len() {
                let negated: Vec<u64> = m.state(k).iter().map(|x| (-x).to_bits()).collect();
                let bits: Vec<u64> = r.state(k).iter().map(|x| x.to_bits()).collect();
                assert_eq!(bits, negated, "{algebra:?} {method} sample {k}");
            }
            assert!(
                dist(r.state(10), l.state(10)) > 1e-3,
                "{algebra:?} {method}"
            );
        }
        // The orbit-preserving methods keep the Casimirs of the right system too.
        let r = integrate(&right, "rkmk4", &mu0, 0.01, 2000, 100).unwrap();
        assert!(max_invariant_drift(&right, &r) < 1e-13, "{algebra:?}");
        assert_eq!(right.side(), Side::Right);
    }
}

#[test]
fn double_bracket_dissipation_is_refused_for_a_right_invariant_system() {
    use lieflow::integrate::problem::Dissipation;
    let right = rigid_quadratic().with_side(Side::Right);
    let e = right
        .dissipation(&Dissipation::DoubleBracket(0.1))
        .err()
        .unwrap();
    assert!(e.to_string().contains("left-invariant"), "{e}");
    assert!(rigid_quadratic()
        .dissipation(&Dissipation::DoubleBracket(0.1))
        .is_ok());
}

fn rigid_quadratic_h() -> LieHamiltonian {
    LieHamiltonian::Quadratic(diag(&INERTIA.map(|i| 1.0 / i)))
}
