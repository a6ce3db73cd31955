//! The tangent Euler top on surfaces (002 §II–III): the surfaces' closed forms against their
//! definitions, the metric g_AB (002 (47), corrected) against the Lagrangian 002 (10), the flat and
//! spherical limits (002 (79)–(80)), frame independence (§II.C), isometries and their momenta
//! (§III.C), orders and long-time energy of the Gauss methods, holonomy (Gauss–Bonnet), the
//! embedded top (§II.D, (37)/(39)) against the ambient kinetic energy and the Euler top, the
//! charged-particle analogue (§III.B) and the involution of the integrals.

// Index loops mirror the index notation of the formulas they check.
#![allow(clippy::needless_range_loop)]

use std::f64::consts::PI;
use std::sync::Arc;

use lieflow::integrate::{integrate, Problem};
use lieflow::lie::so3;
use lieflow::systems::tangent_top::surface::{inverse, Geometry, Jet, Mat2, Vec2};
use lieflow::systems::{
    Graph, HyperbolicPlane, MetricSurface, Plane, Revolution, RigidBody, Sphere, Surface,
    TangentTop,
};
use nalgebra::{Matrix3, Vector3};

// ---------------------------------------------------------------------------------------------
// helpers

fn fd<const N: usize>(f: impl Fn(Vec2) -> [f64; N], x: Vec2, k: usize, h: f64) -> [f64; N] {
    let (mut a, mut b) = (x, x);
    a[k] += h;
    b[k] -= h;
    let (fa, fb) = (f(a), f(b));
    std::array::from_fn(|i| (fa[i] - fb[i]) / (2.0 * h))
}

fn flat(m: Mat2) -> [f64; 4] {
    [m[0][0], m[0][1], m[1][0], m[1][1]]
}

/// α_i = ⟨∇_{∂_i} Ê₁, Ê₂⟩ from the Christoffel symbols Γ^j_{il} = ½ g^{jm}(∂_i g_ml + ∂_l g_mi −
/// ∂_m g_il) of finite differences of the metric, and differences of the frame.
fn alpha_by_definition(s: &dyn Surface, x: Vec2) -> Vec2 {
    let h = 1e-5;
    let g = s.metric(x);
    let gi = inverse(&g);
    let dg = [
        fd(|y| flat(s.metric(y)), x, 0, h),
        fd(|y| flat(s.metric(y)), x, 1, h),
    ];
    let dgm = |k: usize, i: usize, j: usize| dg[k][2 * i + j];
    let e = s.frame(x);
    std::array::from_fn(|i| {
        let de1 = fd(|y| s.frame(y)[0], x, i, h);
        // (∇_{∂_i} Ê₁)^j = ∂_i e₁^j + Γ^j_{il} e₁^l
        let mut nab = [0.0; 2];
        for j in 0..2 {
            nab[j] = de1[j];
            for l in 0..2 {
                let mut gam = 0.0;
                for m in 0..2 {
                    gam += 0.5 * gi[j][m] * (dgm(i, m, l) + dgm(l, m, i) - dgm(m, i, l));
                }
                nab[j] += gam * e[0][l];
            }
        }
        (0..2)
            .flat_map(|j| (0..2).map(move |k| (j, k)))
            .map(|(j, k)| g[j][k] * nab[j] * e[1][k])
            .sum()
    })
}

/// Brioschi's formula for an orthogonal metric E du² + G dv²:
/// K = −1/(2√(EG)) [∂_u(G_u/√(EG)) + ∂_v(E_v/√(EG))], by nested finite differences.
fn brioschi_orthogonal(s: &dyn Surface, x: Vec2) -> f64 {
    let h = 1e-4;
    let eg = |y: Vec2| {
        let g = s.metric(y);
        (g[0][0], g[1][1])
    };
    let gu = |y: Vec2| {
        let d = fd(|z| [eg(z).1], y, 0, h)[0];
        let (e, g) = eg(y);
        [d / (e * g).sqrt()]
    };
    let ev = |y: Vec2| {
        let d = fd(|z| [eg(z).0], y, 1, h)[0];
        let (e, g) = eg(y);
        [d / (e * g).sqrt()]
    };
    let (e, g) = eg(x);
    -(fd(gu, x, 0, 1e-3)[0] + fd(ev, x, 1, 1e-3)[0]) / (2.0 * (e * g).sqrt())
}

fn surfaces() -> Vec<(Arc<dyn Surface>, Vec<Vec2>)> {
    vec![
        (Arc::new(Plane), vec![[0.3, -1.2], [2.0, 0.5]]),
        (
            Arc::new(Sphere::new(1.3).unwrap()),
            vec![[0.4, 0.2], [1.9, -2.5], [2.8, 1.0]],
        ),
        (Arc::new(HyperbolicPlane), vec![[0.3, 0.5], [-1.0, 2.2]]),
        (
            Arc::new(Revolution::torus(2.0, 0.7).unwrap()),
            vec![[0.3, 0.5], [2.5, -1.0], [-1.7, 3.0]],
        ),
        (
            Arc::new(Revolution::sphere(1.3).unwrap()),
            vec![[0.4, 0.2], [1.9, -2.5]],
        ),
        (Arc::new(wavy_graph()), vec![[0.3, -0.4], [1.2, 0.9]]),
        (
            Arc::new(Graph::quadric(0.8, -0.5).unwrap()),
            vec![[0.3, -0.4], [-1.1, 0.7]],
        ),
    ]
}

/// The graph of f = 0.3 sin x cos 1.3y + 0.2xy (non-orthogonal metric, no symmetry).
fn wavy_graph() -> Graph {
    Graph::new(|x: Vec2| {
        let (sa, ca) = x[0].sin_cos();
        let (sb, cb) = (1.3 * x[1]).sin_cos();
        Jet {
            value: 0.3 * sa * cb + 0.2 * x[0] * x[1],
            gradient: [0.3 * ca * cb + 0.2 * x[1], -0.39 * sa * sb + 0.2 * x[0]],
            hessian: [
                [-0.3 * sa * cb, -0.39 * ca * sb + 0.2],
                [-0.39 * ca * sb + 0.2, -0.507 * sa * cb],
            ],
            third: [
                -0.3 * ca * cb,
                0.39 * sa * sb,
                -0.507 * ca * cb,
                0.6591 * sa * sb,
            ],
        }
    })
}

