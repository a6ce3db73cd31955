//! Stability of relative equilibria of the pseudo-rigid body (001 §8): the energy–momentum and
//! spectral verdicts of `pseudo_rigid::stability`, checked against a second route for the
//! Hessian and the linearisation, and against simulations of the full body (Verlet).

use lieflow::integrate::integrate;
use lieflow::pseudo_rigid::dynamics::FullBody;
use lieflow::pseudo_rigid::momentum;
use lieflow::pseudo_rigid::potential::{self, Potential, SaintVenantKirchhoff};
use lieflow::pseudo_rigid::reduced::ReducedState;
use lieflow::pseudo_rigid::stability::{stability, Leaf, Stability};
use lieflow::pseudo_rigid::PseudoRigidBody;
use lieflow::{Error, Mat};
use std::sync::Arc;

fn svk(lambda: f64, mu: f64) -> Arc<dyn Potential> {
    Arc::new(SaintVenantKirchhoff::new(lambda, mu).unwrap())
}

fn diag(a: &[f64]) -> Mat {
    Mat::from_fn(a.len(), a.len(), |i, j| if i == j { a[i] } else { 0.0 })
}

/// w e_01 in so(3).
fn e01(w: f64) -> Mat {
    let mut m = Mat::zeros(3, 3);
    m[(0, 1)] = w;
    m[(1, 0)] = -w;
    m
}

/// The augmented potential U_{Ω⊕Λ}(a) = U(a) − ½‖ΩA − AΛ‖² (001 (8.12), with
/// ⟨Ω⊕Λ, B_A(Ω⊕Λ)⟩ = ‖ΩA − AΛ‖² at A = diag(a)).
fn augmented(pot: &dyn Potential, a: &[f64], om: &Mat, la: &Mat) -> f64 {
    let am = diag(a);
    let v = om * &am - &am * la;
    potential::value(pot, &am).unwrap() - 0.5 * v.norm_l2().powi(2)
}

/// ∂U_{Ω⊕Λ}/∂a: ∂U/∂a (diagonal of ∂U/∂X) minus the gradient of ½‖ΩA − AΛ‖².
fn augmented_gradient(pot: &dyn Potential, a: &[f64], om: &Mat, la: &Mat) -> Vec<f64> {
    let n = a.len();
    let am = diag(a);
    let g = potential::gradient(pot, &am).unwrap();
    let v = om * &am - &am * la;
    // d/da_k ½‖ΩA − AΛ‖² = Σ_i v_ik Ω_ik − Σ_j v_kj Λ_kj.
    (0..n)
        .map(|k| {
            let c: f64 = (0..n)
                .map(|i| v[(i, k)] * om[(i, k)] - v[(k, i)] * la[(k, i)])
                .sum();
            g[(k, k)] - c
        })
        .collect()
}

/// Newton's method on ∂U_{Ω⊕Λ}/∂a = 0 (the force balance of a relative equilibrium with
/// Ω = ω e_01, Λ = λ e_01), with a central-difference Jacobian.
fn solve_shape(pot: &dyn Potential, om: &Mat, la: &Mat, mut a: Vec<f64>) -> Option<Vec<f64>> {
    let n = a.len();
    for _ in 0..50 {
        let f = augmented_gradient(pot, &a, om, la);
        let fnorm = f.iter().map(|x| x * x).sum::<f64>().sqrt();
        if fnorm < 1e-14 {
            return Some(a);
        }
        let h = 1e-6;
        let jac = Mat::from_fn(n, n, |i, l| {
            let (mut ap, mut am) = (a.clone(), a.clone());
            ap[l] += h;
            am[l] -= h;
            (augmented_gradient(pot, &ap, om, la)[i] - augmented_gradient(pot, &am, om, la)[i])
                / (2.0 * h)
        });
        let rhs = Mat::from_fn(n, 1, |i, _| -f[i]);
        let lu = jac.partial_piv_lu();
        let dx = faer::linalg::solvers::Solve::solve(&lu, &rhs);
        for i in 0..n {
            a[i] += dx[(i, 0)];
        }
        if a.iter().any(|x| !x.is_finite() || *x <= 0.0) {
            return None;
        }
    }
    None
}

