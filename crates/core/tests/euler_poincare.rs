//! Mechanics from a reduced Lagrangian (issue 24, 000 §4): the built-in bodies come out of their
//! Lagrangians (the free rigid body from ½⟨Ω, 𝕀Ω⟩, the heavy top from ℓ(Ω, Γ) with the vector
//! action), a non-quadratic ℓ against its Euler–Poincaré equation solved independently, the
//! Legendre transform inverted to round-off, the right system as the mirror of the left, and the
//! diamond map against its definition.

// Index loops mirror the index notation of the formulas they check.
#![allow(clippy::needless_range_loop)]

use std::sync::Arc;

use lieflow::integrate::{integrate, Problem};
use lieflow::systems::user::{
    Action, EulerPoincare, Lagrangian, LagrangianFn, LagrangianGradientFn,
};
use lieflow::systems::{Algebra, HeavyTop, LieHamiltonian, LiePoisson, RigidBody, Side};

mod common;
use common::distance as dist;

const I: [f64; 3] = [1.0, 2.0, 3.0];
const M0: [f64; 3] = [1.0, 0.5, -0.3];

fn diag(v: &[f64]) -> Vec<f64> {
    let d = v.len();
    let mut a = vec![0.0; d * d];
    for i in 0..d {
        a[i * d + i] = v[i];
    }
    a
}

fn cross(a: &[f64], b: &[f64]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[test]
fn the_free_rigid_body_comes_out_of_its_quadratic_lagrangian() {
    // ℓ(Ω) = ½⟨Ω, 𝕀Ω⟩ on so(3): over t = 10 against the exact elliptic solution.
    let ep = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Quadratic(diag(&I)),
        Side::Left,
        None,
    )
    .unwrap();
    assert!(ep.system().is_quadratic());
    let body = RigidBody::new(I).unwrap();
    let exact = integrate(&body, "exact", &M0, 0.01, 1000, 100).unwrap();
    let run = integrate(ep.system(), "rkmk4", &M0, 0.01, 1000, 100).unwrap();
    for k in 0..exact.len() {
        assert!(dist(run.state(k), exact.state(k)) < 1e-8, "sample {k}");
    }
    // The same method on the built-in body gives the same trajectory.
    let builtin = integrate(&body, "rkmk4", &M0, 0.01, 1000, 100).unwrap();
    for k in 0..builtin.len() {
        assert!(dist(run.state(k), builtin.state(k)) < 1e-13, "sample {k}");
    }
}

/// ℓ(Ω, Γ) = ½⟨Ω, 𝕀Ω⟩ − mgl⟨Γ, χ⟩ and its gradient (∂ℓ/∂Ω, ∂ℓ/∂Γ) = (𝕀Ω, −mgl χ).
fn heavy_top_lagrangian(mgl: f64, chi: [f64; 3]) -> Lagrangian {
    let value: LagrangianFn = Arc::new(move |w: &[f64], g: &[f64]| {
        let t: f64 = (0..3).map(|i| 0.5 * I[i] * w[i] * w[i]).sum();
        Ok(t - mgl * (0..3).map(|i| g[i] * chi[i]).sum::<f64>())
    });
    let gradient: LagrangianGradientFn = Arc::new(
        move |w: &[f64], _g: &[f64], dw: &mut [f64], dg: &mut [f64]| {
            for i in 0..3 {
                dw[i] = I[i] * w[i];
                dg[i] = -mgl * chi[i];
            }
            Ok(())
        },
    );
    Lagrangian::Function {
        value,
        gradient: Some(gradient),
        hessian: None,
    }
}

#[test]
fn the_heavy_top_comes_out_of_its_lagrangian_with_the_vector_action() {
    let (mgl, chi) = (0.7, [0.0, 0.6, 0.8]);
    let ep = EulerPoincare::new(
        Algebra::So3,
        heavy_top_lagrangian(mgl, chi),
        Side::Left,
        Some((Action::Vector, 3)),
    )
    .unwrap();
    let top = HeavyTop::new(I, mgl, chi).unwrap();
    let z0 = top.state(M0, [0.3, -0.2, (1.0f64 - 0.13).sqrt()]);
    // The equations: the field of the Lie–Poisson form is the heavy top's, Ṁ = M × Ω + mgl Γ × χ.
    let (mut f_ep, mut f_top) = (vec![0.0; 6], vec![0.0; 6]);
    lieflow::integrate::problem::VectorField::field(ep.system(), &z0, &mut f_ep);
    lieflow::integrate::problem::VectorField::field(&top, &z0, &mut f_top);
    assert!(dist(&f_ep, &f_top) < 1e-14, "{f_ep:?} {f_top:?}");
    // Over t = 10 with rk4 on both: the same trajectory up to the Legendre inversion's rounding;
    // and the energy is the heavy top's.
    let a = integrate(ep.system(), "rk4", &z0, 0.01, 1000, 100).unwrap();
    let b = integrate(&top, "rk4", &z0, 0.01, 1000, 100).unwrap();
    for k in 0..a.len() {
        assert!(dist(a.state(k), b.state(k)) < 1e-11, "sample {k}");
    }
    let (e_ep, e_top) = (ep.system().energy(&z0).unwrap(), top.energy(&z0).unwrap());
    assert!((e_ep - e_top).abs() < 1e-14, "{e_ep} {e_top}");
    // The Casimirs |Γ|², M·Γ kept to round-off by the coadjoint methods.
    let c = integrate(ep.system(), "rkmk4", &z0, 0.01, 1000, 100).unwrap();
    let c0 = ep.system().invariants(&z0).unwrap();
    let c1 = ep.system().invariants(c.state(c.len() - 1)).unwrap();
    assert!(dist(&c0, &c1) < 1e-13, "{c0:?} {c1:?}");
}

