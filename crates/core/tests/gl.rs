//! GL⁺(n): SVD coordinates, polar decomposition, strata (001 (2.4)–(2.6), §6.1, (9.2)).

mod common;

use common::{dist, gl_plus, rotation};
use lieflow::lie::gl;
use lieflow::{Error, Mat};
use proptest::prelude::*;

fn is_rotation(r: &Mat) -> bool {
    let n = r.nrows();
    dist(&(r.transpose() * r), &Mat::identity(n, n)) < 1e-12 && gl::det(r) > 0.0
}

fn diag(a: &[f64]) -> Mat {
    Mat::from_fn(a.len(), a.len(), |i, j| if i == j { a[i] } else { 0.0 })
}

proptest! {
    #[test]
    fn svd_coordinates_reconstruct(n in 1usize..=8, v in prop::collection::vec(-1.0f64..1.0, 192)) {
        let x = gl_plus(n, &v);
        prop_assume!(gl::det(&x) > 1e-6);
        let c = gl::svd_coordinates(&x).unwrap();
        prop_assert!(is_rotation(&c.r) && is_rotation(&c.s));
        prop_assert!(c.a.windows(2).all(|w| w[0] >= w[1]) && c.a[n - 1] > 0.0);
        prop_assert!(dist(&c.matrix(), &x) < 1e-12 * (1.0 + x.norm_l2()));
        let back = gl::from_svd(&c.r, &c.a, &c.s).unwrap();
        prop_assert!(dist(&back, &x) < 1e-12 * (1.0 + x.norm_l2()));
        // Invariance of the singular values under the two-sided action (001 (6.1), (6.3)).
        let (g, h) = (rotation(n, &v[64..]), rotation(n, &v[128..]));
        let y = &g * &x * h.transpose();
        let cy = gl::svd_coordinates(&y).unwrap();
        for (p, q) in c.a.iter().zip(&cy.a) {
            prop_assert!((p - q).abs() < 1e-12 * (1.0 + c.a[0]));
        }
    }

    #[test]
    fn polar_decomposition(n in 1usize..=8, v in prop::collection::vec(-1.0f64..1.0, 64)) {
        let x = gl_plus(n, &v);
        prop_assume!(gl::det(&x) > 1e-6);
        let (r, p) = gl::polar(&x).unwrap();
        prop_assert!(is_rotation(&r));
        prop_assert!((&p - p.transpose()).norm_l2() < 1e-12 * (1.0 + p.norm_l2()));
        let ev = p.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        prop_assert!(ev[0] > 0.0);
        prop_assert!(dist(&(&r * &p), &x) < 1e-12 * (1.0 + x.norm_l2()));
        // P² = XᵀX.
        prop_assert!(dist(&(&p * &p), &(x.transpose() * &x)) < 1e-11 * (1.0 + x.norm_l2()).powi(2));
    }

    #[test]
    fn stratum_detects_coincidences(n in 2usize..=6, v in prop::collection::vec(-1.0f64..1.0, 64),
                                    split in prop::collection::vec(1usize..=3, 6)) {
        // Singular values in blocks of the given multiplicities: 3, 2, 1, … (distinct levels).
        let mut a = Vec::new();
        let mut mult = Vec::new();
        let mut level = 4.0;
        for &m in &split {
            let m = m.min(n - a.len());
            if m == 0 { break; }
            a.extend(std::iter::repeat(level).take(m));
            mult.push(m);
            level *= 0.7;
        }
        let (r, s) = (rotation(n, &v), rotation(n, &v[16..]));
        let x = &r * diag(&a) * s.transpose();
        let st = gl::stratum(&x, gl::STRATUM_TOL).unwrap();
        prop_assert_eq!(&st.multiplicities, &mult);
        prop_assert_eq!(st.is_principal(), mult.iter().all(|&m| m == 1));
        let c = gl::svd_coordinates(&x).unwrap();
        prop_assert_eq!(c.require_principal("t").is_ok(), st.is_principal());
    }
}

#[test]
fn errors_are_typed() {
    let mut x = Mat::identity(3, 3);
    x[(2, 2)] = -2.0;
    let e = gl::svd_coordinates(&x).unwrap_err();
    assert!(matches!(e, Error::NotInGroup { defect, .. } if (defect + 2.0).abs() < 1e-14));
    assert!(e.to_string().contains("det X"));
    assert!(matches!(
        gl::polar(&Mat::zeros(3, 3)),
        Err(Error::NotInGroup { .. })
    ));
    assert!(matches!(
        gl::polar(&Mat::zeros(2, 3)),
        Err(Error::Shape { .. })
    ));
    x[(0, 1)] = f64::NAN;
    assert!(matches!(
        gl::stratum(&x, 1e-8),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        gl::stratum(&Mat::identity(2, 2), -1.0),
        Err(Error::InvalidArgument { .. })
    ));
    let i3 = Mat::identity(3, 3);
    assert!(matches!(
        gl::from_svd(&i3, &[1.0, 0.0, 1.0], &i3),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(matches!(
        gl::from_svd(&i3, &[1.0, 1.0], &i3),
        Err(Error::Shape { .. })
    ));
    let mut refl = Mat::identity(3, 3);
    refl[(0, 0)] = -1.0;
    assert!(matches!(
        gl::from_svd(&refl, &[1.0; 3], &i3),
        Err(Error::NotInGroup { .. })
    ));
    let mut skewed = Mat::identity(3, 3);
    skewed[(0, 1)] = 0.1;
    assert!(matches!(
        gl::from_svd(&i3, &[1.0; 3], &skewed),
        Err(Error::NotInGroup { .. })
    ));
    match gl::svd_coordinates(&i3).unwrap().require_principal("B⁻¹") {
        Err(Error::DegenerateStratum { gap, .. }) => assert_eq!(gap, 0.0),
        other => panic!("{other:?}"),
    }
}

#[test]
fn sign_fix_gives_rotations_for_reflection_svd() {
    // diag(1, −1, −1) has det +1 and singular values 1; any SVD must still give R, S ∈ SO(3).
    let x = diag(&[3.0, -2.0, -1.0]);
    let c = gl::svd_coordinates(&x).unwrap();
    assert!(is_rotation(&c.r) && is_rotation(&c.s));
    assert_eq!(c.a, vec![3.0, 2.0, 1.0]);
    assert!(dist(&c.matrix(), &x) < 1e-14);
}