/// The S-type shape for Ω = ω e_01, Λ = λ e_01 under Saint Venant–Kirchhoff (λ_L, μ_L), from
/// the closed form at λ_L = 0 (a₂ = 1, a₀a₁ = 2ωλ/μ_L, a₀² + a₁² = 1 + (ω² + λ²)/μ_L) by
/// continuation in λ_L.
fn s_type(lam_l: f64, mu_l: f64, w: f64, l: f64) -> Option<Vec<f64>> {
    let p = 2.0 * w * l / mu_l;
    let s = 1.0 + (w * w + l * l) / mu_l;
    let (sum, dif) = ((s + 2.0 * p).sqrt(), (s - 2.0 * p).max(0.0).sqrt());
    let mut a = vec![0.5 * (sum + dif), 0.5 * (sum - dif), 1.0];
    let (om, la) = (e01(w), e01(l));
    for k in 1..=10 {
        let pot = svk(lam_l * k as f64 / 10.0, mu_l);
        a = solve_shape(&*pot, &om, &la, a)?;
    }
    Some(a)
}

fn report(name: &str, s: &Stability) {
    eprintln!(
        "{name}: leaf dim {}, residual {:.2e}, gradient {:.2e}",
        s.leaf_dim, s.residual, s.gradient
    );
    eprintln!(
        "  energy-momentum: stable {} conclusive {}, Hessian eigenvalues {:?}",
        s.energy_momentum.stable,
        s.energy_momentum.conclusive,
        s.energy_momentum
            .eigenvalues
            .iter()
            .map(|e| e.0)
            .collect::<Vec<_>>()
    );
    eprintln!(
        "  spectral: stable {} (max Re {:.3e}, tol {:.1e}), eigenvalues {:?}",
        s.spectral.stable, s.spectral.max_real_part, s.spectral.tol, s.spectral.eigenvalues
    );
    eprintln!("  forced zeros (full Jacobian): {:?}", s.forced_zeros);
}

const LAME: (f64, f64) = (1.0, 1.0);
/// Stable S-type equilibrium (both verdicts stable).
const STABLE: (f64, f64) = (0.5, 0.9);
/// Unstable S-type equilibrium (a real eigenvalue pair ±0.105).
const UNSTABLE: (f64, f64) = (0.3, 0.5);

struct Example {
    body: FullBody,
    a: Vec<f64>,
    om: Mat,
    la: Mat,
}

fn example((w, l): (f64, f64)) -> Example {
    let a = s_type(LAME.0, LAME.1, w, l).expect("S-type shape");
    Example {
        body: FullBody::new(3, svk(LAME.0, LAME.1)).unwrap(),
        a,
        om: e01(w),
        la: e01(l),
    }
}

impl Example {
    fn analyse(&self) -> Stability {
        stability(&self.body, &self.a, &self.om, &self.la).unwrap()
    }
    fn reduced(&self) -> ReducedState {
        let (mu, nu) = momentum::body_momenta(&self.a, &self.om, &self.la).unwrap();
        ReducedState {
            a: self.a.clone(),
            p_a: vec![0.0; 3],
            p_omega: mu,
            p_lambda: nu,
        }
    }
}

#[test]
fn the_examples_are_reduced_equilibria() {
    for (name, p) in [("stable", STABLE), ("unstable", UNSTABLE)] {
        let ex = example(p);
        let r = ex.reduced().vector_field(&ex.body).unwrap();
        let f: f64 = r.p_a_dot.iter().map(|x| x.abs()).sum::<f64>()
            + r.p_omega_dot.norm_l2()
            + r.p_lambda_dot.norm_l2();
        eprintln!("{name}: a = {:?}, |reduced field| = {f:.2e}", ex.a);
        assert!(f < 1e-12, "{name}: {f}");
        let s = ex.analyse();
        assert!(s.residual < 1e-12 && s.gradient < 1e-12, "{name}: {s:?}");
    }
}

