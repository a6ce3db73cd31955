//! Pseudo-rigid body geometry on GL⁺(n) (001 §2–§6): each test checks an identity of the source
//! by an independent route (a second formula, a dense solve, finite differences).

mod common;

use common::{dist, gl_plus, rotation};
use faer::linalg::solvers::Solve;
use lieflow::lie::{gl, so, so3};
use lieflow::pseudo_rigid::{
    connection as cn, momentum as mo, riemann, strata, Action, BiInertia, Body,
};
use lieflow::{Error, Mat};
use nalgebra::Vector3;
use proptest::prelude::*;

fn skew(n: usize, v: &[f64]) -> Mat {
    so::hat_n_unchecked(n, &v[..so::dim(n)])
}

fn diag(a: &[f64]) -> Mat {
    Mat::from_fn(a.len(), a.len(), |i, j| if i == j { a[i] } else { 0.0 })
}

fn conj(g: &Mat, xi: &Mat) -> Mat {
    g * xi * g.transpose()
}

fn tr_inner(y: &Mat, z: &Mat) -> f64 {
    2.0 * so::pairing(y, z)
}

fn stack(xi: &Mat, eta: &Mat) -> Vec<f64> {
    let mut c = so::vee_n_unchecked(xi);
    c.extend(so::vee_n_unchecked(eta));
    c
}

fn col(c: &[f64]) -> Mat {
    Mat::from_fn(c.len(), 1, |i, _| c[i])
}

/// A random scenario: n, X ∈ GL⁺(n) (well away from singular), g, h ∈ SO(n), ξ, η ∈ so(n),
/// a tangent vector Y.
#[derive(Debug)]
struct Case {
    n: usize,
    x: Mat,
    g: Mat,
    h: Mat,
    xi: Mat,
    eta: Mat,
    y: Mat,
}

fn case() -> impl Strategy<Value = Case> {
    (2usize..=6, prop::collection::vec(-1.0f64..1.0, 36 * 5)).prop_map(|(n, v)| {
        let chunk = |k: usize| &v[36 * k..36 * (k + 1)];
        Case {
            n,
            x: gl_plus(n, chunk(0)),
            g: rotation(n, chunk(1)),
            h: rotation(n, chunk(2)),
            xi: skew(n, chunk(3)),
            eta: skew(n, &chunk(3)[15..]),
            y: Mat::from_fn(n, n, |i, j| chunk(4)[i * n + j]),
        }
    })
}

/// Relative gap of the singular values and their smallest value, for prop_assume!.
fn well_posed(x: &Mat) -> bool {
    let c = gl::svd_coordinates(x).unwrap();
    c.min_gap() > 1e-3 * c.a[0] && c.a[c.a.len() - 1] > 1e-2
}

