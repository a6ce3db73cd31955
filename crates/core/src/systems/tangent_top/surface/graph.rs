//! Graphs z = f(x, y) over the plane from the jet of f (value and derivatives to third order):
//! metric, Gram–Schmidt frame, connection and the embedding with its shape operator.

use std::fmt;
use std::sync::Arc;

use super::{add, det, finite2, mul, Embedding, Mat2, Shape, Surface, Vec2};
use crate::check;
use crate::error::Result;

/// The derivatives of a function f(x, y) at a point, up to third order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Jet {
    /// f.
    pub value: f64,
    /// (f_x, f_y).
    pub gradient: Vec2,
    /// [[f_xx, f_xy], [f_xy, f_yy]].
    pub hessian: Mat2,
    /// (f_xxx, f_xxy, f_xyy, f_yyy).
    pub third: [f64; 4],
}

impl Jet {
    fn is_finite(&self) -> bool {
        self.value.is_finite()
            && finite2(self.gradient)
            && self.hessian.iter().flatten().all(|v| v.is_finite())
            && self.third.iter().all(|v| v.is_finite())
    }

    /// f_ijk (symmetric; the number of y's among i, j, k picks the entry).
    fn t(&self, i: usize, j: usize, k: usize) -> f64 {
        self.third[i + j + k]
    }
}

/// A graph z = f(x, y) over the plane, coordinates x = (x, y), from the jet of f (value and
/// derivatives to third order; [`Jet`]).
///
/// With p = f_x, q = f_y, u = 1 + p², D = 1 + p² + q²: g_ij = δ_ij + f_i f_j (det g = D),
/// ∂_k g_ij = f_ik f_j + f_i f_jk; the frame is Gram–Schmidt of (∂x, ∂y),
/// Ê₁ = ∂x/√u, Ê₂ = (−pq ∂x + u ∂y)/√(uD); n = (−p, −q, 1)/√D = Ê₁ × Ê₂; h_ij = f_ij/√D.
///
/// **Connection.** In ℝ³, Ê₁ = (1, 0, p)/√u and Ê₂ = (−pq, u, q)/√(uD); the tangential part of
/// ∂_i Ê₁ is ∇_{∂_i}Ê₁, so α_i = ⟨∂_i Ê₁, Ê₂⟩ = f_xi q/(u√D) (the ∂_i(1/√u) part is along Ê₁).
/// K = (f_xx f_yy − f_xy²)/D².
/// No Killing fields in general (a quadric of revolution is better served by
/// [`Revolution`](super::Revolution)).
#[derive(Clone)]
pub struct Graph {
    jet: Arc<dyn Fn(Vec2) -> Jet + Send + Sync>,
    /// Made by [`Graph::new`] from the caller's function.
    user: bool,
}

impl fmt::Debug for Graph {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Graph").finish_non_exhaustive()
    }
}

/// What the graph's formulas share at one point.
struct GraphLocal {
    j: Jet,
    u: f64,
    d: f64,
    /// ∂_k u, ∂_k D.
    du: Vec2,
    dd: Vec2,
}

impl Graph {
    /// The graph of f given by its jet (module docs of [`Graph`]).
    pub fn new(jet: impl Fn(Vec2) -> Jet + Send + Sync + 'static) -> Self {
        Graph {
            jet: Arc::new(jet),
            user: true,
        }
    }

    /// The quadric z = (a x² + b y²)/2: a paraboloid for ab > 0, a saddle for ab < 0, a cylinder
    /// when one is zero. Errors: a non-finite coefficient.
    pub fn quadric(a: f64, b: f64) -> Result<Self> {
        check::finite_slice("a and b", &[a, b])?;
        Ok(Graph {
            user: false,
            ..Graph::new(move |x| Jet {
                value: 0.5 * (a * x[0] * x[0] + b * x[1] * x[1]),
                gradient: [a * x[0], b * x[1]],
                hessian: [[a, 0.0], [0.0, b]],
                third: [0.0; 4],
            })
        })
    }

    fn local(&self, x: Vec2) -> GraphLocal {
        let j = (self.jet)(x);
        let ([p, q], h) = (j.gradient, j.hessian);
        GraphLocal {
            j,
            u: 1.0 + p * p,
            d: 1.0 + p * p + q * q,
            du: [2.0 * p * h[0][0], 2.0 * p * h[0][1]],
            dd: std::array::from_fn(|k| 2.0 * (p * h[0][k] + q * h[1][k])),
        }
    }

