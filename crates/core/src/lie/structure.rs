//! Lie algebras given by structure constants, as the user-defined Lie–Poisson systems use them
//! ([`crate::systems::LiePoisson`]): a basis e_k with [e_i, e_j] = C_ij^k e_k, kept as the list of
//! non-zero constants, with ad*, the bracket and a bound of ‖ad_u‖; so(3), se(3) and so(n) (in the
//! e_ij coordinates of [`so::vee_n`]) built in, others from a validated array (antisymmetric,
//! Jacobi).

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so;

/// The Lie algebra g of a [`crate::systems::LiePoisson`] system.
#[derive(Clone, Debug, PartialEq)]
pub enum Algebra {
    /// so(3) in the physics basis (ℝ³, [û, v̂] = (u × v)^): μ = M.
    So3,
    /// se(3) = so(3) ⋉ ℝ³ with ξ = (ω, v) ([`crate::lie::se3::ad_matrix`]): μ = (M, Γ).
    Se3,
    /// so(n) in the e_ij coordinates of [`so::vee_n`] (n ≥ 2): μ = M ∈ so(n)*.
    So(usize),
    /// Structure constants C (d×d×d, row-major C\[i\]\[j\]\[k\] = C_ij^k: [e_i, e_j] = C_ij^k e_k),
    /// antisymmetric in (i, j) and satisfying the Jacobi identity (both checked).
    Constants(Vec<f64>),
}

impl Algebra {
    /// dim g.
    ///
    /// Errors: those of invalid structure constants or n < 2 (as [`crate::systems::LiePoisson::new`]).
    pub fn dim(&self) -> Result<usize> {
        Ok(Structure::new(self.clone())?.dim)
    }
}

/// One non-zero structure constant: [e_i, e_j] has c along e_k.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Term {
    i: u32,
    j: u32,
    k: u32,
    c: f64,
}

/// Which group maps the kernels of [`crate::integrate::problem::GroupField`] use.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Kind {
    So3,
    Se3,
    So(usize),
    Generic,
}

/// The algebra as the kernels use it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Structure {
    pub(crate) kind: Kind,
    pub(crate) dim: usize,
    terms: Vec<Term>,
}

