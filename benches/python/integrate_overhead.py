"""Costs of the Python integration driver around the native steppers (free rigid body,
I = diag(1, 2, 3)):

* per-call overhead of `lf.integrate` (steps = 1), and the exact flow with an attitude through
  `lf.integrate` against `body.exact_solution`, before (the lieflow at BEFORE, a checkout whose
  extension is built) and after (the lieflow imported here), each in a subprocess of this run;
* ns per step of a long single run, in one native call versus the default chunking (Ctrl-C
  checks between chunks);
* batch throughput (10^4 bodies x 10^3 steps, GIL released, rayon) on 1 and 2 threads
  (RAYON_NUM_THREADS, set in a subprocess per measurement).

    python benches/python/integrate_overhead.py [--before /path/to/checkout/python]
"""

import os
import subprocess
import sys

import numpy as np

import lieflow as lf
from timing import best_time

M0 = np.array([1.0, 0.5, -0.3])
BEFORE = "/work/wt-base30/python"

CALLS = {
    "lf.integrate(body, M0, dt=0.1, steps=1)":
        lambda body: lf.integrate(body, M0, dt=0.1, steps=1),
    "body.exact_solution(M0, [100.0])":
        lambda body: body.exact_solution(M0, [100.0]),
    'lf.integrate(body, M0, method="exact", attitude=I, steps=1, dt=100)':
        lambda body: lf.integrate(body, M0, method="exact", attitude=np.eye(3), steps=1, dt=100),
    "body.exact_solution(M0, [100.0], attitude=I)":
        lambda body: body.exact_solution(M0, [100.0], attitude=np.eye(3)),
}


def calls_child():
    """Best time per call (us) of each of CALLS, one line each."""
    body = lf.RigidBody([1.0, 2.0, 3.0])
    for fn in CALLS.values():
        fn(body)
    for fn in CALLS.values():
        print(best_time(lambda: fn(body), 20_000)[0] * 1e6)


def batch_child():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = np.random.default_rng(0).standard_normal((10_000, 3))
    sec = best_time(lambda: lf.integrate(body, m0, dt=0.01, steps=1000, save_every=1000), 3)[0]
    print(sec)


def per_call(pythonpath):
    env = dict(os.environ, PYTHONPATH=pythonpath)
    out = subprocess.run([sys.executable, __file__, "--calls-child"], env=env,
                         capture_output=True, text=True, check=True).stdout
    return [float(v) for v in out.split()]


def main():
    before_path = sys.argv[sys.argv.index("--before") + 1] if "--before" in sys.argv else BEFORE
    here = os.path.dirname(os.path.dirname(lf.__file__))
    # Alternated, three rounds, the best of each: both sides see the same load.
    rounds = [(per_call(before_path), per_call(here)) for _ in range(3)]
    before = [min(r[0][i] for r in rounds) for i in range(len(CALLS))]
    after = [min(r[1][i] for r in rounds) for i in range(len(CALLS))]
    print("| call | before (us) | after (us) |")
    print("|---|---:|---:|")
    for name, b, a in zip(CALLS, before, after):
        print(f"| `{name}` | {b:.2f} | {a:.2f} |")
    print(f"\nexact with attitude / exact_solution with attitude: before {before[2] / before[3]:.2f}x, "
          f"after {after[2] / after[3]:.2f}x\n")
    body = lf.RigidBody([1.0, 2.0, 3.0])
    n = 2_000_000
    one = best_time(lambda: lf.integrate(body, M0, dt=1e-3, steps=n, save_every=n, chunk_steps=n), 3)[0]
    chunked = best_time(lambda: lf.integrate(body, M0, dt=1e-3, steps=n, save_every=n), 3)[0]
    print(f"2e6 steps, one native call:                      {one / n * 1e9:8.2f} ns/step")
    print(f"2e6 steps, default chunks of {sys.modules['lieflow.integrate'].CHUNK_WORK} steps:    "
          f"{chunked / n * 1e9:8.2f} ns/step")
    for threads in (1, 2):
        env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
        out = subprocess.run([sys.executable, __file__, "--batch-child"], env=env,
                             capture_output=True, text=True, check=True).stdout
        sec = float(out)
        print(f"batch 1e4 bodies x 1e3 steps, {threads} thread(s):       {sec * 1e3:8.1f} ms "
              f"({sec / 1e7 * 1e9:.1f} ns per body-step)")
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cpus")


if __name__ == "__main__":
    if "--batch-child" in sys.argv:
        batch_child()
    elif "--calls-child" in sys.argv:
        calls_child()
    else:
        main()
