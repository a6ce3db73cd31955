//! Hessians of the pseudo-rigid potentials (001 §4.1, used by the stability of relative
//! equilibria, 001 §8) and the stretch potential U = (k/2) Σ (σ_i − 1)²: every analytic formula
//! against finite differences and a second route.

mod common;

use common::Rng;
use lieflow::error::Error;
use lieflow::lie::gl;
use lieflow::pseudo_rigid::potential::{
    self, Harmonic, Potential, SaintVenantKirchhoff, Stretch, Sum, Volumetric, Workspace, Zero,
};
use lieflow::Mat;
use nalgebra::Matrix3;
use std::sync::Arc;

/// A point of GL⁺(n) with singular values in [0.3, 3] (random rotations, stretches).
fn gl_plus(rng: &mut Rng, n: usize) -> Mat {
    let (r, s) = (rotation(rng, n), rotation(rng, n));
    let a = Mat::from_fn(n, n, |i, j| {
        if i == j {
            0.3 + 1.35 * (1.0 + rng.uniform())
        } else {
            0.0
        }
    });
    &r * &a * s.transpose()
}

/// A rotation in SO(n) (the polar factor of a random matrix of GL⁺(n)).
fn rotation(rng: &mut Rng, n: usize) -> Mat {
    loop {
        let m = rng.mat(n, 1.0);
        if gl::det(&m).abs() > 0.05 {
            let m = if gl::det(&m) > 0.0 { m } else { flip_row0(&m) };
            return gl::polar(&m).unwrap().0;
        }
    }
}

/// `m` with its first row negated (det changes sign).
fn flip_row0(m: &Mat) -> Mat {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| {
        if i == 0 {
            -m[(i, j)]
        } else {
            m[(i, j)]
        }
    })
}

fn inner(a: &Mat, b: &Mat) -> f64 {
    (0..a.nrows())
        .flat_map(|i| (0..a.ncols()).map(move |j| (i, j)))
        .map(|(i, j)| a[(i, j)] * b[(i, j)])
        .sum()
}

fn potentials() -> Vec<Arc<dyn Potential>> {
    let svk: Arc<dyn Potential> = Arc::new(SaintVenantKirchhoff::new(0.7, 1.3).unwrap());
    let gas: Arc<dyn Potential> = Arc::new(Volumetric::polytropic(0.4, 1.4).unwrap());
    vec![
        Arc::new(Zero),
        Arc::new(Harmonic::new(1.7).unwrap()),
        svk.clone(),
        Arc::new(Volumetric::polytropic(0.4, 1.0).unwrap()),
        gas.clone(),
        Arc::new(Stretch::new(2.3).unwrap()),
        Arc::new(Sum::new(vec![
            svk,
            gas,
            Arc::new(Stretch::new(0.9).unwrap()),
            Arc::new(Harmonic::new(0.2).unwrap()),
        ])),
    ]
}

fn hess(pot: &dyn Potential, x: &Mat, v: &Mat) -> Mat {
    potential::hessian_product(pot, x, v).unwrap()
}

/// Central difference of the gradient along V: (∇U(X + hV) − ∇U(X − hV))/(2h).
fn fd_hessian(pot: &dyn Potential, x: &Mat, v: &Mat, h: f64) -> Mat {
    let gp = potential::gradient(pot, &(x + v * faer::Scale(h))).unwrap();
    let gm = potential::gradient(pot, &(x - v * faer::Scale(h))).unwrap();
    (gp - gm) * faer::Scale(0.5 / h)
}

#[test]
fn hessians_match_finite_differences_of_the_gradients() {
    let mut rng = Rng(11);
    let mut worst = 0.0f64;
    for pot in potentials() {
        for n in 2..=5 {
            for _ in 0..4 {
                let x = gl_plus(&mut rng, n);
                let v = rng.mat(n, 1.0);
                let h = hess(&*pot, &x, &v);
                // Fourth-order Richardson extrapolation of two central differences.
                let (f1, f2) = (
                    fd_hessian(&*pot, &x, &v, 1e-3),
                    fd_hessian(&*pot, &x, &v, 5e-4),
                );
                let fd = (f2 * faer::Scale(4.0) - f1) * faer::Scale(1.0 / 3.0);
                let err = (&fd - &h).norm_l2() / h.norm_l2().max(1e-300);
                worst = worst.max(err);
                assert!(err < 1e-7, "{pot:?}, n = {n}: relative error {err:.2e}");
            }
        }
    }
    eprintln!("worst relative finite-difference error of the Hessians: {worst:.2e}");
}

