//! Rotation interop: unit quaternions and Euler angles ↔ rotation matrices, in the conventions of
//! `scipy.spatial.transform.Rotation` (so that values pass between the two unchanged).
//!
//! **Quaternions** are Hamilton quaternions stored scalar first, q = (w, x, y, z) ([`Quat`]); the
//! rotation by θ about the unit axis a is q = (cos θ/2, sin θ/2 · a), and it acts on vectors
//! by v ↦ q v q̄ (an active rotation: R(q) v), so that q₁q₂ ↦ R(q₁) R(q₂) ([`quaternion_multiply`]).
//! q and −q are the same rotation; every quaternion this module returns is *canonical*
//! ([`canonical`]): w ≥ 0, and where w = 0 the first non-zero of x, y, z is positive — scipy's
//! `as_quat(canonical=True)`.
//!
//! **Euler angles** follow scipy's sequence strings ([`EulerSequence`]): three axis letters,
//! upper case for *intrinsic* rotations (about the axes of the rotating frame: "XYZ" is
//! R = Rx(α) Ry(β) Rz(γ)), lower case for *extrinsic* ones (about the fixed axes: "xyz" is
//! R = Rz(γ) Ry(β) Rx(α)); the angles (α, β, γ) are in radians and in the order of the letters.
//! So intrinsic "XYZ" with (α, β, γ) is extrinsic "zyx" with (γ, β, α)
//! ([`EulerSequence::reversed`]). All 12 sequences are allowed: the proper-Euler ones (first and
//! third axis equal: "ZXZ", "XYX", …) and the Tait–Bryan ones (three different axes: "XYZ",
//! "ZYX", …), in both spellings.
//!
//! The sources: Shepperd, "Quaternion from rotation matrix", J. Guidance and Control 1 (1978)
//! 223–224 (the stable choice among four formulas, [`matrix_to_quaternion`]); Bernardes &
//! Viollet, "Quaternion to Euler angles conversion: a direct, general and computationally
//! efficient method", PLoS ONE 17 (2022) e0276302 (the angles of every sequence from one
//! formula, [`quaternion_to_euler`]), which is also what scipy implements; its ranges and its
//! treatment of gimbal lock are scipy's (see [`quaternion_to_euler`] and [`GIMBAL_LOCK_TOL`]).

use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt;
use std::str::FromStr;

use nalgebra::Matrix3;

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so3;

/// A quaternion (w, x, y, z), scalar first (see the module documentation).
pub type Quat = [f64; 4];

/// Half-width of the gimbal-lock band, scipy's: [`quaternion_to_euler`] treats a middle angle
/// within 1e-7 rad of its singular values (0 or π for proper-Euler sequences, ±π/2 for
/// Tait–Bryan ones) as gimbal lock and sets the third angle to zero.
pub const GIMBAL_LOCK_TOL: f64 = 1e-7;

/// The allowed sequence spellings, for error messages.
const SEQUENCE_FORMS: &str = "3 axis letters from x, y, z, all upper case for intrinsic \
    rotations (e.g. \"ZXZ\", \"XYZ\") or all lower case for extrinsic ones (e.g. \"zxz\", \
    \"xyz\"), no two consecutive letters equal: one of the 6 proper-Euler sequences (XYX, XZX, \
    YXY, YZY, ZXZ, ZYZ) or the 6 Tait–Bryan sequences (XYZ, XZY, YXZ, YZX, ZXY, ZYX)";

/// An Euler-angle sequence in scipy's spelling (see the module documentation): three axes
/// (0 = x, 1 = y, 2 = z) with no two consecutive ones equal, intrinsic (upper case, e.g.
/// "ZXZ") or extrinsic (lower case, e.g. "zxz"). Parsed by [`str::parse`] (errors
/// [`Error::InvalidArgument`] naming the allowed forms) and printed back by `Display`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EulerSequence {
    axes: [usize; 3],
    intrinsic: bool,
}

