//! Inertia tensors of a pseudo-rigid body at X ∈ GL⁺(n): the left and right inertia tensors
//! A^L_X, A^R_X (001 (2.11)), Ad_X, Adᵀ_X (001 (6.10)) and the bi-inertia tensor B_X
//! (001 (6.9)) on so(n) ⊕ so(n), with its closed-form inverse (001 (7.6)–(7.9)), its
//! eigen-decomposition (001 (8.14)–(8.15)) and its quadratic form (001 (6.14)).
//!
//! Everything is gathered in [`BiInertia`], built once per configuration X. B_X is computed by
//! one function, [`BiInertia::apply`]; the matrices, the connections and the momenta call it.

use std::sync::OnceLock;

use crate::check;
use crate::error::{Error, Result};
use crate::lie::gl::{self, SvdCoordinates};
use crate::lie::so;
use crate::Mat;

/// g ξ gᵀ (Ad_g for g ∈ SO(n)).
pub(crate) fn conj(g: &Mat, xi: &Mat) -> Mat {
    g * xi * g.transpose()
}

/// gᵀ ξ g (Ad_g⁻¹ for g ∈ SO(n)).
pub(crate) fn conj_t(g: &Mat, xi: &Mat) -> Mat {
    g.transpose() * xi * g
}

/// Q ξ + ξ Q.
fn anticommutator(q: &Mat, xi: &Mat) -> Mat {
    q * xi + xi * q
}

/// The skew matrix with upper-triangle entries f(i, j), i < j.
fn skew_from_fn(n: usize, f: impl Fn(usize, usize) -> f64) -> Mat {
    let mut m = Mat::zeros(n, n);
    for i in 0..n {
        for j in i + 1..n {
            let v = f(i, j);
            m[(i, j)] = v;
            m[(j, i)] = -v;
        }
    }
    m
}

/// The matrix of a linear map on (so(n))^k in the e_ij basis (blocks in order), built column by
/// column from `f` applied to basis vectors.
fn operator_matrix(n: usize, blocks: usize, f: impl Fn(&[Mat]) -> Vec<Mat>) -> Mat {
    let d = so::dim(n);
    let mut m = Mat::zeros(blocks * d, blocks * d);
    let mut e = vec![0.0; blocks * d];
    for col in 0..blocks * d {
        e[col] = 1.0;
        let input: Vec<Mat> = e.chunks(d).map(|c| so::hat_n_unchecked(n, c)).collect();
        for (b, out) in f(&input).iter().enumerate() {
            for (k, v) in so::vee_n_unchecked(out).into_iter().enumerate() {
                m[(b * d + k, col)] = v;
            }
        }
        e[col] = 0.0;
    }
    m
}

/// The inertia tensors of a pseudo-rigid body at a configuration X ∈ GL⁺(n).
///
/// Built by [`BiInertia::new`] (which checks X ∈ GL⁺(n)); computes and caches XXᵀ, XᵀX and the
/// SVD coordinates X = R A Sᵀ on first use. Operators act on skew-symmetric n×n matrices; matrices are
/// in the e_ij basis of DESIGN.md with the ξ block first.
/// m / c^k for a power of two c (exact where representable), or an overflow error naming `what`
/// where an entry leaves the f64 range (the result of a scale-aware formula that is not
/// representable).
pub(crate) fn rescale(what: &str, mut m: Mat, c: f64, k: i32) -> Result<Mat> {
    let f = 1.0 / c;
    for _ in 0..k.max(0) {
        m *= faer::Scale(f);
    }
    for _ in 0..(-k).max(0) {
        m *= faer::Scale(c);
    }
    let big = (0..m.ncols())
        .flat_map(|j| (0..m.nrows()).map(move |i| (i, j)))
        .any(|(i, j)| !m[(i, j)].is_finite());
    if big {
        return Err(Error::overflow(
            "X",
            format!(
                "{what} exceeds the f64 range at this scale of X (it scales like a₁^{}, a₁ ≈ {c:.3e})",
                -k
            ),
        ));
    }
    Ok(m)
}