#[test]
fn hessians_are_symmetric_bilinear_forms() {
    let mut rng = Rng(12);
    for pot in potentials() {
        for n in 2..=5 {
            let x = gl_plus(&mut rng, n);
            let (v, w) = (rng.mat(n, 1.0), rng.mat(n, 1.0));
            let (hv, hw) = (hess(&*pot, &x, &v), hess(&*pot, &x, &w));
            let (a, b) = (inner(&w, &hv), inner(&v, &hw));
            let scale = w.norm_l2() * hv.norm_l2() + v.norm_l2() * hw.norm_l2();
            assert!(
                (a - b).abs() <= 1e-12 * scale.max(1e-300),
                "{pot:?}, n = {n}: ⟨W, H V⟩ = {a}, ⟨V, H W⟩ = {b}"
            );
            // Linear in V (the kernels add to `out`, so accumulate twice from one workspace).
            let mut ws = Workspace::new(n);
            let mut acc = Mat::zeros(n, n);
            pot.add_hessian(x.as_ref(), v.as_ref(), acc.as_mut(), &mut ws);
            pot.add_hessian(x.as_ref(), w.as_ref(), acc.as_mut(), &mut ws);
            let err = (&acc - hess(&*pot, &x, &(&v + &w))).norm_l2();
            assert!(err <= 1e-12 * acc.norm_l2().max(1.0), "{pot:?}: {err:.2e}");
        }
    }
}

#[test]
fn dense_hessian_is_symmetric_and_agrees_with_the_directional_form() {
    let mut rng = Rng(13);
    for pot in potentials() {
        for n in 2..=4 {
            let x = gl_plus(&mut rng, n);
            let h = potential::hessian(&*pot, &x).unwrap();
            assert_eq!((h.nrows(), h.ncols()), (n * n, n * n));
            let asym = (&h - h.transpose()).norm_l2();
            assert!(
                asym <= 1e-12 * h.norm_l2().max(1e-300),
                "{pot:?}: {asym:.2e}"
            );
            // H vec(V) = vec(D²U[V]) in the row-major basis.
            let v = rng.mat(n, 1.0);
            let hv = hess(&*pot, &x, &v);
            let vec_v = Mat::from_fn(n * n, 1, |k, _| v[(k / n, k % n)]);
            let prod = &h * &vec_v;
            let err = (0..n * n)
                .map(|k| (prod[(k, 0)] - hv[(k / n, k % n)]).abs())
                .fold(0.0, f64::max);
            assert!(err <= 1e-12 * hv.norm_l2().max(1.0), "{pot:?}: {err:.2e}");
        }
    }
}

#[test]
fn checked_hessians_refuse_bad_input() {
    let x = Mat::identity(3, 3);
    let harmonic = Harmonic::new(1.0).unwrap();
    assert!(matches!(
        potential::hessian_product(&harmonic, &x, &Mat::zeros(2, 2)),
        Err(Error::Shape { .. })
    ));
    let mut v = Mat::zeros(3, 3);
    v[(1, 2)] = f64::NAN;
    assert!(matches!(
        potential::hessian_product(&harmonic, &x, &v),
        Err(Error::NonFinite { .. })
    ));
    let flipped = Mat::from_fn(3, 3, |i, j| if i == j && i == 0 { -1.0 } else { x[(i, j)] });
    let gas = Volumetric::polytropic(1.0, 1.4).unwrap();
    assert!(matches!(
        potential::hessian(&gas, &flipped),
        Err(Error::NotInGroup { .. })
    ));
    // n⁴ = 1.6·10⁹ entries exceed the dense limit: refused before allocating.
    assert!(matches!(
        potential::hessian(&harmonic, &Mat::identity(200, 200)),
        Err(Error::InvalidArgument { .. })
    ));
}

// ---------------------------------------------------------------------------------------------
// The stretch potential U = (k/2) Σ (σ_i − 1)².

#[test]
fn stretch_gradient_matches_finite_differences_of_the_value() {
    let mut rng = Rng(21);
    let pot = Stretch::new(1.9).unwrap();
    for n in 2..=5 {
        for _ in 0..4 {
            let x = gl_plus(&mut rng, n);
            let v = rng.mat(n, 1.0);
            let g = potential::gradient(&pot, &x).unwrap();
            let u = |t: f64| potential::value(&pot, &(&x + &v * faer::Scale(t))).unwrap();
            let (d1, d2) = ((u(1e-3) - u(-1e-3)) / 2e-3, (u(5e-4) - u(-5e-4)) / 1e-3);
            let fd = (4.0 * d2 - d1) / 3.0;
            let exact = inner(&g, &v);
            let err = (fd - exact).abs() / (g.norm_l2() * v.norm_l2());
            assert!(err < 1e-9, "n = {n}: {exact} vs {fd} ({err:.2e})");
        }
    }
}

