//! Dense linear algebra whose storage is allocated once (faer, sequential): what the inner loops
//! of the implicit methods and the Padé exponential of so(n) solve with.

use crate::Mat;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Accum, MatMut, MatRef, Par};

// Small dense kernels (no allocation; hand loops for tiny n where faer's general machinery costs
// more than the arithmetic).

/// Below this size products use plain loops (faer's matmul has ~90 ns fixed cost at 3×3).
const SMALL: usize = 4;

/// The Euclidean norm √(Σ vᵢ²) of a slice (not scaled: the residuals and tangents of the
/// solvers, far from overflow).
pub(crate) fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// ‖X‖_F² = tr(XᵀX).
pub(crate) fn frob2(x: MatRef<'_, f64>) -> f64 {
    let mut s = 0.0;
    for j in 0..x.ncols() {
        for i in 0..x.nrows() {
            s += x[(i, j)] * x[(i, j)];
        }
    }
    s
}

/// ⟨A, B⟩ = tr(AᵀB).
pub(crate) fn inner(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    let mut s = 0.0;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            s += a[(i, j)] * b[(i, j)];
        }
    }
    s
}

/// y += a x (same shapes).
pub(crate) fn axpy(mut y: MatMut<'_, f64>, a: f64, x: MatRef<'_, f64>) {
    for j in 0..y.ncols() {
        for i in 0..y.nrows() {
            y[(i, j)] += a * x[(i, j)];
        }
    }
}

/// dst = (or +=) alpha · lhs · rhs for square n×n operands (lhs may be a transposed view).
pub(crate) fn mul(
    mut dst: MatMut<'_, f64>,
    accum: Accum,
    lhs: MatRef<'_, f64>,
    rhs: MatRef<'_, f64>,
    alpha: f64,
) {
    let n = dst.nrows();
    if n > SMALL {
        faer::linalg::matmul::matmul(dst, accum, lhs, rhs, alpha, Par::Seq);
        return;
    }
    for j in 0..n {
        for i in 0..n {
            let mut s = 0.0;
            for k in 0..n {
                s += lhs[(i, k)] * rhs[(k, j)];
            }
            match accum {
                Accum::Replace => dst[(i, j)] = alpha * s,
                Accum::Add => dst[(i, j)] += alpha * s,
            }
        }
    }
}

/// Kahan's compensated y += inc, entry by entry: the low-order part each addition loses is kept
/// in `carry` and added back with the next increment, so that an increment which repeats itself
/// below an ulp of y (a steady motion) does not round the same way every step.
pub(crate) fn compensated_add(y: &mut [f64], carry: &mut [f64], inc: &[f64]) {
    for ((yi, ci), &di) in y.iter_mut().zip(carry.iter_mut()).zip(inc) {
        let d = di - *ci;
        let t = *yi + d;
        *ci = (t - *yi) - d;
        *yi = t;
    }
}

/// The Cholesky factor of a symmetric positive definite matrix, in place: `a` ← C, lower
/// triangular with a positive diagonal and CCᵀ = a (the upper triangle is read as the lower's
/// mirror and zeroed). False when `a` is not positive definite (a pivot ≤ 0 or not finite).
pub(crate) fn cholesky(mut a: MatMut<'_, f64>) -> bool {
    let n = a.nrows();
    for j in 0..n {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        let d = d.sqrt();
        a[(j, j)] = d;
        for i in j + 1..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = s / d;
            a[(j, i)] = 0.0;
        }
    }
    true
}

/// b ← C⁻¹b for a lower triangular C with a nonzero diagonal (forward substitution on every
/// column of b).
pub(crate) fn solve_lower(c: MatRef<'_, f64>, mut b: MatMut<'_, f64>) {
    let n = c.nrows();
    for col in 0..b.ncols() {
        for i in 0..n {
            let mut s = b[(i, col)];
            for k in 0..i {
                s -= c[(i, k)] * b[(k, col)];
            }
            b[(i, col)] = s / c[(i, i)];
        }
    }
}

/// A dense n×n LU factorization with partial pivoting (faer) whose storage is allocated once:
/// fill [`DenseLu::matrix`], [`DenseLu::factor`], then [`DenseLu::solve`] any number of times.
/// Shared by the implicit methods (Gauss, RATTLE, the nonholonomic RATTLE) and the Padé
/// exponential of so(n).
pub(crate) struct DenseLu {
    lu: Mat,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
}

impl DenseLu {
    /// Storage for n×n systems.
    pub(crate) fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(n, n.max(1), Par::Seq),
        ]);
        DenseLu {
            lu: Mat::zeros(n, n),
            perm: (0..n).collect(),
            perm_inv: (0..n).collect(),
            mem: MemBuffer::new(req),
        }
    }

    /// The matrix to fill before [`DenseLu::factor`].
    pub(crate) fn matrix(&mut self) -> &mut Mat {
        &mut self.lu
    }

    /// Factors the matrix in place; false when it is not finite or a pivot is zero (singular).
    pub(crate) fn factor(&mut self) -> bool {
        let n = self.lu.nrows();
        for j in 0..n {
            for i in 0..n {
                if !self.lu[(i, j)].is_finite() {
                    return false;
                }
            }
        }
        factor::lu_in_place(
            self.lu.as_mut(),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        (0..n).all(|i| {
            let u = self.lu[(i, i)];
            u != 0.0 && u.is_finite()
        })
    }

    /// Solves the factored system in place for every column of `b` (n rows).
    pub(crate) fn solve_columns(&mut self, b: MatMut<'_, f64>) {
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, self.lu.nrows());
        solve::solve_in_place(
            self.lu.as_ref(),
            self.lu.as_ref(),
            perm,
            b,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }

    /// Solves the factored system in place (`b` has n values).
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        let n = b.len();
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        // `solve_in_place` reads the unit lower triangle of its L argument and the upper
        // triangle of its U argument, so the packed factor serves as both.
        solve::solve_in_place(
            self.lu.as_ref(),
            self.lu.as_ref(),
            perm,
            MatMut::from_column_major_slice_mut(b, n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dense_lu_solves_and_detects_singular_matrices() {
        let mut lu = DenseLu::new(3);
        let a = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
        for (i, row) in a.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                lu.matrix()[(i, j)] = *v;
            }
        }
        assert!(lu.factor());
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = a
            .iter()
            .map(|r| r.iter().zip(&x).map(|(p, q)| p * q).sum())
            .collect();
        lu.solve(&mut b);
        for (u, v) in b.iter().zip(&x) {
            assert!((u - v).abs() < 1e-15);
        }
        *lu.matrix() = Mat::zeros(3, 3);
        assert!(!lu.factor());
        lu.matrix()[(0, 0)] = f64::NAN;
        assert!(!lu.factor());
    }
}
