//! Rotation interop (lie::rotations): quaternions and Euler angles against independent routes
//! (Rodrigues' exp, products of elementary rotations, closed forms), round trips on random
//! rotations for all 24 sequence spellings, gimbal lock, ranges, and every error path.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use lieflow::lie::rotations::{
    self, canonical, from_euler, from_quaternion, matrix_to_quaternion, normalize_quaternion,
    quaternion_multiply, quaternion_to_euler, quaternion_to_matrix, to_euler, to_quaternion,
    EulerSequence, Quat, GIMBAL_LOCK_TOL,
};
use lieflow::lie::so3;
use lieflow::Error;
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;

/// The elementary rotation about axis `a` (0, 1, 2) by `t`, by Rodrigues' formula.
fn elementary(a: usize, t: f64) -> Matrix3<f64> {
    let mut w = Vector3::zeros();
    w[a] = t;
    so3::exp_unchecked(&w)
}

/// The rotation of Euler angles by products of elementary matrices (the definition).
fn euler_reference(angles: &[f64; 3], seq: EulerSequence) -> Matrix3<f64> {
    let [a, b, c] = seq.axes();
    let (r0, r1, r2) = (
        elementary(a, angles[0]),
        elementary(b, angles[1]),
        elementary(c, angles[2]),
    );
    if seq.is_intrinsic() {
        r0 * r1 * r2
    } else {
        r2 * r1 * r0
    }
}

fn seq(s: &str) -> EulerSequence {
    s.parse().unwrap()
}

fn qdist(p: &Quat, q: &Quat) -> f64 {
    p.iter()
        .zip(q)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn vec3(r: f64) -> impl Strategy<Value = Vector3<f64>> {
    prop::array::uniform3(-r..r).prop_map(Vector3::from)
}

/// Rotations of every angle in [0, π] (|w| up to 4 wraps past π).
fn rot() -> impl Strategy<Value = Matrix3<f64>> {
    vec3(4.0).prop_map(|w| so3::exp_unchecked(&w))
}

fn angle_in_range(t: f64) -> bool {
    (-PI..=PI).contains(&t)
}

#[test]
fn sequences_parse_print_and_enumerate() {
    let all: Vec<EulerSequence> = EulerSequence::all().collect();
    assert_eq!(all.len(), 24);
    let names: Vec<String> = all.iter().map(|s| s.to_string()).collect();
    for name in [
        "XYX", "XYZ", "XZX", "XZY", "YXY", "YXZ", "YZX", "YZY", "ZXY", "ZXZ", "ZYX", "ZYZ",
    ] {
        assert!(names.contains(&name.to_string()), "{name}");
        assert!(names.contains(&name.to_lowercase()), "{name}");
    }
    for s in &all {
        assert_eq!(&s.to_string().parse::<EulerSequence>().unwrap(), s);
        assert_eq!(s.reversed().reversed(), *s);
        assert_eq!(s.is_proper(), s.axes()[0] == s.axes()[2]);
    }
    assert_eq!(all.iter().filter(|s| s.is_proper()).count(), 12);
    assert_eq!(seq("XYZ").reversed(), seq("zyx"));
    assert!(seq("ZXZ").is_intrinsic() && !seq("zxz").is_intrinsic());
    assert_eq!(seq("zxz").axes(), [2, 0, 2]);
}

#[test]
fn bad_sequences_are_refused_naming_the_allowed_forms() {
    for bad in [
        "", "x", "xy", "xyzx", "xxy", "XYY", "xYz", "Xyz", "abc", "xyw", "x y", "XYZ ", "ξyz",
        "zyx\0",
    ] {
        match bad.parse::<EulerSequence>() {
            Err(Error::InvalidArgument { what, message }) => {
                assert_eq!(what, "seq");
                assert!(
                    message.contains("upper case") && message.contains("ZXZ"),
                    "{message}"
                );
            }
            other => panic!("{bad:?}: {other:?}"),
        }
    }
    let long = "x".repeat(1000);
    let Err(Error::InvalidArgument { message, .. }) = long.parse::<EulerSequence>() else {
        panic!()
    };
    assert!(
        message.len() < 700,
        "the message does not echo a long input"
    );
    assert!(EulerSequence::new([0, 0, 1], true).is_err());
    assert!(EulerSequence::new([0, 1, 3], true).is_err());
    assert!(EulerSequence::new([0, 1, 0], false).is_ok());
}

#[test]
fn known_values_quarter_turn_about_z() {
    let r = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    let q = to_quaternion(&r).unwrap();
    let s = FRAC_PI_4.sin();
    assert!(qdist(&q, &[s, 0.0, 0.0, s]) < 1e-16, "{q:?}");
    assert!((from_quaternion(&q).unwrap() - r).norm() < 1e-15);
    assert!((r - so3::exp_unchecked(&Vector3::new(0.0, 0.0, FRAC_PI_2))).norm() < 1e-15);
    // It maps x to y.
    assert!((quaternion_to_matrix(&q) * Vector3::x() - Vector3::y()).norm() < 1e-15);
    for (name, want) in [
        ("xyz", [0.0, 0.0, FRAC_PI_2]),
        ("XYZ", [0.0, 0.0, FRAC_PI_2]),
        ("ZYX", [FRAC_PI_2, 0.0, 0.0]),
        ("zyx", [FRAC_PI_2, 0.0, 0.0]),
        // Gimbal lock of a proper sequence (middle angle 0): the first angle takes the turn.
        ("ZXZ", [FRAC_PI_2, 0.0, 0.0]),
        ("zyz", [FRAC_PI_2, 0.0, 0.0]),
    ] {
        let got = to_euler(&r, seq(name)).unwrap();
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-15,
                "{name}: {got:?} vs {want:?}"
            );
        }
    }
    // A half turn about x: w = 0, canonical sign x > 0.
    let r = elementary(0, PI);
    let q = to_quaternion(&r).unwrap();
    assert!(qdist(&q, &[0.0, 1.0, 0.0, 0.0]) < 1e-16, "{q:?}");
    // The exact half turn about y (w = 0: y > 0), and one rounded from exp(−π e_y), whose
    // w = cos(π/2) rounds to +6e-17, so the sign follows w.
    let half_y = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, -1.0));
    assert_eq!(to_quaternion(&half_y).unwrap(), [0.0, 0.0, 1.0, 0.0]);
    let q = to_quaternion(&elementary(1, -PI)).unwrap();
    assert!(
        qdist(&q, &[0.0, 0.0, -1.0, 0.0]) < 1e-16 && q[0] > 0.0,
        "{q:?}"
    );
    assert_eq!(
        to_quaternion(&Matrix3::identity()).unwrap(),
        [1.0, 0.0, 0.0, 0.0]
    );
}

