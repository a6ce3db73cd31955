//! One suite of properties that every [`MatrixLieGroup`] must satisfy (as manif does for its
//! groups). Each function panics with a message on failure; proptest reports the inputs.

use super::{dist, expm_reference};
use lieflow::lie::MatrixLieGroup;
use lieflow::Mat;

fn alg_dist<G: MatrixLieGroup>(a: &G::Algebra, b: &G::Algebra) -> f64 {
    let (a, b) = (G::coords(a), G::coords(b));
    a.iter()
        .zip(&b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn alg_norm<G: MatrixLieGroup>(a: &G::Algebra) -> f64 {
    G::coords(a).iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn lin<G: MatrixLieGroup>(g: &G, a: f64, x: &G::Algebra, b: f64, y: &G::Algebra) -> G::Algebra {
    let (x, y) = (G::coords(x), G::coords(y));
    let c: Vec<f64> = x.iter().zip(&y).map(|(p, q)| a * p + b * q).collect();
    g.algebra_from_coords(&c)
}

fn assert_small(what: &str, err: f64, tol: f64) {
    assert!(err <= tol, "{what}: error {err:.3e} > tolerance {tol:.1e}");
}

/// Group axioms and the matrix representation being a homomorphism.
pub fn group_axioms<G: MatrixLieGroup>(g: &G, h: &G, k: &G) {
    let lhs = g.compose(h).compose(k);
    let rhs = g.compose(&h.compose(k));
    assert_small("associativity", dist(&lhs.matrix(), &rhs.matrix()), 1e-12);
    let e = g.identity_like();
    assert_small(
        "right identity",
        dist(&g.compose(&e).matrix(), &g.matrix()),
        1e-14,
    );
    assert_small(
        "left identity",
        dist(&e.compose(g).matrix(), &g.matrix()),
        1e-14,
    );
    assert_small(
        "inverse",
        dist(&g.compose(&g.inverse()).matrix(), &e.matrix()),
        1e-12,
    );
    assert_small(
        "homomorphism",
        dist(&g.compose(h).matrix(), &(g.matrix() * h.matrix())),
        1e-12,
    );
}

/// exp against an independent matrix exponential; one-parameter subgroup; log∘exp and exp∘log.
/// `xi` must lie inside the injectivity radius of exp (for rotations: angles < π).
pub fn exp_log<G: MatrixLieGroup>(g: &G, xi: &G::Algebra) {
    let scale = 1.0 + alg_norm::<G>(xi);
    let x = G::exp(xi).unwrap();
    assert_small(
        "exp = expm(matrix)",
        dist(&x.matrix(), &expm_reference(&G::hat(xi))),
        1e-12 * scale,
    );
    let half = lin::<G>(g, 0.5, xi, 0.0, xi);
    let hh = G::exp(&half).unwrap().compose(&G::exp(&half).unwrap());
    assert_small(
        "exp(ξ/2)² = exp ξ",
        dist(&hh.matrix(), &x.matrix()),
        1e-12 * scale,
    );
    let back = x.log().expect("log of exp inside the injectivity radius");
    assert_small("log(exp ξ) = ξ", alg_dist::<G>(&back, xi), 1e-10 * scale);
    if let Ok(l) = g.log() {
        let again = G::exp(&l).unwrap();
        assert_small("exp(log g) = g", dist(&again.matrix(), &g.matrix()), 1e-10);
    }
    let c = G::coords(xi);
    assert_small(
        "coords round trip",
        alg_dist::<G>(&g.algebra_from_coords(&c), xi),
        0.0,
    );
}

/// Ad, ad and ad*: matrix formulas, homomorphism, bracket, Jacobi, duality, exp equivariance.
pub fn adjoint_laws<G: MatrixLieGroup>(
    g: &G,
    h: &G,
    xi: &G::Algebra,
    eta: &G::Algebra,
    zeta: &G::Algebra,
) {
    let scale =
        (1.0 + alg_norm::<G>(xi)) * (1.0 + alg_norm::<G>(eta)) * (1.0 + alg_norm::<G>(zeta));
    let gm = g.matrix();
    let gi = g.inverse().matrix();
    // Ad_g ξ = g ξ g⁻¹ in the matrix representation.
    let ad_g = G::hat(&g.adjoint(xi));
    assert_small(
        "Ad_g ξ = g ξ g⁻¹",
        dist(&ad_g, &(&gm * G::hat(xi) * &gi)),
        1e-11 * scale,
    );
    // Ad_{gh} = Ad_g Ad_h.
    let lhs = g.compose(h).adjoint(xi);
    let rhs = g.adjoint(&h.adjoint(xi));
    assert_small("Ad homomorphism", alg_dist::<G>(&lhs, &rhs), 1e-11 * scale);
    // [ξ, η] is the matrix commutator.
    let (xm, ym): (Mat, Mat) = (G::hat(xi), G::hat(eta));
    let br = G::hat(&G::ad(xi, eta));
    assert_small(
        "ad = commutator",
        dist(&br, &(&xm * &ym - &ym * &xm)),
        1e-12 * scale,
    );
    // Ad preserves the bracket.
    let lhs = g.adjoint(&G::ad(xi, eta));
    let rhs = G::ad(&g.adjoint(xi), &g.adjoint(eta));
    assert_small(
        "Ad_g[ξ,η] = [Ad_g ξ, Ad_g η]",
        alg_dist::<G>(&lhs, &rhs),
        1e-10 * scale,
    );
    // Antisymmetry and Jacobi.
    let anti = lin::<G>(g, 1.0, &G::ad(xi, eta), 1.0, &G::ad(eta, xi));
    assert_small("antisymmetry", alg_norm::<G>(&anti), 1e-12 * scale);
    let j1 = G::ad(xi, &G::ad(eta, zeta));
    let j2 = G::ad(eta, &G::ad(zeta, xi));
    let j3 = G::ad(zeta, &G::ad(xi, eta));
    let j = lin::<G>(g, 1.0, &lin::<G>(g, 1.0, &j1, 1.0, &j2), 1.0, &j3);
    assert_small("Jacobi identity", alg_norm::<G>(&j), 1e-11 * scale);
    // ⟨ad*_ξ μ, η⟩ = ⟨μ, ad_ξ η⟩ with μ = ζ.
    let lhs = G::pairing(&G::ad_star(xi, zeta), eta);
    let rhs = G::pairing(zeta, &G::ad(xi, eta));
    assert_small("ad* duality", (lhs - rhs).abs(), 1e-11 * scale);
    // exp(Ad_g ξ) = g exp(ξ) g⁻¹.
    let lhs = G::exp(&g.adjoint(xi)).unwrap().matrix();
    let rhs = &gm * G::exp(xi).unwrap().matrix() * &gi;
    assert_small("exp(Ad_g ξ) = g exp ξ g⁻¹", dist(&lhs, &rhs), 1e-10 * scale);
    // Ad is linear.
    let lhs = g.adjoint(&lin::<G>(g, 2.0, xi, -3.0, eta));
    let rhs = lin::<G>(g, 2.0, &g.adjoint(xi), -3.0, &g.adjoint(eta));
    assert_small("Ad linear", alg_dist::<G>(&lhs, &rhs), 1e-10 * scale);
}

/// The column k of a dim × dim coordinate matrix as an algebra element.
fn column<G: MatrixLieGroup>(g: &G, m: &Mat, k: usize) -> G::Algebra {
    let c: Vec<f64> = (0..m.nrows()).map(|i| m[(i, k)]).collect();
    g.algebra_from_coords(&c)
}

/// Every verb of [`MatrixLieGroup`] against its definition: act (a left action), checked and
/// unchecked exp, hat/vee inverse to each other, Ad_g = d/dt g exp(tξ) g⁻¹ and
/// ad_ξ = d/dt Ad_exp(tξ) (central differences), ad* dual to ad, the Jacobians against central
/// differences of exp, J_l(ξ) = Ad_exp(ξ) J_r(ξ), J_r(−ξ) = J_l(ξ) and the inverses. `xi` must lie
/// where the inverse Jacobians are defined (|ξ| < π for so(n)); `x` is a point of the defining
/// representation, `point` its coordinates.
pub fn verb_laws<G: MatrixLieGroup>(
    g: &G,
    h: &G,
    xi: &G::Algebra,
    eta: &G::Algebra,
    x: &G::Point,
    point: fn(&G::Point) -> Vec<f64>,
) {
    let scale = (1.0 + alg_norm::<G>(xi)) * (1.0 + alg_norm::<G>(eta));
    let pdist = |a: &G::Point, b: &G::Point| {
        let (a, b) = (point(a), point(b));
        assert_eq!(a.len(), b.len());
        a.iter()
            .zip(&b)
            .map(|(p, q)| (p - q).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let px = 1.0 + point(x).iter().map(|v| v * v).sum::<f64>().sqrt();
    // act: a left action with e · x = x and g⁻¹ · (g · x) = x.
    let lhs = g.act(&h.act(x));
    let rhs = g.compose(h).act(x);
    assert_small("g·(h·x) = (gh)·x", pdist(&lhs, &rhs), 1e-12 * px);
    assert_small("e·x = x", pdist(&g.identity_like().act(x), x), 0.0);
    let back = g.inverse().act(&g.act(x));
    assert_small("g⁻¹·(g·x) = x", pdist(&back, x), 1e-12 * px);
    // exp: checked = unchecked on valid input.
    let e = G::exp(xi).expect("exp of a valid ξ");
    assert_small(
        "exp = exp_unchecked",
        dist(&e.matrix(), &G::exp_unchecked(xi).matrix()),
        0.0,
    );
    // hat and vee.
    let m = G::hat(xi);
    let v = G::vee(&m).expect("vee of hat ξ");
    assert_small("vee(hat ξ) = ξ", alg_dist::<G>(&v, xi), 0.0);
    let size = m.nrows();
    let not_algebra = &m + Mat::identity(size, size);
    assert!(G::vee(&not_algebra).is_err(), "vee(hat ξ + I) must fail");
    // Ad_g ξ = d/dt g exp(tξ) g⁻¹ at t = 0.
    let step = 1e-5;
    let scaled = |t: f64, a: &G::Algebra| lin::<G>(g, t, a, 0.0, a);
    let (gm, gi) = (g.matrix(), g.inverse().matrix());
    let conj = |t: f64| &gm * G::exp(&scaled(t, xi)).unwrap().matrix() * &gi;
    let fd = (conj(step) - conj(-step)) * faer::Scale(0.5 / step);
    assert_small(
        "Ad_g ξ = d/dt g exp(tξ) g⁻¹",
        dist(&G::hat(&g.adjoint(xi)), &fd),
        1e-8 * scale * (1.0 + gm.norm_l2() * gi.norm_l2()),
    );
    // ad_ξ η = d/dt Ad_exp(tξ) η at t = 0.
    let ad_t = |t: f64| G::exp(&scaled(t, xi)).unwrap().adjoint(eta);
    let fd = lin::<G>(g, 0.5 / step, &ad_t(step), -0.5 / step, &ad_t(-step));
    assert_small(
        "ad_ξ η = d/dt Ad_exp(tξ) η",
        alg_dist::<G>(&G::ad(xi, eta), &fd),
        1e-8 * scale * scale,
    );
    // ⟨ad*_ξ μ, η⟩ = ⟨μ, ad_ξ η⟩ with μ = Ad_g η (any element).
    let mu = g.adjoint(eta);
    let lhs = G::pairing(&G::ad_star(xi, &mu), eta);
    let rhs = G::pairing(&mu, &G::ad(xi, eta));
    assert_small(
        "⟨ad*_ξ μ, η⟩ = ⟨μ, ad_ξ η⟩",
        (lhs - rhs).abs(),
        1e-11 * scale * scale,
    );
    // Jacobians against central differences of exp along the coordinate axes:
    // exp(ξ)⁻¹ d exp = hat(J_r e_k), d exp exp(ξ)⁻¹ = hat(J_l e_k).
    let jr = G::jacobian_right(xi).expect("J_r");
    let jl = G::jacobian_left(xi).expect("J_l");
    let d = g.dim();
    assert_eq!(
        (jr.nrows(), jr.ncols(), jl.nrows(), jl.ncols()),
        (d, d, d, d)
    );
    let em = e.matrix();
    let ei = e.inverse().matrix();
    let c = G::coords(xi);
    for k in 0..d {
        let shifted = |t: f64| {
            let mut c = c.clone();
            c[k] += t;
            G::exp(&g.algebra_from_coords(&c)).unwrap().matrix()
        };
        let de = (shifted(step) - shifted(-step)) * faer::Scale(0.5 / step);
        let tol = 1e-8 * scale * scale;
        assert_small(
            "J_r by differences",
            dist(&(&ei * &de), &G::hat(&column(g, &jr, k))),
            tol,
        );
        assert_small(
            "J_l by differences",
            dist(&(&de * &ei), &G::hat(&column(g, &jl, k))),
            tol,
        );
        // J_l(ξ) = Ad_exp(ξ) J_r(ξ).
        let ad_col = e.adjoint(&column(g, &jr, k));
        assert_small(
            "J_l = Ad_exp(ξ) J_r",
            alg_dist::<G>(&ad_col, &column(g, &jl, k)),
            1e-12 * scale * (1.0 + em.norm_l2() * ei.norm_l2()),
        );
    }
    // J_r(−ξ) = J_l(ξ).
    let minus = lin::<G>(g, -1.0, xi, 0.0, xi);
    let jr_minus = G::jacobian_right(&minus).unwrap();
    assert_small("J_r(−ξ) = J_l(ξ)", dist(&jr_minus, &jl), 1e-13 * scale);
    // The inverses.
    let id = Mat::identity(d, d);
    let jri = G::jacobian_right_inv(xi).expect("J_r⁻¹");
    let jli = G::jacobian_left_inv(xi).expect("J_l⁻¹");
    assert_small("J_r⁻¹ J_r = I", dist(&(&jri * &jr), &id), 1e-11 * scale);
    assert_small("J_l⁻¹ J_l = I", dist(&(&jli * &jl), &id), 1e-11 * scale);
}
