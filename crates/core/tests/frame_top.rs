//! The tangent Euler top on the three-dimensional space forms (002 §V): each claim by a second
//! route — geodesics and parallel transport in closed form, the Lie–Poisson field by RK4 at small
//! steps, the Killing momenta from positions and velocities, Ṁ = [M, ξ] on SO(4) by differences.
//! The top on a Riemannian chart ([`RiemannianFrameTop`]): its connection against a rotating
//! frame of flat space, its field against Hamilton's equations of H by differences, its motion
//! against the space-form top on ℝ³ (a rotating frame field) and on S³ (stereographic chart).

use lieflow::integrate::problem::VectorField;
use lieflow::integrate::{integrate, Problem};
use lieflow::lie::so3;
use lieflow::systems::{FrameTop, Riemannian, RiemannianFrameTop, SpaceForm, SpaceTop};
use nalgebra::{Matrix3, Matrix4, Vector3};

const INERTIA: [f64; 9] = [2.0, 0.3, -0.1, 0.3, 3.1, 0.2, -0.1, 0.2, 4.2];

fn spaces() -> [SpaceForm; 3] {
    [
        SpaceForm::Euclidean,
        SpaceForm::sphere(1.7).unwrap(),
        SpaceForm::hyperbolic(1.4).unwrap(),
    ]
}

/// A point, a tangent velocity and a frame on each space (the hyperbolic point off the base).
fn start(space: SpaceForm) -> (Vec<f64>, Vec<f64>) {
    match space {
        SpaceForm::Euclidean => (vec![0.3, -0.2, 1.0], vec![0.4, 0.1, -0.3]),
        SpaceForm::Sphere { radius } => {
            let x = [0.5, -0.3, 0.6, 0.2];
            let n = x.iter().map(|v| v * v).sum::<f64>().sqrt();
            let x: Vec<f64> = x.iter().map(|v| v * radius / n).collect();
            let a = [0.2, 0.5, -0.1, 0.4];
            let d: f64 = a.iter().zip(&x).map(|(p, q)| p * q).sum::<f64>() / (radius * radius);
            (
                x.clone(),
                a.iter().zip(&x).map(|(p, q)| p - d * q).collect(),
            )
        }
        SpaceForm::Hyperbolic { radius } => {
            let xs = [0.6, -0.4, 0.9];
            let x0 = (radius * radius + xs.iter().map(|v| v * v).sum::<f64>()).sqrt();
            let x = vec![x0, xs[0], xs[1], xs[2]];
            // Tangent: x₀ẋ₀ = x⃗·ẋ⃗.
            let vs = [0.3, 0.2, -0.5];
            let v0 = xs.iter().zip(&vs).map(|(p, q)| p * q).sum::<f64>() / x0;
            (x, vec![v0, vs[0], vs[1], vs[2]])
        }
    }
}

fn frame() -> Matrix3<f64> {
    so3::exp_unchecked(&Vector3::new(0.4, -0.7, 0.3))
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().map(|v| v.abs()).fold(1.0, f64::max);
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
        / scale
}

#[test]
fn the_state_reads_back_what_it_was_made_of() {
    for space in spaces() {
        let top = FrameTop::new(space, 1.3, &INERTIA).unwrap();
        let (x, xd) = start(space);
        let omega = Vector3::new(0.7, -0.4, 1.1);
        let z = top.state(&x, &frame(), &xd, &omega).unwrap();
        top.check_state(&z).unwrap();
        assert!(dist(&top.position(&z).unwrap(), &x) < 1e-14, "{space:?}");
        assert!(dist(&top.velocity(&z).unwrap(), &xd) < 1e-14, "{space:?}");
        assert!(
            (top.frame(&z).unwrap() - frame()).amax() < 1e-14,
            "{space:?}"
        );
        assert!((top.angular_velocity(&z).unwrap() - omega).amax() < 1e-14);
        // Off the space, not tangent: refused.
        if space != SpaceForm::Euclidean {
            let mut bad = x.clone();
            bad[1] += 1e-3;
            assert!(top.state(&bad, &frame(), &xd, &omega).is_err());
            let bad_v: Vec<f64> = xd.iter().zip(&x).map(|(v, p)| v + 0.1 * p).collect();
            assert!(top.state(&x, &frame(), &bad_v, &omega).is_err());
        }
    }
}

