//! A general surface from a metric and an orthonormal frame given as closures: the derivatives,
//! the connection 1-form and the curvature by finite differences (numerical).

use std::fmt;
use std::sync::Arc;

use super::{det, finite2, inner, Mat2, Surface, Vec2};
use crate::error::{Error, Result};
use crate::numerics::fd::diff4;

/// A closure of the chart returning a 2×2 matrix.
pub type MatrixField = Arc<dyn Fn(Vec2) -> Mat2 + Send + Sync>;
/// A closure deciding the chart's domain.
pub type DomainFn = Arc<dyn Fn(Vec2) -> bool + Send + Sync>;

/// A general surface from closures: the metric g(x) and an orthonormal frame e(x) (`e[a][i]` =
/// e_a^i). **Numerical**: ∂g by fourth-order central differences (step ε^{1/5}·max(1, |x^k|)), α
/// from its definition α_i = ⟨∇_{∂_i} Ê₁, Ê₂⟩ = g_jk (∂_i e₁^j + Γ^j_{il} e₁^l) e₂^k with the
/// Christoffel symbols of those differences, ∂α by fourth-order differences of α (step
/// 5e-3·max(1, |x^k|)) and K = −(∂₁α₂ − ∂₂α₁)/√det g. Expect errors of about 1e-12 in ∂g and α
/// and 1e-9 in ∂α and K for smooth data of order one. No Killing fields, no embedding.
#[derive(Clone)]
pub struct MetricSurface {
    metric: MatrixField,
    frame: MatrixField,
    domain: Option<DomainFn>,
}

impl fmt::Debug for MetricSurface {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MetricSurface").finish_non_exhaustive()
    }
}

/// Step of the first-level differences (≈ ε^{1/5}).
const H1: f64 = 7e-4;
/// Step of the differences of α.
const H2: f64 = 5e-3;

fn flat(m: Mat2) -> [f64; 4] {
    [m[0][0], m[0][1], m[1][0], m[1][1]]
}

fn unflat(v: [f64; 4]) -> Mat2 {
    [[v[0], v[1]], [v[2], v[3]]]
}

impl MetricSurface {
    /// A surface from a metric and an orthonormal frame given as closures, on the points where
    /// `domain` holds (and g is finite and positive definite). Errors: none here; the frame is
    /// checked against the metric at a point by [`MetricSurface::check_frame`].
    pub fn new(
        metric: impl Fn(Vec2) -> Mat2 + Send + Sync + 'static,
        frame: impl Fn(Vec2) -> Mat2 + Send + Sync + 'static,
        domain: Option<DomainFn>,
    ) -> Self {
        MetricSurface {
            metric: Arc::new(metric),
            frame: Arc::new(frame),
            domain,
        }
    }

    /// Checks at x that the frame is orthonormal and positively oriented for the metric
    /// (g(Ê_a, Ê_b) = δ_ab within `tol`, det e > 0). Errors: [`Error::InvalidArgument`] (also
    /// for a tolerance that is not a finite number ≥ 0).
    pub fn check_frame(&self, x: Vec2, tol: f64) -> Result<()> {
        if !(tol.is_finite() && tol >= 0.0) {
            return Err(Error::invalid(
                "tol",
                format!("expected a finite tolerance ≥ 0, got {tol}"),
            ));
        }
        if !self.contains(x) {
            return Err(Error::invalid(
                "x",
                format!("({}, {}) lies outside the domain", x[0], x[1]),
            ));
        }
        let g = (self.metric)(x);
        let e = (self.frame)(x);
        for a in 0..2 {
            for b in 0..2 {
                let gab = inner(&g, e[a], e[b]);
                let want = if a == b { 1.0 } else { 0.0 };
                if (gab - want).abs().is_nan() || (gab - want).abs() > tol {
                    return Err(Error::invalid(
                        "frame",
                        format!("g(Ê_{}, Ê_{}) = {gab}, expected {want}", a + 1, b + 1),
                    ));
                }
            }
        }
        if det(&e).is_nan() || det(&e) <= 0.0 {
            return Err(Error::invalid(
                "frame",
                "the frame must be positively oriented (det e > 0)",
            ));
        }
        Ok(())
    }

    fn dg(&self, x: Vec2) -> [Mat2; 2] {
        let f = |y: Vec2| flat((self.metric)(y));
        [unflat(diff4(f, x, 0, H1)), unflat(diff4(f, x, 1, H1))]
    }

    fn alpha(&self, x: Vec2) -> Vec2 {
        let g = (self.metric)(x);
        let dg = self.dg(x);
        let e = (self.frame)(x);
        let fe = |y: Vec2| (self.frame)(y)[0];
        let de1 = [diff4(fe, x, 0, H1), diff4(fe, x, 1, H1)];
        std::array::from_fn(|i| {
            // g_jk ∂_i e₁^j e₂^k + Γ_{k,il} e₁^l e₂^k, Γ_{k,il} = ½(∂_i g_kl + ∂_l g_ki − ∂_k g_il).
            let mut a = inner(&g, de1[i], e[1]);
            for k in 0..2 {
                for l in 0..2 {
                    let gam = 0.5 * (dg[i][k][l] + dg[l][k][i] - dg[k][i][l]);
                    a += gam * e[0][l] * e[1][k];
                }
            }
            a
        })
    }
}

impl Surface for MetricSurface {
    fn name(&self) -> &'static str {
        "MetricSurface"
    }
    fn calls_out(&self) -> bool {
        true
    }
    fn domain(&self) -> &'static str {
        "the given domain, where g is positive definite"
    }
    fn contains(&self, x: Vec2) -> bool {
        if !finite2(x) || !self.domain.as_ref().map_or(true, |d| d(x)) {
            return false;
        }
        let g = (self.metric)(x);
        g.iter().flatten().all(|v| v.is_finite()) && g[0][0] > 0.0 && det(&g) > 0.0
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        (self.metric)(x)
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        self.dg(x)
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        (self.frame)(x)
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        self.alpha(x)
    }
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        let f = |y: Vec2| self.alpha(y);
        [diff4(f, x, 0, H2), diff4(f, x, 1, H2)]
    }
}
