"""lieflow against what users would otherwise pick, side by side in one process and one run.

1. SO(3) exp and log of a batch of 10⁴ rotation vectors / matrices: lieflow (`lf.lie.so3_exp`,
   `so3_log`, batched), scipy (`Rotation.from_rotvec(...).as_matrix()`, `as_rotvec()`), jaxlie
   (`jax.jit(jax.vmap(SO3.exp))`, compiled before timing), sophuspy and spatialmath-python (one
   call per element: neither has a batch exp). Every result is checked against lieflow's.
2. A batch of 10⁴ free rigid bodies × 10³ Strang steps (M only, one thread): lieflow's batch
   against the best loop a Python user could write: the same Strang splitting (two axis
   rotations per step, half steps fused) compiled by numba (`@njit(fastmath=False)`), checked to
   agree with lieflow's `splitting` to round-off.

Install the peers into the benchmark environment first:

    pip install numba jaxlie spatialmath-python
    python -m venv /tmp/sophusenv && /tmp/sophusenv/bin/pip install "numpy<2" sophuspy
    SOPHUS_PYTHON=/tmp/sophusenv/bin/python python benches/python/peers.py [--quick]

(sophuspy's wheels crash under numpy 2: it runs in that interpreter, on the same data, timed
there.)

Times are the best of several repeats (`timing.best_time`); ratios are peer time / lieflow time
(> 1: lieflow faster).
"""

import argparse
import os

os.environ.setdefault("JAX_PLATFORMS", "cpu")
os.environ.setdefault("XLA_FLAGS", "--xla_force_host_platform_device_count=1")

import numpy as np  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

import lieflow as lf  # noqa: E402
from timing import best_time, environment  # noqa: E402


def versions():
    out = {}
    for name in ("numba", "jax", "jaxlie", "spatialmath"):
        try:
            mod = __import__(name)
            out[name] = getattr(mod, "__version__", "?")
        except ImportError:
            out[name] = "absent"
    return out


def so3_peers(n, rng):
    """Rows (operation, tool, seconds, max deviation from lieflow)."""
    v = rng.standard_normal((n, 3)) * 1.2
    ours_exp = np.asarray(lf.lie.so3_exp(v))
    ours_log = np.asarray(lf.lie.so3_log(ours_exp))
    rows = []

    def add(op, tool, fn, check, repeats=5, budget=0.5):
        sec, out = best_time(fn, repeats=repeats, budget=budget)
        rows.append((op, tool, sec, float(np.max(np.abs(np.asarray(out) - check)))))

    add("exp", "lieflow", lambda: lf.lie.so3_exp(v), ours_exp)
    add("exp", "scipy Rotation", lambda: Rotation.from_rotvec(v).as_matrix(), ours_exp)
    add("log", "lieflow", lambda: lf.lie.so3_log(ours_exp), ours_log)
    add("log", "scipy Rotation", lambda: Rotation.from_matrix(ours_exp).as_rotvec(), ours_log)
    try:
        import jax
        import jax.numpy as jnp
        import jaxlie

        jax.config.update("jax_enable_x64", True)
        jexp = jax.jit(jax.vmap(lambda w: jaxlie.SO3.exp(w).as_matrix()))
        jlog = jax.jit(jax.vmap(lambda r: jaxlie.SO3.from_matrix(r).log()))
        vj, rj = jnp.asarray(v), jnp.asarray(ours_exp)
        jexp(vj).block_until_ready()
        jlog(rj).block_until_ready()
        add("exp", "jaxlie (jit, vmap)", lambda: np.asarray(jexp(vj).block_until_ready()),
            ours_exp)
        add("log", "jaxlie (jit, vmap)", lambda: np.asarray(jlog(rj).block_until_ready()),
            ours_log)
    except ImportError:
        pass
    rows += sophus_rows(v, ours_exp, ours_log)
    try:
        from spatialmath import SO3

        m = min(n, 2000)   # pure Python per element: a smaller batch, time scaled to n
        scale = n / m
        sec, out = best_time(lambda: np.stack([SO3.Exp(w).A for w in v[:m]]), repeats=2)
        rows.append(("exp", f"spatialmath (loop, {m} scaled)", sec * scale,
                     float(np.max(np.abs(out - ours_exp[:m])))))
        sec, out = best_time(lambda: np.stack([SO3(r, check=False).log(twist=True)
                                               for r in ours_exp[:m]]), repeats=2)
        rows.append(("log", f"spatialmath (loop, {m} scaled)", sec * scale,
                     float(np.max(np.abs(out - ours_log[:m])))))
    except ImportError:
        pass
    return rows


SOPHUS_SCRIPT = """
import sys, time, numpy as np, sophuspy as sp
d = np.load(sys.argv[1])
v, r = d["v"], d["r"]
def best(fn, k=2):
    t = []
    for _ in range(k):
        t0 = time.perf_counter(); out = fn(); t.append(time.perf_counter() - t0)
    return min(t), out
te, e = best(lambda: np.stack([sp.SO3.exp(w).matrix() for w in v]))
tl, l = best(lambda: np.stack([sp.SO3(x).log() for x in r]))
np.savez(sys.argv[2], te=te, tl=tl, e=e, l=l)
"""