#[test]
fn the_diamond_is_minus_the_pairing_with_the_action() {
    // ⟨b ⋄ a, η⟩ = −⟨b, η·a⟩ with η·a = η̂ a for the vector action of so(3): b ⋄ a = b × a,
    // so ∂ℓ/∂Γ ⋄ Γ = −mgl χ × Γ = mgl Γ × χ, the heavy top's torque.
    let ep = EulerPoincare::new(
        Algebra::So3,
        heavy_top_lagrangian(0.7, [0.0, 0.0, 1.0]),
        Side::Left,
        Some((Action::Vector, 3)),
    )
    .unwrap();
    let (b, a) = ([0.3, -1.1, 0.4], [0.2, 0.5, -0.7]);
    let mut out = [0.0; 3];
    ep.diamond(&b, &a, &mut out);
    assert!(dist(&out, &cross(&b, &a)) < 1e-15);
    for eta in [[1.0, 0.0, 0.0], [0.2, -0.4, 0.9]] {
        let eta_a = cross(&eta, &a);
        let lhs: f64 = (0..3).map(|i| out[i] * eta[i]).sum();
        let rhs: f64 = -(0..3).map(|i| b[i] * eta_a[i]).sum::<f64>();
        assert!((lhs - rhs).abs() < 1e-15);
    }
}

/// ℓ(Ω) = ½⟨Ω, 𝕀Ω⟩ + (c/4)|Ω|⁴ (and, for the mirror, ℓ(−Ω) + s⟨Ω, Ω⟩⟨k, Ω⟩/3 terms).
fn quartic(c: f64, odd: f64) -> Lagrangian {
    let k = [0.3, -0.2, 0.5];
    let value: LagrangianFn = Arc::new(move |w: &[f64], _: &[f64]| {
        let n2: f64 = w.iter().map(|x| x * x).sum();
        let kw: f64 = (0..3).map(|i| k[i] * w[i]).sum();
        let t: f64 = (0..3).map(|i| 0.5 * I[i] * w[i] * w[i]).sum();
        Ok(t + 0.25 * c * n2 * n2 + odd * n2 * kw / 3.0)
    });
    let gradient: LagrangianGradientFn =
        Arc::new(move |w: &[f64], _: &[f64], dw: &mut [f64], _: &mut [f64]| {
            let n2: f64 = w.iter().map(|x| x * x).sum();
            let kw: f64 = (0..3).map(|i| k[i] * w[i]).sum();
            for i in 0..3 {
                dw[i] = I[i] * w[i] + c * n2 * w[i] + odd * (2.0 * w[i] * kw + n2 * k[i]) / 3.0;
            }
            Ok(())
        });
    Lagrangian::Function {
        value,
        gradient: Some(gradient),
        hessian: None,
    }
}

#[test]
fn a_quartic_lagrangian_against_its_euler_poincare_equation_solved_independently() {
    let c = 0.4;
    let ep = EulerPoincare::new(Algebra::So3, quartic(c, 0.0), Side::Left, None).unwrap();
    let l = ep.legendre();
    // The Legendre transform inverted to round-off.
    let w0 = [0.8, -0.4, 0.3];
    let mut mu0 = [0.0; 3];
    l.momentum(&w0, &[], &mut mu0).unwrap();
    let mut back = [0.0; 3];
    l.velocity(&mu0, &[], &mut back).unwrap();
    assert!(dist(&back, &w0) < 4.0 * f64::EPSILON, "{back:?}");
    // The reference: d/dt ∂ℓ/∂Ω = ∂ℓ/∂Ω × Ω written as an ODE in Ω,
    // (𝕀 + c(|Ω|²1 + 2ΩΩᵀ)) Ω̇ = μ × Ω, by RK4 with h = 1e-4 (error ~1e-16 here).
    let rhs = |w: [f64; 3]| -> [f64; 3] {
        let n2: f64 = w.iter().map(|x| x * x).sum();
        let mu: Vec<f64> = (0..3).map(|i| I[i] * w[i] + c * n2 * w[i]).collect();
        let f = cross(&mu, &w);
        let m = nalgebra::Matrix3::from_fn(|i, j| {
            (if i == j { I[i] + c * n2 } else { 0.0 }) + 2.0 * c * w[i] * w[j]
        });
        let x = m.lu().solve(&nalgebra::Vector3::from(f)).unwrap();
        [x[0], x[1], x[2]]
    };
    let (h, steps) = (1e-4, 100_000);
    let mut w = w0;
    for _ in 0..steps {
        let add =
            |a: [f64; 3], b: [f64; 3], s: f64| [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]];
        let k1 = rhs(w);
        let k2 = rhs(add(w, k1, 0.5 * h));
        let k3 = rhs(add(w, k2, 0.5 * h));
        let k4 = rhs(add(w, k3, h));
        for i in 0..3 {
            w[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    let mut mu_ref = [0.0; 3];
    l.momentum(&w, &[], &mut mu_ref).unwrap();
    let run = integrate(ep.system(), "rkmk4", &mu0, 1e-3, 10_000, 10_000).unwrap();
    let end = run.state(run.len() - 1);
    assert!(dist(end, &mu_ref) < 1e-9, "{end:?} {mu_ref:?}");
    // The energy E = ⟨μ, Ω⟩ − ℓ is kept by the symmetric Lie midpoint (bounded error).
    let mid = integrate(ep.system(), "midpoint", &mu0, 1e-2, 2000, 100).unwrap();
    let e0 = ep.system().energy(&mu0).unwrap();
    for k in 0..mid.len() {
        let e = ep.system().energy(mid.state(k)).unwrap();
        assert!((e - e0).abs() < 1e-4 * e0, "sample {k}: {e} {e0}");
    }
}

#[test]
fn a_right_invariant_lagrangian_is_the_left_one_of_the_inverse_motion() {
    // The right system of ℓ from μ₀ is the left system of ℓ̃(η) = ℓ(−η) from −μ₀, negated.
    // ℓ with an odd term, so ℓ̃ ≠ ℓ: ℓ̃(η) = ½⟨η, 𝕀η⟩ + (c/4)|η|⁴ − (odd term).
    let right = EulerPoincare::new(Algebra::So3, quartic(0.4, 0.5), Side::Right, None).unwrap();
    let mirror = EulerPoincare::new(Algebra::So3, quartic(0.4, -0.5), Side::Left, None).unwrap();
    let left = EulerPoincare::new(Algebra::So3, quartic(0.4, 0.5), Side::Left, None).unwrap();
    let minus: Vec<f64> = M0.iter().map(|x| -x).collect();
    for method in ["rkmk4", "midpoint", "rk4"] {
        let r = integrate(right.system(), method, &M0, 0.01, 300, 30).unwrap();
        let m = integrate(mirror.system(), method, &minus, 0.01, 300, 30).unwrap();
        let l = integrate(left.system(), method, &M0, 0.01, 300, 30).unwrap();
        for k in 0..r.len() {
            let negated: Vec<f64> = m.state(k).iter().map(|x| -x).collect();
            assert!(dist(r.state(k), &negated) < 1e-14, "{method} sample {k}");
        }
        assert!(dist(r.state(10), l.state(10)) > 1e-3, "{method}");
    }
}

#[test]
fn a_singular_legendre_map_is_a_typed_error_naming_the_point() {
    // ℓ = ¼|ξ|⁴: ∂²ℓ/∂ξ² = 0 at ξ = 0, where Newton starts.
    let value: LagrangianFn = Arc::new(|w: &[f64], _: &[f64]| {
        let n2: f64 = w.iter().map(|x| x * x).sum();
        Ok(0.25 * n2 * n2)
    });
    let ep = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Function {
            value,
            gradient: None,
            hessian: None,
        },
        Side::Left,
        None,
    )
    .unwrap();
    let mut xi = [0.0; 3];
    let e = ep.legendre().velocity(&M0, &[], &mut xi).unwrap_err();
    let s = e.to_string();
    assert!(s.contains("singular at xi = [0, 0, 0]"), "{s}");
    // A bad inertia is refused.
    for (i, what) in [
        (
            vec![1.0, 0.1, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0],
            "symmetric",
        ),
        (diag(&[1.0, -2.0, 3.0]), "positive definite"),
    ] {
        let e = EulerPoincare::new(Algebra::So3, Lagrangian::Quadratic(i), Side::Left, None)
            .err()
            .unwrap();
        assert!(e.to_string().contains(what), "{e}");
    }
}

/// A rotation about a unit axis by an angle (row-major).
fn rotation(axis: [f64; 3], angle: f64) -> [f64; 9] {
    let r = nalgebra::Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(nalgebra::Vector3::from(axis)),
        angle,
    );
    let m = r.matrix();
    std::array::from_fn(|k| m[(k / 3, k % 3)])
}

