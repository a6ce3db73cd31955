//! SO(n) × SO(n), the symmetry group of the pseudo-rigid body (001 §6–7), and its Lie algebra
//! so(n) ⊕ so(n).
//!
//! Elements are pairs (g, h); the algebra elements are pairs (ξ, η) with coordinates ξ block
//! first, then η block (DESIGN.md). The matrix representation is block diagonal, diag(g, h) of
//! size 2n × 2n. Everything is componentwise: Ad_(g,h) = Ad_g ⊕ Ad_h, the bracket of
//! 001 (7.26), and the pairing is the sum of the so(n) pairings (001 (6.8)).

use crate::error::{Error, Result};
use crate::lie::so::{self, SOn};
use crate::lie::MatrixLieGroup;
use crate::Mat;

/// An element of so(n) ⊕ so(n): (ξ, η).
pub type PairAlgebra = (Mat, Mat);

/// An element (g, h) of SO(n) × SO(n).
#[derive(Clone, Debug)]
pub struct SOnProduct {
    /// First factor (acting on the left in 001: R).
    pub g: SOn,
    /// Second factor (001: S).
    pub h: SOn,
}

impl SOnProduct {
    /// Validates both factors as rotations of the same size n ≥ 2.
    pub fn new(g: Mat, h: Mat) -> Result<Self> {
        let g = SOn::new(g)?;
        let h = SOn::new(h)?;
        if g.n() != h.n() {
            return Err(Error::shape(
                "h",
                format!("({0}, {0}) like g", g.n()),
                format!("({0}, {0})", h.n()),
            ));
        }
        Ok(Self { g, h })
    }

    /// The identity (I, I) of SO(n) × SO(n).
    pub fn identity(n: usize) -> Result<Self> {
        Ok(Self {
            g: SOn::identity(n)?,
            h: SOn::identity(n)?,
        })
    }

    /// The size n of each factor.
    pub fn n(&self) -> usize {
        self.g.n()
    }
}

/// Checks that (ξ, η) is a pair of n×n skew matrices of one size; returns n. `names` are the
/// names of the two components in errors (the arguments as the caller spells them, e.g.
/// ("xi", "eta") or ("xi1", "eta1")).
pub fn check_pair(names: [&str; 2], x: &PairAlgebra) -> Result<usize> {
    let n = so::check_algebra(names[0], &x.0)?;
    so::check_algebra_of(names[1], &x.1, n)?;
    Ok(n)
}

/// [`check_pair`] for a given n.
fn check_pair_of(names: [&str; 2], x: &PairAlgebra, n: usize) -> Result<()> {
    so::check_algebra_of(names[0], &x.0, n)?;
    so::check_algebra_of(names[1], &x.1, n)
}

/// Ad_(g,h)(ξ, η) = (g ξ gᵀ, h η hᵀ) (001 (7.23): Ad on so(n) ⊕ so(n) is componentwise).
pub fn adjoint(g: &Mat, h: &Mat, x: &PairAlgebra) -> Result<PairAlgebra> {
    let n = check_pair(["xi", "eta"], x)?;
    let gn = so::check_rotation("g", g)?;
    so::check_rotation("h", h)?;
    if gn != n || h.nrows() != n {
        return Err(Error::shape(
            "(g, h)",
            format!("two ({n}, {n}) rotations matching (xi, eta)"),
            format!("({gn}, {gn}) and ({0}, {0})", h.nrows()),
        ));
    }
    Ok((g * &x.0 * g.transpose(), h * &x.1 * h.transpose()))
}

/// The bracket on so(n) ⊕ so(n), 001 (7.26): [(ξ', η'), (ξ, η)] = ([ξ', ξ], [η', η]).
pub fn bracket(a: &PairAlgebra, b: &PairAlgebra) -> Result<PairAlgebra> {
    let n = check_pair(["xi1", "eta1"], a)?;
    let m = check_pair(["xi2", "eta2"], b)?;
    if m != n {
        return Err(Error::shape(
            "(xi2, eta2)",
            format!("two ({n}, {n}) skew matrices like (xi1, eta1)"),
            format!("({m}, {m})"),
        ));
    }
    Ok(bracket_unchecked(a, b))
}

fn bracket_unchecked(a: &PairAlgebra, b: &PairAlgebra) -> PairAlgebra {
    (so::bracket(&a.0, &b.0), so::bracket(&a.1, &b.1))
}

/// The pairing on so(n) ⊕ so(n): ⟨(μ, ν), (ξ, η)⟩ = ⟨μ, ξ⟩ + ⟨ν, η⟩ (001 (6.8)).
pub fn pairing(a: &PairAlgebra, b: &PairAlgebra) -> Result<f64> {
    let n = check_pair(["xi1", "eta1"], a)?;
    check_pair_of(["xi2", "eta2"], b, n)?;
    Ok(pairing_unchecked(a, b))
}

fn pairing_unchecked(a: &PairAlgebra, b: &PairAlgebra) -> f64 {
    so::pairing(&a.0, &b.0) + so::pairing(&a.1, &b.1)
}

fn block_diag(a: &Mat, b: &Mat) -> Mat {
    let n = a.nrows();
    Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => a[(i, j)],
        (false, false) => b[(i - n, j - n)],
        _ => 0.0,
    })
}