fn embedded_surfaces() -> Vec<(Arc<dyn Surface>, Vec<Vec2>)> {
    surfaces()
        .into_iter()
        .filter(|(s, _)| s.embedding().is_some())
        .collect()
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The angle difference a − b wrapped to (−π, π].
fn wrap(d: f64) -> f64 {
    let r = d.rem_euclid(2.0 * PI);
    if r > PI {
        r - 2.0 * PI
    } else {
        r
    }
}

/// Distance of two configurations (x, θ), θ modulo 2π.
fn config_dist(a: &[f64], b: &[f64]) -> f64 {
    (a[0] - b[0])
        .abs()
        .max((a[1] - b[1]).abs())
        .max(wrap(a[2] - b[2]).abs())
}

// ---------------------------------------------------------------------------------------------
// 1. surfaces

#[test]
fn closed_forms_match_their_definitions() {
    for (s, points) in surfaces() {
        for &x in &points {
            let name = s.name();
            assert!(s.contains(x));
            let g = s.metric(x);
            // metric derivatives
            let dg = s.metric_derivatives(x);
            for k in 0..2 {
                let num = fd(|y| flat(s.metric(y)), x, k, 1e-6);
                assert!(dist(&flat(dg[k]), &num) < 1e-8, "{name} ∂g at {x:?}");
            }
            // the frame is orthonormal and positively oriented
            let e = s.frame(x);
            for a in 0..2 {
                for b in 0..2 {
                    let gab = lieflow::systems::tangent_top::surface::inner(&g, e[a], e[b]);
                    assert!((gab - f64::from(u8::from(a == b))).abs() < 1e-14);
                }
            }
            assert!(e[0][0] * e[1][1] - e[0][1] * e[1][0] > 0.0);
            // α against ⟨∇_{∂_i} Ê₁, Ê₂⟩
            let a = s.connection(x);
            let a_def = alpha_by_definition(&*s, x);
            assert!(
                dist(&a, &a_def) < 1e-8,
                "{name} α {a:?} vs {a_def:?} at {x:?}"
            );
            // ∂α
            let da = s.connection_derivatives(x);
            for k in 0..2 {
                let num = fd(|y| s.connection(y), x, k, 1e-6);
                assert!(dist(&da[k], &num) < 1e-8, "{name} ∂α at {x:?}");
            }
            // K: closed form = −dα/dA = Brioschi
            let k = s.curvature(x);
            let k_conn =
                -(da[0][1] - da[1][0]) / lieflow::systems::tangent_top::surface::det(&g).sqrt();
            assert!((k - k_conn).abs() < 1e-12 * (1.0 + k.abs()), "{name} K");
            if g[0][1] == 0.0 {
                let k_b = brioschi_orthogonal(&*s, x);
                assert!(
                    (k - k_b).abs() < 1e-5,
                    "{name} K = {k} vs Brioschi {k_b} at {x:?}"
                );
            }
            // the default geometry agrees with the pieces
            let geo: Geometry = s.geometry(x);
            assert_eq!(geo.alpha, a);
            assert_eq!(geo.dalpha, da);
        }
    }
    // the sphere as a surface of revolution is the sphere
    let (a, b) = (Sphere::new(1.3).unwrap(), Revolution::sphere(1.3).unwrap());
    for x in [[0.4, 0.2], [2.0, 3.0]] {
        assert!(dist(&flat(a.metric(x)), &flat(b.metric(x))) < 1e-14);
        assert!(dist(&a.connection(x), &b.connection(x)) < 1e-14);
        assert!((a.curvature(x) - b.curvature(x)).abs() < 1e-14);
    }
    // known curvatures
    assert!((Sphere::new(2.0).unwrap().curvature([1.0, 0.0]) - 0.25).abs() < 1e-15);
    assert_eq!(HyperbolicPlane.curvature([0.0, 1.0]), -1.0);
    let t = Revolution::torus(2.0, 0.7).unwrap();
    // torus: K = cos s / (b (a + b cos s))
    let s0: f64 = 0.8;
    let want = s0.cos() / (0.7 * (2.0 + 0.7 * s0.cos()));
    assert!((t.curvature([s0, 0.1]) - want).abs() < 1e-14);
}

#[test]
fn embeddings_are_consistent() {
    for (s, points) in embedded_surfaces() {
        let emb = s.embedding().unwrap();
        for x in points {
            let g = s.metric(x);
            let dx = [
                fd(|y| emb.position(y), x, 0, 1e-6),
                fd(|y| emb.position(y), x, 1, 1e-6),
            ];
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            for i in 0..2 {
                for j in 0..2 {
                    assert!((dot(dx[i], dx[j]) - g[i][j]).abs() < 1e-8, "{} g", s.name());
                }
            }
            // n = Ê₁ × Ê₂
            let e = s.frame(x);
            let (e1, e2) = (emb.tangent(x, e[0]), emb.tangent(x, e[1]));
            let c = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            assert!(dist(&c, &emb.normal(x)) < 1e-14, "{} n", s.name());
            // h_ij = ⟨∂_i∂_j X, n⟩
            let h = emb.second_fundamental_form(x);
            let n = emb.normal(x);
            for i in 0..2 {
                for j in 0..2 {
                    let dd = fd(|y| fd(|z| emb.position(z), y, j, 1e-4), x, i, 1e-4);
                    assert!((dot(dd, n) - h[i][j]).abs() < 1e-6, "{} h", s.name());
                }
            }
            // the shape operator W_aμ = −⟨Ê_a, ∂_μ n⟩, and ∂W by differences
            let shape = emb.shape(x);
            for mu in 0..2 {
                let dn = fd(|y| emb.normal(y), x, mu, 1e-6);
                for a in 0..2 {
                    let ea = emb.tangent(x, e[a]);
                    let want = -dot(ea, dn);
                    assert!(
                        (shape.w[a][mu] - want).abs() < 1e-8,
                        "{} W[{a}][{mu}] = {} vs {want}",
                        s.name(),
                        shape.w[a][mu]
                    );
                }
                let num = fd(|y| flat(emb.shape(y).w), x, mu, 1e-6);
                assert!(dist(&flat(shape.dw[mu]), &num) < 1e-8, "{} ∂W", s.name());
            }
        }
    }
}

fn sphere_metric(x: Vec2) -> Mat2 {
    [[1.0, 0.0], [0.0, x[0].sin().powi(2)]]
}

fn sphere_frame(x: Vec2) -> Mat2 {
    [[1.0, 0.0], [0.0, 1.0 / x[0].sin()]]
}

#[test]
fn metric_surface_reproduces_the_sphere_and_a_graph() {
    let domain: lieflow::systems::tangent_top::surface::DomainFn =
        Arc::new(|x: Vec2| x[0] > 0.0 && x[0] < PI);
    let ms = MetricSurface::new(sphere_metric, sphere_frame, Some(domain));
    let sp = Sphere::new(1.0).unwrap();
    ms.check_frame([1.0, 0.5], 1e-14).unwrap();
    for x in [[0.4, 0.2], [1.9, -2.5], [2.6, 1.0]] {
        for k in 0..2 {
            let (a, b) = (ms.metric_derivatives(x)[k], sp.metric_derivatives(x)[k]);
            assert!(dist(&flat(a), &flat(b)) < 1e-11);
        }
        assert!(dist(&ms.connection(x), &sp.connection(x)) < 1e-11);
        assert!(
            dist(
                &flat(ms.connection_derivatives(x)),
                &flat(sp.connection_derivatives(x))
            ) < 1e-8
        );
        assert!((ms.curvature(x) - 1.0).abs() < 1e-8);
    }
    // a graph z = f(x, y) with a non-diagonal metric I + ∇f∇fᵀ and a Gram–Schmidt frame:
    // K = (f_xx f_yy − f_xy²)/(1 + |∇f|²)².
    let grad = |x: Vec2| {
        let (a, b) = (x[0], x[1]);
        [
            0.3 * a.cos() * (1.3 * b).cos() + 0.2 * b,
            -0.39 * a.sin() * (1.3 * b).sin() + 0.2 * a,
        ]
    };
    let metric = move |x: Vec2| {
        let f = grad(x);
        [
            [1.0 + f[0] * f[0], f[0] * f[1]],
            [f[0] * f[1], 1.0 + f[1] * f[1]],
        ]
    };
    let frame = move |x: Vec2| {
        let g = metric(x);
        let e1 = [1.0 / g[0][0].sqrt(), 0.0];
        // e₂ = (∂y − ⟨∂y, e₁⟩ e₁)/|…|
        let c = g[0][1] * e1[0];
        let v = [-c * e1[0], 1.0];
        let n = lieflow::systems::tangent_top::surface::inner(&g, v, v).sqrt();
        [e1, [v[0] / n, v[1] / n]]
    };
    let ms = MetricSurface::new(metric, frame, None);
    for x in [[0.3, -0.4], [1.2, 0.9]] {
        ms.check_frame(x, 1e-14).unwrap();
        let (a, b) = (x[0], x[1]);
        let fxx = -0.3 * a.sin() * (1.3 * b).cos();
        let fyy = -0.507 * a.sin() * (1.3 * b).cos();
        let fxy = -0.39 * a.cos() * (1.3 * b).sin() + 0.2;
        let f = grad(x);
        let want = (fxx * fyy - fxy * fxy) / (1.0 + f[0] * f[0] + f[1] * f[1]).powi(2);
        let k = ms.curvature(x);
        assert!((k - want).abs() < 1e-8, "graph K {k} vs {want}");
        assert!(dist(&ms.connection(x), &alpha_by_definition(&ms, x)) < 1e-8);
    }
}

// ---------------------------------------------------------------------------------------------
// 2. the metric of the top against the Lagrangian (10)

/// 002 (10) on the sphere of radius R in ℝ³, with the body's 2×2 Euler tensor `eul`:
/// L = ½ m|ċ|² + ½ I_ij ⟨∇_ċ E_i, ∇_ċ E_j⟩, ∇ the tangential part of the ambient derivative,
/// E₁ = cos θ Ê₁ + sin θ Ê₂ with the explicit frame Ê₁ = ∂ϑ/R, Ê₂ = ∂φ/(R sin ϑ).
fn lagrangian_10_sphere(r: f64, m: f64, eul: [[f64; 2]; 2], eta: [f64; 3], etad: [f64; 3]) -> f64 {
    let pos = |e: [f64; 3]| {
        let (s, c) = e[0].sin_cos();
        let (sp, cp) = e[1].sin_cos();
        [r * s * cp, r * s * sp, r * c]
    };
    let body = |e: [f64; 3]| {
        let (s, c) = e[0].sin_cos();
        let (sp, cp) = e[1].sin_cos();
        let h1 = [c * cp, c * sp, -s];
        let h2 = [-sp, cp, 0.0];
        let (st, ct) = e[2].sin_cos();
        let e1: [f64; 3] = std::array::from_fn(|k| ct * h1[k] + st * h2[k]);
        let e2: [f64; 3] = std::array::from_fn(|k| -st * h1[k] + ct * h2[k]);
        [e1, e2]
    };
    let h = 1e-5;
    let at = |t: f64| std::array::from_fn::<f64, 3, _>(|k| eta[k] + t * etad[k]);
    let cdot: [f64; 3] = {
        let (a, b) = (pos(at(h)), pos(at(-h)));
        std::array::from_fn(|k| (a[k] - b[k]) / (2.0 * h))
    };
    let n = pos(eta).map(|v| v / r);
    let (ba, bb) = (body(at(h)), body(at(-h)));
    let nab: [[f64; 3]; 2] = std::array::from_fn(|i| {
        let d: [f64; 3] = std::array::from_fn(|k| (ba[i][k] - bb[i][k]) / (2.0 * h));
        let dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
        std::array::from_fn(|k| d[k] - dn * n[k])
    });
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut l = 0.5 * m * dot(cdot, cdot);
    for i in 0..2 {
        for j in 0..2 {
            l += 0.5 * eul[i][j] * dot(nab[i], nab[j]);
        }
    }
    l
}

#[test]
fn metric_47_from_lagrangian_10() {
    let (r, m) = (1.7, 2.3);
    let eul = [[0.7, 0.2], [0.2, 0.4]];
    let top = TangentTop::with_tensor(Arc::new(Sphere::new(r).unwrap()), m, [0.7, 0.2, 0.2, 0.4])
        .unwrap();
    assert!((top.inertia() - 1.1).abs() < 1e-15);
    for eta in [[0.7, 0.3, 0.2], [2.2, -1.0, 2.5]] {
        let g = top.metric(eta).unwrap();
        let unit = |a: usize| std::array::from_fn::<f64, 3, _>(|k| f64::from(u8::from(k == a)));
        for a in 0..3 {
            for b in 0..3 {
                // polarisation of the quadratic form: g_AB = L(e_A + e_B) − L(e_A) − L(e_B)
                let sum: [f64; 3] = std::array::from_fn(|k| unit(a)[k] + unit(b)[k]);
                let gab = lagrangian_10_sphere(r, m, eul, eta, sum)
                    - lagrangian_10_sphere(r, m, eul, eta, unit(a))
                    - lagrangian_10_sphere(r, m, eul, eta, unit(b));
                assert!(
                    (gab - g[a][b]).abs() < 1e-8,
                    "g[{a}][{b}] = {} vs (10): {gab} at {eta:?}",
                    g[a][b]
                );
            }
        }
        // the cross term is large here, so the printed sign of (45)/(47) (−𝕀α) would fail above
        assert!(g[1][2].abs() > 0.1);
        // L itself
        let etad = [0.3, -0.8, 1.1];
        let l = top.lagrangian(eta, etad).unwrap();
        assert!((l - lagrangian_10_sphere(r, m, eul, eta, etad)).abs() < 1e-8);
    }
}

// ---------------------------------------------------------------------------------------------
// 3. dynamics

fn config(z: &[f64]) -> [f64; 3] {
    [z[0], z[1], z[2]]
}

#[test]
fn flat_space_free_translation_and_uniform_rotation() {
    let top = TangentTop::new(Arc::new(Plane), 1.5, 0.4).unwrap();
    let z0 = top.state([0.2, -0.1], 0.3, [0.3, -0.2], 0.7).unwrap();
    assert!(dist(&z0[3..], &[0.45, -0.3, 0.28]) < 1e-15);
    for method in ["midpoint", "gauss4", "gauss6", "rk4"] {
        let traj = integrate(&top, method, &z0, 0.1, 100, 10).unwrap();
        for k in 0..traj.len() {
            let t = traj.t[k];
            let want = [0.2 + 0.3 * t, -0.1 - 0.2 * t, 0.3 + 0.7 * t];
            assert!(dist(&config(traj.state(k)), &want) < 1e-12, "{method}");
            assert!(dist(&traj.state(k)[3..], &z0[3..]) < 1e-14);
        }
    }
}

/// The rotation matrix Q = [n | E₁ | E₂] (columns) of a state on the unit sphere.
fn attitude(top: &TangentTop, z: &[f64]) -> Matrix3<f64> {
    let [c, e1, e2] = top.ambient_frame(z).unwrap().unwrap();
    Matrix3::from_columns(&[Vector3::from(c), Vector3::from(e1), Vector3::from(e2)])
}

#[test]
fn unit_sphere_top_is_the_symmetric_euler_top() {
    // OS² ≅ SO(3): Q = [n | E₁ | E₂]; the body angular velocity Ω (Q̇ = QΩ̂) has Ω₁ = θ̇ + α·ẋ
    // (the spin about n) and ċ = ω × n gives Ω₂ = −ċ·E₂, Ω₃ = ċ·E₁; L = ½𝕀Ω₁² + ½m(Ω₂² + Ω₃²):
    // the symmetric Euler top with moments (𝕀, m, m) (002 (79)–(80)).
    let (m, inertia) = (1.0, 0.6);
    let top = TangentTop::new(Arc::new(Sphere::new(1.0).unwrap()), m, inertia).unwrap();
    let z0 = top.state([1.1, 0.3], 0.4, [0.5, -0.3], 0.8).unwrap();
    let [c, e1, e2] = top.ambient_frame(&z0).unwrap().unwrap();
    let v = top.velocities(&z0).unwrap();
    let emb = top.surface().embedding().unwrap();
    let cdot = emb.tangent([z0[0], z0[1]], [v[0], v[1]]);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let omega = [z0[5] / inertia, -dot(cdot, e2), dot(cdot, e1)];
    let mm = [inertia * omega[0], m * omega[1], m * omega[2]];
    let q0 = attitude(&top, &z0);
    assert!(
        (q0.determinant() - 1.0).abs() < 1e-14
            && (q0.transpose() * q0 - Matrix3::identity()).norm() < 1e-14
    );
    let _ = c;
    let body = RigidBody::new([inertia, m, m]).unwrap().with_attitude();
    let rows: Vec<f64> = (0..9).map(|k| q0[(k / 3, k % 3)]).collect();
    let w0 = body.state_with_attitude(mm, rows.try_into().unwrap());
    // energies agree
    assert!((body.energy(&w0).unwrap() - top.energy(&z0).unwrap()).abs() < 1e-14);
    // the spatial angular momentum Q M is the vector of Killing momenta (J_x, J_y, J_z)
    let j = top.killing_momenta(&z0).unwrap();
    let jm = RigidBody::spatial_momentum(&w0).unwrap();
    assert!(dist(&j, &jm) < 1e-14, "J {j:?} vs QM {jm:?}");
    let (t_end, dt) = (6.0, 0.005);
    let steps = (t_end / dt) as usize;
    let a = integrate(&top, "gauss6", &z0, dt, steps, 100).unwrap();
    let b = integrate(&body, "splitting6", &w0, dt, steps, 100).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..a.len() {
        let q = attitude(&top, a.state(k));
        let r = Matrix3::from_row_slice(&b.state(k)[3..12]);
        worst = worst.max((q - r).norm());
    }
    eprintln!("unit sphere vs RigidBody (𝕀, m, m): max ‖Q − R‖ = {worst:.2e} over t ≤ {t_end}");
    assert!(worst < 1e-9);
}

/// The sphere's frame turned by χ(x) = 0.5 sin 2ϑ cos φ + 0.3 cos ϑ, as a [`MetricSurface`].
fn chi(x: Vec2) -> (f64, [f64; 2]) {
    let (a, b) = (x[0], x[1]);
    (
        0.5 * (2.0 * a).sin() * b.cos() + 0.3 * a.cos(),
        [
            (2.0 * a).cos() * b.cos() - 0.3 * a.sin(),
            -0.5 * (2.0 * a).sin() * b.sin(),
        ],
    )
}

#[test]
fn frame_independence() {
    // Ẽ₁ = cos χ Ê₁ + sin χ Ê₂: α̃ = α + dχ and θ̃ = θ − χ(x) describe the same body (002 §II.C).
    let rotated = move |x: Vec2| {
        let e = sphere_frame(x);
        let (s, c) = chi(x).0.sin_cos();
        [
            [c * e[0][0] + s * e[1][0], c * e[0][1] + s * e[1][1]],
            [-s * e[0][0] + c * e[1][0], -s * e[0][1] + c * e[1][1]],
        ]
    };
    let domain: lieflow::systems::tangent_top::surface::DomainFn =
        Arc::new(|x: Vec2| x[0] > 0.0 && x[0] < PI);
    let ms = MetricSurface::new(sphere_metric, rotated, Some(domain));
    let sp = Sphere::new(1.0).unwrap();
    for x in [[1.0, 0.4], [2.0, -1.0]] {
        ms.check_frame(x, 1e-14).unwrap();
        let (a, at) = (sp.connection(x), ms.connection(x));
        let d = chi(x).1;
        assert!(dist(&at, &[a[0] + d[0], a[1] + d[1]]) < 1e-10);
    }
    let a = TangentTop::new(Arc::new(sp), 1.0, 0.6).unwrap();
    let b = TangentTop::new(Arc::new(ms), 1.0, 0.6).unwrap();
    let (x0, th0, xd, thd) = ([1.3, 0.2], 0.4, [0.3, 0.5], 1.2);
    let za = a.state(x0, th0, xd, thd).unwrap();
    let (c0, dc) = chi(x0);
    let zb = b
        .state(x0, th0 - c0, xd, thd - (dc[0] * xd[0] + dc[1] * xd[1]))
        .unwrap();
    assert!((a.energy(&za).unwrap() - b.energy(&zb).unwrap()).abs() < 1e-10);
    let ta = integrate(&a, "gauss4", &za, 0.01, 400, 20).unwrap();
    let tb = integrate(&b, "gauss4", &zb, 0.01, 400, 20).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..ta.len() {
        let (p, q) = (ta.state(k), tb.state(k));
        let c = chi([q[0], q[1]]).0;
        worst = worst.max(config_dist(p, &[q[0], q[1], q[2] + c]));
    }
    eprintln!("frame independence: max distance of the curves on OM {worst:.2e}");
    assert!(worst < 1e-7);
}

// ---------------------------------------------------------------------------------------------
// isometries

type Flow = Box<dyn Fn(f64, [f64; 3]) -> [f64; 3]>;

/// The one-parameter groups of each surface's isometries acting on (x, θ), in the order of
/// [`Surface::killing`].
fn plane_flows() -> Vec<Flow> {
    vec![
        Box::new(|t, e| [e[0] + t, e[1], e[2]]),
        Box::new(|t, e| [e[0], e[1] + t, e[2]]),
        Box::new(|t, e| {
            let (s, c) = t.sin_cos();
            [c * e[0] - s * e[1], s * e[0] + c * e[1], e[2] + t]
        }),
    ]
}

fn sphere_rotate(rot: Matrix3<f64>, e: [f64; 3]) -> [f64; 3] {
    let (s, c) = e[0].sin_cos();
    let (sp, cp) = e[1].sin_cos();
    let n = rot * Vector3::new(s * cp, s * sp, c);
    let h1 = Vector3::new(c * cp, c * sp, -s);
    let h2 = Vector3::new(-sp, cp, 0.0);
    let e1 = rot * (e[2].cos() * h1 + e[2].sin() * h2);
    let th = n[2].clamp(-1.0, 1.0).acos();
    let ph = n[1].atan2(n[0]);
    let g1 = Vector3::new(th.cos() * ph.cos(), th.cos() * ph.sin(), -th.sin());
    let g2 = Vector3::new(-ph.sin(), ph.cos(), 0.0);
    [th, ph, e1.dot(&g2).atan2(e1.dot(&g1))]
}

fn sphere_flows() -> Vec<Flow> {
    (0..3)
        .map(|k| {
            Box::new(move |t: f64, e: [f64; 3]| {
                let mut w = Vector3::zeros();
                w[k] = t;
                sphere_rotate(so3::exp_unchecked(&w), e)
            }) as Flow
        })
        .collect()
}

fn mobius(g: [f64; 4], e: [f64; 3]) -> [f64; 3] {
    let [a, b, c, d] = g;
    let (x, y) = (e[0], e[1]);
    // (az + b)/(cz + d) and arg g′(z) = −2 arg(cz + d)
    let (nr, ni) = (a * x + b, a * y);
    let (dr, di) = (c * x + d, c * y);
    let den = dr * dr + di * di;
    [
        (nr * dr + ni * di) / den,
        (ni * dr - nr * di) / den,
        e[2] - 2.0 * di.atan2(dr),
    ]
}

fn hyperbolic_flows() -> Vec<Flow> {
    vec![
        Box::new(|t, e| mobius([1.0, t, 0.0, 1.0], e)),
        Box::new(|t, e| mobius([t.exp(), 0.0, 0.0, (-t).exp()], e)),
        Box::new(|t, e| mobius([1.0, 0.0, t, 1.0], e)),
    ]
}

/// The velocity of the image curve Φ(η + tη̇) at t = 0.
fn push(phi: &dyn Fn([f64; 3]) -> [f64; 3], eta: [f64; 3], etad: [f64; 3]) -> [f64; 3] {
    let h = 1e-6;
    let a = phi(std::array::from_fn(|k| eta[k] + h * etad[k]));
    let b = phi(std::array::from_fn(|k| eta[k] - h * etad[k]));
    std::array::from_fn(|k| if k == 2 { wrap(a[k] - b[k]) } else { a[k] - b[k] } / (2.0 * h))
}

fn check_isometries(top: &TangentTop, flows: &[Flow], z0: &[f64], t_map: f64) {
    let name = top.surface().name();
    let eta0 = config(z0);
    let v0 = top.velocities(z0).unwrap();
    assert_eq!(flows.len(), top.surface().killing_count());
    let reference = integrate(top, "gauss6", z0, 0.01, 300, 30).unwrap();
    for (k, flow) in flows.iter().enumerate() {
        // the generator on (x, θ) is d/dt Φ_t at t = 0
        let x = [eta0[0], eta0[1]];
        let gen = push(&|t3: [f64; 3]| flow(t3[0], eta0), [0.0; 3], [1.0, 0.0, 0.0]);
        let kil = top.surface().killing(k, x);
        assert!(
            dist(&gen, &kil) < 1e-8,
            "{name} generator {k}: {gen:?} vs {kil:?}"
        );
        // Φ preserves the Lagrangian (so the lift of θ is right, 002 (74)–(77))
        let phi = |e: [f64; 3]| flow(t_map, e);
        for etad in [[0.3, -0.2, 0.9], [-0.5, 0.1, -0.4]] {
            let (e1, d1) = (phi(eta0), push(&phi, eta0, etad));
            let (l0, l1) = (
                top.lagrangian(eta0, etad).unwrap(),
                top.lagrangian(e1, d1).unwrap(),
            );
            assert!((l0 - l1).abs() < 1e-8, "{name} Φ_{k}: L {l0} vs {l1}");
        }
        // Φ maps the trajectory to the trajectory of the image state
        let (e1, d1) = (phi(eta0), push(&phi, eta0, v0));
        let z1 = top
            .state([e1[0], e1[1]], e1[2], [d1[0], d1[1]], d1[2])
            .unwrap();
        let image = integrate(top, "gauss6", &z1, 0.01, 300, 30).unwrap();
        let mut worst: f64 = 0.0;
        for s in 0..reference.len() {
            worst = worst.max(config_dist(
                &phi(config(reference.state(s))),
                image.state(s),
            ));
        }
        eprintln!("{name}: isometry {k} maps the trajectory to a trajectory within {worst:.1e}");
        assert!(worst < 1e-8, "{name} Φ_{k}: {worst}");
    }
}

#[test]
fn isometries_map_trajectories_to_trajectories() {
    let plane = TangentTop::new(Arc::new(Plane), 1.2, 0.5).unwrap();
    let z = plane.state([0.3, -0.4], 0.2, [0.4, 0.1], -0.6).unwrap();
    check_isometries(&plane, &plane_flows(), &z, 0.7);
    let sphere = TangentTop::new(Arc::new(Sphere::new(1.0).unwrap()), 1.0, 0.6).unwrap();
    let z = sphere.state([1.3, 0.4], 0.5, [0.3, -0.4], 1.1).unwrap();
    check_isometries(&sphere, &sphere_flows(), &z, 0.5);
    let h2 = TangentTop::new(Arc::new(HyperbolicPlane), 1.0, 1.0).unwrap();
    let z = h2.state([0.2, 1.1], 0.3, [0.2, -0.3], 0.9).unwrap();
    check_isometries(&h2, &hyperbolic_flows(), &z, 0.4);
}

fn bounded_sphere() -> (TangentTop, Vec<f64>) {
    // a strong spin (charge p_θ) keeps the centre on small loops away from the poles
    let top = TangentTop::new(Arc::new(Sphere::new(1.0).unwrap()), 1.0, 0.6).unwrap();
    let z = top.state([1.5, 0.2], 0.3, [0.3, 0.2], 1.5).unwrap();
    (top, z)
}

fn bounded_h2() -> (TangentTop, Vec<f64>) {
    // magnetic field p_θ·dα/dA = p_θ against the speed: circles of geodesic curvature > 1
    let top = TangentTop::new(Arc::new(HyperbolicPlane), 1.0, 1.0).unwrap();
    let z = top.state([0.2, 1.0], 0.3, [0.3, 0.2], 1.0).unwrap();
    (top, z)
}

#[test]
fn momenta_are_conserved() {
    for (top, z0) in [bounded_sphere(), bounded_h2()] {
        let name = top.surface().name();
        let j0 = top.killing_momenta(&z0).unwrap();
        let i0 = top.invariants(&z0).unwrap();
        assert_eq!(i0.len(), top.invariant_count());
        for method in ["midpoint", "gauss4", "gauss6", "rk4"] {
            let traj = integrate(&top, method, &z0, 0.01, 2000, 10).unwrap();
            let (mut dj, mut di, mut dpt): (f64, f64, f64) = (0.0, 0.0, 0.0);
            for k in 0..traj.len() {
                let z = traj.state(k);
                dj = dj.max(dist(&top.killing_momenta(z).unwrap(), &j0));
                di = di.max(dist(&top.invariants(z).unwrap(), &i0));
                dpt = dpt.max((z[5] - z0[5]).abs());
            }
            eprintln!(
                "{name} {method}: Killing momenta drift {dj:.1e}, claimed invariants {di:.1e}, p_θ {dpt:.1e}"
            );
            let tol = match method {
                "midpoint" => 1e-4,
                "gauss4" | "rk4" => 1e-8,
                _ => 1e-10,
            };
            assert!(dj < tol, "{name} {method}: J drift {dj}");
            if method != "rk4" {
                assert!(di < 1e-12, "{name} {method}: invariants drift {di}");
            }
            assert!(dpt < 1e-13, "{name} {method}: p_θ drift {dpt}");
        }
    }
}

#[test]
fn observed_orders() {
    for (top, z0) in [bounded_sphere(), bounded_h2()] {
        let name = top.surface().name();
        let t_end = 2.0;
        let run = |method: &str, dt: f64| {
            let steps = (t_end / dt).round() as usize;
            integrate(&top, method, &z0, dt, steps, steps)
                .unwrap()
                .final_state
        };
        let reference = run("gauss6", 0.005);
        for (method, dt, order) in [
            ("midpoint", 0.02, 2.0),
            ("gauss4", 0.1, 4.0),
            ("gauss6", 0.2, 6.0),
            ("rk4", 0.05, 4.0),
        ] {
            let e1 = dist(&run(method, dt), &reference);
            let e2 = dist(&run(method, dt / 2.0), &reference);
            let p = (e1 / e2).log2();
            eprintln!(
                "{name} {method}: errors {e1:.2e}, {e2:.2e} (dt = {dt}, {}): order {p:.2}",
                dt / 2.0
            );
            assert!((p - order).abs() < 0.2, "{name} {method}: order {p}");
        }
    }
}

#[test]
fn energy_bounded_over_long_runs() {
    for (top, z0) in [bounded_sphere(), bounded_h2()] {
        let name = top.surface().name();
        let h0 = top.energy(&z0).unwrap();
        for method in ["midpoint", "gauss4"] {
            let traj = integrate(&top, method, &z0, 0.05, 100_000, 100).unwrap();
            let (mut first, mut last): (f64, f64) = (0.0, 0.0);
            let n = traj.len();
            for k in 0..n {
                let e = ((top.energy(traj.state(k)).unwrap() - h0) / h0).abs();
                if k < n / 10 {
                    first = first.max(e);
                } else if k >= n - n / 10 {
                    last = last.max(e);
                }
            }
            eprintln!(
                "{name} {method}: 10⁵ steps of 0.05, relative energy error {first:.2e} (first tenth), {last:.2e} (last tenth)"
            );
            assert!(
                last < 2.0 * first + 1e-13,
                "{name} {method}: energy drift {first} → {last}"
            );
            assert!(last < if method == "midpoint" { 1e-2 } else { 1e-5 });
        }
    }
}

// ---------------------------------------------------------------------------------------------
// holonomy

/// ∮ w along the chart ellipse x(t) = c + (a cos t, b sin t) (trapezoid rule, spectrally accurate
/// for a periodic integrand), and ∫∫ K dA over its inside (Gauss–Legendre in the radius).
fn loop_and_area(s: &dyn Surface, c: Vec2, a: f64, b: f64) -> (f64, f64) {
    let n = 400;
    let mut w = 0.0;
    for i in 0..n {
        let t = 2.0 * PI * i as f64 / n as f64;
        let x = [c[0] + a * t.cos(), c[1] + b * t.sin()];
        let v = [-a * t.sin(), b * t.cos()];
        let al = s.connection(x);
        w += (al[0] * v[0] + al[1] * v[1]) * 2.0 * PI / n as f64;
    }
    // 20-point Gauss–Legendre on r ∈ (0, 1) from the 10-point rule on two halves
    let (nodes, weights) = gauss_legendre_10();
    let mut area = 0.0;
    for half in 0..2 {
        for (xi, wi) in nodes.iter().zip(&weights) {
            let r = 0.25 * (xi + 1.0) + 0.5 * half as f64;
            for i in 0..n {
                let t = 2.0 * PI * i as f64 / n as f64;
                let x = [c[0] + a * r * t.cos(), c[1] + b * r * t.sin()];
                let da = lieflow::systems::tangent_top::surface::det(&s.metric(x)).sqrt();
                area += 0.25 * wi * s.curvature(x) * da * a * b * r * 2.0 * PI / n as f64;
            }
        }
    }
    (w, area)
}

fn gauss_legendre_10() -> ([f64; 10], [f64; 10]) {
    let x = [
        0.148_874_338_981_631_2,
        0.433_395_394_129_247_2,
        0.679_409_568_299_024_4,
        0.865_063_366_688_984_5,
        0.973_906_528_517_171_7,
    ];
    let w = [
        0.295_524_224_714_752_9,
        0.269_266_719_309_996_4,
        0.219_086_362_515_982,
        0.149_451_349_150_580_6,
        0.066_671_344_308_688_1,
    ];
    let mut n = [0.0; 10];
    let mut v = [0.0; 10];
    for i in 0..5 {
        n[i] = -x[i];
        n[9 - i] = x[i];
        v[i] = w[i];
        v[9 - i] = w[i];
    }
    (n, v)
}

#[test]
fn holonomy_is_the_enclosed_curvature() {
    // A frame parallel along a loop, V = cos β Ê₁ + sin β Ê₂, has β̇ = −w(ẋ): after one turn the
    // reference frame has rotated by ∮ w relative to it, and ∮ w = −∫∫K dA (dw = −K dA, Stokes):
    // the parallel transport turns by ∫∫K dA (Gauss–Bonnet).
    let cases: Vec<(Arc<dyn Surface>, Vec2, f64, f64)> = vec![
        (Arc::new(Sphere::new(1.0).unwrap()), [1.2, 0.3], 0.5, 0.8),
        (Arc::new(Sphere::new(2.0).unwrap()), [1.0, 0.0], 0.3, 0.4),
        (Arc::new(HyperbolicPlane), [0.5, 1.5], 0.6, 0.9),
        (
            Arc::new(Revolution::torus(2.0, 0.7).unwrap()),
            [0.5, 0.0],
            1.5,
            1.0,
        ),
    ];
    for (s, c, a, b) in cases {
        let (w, area) = loop_and_area(&*s, c, a, b);
        eprintln!("{}: ∮w = {w:.12}, ∫∫K dA = {area:.12}", s.name());
        assert!((w + area).abs() < 1e-10, "{}: {w} vs {area}", s.name());
        assert!(area.abs() > 0.05);
    }
    // the latitude ϑ₀ of the unit sphere: ∮ w = 2π cos ϑ₀ = 2π − ∫∫_cap K dA, the 2π being the
    // turn of the reference frame (singular at the pole) around the cap: equal modulo 2π.
    let th0: f64 = 0.9;
    let s = Sphere::new(1.0).unwrap();
    let n = 64;
    let w: f64 = (0..n)
        .map(|i| s.connection([th0, 2.0 * PI * i as f64 / n as f64])[1] * 2.0 * PI / n as f64)
        .sum();
    let cap = 2.0 * PI * (1.0 - th0.cos());
    assert!((w - (2.0 * PI - cap)).abs() < 1e-12);
}

// ---------------------------------------------------------------------------------------------
// embedded tops (002 §II.D)

/// Point masses (m, ξ) of a planar body.
type Points = Vec<(f64, [f64; 2])>;

/// A rigid planar body of point masses with ∑ m ξ = 0: (total mass, Euler tensor ∑ m ξξᵀ,
/// [(m, ξ)]).
fn point_body() -> (f64, [f64; 4], Points) {
    let raw = [
        (0.5, [0.3, 0.1]),
        (0.7, [-0.2, 0.25]),
        (0.4, [0.05, -0.4]),
        (0.6, [0.2, 0.1]),
    ];
    let m: f64 = raw.iter().map(|p| p.0).sum();
    let c: [f64; 2] = std::array::from_fn(|k| raw.iter().map(|p| p.0 * p.1[k]).sum::<f64>() / m);
    let pts: Points = raw
        .iter()
        .map(|&(w, xi)| (w, [xi[0] - c[0], xi[1] - c[1]]))
        .collect();
    let t = |i: usize, j: usize| pts.iter().map(|p| p.0 * p.1[i] * p.1[j]).sum::<f64>();
    (m, [t(0, 0), t(0, 1), t(1, 0), t(1, 1)], pts)
}

#[test]
fn embedded_lagrangian_is_the_ambient_kinetic_energy() {
    // 002 (32): L = ½ ∑ m |d/dt (c + ξ^a E_a)|² in ℝ³, by central differences in time.
    let (m, tensor, pts) = point_body();
    for (s, points) in embedded_surfaces() {
        let top = TangentTop::with_tensor(s.clone(), m, tensor)
            .unwrap()
            .embedded()
            .unwrap();
        for x in points {
            let eta = [x[0], x[1], 0.7];
            let etad = [0.3, -0.5, 0.9];
            let h = 1e-5;
            let body = |t: f64| {
                let e: Vec<f64> = (0..3).map(|k| eta[k] + t * etad[k]).collect();
                let z = [e[0], e[1], e[2], 0.0, 0.0, 0.0];
                let [c, e1, e2] = top.ambient_frame(&z).unwrap().unwrap();
                pts.iter()
                    .map(|(_, xi)| {
                        std::array::from_fn::<f64, 3, _>(|k| c[k] + xi[0] * e1[k] + xi[1] * e2[k])
                    })
                    .collect::<Vec<_>>()
            };
            let (a, b) = (body(h), body(-h));
            let ke: f64 = pts
                .iter()
                .enumerate()
                .map(|(i, (w, _))| {
                    let v: [f64; 3] = std::array::from_fn(|k| (a[i][k] - b[i][k]) / (2.0 * h));
                    0.5 * w * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
                })
                .sum();
            let l = top.lagrangian(eta, etad).unwrap();
            assert!(
                (l - ke).abs() < 1e-8 * (1.0 + ke),
                "{}: L = {l} vs ambient {ke} at {x:?}",
                s.name()
            );
            // without the embedding the normal part is missing (on curved surfaces)
            let intrinsic = TangentTop::with_tensor(s.clone(), m, tensor).unwrap();
            let l0 = intrinsic.lagrangian(eta, etad).unwrap();
            if s.name() != "Plane" {
                assert!(
                    (l0 - ke).abs() > 1e-4,
                    "{}: the term is not negligible",
                    s.name()
                );
            }
        }
    }
}

#[test]
fn symmetric_embedded_top_is_002_39() {
    // I = I₀ Id: the extra term is I₀ g^{αβ} h_αμ h_βν ẋ^μ ẋ^ν / 2, independent of θ.
    let (m, i0) = (1.3, 0.35);
    for (s, points) in embedded_surfaces() {
        let top = TangentTop::new(s.clone(), m, 2.0 * i0)
            .unwrap()
            .embedded()
            .unwrap();
        assert!(top.is_symmetric());
        let emb = s.embedding().unwrap();
        for x in points {
            let (g, h) = (s.metric(x), emb.second_fundamental_form(x));
            let gi = inverse(&g);
            for th in [0.0, 1.1] {
                let ga = top.metric([x[0], x[1], th]).unwrap();
                let a = s.connection(x);
                for mu in 0..2 {
                    for nu in 0..2 {
                        let mut third = 0.0;
                        for al in 0..2 {
                            for be in 0..2 {
                                third += gi[al][be] * h[al][mu] * h[be][nu];
                            }
                        }
                        let want = m * g[mu][nu] + i0 * third + 2.0 * i0 * a[mu] * a[nu];
                        assert!((ga[mu][nu] - want).abs() < 1e-12, "{} (39)", s.name());
                    }
                }
            }
        }
    }
}

#[test]
fn hamiltonian_gradient_by_differences() {
    use lieflow::integrate::problem::Canonical;
    let (m, tensor, _) = point_body();
    let mut tops = vec![TangentTop::new(Arc::new(HyperbolicPlane), 1.2, 0.5).unwrap()];
    for (s, _) in embedded_surfaces() {
        tops.push(
            TangentTop::with_tensor(s, m, tensor)
                .unwrap()
                .embedded()
                .unwrap(),
        );
    }
    for top in tops {
        let z = top.state([0.4, 0.9], 0.6, [1.0, -0.8], 0.8).unwrap();
        let (mut hq, mut hp) = ([0.0; 3], [0.0; 3]);
        top.gradient(&z[..3], &z[3..], &mut hq, &mut hp);
        let h = 1e-6;
        for k in 0..6 {
            let (mut a, mut b) = (z.clone(), z.clone());
            a[k] += h;
            b[k] -= h;
            let num = (top.energy(&a).unwrap() - top.energy(&b).unwrap()) / (2.0 * h);
            let got = if k < 3 { hq[k] } else { hp[k - 3] };
            assert!(
                (num - got).abs() < 1e-8,
                "{} ∂H/∂z[{k}] = {got} vs {num}",
                top.surface().name()
            );
        }
        if top.is_embedded() && top.surface().name() != "Plane" {
            assert!(
                hq[2].abs() > 1e-5,
                "an anisotropic embedded top feels θ: {} ∂H/∂θ = {}",
                top.surface().name(),
                hq[2]
            );
        }
    }
}

#[test]
fn embedded_sphere_top_is_the_euler_top() {
    // The body frame (n, E₁, E₂) of a top on the sphere of radius R turns about the centre: a
    // free rigid body with moments (𝕀, mR² + I₂₂, mR² + I₁₁) for a diagonal Euler tensor.
    let (r, m, i11, i22) = (1.4, 0.9, 0.5, 0.2);
    let sphere: Arc<dyn Surface> = Arc::new(Sphere::new(r).unwrap());
    let top = TangentTop::with_tensor(sphere.clone(), m, [i11, 0.0, 0.0, i22])
        .unwrap()
        .embedded()
        .unwrap();
    let inertia = i11 + i22;
    let z0 = top.state([1.1, 0.3], 0.4, [0.5, -0.3], 0.8).unwrap();
    let [c, e1, e2] = top.ambient_frame(&z0).unwrap().unwrap();
    let v = top.velocities(&z0).unwrap();
    let cdot = sphere
        .embedding()
        .unwrap()
        .tangent([z0[0], z0[1]], [v[0], v[1]]);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let a = sphere.connection([z0[0], z0[1]]);
    let spin = v[2] + a[0] * v[0] + a[1] * v[1];
    let omega = [spin, -dot(cdot, e2) / r, dot(cdot, e1) / r];
    let moments = [inertia, m * r * r + i22, m * r * r + i11];
    let mm: [f64; 3] = std::array::from_fn(|k| moments[k] * omega[k]);
    let frame = |z: &[f64]| {
        let [c, e1, e2] = top.ambient_frame(z).unwrap().unwrap();
        Matrix3::from_columns(&[Vector3::from(c) / r, Vector3::from(e1), Vector3::from(e2)])
    };
    let _ = c;
    let q0 = frame(&z0);
    let body = RigidBody::new(moments).unwrap().with_attitude();
    let rows: Vec<f64> = (0..9).map(|k| q0[(k / 3, k % 3)]).collect();
    let w0 = body.state_with_attitude(mm, rows.try_into().unwrap());
    assert!((body.energy(&w0).unwrap() - top.energy(&z0).unwrap()).abs() < 1e-13);
    let jm = RigidBody::spatial_momentum(&w0).unwrap();
    assert!(dist(&top.killing_momenta(&z0).unwrap(), &jm) < 1e-13);
    let (t_end, dt) = (6.0, 0.005);
    let steps = (t_end / dt) as usize;
    let ta = integrate(&top, "gauss6", &z0, dt, steps, 100).unwrap();
    let tb = integrate(&body, "splitting6", &w0, dt, steps, 100).unwrap();
    let (mut worst, mut pt_range): (f64, f64) = (0.0, 0.0);
    for k in 0..ta.len() {
        let rb = Matrix3::from_row_slice(&tb.state(k)[3..12]);
        worst = worst.max((frame(ta.state(k)) - rb).norm());
        pt_range = pt_range.max((ta.state(k)[5] - z0[5]).abs());
    }
    eprintln!(
        "embedded sphere vs RigidBody: max ‖Q − R‖ = {worst:.2e}; p_θ varies by {pt_range:.2e}"
    );
    assert!(worst < 1e-9);
    // the anisotropic body's spin p_θ is not conserved (and not claimed as an invariant)
    assert!(pt_range > 1e-3);
    assert_eq!(top.invariant_count(), 1);
    // a tensor turned by β at angle θ is the diagonal one at θ + β
    let beta: f64 = 0.6;
    let (sb, cb) = beta.sin_cos();
    let rot = [
        cb * cb * i11 + sb * sb * i22,
        cb * sb * (i11 - i22),
        cb * sb * (i11 - i22),
        sb * sb * i11 + cb * cb * i22,
    ];
    let turned = TangentTop::with_tensor(sphere, m, rot)
        .unwrap()
        .embedded()
        .unwrap();
    let zt = turned
        .state([1.1, 0.3], 0.4 - beta, [0.5, -0.3], 0.8)
        .unwrap();
    assert!((turned.energy(&zt).unwrap() - top.energy(&z0).unwrap()).abs() < 1e-13);
    let tt = integrate(&turned, "gauss6", &zt, dt, 400, 100).unwrap();
    for k in 0..tt.len() {
        let (p, q) = (ta.state(k), tt.state(k));
        assert!(config_dist(p, &[q[0], q[1], q[2] + beta]) < 1e-10);
    }
}

/// {F, G} = ∑ ∂F/∂q_i ∂G/∂p_i − ∂F/∂p_i ∂G/∂q_i by central differences.
fn poisson_bracket(f: &dyn Fn(&[f64]) -> f64, g: &dyn Fn(&[f64]) -> f64, z: &[f64]) -> f64 {
    let h = 1e-5;
    let grad = |fun: &dyn Fn(&[f64]) -> f64| -> Vec<f64> {
        (0..6)
            .map(|k| {
                let (mut a, mut b) = (z.to_vec(), z.to_vec());
                a[k] += h;
                b[k] -= h;
                (fun(&a) - fun(&b)) / (2.0 * h)
            })
            .collect()
    };
    let (df, dg) = (grad(f), grad(g));
    (0..3).map(|i| df[i] * dg[3 + i] - df[3 + i] * dg[i]).sum()
}

#[test]
fn integrals_are_in_involution() {
    // A Killing field ⇒ H, p_θ and its momentum J pairwise commute (002 §III.A).
    let torus = TangentTop::new(Arc::new(Revolution::torus(2.0, 0.7).unwrap()), 1.0, 0.6).unwrap();
    let sphere = TangentTop::new(Arc::new(Sphere::new(1.2).unwrap()), 1.0, 0.6).unwrap();
    for (top, k) in [(&torus, 0), (&sphere, 2)] {
        let z = top.state([0.9, 0.4], 0.3, [0.4, -0.3], 0.7).unwrap();
        let h = |z: &[f64]| top.energy(z).unwrap();
        let pt = |z: &[f64]| z[5];
        let j = |z: &[f64]| top.killing_momenta(z).unwrap()[k];
        for (name, b) in [
            ("{H, p_θ}", poisson_bracket(&h, &pt, &z)),
            ("{H, J}", poisson_bracket(&h, &j, &z)),
            ("{p_θ, J}", poisson_bracket(&pt, &j, &z)),
        ] {
            assert!(b.abs() < 1e-9, "{} {name} = {b}", top.surface().name());
        }
    }
    // the bracket is not blind: on the sphere {J_x, J_y} = J_z ≠ 0
    let z = sphere.state([0.9, 0.4], 0.3, [0.4, -0.3], 0.7).unwrap();
    let jx = |z: &[f64]| sphere.killing_momenta(z).unwrap()[0];
    let jy = |z: &[f64]| sphere.killing_momenta(z).unwrap()[1];
    let jz = sphere.killing_momenta(&z).unwrap()[2];
    let b = poisson_bracket(&jx, &jy, &z);
    assert!(
        jz.abs() > 0.05 && (b - jz).abs() < 1e-8,
        "{{J_x, J_y}} = {b}, J_z = {jz}"
    );
}

#[test]
fn magnetic_analogue_reproduces_the_centre() {
    // 002 §III.B by Routh reduction: (x¹, x²)(t) of the top is the charged particle's path.
    let tops = [
        bounded_sphere(),
        bounded_h2(),
        {
            let t =
                TangentTop::new(Arc::new(Revolution::torus(2.0, 0.7).unwrap()), 1.0, 0.6).unwrap();
            let z = t.state([0.9, 0.4], 0.3, [0.4, -0.3], 0.7).unwrap();
            (t, z)
        },
        {
            let t = TangentTop::new(Arc::new(Sphere::new(1.2).unwrap()), 1.0, 0.6)
                .unwrap()
                .embedded()
                .unwrap();
            let z = t.state([1.2, 0.4], 0.3, [0.4, -0.3], 0.7).unwrap();
            (t, z)
        },
    ];
    for (top, z0) in tops {
        let name = top.surface().name();
        let particle = top.magnetic_analogue(z0[5]).unwrap();
        let v = top.velocities(&z0).unwrap();
        let w0 = particle.state([z0[0], z0[1]], [v[0], v[1]]).unwrap();
        // same momenta p_x, same energy up to the spin energy, same Killing momenta
        assert!(dist(&w0[2..], &z0[3..5]) < 1e-13, "{name}");
        let spin = z0[5] * z0[5] / (2.0 * top.inertia());
        assert!((particle.energy(&w0).unwrap() + spin - top.energy(&z0).unwrap()).abs() < 1e-13);
        assert!(
            dist(
                &particle.killing_momenta(&w0).unwrap(),
                &top.killing_momenta(&z0).unwrap()
            ) < 1e-13
        );
        assert_eq!(
            particle.invariants(&w0).unwrap().len(),
            particle.invariant_count()
        );
        let a = integrate(&top, "gauss6", &z0, 0.01, 500, 50).unwrap();
        let b = integrate(&particle, "gauss6", &w0, 0.01, 500, 50).unwrap();
        let mut worst: f64 = 0.0;
        for k in 0..a.len() {
            worst = worst.max(dist(&a.state(k)[..2], &b.state(k)[..2]));
        }
        eprintln!("{name}: top centre vs charged particle {worst:.1e}");
        assert!(worst < 1e-10, "{name}: {worst}");
        // the analogue with the wrong charge does not reproduce it
        let wrong = top.magnetic_analogue(0.5 * z0[5]).unwrap();
        let w1 = wrong.state([z0[0], z0[1]], [v[0], v[1]]).unwrap();
        let c = integrate(&wrong, "gauss6", &w1, 0.01, 500, 50).unwrap();
        let last = c.len() - 1;
        assert!(dist(&a.state(last)[..2], &c.state(last)[..2]) > 1e-3);
    }
    // an anisotropic embedded top has none
    let (m, tensor, _) = point_body();
    let top = TangentTop::with_tensor(Arc::new(Sphere::new(1.0).unwrap()), m, tensor)
        .unwrap()
        .embedded()
        .unwrap();
    assert!(top.magnetic_analogue(1.0).is_err());
}

// ---------------------------------------------------------------------------------------------
// errors

#[test]
fn bad_input_is_rejected() {
    assert!(TangentTop::new(Arc::new(Plane), 0.0, 1.0).is_err());
    assert!(TangentTop::new(Arc::new(Plane), 1.0, f64::NAN).is_err());
    assert!(TangentTop::with_tensor(Arc::new(Plane), 1.0, [1.0, 2.0, 2.0, 1.0]).is_err());
    assert!(TangentTop::with_tensor(Arc::new(Plane), 1.0, [0.0; 4]).is_err());
    let h2_top = TangentTop::new(Arc::new(HyperbolicPlane), 1.0, 1.0).unwrap();
    assert!(h2_top.embedded().is_err(), "H² has no embedding in ℝ³");
    assert!(Sphere::new(-1.0).is_err());
    assert!(Revolution::torus(1.0, 2.0).is_err());
    let h2 = TangentTop::new(Arc::new(HyperbolicPlane), 1.0, 1.0).unwrap();
    assert!(h2.state([0.0, -1.0], 0.0, [0.0, 0.0], 0.0).is_err());
    assert!(h2.state([0.0, 1.0], f64::NAN, [0.0, 0.0], 0.0).is_err());
    assert!(integrate(&h2, "gauss4", &[0.0, -1.0, 0.0, 0.0, 0.0, 0.0], 0.1, 10, 1).is_err());
    assert!(h2.energy(&[0.0, 1.0, 0.0]).is_err());
    let sp = TangentTop::new(Arc::new(Sphere::new(1.0).unwrap()), 1.0, 1.0).unwrap();
    assert!(sp.state([0.0, 0.0], 0.0, [0.0, 0.0], 0.0).is_err());
    // a top shot into the boundary y = 0 of H² with a huge step: an error, not a panic
    let z = h2.state([0.0, 0.05], 0.0, [0.0, -2.0], 0.0).unwrap();
    let r = integrate(&h2, "midpoint", &z, 5.0, 100, 1);
    assert!(r.is_err());
    let r = integrate(&h2, "rk4", &z, 5.0, 100, 1);
    assert!(r.is_err());
}
