//! Relative equilibria, augmented and amended potentials of the pseudo-rigid body (001 §8).

use lieflow::integrate::{integrate, Problem};
use lieflow::lie::so::{self, hat_n};
use lieflow::pseudo_rigid::dynamics::FullBody;
use lieflow::pseudo_rigid::equilibria::{
    amended_force, amended_gradient, amended_hessian, amended_hessian_matrix, amended_potential,
    amended_velocity_derivative, augmented_gradient, augmented_hessian, augmented_hessian_matrix,
    augmented_potential, equilibria_for_momenta, equilibria_for_shape, equilibria_for_velocities,
    equilibrium_directions, equilibrium_residual, force_balance, search_momenta, search_velocities,
    RelativeEquilibrium,
};
use lieflow::pseudo_rigid::momentum::momentum_map;
use lieflow::pseudo_rigid::potential::{
    self, Harmonic, Potential, SaintVenantKirchhoff, Stretch, Sum, Volumetric,
};
use lieflow::pseudo_rigid::reduced::ReducedState;
use lieflow::pseudo_rigid::{BiInertia, PseudoRigidBody};
use lieflow::{Error, Mat};
use std::sync::Arc;

fn elastic_gas() -> Arc<dyn Potential> {
    Arc::new(Sum::new(vec![
        Arc::new(SaintVenantKirchhoff::new(0.7, 1.3).unwrap()),
        Arc::new(Volumetric::polytropic(0.4, 1.4).unwrap()),
    ]))
}

/// Saint Venant–Kirchhoff with Lamé λ = 0.5, μ = 1 (the closed forms below use these).
fn svk() -> Arc<dyn Potential> {
    Arc::new(SaintVenantKirchhoff::new(0.5, 1.0).unwrap())
}

fn sample_x(n: usize) -> Mat {
    Mat::from_fn(n, n, |i, j| {
        if i == j {
            1.6 - 0.3 * i as f64
        } else {
            0.1 * ((2 * i + 3 * j) as f64).sin()
        }
    })
}

fn skew(n: usize, seed: f64) -> Mat {
    let c: Vec<f64> = (0..n * (n - 1) / 2)
        .map(|k| (seed + 1.7 * k as f64).sin())
        .collect();
    hat_n(&c).unwrap()
}

fn e(n: usize, i: usize, j: usize) -> Mat {
    let mut c = vec![0.0; n * (n - 1) / 2];
    let mut k = 0;
    for p in 0..n {
        for q in p + 1..n {
            if (p, q) == (i, j) {
                c[k] = 1.0;
            }
            k += 1;
        }
    }
    hat_n(&c).unwrap()
}

fn scaled(m: &Mat, s: f64) -> Mat {
    m * faer::Scale(s)
}

/// Central-difference gradient of f at X (tr pairing).
fn fd_gradient(f: impl Fn(&Mat) -> f64, x: &Mat) -> Mat {
    let n = x.nrows();
    let h = 1e-5;
    Mat::from_fn(n, n, |i, j| {
        let (mut p, mut m) = (x.clone(), x.clone());
        p[(i, j)] += h;
        m[(i, j)] -= h;
        (f(&p) - f(&m)) / (2.0 * h)
    })
}

fn rel(a: &Mat, b: &Mat) -> f64 {
    (a - b).norm_l2() / b.norm_l2().max(1e-300)
}

#[test]
fn quadratic_form_of_bi_inertia_is_the_vertical_kinetic_energy() {
    for n in [2, 3, 4] {
        let x = sample_x(n);
        let (xi, eta) = (skew(n, 0.3), skew(n, 1.1));
        let (bx, by) = BiInertia::new(&x).unwrap().apply(&xi, &eta).unwrap();
        let form = so::pairing(&xi, &bx) + so::pairing(&eta, &by);
        let w = &xi * &x - &x * &eta;
        let w2 = &xi * &x + &x * eta.transpose();
        assert!((form - w.norm_l2().powi(2)).abs() < 1e-12 * form.abs());
        assert!((w - w2).norm_l2() < 1e-14);
        // A sign slip (ξX + Xη) would not match.
        let wrong = &xi * &x + &x * &eta;
        assert!((form - wrong.norm_l2().powi(2)).abs() > 1e-3);
    }
}

#[test]
fn augmented_and_amended_gradients_match_finite_differences() {
    let pot = elastic_gas();
    for n in [2, 3, 4] {
        let x = sample_x(n);
        let (xi, eta) = (skew(n, 0.3), skew(n, 1.1));
        let g = augmented_gradient(&*pot, &x, &xi, &eta).unwrap();
        let fd = fd_gradient(|y| augmented_potential(&*pot, y, &xi, &eta).unwrap(), &x);
        assert!(rel(&g, &fd) < 1e-8, "augmented n={n}: {}", rel(&g, &fd));
        let (lam, gam) = (skew(n, 2.0), skew(n, -0.7));
        let g = amended_gradient(&*pot, &x, &lam, &gam).unwrap();
        let fd = fd_gradient(|y| amended_potential(&*pot, y, &lam, &gam).unwrap(), &x);
        assert!(rel(&g, &fd) < 1e-7, "amended n={n}: {}", rel(&g, &fd));
    }
}