/// The eigenvalue (a_i − sign·a_j)² of B_X (001 (8.15)) scale-aware: formed from a_i, a_j
/// divided by a common power of two and multiplied back once; an overflow error naming `what`
/// where it exceeds the f64 range (a ≳ 1e154). The one place these eigenvalues are computed.
pub(crate) fn eigenvalue(what: &str, ai: f64, aj: f64, sign: f64) -> Result<f64> {
    let e = check::pow2_exponent_of([ai, aj]);
    let d = check::ldexp(ai, -e) - sign * check::ldexp(aj, -e);
    check::unscale(
        what,
        "an eigenvalue (a_i ± a_j)² of the bi-inertia tensor",
        d * d,
        2 * e,
    )
}

#[derive(Debug, Clone)]
pub struct BiInertia {
    x: Mat,
    /// X̃ = X·2^−ex, the largest entry in [1, 2) for extreme X ([`check::pow2_exponent`]; X̃ = X,
    /// ex = 0, for moderate X). Every operator of degree k in X is evaluated on X̃ and multiplied
    /// by 2^(k·ex) once, with an overflow error where the result is not representable.
    xs: Mat,
    ex: i32,
    /// X̃X̃ᵀ and X̃ᵀX̃ (of the scaled X̃).
    xxt: OnceLock<Mat>,
    xtx: OnceLock<Mat>,
    svd: OnceLock<SvdCoordinates>,
}

impl BiInertia {
    /// The inertia tensors at X. Errors: X not square with n ≥ 2 (so(1) = {0}: no rotations),
    /// not finite or det X ≤ 0.
    pub fn new(x: &Mat) -> Result<Self> {
        check::square("X", x, 2)?;
        gl::check_gl_plus("X", x)?;
        let ex = check::pow2_exponent_mat(x);
        Ok(BiInertia {
            x: x.clone(),
            xs: check::ldexp_mat(x, -ex),
            ex,
            xxt: OnceLock::new(),
            xtx: OnceLock::new(),
            svd: OnceLock::new(),
        })
    }

    /// X̃X̃ᵀ (scaled, see the field `xs`), computed once.
    fn xxt(&self) -> &Mat {
        self.xxt.get_or_init(|| &self.xs * self.xs.transpose())
    }

    /// X̃ᵀX̃ (scaled), computed once.
    fn xtx(&self) -> &Mat {
        self.xtx.get_or_init(|| self.xs.transpose() * &self.xs)
    }

    /// An so(n) argument divided by a power of two 2^e (see [`check::pow2_exponent`]): (ξ̃, e).
    fn scaled_arg(xi: &Mat) -> (Mat, i32) {
        let e = check::pow2_exponent_mat(xi);
        (check::ldexp_mat(xi, -e), e)
    }

    /// Two so(n) arguments divided by one common power of two: (ξ̃, η̃, e).
    fn scaled_pair(xi: &Mat, eta: &Mat) -> (Mat, Mat, i32) {
        let e = check::pow2_exponent(check::max_abs(xi).max(check::max_abs(eta)));
        (check::ldexp_mat(xi, -e), check::ldexp_mat(eta, -e), e)
    }

    /// The result of a formula of degree 2 in X evaluated on X̃ and on arguments scaled by 2^e,
    /// multiplied back, or an overflow error naming `what` and `quantity`.
    fn unscale(&self, what: &str, quantity: &str, m: &Mat, e: i32) -> Result<Mat> {
        check::unscale_mat(what, quantity, m, 2 * self.ex + e)
    }

    /// n.
    pub fn n(&self) -> usize {
        self.x.nrows()
    }

    /// The configuration X.
    pub fn x(&self) -> &Mat {
        &self.x
    }

    /// SVD coordinates X = R diag(a) Sᵀ (001 (2.4)), computed once.
    pub fn svd(&self) -> Result<&SvdCoordinates> {
        if let Some(c) = self.svd.get() {
            return Ok(c);
        }
        let c = gl::svd_coordinates(&self.x)?;
        Ok(self.svd.get_or_init(|| c))
    }

    /// Checks an so(n) argument of the right size.
    fn arg(&self, what: &str, xi: &Mat) -> Result<()> {
        so::check_algebra_of(what, xi, self.n())
    }

