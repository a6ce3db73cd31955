//! SO(3)/so(3) fast path and SE(3): the generic group-law suite, closed forms against independent
//! routes (matrix exponential, finite differences, explicit inverses), stability near 0 and π,
//! the relation to the general so(n) coordinates, and every error path.

mod common;

use std::f64::consts::PI;

use common::group_laws::{adjoint_laws, exp_log, group_axioms, verb_laws};
use common::{dist, expm_reference};
use lieflow::lie::se3::{self, SE3};
use lieflow::lie::so3::{self, SO3};
use lieflow::lie::{so, MatrixLieGroup};
use lieflow::{Error, Mat};
use nalgebra::{Matrix3, Matrix4, Matrix6, Vector3, Vector6};
use proptest::prelude::*;

fn to_mat<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>) -> Mat {
    Mat::from_fn(R, C, |i, j| m[(i, j)])
}

fn from_mat3(m: &Mat) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[(i, j)])
}

/// Any 3-vector in a box.
fn vec3(r: f64) -> impl Strategy<Value = Vector3<f64>> {
    prop::array::uniform3(-r..r).prop_map(Vector3::from)
}

/// A unit vector.
fn unit3() -> impl Strategy<Value = Vector3<f64>> {
    prop::array::uniform3(-1.0..1.0f64)
        .prop_filter("not too short", |a| Vector3::from(*a).norm() > 0.1)
        .prop_map(|a| Vector3::from(a).normalize())
}

/// A vector of norm in [0, max): inside the injectivity radius π of exp when max ≤ π.
fn ball3(max: f64) -> impl Strategy<Value = Vector3<f64>> {
    (unit3(), 0.0..max).prop_map(|(a, t)| a * t)
}

fn rot() -> impl Strategy<Value = SO3> {
    vec3(4.0).prop_map(|w| SO3::exp_unchecked(&w))
}

fn vec6(r: f64) -> impl Strategy<Value = Vector6<f64>> {
    (vec3(r), vec3(r)).prop_map(|(w, v)| Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z))
}

/// An se(3) element with |ω| < 3 (inside the injectivity radius).
fn se3_small() -> impl Strategy<Value = Vector6<f64>> {
    (ball3(3.0), vec3(3.0)).prop_map(|(w, v)| Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z))
}

fn rigid() -> impl Strategy<Value = SE3> {
    vec6(4.0).prop_map(|xi| se3::exp_unchecked(&xi))
}

fn orthogonality(r: &Matrix3<f64>) -> f64 {
    (r.transpose() * r - Matrix3::identity()).norm()
}

/// Central difference of exp along e_i, pulled back to the identity on the right (J_r) or left
/// (J_l): vee(Rᵀ (exp(w + h e_i) − exp(w − h e_i)) / 2h) and vee((…) Rᵀ / 2h).
fn fd_jacobians(w: &Vector3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let h = 1e-5;
    let r = so3::exp_unchecked(w);
    let (mut jr, mut jl) = (Matrix3::zeros(), Matrix3::zeros());
    for i in 0..3 {
        let mut e = Vector3::zeros();
        e[i] = h;
        let d = (so3::exp_unchecked(&(w + e)) - so3::exp_unchecked(&(w - e))) / (2.0 * h);
        jr.set_column(i, &so3::vee_unchecked(&(r.transpose() * d)));
        jl.set_column(i, &so3::vee_unchecked(&(d * r.transpose())));
    }
    (jr, jl)
}

