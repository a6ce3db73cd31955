//! Batches in SIMD lanes (issue 14): the splittings of the rigid body and of the heavy top step a
//! batch in blocks of lanes ([`Batch`], the `BatchStepper` of `Splitting`), and a body's
//! trajectory is bit for bit the same alone and in a batch, whatever the batch size, its position, the threads and the chunks
//! in which the run is advanced; errors still name the member and the step.

use lieflow::integrate::methods::{Composition, Splitting};
use lieflow::integrate::{integrate, integrate_batch, integrate_with, Batch, Run, System, Until};
use lieflow::systems::{HeavyTop, RigidBody};
use lieflow::Error;

fn body() -> RigidBody {
    RigidBody::new([1.0, 2.0, 3.0]).unwrap()
}

/// Initial momenta of various sizes and signs (a few with zero components, some fast enough
/// that a sub-step turns by more than 0.78 rad, so that groups of lanes mix the kernel's small
/// and general paths).
fn states(n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|k| {
            let a = k as f64;
            match k % 7 {
                0 => vec![0.0, 0.0, 1.0 + a * 1e-3],
                1 => vec![(a * 0.37).sin() * 40.0, 0.5, -(a * 0.11).cos()],
                2 => vec![300.0 + a, -200.0, 150.0 * (a * 0.3).sin()],
                _ => vec![(a * 1.3).sin(), 0.5 + (a * 0.7).cos(), -0.3 + 0.01 * a],
            }
        })
        .collect()
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

const METHODS: [&str; 4] = ["splitting", "splitting4", "splitting6", "processed8"];

#[test]
fn the_splittings_of_the_so3_bodies_offer_lanes_and_the_others_do_not() {
    let b = body();
    assert!(b.batch_stepper("splitting", 0.01, 5).is_some());
    assert!(b.batch_stepper("splitting6", 0.01, 5).is_some());
    assert!(b.batch_stepper("rk4", 0.01, 5).is_none());
    assert!(b.batch_stepper("dmv10", 0.01, 5).is_none());
    assert!(b
        .with_attitude()
        .batch_stepper("splitting", 0.01, 5)
        .is_some());
    let top = heavy_top();
    assert!(top.batch_stepper("splitting4", 0.01, 5).is_some());
    assert!(top.batch_stepper("exact_splitting", 0.01, 5).is_none());
    assert!(top
        .with_attitude()
        .batch_stepper("processed6", 0.01, 5)
        .is_some());
    let runs = vec![Run::new(&b, "splitting", &[1.0, 2.0, 3.0], 0.01, 1, 0.0).unwrap()];
    assert!(Batch::new(&b, "splitting", runs).unwrap().in_lanes());
}

#[test]
fn a_body_alone_and_in_batches_of_any_size_position_and_threads_gives_the_same_bits() {
    let b = body();
    let all = states(600); // more than two groups of lanes, and a ragged last one
    for m in METHODS {
        let alone: Vec<_> = all
            .iter()
            .map(|z| integrate(&b, m, z, 0.01, 300, 7).unwrap())
            .collect();
        for threads in [1, 2] {
            let batch = integrate_batch(&b, m, &all, 0.01, 300, 7, Some(threads)).unwrap();
            for (a, t) in alone.iter().zip(&batch) {
                assert_eq!(bits(&a.states), bits(&t.states), "{m}");
                assert_eq!(bits(&a.final_state), bits(&t.final_state), "{m}");
                assert_eq!(bits(&a.t), bits(&t.t));
            }
        }
        // Other batch sizes and positions: reversed, and a small batch of a few members.
        let rev: Vec<_> = all.iter().rev().cloned().collect();
        let batch = integrate_batch(&b, m, &rev, 0.01, 300, 7, Some(2)).unwrap();
        for (a, t) in alone.iter().rev().zip(&batch) {
            assert_eq!(bits(&a.states), bits(&t.states), "{m} reversed");
        }
        let few: Vec<_> = all[3..6].to_vec();
        let batch = integrate_batch(&b, m, &few, 0.01, 300, 7, None).unwrap();
        for (a, t) in alone[3..6].iter().zip(&batch) {
            assert_eq!(bits(&a.final_state), bits(&t.final_state), "{m} few");
        }
    }
}

fn heavy_top() -> HeavyTop {
    HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap()
}

/// `system` alone and in batches on 1 and 2 threads, for `methods`: the same bits.
fn same_bits_alone_and_in_a_batch<S: System>(system: &S, all: &[Vec<f64>], methods: &[&str]) {
    for &m in methods {
        let alone: Vec<_> = all
            .iter()
            .map(|z| integrate(system, m, z, 0.01, 300, 9).unwrap())
            .collect();
        for threads in [1, 2] {
            let batch = integrate_batch(system, m, all, 0.01, 300, 9, Some(threads)).unwrap();
            for (a, t) in alone.iter().zip(&batch) {
                assert_eq!(bits(&a.states), bits(&t.states), "{m}");
                assert_eq!(bits(&a.final_state), bits(&t.final_state), "{m}");
            }
        }
    }
}

