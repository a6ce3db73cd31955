//! The discrete Moser–Veselov algorithm and its preprocessed versions (`dmv`, `dmv4` … `dmv10`,
//! `lieflow::systems::tops::methods::dmv`) on the free rigid body with its attitude: the step against the
//! discrete Euler–Lagrange equations it solves, the modified moments against Hairer & Vilmart
//! (2006) Table 1 and an independent derivation, observed orders for M and R against the exact
//! momentum and an attitude reference by quadrature, the kept quantities over long runs, the
//! Poisson property, chunking, a matrix inertia and the error paths. Measured values are printed
//! (run with `--nocapture`).

use lieflow::integrate::{integrate, integrate_with, Integrator, Problem, Run, System};
use lieflow::lie::so3;
use lieflow::systems::tops::methods::dmv::{self, Dmv};
use lieflow::systems::{Lgvi, RigidBody};
use lieflow::Error;
use nalgebra::{Matrix3, Vector3};

mod common;
use common::distance as dist;

const MOMENTS: [f64; 3] = [1.0, 2.0, 3.0];
const M0: [f64; 3] = [1.0, 0.5, -0.3];
const METHODS: [(&str, u32); 5] = [
    ("dmv", 2),
    ("dmv4", 4),
    ("dmv6", 6),
    ("dmv8", 8),
    ("dmv10", 10),
];

fn body() -> RigidBody {
    RigidBody::new(MOMENTS).unwrap()
}

fn rows(r: &Matrix3<f64>) -> Vec<f64> {
    (0..9).map(|k| r[(k / 3, k % 3)]).collect()
}

fn r0() -> Matrix3<f64> {
    so3::exp_unchecked(&Vector3::new(0.4, -0.2, 0.1))
}

fn z0() -> Vec<f64> {
    [M0.to_vec(), rows(&r0())].concat()
}

fn run(b: &RigidBody, method: &str, z0: &[f64], dt: f64, steps: usize) -> Vec<f64> {
    integrate(b, method, z0, dt, steps, steps)
        .unwrap_or_else(|e| panic!("{method} dt = {dt}: {e}"))
        .final_state
}

// ---------------------------------------------------------------------------------------------
// An independent attitude reference

