//! The generalized rigid body on so(n)* (Euler–Arnold / Manakov equations, the form of 001 (7.25)).
//!
//! **so(n)\*.** M = JΩ + ΩJ with J = diag(J_i) (the mass matrix; a symmetric J is diagonalised
//! once), so Ω_ij = M_ij / (J_i + J_j); Ṁ = [M, Ω]; H = ½⟨M, Ω⟩ = ½ Σ_{i<j} M_ij Ω_ij; Casimirs
//! C_k = ½ tr((MᵀM)^k), k = 1…⌊n/2⌋ (they fix the spectrum of M). Coordinates are the e_ij
//! coordinates of `lie::so::vee_n`. Sign check against so(3): the matrix of the physics hat map
//! satisfies [hat M, hat Ω] = hat(M × Ω), so Ṁ = [M, Ω] is Euler's equation; in e_ij coordinates
//! c = (−w₃, w₂, −w₁), and with J_i + J_j = I_k ({i, j, k} = {1, 2, 3}) the energies agree (tested).
//!
//! Tangent lift (issue 26, [`crate::integrate::tangent`]): the derivative of the field,
//! δṀ = [δM, Ω] + [M, δΩ], for `rk4`; the derivatives of the generator, the action and dexp
//! ([`GroupFieldTangent`]) for `rkmk4`; `isospectral` differentiates its own step (module docs
//! of `methods::isospectral`, "Tangent map"); J carries no parameter directions.

use super::methods::isospectral::Isospectral;
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Rk4, Rkmk4};
use crate::integrate::problem::{GroupField, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{GroupFieldTangent, Tangent, TangentSystem, VectorFieldTangent};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::so;
use crate::Mat;

/// The generalized rigid body on so(n)*: M = JΩ + ΩJ, Ṁ = [M, Ω] (Euler–Arnold; Manakov).
#[derive(Clone, Debug, PartialEq)]
pub struct GeneralizedRigidBody {
    n: usize,
    j: Vec<f64>,
    frame: Option<Mat>,
    /// d_ij = J_i + J_j, row-major n×n (diagonal unused).
    d: Vec<f64>,
    /// (coordinate index, sign) of entry (i, j) of hat_n, row-major; sign 0 on the diagonal.
    index: Vec<(usize, f64)>,
}

impl GeneralizedRigidBody {
    /// A body with principal mass-matrix entries J_i ≥ 0, n ≥ 2, J_i + J_j > 0 for i ≠ j.
    pub fn new(j: &[f64]) -> Result<Self> {
        let n = j.len();
        if n < 2 {
            return Err(Error::shape("J", "(n,) with n ≥ 2", format!("({n},)")));
        }
        check::finite_slice("J", j)?;
        // The body keeps dense n×n tables (and its steppers n×n scratch): refuse what cannot be
        // allocated instead of aborting.
        check::dense_size("J", n, n)?;
        for (i, &ji) in j.iter().enumerate() {
            if ji < 0.0 {
                return Err(Error::invalid("J", format!("J[{i}] = {ji} < 0")));
            }
        }
        let mut d = vec![0.0; n * n];
        let mut index = vec![(0usize, 0.0); n * n];
        let mut c = 0;
        for i in 0..n {
            for k in i + 1..n {
                let s = j[i] + j[k];
                if s <= 0.0 {
                    return Err(Error::invalid(
                        "J",
                        format!("J[{i}] + J[{k}] = {s} must be > 0 (non-positive inertia)"),
                    ));
                }
                d[i * n + k] = s;
                d[k * n + i] = s;
                index[i * n + k] = (c, 1.0);
                index[k * n + i] = (c, -1.0);
                c += 1;
            }
        }
        Ok(GeneralizedRigidBody {
            n,
            j: j.to_vec(),
            frame: None,
            d,
            index,
        })
    }

    /// A body with a symmetric positive-semidefinite mass matrix J (n×n), diagonalised once.
    pub fn from_matrix(j: &Mat) -> Result<Self> {
        let n = check::square("J", j, 2)?;
        let asym = (0..n)
            .flat_map(|a| (0..n).map(move |b| (a, b)))
            .fold(0.0f64, |s, (a, b)| s.max((j[(a, b)] - j[(b, a)]).abs()));
        if asym > 1e-12 * j.norm_l2().max(1.0) {
            return Err(Error::invalid(
                "J",
                format!("not symmetric (max |J − Jᵀ| = {asym:.3e})"),
            ));
        }
        let eig = j
            .self_adjoint_eigen(faer::Side::Lower)
            .map_err(|e| Error::invalid("J", format!("eigendecomposition failed: {e:?}")))?;
        // Round-off can leave a zero eigenvalue of a PSD J slightly negative: clamp those within
        // 1e-12·‖J‖ to 0 and let `new` reject what is truly negative.
        let floor = 1e-12 * j.norm_l2();
        let vals: Vec<f64> = (0..n)
            .map(|i| eig.S()[i])
            .map(|v| if v < 0.0 && v >= -floor { 0.0 } else { v })
            .collect();
        let mut q = Mat::from_fn(n, n, |a, b| eig.U()[(a, b)]);
        if q.determinant() < 0.0 {
            for a in 0..n {
                q[(a, n - 1)] = -q[(a, n - 1)];
            }
        }
        let mut body = Self::new(&vals)?;
        body.frame = Some(q);
        Ok(body)
    }

    /// n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The principal entries J_i.
    pub fn principal(&self) -> &[f64] {
        &self.j
    }

    fn entry(&self, z: &[f64], i: usize, k: usize) -> f64 {
        let (c, s) = self.index[i * self.n + k];
        s * z[c]
    }

    pub(crate) fn dense(&self, z: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            let (c, s) = self.index[k];
            *o = s * z[c];
        }
    }

    pub(crate) fn coords(&self, m: &[f64], z: &mut [f64]) {
        let n = self.n;
        let mut c = 0;
        for i in 0..n {
            for k in i + 1..n {
                z[c] = m[i * n + k];
                c += 1;
            }
        }
    }

    /// The denominators d_ij = J_i + J_j (row-major n×n, diagonal unused).
    pub(crate) fn denominators(&self) -> &[f64] {
        &self.d
    }

    fn conjugate(&self, z: &mut [f64], transpose_first: bool) {
        if let Some(q) = &self.frame {
            let m = so::hat_n_unchecked(self.n, z);
            let m = if transpose_first {
                q.transpose() * &m * q
            } else {
                q * &m * q.transpose()
            };
            z.copy_from_slice(&so::vee_n_unchecked(&m));
        }
    }
}