/// A rotation R for member k (row-major, an exponential: a state of SO(3)).
fn attitude(k: usize) -> [f64; 9] {
    let a = k as f64;
    let r = lieflow::lie::so3::exp_unchecked(&nalgebra::Vector3::new(
        (a * 0.7).sin(),
        0.3,
        -0.2 * a.cos(),
    ));
    std::array::from_fn(|i| r[(i / 3, i % 3)])
}

/// The heavy top in lanes (M and Γ; the kick, the axis rotations and the Rodrigues turn of Γ),
/// and with its attitude (R's columns rotated, its rows turned): the same bits alone and in a
/// batch, for tops slow and fast (Casimir angles beyond the small-angle path) and at rest
/// (θ = 0), over 300 steps (a retraction of R at step 256).
#[test]
fn a_heavy_top_alone_and_in_a_batch_gives_the_same_bits() {
    let top = heavy_top();
    let all: Vec<Vec<f64>> = states(300)
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let a = k as f64;
            let g = [(a * 0.3).sin(), (a * 0.5).cos(), 0.4];
            let m = if k % 11 == 0 {
                [0.0; 3]
            } else {
                [m[0], m[1], m[2]]
            };
            top.state(m, g)
        })
        .collect();
    same_bits_alone_and_in_a_batch(&top, &all, &["splitting", "splitting4", "processed6"]);
    let with_r: Vec<Vec<f64>> = all
        .iter()
        .enumerate()
        .map(|(k, z)| {
            // Γ = Rᵀe₃, the third row of R.
            let r = attitude(k);
            z[..3].iter().chain(&r[6..]).chain(&r).copied().collect()
        })
        .collect();
    same_bits_alone_and_in_a_batch(&top.with_attitude(), &with_r, &["splitting", "processed6"]);
}

/// The free body with its attitude in lanes: the same bits alone and in a batch.
#[test]
fn a_body_with_attitude_alone_and_in_a_batch_gives_the_same_bits() {
    let all: Vec<Vec<f64>> = states(150)
        .iter()
        .enumerate()
        .map(|(k, m)| m.iter().copied().chain(attitude(k)).collect())
        .collect();
    let methods = ["splitting", "splitting4", "processed8"];
    same_bits_alone_and_in_a_batch(&body().with_attitude(), &all, &methods);
}

#[test]
fn chunks_do_not_change_the_bits() {
    let b = body();
    let all = states(37);
    for m in METHODS {
        let whole = integrate_batch(&b, m, &all, 0.02, 500, 500, Some(1)).unwrap();
        for chunks in [&[1u64, 2, 3, 494][..], &[250, 250], &[7; 72][..], &[499, 1]] {
            let runs = all
                .iter()
                .map(|z| Run::new(&b, m, z, 0.02, 500, 0.0).unwrap())
                .collect();
            let mut batch = Batch::new(&b, m, runs).unwrap();
            let mut outs = vec![Vec::new(); all.len()];
            let mut total = 0;
            for &c in chunks {
                let take = c.min(500 - total);
                if take == 0 {
                    break;
                }
                for r in batch.advance(&b, take, &mut outs) {
                    r.unwrap();
                }
                total += take;
            }
            for (i, w) in whole.iter().enumerate() {
                assert_eq!(
                    bits(&batch.state(&b, i)),
                    bits(&w.final_state),
                    "{m} {chunks:?}"
                );
                assert_eq!(bits(&outs[i]), bits(w.state(1)), "{m} {chunks:?}");
            }
        }
    }
}

#[test]
fn leaving_the_lanes_mid_run_continues_exactly() {
    // Advance in lanes, then detach (as output times or events would), then go on alone.
    let b = body();
    let all = states(20);
    let whole = integrate_batch(&b, "splitting4", &all, 0.01, 400, 400, Some(1)).unwrap();
    let runs = all
        .iter()
        .map(|z| Run::new(&b, "splitting4", z, 0.01, 400, 0.0).unwrap())
        .collect();
    // Runs made alone and put in blocks, and members started in blocks (which get their
    // stepper and scratch only when they leave: Batch::start).
    let built = Batch::new(&b, "splitting4", runs).unwrap();
    let started = Batch::start(&b, "splitting4", &all, 0.01, 400, 0.0).unwrap();
    for mut batch in [built, started] {
        assert!(batch.in_lanes());
        let mut outs = vec![Vec::new(); all.len()];
        for r in batch.advance(&b, 123, &mut outs) {
            r.unwrap();
        }
        for (i, run) in batch.runs_mut().unwrap().iter_mut().enumerate() {
            // Output times between grid times: shortened steps, the user-frame scratch.
            run.save_at(&[2.005, 3.995]).unwrap();
            let mut at = Vec::new();
            run.advance_to(&b, Until::Steps(277), &mut at, None)
                .unwrap();
            assert_eq!(bits(&run.state(&b)), bits(&whole[i].final_state));
            let alone = &mut Run::new(&b, "splitting4", &all[i], 0.01, 400, 0.0).unwrap();
            alone.save_at(&[2.005, 3.995]).unwrap();
            let mut want = Vec::new();
            alone
                .advance_to(&b, Until::Steps(400), &mut want, None)
                .unwrap();
            assert_eq!(bits(&at), bits(&want));
        }
        assert!(!batch.in_lanes());
    }
}