    /// Left inertia tensor A^L_X ξ = XXᵀξ + ξXXᵀ (001 (2.11)). Scale-aware (X and ξ divided by
    /// powers of two, the result multiplied back once); an overflow error
    /// ([`Error::InvalidArgument`]) where the result exceeds the f64 range.
    pub fn left(&self, xi: &Mat) -> Result<Mat> {
        self.arg("xi", xi)?;
        let (x, e) = Self::scaled_arg(xi);
        self.unscale("X, xi", "A^L_X ξ", &anticommutator(self.xxt(), &x), e)
    }

    /// Right inertia tensor A^R_X η = XᵀXη + ηXᵀX (001 (2.11)); scale-aware as
    /// [`BiInertia::left`].
    pub fn right(&self, eta: &Mat) -> Result<Mat> {
        self.arg("eta", eta)?;
        let (y, e) = Self::scaled_arg(eta);
        self.unscale("X, eta", "A^R_X η", &anticommutator(self.xtx(), &y), e)
    }

    /// Ad_X η = X η Xᵀ (001 (6.10)); scale-aware as [`BiInertia::left`].
    pub fn ad_x(&self, eta: &Mat) -> Result<Mat> {
        self.arg("eta", eta)?;
        let (y, e) = Self::scaled_arg(eta);
        self.unscale("X, eta", "Ad_X η", &conj(&self.xs, &y), e)
    }

    /// Adᵀ_X ξ = Xᵀ ξ X (001 (6.10)), the transpose of Ad_X under the pairing (2.8);
    /// scale-aware as [`BiInertia::left`].
    pub fn ad_x_t(&self, xi: &Mat) -> Result<Mat> {
        self.arg("xi", xi)?;
        let (x, e) = Self::scaled_arg(xi);
        self.unscale("X, xi", "Adᵀ_X ξ", &conj_t(&self.xs, &x), e)
    }

    /// The bi-inertia tensor B_X (001 (6.9)):
    /// ξ ⊕ η ↦ (A^L_X ξ − 2 Ad_X η) ⊕ (−2 Adᵀ_X ξ + A^R_X η). Defined on all of GL⁺(n);
    /// symmetric (6.12), positive definite on the principal stratum (6.14). Scale-aware as
    /// [`BiInertia::left`] (an overflow error where B_X(ξ ⊕ η) exceeds the f64 range).
    pub fn apply(&self, xi: &Mat, eta: &Mat) -> Result<(Mat, Mat)> {
        self.arg("xi", xi)?;
        self.arg("eta", eta)?;
        let (x, y, e) = Self::scaled_pair(xi, eta);
        let (top, bottom) = self.apply_scaled(&x, &y);
        let q = "B_X (ξ ⊕ η)";
        Ok((
            self.unscale("X, xi, eta", q, &top, e)?,
            self.unscale("X, xi, eta", q, &bottom, e)?,
        ))
    }

    /// B_X̃ (ξ ⊕ η) on the scaled X̃ (multiply by 2^(2·ex) for B_X).
    fn apply_scaled(&self, xi: &Mat, eta: &Mat) -> (Mat, Mat) {
        let top = anticommutator(self.xxt(), xi) - conj(&self.xs, eta) * faer::Scale(2.0);
        let bottom = anticommutator(self.xtx(), eta) - conj_t(&self.xs, xi) * faer::Scale(2.0);
        (top, bottom)
    }

    /// B_X as an n(n−1)×n(n−1) matrix in the e_ij basis, ξ block first (001 (6.9)); its blocks
    /// are the matrices of A^L_X, −2Ad_X, −2Adᵀ_X, A^R_X.
    /// [`BiInertia::matrix`] scale-safely: c² B_X̃ with X̃ = X/c (`BiInertia::unit_x`), and an
    /// overflow error (InvalidArgument) where an entry exceeds the f64 range (B_X grows like
    /// a₁², so X beyond ~1e154 has no representable bi-inertia matrix).
    pub fn try_matrix(&self) -> Result<Mat> {
        self.unscale("X", "the bi-inertia tensor B_X", &self.matrix_scaled(), 0)
    }

    /// B_X̃ of the scaled X̃ (multiply by 2^(2·ex) for B_X).
    fn matrix_scaled(&self) -> Mat {
        operator_matrix(self.n(), 2, |v| {
            let (a, b) = self.apply_scaled(&v[0], &v[1]);
            vec![a, b]
        })
    }