impl Problem for GeneralizedRigidBody {
    fn name(&self) -> &'static str {
        "GeneralizedRigidBody"
    }
    fn space(&self) -> Space {
        Space::new([("M", Block::SoDual(self.n))])
    }
    /// H = ½ Σ_{i<j} M_ij² / (J_i + J_j) (principal frame).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let mut zi = z.to_vec();
        self.to_internal(&mut zi);
        let n = self.n;
        let mut e = 0.0;
        for i in 0..n {
            for k in i + 1..n {
                let m = self.entry(&zi, i, k);
                e += m * m / self.d[i * n + k];
            }
        }
        Ok(0.5 * e)
    }
    /// C_k = ½ tr((MᵀM)^k), k = 1…⌊n/2⌋ (C₁ = |M|² on so(3)).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let m = so::hat_n_unchecked(self.n, z);
        Ok(crate::lie::so::spectral_invariants(&m))
    }
    fn invariant_names(&self) -> Vec<String> {
        crate::lie::so::spectral_names("M", self.n)
    }
    fn to_internal(&self, z: &mut [f64]) {
        self.conjugate(z, true);
    }
    fn to_user(&self, z: &mut [f64]) {
        self.conjugate(z, false);
    }
}

impl VectorField for GeneralizedRigidBody {
    /// Ṁ = [M, Ω] in e_ij coordinates (principal frame).
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let n = self.n;
        let om = |i: usize, k: usize| {
            if i == k {
                0.0
            } else {
                self.entry(z, i, k) / self.d[i * n + k]
            }
        };
        let mut c = 0;
        for i in 0..n {
            for j in i + 1..n {
                let mut s = 0.0;
                for k in 0..n {
                    s += self.entry(z, i, k) * om(k, j) - om(i, k) * self.entry(z, k, j);
                }
                dz[c] = s;
                c += 1;
            }
        }
    }
}

