//! Tangent maps of the discrete flow (issue 26): the Jacobian a lifted run carries against
//! central differences of the same method, and the symplecticity JᵀΩJ = Ω of the Verlet methods'
//! Jacobian.

use std::sync::Arc;

use lieflow::integrate::tangent::TangentSystem;
use lieflow::integrate::{integrate, Clock, System};
use lieflow::pseudo_rigid::potential::{SaintVenantKirchhoff, Sum, Volumetric};
use lieflow::pseudo_rigid::PseudoRigidBody;
use lieflow::systems::{GeneralizedRigidBody, HeavyTop, RigidBody, SphericalPendulum};

/// (base state at the end, Jacobian d×d row-major) of `steps` steps of `method`.
fn lifted_end(
    t: &dyn TangentSystem,
    method: &str,
    z0: &[f64],
    dt: f64,
    steps: usize,
) -> (Vec<f64>, Vec<f64>) {
    let (z, jac, _) = lifted_end_all(t, method, z0, dt, steps);
    (z, jac)
}

/// (base state, Jacobian, parameter Jacobian d×p) at the end.
fn lifted_end_all(
    t: &dyn TangentSystem,
    method: &str,
    z0: &[f64],
    dt: f64,
    steps: usize,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let d = t.base_dim();
    let np = t.parameter_names().len();
    let seed = t.seed(z0).unwrap();
    let traj = integrate(t, method, &seed, dt, steps, steps).unwrap();
    let (mut z, mut jac, mut pjac) = (vec![0.0; d], vec![0.0; d * d], vec![0.0; d * np]);
    t.jacobian(traj.state(1), &mut z, &mut jac, &mut pjac);
    (z, jac, pjac)
}

/// Central differences of the end state in each initial component (step h·max(1, |z_j|)).
fn differences(
    sys: &dyn System,
    method: &str,
    z0: &[f64],
    dt: f64,
    steps: usize,
    h: f64,
) -> Vec<f64> {
    let d = z0.len();
    let mut jac = vec![0.0; d * d];
    for j in 0..d {
        let hj = h * z0[j].abs().max(1.0);
        let end = |s: f64| {
            let mut z = z0.to_vec();
            z[j] += s;
            integrate(sys, method, &z, dt, steps, steps)
                .unwrap()
                .state(1)
                .to_vec()
        };
        let (p, m) = (end(hj), end(-hj));
        for i in 0..d {
            jac[i * d + j] = (p[i] - m[i]) / (2.0 * hj);
        }
    }
    jac
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// Central differences of the end state along each parameter θ_m, the system rebuilt by
/// `build` with θ_m moved by h·max(1, |θ_m|) (d × p, row-major).
fn parameter_differences<S: System, const P: usize>(
    build: impl Fn([f64; P]) -> S,
    theta: [f64; P],
    method: &str,
    z0: &[f64],
    (dt, steps): (f64, usize),
    h: f64,
) -> Vec<f64> {
    let d = z0.len();
    let mut out = vec![0.0; d * P];
    for m in 0..P {
        let hm = h * theta[m].abs().max(1.0);
        let end = |s: f64| {
            let mut th = theta;
            th[m] += s;
            integrate(&build(th), method, z0, dt, steps, steps)
                .unwrap()
                .state(1)
                .to_vec()
        };
        let (a, b) = (end(hm), end(-hm));
        for i in 0..d {
            out[i * P + m] = (a[i] - b[i]) / (2.0 * hm);
        }
    }
    out
}

/// max |a − b| (absolute).
fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

fn body() -> PseudoRigidBody {
    let elastic = Arc::new(Sum::new(vec![
        Arc::new(SaintVenantKirchhoff::new(1.0, 2.0).unwrap()),
        Arc::new(Volumetric::polytropic(0.5, 1.4).unwrap()),
    ]));
    PseudoRigidBody::new(3, elastic, true).unwrap()
}

fn body_state() -> Vec<f64> {
    let x = [1.3, 0.1, -0.05, 0.02, 1.1, 0.08, -0.03, 0.05, 0.9];
    let p = [0.1, -0.5, 0.2, 0.6, 0.05, -0.3, -0.1, 0.4, 0.02];
    x.iter().chain(p.iter()).copied().collect()
}

/// The Verlet methods on the pseudo-rigid body: the lifted run's Jacobian is the derivative of
/// the method's own map (central differences to 1e-8), its base state is the plain run's, and
/// JᵀΩJ = Ω to round-off.
#[test]
fn verlet_jacobian_of_the_pseudo_rigid_body() {
    let b = body();
    let t = b.tangent().expect("the free body has a tangent lift");
    let z0 = body_state();
    let (dt, steps) = (0.05, 40);
    for method in ["verlet", "verlet4", "verlet6"] {
        let (z, jac) = lifted_end(&*t, method, &z0, dt, steps);
        let plain = integrate(&b, method, &z0, dt, steps, steps).unwrap();
        assert_eq!(
            z,
            plain.state(1),
            "{method}: the base state is the plain run's"
        );
        let fd = differences(&b, method, &z0, dt, steps, 1e-5);
        let err = max_rel(&jac, &fd);
        eprintln!("{method}: Jacobian vs differences {err:.2e}");
        assert!(err < 1e-8, "{method}: {err:e}");
        // JᵀΩJ = Ω with Ω = [[0, 1], [−1, 0]] (blocks of 9).
        let d = 18;
        let omega = |i: usize, j: usize| match (i < 9, j < 9) {
            (true, false) if j == i + 9 => 1.0,
            (false, true) if i == j + 9 => -1.0,
            _ => 0.0,
        };
        let mut worst = 0.0f64;
        for a in 0..d {
            for c in 0..d {
                let mut s = 0.0;
                for i in 0..d {
                    for k in 0..d {
                        s += jac[i * d + a] * omega(i, k) * jac[k * d + c];
                    }
                }
                worst = worst.max((s - omega(a, c)).abs());
            }
        }
        let norm = jac.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        eprintln!("{method}: |JᵀΩJ − Ω| = {worst:.2e} (|J|∞ {norm:.1})");
        assert!(worst < 1e-12 * norm * norm, "{method}: {worst:e}");
    }
}

/// RK4 on the free rigid body and the heavy top (principal frame turned: the lift's chart).
#[test]
fn rk4_jacobian_of_the_tops() {
    let inertia = [2.0, 0.3, -0.1, 0.3, 3.1, 0.2, -0.1, 0.2, 4.2];
    let rb = RigidBody::from_matrix(&inertia).unwrap();
    let ht = HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap();
    let cases: [(&dyn System, Vec<f64>); 2] = [
        (&rb, vec![0.3, -0.8, 1.1]),
        (&ht, vec![1.0, 0.5, -0.3, 0.0, 0.6, 0.8]),
    ];
    for (sys, z0) in cases {
        let t = sys.tangent().expect("a lift");
        let (z, jac) = lifted_end(&*t, "rk4", &z0, 0.02, 100);
        let plain = integrate(sys, "rk4", &z0, 0.02, 100, 100).unwrap();
        assert!(max_rel(&z, plain.state(1)) < 1e-15);
        let fd = differences(sys, "rk4", &z0, 0.02, 100, 1e-5);
        let err = max_rel(&jac, &fd);
        eprintln!("{}: rk4 Jacobian vs differences {err:.2e}", sys.name());
        assert!(err < 1e-8, "{}: {err:e}", sys.name());
    }
}

fn hat(v: &[f64]) -> [[f64; 3]; 3] {
    [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]
}

/// The Lie–Poisson tensor of so(3)* (d = 3) or se(3)* (d = 6, (M, Γ)) at z, up to its overall
/// sign (which a Poisson map keeps either way): [[M̂, Γ̂], [Γ̂, 0]].
fn poisson_tensor(z: &[f64]) -> Vec<f64> {
    let d = z.len();
    let mut b = vec![0.0; d * d];
    let m = hat(&z[..3]);
    for i in 0..3 {
        for j in 0..3 {
            b[i * d + j] = m[i][j];
            if d == 6 {
                let g = hat(&z[3..6]);
                b[i * d + j + 3] = g[i][j];
                b[(i + 3) * d + j] = g[i][j];
            }
        }
    }
    b
}

/// The splittings of the tops (their defaults) on the tangent lift: the Jacobian against central
/// differences of the same method, and on the symplectic leaf: J B(z₀) Jᵀ = B(z) (a Poisson map)
/// and ∇C(z)ᵀJ = ∇C(z₀)ᵀ for the Casimirs (|M|²; |Γ|², M·Γ), to round-off.
#[test]
fn splitting_jacobians_of_the_tops_are_poisson() {
    let rb = RigidBody::from_matrix(&[2.0, 0.3, -0.1, 0.3, 3.1, 0.2, -0.1, 0.2, 4.2]).unwrap();
    let ht = HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap();
    let cases: [(&dyn System, Vec<f64>); 2] = [
        (&rb, vec![0.3, -0.8, 1.1]),
        (&ht, vec![1.0, 0.5, -0.3, 0.0, 0.6, 0.8]),
    ];
    for (sys, z0) in cases {
        let t = sys.tangent().expect("a lift");
        let d = z0.len();
        for method in ["splitting", "splitting4", "splitting6"] {
            let (z, jac) = lifted_end(&*t, method, &z0, 0.05, 60);
            let plain = integrate(sys, method, &z0, 0.05, 60, 60).unwrap();
            assert!(max_rel(&z, plain.state(1)) < 1e-14, "{method}: base state");
            let fd = differences(sys, method, &z0, 0.05, 60, 1e-5);
            let err = max_rel(&jac, &fd);
            eprintln!("{} {method}: Jacobian vs differences {err:.2e}", sys.name());
            assert!(err < 1e-8, "{} {method}: {err:e}", sys.name());
            // J B(z₀) Jᵀ = B(z).
            let (b0, b1) = (poisson_tensor(&z0), poisson_tensor(&z));
            let mut worst = 0.0f64;
            for i in 0..d {
                for k in 0..d {
                    let mut s = 0.0;
                    for a in 0..d {
                        for c in 0..d {
                            s += jac[i * d + a] * b0[a * d + c] * jac[k * d + c];
                        }
                    }
                    worst = worst.max((s - b1[i * d + k]).abs());
                }
            }
            // Casimir gradients: (2M) for the body; (0, 2Γ) and (Γ, M) for the top.
            let grads: Vec<(Vec<f64>, Vec<f64>)> = if d == 3 {
                vec![(
                    z0.iter().map(|x| 2.0 * x).collect(),
                    z.iter().map(|x| 2.0 * x).collect(),
                )]
            } else {
                let g =
                    |v: &[f64]| [vec![0.0; 3], v[3..6].iter().map(|x| 2.0 * x).collect()].concat();
                let mg = |v: &[f64]| [v[3..6].to_vec(), v[..3].to_vec()].concat();
                vec![(g(&z0), g(&z)), (mg(&z0), mg(&z))]
            };
            for (g0, g1) in grads {
                for j in 0..d {
                    let s: f64 = (0..d).map(|i| g1[i] * jac[i * d + j]).sum();
                    worst = worst.max((s - g0[j]).abs());
                }
            }
            eprintln!(
                "{} {method}: Poisson tensor and Casimirs {worst:.2e}",
                sys.name()
            );
            assert!(worst < 1e-12, "{} {method}: {worst:e}", sys.name());
        }
    }
}

/// ∂z/∂θ for the tops' parameters (the moments; mgl and the components of χ), for a splitting
/// and rk4, against central differences of systems built with the parameter moved (χ moved
/// without its normalisation: mgl scaled by |χ + h e_j|).
#[test]
fn parameter_jacobians_of_the_tops() {
    let moments = [1.0, 2.0, 3.0];
    let (mgl, chi) = (0.7, {
        let c = [0.2f64, -0.3, 1.0];
        let n = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        [c[0] / n, c[1] / n, c[2] / n]
    });
    let heavy =
        |moments: [f64; 3], mgl: f64, chi: [f64; 3]| HeavyTop::new(moments, mgl, chi).unwrap();
    let z_rb = vec![0.3, -0.8, 1.1];
    let z_ht = vec![1.0, 0.5, -0.3, 0.0, 0.6, 0.8];
    let h = 1e-6;
    for method in ["splitting4", "rk4"] {
        // The free body.
        let rb = RigidBody::new(moments).unwrap();
        let t = rb.tangent().unwrap();
        assert_eq!(t.parameter_names(), ["I1", "I2", "I3"]);
        let (_, _, pjac) = lifted_end_all(&*t, method, &z_rb, 0.05, 40);
        let free = |i: [f64; 3]| RigidBody::new(i).unwrap();
        let fd = parameter_differences(free, moments, method, &z_rb, (0.05, 40), h);
        let worst = max_abs_diff(&pjac, &fd);
        assert!(worst < 1e-7, "RigidBody {method}: {worst:e}");
        // The heavy top; χ moved without its normalisation (mgl scaled by |χ|).
        let ht = heavy(moments, mgl, chi);
        let t = ht.tangent().unwrap();
        assert_eq!(t.parameter_names().len(), 7);
        let (_, _, pjac) = lifted_end_all(&*t, method, &z_ht, 0.05, 40);
        let build = |th: [f64; 7]| {
            let c = [th[4], th[5], th[6]];
            let g = th[3] * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            heavy([th[0], th[1], th[2]], g, c)
        };
        let theta = [
            moments[0], moments[1], moments[2], mgl, chi[0], chi[1], chi[2],
        ];
        let fd = parameter_differences(build, theta, method, &z_ht, (0.05, 40), h);
        let worst = max_abs_diff(&pjac, &fd);
        eprintln!("HeavyTop {method}: parameter Jacobian vs differences {worst:.2e}");
        assert!(worst < 1e-7, "HeavyTop {method}: {worst:e}");
    }
    // The free body's RKMK4 (the lifted generator's ∂ξ/∂I).
    let t = RigidBody::new(moments).unwrap().tangent().unwrap();
    let (_, _, pjac) = lifted_end_all(&*t, "rkmk4", &z_rb, 0.05, 40);
    let free = |i: [f64; 3]| RigidBody::new(i).unwrap();
    let fd = parameter_differences(free, moments, "rkmk4", &z_rb, (0.05, 40), h);
    let worst = max_abs_diff(&pjac, &fd);
    eprintln!("RigidBody rkmk4: parameter Jacobian vs differences {worst:.2e}");
    assert!(worst < 1e-7, "RigidBody rkmk4: {worst:e}");
}

/// RKMK4 on the group-field lift (the derivative of each of its operations): the lifted run's
/// states are the plain run's bit for bit, and its Jacobian maps the Casimir's gradient
/// consistently (∇C(z)ᵀJ = ∇C(z₀)ᵀ for C = |M|²: the method keeps the orbit, so its derivative
/// keeps the orbit's tangent space) — over a long run with large steps (|u| up to 1.5).
#[test]
fn rkmk4_jacobian_keeps_the_orbit() {
    let rb = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let t = rb.tangent().unwrap();
    let z0 = vec![0.3, -0.8, 1.1];
    for (dt, steps) in [(0.05, 400), (0.5, 200)] {
        let (z, jac) = lifted_end(&*t, "rkmk4", &z0, dt, steps);
        let plain = integrate(&rb, "rkmk4", &z0, dt, steps, steps).unwrap();
        assert_eq!(z, plain.state(1), "dt = {dt}: base state");
        let g = |v: &[f64]| v.iter().map(|x| 2.0 * x).collect::<Vec<f64>>();
        let defect = casimir_defect(&jac, &[(g(&z0), g(&z))]);
        let scale = jac.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        eprintln!("rkmk4 dt = {dt}: Casimir gradient {defect:.2e} (|J| ≤ {scale:.1})");
        assert!(defect < 1e-13 * scale, "dt = {dt}: {defect:e}");
        let fd = differences(&rb, "rkmk4", &z0, dt, steps, 1e-6);
        let err = max_rel(&jac, &fd);
        eprintln!("rkmk4 dt = {dt}: Jacobian vs differences {err:.2e}");
        assert!(err < 1e-8, "dt = {dt}: {err:e}");
    }
}

/// With the attitude: the splittings' (and the free body's RKMK4) Jacobian in left-trivialised coordinates (δR = Rξ̂, the
/// initial attitude moved as R₀exp(hê_j), the final one read as (Rᵀ δR)^∨), against central
/// differences; also along the parameters.
#[test]
fn jacobians_with_the_attitude_left_trivialised() {
    use lieflow::lie::so3;
    use nalgebra::{Matrix3, Vector3};
    let rb = RigidBody::from_matrix(&[2.0, 0.3, -0.1, 0.3, 3.1, 0.2, -0.1, 0.2, 4.2])
        .unwrap()
        .with_attitude();
    let ht = HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0])
        .unwrap()
        .with_attitude();
    let r0 = so3::exp_unchecked(&Vector3::new(0.4, -0.7, 0.3));
    let rows = |r: &Matrix3<f64>| (0..9).map(|k| r[(k / 3, k % 3)]).collect::<Vec<f64>>();
    let cases: [(&dyn System, Vec<f64>); 2] = [
        (&rb, [vec![0.3, -0.8, 1.1], rows(&r0)].concat()),
        (&ht, {
            let g = r0.transpose() * Vector3::z();
            [vec![1.0, 0.5, -0.3], g.as_slice().to_vec(), rows(&r0)].concat()
        }),
    ];
    for (sys, z0) in cases {
        let t = sys.tangent().unwrap();
        let (d, e) = (t.base_dim(), t.tangent_dim());
        assert_eq!(d - e, 6);
        let mut methods = vec!["splitting", "splitting4"];
        if t.methods().iter().any(|(n, _)| *n == "rkmk4") {
            methods.push("rkmk4");
        }
        for method in methods {
            let (_, jac, _) = lifted_end_all(&*t, method, &z0, 0.05, 40);
            let h = 1e-6;
            let mut worst = 0.0f64;
            let heavy = e == 9;
            for j in 0..e {
                // The heavy top's Γ = Rᵀe₃ is a constraint of its state: no column along δΓ
                // alone, and a turn of R moves Γ with it (direction (0, −e_j × Γ₀, e_j)).
                if heavy && (3..6).contains(&j) {
                    continue;
                }
                let mut v = vec![0.0; e];
                v[j] = 1.0;
                if heavy && j >= 6 {
                    let g0 = Vector3::new(z0[3], z0[4], z0[5]);
                    let dg = -Vector3::ith(j - 6, 1.0).cross(&g0);
                    v[3..6].copy_from_slice(dg.as_slice());
                }
                let end = |s: f64| {
                    let mut z = z0.clone();
                    if j < e - 3 {
                        z[j] += s;
                    } else {
                        let mut w = Vector3::zeros();
                        w[j - (e - 3)] = s;
                        let r = r0 * so3::exp_unchecked(&w);
                        z[d - 9..].copy_from_slice(&rows(&r));
                        if heavy {
                            z[3..6].copy_from_slice((r.transpose() * Vector3::z()).as_slice());
                        }
                    }
                    integrate(sys, method, &z, 0.05, 40, 40)
                        .unwrap()
                        .state(1)
                        .to_vec()
                };
                let (p, q) = (end(h), end(-h));
                let rp = Matrix3::from_row_slice(&p[d - 9..]);
                let rq = Matrix3::from_row_slice(&q[d - 9..]);
                let a = (rp + rq) * 0.5;
                let xi = so3::vee_unchecked(&(a.transpose() * (rp - rq) / (2.0 * h)));
                for i in 0..e {
                    let fd = if i < e - 3 {
                        (p[i] - q[i]) / (2.0 * h)
                    } else {
                        xi[i - (e - 3)]
                    };
                    let jv: f64 = (0..e).map(|c| jac[i * e + c] * v[c]).sum();
                    worst = worst.max((jv - fd).abs());
                }
            }
            eprintln!(
                "{} with attitude {method}: Jacobian vs differences {worst:.2e}",
                sys.name()
            );
            assert!(worst < 1e-7, "{} {method}: {worst:e}", sys.name());
        }
        assert!(!t.methods().iter().any(|(n, _)| *n == "rk4"));
    }
}