#[test]
fn amended_equals_augmented_at_the_legendre_pair() {
    let pot = elastic_gas();
    for n in [2, 3, 4] {
        let x = sample_x(n);
        let (lam, gam) = (skew(n, 2.0), skew(n, -0.7));
        let (xi, eta) = BiInertia::new(&x).unwrap().solve(&lam, &gam).unwrap();
        let u = potential::value(&*pot, &x).unwrap();
        let v = amended_potential(&*pot, &x, &lam, &gam).unwrap();
        let w = augmented_potential(&*pot, &x, &xi, &eta).unwrap();
        // ½⟨J, B⁻¹J⟩ = ½⟨v, Bv⟩: the kinetic terms are equal and of opposite sign.
        assert!((v + w - 2.0 * u).abs() < 1e-12 * v.abs().max(1.0));
        assert!(v > u);
        // Legendre: the X-gradients coincide.
        let gv = amended_gradient(&*pot, &x, &lam, &gam).unwrap();
        let gw = augmented_gradient(&*pot, &x, &xi, &eta).unwrap();
        assert!(rel(&gv, &gw) < 1e-11);
    }
}

#[test]
fn amended_potential_needs_the_principal_stratum() {
    let x = Mat::from_fn(3, 3, |i, j| if i == j { [1.0, 1.0, 0.5][i] } else { 0.0 });
    let (lam, gam) = (skew(3, 0.1), skew(3, 0.2));
    let err = amended_potential(&*svk(), &x, &lam, &gam).unwrap_err();
    assert!(matches!(err, Error::DegenerateStratum { .. }), "{err}");
    assert!(amended_gradient(&*svk(), &x, &lam, &gam).is_err());
}

#[test]
fn directions_satisfy_8_6_and_generic_combinations_do_not() {
    for a in [
        vec![1.5, 1.0],
        vec![2.0, 1.3, 0.6],
        vec![2.1, 1.6, 1.0, 0.4],
    ] {
        let n = a.len();
        let dirs = equilibrium_directions(&a).unwrap();
        let (pairs, quads) = (n * (n - 1), if n == 4 { 3 * 4 } else { 0 });
        assert_eq!(dirs.len(), pairs + quads, "n = {n}");
        let b =
            BiInertia::new(&Mat::from_fn(n, n, |i, j| if i == j { a[i] } else { 0.0 })).unwrap();
        for d in &dirs {
            assert!(
                equilibrium_residual(&a, &d.xi, &d.eta).unwrap() < 1e-13,
                "{}",
                d.description
            );
            // Each plane's component is an eigenvector with eigenvalue (a_i − s a_j)² (8.15).
            if d.planes.len() == 1 {
                let (bx, by) = b.apply(&d.xi, &d.eta).unwrap();
                let l = d.eigenvalues[0];
                assert!((&bx - scaled(&d.xi, l)).norm_l2() < 1e-12);
                assert!((&by - scaled(&d.eta, l)).norm_l2() < 1e-12);
            }
        }
        // (8.18) for n = 4: e_12 ⊕ e_12 + e_34 ⊕ e_34, distinct eigenvalues, still admissible.
        if n == 4 {
            let d = dirs
                .iter()
                .find(|d| d.planes == vec![(0, 1), (2, 3)] && d.signs == vec![1.0, 1.0])
                .unwrap();
            assert!(d.eigenvalues[0] != d.eigenvalues[1]);
            assert_eq!(d.description, "e_12 ⊕ e_12 + e_34 ⊕ e_34");
        }
        // Any ω e_ij ⊕ μ e_ij in one plane is admissible too.
        let (x1, y1) = (scaled(&e(n, 0, 1), 0.7), scaled(&e(n, 0, 1), -0.2));
        assert!(equilibrium_residual(&a, &x1, &y1).unwrap() < 1e-13);
        if n >= 3 {
            // Two planes sharing an axis: (8.16) with [e_12, e_13] ≠ 0.
            let xi = &e(n, 0, 1) + &e(n, 0, 2);
            let eta = &e(n, 0, 1) - &e(n, 0, 2);
            assert!(equilibrium_residual(&a, &xi, &eta).unwrap() > 1e-2);
            let (xi, eta) = (skew(n, 0.3), skew(n, 1.1));
            assert!(equilibrium_residual(&a, &xi, &eta).unwrap() > 1e-2);
        }
    }
}

#[test]
fn off_diagonal_augmented_gradient_vanishes_exactly_when_8_6_holds() {
    let pot = elastic_gas();
    let a = [2.1, 1.6, 1.0, 0.4];
    let x = Mat::from_fn(4, 4, |i, j| if i == j { a[i] } else { 0.0 });
    let off = |xi: &Mat, eta: &Mat| {
        let g = augmented_gradient(&*pot, &x, xi, eta).unwrap();
        Mat::from_fn(4, 4, |i, j| if i == j { 0.0 } else { g[(i, j)] }).norm_l2()
    };
    for d in equilibrium_directions(&a).unwrap() {
        let (xi, eta) = (scaled(&d.xi, 0.8), scaled(&d.eta, 0.8));
        assert!(off(&xi, &eta) < 1e-13);
    }
    let (xi, eta) = (skew(4, 0.3), skew(4, 1.1));
    assert!(off(&xi, &eta) > 1e-2 && equilibrium_residual(&a, &xi, &eta).unwrap() > 1e-2);
}