fn close(a: &Mat, b: &Mat, scale: f64) -> bool {
    dist(a, b) <= 1e-9 * scale.max(1.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// B_X symmetric (6.12), positive definite on the principal stratum (6.14); its matrix has
    /// the blocks A^L, −2Ad_X, −2Adᵀ_X, A^R and equals the locked inertia tensors from the metric
    /// (2.27)–(2.28), (6.24)–(6.25).
    #[test]
    fn bi_inertia_symmetric_positive_and_locked(c in case()) {
        let b = BiInertia::new(&c.x).unwrap();
        let m = b.matrix();
        let s = m.norm_l2();
        prop_assert!((&m - m.transpose()).norm_l2() < 1e-12 * s);
        let d = so::dim(c.n);
        let block = |r: usize, k: usize| Mat::from_fn(d, d, |i, j| m[(r * d + i, k * d + j)]);
        prop_assert!(close(&block(0, 0), &b.left_matrix(), s));
        prop_assert!(close(&block(1, 1), &b.right_matrix(), s));
        prop_assert!(close(&block(0, 1), &(b.ad_x_matrix() * faer::Scale(-2.0)), s));
        prop_assert!(close(&block(1, 0), &(b.ad_x_t_matrix() * faer::Scale(-2.0)), s));
        prop_assert!(close(&m, &cn::locked_inertia(&b, Action::TwoSided).unwrap(), s));
        prop_assert!(close(&b.left_matrix(), &cn::locked_inertia(&b, Action::Left).unwrap(), s));
        prop_assert!(close(&b.right_matrix(), &cn::locked_inertia(&b, Action::Right).unwrap(), s));
        // Adᵀ_X is the transpose of Ad_X under the pairing (2.8).
        prop_assert!(close(&b.ad_x_matrix().transpose().to_owned(), &b.ad_x_t_matrix(), s));
        if well_posed(&c.x) {
            let ev = m.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
            prop_assert!(ev[0] > 0.0);
        }
    }

    /// (2.12), (2.13), (6.16), (6.11): equivariance of A^L, A^R, Ad_X, Adᵀ_X and B_X.
    #[test]
    fn inertia_equivariance(c in case()) {
        let (g, h, xi, eta) = (&c.g, &c.h, &c.xi, &c.eta);
        let b = BiInertia::new(&c.x).unwrap();
        let bg = BiInertia::new(&(g * &c.x)).unwrap();
        let bh = BiInertia::new(&(&c.x * h.transpose())).unwrap();
        let bgh = BiInertia::new(&(g * &c.x * h.transpose())).unwrap();
        let s = c.x.norm_l2().powi(2) * (1.0 + xi.norm_l2() + eta.norm_l2());
        let gi = g.transpose().to_owned();
        let hi = h.transpose().to_owned();
        // (2.12)
        prop_assert!(close(&bg.left(xi).unwrap(), &conj(g, &b.left(&conj(&gi, xi)).unwrap()), s));
        prop_assert!(close(&bh.left(xi).unwrap(), &b.left(xi).unwrap(), s));
        // (2.13)
        prop_assert!(close(&bg.right(xi).unwrap(), &b.right(xi).unwrap(), s));
        prop_assert!(close(&bh.right(xi).unwrap(), &conj(h, &b.right(&conj(&hi, xi)).unwrap()), s));
        // (6.16)
        prop_assert!(close(&bgh.ad_x(eta).unwrap(), &conj(g, &b.ad_x(&conj(&hi, eta)).unwrap()), s));
        prop_assert!(close(&bgh.ad_x_t(xi).unwrap(), &conj(h, &b.ad_x_t(&conj(&gi, xi)).unwrap()), s));
        // (6.11)
        let (p, q) = bgh.apply(xi, eta).unwrap();
        let (p0, q0) = b.apply(&conj(&gi, xi), &conj(&hi, eta)).unwrap();
        prop_assert!(close(&p, &conj(g, &p0), s) && close(&q, &conj(h, &q0), s));
    }

    /// (6.14) = ⟨ξ ⊕ η, B_X(ξ ⊕ η)⟩ = ‖ξX + Xηᵀ‖² (6.24).
    #[test]
    fn quadratic_form_three_routes(c in case()) {
        let b = BiInertia::new(&c.x).unwrap();
        let q = b.quadratic_form(&c.xi, &c.eta).unwrap();
        let (p, r) = b.apply(&c.xi, &c.eta).unwrap();
        let op = so::pairing(&c.xi, &p) + so::pairing(&c.eta, &r);
        let v = cn::vertical_vector(&b, &c.xi, &c.eta).unwrap();
        let metric = v.norm_l2().powi(2);
        let s = 1e-10 * (1.0 + metric);
        prop_assert!((q - op).abs() < s && (q - metric).abs() < s);
    }

    /// Closed-form inverse (7.6)–(7.9) = dense faer solve of the n(n−1) system; B(B⁻¹ v) = v;
    /// the least-squares inverse agrees on the principal stratum.
    #[test]
    fn closed_form_inverse_equals_dense_solve(c in case()) {
        prop_assume!(well_posed(&c.x));
        let b = BiInertia::new(&c.x).unwrap();
        let (lam, gam) = (&c.xi, &c.eta);
        let (xi, eta) = b.solve(lam, gam).unwrap();
        let dense = b.matrix().partial_piv_lu().solve(col(&stack(lam, gam)));
        let got = stack(&xi, &eta);
        let scale = got.iter().map(|v| v.abs()).fold(1.0, f64::max);
        for (k, v) in got.iter().enumerate() {
            prop_assert!((v - dense[(k, 0)]).abs() < 1e-8 * scale, "entry {}: {} vs {}", k, v, dense[(k, 0)]);
        }
        let (l2, g2) = b.apply(&xi, &eta).unwrap();
        prop_assert!(close(&l2, lam, 1.0) && close(&g2, gam, 1.0));
        let (xl, el) = b.solve_least_squares(lam, gam).unwrap();
        prop_assert!(close(&xl, &xi, scale) && close(&el, &eta, scale));
        // (A^L)⁻¹ and (A^R)⁻¹ (used by ω^L, ω^R).
        prop_assert!(close(&b.left(&b.left_solve(lam).unwrap()).unwrap(), lam, 1.0));
        prop_assert!(close(&b.right(&b.right_solve(gam).unwrap()).unwrap(), gam, 1.0));
    }

    /// Eigenpairs (8.14)–(8.15) transported by (6.11): B v = λ v, V orthonormal, eigenvalues
    /// equal to those of a dense symmetric eigensolver.
    #[test]
    fn eigenpairs(c in case()) {
        let b = BiInertia::new(&c.x).unwrap();
        let (vals, v) = b.eigen().unwrap();
        let m = b.matrix();
        let s = m.norm_l2();
        let bv = &m * &v;
        for k in 0..vals.len() {
            for i in 0..vals.len() {
                prop_assert!((bv[(i, k)] - vals[k] * v[(i, k)]).abs() < 1e-11 * s);
            }
        }
        let id = Mat::identity(vals.len(), vals.len());
        prop_assert!(dist(&(v.transpose() * &v), &id) < 1e-12);
        let dense = m.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        for (p, q) in vals.iter().zip(&dense) {
            prop_assert!((p - q).abs() < 1e-11 * s);
        }
    }

    /// (6.19) ω^B(ξX + Xηᵀ) = ξ ⊕ η; (6.23) ker ω^B = H_X; (2.16), (2.17); vertical ⟂ horizontal
    /// in tr(YᵀZ) for all three actions; (2.20), (2.21), (6.6) for the horizontal parts.
    #[test]
    fn connections_reproduce_and_split(c in case()) {
        let b = BiInertia::new(&c.x).unwrap();
        let x = &c.x;
        let s = 1.0 + c.xi.norm_l2() + c.eta.norm_l2();
        prop_assert!(close(&cn::left_connection(&b, &(&c.xi * x)).unwrap(), &c.xi, s));
        prop_assert!(close(&cn::right_connection(&b, &(x * c.eta.transpose())).unwrap(), &c.eta, s));
        let zero = Mat::zeros(c.n, c.n);
        for (action, xi, eta) in [(Action::Left, &c.xi, &zero), (Action::Right, &zero, &c.eta),
                                  (Action::TwoSided, &c.xi, &c.eta)] {
            let hp = cn::horizontal_part(&b, &c.y, action).unwrap();
            let vp = cn::vertical_part(&b, &c.y, action).unwrap();
            prop_assert!(close(&(&hp + &vp), &c.y, 1.0));
            let probe = cn::vertical_vector(&b, xi, eta).unwrap();
            let sc = x.norm_l2() * (1.0 + c.y.norm_l2()) * s;
            prop_assert!(tr_inner(&hp, &probe).abs() < 1e-9 * sc, "{:?}", action);
            prop_assert!(tr_inner(&hp, &vp).abs() < 1e-9 * sc, "{:?}", action);
            let (l, g) = mo::momentum_map(x, &hp).unwrap();
            let sc2 = x.norm_l2() * (1.0 + c.y.norm_l2());
            if action != Action::Right { prop_assert!(l.norm_l2() < 1e-9 * sc2, "(2.20) {:?}", action); }
            if action != Action::Left { prop_assert!(g.norm_l2() < 1e-9 * sc2, "(2.21) {:?}", action); }
        }
        if well_posed(x) {
            let v = cn::vertical_vector(&b, &c.xi, &c.eta).unwrap();
            let (p, q) = cn::bi_connection(&b, &v).unwrap();
            prop_assert!(close(&p, &c.xi, 1e3 * s) && close(&q, &c.eta, 1e3 * s), "(6.19)");
            let hp = cn::horizontal_part(&b, &c.y, Action::TwoSided).unwrap();
            let (p, q) = cn::bi_connection(&b, &hp).unwrap();
            prop_assert!(p.norm_l2() < 1e-6 && q.norm_l2() < 1e-6, "(6.23)");
        }
    }

    /// (2.16), (2.17), (6.20): equivariance of the connections; (2.31), (7.4) of L, Γ;
    /// (2.30) A^L(ω^L(Ẋ)) = L, A^R(ω^R(Ẋ)) = Γ.
    #[test]
    fn connection_equivariance_and_momenta(c in case()) {
        let (g, h, x, y) = (&c.g, &c.h, &c.x, &c.y);
        let b = BiInertia::new(x).unwrap();
        let ht = h.transpose().to_owned();
        let bg = BiInertia::new(&(g * x)).unwrap();
        let bh = BiInertia::new(&(x * &ht)).unwrap();
        let wl = cn::left_connection(&b, y).unwrap();
        let wr = cn::right_connection(&b, y).unwrap();
        let s = 1e2 * (1.0 + wl.norm_l2() + wr.norm_l2());
        prop_assert!(close(&cn::left_connection(&bg, &(g * y)).unwrap(), &conj(g, &wl), s));
        prop_assert!(close(&cn::right_connection(&bh, &(y * &ht)).unwrap(), &conj(h, &wr), s));
        let (l, gm) = mo::momentum_map(x, y).unwrap();
        prop_assert!(close(&b.left(&wl).unwrap(), &l, s) && close(&b.right(&wr).unwrap(), &gm, s));
        let (l2, g2) = mo::momentum_map(&(g * x * &ht), &(g * y * &ht)).unwrap();
        prop_assert!(close(&l2, &conj(g, &l), s) && close(&g2, &conj(h, &gm), s));
        prop_assert!(close(&mo::angular_momentum(x, y).unwrap(), &l, 1.0));
        prop_assert!(close(&mo::circulation(x, y).unwrap(), &gm, 1.0));
        if well_posed(x) {
            let bgh = BiInertia::new(&(g * x * &ht)).unwrap();
            let (p, q) = cn::bi_connection(&b, y).unwrap();
            let (p2, q2) = cn::bi_connection(&bgh, &(g * y * &ht)).unwrap();
            let s = 1e2 * (1.0 + p.norm_l2() + q.norm_l2());
            prop_assert!(close(&p2, &conj(g, &p), s) && close(&q2, &conj(h, &q), s), "(6.20)");
        }
    }

    /// Body coordinates: round trip, Ω = RᵀṘ and Λ = SᵀṠ by finite differences of the SVD,
    /// (2.32), (6.27), the kinetic-energy forms (3.2), (4.5), (4.12), (6.28), (6.30), (7.18), and
    /// E (4.8) = ∂K/∂A by finite differences.
    #[test]
    fn body_coordinates_and_kinetic_energy(c in case()) {
        prop_assume!(well_posed(&c.x));
        let (x, v) = (&c.x, &c.y);
        let body = mo::to_body(x, v).unwrap();
        let (x2, v2) = body.to_state().unwrap();
        prop_assert!(close(&x2, x, 1.0) && close(&v2, v, 1e3));
        // Finite differences of the SVD along X + tV (columns aligned with R).
        let t = 1e-6;
        let at = |s: f64| {
            let xt = x + v * faer::Scale(s);
            let mut ct = gl::svd_coordinates(&xt).unwrap();
            for k in 0..c.n {
                let dotk: f64 = (0..c.n).map(|i| ct.r[(i, k)] * body.r[(i, k)]).sum();
                if dotk < 0.0 {
                    for i in 0..c.n { ct.r[(i, k)] = -ct.r[(i, k)]; ct.s[(i, k)] = -ct.s[(i, k)]; }
                }
            }
            ct
        };
        let (cp, cm) = (at(t), at(-t));
        let rdot = (&cp.r - &cm.r) * faer::Scale(0.5 / t);
        let sdot = (&cp.s - &cm.s) * faer::Scale(0.5 / t);
        let fd_scale = 1e4 * (1.0 + body.omega.norm_l2() + body.lambda.norm_l2());
        prop_assert!(dist(&(body.r.transpose() * rdot), &body.omega) < 1e-6 * fd_scale);
        prop_assert!(dist(&(body.s.transpose() * sdot), &body.lambda) < 1e-6 * fd_scale);
        for k in 0..c.n {
            prop_assert!(((cp.a[k] - cm.a[k]) / (2.0 * t) - body.adot[k]).abs() < 1e-5 * fd_scale);
        }
        // (6.26): ω^B(Ẋ) = Ad_(R,S)(Ω ⊕ Λ) — the body velocities are the bi-connection.
        let b = BiInertia::new(x).unwrap();
        let (wx, wy) = cn::bi_connection(&b, v).unwrap();
        let sw = 1e3 * (1.0 + wx.norm_l2() + wy.norm_l2());
        prop_assert!(close(&wx, &conj(&body.r, &body.omega), sw));
        prop_assert!(close(&wy, &conj(&body.s, &body.lambda), sw));
        // (2.32), (6.27)
        let (po, pl) = body.momenta().unwrap();
        let (l, g) = mo::momentum_map(x, v).unwrap();
        let s = 1.0 + po.norm_l2() + pl.norm_l2();
        prop_assert!(close(&po, &(body.r.transpose() * &l * &body.r), s));
        prop_assert!(close(&pl, &(body.s.transpose() * &g * &body.s), s));
        // Kinetic energy in all its forms.
        let k = mo::kinetic_energy(x, v).unwrap();
        let tol = 1e-9 * (1.0 + k);
        prop_assert!((body.kinetic_energy().unwrap() - k).abs() < tol, "(4.5)");
        prop_assert!((body.kinetic_energy_momenta().unwrap() - k).abs() < tol, "(4.12)");
        prop_assert!((body.kinetic_energy_bi_inertia().unwrap() - k).abs() < tol, "(6.28)");
        let kh = mo::kinetic_energy_hamiltonian(&body.a, &body.adot, &po, &pl).unwrap();
        prop_assert!((kh - k).abs() < 1e-7 * (1.0 + k), "(6.30)");
        let hp = cn::horizontal_part(&b, v, Action::TwoSided).unwrap();
        let (xi, eta) = cn::bi_connection(&b, v).unwrap();
        let k718 = 0.5 * hp.norm_l2().powi(2) + 0.5 * b.quadratic_form(&xi, &eta).unwrap();
        prop_assert!((k718 - k).abs() < 1e-7 * (1.0 + k), "(7.18)");
        // E (4.8) = ∂K/∂a at fixed Ω, Ȧ, Λ.
        let e = body.e_term().unwrap();
        for (i, &ei) in e.iter().enumerate() {
            let shifted = |d: f64| {
                let mut bb = body.clone();
                bb.a[i] += d;
                bb.kinetic_energy().unwrap()
            };
            let h = 1e-5 * body.a[i];
            let fd = (shifted(h) - shifted(-h)) / (2.0 * h);
            prop_assert!((fd - ei).abs() < 1e-5 * (1.0 + ei.abs() + k), "E[{}] {} vs {}", i, ei, fd);
        }
    }

    /// n = 3 vector forms (5.3), (5.4), (5.6) against the matrix forms, with Ω = hat(ω).
    #[test]
    fn three_dimensional_vector_forms(a in prop::collection::vec(0.2f64..3.0, 3),
                                      w in prop::collection::vec(-2.0f64..2.0, 9)) {
        let av = Vector3::new(a[0], a[1], a[2]);
        let (om, la, ad) = (Vector3::new(w[0], w[1], w[2]), Vector3::new(w[3], w[4], w[5]),
                            Vector3::new(w[6], w[7], w[8]));
        let to_mat = |m: nalgebra::Matrix3<f64>| Mat::from_fn(3, 3, |i, j| m[(i, j)]);
        let body = Body { r: Mat::identity(3, 3), a: a.clone(), s: Mat::identity(3, 3),
                          omega: to_mat(so3::hat(&om)), adot: w[6..].to_vec(), lambda: to_mat(so3::hat(&la)) };
        let (m, cv) = mo::body_momenta_3(&av, &om, &la);
        let (po, pl) = body.momenta().unwrap();
        prop_assert!(dist(&to_mat(so3::hat(&m)), &po) < 1e-12 * (1.0 + po.norm_l2()));
        prop_assert!(dist(&to_mat(so3::hat(&cv)), &pl) < 1e-12 * (1.0 + pl.norm_l2()));
        let e3 = mo::e_term_3(&av, &om, &la);
        let e = body.e_term().unwrap();
        for i in 0..3 { prop_assert!((e3[i] - e[i]).abs() < 1e-12 * (1.0 + e[i].abs())); }
        let k3 = mo::kinetic_energy_3(&av, &ad, &om, &la);
        let k = body.kinetic_energy().unwrap();
        prop_assert!((k3 - k).abs() < 1e-12 * (1.0 + k));
    }

    /// dim V_X = rank of the vertical map agrees with the isotropy dimension for every
    /// multiplicity pattern, n = 2…6.
    #[test]
    fn strata_dimensions(n in 2usize..=6, v in prop::collection::vec(-1.0f64..1.0, 72),
                         split in prop::collection::vec(1usize..=3, 6)) {
        let mut a = Vec::new();
        let mut level = 3.0;
        for &m in &split {
            let m = m.min(n - a.len());
            if m == 0 { break; }
            a.extend(std::iter::repeat(level).take(m));
            level *= 0.6;
        }
        let x = rotation(n, &v) * diag(&a) * rotation(n, &v[36..]).transpose();
        let info = strata::classify(&x, gl::STRATUM_TOL).unwrap();
        let iso: usize = info.stratum.multiplicities.iter().map(|&m| m * (m - 1) / 2).sum();
        prop_assert_eq!(info.dim_vertical, n * (n - 1) - iso);
        prop_assert_eq!(info.dim_horizontal + info.dim_vertical, n * n);
        // A second route: the rank of B_X = L*L (its eigenvalues (a_i ∓ a_j)², 001 (8.15)) from
        // the symmetric eigen-decomposition of the dense matrix.
        let bmat = BiInertia::new(&x).unwrap().matrix();
        let eig = bmat.self_adjoint_eigen(faer::Side::Lower).unwrap();
        let top = (0..bmat.nrows()).map(|k| eig.S()[k]).fold(0.0f64, f64::max);
        let rank = (0..bmat.nrows()).filter(|&k| eig.S()[k] > 1e-9 * top).count();
        prop_assert_eq!(rank, info.dim_vertical);
    }

    /// (9.1) against the canonical bracket on T*GL⁺(n) for linear functions
    /// f = tr(F_Qᵀ Q) + tr(F_Nᵀ N), with ∂f/∂X = (F_Q + F_Qᵀ)X + F_N P, ∂f/∂P = F_Nᵀ X.
    #[test]
    fn riemann_poisson_brackets(c in case(), w in prop::collection::vec(-1.0f64..1.0, 4 * 36)) {
        let n = c.n;
        let (x, p) = (&c.x, &c.y);
        let m = |k: usize| Mat::from_fn(n, n, |i, j| w[36 * k + i * n + j]);
        let (fq, fnn, gq, gn) = (m(0), m(1), m(2), m(3));
        let (q, nm) = riemann::riemann_variables(x, p).unwrap();
        let got = riemann::poisson_bracket(&q, &nm, (&fq, &fnn), (&gq, &gn)).unwrap();
        let dx = |fq: &Mat, fnn: &Mat| (fq + fq.transpose()) * x + fnn * p;
        let dp = |fnn: &Mat| fnn.transpose() * x;
        let canon = tr_inner(&dx(&fq, &fnn), &dp(&gn)) - tr_inner(&dp(&fnn), &dx(&gq, &gn));
        prop_assert!((got - canon).abs() < 1e-10 * (1.0 + canon.abs()), "{} vs {}", got, canon);
        // (3.10): N = ½(−L + Q̇).
        let (qdot, l) = riemann::split_shear(&nm).unwrap();
        prop_assert!(close(&l, &mo::angular_momentum(x, p).unwrap(), 1.0));
        prop_assert!(close(&((qdot - l) * faer::Scale(0.5)), &nm, 1.0));
    }
}

/// (6.7): at a diagonal A with distinct entries the horizontal space is the diagonal matrices, so
/// the two-sided horizontal part of Y is diag(Y); the body coordinates give Ȧ = diag(Y) too.
#[test]
fn horizontal_space_at_a_is_diagonal() {
    let a = diag(&[3.0, 2.0, 1.5, 0.5]);
    let y = Mat::from_fn(4, 4, |i, j| ((3 * i + j) as f64).sin());
    let b = BiInertia::new(&a).unwrap();
    let hp = cn::horizontal_part(&b, &y, Action::TwoSided).unwrap();
    let dy = Mat::from_fn(4, 4, |i, j| if i == j { y[(i, i)] } else { 0.0 });
    assert!(dist(&hp, &dy) < 1e-13, "{hp:?}");
}

/// (9.2), (9.3) for n = 3 on each stratum.
#[test]
fn strata_of_three_dimensional_bodies() {
    let g = rotation(3, &[0.3, -0.2, 0.9, 0.1, 0.8, -0.4, 0.5, 0.2, 0.7]);
    let h = rotation(3, &[0.6, 0.1, -0.3, -0.2, 0.9, 0.4, 0.3, -0.5, 0.8]);
    for (a, dims, iso) in [
        ([3.0, 2.0, 1.0], (6, 3), "(Z2)^2"),
        ([2.0, 2.0, 1.0], (5, 4), "S(O(2)×O(1))"),
        ([2.0, 1.0, 1.0], (5, 4), "S(O(1)×O(2))"),
        ([1.5, 1.5, 1.5], (3, 6), "SO(3)"),
    ] {
        let x = &g * diag(&a) * h.transpose();
        let info = strata::classify(&x, gl::STRATUM_TOL).unwrap();
        assert_eq!((info.dim_vertical, info.dim_horizontal), dims, "{a:?}");
        assert_eq!(info.isotropy, iso);
    }
}

/// Off the principal stratum: the functions that need it fail with the gap; the others work,
/// including at X = I.
#[test]
fn degenerate_strata_and_identity() {
    let i3 = Mat::identity(3, 3);
    let b = BiInertia::new(&i3).unwrap();
    let xi = so::hat_n_unchecked(3, &[0.1, -0.4, 0.7]);
    let y = Mat::from_fn(3, 3, |i, j| (i + 2 * j) as f64 * 0.1 - 0.3);
    for r in [
        b.solve(&xi, &xi).map(|_| ()),
        cn::bi_connection(&b, &y).map(|_| ()),
        mo::to_body(&i3, &y).map(|_| ()),
    ] {
        assert!(
            matches!(r, Err(Error::DegenerateStratum { gap, .. }) if gap == 0.0),
            "{r:?}"
        );
    }
    // A^L_I ξ = 2ξ; ω^L(ξ) at I = ξ-part; B_I(ξ ⊕ ξ) = 0 (the isotropy direction).
    assert!(dist(&b.left(&xi).unwrap(), &(&xi * faer::Scale(2.0))) < 1e-15);
    let (p, q) = b.apply(&xi, &xi).unwrap();
    assert!(p.norm_l2() < 1e-15 && q.norm_l2() < 1e-15);
    assert!(dist(&cn::left_connection(&b, &(&xi * &i3)).unwrap(), &xi) < 1e-14);
    assert!(
        dist(
            &cn::right_connection(&b, &xi.transpose().to_owned()).unwrap(),
            &xi
        ) < 1e-14
    );
    assert!(mo::angular_momentum(&i3, &y).is_ok() && b.eigen().is_ok());
    // Two-sided split at a degenerate X = g diag(2, 1, 1) hᵀ: horizontal ⟂ every vertical vector.
    let g = rotation(3, &[0.3, -0.2, 0.9, 0.1, 0.8, -0.4, 0.5, 0.2, 0.7]);
    let x = &g * diag(&[2.0, 1.0, 1.0]) * g.transpose();
    let bx = BiInertia::new(&x).unwrap();
    let hp = cn::horizontal_part(&bx, &y, Action::TwoSided).unwrap();
    for k in 0..6 {
        let mut c = [0.0; 6];
        c[k] = 1.0;
        let v = cn::vertical_vector(
            &bx,
            &so::hat_n_unchecked(3, &c[..3]),
            &so::hat_n_unchecked(3, &c[3..]),
        )
        .unwrap();
        assert!(tr_inner(&hp, &v).abs() < 1e-12);
    }
    let (l, gm) = mo::momentum_map(&x, &hp).unwrap();
    assert!(l.norm_l2() < 1e-12 && gm.norm_l2() < 1e-12);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let mut neg = Mat::identity(3, 3);
    neg[(1, 1)] = -0.5;
    let e = BiInertia::new(&neg).unwrap_err();
    assert!(
        matches!(e, Error::NotInGroup { defect, .. } if (defect + 0.5).abs() < 1e-14),
        "{e:?}"
    );
    assert!(matches!(
        BiInertia::new(&Mat::zeros(2, 3)),
        Err(Error::Shape { .. })
    ));
    let mut nan = Mat::identity(2, 2);
    nan[(0, 1)] = f64::NAN;
    assert!(matches!(BiInertia::new(&nan), Err(Error::NonFinite { .. })));
    let b = BiInertia::new(&diag(&[3.0, 2.0, 1.0])).unwrap();
    let not_skew = Mat::identity(3, 3);
    assert!(matches!(b.left(&not_skew), Err(Error::NotInGroup { .. })));
    assert!(matches!(
        b.apply(&Mat::zeros(2, 2), &Mat::zeros(3, 3)),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        cn::bi_connection(&b, &Mat::zeros(2, 2)),
        Err(Error::Shape { .. })
    ));
    assert!(matches!(
        mo::kinetic_energy(&neg, &Mat::zeros(3, 3)),
        Err(Error::NotInGroup { .. })
    ));
    assert!(matches!(
        "sideways".parse::<Action>(),
        Err(Error::InvalidArgument { .. })
    ));
    assert_eq!("two-sided".parse::<Action>(), Ok(Action::TwoSided));
    let body = Body {
        r: Mat::identity(3, 3),
        a: vec![1.0, -1.0, 2.0],
        s: Mat::identity(3, 3),
        omega: Mat::zeros(3, 3),
        adot: vec![0.0; 3],
        lambda: Mat::zeros(3, 3),
    };
    assert!(matches!(
        body.to_state(),
        Err(Error::InvalidArgument { .. })
    ));
}

/// Kelvin's circulation as a loop integral (001 (2.34)–(2.36)): the space integral ∮ v·dx of a
/// material loop equals ⟨Γ, ζ⟩ with ζ the loop's oriented areas; the unit square's ζ is its area.
#[test]
fn loop_circulation_is_the_pairing_of_gamma_with_the_loop_areas() {
    let square = Mat::from_fn(4, 2, |k, i| {
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]][k][i]
    });
    let z = mo::loop_area(&square).unwrap();
    assert_eq!((z[(0, 1)], z[(1, 0)]), (1.0, -1.0));
    for n in [2, 3, 4] {
        let x = gl_plus(
            n,
            &(0..n * n)
                .map(|k| {
                    if k % (n + 1) == 0 {
                        1.5
                    } else {
                        0.3 * (k as f64 * 1.7).sin()
                    }
                })
                .collect::<Vec<_>>(),
        );
        let v = Mat::from_fn(n, n, |i, j| ((i * 5 + j * 3) as f64).sin());
        // A closed curve in label space sampled at 64 points (a tilted, off-centre ellipse).
        let labels = Mat::from_fn(64, n, |k, i| {
            let s = std::f64::consts::TAU * k as f64 / 64.0;
            0.2 * i as f64 + (1.0 + 0.3 * i as f64) * (s + i as f64).cos()
        });
        let lhs = mo::loop_circulation(&x, &v, &labels).unwrap();
        let rhs = so::pairing(
            &mo::circulation(&x, &v).unwrap(),
            &mo::loop_area(&labels).unwrap(),
        );
        assert!(
            (lhs - rhs).abs() < 1e-12 * (1.0 + rhs.abs()),
            "n={n}: {lhs} vs {rhs}"
        );
        // An irrotational motion (horizontal for the right connection, V = X⁻ᵀS with S
        // symmetric, 001 (2.21)) has no circulation around any loop.
        let s = Mat::from_fn(n, n, |i, j| ((i + j) as f64).cos());
        let v0 = x.transpose().partial_piv_lu().solve(&s);
        let c = mo::loop_circulation(&x, &v0, &labels).unwrap();
        assert!(c.abs() < 1e-12 * (1.0 + lhs.abs()), "{c}");
    }
    assert!(mo::loop_area(&Mat::zeros(2, 3)).is_err());
}

