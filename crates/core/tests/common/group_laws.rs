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
