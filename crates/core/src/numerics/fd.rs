//! Finite differences: the one Jacobian (and gradient, its one-row case) by central differences
//! of the analysis layers, the relative-equilibrium solvers and the user-defined systems. The
//! steps are the caller's (each has its own rule: the step is part of its result), the scheme is
//! a parameter.

use crate::Mat;

/// The difference quotient of a column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// D(h) = (f(x + h e_l) − f(x − h e_l))/2h, error O(h²).
    Central,
    /// One Richardson extrapolation (4D(h/2) − D(h))/3, error O(h⁴).
    Richardson,
}

/// Jacobian of f at x (column l = ∂f/∂x_l) with steps h_l by `scheme`; the first error of f is
/// returned.
pub(crate) fn jacobian<E, F>(f: &F, x: &[f64], h: &[f64], scheme: Scheme) -> Result<Mat, E>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, E> + ?Sized,
{
    let mut cols: Vec<Vec<f64>> = Vec::with_capacity(x.len());
    let mut xp = x.to_vec();
    for (l, &hl) in h.iter().enumerate() {
        let mut diff = |h: f64| -> Result<Vec<f64>, E> {
            xp[l] = x[l] + h;
            let fp = f(&xp)?;
            xp[l] = x[l] - h;
            let fm = f(&xp)?;
            xp[l] = x[l];
            Ok(fp
                .iter()
                .zip(&fm)
                .map(|(p, m)| (p - m) / (2.0 * h))
                .collect())
        };
        cols.push(match scheme {
            Scheme::Central => diff(hl)?,
            Scheme::Richardson => {
                let (d1, d2) = (diff(hl)?, diff(0.5 * hl)?);
                d1.iter()
                    .zip(&d2)
                    .map(|(a, b)| (4.0 * b - a) / 3.0)
                    .collect()
            }
        });
    }
    let rows = cols.first().map_or(0, Vec::len);
    Ok(Mat::from_fn(rows, x.len(), |i, j| cols[j][i]))
}

/// ∇f(x) into `out` with steps h_l by `scheme` (the one-row [`jacobian`]).
pub(crate) fn gradient<E, F>(
    f: &F,
    x: &[f64],
    h: &[f64],
    scheme: Scheme,
    out: &mut [f64],
) -> Result<(), E>
where
    F: Fn(&[f64]) -> Result<f64, E> + ?Sized,
{
    let jac = jacobian(&|y| f(y).map(|v| vec![v]), x, h, scheme)?;
    for (i, o) in out.iter_mut().enumerate() {
        *o = jac[(0, i)];
    }
    Ok(())
}