#[test]
fn stretch_gradient_is_k_times_x_minus_its_polar_rotation() {
    let mut rng = Rng(22);
    let k = 0.8;
    let pot = Stretch::new(k).unwrap();
    for n in 2..=6 {
        let x = gl_plus(&mut rng, n);
        let (r, _) = gl::polar(&x).unwrap();
        let closed = (&x - &r) * faer::Scale(k);
        let g = potential::gradient(&pot, &x).unwrap();
        assert!((&g - &closed).norm_l2() < 1e-12 * closed.norm_l2().max(1.0));
        // The value in closed form: (k/2)(‖X‖² − 2 tr P + n) with X = R P.
        let (_, p) = gl::polar(&x).unwrap();
        let tr_p: f64 = (0..n).map(|i| p[(i, i)]).sum();
        let closed_u = 0.5 * k * (x.norm_l2().powi(2) - 2.0 * tr_p + n as f64);
        let u = potential::value(&pot, &x).unwrap();
        assert!((u - closed_u).abs() < 1e-12 * closed_u.abs().max(1.0));
    }
}

#[test]
fn stretch_is_bi_invariant_and_vanishes_with_its_gradient_on_rotations() {
    let mut rng = Rng(23);
    let pot = Stretch::new(3.1).unwrap();
    for n in 2..=5 {
        let x = gl_plus(&mut rng, n);
        let (g, h) = (rotation(&mut rng, n), rotation(&mut rng, n));
        let u = potential::value(&pot, &x).unwrap();
        let moved = &g * &x * h.transpose();
        let u_moved = potential::value(&pot, &moved).unwrap();
        assert!((u - u_moved).abs() < 1e-12 * u.max(1.0), "n = {n}");
        // The gradient is equivariant: ∇U(gXhᵀ) = g ∇U(X) hᵀ.
        let grad = potential::gradient(&pot, &x).unwrap();
        let grad_moved = potential::gradient(&pot, &moved).unwrap();
        let err = (&grad_moved - &g * &grad * h.transpose()).norm_l2();
        assert!(err < 1e-12 * grad.norm_l2().max(1.0));

        assert!(potential::value(&pot, &g).unwrap().abs() < 1e-24);
        assert!(potential::gradient(&pot, &g).unwrap().norm_l2() < 1e-13);
        // At a rotation Q (all σ = 1): ⟨V, D²U[V]⟩ = k‖sym(QᵀV)‖², zero along so(n) rotations.
        let v = rng.mat(n, 1.0);
        let qv = g.transpose() * &v;
        let sym = (&qv + qv.transpose()) * faer::Scale(0.5);
        let quad = inner(&v, &hess(&pot, &g, &v));
        assert!((quad - 3.1 * sym.norm_l2().powi(2)).abs() < 1e-12 * quad.abs().max(1.0));
        let skew = (&qv - qv.transpose()) * faer::Scale(0.5);
        let tangent = &g * &skew;
        assert!(hess(&pot, &g, &tangent).norm_l2() < 1e-13 * tangent.norm_l2().max(1.0));
    }
}

#[test]
fn stretch_hessian_where_singular_values_coincide_or_det_is_negative() {
    // Coincident σ (1.3·Q, 2·I): the SVD is not unique there but the polar factor is.
    // det X < 0: the SVD form extends U smoothly (R Sᵀ is then orthogonal with det −1).
    let mut rng = Rng(24);
    let pot = Stretch::new(1.1).unwrap();
    for n in 2..=4 {
        let q = rotation(&mut rng, n);
        let mut points = vec![
            &q * faer::Scale(1.3),
            Mat::identity(n, n) * faer::Scale(2.0),
        ];
        points.push(flip_row0(&gl_plus(&mut rng, n)));
        for x in points {
            let v = rng.mat(n, 1.0);
            let h = hess(&pot, &x, &v);
            let fd = fd_hessian(&pot, &x, &v, 1e-5);
            let err = (&fd - &h).norm_l2() / h.norm_l2();
            assert!(err < 1e-7, "n = {n}, det X = {}: {err:.2e}", gl::det(&x));
        }
    }
}

#[test]
fn stretch_fixed_size_gradient_matches_the_general_kernel() {
    let mut rng = Rng(25);
    let pot = Stretch::new(1.4).unwrap();
    for _ in 0..10 {
        let x = gl_plus(&mut rng, 3);
        let g = potential::gradient(&pot, &x).unwrap();
        let g3 = pot.gradient3(&Matrix3::from_fn(|i, j| x[(i, j)])).unwrap();
        let err = (0..9)
            .map(|k| (g[(k / 3, k % 3)] - g3[(k / 3, k % 3)]).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-13 * g.norm_l2().max(1.0), "{err:.2e}");
    }
}

