"""lieflow's Strang splitting against the C loop a programmer would write (issue 28).

The free rigid body I = (1, 2, 3) and the heavy top (mgl = 0.7, chi = (0.2, -0.3, 1)), dt = 0.01,
`method="splitting"`: one body over 2·10⁶ steps, and 10⁴ bodies over 10³ steps with 1 and 2
threads, each with and without the attitude. The C twin (`benches/c/strang_loop.c`: the same
flows, the first and last half flows of consecutive steps fused, the same sin/cos polynomial, the
attitude as a unit quaternion; one body alone, a batch component by component in blocks the
compiler vectorises) is built with the system's C compiler (`cc -O3 -march=native`, with OpenMP
when the compiler has it), and again with `-ffp-contract=off` (no fused multiply-adds: what
they are worth here); without a compiler the C columns are skipped with a message. Times are the best of ROUNDS rounds, C and lieflow alternating; lieflow is one
`lf.integrate` call that saves the last state only. Body 0's final state is compared with the C
loop's (the two round differently: quaternion against matrix), as a check that both compute the
same thing.

    python benches/python/c_loop.py [--rounds 5]

Then the cost of `splitting4` and `processed8` per step, and per stage against the Strang step
(which should be 1: they run the same kernel).
"""

import argparse
import os
import shutil
import subprocess
import tempfile
import time

import numpy as np

import lieflow as lf

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.join(HERE, "..", "c", "strang_loop.c")
DT = 0.01
ONE_STEPS = 2_000_000
BATCH, BATCH_STEPS = 10_000, 1_000