#[test]
fn the_noether_momentum_is_conserved_along_the_motion() {
    // 000 Theorem 4.3 (4.2 for the rigid body): along a left-invariant motion (M(t), R(t)) the
    // spatial momentum Ad*_{R⁻¹} M = R M is constant; with the right-invariant Lagrangian the
    // same motion is (−M, Rᵀ) (the mirror) and Ad*_{Rᵀ}(−M) = −R M (Theorem 4.4).
    let left = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Quadratic(diag(&I)),
        Side::Left,
        None,
    )
    .unwrap();
    let right = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Quadratic(diag(&I)),
        Side::Right,
        None,
    )
    .unwrap();
    let body = RigidBody::new(I).unwrap().with_attitude();
    let r0 = rotation([0.3, -0.5, 0.8], 0.7);
    let z0 = body.state_with_attitude(M0, r0);
    let tr = integrate(&body, "splitting", &z0, 0.01, 2000, 100).unwrap();
    let mut p0 = [0.0; 3];
    left.noether(&M0, &r0, &mut p0).unwrap();
    for k in 0..tr.len() {
        let z = tr.state(k);
        let (m, r) = (&z[..3], &z[3..12]);
        let mut p = [0.0; 3];
        left.noether(m, r, &mut p).unwrap();
        assert!(dist(&p, &p0) < 1e-13, "sample {k}: {p:?} {p0:?}");
        let rt: Vec<f64> = (0..9).map(|i| r[(i % 3) * 3 + i / 3]).collect();
        let minus: Vec<f64> = m.iter().map(|x| -x).collect();
        right.noether(&minus, &rt, &mut p).unwrap();
        assert!(dist(&p, &p0.map(|x| -x)) < 1e-13, "sample {k}");
    }
    // The heavy top (Theorem 4.11): only the vertical component e₃·(R M) is conserved.
    let (mgl, chi) = (0.7, [0.0, 0.6, 0.8]);
    let ep = EulerPoincare::new(
        Algebra::So3,
        heavy_top_lagrangian(mgl, chi),
        Side::Left,
        Some((Action::Vector, 3)),
    )
    .unwrap();
    let top = HeavyTop::new(I, mgl, chi).unwrap().with_attitude();
    let tr = integrate(
        &top,
        "splitting",
        &top.state_with_attitude(M0, r0),
        0.01,
        2000,
        100,
    )
    .unwrap();
    let (mut first, mut moved) = (None, 0.0f64);
    for k in 0..tr.len() {
        let z = tr.state(k);
        let mut p = [0.0; 3];
        ep.noether(&z[..6], &z[6..15], &mut p).unwrap();
        let p0 = *first.get_or_insert(p);
        assert!((p[2] - p0[2]).abs() < 1e-13, "sample {k}: {p:?} {p0:?}");
        moved = moved.max((p[0] - p0[0]).abs());
    }
    assert!(
        moved > 1e-2,
        "the horizontal components are not conserved: {moved}"
    );
    // Bad group elements are refused.
    let mut p = [0.0; 3];
    assert!(left
        .noether(&M0, &[1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 1.0], &mut p)
        .is_err());
    assert!(left.noether(&M0, &[1.0, 0.0, 0.0, 1.0], &mut p).is_err());
}

