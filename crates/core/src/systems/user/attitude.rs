//! The configuration g ∈ G that a Lie–Poisson system carries along (its attitude): the
//! reconstruction ġ = gξ (left, 000 Theorem 4.3) or ġ = ξg (right, Theorem 4.4) with
//! ξ = ∂H/∂μ, and the Noether momentum that g and μ conserve together.
//!
//! **The step that goes with a coadjoint step.** The methods of a [`LiePoisson`] system move μ
//! by the coadjoint action, μ ← exp(θ)·μ = Ad*_{exp(−θ)} μ ([`GroupField`]). For a steady
//! velocity ξ, the left motion g(t) = g₀ exp(tξ) has μ(t) = Ad*_{exp(tξ)} μ₀, i.e. θ = −tξ;
//! the right motion g(t) = exp(tξ) g₀ has μ(t) = Ad*_{exp(−tξ)} μ₀, i.e. θ = tξ. So a step
//! μ ← exp(θ)·μ moves g by g ← g exp(−θ) (left) or g ← exp(θ) g (right) ([`Group::follow`]).
//! This is the same method applied to the lifted system on G × g*, on which G acts by
//! h·(g, μ) = (g h⁻¹, Ad*_{h⁻¹} μ) (left; (h g, …) right) with the same generator: the order
//! of the method is kept, and the Noether momentum Ad*_{g⁻¹}μ (left) or Ad*_g μ (right) is
//! kept exactly up to round-off: Ad*_{(g exp(−θ))⁻¹} Ad*_{exp(−θ)} μ = Ad*_{g⁻¹} μ.
//!
//! With an advected parameter the system lives on g ⋉ V while g stays in G: the G-part of a
//! semidirect element exp(θ, w) is exp(θ) (the projection G ⋉ V → G is a homomorphism), so only
//! the first dim g components of θ move the attitude.
//!
//! [`GroupField`]: crate::integrate::problem::GroupField
//! [`LiePoisson`]: super::LiePoisson

use nalgebra::{Matrix3, Matrix4, Vector3, Vector6};

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::space::Block;
use crate::lie::structure::Algebra;
use crate::lie::{se3, so, so3, MatrixLieGroup};
use crate::systems::tops::generalized::SoScratch;

/// The invariance a Lie–Poisson system comes from, which fixes the sign of its bracket (the
/// module docs of [`super`], "Left and right"): reduction of a left-invariant system gives
/// μ̇ = ad*_{∇H} μ (000 §4.1, Theorem 4.3: the body frame), of a right-invariant one
/// μ̇ = −ad*_{∇H} μ (Theorem 4.4: the spatial frame).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Side {
    /// Left-invariant (the rigid body in the body frame): μ̇ = ad*_{∇H} μ.
    #[default]
    Left,
    /// Right-invariant (spatial form): μ̇ = −ad*_{∇H} μ.
    Right,
}

impl Side {
    /// "left" or "right".
    pub fn name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }

    /// +1 for [`Side::Left`], −1 for [`Side::Right`]: the sign of the bracket.
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

/// g ← g + gE (left) or g + Eg (right) for N×N row-major matrices (sizes known to the compiler).
fn product_add<const N: usize>(side: Side, g: &mut [f64], e: &[f64]) {
    let mut t = [[0.0; N]; N];
    for (i, row) in t.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = match side {
                Side::Left => (0..N).map(|k| g[i * N + k] * e[k * N + j]).sum(),
                Side::Right => (0..N).map(|k| e[i * N + k] * g[k * N + j]).sum(),
            };
        }
    }
    for (i, row) in t.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            g[i * N + j] += x;
        }
    }
}

/// A matrix group of the built-in algebras, as the configuration space of a system.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// SO(3), rotations R (3×3), so(3) in the physics basis.
    So3,
    /// SO(n) (n×n), so(n) in the e_ij coordinates of [`so::vee_n`].
    So(usize),
    /// SE(3) as homogeneous matrices [[R, t], [0, 1]] (4×4), se(3) as ξ = (ω, v).
    Se3,
}

/// Scratch of [`Group::follow`]: the Taylor series of SO(n), exp(θ) − I,
/// a matrix and the negated increment.
pub struct GroupScratch {
    exp: SoScratch,
    e: Vec<f64>,
    a: Vec<f64>,
    t: Vec<f64>,
}

impl Group {
    /// The group of a built-in algebra; None for structure constants (no matrices).
    pub fn of(algebra: &Algebra) -> Option<Group> {
        match algebra {
            Algebra::So3 => Some(Group::So3),
            Algebra::So(n) => Some(Group::So(*n)),
            Algebra::Se3 => Some(Group::Se3),
            Algebra::Constants(_) => None,
        }
    }