/// Without spin the centre moves on a geodesic and the frame is parallel transported: on S³
/// x(t) = x₀ cos θ + (r/|v|)ẋ₀ sin θ, θ = |v|t/r (cosh, sinh on H³, a line on ℝ³), and a frame
/// vector keeps its component along ẋ(t)/|v| and its part orthogonal to the plane (x, ẋ).
#[test]
fn without_spin_geodesics_and_parallel_transport_in_closed_form() {
    for space in spaces() {
        let top = FrameTop::new(space, 1.3, &INERTIA).unwrap();
        let (x0, v0) = start(space);
        let z0 = top.state(&x0, &frame(), &v0, &Vector3::zeros()).unwrap();
        let e0: Vec<Vec<f64>> = (0..3)
            .map(|k| {
                let mut c = Vector3::zeros();
                c[k] = 1.0;
                ambient(&top, &z0, &c)
            })
            .collect();
        let speed = space.metric(&v0, &v0).sqrt();
        let t = 1.3;
        let traj = integrate(&top, "exact", &z0, t / 10.0, 10, 10).unwrap();
        let z = traj.state(1);
        let (r, s) = (space.length(), space.sigma());
        let th = speed * t / r;
        let (c, sn, dc, ds) = match s as i32 {
            1 => (th.cos(), th.sin(), -th.sin(), th.cos()),
            -1 => (th.cosh(), th.sinh(), th.sinh(), th.cosh()),
            _ => (1.0, th, 0.0, 1.0),
        };
        // x(t) = c x₀ + sn (r/|v|) ẋ₀ (Euclidean: x₀ + t ẋ₀ with r = 1, th = |v|t).
        let x: Vec<f64> = x0
            .iter()
            .zip(&v0)
            .map(|(p, q)| {
                if s == 0.0 {
                    p + t * q
                } else {
                    c * p + sn * r / speed * q
                }
            })
            .collect();
        assert!(dist(&top.position(z).unwrap(), &x) < 1e-12, "{space:?}");
        // ẋ(t)/|v| = (dc/r·|v|... ) the unit tangent: (s·dc x₀/r + ds ẋ₀/|v|).
        let unit: Vec<f64> = x0
            .iter()
            .zip(&v0)
            .map(|(p, q)| {
                if s == 0.0 {
                    q / speed
                } else {
                    dc * p / r + ds * q / speed
                }
            })
            .collect();
        let unit0: Vec<f64> = v0.iter().map(|q| q / speed).collect();
        for (k, e) in e0.iter().enumerate() {
            let along = space.metric(e, &unit0);
            let want: Vec<f64> = e
                .iter()
                .zip(&unit0)
                .zip(&unit)
                .map(|((ei, u0), u)| ei - along * u0 + along * u)
                .collect();
            let mut ck = Vector3::zeros();
            ck[k] = 1.0;
            let got = ambient(&top, z, &ck);
            assert!(
                dist(&got, &want) < 1e-12,
                "{space:?} e{k}: {}",
                dist(&got, &want)
            );
        }
    }
}

fn ambient(top: &FrameTop, z: &[f64], c: &Vector3<f64>) -> Vec<f64> {
    let g = Matrix4::from_row_slice(&z[..16]);
    top.space().ambient(&g, c)
}

/// The exact flow against RK4 of the Lie–Poisson field at small steps; the splittings' orders.
#[test]
fn exact_flow_against_rk4_and_the_orders_of_the_splittings() {
    for space in spaces() {
        let top = FrameTop::new(space, 1.3, &INERTIA).unwrap();
        let (x, xd) = start(space);
        let z0 = top
            .state(&x, &frame(), &xd, &Vector3::new(0.7, -0.4, 1.1))
            .unwrap();
        let t_end = 2.0;
        let exact = integrate(&top, "exact", &z0, t_end / 7.0, 7, 7).unwrap();
        let zr = exact.state(1).to_vec();
        let rk = integrate(&top, "rk4", &z0, t_end / 4000.0, 4000, 4000).unwrap();
        assert!(
            dist(rk.state(1), &zr) < 1e-11,
            "{space:?}: {}",
            dist(rk.state(1), &zr)
        );
        let err = |m: &str, n: usize| {
            dist(
                integrate(&top, m, &z0, t_end / n as f64, n, n)
                    .unwrap()
                    .state(1),
                &zr,
            )
        };
        for (m, order, n) in [
            ("splitting", 2.0, 40),
            ("splitting4", 4.0, 20),
            ("rk4", 4.0, 40),
        ] {
            let observed = (err(m, n) / err(m, 2 * n)).log2();
            assert!((observed - order).abs() < 0.25, "{space:?} {m}: {observed}");
        }
    }
}

