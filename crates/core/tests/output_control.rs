//! Output control of the driver (issue 15): states at given times by shortened steps, events
//! located on the method's own trajectory, the last shortened step to an end time, and the state
//! a failed run keeps — checked on the free rigid body against its exact solution.

use std::sync::{Arc, Mutex};

use lieflow::integrate::methods::{Composition, Splitting};
use lieflow::integrate::{Event, Events, Problem, Run, Until};
use lieflow::pseudo_rigid::potential::Harmonic;
use lieflow::pseudo_rigid::PseudoRigidBody;
use lieflow::systems::RigidBody;
use lieflow::{Error, Mat};

const M0: [f64; 3] = [1.0, 0.5, -0.3];

fn body() -> RigidBody {
    RigidBody::new([1.0, 2.0, 3.0]).unwrap()
}

fn casimir(m: &[f64]) -> f64 {
    m.iter().map(|x| x * x).sum()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The zeros of M₂(t) of the exact solution in (t0, t1): sign changes on a grid, bisected.
fn exact_zeros(body: &RigidBody, t0: f64, t1: f64) -> Vec<(f64, f64)> {
    let m2 = |t: f64| body.exact_momentum(&M0, t).unwrap()[1];
    let n = 20_000;
    let mut zeros = Vec::new();
    for k in 0..n {
        let (mut a, mut b) = (
            t0 + (t1 - t0) * k as f64 / n as f64,
            t0 + (t1 - t0) * (k + 1) as f64 / n as f64,
        );
        let (fa, fb) = (m2(a), m2(b));
        if fa.signum() == fb.signum() {
            continue;
        }
        let rising = fb > fa;
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid == a || mid == b {
                break;
            }
            if (m2(mid) > 0.0) == (fb > 0.0) {
                b = mid
            } else {
                a = mid
            }
        }
        zeros.push((0.5 * (a + b), if rising { 1.0 } else { -1.0 }));
    }
    zeros
}

#[test]
fn output_times_match_the_exact_solution_and_keep_the_casimir() {
    let body = body();
    let times: Vec<f64> = (0..40).map(|k| 0.0137 + 0.2443 * k as f64).collect();
    for (method, dt, tol) in [
        ("splitting", 1e-3, 2e-6),
        ("splitting6", 1e-2, 1e-9),
        ("isospectral", 1e-3, 2e-6),
        ("lgvi", 1e-3, 2e-6),
        ("rk4", 1e-2, 1e-7),
    ] {
        let steps = (10.0 / dt) as u64;
        let mut run = Run::new(&body, method, &M0, dt, 1, 0.0).unwrap();
        run.save_at(&times).unwrap();
        let mut out = Vec::new();
        let n = run
            .advance_to(&body, Until::Steps(steps), &mut out, None)
            .unwrap();
        assert_eq!(n, times.len());
        let c0 = casimir(&M0);
        for (k, &t) in times.iter().enumerate() {
            let m = &out[3 * k..3 * k + 3];
            let exact = body.exact_momentum(&M0, t).unwrap();
            assert!(
                max_diff(m, &exact) < tol,
                "{method} t = {t}: {m:?} vs {exact:?}"
            );
            if method != "rk4" {
                // The shortened steps are steps of the method: |M|² to round-off.
                assert!((casimir(m) / c0 - 1.0).abs() < 1e-13, "{method} t = {t}");
            }
        }
        // The run went on on its grid: its final state is that of a run without output times.
        let mut plain = Run::new(&body, method, &M0, dt, steps as usize, 0.0).unwrap();
        plain.advance(&body, steps, &mut Vec::new()).unwrap();
        assert_eq!(run.state(&body), plain.state(&body), "{method}");
        assert_eq!(run.steps_done(), steps);
    }
}

#[test]
fn grid_times_are_grid_states_and_chunks_do_not_matter() {
    let body = body();
    let dt = 0.01;
    // Grid times (also as computed in decimal: 0.3 is not 30 × 0.01 in binary) and between.
    let times = [0.0, 0.005, 0.3, 0.31, 0.3149, 1.0, 1.7];
    let mut one = Run::new(&body, "splitting4", &M0, dt, 1, 0.0).unwrap();
    one.save_at(&times).unwrap();
    let mut a = Vec::new();
    one.advance_to(&body, Until::Steps(200), &mut a, None)
        .unwrap();
    assert_eq!(a.len(), 3 * times.len());
    let mut every = Run::new(&body, "splitting4", &M0, dt, 1, 0.0).unwrap();
    let mut grid = M0.to_vec();
    every.advance(&body, 200, &mut grid).unwrap();
    for (k, step) in [(0, 0), (2, 30), (3, 31), (5, 100), (6, 170)] {
        assert_eq!(
            &a[3 * k..3 * k + 3],
            &grid[3 * step..3 * step + 3],
            "t = {}",
            times[k]
        );
    }
    // In chunks of 7 steps: the same states.
    let mut chunked = Run::new(&body, "splitting4", &M0, dt, 1, 0.0).unwrap();
    chunked.save_at(&times).unwrap();
    let mut b = Vec::new();
    for _ in 0..(200 / 7 + 1) {
        let left = 200 - chunked.steps_done();
        chunked
            .advance_to(&body, Until::Steps(left.min(7)), &mut b, None)
            .unwrap();
    }
    assert_eq!(a, b);
    // Plain `advance` saves grid times but refuses a time between grid times.
    let mut plain = Run::new(&body, "splitting4", &M0, dt, 1, 0.0).unwrap();
    plain.save_at(&[0.3, 0.305]).unwrap();
    let e = plain.advance(&body, 100, &mut Vec::new()).unwrap_err();
    assert!(e.to_string().contains("shortened step"), "{e}");
}