/// The closed-form Riemann-type ellipsoid of U = SVK(λ = 1/2, μ = 1), n = 3, Ω = ω e_12,
/// Λ = m e_12: a₁² + a₂² = q, a₁a₂ = 2ωm, a₃² = q − s with s = ω² + m² and
/// q = (s(1 + λ/2μ) + 3λ/2 + μ)/(μ + λ) (derived in the comments of the test body).
fn svk_closed_form(w: f64, m: f64) -> [f64; 3] {
    // g_k = a_k(c + a_k²), c = λ tr E − μ; force balance in the plane gives c − s + q = 0 and
    // a₁a₂ = 2ωm (μ = 1); g₃ = 0 gives a₃² = −c; tr E = ½(q + a₃² − 3).
    let (lam, mu) = (0.5, 1.0);
    let s = w * w + m * m;
    let q = (s * (1.0 + lam / (2.0 * mu)) + 1.5 * lam + mu) / (mu + lam);
    let p = 2.0 * w * m / mu;
    let (plus, minus) = ((q + 2.0 * p).sqrt(), (q - 2.0 * p).sqrt());
    let c = s - mu * q;
    [0.5 * (plus + minus), 0.5 * (plus - minus), (-c / mu).sqrt()]
}

#[test]
fn velocities_solver_finds_the_closed_form_svk_ellipsoids() {
    let pot = svk();
    let (w, m) = (0.6, 0.4);
    let expect = svk_closed_form(w, m);
    assert!((expect[0] - 1.2).abs() < 1e-12 && (expect[1] - 0.4).abs() < 1e-12);
    let (xi, eta) = (scaled(&e(3, 0, 1), w), scaled(&e(3, 0, 1), m));
    let sols = equilibria_for_velocities(&*pot, &xi, &eta, (0.2, 2.0), 5).unwrap();
    assert_eq!(
        sols.len(),
        2,
        "{:?}",
        sols.iter().map(|s| &s.a).collect::<Vec<_>>()
    );
    let swapped = [expect[1], expect[0], expect[2]];
    for target in [expect, swapped] {
        let s = sols
            .iter()
            .find(|s| s.a.iter().zip(&target).all(|(x, y)| (x - y).abs() < 1e-9))
            .unwrap_or_else(|| panic!("missing {target:?}"));
        assert!(s.residuals.force < 1e-10 && s.residuals.motion < 1e-10);
        assert!(s.residuals.commutator < 1e-13);
        // λ ⊕ γ = L ⊕ Γ of (X₀, P₀).
        let (l, g) = momentum_map(&s.x0(), &s.p0()).unwrap();
        assert!((&l - &s.lam).norm_l2() < 1e-13 && (&g - &s.gam).norm_l2() < 1e-13);
    }
    // A wrong centrifugal sign would move the solution: check the force balance directly.
    let f = force_balance(&*pot, &expect, &xi, &eta).unwrap();
    assert!(f.iter().all(|v| v.abs() < 1e-12));
    let f_wrong = force_balance(&*pot, &expect, &xi, &scaled(&eta, -1.0)).unwrap();
    assert!(f_wrong.iter().any(|v| v.abs() > 1e-2));
}

#[test]
fn opposite_senses_have_only_coincident_axes() {
    // ωμ < 0 needs a₁a₂ < 0: no principal solution; the solver reports the axisymmetric ones.
    let (xi, eta) = (scaled(&e(3, 0, 1), 0.6), scaled(&e(3, 0, 1), -0.4));
    match equilibria_for_velocities(&*svk(), &xi, &eta, (0.2, 2.0), 4) {
        Err(Error::DegenerateStratum { what, .. }) => assert!(what.contains("coincident")),
        Ok(v) => assert!(v.is_empty()),
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn shape_solver_recovers_the_velocities_exactly() {
    let pot = svk();
    let a = svk_closed_form(0.6, 0.4);
    let sols = equilibria_for_shape(&*pot, &a, (0, 1), false).unwrap();
    assert_eq!(sols.len(), 4);
    let wm: Vec<(f64, f64)> = sols.iter().map(|s| (s.xi[(0, 1)], s.eta[(0, 1)])).collect();
    for target in [(0.6, 0.4), (0.4, 0.6), (-0.6, -0.4), (-0.4, -0.6)] {
        assert!(
            wm.iter()
                .any(|(w, m)| (w - target.0).abs() < 1e-12 && (m - target.1).abs() < 1e-12),
            "{target:?} not in {wm:?}"
        );
    }
    for s in &sols {
        assert!(s.residuals.motion < 1e-12 && s.residuals.commutator < 1e-13);
    }
    // Another plane: the force on a₂ is not balanced there.
    let err = equilibria_for_shape(&*pot, &a, (0, 2), false).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument { .. }), "{err}");
    let err = equilibria_for_shape(&*pot, &[1.0, 1.0, 0.9], (0, 1), false).unwrap_err();
    assert!(matches!(err, Error::DegenerateStratum { .. }), "{err}");
}

#[test]
fn shape_solver_closed_form_harmonic_plus_gas_in_two_dimensions() {
    // U = (k/2)|X|² − κ... polytropic: g_k = k a_k − c/a_k with c = κ d^{1−γ}, d = a₁a₂, so
    // (ω + μ)² = k + c/d and (ω − μ)² = k − c/d.
    let (k, kappa, gamma) = (1.0, 0.4, 1.4);
    let pot: Arc<dyn Potential> = Arc::new(Sum::new(vec![
        Arc::new(Harmonic::new(k).unwrap()),
        Arc::new(Volumetric::polytropic(kappa, gamma).unwrap()),
    ]));
    let a = [1.5, 0.8];
    let d: f64 = a[0] * a[1];
    let c = kappa * d.powf(1.0 - gamma);
    let (u, v) = ((k + c / d).sqrt(), (k - c / d).sqrt());
    let sols = equilibria_for_shape(&*pot, &a, (0, 1), false).unwrap();
    assert_eq!(sols.len(), 4);
    for s in &sols {
        let (w, m) = (s.xi[(0, 1)], s.eta[(0, 1)]);
        assert!(((w + m).abs() - u).abs() < 1e-12 && ((w - m).abs() - v).abs() < 1e-12);
        assert!(s.residuals.motion < 1e-12);
    }
    // A small body: the gas pressure wins, (ω − μ)² < 0.
    let err = equilibria_for_shape(&*pot, &[0.5, 0.3], (0, 1), false).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument { .. }), "{err}");
}

