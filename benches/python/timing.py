"""Wall-clock timing shared by the benchmark scripts in this folder."""

import time


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
