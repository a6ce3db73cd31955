//! A Riemannian 3-manifold in one chart, from its metric g(x) and an orthonormal frame field
//! Ê_a(x) given as closures: the stage of [`super::frame_top::RiemannianFrameTop`], the top of
//! 002 §V on a general three-dimensional space (the three-dimensional analogue of
//! [`super::surface::MetricSurface`]).
//!
//! # The connection of the frame (002 (121), derived again)
//! With the frame as the matrix E (column a = the components e_a^i of Ê_a), the connection forms
//! are the antisymmetric matrices A_j = (g(Ê_a, ∇_{∂_j}Ê_b))_ab, so that ∇_v Ê_b = Σ_a Ê_a A(v)_ab:
//!
//! A_j = Eᵀ(g ∂_jE + Γ̃_j E),  (Γ̃_j)_kl = Γ_{k,jl} = ½(∂_j g_kl + ∂_l g_kj − ∂_k g_jl).
//!
//! Their axial vectors c_j = A_j^∨ (A = ĉ, ĉv = c × v) are the columns of the 3×3 matrix C(x); a
//! body frame F = ÊR moving along x(t) has ∇F/dt = F ω̂ with ω = ω_R + RᵀCẋ, ω_R = (RᵀṘ)^∨: the
//! angular velocity relative to parallel transport is the frame's own plus the connection's.
//! 002 (121) writes the Christoffel term without the frame vector it acts on (it should read
//! X^γΓ^α_{γδ}Ê_j^δ); the form above is checked in `tests/frame_top.rs` against a rotating frame of
//! flat space (C = axial vectors of QᵀdQ) and, through the motion, against the 3-sphere.
//!
//! **Numerical**, like `MetricSurface`: ∂g and ∂E by fourth-order central differences
//! (`numerics::fd::diff4`, step 7e-4·max(1, |x^k|)), C from them, ∂C by fourth-order
//! differences of C (step 5e-3·max(1, |x^k|)). Expect errors of about 1e-12 in C and 1e-9 in ∂C
//! for smooth data of order one. No Killing fields are known for a general metric.

use std::fmt;
use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use crate::error::{Error, Result};
use crate::numerics::fd::diff4;

/// A point of the chart, (x¹, x², x³).
pub type Point = [f64; 3];
/// A closure of the chart returning a 3×3 matrix, `m[i][j]`.
pub type Field = Arc<dyn Fn(Point) -> [[f64; 3]; 3] + Send + Sync>;
/// A closure deciding the chart's domain.
pub type Domain = Arc<dyn Fn(Point) -> bool + Send + Sync>;

/// Step of the first-level differences (≈ ε^{1/5}).
const H1: f64 = 7e-4;
/// Step of the differences of C.
const H2: f64 = 5e-3;

/// A Riemannian 3-manifold in a chart (module docs): the metric g(x) (`g[i][j]` = g_ij) and an
/// orthonormal frame (`e[a][i]` = e_a^i, the components of Ê_a), on the points where `domain`
/// holds and g is finite and positive definite.
#[derive(Clone)]
pub struct Riemannian {
    metric: Field,
    frame: Field,
    domain: Option<Domain>,
}

impl fmt::Debug for Riemannian {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Riemannian").finish_non_exhaustive()
    }
}

/// What the top's kernels need at a point: g, g⁻¹, ∂g, the frame E and the connection C, ∂C.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// g_ij.
    pub g: Matrix3<f64>,
    /// g⁻¹.
    pub g_inv: Matrix3<f64>,
    /// `dg[k]` = ∂_k g.
    pub dg: [Matrix3<f64>; 3],
    /// Column a = the components of Ê_a.
    pub e: Matrix3<f64>,
    /// Column j = c_j, the axial vector of the connection form A_j (module docs).
    pub c: Matrix3<f64>,
    /// `dc[k]` = ∂_k C.
    pub dc: [Matrix3<f64>; 3],
}

fn to_matrix(m: [[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[i][j])
}

fn flat(m: [[f64; 3]; 3]) -> [f64; 9] {
    std::array::from_fn(|k| m[k / 3][k % 3])
}

fn from_flat(v: [f64; 9]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| v[3 * i + j])
}

impl Riemannian {
    /// A manifold from a metric and an orthonormal frame given as closures (module docs).
    /// Errors: none here; [`Riemannian::check_frame`] checks the frame at a point.
    pub fn new(
        metric: impl Fn(Point) -> [[f64; 3]; 3] + Send + Sync + 'static,
        frame: impl Fn(Point) -> [[f64; 3]; 3] + Send + Sync + 'static,
        domain: Option<Domain>,
    ) -> Self {
        Riemannian {
            metric: Arc::new(metric),
            frame: Arc::new(frame),
            domain,
        }
    }