    /// The frame e and its derivatives ∂_k e.
    fn frame_and_derivatives(l: &GraphLocal) -> (Mat2, [Mat2; 2]) {
        let ([p, q], h) = (l.j.gradient, l.j.hessian);
        let (u, d) = (l.u, l.d);
        let a = 1.0 / u.sqrt();
        let c = 1.0 / (u * d).sqrt();
        let e = [[a, 0.0], [-p * q * c, u * c]];
        let de = std::array::from_fn(|k| {
            let da = -0.5 * a * l.du[k] / u;
            let dc = -0.5 * c * (l.du[k] / u + l.dd[k] / d);
            let dpq = h[0][k] * q + p * h[1][k];
            [[da, 0.0], [-dpq * c - p * q * dc, l.du[k] * c + u * dc]]
        });
        (e, de)
    }
}

impl Surface for Graph {
    fn name(&self) -> &'static str {
        "Graph"
    }
    fn calls_out(&self) -> bool {
        self.user
    }
    fn domain(&self) -> &'static str {
        "the points where f and its derivatives are finite"
    }
    fn contains(&self, x: Vec2) -> bool {
        finite2(x) && (self.jet)(x).is_finite()
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        let [p, q] = (self.jet)(x).gradient;
        [[1.0 + p * p, p * q], [p * q, 1.0 + q * q]]
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        let j = (self.jet)(x);
        let (f, h) = (j.gradient, j.hessian);
        std::array::from_fn(|k| {
            std::array::from_fn(|a| std::array::from_fn(|b| h[a][k] * f[b] + f[a] * h[b][k]))
        })
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        Graph::frame_and_derivatives(&self.local(x)).0
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        let l = self.local(x);
        let q = l.j.gradient[1];
        let den = l.u * l.d.sqrt();
        [l.j.hessian[0][0] * q / den, l.j.hessian[0][1] * q / den]
    }
    /// ∂_k α_i = (f_xik q + f_xi f_yk)/(u√D) − α_i (∂_k u/u + ½ ∂_k D/D).
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        let l = self.local(x);
        let (q, h) = (l.j.gradient[1], l.j.hessian);
        let den = l.u * l.d.sqrt();
        std::array::from_fn(|k| {
            let dlog = l.du[k] / l.u + 0.5 * l.dd[k] / l.d;
            std::array::from_fn(|i| {
                let alpha = h[0][i] * q / den;
                (l.j.t(0, i, k) * q + h[0][i] * h[1][k]) / den - alpha * dlog
            })
        })
    }
    fn curvature(&self, x: Vec2) -> f64 {
        let l = self.local(x);
        det(&l.j.hessian) / (l.d * l.d)
    }
    fn embedding(&self) -> Option<&dyn Embedding> {
        Some(self)
    }
}

impl Embedding for Graph {
    fn position(&self, x: Vec2) -> [f64; 3] {
        [x[0], x[1], (self.jet)(x).value]
    }
    fn normal(&self, x: Vec2) -> [f64; 3] {
        let [p, q] = (self.jet)(x).gradient;
        let r = (1.0 + p * p + q * q).sqrt();
        [-p / r, -q / r, 1.0 / r]
    }
    fn second_fundamental_form(&self, x: Vec2) -> Mat2 {
        let j = (self.jet)(x);
        let [p, q] = j.gradient;
        let r = (1.0 + p * p + q * q).sqrt();
        j.hessian.map(|row| row.map(|v| v / r))
    }
    fn tangent(&self, x: Vec2, v: Vec2) -> [f64; 3] {
        let [p, q] = (self.jet)(x).gradient;
        [v[0], v[1], p * v[0] + q * v[1]]
    }
    /// W = e h, ∂_k W = (∂_k e) h + e ∂_k h with ∂_k h_ij = f_ijk/√D − ½ f_ij ∂_k D/D^{3/2}.
    fn shape(&self, x: Vec2) -> Shape {
        let l = self.local(x);
        let (e, de) = Graph::frame_and_derivatives(&l);
        let r = l.d.sqrt();
        let h: Mat2 = l.j.hessian.map(|row| row.map(|v| v / r));
        let dh: [Mat2; 2] = std::array::from_fn(|k| {
            std::array::from_fn(|i| {
                std::array::from_fn(|jj| {
                    l.j.t(i, jj, k) / r - 0.5 * l.j.hessian[i][jj] * l.dd[k] / (l.d * r)
                })
            })
        });
        Shape {
            w: mul(&e, &h),
            dw: std::array::from_fn(|k| add(&mul(&de[k], &h), &mul(&e, &dh[k]))),
        }
    }
}