#[test]
fn harmonic_rigid_rotation_is_a_whole_family() {
    // U = (k/2)|X|², n = 2, Ω = ω e_12, Λ = 0: force balance (k − ω²)a = 0.
    let k = 2.0;
    let pot = Harmonic::new(k).unwrap();
    let xi = scaled(&e(2, 0, 1), k.sqrt());
    let err = equilibria_for_velocities(&pot, &xi, &Mat::zeros(2, 2), (0.5, 2.0), 3).unwrap_err();
    match err {
        Error::InvalidArgument { message, .. } => assert!(message.contains("continuum")),
        e => panic!("{e}"),
    }
    // The shape solver sees the same: (ω, μ) = (±√k, 0), (0, ±√k) for any shape.
    let sols = equilibria_for_shape(&pot, &[1.7, 0.6], (0, 1), false).unwrap();
    assert_eq!(sols.len(), 4);
    // ω² ≠ k: no relative equilibrium at all.
    let xi = scaled(&e(2, 0, 1), 1.0);
    let sols = equilibria_for_velocities(&pot, &xi, &Mat::zeros(2, 2), (0.5, 2.0), 3).unwrap();
    assert!(sols.is_empty());
}

#[test]
fn velocities_violating_8_6_are_reported() {
    let pot = svk();
    let (xi, eta) = (scaled(&e(3, 0, 1), 0.5), scaled(&e(3, 0, 2), 0.5));
    let err = equilibria_for_velocities(&*pot, &xi, &eta, (0.3, 2.0), 3).unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidArgument { .. } | Error::DegenerateStratum { .. }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("8.6") || err.to_string().contains("coincident"));
}

#[test]
fn four_dimensional_sum_over_two_disjoint_planes() {
    // SVK(λ = 1/2, μ = 1), Ω = ω₁e_12 + ω₂e_34, Λ = m₁e_12 + m₂e_34 (8.18): per plane
    // c − s_k + q_k = 0, a_i a_j = 2ω_k m_k, and c = λ tr E − μ with tr E = ½(q₁ + q₂ − 4), so
    // c(1 + λ) = λ(s₁ + s₂)/2 − 2λ − 1.
    let pot = svk();
    let ((w1, m1), (w2, m2)) = ((0.6, 0.4), (0.5, 0.3));
    let (s1, s2) = (w1 * w1 + m1 * m1, w2 * w2 + m2 * m2);
    let c = (0.5 * (s1 + s2) / 2.0 - 1.0 - 1.0) / 1.5;
    let axes = |s: f64, p: f64| {
        let q = s - c;
        let (u, v) = ((q + 2.0 * p).sqrt(), (q - 2.0 * p).sqrt());
        (0.5 * (u + v), 0.5 * (u - v))
    };
    let (a1, a2) = axes(s1, 2.0 * w1 * m1);
    let (a3, a4) = axes(s2, 2.0 * w2 * m2);
    let xi = &scaled(&e(4, 0, 1), w1) + &scaled(&e(4, 2, 3), w2);
    let eta = &scaled(&e(4, 0, 1), m1) + &scaled(&e(4, 2, 3), m2);
    assert!(equilibrium_residual(&[a1, a2, a3, a4], &xi, &eta).unwrap() < 1e-13);
    let sols = equilibria_for_velocities(&*pot, &xi, &eta, (0.2, 2.0), 4).unwrap();
    assert_eq!(
        sols.len(),
        4,
        "{:?}",
        sols.iter().map(|s| &s.a).collect::<Vec<_>>()
    );
    for target in [
        [a1, a2, a3, a4],
        [a2, a1, a3, a4],
        [a1, a2, a4, a3],
        [a2, a1, a4, a3],
    ] {
        let s = sols
            .iter()
            .find(|s| s.a.iter().zip(&target).all(|(x, y)| (x - y).abs() < 1e-9))
            .unwrap_or_else(|| panic!("missing {target:?}"));
        assert!(s.residuals.motion < 1e-10 && s.residuals.commutator < 1e-13);
    }
    check_motion(&pot, &sols[0]);
    let worst = check_verlet(&pot, &sols[0], 0.01, 1000);
    assert!(worst < 1e-7, "{worst}");
}