#[test]
fn the_noether_momentum_of_so_n_and_se3_composes_as_the_coadjoint_action() {
    // π(μ, g₁g₂) = Ad*_{g₁⁻¹} π(μ, g₂) (left): g₁ π g₁ᵀ on so(n); on se(3) the spatial
    // momentum of a body at (R, t): (R M + t × R Γ, R Γ).
    let n = 4;
    let ep = EulerPoincare::new(
        Algebra::So(n),
        Lagrangian::Quadratic(diag(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0])),
        Side::Left,
        None,
    )
    .unwrap();
    let q = |a: f64, b: f64| {
        // A rotation of ℝ⁴ in the planes (0, 1) and (2, 3).
        let mut g = [0.0; 16];
        g[0] = a.cos();
        g[1] = -a.sin();
        g[4] = a.sin();
        g[5] = a.cos();
        g[10] = b.cos();
        g[11] = -b.sin();
        g[14] = b.sin();
        g[15] = b.cos();
        g
    };
    let (g1, g2) = (q(0.4, -0.9), q(1.1, 0.3));
    let mut g12 = [0.0; 16];
    for i in 0..4 {
        for j in 0..4 {
            g12[i * 4 + j] = (0..4).map(|k| g1[i * 4 + k] * g2[k * 4 + j]).sum();
        }
    }
    let mu = [0.3, -0.2, 0.5, 0.1, 0.4, -0.6];
    let (mut p12, mut p2, mut p1_of_p2) = ([0.0; 6], [0.0; 6], [0.0; 6]);
    ep.noether(&mu, &g12, &mut p12).unwrap();
    ep.noether(&mu, &g2, &mut p2).unwrap();
    ep.noether(&p2, &g1, &mut p1_of_p2).unwrap();
    assert!(dist(&p12, &p1_of_p2) < 1e-15, "{p12:?} {p1_of_p2:?}");
    // The norm of the momentum (a Casimir of so(n)*: ½ tr(MᵀM)) is kept by the action.
    let n2 = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
    assert!((n2(&p12) - n2(&mu)).abs() < 1e-15);
    // se(3): for g = (R, t), Ad*_{g⁻¹}(M, Γ) = (R M + t × R Γ, R Γ).
    let ep = EulerPoincare::new(
        Algebra::Se3,
        Lagrangian::Quadratic(diag(&[1.0; 6])),
        Side::Left,
        None,
    )
    .unwrap();
    let r = rotation([0.3, -0.5, 0.8], 0.7);
    let t = [0.4, -1.2, 0.9];
    let mut g = [0.0; 16];
    for i in 0..3 {
        for j in 0..3 {
            g[i * 4 + j] = r[i * 3 + j];
        }
        g[i * 4 + 3] = t[i];
    }
    g[15] = 1.0;
    let mu = [1.0, 0.5, -0.3, 0.2, -0.1, 0.4];
    let mut p = [0.0; 6];
    ep.noether(&mu, &g, &mut p).unwrap();
    let rv = |v: &[f64]| -> [f64; 3] {
        std::array::from_fn(|i| (0..3).map(|j| r[i * 3 + j] * v[j]).sum())
    };
    let (rm, rg) = (rv(&mu[..3]), rv(&mu[3..]));
    let tg = cross(&t, &rg);
    let want = [
        rm[0] + tg[0],
        rm[1] + tg[1],
        rm[2] + tg[2],
        rg[0],
        rg[1],
        rg[2],
    ];
    assert!(dist(&p, &want) < 1e-14, "{p:?} {want:?}");
}

/// g₁ g₂ for n×n row-major matrices.
fn matmul(n: usize, a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut c = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            c[i * n + j] = (0..n).map(|k| a[i * n + k] * b[k * n + j]).sum();
        }
    }
    c
}

/// max |gᵀg − I| of an n×n row-major matrix's n×n block of rows and columns `k`.
fn orthogonality_defect(n: usize, k: usize, g: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            let s: f64 = (0..k).map(|l| g[l * n + i] * g[l * n + j]).sum();
            worst = worst.max((s - if i == j { 1.0 } else { 0.0 }).abs());
        }
    }
    worst
}

#[test]
fn the_attitude_of_a_lie_poisson_system_is_the_rigid_body_attitude_on_so3() {
    // ℓ = ½⟨Ω, 𝕀Ω⟩ lifted: (M, R) against the built-in body with attitude, same method (the
    // same reconstruction R ← R exp(−θ)), and against the exact solution.
    let ep = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Quadratic(diag(&I)),
        Side::Left,
        None,
    )
    .unwrap();
    let sys = ep.system().with_attitude().unwrap();
    assert_eq!(sys.space().dim(), 12);
    let body = RigidBody::new(I).unwrap().with_attitude();
    let r0 = rotation([0.3, -0.5, 0.8], 0.7);
    let z0 = body.state_with_attitude(M0, r0);
    let exact = integrate(&body, "exact", &z0, 0.01, 1000, 100).unwrap();
    let builtin = integrate(&body, "rkmk4", &z0, 0.01, 1000, 100).unwrap();
    for method in ["rkmk4", "midpoint"] {
        let run = integrate(&sys, method, &z0, 0.01, 1000, 100).unwrap();
        for k in 0..run.len() {
            if method == "rkmk4" {
                assert!(dist(run.state(k), builtin.state(k)) < 1e-12, "sample {k}");
            }
            let tol = if method == "rkmk4" { 1e-8 } else { 1e-3 };
            assert!(dist(run.state(k), exact.state(k)) < tol, "{method} {k}");
        }
    }
    // A non-rotation is refused at the start.
    let mut bad = z0.clone();
    bad[3] = 2.0;
    assert!(integrate(&sys, "rkmk4", &bad, 0.01, 10, 1).is_err());
    // Structure constants have no matrix group, hence no attitude.
    let so3: Vec<f64> = (0..27)
        .map(|c| {
            let (i, j, k) = (c / 9, (c / 3) % 3, c % 3);
            match (i, j, k) {
                (0, 1, 2) | (1, 2, 0) | (2, 0, 1) => 1.0,
                (1, 0, 2) | (2, 1, 0) | (0, 2, 1) => -1.0,
                _ => 0.0,
            }
        })
        .collect();
    let generic = EulerPoincare::new(
        Algebra::Constants(so3),
        Lagrangian::Quadratic(diag(&I)),
        Side::Left,
        None,
    )
    .unwrap();
    assert!(generic.system().with_attitude().is_none());
}