/// C₁, C₂, T, the Killing momenta and H along 10⁴ exact and splitting steps (the energy error
/// of the splitting bounded); the Killing momenta
/// by a second route: K = m(ẋxᵀ − xẋᵀ) + eΠ̂eᵀ on S³ and H³, (x × mẋ + RΠ, mẋ) on ℝ³.
#[test]
fn integrals_are_kept_and_the_killing_momenta_are_the_spatial_momentum() {
    for space in spaces() {
        let top = FrameTop::new(space, 1.3, &INERTIA).unwrap();
        let (x, xd) = start(space);
        let z0 = top
            .state(&x, &frame(), &xd, &Vector3::new(0.7, -0.4, 1.1))
            .unwrap();
        // Second route for J at the start.
        let j = top.killing_momenta(&z0).unwrap();
        let g = Matrix4::from_row_slice(&z0[..16]);
        let pi = Vector3::from_column_slice(&z0[16..19]);
        let m = 1.3;
        let (jpi, jp) = match space {
            SpaceForm::Euclidean => {
                let r = g.fixed_view::<3, 3>(1, 1).into_owned();
                let xv = Vector3::from_column_slice(&x);
                let p = Vector3::from_column_slice(&xd) * m;
                (xv.cross(&p) + r * pi, p)
            }
            _ => {
                let e = g.fixed_view::<4, 3>(0, 1).into_owned();
                let xv = nalgebra::Vector4::from_column_slice(&x);
                let vv = nalgebra::Vector4::from_column_slice(&xd);
                let k = (vv * xv.transpose() - xv * vv.transpose()) * m
                    + e * so3::hat(&pi) * e.transpose();
                let l = space.length();
                (
                    Vector3::new(k[(3, 2)], k[(1, 3)], k[(2, 1)]),
                    Vector3::new(k[(1, 0)], k[(2, 0)], k[(3, 0)]) / l,
                )
            }
        };
        let want = [jpi[0], jpi[1], jpi[2], jp[0], jp[1], jp[2]];
        assert!(dist(&j, &want) < 1e-13, "{space:?}: {j:?} vs {want:?}");
        // On H³ the entries of g grow like e^{d/r} with the distance d travelled and J is their
        // difference: t = 5 there (d ≈ 3.5), t = 500 elsewhere.
        let dt = if space.sigma() < 0.0 { 5e-4 } else { 0.05 };
        for method in ["exact", "splitting4"] {
            let traj = integrate(&top, method, &z0, dt, 10_000, 1000).unwrap();
            let (i0, e0) = (top.invariants(&z0).unwrap(), top.energy(&z0).unwrap());
            for k in 0..traj.len() {
                let i = top.invariants(traj.state(k)).unwrap();
                assert!(
                    dist(&i, &i0) < 1e-11,
                    "{space:?} {method} k={k}: {i:?} vs {i0:?}"
                );
                let e = top.energy(traj.state(k)).unwrap();
                let tol = if method == "exact" { 1e-12 } else { 1e-5 };
                assert!((e - e0).abs() < tol * e0, "{space:?} {method}: {e} vs {e0}");
            }
        }
    }
}