/// Guichardet's connection of N particles (001 (2.23)–(2.28)): for particles x = Xu whose labels
/// have Σ m u uᵀ = 1 it is the left connection ω^L_X(Ẋ), and their locked inertia is A^L_X; in
/// three dimensions hat⁻¹ω = A⁻¹ Σ m x × ẋ with the inertia tensor A = tr(Q)1 − Q.
#[test]
fn guichardet_connection_is_the_left_connection_of_a_homogeneous_body() {
    for n in [2, 3, 4] {
        let x = gl_plus(
            n,
            &(0..n * n)
                .map(|k| {
                    if k % (n + 1) == 0 {
                        1.2 + 0.1 * k as f64
                    } else {
                        0.4 * (k as f64 * 2.3).cos()
                    }
                })
                .collect::<Vec<_>>(),
        );
        let y = Mat::from_fn(n, n, |i, j| ((i * 3 + j * 7) as f64).cos());
        // 2n particles at ±e_i of mass ½: Σ m u uᵀ = 1.
        let labels = Mat::from_fn(2 * n, n, |a, i| {
            if a % n == i {
                if a < n {
                    1.0
                } else {
                    -1.0
                }
            } else {
                0.0
            }
        });
        let masses = vec![0.5; 2 * n];
        let pos = &labels * x.transpose();
        let vel = &labels * y.transpose();
        let w = cn::guichardet_connection(&masses, &pos, &vel).unwrap();
        let b = BiInertia::new(&x).unwrap();
        let wl = cn::left_connection(&b, &y).unwrap();
        assert!(
            dist(&w, &wl) < 1e-12 * (1.0 + wl.norm_l2()),
            "n={n}: {}",
            dist(&w, &wl)
        );
        let i_p = cn::particle_locked_inertia(&masses, &pos).unwrap();
        let i_l = cn::locked_inertia(&b, Action::Left).unwrap();
        assert!(dist(&i_p, &i_l) < 1e-12 * i_l.norm_l2(), "n={n}");
    }
    // Three dimensions, arbitrary particles: the vector form (2.23)–(2.24) with A⁻¹.
    let masses = [1.0, 2.0, 0.5, 1.5];
    let pos = Mat::from_fn(4, 3, |a, i| ((a * 3 + i) as f64 * 1.3).sin());
    let vel = Mat::from_fn(4, 3, |a, i| ((a * 5 + 2 * i) as f64 * 0.7).cos());
    let (mut q, mut l) = (nalgebra::Matrix3::<f64>::zeros(), Vector3::zeros());
    for a in 0..4 {
        let xa = Vector3::new(pos[(a, 0)], pos[(a, 1)], pos[(a, 2)]);
        let va = Vector3::new(vel[(a, 0)], vel[(a, 1)], vel[(a, 2)]);
        q += masses[a] * xa * xa.transpose();
        l += masses[a] * xa.cross(&va);
    }
    let inertia = nalgebra::Matrix3::identity() * q.trace() - q;
    let omega = inertia.try_inverse().unwrap() * l;
    let w = cn::guichardet_connection(&masses, &pos, &vel).unwrap();
    let w3 = so3::hat(&omega);
    let w3 = Mat::from_fn(3, 3, |i, j| w3[(i, j)]);
    assert!(dist(&w, &w3) < 1e-12 * omega.norm(), "{}", dist(&w, &w3));
    // Collinear particles: A_Q is singular.
    let line = Mat::from_fn(4, 3, |a, i| a as f64 * [1.0, 2.0, 3.0][i]);
    assert!(cn::guichardet_connection(&masses, &line, &vel).is_err());
}