/// The pseudo-rigid body's parameters are its potential's constants (λ, μ, κ, γ): ∂z/∂θ
/// against bodies rebuilt with a constant moved; free (Verlet) and incompressible (RATTLE, from
/// a state on T*{det X = det X₀}: P projected off cof X).
#[test]
fn parameter_jacobian_of_the_pseudo_rigid_body() {
    for (incompressible, method) in [(false, "verlet4"), (true, "rattle4")] {
        let build = |t: [f64; 4]| {
            let elastic = Arc::new(Sum::new(vec![
                Arc::new(SaintVenantKirchhoff::new(t[0], t[1]).unwrap()),
                Arc::new(Volumetric::polytropic(t[2], t[3]).unwrap()),
            ]));
            match incompressible {
                true => PseudoRigidBody::incompressible(3, elastic).unwrap(),
                false => PseudoRigidBody::new(3, elastic, true).unwrap(),
            }
        };
        let theta = [1.0, 2.0, 0.5, 1.4];
        let b = build(theta);
        let t = b.tangent().unwrap();
        assert_eq!(t.parameter_names(), ["lambda", "mu", "kappa", "gamma"]);
        let mut z0 = body_state();
        if incompressible {
            let x = nalgebra::Matrix3::from_row_slice(&z0[..9]);
            let cof = x.determinant() * x.try_inverse().unwrap().transpose();
            let c: Vec<f64> = (0..9).map(|k| cof[(k / 3, k % 3)]).collect();
            let along = (0..9).map(|k| c[k] * z0[9 + k]).sum::<f64>()
                / c.iter().map(|x| x * x).sum::<f64>();
            for k in 0..9 {
                z0[9 + k] -= along * c[k];
            }
        }
        let (_, _, pjac) = lifted_end_all(&*t, method, &z0, 0.05, 40);
        let fd = parameter_differences(build, theta, method, &z0, (0.05, 40), 1e-6);
        let worst = max_abs_diff(&pjac, &fd);
        eprintln!("PseudoRigidBody {method}: parameter Jacobian vs differences {worst:.2e}");
        assert!(worst < 1e-7, "{method}: {worst:e}");
    }
}