#[test]
fn save_at_refuses_bad_times() {
    let body = body();
    let mut run = Run::new(&body, "splitting", &M0, 0.1, 1, 2.0).unwrap();
    for (times, what) in [
        (vec![2.0, 2.5, 2.5], "strictly increasing"),
        (vec![3.0, 2.5], "strictly increasing"),
        (vec![1.0, 2.5], "precede"),
    ] {
        let e = run.save_at(&times).unwrap_err();
        assert!(e.to_string().contains(what), "{times:?}: {e}");
    }
    assert!(matches!(
        run.save_at(&[2.0, f64::NAN]),
        Err(Error::NonFinite { .. })
    ));
    // No output time at all is refused, as lf.integrate(t_eval=[]) is.
    assert!(matches!(run.save_at(&[]), Err(Error::Shape { .. })));
    assert_eq!(run.grid_steps(2.0).unwrap(), 0);
    assert_eq!(run.grid_steps(2.3).unwrap(), 3);
    assert_eq!(run.grid_steps(2.35).unwrap(), 3);
    assert!(run.grid_steps(1.0).is_err() && run.grid_steps(f64::INFINITY).is_err());
}

#[test]
fn until_time_ends_the_run_with_a_shortened_step() {
    let body = body();
    let mut run = Run::new(&body, "splitting6", &M0, 0.01, 1000, 1.0).unwrap();
    let mut out = Vec::new();
    // Every-mode: the end state is saved last.
    assert_eq!(
        run.advance_to(&body, Until::Time(3.2345), &mut out, None)
            .unwrap(),
        1
    );
    assert_eq!(run.ended(), Some(3.2345));
    assert_eq!(run.time(), 3.2345);
    assert_eq!(run.steps_done(), 223);
    let exact = body.exact_momentum(&M0, 3.2345 - 1.0).unwrap();
    assert!(max_diff(&run.state(&body), &exact) < 1e-10);
    assert_eq!(&out[..], &run.state(&body)[..]);
    let e = run
        .advance_to(&body, Until::Steps(1), &mut out, None)
        .unwrap_err();
    assert!(e.to_string().contains("the run ended at t = 3.2345"), "{e}");
    // A grid time: no shortened step, the run goes on.
    let mut run = Run::new(&body, "splitting6", &M0, 0.01, 1000, 0.0).unwrap();
    run.advance_to(&body, Until::Time(0.5), &mut Vec::new(), None)
        .unwrap();
    assert_eq!((run.ended(), run.steps_done()), (None, 50));
}

#[test]
fn method_values_take_shortened_steps_with_advance_to_with() {
    let body = body();
    let method = Splitting(Composition::suzuki4());
    let mut run = Run::with(&body, &method, &M0, 0.01, 1, 0.0).unwrap();
    run.save_at(&[0.123]).unwrap();
    let e = run
        .advance_to(&body, Until::Steps(20), &mut Vec::new(), None)
        .unwrap_err();
    assert!(e.to_string().contains("advance_to_with"), "{e}");
    let mut out = Vec::new();
    run.advance_to_with(&body, &method, Until::Steps(20), &mut out, None)
        .unwrap();
    let mut named = Run::new(&body, "splitting4", &M0, 0.01, 1, 0.0).unwrap();
    named.save_at(&[0.123]).unwrap();
    let mut same = Vec::new();
    named
        .advance_to(&body, Until::Steps(20), &mut same, None)
        .unwrap();
    assert_eq!(out, same);
}

/// A shared record of an event function's calls (t, M₂).
fn m2_event(log: &Arc<Mutex<Vec<f64>>>) -> impl FnMut(f64, &[f64]) -> lieflow::Result<f64> {
    let log = log.clone();
    move |t, z| {
        log.lock().unwrap().push(t);
        Ok(z[1])
    }
}