#[test]
fn stretch_needs_a_positive_stiffness() {
    for k in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            Stretch::new(k),
            Err(Error::InvalidArgument { .. })
        ));
    }
    let pot = Stretch::new(2.0).unwrap();
    assert_eq!(pot.k(), 2.0);
    assert!(!pot.needs_positive_det());
}

/// hessian3, the stack path of the n = 3 tangent lift, equals the general add_hessian for every
/// potential that has it (and a sum of them).
#[test]
fn fixed_size_hessians_match_the_general_kernel() {
    use lieflow::pseudo_rigid::potential::{Harmonic, SaintVenantKirchhoff, Sum, Volumetric};
    use std::sync::Arc;
    let mut rng = Rng(31);
    let pots: Vec<Arc<dyn Potential>> = vec![
        Arc::new(Harmonic::new(1.3).unwrap()),
        Arc::new(SaintVenantKirchhoff::new(0.7, 1.9).unwrap()),
        Arc::new(Volumetric::polytropic(0.5, 1.4).unwrap()),
        Arc::new(Volumetric::polytropic(0.8, 1.0).unwrap()),
        Arc::new(Sum::new(vec![
            Arc::new(SaintVenantKirchhoff::new(1.0, 2.0).unwrap()),
            Arc::new(Volumetric::polytropic(0.5, 1.4).unwrap()),
        ])),
    ];
    for pot in &pots {
        for _ in 0..10 {
            let x = gl_plus(&mut rng, 3);
            let v = rng.mat(3, 1.0);
            let h = potential::hessian_product(&**pot, &x, &v).unwrap();
            let h3 = pot
                .hessian3(
                    &Matrix3::from_fn(|i, j| x[(i, j)]),
                    &Matrix3::from_fn(|i, j| v[(i, j)]),
                )
                .expect("a stack Hessian");
            let err = (0..9)
                .map(|k| (h[(k / 3, k % 3)] - h3[(k / 3, k % 3)]).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12 * h.norm_l2().max(1.0), "{pot:?}: {err:.2e}");
        }
    }
}

/// ∂(∂U/∂X)/∂θ of every built-in potential's constants against central differences of the
/// gradient in the constant.
#[test]
fn parameter_gradients_match_differences_in_the_constants() {
    use lieflow::pseudo_rigid::potential::{
        Harmonic, SaintVenantKirchhoff, SelfGravity, Stretch, Volumetric,
    };
    type Make = Box<dyn Fn(&[f64]) -> Arc<dyn Potential>>;
    let cases: Vec<(Vec<f64>, Make)> = vec![
        (
            vec![1.3],
            Box::new(|t| Arc::new(Harmonic::new(t[0]).unwrap())),
        ),
        (
            vec![0.7, 1.9],
            Box::new(|t| Arc::new(SaintVenantKirchhoff::new(t[0], t[1]).unwrap())),
        ),
        (
            vec![0.5, 1.4],
            Box::new(|t| Arc::new(Volumetric::polytropic(t[0], t[1]).unwrap())),
        ),
        (
            vec![0.8, 1.0 + 1e-4],
            Box::new(|t| Arc::new(Volumetric::polytropic(t[0], t[1]).unwrap())),
        ),
        (
            vec![1.1],
            Box::new(|t| Arc::new(Stretch::new(t[0]).unwrap())),
        ),
        (
            vec![1.2, 0.9],
            Box::new(|t| Arc::new(SelfGravity::new(t[0], t[1]).unwrap())),
        ),
    ];
    let mut rng = Rng(41);
    for (theta, make) in cases {
        let pot = make(&theta);
        assert_eq!(pot.parameters().len(), theta.len(), "{pot:?}");
        let x = gl_plus(&mut rng, 3);
        let mut ws = lieflow::pseudo_rigid::potential::Workspace::new(3);
        for m in 0..theta.len() {
            let mut d = Mat::zeros(3, 3);
            pot.add_parameter_gradient(x.as_ref(), m, d.as_mut(), &mut ws);
            let h = 1e-6 * theta[m];
            let g = |s: f64| {
                let mut t = theta.clone();
                t[m] += s;
                potential::gradient(&*make(&t), &x).unwrap()
            };
            let fd = (g(h) - g(-h)) * faer::Scale(0.5 / h);
            let err = (&fd - &d).norm_l2() / fd.norm_l2().max(1e-300);
            assert!(err < 1e-7, "{pot:?} θ_{m}: {err:.2e}");
        }
    }
}