#[test]
fn yaw_pitch_roll_closed_form() {
    // Intrinsic ZYX = R = Rz(ψ) Ry(θ) Rx(φ): θ = −asin R₂₀, ψ = atan2(R₁₀, R₀₀), φ = atan2(R₂₁, R₂₂).
    let (psi, theta, phi) = (2.5, -0.7, -1.9);
    let r = elementary(2, psi) * elementary(1, theta) * elementary(0, phi);
    let closed = [
        r[(1, 0)].atan2(r[(0, 0)]),
        -r[(2, 0)].asin(),
        r[(2, 1)].atan2(r[(2, 2)]),
    ];
    let got = to_euler(&r, seq("ZYX")).unwrap();
    for k in 0..3 {
        assert!((got[k] - closed[k]).abs() < 1e-14, "{got:?} vs {closed:?}");
        assert!((got[k] - [psi, theta, phi][k]).abs() < 1e-14);
    }
}

#[test]
fn canonical_sign_and_quaternion_product() {
    assert_eq!(canonical(&[-0.5, 0.5, -0.5, 0.5]), [0.5, -0.5, 0.5, -0.5]);
    assert_eq!(canonical(&[0.0, -1.0, 0.0, 0.0]), [0.0, 1.0, 0.0, 0.0]);
    assert_eq!(canonical(&[-0.0, 0.0, -0.0, -1.0]), [0.0, 0.0, 0.0, 1.0]);
    assert!(canonical(&[-0.0, 0.0, 0.0, 1.0])[0].is_sign_positive());
    // R(p q) = R(p) R(q).
    let p = normalize_quaternion(&[0.3, -0.2, 0.9, 0.1]).unwrap();
    let q = normalize_quaternion(&[-0.5, 0.4, 0.1, -0.7]).unwrap();
    let lhs = quaternion_to_matrix(&quaternion_multiply(&p, &q));
    let rhs = quaternion_to_matrix(&p) * quaternion_to_matrix(&q);
    assert!((lhs - rhs).norm() < 1e-15);
}