/// δṀ = [δM, Ω] + [M, δΩ], δΩ_ij = δM_ij/(J_i + J_j) (principal frame).
impl VectorFieldTangent for GeneralizedRigidBody {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        let n = self.n;
        let om = |v: &[f64], i: usize, k: usize| {
            if i == k {
                0.0
            } else {
                self.entry(v, i, k) / self.d[i * n + k]
            }
        };
        let mut c = 0;
        for i in 0..n {
            for j in i + 1..n {
                let mut s = 0.0;
                for k in 0..n {
                    s += self.entry(dz, i, k) * om(z, k, j) - om(z, i, k) * self.entry(dz, k, j)
                        + self.entry(z, i, k) * om(dz, k, j)
                        - om(dz, i, k) * self.entry(z, k, j);
                }
                out[c] = s;
                c += 1;
            }
        }
    }
}

impl Catalog for GeneralizedRigidBody {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("isospectral", || Isospectral),
            Entry::new("rk4", || Rk4),
            Entry::new("rkmk4", || Rkmk4),
        ]
    }

    /// The tangent lift of `isospectral` and `rk4` (module docs).
    fn tangent(&self) -> Option<std::sync::Arc<dyn TangentSystem>> {
        Some(Tangent::field(self.clone()).into_system())
    }

    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> crate::Result<std::sync::Arc<dyn crate::integrate::forcing::Perturbation>> {
        crate::integrate::forcing::double_bracket(self, d)
    }
}

/// so(n) in e_ij coordinates acting on so(n)* (principal frame): ξ(M) = −Ω, so that the generator
/// [ξ, M] = [M, Ω] is the Euler–Arnold equation, and g = exp(ξ) acts by M ↦ gMgᵀ (a left action
/// that keeps the spectrum of M). The kernels work on the dense skew matrices in [`SoScratch`],
/// without allocation: exp − I by scaling and squaring of its Taylor series, dexp⁻¹ by its
/// Bernoulli series (the conventions of [`so::exp`] and [`so::dexp_inv`], checked against them in
/// the tests).
impl GroupField for GeneralizedRigidBody {
    type Scratch = SoScratch;
    fn scratch(&self) -> SoScratch {
        SoScratch::new(self.n)
    }
    fn algebra_dim(&self) -> usize {
        so::dim(self.n)
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut SoScratch) {
        let n = self.n;
        let mut c = 0;
        for i in 0..n {
            for k in i + 1..n {
                xi[c] = -z[c] / self.d[i * n + k];
                c += 1;
            }
        }
    }
    /// M ← gMgᵀ = M + (P − Pᵀ) + P(g − I)ᵀ with P = (g − I)M: the increment is formed from
    /// g − I (summed apart from I), so its rounding errors are relative to |ξ||M| rather than
    /// |M| (with g itself the spectrum drifts by ~1e-16 per step, systematically).
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut SoScratch) {
        let mut dz = std::mem::take(&mut s.dz);
        self.act_increment(xi, z, &mut dz, s);
        z.iter_mut().zip(&dz).for_each(|(zi, d)| *zi += d);
        s.dz = dz;
    }
    /// gMgᵀ − M = (G M + M Gᵀ) + G M Gᵀ with G = exp(ξ) − I, in e_ij coordinates.
    fn act_increment(&self, xi: &[f64], z: &[f64], dz: &mut [f64], s: &mut SoScratch) -> bool {
        let n = self.n;
        self.dense(xi, &mut s.a);
        s.expm1();
        self.dense(z, &mut s.m);
        matmul(n, &s.g, &s.m, &mut s.b);
        let mut c = 0;
        for i in 0..n {
            for j in i + 1..n {
                let q: f64 = (0..n).map(|k| s.b[i * n + k] * s.g[j * n + k]).sum();
                dz[c] = (s.b[i * n + j] - s.b[j * n + i]) + q;
                c += 1;
            }
        }
        true
    }
    /// Σ_k B_k/k! ad_uᵏ v, summed until a bound of the tail is below 10⁻¹⁷ of the sum; NaN for
    /// |u| ≥ π/2 (the series converges for |u| < π; the bound keeps the number of terms ≤ 64).
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut SoScratch) {
        let n = self.n;
        let nu = u.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !nu.is_finite() || nu >= std::f64::consts::FRAC_PI_2 || v.iter().any(|x| !x.is_finite())
        {
            out.fill(f64::NAN);
            return;
        }
        self.dense(u, &mut s.a);
        self.dense(v, &mut s.m);
        out.copy_from_slice(v);
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut bound = 1.0;
        for &ck in &so::bernoulli_coefficients()[1..] {
            // p ← [u, p] = u p − (u p)ᵀ for skew u, p.
            matmul(n, &s.a, &s.m, &mut s.b);
            let mut c = 0;
            let mut pn = 0.0;
            for i in 0..n {
                s.m[i * n + i] = 0.0;
                for j in i + 1..n {
                    let x = s.b[i * n + j] - s.b[j * n + i];
                    s.m[i * n + j] = x;
                    s.m[j * n + i] = -x;
                    out[c] += ck * x;
                    pn += x * x;
                    c += 1;
                }
            }
            // |b_j| ≤ 4/(2π)^j (j ≥ 2) and |ad_uʲ⁻ᵏ p| ≤ (2|u|)^{j−k} |p|, so the terms after k
            // sum to at most 4|p|/(2π)^k · r/(1 − r) ≤ 4|p|/(2π)^k, r = |u|/π ≤ ½.
            bound /= two_pi;
            let sum = out.iter().map(|x| x * x).sum::<f64>().sqrt();
            if 4.0 * pn.sqrt() * bound <= 1e-17 * sum || pn == 0.0 {
                return;
            }
        }
    }
}