/// RATTLE's Jacobian (the constrained lift: constraints (g, G δq), force rows paired the other
/// way) is symplectic on the constrained phase space: for a basis B of T(T*{|q| = l}) at z₀,
/// BᵀJᵀΩJB = BᵀΩB to round-off; it maps B into the tangent space at the end (G δq = 0,
/// δ(q·p) = 0); and its base state is the plain run's.
#[test]
fn rattle_jacobian_is_symplectic_on_the_constraint_manifold() {
    use lieflow::systems::SphereParticle;
    let sys = SphereParticle::new(2.0, 1.5, 9.81).unwrap();
    let t = sys.tangent().unwrap();
    let z0 = [0.0, 0.9, 1.2, 0.4, 1.2, -0.9];
    let (z, jac) = lifted_end(&*t, "rattle", &z0, 0.02, 200);
    let plain = integrate(&sys, "rattle", &z0, 0.02, 200, 200).unwrap();
    // The base state is the plain run's up to the iteration's stopping (on the lifted update).
    let moved = max_rel(&z, plain.state(1));
    assert!(moved < 1e-12, "{moved:e}");
    // The tangent space at z: δq ⟂ q and p·δq + q·δp = 0; a basis by Gram–Schmidt of the
    // projections of the unit vectors.
    let basis = |z: &[f64]| -> Vec<Vec<f64>> {
        let rows = [
            [z[0], z[1], z[2], 0.0, 0.0, 0.0],
            [z[3], z[4], z[5], z[0], z[1], z[2]],
        ];
        let mut ortho: Vec<Vec<f64>> = Vec::new();
        for r in rows {
            let mut v = r.to_vec();
            for o in &ortho {
                let c: f64 = (0..6).map(|i| v[i] * o[i]).sum();
                (0..6).for_each(|i| v[i] -= c * o[i]);
            }
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            ortho.push(v.iter().map(|x| x / n).collect());
        }
        let mut out = Vec::new();
        for k in 0..6 {
            let mut v = [0.0; 6];
            v[k] = 1.0;
            for o in ortho.iter().chain(out.iter()) {
                let c: f64 = (0..6).map(|i| v[i] * o[i]).sum();
                (0..6).for_each(|i| v[i] -= c * o[i]);
            }
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n > 1e-6 {
                out.push(v.iter().map(|x| x / n).collect());
            }
        }
        assert_eq!(out.len(), 4);
        out
    };
    let b = basis(&z0);
    let apply = |v: &[f64]| -> Vec<f64> {
        (0..6)
            .map(|i| (0..6).map(|j| jac[i * 6 + j] * v[j]).sum())
            .collect()
    };
    let omega =
        |u: &[f64], v: &[f64]| -> f64 { (0..3).map(|i| u[i] * v[3 + i] - u[3 + i] * v[i]).sum() };
    let (mut sym, mut tangent) = (0.0f64, 0.0f64);
    for u in &b {
        let ju = apply(u);
        // Tangent at the end: both constraint derivatives vanish.
        let g1: f64 = (0..3).map(|i| z[i] * ju[i]).sum();
        let g2: f64 = (0..3).map(|i| z[3 + i] * ju[i] + z[i] * ju[3 + i]).sum();
        tangent = tangent.max(g1.abs()).max(g2.abs());
        for w in &b {
            sym = sym.max((omega(&ju, &apply(w)) - omega(u, w)).abs());
        }
    }
    eprintln!(
        "RATTLE on the sphere: |BᵀJᵀΩJB − BᵀΩB| {sym:.1e}, off the tangent space {tangent:.1e}, \
         base state moved {moved:.1e}"
    );
    assert!(sym < 1e-12 && tangent < 1e-12, "{sym:e} {tangent:e}");
}

/// Hénon–Heiles, U = (x² + y²)/2 + x²y − y³/3, as a user system with its Hessian.
fn henon_heiles() -> lieflow::systems::UserSeparable {
    use lieflow::systems::{KineticMass, UserSeparable};
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

/// |JᵀΩJ − Ω|_max for the canonical Ω of d/2 degrees of freedom.
fn symplecticity_defect(jac: &[f64], d: usize) -> f64 {
    let n = d / 2;
    let omega = |i: usize, j: usize| {
        if i < n && j == i + n {
            1.0
        } else if i >= n && i == j + n {
            -1.0
        } else {
            0.0
        }
    };
    let mut worst = 0.0f64;
    for a in 0..d {
        for c in 0..d {
            let mut s = 0.0;
            for i in 0..d {
                for k in 0..d {
                    s += jac[i * d + a] * omega(i, k) * jac[k * d + c];
                }
            }
            worst = worst.max((s - omega(a, c)).abs());
        }
    }
    worst
}

/// Issue 26: the implicit Gauss methods differentiate themselves through the implicit-function
/// theorem (the lifted Newton matrix factored on the base block only) — against differences of
/// the same method, symplectic to round-off (RK4, not symplectic, visibly is not); the Verlet
/// methods of the same lift (separable layout) too.
#[test]
fn gauss_and_verlet_jacobians_of_a_user_system_are_symplectic() {
    let sys = henon_heiles();
    let t = sys.tangent().expect("gradient and Hessian given");
    let z0 = [0.3, -0.2, 0.25, 0.31];
    let (dt, steps) = (0.1, 100);
    let names: Vec<_> = t.methods().into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        sys.methods()
            .into_iter()
            .map(|(n, _)| n)
            .collect::<Vec<_>>()
    );
    for method in names {
        let (z, jac) = lifted_end(&*t, method, &z0, dt, steps);
        let plain = integrate(&sys, method, &z0, dt, steps, steps).unwrap();
        let moved = max_rel(&z, plain.state(1));
        assert!(moved < 1e-14, "{method}: the base state moved by {moved:e}");
        let fd = differences(&sys, method, &z0, dt, steps, 1e-5);
        let err = max_rel(&jac, &fd);
        let defect = symplecticity_defect(&jac, 4);
        eprintln!("{method}: vs differences {err:.1e}, |JᵀΩJ − Ω| {defect:.1e}");
        assert!(err < 1e-8, "{method}: {err:e}");
        if method == "rk4" {
            assert!(defect > 1e-8, "rk4 is not symplectic: {defect:e}");
        } else {
            assert!(defect < 1e-12, "{method}: {defect:e}");
        }
    }
}

/// The same Hénon–Heiles as a general canonical system (H and its derivatives as closures): its
/// field lift gives the Gauss and RK4 Jacobians of the separable system's lift (another layout,
/// another kind of user system), to round-off.
#[test]
fn a_user_canonical_system_lifts_as_its_separable_twin() {
    use lieflow::systems::UserCanonical;
    let h = Arc::new(|q: &[f64], p: &[f64]| -> lieflow::Result<f64> {
        let (x, y) = (q[0], q[1]);
        Ok(0.5 * (p[0] * p[0] + p[1] * p[1] + x * x + y * y) + x * x * y - y * y * y / 3.0)
    });
    let g = Arc::new(
        |q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]| -> lieflow::Result<()> {
            let (x, y) = (q[0], q[1]);
            hq[0] = x + 2.0 * x * y;
            hq[1] = y + x * x - y * y;
            hp.copy_from_slice(p);
            Ok(())
        },
    );
    let hess = Arc::new(
        |q: &[f64], _p: &[f64], dq: &[f64], dp: &[f64], hq: &mut [f64], hp: &mut [f64]| {
            let (x, y) = (q[0], q[1]);
            hq[0] = (1.0 + 2.0 * y) * dq[0] + 2.0 * x * dq[1];
            hq[1] = 2.0 * x * dq[0] + (1.0 - 2.0 * y) * dq[1];
            hp.copy_from_slice(dp);
            Ok(())
        },
    );
    let canonical = UserCanonical::new(2, h.clone(), Some(g.clone())).unwrap();
    assert!(canonical.tangent().is_none(), "no Hessian, no lift");
    let canonical = canonical.with_hessian(hess);
    let t = canonical.tangent().unwrap();
    let twin = henon_heiles().tangent().unwrap();
    let z0 = [0.3, -0.2, 0.25, 0.31];
    for method in ["gauss4", "gauss6", "midpoint", "rk4"] {
        let (z, jac) = lifted_end(&*t, method, &z0, 0.1, 100);
        let (z2, jac2) = lifted_end(&*twin, method, &z0, 0.1, 100);
        let (dz, dj) = (max_rel(&z, &z2), max_rel(&jac, &jac2));
        eprintln!("{method}: states {dz:.1e}, Jacobians {dj:.1e}");
        assert!(dz < 1e-13 && dj < 1e-12, "{method}: {dz:e} {dj:e}");
    }
    // A Hessian closure that returns NaN stops the run with a typed error.
    let nan = Arc::new(
        |_: &[f64], _: &[f64], _: &[f64], _: &[f64], hq: &mut [f64], _: &mut [f64]| {
            hq.fill(f64::NAN);
            Ok(())
        },
    );
    let bad = UserCanonical::new(2, h, Some(g)).unwrap().with_hessian(nan);
    let t = bad.tangent().unwrap();
    let err = integrate(&*t, "gauss4", &t.seed(&z0).unwrap(), 0.1, 5, 5).unwrap_err();
    assert!(err.to_string().contains("Hessian"), "{err}");
}

/// The end state of `steps` steps of `method` from any z (user frame) through the method's
/// stepper: its map also off the constraints a run checks (|q| = 1, Q symmetric), which the
/// lift differentiates across.
fn stepped(sys: &dyn System, method: &str, z0: &[f64], dt: f64, steps: usize) -> Vec<f64> {
    let (mut st, _) = sys.stepper(method, dt).unwrap();
    let mut z = z0.to_vec();
    sys.to_internal(&mut z);
    st.set(&z).unwrap();
    st.advance(
        steps,
        Clock {
            t0: 0.0,
            dt,
            done: 0,
        },
    )
    .unwrap();
    st.get(&mut z);
    sys.to_user(&mut z);
    z
}

/// [`differences`] through [`stepped`].
fn stepped_differences(
    sys: &dyn System,
    method: &str,
    z0: &[f64],
    dt: f64,
    steps: usize,
    h: f64,
) -> Vec<f64> {
    let d = z0.len();
    let mut jac = vec![0.0; d * d];
    for j in 0..d {
        let hj = h * z0[j].abs().max(1.0);
        let end = |s: f64| {
            let mut z = z0.to_vec();
            z[j] += s;
            stepped(sys, method, &z, dt, steps)
        };
        let (p, m) = (end(hj), end(-hj));
        for i in 0..d {
            jac[i * d + j] = (p[i] - m[i]) / (2.0 * hj);
        }
    }
    jac
}

