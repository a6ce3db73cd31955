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

/// The fourth-order central difference (8(f(x + h) − f(x − h)) − (f(x + 2h) − f(x − 2h)))/12h of a
/// fixed-size map along coordinate k, with the step h·max(1, |x_k|) (the closed-form charts'
/// derivative checks and the numerical surfaces and 3-manifolds; no allocation).
pub(crate) fn diff4<const D: usize, const N: usize>(
    f: impl Fn([f64; D]) -> [f64; N],
    x: [f64; D],
    k: usize,
    h: f64,
) -> [f64; N] {
    let h = h * x[k].abs().max(1.0);
    let at = |t: f64| {
        let mut y = x;
        y[k] += t;
        f(y)
    };
    let (p1, m1, p2, m2) = (at(h), at(-h), at(2.0 * h), at(-2.0 * h));
    std::array::from_fn(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x) = (x₀² x₁, sin x₀ + x₁³) and its Jacobian in closed form.
    fn f(x: &[f64]) -> Result<Vec<f64>, ()> {
        Ok(vec![x[0] * x[0] * x[1], x[0].sin() + x[1].powi(3)])
    }
    fn exact(x: &[f64]) -> [[f64; 2]; 2] {
        [
            [2.0 * x[0] * x[1], x[0] * x[0]],
            [x[0].cos(), 3.0 * x[1] * x[1]],
        ]
    }
    fn error(h: f64, scheme: Scheme) -> f64 {
        let x = [0.7, -1.3];
        let j = jacobian(&f, &x, &[h, h], scheme).unwrap();
        let e = exact(&x);
        (0..2)
            .flat_map(|r| (0..2).map(move |c| (r, c)))
            .map(|(r, c)| (j[(r, c)] - e[r][c]).abs())
            .fold(0.0, f64::max)
    }

    /// The observed orders: halving h divides the error by 4 (central) and 16 (Richardson).
    #[test]
    fn the_schemes_have_their_orders() {
        let central = error(1e-2, Scheme::Central) / error(5e-3, Scheme::Central);
        assert!((central - 4.0).abs() < 0.05, "central ratio {central}");
        let rich = error(8e-2, Scheme::Richardson) / error(4e-2, Scheme::Richardson);
        assert!((rich - 16.0).abs() < 0.5, "Richardson ratio {rich}");
        assert!(error(1e-5, Scheme::Central) < 1e-9);
    }

    /// The gradient is the one row of the Jacobian; the first error of f is returned.
    #[test]
    fn gradient_and_errors() {
        let g = |x: &[f64]| -> Result<f64, ()> { Ok(x[0] * x[0] * x[1]) };
        let mut out = [0.0; 2];
        gradient(&g, &[0.7, -1.3], &[1e-5, 1e-5], Scheme::Central, &mut out).unwrap();
        assert!((out[0] - 2.0 * 0.7 * -1.3).abs() < 1e-9 && (out[1] - 0.49).abs() < 1e-9);
        let failing = |x: &[f64]| -> Result<Vec<f64>, &'static str> {
            if x[1] > 0.0 {
                Err("refused")
            } else {
                Ok(vec![x[0]])
            }
        };
        let r = jacobian(&failing, &[0.0, 0.0], &[1e-3, 1e-3], Scheme::Central);
        assert_eq!(r.err(), Some("refused"));
    }
}