impl EulerSequence {
    /// The sequence of `axes` (each 0, 1 or 2, no two consecutive equal), intrinsic or
    /// extrinsic; [`Error::InvalidArgument`] otherwise.
    pub fn new(axes: [usize; 3], intrinsic: bool) -> Result<Self> {
        if axes.iter().any(|&a| a > 2) || axes[0] == axes[1] || axes[1] == axes[2] {
            return Err(Error::invalid(
                "seq",
                format!("axes {axes:?} (0 = x, 1 = y, 2 = z): expected {SEQUENCE_FORMS}"),
            ));
        }
        Ok(EulerSequence { axes, intrinsic })
    }

    /// The axes in the order of the angles (0 = x, 1 = y, 2 = z).
    pub fn axes(&self) -> [usize; 3] {
        self.axes
    }

    /// Whether the rotations are about the axes of the rotating frame (upper case).
    pub fn is_intrinsic(&self) -> bool {
        self.intrinsic
    }

    /// Whether the first and third axes are equal (a proper-Euler sequence such as "ZXZ"; else
    /// Tait–Bryan, such as "XYZ").
    pub fn is_proper(&self) -> bool {
        self.axes[0] == self.axes[2]
    }

    /// The same rotations spelled the other way: the axes reversed and intrinsic ↔ extrinsic
    /// ("XYZ" ↔ "zyx"). Angles (α, β, γ) in `self` are (γ, β, α) in the result, since
    /// Rx(α) Ry(β) Rz(γ) is both.
    pub fn reversed(&self) -> Self {
        let [a, b, c] = self.axes;
        EulerSequence {
            axes: [c, b, a],
            intrinsic: !self.intrinsic,
        }
    }

    /// All 24 spellings: the 12 sequences, intrinsic then extrinsic.
    pub fn all() -> impl Iterator<Item = EulerSequence> {
        [true, false].into_iter().flat_map(|intrinsic| {
            (0..27).filter_map(move |n| {
                EulerSequence::new([n / 9, (n / 3) % 3, n % 3], intrinsic).ok()
            })
        })
    }
}

impl FromStr for EulerSequence {
    type Err = Error;

    /// Parses scipy's spelling: "XYZ", "ZXZ" (intrinsic), "xyz", "zxz" (extrinsic).
    fn from_str(s: &str) -> Result<Self> {
        let n = s.chars().count();
        let shown = if n <= 16 {
            format!("{s:?}")
        } else {
            format!("a string of {n} characters")
        };
        let fail = |reason: String| {
            Error::invalid(
                "seq",
                format!("{reason}; expected {SEQUENCE_FORMS}; got {shown}"),
            )
        };
        if n != 3 {
            return Err(fail(format!("an Euler sequence has 3 letters, not {n}")));
        }
        let mut axes = [0; 3];
        let mut upper = [false; 3];
        for (k, ch) in s.chars().enumerate() {
            (axes[k], upper[k]) = match ch {
                'x' => (0, false),
                'y' => (1, false),
                'z' => (2, false),
                'X' => (0, true),
                'Y' => (1, true),
                'Z' => (2, true),
                _ => return Err(fail(format!("{ch:?} is not an axis"))),
            };
        }
        if upper[0] != upper[1] || upper[1] != upper[2] {
            return Err(fail(
                "upper case (intrinsic) and lower case (extrinsic) letters are mixed".into(),
            ));
        }
        if axes[0] == axes[1] || axes[1] == axes[2] {
            return Err(fail("two consecutive axes are equal".into()));
        }
        Ok(EulerSequence {
            axes,
            intrinsic: upper[0],
        })
    }
}

impl fmt::Display for EulerSequence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for &a in &self.axes {
            let c = [b'x', b'y', b'z'][a] as char;
            write!(
                f,
                "{}",
                if self.intrinsic {
                    c.to_ascii_uppercase()
                } else {
                    c
                }
            )?;
        }
        Ok(())
    }
}

/// The canonical one of ±q (scipy's `as_quat(canonical=True)`): w ≥ 0, and where w = 0 the
/// first non-zero of x, y, z positive. Zeros come out as +0.
#[inline]
pub fn canonical(q: &Quat) -> Quat {
    let flip = q[0] < 0.0
        || (q[0] == 0.0
            && (q[1] < 0.0 || (q[1] == 0.0 && (q[2] < 0.0 || (q[2] == 0.0 && q[3] < 0.0)))));
    let s = if flip { -1.0 } else { 1.0 };
    // `+ 0.0` turns −0 into +0.
    q.map(|c| s * c + 0.0)
}