#[test]
fn momenta_solver_finds_the_amended_critical_points() {
    let pot = svk();
    let a = svk_closed_form(0.6, 0.4);
    let re = RelativeEquilibrium::from_velocities(
        &*pot,
        &a,
        &scaled(&e(3, 0, 1), 0.6),
        &scaled(&e(3, 0, 1), 0.4),
    )
    .unwrap();
    // The amended force vanishes there and equals −ṗ_a of the reduced vector field.
    let f = amended_force(&*pot, &a, &re.lam, &re.gam).unwrap();
    assert!(f.iter().all(|v| v.abs() < 1e-12), "{f:?}");
    let b = [1.3, 0.7, 1.1];
    let f = amended_force(&*pot, &b, &re.lam, &re.gam).unwrap();
    let state = ReducedState {
        a: b.to_vec(),
        p_a: vec![0.0; 3],
        p_omega: re.lam.clone(),
        p_lambda: re.gam.clone(),
    };
    let rates = state
        .vector_field(&FullBody::new(3, pot.clone()).unwrap())
        .unwrap();
    for (fk, pk) in f.iter().zip(&rates.p_a_dot) {
        assert!((fk + pk).abs() < 1e-12);
    }
    // And the gradient of the amended potential over shapes (finite differences in a).
    let v = |a: &[f64]| {
        let x = Mat::from_fn(3, 3, |i, j| if i == j { a[i] } else { 0.0 });
        amended_potential(&*pot, &x, &re.lam, &re.gam).unwrap()
    };
    for k in 0..3 {
        let (mut p, mut m) = (b.to_vec(), b.to_vec());
        p[k] += 1e-6;
        m[k] -= 1e-6;
        assert!(((v(&p) - v(&m)) / 2e-6 - f[k]).abs() < 1e-7);
    }
    let sols = equilibria_for_momenta(&*pot, &re.lam, &re.gam, (0.2, 2.0), 5).unwrap();
    let hit = sols
        .iter()
        .find(|s| s.a.iter().zip(&a).all(|(x, y)| (x - y).abs() < 1e-9))
        .expect("the velocity solution is an amended critical point");
    assert!((&hit.xi - &re.xi).norm_l2() < 1e-9 && (&hit.eta - &re.eta).norm_l2() < 1e-9);
    for s in &sols {
        assert!(s.residuals.motion < 1e-9, "{:?}", s.residuals);
    }
}

/// The curve solves Hamilton's equations (finite differences in t), verlet4 follows it, and
/// L, Γ, E stay at the equilibrium's values.
fn check_motion(pot: &Arc<dyn Potential>, re: &RelativeEquilibrium) {
    let n = re.n();
    let body = FullBody::new(n, pot.clone()).unwrap();
    let h = 1e-4;
    for t in [0.0, 0.7, 3.1] {
        let m = re.motion(&[t - h, t, t + h]).unwrap();
        let (x, p) = &m[1];
        let (xd, pd) = body.vector_field(x, p).unwrap();
        let xfd = (&m[2].0 - &m[0].0) * faer::Scale(0.5 / h);
        let pfd = (&m[2].1 - &m[0].1) * faer::Scale(0.5 / h);
        assert!(rel(&xfd, &xd) < 1e-8, "Ẋ at t={t}: {}", rel(&xfd, &xd));
        assert!(rel(&pfd, &pd) < 1e-8, "Ṗ at t={t}: {}", rel(&pfd, &pd));
        let (l, g) = momentum_map(x, p).unwrap();
        assert!((&l - &re.lam).norm_l2() < 1e-12 && (&g - &re.gam).norm_l2() < 1e-12);
        assert!((body.hamiltonian(x, p).unwrap() - re.energy).abs() < 1e-12);
    }
}

/// A verlet4 run from (X₀, P₀) follows X(t) = e^{tΩ}A₀e^{−tΛ}; L, Γ and E keep their values.
/// Returns the largest deviation in (X, P).
fn check_verlet(pot: &Arc<dyn Potential>, re: &RelativeEquilibrium, dt: f64, steps: usize) -> f64 {
    let body = PseudoRigidBody::new(re.n(), pot.clone(), true).unwrap();
    let z0 = body.state(&re.x0(), &re.p0()).unwrap();
    let every = 100;
    let traj = integrate(&body, "verlet4", &z0, dt, steps, every).unwrap();
    let times: Vec<f64> = (0..traj.len()).map(|k| (k * every) as f64 * dt).collect();
    let exact = re.motion(&times).unwrap();
    let mut worst: f64 = 0.0;
    let (mut dl, mut de): (f64, f64) = (0.0, 0.0);
    for (k, (x, p)) in exact.iter().enumerate() {
        let (xn, pn) = body.split(traj.state(k)).unwrap();
        worst = worst.max((&xn - x).norm_l2().max((&pn - p).norm_l2()));
        let (l, g) = body.momenta(traj.state(k)).unwrap();
        dl = dl.max((&l - &re.lam).norm_l2().max((&g - &re.gam).norm_l2()));
        de = de.max((body.energy(traj.state(k)).unwrap() - re.energy).abs());
    }
    eprintln!(
        "n = {}, verlet4 dt = {dt}, t = {}: max |Δ(X, P)| = {worst:.2e}, |ΔJ| = {dl:.2e}, \
         |ΔE| = {de:.2e}",
        re.n(),
        steps as f64 * dt
    );
    assert!(dl < 1e-11, "{dl}");
    assert!(de < 1e-9, "{de}");
    worst
}

#[test]
fn verlet4_stays_on_the_relative_equilibrium() {
    let pot = svk();
    let sols = equilibria_for_shape(&*pot, &svk_closed_form(0.6, 0.4), (0, 1), false).unwrap();
    let re = &sols[0];
    check_motion(&pot, re);
    let worst = check_verlet(&pot, re, 0.01, 2000);
    assert!(worst < 1e-7, "{worst}");
    // Fourth order: halving dt divides the deviation by ≈ 16.
    let finer = check_verlet(&pot, re, 0.005, 4000);
    assert!(worst / finer > 10.0, "{worst} / {finer}");
}