proptest! {
    #[test]
    fn so3_group_laws(g in rot(), h in rot(), k in rot(), xi in ball3(3.1),
                      a in vec3(3.0), b in vec3(3.0), c in vec3(3.0)) {
        group_axioms(&g, &h, &k);
        exp_log(&g, &xi);
        adjoint_laws(&g, &h, &a, &b, &c);
    }

    #[test]
    fn se3_group_laws(g in rigid(), h in rigid(), k in rigid(), xi in se3_small(),
                      a in vec6(3.0), b in vec6(3.0), c in vec6(3.0)) {
        group_axioms(&g, &h, &k);
        exp_log(&g, &xi);
        adjoint_laws(&g, &h, &a, &b, &c);
    }

    /// Every verb of the trait for SO(3) and SE(3) (act, checked exp, hat/vee, Ad, ad, ad*, the
    /// Jacobians and their inverses) against its definition.
    #[test]
    fn so3_se3_verbs(g in rot(), h in rot(), xi in ball3(3.0), eta in vec3(3.0), x in vec3(3.0),
                     p in rigid(), q in rigid(), zeta in se3_small(), nu in vec6(3.0)) {
        let pt = |v: &Vector3<f64>| v.as_slice().to_vec();
        verb_laws(&g, &h, &xi, &eta, &x, pt);
        verb_laws(&p, &q, &zeta, &nu, &x, pt);
    }

    /// hat is a Lie algebra isomorphism (R³, ×) → so(3): hat(u × v) = [hat u, hat v].
    #[test]
    fn hat_of_cross_is_commutator(u in vec3(5.0), v in vec3(5.0)) {
        let (hu, hv) = (so3::hat(&u), so3::hat(&v));
        prop_assert!((so3::hat(&u.cross(&v)) - (hu * hv - hv * hu)).norm() < 1e-12);
        prop_assert!((hu * v - u.cross(&v)).norm() < 1e-13);
        prop_assert_eq!(so3::vee_unchecked(&hu), u);
    }

    /// Rodrigues against an independent expm for |w| from 1e-9 to 1e3; R orthogonal to 1e-14.
    #[test]
    fn rodrigues_matches_expm_all_scales(a in unit3(), e in -9.0..3.0f64) {
        let w = a * 10f64.powf(e);
        let r = so3::exp_unchecked(&w);
        let reference = expm_reference(&to_mat(&so3::hat(&w)));
        let scale = 1.0 + w.norm();
        prop_assert!(dist(&to_mat(&r), &reference) < 1e-13 * scale,
            "|w| = {:e}: {:e}", w.norm(), dist(&to_mat(&r), &reference));
        prop_assert!(orthogonality(&r) < 1e-14, "defect {:e}", orthogonality(&r));
        prop_assert!((r.determinant() - 1.0).abs() < 1e-14);
        // The axis is fixed and the angle is |w| mod 2π.
        prop_assert!((r * a - a).norm() < 1e-14);
    }

    /// log∘exp = id for |w| < π (tight, including |w| ~ 1e-9 and close to π), exp∘log = id.
    #[test]
    fn log_exp_round_trip(a in unit3(), t in 0.0..PI, e in -9.0..0.0f64) {
        for theta in [t, 10f64.powf(e), PI - 10f64.powf(e).max(1e-10)] {
            let w = a * theta;
            let back = so3::log_unchecked(&so3::exp_unchecked(&w));
            prop_assert!((back - w).norm() < 2e-14 * (1.0 + theta),
                "θ = {theta:e}: {:e}", (back - w).norm());
        }
        let r = so3::exp_unchecked(&(a * t));
        prop_assert!((so3::exp_unchecked(&so3::log_unchecked(&r)) - r).norm() < 1e-14);
    }

    /// Angles within 1e-6 and 1e-10 of π: log recovers the vector (not its antipode) and the
    /// trait log accepts them; exactly at π one of the two logarithms ±π a comes back.
    #[test]
    fn log_near_and_at_pi(a in unit3()) {
        for delta in [1e-6, 1e-10] {
            let w = a * (PI - delta);
            let r = so3::exp_unchecked(&w);
            prop_assert!((so3::log_unchecked(&r) - w).norm() < 1e-13);
            let g = SO3::new(r).unwrap();
            prop_assert!((g.log().unwrap() - w).norm() < 1e-13);
        }
        let r = 2.0 * a * a.transpose() - Matrix3::identity();
        let l = so3::log_unchecked(&r);
        prop_assert!((l - a * PI).norm() < 1e-14 || (l + a * PI).norm() < 1e-14);
        prop_assert!((so3::exp_unchecked(&l) - r).norm() < 1e-14);
        let err = SO3::new(r).unwrap().log().unwrap_err();
        prop_assert!(matches!(err, Error::NoUniqueLog { .. }), "{err:?}");
    }

    /// exp(w + δ) = exp(w) exp(J_r(w) δ) + O(δ²) = exp(J_l(w) δ) exp(w) + O(δ²): the closed forms
    /// against central differences; J_l = J_rᵀ = exp(w) J_r; inverses.
    #[test]
    fn jacobians(w in vec3(4.0), e in -6.0..0.0f64, a in unit3()) {
        for w in [w, a * 10f64.powf(e)] {
            let (jr_fd, jl_fd) = fd_jacobians(&w);
            let (jr, jl) = (so3::jacobian_right_unchecked(&w), so3::jacobian_left_unchecked(&w));
            prop_assert!((jr - jr_fd).norm() < 1e-8, "J_r: {:e}", (jr - jr_fd).norm());
            prop_assert!((jl - jl_fd).norm() < 1e-8, "J_l: {:e}", (jl - jl_fd).norm());
            prop_assert!((jl - jr.transpose()).norm() < 1e-14);
            prop_assert!((jl - so3::exp_unchecked(&w) * jr).norm() < 1e-13);
            let jri = so3::jacobian_right_inv(&w).unwrap();
            let jli = so3::jacobian_left_inv(&w).unwrap();
            // J⁻¹J = I to round-off times the condition number (J is singular at |w| = 2π)
            let tol = 1e-14 * (jr.norm() * jri.norm()).max(100.0);
            let (er, el) = (
                (jri * jr - Matrix3::identity()).norm(),
                (jli * jl - Matrix3::identity()).norm(),
            );
            prop_assert!(er < tol && el < tol, "J⁻¹J − I: {er:e}, {el:e} (tolerance {tol:e})");
        }
    }

    /// cay(w) = (I − ŵ/2)⁻¹(I + ŵ/2) ∈ SO(3), a rotation by 2 atan(|w|/2) about w; cay⁻¹ inverts it.
    #[test]
    fn cayley(w in vec3(20.0)) {
        let r = so3::cayley(&w);
        let h = so3::hat(&w) * 0.5;
        let reference = (Matrix3::identity() - h).try_inverse().unwrap() * (Matrix3::identity() + h);
        prop_assert!((r - reference).norm() < 1e-13);
        prop_assert!(orthogonality(&r) < 1e-14);
        let angle = 2.0 * (0.5 * w.norm()).atan();
        prop_assert!((so3::log_unchecked(&r) - w.normalize() * angle).norm() < 1e-12);
        let back = so3::cayley_inv(&r).unwrap();
        prop_assert!((back - w).norm() < 1e-13 * (1.0 + w.norm_squared()));
    }

    /// so3 and so(n) at n = 3: c = (−w₃, w₂, −w₁) maps hat to hat_n, brackets to brackets and
    /// pairings to pairings, and so3::exp_unchecked(w) = expm(hat_n(c)).
    #[test]
    fn relation_to_so_n(w in vec3(5.0), u in vec3(5.0)) {
        let c = so3::to_eij(&w);
        let m = so::hat_n(&c).unwrap();
        prop_assert_eq!(from_mat3(&m), so3::hat(&w));
        prop_assert_eq!(so3::from_eij(&c), w);
        let mu = so::hat_n(&so3::to_eij(&u)).unwrap();
        prop_assert!((so::pairing(&m, &mu) - w.dot(&u)).abs() < 1e-12);
        let br = so::bracket(&m, &mu);
        prop_assert!(dist(&br, &so::hat_n(&so3::to_eij(&w.cross(&u))).unwrap()) < 1e-12);
        let e = expm_reference(&m);
        prop_assert!((from_mat3(&e) - so3::exp_unchecked(&w)).norm() < 1e-12 * (1.0 + w.norm()));
    }

    /// The polar factor: project(R P) = R for P symmetric positive definite; project(R) = R.
    #[test]
    fn project_is_polar_factor(g in rot(), b in prop::array::uniform9(-1.0..1.0f64)) {
        let r = *g.matrix3();
        let b = Matrix3::from_column_slice(&b);
        let p = b * b.transpose() + Matrix3::identity() * 0.1;
        let q = so3::project(&(r * p)).unwrap();
        prop_assert!((q - r).norm() < 1e-10 * p.norm() / 0.1);
        prop_assert!((so3::project(&r).unwrap() - r).norm() < 1e-14);
        prop_assert!(so3::is_rotation(&q, 1e-13));
    }

    /// SE(3): 6×6 Ad and ad matrices against the vector forms and each other:
    /// Ad_{gh} = Ad_g Ad_h, Ad_{g⁻¹} = Ad_g⁻¹, Ad_{exp ξ} = expm(ad_ξ), ad* = adᵀ.
    #[test]
    fn se3_adjoint_matrices(g in rigid(), h in rigid(), xi in vec6(2.0), eta in vec6(2.0)) {
        let (ag, ah) = (g.adjoint_matrix(), h.adjoint_matrix());
        prop_assert!((g.compose(&h).adjoint_matrix() - ag * ah).norm() < 1e-11 * (1.0 + ag.norm() * ah.norm()));
        prop_assert!((ag * xi - g.adjoint(&xi)).norm() < 1e-12 * (1.0 + ag.norm()) * (1.0 + xi.norm()));
        prop_assert!((g.inverse().adjoint_matrix() * ag - Matrix6::identity()).norm() < 1e-10 * (1.0 + ag.norm()).powi(2));
        prop_assert!((se3::ad_matrix(&xi) * eta - SE3::ad(&xi, &eta)).norm() < 1e-13 * (1.0 + xi.norm() * eta.norm()));
        prop_assert!((se3::ad_matrix(&xi).transpose() * eta - SE3::ad_star(&xi, &eta)).norm() < 1e-13 * (1.0 + xi.norm() * eta.norm()));
        let e = expm_reference(&to_mat(&se3::ad_matrix(&xi)));
        let a = se3::exp_unchecked(&xi).adjoint_matrix();
        prop_assert!(dist(&to_mat(&a), &e) < 1e-10 * (1.0 + a.norm()));
    }

    /// SE(3) log∘exp with the rotation angle near 0 and within 1e-6, 1e-10 of π; homogeneous
    /// matrix round trip; g · x = R x + t.
    #[test]
    fn se3_log_exp_edges(a in unit3(), v in vec3(3.0), e in -12.0..-1.0f64, x in vec3(2.0)) {
        for theta in [0.0, 10f64.powf(e), PI - 1e-6, PI - 1e-10] {
            let w = a * theta;
            let xi = Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z);
            let g = se3::exp_unchecked(&xi);
            prop_assert!((se3::log_unchecked(&g) - xi).norm() < 1e-12, "θ = {theta:e}: {:e}", (se3::log_unchecked(&g) - xi).norm());
            let m = g.matrix4();
            let back = SE3::from_matrix4(&m).unwrap();
            prop_assert_eq!(back, g);
            let hx = m * nalgebra::Vector4::new(x.x, x.y, x.z, 1.0);
            prop_assert!((g.act(&x) - hx.xyz()).norm() < 1e-13);
        }
        // Pure translation: exp(0, v) = (I, v).
        let g = se3::exp_unchecked(&Vector6::new(0.0, 0.0, 0.0, v.x, v.y, v.z));
        prop_assert_eq!(*g.rot(), Matrix3::identity());
        prop_assert_eq!(*g.trans(), v);
    }
}