/// max |∇C(z)ᵀJ − ∇C(z₀)ᵀ| over the gradients (∇C(z₀), ∇C(z)) of some invariants.
fn casimir_defect(jac: &[f64], grads: &[(Vec<f64>, Vec<f64>)]) -> f64 {
    let d = grads[0].0.len();
    let mut worst = 0.0f64;
    for (g0, g1) in grads {
        for j in 0..d {
            let s: f64 = (0..d).map(|i| g1[i] * jac[i * d + j]).sum();
            worst = worst.max((s - g0[j]).abs());
        }
    }
    worst
}

/// max |J B(z₀) Jᵀ − B(z)| for a Poisson tensor B.
fn poisson_defect(jac: &[f64], b0: &[f64], b1: &[f64]) -> f64 {
    let d = (b0.len() as f64).sqrt() as usize;
    let mut worst = 0.0f64;
    for i in 0..d {
        for k in 0..d {
            let mut s = 0.0;
            for a in 0..d {
                for c in 0..d {
                    s += jac[i * d + a] * b0[a * d + c] * jac[k * d + c];
                }
            }
            worst = worst.max((s - b1[i * d + k]).abs());
        }
    }
    worst
}

/// The spherical pendulum (q, L) on e(3)*: every method's Jacobian against differences of its
/// map (off the sphere too: both flows and the field are defined on R⁶); for the splittings,
/// ∇C(z)ᵀJ = ∇C(z₀)ᵀ for the Casimirs |q|², q·L (their flows keep both on all of R⁶) and
/// J B(z₀) Jᵀ = B(z) for the Lie–Poisson tensor B = [[0, q̂], [q̂, L̂]] (each flow is the exact
/// flow of a piece of H: a Poisson map), to round-off.
#[test]
fn spherical_pendulum_jacobians_keep_the_casimirs_and_the_bracket() {
    let pend = SphericalPendulum::new(2.0, 1.5, 9.81).unwrap();
    let z0 = pend.state_from_spherical(0.8, 0.1, 0.3, 1.2).unwrap();
    let t = pend.tangent().expect("a lift");
    let names: Vec<_> = t.methods().iter().map(|(n, _)| *n).collect();
    assert_eq!(names, ["splitting", "splitting4", "splitting6", "rk4"]);
    let (dt, steps) = (0.02, 100);
    let tensor = |z: &[f64]| {
        let (q, l) = (hat(&z[..3]), hat(&z[3..]));
        let mut b = vec![0.0; 36];
        for i in 0..3 {
            for j in 0..3 {
                b[i * 6 + j + 3] = q[i][j];
                b[(i + 3) * 6 + j] = q[i][j];
                b[(i + 3) * 6 + j + 3] = l[i][j];
            }
        }
        b
    };
    let grads = |z: &[f64]| {
        (
            [z[..3].iter().map(|x| 2.0 * x).collect(), vec![0.0; 3]].concat(),
            [z[3..].to_vec(), z[..3].to_vec()].concat(),
        )
    };
    for method in names {
        let (z, jac) = lifted_end(&*t, method, &z0, dt, steps);
        let plain = integrate(&pend, method, &z0, dt, steps, steps).unwrap();
        assert!(max_rel(&z, plain.state(1)) < 1e-14, "{method}: base state");
        let fd = stepped_differences(&pend, method, &z0, dt, steps, 1e-5);
        let err = max_rel(&jac, &fd);
        eprintln!("SphericalPendulum {method}: Jacobian vs differences {err:.2e}");
        assert!(err < 1e-8, "{method}: {err:e}");
        if method == "rk4" {
            continue;
        }
        let ((a0, b0), (a1, b1)) = (grads(&z0), grads(&z));
        let cas = casimir_defect(&jac, &[(a0, a1), (b0, b1)]);
        let poisson = poisson_defect(&jac, &tensor(&z0), &tensor(&z));
        eprintln!(
            "SphericalPendulum {method}: Casimir gradients {cas:.2e}, J B Jᵀ − B {poisson:.2e}"
        );
        assert!(cas < 1e-12, "{method}: {cas:e}");
        assert!(poisson < 1e-12, "{method}: {poisson:e}");
    }
}

/// ∂z/∂θ of the spherical pendulum along (mass, length, g), against pendulums rebuilt with a
/// constant moved.
#[test]
fn parameter_jacobian_of_the_spherical_pendulum() {
    let theta = [2.0, 1.5, 9.81];
    let build = |t: [f64; 3]| SphericalPendulum::new(t[0], t[1], t[2]).unwrap();
    let pend = build(theta);
    let z0 = pend.state_from_spherical(0.8, 0.1, 0.3, 1.2).unwrap();
    let t = pend.tangent().unwrap();
    assert_eq!(t.parameter_names(), ["mass", "length", "g"]);
    for method in ["splitting", "splitting6", "rk4"] {
        let (_, _, pjac) = lifted_end_all(&*t, method, &z0, 0.02, 100);
        let fd = parameter_differences(build, theta, method, &z0, (0.02, 100), 1e-6);
        let worst = max_abs_diff(&pjac, &fd);
        eprintln!("SphericalPendulum {method}: parameter Jacobian vs differences {worst:.2e}");
        assert!(worst < 1e-7, "{method}: {worst:e}");
    }
}

/// The generalized rigid body on so(n)*: rk4's Jacobian (the only method of its lift) against
/// differences, with J given as a matrix (the principal frame is the lift's chart), n = 3, 4, 5.
#[test]
fn rk4_jacobian_of_the_generalized_rigid_body() {
    for n in 3..=5 {
        let j = lieflow::Mat::from_fn(n, n, |a, b| {
            if a == b {
                1.0 + 0.7 * a as f64
            } else {
                0.1 / (1.0 + (a + b) as f64)
            }
        });
        let body = GeneralizedRigidBody::from_matrix(&j).unwrap();
        let t = body.tangent().expect("a lift");
        let names: Vec<_> = t.methods().iter().map(|(n, _)| *n).collect();
        assert_eq!(names, ["rk4"]);
        assert!(t.parameter_names().is_empty());
        let z0: Vec<f64> = (0..n * (n - 1) / 2)
            .map(|k| (0.9 * k as f64 + 0.3).sin())
            .collect();
        let (z, jac) = lifted_end(&*t, "rk4", &z0, 0.02, 100);
        let plain = integrate(&body, "rk4", &z0, 0.02, 100, 100).unwrap();
        assert!(max_rel(&z, plain.state(1)) < 1e-14);
        let fd = differences(&body, "rk4", &z0, 0.02, 100, 1e-5);
        let err = max_rel(&jac, &fd);
        eprintln!("GeneralizedRigidBody so({n}) rk4: Jacobian vs differences {err:.2e}");
        assert!(err < 1e-8, "so({n}): {err:e}");
    }
}

/// The right-reduced pseudo-rigid body (Q, N[, X]): every method's Jacobian against differences
/// of its map (ambient directions, Q moved off the symmetric matrices too), with and without
/// the reconstruction of X; the reduced Verlet steps keep L = Nᵀ − N (U left-invariant: CGᵀ is
/// symmetric), so ∇C(z)ᵀJ = ∇C(z₀)ᵀ for C = ½|L|², ∇_N C = −2L; and ∂z/∂θ along the
/// potential's constants against bodies rebuilt with one moved.
#[test]
fn jacobians_of_the_right_reduced_body() {
    use lieflow::pseudo_rigid::RightReduced;
    let build = |t: [f64; 4]| {
        RightReduced::new(
            3,
            Arc::new(Sum::new(vec![
                Arc::new(SaintVenantKirchhoff::new(t[0], t[1]).unwrap()),
                Arc::new(Volumetric::polytropic(t[2], t[3]).unwrap()),
            ])),
        )
        .unwrap()
    };
    let theta = [1.0, 2.0, 0.5, 1.4];
    let full = body_state();
    let x = lieflow::Mat::from_fn(3, 3, |i, j| full[3 * i + j]);
    let p = lieflow::Mat::from_fn(3, 3, |i, j| full[9 + 3 * i + j]);
    let (dt, steps) = (0.05, 40);
    for reconstruct in [false, true] {
        let sys = match reconstruct {
            false => build(theta),
            true => build(theta).reconstructing(),
        };
        let z0 = sys.reduce(&x, &p).unwrap();
        let d = z0.len();
        let t = sys.tangent().expect("a lift");
        assert_eq!(t.parameter_names(), ["lambda", "mu", "kappa", "gamma"]);
        for method in ["verlet", "verlet4", "verlet6", "rk4"] {
            let (z, jac, pjac) = lifted_end_all(&*t, method, &z0, dt, steps);
            let plain = integrate(&sys, method, &z0, dt, steps, steps).unwrap();
            assert!(max_rel(&z, plain.state(1)) < 1e-14, "{method}: base state");
            let fd = stepped_differences(&sys, method, &z0, dt, steps, 1e-5);
            let err = max_rel(&jac, &fd);
            eprintln!(
                "RightReduced (X: {reconstruct}) {method}: Jacobian vs differences {err:.2e}"
            );
            assert!(err < 1e-8, "{method}: {err:e}");
            let rebuild = |th: [f64; 4]| match reconstruct {
                false => build(th),
                true => build(th).reconstructing(),
            };
            let fd = parameter_differences(rebuild, theta, method, &z0, (dt, steps), 1e-6);
            let worst = max_abs_diff(&pjac, &fd);
            eprintln!("RightReduced (X: {reconstruct}) {method}: parameter Jacobian {worst:.2e}");
            assert!(worst < 1e-7, "{method}: {worst:e}");
            if method == "rk4" {
                continue;
            }
            let grad = |z: &[f64]| {
                let mut g = vec![0.0; d];
                for i in 0..3 {
                    for j in 0..3 {
                        g[9 + 3 * i + j] = -2.0 * (z[9 + 3 * j + i] - z[9 + 3 * i + j]);
                    }
                }
                g
            };
            let cas = casimir_defect(&jac, &[(grad(&z0), grad(&z))]);
            eprintln!("RightReduced (X: {reconstruct}) {method}: ∇½|L|² defect {cas:.2e}");
            assert!(cas < 1e-12, "{method}: {cas:e}");
        }
    }
}

