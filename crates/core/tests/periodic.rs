//! Periodic orbits by shooting (`analysis::periodic`): the free rigid body's period against the
//! closed form 4K(k)/λ on both sides of the separatrix (exact flow and DMV10), the Jordan
//! structure of its monodromy, a nonlinear oscillator's normal multipliers against the
//! linearisation, and the errors of bad input. Measured values are printed (`--nocapture`).

use lieflow::analysis::periodic::{periodic_orbit, Fix, Options};
use lieflow::integrate::Problem;
use lieflow::numerics::elliptic::ellipk;
use lieflow::systems::RigidBody;

const I: [f64; 3] = [1.0, 2.0, 3.0];

/// The period of M(t) in closed form (Landau–Lifshitz §37): 4K(k)/λ, the axes relabelled so
/// that the orbit circles axis 1 or 3 as the case requires.
fn closed_form_period(m: [f64; 3]) -> f64 {
    let l2: f64 = m.iter().map(|x| x * x).sum();
    let e2: f64 = (0..3).map(|k| m[k] * m[k] / I[k]).sum();
    // Landau's I1 < I2 < I3 with M² > 2E I2; otherwise 1 and 3 exchange.
    let (i1, i2, i3) = if l2 > e2 * I[1] {
        (I[0], I[1], I[2])
    } else {
        (I[2], I[1], I[0])
    };
    let lambda = ((i3 - i2) * (l2 - e2 * i1) / (i1 * i2 * i3)).sqrt();
    let k2 = (i2 - i1) * (e2 * i3 - l2) / ((i3 - i2) * (l2 - e2 * i1));
    4.0 * ellipk(k2).unwrap() / lambda
}

fn options(steps: usize, fix: Fix) -> Options {
    Options {
        steps,
        fix,
        ..Options::default()
    }
}

#[test]
fn the_free_body_period_is_the_closed_form_on_both_sides_of_the_separatrix() {
    let body = RigidBody::new(I).unwrap();
    // About the least axis (M² < 2E I2 relabelled) and about the largest; one near the separatrix.
    for m0 in [
        [1.0, 0.3, 0.2],
        [0.2, 0.3, 1.0],
        [0.3, 1.0, 0.25],
        [0.25, 1.0, 0.3],
    ] {
        // The shooting keeps the guess's energy and Casimir: the orbit is the one through m0,
        // found from a period off by 2 %.
        let exact = closed_form_period(m0);
        for (method, steps) in [("exact", 8), ("dmv10", 400)] {
            let orbit = periodic_orbit(
                &body,
                method,
                &m0,
                exact * 1.02,
                None,
                &options(steps, Fix::Energy),
            )
            .unwrap();
            let err = (orbit.period - exact).abs() / exact;
            println!(
                "M0 = {m0:?} {method}: T = {:.15} closed form {exact:.15} rel {err:.2e}, \
                 residual {:.1e}, {} iterations",
                orbit.period, orbit.residual, orbit.iterations
            );
            assert!(err <= 1e-10, "{method}: {err:e}");
            assert!(orbit.residual <= 1e-13, "{}", orbit.residual);
            // On the levels of m0 (energy fixed, Casimir kept).
            assert!((orbit.energy - body.energy(&m0).unwrap()).abs() <= 1e-14);
        }
    }
}

