//! Shared helpers of the integration tests.
#![allow(dead_code)]

pub mod group_laws;

use lieflow::integrate::System;
use lieflow::lie::gl;
use lieflow::systems::{RollingDisks, RollingSpheres};
use lieflow::Mat;

/// Euclidean distance between two flat states of the same length.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Frobenius distance between two matrices of the same shape.
pub fn dist(a: &Mat, b: &Mat) -> f64 {
    (a - b).norm_l2()
}

/// Matrix exponential by scaling and squaring of a Taylor series: an independent route to exp
/// for the tests (not used by the library).
pub fn expm_reference(a: &Mat) -> Mat {
    let n = a.nrows();
    let norm = a.norm_l2();
    let s = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let scaled = a * faer::Scale(0.5f64.powi(s));
    let mut term = Mat::identity(n, n);
    let mut sum = Mat::identity(n, n);
    for k in 1..30 {
        term = &term * &scaled * faer::Scale(1.0 / k as f64);
        sum += &term;
    }
    for _ in 0..s {
        sum = &sum * &sum;
    }
    sum
}

/// An n×n matrix with det > 0 from the first n² entries of `v` (the first row is flipped if
/// needed).
pub fn gl_plus(n: usize, v: &[f64]) -> Mat {
    let mut m = Mat::from_fn(n, n, |i, j| v[i * n + j]);
    if gl::det(&m) < 0.0 {
        for j in 0..n {
            m[(0, j)] = -m[(0, j)];
        }
    }
    m
}

/// A rotation in SO(n): the polar factor of [`gl_plus`].
pub fn rotation(n: usize, v: &[f64]) -> Mat {
    gl::polar(&gl_plus(n, v)).unwrap().0
}

/// The nominal order of the method called `name` in the system's catalog.
pub fn order<S: System + ?Sized>(sys: &S, name: &str) -> u32 {
    sys.methods()
        .into_iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("{} has no method {name:?}", sys.name()))
        .1
        .order
}

/// SplitMix64 → uniform numbers in [−1, 1): a small deterministic generator for the tests.
pub struct Rng(pub u64);

impl Rng {
    /// The next uniform number in [−1, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// An n×n matrix of uniform entries in [−scale, scale).
    pub fn mat(&mut self, n: usize, scale: f64) -> Mat {
        Mat::from_fn(n, n, |_, _| scale * self.uniform())
    }
}

/// The two rolling disks of the catalog and convergence tests (distinct radii, offset centres of
/// mass, rolling constant 0.4).
pub fn rolling_disks() -> RollingDisks {
    RollingDisks::new(
        [1.0, 0.7],
        [[0.3, 0.1], [-0.2, 0.25]],
        [1.0, 1.5],
        [0.8, 0.6],
    )
    .unwrap()
    .with_rolling_constant(0.4)
    .unwrap()
}

/// The two rolling spheres of the catalog and convergence tests (full inertia tensors, offset
/// centres of mass).
pub fn rolling_spheres() -> RollingSpheres {
    RollingSpheres::new(
        0.7,
        1.3,
        [0.1, -0.2, 0.15],
        [-0.3, 0.2, 0.4],
        2.0,
        3.5,
        [[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]],
        [[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]],
    )
    .unwrap()
}

/// Hénon–Heiles, U = (x² + y²)/2 + x²y − y³/3, as a user system with its Hessian.
pub fn henon_heiles() -> lieflow::systems::UserSeparable {
    use lieflow::systems::{KineticMass, UserSeparable};
    use std::sync::Arc;
    let u = Arc::new(|q: &[f64]| -> lieflow::Result<f64> {
        let (x, y) = (q[0], q[1]);
        Ok(0.5 * (x * x + y * y) + x * x * y - y * y * y / 3.0)
    });
    let g = Arc::new(|q: &[f64], g: &mut [f64]| -> lieflow::Result<()> {
        let (x, y) = (q[0], q[1]);
        g[0] = x + 2.0 * x * y;
        g[1] = y + x * x - y * y;
        Ok(())
    });
    let h = Arc::new(
        |q: &[f64], v: &[f64], out: &mut [f64]| -> lieflow::Result<()> {
            let (x, y) = (q[0], q[1]);
            out[0] = (1.0 + 2.0 * y) * v[0] + 2.0 * x * v[1];
            out[1] = 2.0 * x * v[0] + (1.0 - 2.0 * y) * v[1];
            Ok(())
        },
    );
    UserSeparable::new(KineticMass::Scalar(1.0), Some(2), u, Some(g))
        .unwrap()
        .with_hessian(h)
}