    /// n of the n×n matrices.
    pub fn size(self) -> usize {
        match self {
            Group::So3 => 3,
            Group::So(n) => n,
            Group::Se3 => 4,
        }
    }

    /// dim g.
    pub fn dim(self) -> usize {
        match self {
            Group::So3 => 3,
            Group::So(n) => so::dim(n),
            Group::Se3 => 6,
        }
    }

    /// The block of a state that holds an element: `SO(3)` for rotations (checked and retracted
    /// by the driver), n×n matrices otherwise (checked by [`Group::check`]).
    pub(crate) fn block(self) -> Block {
        match self {
            Group::So3 => Block::SO3,
            _ => Block::Matrix(self.size()),
        }
    }

    /// The name of that block: `R` for a rotation, `g` otherwise.
    pub(crate) fn block_name(self) -> &'static str {
        match self {
            Group::So3 => "R",
            _ => "g",
        }
    }

    /// Errors unless `g` (n×n, row-major) is finite and in the group (the group's own check:
    /// [`Error::NotInGroup`] with its defect).
    pub fn check(self, what: &str, g: &[f64]) -> Result<()> {
        let n = self.size();
        if g.len() != n * n {
            return Err(Error::shape(
                what,
                format!("({n}, {n})"),
                format!("{} values", g.len()),
            ));
        }
        check::finite_slice(what, g)?;
        match self {
            Group::So3 => so3::check_rotation(what, &Matrix3::from_row_slice(g)),
            Group::So(n) => {
                so::check_rotation_of(what, &crate::Mat::from_fn(n, n, |i, j| g[i * n + j]), n)
            }
            Group::Se3 => se3::SE3::from_matrix4(&Matrix4::from_row_slice(g))
                .map(|_| ())
                .map_err(|e| match e {
                    Error::NotInGroup {
                        group,
                        defect_name,
                        defect,
                        tol,
                        ..
                    } => Error::NotInGroup {
                        what: what.into(),
                        group,
                        defect_name,
                        defect,
                        tol,
                    },
                    other => other,
                }),
        }
    }

    /// The matrix ξ̂ (n×n, row-major) of ξ ∈ g.
    fn hat(self, xi: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        match self {
            Group::So3 | Group::Se3 => {
                let w = [
                    [0.0, -xi[2], xi[1]],
                    [xi[2], 0.0, -xi[0]],
                    [-xi[1], xi[0], 0.0],
                ];
                let n = self.size();
                for i in 0..3 {
                    out[i * n..i * n + 3].copy_from_slice(&w[i]);
                }
                if self == Group::Se3 {
                    for i in 0..3 {
                        out[i * 4 + 3] = xi[3 + i];
                    }
                }
            }
            Group::So(n) => {
                let mut k = 0;
                for i in 0..n {
                    for j in i + 1..n {
                        out[i * n + j] = xi[k];
                        out[j * n + i] = -xi[k];
                        k += 1;
                    }
                }
            }
        }
    }

    /// The scratch of [`Group::follow`].
    pub fn scratch(self) -> GroupScratch {
        let n = self.size();
        GroupScratch {
            exp: SoScratch::new(n),
            e: vec![0.0; n * n],
            a: vec![0.0; n * n],
            t: vec![0.0; self.dim()],
        }
    }

    /// E = exp(ξ̂) − I into `s.exp_m1` (n×n): Rodrigues' closed form on SO(3) and SE(3)
    /// (E_R = a ξ̂ + b ξ̂², a = sin θ/θ, b = ½ (sin(θ/2)/(θ/2))², no cancellation at small θ;
    /// SE(3)'s translation V v = v + b ω×v + c ω×(ω×v), c = (θ − sin θ)/θ³), the scaled Taylor
    /// series of [`SoScratch`] on SO(n).
    fn expm1(self, xi: &[f64], s: &mut GroupScratch) {
        let n = self.size();
        self.hat(xi, &mut s.a);
        match self {
            Group::So(_) => {
                let e = s.exp.expm1_of(&s.a);
                s.e.copy_from_slice(e);
            }
            Group::So3 | Group::Se3 => {
                let theta = (xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]).sqrt();
                // sin θ/θ = (sin(θ/2)/(θ/2)) cos(θ/2): one sin_cos.
                let (sh, ch) = (0.5 * theta).sin_cos();
                let half = if theta == 0.0 {
                    1.0
                } else {
                    sh / (0.5 * theta)
                };
                let a = half * ch;
                let b = 0.5 * half * half;
                // w² = w wᵀ − θ² I (3×3 block of ξ̂²).
                for i in 0..3 {
                    for j in 0..3 {
                        let w2 = xi[i] * xi[j] - if i == j { theta * theta } else { 0.0 };
                        s.e[i * n + j] = a * s.a[i * n + j] + b * w2;
                    }
                }
                if self == Group::Se3 {
                    let c = if theta < 1e-2 {
                        let t2 = theta * theta;
                        1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0
                    } else {
                        (theta - theta.sin()) / (theta * theta * theta)
                    };
                    let (w, v) = (&xi[..3], &xi[3..6]);
                    let wv = [
                        w[1] * v[2] - w[2] * v[1],
                        w[2] * v[0] - w[0] * v[2],
                        w[0] * v[1] - w[1] * v[0],
                    ];
                    let wwv = [
                        w[1] * wv[2] - w[2] * wv[1],
                        w[2] * wv[0] - w[0] * wv[2],
                        w[0] * wv[1] - w[1] * wv[0],
                    ];
                    for i in 0..3 {
                        s.e[i * 4 + 3] = v[i] + b * wv[i] + c * wwv[i];
                        s.e[12 + i] = 0.0;
                    }
                    s.e[15] = 0.0;
                }
            }
        }
    }

    /// g ← g exp(−θ) (left) or exp(θ) g (right): the configuration's step that goes with the
    /// momentum's μ ← exp(θ)·μ (module docs). The product is formed as g + g(exp(∓θ) − I), so
    /// that its rounding errors are relative to |θ||g| rather than |g|.
    pub fn follow(self, side: Side, theta: &[f64], g: &mut [f64], s: &mut GroupScratch) {
        let n = self.size();
        if self == Group::So3 {
            // Rodrigues by increments (so3::Rodrigues): left R ← R exp(θ)ᵀ, every row r ↦
            // exp(θ) r; right R ← exp(θ) R, every column c ↦ exp(θ) c.
            let rot = so3::Rodrigues::exp(&Vector3::new(theta[0], theta[1], theta[2]));
            for k in 0..3 {
                let at = |i: usize| match side {
                    Side::Left => k * 3 + i,
                    Side::Right => i * 3 + k,
                };
                let mut v = Vector3::new(g[at(0)], g[at(1)], g[at(2)]);
                rot.apply(&mut v);
                for i in 0..3 {
                    g[at(i)] = v[i];
                }
            }
            return;
        }
        let sign = side.sign();
        for (t, x) in s.t.iter_mut().zip(theta) {
            *t = -sign * x;
        }
        let minus = std::mem::take(&mut s.t);
        self.expm1(&minus[..self.dim()], s);
        s.t = minus;
        match self {
            Group::So3 => unreachable!("by Rodrigues above"),
            Group::Se3 => product_add::<4>(side, g, &s.e),
            Group::So(_) => {
                for i in 0..n {
                    for j in 0..n {
                        s.a[i * n + j] = match side {
                            Side::Left => (0..n).map(|k| g[i * n + k] * s.e[k * n + j]).sum(),
                            Side::Right => (0..n).map(|k| s.e[i * n + k] * g[k * n + j]).sum(),
                        };
                    }
                }
                g.iter_mut().zip(&s.a).for_each(|(x, t)| *x += t);
            }
        }
    }

    /// The derivative of [`Group::follow`] for a tangent lift: given the new configuration g'
    /// and w = dexp_θ δθ (right-trivialised, the G-part of the algebra's), dg ← D(follow)\[δθ, dg\]:
    /// on a matrix block (ambient directions) dg exp(−θ) − g'ŵ (left) or exp(θ) dg + ŵg'
    /// (right); on `R` (left-trivialised, δR = Rη̂) η' = exp(θ)η − w (left) or η + R'ᵀw
    /// (right). From exp(θ + εδθ) = exp(εw) exp(θ) to first order, and for the left side
    /// g ŵ_r exp(−θ) = g'(Ad_{exp θ} ŵ_r) with Ad_{exp θ} dexp_{−θ} = dexp_θ.
    pub(crate) fn follow_tangent(
        self,
        side: Side,
        theta: &[f64],
        w: &[f64],
        g_new: &[f64],
        dg: &mut [f64],
        s: &mut GroupScratch,
    ) {
        if self == Group::So3 {
            let mut eta = Vector3::new(dg[0], dg[1], dg[2]);
            let w = Vector3::new(w[0], w[1], w[2]);
            let eta = match side {
                Side::Left => {
                    so3::Rodrigues::exp(&Vector3::new(theta[0], theta[1], theta[2]))
                        .apply(&mut eta);
                    eta - w
                }
                Side::Right => eta + Matrix3::from_row_slice(g_new).transpose() * w,
            };
            dg[..3].copy_from_slice(eta.as_slice());
            return;
        }
        self.follow(side, theta, dg, s);
        let mut a = std::mem::take(&mut s.a);
        self.velocity(side, w, g_new, &mut a);
        let sign = -side.sign();
        dg.iter_mut().zip(&a).for_each(|(x, y)| *x += sign * y);
        s.a = a;
    }

    /// The derivative of [`Group::velocity`] along (δξ, δg): δg ξ̂ + g δξ̂ (left) or
    /// ξ̂ δg + δξ̂ g (right), into `out` (matrix blocks).
    pub(crate) fn velocity_tangent(
        self,
        side: Side,
        (xi, dxi): (&[f64], &[f64]),
        (g, dg): (&[f64], &[f64]),
        out: &mut [f64],
    ) {
        let n = self.size();
        for i in 0..n {
            for j in 0..n {
                out[i * n + j] = match side {
                    Side::Left => (0..n)
                        .map(|k| {
                            dg[i * n + k] * self.hat_entry(xi, k, j)
                                + g[i * n + k] * self.hat_entry(dxi, k, j)
                        })
                        .sum(),
                    Side::Right => (0..n)
                        .map(|k| {
                            self.hat_entry(xi, i, k) * dg[k * n + j]
                                + self.hat_entry(dxi, i, k) * g[k * n + j]
                        })
                        .sum(),
                };
            }
        }
    }

    /// The entry (i, j) of ξ̂ (n×n).
    fn hat_entry(self, xi: &[f64], i: usize, j: usize) -> f64 {
        match self {
            Group::So3 | Group::Se3 => match (i, j) {
                (0, 1) => -xi[2],
                (0, 2) => xi[1],
                (1, 0) => xi[2],
                (1, 2) => -xi[0],
                (2, 0) => -xi[1],
                (2, 1) => xi[0],
                (r, 3) if r < 3 => xi[3 + r],
                _ => 0.0,
            },
            Group::So(n) => {
                let (lo, hi, sign) = match i.cmp(&j) {
                    std::cmp::Ordering::Less => (i, j, 1.0),
                    std::cmp::Ordering::Greater => (j, i, -1.0),
                    std::cmp::Ordering::Equal => return 0.0,
                };
                // e_ij coordinates: the upper triangle row by row.
                sign * xi[lo * n - lo * (lo + 1) / 2 + (hi - lo - 1)]
            }
        }
    }

    /// ġ = gξ̂ (left) or ξ̂g (right) into `dg`.
    pub(crate) fn velocity(self, side: Side, xi: &[f64], g: &[f64], dg: &mut [f64]) {
        let n = self.size();
        for i in 0..n {
            for j in 0..n {
                dg[i * n + j] = match side {
                    Side::Left => (0..n)
                        .map(|k| g[i * n + k] * self.hat_entry(xi, k, j))
                        .sum(),
                    Side::Right => (0..n)
                        .map(|k| self.hat_entry(xi, i, k) * g[k * n + j])
                        .sum(),
                };
            }
        }
    }

    /// The Noether momentum of the momentum μ (dim g) at g (n×n, row-major; body to space):
    /// Ad*_{g⁻¹}μ for a left-invariant system, constant along ġ = gξ (000 Theorem 4.3; the
    /// spatial angular momentum R M of the rigid body, Theorem 4.2), Ad*_g μ for a
    /// right-invariant one (ġ = ξg, Theorem 4.4). With ⟨Ad*_h μ, ξ⟩ = ⟨μ, Ad_h ξ⟩: so(3)
    /// R M (left), Rᵀ M (right); so(n) g M gᵀ, gᵀ M g (as skew matrices, pairing ½ tr(AᵀB));
    /// se(3) (Ad_{g∓1})ᵀ μ.
    ///
    /// Errors: those of [`Group::check`].
    pub fn noether(self, side: Side, mu: &[f64], g: &[f64], out: &mut [f64]) -> Result<()> {
        self.check("g", g)?;
        let left = side == Side::Left;
        match self {
            Group::So3 => {
                let r = Matrix3::from_row_slice(g);
                let m = Vector3::from_column_slice(&mu[..3]);
                let p = if left { r * m } else { r.transpose() * m };
                out.copy_from_slice(p.as_slice());
            }
            Group::So(n) => {
                let q = crate::Mat::from_fn(n, n, |i, j| g[i * n + j]);
                let m = so::hat_n_unchecked(n, &mu[..so::dim(n)]);
                let p = if left {
                    &q * m * q.transpose()
                } else {
                    q.transpose() * m * &q
                };
                out.copy_from_slice(&so::vee_n_unchecked(&p));
            }
            Group::Se3 => {
                let h = se3::SE3::from_matrix4(&Matrix4::from_row_slice(g))?;
                let h = if left { h.inverse() } else { h };
                let p = h.adjoint_matrix().transpose() * Vector6::from_column_slice(&mu[..6]);
                out.copy_from_slice(p.as_slice());
            }
        }
        Ok(())
    }
}