/// On S³: Ṁ = [M, ξ] with ξ = 𝕁⁻¹M on so(4) (central differences along the exact motion), and
/// ½tr(MᵀM) = r²C₂, Pf M = r C₁.
#[test]
fn on_the_three_sphere_the_top_is_the_so4_rigid_body() {
    let space = SpaceForm::sphere(1.7).unwrap();
    let top = FrameTop::new(space, 1.3, &INERTIA).unwrap();
    let (x, xd) = start(space);
    let z0 = top
        .state(&x, &frame(), &xd, &Vector3::new(0.7, -0.4, 1.1))
        .unwrap();
    let jm = nalgebra::Matrix6::from_row_slice(&top.group_inertia().unwrap());
    let jinv = jm.try_inverse().unwrap();
    let coords = |m: &Matrix4<f64>| {
        nalgebra::Vector6::new(
            m[(0, 1)],
            m[(0, 2)],
            m[(0, 3)],
            m[(1, 2)],
            m[(1, 3)],
            m[(2, 3)],
        )
    };
    let hat4 = |c: &nalgebra::Vector6<f64>| {
        let mut a = Matrix4::zeros();
        for (k, (i, j)) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
            .iter()
            .enumerate()
        {
            a[(*i, *j)] = c[k];
            a[(*j, *i)] = -c[k];
        }
        a
    };
    let h = 1e-3;
    let traj = integrate(&top, "exact", &z0, h, 200, 1).unwrap();
    let m_at = |k: usize| top.group_momentum(traj.state(k)).unwrap();
    let mut worst = 0.0f64;
    for k in [50usize, 100, 150] {
        let m = m_at(k);
        let xi = hat4(&(jinv * coords(&m)));
        let rate = (m_at(k + 1) - m_at(k - 1)) / (2.0 * h);
        worst = worst.max((rate - (m * xi - xi * m)).amax());
        // ξ is also g⁻¹ġ.
        let g = |k: usize| Matrix4::from_row_slice(&traj.state(k)[..16]);
        let gd = (g(k + 1) - g(k - 1)) / (2.0 * h);
        assert!((g(k).transpose() * gd - xi).amax() < 1e-5);
    }
    assert!(worst < 1e-5, "Ṁ − [M, ξ]: {worst}");
    let m = m_at(0);
    let [c1, c2] = top.casimirs(&z0).unwrap();
    let pf = m[(0, 1)] * m[(2, 3)] - m[(0, 2)] * m[(1, 3)] + m[(0, 3)] * m[(1, 2)];
    assert!((0.5 * (m.transpose() * m).trace() - 1.7f64.powi(2) * c2).abs() < 1e-12);
    assert!((pf - 1.7 * c1).abs() < 1e-12, "{pf} vs {}", 1.7 * c1);
    assert!(FrameTop::new(SpaceForm::Euclidean, 1.0, &INERTIA)
        .unwrap()
        .group_inertia()
        .is_err());
}

/// On ℝ³ the top is a free particle and a free rigid body.
#[test]
fn in_euclidean_space_a_free_particle_and_a_free_rigid_body() {
    let top = FrameTop::new(SpaceForm::Euclidean, 1.3, &INERTIA).unwrap();
    let (x, xd) = start(SpaceForm::Euclidean);
    let omega = Vector3::new(0.7, -0.4, 1.1);
    let z0 = top.state(&x, &frame(), &xd, &omega).unwrap();
    let t = 3.0;
    let z = integrate(&top, "exact", &z0, t / 10.0, 10, 10)
        .unwrap()
        .state(1)
        .to_vec();
    let want: Vec<f64> = x.iter().zip(&xd).map(|(p, q)| p + t * q).collect();
    assert!(dist(&top.position(&z).unwrap(), &want) < 1e-13);
    let body = lieflow::systems::RigidBody::from_matrix(&INERTIA)
        .unwrap()
        .with_attitude();
    let m0 = Matrix3::from_row_slice(&INERTIA) * omega;
    let r0 = frame();
    let mut zb: Vec<f64> = m0.iter().copied().collect();
    zb.extend((0..9).map(|k| r0[(k / 3, k % 3)]));
    let b = integrate(&body, "exact", &zb, t / 10.0, 10, 10).unwrap();
    let rb = Matrix3::from_row_slice(&b.state(1)[3..12]);
    assert!((top.frame(&z).unwrap() - rb).amax() < 1e-12);
}

/// exp(X) − 1 by Taylor and doublings: against nalgebra's Padé exponential at every scale, and to
/// its own precision for a tiny X (where exp(X) − 1 rounded from exp(X) has lost the digits).
#[test]
fn expm1_of_the_group_elements() {
    use lieflow::systems::tangent_top::space_form::expm1;
    let space = SpaceForm::hyperbolic(1.4).unwrap();
    for scale in [1e-9, 1e-3, 0.3, 2.0, 7.0] {
        let x = space.hat(
            &(Vector3::new(0.3, -1.1, 0.7) * scale),
            &(Vector3::new(0.9, 0.2, -0.5) * scale),
        );
        let want = x.exp() - Matrix4::identity();
        let got = expm1(&x);
        let err = (got - want).amax() / want.amax();
        let tol = if scale < 1e-2 { 1e-6 } else { 1e-13 };
        assert!(err < tol, "scale {scale}: {err:e}");
        if scale < 1e-6 {
            let series = x + x * x / 2.0 + x * x * x / 6.0;
            assert!(
                (got - series).amax() / series.amax() < 1e-15,
                "scale {scale}"
            );
        }
    }
}