/// A rotation of ℝ⁴ in the planes (0, 1) and (2, 3), row-major.
fn rotation4(a: f64, b: f64) -> Vec<f64> {
    let mut g = vec![0.0; 16];
    g[0] = a.cos();
    g[1] = -a.sin();
    g[4] = a.sin();
    g[5] = a.cos();
    g[10] = b.cos();
    g[11] = -b.sin();
    g[14] = b.sin();
    g[15] = b.cos();
    g
}

#[test]
fn the_configuration_keeps_the_noether_momentum_on_so4_and_se3_and_converges_at_the_order() {
    // so(4), ℓ = ½⟨Ω, JΩ + ΩJ⟩ = ½ Σ_{i<j} (J_i + J_j) Ω_ij² (the generalized rigid body), and a
    // Kirchhoff body on se(3) with a coupled inertia: the Noether momentum (in the invariants
    // after the Casimirs) is kept to round-off by the orbit methods, g stays in the group, and
    // rkmk4's configuration converges at order 4.
    let j = [1.0, 1.5, 2.2, 3.1];
    let mut inertia = Vec::new();
    for a in 0..4 {
        for b in a + 1..4 {
            inertia.push(j[a] + j[b]);
        }
    }
    let mut kirchhoff = diag(&[2.0, 3.0, 4.0, 1.0, 1.5, 2.5]);
    kirchhoff[2] = 0.3;
    kirchhoff[12] = 0.3;
    kirchhoff[4] = -0.2;
    kirchhoff[24] = -0.2;
    let se3_g0 = {
        let r = rotation([0.3, -0.5, 0.8], 0.7);
        let mut g = vec![0.0; 16];
        for i in 0..3 {
            g[i * 4..i * 4 + 3].copy_from_slice(&r[i * 3..i * 3 + 3]);
            g[i * 4 + 3] = [0.4, -1.2, 0.9][i];
        }
        g[15] = 1.0;
        g
    };
    // (algebra, inertia, μ₀, g₀, the size of g's orthogonal block)
    type Case = (Algebra, Vec<f64>, Vec<f64>, Vec<f64>, usize);
    let cases: [Case; 2] = [
        (
            Algebra::So(4),
            diag(&inertia),
            vec![0.3, -0.2, 0.5, 0.1, 0.4, -0.6],
            rotation4(0.4, -0.9),
            4,
        ),
        (
            Algebra::Se3,
            kirchhoff,
            vec![1.0, 0.5, -0.3, 0.2, -0.1, 0.4],
            se3_g0,
            3,
        ),
    ];
    for (algebra, inertia, mu0, g0, rot) in cases {
        let name = format!("{algebra:?}");
        let ep =
            EulerPoincare::new(algebra, Lagrangian::Quadratic(inertia), Side::Left, None).unwrap();
        let sys = ep.system().with_attitude().unwrap();
        let z0 = [mu0.clone(), g0.clone()].concat();
        let casimirs = ep.system().invariant_count();
        let inv0 = sys.invariants(&z0).unwrap();
        assert_eq!(inv0.len(), casimirs + 6, "{name}");
        for method in ["rkmk4", "midpoint"] {
            let run = integrate(&sys, method, &z0, 0.01, 2000, 200).unwrap();
            for k in 0..run.len() {
                let z = run.state(k);
                let inv = sys.invariants(z).unwrap();
                let drift = dist(&inv[casimirs..], &inv0[casimirs..]);
                assert!(
                    drift < 2e-14,
                    "{name} {method} sample {k}: Noether drift {drift:e}"
                );
                let defect = orthogonality_defect(4, rot, &z[6..]);
                assert!(defect < 1e-14, "{name} {method}: {defect:e}");
            }
            // The motion moves g (the test is not vacuous).
            assert!(dist(&run.state(run.len() - 1)[6..], &g0) > 0.1, "{name}");
        }
        // Order 4 of the configuration: errors at dt and dt/2 against dt/8.
        let reference = integrate(&sys, "rkmk4", &z0, 0.0125, 800, 800).unwrap();
        let err = |dt: f64, steps: usize| {
            let r = integrate(&sys, "rkmk4", &z0, dt, steps, steps).unwrap();
            dist(&r.state(1)[6..], &reference.state(1)[6..])
        };
        let ratio = err(0.1, 100) / err(0.05, 200);
        assert!((13.0..19.0).contains(&ratio), "{name}: ratio {ratio}");
    }
}

#[test]
fn the_right_configuration_is_the_inverse_of_the_left_one() {
    // The mirror g ↦ g⁻¹ with the configuration: the right run of H from (μ₀, g₀) is the left run
    // of H(−μ) = H (quadratic) from (−μ₀, g₀⁻¹), negated and inverted; its Noether momentum
    // Ad*_g μ is kept.
    let make = |side| {
        EulerPoincare::new(
            Algebra::So(4),
            Lagrangian::Quadratic(diag(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0])),
            side,
            None,
        )
        .unwrap()
        .system()
        .with_attitude()
        .unwrap()
    };
    let (left, right) = (make(Side::Left), make(Side::Right));
    let mu0 = [0.3, -0.2, 0.5, 0.1, 0.4, -0.6];
    let g0 = rotation4(0.4, -0.9);
    let g0t: Vec<f64> = (0..16).map(|k| g0[(k % 4) * 4 + k / 4]).collect();
    let zr = [mu0.to_vec(), g0.clone()].concat();
    let zl = [mu0.iter().map(|x| -x).collect(), g0t].concat();
    let rr = integrate(&right, "rkmk4", &zr, 0.01, 1000, 100).unwrap();
    let rl = integrate(&left, "rkmk4", &zl, 0.01, 1000, 100).unwrap();
    let inv0 = right.invariants(&zr).unwrap();
    for k in 0..rr.len() {
        let (a, b) = (rr.state(k), rl.state(k));
        let neg: Vec<f64> = b[..6].iter().map(|x| -x).collect();
        assert!(dist(&a[..6], &neg) < 1e-14, "sample {k}");
        let gl_t: Vec<f64> = (0..16).map(|q| b[6 + (q % 4) * 4 + q / 4]).collect();
        assert!(dist(&a[6..], &gl_t) < 1e-13, "sample {k}");
        let inv = right.invariants(a).unwrap();
        assert!(dist(&inv, &inv0) < 1e-13, "sample {k}");
        // g g⁻¹ = 1 as a check of the helper.
        let id = matmul(4, &a[6..], &b[6..]);
        assert!((id[0] - 1.0).abs() < 1e-13);
    }
}

