//! How the round-off of the invariants grows over long runs (issue 29, part 6: Brouwer's law).
//!
//! A method that keeps an invariant to round-off still rounds at every step; if the rounding
//! errors are unbiased they random-walk and the error grows like √N (slope ½ of log error
//! against log steps); a biased operation (one that rounds the same way at every step) makes it
//! grow like N (slope 1). For every (system, method) that claims invariants, this prints the
//! error of each invariant (and of the energy for symplectic methods, and ‖RᵀR − I‖_F for
//! attitudes) after 10³ … 10^max steps and the least-squares slope of log₁₀ error against log₁₀
//! steps over the decades.
//!
//! The error at N steps is the largest |q(t) − q(0)| over the run up to N (sampled 10⁴ times per
//! decade), root-mean-squared over `--seeds` nearby initial states (the walk averaged). Errors are
//! absolute (the states have invariants of order one). The steppers run bare (`System::stepper`),
//! without the driver's retraction of SO(3) every 256 steps, so that ‖RᵀR − I‖ shows the flows
//! themselves. The systems of implicit methods (so(4), the canonical and constrained ones) run to
//! 10^`--slow-max` steps.
//!
//! `cargo run -p lieflow --release --example roundoff_slopes -- [--max 7] [--slow-max 6]
//! [--seeds 3] [--threads 2] [--only SUBSTRING] [--methods a,b]`
//! (docs/benchmarks.md has the table.)

use lieflow::integrate::{Clock, System};
use lieflow::lie::so3;
use lieflow::systems::{
    GeneralizedRigidBody, HeavyTop, Pendulum, RigidBody, RollingDisks, RollingSpheres, Sphere,
    SphereParticle, SphericalPendulum, TangentTop,
};
use nalgebra::{Matrix3, Vector3};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// A system, its step and a family of initial states (user frame), and where R sits.
struct Case {
    name: String,
    system: Arc<dyn System + Send + Sync>,
    dt: f64,
    states: Vec<Vec<f64>>,
    labels: Vec<&'static str>,
    /// Offsets of the attitudes R (row-major) in the state, for ‖RᵀR − I‖.
    attitude: &'static [usize],
    /// Costly per step (implicit methods): run to 10^`--slow-max` only.
    slow: bool,
}

/// A rotation whose third row is the unit vector g (so Γ = Rᵀe₃ = g).
fn rotation_with_third_row(g: [f64; 3]) -> [f64; 9] {
    let g = Vector3::from(g).normalize();
    let a = if g.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = (a - g * g.dot(&a)).normalize();
    let e2 = g.cross(&e1);
    [e1.x, e1.y, e1.z, e2.x, e2.y, e2.z, g.x, g.y, g.z]
}

fn rows(r: &Matrix3<f64>) -> [f64; 9] {
    std::array::from_fn(|k| r[(k / 3, k % 3)])
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    Vector3::from(v).normalize().into()
}

/// Seed k's small perturbation of a vector (the same k gives the same numbers; seed 0 is v).
fn nudge(v: [f64; 3], k: usize, size: f64) -> [f64; 3] {
    if k == 0 {
        return v;
    }
    let k = k as f64;
    [
        v[0] + size * (1.3 * k).sin(),
        v[1] + size * (2.1 * k + 0.4).sin(),
        v[2] + size * (0.7 * k + 1.1).sin(),
    ]
}