#[test]
fn the_free_body_monodromy_is_one_jordan_block_and_a_simple_one() {
    // M fixes the flow; along the family the period varies (shear): (M − I)² = 0, M ≠ I, every
    // multiplier trivial (one degree of freedom on the momentum sphere leaves no normal motion).
    let body = RigidBody::new(I).unwrap();
    for m0 in [[1.0, 0.3, 0.2], [0.25, 1.0, 0.3]] {
        let orbit = periodic_orbit(
            &body,
            "exact",
            &m0,
            closed_form_period(m0),
            None,
            &options(8, Fix::Energy),
        )
        .unwrap();
        let m = &orbit.monodromy;
        let n = lieflow::Mat::from_fn(3, 3, |i, j| m[(i, j)] - if i == j { 1.0 } else { 0.0 });
        let n2 = &n * &n;
        let size = |a: &lieflow::Mat| {
            (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .fold(0.0_f64, |s, (i, j)| s.max(a[(i, j)].abs()))
        };
        let spread = orbit
            .multipliers
            .iter()
            .fold(0.0_f64, |s, &(re, im)| s.max((re - 1.0).hypot(im)));
        println!(
            "M0 = {m0:?}: |M − I| = {:.3e}, |(M − I)²| = {:.3e}, multipliers within {spread:.1e} \
             of 1",
            size(&n),
            size(&n2)
        );
        assert!(size(&n) > 0.1, "the period varies along the family");
        assert!(size(&n2) <= 1e-9 * size(&n).powi(2), "{}", size(&n2));
        // A Jordan block of size 2 splits its eigenvalues by √ε.
        assert!(spread <= 1e-6, "{spread:e}");
        assert!(orbit.trivial.iter().all(|&t| t) && orbit.normal.is_empty());
        assert!(orbit.stable());
    }
}

/// ½|p|² + ½x² + ½ω²y² + ½βx²y²: the orbits y = 0 are the harmonic x-oscillations (period 2π),
/// and the motion across them obeys Mathieu's equation δÿ + (ω² + βA²cos²t)δy = 0.
fn coupled(omega: f64, beta: f64) -> lieflow::systems::UserSeparable {
    use lieflow::systems::{KineticMass, UserSeparable};
    use std::sync::Arc;
    let w2 = omega * omega;
    let u = Arc::new(move |q: &[f64]| -> lieflow::Result<f64> {
        let (x, y) = (q[0], q[1]);
        Ok(0.5 * (x * x + w2 * y * y + beta * x * x * y * y))
    });
    let g = Arc::new(move |q: &[f64], g: &mut [f64]| -> lieflow::Result<()> {
        let (x, y) = (q[0], q[1]);
        g[0] = x + beta * x * y * y;
        g[1] = w2 * y + beta * x * x * y;
        Ok(())
    });
    let h = Arc::new(
        move |q: &[f64], v: &[f64], out: &mut [f64]| -> lieflow::Result<()> {
            let (x, y) = (q[0], q[1]);
            out[0] = (1.0 + beta * y * y) * v[0] + 2.0 * beta * x * y * v[1];
            out[1] = 2.0 * beta * x * y * v[0] + (w2 + beta * x * x) * v[1];
            Ok(())
        },
    );
    UserSeparable::new(KineticMass::Scalar(1.0), Some(2), u, Some(g))
        .unwrap()
        .with_hessian(h)
}

/// The eigenvalues of Mathieu's monodromy over 2π (classical RK4, 20000 steps).
fn mathieu_multipliers(omega: f64, beta: f64, amplitude: f64) -> [(f64, f64); 2] {
    let f = |t: f64, y: [f64; 2]| {
        let c = t.cos();
        [
            y[1],
            -(omega * omega + beta * amplitude * amplitude * c * c) * y[0],
        ]
    };
    let n = 20000;
    let h = 2.0 * std::f64::consts::PI / n as f64;
    let mut cols = [[1.0, 0.0], [0.0, 1.0]];
    for col in cols.iter_mut() {
        let mut y = *col;
        for k in 0..n {
            let t = k as f64 * h;
            let k1 = f(t, y);
            let k2 = f(
                t + h / 2.0,
                [y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]],
            );
            let k3 = f(
                t + h / 2.0,
                [y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]],
            );
            let k4 = f(t + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
            for i in 0..2 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        *col = y;
    }
    // Eigenvalues of [[a, b], [c, d]] with columns cols.
    let (a, b, c, d) = (cols[0][0], cols[1][0], cols[0][1], cols[1][1]);
    let (tr, det) = (a + d, a * d - b * c);
    let disc = tr * tr / 4.0 - det;
    if disc < 0.0 {
        [(tr / 2.0, (-disc).sqrt()), (tr / 2.0, -(-disc).sqrt())]
    } else {
        [(tr / 2.0 + disc.sqrt(), 0.0), (tr / 2.0 - disc.sqrt(), 0.0)]
    }
}

#[test]
fn normal_multipliers_are_those_of_the_linearisation_across_the_orbit() {
    let (omega, beta) = (1.3, 0.4);
    let sys = coupled(omega, beta);
    // A guess off the orbit (y ≠ 0) and off in period: the orbit found is y = 0 at the
    // guess's energy.
    let guess = [0.8, 0.01, 0.0, 0.005];
    for (method, steps, tol) in [("gauss6", 200, 1e-10), ("verlet4", 2000, 1e-10)] {
        let orbit = periodic_orbit(
            &sys,
            method,
            &guess,
            6.0,
            None,
            &options(steps, Fix::Energy),
        )
        .unwrap();
        let z = &orbit.state0;
        let amplitude = (z[0] * z[0] + z[2] * z[2]).sqrt();
        let reference = mathieu_multipliers(omega, beta, amplitude);
        let err = orbit
            .normal
            .iter()
            .zip(&reference)
            .fold(0.0_f64, |m, (a, b)| m.max((a.0 - b.0).hypot(a.1 - b.1)));
        println!(
            "{method}: T − 2π = {:.2e}, y = {:.1e}, normal {:?} vs Mathieu {reference:?}: {err:.1e}",
            orbit.period - 2.0 * std::f64::consts::PI,
            z[1].abs().max(z[3].abs()),
            orbit.normal
        );
        assert_eq!(orbit.normal.len(), 2);
        assert!(err <= tol, "{method}: {err:e}");
        assert!((orbit.period - 2.0 * std::f64::consts::PI).abs() <= 10.0 * tol);
        assert!(orbit.stable());
        assert_eq!(orbit.trivial.iter().filter(|&&t| t).count(), 2);
    }
}

#[test]
fn bad_input_is_refused_with_what_was_expected() {
    let body = RigidBody::new(I).unwrap();
    let m0 = [1.0, 0.3, 0.2];
    let err = |r: lieflow::Result<_>| {
        r.map(|_: lieflow::analysis::periodic::PeriodicOrbit| ())
            .unwrap_err()
            .to_string()
    };
    let o = options(8, Fix::Energy);
    assert!(err(periodic_orbit(&body, "exact", &m0, -1.0, None, &o)).contains("invalid period"));
    assert!(err(periodic_orbit(&body, "exact", &m0, f64::NAN, None, &o)).contains("invalid period"));
    assert!(err(periodic_orbit(
        &body,
        "exact",
        &m0,
        1.0,
        None,
        &options(0, Fix::Energy)
    ))
    .contains("steps"));
    assert!(err(periodic_orbit(&body, "exact", &[1.0, 0.0], 1.0, None, &o)).contains("shape"));
    assert!(err(periodic_orbit(&body, "nope", &m0, 1.0, None, &o)).contains("not supported"));
    // A steady rotation is an equilibrium of M: no period.
    assert!(err(periodic_orbit(
        &body,
        "exact",
        &[1.0, 0.0, 0.0],
        1.0,
        None,
        &o
    ))
    .contains("equilibrium"));
}

/// The solid angle Λ = ∮(1 − cos ϑ) dφ enclosed by M(t)/‖M‖ over one period, the pole on the
/// principal axis the orbit circles, oriented by the motion: the periodic trapezoidal rule on
/// samples of the exact solution (exponentially accurate for a smooth periodic integrand).
fn solid_angle(body: &RigidBody, m0: [f64; 3], period: f64) -> f64 {
    let n = 4000;
    let traj = lieflow::integrate::integrate(body, "exact", &m0, period / n as f64, n, 1).unwrap();
    let l: f64 = m0.iter().map(|x| x * x).sum::<f64>().sqrt();
    // The pole: the axis whose component keeps its sign.
    let pole = if m0[0].abs() > m0[2].abs() && traj.states.chunks(3).all(|m| m[0] * m0[0] > 0.0) {
        0
    } else {
        2
    };
    let (a, b) = ((pole + 1) % 3, (pole + 2) % 3);
    let sign = m0[pole].signum();
    let mut sum = 0.0;
    for m in traj.states.chunks(3).take(n) {
        let w = [m[0] / I[0], m[1] / I[1], m[2] / I[2]];
        let mdot = [
            m[1] * w[2] - m[2] * w[1],
            m[2] * w[0] - m[0] * w[2],
            m[0] * w[1] - m[1] * w[0],
        ];
        let phidot = (m[a] * mdot[b] - m[b] * mdot[a]) / (m[a] * m[a] + m[b] * m[b]);
        // About the pole's positive direction (ϑ from +pole): a pole at −axis flips both.
        sum += (1.0 - sign * m[pole] / l) * phidot * sign;
    }
    sum * period / n as f64
}

#[test]
fn the_relative_orbit_drift_is_montgomery_s_angle() {
    use lieflow::analysis::periodic::attitude_drift;
    use lieflow::lie::so3;
    let body = RigidBody::new(I).unwrap();
    let r0 = so3::exp_unchecked(&nalgebra::Vector3::new(0.4, -0.7, 0.3));
    let rows: [f64; 9] = std::array::from_fn(|k| r0[(k / 3, k % 3)]);
    for m0 in [
        [1.0, 0.3, 0.2],
        [0.2, 0.3, 1.0],
        [0.25, 1.0, 0.3],
        [-0.3, 1.0, -0.25],
    ] {
        let t = closed_form_period(m0);
        let l = m0.iter().map(|x| x * x).sum::<f64>().sqrt();
        let e = body.energy(&m0).unwrap();
        let expected = 2.0 * e * t / l - solid_angle(&body, m0, t);
        let pi = r0 * nalgebra::Vector3::from(m0) / l;
        for (method, steps) in [("exact", 8), ("dmv10", 400)] {
            let orbit =
                periodic_orbit(&body, method, &m0, t, None, &options(steps, Fix::Energy)).unwrap();
            let w = nalgebra::Vector3::from(attitude_drift(&body, method, &orbit, &rows).unwrap());
            // g = exp(θ π̂): ω ∥ π, θ = ω·π̂ modulo 2π.
            let theta = w.dot(&pi);
            let across = (w - pi * theta).norm();
            let tau = 2.0 * std::f64::consts::PI;
            let diff = (theta - expected).rem_euclid(tau);
            let err = diff.min(tau - diff);
            println!(
                "M0 = {m0:?} {method}: drift {theta:.15} Montgomery {expected:.15} (mod 2π) \
                 err {err:.1e}, across π {across:.1e}"
            );
            assert!(
                err <= 1e-9 && across <= 1e-12,
                "{method}: {err:e} {across:e}"
            );
        }
    }
}

/// A Lyapunov orbit about a stable Jacobi ellipsoid (the incompressible self-gravitating body,
/// RATTLE): started from a normal mode of the co-moving linearisation, shot as a relative
/// periodic orbit X(T) = e^ζ X(0) e^{−η}. As the amplitude shrinks its period tends to the
/// mode's 2π/ω and its drift to T·(Ω ⊕ 0); its normal multipliers lie on the unit circle (the
/// linear analysis says stable) and tend to e^{±iω_k T} of the other modes.
#[test]
fn a_lyapunov_orbit_of_the_jacobi_ellipsoid_is_the_normal_mode_at_small_amplitude() {
    use lieflow::analysis::comoving;
    use lieflow::pseudo_rigid::ellipsoids::Fluid;
    let fl = Fluid::new(1.0, 1.0).unwrap();
    let fig = fl.jacobi(0.6).unwrap();
    let (ze, xi) = Fluid::state(&fig);
    let body = fl.body().unwrap();
    let st = comoving::stability(&body, &ze, &xi).unwrap();
    assert!(st.spectral.stable);
    let omegas: Vec<f64> = st.modes.iter().map(|m| m.eigenvalue.1).collect();
    println!(
        "Jacobi a2/a1 = 0.6: mode frequencies {omegas:?}, normal dim {}",
        st.normal_dim
    );
    let mode = &st.modes[0];
    let omega = mode.eigenvalue.1;
    let size = ze.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let mut previous = f64::INFINITY;
    for amplitude in [1e-2, 5e-3] {
        let z0: Vec<f64> = ze
            .iter()
            .zip(&mode.re)
            .map(|(z, v)| z + amplitude * size * v)
            .collect();
        let t = 2.0 * std::f64::consts::PI / omega;
        let zeta: Vec<f64> = xi.iter().map(|x| x * t).collect();
        let opts = Options {
            relative: true,
            ..options(200, Fix::Energy)
        };
        let orbit = periodic_orbit(&body, "rattle6", &z0, t, Some(&zeta), &opts).unwrap();
        let drift = orbit.drift.as_ref().unwrap();
        let dz: f64 = drift
            .iter()
            .zip(&zeta)
            .fold(0.0, |m, (a, b)| m.max((a - b).abs()));
        let dt = (orbit.period - t).abs() / t;
        let on_circle = orbit
            .normal
            .iter()
            .fold(0.0_f64, |m, &(re, im)| m.max((re.hypot(im) - 1.0).abs()));
        println!(
            "amplitude {amplitude:.0e}: T = {:.10} (2π/ω = {t:.10}, rel {dt:.1e}), drift − Tξ {dz:.1e}, \
             {} iterations, residual {:.1e}, normal {:?} (|μ| − 1 ≤ {on_circle:.1e})",
            orbit.period, orbit.iterations, orbit.residual, orbit.normal
        );
        assert!(orbit.stable() && on_circle <= 1e-9, "{on_circle:e}");
        assert_eq!(orbit.normal.len(), 2 * (omegas.len() - 1));
        // The other modes turn by e^{±iω_k T} over the period, to O(amplitude²).
        for w in &omegas[1..] {
            let (c, s) = ((w * orbit.period).cos(), (w * orbit.period).sin().abs());
            let near = orbit.normal.iter().fold(f64::INFINITY, |m, &(re, im)| {
                m.min((re - c).hypot(im.abs() - s))
            });
            assert!(near <= 100.0 * amplitude * amplitude, "ω = {w}: {near:e}");
        }
        // The period's offset from 2π/ω and the drift's from Tξ are O(amplitude²).
        assert!(dt <= 2.0 * amplitude * amplitude && dz <= 5.0 * amplitude * amplitude);
        assert!(dt < previous / 3.0);
        previous = dt;
    }
}

/// The family's tangent is the secant of two orbits of the family at nearby energies (the
/// same levels, the same phase hyperplane), to O(δ).
#[test]
fn the_family_tangent_is_the_secant_of_nearby_orbits() {
    let body = RigidBody::new(I).unwrap();
    let m0 = [1.0, 0.3, 0.2];
    let t0 = closed_form_period(m0);
    let casimir: f64 = m0.iter().map(|x| x * x).sum();
    let o = options(8, Fix::Energy);
    let orbit = periodic_orbit(&body, "exact", &m0, t0, None, &o).unwrap();
    assert_eq!(orbit.levels.len(), 1);
    assert!((orbit.levels[0] - casimir).abs() <= 1e-14);
    let tan = &orbit.tangent;
    assert_eq!(tan.len(), 4);
    // Nearby orbits on m0's sphere, on the phase plane through m0 (across the flow f there):
    // the guesses m0 ± δu, u = m0 × f(m0), lie on their own orbits.
    let w: Vec<f64> = (0..3).map(|k| m0[k] / I[k]).collect();
    let f = [
        m0[1] * w[2] - m0[2] * w[1],
        m0[2] * w[0] - m0[0] * w[2],
        m0[0] * w[1] - m0[1] * w[0],
    ];
    let u = [
        m0[1] * f[2] - m0[2] * f[1],
        m0[2] * f[0] - m0[0] * f[2],
        m0[0] * f[1] - m0[1] * f[0],
    ];
    let delta = 1e-5;
    let shoot = |s: f64| {
        let g: Vec<f64> = (0..3).map(|k| m0[k] + s * u[k]).collect();
        let opts = Options {
            levels: Some(vec![casimir]),
            ..o.clone()
        };
        periodic_orbit(&body, "exact", &g, t0, None, &opts).unwrap()
    };
    let (p, m) = (shoot(delta), shoot(-delta));
    let mut secant: Vec<f64> = (0..3).map(|i| p.state0[i] - m.state0[i]).collect();
    secant.push(p.period - m.period);
    let norm = secant.iter().map(|x| x * x).sum::<f64>().sqrt();
    let sign = if p.energy > m.energy { 1.0 } else { -1.0 };
    let err = secant
        .iter()
        .zip(tan)
        .fold(0.0_f64, |e, (s, t)| e.max((sign * s / norm - t).abs()));
    println!(
        "tangent {tan:?}, secant {:?} error {err:.1e}",
        secant.iter().map(|s| sign * s / norm).collect::<Vec<_>>()
    );
    // The phase plane's normal is the chord of a step of 1e-5·T: f to O(1e-5).
    assert!(err <= 1e-4, "{err:e}");
    // Both orbits keep m0's Casimir.
    for q in [&p, &m] {
        let c: f64 = q.state0.iter().map(|x| x * x).sum();
        assert!((c - casimir).abs() <= 1e-13);
    }
}

/// The error paths of the relative and continuation options: a drift guess, levels or an
/// arclength condition of the wrong size, a relative orbit of a system without an action.
#[test]
fn wrong_sizes_of_the_relative_and_continuation_options_are_refused() {
    use lieflow::pseudo_rigid::ellipsoids::Fluid;
    let body = RigidBody::new(I).unwrap();
    let m0 = [1.0, 0.3, 0.2];
    let err = |o: Options, drift: Option<&[f64]>| {
        periodic_orbit(&body, "exact", &m0, 10.9, drift, &o)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let base = options(8, Fix::Energy);
    let relative = Options {
        relative: true,
        ..base.clone()
    };
    assert!(err(relative, None).contains("no symmetry"));
    let levels = Options {
        levels: Some(vec![1.0, 2.0]),
        ..base.clone()
    };
    assert!(err(levels, None).contains("levels"));
    let arclength = Options {
        fix: Fix::Arclength {
            from: vec![0.0; 3],
            tangent: vec![0.0; 4],
            step: 0.1,
        },
        ..base.clone()
    };
    assert!(err(arclength, None).contains("arclength"));
    // A drift guess of the wrong length for SO(3)×SO(3) (6 values).
    let fl = Fluid::new(1.0, 1.0).unwrap();
    let (ze, _) = Fluid::state(&fl.jacobi(0.6).unwrap());
    let jbody = fl.body().unwrap();
    let o = Options {
        relative: true,
        ..options(50, Fix::Energy)
    };
    let e = periodic_orbit(&jbody, "rattle", &ze, 2.0, Some(&[0.0; 3]), &o)
        .map(|_| ())
        .unwrap_err();
    assert!(matches!(e, lieflow::Error::Shape { .. }), "{e}");
}

/// H = H₁(1 + C) + (ω₂/2)(p₂² + q₂²) − (ω₃/2)(p₃² + q₃²), H₁ = ½(q₁² + p₁²), C = q₂q₃ − p₂p₃:
/// across the orbits x₁ = A cos t (period 2π, E = H₁) the normal system is H₂₃ + E·C,
/// autonomous, with eigenvalues ±i(ω̄ ± √(δ² − E²)) (ω̄, δ the mean and half the difference of
/// ω₂, ω₃): two oscillators of opposite Krein signature whose multipliers collide at E = δ.
fn krein(w2: f64, w3: f64) -> lieflow::systems::UserCanonical {
    use lieflow::systems::UserCanonical;
    use std::sync::Arc;
    let parts =
        |q: &[f64], p: &[f64]| (0.5 * (q[0] * q[0] + p[0] * p[0]), q[1] * q[2] - p[1] * p[2]);
    let h = Arc::new(move |q: &[f64], p: &[f64]| -> lieflow::Result<f64> {
        let (h1, c) = parts(q, p);
        Ok(h1 * (1.0 + c) + 0.5 * w2 * (q[1] * q[1] + p[1] * p[1])
            - 0.5 * w3 * (q[2] * q[2] + p[2] * p[2]))
    });
    let g = Arc::new(
        move |q: &[f64], p: &[f64], gq: &mut [f64], gp: &mut [f64]| -> lieflow::Result<()> {
            let (h1, c) = parts(q, p);
            gq.copy_from_slice(&[
                q[0] * (1.0 + c),
                w2 * q[1] + h1 * q[2],
                -w3 * q[2] + h1 * q[1],
            ]);
            gp.copy_from_slice(&[
                p[0] * (1.0 + c),
                w2 * p[1] - h1 * p[2],
                -w3 * p[2] - h1 * p[1],
            ]);
            Ok(())
        },
    );
    let hess = Arc::new(
        move |q: &[f64],
              p: &[f64],
              dq: &[f64],
              dp: &[f64],
              oq: &mut [f64],
              op: &mut [f64]|
              -> lieflow::Result<()> {
            let (h1, c) = parts(q, p);
            let dh1 = q[0] * dq[0] + p[0] * dp[0];
            let dc = dq[1] * q[2] + q[1] * dq[2] - dp[1] * p[2] - p[1] * dp[2];
            oq.copy_from_slice(&[
                dq[0] * (1.0 + c) + q[0] * dc,
                w2 * dq[1] + dh1 * q[2] + h1 * dq[2],
                -w3 * dq[2] + dh1 * q[1] + h1 * dq[1],
            ]);
            op.copy_from_slice(&[
                dp[0] * (1.0 + c) + p[0] * dc,
                w2 * dp[1] - dh1 * p[2] - h1 * dp[2],
                -w3 * dp[2] - dh1 * p[1] - h1 * dp[1],
            ]);
            Ok(())
        },
    );
    UserCanonical::new(3, h, Some(g))
        .unwrap()
        .with_hessian(hess)
}

/// A family crosses a Krein collision: located, named, its multipliers the closed form's on
/// both sides; the step control, stop and progress hook; bad options refused.
#[test]
fn a_family_through_a_krein_collision() {
    use lieflow::analysis::periodic::{periodic_family, End, FamilyOptions, Kind};
    use lieflow::Error;
    let (w2, w3) = (1.3, 1.2);
    let (mean, half) = ((w2 + w3) / 2.0, (w2 - w3) / 2.0);
    let sys = krein(w2, w3);
    let two_pi = 2.0 * std::f64::consts::PI;
    let start = periodic_orbit(
        &sys,
        "gauss6",
        &[0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
        two_pi,
        None,
        &options(60, Fix::Energy),
    )
    .unwrap();
    let opts = FamilyOptions {
        stop: Some(0.07),
        max_points: 20,
        ..FamilyOptions::default()
    };
    let mut seen = 0;
    let family = periodic_family(&sys, "gauss6", &start, &opts, &mut |_| {
        seen += 1;
        Ok(())
    })
    .unwrap();
    assert_eq!(family.end, End::Stop);
    assert_eq!(seen, family.points.len() - 1);
    assert!(family.points.last().unwrap().energy >= 0.07);
    assert_eq!(family.special.len(), 1, "{:?}", family.special);
    let sp = &family.special[0];
    assert_eq!(sp.kind, Kind::Krein);
    assert!((0.05..=0.05 + 5e-6).contains(&sp.value), "{}", sp.value);
    for o in &family.points {
        // ±i(ω̄ ± √(δ² − E²)): on the circle before E = δ, a quadruplet after.
        let r = half * half - o.energy * o.energy;
        let (re, im) = if r >= 0.0 {
            (0.0, r.sqrt())
        } else {
            ((-r).sqrt(), 0.0)
        };
        let mut exact = Vec::new();
        for (a, b) in [
            (re, mean + im),
            (-re, mean - im),
            (re, -mean - im),
            (-re, -mean + im),
        ] {
            let m = (two_pi * a).exp();
            exact.push((m * (two_pi * b).cos(), m * (two_pi * b).sin()));
        }
        let err = exact.iter().fold(0.0_f64, |e, x| {
            e.max(
                o.normal
                    .iter()
                    .fold(f64::INFINITY, |m, y| m.min((x.0 - y.0).hypot(x.1 - y.1))),
            )
        });
        assert!(err <= 1e-6, "E = {}: {err:e}", o.energy);
        assert_eq!(o.stable(), o.energy < half);
        assert!((o.period - two_pi).abs() <= 1e-9);
    }
    // The hook ends the continuation with its error.
    let stopped = periodic_family(&sys, "gauss6", &start, &opts, &mut |_| {
        Err(Error::Interrupted { steps_done: 1 })
    });
    assert!(matches!(stopped, Err(Error::Interrupted { steps_done: 1 })));
    // Bad options and a start without its tangent.
    for bad in [
        FamilyOptions {
            step: 0.0,
            ..opts.clone()
        },
        FamilyOptions {
            max_step: 0.01,
            ..opts.clone()
        },
        FamilyOptions {
            max_points: 0,
            ..opts.clone()
        },
        FamilyOptions {
            tol: 1.5,
            ..opts.clone()
        },
    ] {
        let err = periodic_family(&sys, "gauss6", &start, &bad, &mut |_| Ok(())).unwrap_err();
        assert!(matches!(err, Error::InvalidArgument { .. }), "{err}");
    }
    let bare = lieflow::analysis::periodic::PeriodicOrbit {
        tangent: Vec::new(),
        ..start.clone()
    };
    let err = periodic_family(&sys, "gauss6", &bare, &opts, &mut |_| Ok(())).unwrap_err();
    assert!(err.to_string().contains("tangent"), "{err}");
}