/// The error at the end of `method` on `sys` from z0 over t = `t` in `steps` steps against `want`.
fn end_error(
    sys: &EulerPoincare,
    method: &str,
    z0: &[f64],
    t: f64,
    steps: usize,
    want: &[f64],
) -> f64 {
    let r = integrate(sys, method, z0, t / steps as f64, steps, steps).unwrap();
    dist(r.state(1), want)
}

#[test]
fn the_variational_method_converges_at_orders_2_4_6_and_keeps_the_coadjoint_orbit() {
    // The free rigid body from ℓ = ½⟨Ω, 𝕀Ω⟩ against its exact solution (M and R): the discrete
    // Euler–Poincaré method is of order 2 and its Suzuki/Yoshida compositions of orders 4 and 6
    // (which also shows that the method is symmetric); |M|² and R M are kept to round-off.
    let ep = EulerPoincare::new(
        Algebra::So3,
        Lagrangian::Quadratic(diag(&I)),
        Side::Left,
        None,
    )
    .unwrap()
    .with_attitude()
    .unwrap();
    let body = RigidBody::new(I).unwrap().with_attitude();
    let z0 = body.state_with_attitude(M0, rotation([0.3, -0.5, 0.8], 0.7));
    let t = 4.0;
    let exact = integrate(&body, "exact", &z0, t, 1, 1).unwrap();
    let want = exact.state(1);
    for (method, order, steps) in [
        ("variational", 2, 100),
        ("variational4", 4, 40),
        ("variational6", 6, 20),
    ] {
        let ratio = end_error(&ep, method, &z0, t, steps, want)
            / end_error(&ep, method, &z0, t, 2 * steps, want);
        let expect = 2f64.powi(order);
        assert!(
            (0.75 * expect..1.3 * expect).contains(&ratio),
            "{method}: ratio {ratio}, expected {expect}"
        );
    }
    // The method and the built-in LGVI are different second-order discretisations of the same
    // motion: their difference shrinks like h².
    let diff = |steps: usize| {
        let dt = t / steps as f64;
        let a = integrate(&ep, "variational", &z0, dt, steps, steps).unwrap();
        let b = integrate(&body, "lgvi", &z0, dt, steps, steps).unwrap();
        dist(&a.state(1)[..3], &b.state(1)[..3])
    };
    let ratio = diff(200) / diff(400);
    assert!(
        (3.5..4.5).contains(&ratio),
        "variational − lgvi: ratio {ratio}"
    );
    // 10⁵ steps: the Casimir and the Noether momentum R M to round-off.
    let run = integrate(&ep, "variational", &z0, 0.01, 100_000, 10_000).unwrap();
    let inv0 = ep.invariants(&z0).unwrap();
    let (e0, mut de) = (ep.energy(&z0).unwrap(), 0.0f64);
    for k in 0..run.len() {
        let inv = ep.invariants(run.state(k)).unwrap();
        assert!((inv[0] - inv0[0]).abs() < 1e-13, "sample {k}: |M|² {inv:?}");
        let drift = dist(&inv[1..], &inv0[1..]);
        assert!(drift <= 1e-13, "sample {k}: Noether drift {drift:e}");
        de = de.max((ep.energy(run.state(k)).unwrap() - e0).abs());
    }
    // Bounded energy error (a symplectic method): O(h²), no drift.
    assert!(de < 1e-4 * e0, "energy error {de:e}");
}