/// The Hamilton product p q (scalar first): (p_w q_w − p·q, p_w q + q_w p + p × q), so that
/// R(p q) = R(p) R(q).
#[inline]
pub fn quaternion_multiply(p: &Quat, q: &Quat) -> Quat {
    let [pw, px, py, pz] = *p;
    let [qw, qx, qy, qz] = *q;
    [
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + qw * px + (py * qz - pz * qy),
        pw * qy + qw * py + (pz * qx - px * qz),
        pw * qz + qw * pz + (px * qy - py * qx),
    ]
}

/// The rotation matrix of a unit quaternion (w, x, y, z):
/// R = [[w²+x²−y²−z², 2(xy−wz), 2(xz+wy)], [2(xy+wz), w²−x²+y²−z², 2(yz−wx)],
/// [2(xz−wy), 2(yz+wx), w²−x²−y²+z²]] (the homogeneous form, as scipy's `as_matrix`). No checks:
/// for a non-unit q this is |q|² times a rotation ([`from_quaternion`] normalises first).
#[inline]
pub fn quaternion_to_matrix(q: &Quat) -> Matrix3<f64> {
    let [w, x, y, z] = *q;
    let (w2, x2, y2, z2) = (w * w, x * x, y * y, z * z);
    let (xy, zw, xz, yw, yz, xw) = (x * y, z * w, x * z, y * w, y * z, x * w);
    Matrix3::new(
        w2 + x2 - y2 - z2,
        2.0 * (xy - zw),
        2.0 * (xz + yw),
        2.0 * (xy + zw),
        w2 - x2 + y2 - z2,
        2.0 * (yz - xw),
        2.0 * (xz - yw),
        2.0 * (yz + xw),
        w2 - x2 - y2 + z2,
    )
}

/// The canonical unit quaternion of a rotation matrix by Shepperd's method (1978): of the four
/// proportional formulas 4w² = 1 + tr R, 4x² = 1 − tr R + 2R₀₀, … the one with the largest of
/// (R₀₀, R₁₁, R₂₂, tr R) is used (first on ties, as scipy): that picks the largest of
/// 4w², 4x², 4y², 4z² (they sum to 4, so the leading component is ≥ 1 before normalisation and
/// nothing small is divided by); the other components come from the sums and differences of the
/// off-diagonal pairs, then the result is normalised (which also absorbs a rounding-level
/// defect of R) and made [`canonical`].
///
/// No checks: `r` is assumed to be a rotation (use [`to_quaternion`]).
pub fn matrix_to_quaternion(r: &Matrix3<f64>) -> Quat {
    let tr = r[(0, 0)] + r[(1, 1)] + r[(2, 2)];
    let decision = [r[(0, 0)], r[(1, 1)], r[(2, 2)], tr];
    let mut choice = 0;
    for (k, &d) in decision.iter().enumerate().skip(1) {
        if d > decision[choice] {
            choice = k;
        }
    }
    // (w, x, y, z) with v = (x, y, z) at 1 + axis.
    let mut q = [0.0; 4];
    if choice == 3 {
        q[0] = 1.0 + tr;
        q[1] = r[(2, 1)] - r[(1, 2)];
        q[2] = r[(0, 2)] - r[(2, 0)];
        q[3] = r[(1, 0)] - r[(0, 1)];
    } else {
        let i = choice;
        let j = (i + 1) % 3;
        let k = (j + 1) % 3;
        q[1 + i] = 1.0 - tr + 2.0 * r[(i, i)];
        q[1 + j] = r[(j, i)] + r[(i, j)];
        q[1 + k] = r[(k, i)] + r[(i, k)];
        q[0] = r[(k, j)] - r[(j, k)];
    }
    let n = super::scaled_norm(q.iter());
    canonical(&q.map(|c| c / n))
}