// The top on a Riemannian chart.

/// A rotating orthonormal frame of flat space, Q(x) = exp(ŵ(x)).
fn twist(x: [f64; 3]) -> Matrix3<f64> {
    so3::exp_unchecked(&Vector3::new(
        0.3 * x[0] + 0.1 * x[1] * x[1],
        -0.2 * x[2] + 0.4 * x[0] * x[1],
        0.5 * x[0] * x[2] - 0.3 * x[1],
    ))
}

/// Rows of a matrix's transpose: the closures take `e[a][i]` = component i of Ê_a = column a.
fn rows_of_columns(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|a| std::array::from_fn(|i| m[(i, a)]))
}

fn flat_twisted() -> Riemannian {
    Riemannian::new(
        |_| [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        |x| rows_of_columns(&twist(x)),
        None,
    )
}

/// The stereographic chart of S³(r) from its south pole: X(y) = r((1 − s)/(1 + s), 2y/(1 + s)),
/// s = |y|², with g = 4r²/(1 + s)² and the frame Ê_a = (1 + s)/(2r) ∂_a.
const R3: f64 = 1.3;

fn stereo(y: [f64; 3]) -> Vec<f64> {
    let s = y.iter().map(|v| v * v).sum::<f64>();
    let mut x = vec![R3 * (1.0 - s) / (1.0 + s)];
    x.extend(y.iter().map(|v| 2.0 * R3 * v / (1.0 + s)));
    x
}

/// dX (4×3, row-major by ambient component).
fn stereo_jacobian(y: [f64; 3]) -> [[f64; 3]; 4] {
    let s = y.iter().map(|v| v * v).sum::<f64>();
    let d2 = (1.0 + s) * (1.0 + s);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            if i == 0 {
                -4.0 * R3 * y[j] / d2
            } else {
                let delta = if i - 1 == j { 1.0 + s } else { 0.0 };
                2.0 * R3 * (delta - 2.0 * y[i - 1] * y[j]) / d2
            }
        })
    })
}

fn stereo_chart() -> Riemannian {
    let conformal = |y: [f64; 3]| 1.0 + y.iter().map(|v| v * v).sum::<f64>();
    Riemannian::new(
        move |y| {
            let l = 2.0 * R3 / conformal(y);
            let l2 = l * l;
            [[l2, 0.0, 0.0], [0.0, l2, 0.0], [0.0, 0.0, l2]]
        },
        move |y| {
            let e = conformal(y) / (2.0 * R3);
            [[e, 0.0, 0.0], [0.0, e, 0.0], [0.0, 0.0, e]]
        },
        Some(std::sync::Arc::new(|y: [f64; 3]| {
            y.iter().map(|v| v * v).sum::<f64>() < 100.0
        })),
    )
}

/// The ambient components of dX(y) E(y) R: the body axes of the chart's top in ℝ⁴.
fn stereo_axes(y: [f64; 3], r: &Matrix3<f64>) -> Matrix4<f64> {
    let j = stereo_jacobian(y);
    let e = (1.0 + y.iter().map(|v| v * v).sum::<f64>()) / (2.0 * R3);
    let mut a = Matrix4::zeros();
    for i in 0..4 {
        for c in 0..3 {
            a[(i, c)] = (0..3).map(|k| j[i][k] * e * r[(k, c)]).sum();
        }
    }
    a
}