#[test]
fn verdicts_of_the_stable_and_the_unstable_example() {
    let s = example(STABLE).analyse();
    report("stable", &s);
    assert_eq!(s.leaf_dim, 10);
    assert!(s.energy_momentum.stable && s.energy_momentum.conclusive);
    assert!(s.energy_momentum.min_real_part > 1e-2);
    assert!(s.spectral.stable && !s.spectral.conclusive);
    // A positive definite Hessian makes L = Π D²H similar to a skew matrix: a pure imaginary
    // spectrum.
    let re = s
        .spectral
        .eigenvalues
        .iter()
        .fold(0.0f64, |m, e| m.max(e.0.abs()));
    eprintln!("stable example: max |Re λ| = {re:.1e}");
    assert!(re < 1e-12, "{re:e}");

    let u = example(UNSTABLE).analyse();
    report("unstable", &u);
    assert!(!u.energy_momentum.stable && !u.energy_momentum.conclusive);
    assert!(u.energy_momentum.min_real_part < -1e-2);
    assert!(!u.spectral.stable && u.spectral.conclusive);
    assert!(u.spectral.max_real_part > 0.05);
    // Hamiltonian spectrum: λ and −λ together.
    for &(re, im) in &u.spectral.eigenvalues {
        let m = u
            .spectral
            .eigenvalues
            .iter()
            .map(|&(r2, i2)| (r2 + re).hypot(i2 + im))
            .fold(f64::INFINITY, f64::min);
        assert!(m < 1e-8, "no partner of ({re}, {im})");
    }
}

#[test]
fn energy_momentum_inconclusive_where_spectrally_stable() {
    // Near the bifurcation from the axisymmetric family (ω = λ): the Hessian on the leaf is
    // indefinite (inconclusive) while the spectrum is on the imaginary axis.
    let s = example((0.7, 0.7)).analyse();
    report("indefinite", &s);
    assert!(!s.energy_momentum.stable && !s.energy_momentum.conclusive);
    assert!(s.spectral.stable);
}

#[test]
fn dedekind_reciprocity_gives_the_same_verdicts() {
    // X ↦ Xᵀ swaps Ω and Λ (Dedekind): (ω, λ) and (λ, ω) have the same shape and spectra.
    for (w, l) in [STABLE, UNSTABLE] {
        let (s, t) = (example((w, l)).analyse(), example((l, w)).analyse());
        let ea: Vec<f64> = s
            .spectral
            .eigenvalues
            .iter()
            .map(|e| e.0.hypot(e.1))
            .collect();
        let eb: Vec<f64> = t
            .spectral
            .eigenvalues
            .iter()
            .map(|e| e.0.hypot(e.1))
            .collect();
        let mut ea = ea;
        let mut eb = eb;
        ea.sort_by(f64::total_cmp);
        eb.sort_by(f64::total_cmp);
        for (x, y) in ea.iter().zip(&eb) {
            assert!((x - y).abs() < 1e-8 * (1.0 + x), "{x} {y}");
        }
        assert_eq!(s.spectral.stable, t.spectral.stable);
        assert_eq!(s.energy_momentum.stable, t.energy_momentum.stable);
    }
}

/// Second derivative matrix of f at x by central second differences with one Richardson step.
fn hessian_by_values(f: &dyn Fn(&[f64]) -> f64, x: &[f64], h: f64) -> Mat {
    let m = x.len();
    let d2 = |h: f64| {
        Mat::from_fn(m, m, |i, j| {
            let v = |si: f64, sj: f64| {
                let mut y = x.to_vec();
                y[i] += si * h;
                y[j] += sj * h;
                f(&y)
            };
            (v(1.0, 1.0) - v(1.0, -1.0) - v(-1.0, 1.0) + v(-1.0, -1.0)) / (4.0 * h * h)
        })
    };
    let (a, b) = (d2(h), d2(0.5 * h));
    (b * 4.0 - a) * (1.0 / 3.0)
}

fn rel(a: &Mat, b: &Mat) -> f64 {
    (a - b).norm_l2() / b.norm_l2()
}