#[test]
fn jacobian_inverse_singular_at_two_pi() {
    let w = Vector3::new(0.0, 2.0 * PI, 0.0);
    for r in [so3::jacobian_right_inv(&w), so3::jacobian_left_inv(&w)] {
        assert!(matches!(r, Err(Error::InvalidArgument { .. })), "{r:?}");
    }
    // Just away from 2π and at π the inverse exists and inverts.
    for t in [PI, 2.0 * PI - 1e-3] {
        let w = Vector3::new(0.0, t, 0.0);
        let j = so3::jacobian_right_inv(&w).unwrap() * so3::jacobian_right_unchecked(&w);
        assert!((j - Matrix3::identity()).norm() < 1e-11);
    }
}

#[test]
fn cayley_inv_rejects_half_turn() {
    let r = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
    let err = so3::cayley_inv(&r).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument { .. }));
    assert!(err.to_string().contains("1 + tr R"), "{err}");
    assert!(so3::cayley_inv(&Matrix3::from_element(f64::NAN)).is_err());
}

#[test]
fn rotation_validation_errors() {
    let mut r = so3::exp_unchecked(&Vector3::new(0.3, -0.2, 1.0));
    assert!(SO3::new(r).is_ok());
    assert!(so3::is_rotation(&r, 1e-14));
    r[(0, 1)] += 1e-6;
    let err = SO3::new(r).unwrap_err();
    assert!(matches!(err, Error::NotInGroup { .. }), "{err:?}");
    assert!(err.to_string().contains("‖RᵀR − I‖_F"), "{err}");
    assert!(!so3::is_rotation(&r, 1e-10));
    let reflection = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    let err = SO3::new(reflection).unwrap_err();
    assert!(err.to_string().contains("det R"), "{err}");
    assert!(!so3::is_rotation(&reflection, 1e-10));
    r[(2, 2)] = f64::INFINITY;
    assert!(matches!(SO3::new(r), Err(Error::NonFinite { .. })));
    assert!(matches!(so3::project(&r), Err(Error::NonFinite { .. })));
    // project fixes the determinant of a reflection: the nearest rotation to diag(1, 1, −1)
    // (σ₂ = σ₃, so one of several) is a rotation at distance 2 from it.
    let q = so3::project(&reflection).unwrap();
    assert!(so3::is_rotation(&q, 1e-14));
    assert!(((q - reflection).norm() - 2.0).abs() < 1e-14);
}