#[test]
fn events_are_located_on_the_trajectory_against_the_exact_zeros() {
    let body = body();
    let zeros = exact_zeros(&body, 0.0, 20.0);
    assert!(zeros.len() >= 4, "{zeros:?}");
    for (method, dt, tol) in [
        ("splitting6", 1e-2, 1e-10),
        ("splitting", 1e-3, 1e-5),
        ("isospectral", 1e-3, 1e-5),
        ("lgvi", 1e-3, 1e-5),
        ("rk4", 5e-3, 1e-8),
    ] {
        let log = Arc::new(Mutex::new(Vec::new()));
        let mut events = Events::new(
            vec![
                Event::new(m2_event(&log)),
                Event::new(|_, z: &[f64]| Ok(z[1])).direction(1.0),
                Event::new(|_, z: &[f64]| Ok(z[1])).direction(-1.0),
            ],
            0.0,
        )
        .unwrap();
        let mut run = Run::new(&body, method, &M0, dt, 100, 0.0).unwrap();
        let mut out = Vec::new();
        run.advance_to(
            &body,
            Until::Steps((20.0 / dt) as u64),
            &mut out,
            Some(&mut events),
        )
        .unwrap();
        let all: Vec<_> = events.hits.iter().filter(|h| h.event == 0).collect();
        assert_eq!(all.len(), zeros.len(), "{method}");
        let mut worst: f64 = 0.0;
        for (hit, &(t, dir)) in all.iter().zip(&zeros) {
            worst = worst.max((hit.t - t).abs());
            // M₂ at the event state: the zero of the method's trajectory, to round-off.
            assert!(hit.state[1].abs() < 1e-13, "{method}: {:?}", hit.state);
            if method != "rk4" {
                assert!((casimir(&hit.state) / casimir(&M0) - 1.0).abs() < 1e-13);
            }
            // Directions: event 1 only at rising zeros, event 2 only at falling ones.
            let k = if dir > 0.0 { 1 } else { 2 };
            assert!(events
                .hits
                .iter()
                .any(|h| h.event == k && h.t == hit.t && h.state == hit.state));
        }
        assert_eq!(
            events.counts()[1] + events.counts()[2],
            events.counts()[0],
            "{method}"
        );
        eprintln!("{method} dt = {dt}: max |t_event − t_exact| = {worst:.2e}");
        assert!(worst < tol, "{method}: {worst:.3e}");
        assert_eq!(events.stopped_by(), None);
        assert_eq!(run.steps_done(), (20.0 / dt) as u64);
        // Evaluated at every step and a few times per event.
        let calls = log.lock().unwrap().len() as u64;
        assert!(calls > run.steps_done() && calls < run.steps_done() + 20 * all.len() as u64);
    }
}

#[test]
fn a_terminal_event_ends_the_run_at_the_event() {
    let body = body();
    let zeros = exact_zeros(&body, 0.0, 20.0);
    let second_falling = zeros.iter().filter(|z| z.1 < 0.0).nth(1).unwrap().0;
    let mut events = Events::new(
        vec![
            Event::new(|_, z: &[f64]| Ok(z[1])),
            Event::new(|_, z: &[f64]| Ok(z[1]))
                .direction(-1.0)
                .terminal(2),
        ],
        0.0,
    )
    .unwrap();
    let dt = 1e-2;
    let mut run = Run::new(&body, "splitting6", &M0, dt, 10, 0.0).unwrap();
    let mut out = M0.to_vec();
    run.advance_to(&body, Until::Steps(2000), &mut out, Some(&mut events))
        .unwrap();
    let t_end = run.ended().unwrap();
    assert_eq!(events.stopped_by(), Some(1));
    assert!(
        (t_end - second_falling).abs() < 1e-10,
        "{t_end} vs {second_falling}"
    );
    assert_eq!(run.time(), t_end);
    assert_eq!(run.steps_done(), (t_end / dt).floor() as u64);
    // The last saved state is the event's state; the others are on the grid every 10 steps.
    let last = events.hits.last().unwrap();
    assert_eq!((last.event, last.t), (1, t_end));
    assert_eq!(&out[out.len() - 3..], &last.state[..]);
    assert_eq!(run.state(&body), last.state);
    assert_eq!(out.len() / 3, 1 + run.steps_done() as usize / 10 + 1);
    // Event 0 saw every zero up to the terminal one.
    let before = zeros.iter().filter(|z| z.0 <= t_end + 1e-9).count();
    assert_eq!(events.counts()[0] as usize, before);
    // With output times: only those before the event are saved.
    let mut events =
        Events::new(vec![Event::new(|_, z: &[f64]| Ok(z[1])).terminal(1)], 0.0).unwrap();
    let mut run = Run::new(&body, "splitting6", &M0, dt, 1, 0.0).unwrap();
    let times: Vec<f64> = (0..100).map(|k| 0.05 * k as f64 + 0.001).collect();
    run.save_at(&times).unwrap();
    let mut out = Vec::new();
    let n = run
        .advance_to(&body, Until::Steps(2000), &mut out, Some(&mut events))
        .unwrap();
    let t_end = run.ended().unwrap();
    assert!((t_end - zeros[0].0).abs() < 1e-10);
    assert_eq!(n, times.iter().filter(|&&t| t <= t_end).count());
}