#[test]
fn method_values_use_the_lanes_too() {
    let b = body();
    let m = Splitting(Composition::triple_jump4());
    let all = states(10);
    let runs = all
        .iter()
        .map(|z| Run::with(&b, &m, z, 0.05, 10, 0.0).unwrap())
        .collect();
    let mut batch = Batch::with(&b, &m, runs).unwrap();
    assert!(batch.in_lanes());
    let mut outs = vec![Vec::new(); all.len()];
    for r in batch.advance(&b, 100, &mut outs) {
        r.unwrap();
    }
    for (i, z) in all.iter().enumerate() {
        let alone = integrate_with(&b, &m, z, 0.05, 100, 10).unwrap();
        assert_eq!(bits(&batch.state(&b, i)), bits(&alone.final_state));
        assert_eq!(bits(&outs[i]), bits(&alone.states[3..]));
    }
}

#[test]
fn the_casimir_is_kept_to_round_off_in_lanes() {
    let b = body();
    let all = states(16);
    let trajs = integrate_batch(&b, "splitting", &all, 0.01, 100_000, 100_000, Some(1)).unwrap();
    for (z0, t) in all.iter().zip(&trajs) {
        let c0: f64 = z0.iter().map(|x| x * x).sum();
        let c1: f64 = t.final_state.iter().map(|x| x * x).sum();
        assert!((c1 - c0).abs() <= 2e-12 * c0.max(1e-300), "{c0} → {c1}");
    }
}

#[test]
fn errors_name_the_member_and_the_step() {
    // Member 5 of 300 rotates by an angle beyond the resolvable range (|θ| > 2.25e14) after
    // some steps (M₁ grows beyond 4.5e14 under the pseudo-random rotations), member 250 at once.
    let b = body();
    let mut all = states(300);
    all[5] = vec![3e14, 3e14, 3e14];
    all[250] = vec![4e15, 1.0, 1.0];
    for threads in [1, 2] {
        let e = integrate_batch(&b, "splitting", &all, 1.0, 200, 10, Some(threads)).unwrap_err();
        let alone = integrate(&b, "splitting", &all[5], 1.0, 200, 10).unwrap_err();
        match (&e, &alone) {
            (
                Error::LeftDomain { what, t, message },
                Error::LeftDomain {
                    what: w_alone,
                    t: t_alone,
                    message: m_alone,
                },
            ) => {
                assert_eq!(what, &format!("batch member 5: {w_alone}"));
                assert_eq!(t, t_alone);
                assert_eq!(message, m_alone);
                assert!(message.contains("step"), "{message}");
                assert!(*t > 1.0, "the failure should come after step 1: {message}");
            }
            other => panic!("{other:?}"),
        }
    }
    // The checked state and the step count of a failed member are those of the run alone
    // (members started in blocks without steppers of their own: Batch::start).
    let mut batch = Batch::start(&b, "splitting", &all, 1.0, 10, 0.0).unwrap();
    assert!(batch.in_lanes());
    let mut outs = vec![Vec::new(); all.len()];
    let results = batch.advance(&b, 200, &mut outs);
    let mut alone = Run::new(&b, "splitting", &all[5], 1.0, 10, 0.0).unwrap();
    let mut out = Vec::new();
    let e_alone = alone.advance(&b, 200, &mut out).unwrap_err();
    assert_eq!(
        results[5].as_ref().unwrap_err().to_string(),
        e_alone.to_string()
    );
    assert!(results[250].is_err());
    assert!(results
        .iter()
        .enumerate()
        .all(|(i, r)| r.is_ok() || i == 5 || i == 250));
    let run = &batch.runs()[5];
    assert_eq!(run.steps_done(), alone.steps_done());
    assert_eq!(bits(&run.checked_state(&b)), bits(&alone.checked_state(&b)));
    assert_eq!(bits(&outs[5]), bits(&out));
    assert_eq!(bits(&batch.state(&b, 5)), bits(&alone.state(&b)));
    // The others went on, each as alone.
    let other = integrate(&b, "splitting", &all[7], 1.0, 200, 10).unwrap();
    assert_eq!(bits(&batch.state(&b, 7)), bits(&other.final_state));
    assert_eq!(bits(&outs[7]), bits(&other.states[3..]));
    // Bad input is refused naming the first member that has it.
    let mut bad = states(5);
    bad[3][1] = f64::NAN;
    let (i, e) = Batch::start(&b, "splitting", &bad, 0.1, 1, 0.0)
        .err()
        .unwrap();
    assert_eq!(i, Some(3));
    assert!(matches!(e, Error::NonFinite { .. }), "{e:?}");
    let (_, e) = Batch::start(&b, "splitting9", &bad, 0.1, 1, 0.0)
        .err()
        .unwrap();
    assert!(matches!(e, Error::UnsupportedMethod { .. }), "{e:?}");
}
