"""Batch throughput of the free rigid body's Strang splitting in SIMD lanes (issue 14):
`lf.integrate(lf.RigidBody([1, 2, 3]), M, dt=0.01, steps=1000, save_every=1000, threads=t)`
with M of shape (10^4, 3) from a standard normal, t = 1 and 2 alternating in each of 7 rounds
(best of the rounds), and the native stepping alone (one `advance(1000)` of a started run), so
that the part around the stepping (set-up, output) shows.

    python benches/python/batch_lanes.py
"""

import time

import numpy as np

import lieflow as lf

ROUNDS = 7


def main():
    body = lf.RigidBody([1, 2, 3])
    m = np.random.default_rng(0).standard_normal((10_000, 3))
    lf.integrate(body, m[:10], dt=0.01, steps=10, save_every=10)  # warm-up
    whole, stepping = {1: np.inf, 2: np.inf}, {1: np.inf, 2: np.inf}
    z, _ = body._normalize_state(m)
    for _ in range(ROUNDS):
        for t in (1, 2):
            t0 = time.perf_counter()
            lf.integrate(body, m, dt=0.01, steps=1000, save_every=1000, threads=t)
            whole[t] = min(whole[t], time.perf_counter() - t0)
            run = body._start(z, None, 0.01, "splitting", 1000, t0=0.0, threads=t, steps=1000)
            t0 = time.perf_counter()
            run.advance(1000)
            stepping[t] = min(stepping[t], time.perf_counter() - t0)
    print("| threads | lf.integrate | per body-step | native advance(1000) alone |")
    print("|---|---|---|---|")
    for t in (1, 2):
        print(f"| {t} | {whole[t] * 1e3:.1f} ms | {whole[t] / 1e7 * 1e9:.2f} ns "
              f"| {stepping[t] * 1e3:.1f} ms |")
    print(f"speed-up 1 -> 2 threads: lf.integrate {whole[1] / whole[2]:.2f}x, "
          f"stepping {stepping[1] / stepping[2]:.2f}x")


if __name__ == "__main__":
    main()