/// [`matrix_to_quaternion`] of a checked rotation: `r` finite ([`Error::NonFinite`]) with
/// ‖RᵀR − I‖_F and |det R − 1| at most [`so3::ROTATION_TOL`] ([`Error::NotInGroup`]), read as
/// the nearest rotation ([`so3::rotation_of`]). Returns the canonical unit quaternion
/// (w, x, y, z) with w ≥ 0.
pub fn to_quaternion(r: &Matrix3<f64>) -> Result<Quat> {
    Ok(matrix_to_quaternion(&so3::rotation_of("R", r)?))
}

/// q/|q|, computed scale-safely (q is first divided by its largest |component|, so quaternions
/// of any finite size, 1e-310 or 1e300, are normalised without underflow or overflow). Errors:
/// [`Error::NonFinite`] for NaN/inf, [`Error::InvalidArgument`] for the zero quaternion (no
/// rotation).
pub fn normalize_quaternion(q: &Quat) -> Result<Quat> {
    check::finite_slice("q", q)?;
    let m = q.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if m == 0.0 {
        return Err(Error::invalid(
            "q",
            "the zero quaternion is no rotation: a quaternion needs |q| > 0 (it is normalised)",
        ));
    }
    let s = q.map(|c| c / m);
    let n = super::scaled_norm(s.iter());
    Ok(s.map(|c| c / n))
}

/// The rotation matrix of a quaternion (w, x, y, z) of any non-zero size: q is normalised
/// ([`normalize_quaternion`], as scipy's `from_quat`), then [`quaternion_to_matrix`]. Both q
/// and −q give the same rotation. Errors: [`Error::NonFinite`], [`Error::InvalidArgument`] (zero).
pub fn from_quaternion(q: &Quat) -> Result<Matrix3<f64>> {
    Ok(quaternion_to_matrix(&normalize_quaternion(q)?))
}

/// The unit quaternion of the Euler angles `angles` (radians, in the order of the letters) of
/// `seq`: with e_a(θ) = (cos θ/2, sin θ/2 · e_a) the elementary rotation about axis a,
/// q = e₀(α) e₁(β) e₂(γ) for an intrinsic sequence and q = e₂(γ) e₁(β) e₀(α) for an extrinsic
/// one (scipy's `from_euler`). Not made canonical. No checks (see [`from_euler`]).
pub fn euler_to_quaternion(angles: &[f64; 3], seq: EulerSequence) -> Quat {
    let elementary = |k: usize| {
        let (s, c) = (0.5 * angles[k]).sin_cos();
        let mut e = [c, 0.0, 0.0, 0.0];
        e[1 + seq.axes[k]] = s;
        e
    };
    let mut q = elementary(0);
    for k in 1..3 {
        let e = elementary(k);
        q = if seq.intrinsic {
            quaternion_multiply(&q, &e)
        } else {
            quaternion_multiply(&e, &q)
        };
    }
    q
}

