//! Instruction counts of fixed workloads, for before/after comparisons on a noisy machine (issue 30):
//! `valgrind --tool=callgrind --callgrind-out-file=/dev/null target/release/examples/instr_count CASE`
//! with CASE one of the match arms below (rb_: the free rigid body, rba_: with attitude, ht_: the
//! heavy top, then the method; rb_call_exact: 2000 calls of one step, the per-call cost).
//! Run it in two worktrees (before, after) and compare the counts: docs/benchmarks.md.
use lieflow::integrate::{integrate, integrate_batch};
use lieflow::systems::{GeneralizedRigidBody, HeavyTop, RigidBody};
use std::hint::black_box;

fn main() {
    let case = std::env::args().nth(1).unwrap();
    let m0 = [1.0, 0.5, -0.3];
    let i3 = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let body = RigidBody::new([1.0, 2.0, 3.0]).unwrap();
    let top = HeavyTop::new([1.0, 2.0, 3.0], 0.7, [0.2, -0.3, 1.0]).unwrap();
    let reps = 20;
    match case.as_str() {
        "rb_splitting" | "rb_exact" | "rb_dmv" | "rb_splitting4" | "rb_lgvi" | "rb_rk4" => {
            let m = &case[3..];
            for _ in 0..reps {
                black_box(integrate(&body, m, &m0, 0.01, 1000, 1000).unwrap());
            }
        }
        "rb_call_exact" => {
            for _ in 0..2000 {
                black_box(integrate(&body, "exact", &m0, 0.01, 1, 1).unwrap());
            }
        }
        "rba_splitting" | "rba_exact" => {
            let l = body.with_attitude();
            let s = l.state_with_attitude(m0, i3);
            for _ in 0..reps {
                black_box(integrate(&l, &case[4..], &s, 0.01, 1000, 1000).unwrap());
            }
        }
        "ht_splitting" | "ht_processed6" | "ht_lgvi" => {
            let s = top.state(m0, [0.0, 0.0, 1.0]);
            for _ in 0..reps {
                black_box(integrate(&top, &case[3..], &s, 0.01, 1000, 1000).unwrap());
            }
        }
        "so4_isospectral" => {
            let b = GeneralizedRigidBody::new(&[1.0, 1.5, 2.5, 3.0]).unwrap();
            let s = vec![0.3, -0.2, 0.5, 0.1, 0.4, -0.6];
            for _ in 0..reps {
                black_box(integrate(&b, "isospectral", &s, 0.01, 200, 200).unwrap());
            }
        }
        "batch_rb" => {
            let states: Vec<Vec<f64>> = (0..1000)
                .map(|k| vec![1.0 + 0.001 * k as f64, 0.5, -0.3])
                .collect();
            black_box(
                integrate_batch(&body, "splitting", &states, 0.01, 200, 200, Some(1)).unwrap(),
            );
        }
        _ => panic!("unknown case"),
    }
}