def sophus_rows(v, ours_exp, ours_log):
    """sophuspy's exp and log, one call per element. The sophuspy wheels are built against
    numpy 1 and crash under numpy 2, so with numpy >= 2 they run in a subprocess of the
    interpreter named by $SOPHUS_PYTHON (one with numpy < 2 and sophuspy), on the same data."""
    import subprocess
    import sys
    import tempfile

    python = os.environ.get("SOPHUS_PYTHON")
    if python is None and int(np.__version__.split(".")[0]) < 2:
        python = sys.executable
    if python is None:
        print("(sophuspy skipped: set SOPHUS_PYTHON to a python with numpy<2 and sophuspy)")
        return []
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.npz")
        np.savez(src, v=v, r=ours_exp)
        subprocess.run([python, "-c", SOPHUS_SCRIPT, src, dst], check=True)
        d = np.load(dst)
        return [("exp", "sophuspy (loop)", float(d["te"]),
                 float(np.max(np.abs(d["e"] - ours_exp)))),
                ("log", "sophuspy (loop)", float(d["tl"]),
                 float(np.max(np.abs(d["l"] - ours_log))))]


def numba_strang():
    """lieflow's Strang splitting of the free rigid body written as a Python user would, compiled
    by numba: T = ½|M|²/I_r + ½ a_p M_p² + ½ a_q M_q² (I_r the middle moment, a_k = 1/I_k −
    1/I_r; the first piece does not move M), the half steps of consecutive steps fused, so
    two sin/cos per step, as lieflow does; or None without numba."""
    try:
        from numba import njit
    except ImportError:
        return None

    @njit(cache=False, fastmath=False)
    def rotate(m, k, angle):
        # the exact flow of ½ a_k M_k²: M turns about e_k (Ṁ_j = w M_l, Ṁ_l = −w M_j)
        j, l = (k + 1) % 3, (k + 2) % 3
        c, s = np.cos(angle), np.sin(angle)
        mj, ml = m[j], m[l]
        m[j] = c * mj + s * ml
        m[l] = -s * mj + c * ml

    @njit(cache=False, fastmath=False)
    def run(ms, inertia, h, steps):
        r = np.argsort(inertia)[1]
        p, q = (r + 1) % 3, (r + 2) % 3        # lieflow's order: p outer, q inner
        ap, aq = 1.0 / inertia[p] - 1.0 / inertia[r], 1.0 / inertia[q] - 1.0 / inertia[r]
        out = ms.copy()
        for b in range(out.shape[0]):
            m = out[b]
            rotate(m, p, 0.5 * h * ap * m[p])
            for k in range(steps):
                rotate(m, q, h * aq * m[q])
                rotate(m, p, (0.5 if k == steps - 1 else 1.0) * h * ap * m[p])
        return out

    return run


def batch_peers(bodies, steps, rng):
    inertia = np.array([1.0, 2.0, 3.0])
    body = lf.RigidBody(inertia)
    m0 = rng.standard_normal((bodies, 3))
    dt = 0.01
    sec, tr = best_time(lambda: lf.integrate(body, m0, dt=dt, steps=steps, save_every=steps,
                                             threads=1), repeats=3)
    ours = np.asarray(tr.final_state)
    rows = [("batch Strang, 1 thread", "lieflow splitting", sec, 0.0)]
    run = numba_strang()
    if run is not None:
        run(m0[:2], inertia, dt, 2)       # compile outside the timing
        sec, out = best_time(lambda: run(m0, inertia, dt, steps), repeats=3)
        rows.append(("batch Strang, 1 thread", "numba (same Strang loop)", sec,
                     float(np.max(np.abs(out - ours)))))
    return rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    print(environment(**versions()))
    n = 2000 if args.quick else 10_000
    bodies, steps = (1000, 200) if args.quick else (10_000, 1000)
    rows = so3_peers(n, rng) + batch_peers(bodies, steps, rng)
    base = {op: sec for op, tool, sec, _ in rows if tool.startswith("lieflow")}
    print(f"\nSO(3) batches of {n}; rigid bodies: {bodies} x {steps} steps")
    print(f"| operation | tool | time | per item | max deviation from lieflow | "
          f"peer time / lieflow time |")
    print("|---|---|---|---|---|---|")
    for op, tool, sec, dev in rows:
        items = bodies * steps if op.startswith("batch") else n
        per = sec / items * 1e9
        ratio = "1" if tool.startswith("lieflow") else f"{sec / base[op]:.1f}"
        print(f"| {op} | {tool} | {sec * 1e3:.2f} ms | {per:.1f} ns | {dev:.1e} | {ratio} |")


if __name__ == "__main__":
    main()