/// The nonholonomic lift (constraint rows Ã = \[\[A, 0\], \[DA\[δq\], A\]\], force rows paired
/// the other way) on the rolling disk with a spring and a tilt: the lifted run's base state is
/// the plain run's; its Jacobian is the derivative of the method's map (central differences
/// through the stepper, off the rolling constraint too) and its parameter Jacobian that of
/// disks rebuilt with k or g̃ moved; and J maps every direction into the tangent space of the
/// constrained phase space {A(q)M⁻¹p = 0} at the end (DA\[δq\]v + A δv = 0), in particular the
/// directions tangent to it at the start.
#[test]
fn nonholonomic_jacobian_of_the_rolling_disk() {
    use lieflow::systems::RollingDisk;
    let (mass, radius, roll, turn) = (1.0, 0.5, 0.125, 0.0625);
    let theta = [0.4, 0.3];
    let build = |th: [f64; 2]| {
        RollingDisk::new(mass, radius, roll, turn)
            .unwrap()
            .with_potential(th[0], th[1])
            .unwrap()
    };
    let disk = build(theta);
    let z0 = disk.state([0.1, -0.2, 0.3, 0.7], 2.0, 0.5).unwrap();
    let t = disk.tangent().unwrap();
    assert_eq!(t.parameter_names(), ["spring", "tilt"]);
    let (dt, steps) = (0.01, 200);
    let (z, jac, pjac) = lifted_end_all(&*t, "nonholonomic", &z0, dt, steps);
    let plain = integrate(&disk, "nonholonomic", &z0, dt, steps, steps).unwrap();
    let moved = max_rel(&z, plain.state(1));
    let fd = stepped_differences(&disk, "nonholonomic", &z0, dt, steps, 1e-6);
    let err = max_rel(&jac, &fd);
    // h = 1e-5: the end state's round-off (~1e-14, the multiplier iteration stopping at
    // round-off) over 2h stays below the O(h²) truncation (1e-6 gave 1.3e-8 along g̃, 1e-7
    // 4.3e-8, the lifted value the same).
    let pfd = parameter_differences(build, theta, "nonholonomic", &z0, (dt, steps), 1e-5);
    let perr = max_abs_diff(&pjac, &pfd);
    // The linearised constraint at a state: L(z)(δq, δp) = DA(q)[δq]M⁻¹p + A(q)M⁻¹δp (2 × 8).
    let linearised = |z: &[f64]| -> [[f64; 8]; 2] {
        let (s, c) = z[3].sin_cos();
        let wt = z[6] / roll;
        [
            [
                0.0,
                0.0,
                0.0,
                radius * s * wt,
                1.0 / mass,
                0.0,
                -radius * c / roll,
                0.0,
            ],
            [
                0.0,
                0.0,
                0.0,
                -radius * c * wt,
                0.0,
                1.0 / mass,
                -radius * s / roll,
                0.0,
            ],
        ]
    };
    // A basis of its kernel at z₀: the unit vectors projected off its rows and off each
    // other (Gram–Schmidt).
    let mut ortho: Vec<Vec<f64>> = Vec::new();
    let rows = linearised(&z0).map(|r| r.to_vec());
    let units = (0..8).map(|k| (0..8).map(|i| f64::from(u8::from(i == k))).collect());
    for (k, mut v) in rows.into_iter().chain(units).enumerate() {
        for o in &ortho {
            let c: f64 = (0..8).map(|i| v[i] * o[i]).sum::<f64>();
            (0..8).for_each(|i| v[i] -= c * o[i]);
        }
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if k < 2 || n > 1e-6 {
            ortho.push(v.iter().map(|x| x / n).collect());
        }
    }
    let basis = &ortho[2..];
    assert_eq!(basis.len(), 6);
    let l1 = linearised(&z);
    let jscale = jac.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let apply = |v: &[f64]| -> Vec<f64> {
        (0..8)
            .map(|i| (0..8).map(|j| jac[i * 8 + j] * v[j]).sum())
            .collect()
    };
    let defect = |dz: &[f64]| -> f64 {
        l1.iter()
            .map(|row| (0..8).map(|i| row[i] * dz[i]).sum::<f64>().abs())
            .fold(0.0, f64::max)
    };
    let tangent = basis.iter().map(|b| defect(&apply(b))).fold(0.0, f64::max) / jscale;
    let every = (0..8)
        .map(|j| defect(&(0..8).map(|i| jac[i * 8 + j]).collect::<Vec<_>>()))
        .fold(0.0, f64::max)
        / jscale;
    eprintln!(
        "RollingDisk nonholonomic: base state moved {moved:.1e}, Jacobian vs differences \
         {err:.1e}, parameter Jacobian {perr:.1e}, linearised constraint at the end {tangent:.1e} \
         (tangent directions), {every:.1e} (every direction)"
    );
    assert!(moved < 1e-13, "{moved:e}");
    assert!(err < 1e-7 && perr < 1e-7, "{err:e} {perr:e}");
    assert!(tangent < 1e-13 && every < 1e-13, "{tangent:e} {every:e}");
}

/// The incompressible body's closed-form D²det(X)\[U, ·\] (what its RATTLE lift uses) is the
/// polarisation of its curvature form D²det(X)\[W, W\].
#[test]
fn the_incompressible_bodys_second_derivative_is_its_curvatures_polarisation() {
    use lieflow::integrate::problem::{Constrained, Separable};
    let inc =
        PseudoRigidBody::incompressible(3, Arc::new(SaintVenantKirchhoff::new(1.0, 2.0).unwrap()))
            .unwrap();
    let mut s = inc.scratch();
    let x = [1.3, 0.1, -0.05, 0.02, 1.1, 0.08, -0.03, 0.05, 0.9];
    let u = [0.3, -0.2, 0.5, 0.1, 0.7, -0.4, 0.2, 0.6, -0.1];
    let mut rows = [0.0; 9];
    assert!(inc.constraint_second(&x, &u, &mut rows, &mut s));
    let (mut cp, mut cm) = ([0.0], [0.0]);
    for k in 0..9 {
        let (mut wp, mut wm) = (u, u);
        wp[k] += 1.0;
        wm[k] -= 1.0;
        inc.constraint_curvature(&x, &wp, &mut cp, &mut s);
        inc.constraint_curvature(&x, &wm, &mut cm, &mut s);
        let polar = 0.25 * (cp[0] - cm[0]);
        assert!(
            (rows[k] - polar).abs() < 1e-14,
            "{k}: {} vs {polar}",
            rows[k]
        );
    }
}

/// The orbits of the exact method's tangent tests (I = (1, 2, 3), periods 10.9, 18.9, 50, 50,
/// 16.7): near the axis of the least moment and near that of the largest (both sides of the
/// separatrix), close to the separatrix on either side (k′ ≈ 0.025), and a generic one.
fn exact_orbits() -> Vec<(&'static str, Vec<f64>)> {
    vec![
        ("near e1", vec![1.0, 0.15, -0.1]),
        ("near e3", vec![0.1, -0.2, 1.0]),
        ("separatrix, e1 side", vec![0.5, 1.0, 0.8655]),
        ("separatrix, e3 side", vec![0.5, -1.0, 0.8665]),
        ("generic", vec![0.3, -0.8, 1.1]),
    ]
}

/// A double-double number (hi + lo, |lo| ≤ ulp(hi)/2): + and × to ~1e-32 (Dekker, Knuth;
/// products by fma), enough for a reference solution of the variational equations whose
/// round-off, amplified by |J| ~ 1e3 near the separatrix over thousands of steps, would reach
/// 1e-11 in f64.
#[derive(Clone, Copy, Debug)]
struct Dd(f64, f64);

impl Dd {
    fn quick(s: f64, e: f64) -> Dd {
        let h = s + e;
        Dd(h, e - (h - s))
    }
    fn two_sum(a: f64, b: f64) -> (f64, f64) {
        let s = a + b;
        let bb = s - a;
        (s, (a - (s - bb)) + (b - bb))
    }
    fn recip(x: f64) -> Dd {
        let q = 1.0 / x;
        let r = (-q).mul_add(x, 1.0);
        Dd::quick(q, r / x)
    }
}

impl std::ops::Add for Dd {
    type Output = Dd;
    fn add(self, y: Dd) -> Dd {
        let (s, e) = Dd::two_sum(self.0, y.0);
        let (t, f) = Dd::two_sum(self.1, y.1);
        let Dd(s, e) = Dd::quick(s, e + t);
        Dd::quick(s, e + f)
    }
}

impl std::ops::Sub for Dd {
    type Output = Dd;
    fn sub(self, y: Dd) -> Dd {
        self + Dd(-y.0, -y.1)
    }
}

impl std::ops::Mul for Dd {
    type Output = Dd;
    fn mul(self, y: Dd) -> Dd {
        let p = self.0 * y.0;
        let e = self.0.mul_add(y.0, -p) + (self.0 * y.1 + self.1 * y.0);
        Dd::quick(p, e)
    }
}