#[test]
fn bad_input_is_rejected() {
    let pot = svk();
    let z = Mat::zeros(3, 3);
    assert!(equilibrium_residual(&[1.0, -1.0, 0.5], &z, &z).is_err());
    assert!(equilibrium_directions(&[1.0]).is_err());
    assert!(equilibria_for_velocities(&*pot, &z, &z, (1.0, 0.5), 3).is_err());
    assert!(equilibria_for_velocities(&*pot, &z, &z, (0.5, 1.0), 0).is_err());
    assert!(equilibria_for_shape(&*pot, &[1.0, 0.5, 0.7], (1, 1), false).is_err());
    assert!(equilibria_for_shape(&*pot, &[1.0, f64::NAN, 0.7], (0, 1), false).is_err());
    let not_skew = Mat::from_fn(3, 3, |i, j| (i + j) as f64);
    assert!(augmented_potential(&*pot, &sample_x(3), &not_skew, &z).is_err());
}

#[test]
fn harmonic_gas_plane_rotation_is_degenerate_or_a_family() {
    // U = (k/2)|X|² + polytropic gas, n = 3, Ω = ω e_12, Λ = μ e_12: with c = κ det^{1−γ},
    // a₁F₁ − a₂F₂ = (k − ω² − μ²)(a₁² − a₂²), so for ω² + μ² ≠ k only a₁ = a₂ balances
    // (B_A singular, seed-errata §8), and for ω² + μ² = k the balance is c = 2ωμ a₁a₂, k a₃² = c:
    // a one-parameter family of shapes.
    let pot: Arc<dyn Potential> = Arc::new(Sum::new(vec![
        Arc::new(Harmonic::new(1.0).unwrap()),
        Arc::new(Volumetric::polytropic(0.4, 1.4).unwrap()),
    ]));
    let (xi, eta) = (scaled(&e(3, 0, 1), 0.6), scaled(&e(3, 0, 1), 0.4));
    let err = equilibria_for_velocities(&*pot, &xi, &eta, (0.3, 2.0), 4).unwrap_err();
    assert!(matches!(err, Error::DegenerateStratum { .. }), "{err}");
    let (xi, eta) = (scaled(&e(3, 0, 1), 0.8), scaled(&e(3, 0, 1), 0.6));
    match equilibria_for_velocities(&*pot, &xi, &eta, (0.3, 2.0), 4).unwrap_err() {
        Error::InvalidArgument { message, .. } => assert!(message.contains("continuum")),
        e => panic!("{e}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Hessians of the augmented and amended potentials (001 (8.11)–(8.12))

/// A small deterministic generator (xorshift) for the random points below.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
    fn mat(&mut self, n: usize, s: f64) -> Mat {
        Mat::from_fn(n, n, |_, _| s * self.next())
    }
    fn skew(&mut self, n: usize, s: f64) -> Mat {
        let m = self.mat(n, s);
        (&m - m.transpose()) * faer::Scale(0.5)
    }
    /// A point of the principal stratum: det > 0, singular values separated by ≥ 0.1.
    fn principal(&mut self, n: usize) -> Mat {
        loop {
            let x = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + 0.3 * i as f64 } else { 0.0 })
                + self.mat(n, 0.25);
            let sv = x.singular_values().unwrap();
            let sep = sv.windows(2).all(|w| (w[0] - w[1]).abs() > 0.1);
            if sep && x.determinant() > 0.0 && sv[n - 1] > 0.3 {
                return x;
            }
        }
    }
}

fn hessian_potentials() -> Vec<(&'static str, Arc<dyn Potential>)> {
    vec![
        (
            "SVK",
            Arc::new(SaintVenantKirchhoff::new(0.7, 1.3).unwrap()),
        ),
        (
            "Harmonic+Volumetric",
            Arc::new(Sum::new(vec![
                Arc::new(Harmonic::new(0.8).unwrap()),
                Arc::new(Volumetric::polytropic(0.4, 1.4).unwrap()),
            ])),
        ),
        ("Stretch", Arc::new(Stretch::new(1.1).unwrap())),
    ]
}

/// Central difference of a matrix-valued map along V.
fn fd_direction(f: impl Fn(&Mat) -> Mat, x: &Mat, v: &Mat, h: f64) -> Mat {
    (f(&(x + v * faer::Scale(h))) - f(&(x - v * faer::Scale(h)))) * faer::Scale(0.5 / h)
}

fn tr(a: &Mat, b: &Mat) -> f64 {
    (a.transpose() * b).diagonal().column_vector().iter().sum()
}

#[test]
fn hessians_match_finite_differences_of_the_gradients() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut worst_aug, mut worst_am) = (0.0_f64, 0.0_f64);
    for n in [2, 3, 4] {
        for (name, pot) in hessian_potentials() {
            for _ in 0..3 {
                let x = rng.principal(n);
                let (xi, eta) = (rng.skew(n, 0.8), rng.skew(n, 0.8));
                let (lam, gam) = (rng.skew(n, 1.0), rng.skew(n, 1.0));
                let v = rng.mat(n, 1.0);
                let h = augmented_hessian(&*pot, &x, &xi, &eta, &v).unwrap();
                let fd = fd_direction(
                    |y| augmented_gradient(&*pot, y, &xi, &eta).unwrap(),
                    &x,
                    &v,
                    1e-5,
                );
                let e = rel(&h, &fd);
                worst_aug = worst_aug.max(e);
                assert!(e < 1e-7, "augmented {name} n={n}: {e:.2e}");
                let h = amended_hessian(&*pot, &x, &lam, &gam, &v).unwrap();
                let fd = fd_direction(
                    |y| amended_gradient(&*pot, y, &lam, &gam).unwrap(),
                    &x,
                    &v,
                    1e-5,
                );
                let e = rel(&h, &fd);
                worst_am = worst_am.max(e);
                assert!(e < 1e-6, "amended {name} n={n}: {e:.2e}");
            }
        }
    }
    println!("worst relative FD error: augmented {worst_aug:.2e}, amended {worst_am:.2e}");
}