impl Structure {
    pub(crate) fn new(algebra: Algebra) -> Result<Self> {
        let t = |i: usize, j: usize, k: usize, c: f64| Term {
            i: i as u32,
            j: j as u32,
            k: k as u32,
            c,
        };
        const CYCLIC: [(usize, usize, usize); 3] = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];
        match algebra {
            Algebra::So3 => {
                // [e_i, e_j] = ε_ijk e_k.
                let mut terms = Vec::new();
                for (i, j, k) in CYCLIC {
                    terms.push(t(i, j, k, 1.0));
                    terms.push(t(j, i, k, -1.0));
                }
                Ok(Structure {
                    kind: Kind::So3,
                    dim: 3,
                    terms,
                })
            }
            Algebra::Se3 => {
                // [e_i, e_j] = ε_ijk e_k, [e_i, e_{3+j}] = ε_ijk e_{3+k} = −[e_{3+j}, e_i],
                // [e_{3+i}, e_{3+j}] = 0.
                let mut terms = Vec::new();
                for (i, j, k) in CYCLIC {
                    terms.push(t(i, j, k, 1.0));
                    terms.push(t(j, i, k, -1.0));
                    terms.push(t(i, 3 + j, 3 + k, 1.0));
                    terms.push(t(3 + j, i, 3 + k, -1.0));
                    terms.push(t(j, 3 + i, 3 + k, -1.0));
                    terms.push(t(3 + i, j, 3 + k, 1.0));
                }
                Ok(Structure {
                    kind: Kind::Se3,
                    dim: 6,
                    terms,
                })
            }
            Algebra::So(n) => {
                if n < 2 {
                    return Err(Error::invalid(
                        "algebra",
                        format!("so(n) needs n ≥ 2, got n = {n}"),
                    ));
                }
                // O(n³) non-zero constants, kept as (i, j, k, c): refuse what cannot be held.
                check::array_size("algebra so(n)", &[n, n, n, 4])?;
                Ok(Structure {
                    kind: Kind::So(n),
                    dim: so::dim(n),
                    terms: so_terms(n),
                })
            }
            Algebra::Constants(c) => Self::from_constants(&c),
        }
    }

    /// Structure constants given as an array: validated (finite, antisymmetric, Jacobi).
    pub(crate) fn from_constants(c: &[f64]) -> Result<Self> {
        let d = (c.len() as f64).cbrt().round() as usize;
        if d == 0 || d * d * d != c.len() {
            return Err(Error::shape(
                "algebra",
                "structure constants (d, d, d) with d ≥ 1",
                format!("{} values", c.len()),
            ));
        }
        check::finite_slice("algebra (structure constants)", c)?;
        let at = |i: usize, j: usize, k: usize| c[(i * d + j) * d + k];
        let cmax = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..d {
            for j in 0..d {
                for k in 0..d {
                    let s = at(i, j, k) + at(j, i, k);
                    if s.abs() > 1e-12 * cmax {
                        return Err(Error::invalid(
                            "algebra",
                            format!(
                                "structure constants not antisymmetric: C[{i}, {j}, {k}] + \
                                 C[{j}, {i}, {k}] = {s:.3e}"
                            ),
                        ));
                    }
                }
            }
        }
        // Rows: the non-zero (k, C_ab^k) of each bracket [e_a, e_b].
        let rows: Vec<Vec<(usize, f64)>> = (0..d * d)
            .map(|ab| {
                (0..d)
                    .filter_map(|k| {
                        let v = c[ab * d + k];
                        (v != 0.0).then_some((k, v))
                    })
                    .collect()
            })
            .collect();
        // Jacobi: [[e_i, e_j], e_l] + [[e_j, e_l], e_i] + [[e_l, e_i], e_j] = 0.
        let mut acc = vec![0.0; d];
        let tol = 1e-10 * cmax * cmax;
        let nested = |a: usize, b: usize, l: usize, acc: &mut [f64]| {
            for &(k, x) in &rows[a * d + b] {
                for &(m, y) in &rows[k * d + l] {
                    acc[m] += x * y;
                }
            }
        };
        for i in 0..d {
            for j in i + 1..d {
                for l in j + 1..d {
                    acc.fill(0.0);
                    nested(i, j, l, &mut acc);
                    nested(j, l, i, &mut acc);
                    nested(l, i, j, &mut acc);
                    if let Some(m) = acc.iter().position(|x| x.abs() > tol) {
                        return Err(Error::invalid(
                            "algebra",
                            format!(
                                "structure constants violate the Jacobi identity: component {m} \
                                 of [[e_{i}, e_{j}], e_{l}] + cyclic = {:.3e}",
                                acc[m]
                            ),
                        ));
                    }
                }
            }
        }
        let mut terms = Vec::new();
        for i in 0..d {
            for j in 0..d {
                for &(k, v) in &rows[i * d + j] {
                    terms.push(Term {
                        i: i as u32,
                        j: j as u32,
                        k: k as u32,
                        c: v,
                    });
                }
            }
        }
        Ok(Structure {
            kind: Kind::Generic,
            dim: d,
            terms,
        })
    }

    /// out ← ad*_g μ, (ad*_g μ)_j = Σ C_ij^k g_i μ_k (on so(3) the cross product μ × g).
    pub(crate) fn ad_star(&self, g: &[f64], mu: &[f64], out: &mut [f64]) {
        if let (Kind::So3, [g0, g1, g2, ..], [m0, m1, m2, ..], [o0, o1, o2, ..]) =
            (&self.kind, g, mu, &mut *out)
        {
            *o0 = m1 * g2 - m2 * g1;
            *o1 = m2 * g0 - m0 * g2;
            *o2 = m0 * g1 - m1 * g0;
            return;
        }
        out.fill(0.0);
        for t in &self.terms {
            out[t.j as usize] += t.c * g[t.i as usize] * mu[t.k as usize];
        }
    }

    /// out ← [u, v] = ad_u v, [u, v]_k = Σ C_ij^k u_i v_j.
    pub(crate) fn bracket(&self, u: &[f64], v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.bracket_add(u, v, out);
    }

    /// out ← out + [u, v].
    fn bracket_add(&self, u: &[f64], v: &[f64], out: &mut [f64]) {
        for t in &self.terms {
            out[t.k as usize] += t.c * u[t.i as usize] * v[t.j as usize];
        }
    }

    /// dexp_u v = Σ_{k≥0} ad_uᵏ v/(k+1)! (right-trivialised, the inverse of
    /// [`Structure::dexp_inv_series`]) into `value`, and with `du` also its derivative in u,
    ///
    ///   D_u(dexp_u v)\[du\] = Σ_{k≥1} 1/(k+1)! Σ_{i+j=k−1} ad_uⁱ ad_du ad_uʲ v,
    ///
    /// the series differentiated term by term, into `deriv` (as [`crate::lie::so::dexp_derivative`]
    /// on so(n)): the derivative of T_k = ad_uᵏ v is D_k = ad_du T_{k−1} + ad_u D_{k−1}, that
    /// inner sum, so one pass carries both. Truncated once the terms of both sums are below
    /// 10⁻¹⁷ of their sums (max-norms; at most 64 terms); for the domain of dexp⁻¹ (‖ad_u‖ < π,
    /// the terms fall like ‖ad_u‖ᵏ/(k+1)!). `work`: three vectors of length d.
    pub(crate) fn dexp_series(
        &self,
        u: &[f64],
        v: &[f64],
        du: Option<&[f64]>,
        value: &mut [f64],
        mut deriv: Option<&mut [f64]>,
        work: [&mut [f64]; 3],
    ) {
        let [t, d, p] = work;
        let max = |a: &[f64]| a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        value.copy_from_slice(v);
        t.copy_from_slice(v);
        d.fill(0.0);
        if let Some(out) = deriv.as_deref_mut() {
            out.fill(0.0);
        }
        for k in 1..64 {
            let inv = 1.0 / (k + 1) as f64;
            // With t = T_{k−1}/k!, d = D_{k−1}/k!: d ← ([u, d] + [du, t])/(k + 1) before t
            // moves on, t ← [u, t]/(k + 1).
            let mut small = true;
            if let (Some(du), Some(out)) = (du, deriv.as_deref_mut()) {
                self.bracket(u, d, p);
                self.bracket_add(du, t, p);
                for ((di, pi), o) in d.iter_mut().zip(p.iter()).zip(out.iter_mut()) {
                    *di = pi * inv;
                    *o += *di;
                }
                small = max(d) <= 1e-17 * max(out);
            }
            self.bracket(u, t, p);
            for ((ti, pi), vi) in t.iter_mut().zip(p.iter()).zip(value.iter_mut()) {
                *ti = pi * inv;
                *vi += *ti;
            }
            if small && max(t) <= 1e-17 * max(value) {
                return;
            }
        }
    }

    /// A bound of ‖ad_u‖_∞ (and of ‖ad_uᵀ‖_∞): max over rows of Σ |C_ij^k u_i| for the two
    /// index placements.
    pub(crate) fn ad_bound(&self, u: &[f64], rows: &mut [f64], cols: &mut [f64]) -> f64 {
        rows.fill(0.0);
        cols.fill(0.0);
        for t in &self.terms {
            let a = (t.c * u[t.i as usize]).abs();
            rows[t.k as usize] += a;
            cols[t.j as usize] += a;
        }
        rows.iter()
            .chain(cols.iter())
            .fold(0.0f64, |m, x| m.max(*x))
    }

    /// dexp⁻¹_u v = Σ_k B_k/k! ad_uᵏ v (right-trivialised: d/dε exp(u + εw) exp(−u) = dexp_u w),
    /// or with `dual` its transpose (dexp⁻¹_u)ᵀ v = Σ_k B_k/k! (ad*_u)ᵏ v, by the Bernoulli series
    /// (B₁ = −½); NaN when the bound of ‖ad_u‖ reaches π (the series converges for ‖ad_u‖ < 2π,
    /// slowly near it). Summed until a bound of the tail is below 10⁻¹⁷ of the sum; `work`: four
    /// vectors of length d.
    pub(crate) fn dexp_inv_series(
        &self,
        u: &[f64],
        v: &[f64],
        out: &mut [f64],
        dual: bool,
        work: [&mut Vec<f64>; 4],
    ) {
        let [rows, cols, term, next] = work;
        let beta = self.ad_bound(u, rows, cols);
        if beta.is_nan() || beta >= std::f64::consts::PI || v.iter().any(|x| !x.is_finite()) {
            out.fill(f64::NAN);
            return;
        }
        out.copy_from_slice(v);
        term.copy_from_slice(v);
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut bound = 1.0;
        for &b in &so::bernoulli_coefficients()[1..] {
            if dual {
                self.ad_star(u, term, next);
            } else {
                self.bracket(u, term, next);
            }
            std::mem::swap(term, next);
            let mut pn = 0.0f64;
            for (o, t) in out.iter_mut().zip(term.iter()) {
                *o += b * t;
                pn = pn.max(t.abs());
            }
            // |b_j| ≤ 4/(2π)^j (j ≥ 2) and ‖ad_u‖ ≤ β < π: the rest is below 4‖p_k‖/(2π)^k.
            bound /= two_pi;
            let sum = out.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if pn == 0.0 || 4.0 * pn * bound <= 1e-17 * sum {
                return;
            }
        }
    }

    /// The dense (d, d, d) array C[i][j][k].
    pub(crate) fn dense(&self) -> Vec<f64> {
        let d = self.dim;
        let mut c = vec![0.0; d * d * d];
        for t in &self.terms {
            c[(t.i as usize * d + t.j as usize) * d + t.k as usize] += t.c;
        }
        c
    }
}

