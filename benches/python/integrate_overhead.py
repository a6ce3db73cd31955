"""Costs of the Python integration driver around the native steppers (free rigid body,
I = diag(1, 2, 3), method "splitting"):

* per-call overhead of `lf.integrate` (steps = 1),
* ns per step of a long single run, in one native call versus the default chunking (Ctrl-C
  checks between chunks),
* batch throughput (10^4 bodies x 10^3 steps, GIL released, rayon) on 1 and 2 threads
  (RAYON_NUM_THREADS, set in a subprocess per measurement).

    python benches/python/integrate_overhead.py
"""

import os
import subprocess
import sys

import numpy as np

import lieflow as lf
from timing import best_time

M0 = np.array([1.0, 0.5, -0.3])


def batch_child():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = np.random.default_rng(0).standard_normal((10_000, 3))
    sec = best_time(lambda: lf.integrate(body, m0, dt=0.01, steps=1000, save_every=1000), 3)[0]
    print(sec)


def main():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    sec = best_time(lambda: lf.integrate(body, M0, dt=0.01, steps=1), 2000)[0]
    print(f"lf.integrate per-call overhead (steps=1):        {sec * 1e6:8.2f} us")
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
    batch_child() if "--batch-child" in sys.argv else main()