#[test]
fn shape_block_is_the_augmented_hessian_plus_the_amendment() {
    // ∂²/∂a² of the amended potential U + ½⟨m, B_A⁻¹ m⟩ at fixed m = B_A ξ equals the Hessian of
    // the augmented potential U − ½⟨ξ, B_A ξ⟩ (001 (8.12)) plus Gᵀ B_A⁻¹ G with
    // G_k = ∂B_A/∂a_k ξ (differentiate K(a) = ½⟨m, B⁻¹m⟩ twice).
    for p in [STABLE, UNSTABLE] {
        let ex = example(p);
        let s = ex.analyse();
        let pot = ex.body.potential_arc();
        let aug = |a: &[f64]| augmented(&*pot, a, &ex.om, &ex.la);
        let h_aug = hessian_by_values(&aug, &ex.a, 1e-3);
        // G_k by central differences (B_A ξ is quadratic in a: exact).
        let g: Vec<(Mat, Mat)> = (0..3)
            .map(|k| {
                let (mut ap, mut am) = (ex.a.clone(), ex.a.clone());
                ap[k] += 1e-3;
                am[k] -= 1e-3;
                let (mp, np) = momentum::body_momenta(&ap, &ex.om, &ex.la).unwrap();
                let (mm, nm) = momentum::body_momenta(&am, &ex.om, &ex.la).unwrap();
                ((mp - mm) * 500.0, (np - nm) * 500.0)
            })
            .collect();
        let binv: Vec<(Mat, Mat)> = g
            .iter()
            .map(|(x, y)| {
                ReducedState {
                    a: ex.a.clone(),
                    p_a: vec![0.0; 3],
                    p_omega: x.clone(),
                    p_lambda: y.clone(),
                }
                .velocities()
                .unwrap()
            })
            .collect();
        let pairing = |x: &Mat, y: &Mat| 0.5 * (x.transpose() * y).diagonal().column_vector().sum();
        let second = Mat::from_fn(3, 3, |k, l| {
            h_aug[(k, l)] + pairing(&g[k].0, &binv[l].0) + pairing(&g[k].1, &binv[l].1)
        });
        let block = s.hessian.as_ref().submatrix(0, 0, 3, 3).to_owned();
        let e = rel(&block, &second);
        eprintln!("shape block vs augmented + amendment: {e:.2e}");
        assert!(e < 1e-7, "{e}\n{block:?}\n{second:?}");
    }
}

#[test]
fn leaf_hessian_matches_second_differences_of_h_in_the_chart() {
    for p in [STABLE, UNSTABLE, (0.7, 0.7)] {
        let ex = example(p);
        let s = ex.analyse();
        let leaf = Leaf::new(ex.reduced()).unwrap();
        assert_eq!(leaf.dim(), s.leaf_dim);
        let h = |c: &[f64]| leaf.point(c).unwrap().hamiltonian(&ex.body).unwrap();
        let fd = hessian_by_values(&h, &vec![0.0; leaf.dim()], 1e-3);
        let e = rel(&s.hessian, &fd);
        eprintln!("leaf Hessian vs second differences of H: {e:.2e}");
        assert!(e < 1e-7, "{e}");
        // The chart moves the point: every orbit direction changes μ or ν at first order.
        for v in leaf.basis_omega.iter().chain(&leaf.basis_lambda) {
            assert!((v.norm_l2() - 2f64.sqrt()).abs() < 1e-12); // unit for ⟨ξ, η⟩ = ½tr(ξᵀη)
        }
    }
}

#[test]
fn leaf_spectrum_plus_forced_zeros_is_the_full_jacobian_spectrum() {
    for p in [STABLE, UNSTABLE] {
        let s = example(p).analyse();
        // n = 3, μ, ν ≠ 0: each orbit is a 2-sphere, one Casimir each.
        assert_eq!(s.forced_zeros.len(), 2);
        assert_eq!(s.full_spectrum.len(), s.leaf_dim + 2);
        let radius = s
            .full_spectrum
            .iter()
            .map(|e| e.0.hypot(e.1))
            .fold(0.0, f64::max);
        for z in &s.forced_zeros {
            assert!(z.0.hypot(z.1) < 1e-6 * radius, "{z:?}");
        }
        for &(re, im) in &s.spectral.eigenvalues {
            let m = s
                .full_spectrum
                .iter()
                .map(|&(r2, i2)| (r2 - re).hypot(i2 - im))
                .fold(f64::INFINITY, f64::min);
            assert!(
                m < 1e-6 * radius,
                "({re}, {im}) not in the full spectrum, distance {m}"
            );
        }
        eprintln!("full spectrum {:?}", s.full_spectrum);
    }
}

