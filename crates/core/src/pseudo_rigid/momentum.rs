//! Momenta, body coordinates and kinetic energy of a pseudo-rigid body (001 §2.4, §4, §5, §6.4).
//!
//! With the metric tr(YᵀZ) (001 (2.9)) a velocity Ẋ and a momentum P are the same matrix, so
//! every function taking a velocity `v` also takes a momentum P: L = PXᵀ − XPᵀ and
//! Γ = PᵀX − XᵀP (001 (7.3), DESIGN.md) are (2.29) with P = Ẋ.

use nalgebra::Vector3;

use super::inertia::BiInertia;
use crate::error::{Error, Result};
use crate::lie::gl::{self, SvdCoordinates};
use crate::lie::so;
use crate::{check, Mat};

/// Checks a configuration X ∈ GL⁺(n) and a velocity/momentum V of the same size; returns n.
fn check_state(x: &Mat, v: &Mat) -> Result<usize> {
    let n = gl::check_gl_plus("X", x)?;
    check::square_of("V", v, n)?;
    Ok(n)
}

/// J = L ⊕ Γ without checks (shared with the connections).
pub(crate) fn momentum_map_unchecked(x: &Mat, p: &Mat) -> (Mat, Mat) {
    let pxt = p * x.transpose();
    let ptx = p.transpose() * x;
    (&pxt - pxt.transpose(), &ptx - ptx.transpose())
}

/// J = L ⊕ Γ scale-aware, for finite X and P: evaluated on X and P divided by powers of two
/// ([`check::pow2_exponent`]; the plain formula for moderate values) and multiplied back once,
/// each part an overflow error (naming X, P) where it exceeds the f64 range.
pub(crate) fn momentum_map_scaled(x: &Mat, p: &Mat) -> (Result<Mat>, Result<Mat>) {
    let (ex, ep) = (check::pow2_exponent_mat(x), check::pow2_exponent_mat(p));
    let (l, g) = momentum_map_unchecked(&check::ldexp_mat(x, -ex), &check::ldexp_mat(p, -ep));
    let what = "X, P";
    (
        check::unscale_mat(what, "the angular momentum L = PXᵀ − XPᵀ", &l, ex + ep),
        check::unscale_mat(what, "the circulation Γ = PᵀX − XᵀP", &g, ex + ep),
    )
}

/// Angular momentum L = VXᵀ − XVᵀ (001 (2.29), (7.3)) for a velocity or momentum V at X.
/// Scale-aware; an overflow error where L exceeds the f64 range.
pub fn angular_momentum(x: &Mat, v: &Mat) -> Result<Mat> {
    check_state(x, v)?;
    momentum_map_scaled(x, v).0
}

/// Circulation Γ = VᵀX − XᵀV (001 (2.29), (7.3)) for a velocity or momentum V at X.
/// Scale-aware; an overflow error where Γ exceeds the f64 range.
pub fn circulation(x: &Mat, v: &Mat) -> Result<Mat> {
    check_state(x, v)?;
    momentum_map_scaled(x, v).1
}

/// Kelvin's circulation ∮_C v·dx of the material loop C = X(C₀) (001 §2.5, (2.34)): C₀ is the
/// closed polygon through the label points u_0, …, u_{m−1} (rows of `labels`, m × n; closed back
/// to u_0), its particles sit at x = Xu and move with v = Vu. Computed in space, segment by
/// segment: v is linear and dx constant along a segment, so ∫ v·dx = ½(v_k + v_{k+1})·(x_{k+1} −
/// x_k) exactly. Equals ⟨Γ, ζ⟩ = ½ tr(Γᵀζ) with Γ = VᵀX − XᵀV and ζ = [`loop_area`] (2.35) —
/// the circulation Γ is the loop integral of every loop at once, so Kelvin's theorem (the loop
/// integral is constant along the motion) is the conservation of Γ.
pub fn loop_circulation(x: &Mat, v: &Mat, labels: &Mat) -> Result<f64> {
    let n = check_state(x, v)?;
    check_loop(labels, n)?;
    let (xs, vs) = (labels * x.transpose(), labels * v.transpose());
    let m = labels.nrows();
    let mut s = 0.0;
    for k in 0..m {
        let l = (k + 1) % m;
        for i in 0..n {
            s += 0.5 * (vs[(k, i)] + vs[(l, i)]) * (xs[(l, i)] - xs[(k, i)]);
        }
    }
    if !s.is_finite() {
        return Err(check::overflow_error("labels", "∮ v·dx"));
    }
    Ok(s)
}