fn dd_cross(a: &[Dd], b: &[Dd]) -> [Dd; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The free body's variational equations in double-double: M, the directions δM_j (j < 3) and
/// ∂M/∂I_q, Ṁ = M × Ω, δṀ = δM × Ω + M × I⁻¹δM (+ M × ∂Ω/∂I_q, ∂Ω = −M_q/I_q² e_q), by RK4
/// with `n` steps of `time`/n: (M, J row-major, ∂M/∂I row-major).
fn variational_dd(moments: [f64; 3], m0: &[f64], time: f64, n: usize) -> [Vec<f64>; 3] {
    let inv = moments.map(Dd::recip);
    let field = |y: &[Dd; 21]| -> [Dd; 21] {
        let m = &y[..3];
        let w: Vec<Dd> = (0..3).map(|i| m[i] * inv[i]).collect();
        let mut out = [Dd(0.0, 0.0); 21];
        out[..3].copy_from_slice(&dd_cross(m, &w));
        for j in 0..6 {
            let d = &y[3 + 3 * j..6 + 3 * j];
            let dw: Vec<Dd> = (0..3).map(|i| d[i] * inv[i]).collect();
            let (a, b) = (dd_cross(d, &w), dd_cross(m, &dw));
            let mut v = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
            if j >= 3 {
                let q = j - 3;
                let mut dq = [Dd(0.0, 0.0); 3];
                dq[q] = Dd(0.0, 0.0) - m[q] * inv[q] * inv[q];
                let c = dd_cross(m, &dq);
                v = [v[0] + c[0], v[1] + c[1], v[2] + c[2]];
            }
            out[3 + 3 * j..6 + 3 * j].copy_from_slice(&v);
        }
        out
    };
    let mut y = [Dd(0.0, 0.0); 21];
    for i in 0..3 {
        y[i] = Dd(m0[i], 0.0);
        y[3 + 4 * i] = Dd(1.0, 0.0);
    }
    let h = Dd(time / n as f64, 0.0);
    assert_eq!(time / n as f64 * n as f64, time, "an exact step");
    let (half, sixth) = (Dd(0.5, 0.0) * h, h * Dd::recip(6.0));
    let two = Dd(2.0, 0.0);
    let axpy = |y: &[Dd; 21], a: Dd, k: &[Dd; 21]| -> [Dd; 21] {
        std::array::from_fn(|i| y[i] + a * k[i])
    };
    for _ in 0..n {
        let k1 = field(&y);
        let k2 = field(&axpy(&y, half, &k1));
        let k3 = field(&axpy(&y, half, &k2));
        let k4 = field(&axpy(&y, h, &k3));
        y = std::array::from_fn(|i| y[i] + sixth * (k1[i] + two * (k2[i] + k3[i]) + k4[i]));
    }
    let at = |i: usize| y[i].0 + y[i].1;
    [
        (0..3).map(at).collect(),
        // Row i, column j: component i of direction j.
        (0..9).map(|k| at(3 + 3 * (k % 3) + k / 3)).collect(),
        (0..9).map(|k| at(12 + 3 * (k % 3) + k / 3)).collect(),
    ]
}

/// The exact flow's Jacobian (and its parameter Jacobian along I₁, I₂, I₃) against the
/// variational equations of the continuous flow over t = 60 (3 to 5 periods of the orbits near
/// the axes, more than one near the separatrix): integrated in double-double by RK4 with steps
/// 2⁻⁸, 2⁻⁹, 2⁻¹⁰ and Romberg-extrapolated (error below 1e-15 relative), and by the library's
/// own rk4 lift (f64, also Romberg-extrapolated), whose round-off, amplified by the conditioning
/// of the motion (|J| up to 800), allows 1e-12 only away from the separatrix. To 1e-12
/// relative to max |J|; closer to the separatrix (k′ = 5e-3, 7e-4) reported.
#[test]
fn exact_jacobian_is_the_variational_equations() {
    let moments = [1.0, 2.0, 3.0];
    let rb = RigidBody::new(moments).unwrap();
    let t = rb.tangent().unwrap();
    let time = 60.0;
    let mut worst = 0.0f64;
    let mut orbits = exact_orbits();
    orbits.push(("k′ 5e-3", vec![0.5, 1.0, 0.866]));
    orbits.push(("k′ 7e-4", vec![0.5, 1.0, 0.866025]));
    let rich = |a: &[f64], b: &[f64], f: f64| -> Vec<f64> {
        a.iter()
            .zip(b)
            .map(|(x, y)| (f * y - x) / (f - 1.0))
            .collect()
    };
    let romberg = |[a, b, c]: [&Vec<f64>; 3]| {
        let (r1, r2) = (rich(a, b, 16.0), rich(b, c, 16.0));
        (rich(&r1, &r2, 64.0), max_rel(&r1, &r2))
    };
    for (name, z0) in orbits {
        let (z, jac, pjac) = lifted_end_all(&*t, "exact", &z0, time, 1);
        let plain = integrate(&rb, "exact", &z0, time, 1, 1).unwrap();
        assert_eq!(
            z,
            plain.state(1),
            "{name}: the base state is the plain run's"
        );
        // Double-double.
        let dd = [15_360, 30_720, 61_440].map(|n| variational_dd(moments, &z0, time, n));
        let pick = |k: usize| [&dd[0][k], &dd[1][k], &dd[2][k]];
        let ((zr, _), (jr, conv), (pr, _)) = (romberg(pick(0)), romberg(pick(1)), romberg(pick(2)));
        let (ez, ej, ep) = (max_rel(&z, &zr), max_rel(&jac, &jr), max_rel(&pjac, &pr));
        let scale = jr.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        // The library's rk4 lift, steps 60/15000 and halves.
        let rk =
            [15_000, 30_000, 60_000].map(|n| lifted_end_all(&*t, "rk4", &z0, time / n as f64, n));
        let (jrk, _) = romberg([&rk[0].1, &rk[1].1, &rk[2].1]);
        let (prk, _) = romberg([&rk[0].2, &rk[1].2, &rk[2].2]);
        let (erk, eprk) = (max_rel(&jac, &jrk), max_rel(&pjac, &prk));
        eprintln!(
            "exact, {name}: |J| {scale:.1}, vs the variational equations (double-double): M \
             {ez:.1e}, J {ej:.1e}, ∂M/∂I {ep:.1e} (last Romberg correction {conv:.0e}); vs the \
             rk4 lift: J {erk:.1e}, ∂M/∂I {eprk:.1e}"
        );
        if name.starts_with("k′") {
            continue;
        }
        worst = worst.max(ez).max(ej).max(ep);
        if !name.starts_with("separatrix") {
            assert!(
                erk.max(eprk) < 1e-12,
                "{name}: vs the rk4 lift {erk:e} {eprk:e}"
            );
        }
    }
    assert!(worst < 1e-12, "{worst:e}");
}

/// The exact method's lifted Jacobian against central differences of the method itself (in M₀
/// and in the moments), also over many steps of a run and for an inertia given as a matrix.
#[test]
fn exact_jacobian_against_differences() {
    let moments = [1.0, 2.0, 3.0];
    let h = 1e-6;
    let mut worst = (0.0f64, 0.0f64);
    for (name, z0) in exact_orbits() {
        for (dt, steps) in [(7.0, 1), (0.1, 137)] {
            let rb = RigidBody::new(moments).unwrap();
            let t = rb.tangent().unwrap();
            let (_, jac, pjac) = lifted_end_all(&*t, "exact", &z0, dt, steps);
            let fd = differences(&rb, "exact", &z0, dt, steps, h);
            let ej = max_rel(&jac, &fd);
            let free = |i: [f64; 3]| RigidBody::new(i).unwrap();
            let pfd = parameter_differences(free, moments, "exact", &z0, (dt, steps), h);
            let ep = max_rel(&pjac, &pfd);
            eprintln!("exact, {name}, {steps} steps: vs differences J {ej:.1e}, ∂M/∂I {ep:.1e}");
            worst = (worst.0.max(ej), worst.1.max(ep));
        }
    }
    // A body given by its inertia matrix: the chart turns the directions as the states.
    let rb = RigidBody::from_matrix(&[2.0, 0.3, -0.1, 0.3, 3.1, 0.2, -0.1, 0.2, 4.2]).unwrap();
    let z0 = [0.4, -0.7, 1.2];
    let (_, jac) = lifted_end(&*rb.tangent().unwrap(), "exact", &z0, 0.2, 50);
    let ej = max_rel(&jac, &differences(&rb, "exact", &z0, 0.2, 50, h));
    eprintln!("exact, inertia matrix: vs differences {ej:.1e}");
    assert!(worst.0.max(worst.1).max(ej) < 1e-8, "{worst:?} {ej:e}");
    // A symmetric body (closed form): along I₁ or I₂ alone the symmetry breaks, and the
    // differences run the elliptic flow of the nearby asymmetric bodies.
    let moments = [2.0, 2.0, 1.0];
    let rb = RigidBody::new(moments).unwrap();
    let z0 = [0.3, -0.8, 1.1];
    let (_, jac, pjac) = lifted_end_all(&*rb.tangent().unwrap(), "exact", &z0, 3.0, 4);
    let ej = max_rel(&jac, &differences(&rb, "exact", &z0, 3.0, 4, h));
    let free = |i: [f64; 3]| RigidBody::new(i).unwrap();
    let pfd = parameter_differences(free, moments, "exact", &z0, (3.0, 4), h);
    let ep = max_rel(&pjac, &pfd);
    eprintln!("exact, symmetric body: vs differences J {ej:.1e}, ∂M/∂I {ep:.1e}");
    assert!(ej.max(ep) < 1e-8, "{ej:e} {ep:e}");
}

/// The exact Jacobian keeps the invariants' gradients: ∇C(M)ᵀJ = ∇C(M₀)ᵀ for C = ½|M|² and
/// H = ½M·I⁻¹M, and along the moments ∇C(M)·∂M/∂I_q = 0, ∇H(M)·∂M/∂I_q + ∂H/∂I_q (M) =
/// ∂H/∂I_q (M₀) (H(M(t); I) = H(M₀; I) for every I), to round-off (1e-14 relative to |J|;
/// near the separatrix, k′ = 0.025, to ε/k′²: 1.3e-13 measured at t = 0.5).
#[test]
fn exact_jacobian_keeps_the_invariants_gradients() {
    let moments = [1.0, 2.0, 3.0];
    let rb = RigidBody::new(moments).unwrap();
    let t = rb.tangent().unwrap();
    let mut worst = 0.0f64;
    for (name, z0) in exact_orbits() {
        for time in [0.5, 9.0, 60.0] {
            let (z, jac, pjac) = lifted_end_all(&*t, "exact", &z0, time, 1);
            let scale = jac.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let omega = |m: &[f64]| [m[0] / moments[0], m[1] / moments[1], m[2] / moments[2]];
            let (w0, w) = (omega(&z0), omega(&z));
            let mut defect = 0.0f64;
            for j in 0..3 {
                let c: f64 = (0..3).map(|i| z[i] * jac[i * 3 + j]).sum();
                let e: f64 = (0..3).map(|i| w[i] * jac[i * 3 + j]).sum();
                defect = defect.max((c - z0[j]).abs()).max((e - w0[j]).abs());
                let dh = |m: &[f64]| -0.5 * m[j] * m[j] / (moments[j] * moments[j]);
                let cp: f64 = (0..3).map(|i| z[i] * pjac[i * 3 + j]).sum();
                let ep: f64 = (0..3).map(|i| w[i] * pjac[i * 3 + j]).sum::<f64>() + dh(&z);
                defect = defect.max(cp.abs()).max((ep - dh(&z0)).abs());
            }
            let rel = defect / scale;
            eprintln!("exact, {name}, t = {time}: |J| {scale:.1}, invariants' gradients {rel:.1e}");
            // Near the separatrix the m-derivative's 1/k′² cancels (module docs of
            // `methods::exact`): ε/k′² ≈ 3.5e-13 at k′ = 0.025.
            let bound = if name.starts_with("separatrix") {
                3.5e-13
            } else {
                1e-14
            };
            assert!(rel < bound, "{name}, t = {time}: {rel:e}");
            worst = worst.max(rel);
        }
    }
    eprintln!("worst {worst:.1e}");
}

// ---- Issue 26: the canonical systems of 002 and 003 through CanonicalTangent (the tangent
// Euler top, its charged particle, the rolling disks). ----

/// The tangent tops of these tests: (name, top) on the sphere, intrinsic and embedded
/// anisotropic, on the hyperbolic plane, on a torus (intrinsic), embedded in the plane.
fn tangent_tops() -> Vec<(&'static str, lieflow::systems::TangentTop)> {
    use lieflow::systems::{HyperbolicPlane, Plane, Revolution, Sphere, TangentTop};
    vec![
        (
            "sphere",
            TangentTop::new(Arc::new(Sphere::new(1.0).unwrap()), 1.0, 0.6).unwrap(),
        ),
        (
            "sphere, embedded, anisotropic",
            TangentTop::with_tensor(
                Arc::new(Sphere::new(1.4).unwrap()),
                0.9,
                [0.5, 0.1, 0.1, 0.2],
            )
            .unwrap()
            .embedded()
            .unwrap(),
        ),
        (
            "hyperbolic plane",
            TangentTop::new(Arc::new(HyperbolicPlane), 1.2, 0.7).unwrap(),
        ),
        (
            "torus",
            TangentTop::with_tensor(
                Arc::new(Revolution::torus(2.0, 0.7).unwrap()),
                0.8,
                [0.4, -0.1, -0.1, 0.3],
            )
            .unwrap(),
        ),
        (
            "plane, embedded, anisotropic",
            TangentTop::with_tensor(Arc::new(Plane), 1.1, [0.3, 0.05, 0.05, 0.6])
                .unwrap()
                .embedded()
                .unwrap(),
        ),
    ]
}

/// A state of each top: x = (1.1, 0.6) (y > 0 on the half-plane), θ = 0.4.
fn tangent_top_state(top: &lieflow::systems::TangentTop) -> Vec<f64> {
    top.state([1.1, 0.6], 0.4, [0.5, -0.3], 0.8).unwrap()
}

/// The charged particles: of the sphere's intrinsic top (e = 0.7) and of a symmetric top
/// embedded in the sphere (G = m g + (𝕀/2)WᵀW, e = −0.4).
fn charged_particles() -> Vec<(&'static str, lieflow::systems::ChargedParticle)> {
    use lieflow::systems::{Sphere, TangentTop};
    let sphere = Arc::new(Sphere::new(1.0).unwrap());
    vec![
        (
            "charged particle, sphere",
            TangentTop::new(sphere.clone(), 1.0, 0.6)
                .unwrap()
                .magnetic_analogue(0.7)
                .unwrap(),
        ),
        (
            "charged particle, sphere, embedded",
            TangentTop::new(Arc::new(Sphere::new(1.3).unwrap()), 0.9, 0.5)
                .unwrap()
                .embedded()
                .unwrap()
                .magnetic_analogue(-0.4)
                .unwrap(),
        ),
    ]
}

/// The rolling disks of the catalog (tests/common): r = (1, 0.7), γ = ((0.3, 0.1),
/// (−0.2, 0.25)), m = (1, 1.5), I = (0.8, 0.6), c = 0.4 — from its parameters
/// (r₁, r₂, m₁, m₂, I₁, I₂, c).
fn rolling_disks_with(th: [f64; 7]) -> lieflow::systems::RollingDisks {
    lieflow::systems::RollingDisks::new(
        [th[0], th[1]],
        [[0.3, 0.1], [-0.2, 0.25]],
        [th[2], th[3]],
        [th[4], th[5]],
    )
    .unwrap()
    .with_rolling_constant(th[6])
    .unwrap()
}

const DISKS: [f64; 7] = [1.0, 0.7, 1.0, 1.5, 0.8, 0.6, 0.4];

/// The gradient (∂H/∂q, ∂H/∂p) of a canonical system at z, flat.
fn flat_gradient<S: lieflow::integrate::problem::Canonical>(s: &S, z: &[f64]) -> Vec<f64> {
    let d = s.dof();
    let mut g = vec![0.0; 2 * d];
    let (hq, hp) = g.split_at_mut(d);
    s.gradient(&z[..d], &z[d..], hq, hp);
    g
}

/// max over the components of |D²H(z)dz − (fourth-order central difference of ∇H along dz)|
/// relative to max(1, |D²H dz|).
fn hessian_defect<S: lieflow::integrate::tangent::CanonicalTangent>(
    s: &S,
    z: &[f64],
    dz: &[f64],
) -> f64 {
    let d = s.dof();
    let mut hv = vec![0.0; 2 * d];
    let (hq, hp) = hv.split_at_mut(d);
    s.gradient_tangent(&z[..d], &z[d..], &dz[..d], &dz[d..], hq, hp);
    let h = 5e-4;
    let at = |t: f64| {
        let y: Vec<f64> = z.iter().zip(dz).map(|(a, b)| a + t * b).collect();
        flat_gradient(s, &y)
    };
    let (p1, m1, p2, m2) = (at(h), at(-h), at(2.0 * h), at(-2.0 * h));
    let fd: Vec<f64> = (0..2 * d)
        .map(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h))
        .collect();
    max_rel(&hv, &fd)
}