/// Deviation max_i |a_i(t) − a_i| of the semi-axes from `a` along a verlet4 run (dt = 0.01) of
/// the full body from the relative equilibrium X₀ = diag(a), P₀ = ΩA − AΛ perturbed by `eps`,
/// sampled every 0.1 for `steps` steps.
fn deviations(ex: &Example, eps: f64, steps: usize) -> Vec<f64> {
    // SVK is defined on all n×n matrices: let an unstable motion pass through det X = 0.
    let sys = PseudoRigidBody::new(3, ex.body.potential_arc(), false).unwrap();
    let x0 = diag(&ex.a);
    let p0 = &ex.om * &x0 - &x0 * &ex.la;
    let pert = Mat::from_fn(3, 3, |i, j| ((1 + 3 * i + 7 * j) as f64).sin());
    let (x0, p0) = (&x0 + &pert * eps, &p0 + pert.transpose() * eps);
    let traj = integrate(
        &sys,
        "verlet4",
        &sys.state(&x0, &p0).unwrap(),
        0.01,
        steps,
        10,
    )
    .unwrap();
    let mut a0 = ex.a.clone();
    a0.sort_by(|x, y| y.total_cmp(x));
    (0..traj.len())
        .map(|k| {
            let s = sys.singular_values(traj.state(k)).unwrap();
            s.iter()
                .zip(&a0)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        })
        .collect()
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

#[test]
fn simulations_agree_with_the_verdicts() {
    let (st, un) = (example(STABLE), example(UNSTABLE));
    // Up to t = 200 from a 1e-4 perturbation.
    let (ds, du) = (
        max(&deviations(&st, 1e-4, 20_000)),
        max(&deviations(&un, 1e-4, 20_000)),
    );
    eprintln!(
        "max |a(t) − a| up to t = 200 (perturbation 1e-4): stable {ds:.3e}, unstable {du:.3e}"
    );
    assert!(ds < 1e-3, "{ds}");
    assert!(du > 1e-1, "{du}");
    // Unperturbed, the integrator follows the relative equilibrium (t = 50).
    let d0 = max(&deviations(&un, 0.0, 5_000));
    eprintln!("unperturbed unstable equilibrium up to t = 50: {d0:.3e}");
    assert!(d0 < 1e-6, "{d0}");
    // In the linear regime the deviation grows like exp(max Re λ · t): compare the envelopes
    // (maxima over 10 time units) around t = 40 and t = 100.
    let s = un.analyse();
    let d = deviations(&un, 1e-9, 11_000);
    let (e1, e2) = (max(&d[300..400]), max(&d[1000..1100]));
    let rate = (e2 / e1).ln() / 70.0;
    eprintln!(
        "growth rate from the simulation {rate:.4}, max Re λ = {:.4} (envelopes {e1:.2e}, {e2:.2e})",
        s.spectral.max_real_part
    );
    assert!(
        (rate / s.spectral.max_real_part - 1.0).abs() < 0.1,
        "{rate}"
    );
}

#[test]
fn errors_are_typed() {
    let ex = example(STABLE);
    // Not an equilibrium: the shape moved.
    let mut a = ex.a.clone();
    a[0] += 1e-3;
    assert!(matches!(
        stability(&ex.body, &a, &ex.om, &ex.la),
        Err(Error::InvalidArgument { .. })
    ));
    // Coincident semi-axes.
    assert!(matches!(
        stability(&ex.body, &[1.0, 1.0, 0.9], &ex.om, &ex.la),
        Err(Error::DegenerateStratum { .. })
    ));
    let mut a = ex.a.clone();
    a[1] = f64::NAN;
    assert!(matches!(
        stability(&ex.body, &a, &ex.om, &ex.la),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        stability(&ex.body, &ex.a[..2], &ex.om, &ex.la),
        Err(Error::Shape { .. })
    ));
    let mut om = ex.om.clone();
    om[(0, 0)] = 1.0;
    assert!(stability(&ex.body, &ex.a, &om, &ex.la).is_err());
    let e = stability(&ex.body, &[1.2, -0.5, 1.0], &ex.om, &ex.la);
    eprintln!("a_1 < 0: {e:?}");
    assert!(e.is_err());
}

/// The verdicts over a grid of S-type equilibria (`--ignored --nocapture` prints them; the
/// examples above were chosen from it).
#[test]
#[ignore]
fn scan() {
    let (lam_l, mu_l) = (1.0, 1.0);
    for &w in &[0.3, 0.5, 0.7, 0.9, 1.1, 1.3] {
        for &l in &[0.1, 0.3, 0.5, 0.7, 0.9, 1.1] {
            let Some(a) = s_type(lam_l, mu_l, w, l) else {
                continue;
            };
            let body = FullBody::new(3, svk(lam_l, mu_l)).unwrap();
            match stability(&body, &a, &e01(w), &e01(l)) {
                Ok(s) => eprintln!(
                    "w {w} l {l} a {a:.4?}: EM {} min {:.3e}, spectral {} maxRe {:.3e}",
                    s.energy_momentum.stable,
                    s.energy_momentum.min_real_part,
                    s.spectral.stable,
                    s.spectral.max_real_part
                ),
                Err(e) => eprintln!("w {w} l {l} a {a:.4?}: {e}"),
            }
        }
    }
}

#[test]
fn free_body_at_rest_is_finite_and_marginal() {
    // U = 0, Ω = Λ = 0: every shape is an equilibrium, the orbits are points (leaf = (a, p_a)),
    // D²H = diag(0, I) (inconclusive) and L is nilpotent (all eigenvalues 0, spectrally stable).
    let body = FullBody::new(3, Arc::new(potential::Zero)).unwrap();
    let z = Mat::zeros(3, 3);
    let s = stability(&body, &[1.3, 1.0, 0.8], &z, &z).unwrap();
    assert_eq!(s.leaf_dim, 6);
    assert_eq!(s.forced_zeros.len(), 6);
    assert!(!s.energy_momentum.stable && !s.energy_momentum.conclusive);
    assert!(s.spectral.stable);
    let all = s
        .energy_momentum
        .eigenvalues
        .iter()
        .chain(&s.spectral.eigenvalues)
        .chain(&s.full_spectrum);
    assert!(all.clone().all(|e| e.0.is_finite() && e.1.is_finite()));
    assert!(s
        .spectral
        .eigenvalues
        .iter()
        .all(|e| e.0 == 0.0 && e.1 == 0.0));
}

/// The second, independent route: the co-moving linearisation of the full body on the symplectic
/// normal space (`analysis::comoving`, no reduced coordinates) gives the same spectrum and the
/// same verdicts as the reduced leaf.
#[test]
fn comoving_route_agrees_with_the_reduced_leaf() {
    use lieflow::analysis::comoving;
    for p in [STABLE, UNSTABLE, (0.7, 0.7)] {
        let ex = example(p);
        let s = ex.analyse();
        let body = PseudoRigidBody::new(3, svk(LAME.0, LAME.1), true).unwrap();
        let x = diag(&ex.a);
        let pm = &ex.om * &x - &x * &ex.la;
        let z = body.state(&x, &pm).unwrap();
        let xi = [p.0, 0.0, 0.0, p.1, 0.0, 0.0];
        let c = comoving::stability(&body, &z, &xi).unwrap();
        assert_eq!(c.normal_dim, s.leaf_dim, "{p:?}");
        assert_eq!(c.spectral.stable, s.spectral.stable, "{p:?}");
        assert_eq!(c.energy_momentum.stable, s.energy_momentum.stable, "{p:?}");
        let radius = s
            .spectral
            .eigenvalues
            .iter()
            .fold(0.0f64, |m, e| m.max(e.0.hypot(e.1)));
        for &(re, im) in &s.spectral.eigenvalues {
            let d = c
                .spectral
                .eigenvalues
                .iter()
                .map(|&(r2, i2)| (r2 - re).hypot(i2 - im))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d < 1e-6 * radius,
                "{p:?}: no match for ({re}, {im}): {:?}",
                c.spectral
            );
        }
    }
}