#[test]
fn event_tolerance_and_errors() {
    let body = body();
    let exact = exact_zeros(&body, 0.0, 5.0)[0].0;
    let mut loose = Events::new(vec![Event::new(|_, z: &[f64]| Ok(z[1]))], 1e-4).unwrap();
    let mut run = Run::new(&body, "splitting6", &M0, 1e-2, 1000, 0.0).unwrap();
    run.advance_to(&body, Until::Steps(500), &mut Vec::new(), Some(&mut loose))
        .unwrap();
    let t = loose.hits[0].t;
    assert!(
        (t - exact).abs() < 1e-4 && (t - exact).abs() > 0.0,
        "{t} {exact}"
    );
    assert!(Events::new(vec![], -1.0).is_err());
    assert!(Events::new(
        vec![Event::new(|_, _: &[f64]| Ok(0.0)).direction(f64::NAN)],
        0.0
    )
    .is_err());
    // A non-finite value, an error of the function: the run stays at its last step.
    let mut bad = Events::new(
        vec![Event::new(|t, _: &[f64]| {
            Ok(if t > 0.5 { f64::NAN } else { 1.0 })
        })],
        0.0,
    )
    .unwrap();
    let mut run = Run::new(&body, "splitting6", &M0, 1e-2, 1000, 0.0).unwrap();
    let e = run
        .advance_to(&body, Until::Steps(500), &mut Vec::new(), Some(&mut bad))
        .unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    assert_eq!(run.steps_done(), 50);
    assert_eq!(run.state(&body), run.checked_state(&body));
    let mut failing = Events::new(
        vec![Event::new(|t, _: &[f64]| {
            if t > 0.25 {
                Err(Error::invalid("g", "fails"))
            } else {
                Ok(1.0)
            }
        })],
        0.0,
    )
    .unwrap();
    let mut run = Run::new(&body, "splitting6", &M0, 1e-2, 1000, 0.0).unwrap();
    let e = run
        .advance_to(
            &body,
            Until::Steps(500),
            &mut Vec::new(),
            Some(&mut failing),
        )
        .unwrap_err();
    assert!(e.to_string().contains("fails"));
    assert_eq!(run.steps_done(), 25);
}

#[test]
fn a_failed_run_names_the_step_and_keeps_the_last_checked_state() {
    // X(t) = X0 (cos t − sin t) leaves GL⁺(3) at t = π/4: found in step 786 with dt = 1e-3,
    // inside a chunk of 100 steps (save_every) that the driver takes again step by step.
    let x0 = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + 0.5 * i as f64 } else { 0.0 });
    let body = PseudoRigidBody::new(3, Arc::new(Harmonic::new(1.0).unwrap()), true).unwrap();
    let z0 = body.state(&x0, &(-&x0)).unwrap();
    let mut run = Run::new(&body, "verlet", &z0, 1e-3, 100, 0.0).unwrap();
    let mut out = Vec::new();
    let e = run.advance(&body, 2000, &mut out).unwrap_err();
    match &e {
        Error::LeftDomain { t, message, .. } => {
            assert!((t - 0.786).abs() < 1e-12, "{e}");
            assert!(message.contains("found in step 786"), "{e}");
        }
        other => panic!("expected LeftDomain, got {other:?}"),
    }
    assert_eq!(out.len(), 7 * 18); // steps 100 … 700
    assert_eq!(run.steps_done(), 785);
    let det = |z: &[f64]| body.split(z).unwrap().0.as_ref().determinant();
    assert!(det(&run.checked_state(&body)) > 0.0);
    assert!(det(&run.state(&body)) <= 0.0); // where the stepper stopped
    let c = 0.785f64.cos() - 0.785f64.sin();
    let (x, _) = body.split(&run.checked_state(&body)).unwrap();
    assert!((x[(0, 0)] - c).abs() < 1e-6);
    // A non-finite blow-up in a long chunk: the message names the one step.
    let rb = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let mut run = Run::new(&rb, "rk4", &[100.0, 50.0, -30.0], 10.0, 100, 0.0).unwrap();
    let e = run.advance(&rb, 100, &mut Vec::new()).unwrap_err();
    let step = run.steps_done() + 1;
    assert!(e.to_string().contains(&format!("step {step} ")), "{e}");
    assert!(rb.energy(&run.checked_state(&rb)).unwrap().is_finite());
}