/// max |∂∇H/∂θ_m − (fourth-order difference of ∇H of the rebuilt system, step 1e-3·|θ_m|)|
/// relative to max(1, |∂∇H/∂θ|), over the parameters (θ_m ≠ 0).
fn gradient_parameter_defect<S, const P: usize>(
    build: impl Fn([f64; P]) -> S,
    theta: [f64; P],
    z: &[f64],
) -> f64
where
    S: lieflow::integrate::tangent::CanonicalTangent,
{
    let s = build(theta);
    let d = s.dof();
    assert_eq!(s.parameters().len(), P);
    let mut worst = 0.0f64;
    for m in 0..P {
        let mut g = vec![0.0; 2 * d];
        let (hq, hp) = g.split_at_mut(d);
        s.gradient_parameter(&z[..d], &z[d..], m, hq, hp);
        // A step relative to θ_m (a small inertia changes H on its own scale).
        let h = 1e-3 * theta[m].abs();
        let at = |t: f64| {
            let mut th = theta;
            th[m] += t;
            flat_gradient(&build(th), z)
        };
        let (p1, m1, p2, m2) = (at(h), at(-h), at(2.0 * h), at(-2.0 * h));
        let fd: Vec<f64> = (0..2 * d)
            .map(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h))
            .collect();
        worst = worst.max(max_rel(&g, &fd));
    }
    worst
}

/// Directions: the unit vectors and two dense ones.
fn probe_directions(n: usize) -> Vec<Vec<f64>> {
    let mut dirs: Vec<Vec<f64>> = (0..n)
        .map(|j| (0..n).map(|i| f64::from(u8::from(i == j))).collect())
        .collect();
    dirs.push((0..n).map(|i| 0.3 + 0.17 * i as f64).collect());
    dirs.push((0..n).map(|i| (1.3 * i as f64 + 0.2).sin()).collect());
    dirs
}

/// Issue 26, before the lifts: the closed-form Hessian products D²H\[dz\] of the tangent top
/// (intrinsic on the sphere, the hyperbolic plane and a torus; embedded and anisotropic on the
/// sphere and the plane), of its charged particle and of the rolling disks are the derivatives
/// of their gradients (fourth-order differences, ≤ 1e-8), and so are the parameter derivatives
/// ∂∇H/∂θ (mass, inertia, charge; radii, masses, moments, rolling constant).
#[test]
fn hessians_of_the_tangent_tops_and_the_disks_are_their_gradients_derivatives() {
    use lieflow::systems::{ChargedParticle, TangentTop};
    let mut worst = 0.0f64;
    for (name, top) in tangent_tops() {
        let z = tangent_top_state(&top);
        let h = probe_directions(6)
            .iter()
            .fold(0.0f64, |m, dz| m.max(hessian_defect(&top, &z, dz)));
        // Parameters: m, and 𝕀 with the tensor's shape kept.
        let tensor = top.tensor();
        let tr = top.inertia();
        let surface = top.surface().clone();
        let embedded = top.is_embedded();
        let build = |th: [f64; 2]| {
            let t = TangentTop::with_tensor(surface.clone(), th[0], tensor.map(|v| v * th[1] / tr))
                .unwrap();
            if embedded {
                t.embedded().unwrap()
            } else {
                t
            }
        };
        let p = gradient_parameter_defect(build, [top.mass(), tr], &z);
        eprintln!("TangentTop on the {name}: Hessian {h:.1e}, parameters {p:.1e}");
        assert!(h < 1e-8 && p < 1e-8, "{name}: {h:e} {p:e}");
        worst = worst.max(h).max(p);
    }
    for (name, cp) in charged_particles() {
        let z = cp.state([1.1, 0.6], [0.5, -0.3]).unwrap();
        let h = probe_directions(4)
            .iter()
            .fold(0.0f64, |m, dz| m.max(hessian_defect(&cp, &z, dz)));
        let top = cp.top().clone();
        let surface = top.surface().clone();
        let embedded = top.is_embedded();
        let build = |th: [f64; 3]| -> ChargedParticle {
            let t = TangentTop::new(surface.clone(), th[0], th[1]).unwrap();
            let t = if embedded { t.embedded().unwrap() } else { t };
            t.magnetic_analogue(th[2]).unwrap()
        };
        let p = gradient_parameter_defect(build, [top.mass(), top.inertia(), cp.charge()], &z);
        eprintln!("{name}: Hessian {h:.1e}, parameters {p:.1e}");
        assert!(h < 1e-8 && p < 1e-8, "{name}: {h:e} {p:e}");
        worst = worst.max(h).max(p);
    }
    let disks = rolling_disks_with(DISKS);
    for z in [
        disks.state([0.3, -1.1], [0.7, 0.2]).unwrap(),
        disks.state([2.0, 0.5], [-0.4, 1.1]).unwrap(),
    ] {
        let h = probe_directions(4)
            .iter()
            .fold(0.0f64, |m, dz| m.max(hessian_defect(&disks, &z, dz)));
        let p = gradient_parameter_defect(rolling_disks_with, DISKS, &z);
        eprintln!("RollingDisks: Hessian {h:.1e}, parameters {p:.1e}");
        assert!(h < 1e-8 && p < 1e-8, "disks: {h:e} {p:e}");
        worst = worst.max(h).max(p);
    }
    eprintln!("worst {worst:.1e}");
}

/// Every lifted method of a canonical system from z0: the base state is the plain run's (to
/// 1e-14), the Jacobian the method's derivative (central differences, ≤ 1e-8 relative), and
/// the Gauss methods' Jacobians are symplectic (|JᵀΩJ − Ω| ≤ 1e-12; RK4's defect is printed:
/// it is not symplectic, though exact on the free motion of the plane). Returns the worst
/// difference over the Gauss methods.
fn check_canonical_lift(name: &str, sys: &dyn System, z0: &[f64], dt: f64, steps: usize) -> f64 {
    let t = sys.tangent().unwrap_or_else(|| panic!("{name} has a lift"));
    let d = z0.len();
    let mut worst = 0.0f64;
    for (method, _) in t.methods() {
        let (z, jac) = lifted_end(&*t, method, z0, dt, steps);
        let plain = integrate(sys, method, z0, dt, steps, steps).unwrap();
        let moved = max_rel(&z, plain.state(1));
        let fd = differences(sys, method, z0, dt, steps, 1e-5);
        let err = max_rel(&jac, &fd);
        let defect = symplecticity_defect(&jac, d);
        eprintln!(
            "{name}: {method}: moved {moved:.1e}, vs differences {err:.1e}, |JᵀΩJ − Ω| \
             {defect:.1e}"
        );
        assert!(
            moved < 1e-14,
            "{name} {method}: the base state moved by {moved:e}"
        );
        assert!(err < 1e-8, "{name} {method}: {err:e}");
        if method != "rk4" {
            assert!(defect < 1e-12, "{name} {method}: {defect:e}");
            worst = worst.max(err);
        }
    }
    worst
}