/// The derivatives of the so(n) action for the tangent lift (RKMK4 with sensitivities):
/// g = exp(u), δg = ŵg with w = dexp_u δu (right-trivialised, as the dexp⁻¹ above), so
/// δ(gMgᵀ) = g δM gᵀ + ŵ gMgᵀ − gMgᵀ ŵ = g δM gᵀ + [ŵ, Y] at Y = gMgᵀ (the generator of the
/// action at Y, [ξ, M]); D_u(dexp_u w)\[δu\] by the dexp series differentiated term by term
/// ([`so::dexp_derivative`]). Both on the scratch's dense matrices, without allocation.
impl GroupFieldTangent for GeneralizedRigidBody {
    fn generator_tangent(&self, _z: &[f64], dz: &[f64], dxi: &mut [f64], s: &mut SoScratch) {
        self.generator(dz, dxi, s);
    }
    fn act_tangent(&self, u: &[f64], du: &[f64], y: &[f64], dz: &mut [f64], s: &mut SoScratch) {
        self.act(u, dz, s);
        let n = self.n;
        let [uu, dd, ww, yy, t, d, p, _] = s.lift_buffers();
        self.dense(u, uu);
        self.dense(du, dd);
        so::dexp_series_dense(n, uu, dd, None, ww, None, [t, d, p]);
        self.dense(y, yy);
        matmul(n, ww, yy, p);
        let mut c = 0;
        for i in 0..n {
            for j in i + 1..n {
                dz[c] += p[i * n + j] - p[j * n + i];
                c += 1;
            }
        }
    }
    fn dexp_tangent(&self, u: &[f64], du: &[f64], w: &[f64], out: &mut [f64], s: &mut SoScratch) {
        let n = self.n;
        let [uu, dd, ww, value, t, d, p, deriv] = s.lift_buffers();
        self.dense(u, uu);
        self.dense(du, dd);
        self.dense(w, ww);
        so::dexp_series_dense(n, uu, ww, Some(dd), value, Some(deriv), [t, d, p]);
        self.coords(deriv, out);
    }
}

impl GeneralizedRigidBody {
    /// out = dexp_u v (e_ij coordinates), by the series of [`so::dexp_derivative`]'s kernel.
    pub(crate) fn dexp_apply(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut SoScratch) {
        let n = self.n;
        let [uu, vv, ww, _, t, d, p, _] = s.lift_buffers();
        self.dense(u, uu);
        self.dense(v, vv);
        so::dexp_series_dense(n, uu, vv, None, ww, None, [t, d, p]);
        self.coords(ww, out);
    }
}