impl MatrixLieGroup for SOnProduct {
    type Algebra = PairAlgebra;
    type Point = (Vec<f64>, Vec<f64>);

    fn dim(&self) -> usize {
        2 * so::dim(self.n())
    }
    fn identity_like(&self) -> Self {
        Self {
            g: self.g.identity_like(),
            h: self.h.identity_like(),
        }
    }
    fn compose(&self, other: &Self) -> Self {
        Self {
            g: self.g.compose(&other.g),
            h: self.h.compose(&other.h),
        }
    }
    fn inverse(&self) -> Self {
        Self {
            g: self.g.inverse(),
            h: self.h.inverse(),
        }
    }
    /// (g x, h y).
    fn act(&self, p: &(Vec<f64>, Vec<f64>)) -> (Vec<f64>, Vec<f64>) {
        (self.g.act(&p.0), self.h.act(&p.1))
    }
    /// (exp ξ, exp η), after checking that ξ, η have one size ([`check_pair`]).
    fn exp(x: &PairAlgebra) -> Result<Self> {
        check_pair(["xi", "eta"], x)?;
        Ok(Self {
            g: SOn::exp(&x.0)?,
            h: SOn::exp(&x.1)?,
        })
    }
    fn exp_unchecked(x: &PairAlgebra) -> Self {
        Self {
            g: SOn::exp_unchecked(&x.0),
            h: SOn::exp_unchecked(&x.1),
        }
    }
    fn log(&self) -> Result<PairAlgebra> {
        Ok((self.g.log()?, self.h.log()?))
    }
    fn adjoint(&self, x: &PairAlgebra) -> PairAlgebra {
        (self.g.adjoint(&x.0), self.h.adjoint(&x.1))
    }
    fn ad(a: &PairAlgebra, b: &PairAlgebra) -> PairAlgebra {
        bracket_unchecked(a, b)
    }
    fn ad_star(x: &PairAlgebra, mu: &PairAlgebra) -> PairAlgebra {
        (SOn::ad_star(&x.0, &mu.0), SOn::ad_star(&x.1, &mu.1))
    }
    fn pairing(mu: &PairAlgebra, x: &PairAlgebra) -> f64 {
        pairing_unchecked(mu, x)
    }
    fn matrix(&self) -> Mat {
        block_diag(self.g.as_mat(), self.h.as_mat())
    }
    fn hat(x: &PairAlgebra) -> Mat {
        block_diag(&x.0, &x.1)
    }
    /// The diagonal blocks of a block-diagonal 2n × 2n matrix (off-diagonal blocks zero to
    /// [`so::SKEW_TOL`] relative, as the skew test of so(n)).
    fn vee(m: &Mat) -> Result<PairAlgebra> {
        let size = crate::check::square("xi", m, 4)?;
        if size % 2 == 1 {
            return Err(Error::shape(
                "xi",
                "a (2n, 2n) block-diagonal matrix",
                format!("({size}, {size})"),
            ));
        }
        let n = size / 2;
        let off = m.subrows(0, n).subcols(n, n).norm_l2() + m.subrows(n, n).subcols(0, n).norm_l2();
        let defect = off / m.norm_l2().max(1.0);
        if defect > so::SKEW_TOL {
            return Err(Error::NotInGroup {
                what: "xi".into(),
                group: format!("so({n}) ⊕ so({n})"),
                defect_name: "off-diagonal blocks ‖·‖_F / max(1, ‖ξ‖_F)".into(),
                defect,
                tol: so::SKEW_TOL,
            });
        }
        let x = (
            m.subrows(0, n).subcols(0, n).to_owned(),
            m.subrows(n, n).subcols(n, n).to_owned(),
        );
        check_pair(["xi", "eta"], &x)?;
        Ok(x)
    }
    fn coords(x: &PairAlgebra) -> Vec<f64> {
        let mut c = so::vee_n_unchecked(&x.0);
        c.extend(so::vee_n_unchecked(&x.1));
        c
    }
    fn jacobian_right(x: &PairAlgebra) -> Result<Mat> {
        check_pair(["xi", "eta"], x)?;
        Ok(block_diag(
            &so::jacobian_right(&x.0)?,
            &so::jacobian_right(&x.1)?,
        ))
    }
    fn jacobian_left(x: &PairAlgebra) -> Result<Mat> {
        check_pair(["xi", "eta"], x)?;
        Ok(block_diag(
            &so::jacobian_left(&x.0)?,
            &so::jacobian_left(&x.1)?,
        ))
    }
    fn jacobian_right_inv(x: &PairAlgebra) -> Result<Mat> {
        check_pair(["xi", "eta"], x)?;
        Ok(block_diag(
            &so::jacobian_right_inv(&x.0)?,
            &so::jacobian_right_inv(&x.1)?,
        ))
    }
    fn jacobian_left_inv(x: &PairAlgebra) -> Result<Mat> {
        check_pair(["xi", "eta"], x)?;
        Ok(block_diag(
            &so::jacobian_left_inv(&x.0)?,
            &so::jacobian_left_inv(&x.1)?,
        ))
    }
    fn algebra_from_coords(&self, c: &[f64]) -> PairAlgebra {
        let d = so::dim(self.n());
        let (a, b) = c.split_at(d.min(c.len()));
        (
            so::hat_n_unchecked(self.n(), a),
            so::hat_n_unchecked(self.n(), b),
        )
    }
}