    /// B_X as a matrix (entries ±inf where they exceed the f64 range; see
    /// [`BiInertia::try_matrix`]).
    pub fn matrix(&self) -> Mat {
        check::ldexp_mat(&self.matrix_scaled(), 2 * self.ex)
    }

    /// A^L_X as a matrix in the e_ij basis (001 (2.11)).
    pub fn left_matrix(&self) -> Mat {
        let m = operator_matrix(self.n(), 1, |v| vec![anticommutator(self.xxt(), &v[0])]);
        check::ldexp_mat(&m, 2 * self.ex)
    }

    /// A^R_X as a matrix in the e_ij basis (001 (2.11)).
    pub fn right_matrix(&self) -> Mat {
        let m = operator_matrix(self.n(), 1, |v| vec![anticommutator(self.xtx(), &v[0])]);
        check::ldexp_mat(&m, 2 * self.ex)
    }

    /// Ad_X as a matrix in the e_ij basis (001 (6.10)).
    pub fn ad_x_matrix(&self) -> Mat {
        let m = operator_matrix(self.n(), 1, |v| vec![conj(&self.xs, &v[0])]);
        check::ldexp_mat(&m, 2 * self.ex)
    }

    /// Adᵀ_X as a matrix in the e_ij basis (001 (6.10)).
    pub fn ad_x_t_matrix(&self) -> Mat {
        let m = operator_matrix(self.n(), 1, |v| vec![conj_t(&self.xs, &v[0])]);
        check::ldexp_mat(&m, 2 * self.ex)
    }

    /// (A^L_X)⁻¹ λ, on all of GL⁺(n): with XXᵀ = R A² Rᵀ, λ' = Rᵀλ R, the solution is
    /// ξ = R ξ' Rᵀ with ξ'_ij = λ'_ij / (a_i² + a_j²) (A^L_A acts entrywise, 001 (8.14)).
    pub fn left_solve(&self, lam: &Mat) -> Result<Mat> {
        self.arg("lam", lam)?;
        self.left_solve_scaled(lam, 2)
    }

    /// (A^L_X̃)⁻¹ λ / c^k with X̃ = X/c, c = [`SvdCoordinates::unit`]'s scale: the solve on
    /// singular values near one, rescaled once (k = 2 for λ itself, k = 1 for a λ computed from
    /// X̃ as the connections do), with an overflow error where the result is not representable.
    pub(crate) fn left_solve_scaled(&self, lam: &Mat, k: i32) -> Result<Mat> {
        let c = self.svd()?;
        let (u, scale) = c.unit();
        rescale("(A^L_X)⁻¹ λ", Self::diagonal_solve(&c.r, &u, lam), scale, k)
    }

    /// The scale c of [`SvdCoordinates::unit`] and X̃ = X/c (exact: c is a power of two).
    pub(crate) fn unit_x(&self) -> Result<(Mat, f64)> {
        let (_, c) = self.svd()?.unit();
        Ok((&self.x * faer::Scale(1.0 / c), c))
    }

    /// (A^R_X)⁻¹ γ, on all of GL⁺(n): as [`BiInertia::left_solve`] in the frame S of XᵀX = S A² Sᵀ.
    pub fn right_solve(&self, gam: &Mat) -> Result<Mat> {
        self.arg("gam", gam)?;
        self.right_solve_scaled(gam, 2)
    }

    /// The right analogue of [`BiInertia::left_solve_scaled`].
    pub(crate) fn right_solve_scaled(&self, gam: &Mat, k: i32) -> Result<Mat> {
        let c = self.svd()?;
        let (u, scale) = c.unit();
        rescale("(A^R_X)⁻¹ γ", Self::diagonal_solve(&c.s, &u, gam), scale, k)
    }

    fn diagonal_solve(frame: &Mat, a: &[f64], rhs: &Mat) -> Mat {
        let p = conj_t(frame, rhs);
        let sol = skew_from_fn(a.len(), |i, j| p[(i, j)] / (a[i] * a[i] + a[j] * a[j]));
        conj(frame, &sol)
    }

