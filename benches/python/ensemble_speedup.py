"""Speed-up of lieflow.ensemble: a 10^5-member rigid-body ensemble (I = diag(1, 2, 3), random M,
1000 Strang steps of dt = 0.01, only the initial and the final state kept) computed

* in one process on one thread: ``lf.integrate(..., threads=1)`` (the baseline),
* by ``lf.integrate(..., threads=2)`` (rayon inside one native call; for reference),
* by ``lf.ensemble.integrate`` on Dask's threaded scheduler (the default without a client),
* by ``lf.ensemble.integrate`` on a ``dask.distributed.LocalCluster`` of 2 worker processes x 1
  thread (start-up of the cluster reported apart, not in the run time),

with the default chunking (about 4 tasks per core: 8 tasks of 12,500 members). Every result is
checked bit for bit against the baseline. Wall times are the best of ``REPEATS`` rounds; the cold
first run on the cluster (workers import lieflow) is reported too.

    python benches/python/ensemble_speedup.py
"""

import os
import time

import numpy as np

import lieflow as lf
from timing import best_time, environment

B, STEPS, DT = 100_000, 1000, 0.01
REPEATS = int(os.environ.get("REPEATS", "3"))


def main():
    import dask
    import distributed
    import xarray

    print(environment(dask=dask.__version__, distributed=distributed.__version__,
                      xarray=xarray.__version__))
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = np.random.default_rng(0).standard_normal((B, 3))
    print(f"ensemble: {B} rigid bodies x {STEPS} steps (splitting, dt = {DT}), save_every = "
          f"{STEPS}; best of {REPEATS}")

    def batch(threads):
        return lf.integrate(body, m0, dt=DT, steps=STEPS, save_every=STEPS, threads=threads)

    def ensemble():
        return lf.ensemble.integrate(body, m0, DT, STEPS, save_every=STEPS).compute()

    def same(ds, ref):
        return (np.array_equal(ds.states.values, ref.states)
                and np.array_equal(ds.final_state.values, ref.final_state)
                and np.array_equal(ds.energy.values, ref.energy()))

    steal0 = _steal()
    ref = batch(1)
    build, ds = best_time(lambda: lf.ensemble.integrate(body, m0, DT, STEPS, save_every=STEPS),
                          REPEATS)
    chunks = ds.states.data.chunks[0]

    t = time.perf_counter()
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster, set_as_default=False)
    client.wait_for_workers(2)
    startup = time.perf_counter() - t
    best = {k: float("inf") for k in ("one", "two", "threaded", "dist")}
    try:
        with client.as_current():
            t = time.perf_counter()
            out = ensemble()
            cold = time.perf_counter() - t
        assert same(out, ref)
        # Rounds that alternate the four ways, so that load from elsewhere hits them alike.
        for _ in range(REPEATS):
            for key, fn in (("one", lambda: batch(1)), ("two", lambda: batch(2)),
                            ("threaded", ensemble), ("dist", ensemble)):
                t = time.perf_counter()
                if key == "dist":
                    with client.as_current():
                        out = fn()
                else:
                    out = fn()
                best[key] = min(best[key], time.perf_counter() - t)
                ok = (np.array_equal(out.states, ref.states) if key in ("one", "two")
                      else same(out, ref))
                assert ok, key
    finally:
        client.close()
        cluster.close()
    one, two, threaded, dist = best["one"], best["two"], best["threaded"], best["dist"]

    rows = [("lf.integrate, threads=1 (one process, one thread)", one),
            ("lf.integrate, threads=2 (rayon, for reference)", two),
            ("lf.ensemble, threaded scheduler (default, 2 threads)", threaded),
            ("lf.ensemble, LocalCluster 2 processes x 1 thread", dist),
            ("  the same, first run on fresh workers", cold)]
    print(f"tasks: {len(chunks)} of {chunks[0]} members; the driver's checks and the lazy "
          f"Dataset: {build * 1e3:.0f} ms (included in the ensemble times)")
    print(f"LocalCluster(n_workers=2, threads_per_worker=1) start-up: {startup:.2f} s "
          f"(not included)")
    print(f"{'':54s} {'wall':>8s} {'speed-up':>9s}")
    for name, sec in rows:
        print(f"{name:54s} {sec:7.3f}s {one / sec:8.2f}x")
    print("all results equal lf.integrate(threads=1) bit for bit")
    print(f"load average after: {os.getloadavg()[0]:.2f}; CPU time stolen by the host during "
          f"the run: {_steal() - steal0:.1f} s")


def _steal():
    """Seconds of CPU time stolen from this VM by its host (all cpus), from /proc/stat."""
    try:
        with open("/proc/stat") as f:
            fields = f.readline().split()
        return int(fields[8]) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return float("nan")


if __name__ == "__main__":
    main()