/// Issue 26: the tangent top (five surfaces, intrinsic and embedded anisotropic), its charged
/// particles and the rolling disks lift through `CanonicalTangent`: every method's Jacobian
/// is its derivative and the Gauss ones are symplectic; a surface without second derivatives
/// (a graph, a metric given by closures) gives no lift.
#[test]
fn jacobians_of_the_tangent_tops_and_the_disks_are_symplectic() {
    use lieflow::systems::{Graph, TangentTop};
    let (dt, steps) = (0.05, 40);
    for (name, top) in tangent_tops() {
        let z0 = tangent_top_state(&top);
        check_canonical_lift(&format!("TangentTop on the {name}"), &top, &z0, dt, steps);
    }
    for (name, cp) in charged_particles() {
        let z0 = cp.state([1.1, 0.6], [0.5, -0.3]).unwrap();
        check_canonical_lift(name, &cp, &z0, dt, steps);
    }
    let disks = rolling_disks_with(DISKS);
    let z0 = disks.state([0.3, -1.1], [0.7, 0.2]).unwrap();
    check_canonical_lift("RollingDisks", &disks, &z0, dt, steps);
    let graph = TangentTop::new(Arc::new(Graph::quadric(0.5, -0.3).unwrap()), 1.0, 0.6).unwrap();
    assert!(graph.tangent().is_none(), "a graph gives no ∂²α");
    let bowl = TangentTop::with_tensor(
        Arc::new(lieflow::systems::Revolution::torus(2.0, 0.7).unwrap()),
        1.0,
        [0.4, 0.0, 0.0, 0.2],
    )
    .unwrap()
    .embedded()
    .unwrap();
    assert!(
        bowl.tangent().is_none(),
        "an embedded revolution gives no ∂²W"
    );
}

/// Issue 26: the parameter Jacobians ∂z/∂θ of the Gauss runs against differences of rebuilt
/// systems: the top's mass and inertia (intrinsic on the sphere, embedded anisotropic), the
/// charged particle's mass, inertia and charge, and the disks' radii, masses, moments and
/// rolling constant.
#[test]
fn parameter_jacobians_of_the_tangent_tops_and_the_disks() {
    use lieflow::systems::TangentTop;
    let (dt, steps) = (0.05, 40);
    let report = |name: &str, method: &str, pj: &[f64], fd: &[f64]| {
        let err = max_rel(pj, fd);
        eprintln!("{name}: {method}: parameter Jacobian vs differences {err:.1e}");
        assert!(err < 1e-8, "{name} {method}: {err:e}");
    };
    for (name, top) in tangent_tops().into_iter().take(2) {
        let z0 = tangent_top_state(&top);
        let t = top.tangent().unwrap();
        assert_eq!(t.parameter_names(), ["mass", "inertia"]);
        let (tensor, tr) = (top.tensor(), top.inertia());
        let surface = top.surface().clone();
        let embedded = top.is_embedded();
        let build = |th: [f64; 2]| {
            let t = TangentTop::with_tensor(surface.clone(), th[0], tensor.map(|v| v * th[1] / tr))
                .unwrap();
            if embedded {
                t.embedded().unwrap()
            } else {
                t
            }
        };
        for method in ["gauss4", "midpoint"] {
            let (_, _, pj) = lifted_end_all(&*t, method, &z0, dt, steps);
            let fd = parameter_differences(build, [top.mass(), tr], method, &z0, (dt, steps), 1e-5);
            report(&format!("TangentTop on the {name}"), method, &pj, &fd);
        }
    }
    for (name, cp) in charged_particles() {
        let z0 = cp.state([1.1, 0.6], [0.5, -0.3]).unwrap();
        let t = cp.tangent().unwrap();
        let top = cp.top().clone();
        let surface = top.surface().clone();
        let embedded = top.is_embedded();
        let build = |th: [f64; 3]| {
            let t = TangentTop::new(surface.clone(), th[0], th[1]).unwrap();
            let t = if embedded { t.embedded().unwrap() } else { t };
            t.magnetic_analogue(th[2]).unwrap()
        };
        let theta = [top.mass(), top.inertia(), cp.charge()];
        let (_, _, pj) = lifted_end_all(&*t, "gauss4", &z0, dt, steps);
        let fd = parameter_differences(build, theta, "gauss4", &z0, (dt, steps), 1e-5);
        report(name, "gauss4", &pj, &fd);
    }
    let disks = rolling_disks_with(DISKS);
    let z0 = disks.state([0.3, -1.1], [0.7, 0.2]).unwrap();
    let t = disks.tangent().unwrap();
    for method in ["gauss4", "gauss6"] {
        let (_, _, pj) = lifted_end_all(&*t, method, &z0, dt, steps);
        let fd = parameter_differences(rolling_disks_with, DISKS, method, &z0, (dt, steps), 1e-5);
        report("RollingDisks", method, &pj, &fd);
    }
}

/// A Legendre top of 002 §IV built from its parameters (m, 𝕀), checked whole: the Hessian of H
/// (implicit-function theorem on the Legendre map) and ∂∇H/∂θ against differences of the
/// gradient (≤ 1e-8), every lifted method's Jacobian (and the Gauss ones symplectic) and the
/// gauss4 parameter Jacobian against differences of the runs (≤ 1e-8). Returns the worst
/// (Hessian, parameter) defects.
fn check_legendre_top<S>(
    name: &str,
    build: impl Fn([f64; 2]) -> S + Copy,
    theta: [f64; 2],
    z0: &[f64],
) -> (f64, f64)
where
    S: lieflow::integrate::tangent::CanonicalTangent + System,
{
    let top = build(theta);
    let h = probe_directions(6)
        .iter()
        .fold(0.0f64, |m, dz| m.max(hessian_defect(&top, z0, dz)));
    let p = gradient_parameter_defect(build, theta, z0);
    eprintln!("{name}: Hessian {h:.1e}, parameters {p:.1e}");
    assert!(h < 1e-8 && p < 1e-8, "{name}: {h:e} {p:e}");
    let (dt, steps) = (0.05, 20);
    check_canonical_lift(name, &top, z0, dt, steps);
    let t = top.tangent().unwrap();
    assert_eq!(t.parameter_names(), ["mass", "inertia"]);
    let (_, _, pj) = lifted_end_all(&*t, "gauss4", z0, dt, steps);
    // A step of 1e-6 (θ = 0.07 moved by 1e-5 would leave a truncation of 2e-8).
    let fd = parameter_differences(build, theta, "gauss4", z0, (dt, steps), 1e-6);
    let err = max_rel(&pj, &fd);
    eprintln!("{name}: gauss4: parameter Jacobian vs differences {err:.1e}");
    assert!(err < 1e-8, "{name}: {err:e}");
    (h, p)
}

/// Issue 26: the relativistic tops of 002 §IV (Minkowski, symmetric and anisotropic; on the
/// sphere and the hyperbolic plane, symmetric and anisotropic, the anisotropic kernel reading
/// the frame's derivative), the weak-field top (point mass, uniform field) and the static-field
/// top (flat, on the sphere) lift through the implicit-function theorem on their Legendre maps;
/// a custom potential (no third derivatives) or a graph (no second derivatives) gives no lift.
#[test]
fn legendre_tops_lift_through_the_inverse_legendre_map() {
    use lieflow::systems::{
        Graph, HyperbolicPlane, Potential, PotentialValue, RelativisticTangentTop, Sphere,
        StaticFieldTop, Surface, WeakFieldTop,
    };
    let (x, th, xd, td) = ([0.3, 0.6], 0.4, [0.25, -0.15], 1.2);
    // Minkowski, anisotropic and symmetric.
    let moments = [0.05, 0.01, 0.02];
    let tr = moments[0] + moments[2];
    let mink =
        |t: [f64; 2]| RelativisticTangentTop::new(t[0], moments.map(|i| i * t[1] / tr)).unwrap();
    let z0 = mink([1.2, tr]).state(x, th, xd, td).unwrap();
    check_legendre_top("Minkowski, anisotropic", mink, [1.2, tr], &z0);
    let sym = |t: [f64; 2]| RelativisticTangentTop::symmetric(t[0], t[1]).unwrap();
    let z0 = sym([1.0, 0.2]).state(x, th, xd, td).unwrap();
    check_legendre_top("Minkowski, symmetric", sym, [1.0, 0.2], &z0);
    // On surfaces.
    let sphere: Arc<dyn Surface> = Arc::new(Sphere::new(1.0).unwrap());
    let hyp: Arc<dyn Surface> = Arc::new(HyperbolicPlane);
    for (sname, surface) in [("sphere", sphere.clone()), ("hyperbolic plane", hyp)] {
        let s1 = surface.clone();
        let curved =
            move |t: [f64; 2]| RelativisticTangentTop::on_surface(s1.clone(), t[0], t[1]).unwrap();
        let z0 = curved([1.0, 0.2]).state(x, th, xd, td).unwrap();
        check_legendre_top(&format!("{sname}, symmetric"), &curved, [1.0, 0.2], &z0);
        let moments = [0.15, 0.04, 0.05];
        let tr = moments[0] + moments[2];
        let s2 = surface.clone();
        let aniso = move |t: [f64; 2]| {
            RelativisticTangentTop::on_surface_with_moments(
                s2.clone(),
                t[0],
                moments.map(|i| i * t[1] / tr),
            )
            .unwrap()
        };
        let z0 = aniso([1.0, tr]).state(x, th, xd, td).unwrap();
        check_legendre_top(&format!("{sname}, anisotropic"), &aniso, [1.0, tr], &z0);
    }
    // The weak field and the static field.
    let weak =
        |t: [f64; 2]| WeakFieldTop::new(t[0], t[1], Potential::point_mass(1.0).unwrap()).unwrap();
    let z0 = weak([1.0, 0.2])
        .state([1.0, 0.2], 0.0, [-0.1, 0.6], 1.0)
        .unwrap();
    check_legendre_top("weak field, point mass", weak, [1.0, 0.2], &z0);
    let uniform = |t: [f64; 2]| {
        WeakFieldTop::new(t[0], t[1], Potential::uniform([0.3, -0.8]).unwrap()).unwrap()
    };
    let z0 = uniform([1.0, 0.2])
        .state([1.0, 0.2], 0.0, [-0.1, 0.6], 1.0)
        .unwrap();
    check_legendre_top("weak field, uniform", uniform, [1.0, 0.2], &z0);
    let flat = |t: [f64; 2]| {
        StaticFieldTop::new(t[0], t[1], Potential::point_mass(0.15).unwrap()).unwrap()
    };
    let z0 = flat([1.0, 0.2])
        .state([1.0, 0.2], 0.3, [-0.1, 0.4], 1.0)
        .unwrap();
    check_legendre_top("static field, point mass", flat, [1.0, 0.2], &z0);
    let s3 = sphere.clone();
    let on_sphere = move |t: [f64; 2]| {
        StaticFieldTop::on_surface(s3.clone(), t[0], t[1], Potential::point_mass(0.1).unwrap())
            .unwrap()
    };
    let z0 = on_sphere([1.0, 0.2])
        .state([1.0, 0.4], 0.3, [0.2, -0.3], 1.0)
        .unwrap();
    check_legendre_top(
        "static field, point mass, sphere",
        &on_sphere,
        [1.0, 0.2],
        &z0,
    );
    // No lift without the data's higher derivatives.
    let custom = Potential::custom(|x| PotentialValue {
        phi: 0.1 * x[0],
        grad: [0.1, 0.0],
        hess: [0.0; 3],
    });
    assert!(WeakFieldTop::new(1.0, 0.2, custom)
        .unwrap()
        .tangent()
        .is_none());
    let graph = Arc::new(Graph::quadric(0.5, -0.3).unwrap());
    assert!(RelativisticTangentTop::on_surface(graph, 1.0, 0.2)
        .unwrap()
        .tangent()
        .is_none());
}