/// The oriented areas ζ_ij = ∫_{S₀} du_i ∧ du_j = ∮_{C₀} u_i du_j (001 (2.36)) of the closed
/// polygon C₀ through the rows of `labels` (m × n, m ≥ 3): a skew n×n matrix (ζ_ij is the area of
/// the loop's projection onto the (i, j) plane, counterclockwise positive). Exact for the polygon
/// (u_i is linear and du_j constant along a segment); the skew part is taken, which removes the
/// round-off of the exact zero ∮ d(u_i u_j)/2.
pub fn loop_area(labels: &Mat) -> Result<Mat> {
    let n = labels.ncols();
    check_loop(labels, n)?;
    let m = labels.nrows();
    let mut z = Mat::zeros(n, n);
    for k in 0..m {
        let l = (k + 1) % m;
        for i in 0..n {
            for j in 0..n {
                z[(i, j)] +=
                    0.5 * (labels[(k, i)] + labels[(l, i)]) * (labels[(l, j)] - labels[(k, j)]);
            }
        }
    }
    let z = (&z - z.transpose()) * faer::Scale(0.5);
    check::finite_mat("loop area", &z).map_err(|_| check::overflow_error("labels", "ζ"))?;
    Ok(z)
}

/// A loop's label points: m ≥ 3 rows of n finite values.
fn check_loop(labels: &Mat, n: usize) -> Result<()> {
    if labels.ncols() != n || labels.nrows() < 3 {
        return Err(Error::shape(
            "labels",
            format!("(m, {n}) with m ≥ 3 points of a closed loop"),
            format!("({}, {})", labels.nrows(), labels.ncols()),
        ));
    }
    check::finite_mat("labels", labels)
}

/// Momentum map J(X, P) = L ⊕ Γ of the two-sided SO(n)×SO(n) action (001 (7.2)).
/// Scale-aware; an overflow error where L or Γ exceeds the f64 range.
pub fn momentum_map(x: &Mat, p: &Mat) -> Result<(Mat, Mat)> {
    check_state(x, p)?;
    let (l, g) = momentum_map_scaled(x, p);
    Ok((l?, g?))
}

/// Local coordinates (R, A, S, Ω, Ȧ, Λ) of T GL⁺(n) (001 §4.1, (2.33)): X = R A Sᵀ,
/// Ω = RᵀṘ, Λ = SᵀṠ.
#[derive(Debug, Clone)]
pub struct Body {
    /// R ∈ SO(n).
    pub r: Mat,
    /// Singular values a (the diagonal of A).
    pub a: Vec<f64>,
    /// S ∈ SO(n).
    pub s: Mat,
    /// Ω = RᵀṘ ∈ so(n).
    pub omega: Mat,
    /// Ȧ (the diagonal).
    pub adot: Vec<f64>,
    /// Λ = SᵀṠ ∈ so(n).
    pub lambda: Mat,
}