#[test]
fn quaternion_of_exp_is_half_angle() {
    // exp(θ a) has the quaternion (cos θ/2, sin θ/2 a), up to the canonical sign.
    for w in [
        Vector3::new(0.3, -1.2, 2.0),
        Vector3::new(1e-9, 2e-9, -1e-9),
        Vector3::new(0.0, 0.0, PI - 1e-12),
        Vector3::new(-2.0, 0.5, 0.1),
    ] {
        let t = w.norm();
        let a = w / t;
        let (s, c) = (0.5 * t).sin_cos();
        let want = canonical(&[c, s * a.x, s * a.y, s * a.z]);
        let got = to_quaternion(&so3::exp_unchecked(&w)).unwrap();
        assert!(qdist(&got, &want) < 1e-15, "{w:?}: {got:?} vs {want:?}");
    }
}

#[test]
fn from_quaternion_normalises_any_scale() {
    let q = [0.3, -0.2, 0.9, 0.1];
    let r = from_quaternion(&q).unwrap();
    assert!(so3::is_rotation(&r, 1e-15));
    for scale in [1e-300, 1e-170, 1e160, 1e300, -1.0, -1e300] {
        let qs = q.map(|c| c * scale);
        let rs = from_quaternion(&qs).unwrap();
        assert!((rs - r).norm() < 1e-15, "scale {scale}: {rs}");
    }
    // Subnormal input has only ~10 significant digits left: the result is as good as that.
    let rs = from_quaternion(&q.map(|c| c * 1e-313)).unwrap();
    assert!(
        (rs - r).norm() < 1e-9 && so3::is_rotation(&rs, 1e-15),
        "{rs}"
    );
    // One huge and one subnormal entry.
    let r = from_quaternion(&[f64::MAX, 5e-324, 0.0, -f64::MAX]).unwrap();
    assert!(r.iter().all(|x| x.is_finite()) && so3::is_rotation(&r, 1e-15));
    let r = from_quaternion(&[0.0, 0.0, 5e-324, 0.0]).unwrap();
    assert!((r - elementary(1, PI)).norm() < 1e-15);
}

#[test]
fn error_paths() {
    let nan = f64::NAN;
    assert!(matches!(
        from_quaternion(&[0.0; 4]),
        Err(Error::InvalidArgument { ref what, .. }) if what == "q"
    ));
    assert!(matches!(
        from_quaternion(&[1.0, nan, 0.0, 0.0]),
        Err(Error::NonFinite { ref what, .. }) if what == "q"
    ));
    assert!(matches!(
        from_quaternion(&[1.0, f64::INFINITY, 0.0, 0.0]),
        Err(Error::NonFinite { .. })
    ));
    let not_rot = Matrix3::identity() * 2.0;
    let reflection = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
    let near = so3::exp_unchecked(&Vector3::new(0.1, 0.2, 0.3)) * (1.0 + 1e-8);
    let huge = Matrix3::identity() * 1e300;
    for m in [not_rot, reflection, near, huge, Matrix3::zeros()] {
        assert!(
            matches!(to_quaternion(&m), Err(Error::NotInGroup { ref what, .. }) if what == "R"),
            "{m}"
        );
        assert!(matches!(
            to_euler(&m, seq("xyz")),
            Err(Error::NotInGroup { .. })
        ));
    }
    let mut m = Matrix3::identity();
    m[(1, 2)] = nan;
    assert!(matches!(to_quaternion(&m), Err(Error::NonFinite { .. })));
    assert!(matches!(
        from_euler(&[0.1, nan, 0.2], seq("XYZ")),
        Err(Error::NonFinite { ref what, .. }) if what == "angles"
    ));
    assert!(matches!(
        from_euler(&[0.1, 1e300, 0.2], seq("XYZ")),
        Err(Error::InvalidArgument { ref what, .. }) if what == "angles"
    ));
    // Large but representable angles are fine.
    let r = from_euler(&[1e6, -1e8, 3.0], seq("zxz")).unwrap();
    assert!(so3::is_rotation(&r, 1e-14));
}