fn cases(seeds: usize) -> Vec<Case> {
    let mut out = Vec::new();
    let seeds_of = |f: &dyn Fn(usize) -> Vec<f64>| (0..seeds).map(f).collect::<Vec<_>>();

    // The Lagrange top of the issue: I = (1, 1, ½), mgl = 1, χ = e₃, dt = 1e-3.
    let lagrange = HeavyTop::new([1.0, 1.0, 0.5], 1.0, [0.0, 0.0, 1.0]).unwrap();
    let m0 = [0.1, 0.2, 0.9];
    let g0 = [0.2, 0.1, 0.97];
    out.push(Case {
        name: "Lagrange top".into(),
        system: Arc::new(lagrange.clone()),
        dt: 1e-3,
        states: seeds_of(&|k| lagrange.state(nudge(m0, k, 0.01), unit(nudge(g0, k, 0.01)))),
        labels: vec!["‖Γ‖²", "M·Γ"],
        attitude: &[],
        slow: false,
    });
    let lifted = lagrange.with_attitude();
    out.push(Case {
        name: "Lagrange top with attitude".into(),
        system: Arc::new(lifted.clone()),
        dt: 1e-3,
        states: seeds_of(&|k| {
            let r = rotation_with_third_row(nudge(g0, k, 0.01));
            lifted.state_with_attitude(nudge(m0, k, 0.01), r)
        }),
        labels: vec!["‖Γ‖²", "M·Γ"],
        attitude: &[6],
        slow: false,
    });
    // Its steady precession (a relative equilibrium): M = (a, 0, m₃), Γ = (sin β, 0, cos β)
    // turn rigidly about e₃ when cos β·a² − sin β·m₃·a + I₁ mgl sin²β = 0.
    out.push(Case {
        name: "Lagrange top, steady precession".into(),
        system: Arc::new(lagrange.clone()),
        dt: 1e-3,
        states: seeds_of(&|k| {
            let (beta, m3) = (0.3 + 0.01 * k as f64, 3.0);
            let (sb, cb) = beta.sin_cos();
            let disc = (sb * m3).powi(2) - 4.0 * cb * sb * sb;
            let a = (sb * m3 + disc.sqrt()) / (2.0 * cb);
            lagrange.state([a, 0.0, m3], [sb, 0.0, cb])
        }),
        labels: vec!["‖Γ‖²", "M·Γ"],
        attitude: &[],
        slow: false,
    });

    // A generic heavy top (the catalog test's).
    let top = HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap();
    out.push(Case {
        name: "heavy top (1, 2, 3)".into(),
        system: Arc::new(top.clone()),
        dt: 1e-3,
        states: seeds_of(&|k| {
            top.state(
                nudge([1.0, 0.5, -0.3], k, 0.01),
                unit(nudge([0.1, 0.2, 0.97], k, 0.01)),
            )
        }),
        labels: vec!["‖Γ‖²", "M·Γ"],
        attitude: &[],
        slow: false,
    });

    // The symmetric free body I = (1, 1, 2): every step turns M about e₃ by the same angle.
    let sym = RigidBody::new([1.0, 1.0, 2.0]).unwrap();
    let msym = [0.6, 0.3, 0.8];
    out.push(Case {
        name: "symmetric rigid body (1, 1, 2)".into(),
        system: Arc::new(sym.clone()),
        dt: 1e-2,
        states: seeds_of(&|k| nudge(msym, k, 0.01).to_vec()),
        labels: vec!["‖M‖²"],
        attitude: &[],
        slow: false,
    });
    let sym_l = sym.with_attitude();
    out.push(Case {
        name: "symmetric rigid body (1, 1, 2) with attitude".into(),
        system: Arc::new(sym_l.clone()),
        dt: 1e-2,
        states: seeds_of(&|k| {
            let r = so3::exp_unchecked(&Vector3::new(0.4, -0.2, 0.1 + 0.01 * k as f64));
            sym_l.state_with_attitude(nudge(msym, k, 0.01), rows(&r))
        }),
        labels: vec!["‖M‖²", "(RM)₁", "(RM)₂", "(RM)₃"],
        attitude: &[3],
        slow: false,
    });
    // A generic body (1, 2, 3).
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    out.push(Case {
        name: "rigid body (1, 2, 3)".into(),
        system: Arc::new(body.clone()),
        dt: 1e-2,
        states: seeds_of(&|k| nudge([1.0, 0.5, -0.3], k, 0.01).to_vec()),
        labels: vec!["‖M‖²"],
        attitude: &[],
        slow: false,
    });
    // Steady rotation about the major axis (a relative equilibrium): M = e₃ is a fixed point of
    // every sub-flow, R turns by the same angle every step.
    let body_l = body.with_attitude();
    out.push(Case {
        name: "rigid body (1, 2, 3), steady rotation, with attitude".into(),
        system: Arc::new(body_l.clone()),
        dt: 1e-2,
        states: seeds_of(&|k| {
            let r = so3::exp_unchecked(&Vector3::new(0.4, -0.2, 0.1 + 0.01 * k as f64));
            body_l.state_with_attitude([0.0, 0.0, 1.0 + 0.01 * k as f64], rows(&r))
        }),
        labels: vec!["‖M‖²", "(RM)₁", "(RM)₂", "(RM)₃"],
        attitude: &[3],
        slow: false,
    });

    // The spherical pendulum: a generic motion and the conical pendulum (a relative
    // equilibrium: θ̇ = 0, φ̇² = g/(l cos θ)).
    let pend = SphericalPendulum::new(1.0, 1.0, 9.81).unwrap();
    out.push(Case {
        name: "spherical pendulum".into(),
        system: Arc::new(pend.clone()),
        dt: 1e-3,
        states: seeds_of(&|k| {
            pend.state_from_spherical(0.8 + 0.01 * k as f64, 0.1, 0.3, 1.2)
                .unwrap()
        }),
        labels: vec!["‖q‖²", "q·L"],
        attitude: &[],
        slow: false,
    });
    out.push(Case {
        name: "spherical pendulum, conical".into(),
        system: Arc::new(pend.clone()),
        dt: 1e-3,
        states: seeds_of(&|k| {
            let th = 0.8 + 0.01 * k as f64;
            let w = (9.81 / th.cos()).sqrt();
            pend.state_from_spherical(th, 0.1, 0.0, w).unwrap()
        }),
        labels: vec!["‖q‖²", "q·L"],
        attitude: &[],
        slow: false,
    });

    // The generalized rigid body on so(4): generic, and with J = (1, 1, 2, 2) (resonant).
    for (name, j) in [
        ("so(4) body J = (1, 1.5, 2.5, 3)", [1.0, 1.5, 2.5, 3.0]),
        ("so(4) body J = (1, 1, 2, 2)", [1.0, 1.0, 2.0, 2.0]),
    ] {
        let b = GeneralizedRigidBody::new(&j).unwrap();
        out.push(Case {
            name: name.into(),
            system: Arc::new(b),
            dt: 1e-2,
            states: seeds_of(&|k| {
                let k = k as f64;
                vec![0.3, -0.2 + 0.01 * k, 0.5, 0.1, 0.4 - 0.01 * k, -0.6]
            }),
            labels: vec!["C₁", "C₂"],
            attitude: &[],
            slow: true,
        });
    }

    // The systems of the canonical and constrained kinds that claim invariants.
    let particle = SphereParticle::new(1.0, 1.0, 9.81).unwrap();
    out.push(Case {
        name: "particle on a sphere".into(),
        system: Arc::new(particle.clone()),
        dt: 1e-3,
        states: seeds_of(&|k| {
            let s = pend
                .state_from_spherical(0.8 + 0.01 * k as f64, 0.1, 0.3, 1.2)
                .unwrap();
            particle.from_spherical(&s).unwrap()
        }),
        labels: vec!["(q × p)₃"],
        attitude: &[],
        slow: true,
    });
    let disks = RollingDisks::new(
        [1.0, 0.7],
        [[0.3, 0.1], [-0.2, 0.25]],
        [1.0, 1.5],
        [0.8, 0.6],
    )
    .unwrap()
    .with_rolling_constant(0.4)
    .unwrap();
    out.push(Case {
        name: "rolling disks".into(),
        system: Arc::new(disks.clone()),
        dt: 1e-2,
        states: seeds_of(&|k| {
            disks
                .state([0.3 + 0.01 * k as f64, -1.1], [0.7, 0.2])
                .unwrap()
        }),
        labels: vec!["J"],
        attitude: &[],
        slow: true,
    });
    let tangent = TangentTop::new(Arc::new(Sphere::new(1.0).unwrap()), 1.0, 0.6).unwrap();
    out.push(Case {
        name: "tangent top on the sphere".into(),
        system: Arc::new(tangent.clone()),
        dt: 1e-2,
        states: seeds_of(&|k| {
            tangent
                .state([1.2, 0.3 + 0.01 * k as f64], 0.4, [0.5, -0.3], 0.8)
                .unwrap()
        }),
        labels: vec!["θ̇-momentum", "p_φ (rotation about z)"],
        attitude: &[],
        slow: true,
    });
    let spheres = RollingSpheres::new(
        0.7,
        1.3,
        [0.1, -0.2, 0.15],
        [-0.3, 0.2, 0.4],
        2.0,
        3.5,
        [[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]],
        [[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]],
    )
    .unwrap();
    out.push(Case {
        name: "rolling spheres".into(),
        system: Arc::new(spheres.clone()),
        dt: 1e-2,
        states: seeds_of(&|k| {
            let r1 = so3::exp_unchecked(&Vector3::new(0.3, -0.2, 0.5 + 0.01 * k as f64));
            let r2 = so3::exp_unchecked(&Vector3::new(-0.4, 0.1, 0.2));
            let m = |r: Matrix3<f64>| std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)]));
            spheres
                .state(
                    m(r1),
                    m(r2),
                    [0.6, 0.0, 0.8],
                    [0.5, -0.3, 0.8],
                    [-0.2, 0.4, 0.1],
                )
                .unwrap()
        }),
        labels: vec!["L₁", "L₂", "L₃"],
        attitude: &[0, 9],
        slow: true,
    });
    let pendulum = Pendulum::new(1.0, 1.0, 9.81).unwrap();
    out.push(Case {
        name: "pendulum".into(),
        system: Arc::new(pendulum),
        dt: 1e-2,
        states: seeds_of(&|k| vec![1.2 + 0.01 * k as f64, 0.3]),
        labels: vec![],
        attitude: &[],
        slow: true,
    });
    out
}

