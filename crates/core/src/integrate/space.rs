//! State spaces described by named blocks.
//!
//! A state of every system is one flat `f64` vector; its [`Space`] says how that vector is cut into
//! named blocks — ℝᵏ, a rotation in SO(3), a unit vector on S², an n×n matrix, a point of so(n)* —
//! and gives each block its membership check, its retraction (the map back onto the manifold that
//! removes accumulated round-off) and a named view. A product state is a bundle of blocks, in the
//! manner of manif's bundles: a rigid body carrying its attitude has the space `M: ℝ³ × R: SO(3)`,
//! the same body without attitude just `M: ℝ³`.

use crate::check;
use crate::error::{Error, Result};
use crate::lie::{so, so3};
use nalgebra::Matrix3;

/// One block of a state vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// ℝᵏ (k values).
    Real(usize),
    /// A rotation R ∈ SO(3), row-major (9 values).
    SO3,
    /// A unit vector u ∈ S² ⊂ ℝ³ (3 values).
    Sphere,
    /// An n×n real matrix, row-major (n² values): a point of GL(n) or its cotangent fibre.
    Matrix(usize),
    /// A point of so(n)* in the e_ij coordinates of [`so::vee_n`] (n(n−1)/2 values).
    SoDual(usize),
}

/// Tolerance of the S² membership check, | |u| − 1 |.
pub const SPHERE_TOL: f64 = 1e-10;

impl Block {
    /// The number of values the block occupies.
    pub fn len(self) -> usize {
        match self {
            Block::Real(k) => k,
            Block::SO3 => 9,
            Block::Sphere => 3,
            Block::Matrix(n) => n * n,
            Block::SoDual(n) => so::dim(n),
        }
    }

    /// The number of coordinates of a tangent vector in the block: 3 for SO(3) (left-trivialised,
    /// δR = Rξ̂), else [`Block::len`] (tangent vectors in the block's own coordinates).
    pub fn tangent_len(self) -> usize {
        match self {
            Block::SO3 => 3,
            b => b.len(),
        }
    }

    /// Whether the block holds no value (ℝ⁰).
    pub fn is_empty(self) -> bool {
        self.len() == 0
    }

    /// The shape of the block's named view: (k,), (3, 3), (3,), (n, n), and (n, n) for so(n)*
    /// (the skew matrix, [`so::hat_n`]).
    pub fn shape(self) -> Vec<usize> {
        match self {
            Block::Real(k) => vec![k],
            Block::SO3 => vec![3, 3],
            Block::Sphere => vec![3],
            Block::Matrix(n) | Block::SoDual(n) => vec![n, n],
        }
    }

    /// Whether [`Block::retract`] changes anything (the block is a curved manifold).
    pub fn is_curved(self) -> bool {
        matches!(self, Block::SO3 | Block::Sphere)
    }

