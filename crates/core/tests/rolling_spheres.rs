//! 003 §2, two rolling spheres: every formula of `RollingSpheres` against a second route — the
//! Lagrangian (8) and the momenta against point-mass bodies moved by (4), the Lagrange–d'Alembert
//! accelerations against constrained Newton–Euler in physical units, the printed (and the
//! corrected) final equation of §2.3, the curvature of §2.2 against flow commutators, the
//! holonomic subsystem of §2.4 — and the methods: manifold, (10), energy, momentum, orders,
//! reversibility, and the generic `LieMidpoint` on the lifted rigid body. Measured values are
//! printed (run with `--nocapture`).

use lieflow::integrate::methods::{Composition, LieMidpoint, Rkmk4};
use lieflow::integrate::{integrate, integrate_with, Integrator, Problem, System};
use lieflow::lie::so3::{self, hat};
use lieflow::systems::{RigidBody, RollingSpheres};
use lieflow::Error;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

mod common;
use common::distance as dist;

// ---------------------------------------------------------------------------------------------
// Helpers

/// A small deterministic generator (xorshift64*), uniform in [−1, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        2.0 * (x as f64 / (1u64 << 53) as f64) - 1.0
    }
    fn vec3(&mut self) -> Vector3<f64> {
        Vector3::new(self.next(), self.next(), self.next())
    }
    fn rotation(&mut self) -> Matrix3<f64> {
        so3::exp_unchecked(&(self.vec3() * 3.0))
    }
    fn unit(&mut self) -> Vector3<f64> {
        self.vec3().normalize()
    }
}

fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[(i, j)]))
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::from(a)
}

/// A body of point masses inside the ball of radius r: (points, masses).
struct Points {
    p: Vec<Vector3<f64>>,
    m: Vec<f64>,
}

impl Points {
    fn random(rng: &mut Rng, r: f64, n: usize) -> Self {
        let mut p = Vec::new();
        let mut m = Vec::new();
        while p.len() < n {
            let x = rng.vec3() * r;
            if x.norm() < 0.95 * r {
                p.push(x);
                m.push(1.2 + rng.next());
            }
        }
        Points { p, m }
    }
    fn mass(&self) -> f64 {
        self.m.iter().sum()
    }
    fn gamma(&self) -> Vector3<f64> {
        self.p
            .iter()
            .zip(&self.m)
            .fold(Vector3::zeros(), |s, (p, m)| s + p * *m)
            / self.mass()
    }
    /// I = Σ m (p − γ)(p − γ)ᵀ (003 §2).
    fn second_moment(&self) -> Matrix3<f64> {
        let g = self.gamma();
        self.p
            .iter()
            .zip(&self.m)
            .fold(Matrix3::zeros(), |s, (p, m)| {
                s + (p - g) * (p - g).transpose() * *m
            })
    }
}

/// Two point-mass bodies and the system they make.
fn point_bodies(seed: u64) -> (RollingSpheres, [Points; 2], [f64; 2]) {
    let mut rng = Rng(seed);
    let r = [0.7, 1.3];
    let b = [
        Points::random(&mut rng, r[0], 6),
        Points::random(&mut rng, r[1], 7),
    ];
    let sys = RollingSpheres::new(
        r[0],
        r[1],
        arr(&b[0].gamma()),
        arr(&b[1].gamma()),
        b[0].mass(),
        b[1].mass(),
        rows(&b[0].second_moment()),
        rows(&b[1].second_moment()),
    )
    .unwrap();
    (sys, b, r)
}

/// Spheres with full (non-diagonal) inertia and off-centre centres of mass.
use common::rolling_spheres as spheres;

fn random_state(sys: &RollingSpheres, rng: &mut Rng, speed: f64) -> Vec<f64> {
    sys.state(
        rows(&rng.rotation()),
        rows(&rng.rotation()),
        arr(&rng.unit()),
        arr(&(rng.vec3() * speed)),
        arr(&(rng.vec3() * speed)),
    )
    .unwrap()
}

struct Parts {
    z: [Matrix3<f64>; 2],
    u: Vector3<f64>,
    o: [Vector3<f64>; 2],
}

fn parts(z: &[f64]) -> Parts {
    Parts {
        z: [
            Matrix3::from_row_slice(&z[0..9]),
            Matrix3::from_row_slice(&z[9..18]),
        ],
        u: Vector3::from_column_slice(&z[18..21]),
        o: [
            Vector3::from_column_slice(&z[21..24]),
            Vector3::from_column_slice(&z[24..27]),
        ],
    }
}

/// The state at time t on the constrained curve with constant Ω_k through z:
/// z_k(t) = z_k exp(tΩ̂_k), u(t) = exp(t b̂)u, b = α₁z₁Ω₁ + α₂z₂Ω₂ (velocity (Ω₁, Ω₂, u̇ of (10))).
fn along(sys: &RollingSpheres, z: &[f64], t: f64) -> Vec<f64> {
    let q = parts(z);
    let [a1, a2] = sys.alphas();
    let b = q.z[0] * q.o[0] * a1 + q.z[1] * q.o[1] * a2;
    let u = so3::exp_unchecked(&(b * t)) * q.u;
    sys.state(
        rows(&(q.z[0] * so3::exp_unchecked(&(q.o[0] * t)))),
        rows(&(q.z[1] * so3::exp_unchecked(&(q.o[1] * t)))),
        arr(&u),
        arr(&q.o[0]),
        arr(&q.o[1]),
    )
    .unwrap()
}