/// The co-moving analysis takes ∇⟨J, ξ⟩ = (−ξ_Z^p, ξ_Z^q) from the generator (issue 26: exact,
/// no nested differences): J must be the momentum map of the cotangent-lifted action. Checked
/// against central differences of `momentum_map` (exact for a quadratic J up to round-off).
#[test]
fn the_momentum_map_generates_the_action() {
    use lieflow::integrate::problem::Symmetric;
    let body = PseudoRigidBody::new(3, svk(LAME.0, LAME.1), true).unwrap();
    let z: Vec<f64> = (0..18)
        .map(|i| ((i * 7 + 3) % 11) as f64 / 5.0 - 1.0)
        .collect();
    let xi = [0.3, -0.7, 0.2, 1.1, 0.4, -0.5];
    let gen = body.generator(&xi, &z).unwrap();
    let pairing = |z: &[f64]| -> f64 {
        let j = body.momentum_map(z).unwrap();
        j.iter().zip(&xi).map(|(a, b)| a * b).sum()
    };
    for k in 0..18 {
        let h = 1e-3;
        let (mut zp, mut zm) = (z.clone(), z.clone());
        zp[k] += h;
        zm[k] -= h;
        let fd = (pairing(&zp) - pairing(&zm)) / (2.0 * h);
        let exact = if k < 9 { -gen[9 + k] } else { gen[k - 9] };
        assert!((fd - exact).abs() < 1e-11, "{k}: {fd} vs {exact}");
    }
}