    /// B_X⁻¹(λ ⊕ γ) by the closed form in the SVD frame (001 (7.6)–(7.9)): λ' = Rᵀλ R,
    /// γ' = Sᵀγ S, then for i < j
    /// ξ'_ij = ((a_i² + a_j²) λ'_ij + 2 a_i a_j γ'_ij) / (a_i² − a_j²)²,
    /// η'_ij = ((a_i² + a_j²) γ'_ij + 2 a_i a_j λ'_ij) / (a_i² − a_j²)²,
    /// and ξ ⊕ η = R ξ' Rᵀ ⊕ S η' Sᵀ. O(n³) work; no n(n−1)-sized solve. (7.9) checked against
    /// a dense solve: correct as printed.
    ///
    /// Errors: [`Error::DegenerateStratum`] off the principal stratum (gap ≤
    /// [`gl::STRATUM_TOL`]·a₁), shape / non-finite / non-skew arguments.
    pub fn solve(&self, lam: &Mat, gam: &Mat) -> Result<(Mat, Mat)> {
        self.arg("lam", lam)?;
        self.arg("gam", gam)?;
        self.solve_scaled(lam, gam, 2)
    }

    /// B_X̃⁻¹ (λ ⊕ γ) / c^k on the singular values scaled near one (see
    /// [`BiInertia::left_solve_scaled`]).
    pub(crate) fn solve_scaled(&self, lam: &Mat, gam: &Mat, k: i32) -> Result<(Mat, Mat)> {
        let c = self.svd()?;
        c.require_principal("bi-inertia inverse B_X⁻¹")?;
        let (l, g) = (conj_t(&c.r, lam), conj_t(&c.s, gam));
        let (a, scale) = c.unit();
        let a = &a;
        let coef = |i: usize, j: usize| {
            let (s, p) = (a[i] * a[i] + a[j] * a[j], 2.0 * a[i] * a[j]);
            let d = (a[i] * a[i] - a[j] * a[j]).powi(2);
            (s / d, p / d)
        };
        let n = self.n();
        let xi = skew_from_fn(n, |i, j| {
            let (s, p) = coef(i, j);
            s * l[(i, j)] + p * g[(i, j)]
        });
        let eta = skew_from_fn(n, |i, j| {
            let (s, p) = coef(i, j);
            s * g[(i, j)] + p * l[(i, j)]
        });
        let what = "B_X⁻¹ (λ ⊕ γ)";
        Ok((
            rescale(what, conj(&c.r, &xi), scale, k)?,
            rescale(what, conj(&c.s, &eta), scale, k)?,
        ))
    }

    /// The minimum-norm least-squares solution B_X⁺(λ ⊕ γ), defined on every stratum: in the SVD
    /// frame each (i, j) block of B_A is diagonalised by (e_ij ⊕ ±e_ij)/√2 with eigenvalues
    /// (a_i ∓ a_j)² (001 (8.15)); components along eigenvalues with a_i − a_j ≤
    /// [`gl::STRATUM_TOL`]·a₁ are dropped. Equals [`BiInertia::solve`] on the principal stratum.
    /// Used for the two-sided vertical projection, which is defined everywhere.
    pub fn solve_least_squares(&self, lam: &Mat, gam: &Mat) -> Result<(Mat, Mat)> {
        self.arg("lam", lam)?;
        self.arg("gam", gam)?;
        self.solve_least_squares_scaled(lam, gam, 2)
    }

    /// B_X̃⁺ (λ ⊕ γ) / c^k (see [`BiInertia::left_solve_scaled`]).
    pub(crate) fn solve_least_squares_scaled(
        &self,
        lam: &Mat,
        gam: &Mat,
        k: i32,
    ) -> Result<(Mat, Mat)> {
        let c = self.svd()?;
        let (l, g) = (conj_t(&c.r, lam), conj_t(&c.s, gam));
        let (a, scale) = c.unit();
        let a = &a;
        let tol = gl::STRATUM_TOL * a[0];
        // Halves of the components along (1, 1) and (1, −1), divided by their eigenvalues.
        let parts = |i: usize, j: usize| {
            let (x, y) = (l[(i, j)], g[(i, j)]);
            let plus = if a[i] - a[j] > tol {
                (x + y) / (2.0 * (a[i] - a[j]).powi(2))
            } else {
                0.0
            };
            (plus, (x - y) / (2.0 * (a[i] + a[j]).powi(2)))
        };
        let n = self.n();
        let xi = skew_from_fn(n, |i, j| {
            let (p, m) = parts(i, j);
            p + m
        });
        let eta = skew_from_fn(n, |i, j| {
            let (p, m) = parts(i, j);
            p - m
        });
        let what = "B_X⁻¹ (λ ⊕ γ)";
        Ok((
            rescale(what, conj(&c.r, &xi), scale, k)?,
            rescale(what, conj(&c.s, &eta), scale, k)?,
        ))
    }