/// Scratch of the so(n) kernels of [`GeneralizedRigidBody`]'s [`GroupField`]: dense n×n
/// matrices (row-major).
#[derive(Clone, Debug)]
pub struct SoScratch {
    n: usize,
    a: Vec<f64>,
    b: Vec<f64>,
    g: Vec<f64>,
    m: Vec<f64>,
    t: Vec<f64>,
    /// The increment of [`GroupField::act`] (e_ij coordinates).
    dz: Vec<f64>,
    /// The dense buffers of the tangent lift's kernels (sized at their first use).
    lift: Vec<Vec<f64>>,
}

impl SoScratch {
    pub(crate) fn new(n: usize) -> Self {
        SoScratch {
            n,
            a: vec![0.0; n * n],
            b: vec![0.0; n * n],
            g: vec![0.0; n * n],
            m: vec![0.0; n * n],
            t: vec![0.0; n * n],
            dz: vec![0.0; n * (n - 1) / 2],
            lift: Vec::new(),
        }
    }

    /// The lift's eight dense n×n buffers, allocated at their first use.
    fn lift_buffers(&mut self) -> [&mut [f64]; 8] {
        if self.lift.is_empty() {
            self.lift = vec![vec![0.0; self.n * self.n]; 8];
        }
        let [a, b, c, d, e, f, g, h] = &mut self.lift[..] else {
            unreachable!("eight buffers")
        };
        [a, b, c, d, e, f, g, h]
    }

    /// exp(A) − I of a dense n×n matrix A (row-major; any matrix: the series below does not use
    /// skewness), held in the scratch until its next use.
    pub(crate) fn expm1_of(&mut self, a: &[f64]) -> &[f64] {
        self.a.copy_from_slice(a);
        self.expm1();
        &self.g
    }

    /// g ← exp(a) − I for the skew matrix in `a` (overwritten): the Taylor series of exp − I at
    /// a/2ˢ, ‖a/2ˢ‖_F ≤ ½, summed until a term is below 10⁻¹⁸ (at most 17 terms), then s
    /// doublings exp(2x) − I = 2(eˣ − I) + (eˣ − I)², which keep the small increment apart from I.
    fn expm1(&mut self) {
        let n = self.n;
        let norm = self.a.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !norm.is_finite() {
            self.g.fill(f64::NAN);
            return;
        }
        let mut doublings = 0;
        let mut scale = 1.0;
        while norm * scale > 0.5 {
            scale *= 0.5;
            doublings += 1;
        }
        self.a.iter_mut().for_each(|x| *x *= scale);
        // g = a, t = a; then t ← t a / k, g += t.
        self.t.copy_from_slice(&self.a);
        self.g.copy_from_slice(&self.a);
        for k in 2..=30 {
            matmul(n, &self.t, &self.a, &mut self.b);
            let inv = 1.0 / k as f64;
            let mut tn = 0.0;
            for ((t, b), g) in self.t.iter_mut().zip(&self.b).zip(self.g.iter_mut()) {
                *t = b * inv;
                *g += *t;
                tn += *t * *t;
            }
            if tn.sqrt() <= 1e-18 {
                break;
            }
        }
        for _ in 0..doublings {
            matmul(n, &self.g, &self.g, &mut self.b);
            for (g, b) in self.g.iter_mut().zip(&self.b) {
                *g = 2.0 * *g + b;
            }
        }
    }
}

/// c = a·b for dense row-major n×n matrices.
fn matmul(n: usize, a: &[f64], b: &[f64], c: &mut [f64]) {
    for i in 0..n {
        for j in 0..n {
            c[i * n + j] = (0..n).map(|k| a[i * n + k] * b[k * n + j]).sum();
        }
    }
}

/// `isospectral` (its own tangent stepper), `rk4` and `rkmk4` on the tangent lift.
impl Catalog for Tangent<GeneralizedRigidBody> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("isospectral", || Isospectral),
            Entry::new("rk4", || Rk4),
            Entry::new("rkmk4", || Rkmk4),
        ]
    }
}