#[test]
fn try_vee_errors() {
    let w = Vector3::new(1.0, -2.0, 3.0);
    assert_eq!(so3::vee(&so3::hat(&w)).unwrap(), w);
    let mut m = so3::hat(&w);
    m[(0, 0)] = 1e-3;
    assert!(matches!(so3::vee(&m), Err(Error::NotInGroup { .. })));
    m[(0, 0)] = f64::NAN;
    assert!(matches!(so3::vee(&m), Err(Error::NonFinite { .. })));
}

#[test]
fn se3_validation_errors() {
    let g = se3::exp_unchecked(&Vector6::new(0.1, 0.2, -0.3, 1.0, 2.0, 3.0));
    let mut m = g.matrix4();
    m[(3, 0)] = 1e-6;
    let err = SE3::from_matrix4(&m).unwrap_err();
    assert!(matches!(err, Error::NotInGroup { .. }));
    assert!(err.to_string().contains("last row"), "{err}");
    let mut m = g.matrix4();
    m[(0, 0)] += 1e-3;
    assert!(matches!(
        SE3::from_matrix4(&m),
        Err(Error::NotInGroup { .. })
    ));
    let mut m = g.matrix4();
    m[(1, 3)] = f64::NAN;
    assert!(matches!(
        SE3::from_matrix4(&m),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        SE3::new(*g.rot(), Vector3::new(0.0, f64::INFINITY, 0.0)),
        Err(Error::NonFinite { .. })
    ));
    // The trait log refuses a half turn; the free log returns one of the two logarithms.
    let half = SE3::new(
        Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, -1.0)),
        Vector3::new(1.0, 2.0, 3.0),
    )
    .unwrap();
    assert!(matches!(half.log(), Err(Error::NoUniqueLog { .. })));
    let l = se3::log_unchecked(&half);
    let again = se3::exp_unchecked(&l);
    assert!((again.matrix4() - half.matrix4()).norm() < 1e-14);
    assert!((Vector3::new(l[0], l[1], l[2]).norm() - PI).abs() < 1e-15);
}

#[test]
fn se3_hat_and_matrix_layout() {
    // Rotation first: ξ = (ω, v) ↦ [[ω̂, v], [0, 0]].
    let xi = Vector6::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
    let m = se3::hat(&xi);
    let expect = Matrix4::new(
        0.0, -3.0, 2.0, 4.0, 3.0, 0.0, -1.0, 5.0, -2.0, 1.0, 0.0, 6.0, 0.0, 0.0, 0.0, 0.0,
    );
    assert_eq!(m, expect);
    assert_eq!(SE3::coords(&xi), vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
}