#[test]
fn the_variational_method_on_the_heavy_top_so4_and_se3() {
    // The heavy top from ℓ(Ω, Γ) with its attitude: against the built-in top (a fine splitting8 run),
    // the Casimirs |Γ|², M·Γ and the vertical Noether component e₃·(R M) to round-off.
    let (mgl, chi) = (0.7, [0.0, 0.6, 0.8]);
    let ep = EulerPoincare::new(
        Algebra::So3,
        heavy_top_lagrangian(mgl, chi),
        Side::Left,
        Some((Action::Vector, 3)),
    )
    .unwrap()
    .with_attitude()
    .unwrap();
    let top = HeavyTop::new(I, mgl, chi).unwrap().with_attitude();
    let r0 = rotation([0.3, -0.5, 0.8], 0.7);
    let z0 = top.state_with_attitude(M0, r0);
    let reference = integrate(&top, "splitting8", &z0, 1e-3, 10_000, 10_000).unwrap();
    let run = integrate(&ep, "variational6", &z0, 0.02, 500, 500).unwrap();
    let err = dist(run.state(1), reference.state(1));
    assert!(err < 1e-8, "variational6 against the heavy top: {err:e}");
    let ratio = end_error(
        &ep,
        "variational",
        &z0,
        2.0,
        100,
        reference_at(&top, &z0, 2.0).as_slice(),
    ) / end_error(
        &ep,
        "variational",
        &z0,
        2.0,
        200,
        reference_at(&top, &z0, 2.0).as_slice(),
    );
    assert!(
        (3.3..4.8).contains(&ratio),
        "order 2 with a parameter: ratio {ratio}"
    );
    let long = integrate(&ep, "variational", &z0, 0.01, 20_000, 1000).unwrap();
    let vertical = |z: &[f64]| {
        let mut p = [0.0; 3];
        ep.noether(&z[..6], &z[6..], &mut p).unwrap();
        p[2]
    };
    let (c0, v0) = (top.invariants(&z0).unwrap(), vertical(&z0));
    for k in 0..long.len() {
        let z = long.state(k);
        let c = ep.invariants(z).unwrap();
        assert!(
            (c[0] - c0[0]).abs() < 1e-13 && (c[1] - c0[1]).abs() < 1e-13,
            "{k}: {c:?}"
        );
        assert!((vertical(z) - v0).abs() < 1e-13, "sample {k}: e3·RM");
    }
    // so(4) and a Kirchhoff body on se(3): Casimirs and the Noether momentum.
    let mut kirchhoff = diag(&[2.0, 3.0, 4.0, 1.0, 1.5, 2.5]);
    kirchhoff[2] = 0.3;
    kirchhoff[12] = 0.3;
    let mut g_se3 = vec![0.0; 16];
    for i in 0..3 {
        g_se3[i * 4..i * 4 + 3].copy_from_slice(&r0[i * 3..i * 3 + 3]);
        g_se3[i * 4 + 3] = [0.4, -1.2, 0.9][i];
    }
    g_se3[15] = 1.0;
    for (algebra, inertia, g0) in [
        (
            Algebra::So(4),
            diag(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
            rotation4(0.4, -0.9),
        ),
        (Algebra::Se3, kirchhoff, g_se3),
    ] {
        let name = format!("{algebra:?}");
        let ep = EulerPoincare::new(algebra, Lagrangian::Quadratic(inertia), Side::Left, None)
            .unwrap()
            .with_attitude()
            .unwrap();
        let z0 = [vec![0.3, -0.2, 0.5, 0.1, 0.4, -0.6], g0].concat();
        let inv0 = ep.invariants(&z0).unwrap();
        let run = integrate(&ep, "variational", &z0, 0.01, 10_000, 1000).unwrap();
        for k in 0..run.len() {
            // Relative to the state's size: on se(3) the spatial momentum R M + t × RΓ adds terms
            // of size |t| (the body drifts away, |t| ≈ 30 here) that cancel to a constant.
            let z = run.state(k);
            let inv = ep.invariants(z).unwrap();
            let scale = z.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let drift = dist(&inv, &inv0) / scale;
            assert!(drift < 2e-14, "{name} sample {k}: {drift:e}");
        }
        // The same motion as the Lie–Poisson methods (variational6 against rkmk4, t = 1).
        let a = integrate(&ep, "variational6", &z0, 0.05, 20, 20).unwrap();
        let b = integrate(&ep, "rkmk4", &z0, 0.005, 200, 200).unwrap();
        assert!(dist(a.state(1), b.state(1)) < 1e-8, "{name}");
    }
}

/// The heavy top's state at t by a fine run of its order-8 splitting.
fn reference_at(top: &HeavyTop, z0: &[f64], t: f64) -> Vec<f64> {
    let steps = (t / 1e-3).round() as usize;
    integrate(top, "splitting8", z0, t / steps as f64, steps, steps)
        .unwrap()
        .state(1)
        .to_vec()
}

#[test]
fn the_variational_method_for_a_quartic_and_a_right_invariant_lagrangian() {
    // ℓ = ½⟨Ω, 𝕀Ω⟩ + (c/4)|Ω|⁴: variational6 against rkmk4 at a tenth of the step (the rkmk4
    // run is itself checked against the independent solution above), and the right system as the
    // mirror of the left one.
    let ep = EulerPoincare::new(Algebra::So3, quartic(0.4, 0.0), Side::Left, None).unwrap();
    let mut mu0 = [0.0; 3];
    ep.legendre()
        .momentum(&[0.8, -0.4, 0.3], &[], &mut mu0)
        .unwrap();
    let a = integrate(&ep, "variational6", &mu0, 1e-2, 1000, 1000).unwrap();
    let b = integrate(&ep, "rkmk4", &mu0, 1e-3, 10_000, 10_000).unwrap();
    assert!(
        dist(a.state(1), b.state(1)) < 1e-9,
        "{:?} {:?}",
        a.state(1),
        b.state(1)
    );
    let right = EulerPoincare::new(Algebra::So3, quartic(0.4, 0.5), Side::Right, None).unwrap();
    let mirror = EulerPoincare::new(Algebra::So3, quartic(0.4, -0.5), Side::Left, None).unwrap();
    let minus: Vec<f64> = M0.iter().map(|x| -x).collect();
    let r = integrate(&right, "variational", &M0, 0.01, 300, 30).unwrap();
    let m = integrate(&mirror, "variational", &minus, 0.01, 300, 30).unwrap();
    for k in 0..r.len() {
        let negated: Vec<f64> = m.state(k).iter().map(|x| -x).collect();
        assert!(dist(r.state(k), &negated) < 1e-14, "sample {k}");
    }
}

#[test]
fn kirchhoffs_body_comes_out_of_its_lagrangian_on_se3() {
    // ℓ(Ω, V) = ½⟨(Ω, V), 𝕀(Ω, V)⟩ on se(3) (a body in an ideal fluid, added masses coupling
    // rotation and translation) is the Lie–Poisson system of H = ½⟨μ, 𝕀⁻¹μ⟩ (Kirchhoff's
    // equations; examples/kirchhoff.py): the same trajectory with the same method over t = 10,
    // and the Clebsch–Kirchhoff Casimirs |Γ|², M·Γ kept by the variational method.
    let mut inertia = diag(&[2.0, 3.0, 4.0, 1.0, 1.5, 2.5]);
    for (i, j, v) in [(0, 4, 0.2), (1, 3, -0.1), (2, 5, 0.15)] {
        inertia[i * 6 + j] = v;
        inertia[j * 6 + i] = v;
    }
    let ep = EulerPoincare::new(
        Algebra::Se3,
        Lagrangian::Quadratic(inertia.clone()),
        Side::Left,
        None,
    )
    .unwrap();
    let h = nalgebra::DMatrix::from_row_slice(6, 6, &inertia)
        .try_inverse()
        .unwrap();
    let h: Vec<f64> = (0..36).map(|k| h[(k / 6, k % 6)]).collect();
    let lp = LiePoisson::new(Algebra::Se3, LieHamiltonian::Quadratic(h), None).unwrap();
    let z0 = [1.0, 0.5, -0.3, 0.2, -0.1, 0.4];
    let a = integrate(&ep, "rkmk4", &z0, 0.01, 1000, 100).unwrap();
    let b = integrate(&lp, "rkmk4", &z0, 0.01, 1000, 100).unwrap();
    for k in 0..a.len() {
        assert!(dist(a.state(k), b.state(k)) < 1e-13, "sample {k}");
    }
    let v = integrate(&ep, "variational", &z0, 0.01, 1000, 100).unwrap();
    let c0 = ep.invariants(&z0).unwrap();
    for k in 0..v.len() {
        let c = ep.invariants(v.state(k)).unwrap();
        assert!(dist(&c, &c0) < 1e-14, "sample {k}: {c:?}");
        assert!(dist(v.state(k), a.state(k)) < 1e-3, "sample {k}");
    }
}

#[test]
fn a_vehicle_on_se3_with_gravity_at_rest_in_translation_is_the_heavy_top() {
    // ℓ(Ω, V, Γ) = ½⟨(Ω, V), 𝕀(Ω, V)⟩ − mgl⟨Γ, χ⟩ on se(3) with the vector action of its
    // rotations on Γ (a body in a fluid under gravity): Ṁ = M × Ω + P × V + mgl Γ × χ,
    // Ṗ = P × Ω, Γ̇ = Γ × Ω. With 𝕀 block-diagonal and P₀ = 0, P stays 0 and (M, Γ) is the heavy
    // top's motion (an independent route: the built-in HeavyTop).
    let (mgl, chi) = (0.7, [0.0, 0.6, 0.8]);
    let masses = [1.0, 1.5, 2.5];
    let value: LagrangianFn = Arc::new(move |x: &[f64], g: &[f64]| {
        let t: f64 = (0..3)
            .map(|i| 0.5 * (I[i] * x[i] * x[i] + masses[i] * x[3 + i] * x[3 + i]))
            .sum();
        Ok(t - mgl * (0..3).map(|i| g[i] * chi[i]).sum::<f64>())
    });
    let gradient: LagrangianGradientFn = Arc::new(
        move |x: &[f64], _g: &[f64], dx: &mut [f64], dg: &mut [f64]| {
            for i in 0..3 {
                dx[i] = I[i] * x[i];
                dx[3 + i] = masses[i] * x[3 + i];
                dg[i] = -mgl * chi[i];
            }
            Ok(())
        },
    );
    let vehicle = EulerPoincare::new(
        Algebra::Se3,
        Lagrangian::Function {
            value,
            gradient: Some(gradient),
            hessian: None,
        },
        Side::Left,
        Some((Action::Vector, 3)),
    )
    .unwrap();
    assert_eq!(vehicle.dims(), (6, 3));
    let top = HeavyTop::new(I, mgl, chi).unwrap();
    let gamma = [0.3, -0.2, 0.87f64.sqrt()];
    let z_top = top.state(M0, gamma);
    let z_vehicle = [M0.to_vec(), vec![0.0; 3], gamma.to_vec()].concat();
    let a = integrate(&vehicle, "variational6", &z_vehicle, 0.02, 500, 50).unwrap();
    let b = integrate(&top, "splitting8", &z_top, 0.002, 5000, 500).unwrap();
    for k in 0..a.len() {
        let (za, zb) = (a.state(k), b.state(k));
        assert!(
            za[3..6].iter().all(|p| p.abs() < 1e-15),
            "sample {k}: P = {:?}",
            &za[3..6]
        );
        let mg = [&za[..3], &za[6..]].concat();
        assert!(dist(&mg, zb) < 1e-8, "sample {k}");
    }
    // A vector action on structure constants is refused.
    let so3: Vec<f64> = (0..27)
        .map(|c| match (c / 9, (c / 3) % 3, c % 3) {
            (0, 1, 2) | (1, 2, 0) | (2, 0, 1) => 1.0,
            (1, 0, 2) | (2, 1, 0) | (0, 2, 1) => -1.0,
            _ => 0.0,
        })
        .collect();
    assert!(EulerPoincare::new(
        Algebra::Constants(so3),
        heavy_top_lagrangian(mgl, chi),
        Side::Left,
        Some((Action::Vector, 3))
    )
    .is_err());
}

#[test]
fn the_attitude_field_is_the_one_the_group_methods_integrate() {
    // ġ = gξ̂ (left) / ξ̂g (right) in the vector field (rk4) against rkmk4's g ← g exp(−θ) /
    // exp(θ) g: two routes to g(t = 1) that agree to their O(h⁴) error only if the hat of every
    // group (so(3), so(4) e_ij, se(3)) and the side are right.
    let mut se3_g0 = vec![0.0; 16];
    let r = rotation([0.3, -0.5, 0.8], 0.7);
    for i in 0..3 {
        se3_g0[i * 4..i * 4 + 3].copy_from_slice(&r[i * 3..i * 3 + 3]);
        se3_g0[i * 4 + 3] = [0.4, -1.2, 0.9][i];
    }
    se3_g0[15] = 1.0;
    let cases = [
        (Algebra::So3, diag(&I), vec![1.0, 0.5, -0.3], r.to_vec()),
        (
            Algebra::So(4),
            diag(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
            vec![0.3, -0.2, 0.5, 0.1, 0.4, -0.6],
            rotation4(0.4, -0.9),
        ),
        (
            Algebra::Se3,
            diag(&[2.0, 3.0, 4.0, 1.0, 1.5, 2.5]),
            vec![1.0, 0.5, -0.3, 0.2, -0.1, 0.4],
            se3_g0,
        ),
    ];
    for (algebra, inertia, mu0, g0) in cases {
        for side in [Side::Left, Side::Right] {
            let name = format!("{algebra:?} {side:?}");
            let ep = EulerPoincare::new(
                algebra.clone(),
                Lagrangian::Quadratic(inertia.clone()),
                side,
                None,
            )
            .unwrap()
            .with_attitude()
            .unwrap();
            let z0 = [mu0.clone(), g0.clone()].concat();
            let a = integrate(&ep, "rk4", &z0, 0.01, 100, 100).unwrap();
            let b = integrate(&ep, "rkmk4", &z0, 0.01, 100, 100).unwrap();
            let n = mu0.len();
            let err = dist(&a.state(1)[n..], &b.state(1)[n..]);
            assert!(err < 1e-9, "{name}: {err:e}");
            assert!(dist(&a.state(1)[n..], &g0) > 0.1, "{name}: g moved");
        }
    }
}
