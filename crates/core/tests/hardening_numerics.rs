//! Issue 16, the numerical part: one rule for the exponentials, no NaN from finite input, the
//! driver's finiteness guard, GL⁺(n) membership by the sign of an LU factorization.

// The fuzz suite's reproducers are kept digit for digit as it printed them.
#![allow(clippy::excessive_precision)]

use lieflow::integrate::integrate;
use lieflow::lie::{gl, se3, so, so3};
use lieflow::numerics::angle::EXP_MAX_NORM;
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
    const { assert!(EXP_MAX_NORM > 2.2e14 && EXP_MAX_NORM < 2.3e14) };
    let w = Vector3::new(1e14, 0.0, 0.0);
    let r = so3::exp(&w).unwrap();
    assert!(is_rotation3(&r));
    let (s, c) = 1e14f64.sin_cos();
    assert!((r[(1, 1)] - c).abs() < 1e-9 && (r[(2, 1)] - s).abs() < 1e-9);
    assert!(so3::jacobian_left(&w)
        .unwrap()
        .iter()
        .all(|x| x.is_finite()));
    assert!(so3::jacobian_right(&w)
        .unwrap()
        .iter()
        .all(|x| x.is_finite()));
    assert!(so3::jacobian_right_inv(&w)
        .unwrap()
        .iter()
        .all(|x| x.is_finite()));
    let g = se3::exp(&Vector6::new(1e14, 0.0, 0.0, 1.0, 2.0, 3.0)).unwrap();
    assert!(is_rotation3(g.rot()));
    let xi = so::hat_n(&[1e14, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
    let r4 = so::exp(&xi).unwrap();
    assert!(so::is_rotation(&r4, 1e-12).unwrap());
    // At and beyond the rule: one typed error naming the map and the lost angle, never NaN.
    for t in [1e15, 1e16, 1e154, 1e300] {
        let w = Vector3::new(t, 0.0, 0.0);
        let words = ["lost to rounding", "|w|"];
        assert!(invalid_naming(&so3::exp(&w).unwrap_err(), &words));
        assert!(invalid_naming(&so3::jacobian_left(&w).unwrap_err(), &words));
        assert!(invalid_naming(
            &so3::jacobian_right(&w).unwrap_err(),
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
        let e = se3::exp(&Vector6::new(t, 0.0, 0.0, 1.0, 2.0, 3.0)).unwrap_err();
        assert!(invalid_naming(&e, &["SE(3)", "lost to rounding"]));
        let xi = so::hat_n(&[t, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!(invalid_naming(
            &so::exp(&xi).unwrap_err(),
            &["lost to rounding"]
        ));
        let eta = so::hat_n(&[0.0, 1.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!(invalid_naming(&so::dexp(&xi, &eta).unwrap_err(), &["dexp"]));
        // The message prints the norm compactly.
        let msg = so3::exp(&w).unwrap_err().to_string();
        assert!(msg.len() < 250, "{msg}");
        // The unchecked free functions give NaN (for the driver's guard), not a rotation.
        assert!(so3::exp_unchecked(&w).iter().all(|x| x.is_nan()));
    }
    // SE(3): a translation beyond the f64 range is an overflow error, not inf.
    let e = se3::exp(&Vector6::new(0.0, 0.0, 0.3, 1.7e308, 1.7e308, 1.7e308)).unwrap_err();
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
    // A chunk of several steps is replayed step by step: the error names the exact step.
    let e = integrate(&lifted, "splitting", &z, 1e300, 7, 7).unwrap_err();
    assert!(e.to_string().contains("step 1"), "{e}");
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

// --- Silent NaN from finite input: the pseudo-rigid family, strata, the systems (issue 16) -------

mod no_silent_nan {
    use super::invalid_naming;
    use lieflow::lie::gl;
    use lieflow::pseudo_rigid::equilibria::equilibrium_directions;
    use lieflow::pseudo_rigid::momentum;
    use lieflow::pseudo_rigid::potential::Harmonic;
    use lieflow::pseudo_rigid::reduced::{reconstruct, ReducedState};
    use lieflow::pseudo_rigid::{BiInertia, PseudoRigidBody};
    use lieflow::systems::tangent_top::relativistic::{Potential, WeakFieldTop};
    use lieflow::systems::{RollingSpheres, SphereParticle};
    use lieflow::{Error, Mat};
    use std::sync::Arc;

    fn m3(r: [[f64; 3]; 3]) -> Mat {
        Mat::from_fn(3, 3, |i, j| r[i][j])
    }
    fn x0() -> Mat {
        m3([[3.0, 0.2, 0.1], [0.1, 2.0, 0.3], [0.0, 0.2, 1.0]])
    }
    fn skew() -> Mat {
        m3([[0.0, 1.0, -2.0], [-1.0, 0.0, 0.5], [2.0, -0.5, 0.0]])
    }
    fn finite(m: &Mat) -> bool {
        (0..m.nrows()).all(|i| (0..m.ncols()).all(|j| m[(i, j)].is_finite()))
    }
    fn close(a: &Mat, b: &Mat, rel: f64) -> bool {
        (a - b).norm_l2() <= rel * b.norm_l2()
    }
    fn overflow(r: Result<impl std::fmt::Debug, Error>) -> bool {
        match r {
            Err(e) => invalid_naming(&e, &["overflow", "f64 range"]),
            Ok(v) => panic!("expected an overflow error, got {v:?}"),
        }
    }

    #[test]
    fn inertia_operators_are_scale_aware() {
        let (x, xi) = (x0(), skew());
        let b = BiInertia::new(&x).unwrap();
        let (l, r) = (b.left(&xi).unwrap(), b.right(&xi).unwrap());
        // Moderate X: the plain formula, bit for bit.
        let xxt = &x * x.transpose();
        assert_eq!(l, &xxt * &xi + &xi * &xxt);
        // 1e160·X (the fuzz case right_inertia(X=1e160·X)): A^R ~ 1e320, not representable.
        let big = BiInertia::new(&(&x * faer::Scale(1e160))).unwrap();
        assert!(overflow(big.right(&xi)));
        assert!(overflow(big.left(&xi)));
        assert!(overflow(big.ad_x(&xi)));
        assert!(overflow(big.apply(&xi, &xi)));
        // ...representable with a small ξ: the exact scaling.
        let r2 = big.right(&(&xi * faer::Scale(1e-200))).unwrap();
        assert!(close(&r2, &(&r * faer::Scale(1e120)), 1e-15));
        // right_inertia(X=<numeric#1>) of the fuzz table.
        let n1 = m3([
            [
                3.4191949199107441e199,
                1.7665638650785324e198,
                -2.3590247469698043e198,
            ],
            [
                -7.3081151741346844e198,
                3.7958424867123193e199,
                1.2550647052641494e199,
            ],
            [
                3.1607297152596162e198,
                -1.3982491943298273e199,
                3.3152618097405307e199,
            ],
        ]);
        assert!(overflow(BiInertia::new(&n1).unwrap().right(&xi)));
        // right_inertia(xi=max-float).
        assert!(overflow(b.right(&(&xi * faer::Scale(f64::MAX / 2.0)))));
        // Tiny X: underflow-free (XXᵀ alone would be 0 below ~1e-162).
        let tiny = BiInertia::new(&(&x * faer::Scale(1e-170))).unwrap();
        let lt = tiny.left(&(&xi * faer::Scale(1e300))).unwrap();
        assert!(close(&lt, &(&l * faer::Scale(1e-40)), 1e-15));
        assert!(finite(&tiny.matrix()));
    }

    #[test]
    fn quadratic_form_and_eigenvalues_overflow_as_typed_errors() {
        let (x, xi) = (x0(), skew());
        let b = BiInertia::new(&x).unwrap();
        let q = b.quadratic_form(&xi, &xi).unwrap();
        // bi_inertia_quadratic_form(eta=1e300·…) and (X=1e300·…), bi_inertia_eigen(X=1e300·…).
        assert!(overflow(b.quadratic_form(&xi, &(&xi * faer::Scale(1e300)))));
        let huge = BiInertia::new(&(&x * faer::Scale(1e300))).unwrap();
        assert!(overflow(huge.quadratic_form(&xi, &xi)));
        assert!(overflow(huge.eigen()));
        // Representable extremes: exact scaling.
        let q2 = huge
            .quadratic_form(&(&xi * faer::Scale(1e-300)), &(&xi * faer::Scale(1e-300)))
            .unwrap();
        assert!((q2 - q).abs() <= 1e-13 * q, "{q2} {q}");
        let (ev, _) = BiInertia::new(&(&x * faer::Scale(1e150)))
            .unwrap()
            .eigen()
            .unwrap();
        assert!(ev.iter().all(|v| v.is_finite() && *v > 0.0));
        // equilibrium_directions(a=1e300·…): eigenvalues (a_i ± a_j)² overflow.
        assert!(overflow(equilibrium_directions(&[3e300, 2e300, 1e300])));
        let d = equilibrium_directions(&[3e150, 2e150, 1e150]).unwrap();
        assert!((d[0].eigenvalues[0] - 1e300).abs() < 1e286);
    }

    #[test]
    fn reconstruct_at_tiny_semi_axes() {
        // reconstruct(a=<numeric#0>): (a_i − a_j)² underflows, Ω ~ 1e376 is not representable
        // but P = R(ΩA − AΛ)Sᵀ ~ 1e188 is.
        let a = vec![
            4.480262692850076e-191,
            1.828685890397971e-188,
            5.854556749629787e-189,
        ];
        let st = |a: Vec<f64>| ReducedState {
            a,
            p_a: vec![0.0; 3],
            p_omega: skew(),
            p_lambda: skew() * faer::Scale(0.5),
        };
        let i3 = Mat::identity(3, 3);
        let (x, p) = reconstruct(&i3, &i3, &st(a.clone())).unwrap();
        assert!(finite(&x) && finite(&p));
        // P is of degree −1 in a: compare with the same state at a·2^600.
        let c = 2f64.powi(600);
        let (_, p2) = reconstruct(&i3, &i3, &st(a.iter().map(|v| v * c).collect())).unwrap();
        assert!(close(&p, &(&p2 * faer::Scale(c)), 1e-12));
        assert!(overflow(st(a).velocities()));
    }

    #[test]
    fn svd_and_stratum_at_the_ends_of_the_range() {
        // lie.stratum(tol=max-float): the tolerance is clamped to 1 (a₁ bounds every gap).
        let st = gl::stratum(&x0(), f64::MAX).unwrap();
        assert!(st.tol.is_finite());
        assert_eq!(st.multiplicities, vec![3]);
        // The hypothesis case of svd_coordinates/polar/stratum: entries up to 2 ulp below
        // f64::MAX, but a₁ = 1.7976931348623155e308 itself is representable (the other entries
        // are far below its ulp). It used to be refused only because the scale 2^⌊log₂ a⌋ was
        // computed as ∞ (log₂ rounds up to 1024); now the SVD is of X/2^1023 and exact.
        let h = m3([
            [1.7976931348623155e308, -1.407e-294, 6.394e16],
            [3.729e16, 1.381e-274, -1.311e64],
            [1e2, 3.525e277, 2.359e16],
        ]);
        let c = gl::svd_coordinates(&h).unwrap();
        assert!(c.a.iter().all(|a| a.is_finite() && *a > 0.0));
        assert_eq!(c.a[0], 1.7976931348623155e308);
        let back = gl::from_svd(&c.r, &c.a, &c.s).unwrap();
        assert!((0..3).all(|i| (0..3).all(|j| (back[(i, j)] - h[(i, j)]).abs() <= 1e-15 * c.a[0])));
        // Where a₁ really exceeds f64::MAX (√2·MAX), the overflow is named.
        let big = m3([
            [f64::MAX, f64::MAX, 0.0],
            [-f64::MAX, f64::MAX, 0.0],
            [0.0, 0.0, 1.0],
        ]);
        assert!(overflow(gl::svd_coordinates(&big)));
        assert!(overflow(gl::polar(&big)));
    }

    #[test]
    fn momenta_of_pseudo_rigid_states() {
        let body = PseudoRigidBody::new(3, Arc::new(Harmonic::new(1.5).unwrap()), true).unwrap();
        // circulation(states=<numeric#0>): X and P mix 1e148 and 1e308.
        let z0: Vec<f64> = vec![
            6.5578099962665044e148,
            -2.3524343880421662e147,
            7.4315233624879512e148,
            -2.4516313376328094e148,
            1e308,
            1.0,
            1.9571858563554551e148,
            7.2019776270555808e148,
            -1.6537738041521307e148,
            -3.1883319606807944e148,
            -2.0433781241455773e148,
            -1.4291555800578112e148,
            3.5053525021861349e148,
            -1.0137212244042475e149,
            -1.1790418371131496e147,
            -1.0,
            -1.1433022531021249e148,
            -3.4628117123365280e148,
        ];
        assert!(overflow(body.momenta(&z0)));
        let z: Vec<f64> = (0..18)
            .map(|k| (k as f64 * 0.7).sin() + if k % 4 == 0 { 2.0 } else { 0.0 })
            .collect();
        assert!(overflow(
            body.momenta(&z.iter().map(|v| v * 1e300).collect::<Vec<_>>())
        ));
        // Representable: exact scaling (L is bilinear in X and P).
        let (l, _) = body.momenta(&z).unwrap();
        let zs: Vec<f64> = z
            .iter()
            .enumerate()
            .map(|(k, v)| if k < 9 { v * 1e300 } else { v * 1e-300 })
            .collect();
        let (ls, _) = body.momenta(&zs).unwrap();
        assert!(close(&ls, &l, 1e-14));
        let x = Mat::from_fn(3, 3, |i, j| z[3 * i + j]);
        let v = Mat::from_fn(3, 3, |i, j| z[9 + 3 * i + j]);
        let big = |m: &Mat| m * faer::Scale(1e300);
        assert!(overflow(momentum::angular_momentum(&big(&x), &big(&v))));
        assert!(overflow(momentum::circulation(&big(&x), &big(&v))));
    }

    #[test]
    fn systems_refuse_or_rescale() {
        let i1 = [[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]];
        let rs = |r1: f64, m1: f64| {
            RollingSpheres::new(
                r1,
                1.3,
                [0.1, -0.2, 0.15],
                [-0.3, 0.2, 0.4],
                m1,
                3.5,
                i1,
                i1,
            )
        };
        // RollingSpheres(r1 = 1e300 / max-float / 4.8e297): eR² overflows.
        for r1 in [0.7e300, f64::MAX, 4.768283108120774e297] {
            assert!(overflow(rs(r1, 2.0)));
        }
        // m1 = max-float: e = m₁m₂/(m₁ + m₂) without overflow.
        let heavy = rs(0.7, f64::MAX).unwrap();
        assert!((heavy.reduced_mass() - 3.5).abs() < 1e-12);
        // Observables refuse states outside SO(3)² × S² × R⁶ (zeros, 1e-170·z, 1e300·z).
        let sys = rs(0.7, 2.0).unwrap();
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let z = sys
            .state(id, id, [1.0, 0.0, 0.0], [1.1, -0.6, 0.8], [-0.4, 0.9, 0.5])
            .unwrap();
        assert!(sys
            .accelerations(&z)
            .unwrap()
            .iter()
            .flatten()
            .all(|v| v.is_finite()));
        for s in [0.0, 1e-170, 1e300] {
            let zs: Vec<f64> = z.iter().map(|v| v * s).collect();
            assert!(matches!(
                sys.accelerations(&zs),
                Err(Error::NotInGroup { .. })
            ));
            assert!(matches!(sys.udot(&zs), Err(Error::NotInGroup { .. })));
            assert!(matches!(
                sys.spatial_momenta(&zs),
                Err(Error::NotInGroup { .. })
            ));
            assert!(matches!(
                sys.angular_momentum(&zs),
                Err(Error::NotInGroup { .. })
            ));
        }
        // A valid configuration with velocities at the end of the range: finite, or an overflow
        // error.
        let mut zb = z.clone();
        for f in [1e300, 1e307, 1.5e308] {
            zb[21..].copy_from_slice(&z[21..].iter().map(|v| v * f).collect::<Vec<_>>());
            zb[21..]
                .iter_mut()
                .for_each(|v| *v = v.clamp(-f64::MAX, f64::MAX));
            match sys.angular_momentum(&zb) {
                Ok(j) => assert!(j.iter().all(|v| v.is_finite())),
                Err(e) => assert!(invalid_naming(&e, &["overflow"]), "{e}"),
            }
        }
        // WeakFieldTop.angular_momentum(states=1e300·…), scale-aware.
        let wf = WeakFieldTop::new(1.0, 1e-3, Potential::point_mass(1e-4).unwrap()).unwrap();
        assert!(overflow(
            wf.angular_momentum(&[1e300, 0.5e300, 0.1, 0.2e300, 1e300, 0.3])
        ));
        let l = wf
            .angular_momentum(&[1e300, 0.0, 0.1, 0.0, 1e-300, 0.3])
            .unwrap();
        assert_eq!(l, 1.0);
        // SphereParticle.from_spherical(states=<numeric#0>): u is not a unit vector.
        let sp = SphereParticle::new(2.0, 1.5, 9.81).unwrap();
        let u = [
            1.3220016008497747e282,
            2.5698777641569983e282,
            3.2081448633123943e282,
        ];
        let l3 = [
            2.4579397683821775e282,
            -2.2635960921590879e282,
            2.6865553957306928e282,
        ];
        assert!(matches!(
            sp.from_spherical(&[u, l3].concat()),
            Err(Error::InvalidArgument { .. })
        ));
    }
}