/// The quantities measured on a state: the invariants, H (when claimed bounded), ‖RᵀR − I‖_F.
fn quantities(case: &Case, energy: bool, z: &[f64]) -> Vec<f64> {
    let mut q = case.system.invariants(z).expect("invariants");
    if energy {
        q.push(case.system.energy(z).expect("energy"));
    }
    for &at in case.attitude {
        let r = Matrix3::from_row_slice(&z[at..at + 9]);
        q.push((r.transpose() * r - Matrix3::identity()).norm());
    }
    q
}

/// The running max of |q(t) − q(0)| at 10³ … 10^max steps, for one initial state.
fn run_one(case: &Case, method: &str, energy: bool, z0: &[f64], max_exp: u32) -> Vec<Vec<f64>> {
    let (mut stepper, _) = case.system.stepper(method, case.dt).expect("stepper");
    let mut z = z0.to_vec();
    case.system.to_internal(&mut z);
    stepper.set(&z).expect("set");
    let q0 = quantities(case, energy, z0);
    let is_defect = |i: usize| i + case.attitude.len() >= q0.len();
    let mut worst = vec![0.0f64; q0.len()];
    let mut out = Vec::new();
    let mut done = 0u64;
    let mut user = z.clone();
    for e in 3..=max_exp {
        let target = 10u64.pow(e);
        let stride = (target / 10_000).max(1);
        while done < target {
            let k = stride.min(target - done);
            let clock = Clock {
                t0: 0.0,
                dt: case.dt,
                done,
            };
            stepper.advance(k as usize, clock).expect("advance");
            done += k;
            stepper.get(&mut user);
            case.system.to_user(&mut user);
            let q = quantities(case, energy, &user);
            for (i, w) in worst.iter_mut().enumerate() {
                let d = if is_defect(i) {
                    q[i]
                } else {
                    (q[i] - q0[i]).abs()
                };
                *w = w.max(d);
            }
        }
        out.push(worst.clone());
    }
    out
}