def build(tmp, extra=(), name="strang_loop"):
    """The C loop's executable, or None (with the reason printed) without a C compiler."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        print("no C compiler found (set CC): the C column is skipped")
        return None
    exe = os.path.join(tmp, name)
    for flags in (["-fopenmp", *extra], list(extra)):
        cmd = [cc, "-O3", "-march=native", *flags, SOURCE, "-o", exe, "-lm"]
        if subprocess.run(cmd, capture_output=True).returncode == 0:
            print("built:", " ".join([os.path.basename(cc), *cmd[1:-4], "strang_loop.c"]))
            return exe
    print(f"{cc} could not build {SOURCE}: the C column is skipped")
    return None


def run_c(exe, system, attitude, bodies, steps, threads):
    out = subprocess.run([exe, system, str(int(attitude)), str(bodies), str(steps), str(threads)],
                         capture_output=True, text=True, check=True).stdout.split("\n")
    sec = float(out[0])
    z = np.array(out[1].split(), dtype=float)
    r = np.array(out[2].split(), dtype=float).reshape(3, 3)
    return sec, z, r


def states(system, bodies):
    """The initial states of strang_loop.c: M_k = (1, 0.5, -0.3) + 0.1 sin(...), Gamma = e3."""
    k = np.arange(bodies, dtype=float)
    m = np.stack([1.0 + 0.1 * np.sin(1.3 * k), 0.5 + 0.1 * np.sin(2.1 * k + 0.4),
                  -0.3 + 0.1 * np.sin(0.7 * k + 1.1)], axis=1)
    if system == "heavy":
        m = np.concatenate([m, np.tile([0.0, 0.0, 1.0], (bodies, 1))], axis=1)
    return m[0] if bodies == 1 else m


def run_lieflow(system, attitude, bodies, steps, threads, method="splitting"):
    body = (lf.RigidBody([1, 2, 3]) if system == "rigid"
            else lf.HeavyTop([1, 2, 3], 0.7, chi=[0.2, -0.3, 1.0]))
    z0 = states(system, bodies)
    r0 = np.eye(3) if attitude else None
    t0 = time.perf_counter()
    tr = lf.integrate(body, z0, dt=DT, steps=steps, save_every=steps, attitude=r0,
                      threads=threads, method=method)
    sec = time.perf_counter() - t0
    z = np.asarray(tr.states)
    r = None if tr.attitude is None else np.asarray(tr.attitude)
    if bodies > 1:
        z, r = z[0], (None if r is None else r[0])
    return sec, z[-1], (None if r is None else r[-1])


# (system, attitude, bodies, steps, threads): one body, then batches on 1 and 2 threads.
ROWS = [(system, attitude, bodies, steps, threads)
        for system in ("rigid", "heavy")
        for bodies, steps, threads in ((1, ONE_STEPS, 1), (BATCH, BATCH_STEPS, 1),
                                       (BATCH, BATCH_STEPS, 2))
        for attitude in (False, True)]


def label(system, attitude, bodies, steps, threads):
    name = "rigid body" if system == "rigid" else "heavy top"
    what = "with attitude" if attitude else ("M only" if system == "rigid" else "M, Γ only")
    if bodies == 1:
        return f"{name}, one body, {what}, {steps:.0e} steps"
    return f"{name}, {bodies:.0e} bodies × {steps:.0e} steps, {what}, {threads} thread(s)"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    lf.integrate(lf.RigidBody([1, 2, 3]), [1.0, 0.5, -0.3], dt=DT, steps=10)  # warm-up
    with tempfile.TemporaryDirectory() as tmp:
        exe = build(tmp)
        # The same source without contracting a*b + c into fused multiply-adds (gcc's default
        # for C with -march=native contracts them, as lieflow's kernels fuse them): what FMA is
        # worth on this machine.
        plain = build(tmp, ["-ffp-contract=off"], "strang_loop_plain") if exe else None
        print(f"\nbest of {args.rounds} rounds, C and lieflow alternating; per step and body.\n")
        print("| loop | C | C, no FMA | lieflow | lieflow / C | body 0: max difference |")
        print("|---|---:|---:|---:|---:|---:|")
        for row in ROWS:
            work = row[2] * row[3]
            best_c, best_p, best_l = np.inf, np.inf, np.inf
            for _ in range(args.rounds):
                if exe is not None:
                    sec, zc, rc = run_c(exe, *row)
                    best_c = min(best_c, sec)
                    best_p = min(best_p, run_c(plain, *row)[0])
                sec, zl, rl = run_lieflow(*row)
                best_l = min(best_l, sec)
            ns_l = best_l / work * 1e9
            if exe is None:
                print(f"| {label(*row)} | – | – | {ns_l:.1f} ns | – | – |")
                continue
            d = len(zl)
            diff = np.abs(zc[:d] - zl).max()
            if rl is not None:
                diff = max(diff, np.abs(rc - rl).max())
            ns_c, ns_p = best_c / work * 1e9, best_p / work * 1e9
            print(f"| {label(*row)} | {ns_c:.1f} ns | {ns_p:.1f} ns | {ns_l:.1f} ns "
                  f"| {ns_l / ns_c:.2f} | {diff:.1e} |", flush=True)
    stages(args.rounds)


# The higher-order splittings and their stages (a Strang step each): their cost per stage should
# be the Strang step's.
STAGED = [("splitting", 1), ("splitting4", 5), ("processed8", 13)]


def stages(rounds):
    """Cost per step of the higher-order splittings against the Strang step, per stage."""
    print("\nhigher order, per step and body (and per stage against splitting):\n")
    print("| system | " + " | ".join(f"{m} ({k} stage{'s' * (k > 1)})" for m, k in STAGED) + " |")
    print("|---|" + "---:|" * len(STAGED))
    for system in ("rigid", "heavy"):
        for attitude in (False, True):
            for bodies, steps in ((1, 200_000), (BATCH, 200)):
                ns = [min(run_lieflow(system, attitude, bodies, steps, 1, method=m)[0]
                          for _ in range(rounds)) / (bodies * steps) * 1e9 for m, _ in STAGED]
                cells = [f"{t:.1f} ns" + ("" if k == 1 else f" ({t / ns[0] / k:.2f})")
                         for t, (_, k) in zip(ns, STAGED)]
                name = label(system, attitude, bodies, steps, 1)
                print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
