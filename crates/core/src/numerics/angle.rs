//! Rotation angles in floating point: the rule of every exponential-type map
//! ([`ANGLE_ROUNDING_TOL`], [`EXP_MAX_NORM`]) and (sin θ, cos θ) under it ([`angle_sin_cos`]).

/// The one rule of every exponential-type map (so(n) and so(3) exp, dexp, the so(3) Jacobians
/// and their inverses, the SE(3) exp): a rotation angle θ is only determined by its floating-point
/// input to about ε_mach·θ (a relative change of one rounding unit in ξ turns exp ξ by that much,
/// and every evaluation of |ξ| makes such a change), so the maps refuse |ξ| >
/// [`EXP_MAX_NORM`] = [`ANGLE_ROUNDING_TOL`]/ε_mach ≈ 2.25e14, where more than
/// [`ANGLE_ROUNDING_TOL`] rad of the angle is lost to rounding, and compute scale-safely below
/// it. Maps that stay well defined for every |ξ| (the Cayley maps, whose angle 2 atan(|ξ|/2)
/// tends to π) are computed scale-safely for every finite ξ instead.
pub const ANGLE_ROUNDING_TOL: f64 = 0.05;

/// Largest |ξ| accepted by the exponential-type maps (see [`ANGLE_ROUNDING_TOL`]):
/// 0.05/ε_mach ≈ 2.25e14.
pub const EXP_MAX_NORM: f64 = ANGLE_ROUNDING_TOL / f64::EPSILON;

/// (sin θ, cos θ) of a rotation angle for unchecked inner loops (exact sub-flows), by the
/// platform's `sin_cos` (exact argument reduction): NaN beyond [`EXP_MAX_NORM`] (where the angle
/// is lost to rounding, see [`ANGLE_ROUNDING_TOL`]) and for a non-finite θ, so that the
/// integration driver's finiteness guard reports the step instead of a meaningless rotation.
/// The SIMD lanes' polynomial form is [`super::simd::lane_sin_cos`].
#[inline]
pub fn angle_sin_cos(theta: f64) -> (f64, f64) {
    if theta.abs() <= EXP_MAX_NORM {
        theta.sin_cos()
    } else {
        (f64::NAN, f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// libm's (sin θ, cos θ) up to and at the bound, NaN beyond it and for non-finite θ.
    #[test]
    fn the_rule_of_the_angle() {
        for theta in [0.0, -0.0, 1e-300, 0.3, -2.5, 1e6, -1e14, EXP_MAX_NORM] {
            assert_eq!(angle_sin_cos(theta), theta.sin_cos(), "θ = {theta}");
        }
        for theta in [
            EXP_MAX_NORM * (1.0 + f64::EPSILON),
            -1e15,
            f64::INFINITY,
            f64::NAN,
        ] {
            let (s, c) = angle_sin_cos(theta);
            assert!(s.is_nan() && c.is_nan(), "θ = {theta}");
        }
        assert!((EXP_MAX_NORM * f64::EPSILON - ANGLE_ROUNDING_TOL).abs() < 1e-17);
    }
}