#[test]
fn hessians_are_symmetric_and_the_dense_matrices_agree() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for n in [2, 3, 4] {
        for (name, pot) in hessian_potentials() {
            let x = rng.principal(n);
            let (xi, eta) = (rng.skew(n, 0.8), rng.skew(n, 0.8));
            let (lam, gam) = (rng.skew(n, 1.0), rng.skew(n, 1.0));
            let (v, w) = (rng.mat(n, 1.0), rng.mat(n, 1.0));
            let aug = |d: &Mat| augmented_hessian(&*pot, &x, &xi, &eta, d).unwrap();
            let am = |d: &Mat| amended_hessian(&*pot, &x, &lam, &gam, d).unwrap();
            for (what, f) in [
                ("augmented", &aug as &dyn Fn(&Mat) -> Mat),
                ("amended", &am),
            ] {
                let (a, b) = (tr(&w, &f(&v)), tr(&v, &f(&w)));
                assert!(
                    (a - b).abs() < 1e-12 * a.abs().max(1.0),
                    "{what} {name} n={n}: {a} vs {b}"
                );
            }
            let ha = augmented_hessian_matrix(&*pot, &x, &xi, &eta).unwrap();
            let hm = amended_hessian_matrix(&*pot, &x, &lam, &gam).unwrap();
            for (what, m, f) in [
                ("augmented", &ha, &aug as &dyn Fn(&Mat) -> Mat),
                ("amended", &hm, &am),
            ] {
                assert_eq!((m.nrows(), m.ncols()), (n * n, n * n));
                assert!(
                    rel(&m.transpose().to_owned(), m) < 1e-12,
                    "{what} {name} n={n} not symmetric"
                );
                let fv = f(&v);
                let mv = m * Mat::from_fn(n * n, 1, |k, _| v[(k / n, k % n)]);
                let col = Mat::from_fn(n, n, |i, j| mv[(i * n + j, 0)]);
                assert!(
                    rel(&col, &fv) < 1e-12,
                    "{what} {name} n={n}: dense ≠ directional"
                );
            }
        }
    }
}

/// ⟨Y, D²V[V]⟩ − ⟨Y, D²U_κ[V]⟩ = tr((L_X Dκ[Y])ᵀ L_X Dκ[V]) with κ = B_X⁻¹(λ ⊕ γ); Dκ both
/// analytic and by finite differences of B_X⁻¹(λ ⊕ γ) (the second route).
fn check_relation(pot: &dyn Potential, x: &Mat, lam: &Mat, gam: &Mat, y: &Mat, v: &Mat) -> f64 {
    let b = BiInertia::new(x).unwrap();
    let (xi, eta) = b.solve(lam, gam).unwrap();
    let lx = |(p, q): &(Mat, Mat)| p * x - x * q;
    let dk = |d: &Mat| amended_velocity_derivative(x, lam, gam, d).unwrap();
    let (dy, dv) = (dk(y), dk(v));
    // Dκ by finite differences of κ(X) = B_X⁻¹(λ ⊕ γ).
    let kappa = |z: &Mat| BiInertia::new(z).unwrap().solve(lam, gam).unwrap();
    for (d, an) in [(y, &dy), (v, &dv)] {
        let fd0 = fd_direction(|z| kappa(z).0, x, d, 1e-5);
        let fd1 = fd_direction(|z| kappa(z).1, x, d, 1e-5);
        assert!(rel(&an.0, &fd0) < 1e-6 && rel(&an.1, &fd1) < 1e-6);
    }
    let am = tr(y, &amended_hessian(pot, x, lam, gam, v).unwrap());
    let aug = tr(y, &augmented_hessian(pot, x, &xi, &eta, v).unwrap());
    let extra = tr(&lx(&dy), &lx(&dv));
    // Also ⟨Dκ[Y], B_X Dκ[V]⟩ via BiInertia (the so(n) ⊕ so(n) pairing).
    let (p, q) = b.apply(&dv.0, &dv.1).unwrap();
    let extra2 = so::pairing(&dy.0, &p) + so::pairing(&dy.1, &q);
    assert!((extra - extra2).abs() < 1e-12 * extra.abs().max(1.0));
    let err = (am - aug - extra).abs() / am.abs().max(aug.abs()).max(1.0);
    assert!(err < 1e-11, "relation: {am} vs {aug} + {extra}");
    // The extra term is positive semidefinite: ⟨Dκ[V], B_X Dκ[V]⟩ = ‖L_X Dκ[V]‖² ≥ 0, and the
    // quadratic forms differ by it.
    let qa = tr(v, &amended_hessian(pot, x, lam, gam, v).unwrap());
    let qu = tr(v, &augmented_hessian(pot, x, &xi, &eta, v).unwrap());
    assert!(qa - qu >= -1e-12 * qa.abs().max(1.0));
    err
}