#[test]
fn intrinsic_is_extrinsic_reversed() {
    let angles = [0.4, -1.1, 2.7];
    for s in EulerSequence::all() {
        let r = from_euler(&angles, s).unwrap();
        let rev = [angles[2], angles[1], angles[0]];
        let r2 = from_euler(&rev, s.reversed()).unwrap();
        assert!((r - r2).norm() < 1e-15, "{s}");
        assert!((r - euler_reference(&angles, s)).norm() < 1e-14, "{s}");
    }
    // Concretely: intrinsic XYZ = Rx Ry Rz = extrinsic zyx with the angles reversed.
    let r = elementary(0, 0.4) * elementary(1, -1.1) * elementary(2, 2.7);
    let a = to_euler(&r, seq("XYZ")).unwrap();
    let b = to_euler(&r, seq("zyx")).unwrap();
    for k in 0..3 {
        assert!((a[k] - [0.4, -1.1, 2.7][k]).abs() < 1e-14);
        assert!((a[k] - b[2 - k]).abs() < 1e-14, "{a:?} vs {b:?}");
    }
}

/// The middle angles at gimbal lock: 0 and π for proper sequences, ±π/2 for Tait–Bryan ones.
fn singular_middles(s: EulerSequence) -> [f64; 2] {
    if s.is_proper() {
        [0.0, PI]
    } else {
        [FRAC_PI_2, -FRAC_PI_2]
    }
}

#[test]
fn gimbal_lock_third_angle_zero_and_exact_round_trip() {
    for s in EulerSequence::all() {
        for beta in singular_middles(s) {
            for (a, c) in [(0.3, 0.5), (-2.9, 2.8), (1.0, -1.0), (PI, 0.0), (0.0, 0.0)] {
                let r = from_euler(&[a, beta, c], s).unwrap();
                let got = to_euler(&r, s).unwrap();
                assert!(got.iter().all(|t| t.is_finite()), "{s}: {got:?}");
                assert_eq!(got[2], 0.0, "{s} at β = {beta}: third angle {got:?}");
                assert!((got[1] - beta).abs() < 1e-7 || (got[1] + beta).abs() < 1e-7);
                let back = from_euler(&got, s).unwrap();
                assert!((back - r).norm() < 1e-14, "{s} at β = {beta}: {got:?}");
            }
        }
    }
}