/// Body coordinates of (X, Ẋ) on the principal stratum (001 §4.1). With X = R A Sᵀ
/// ([`gl::svd_coordinates`]) differentiation gives RᵀẊS = ΩA + Ȧ − AΛ =: M; the diagonal is Ȧ
/// and for i ≠ j the pair (M_ij, M_ji) = (a_j Ω_ij − a_i Λ_ij, −a_i Ω_ij + a_j Λ_ij) solves to
/// Ω_ij = (a_j M_ij + a_i M_ji)/(a_j² − a_i²), Λ_ij = (a_i M_ij + a_j M_ji)/(a_j² − a_i²).
///
/// Errors: X ∉ GL⁺(n), V of the wrong shape or non-finite, [`Error::DegenerateStratum`] off the
/// principal stratum (Ω and Λ are not determined there).
pub fn to_body(x: &Mat, v: &Mat) -> Result<Body> {
    let n = check_state(x, v)?;
    let c = gl::svd_coordinates(x)?;
    c.require_principal("body coordinates (Ω, Λ)")?;
    // Scale-aware: Ω, Λ are of degree −1 in a, so they are formed from ã = a/c (c a power of
    // two, [`SvdCoordinates::unit`]) and divided by c once; a_j² − a_i² would underflow below
    // ~1e-154 and overflow above ~1e154.
    let (u, scale) = c.unit();
    let SvdCoordinates { r, a, s } = c;
    let m = r.transpose() * v * &s;
    let mut omega = Mat::zeros(n, n);
    let mut lambda = Mat::zeros(n, n);
    for i in 0..n {
        for j in i + 1..n {
            let den = (u[j] - u[i]) * (u[j] + u[i]);
            let (mij, mji) = (m[(i, j)], m[(j, i)]);
            let o = (u[j] * mij + u[i] * mji) / den / scale;
            let l = (u[i] * mij + u[j] * mji) / den / scale;
            if !(o.is_finite() && l.is_finite()) {
                return Err(Error::overflow(
                    "V",
                    format!(
                        "the body velocities Ω, Λ exceed the f64 range (|V| / a ≈ {})",
                        crate::error::fmt_num(m.norm_l2() / a[n - 1])
                    ),
                ));
            }
            omega[(i, j)] = o;
            omega[(j, i)] = -o;
            lambda[(i, j)] = l;
            lambda[(j, i)] = -l;
        }
    }
    let adot = (0..n).map(|i| m[(i, i)]).collect();
    Ok(Body {
        r,
        a,
        s,
        omega,
        adot,
        lambda,
    })
}

impl Body {
    /// Checks shapes, finiteness, R, S ∈ SO(n), a_i > 0, Ω, Λ ∈ so(n).
    pub fn validate(&self) -> Result<usize> {
        let n = self.a.len();
        gl::from_svd(&self.r, &self.a, &self.s)?;
        check::len_of("adot", &self.adot, n)?;
        so::check_algebra_of("Omega", &self.omega, n)?;
        so::check_algebra_of("Lambda", &self.lambda, n)?;
        Ok(n)
    }

    /// A = diag(a).
    pub fn a_matrix(&self) -> Mat {
        diag(&self.a)
    }

    /// (X, Ẋ) from body coordinates: X = R A Sᵀ, Ẋ = R(ΩA + Ȧ − AΛ)Sᵀ (001 §4.1, from
    /// Ṙ = RΩ, Ṡ = SΛ). Defined on every stratum.
    pub fn to_state(&self) -> Result<(Mat, Mat)> {
        self.validate()?;
        let a = self.a_matrix();
        let x = &self.r * &a * self.s.transpose();
        let m = &self.omega * &a + diag(&self.adot) - &a * &self.lambda;
        Ok((x, &self.r * m * self.s.transpose()))
    }

    /// Body momenta p_Ω ⊕ p_Λ = B_A(Ω ⊕ Λ) = (A²Ω + ΩA² − 2AΛA) ⊕ (A²Λ + ΛA² − 2AΩA)
    /// (001 (4.15), (6.27), (6.29)); equal to RᵀLR ⊕ SᵀΓS (001 (2.32)).
    pub fn momenta(&self) -> Result<(Mat, Mat)> {
        self.validate()?;
        body_momenta(&self.a, &self.omega, &self.lambda)
    }

    /// The E term of 001 (4.8): E = 𝔇(−(Ω² + Λ²)A + ΩAΛ + ΛAΩ) = ∂K/∂A at fixed Ω, Λ, Ȧ
    /// (the diagonal, as a vector). Checked against finite differences of (4.5).
    pub fn e_term(&self) -> Result<Vec<f64>> {
        self.validate()?;
        Ok(e_term_unchecked(&self.a, &self.omega, &self.lambda))
    }

    /// Kinetic energy in body coordinates (001 (4.5)):
    /// K = ½ tr(Ȧ² − A²(Ω² + Λ²) + 2ΩAΛA).
    pub fn kinetic_energy(&self) -> Result<f64> {
        self.validate()?;
        let a = self.a_matrix();
        let (o, l) = (&self.omega, &self.lambda);
        let m = -(&a * &a) * (o * o + l * l) + o * &a * l * &a * faer::Scale(2.0);
        let tr: f64 = (0..self.a.len()).map(|i| m[(i, i)]).sum();
        Ok(0.5 * (dot(&self.adot, &self.adot) + tr))
    }