/// C's columns are the axial vectors of QᵀdQ for a rotating frame Q of flat space (by central
/// differences of Q at a small step, a route independent of the chart's stencil), and the frame
/// check passes or names the defect.
#[test]
fn connection_of_a_rotating_frame_of_flat_space() {
    let space = flat_twisted();
    let x = [0.4, -0.7, 0.9];
    let c = space.connection(x);
    let h = 1e-6;
    for j in 0..3 {
        let (mut xp, mut xm) = (x, x);
        xp[j] += h;
        xm[j] -= h;
        let a = twist(x).transpose() * (twist(xp) - twist(xm)) / (2.0 * h);
        let want = Vector3::new(a[(2, 1)], a[(0, 2)], a[(1, 0)]);
        assert!((c.column(j) - want).amax() < 1e-8, "{j}: {c} vs {want}");
    }
    space.check_frame(x, 1e-12).unwrap();
    let bad = Riemannian::new(
        |_| [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        |x| rows_of_columns(&twist(x)),
        None,
    );
    assert!(bad.check_frame(x, 1e-10).is_err());
}

/// The field is Hamilton's equations of H (by differences of the energy): ẋ = ∂H/∂p,
/// ṗ = −∂H/∂x, Ṙ = R(∂H/∂Π)^, on the sphere's chart with a turned frame and a spin.
#[test]
fn the_field_is_hamiltons_equations_of_h() {
    let top = RiemannianFrameTop::new(
        stereo_chart(),
        1.3,
        &[2.0, 0.0, 0.0, 0.0, 3.1, 0.0, 0.0, 0.0, 4.2],
    )
    .unwrap();
    let z = top
        .state(
            &[0.3, -0.2, 0.5],
            &frame(),
            &[0.4, 0.1, -0.3],
            &Vector3::new(0.7, -0.4, 1.1),
        )
        .unwrap();
    let mut dz = vec![0.0; 18];
    top.field(&z, &mut dz);
    let h = 1e-5;
    let d = |k: usize| {
        let (mut zp, mut zm) = (z.clone(), z.clone());
        zp[k] += h;
        zm[k] -= h;
        (top.energy(&zp).unwrap() - top.energy(&zm).unwrap()) / (2.0 * h)
    };
    for k in 0..3 {
        assert!((dz[k] - d(3 + k)).abs() < 1e-8, "xdot {k}");
        assert!(
            (dz[3 + k] + d(k)).abs() < 1e-7,
            "pdot {k}: {} vs {}",
            dz[3 + k],
            -d(k)
        );
    }
    let dh_dpi = Vector3::new(d(15), d(16), d(17));
    let r = Matrix3::from_row_slice(&z[6..15]);
    let rdot = Matrix3::from_row_slice(&dz[6..15]);
    assert!((r.transpose() * rdot - so3::hat(&dh_dpi)).amax() < 1e-8);
    // Π̇ = Π × 𝕀⁻¹Π: the free Euler top.
    let pi = Vector3::from_column_slice(&z[15..18]);
    let w = Vector3::new(pi[0] / 2.0, pi[1] / 3.1, pi[2] / 4.2);
    assert!((Vector3::from_column_slice(&dz[15..18]) - pi.cross(&w)).amax() < 1e-15);
}

/// On flat space with a rotating frame field the top is a free particle and a free rigid body:
/// the same motion as `FrameTop` on ℝ³ (its body axes Q(x)R in space).
#[test]
fn on_flat_space_with_a_rotating_frame_the_euclidean_top() {
    let top = RiemannianFrameTop::new(flat_twisted(), 1.3, &INERTIA).unwrap();
    let euclid = FrameTop::new(SpaceForm::Euclidean, 1.3, &INERTIA).unwrap();
    let (x, xd) = (vec![0.3, -0.2, 1.0], vec![0.4, 0.1, -0.3]);
    let omega = Vector3::new(0.7, -0.4, 1.1);
    let z0 = top.state(&x, &frame(), &xd, &omega).unwrap();
    let q0 = twist([x[0], x[1], x[2]]);
    let e0 = euclid.state(&x, &(q0 * frame()), &xd, &omega).unwrap();
    let (t, n) = (2.0, 200);
    let a = integrate(&top, "midpoint6", &z0, t / n as f64, n, n).unwrap();
    let b = integrate(&euclid, "exact", &e0, t, 1, 1).unwrap();
    let (za, zb) = (a.state(1), b.state(1));
    let xa = top.position(za).unwrap();
    assert!(dist(&xa, &euclid.position(zb).unwrap()) < 1e-9);
    let axes = twist([xa[0], xa[1], xa[2]]) * top.frame(za).unwrap();
    assert!((axes - euclid.frame(zb).unwrap()).amax() < 1e-8);
    assert!(dist(&top.velocity(za).unwrap(), &xd) < 1e-9);
}

/// On S³ in the stereographic chart: the same motion as `FrameTop` on the sphere (positions and
/// body axes in ℝ⁴, the angular velocity), so the coupling to the curvature is the one the group
/// picture derives; the orders of the methods; H − T and |Π| kept to round-off, H bounded.
#[test]
fn on_the_three_sphere_in_a_stereographic_chart() {
    let chart = RiemannianFrameTop::new(stereo_chart(), 1.3, &INERTIA).unwrap();
    let sphere = SpaceForm::sphere(R3).unwrap();
    let group = FrameTop::new(sphere, 1.3, &INERTIA).unwrap();
    let (y0, yd0) = ([0.3, -0.2, 0.5], [0.4, 0.1, -0.3]);
    let omega = Vector3::new(0.7, -0.4, 1.1);
    let z0 = chart.state(&y0, &frame(), &yd0, &omega).unwrap();
    // The same body in ℝ⁴: x = X(y), ẋ = dX ẏ, axes dX E R = Ê(x) R'.
    let x0 = stereo(y0);
    let j = stereo_jacobian(y0);
    let xd0: Vec<f64> = (0..4)
        .map(|i| (0..3).map(|k| j[i][k] * yd0[k]).sum())
        .collect();
    let reference = sphere.reference(&x0);
    let axes = stereo_axes(y0, &frame());
    let r0 = (reference.transpose() * axes)
        .fixed_view::<3, 3>(1, 0)
        .into_owned();
    let g0 = group.state(&x0, &r0, &xd0, &omega).unwrap();
    let (t, n) = (1.5, 150);
    let a = integrate(&chart, "midpoint6", &z0, t / n as f64, n, n).unwrap();
    let b = integrate(&group, "exact", &g0, t, 1, 1).unwrap();
    let (za, zb) = (a.state(1), b.state(1));
    let y: Vec<f64> = chart.position(za).unwrap();
    let y = [y[0], y[1], y[2]];
    assert!(dist(&stereo(y), &group.position(zb).unwrap()) < 1e-8);
    let g = Matrix4::from_row_slice(&zb[..16]);
    let want = g.fixed_view::<4, 3>(0, 1).into_owned();
    let got = stereo_axes(y, &chart.frame(za).unwrap());
    assert!((got.fixed_view::<4, 3>(0, 0) - want).amax() < 1e-8);
    assert!(
        (chart.angular_velocity(za).unwrap() - group.angular_velocity(zb).unwrap()).amax() < 1e-12
    );
    assert!(
        (chart.translational_energy(za).unwrap() - group.translational_energy(zb).unwrap()).abs()
            < 1e-8
    );

    // Orders against the finest run; invariants.
    let end = |m: &str, n: usize| integrate(&chart, m, &z0, t / n as f64, n, n).unwrap();
    let zr = za.to_vec();
    for (m, order, n) in [
        ("midpoint", 2.0, 20),
        ("midpoint4", 4.0, 10),
        ("rkmk4", 4.0, 20),
    ] {
        let e1 = dist(end(m, n).state(1), &zr);
        let e2 = dist(end(m, 2 * n).state(1), &zr);
        let observed = (e1 / e2).log2();
        assert!(
            (observed - order).abs() < 0.3,
            "{m}: {observed} ({e1:e}, {e2:e})"
        );
    }
    let long = integrate(&chart, "midpoint", &z0, 0.05, 2000, 20).unwrap();
    let (h0, i0) = (chart.energy(&z0).unwrap(), chart.invariants(&z0).unwrap());
    let mut worst_h = 0.0f64;
    for k in 0..long.len() {
        let z = long.state(k);
        worst_h = worst_h.max((chart.energy(z).unwrap() - h0).abs() / h0);
        let i = chart.invariants(z).unwrap();
        assert!(
            (i[0] - i0[0]).abs() < 1e-13 * i0[0],
            "H − T: {} vs {}",
            i[0],
            i0[0]
        );
        assert!((i[1] - i0[1]).abs() < 1e-13 * i0[1], "|Π|²");
    }
    assert!(worst_h < 1e-3, "H: {worst_h}");
}