    /// Whether x lies in the chart: finite, in the domain, g finite and positive definite.
    pub fn contains(&self, x: Point) -> bool {
        if !x.iter().all(|v| v.is_finite()) || !self.domain.as_ref().map_or(true, |d| d(x)) {
            return false;
        }
        let g = to_matrix((self.metric)(x));
        g.iter().all(|v| v.is_finite()) && g.cholesky().is_some()
    }

    /// Errors: [`Error::InvalidArgument`] for x outside the chart.
    pub fn check_point(&self, x: Point) -> Result<()> {
        if self.contains(x) {
            return Ok(());
        }
        Err(Error::invalid(
            "x",
            format!(
                "({}, {}, {}) lies outside the chart (its domain, where the metric is finite and \
                 positive definite)",
                x[0], x[1], x[2]
            ),
        ))
    }

    /// Checks at x that the frame is orthonormal and positively oriented for the metric:
    /// g(Ê_a, Ê_b) = δ_ab within `tol`, det E > 0. Errors: [`Error::InvalidArgument`] (also for
    /// x outside the chart and a tolerance that is not a finite number ≥ 0).
    pub fn check_frame(&self, x: Point, tol: f64) -> Result<()> {
        if !(tol.is_finite() && tol >= 0.0) {
            return Err(Error::invalid(
                "tol",
                format!("expected a finite tolerance ≥ 0, got {tol}"),
            ));
        }
        self.check_point(x)?;
        let (g, e) = (self.metric(x), self.frame(x));
        let gram = e.transpose() * g * e;
        for a in 0..3 {
            for b in 0..3 {
                let want = if a == b { 1.0 } else { 0.0 };
                let d = (gram[(a, b)] - want).abs();
                if d.is_nan() || d > tol {
                    return Err(Error::invalid(
                        "frame",
                        format!(
                            "g(Ê_{}, Ê_{}) = {}, expected {want}",
                            a + 1,
                            b + 1,
                            gram[(a, b)]
                        ),
                    ));
                }
            }
        }
        let det = e.determinant();
        if det.is_nan() || det <= 0.0 {
            return Err(Error::invalid(
                "frame",
                "the frame must be positively oriented (det E > 0, E the matrix with columns Ê_a)",
            ));
        }
        Ok(())
    }

    /// g(x).
    pub fn metric(&self, x: Point) -> Matrix3<f64> {
        to_matrix((self.metric)(x))
    }

    /// E(x): column a = the components of Ê_a.
    pub fn frame(&self, x: Point) -> Matrix3<f64> {
        to_matrix((self.frame)(x)).transpose()
    }

    fn dg(&self, x: Point) -> [Matrix3<f64>; 3] {
        let f = |y: Point| flat((self.metric)(y));
        std::array::from_fn(|k| from_flat(diff4(f, x, k, H1)))
    }

    /// C(x) from g, ∂g, E and ∂E (module docs).
    fn connection_from(&self, x: Point, g: &Matrix3<f64>, dg: &[Matrix3<f64>; 3]) -> Matrix3<f64> {
        let e = self.frame(x);
        // ∂_j of the rows e_a^i, i.e. of Eᵀ.
        let f = |y: Point| flat((self.frame)(y));
        let mut c = Matrix3::zeros();
        for j in 0..3 {
            let de = from_flat(diff4(f, x, j, H1)).transpose();
            let gam =
                Matrix3::from_fn(|k, l| 0.5 * (dg[j][(k, l)] + dg[l][(k, j)] - dg[k][(j, l)]));
            let a = e.transpose() * (g * de + gam * e);
            c.set_column(
                j,
                &Vector3::new(
                    0.5 * (a[(2, 1)] - a[(1, 2)]),
                    0.5 * (a[(0, 2)] - a[(2, 0)]),
                    0.5 * (a[(1, 0)] - a[(0, 1)]),
                ),
            );
        }
        c
    }

    /// C(x): column j = the axial vector of A_j = (g(Ê_a, ∇_{∂_j}Ê_b))_ab.
    pub fn connection(&self, x: Point) -> Matrix3<f64> {
        let g = self.metric(x);
        self.connection_from(x, &g, &self.dg(x))
    }

    /// Everything at x ([`Geometry`]); non-finite where x is outside the chart (g not positive
    /// definite, outside the domain), so that a step through such a point fails.
    pub fn geometry(&self, x: Point) -> Geometry {
        let g = self.metric(x);
        let g_inv = match (self.contains(x), g.try_inverse()) {
            (true, Some(inv)) => inv,
            _ => Matrix3::from_element(f64::NAN),
        };
        let dg = self.dg(x);
        let c = self.connection_from(x, &g, &dg);
        let fc = |y: Point| {
            let c = self.connection(y);
            std::array::from_fn(|k| c[(k / 3, k % 3)])
        };
        Geometry {
            g,
            g_inv,
            dg,
            e: self.frame(x),
            c,
            dc: std::array::from_fn(|k| from_flat(diff4(fc, x, k, H2))),
        }
    }
}