    /// Kinetic energy through the momenta (001 (4.12)):
    /// K = ½⟨Ȧ, Ȧ⟩ + ½(⟨Ω, RᵀLR⟩ + ⟨Λ, SᵀΓS⟩), with RᵀLR, SᵀΓS computed from (X, Ẋ).
    pub fn kinetic_energy_momenta(&self) -> Result<f64> {
        let (x, v) = self.to_state()?;
        let (l, g) = momentum_map_unchecked(&x, &v);
        let (lb, gb) = (
            self.r.transpose() * l * &self.r,
            self.s.transpose() * g * &self.s,
        );
        Ok(0.5 * dot(&self.adot, &self.adot)
            + 0.5 * (so::pairing(&self.omega, &lb) + so::pairing(&self.lambda, &gb)))
    }

    /// Kinetic energy through the bi-inertia tensor (001 (6.28)):
    /// K = ½⟨Ȧ, Ȧ⟩ + ½⟨Ω ⊕ Λ, B_A(Ω ⊕ Λ)⟩.
    pub fn kinetic_energy_bi_inertia(&self) -> Result<f64> {
        let (po, pl) = self.momenta()?;
        Ok(0.5 * dot(&self.adot, &self.adot)
            + 0.5 * (so::pairing(&self.omega, &po) + so::pairing(&self.lambda, &pl)))
    }
}

/// Checks the arguments (A = diag(a), Ω, Λ) of the formulas in body coordinates that need no
/// frames (E of (4.8), the Euler–Lagrange equations of 001 Prop. 4.2): a of length n ≥ 2, finite,
/// every a_i > 0; Ω, Λ finite, n×n and skew (to [`so::SKEW_TOL`]). Returns n.
pub fn check_velocities(a: &[f64], omega: &Mat, lambda: &Mat) -> Result<usize> {
    let n = a.len();
    if n < 2 {
        return Err(Error::shape("a", "(n,) with n ≥ 2", format!("({n},)")));
    }
    check::finite_slice("a", a)?;
    if let Some(i) = a.iter().position(|&ai| ai <= 0.0) {
        return Err(Error::invalid(
            "a",
            format!("singular values must be > 0, got a[{i}] = {}", a[i]),
        ));
    }
    for (what, m) in [("Omega", omega), ("Lambda", lambda)] {
        check::square_of(what, m, n)?;
        check::finite_mat(what, m)?;
        so::check_algebra_of(what, m, n)?;
    }
    Ok(n)
}

/// The E term of 001 (4.8) at (A, Ω, Λ) with A = diag(a):
/// E = 𝔇(−(Ω² + Λ²)A + ΩAΛ + ΛAΩ) = ∂K/∂A at fixed Ω, Λ, Ȧ (the diagonal, as a vector).
/// Checked ([`check_velocities`]); [`e_term_3`] is the n = 3 vector form (5.4).
pub fn e_term(a: &[f64], omega: &Mat, lambda: &Mat) -> Result<Vec<f64>> {
    check_velocities(a, omega, lambda)?;
    Ok(e_term_unchecked(a, omega, lambda))
}

/// [`e_term`] without checks (callers validate): the diagonal of −(Ω² + Λ²)A + ΩAΛ + ΛAΩ.
pub(crate) fn e_term_unchecked(a: &[f64], omega: &Mat, lambda: &Mat) -> Vec<f64> {
    let a = diag(a);
    let (o, l) = (omega, lambda);
    let e = -(o * o + l * l) * &a + o * &a * l + l * &a * o;
    (0..a.nrows()).map(|i| e[(i, i)]).collect()
}

/// Body momenta p_Ω ⊕ p_Λ = B_A(Ω ⊕ Λ) at A = diag(a) (001 (4.15), (6.27)); [`Body::momenta`]
/// is the same at a full body state. `a` > 0 in any order, Ω, Λ skew n×n (checked).
pub fn body_momenta(a: &[f64], omega: &Mat, lambda: &Mat) -> Result<(Mat, Mat)> {
    BiInertia::new(&diag(a))?.apply(omega, lambda)
}