    /// Checks that `v` (the block's values) is finite and on the manifold (SO(3) to
    /// [`so3::ROTATION_TOL`], S² to [`SPHERE_TOL`]).
    pub fn check(self, name: &str, v: &[f64]) -> Result<()> {
        check::finite_slice(name, v)?;
        match self {
            Block::SO3 => so3::check_rotation(name, &Matrix3::from_row_slice(v)),
            Block::Sphere => {
                let r = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if (r - 1.0).abs() > SPHERE_TOL {
                    return Err(Error::NotInGroup {
                        what: name.into(),
                        group: "S² (unit vectors)".into(),
                        defect_name: "| |u| − 1 |".into(),
                        defect: (r - 1.0).abs(),
                        tol: SPHERE_TOL,
                    });
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// Maps values that are near the manifold back onto it: one Newton step of the polar
    /// decomposition R ↦ R(3I − RᵀR)/2 on SO(3) (for R = Q(I + E), E symmetric, the result is
    /// Q(I + O(E²))), u ↦ u/|u| on S²; the identity on flat blocks.
    pub fn retract(self, v: &mut [f64]) {
        match self {
            Block::SO3 => {
                let r = Matrix3::from_row_slice(v);
                let r = r * (Matrix3::identity() * 3.0 - r.transpose() * r) * 0.5;
                for i in 0..3 {
                    for j in 0..3 {
                        v[3 * i + j] = r[(i, j)];
                    }
                }
            }
            Block::Sphere => {
                let r = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                v.iter_mut().for_each(|x| *x /= r);
            }
            _ => {}
        }
    }

    /// The named view of the block's values (row-major, [`Block::shape`]): the values
    /// themselves, or the skew matrix of a point of so(n)*.
    pub fn view(self, v: &[f64], out: &mut [f64]) {
        match self {
            Block::SoDual(n) => {
                let m = so::hat_n_unchecked(n, v);
                for (k, o) in out.iter_mut().enumerate() {
                    *o = m[(k / n, k % n)];
                }
            }
            _ => out.copy_from_slice(v),
        }
    }
}

/// The most blocks a [`Space`] holds (the systems have at most five).
pub const MAX_BLOCKS: usize = 8;

/// A state space: named blocks laid out one after the other in a flat vector. Held inline (no
/// allocation: a batch checks and lays out every member's state with it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Space {
    items: [(&'static str, Block); MAX_BLOCKS],
    len: usize,
}

impl Default for Space {
    fn default() -> Self {
        Space {
            items: [("", Block::Real(0)); MAX_BLOCKS],
            len: 0,
        }
    }
}

impl Space {
    /// The space of the given (name, block) pairs, in order (at most [`MAX_BLOCKS`]).
    pub fn new(blocks: impl IntoIterator<Item = (&'static str, Block)>) -> Self {
        blocks
            .into_iter()
            .fold(Space::default(), |s, (name, b)| s.with(name, b))
    }

    /// The same space with one more block at the end (e.g. the attitude `R: SO(3)`).
    ///
    /// Panics beyond [`MAX_BLOCKS`] blocks (a system's layout, fixed in the code).
    pub fn with(mut self, name: &'static str, block: Block) -> Self {
        assert!(
            self.len < MAX_BLOCKS,
            "a Space holds at most {MAX_BLOCKS} blocks"
        );
        self.items[self.len] = (name, block);
        self.len += 1;
        self
    }

    /// The blocks with their names.
    pub fn blocks(&self) -> &[(&'static str, Block)] {
        &self.items[..self.len]
    }

    /// The length of a state vector.
    pub fn dim(&self) -> usize {
        self.blocks().iter().map(|(_, b)| b.len()).sum()
    }

    /// The length of a tangent vector ([`Block::tangent_len`]).
    pub fn tangent_dim(&self) -> usize {
        self.blocks().iter().map(|(_, b)| b.tangent_len()).sum()
    }

    /// The blocks with their names and value ranges.
    pub fn ranges(
        &self,
    ) -> impl Iterator<Item = (&'static str, Block, std::ops::Range<usize>)> + '_ {
        self.blocks().iter().scan(0, |start, &(name, b)| {
            let r = *start..*start + b.len();
            *start = r.end;
            Some((name, b, r))
        })
    }

    /// The value range of the block called `name`.
    pub fn range(&self, name: &str) -> Option<std::ops::Range<usize>> {
        self.ranges()
            .find(|(n, _, _)| *n == name)
            .map(|(_, _, r)| r)
    }

    /// Whether some block is curved (the driver then retracts the state now and then).
    pub fn is_curved(&self) -> bool {
        self.blocks().iter().any(|(_, b)| b.is_curved())
    }

    /// Checks the length of `z` and every block ([`Block::check`]).
    pub fn check(&self, what: &str, z: &[f64]) -> Result<()> {
        check::len_of(what, z, self.dim())?;
        for (name, b, r) in self.ranges() {
            // The block's name is formatted only for an error (a batch checks every member).
            if b.check(what, &z[r.clone()]).is_err() {
                b.check(&format!("{what} ({name})"), &z[r])?;
            }
        }
        Ok(())
    }

    /// Retracts every curved block of `z` onto its manifold ([`Block::retract`]).
    pub fn retract(&self, z: &mut [f64]) {
        for (_, b, r) in self.ranges() {
            b.retract(&mut z[r]);
        }
    }

    /// A short description such as `M: R^3 × R: SO(3)`.
    pub fn describe(&self) -> String {
        let parts: Vec<String> = self
            .blocks()
            .iter()
            .map(|(name, b)| {
                let s = match b {
                    Block::Real(k) => format!("R^{k}"),
                    Block::SO3 => "SO(3)".into(),
                    Block::Sphere => "S^2".into(),
                    Block::Matrix(n) => format!("R^({n}x{n})"),
                    Block::SoDual(n) => format!("so({n})*"),
                };
                format!("{name}: {s}")
            })
            .collect();
        parts.join(" × ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_views_and_retraction() {
        let s = Space::new([("M", Block::Real(3))]).with("R", Block::SO3);
        assert_eq!(s.dim(), 12);
        assert_eq!(s.range("R"), Some(3..12));
        assert!(s.is_curved());
        assert_eq!(s.describe(), "M: R^3 × R: SO(3)");
        let mut z = vec![1.0, 2.0, 3.0, 1.0, 1e-11, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        assert!(s.check("z", &z).is_ok());
        z[4] = 1e-3;
        assert!(matches!(s.check("z", &z), Err(Error::NotInGroup { .. })));
        z[4] = 1e-7;
        s.retract(&mut z);
        let r = Matrix3::from_row_slice(&z[3..]);
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-13);
        assert_eq!(&z[..3], &[1.0, 2.0, 3.0]);
        let mut u = [0.0, 3.0, 4.0];
        Block::Sphere.retract(&mut u);
        assert_eq!(u, [0.0, 0.6, 0.8]);
        let mut m = [0.0; 9];
        Block::SoDual(3).view(&[1.0, 2.0, 3.0], &mut m);
        assert_eq!(m, [0.0, 1.0, 2.0, -1.0, 0.0, 3.0, -2.0, -3.0, 0.0]);
        assert!(s.check("z", &[0.0; 11]).is_err());
    }
}