/// The attitude at time t of the exact motion of `body` (principal moments, no frame) from
/// (m0, r0). With a fixed rotation G turning the spatial momentum π = R₀M₀ into μe₃ (μ = |M|),
/// the rows of G·R(t) are r₁ = c a + s b, r₂ = −s a + c b, r₃ = n, where n = M/μ (R M = π),
/// a = (e₁ × n)/|e₁ × n|, b = n × a and (c, s) = (cos ψ, sin ψ). From ṙ_i = r_i × Ω (the rows of
/// Ṙ = RΩ̂): ψ̇ = ṙ₁·r₂ − ȧ·b = −Ω·n − (e₁·n)(ṅ·(e₁ × n))/|e₁ × n|², ṅ = n × Ω, a quadrature
/// along M(t) = `exact_momentum` (composite 5-point Gauss–Legendre on `pieces` intervals). Valid
/// while M stays away from ±e₁ (asserted).
fn attitude_reference(
    body: &RigidBody,
    m0: &[f64; 3],
    r0: &Matrix3<f64>,
    t: f64,
    pieces: usize,
) -> Matrix3<f64> {
    let mu = Vector3::from(*m0).norm();
    let pi = r0 * Vector3::from(*m0) / mu;
    // G: rows g₁ ⟂ π, g₂ = π × g₁, g₃ = π (right-handed, G π = e₃).
    let g1 = if pi.cross(&Vector3::z()).norm() > 0.1 {
        pi.cross(&Vector3::z()).normalize()
    } else {
        pi.cross(&Vector3::x()).normalize()
    };
    let g = Matrix3::from_rows(&[g1.transpose(), pi.cross(&g1).transpose(), pi.transpose()]);
    let frame = |m: &Vector3<f64>| {
        let n = m / mu;
        let kn = Vector3::x().cross(&n);
        let rho = kn.norm();
        assert!(rho > 0.2, "M too close to e1: {rho}");
        let a = kn / rho;
        (n, a, n.cross(&a), kn, rho)
    };
    let rate = |time: f64| {
        let m = Vector3::from(body.exact_momentum(m0, time).unwrap());
        let omega = Vector3::from_fn(|i, _| m[i] / MOMENTS[i]);
        let (n, _, _, kn, rho) = frame(&m);
        let ndot = n.cross(&omega);
        -omega.dot(&n) - n[0] * ndot.dot(&kn) / (rho * rho)
    };
    let r0p = g * r0;
    let (_, a0, b0, _, _) = frame(&Vector3::from(*m0));
    let row1 = r0p.row(0).transpose();
    let mut psi = row1.dot(&b0).atan2(row1.dot(&a0));
    let x1 = (5.0f64 - 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0;
    let x2 = (5.0f64 + 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0;
    let w1 = (322.0 + 13.0 * 70.0f64.sqrt()) / 900.0;
    let w2 = (322.0 - 13.0 * 70.0f64.sqrt()) / 900.0;
    let nodes = [
        (0.0, 128.0 / 225.0),
        (-x1, w1),
        (x1, w1),
        (-x2, w2),
        (x2, w2),
    ];
    let piece = t / pieces as f64;
    for k in 0..pieces {
        let mid = (k as f64 + 0.5) * piece;
        psi += 0.5
            * piece
            * nodes
                .iter()
                .map(|&(x, w)| w * rate(mid + 0.5 * piece * x))
                .sum::<f64>();
    }
    let m = Vector3::from(body.exact_momentum(m0, t).unwrap());
    let (n, a, b, _, _) = frame(&m);
    let (s, c) = psi.sin_cos();
    let rp = Matrix3::from_rows(&[
        (a * c + b * s).transpose(),
        (b * c - a * s).transpose(),
        n.transpose(),
    ]);
    g.transpose() * rp
}

/// The exact state (M, R) at t from z0().
fn exact_state(t: f64) -> Vec<f64> {
    let b = body();
    let m = b.exact_momentum(&M0, t).unwrap();
    let r = attitude_reference(&b, &M0, &r0(), t, (t / 0.02).ceil() as usize);
    [m.to_vec(), rows(&r)].concat()
}

#[test]
fn attitude_reference_solves_the_attitude_equation() {
    // At t = 0 it is R₀; its derivative is R Ω̂ (central differences); R M is conserved.
    let b = body();
    let r = attitude_reference(&b, &M0, &r0(), 0.0, 1);
    assert!((r - r0()).norm() < 1e-14, "{}", (r - r0()).norm());
    let (t, eps) = (3.7, 1e-4);
    let rt = |t: f64| attitude_reference(&b, &M0, &r0(), t, 200);
    let deriv = (rt(t + eps) - rt(t - eps)) / (2.0 * eps);
    let m = Vector3::from(b.exact_momentum(&M0, t).unwrap());
    let omega = Vector3::from_fn(|i, _| m[i] / MOMENTS[i]);
    let want = rt(t) * so3::hat(&omega);
    eprintln!(
        "attitude reference: |dR/dt − R Ω̂| = {:.2e}",
        (deriv - want).norm()
    );
    assert!((deriv - want).norm() < 1e-7, "{}", (deriv - want).norm());
    let pi0 = r0() * Vector3::from(M0);
    assert!((rt(t) * m - pi0).norm() < 1e-14);
    // Refining the quadrature changes nothing at T = 100.
    let coarse = attitude_reference(&b, &M0, &r0(), 100.0, 5000);
    let fine = attitude_reference(&b, &M0, &r0(), 100.0, 10_000);
    eprintln!(
        "attitude reference at T = 100: quadrature refinement changes it by {:.2e}",
        (coarse - fine).norm()
    );
    assert!((coarse - fine).norm() < 4e-13);
}

// ---------------------------------------------------------------------------------------------
// The step and the modified moments

/// D = ½ tr(I)·1 − I of principal moments.
fn mass_matrix(i: &[f64; 3]) -> Matrix3<f64> {
    let half = 0.5 * (i[0] + i[1] + i[2]);
    Matrix3::from_diagonal(&Vector3::new(half - i[0], half - i[1], half - i[2]))
}

#[test]
fn one_step_solves_the_discrete_euler_lagrange_equations() {
    // From (M₀, R = 1): F = R₁ must satisfy h M̂₀ = F D̃ − D̃ Fᵀ and M₁ = Fᵀ M₀, with D̃ the mass
    // matrix of the modified moments of the method (the moments themselves for dmv).
    let b = body().with_attitude();
    let z = [M0.to_vec(), rows(&Matrix3::identity())].concat();
    for (name, order) in METHODS {
        for h in [0.05, 0.3, 0.8] {
            let inertia = dmv::modified_moments(&MOMENTS, &M0, h, order).unwrap();
            let d = mass_matrix(&inertia);
            let z1 = run(&b, name, &z, h, 1);
            let f = Matrix3::from_row_slice(&z1[3..]);
            let el = (f * d - d * f.transpose()) - so3::hat(&Vector3::from(M0)) * h;
            let push = Vector3::from_column_slice(&z1[..3]) - f.transpose() * Vector3::from(M0);
            let orth = (f.transpose() * f - Matrix3::identity()).norm();
            eprintln!(
                "{name} h = {h}: |h M̂₀ − (F D̃ − D̃ Fᵀ)| {:.1e}, |M₁ − Fᵀ M₀| {:.1e}, |FᵀF − 1| \
                 {orth:.1e}",
                el.norm(),
                push.norm()
            );
            assert!(
                el.norm() < 1e-15 && push.norm() < 2e-15 && orth < 4e-15,
                "{name} h = {h}"
            );
        }
    }
}

#[test]
fn dmv_is_the_free_body_lgvi() {
    // The same discrete Lagrangian: the two solvers give the same map (to round-off).
    let b = body().with_attitude();
    let a = run(&b, "dmv", &z0(), 0.05, 2000);
    let l = integrate_with(&b, &Lgvi, &z0(), 0.05, 2000, 2000)
        .unwrap()
        .final_state;
    eprintln!("dmv vs lgvi after 2000 steps of 0.05: {:.2e}", dist(&a, &l));
    assert!(dist(&a, &l) < 1e-12, "{}", dist(&a, &l));
}

/// HV06 Table 1 (s₃ … d₇) in δ = I₁I₂I₃, σ_a = Σ I_j^a, τ_{b,c} = Σ (I_j^b + I_k^b)/I_i^c, as
/// coefficients of H^{k−i} C^i.
fn table1(i: &[f64; 3]) -> Vec<([f64; 5], [f64; 5])> {
    let delta = i[0] * i[1] * i[2];
    let sigma = |a: i32| i.iter().map(|x| x.powi(a)).sum::<f64>();
    let tau = |b: i32, c: i32| {
        (0..3)
            .map(|k| (i[(k + 1) % 3].powi(b) + i[(k + 2) % 3].powi(b)) / i[k].powi(c))
            .sum::<f64>()
    };
    let (d, d2, d3) = (delta, delta * delta, delta * delta * delta);
    vec![
        (
            [-sigma(-1) / 3.0, sigma(1) / (6.0 * d), 0.0, 0.0, 0.0],
            [sigma(1) / (6.0 * d), -1.0 / (3.0 * d), 0.0, 0.0, 0.0],
        ),
        (
            [
                (3.0 * sigma(1) + 2.0 * d * sigma(-2)) / (60.0 * d),
                (1.0 - tau(1, 1)) / (30.0 * d),
                (sigma(2) - d * sigma(-1)) / (30.0 * d2),
                0.0,
                0.0,
            ],
            [
                -(9.0 + tau(1, 1)) / (60.0 * d),
                (6.0 * d * sigma(-1) - sigma(2)) / (60.0 * d2),
                -sigma(1) / (60.0 * d2),
                0.0,
                0.0,
            ],
        ),
        (
            [
                (15.0 - d * sigma(-3) - 2.0 * tau(1, 1)) / (630.0 * d),
                (6.0 * d * tau(1, 2) - 100.0 * d * sigma(-1) + 53.0 * sigma(2)) / (2520.0 * d2),
                (9.0 * sigma(1) + 10.0 * d * sigma(-2) - 6.0 * tau(2, 1)) / (420.0 * d2),
                (4.0 * d + 17.0 * sigma(3) - 15.0 * d * tau(1, 1)) / (2520.0 * d3),
                0.0,
            ],
            [
                (9.0 * d * sigma(-1) + d * tau(1, 2) - 11.0 * sigma(2)) / (1260.0 * d2),
                (47.0 * sigma(1) + 13.0 * tau(2, 1) - 38.0 * d * sigma(-2)) / (2520.0 * d2),
                (sigma(3) + 2.0 * d * tau(1, 1) - 85.0 * d) / (1260.0 * d3),
                (34.0 * d * sigma(-1) - 19.0 * sigma(2)) / (2520.0 * d3),
                0.0,
            ],
        ),
    ]
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - y).abs() <= tol * y.abs().max(1e-3))
}