/// Kinetic energy K = ½ tr(VᵀV) of a velocity V at X (001 (2.10), (3.2)); with V = P it is
/// the kinetic part of the Hamiltonian (3.22).
pub fn kinetic_energy(x: &Mat, v: &Mat) -> Result<f64> {
    check_state(x, v)?;
    // Scale-aware: |V|² from V divided by a power of two, multiplied back once.
    let e = check::pow2_exponent_mat(v);
    let n2 = check::ldexp_mat(v, -e).norm_l2().powi(2);
    check::unscale("V", "the kinetic energy ½|V|²", 0.5 * n2, 2 * e)
}

/// Kinetic part of the Hamiltonian in reduced coordinates (001 (6.30)):
/// ½⟨p_A, p_A⟩ + ½⟨p_Ω ⊕ p_Λ, B_A⁻¹(p_Ω ⊕ p_Λ)⟩, needing distinct a_i > 0 (principal stratum).
pub fn kinetic_energy_hamiltonian(
    a: &[f64],
    p_a: &[f64],
    p_omega: &Mat,
    p_lambda: &Mat,
) -> Result<f64> {
    check::len_of("p_a", p_a, a.len())?;
    for &ai in a {
        check::positive("a", ai)?;
    }
    let b = BiInertia::new(&diag(a))?;
    let (o, l) = b.solve(p_omega, p_lambda)?;
    Ok(0.5 * dot(p_a, p_a) + 0.5 * (so::pairing(p_omega, &o) + so::pairing(p_lambda, &l)))
}

fn diag(a: &[f64]) -> Mat {
    Mat::from_fn(a.len(), a.len(), |i, j| if i == j { a[i] } else { 0.0 })
}

fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(p, q)| p * q).sum()
}

/// n = 3 body angular momentum m and circulation c (001 (5.3)), with Ω = hat(ω), Λ = hat(λ)
/// (physics hat map, DESIGN.md):
/// m_k = (a_i² + a_j²) ω_k − 2 a_i a_j λ_k, c_k = (a_i² + a_j²) λ_k − 2 a_i a_j ω_k for (i, j, k)
/// cyclic. hat(m) = RᵀLR and hat(c) = SᵀΓS (5.2); checked against the matrix forms (4.15).
pub fn body_momenta_3(
    a: &Vector3<f64>,
    omega: &Vector3<f64>,
    lambda: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let (s, p) = pair_coefficients_3(a);
    (
        s.component_mul(omega) - 2.0 * p.component_mul(lambda),
        s.component_mul(lambda) - 2.0 * p.component_mul(omega),
    )
}

/// (a_i² + a_j², a_i a_j) for the pair (i, j) complementary to each k.
fn pair_coefficients_3(a: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let sq = a.component_mul(a);
    (
        Vector3::new(sq[1] + sq[2], sq[2] + sq[0], sq[0] + sq[1]),
        Vector3::new(a[1] * a[2], a[2] * a[0], a[0] * a[1]),
    )
}

/// n = 3 vector form of E (001 (5.4)):
/// E_1 = a_1(ω_2² + ω_3² + λ_2² + λ_3²) − 2a_2 ω_3 λ_3 − 2a_3 ω_2 λ_2 and cyclically.
/// Checked against the matrix form (4.8): correct as printed.
pub fn e_term_3(a: &Vector3<f64>, omega: &Vector3<f64>, lambda: &Vector3<f64>) -> Vector3<f64> {
    let w2 = omega.component_mul(omega) + lambda.component_mul(lambda);
    let wl = omega.component_mul(lambda);
    Vector3::from_fn(|i, _| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        a[i] * (w2[j] + w2[k]) - 2.0 * a[j] * wl[k] - 2.0 * a[k] * wl[j]
    })
}

/// n = 3 kinetic energy (001 (5.6)):
/// K = ½ Σ ȧ_i² + ½ Σ_cyclic ((a_i² + a_j²)(ω_k² + λ_k²) − 4 a_i a_j ω_k λ_k).
pub fn kinetic_energy_3(
    a: &Vector3<f64>,
    adot: &Vector3<f64>,
    omega: &Vector3<f64>,
    lambda: &Vector3<f64>,
) -> f64 {
    let (s, p) = pair_coefficients_3(a);
    let w2 = omega.component_mul(omega) + lambda.component_mul(lambda);
    0.5 * adot.norm_squared() + 0.5 * (s.dot(&w2) - 4.0 * p.dot(&omega.component_mul(lambda)))
}