/// The structure constants of so(n) in the e_ij basis: with E_ab = −E_ba,
/// [E_ab, E_cd] = δ_bc E_ad − δ_bd E_ac − δ_ac E_bd + δ_ad E_bc.
fn so_terms(n: usize) -> Vec<Term> {
    // index[a][b]: (coordinate, sign) of E_ab.
    let mut index = vec![(0usize, 0.0f64); n * n];
    let mut c = 0;
    for a in 0..n {
        for b in a + 1..n {
            index[a * n + b] = (c, 1.0);
            index[b * n + a] = (c, -1.0);
            c += 1;
        }
    }
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
        .collect();
    let mut terms = Vec::new();
    let add = |i: usize, j: usize, x: usize, y: usize, s: f64, terms: &mut Vec<Term>| {
        let (k, sign) = index[x * n + y];
        if sign != 0.0 {
            terms.push(Term {
                i: i as u32,
                j: j as u32,
                k: k as u32,
                c: s * sign,
            });
        }
    };
    for (i, &(a, b)) in pairs.iter().enumerate() {
        for (j, &(cc, dd)) in pairs.iter().enumerate() {
            if b == cc {
                add(i, j, a, dd, 1.0, &mut terms);
            }
            if b == dd {
                add(i, j, a, cc, -1.0, &mut terms);
            }
            if a == cc {
                add(i, j, b, dd, -1.0, &mut terms);
            }
            if a == dd {
                add(i, j, b, cc, 1.0, &mut terms);
            }
        }
    }
    terms
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dexp series inverts the Bernoulli series of dexp⁻¹, and its derivative is the central
    /// difference of dexp (step 1e-5), on se(3), so(4) and a semidirect so(3) ⋉ ℝ³ given as
    /// constants (se(3) again: a generic path with non-skew ad).
    #[test]
    fn the_dexp_series_and_its_derivative() {
        let constants = Structure::new(Algebra::Se3).unwrap().dense();
        for algebra in [Algebra::Se3, Algebra::So(4), Algebra::Constants(constants)] {
            let g = Structure::new(algebra).unwrap();
            let d = g.dim;
            let f = |seed: f64, s: f64| -> Vec<f64> {
                (0..d)
                    .map(|k| s * ((k as f64 + 1.0) * seed).sin())
                    .collect()
            };
            let (u, du, v) = (f(1.3, 0.4), f(0.7, 1.0), f(2.1, 1.0));
            let [mut t, mut e, mut p, mut a, mut b] = std::array::from_fn(|_| vec![0.0; d]);
            let (mut value, mut deriv, mut back) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
            g.dexp_series(
                &u,
                &v,
                Some(&du),
                &mut value,
                Some(&mut deriv),
                [&mut t, &mut e, &mut p],
            );
            g.dexp_inv_series(
                &u,
                &value,
                &mut back,
                false,
                [&mut a, &mut b, &mut t, &mut e],
            );
            let inv = back
                .iter()
                .zip(&v)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(inv < 1e-15, "dexp⁻¹ dexp v − v: {inv:e}");
            let h = 1e-5;
            let at = |s: f64| {
                let us: Vec<f64> = u.iter().zip(&du).map(|(x, y)| x + s * y).collect();
                let [mut t, mut e, mut p] = std::array::from_fn(|_| vec![0.0; d]);
                let mut out = vec![0.0; d];
                g.dexp_series(&us, &v, None, &mut out, None, [&mut t, &mut e, &mut p]);
                out
            };
            let (up, dn) = (at(h), at(-h));
            let err = (0..d)
                .map(|k| (deriv[k] - (up[k] - dn[k]) / (2.0 * h)).abs())
                .fold(0.0f64, f64::max);
            eprintln!("{:?}: D dexp vs differences {err:.1e}", g.kind);
            assert!(err < 1e-9, "{err:e}");
        }
    }

    #[test]
    fn the_dual_bernoulli_series_is_the_transpose_of_the_plain_one() {
        // ⟨(dexp⁻¹_u)ᵀ p, v⟩ = ⟨p, dexp⁻¹_u v⟩ on se(3) (not skew in its coordinates) and so(4).
        for algebra in [Algebra::Se3, Algebra::So(4)] {
            let g = Structure::new(algebra).unwrap();
            let d = g.dim;
            let u: Vec<f64> = (0..d)
                .map(|k| 0.3 * ((k as f64 + 1.0) * 1.3).sin())
                .collect();
            let p: Vec<f64> = (0..d).map(|k| ((k as f64 + 2.0) * 0.7).cos()).collect();
            let v: Vec<f64> = (0..d).map(|k| ((k as f64 + 1.0) * 2.1).sin()).collect();
            let [mut a, mut b, mut c, mut e] = std::array::from_fn(|_| vec![0.0; d]);
            let (mut dual, mut plain) = (vec![0.0; d], vec![0.0; d]);
            g.dexp_inv_series(&u, &p, &mut dual, true, [&mut a, &mut b, &mut c, &mut e]);
            g.dexp_inv_series(&u, &v, &mut plain, false, [&mut a, &mut b, &mut c, &mut e]);
            let lhs: f64 = dual.iter().zip(&v).map(|(x, y)| x * y).sum();
            let rhs: f64 = p.iter().zip(&plain).map(|(x, y)| x * y).sum();
            assert!((lhs - rhs).abs() < 1e-15, "{lhs} {rhs}");
            // Not the identity: the series has terms.
            assert!(dual.iter().zip(&p).any(|(x, y)| (x - y).abs() > 1e-3));
        }
    }
}
