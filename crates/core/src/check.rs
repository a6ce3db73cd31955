//! Input validation shared by every module: finiteness, squareness, sizes.

use crate::error::{Error, Result};
use crate::Mat;

/// Checks that every entry of `m` is finite.
pub fn finite_mat(what: &str, m: &Mat) -> Result<()> {
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if !m[(i, j)].is_finite() {
                return Err(Error::NonFinite {
                    what: what.into(),
                    location: format!("({i}, {j})"),
                });
            }
        }
    }
    Ok(())
}

/// Checks that every entry of a slice is finite.
pub fn finite_slice(what: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(Error::NonFinite {
            what: what.into(),
            location: format!("index {i}"),
        }),
        None => Ok(()),
    }
}

/// Checks that `m` is square n×n with n ≥ `min_n` and finite; returns n.
pub fn square(what: &str, m: &Mat, min_n: usize) -> Result<usize> {
    let (r, c) = (m.nrows(), m.ncols());
    if r != c || r < min_n {
        return Err(Error::shape(
            what,
            format!("a square (n, n) matrix with n ≥ {min_n}"),
            format!("({r}, {c})"),
        ));
    }
    finite_mat(what, m)?;
    Ok(r)
}

/// Checks that `m` is n×n (n given) and finite.
pub fn square_of(what: &str, m: &Mat, n: usize) -> Result<()> {
    if m.nrows() != n || m.ncols() != n {
        return Err(Error::shape(
            what,
            format!("({n}, {n})"),
            format!("({}, {})", m.nrows(), m.ncols()),
        ));
    }
    finite_mat(what, m)
}

/// Checks that a slice has length `len` and is finite.
pub fn len_of(what: &str, v: &[f64], len: usize) -> Result<()> {
    if v.len() != len {
        return Err(Error::shape(
            what,
            format!("({len},)"),
            format!("({},)", v.len()),
        ));
    }
    finite_slice(what, v)
}

/// Checks that a scalar is finite and strictly positive.
pub fn positive(what: &str, x: f64) -> Result<()> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            what,
            format!(
                "expected a finite number > 0, got {}",
                crate::error::fmt_num(x)
            ),
        ))
    }
}

/// Largest dense array lieflow allocates on request: 2²⁸ entries (2 GiB of f64). Larger requests
/// (e.g. the n(n−1)×n(n−1) bi-inertia matrix at n ≳ 130) are refused with a clear error instead
/// of aborting the process when the allocation fails.
pub const MAX_DENSE_ENTRIES: usize = 1 << 28;

/// Checks that a dense `rows × cols` array fits [`MAX_DENSE_ENTRIES`] (without overflow).
pub fn dense_size(what: &str, rows: usize, cols: usize) -> Result<()> {
    match rows.checked_mul(cols) {
        Some(k) if k <= MAX_DENSE_ENTRIES => Ok(()),
        _ => Err(Error::invalid(
            what,
            format!(
                "a dense {rows}×{cols} array exceeds the limit of {MAX_DENSE_ENTRIES} entries \
                 (2 GiB); use the operator form or a smaller n"
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_nan_and_shape() {
        let mut m = Mat::zeros(3, 3);
        assert_eq!(square("X", &m, 2), Ok(3));
        m[(1, 2)] = f64::NAN;
        assert!(matches!(square("X", &m, 2), Err(Error::NonFinite { .. })));
        let r = Mat::zeros(2, 3);
        assert!(matches!(square("X", &r, 2), Err(Error::Shape { .. })));
        assert!(positive("dt", 0.0).is_err());
        assert!(positive("dt", f64::INFINITY).is_err());
        assert!(len_of("v", &[1.0, 2.0], 3).is_err());
        assert!(len_of("v", &[1.0, f64::NAN], 2).is_err());
        assert!(dense_size("B", 1 << 14, 1 << 14).is_ok());
        assert!(dense_size("B", (1 << 14) + 1, 1 << 14).is_err());
        assert!(dense_size("B", usize::MAX, 2).is_err());
    }
}