/// The Euler angles of `seq` of the rotation of the unit quaternion `q` (either sign), by the
/// direct method of Bernardes & Viollet (2022), as scipy's `as_euler`.
///
/// The method, for an extrinsic sequence (i, j, k) (an intrinsic one is the extrinsic one of the
/// reversed axes, with the angles reversed): for a proper-Euler sequence (k = i, and k is taken
/// as the third axis, ε = ±1 the parity of (i, j, k)) the quaternion's components are
/// (a, b, c, d) = (w, q_i, q_j, ε q_k); a Tait–Bryan sequence is turned into a proper one by a
/// rotation of λ = π/2 about j, (a, b, c, d) = (w − q_j, q_i + ε q_k, q_j + w, ε q_k − q_i)
/// (up to a factor √2). Then the middle angle is θ₂ = 2 atan2(|(c, d)|, |(a, b)|) (no arcsine
/// of a rounded cosine), θ₊ = atan2(b, a), θ₋ = atan2(d, c), the outer angles are θ₊ ∓ θ₋ and,
/// for Tait–Bryan, the third is multiplied by ε and λ is subtracted from θ₂.
///
/// Ranges (scipy's): the first and third angles in [−π, π]; the middle one in [0, π] for
/// proper-Euler sequences and in [−π/2, π/2] for Tait–Bryan ones.
///
/// Gimbal lock (scipy's rule): where θ₂ before the shift by λ is within [`GIMBAL_LOCK_TOL`] of 0
/// or π only the sum or the difference of the outer angles is determined; the **third** angle
/// (the last of the sequence) is then set to 0 and the first carries the whole rotation about
/// the common axis (2θ₊ at 0, ±2θ₋ at π). scipy warns there; this function does not (the result
/// is a valid, deterministic decomposition; never NaN). Within the band the returned angles
/// reproduce R only to about |θ₂ − θ₂*| ≤ 1e-7 rad (θ₂* the singular value), exactly as scipy's;
/// at the singular values themselves, to rounding.
pub fn quaternion_to_euler(q: &Quat, seq: EulerSequence) -> [f64; 3] {
    let extrinsic = !seq.intrinsic;
    let [i, j, mut k] = if extrinsic {
        seq.axes
    } else {
        let [a, b, c] = seq.axes;
        [c, b, a]
    };
    let symmetric = i == k;
    if symmetric {
        k = 3 - i - j;
    }
    let (ii, jj, kk) = (i as i64, j as i64, k as i64);
    let sign = ((ii - jj) * (jj - kk) * (kk - ii) / 2) as f64;
    let w = q[0];
    let v = [q[1], q[2], q[3]];
    let (a, b, c, d) = if symmetric {
        (w, v[i], v[j], v[k] * sign)
    } else {
        (w - v[j], v[i] + v[k] * sign, v[j] + w, v[k] * sign - v[i])
    };

    let (first, third) = if extrinsic { (0, 2) } else { (2, 0) };
    let mut angles = [0.0; 3];
    angles[1] = 2.0 * c.hypot(d).atan2(a.hypot(b));
    let half_sum = b.atan2(a);
    let half_diff = d.atan2(c);
    if angles[1].abs() <= GIMBAL_LOCK_TOL {
        angles[0] = 2.0 * half_sum;
    } else if (angles[1] - PI).abs() <= GIMBAL_LOCK_TOL {
        angles[0] = 2.0 * half_diff * if extrinsic { -1.0 } else { 1.0 };
    } else {
        angles[first] = half_sum - half_diff;
        angles[third] = half_sum + half_diff;
    }
    if !symmetric {
        angles[third] *= sign;
        angles[1] -= FRAC_PI_2;
    }
    angles.map(|t| {
        if t < -PI {
            t + 2.0 * PI
        } else if t > PI {
            t - 2.0 * PI
        } else {
            t
        }
    })
}

/// The Euler angles of `seq` of a checked rotation `r` (radians, in the order of the letters):
/// [`quaternion_to_euler`] of [`to_quaternion`] (ranges and gimbal lock documented there).
/// Errors: [`Error::NonFinite`], [`Error::NotInGroup`] (not a rotation).
pub fn to_euler(r: &Matrix3<f64>, seq: EulerSequence) -> Result<[f64; 3]> {
    Ok(quaternion_to_euler(&to_quaternion(r)?, seq))
}

/// The rotation matrix of the Euler angles `angles` of `seq` (radians, in the order of the
/// letters; any values, no range is required): intrinsic "XYZ" is Rx(α) Ry(β) Rz(γ), extrinsic
/// "xyz" is Rz(γ) Ry(β) Rx(α) (through [`euler_to_quaternion`]).
///
/// Errors: [`Error::NonFinite`]; [`Error::InvalidArgument`] for an angle beyond
/// [`super::EXP_MAX_NORM`] ≈ 2.25e14 rad, where more than [`super::ANGLE_ROUNDING_TOL`] rad of
/// it is lost to rounding (the rule of every exponential-type map of [`crate::lie`]; each
/// elementary rotation is exp(θ ê_a)).
pub fn from_euler(angles: &[f64; 3], seq: EulerSequence) -> Result<Matrix3<f64>> {
    check::finite_slice("angles", angles)?;
    for t in angles {
        super::check_exp_norm("angles", "from_euler", t.abs())?;
    }
    Ok(quaternion_to_matrix(&euler_to_quaternion(angles, seq)))
}
