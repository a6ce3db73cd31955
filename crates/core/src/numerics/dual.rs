//! Forward-mode dual numbers a + bε (ε² = 0): a kernel written over [`Real`] and evaluated at
//! x + ε dx gives its value and its directional derivative along dx, exact to round-off (no
//! step). The tangent lifts of the Legendre tops use it for the derivatives of ∂L/∂q̇ and
//! ∂L/∂q ([`crate::systems::tangent_top::relativistic`]).

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// The scalars a kernel is written over: `f64` (its value) or [`Dual`] (value and derivative).
/// Constants multiply on the right (`x * 0.5`), which for `f64` is the same number as `0.5 * x`.
pub(crate) trait Real:
    Copy
    + std::fmt::Debug
    + From<f64>
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Whether the type carries a derivative (a kernel skips the inputs' derivatives for f64).
    const DUAL: bool;
    /// a + bε (b ignored by f64).
    fn with(a: f64, b: f64) -> Self;
    /// The value a.
    fn re(self) -> f64;
    /// The derivative b (0 for f64).
    fn eps(self) -> f64;
    fn sqrt(self) -> Self;
    fn exp(self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn is_finite(self) -> bool {
        self.re().is_finite() && self.eps().is_finite()
    }
}

impl Real for f64 {
    const DUAL: bool = false;
    #[inline]
    fn with(a: f64, _b: f64) -> Self {
        a
    }
    #[inline]
    fn re(self) -> f64 {
        self
    }
    #[inline]
    fn eps(self) -> f64 {
        0.0
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn exp(self) -> Self {
        f64::exp(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
}

/// a + bε.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Dual {
    pub(crate) a: f64,
    pub(crate) b: f64,
}

impl From<f64> for Dual {
    #[inline]
    fn from(a: f64) -> Self {
        Dual { a, b: 0.0 }
    }
}

impl Real for Dual {
    const DUAL: bool = true;
    #[inline]
    fn with(a: f64, b: f64) -> Self {
        Dual { a, b }
    }
    #[inline]
    fn re(self) -> f64 {
        self.a
    }
    #[inline]
    fn eps(self) -> f64 {
        self.b
    }
    #[inline]
    fn sqrt(self) -> Self {
        let r = self.a.sqrt();
        Dual {
            a: r,
            b: self.b / (2.0 * r),
        }
    }
    #[inline]
    fn exp(self) -> Self {
        let e = self.a.exp();
        Dual {
            a: e,
            b: e * self.b,
        }
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.a.sin_cos();
        (
            Dual {
                a: s,
                b: c * self.b,
            },
            Dual {
                a: c,
                b: -s * self.b,
            },
        )
    }
}

impl Add for Dual {
    type Output = Dual;
    #[inline]
    fn add(self, o: Dual) -> Dual {
        Dual {
            a: self.a + o.a,
            b: self.b + o.b,
        }
    }
}

impl Sub for Dual {
    type Output = Dual;
    #[inline]
    fn sub(self, o: Dual) -> Dual {
        Dual {
            a: self.a - o.a,
            b: self.b - o.b,
        }
    }
}

impl Mul for Dual {
    type Output = Dual;
    #[inline]
    fn mul(self, o: Dual) -> Dual {
        Dual {
            a: self.a * o.a,
            b: self.a * o.b + self.b * o.a,
        }
    }
}

impl Div for Dual {
    type Output = Dual;
    #[inline]
    fn div(self, o: Dual) -> Dual {
        let q = self.a / o.a;
        Dual {
            a: q,
            b: (self.b - q * o.b) / o.a,
        }
    }
}

impl Neg for Dual {
    type Output = Dual;
    #[inline]
    fn neg(self) -> Dual {
        Dual {
            a: -self.a,
            b: -self.b,
        }
    }
}

impl Add<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn add(self, o: f64) -> Dual {
        Dual {
            a: self.a + o,
            b: self.b,
        }
    }
}

impl Sub<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn sub(self, o: f64) -> Dual {
        Dual {
            a: self.a - o,
            b: self.b,
        }
    }
}

impl Mul<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn mul(self, o: f64) -> Dual {
        Dual {
            a: self.a * o,
            b: self.b * o,
        }
    }
}

impl Div<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn div(self, o: f64) -> Dual {
        Dual {
            a: self.a / o,
            b: self.b / o,
        }
    }
}

impl AddAssign for Dual {
    #[inline]
    fn add_assign(&mut self, o: Dual) {
        *self = *self + o;
    }
}

impl SubAssign for Dual {
    #[inline]
    fn sub_assign(&mut self, o: Dual) {
        *self = *self - o;
    }
}

impl MulAssign for Dual {
    #[inline]
    fn mul_assign(&mut self, o: Dual) {
        *self = *self * o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x) = exp(sin x)·√(1 + x²)/(2 − x) and its derivative against the closed form.
    #[test]
    fn dual_derivative_is_the_derivative() {
        fn f<T: Real>(x: T) -> T {
            let (s, _) = x.sin_cos();
            s.exp() * (x * x + 1.0).sqrt() / (-x + 2.0)
        }
        let x = 0.7;
        let d = f(Dual::with(x, 1.0));
        let (s, c) = f64::sin_cos(x);
        let (r, w) = ((1.0 + x * x).sqrt(), 2.0 - x);
        let exact = s.exp() * (c * r / w + x / (r * w) + r / (w * w));
        assert_eq!(d.a, f(x));
        assert!((d.b - exact).abs() < 1e-15 * exact.abs(), "{} {exact}", d.b);
    }
}
