"""Wall-clock timing and reporting shared by the benchmark scripts in this folder."""

import os
import platform
import time

import numpy as np


def best_time(fn, repeats=3, budget=0.0, max_repeats=500):
    """Best wall time of ``fn()`` over at least ``repeats`` calls, and more while the calls so far
    took less than ``budget`` seconds (at most ``max_repeats``). Returns (seconds, last result)."""
    best, out, spent, n = float("inf"), None, 0.0, 0
    while n < repeats or (spent < budget and n < max_repeats):
        t0 = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t0
        best, spent, n = min(best, dt), spent + dt, n + 1
    return best, out


def environment(**extra):
    """One line naming the versions, the cpus and the load (the head of every benchmark's output);
    ``extra`` adds name=version pairs."""
    import scipy

    import lieflow

    parts = [f"python {platform.python_version()}", f"numpy {np.__version__}",
             f"scipy {scipy.__version__}", f"lieflow {lieflow.__version__}"]
    parts += [f"{k} {v}" for k, v in extra.items()]
    parts += [f"{os.cpu_count()} cpus", f"load average {os.getloadavg()[0]:.2f}"]
    return ", ".join(parts)


def time_to(points, target):
    """Interpolated (log-log) wall time at which a method first reaches error ``target``, from
    its (error, seconds) points, or None: the first pair of points, in order of time, whose
    errors bracket the target (near round-off the errors stop falling, and pairing points by
    error would join runs far apart in time)."""
    pts = sorted((s, e) for e, s in points if e > 0)
    for (s1, e1), (s2, e2) in zip(pts, pts[1:]):
        if e2 <= target < e1:
            w = (np.log(target) - np.log(e1)) / (np.log(e2) - np.log(e1))
            return float(np.exp(np.log(s1) + w * (np.log(s2) - np.log(s1))))
    return None


def print_ratios(points, targets, base="scipy DOP853", width=18):
    """For each target error, the wall time each method needs and the ratio to ``base``:
    ``points`` maps a method's name to its (error, seconds) points."""
    for target in targets:
        ref = time_to(points.get(base, []), target)
        print(f"  wall time to reach error {target:g}:")
        for name, pts in points.items():
            t = time_to(pts, target)
            if t is not None:
                ratio = f"  (DOP853 / this = {ref / t:.1f}x)" if ref else ""
                print(f"    {name:{width}s} {t * 1e3:9.3f} ms{ratio}")
