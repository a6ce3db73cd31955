"""so_exp from Python against scipy.linalg.expm on the same inputs.

Run: python benches/python/bench_so_exp.py [--quick]
     python benches/python/bench_so_exp.py --processes 10     # steadiness of single n = 50 calls

For n = 3 and n = 50: one call, and a batch (10⁴ for n = 3; 10³ for n = 50, where 10⁴ inputs
would be 200 MB of input and output and minutes of scipy time). scipy is timed as a Python loop
over expm and as one call of expm on the stacked (b, n, n) array (supported since scipy 1.9).
Prints a Markdown table of the best-of-k wall times. With --processes K: K fresh processes, each
timing 300 single n = 50 calls of both on one input (the median and the 90th percentile per
process), which is where single calls used to be unsteady (52 µs in one process, 400 µs in
another).
"""

import argparse
import os
import subprocess
import sys
import time

import numpy as np
import scipy
import scipy.linalg

import lieflow as lf
from timing import best_time


def skew_batch(b, n, rng):
    a = rng.normal(size=(b, n, n))
    xi = a - np.swapaxes(a, 1, 2)
    norms = np.sqrt(0.5 * np.einsum("bij,bij->b", xi, xi))
    return xi * (1.5 / norms)[:, None, None]


def fmt(t):
    return f"{t * 1e6:.1f} µs" if t < 1e-3 else f"{t * 1e3:.2f} ms"


def one_process():
    """300 single n = 50 calls of so_exp and of expm in this process: the median and the 90th
    percentile of each, in µs, on one line."""
    x = skew_batch(1, 50, np.random.default_rng(0))[0]
    out = []
    for f in (lf.lie.so_exp, scipy.linalg.expm):
        f(x)
        ts = []
        for _ in range(300):
            t0 = time.perf_counter()
            f(x)
            ts.append(time.perf_counter() - t0)
        out += [np.median(ts) * 1e6, np.percentile(ts, 90) * 1e6]
    print(" ".join(f"{v:.1f}" for v in out))


def processes(k):
    print(f"lieflow {lf.__version__}, load average {os.getloadavg()[0]:.2f}, {k} processes\n")
    print("| process | so_exp median | so_exp p90 | expm median | expm p90 |")
    print("|---|---|---|---|---|")
    rows = []
    for i in range(k):
        line = subprocess.run([sys.executable, __file__, "--one-process"], check=True,
                              capture_output=True, text=True).stdout.split()
        rows.append([float(v) for v in line])
        print(f"| {i + 1} | " + " | ".join(f"{v:.1f} µs" for v in rows[-1]) + " |")
    r = np.array(rows)
    print(f"\nso_exp medians {r[:, 0].min():.1f}–{r[:, 0].max():.1f} µs, "
          f"expm medians {r[:, 2].min():.1f}–{r[:, 2].max():.1f} µs")


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--quick", action="store_true", help="fewer repeats and smaller batches")
    p.add_argument("--processes", type=int, default=0, help="steadiness over K processes")
    p.add_argument("--one-process", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.one_process:
        return one_process()
    if args.processes:
        return processes(args.processes)
    rng = np.random.default_rng(0)
    cases = [(3, 1), (3, 10_000), (50, 1), (50, 1_000)]
    if args.quick:
        cases = [(3, 1), (3, 1_000), (50, 1), (50, 100)]
    print(f"lieflow {lf.__version__}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"{os.cpu_count()} CPUs")
    print()
    print("| n | batch | lieflow so_exp | scipy expm loop | scipy expm stacked | "
          "speed-up vs loop | speed-up vs stacked |")
    print("|---|---|---|---|---|---|---|")
    for n, b in cases:
        xs = skew_batch(b, n, rng)
        repeat = 3 if b > 1 else 200
        if args.quick:
            repeat = max(1, repeat // 10)
        if b == 1:
            x = xs[0]
            t_lf = best_time(lambda: lf.lie.so_exp(x), repeat)[0]
            t_loop = best_time(lambda: scipy.linalg.expm(x), repeat)[0]
            t_stack = t_loop
            np.testing.assert_allclose(lf.lie.so_exp(x), scipy.linalg.expm(x), atol=1e-12)
        else:
            t_lf = best_time(lambda: lf.lie.so_exp(xs), repeat)[0]
            t_loop = best_time(lambda: [scipy.linalg.expm(x) for x in xs], repeat)[0]
            t_stack = best_time(lambda: scipy.linalg.expm(xs), repeat)[0]
            np.testing.assert_allclose(lf.lie.so_exp(xs), scipy.linalg.expm(xs), atol=1e-12)
        print(f"| {n} | {b} | {fmt(t_lf)} | {fmt(t_loop)} | {fmt(t_stack)} | "
              f"{t_loop / t_lf:.1f}× | {t_stack / t_lf:.1f}× |")


if __name__ == "__main__":
    main()