#[test]
fn modified_moments_agree_with_hairer_vilmart_table_1() {
    for i in [
        [1.0, 2.0, 3.0],
        [0.6, 0.8, 1.0],
        [0.345, 0.653, 1.0],
        [2.5, 0.7, 1.3],
    ] {
        for (k, (s, d)) in table1(&i).into_iter().enumerate() {
            let (ms, md) = dmv::series_coefficients(&i, k + 1);
            eprintln!("I = {i:?}: s{} {ms:?} vs {s:?}", 2 * k + 3);
            assert!(
                close(&ms, &s, 1e-13),
                "s{} at {i:?}: {ms:?} vs {s:?}",
                2 * k + 3
            );
            assert!(
                close(&md, &d, 1e-13),
                "d{} at {i:?}: {md:?} vs {d:?}",
                2 * k + 3
            );
        }
    }
}

#[test]
fn modified_moments_agree_with_the_series_derivation() {
    // The coefficients of H^{k−i} C^i at I = (1, 2, 3) as exact rationals, from matching the
    // Taylor series of one DMV step with modified moments against the exact flow of (M, R) at
    // this inertia (before the fit in the inverse moments that the library's table comes from).
    let q = |n: f64, d: f64| n / d;
    let want: [([f64; 5], [f64; 5]); 4] = [
        (
            [q(-11.0, 18.0), q(1.0, 6.0), 0.0, 0.0, 0.0],
            [q(1.0, 6.0), q(-1.0, 18.0), 0.0, 0.0, 0.0],
        ),
        (
            [q(103.0, 1080.0), q(-7.0, 180.0), q(1.0, 360.0), 0.0, 0.0],
            [q(-17.0, 360.0), q(13.0, 540.0), q(-1.0, 360.0), 0.0, 0.0],
        ),
        (
            [
                q(-41.0, 19440.0),
                q(-13.0, 9072.0),
                q(53.0, 45360.0),
                q(-1.0, 6480.0),
                0.0,
            ],
            [
                q(-17.0, 45360.0),
                q(341.0, 136080.0),
                q(-1.0, 720.0),
                q(1.0, 5040.0),
                0.0,
            ],
        ),
        (
            [
                q(11023.0, 29393280.0),
                q(-1523.0, 2449440.0),
                q(157.0, 326592.0),
                q(-19.0, 116640.0),
                q(1.0, 51840.0),
            ],
            [
                q(-347.0, 1399680.0),
                q(3233.0, 7348320.0),
                q(-79.0, 233280.0),
                q(31.0, 272160.0),
                q(-19.0, 1399680.0),
            ],
        ),
    ];
    for (k, (s, d)) in want.iter().enumerate() {
        let (ms, md) = dmv::series_coefficients(&MOMENTS, k + 1);
        assert!(close(&ms, s, 1e-13), "s{}: {ms:?} vs {s:?}", 2 * k + 3);
        assert!(close(&md, d, 1e-13), "d{}: {md:?} vs {d:?}", 2 * k + 3);
    }
    // The modified moments are 1/(s/I_j + d) with the truncated series.
    let h: f64 = 0.3;
    let (hh, cc) = (
        0.5 * (0..3).map(|j| M0[j] * M0[j] / MOMENTS[j]).sum::<f64>(),
        0.5 * M0.iter().map(|x| x * x).sum::<f64>(),
    );
    for (_, order) in METHODS {
        let (mut s, mut d) = (1.0, 0.0);
        for (k, (sk, dk)) in want.iter().enumerate().take(order as usize / 2 - 1) {
            let k1 = k + 1;
            for i in 0..=k1 {
                let mono = h.powi(2 * k1 as i32) * hh.powi((k1 - i) as i32) * cc.powi(i as i32);
                s += sk[i] * mono;
                d += dk[i] * mono;
            }
        }
        let got = dmv::modified_moments(&MOMENTS, &M0, h, order).unwrap();
        for j in 0..3 {
            let want = 1.0 / (s / MOMENTS[j] + d);
            assert!(
                (got[j] - want).abs() < 1e-14 * want,
                "order {order}: {got:?} vs {want}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Orders and accuracy

#[test]
fn observed_orders_for_m_and_r() {
    // T = 100 (about 23 turns of M); the steps put the errors well above round-off (the reference
    // is accurate to ~1e-14), and at order 10 the smallest error is ~1e-12.
    let t_end = 100.0;
    let exact = exact_state(t_end);
    let b = body().with_attitude();
    for (name, order, dts) in [
        ("dmv", 2, [0.05, 0.025, 0.0125]),
        ("dmv4", 4, [0.2, 0.1, 0.05]),
        ("dmv6", 6, [0.2, 0.1, 0.05]),
        ("dmv8", 8, [0.4, 0.2, 0.1]),
        ("dmv10", 10, [0.8, 0.4, 0.2]),
    ] {
        let errors: Vec<(f64, f64)> = dts
            .iter()
            .map(|&dt| {
                let n = (t_end / dt).round() as usize;
                let z = run(&b, name, &z0(), dt, n);
                (dist(&z[..3], &exact[..3]), dist(&z[3..], &exact[3..]))
            })
            .collect();
        let om = [0, 1].map(|k| (errors[k].0 / errors[k + 1].0).log2());
        let or = [0, 1].map(|k| (errors[k].1 / errors[k + 1].1).log2());
        eprintln!(
            "{name}: dt {dts:?}: errors M {:.2e} {:.2e} {:.2e} (orders {:.2} {:.2}), R {:.2e} \
             {:.2e} {:.2e} (orders {:.2} {:.2})",
            errors[0].0,
            errors[1].0,
            errors[2].0,
            om[0],
            om[1],
            errors[0].1,
            errors[1].1,
            errors[2].1,
            or[0],
            or[1]
        );
        for o in [om[1], or[1]] {
            assert!(
                (o - order as f64).abs() < 0.25,
                "{name}: observed order {o}, nominal {order}"
            );
        }
    }
}

#[test]
fn accuracy_at_t_100_against_the_exact_motion() {
    // The test: I = (1, 2, 3), M₀ = (1, 0.5, −0.3), R₀ = 1, T = 100.
    let b = body().with_attitude();
    let z = [M0.to_vec(), rows(&Matrix3::identity())].concat();
    let m = b.exact_momentum(&M0, 100.0).unwrap();
    let r = attitude_reference(&body(), &M0, &Matrix3::identity(), 100.0, 5000);
    let exact = [m.to_vec(), rows(&r)].concat();
    for (name, dt, tol) in [
        ("dmv", 0.01f64, 6e-3),
        ("dmv4", 0.05, 2e-5),
        ("dmv6", 0.1, 1e-7),
        ("dmv8", 0.2, 4e-9),
        ("dmv10", 0.25, 2e-11),
        ("dmv10", 0.1, 5e-13),
    ] {
        let n = (100.0 / dt).round() as usize;
        let zn = run(&b, name, &z, dt, n);
        let e = dist(&zn, &exact);
        eprintln!("{name} dt = {dt}: error at T = 100 (M and R) {e:.2e}");
        assert!(e < tol, "{name} dt = {dt}: {e:e}");
    }
}

// ---------------------------------------------------------------------------------------------
// What the methods keep

#[test]
fn casimir_spatial_momentum_energy_and_group_over_1e6_steps() {
    let b = body().with_attitude();
    let z0 = z0();
    let (c0, h0) = (
        M0.iter().map(|x| x * x).sum::<f64>(),
        b.energy(&z0).unwrap(),
    );
    let s0 = Vector3::from(RigidBody::spatial_momentum(&z0).unwrap());
    for (name, _) in METHODS {
        let dt = 0.05;
        let traj = integrate(&b, name, &z0, dt, 1_000_000, 1000).unwrap();
        let (mut dc, mut ds, mut dr) = (0.0f64, 0.0f64, 0.0f64);
        let mut de = Vec::new();
        for k in 0..traj.len() {
            let z = traj.state(k);
            dc = dc.max((z[..3].iter().map(|x| x * x).sum::<f64>() - c0).abs() / c0);
            let s = Vector3::from(RigidBody::spatial_momentum(z).unwrap());
            ds = ds.max((s - s0).norm() / s0.norm());
            let r = Matrix3::from_row_slice(&z[3..]);
            dr = dr.max((r.transpose() * r - Matrix3::identity()).norm());
            de.push((b.energy(z).unwrap() - h0).abs() / h0);
        }
        let tenth = de.len() / 10;
        let max = |v: &[f64]| v.iter().fold(0.0f64, |a, &x| a.max(x));
        let (first, last) = (max(&de[1..tenth]), max(&de[de.len() - tenth..]));
        eprintln!(
            "{name}, dt = {dt}, 1e6 steps (T = 5e4): max relative drift of |M|² {dc:.1e}, of R M \
             {ds:.1e}, max |RᵀR − 1| {dr:.1e}, relative energy error {first:.1e} (first tenth) → \
             {last:.1e} (last tenth)"
        );
        assert!(dc < 1e-13 && ds < 1e-12 && dr < 1e-14, "{name}");
        // The energy is kept too (a modified energy sH + dC and C with constant s, d): its error
        // is round-off, growing no faster than a random walk.
        assert!(
            first < 1e-14 && last < 1e-13,
            "{name}: {first:e} → {last:e}"
        );
    }
}

/// The defect of the Lie–Poisson structure B(M) = M̂ under the one-step map φ of M (with the
/// modified moments recomputed from the perturbed M, as a stepper does):
/// max |Dφ B(M) Dφᵀ − B(φ(M))| by fourth-order central differences.
fn poisson_defect(method: &dyn Integrator<RigidBody>, m: &[f64; 3], h: f64) -> f64 {
    let b = body();
    let step = |x: &[f64]| integrate_with(&b, method, x, h, 1, 1).unwrap().final_state;
    let delta = 1e-3;
    let mut jac = Matrix3::zeros();
    for j in 0..3 {
        let at = |eps: f64| {
            let mut x = m.to_vec();
            x[j] += eps;
            Vector3::from_column_slice(&step(&x))
        };
        let col = (8.0 * (at(delta) - at(-delta)) - (at(2.0 * delta) - at(-2.0 * delta)))
            / (12.0 * delta);
        jac.set_column(j, &col);
    }
    let image = Vector3::from_column_slice(&step(m));
    (jac * so3::hat(&Vector3::from(*m)) * jac.transpose() - so3::hat(&image)).amax()
}

#[test]
fn the_momentum_map_is_poisson() {
    for order in [2, 4, 6, 8, 10] {
        let d = poisson_defect(&Dmv(order), &M0, 0.3);
        eprintln!("Poisson defect of dmv{order} (h = 0.3): {d:.1e}");
        assert!(d < 1e-10, "dmv{order}: {d:e}");
    }
    // The test sees a map that is not Poisson.
    let d = poisson_defect(&lieflow::integrate::methods::Rk4, &M0, 0.3);
    eprintln!("Poisson defect of rk4 (h = 0.3, control): {d:.1e}");
    assert!(d > 1e-8, "rk4: {d:e}");
}

// ---------------------------------------------------------------------------------------------
// The driver: chunks, frames, errors

#[test]
fn chunking_does_not_change_the_states() {
    let b = body().with_attitude();
    for (name, _) in METHODS {
        let dt = 0.1;
        let mut one = Run::new(&b, name, &z0(), dt, 1, 0.0).unwrap();
        let mut all = z0();
        one.advance(&b, 1000, &mut all).unwrap();
        // Chunks of 1, 7 and 300 steps (across the retractions every 256 steps).
        let mut chunked = Run::new(&b, name, &z0(), dt, 1, 0.0).unwrap();
        let mut parts = z0();
        for &k in [1u64, 7, 300].iter().cycle() {
            let left = 1000 - chunked.steps_done();
            if left == 0 {
                break;
            }
            chunked.advance(&b, k.min(left), &mut parts).unwrap();
        }
        assert_eq!(all, parts, "{name}");
        // Saving every 100th state only, and through `integrate`: the same states.
        let sparse = integrate(&b, name, &z0(), dt, 1000, 100).unwrap();
        for k in 0..sparse.len() {
            assert_eq!(
                sparse.state(k),
                &all[12 * 100 * k..12 * (100 * k + 1)],
                "{name}"
            );
        }
        assert_eq!(sparse.final_state, one.state(&b), "{name}");
    }
}

#[test]
fn inertia_as_a_matrix() {
    // I = Q diag(1, 2, 3) Qᵀ: the run in the user frame is the principal run seen through the
    // body's frame, and M follows the exact momentum.
    let q = so3::exp_unchecked(&Vector3::new(0.3, -0.5, 0.7));
    let imat = q * Matrix3::from_diagonal(&Vector3::from(MOMENTS)) * q.transpose();
    let user = RigidBody::from_matrix(&rows(&imat).try_into().unwrap())
        .unwrap()
        .with_attitude();
    let frame = user.frame().unwrap();
    let principal = RigidBody::new(user.moments()).unwrap().with_attitude();
    let mu = q * Vector3::from(M0);
    let zu = [mu.as_slice().to_vec(), rows(&r0())].concat();
    let zp = [
        (frame.transpose() * mu).as_slice().to_vec(),
        rows(&(r0() * frame)),
    ]
    .concat();
    for (name, _) in METHODS {
        let (dt, n) = (0.1, 200);
        let a = run(&user, name, &zu, dt, n);
        let p = run(&principal, name, &zp, dt, n);
        let back = [
            (frame * Vector3::from_column_slice(&p[..3]))
                .as_slice()
                .to_vec(),
            rows(&(Matrix3::from_row_slice(&p[3..]) * frame.transpose())),
        ]
        .concat();
        let exact = user.exact_momentum(mu.as_slice(), dt * n as f64).unwrap();
        eprintln!(
            "{name}, matrix inertia: user vs principal run {:.1e}, M vs exact {:.1e}",
            dist(&a, &back),
            dist(&a[..3], &exact)
        );
        assert!(dist(&a, &back) < 1e-13, "{name}");
    }
    let m = run(&user, "dmv10", &zu, 0.1, 200);
    let exact = user.exact_momentum(mu.as_slice(), 20.0).unwrap();
    assert!(dist(&m[..3], &exact) < 1e-12, "{}", dist(&m[..3], &exact));
}

#[test]
fn errors_are_typed() {
    let b = body().with_attitude();
    // An order that does not exist.
    let e = integrate_with(&b, &Dmv(3), &z0(), 0.1, 1, 1).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { .. }), "{e}");
    assert!(dmv::modified_moments(&MOMENTS, &M0, 0.1, 12).is_err());
    // A step so large that the modified moments are not positive: refused at the start.
    let e = integrate(&b, "dmv10", &z0(), 50.0, 1, 1).unwrap_err();
    eprintln!("dmv10, dt = 50: {e}");
    assert!(
        matches!(e, Error::InvalidArgument { .. }) && e.to_string().contains("dt"),
        "{e}"
    );
    // Huge steps of the plain DMV: a rotation or a typed error, never a NaN or a panic.
    for dt in [1.0f64, 10.0, 1e3, 1e8, 1e300] {
        match integrate(&b, "dmv", &z0(), dt, 3, 1) {
            Ok(t) => {
                assert!(t.final_state.iter().all(|x| x.is_finite()), "dt = {dt}");
                let r = Matrix3::from_row_slice(&t.final_state[3..]);
                assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-12);
            }
            Err(e) => {
                eprintln!("dmv, dt = {dt:e}: {e}");
                assert!(
                    matches!(
                        e,
                        Error::NotConverged { .. } | Error::InvalidArgument { .. }
                    ),
                    "dt = {dt}: {e}"
                );
            }
        }
    }
    // The catalog knows them, with their orders, after lgvi.
    let names: Vec<(&str, u32)> = b.methods().iter().map(|(n, p)| (*n, p.order)).collect();
    let at = names.iter().position(|(n, _)| *n == "dmv").unwrap();
    assert_eq!(&names[at..at + 5], &METHODS);
    // A stepper reports the state it was set to (nothing is processed on the way in or out).
    let mut s = Dmv(10).stepper(&b, 0.1).unwrap();
    s.set(&z0()).unwrap();
    let mut z = vec![0.0; 12];
    s.get(&mut z);
    assert!(dist(&z, &z0()) < 1e-15);
}