/// d/dt f(along(t)) at 0, fourth-order central differences.
fn ddt<const N: usize>(
    f: &dyn Fn(&[f64]) -> [Vector3<f64>; N],
    sys: &RollingSpheres,
    z: &[f64],
) -> [Vector3<f64>; N] {
    let h = 1e-3;
    let v = [h, -h, 2.0 * h, -2.0 * h].map(|t| f(&along(sys, z, t)));
    std::array::from_fn(|i| (8.0 * (v[0][i] - v[1][i]) - (v[2][i] - v[3][i])) / (12.0 * h))
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt();
    let n: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    d / n.max(1e-300)
}

// ---------------------------------------------------------------------------------------------
// Construction and inputs

#[test]
fn inputs_are_validated() {
    let i = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let g = [0.1, 0.0, 0.0];
    let ok = |r1: f64, g1: [f64; 3], m1: f64, i1: [[f64; 3]; 3]| {
        RollingSpheres::new(r1, 1.0, g1, g, m1, 1.0, i1, i)
    };
    assert!(ok(1.0, g, 1.0, i).is_ok());
    assert!(matches!(
        ok(0.0, g, 1.0, i),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(matches!(
        ok(1.0, g, -1.0, i),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(matches!(
        ok(f64::NAN, g, 1.0, i),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        ok(1.0, [1.0, 0.0, 0.0], 1.0, i),
        Err(Error::InvalidArgument { .. })
    ));
    let asym = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let e = ok(1.0, g, 1.0, asym).unwrap_err().to_string();
    assert!(e.contains("symmetric"), "{e}");
    let indefinite = [[1.0, 0.0, 0.0], [0.0, -0.5, 0.0], [0.0, 0.0, 1.0]];
    let e = ok(1.0, g, 1.0, indefinite).unwrap_err().to_string();
    assert!(e.contains("semi-definite"), "{e}");
    let rod = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let e = ok(1.0, g, 1.0, rod).unwrap_err().to_string();
    assert!(e.contains("positive definite"), "{e}");
    // States: rotations and unit u are checked.
    let sys = spheres();
    let z = rows(&so3::exp_unchecked(&Vector3::new(0.3, 0.2, -0.1)));
    assert!(sys.state(z, z, [0.0, 0.0, 1.0], [1.0; 3], [0.0; 3]).is_ok());
    let mut bad = z;
    bad[0][0] += 1e-3;
    assert!(matches!(
        sys.state(bad, z, [0.0, 0.0, 1.0], [1.0; 3], [0.0; 3]),
        Err(Error::NotInGroup { .. })
    ));
    assert!(matches!(
        sys.state(z, z, [0.0, 0.0, 1.1], [1.0; 3], [0.0; 3]),
        Err(Error::NotInGroup { .. })
    ));
    assert!(sys.udot(&[0.0; 5]).is_err());
    assert_eq!(
        sys.space().describe(),
        "z1: SO(3) × z2: SO(3) × u: S^2 × Omega1: R^3 × Omega2: R^3"
    );
}

// ---------------------------------------------------------------------------------------------
// The Lagrangian (8), the rolling constraint (10) and the momenta against point-mass bodies

#[test]
fn rescaled_lagrangian_and_momenta_against_point_masses() {
    let (sys, bodies, r) = point_bodies(7);
    let mut rng = Rng(99);
    let scale = sys.scale();
    for _ in 0..5 {
        let z = random_state(&sys, &mut rng, 1.5);
        // Positions of every point of both bodies by (4), as functions of the state.
        let points = |s: &[f64]| -> Vec<Vector3<f64>> {
            let q = parts(s);
            let a = sys.centres(s).unwrap();
            let mut x = Vec::new();
            for k in 0..2 {
                for p in &bodies[k].p {
                    x.push(q.z[k] * p + v3(a[k]));
                }
            }
            x
        };
        let h = 1e-3;
        let traj: Vec<Vec<Vector3<f64>>> = [h, -h, 2.0 * h, -2.0 * h, 0.0]
            .iter()
            .map(|&t| points(&along(&sys, &z, t)))
            .collect();
        let vel: Vec<Vector3<f64>> = (0..traj[0].len())
            .map(|i| (8.0 * (traj[0][i] - traj[1][i]) - (traj[2][i] - traj[3][i])) / (12.0 * h))
            .collect();
        let masses: Vec<f64> = bodies[0].m.iter().chain(&bodies[1].m).copied().collect();
        let ke: f64 = vel
            .iter()
            .zip(&masses)
            .map(|(v, m)| 0.5 * m * v.norm_squared())
            .sum();
        let lmom: Vector3<f64> = vel.iter().zip(&masses).map(|(v, m)| v * *m).sum();
        let ang: Vector3<f64> = traj[4]
            .iter()
            .zip(&vel)
            .zip(&masses)
            .map(|((x, v), m)| x.cross(v) * *m)
            .sum();
        let cm: Vector3<f64> = traj[4].iter().zip(&masses).map(|(x, m)| x * *m).sum();
        let energy = sys.energy(&z).unwrap();
        let l8 = sys.lagrangian(&z).unwrap();
        eprintln!(
            "KE points {ke:.12e}, energy {energy:.12e}, eR²·L(8) {:.12e}",
            scale * l8
        );
        assert!(
            (ke - energy).abs() < 1e-9 * ke,
            "KE {ke} vs energy {energy}"
        );
        assert!((energy - scale * l8).abs() < 1e-13 * energy);
        // Centre-of-mass frame (3): total mass moment and momentum vanish.
        assert!(
            cm.norm() < 1e-13 && lmom.norm() < 1e-8 * ke.sqrt(),
            "{cm} {lmom}"
        );
        // Total angular momentum = eR²·J (Noether momentum of §2.1).
        let am = v3(sys.angular_momentum(&z).unwrap());
        assert!((am - ang).norm() < 1e-9 * ang.norm(), "{am} vs {ang}");
        // Body momenta eR²p_k = z_kᵀ Σ m (x − a_k) × ẋ (angular momentum about the centre a_k).
        let a = sys.centres(&z).unwrap();
        let bm = sys.body_momenta(&z).unwrap();
        let q = parts(&z);
        let n0 = bodies[0].p.len();
        for k in 0..2 {
            let range = if k == 0 { 0..n0 } else { n0..traj[4].len() };
            let h_k: Vector3<f64> = range
                .map(|i| (traj[4][i] - v3(a[k])).cross(&vel[i]) * masses[i])
                .sum();
            assert!((q.z[k] * v3(bm[k]) - h_k).norm() < 1e-9 * h_k.norm());
        }
        // Contact geometry: c on both spheres; no slip — the material points of both bodies at
        // c move with equal velocities (this is (7)/(10)).
        let c = v3(sys.contact_point(&z).unwrap());
        assert!(((c - v3(a[0])).norm() - r[0]).abs() < 1e-14);
        assert!(((c - v3(a[1])).norm() - r[1]).abs() < 1e-14);
        let mat = [
            q.z[0].transpose() * q.u * r[0],
            -q.z[1].transpose() * q.u * r[1],
        ];
        let slip = ddt(
            &|s: &[f64]| {
                let qq = parts(s);
                let a = sys.centres(s).unwrap();
                [qq.z[0] * mat[0] + v3(a[0]) - qq.z[1] * mat[1] - v3(a[1])]
            },
            &sys,
            &z,
        )[0];
        assert!(slip.norm() < 1e-9, "slip velocity {slip}");
        // u̇ of (10) is the derivative of u along the curve; (7) holds for it.
        let ud = ddt(
            &|s: &[f64]| [Vector3::from_column_slice(&s[18..21])],
            &sys,
            &z,
        )[0];
        assert!((ud - v3(sys.udot(&z).unwrap())).norm() < 1e-10);
        assert!(sys.constraint_residual(&z, sys.udot(&z).unwrap()).unwrap() < 1e-14);
    }
}

#[test]
fn lagrangian_forms_and_derived_parameters() {
    let sys = spheres();
    let [m1, m2] = sys.masses();
    let [r1, r2] = sys.radii();
    assert!((sys.reduced_mass() - m1 * m2 / (m1 + m2)).abs() < 1e-15);
    assert!((sys.alphas()[0] + sys.alphas()[1] - 1.0).abs() < 1e-15);
    assert!((sys.e_vectors()[0][2] - 0.15 / r1).abs() < 1e-15);
    assert!((sys.e_vectors()[1][2] - 0.4 / r2).abs() < 1e-15);
    let j0 = sys.moment_tensors();
    // J⁰ = tr(I)𝟙 − I for I₁ of `spheres()`.
    assert!((j0[0][(0, 0)] - (0.30 + 0.25)).abs() < 1e-14 && (j0[0][(0, 1)] + 0.05).abs() < 1e-14);
    // The literal (8) equals the completed-square form used for the energy.
    let mut rng = Rng(3);
    for _ in 0..10 {
        let z = random_state(&sys, &mut rng, 2.0);
        let l = sys.lagrangian(&z).unwrap();
        assert!((sys.energy(&z).unwrap() - sys.scale() * l).abs() < 1e-13 * sys.scale() * l);
    }
}

// ---------------------------------------------------------------------------------------------
// Equations of motion

/// Constrained Newton–Euler in physical units: body k (mass m_k, J_k⁰ about its centre of mass
/// x_k) feels the contact force −λ (k = 1) or +λ (k = 2) at the contact point c;
/// J_k^s ω̇_k = (J_k^s ω_k) × ω_k + (c − x_k) × F_k, ẍ₁ = −λ/m₁, ẍ₂ = λ/m₂, and the second
/// derivative of the no-slip condition, d/dt[ẋ₁ + ω₁ × (c − x₁) − ẋ₂ − ω₂ × (c − x₂)] = 0, with
/// ċ = ȧ₁ + r₁u̇. The 9 × 9 linear system is solved for (ω̇₁, ω̇₂, λ).
fn newton_euler(sys: &RollingSpheres, gam: [Vector3<f64>; 2], z: &[f64]) -> [Vector3<f64>; 2] {
    let q = parts(z);
    let [m1, m2] = sys.masses();
    let [r1, r2] = sys.radii();
    let big = r1 + r2;
    let w = [q.z[0] * q.o[0], q.z[1] * q.o[1]];
    // u̇ from the velocities of the centres: the no-slip condition written out once more.
    let ud = (w[0] * r1 + w[1] * r2).cross(&q.u) / big;
    let g = [q.z[0] * gam[0], q.z[1] * gam[1]];
    let gd = [w[0].cross(&g[0]), w[1].cross(&g[1])];
    let m = m1 + m2;
    let a1 = -(g[0] * m1 + g[1] * m2 + q.u * (big * m2)) / m;
    let a2 = a1 + q.u * big;
    let ad1 = -(gd[0] * m1 + gd[1] * m2 + ud * (big * m2)) / m;
    let ad2 = ad1 + ud * big;
    let x = [g[0] + a1, g[1] + a2];
    let xd = [gd[0] + ad1, gd[1] + ad2];
    let c = a1 + q.u * r1;
    let cd = ad1 + ud * r1;
    let vc = [
        xd[0] + w[0].cross(&(c - x[0])),
        xd[1] + w[1].cross(&(c - x[1])),
    ];
    assert!((vc[0] - vc[1]).norm() < 1e-12, "the state must roll");
    let j0 = sys.moment_tensors();
    let js = [
        q.z[0] * j0[0] * q.z[0].transpose(),
        q.z[1] * j0[1] * q.z[1].transpose(),
    ];
    let mut a = DMatrix::<f64>::zeros(9, 9);
    let mut b = DVector::<f64>::zeros(9);
    let put = |a: &mut DMatrix<f64>, i: usize, j: usize, m: &Matrix3<f64>| {
        a.view_mut((i, j), (3, 3)).copy_from(m);
    };
    // J₁ω̇₁ − (c − x₁) × (−λ) = gyro₁;  J₂ω̇₂ − (c − x₂) × λ = gyro₂.
    put(&mut a, 0, 0, &js[0]);
    put(&mut a, 0, 6, &hat(&(c - x[0])));
    put(&mut a, 3, 3, &js[1]);
    put(&mut a, 3, 6, &(-hat(&(c - x[1]))));
    b.rows_mut(0, 3).copy_from(&(js[0] * w[0]).cross(&w[0]));
    b.rows_mut(3, 3).copy_from(&(js[1] * w[1]).cross(&w[1]));
    // −λ/m₁ + ω̇₁ × (c − x₁) + ω₁ × (ċ − ẋ₁) − λ/m₂ − ω̇₂ × (c − x₂) − ω₂ × (ċ − ẋ₂) = 0.
    put(&mut a, 6, 0, &(-hat(&(c - x[0]))));
    put(&mut a, 6, 3, &hat(&(c - x[1])));
    put(
        &mut a,
        6,
        6,
        &(-Matrix3::identity() * (1.0 / m1 + 1.0 / m2)),
    );
    b.rows_mut(6, 3)
        .copy_from(&(w[1].cross(&(cd - xd[1])) - w[0].cross(&(cd - xd[0]))));
    let sol = a.lu().solve(&b).unwrap();
    let wd = [
        Vector3::new(sol[0], sol[1], sol[2]),
        Vector3::new(sol[3], sol[4], sol[5]),
    ];
    [q.z[0].transpose() * wd[0], q.z[1].transpose() * wd[1]]
}

#[test]
fn lagrange_dalembert_agrees_with_constrained_newton_euler() {
    let sys = spheres();
    let gam = [Vector3::new(0.1, -0.2, 0.15), Vector3::new(-0.3, 0.2, 0.4)];
    let mut rng = Rng(11);
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let z = random_state(&sys, &mut rng, 2.0);
        let acc = sys.accelerations(&z).unwrap();
        let ne = newton_euler(&sys, gam, &z);
        let scale = 1.0 + ne[0].norm() + ne[1].norm();
        for k in 0..2 {
            worst = worst.max((v3(acc[k]) - ne[k]).norm() / scale);
        }
    }
    eprintln!("Lagrange–d'Alembert vs Newton–Euler: max relative difference {worst:.2e}");
    assert!(worst < 1e-12, "{worst}");
    // Point-mass bodies too (general second moments from the points).
    let (sys, bodies, _) = point_bodies(5);
    for _ in 0..20 {
        let z = random_state(&sys, &mut rng, 2.0);
        let acc = sys.accelerations(&z).unwrap();
        let ne = newton_euler(&sys, [bodies[0].gamma(), bodies[1].gamma()], &z);
        let scale = 1.0 + ne[0].norm() + ne[1].norm();
        assert!((v3(acc[0]) - ne[0]).norm() + (v3(acc[1]) - ne[1]).norm() < 1e-12 * scale);
    }
}

/// The residual of the final equation of 003 §2.3 for body 1 (`corrected`: with the Ω̇₂
/// coefficient (e₁ − z₁⁻¹u)^(z₁⁻¹u + z₁⁻¹z₂e₂)^ and (z₂⁻¹z₁e₁)^ in place of 𝟙; otherwise as
/// printed). Body 2: `swap` exchanges the indices and negates u (as 003 prescribes).
fn seed_equation(sys: &RollingSpheres, z: &[f64], corrected: bool, swap: bool) -> Vector3<f64> {
    let q = parts(z);
    let acc = sys.accelerations(z).unwrap();
    let mut a = sys.alphas();
    let mut e = sys.e_vectors().map(v3);
    let mut jt = sys.j_tensors();
    let (mut z1, mut z2, mut o1, mut o2, mut od1, mut od2, mut u) =
        (q.z[0], q.z[1], q.o[0], q.o[1], v3(acc[0]), v3(acc[1]), q.u);
    if swap {
        std::mem::swap(&mut z1, &mut z2);
        std::mem::swap(&mut o1, &mut o2);
        std::mem::swap(&mut od1, &mut od2);
        a.swap(0, 1);
        e.swap(0, 1);
        jt.swap(0, 1);
        u = -u;
    }
    let ud = (z1 * o1 * a[0] + z2 * o2 * a[1]).cross(&u);
    let zu = z1.transpose() * u;
    let z12 = z1.transpose() * z2;
    let (a1, a2, e1, e2, j1) = (a[0], a[1], e[0], e[1], jt[0]);
    let m1 = j1 + hat(&(e1 - zu)) * hat(&zu) * (a1 * a1) + hat(&zu) * hat(&e1) * (a1 * a1);
    let m2 = if corrected {
        hat(&(e1 - zu)) * hat(&(zu + z12 * e2)) * z12 * (a1 * a2)
    } else {
        (hat(&(e1 - zu)) * hat(&zu) - hat(&zu) * hat(&(z12 * e2))) * z12 * (a1 * a2)
    };
    let first = if corrected {
        hat(&(z12.transpose() * e1))
    } else {
        Matrix3::identity()
    };
    -m1 * od1 - m2 * od2
        + (j1 * o1).cross(&o1)
        + zu.cross(&o1.cross(&o1.cross(&e1))) * (a1 * a1)
        + z12 * (first - hat(&(z2.transpose() * u))) * o2.cross(&o2.cross(&e2)) * (a1 * a2)
        + (e1 - zu).cross(&(o1 * a1 + z12 * o2 * a2).cross(&(z1.transpose() * ud))) * a1
}

#[test]
fn final_equation_of_the_seed_holds_only_corrected() {
    let sys = spheres();
    let mut rng = Rng(17);
    let (mut printed, mut fixed) = (f64::INFINITY, 0.0f64);
    for _ in 0..50 {
        let z = random_state(&sys, &mut rng, 2.0);
        let s = sys.accelerations(&z).unwrap();
        let scale = 1.0 + v3(s[0]).norm() + v3(s[1]).norm();
        for swap in [false, true] {
            fixed = fixed.max(seed_equation(&sys, &z, true, swap).norm() / scale);
            printed = printed.min(seed_equation(&sys, &z, false, swap).norm() / scale);
        }
    }
    eprintln!(
        "003 §2.3 final equation: corrected residual ≤ {fixed:.2e}, as printed ≥ {printed:.2e}"
    );
    assert!(fixed < 1e-13, "{fixed}");
    assert!(printed > 1e-6, "{printed}");
}

// ---------------------------------------------------------------------------------------------
// Curvature (003 §2.2)

#[test]
fn curvature_closed_form_against_brackets() {
    let sys = spheres();
    let mut rng = Rng(23);
    let mut worst = 0.0f64;
    let mut smallest = f64::INFINITY;
    for _ in 0..20 {
        let z = random_state(&sys, &mut rng, 1.0);
        let o = [arr(&rng.vec3()), arr(&rng.vec3())];
        let ot = [arr(&rng.vec3()), arr(&rng.vec3())];
        let closed = sys.curvature(&z, o, ot).unwrap();
        let num = sys.curvature_by_brackets(&z, o, ot, 2e-3).unwrap();
        let d = rel(&num, &closed);
        worst = worst.max(d);
        smallest = smallest.min(v3(closed).norm());
        // Antisymmetric.
        let swapped = sys.curvature(&z, ot, o).unwrap();
        assert!((v3(swapped) + v3(closed)).norm() < 1e-15);
    }
    eprintln!(
        "curvature: bracket vs closed form, max relative difference {worst:.2e}; smallest |Δ| {smallest:.2e}"
    );
    assert!(worst < 1e-8, "{worst}");
    assert!(smallest > 1e-3, "Δ is nonzero in general");
}

fn planar_spheres(gz: f64) -> RollingSpheres {
    RollingSpheres::new(
        0.8,
        1.2,
        [0.2, -0.1, gz],
        [-0.3, 0.25, 0.0],
        1.5,
        2.5,
        [[0.40, 0.05, 0.0], [0.05, 0.30, 0.0], [0.0, 0.0, 0.25]],
        [[0.90, -0.10, 0.0], [-0.10, 1.10, 0.0], [0.0, 0.0, 0.70]],
    )
    .unwrap()
}

#[test]
fn curvature_vanishes_on_the_planar_subbundle() {
    let sys = planar_spheres(0.0);
    assert!(sys.is_planar(1e-14));
    assert!(!planar_spheres(0.1).is_planar(1e-14));
    let z = sys.planar_state([0.3, -1.1], 0.7, [1.0, -0.4]).unwrap();
    let o = [[0.0, 0.0, 1.3], [0.0, 0.0, -0.2]];
    let ot = [[0.0, 0.0, -0.5], [0.0, 0.0, 2.0]];
    assert_eq!(v3(sys.curvature(&z, o, ot).unwrap()).norm(), 0.0);
    let num = v3(sys.curvature_by_brackets(&z, o, ot, 5e-3).unwrap());
    assert!(num.norm() < 1e-10, "{num}");
    // … but not for velocities off T𝒬₀ at the same point.
    let o2 = [[0.3, 0.0, 1.3], [0.0, 0.0, -0.2]];
    assert!(v3(sys.curvature(&z, o2, ot).unwrap()).norm() > 1e-2);
}

// ---------------------------------------------------------------------------------------------
// The methods

fn z0(sys: &RollingSpheres) -> Vec<f64> {
    sys.state(
        rows(&so3::exp_unchecked(&Vector3::new(0.3, -0.5, 0.9))),
        rows(&so3::exp_unchecked(&Vector3::new(-1.2, 0.4, 0.2))),
        arr(&Vector3::new(0.2, 0.9, -0.3).normalize()),
        [1.1, -0.6, 0.8],
        [-0.4, 0.9, 0.5],
    )
    .unwrap()
}

fn orthogonality_defect(z: &[f64]) -> f64 {
    let q = parts(z);
    let d = |r: &Matrix3<f64>| (r.transpose() * r - Matrix3::identity()).norm();
    d(&q.z[0]).max(d(&q.z[1])).max((q.u.norm() - 1.0).abs())
}

#[test]
fn long_run_energy_momentum_and_manifold() {
    let sys = spheres();
    let z = z0(&sys);
    let (dt, steps, every) = (0.02, 100_000, 100);
    let e0 = sys.energy(&z).unwrap();
    let j0 = v3(sys.angular_momentum(&z).unwrap());
    let ax = [
        v3(sys.e_vectors()[0]).normalize(),
        v3(sys.e_vectors()[1]).normalize(),
    ];
    for method in ["midpoint", "rkmk4", "rk4"] {
        let t = integrate(&sys, method, &z, dt, steps, every).unwrap();
        let n = t.len();
        let (mut de_first, mut de_second, mut dj, mut manifold) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let (mut pmin, mut pmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..n {
            let s = t.state(k);
            let de = (sys.energy(s).unwrap() - e0).abs() / e0;
            if k < n / 2 {
                de_first = de_first.max(de);
            } else {
                de_second = de_second.max(de);
            }
            // J as the run reads it (the invariants take states as they are); the observables
            // take states of the state space only, so RK4's (off SO(3) by its drift) are
            // retracted first.
            let jt = sys.invariants(s).unwrap();
            dj = dj.max((Vector3::new(jt[0], jt[1], jt[2]) - j0).norm() / j0.norm());
            manifold = manifold.max(orthogonality_defect(s));
            let mut on = s.to_vec();
            sys.space().retract(&mut on);
            let p = v3(sys.body_momenta(&on).unwrap()[0]).dot(&ax[0]);
            pmin = pmin.min(p);
            pmax = pmax.max(p);
        }
        eprintln!(
            "{method}, dt = {dt}, {steps} steps: max |ΔE|/E first half {de_first:.3e}, second \
             half {de_second:.3e}; max |ΔJ|/|J| {dj:.3e}; SO(3)/S² defect {manifold:.1e}; \
             material momentum p₁·ê₁ ∈ [{pmin:.4}, {pmax:.4}]"
        );
        if method != "rk4" {
            assert!(manifold < 1e-13, "{manifold}");
        }
        assert!(pmax - pmin > 1e-2, "the material momentum varies");
        // The angular momentum is the sum of two internal blocks whose increments cancel.
        // (RK4 keeps P₁ + P₂ too, but leaves SO(3), and J read back in the user frame with it.)
        if method != "rk4" {
            assert!(dj < 1e-12, "{dj}");
        }
        if method == "midpoint" {
            // Bounded, not drifting: the second half is no worse than the first (up to noise).
            assert!(de_second < 1.5 * de_first + 1e-14, "{de_first} {de_second}");
            assert!(de_first < 1e-4);
        }
    }
}

#[test]
fn computed_motions_roll() {
    // (10) along computed motions: central differences of the saved u and z_k against u̇(z) and
    // z_kΩ̂_k (O(h²) agreement), and (7) to round-off at every state.
    let sys = spheres();
    let h = 1e-3;
    let t = integrate(&sys, "midpoint4", &z0(&sys), h, 400, 1).unwrap();
    let mut worst = 0.0f64;
    for k in 1..t.len() - 1 {
        let (a, s, b) = (t.state(k - 1), t.state(k), t.state(k + 1));
        let ud = (Vector3::from_column_slice(&b[18..21]) - Vector3::from_column_slice(&a[18..21]))
            / (2.0 * h);
        worst = worst.max((ud - v3(sys.udot(s).unwrap())).norm());
        let q = parts(s);
        let zd =
            (Matrix3::from_row_slice(&b[0..9]) - Matrix3::from_row_slice(&a[0..9])) / (2.0 * h);
        worst = worst.max((zd - q.z[0] * hat(&q.o[0])).norm());
        assert!(sys.constraint_residual(s, sys.udot(s).unwrap()).unwrap() < 1e-14);
    }
    eprintln!("u̇ and ż by differences of the computed motion vs (10): {worst:.2e} (h = {h})");
    assert!(worst < 1e-5, "{worst}");
}

#[test]
fn observed_orders() {
    let sys = spheres();
    let z = z0(&sys);
    let t_end: f64 = 1.0;
    let reference = integrate(&sys, "midpoint4", &z, 1.0 / 1600.0, 1600, 1600)
        .unwrap()
        .final_state;
    for (method, nominal, dt) in [
        ("midpoint", 2.0, 0.05),
        ("midpoint4", 4.0, 0.1),
        ("rkmk4", 4.0, 0.05),
        ("rk4", 4.0, 0.05),
    ] {
        let e: Vec<f64> = [1.0, 2.0, 4.0]
            .iter()
            .map(|k| {
                let h = dt / k;
                let n = (t_end / h).round() as usize;
                dist(
                    &integrate(&sys, method, &z, h, n, n).unwrap().final_state,
                    &reference,
                )
            })
            .collect();
        let o = [(e[0] / e[1]).log2(), (e[1] / e[2]).log2()];
        eprintln!(
            "order {method}: errors {:.3e} {:.3e} {:.3e}, observed {:.3} {:.3} (nominal {nominal})",
            e[0], e[1], e[2], o[0], o[1]
        );
        assert!((o[1] - nominal).abs() < 0.25, "{method}: {o:?}");
        assert_eq!(
            sys.methods()
                .iter()
                .find(|m| m.0 == method)
                .unwrap()
                .1
                .order as f64,
            nominal
        );
    }
}

/// ρ(z₁, z₂, u, Ω₁, Ω₂) = (z₁, z₂, u, −Ω₁, −Ω₂).
fn reverse(z: &mut [f64]) {
    z[21..27].iter_mut().for_each(|x| *x = -*x);
}

#[test]
fn symmetric_methods_are_reversible() {
    let sys = spheres();
    let z = z0(&sys);
    for (method, symmetric) in [("midpoint", true), ("midpoint4", true), ("rkmk4", false)] {
        let mut y = integrate(&sys, method, &z, 0.05, 40, 40)
            .unwrap()
            .final_state;
        reverse(&mut y);
        let mut back = integrate(&sys, method, &y, 0.05, 40, 40)
            .unwrap()
            .final_state;
        reverse(&mut back);
        let d = dist(&back, &z);
        eprintln!("{method}: ρ-reversibility defect {d:.2e}");
        assert_eq!(d < 1e-12, symmetric, "{method}: {d}");
        let p = sys.methods().into_iter().find(|m| m.0 == method).unwrap().1;
        assert_eq!(p.symmetric, symmetric);
        assert!(p.manifold);
    }
}

// ---------------------------------------------------------------------------------------------
// The holonomic subsystem (003 §2.4) and the planar map

#[test]
fn planar_subbundle_is_invariant() {
    let sys = planar_spheres(0.0);
    let (th, phi, thd) = ([0.3, -1.1], 0.7, [1.0, -0.4]);
    let z = sys.planar_state(th, phi, thd).unwrap();
    let back = sys.to_planar(&z, 1e-15).unwrap();
    assert!(dist(&back, &[th[0], th[1], phi, thd[0], thd[1]]) < 1e-15);
    // u̇ = φ̇ e₃ × u with R φ̇ = r₁θ̇₁ + r₂θ̇₂ (003 §1).
    let [r1, r2] = sys.radii();
    let phid = (r1 * thd[0] + r2 * thd[1]) / (r1 + r2);
    let ud = v3(sys.udot(&z).unwrap());
    assert!((ud - Vector3::new(-phi.sin(), phi.cos(), 0.0) * phid).norm() < 1e-15);
    let t = integrate(&sys, "midpoint", &z, 0.01, 3000, 30).unwrap();
    let mut worst = 0.0f64;
    for k in 0..t.len() {
        let s = t.state(k);
        let q = parts(s);
        let e3 = Vector3::z();
        let off = (q.z[0] * e3 - e3)
            .norm()
            .max((q.z[1] * e3 - e3).norm())
            .max(q.u[2].abs())
            .max(q.o[0].xy().norm())
            .max(q.o[1].xy().norm());
        worst = worst.max(off);
    }
    eprintln!("T𝒬₀ invariance: max distance from T𝒬₀ over 3000 steps {worst:.2e}");
    assert!(worst < 1e-13, "{worst}");
    assert!(sys.to_planar(t.state(t.len() - 1), 1e-12).is_ok());
    // The same start with a centre of mass off the plane leaves T𝒬₀.
    let tilted = planar_spheres(0.1);
    let t = integrate(&tilted, "midpoint", &z, 0.01, 300, 300).unwrap();
    assert!(tilted.to_planar(&t.final_state, 1e-3).is_err());
}

// ---------------------------------------------------------------------------------------------
// The generic LieMidpoint on another GroupField: the lifted free rigid body

#[test]
fn lie_midpoint_on_the_lifted_rigid_body() {
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap().with_attitude();
    let r = so3::exp_unchecked(&Vector3::new(0.4, -0.2, 0.1));
    let z: Vec<f64> = [1.0, 0.5, -0.3]
        .into_iter()
        .chain((0..9).map(|k| r[(k / 3, k % 3)]))
        .collect();
    let reference = integrate_with(&body, &Rkmk4, &z, 1e-3, 2000, 2000)
        .unwrap()
        .final_state;
    for (m, nominal) in [
        (LieMidpoint::new(), 2.0),
        (LieMidpoint(Composition::triple_jump4()), 4.0),
    ] {
        assert_eq!(
            Integrator::<RigidBody>::properties(&m).order as f64,
            nominal
        );
        let e: Vec<f64> = [0.1, 0.05, 0.025]
            .iter()
            .map(|&h| {
                let n = (2.0_f64 / h).round() as usize;
                dist(
                    &integrate_with(&body, &m, &z, h, n, n).unwrap().final_state,
                    &reference,
                )
            })
            .collect();
        let o = (e[1] / e[2]).log2();
        eprintln!("LieMidpoint (order {nominal}) on the rigid body: errors {e:?}, observed {o:.3}");
        assert!((o - nominal).abs() < 0.25);
        // The orbit: |M| and R M (Casimir and spatial momentum) to round-off, R ∈ SO(3).
        let t = integrate_with(&body, &m, &z, 0.1, 2000, 2000).unwrap();
        let inv0 = body.invariants(&z).unwrap();
        let inv = body.invariants(&t.final_state).unwrap();
        assert!(dist(&inv, &inv0) < 1e-12, "{inv:?} {inv0:?}");
        // Symmetric: ρ(M, R) = (−M, R) reverses the free rigid body.
        let mut y = t.final_state.clone();
        y[..3].iter_mut().for_each(|x| *x = -*x);
        let mut back = integrate_with(&body, &m, &y, 0.1, 2000, 2000)
            .unwrap()
            .final_state;
        back[..3].iter_mut().for_each(|x| *x = -*x);
        assert!(dist(&back, &z) < 1e-10, "{}", dist(&back, &z));
    }
}

#[test]
fn momentum_form_agrees_with_lagrange_dalembert() {
    // The methods integrate Ṗ_k = ṡ_k × w (P = Mω); along a computed motion the differences of
    // Ω must be the Lagrange–d'Alembert accelerations, those of P the rates, and P₁ + P₂ = J.
    let sys = spheres();
    let h = 1e-3;
    let t = integrate(&sys, "midpoint4", &z0(&sys), h, 200, 1).unwrap();
    let (mut acc, mut rate) = (0.0f64, 0.0f64);
    for k in 1..t.len() - 1 {
        let (a, s, b) = (t.state(k - 1), t.state(k), t.state(k + 1));
        let od = (Vector3::from_column_slice(&b[21..24]) - Vector3::from_column_slice(&a[21..24]))
            / (2.0 * h);
        acc = acc.max((od - v3(sys.accelerations(s).unwrap()[0])).norm());
        let (pa, pb) = (
            sys.spatial_momenta(a).unwrap(),
            sys.spatial_momenta(b).unwrap(),
        );
        let r = sys.momentum_rates(s).unwrap();
        rate = rate.max(((v3(pb[1]) - v3(pa[1])) / (2.0 * h) - v3(r[1])).norm());
        let p = sys.spatial_momenta(s).unwrap();
        let j = v3(sys.angular_momentum(s).unwrap());
        assert!((v3(p[0]) + v3(p[1]) - j).norm() < 1e-13 * j.norm());
        assert!((v3(r[0]) + v3(r[1])).norm() < 1e-13 * (1.0 + v3(r[0]).norm()));
    }
    eprintln!(
        "momentum form vs Lagrange–d'Alembert along a motion: Ω̇ {acc:.2e}, Ṗ {rate:.2e} (h = {h})"
    );
    assert!(acc < 1e-5 && rate < 1e-5, "{acc} {rate}");
    // The chart round trip.
    let z = z0(&sys);
    let mut y = z.clone();
    sys.to_internal(&mut y);
    sys.to_user(&mut y);
    assert!(dist(&y, &z) < 1e-14);
}