#[test]
fn inside_the_gimbal_band_the_round_trip_is_scipys() {
    // Within 1e-7 of the singular middle angle the third angle is still set to 0: the round
    // trip is then good to ~|β − β*| (as scipy); just outside the band it is exact again.
    for s in EulerSequence::all() {
        let b0 = singular_middles(s)[0];
        let dir = if s.is_proper() { 1.0 } else { -1.0 };
        let inside = b0 + dir * 0.5 * GIMBAL_LOCK_TOL;
        let r = from_euler(&[0.3, inside, 0.5], s).unwrap();
        let got = to_euler(&r, s).unwrap();
        assert_eq!(got[2], 0.0, "{s}");
        assert!((from_euler(&got, s).unwrap() - r).norm() < 1e-7, "{s}");
        let outside = b0 + dir * 4.0 * GIMBAL_LOCK_TOL;
        let r = from_euler(&[0.3, outside, 0.5], s).unwrap();
        let got = to_euler(&r, s).unwrap();
        assert!(got[2] != 0.0, "{s}");
        assert!((from_euler(&got, s).unwrap() - r).norm() < 1e-13, "{s}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn matrix_quaternion_round_trip(r in rot()) {
        let q = to_quaternion(&r).unwrap();
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        prop_assert!((n - 1.0).abs() < 1e-15);
        prop_assert!(q[0] >= 0.0);
        prop_assert_eq!(canonical(&q), q);
        prop_assert!((from_quaternion(&q).unwrap() - r).norm() < 2e-15);
        // q → R → q, from either sign.
        prop_assert!(qdist(&matrix_to_quaternion(&quaternion_to_matrix(&q)), &q) < 2e-15);
        let neg = q.map(|c| -c);
        prop_assert!((from_quaternion(&neg).unwrap() - r).norm() < 2e-15);
    }

    #[test]
    fn euler_round_trip_all_sequences(r in rot()) {
        for s in EulerSequence::all() {
            let a = to_euler(&r, s).unwrap();
            prop_assert!(a.iter().all(|t| angle_in_range(*t)), "{}: {:?}", s, a);
            if s.is_proper() {
                prop_assert!((0.0..=PI).contains(&a[1]), "{}: {:?}", s, a);
            } else {
                prop_assert!((-FRAC_PI_2..=FRAC_PI_2).contains(&a[1]), "{}: {:?}", s, a);
            }
            let back = from_euler(&a, s).unwrap();
            // Inside the gimbal band (probability ~1e-7 here) the round trip is good to ~1e-7.
            prop_assert!((back - r).norm() < 1e-13, "{}: {:?}, error {:e}", s, a,
                (back - r).norm());
            prop_assert!((euler_reference(&a, s) - r).norm() < 1e-13);
            // Through the quaternion of either sign.
            let q = to_quaternion(&r).unwrap();
            let b = quaternion_to_euler(&q.map(|c| -c), s);
            for k in 0..3 {
                let d = (a[k] - b[k]).abs();
                prop_assert!(d < 1e-13 || (d - 2.0 * PI).abs() < 1e-13, "{}: {:?} {:?}", s, a, b);
            }
            let rev = to_euler(&r, s.reversed()).unwrap();
            prop_assert!((from_euler(&[rev[2], rev[1], rev[0]], s).unwrap() - r).norm() < 1e-13);
        }
    }

    #[test]
    fn angles_in_range_are_recovered(
        a in -3.1..3.1f64,
        b in 0.01..1.55f64,
        c in -3.1..3.1f64,
        flip in any::<bool>(),
    ) {
        for s in EulerSequence::all() {
            // Middle angles inside the principal range and away from gimbal lock.
            let mid = if s.is_proper() {
                if flip { PI - b } else { b }
            } else if flip {
                -b
            } else {
                b
            };
            let got = to_euler(&from_euler(&[a, mid, c], s).unwrap(), s).unwrap();
            for (k, want) in [a, mid, c].into_iter().enumerate() {
                prop_assert!((got[k] - want).abs() < 1e-12 * (1.0 + 1.0 / b),
                    "{}: {:?} vs {:?}", s, got, [a, mid, c]);
            }
        }
    }

    #[test]
    fn euler_of_arbitrary_angles_matches_the_definition(
        a in -20.0..20.0f64,
        b in -20.0..20.0f64,
        c in -20.0..20.0f64,
    ) {
        for s in EulerSequence::all() {
            let r = from_euler(&[a, b, c], s).unwrap();
            prop_assert!((r - euler_reference(&[a, b, c], s)).norm() < 1e-13);
            prop_assert!(so3::is_rotation(&r, 1e-14));
        }
    }
}

#[test]
fn module_constants() {
    assert_eq!(GIMBAL_LOCK_TOL, 1e-7);
    // The unchecked kernels agree with the checked ones.
    let r = so3::exp_unchecked(&Vector3::new(0.3, -0.2, 0.5));
    assert_eq!(
        rotations::to_quaternion(&r).unwrap(),
        matrix_to_quaternion(&r)
    );
}

proptest! {
    /// At θ = π exactly (R = 2aaᵀ − I, symmetric) the logarithm and the canonical quaternion
    /// name the same axis: one tie rule (the first nonzero component positive).
    #[test]
    fn the_logarithm_and_the_quaternion_break_the_tie_at_pi_alike(a in vec3(1.0)) {
        prop_assume!(a.norm() > 0.1);
        let a = a / a.norm();
        let r = a * a.transpose() * 2.0 - Matrix3::identity();
        let r = (r + r.transpose()) * 0.5;
        let w = so3::log_unchecked(&r);
        let q = to_quaternion(&r).unwrap();
        let axis = Vector3::new(q[1], q[2], q[3]);
        prop_assert!((w / PI - axis).amax() <= 1e-9, "log {w:?}, quaternion {q:?}");
    }

    /// A matrix within the tolerance of SO(3) but 1e-11 off orthogonal is read as its nearest
    /// rotation: its quaternion's matrix is that rotation to round-off (a few ulps), not to 1e-11.
    #[test]
    fn a_nearly_orthogonal_matrix_is_read_as_the_nearest_rotation(
        r in rot(), e in proptest::array::uniform9(-1.0f64..1.0)
    ) {
        let m = r + Matrix3::from_row_slice(&e) * 1e-11;
        let nearest = so3::project(&m).unwrap();
        let q = to_quaternion(&m).unwrap();
        prop_assert!((from_quaternion(&q).unwrap() - nearest).amax() <= 1e-14);
        let g = so3::SO3::new(m).unwrap();
        prop_assert!((g.matrix3() - nearest).amax() <= 1e-14);
        // An exact rotation is kept as it is.
        prop_assert_eq!(*so3::SO3::new(r).unwrap().matrix3(), r);
    }
}