    /// Eigen-decomposition of B_X on all of GL⁺(n) (001 (8.14)–(8.15) with (6.11)): the
    /// eigenvalues are (a_i − a_j)² and (a_i + a_j)² (i < j) with orthonormal eigenvectors
    /// Ad_(R,S)(e_ij ⊕ ±e_ij)/√2 = (R e_ij Rᵀ ⊕ ±S e_ij Sᵀ)/√2. (8.15) checked numerically:
    /// correct as printed; the unit-norm vectors need the factor 1/√2 under the pairing (6.8).
    ///
    /// Returns the eigenvalues in non-decreasing order and the n(n−1)×n(n−1) matrix whose
    /// columns are the eigenvectors in e_ij coordinates (ξ block first), so B = V diag(λ) Vᵀ.
    /// Errors: an overflow error where an eigenvalue (a_i + a_j)² exceeds the f64 range.
    pub fn eigen(&self) -> Result<(Vec<f64>, Mat)> {
        let c = self.svd()?;
        let (n, d) = (self.n(), so::dim(self.n()));
        let mut pairs: Vec<(f64, usize, usize, f64)> = Vec::with_capacity(2 * d);
        for i in 0..n {
            for j in i + 1..n {
                for sign in [1.0, -1.0] {
                    pairs.push((eigenvalue("X", c.a[i], c.a[j], sign)?, i, j, sign));
                }
            }
        }
        pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut v = Mat::zeros(2 * d, 2 * d);
        for (col, &(_, i, j, sign)) in pairs.iter().enumerate() {
            // (g e_ij gᵀ)_pq = g_pi g_qj − g_pj g_qi for p < q.
            let mut k = 0;
            for p in 0..n {
                for q in p + 1..n {
                    v[(k, col)] = h * (c.r[(p, i)] * c.r[(q, j)] - c.r[(p, j)] * c.r[(q, i)]);
                    v[(d + k, col)] =
                        sign * h * (c.s[(p, i)] * c.s[(q, j)] - c.s[(p, j)] * c.s[(q, i)]);
                    k += 1;
                }
            }
        }
        Ok((pairs.iter().map(|p| p.0).collect(), v))
    }

    /// The quadratic form ⟨ξ ⊕ η, B_X(ξ ⊕ η)⟩ in SVD coordinates (001 (6.14)): with
    /// ξ' = Rᵀξ R, η' = Sᵀη S,
    /// Σ_{i<j} (a_i − a_j)² ξ'_ij² + 2 a_i a_j (ξ'_ij − η'_ij)² + (a_i − a_j)² η'_ij².
    /// Checked against the operator: correct as printed. Scale-aware (evaluated on a/c and on
    /// ξ, η divided by a common power of two, multiplied back once): an overflow error where the
    /// value exceeds the f64 range.
    pub fn quadratic_form(&self, xi: &Mat, eta: &Mat) -> Result<f64> {
        self.arg("xi", xi)?;
        self.arg("eta", eta)?;
        let c = self.svd()?;
        let (xi, eta, e) = Self::scaled_pair(xi, eta);
        let (x, y) = (conj_t(&c.r, &xi), conj_t(&c.s, &eta));
        let (a, scale) = c.unit();
        let a = &a;
        let mut sum = 0.0;
        for i in 0..self.n() {
            for j in i + 1..self.n() {
                let d2 = (a[i] - a[j]).powi(2);
                let (u, w) = (x[(i, j)], y[(i, j)]);
                sum += d2 * u * u + 2.0 * a[i] * a[j] * (u - w).powi(2) + d2 * w * w;
            }
        }
        // scale is an exact power of two.
        let ec = scale.log2() as i32;
        check::unscale("X, xi, eta", "⟨ξ ⊕ η, B_X(ξ ⊕ η)⟩", sum, 2 * ec + 2 * e)
    }
}