/// Least-squares slope of log₁₀ e against log₁₀ N (errors floored at 1e-17: "exactly kept").
fn slope(errs: &[f64], first_exp: u32) -> f64 {
    let pts: Vec<(f64, f64)> = errs
        .iter()
        .enumerate()
        .map(|(i, &e)| ((first_exp + i as u32) as f64, e.max(1e-17).log10()))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

struct Job {
    case: usize,
    method: &'static str,
    energy: bool,
    seed: usize,
}

/// One run: the job and its errors at each decade (per quantity), and its time.
struct Outcome {
    case: usize,
    method: &'static str,
    energy: bool,
    errors: Vec<Vec<f64>>,
    secs: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let max_exp: u32 = arg("--max").map_or(7, |s| s.parse().expect("--max"));
    let slow_max: u32 = arg("--slow-max").map_or(6, |s| s.parse().expect("--slow-max"));
    let seeds: usize = arg("--seeds").map_or(3, |s| s.parse().expect("--seeds"));
    let threads: usize = arg("--threads").map_or(2, |s| s.parse().expect("--threads"));
    let only = arg("--only");
    let methods_arg = arg("--methods");
    let cases: Vec<Case> = cases(seeds)
        .into_iter()
        .filter(|c| only.as_ref().map_or(true, |o| c.name.contains(o.as_str())))
        .collect();
    let last = |c: &Case| {
        if c.slow {
            max_exp.min(slow_max)
        } else {
            max_exp
        }
    };

    // Every (case, method claiming invariants or symplecticity, seed).
    let mut jobs = Vec::new();
    for (ci, c) in cases.iter().enumerate() {
        for (m, p) in c.system.methods() {
            if let Some(list) = &methods_arg {
                if !list.split(',').any(|x| x == m) {
                    continue;
                }
            }
            if !(p.invariants || p.symplectic || p.exact) {
                continue;
            }
            for seed in 0..c.states.len() {
                jobs.push(Job {
                    case: ci,
                    method: m,
                    energy: p.symplectic && !p.exact,
                    seed,
                });
            }
        }
    }
    let results: Mutex<Vec<Outcome>> = Mutex::new(Vec::new());
    let next = Mutex::new(0usize);
    let t_all = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let j = {
                    let mut n = next.lock().unwrap();
                    let j = *n;
                    *n += 1;
                    j
                };
                let Some(job) = jobs.get(j) else { break };
                let c = &cases[job.case];
                let t = Instant::now();
                let errors = run_one(c, job.method, job.energy, &c.states[job.seed], last(c));
                let secs = t.elapsed().as_secs_f64();
                eprintln!(
                    "[{:.0} s] {} / {} seed {}: {:.1} s",
                    t_all.elapsed().as_secs_f64(),
                    c.name,
                    job.method,
                    job.seed,
                    secs
                );
                results.lock().unwrap().push(Outcome {
                    case: job.case,
                    method: job.method,
                    energy: job.energy,
                    errors,
                    secs,
                });
            });
        }
    });
    let results = results.into_inner().unwrap();

    println!(
        "Errors: the largest |q(t) − q(0)| over the run up to N steps (‖RᵀR − I‖_F itself), RMS \
         over {seeds} initial states; slope: least squares of log₁₀ error on log₁₀ N over the \
         decades, and over the last three; ns/step: the run's time per step and state (with the \
         measurements).\n"
    );
    let mut head = String::from("| system | dt | method | quantity |");
    let mut rule = String::from("|---|---|---|---|");
    for e in 3..=max_exp {
        head.push_str(&format!(" 10^{e} |"));
        rule.push_str("---:|");
    }
    head.push_str(" slope | last 3 | ns/step |");
    rule.push_str("---:|---:|---:|");
    println!("{head}\n{rule}");
    let mut worst: (f64, String) = (f64::NEG_INFINITY, String::new());
    for (ci, c) in cases.iter().enumerate() {
        for (m, _) in c.system.methods() {
            let runs: Vec<&Outcome> = results
                .iter()
                .filter(|r| r.case == ci && r.method == m)
                .collect();
            let Some(first) = runs.first() else {
                continue;
            };
            let mut labels: Vec<String> = c.labels.iter().map(|s| s.to_string()).collect();
            if first.energy {
                labels.push("H".into());
            }
            for (i, _) in c.attitude.iter().enumerate() {
                labels.push(match c.attitude.len() {
                    1 => "‖RᵀR − I‖".into(),
                    _ => format!("‖R{}ᵀR{} − I‖", i + 1, i + 1),
                });
            }
            assert_eq!(
                labels.len(),
                first.errors[0].len(),
                "{}: one label per measured quantity",
                c.name
            );
            let decades = first.errors.len();
            let ns = 1e9 * runs.iter().map(|r| r.secs).sum::<f64>()
                / runs.len() as f64
                / 10f64.powi(last(c) as i32);
            for (qi, label) in labels.iter().enumerate() {
                let errs: Vec<f64> = (0..decades)
                    .map(|d| {
                        let ms = runs.iter().map(|r| r.errors[d][qi].powi(2)).sum::<f64>();
                        (ms / runs.len() as f64).sqrt()
                    })
                    .collect();
                let sl = slope(&errs, 3);
                let tail = slope(&errs[decades.saturating_sub(3)..], 3 + decades as u32 - 3);
                let mut line = format!("| {} | {} | {m} | {label} |", c.name, c.dt);
                for e in 3..=max_exp {
                    match errs.get((e - 3) as usize) {
                        Some(v) => line.push_str(&format!(" {v:.1e} |")),
                        None => line.push_str(" – |"),
                    }
                }
                line.push_str(&format!(" {sl:.2} | {tail:.2} | {ns:.0} |"));
                println!("{line}");
                if sl > worst.0 {
                    worst = (sl, format!("{} / {m} / {label}", c.name));
                }
            }
        }
    }
    println!("\nlargest slope: {:.2} ({})", worst.0, worst.1);
}