#[test]
fn amended_hessian_is_augmented_plus_a_positive_term() {
    let mut rng = Rng(0xdead_beef_cafe_f00d);
    // Random points of the principal stratum.
    for n in [2, 3, 4] {
        for (_, pot) in hessian_potentials() {
            let x = rng.principal(n);
            let (lam, gam) = (rng.skew(n, 1.0), rng.skew(n, 1.0));
            let (y, v) = (rng.mat(n, 1.0), rng.mat(n, 1.0));
            check_relation(&*pot, &x, &lam, &gam, &y, &v);
        }
    }
    // At relative equilibria from the exact shape solver: both gradients vanish there, and the
    // Hessians are related as above (λ ⊕ γ = B_A(Ω ⊕ Λ), A = diag(a), body = spatial at t = 0).
    let pot = svk();
    let a = svk_closed_form(0.6, 0.4);
    let sols = equilibria_for_shape(&*pot, &a, (0, 1), false).unwrap();
    assert_eq!(sols.len(), 4);
    for re in &sols {
        let x = re.x0();
        let ga = augmented_gradient(&*pot, &x, &re.xi, &re.eta).unwrap();
        let gm = amended_gradient(&*pot, &x, &re.lam, &re.gam).unwrap();
        assert!(ga.norm_l2() < 1e-11 && gm.norm_l2() < 1e-11);
        let hm = amended_hessian_matrix(&*pot, &x, &re.lam, &re.gam).unwrap();
        let ha = augmented_hessian_matrix(&*pot, &x, &re.xi, &re.eta).unwrap();
        // The difference is C*B_X C with C = Dκ: symmetric positive semidefinite, rank ≤ 6.
        let d = &hm - &ha;
        let ev = d.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        let top = ev.iter().copied().fold(0.0, f64::max);
        assert!(ev.iter().all(|&l| l >= -1e-10 * top), "{ev:?}");
        assert!(ev.iter().filter(|&&l| l > 1e-10 * top).count() <= 6);
        for _ in 0..5 {
            let (y, v) = (rng.mat(3, 1.0), rng.mat(3, 1.0));
            check_relation(&*pot, &x, &re.lam, &re.gam, &y, &v);
        }
    }
}

#[test]
fn hessians_reject_bad_input() {
    let pot = svk();
    let x = sample_x(3);
    let (xi, eta) = (skew(3, 0.3), skew(3, 1.1));
    assert!(augmented_hessian(&*pot, &x, &xi, &eta, &Mat::zeros(2, 2)).is_err());
    assert!(augmented_hessian(&*pot, &x, &x, &eta, &x).is_err());
    let degenerate = Mat::identity(3, 3);
    let err = amended_hessian(&*pot, &degenerate, &xi, &eta, &x).unwrap_err();
    assert!(matches!(err, Error::DegenerateStratum { .. }), "{err}");
    let err = amended_hessian_matrix(&*pot, &degenerate, &xi, &eta).unwrap_err();
    assert!(matches!(err, Error::DegenerateStratum { .. }), "{err}");
}

#[test]
fn search_reports_the_coincident_solutions_the_solvers_drop() {
    let pot = svk();
    let (xi, eta) = (scaled(&e(3, 0, 1), 0.6), scaled(&e(3, 0, 1), 0.4));
    let found = search_velocities(&*pot, &xi, &eta, (0.2, 2.0), 5).unwrap();
    let sols = equilibria_for_velocities(&*pot, &xi, &eta, (0.2, 2.0), 5).unwrap();
    assert_eq!(found.equilibria, sols);
    println!(
        "velocities: coincident shapes dropped: {:?}",
        found.coincident
    );
    for a in &found.coincident {
        let g = (0..a.len())
            .flat_map(|i| (i + 1..a.len()).map(move |j| (i, j)))
            .map(|(i, j)| (a[i] - a[j]).abs())
            .fold(f64::INFINITY, f64::min);
        assert!(g <= 1e-7 * 2.0, "{a:?}");
        // They do balance the forces: X(t) = e^{tΩ}Ae^{−tΛ} is a motion there too.
        let f = force_balance(&*pot, a, &xi, &eta).unwrap();
        assert!(f.iter().all(|v| v.abs() < 1e-8), "{f:?}");
    }
    let re = &sols[0];
    let found = search_momenta(&*pot, &re.lam, &re.gam, (0.2, 2.0), 5).unwrap();
    let sols = equilibria_for_momenta(&*pot, &re.lam, &re.gam, (0.2, 2.0), 5).unwrap();
    assert_eq!(found.equilibria, sols);
    println!("momenta: coincident shapes dropped: {:?}", found.coincident);
}

/// The incompressible body (det X = ∏a kept; pressure as multiplier): a shape of a
/// self-gravitating fluid in rigid rotation is a relative equilibrium exactly when it is a
/// Jacobi ellipsoid (the second route is `pseudo_rigid::ellipsoids`), and the pressure is the
/// multiplier of the force off the plane.
#[test]
fn incompressible_shape_equilibria_are_the_jacobi_ellipsoids() {
    use lieflow::pseudo_rigid::ellipsoids::Fluid;
    let fl = Fluid::new(1.0, 1.0).unwrap();
    let j = fl.jacobi(0.6).unwrap();
    let pot = fl.potential();
    let sols = equilibria_for_shape(&*pot, &j.a, (0, 1), true).unwrap();
    // (ω + μ)² = (ω − μ)² = ω_J²: four sign choices, two of them rigid rotations (μ = 0).
    let rigid: Vec<_> = sols.iter().filter(|s| s.eta.norm_l2() < 1e-12).collect();
    assert_eq!(rigid.len(), 2, "{sols:?}");
    for s in &sols {
        assert!(s.residuals.motion < 1e-12, "{:?}", s.residuals);
        assert!((s.pressure - j.pressure).abs() < 1e-12 * j.pressure);
    }
    assert!(rigid
        .iter()
        .any(|s| (s.xi[(0, 1)] - j.omega).abs() < 1e-12 * j.omega.abs()));
    // Compressible, the same shape is not an equilibrium of self-gravity alone (no pressure).
    assert!(equilibria_for_shape(&*pot, &j.a, (0, 1), false).is_err());
}
