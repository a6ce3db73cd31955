//! Issue 16, the numerical part: one rule for the exponentials, no NaN from finite input, the
//! driver's finiteness guard, GL⁺(n) membership by the sign of an LU factorization.

use lieflow::integrate::integrate;
use lieflow::lie::{gl, se3, so, so3, EXP_MAX_NORM};
use lieflow::systems::RigidBody;
use lieflow::{Error, Mat};
use nalgebra::{Matrix3, Vector3, Vector6};

fn is_rotation3(r: &Matrix3<f64>) -> bool {
    r.iter().all(|x| x.is_finite()) && so3::is_rotation(r, 1e-12)
}

fn invalid_naming(e: &Error, words: &[&str]) -> bool {
    let msg = e.to_string();
    matches!(e, Error::InvalidArgument { .. }) && words.iter().all(|w| msg.contains(w))
}

#[test]
fn one_rule_for_every_exponential() {
    // Below the rule (1e14 < EXP_MAX_NORM ≈ 2.25e14): a rotation by the angle 1e14 (mod 2π).
    assert!(EXP_MAX_NORM > 2.2e14 && EXP_MAX_NORM < 2.3e14);
    let w = Vector3::new(1e14, 0.0, 0.0);
    let r = so3::try_exp(&w).unwrap();
    assert!(is_rotation3(&r));
    let (s, c) = 1e14f64.sin_cos();
    assert!((r[(1, 1)] - c).abs() < 1e-9 && (r[(2, 1)] - s).abs() < 1e-9);
    assert!(so3::try_jacobian_left(&w)
        .unwrap()
        .iter()
        .all(|x| x.is_finite()));
    assert!(so3::try_jacobian_right(&w)
        .unwrap()
        .iter()
        .all(|x| x.is_finite()));
    assert!(so3::jacobian_right_inv(&w)
        .unwrap()
        .iter()
        .all(|x| x.is_finite()));
    let g = se3::try_exp(&Vector6::new(1e14, 0.0, 0.0, 1.0, 2.0, 3.0)).unwrap();
    assert!(is_rotation3(g.rot()));
    let xi = so::hat_n(&[1e14, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
    let r4 = so::exp(&xi).unwrap();
    assert!(so::is_rotation(&r4, 1e-12).unwrap());
    // At and beyond the rule: one typed error naming the map and the lost angle, never NaN.
    for t in [1e15, 1e16, 1e154, 1e300] {
        let w = Vector3::new(t, 0.0, 0.0);
        let words = ["lost to rounding", "|w|"];
        assert!(invalid_naming(&so3::try_exp(&w).unwrap_err(), &words));
        assert!(invalid_naming(
            &so3::try_jacobian_left(&w).unwrap_err(),
            &words
        ));
        assert!(invalid_naming(
            &so3::try_jacobian_right(&w).unwrap_err(),
            &words
        ));
        assert!(invalid_naming(
            &so3::jacobian_left_inv(&w).unwrap_err(),
            &words
        ));
        assert!(invalid_naming(
            &so3::jacobian_right_inv(&w).unwrap_err(),
            &words
        ));
        let e = se3::try_exp(&Vector6::new(t, 0.0, 0.0, 1.0, 2.0, 3.0)).unwrap_err();
        assert!(invalid_naming(&e, &["SE(3)", "lost to rounding"]));
        let xi = so::hat_n(&[t, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!(invalid_naming(
            &so::exp(&xi).unwrap_err(),
            &["lost to rounding"]
        ));
        let eta = so::hat_n(&[0.0, 1.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!(invalid_naming(&so::dexp(&xi, &eta).unwrap_err(), &["dexp"]));
        // The message prints the norm compactly.
        let msg = so3::try_exp(&w).unwrap_err().to_string();
        assert!(msg.len() < 250, "{msg}");
        // The unchecked free functions give NaN (for the driver's guard), not a rotation.
        assert!(so3::exp(&w).iter().all(|x| x.is_nan()));
    }
    // SE(3): a translation beyond the f64 range is an overflow error, not inf.
    let e = se3::try_exp(&Vector6::new(0.0, 0.0, 0.3, 1.7e308, 1.7e308, 1.7e308)).unwrap_err();
    assert!(invalid_naming(&e, &["overflow"]), "{e}");
}

#[test]
fn cayley_is_scale_safe() {
    for t in [1e14, 1e16, 1e154, 1e300] {
        let w = Vector3::new(t, -0.5 * t, 0.25 * t);
        let r = so3::cayley(&w);
        assert!(is_rotation3(&r), "{t:e}: {r}");
        // A rotation by 2 atan(|w|/2) → π about w: R w = w and tr R = −1 to rounding.
        assert!((r.trace() + 1.0).abs() < 1e-12);
        let u = w / lieflow::lie::scaled_norm(w.iter());
        assert!((r * u - u).norm() < 1e-12);
        let xi = so::hat_n(&[t, 0.0, -0.5 * t, 0.3 * t, 0.0, 2.0]).unwrap();
        let rn = so::cayley(&xi).unwrap();
        assert!(so::is_rotation(&rn, 1e-12).unwrap(), "{t:e}");
    }
    // Agreement with the unscaled formula where both apply.
    let w = Vector3::new(3e99, 1e99, -2e99);
    let t2 = w.norm_squared();
    let f = 4.0 / (4.0 + t2);
    let direct = Matrix3::identity()
        + (so3::hat(&w) + (w * w.transpose() - Matrix3::from_diagonal_element(t2)) * 0.5) * f;
    assert!((so3::cayley(&(w * 1e2)) - direct).norm() < 1e-12);
}

#[test]
fn the_driver_reports_the_step_that_left_the_finite_range() {
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let lifted = body.with_attitude();
    let eye = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let z = lifted.state_with_attitude([1.0, 0.5, -0.3], eye);
    for method in [
        "splitting",
        "splitting4",
        "isospectral",
        "lgvi",
        "rk4",
        "rkmk4",
    ] {
        for (z0, dt) in [
            (z.clone(), 1e300),
            (lifted.state_with_attitude([1e160, 0.5, -0.3], eye), 1e-2),
        ] {
            let e = integrate(&lifted, method, &z0, dt, 5, 1).unwrap_err();
            let msg = e.to_string();
            // LeftDomain from the guard, or NotConverged from an implicit step that sees it.
            let typed = matches!(e, Error::LeftDomain { .. } | Error::NotConverged { .. });
            assert!(typed, "{method}: {msg}");
            assert!(
                msg.contains("step 1") && msg.contains("dt = "),
                "{method}: {msg}"
            );
            assert!(msg.len() < 400, "{method}: {msg}");
        }
        // Without the attitude as well (the M flows refuse a lost angle).
        let e = integrate(&body, method, &[1.0, 0.5, -0.3], 1e300, 5, 5).unwrap_err();
        let typed = matches!(e, Error::LeftDomain { .. } | Error::NotConverged { .. });
        assert!(typed, "{method}: {e}");
        assert!(e.to_string().contains("t = 1e300"), "{e}");
    }
    // A chunk of several steps names the range.
    let e = integrate(&lifted, "splitting", &z, 1e300, 7, 7).unwrap_err();
    assert!(e.to_string().contains("one of the steps 1 to 7"), "{e}");
}

#[test]
fn gl_plus_membership_by_the_sign_of_the_lu() {
    let n = 2000;
    let x = Mat::from_fn(n, n, |i, j| if i == j { (i + 1) as f64 } else { 0.0 });
    assert_eq!(gl::check_gl_plus("X", &x).unwrap(), n);
    let (sign, ln) = gl::det_sign_ln(&x);
    let ln_fact: f64 = (1..=n).map(|k| (k as f64).ln()).sum();
    assert_eq!(sign, 1.0);
    assert!((ln - ln_fact).abs() < 1e-9 * ln_fact);
    let v = Mat::zeros(n, n);
    let l = lieflow::pseudo_rigid::momentum::angular_momentum(&x, &v).unwrap();
    assert_eq!(l.norm_l2(), 0.0);
    // Tiny and huge scales at small n.
    for s in [1e-120, 1e120] {
        let y = Mat::from_fn(
            3,
            3,
            |i, j| if i == j { s * (3 - i) as f64 } else { 0.1 * s },
        );
        gl::check_gl_plus("X", &y).unwrap();
    }
    // det < 0 still refused, with the sign named when |det X| overflows.
    let mut y = x.clone();
    y[(0, 0)] = -1.0;
    let e = gl::check_gl_plus("X", &y).unwrap_err();
    assert!(matches!(e, Error::NotInGroup { .. }));
    assert!(e.to_string().contains("sign of det X"), "{e}");
    // A permutation with det −1 (odd cycle structure) and one with det +1.
    let p = Mat::from_fn(3, 3, |i, j| if (i + 1) % 3 == j { 1.0 } else { 0.0 });
    assert_eq!(gl::det_sign_ln(&p).0, 1.0);
    let q = Mat::from_fn(3, 3, |i, j| {
        if (i == 0 && j == 1) || (i == 1 && j == 0) || (i == 2 && j == 2) {
            1.0
        } else {
            0.0
        }
    });
    assert_eq!(gl::det_sign_ln(&q).0, -1.0);
}

#[test]
fn so_log_is_accurate_up_to_pi_for_n_up_to_3() {
    use std::f64::consts::PI;
    for n in 2..=3 {
        // A conjugating rotation and the angles (π − d, 0.7) in two planes.
        let q = so::exp(
            &so::hat_n(
                &(0..so::dim(n))
                    .map(|k| 0.3 + 0.1 * k as f64)
                    .collect::<Vec<_>>(),
            )
            .unwrap(),
        )
        .unwrap();
        for d in [1e-5, 1e-7, 1e-9, 1e-11] {
            let mut c = vec![0.0; so::dim(n)];
            c[0] = PI - d;
            if n >= 4 {
                c[so::dim(n) - 1] = 0.7;
            }
            let xi0 = &q * so::hat_n(&c).unwrap() * q.transpose();
            let r = so::exp(&xi0).unwrap();
            let xi = so::log(&r).unwrap_or_else(|e| panic!("n = {n}, d = {d:e}: {e}"));
            let back = so::exp(&xi).unwrap();
            let be = (&back - &r).norm_l2();
            eprintln!(
                "n = {n}, d = {d:e}: backward {be:e}, forward {:e}",
                (&xi - &xi0).norm_l2()
            );
            assert!(be < 1e-12, "n = {n}, d = {d:e}");
            // Forward error within the problem's condition ~ε/d.
            assert!(
                (&xi - &xi0).norm_l2() < 1e-14 / d + 1e-13,
                "n = {n}, d = {d:e}: {:e}",
                (&xi - &xi0).norm_l2()
            );
        }
        // At π within round-off: refused, with the angle in the message.
        let mut c = vec![0.0; so::dim(n)];
        c[0] = PI;
        let r = so::exp(&so::hat_n(&c).unwrap()).unwrap();
        let e = so::log(&r).unwrap_err();
        assert!(
            matches!(e, Error::NoUniqueLog { .. }) && e.to_string().contains("round-off"),
            "{e}"
        );
    }
}
