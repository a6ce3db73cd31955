"""Exact Jacobians of the free rigid body's Lie–Poisson splitting (issue 26): lieflow's
``sensitivity=True`` against ``jax.jacfwd`` of the same discrete map written in JAX.

The JAX step is lieflow's ``splitting`` / ``splitting4`` of a ``RigidBody`` (crates/core:
``systems/tops/top.rs``, ``integrate/methods/composition.rs``): H = ½|M|²/I_r + Σ ½ a_k M_k²
with r the axis of the middle moment, a_k = 1/I_k − 1/I_r for the two other axes k = r + 1,
r + 2 (mod 3). Flow 0 and flow 1 turn M (and the rows of R) about e_k by the angle −τ a_k M_k;
with the attitude a third flow, the Casimir ½|M|²/I_r, turns the rows of R by exp(−τ M̂/I_r)
and leaves M. The Strang step is φ₀(h/2) φ₁(h/2) … φ_last(h) … φ₁(h/2) φ₀(h/2) (flows applied
in this order; without the attitude φ₀(h/2) φ₁(h) φ₀(h/2)); ``splitting4`` composes it with
Suzuki's weights (p, p, 1 − 4p, p, p), p = 1/(4 − 4^{1/3}); adjacent φ₀ are merged and the
last φ₀ of a step fused with the first of the next, as lieflow does. The run is a
``jax.lax.fori_loop`` in float64, jit-compiled; its Jacobian is ``jax.jit(jax.jacfwd(...))``
with respect to (M0, [ξ0,] inertia), ξ0 the left-trivialised attitude direction
(R0 ↦ R0 exp(ξ̂0), lieflow's convention; the output's ξ = (Rᵀ δR)ᵛ). Both sides compute the
same map, so the final states and Jacobians must agree to round-off: the script checks it.
The state is a (blocks, 3) array updated with ``.at[].set``; separate columns, separate scalars
and masked updates (fewer XLA fusions) were tried and were not faster overall.

Timed in one run, interleaved, median of REPEATS: lieflow's plain run, lieflow with
``sensitivity=True`` (state and parameter Jacobians), the jitted JAX run, the jitted JAX
jacfwd (compile times apart). JAX is a benchmark-only dependency, not one of lieflow's:

    pip install "jax[cpu]"
    python benches/python/sensitivity_jax.py

Without JAX the script says so and exits 0.
"""

import statistics
import sys
import time

import numpy as np

import lieflow as lf
from timing import environment

try:
    import jax
    import jax.numpy as jnp
except ImportError:  # benchmark-only dependency
    HAVE_JAX = False
else:
    HAVE_JAX = True

DT = 0.01
STEPS = (10_000, 100_000)
REPEATS = 7
MOMENTS = np.array([1.0, 2.0, 3.0])
M0 = np.array([0.3, -0.8, 1.1])
ATT0 = [0.4, -0.7, 0.3]


def gammas(method):
    """Composition weights of lieflow's ``splitting`` (Strang) and ``splitting4`` (Suzuki)."""
    if method == "splitting":
        return [1.0]
    p = 1.0 / (4.0 - 4.0 ** (1.0 / 3.0))
    return [p, p, 1.0 - 4.0 * p, p, p]


def flatten(weights, n_flows):
    """lieflow's ``flatten``: the Strang steps as (flow, fraction of h), adjacent flows merged."""
    seq = []
    for g in weights:
        stage = [(i, 0.5 * g) for i in range(n_flows - 1)] + [(n_flows - 1, g)]
        stage += [(i, 0.5 * g) for i in reversed(range(n_flows - 1))]
        for i, c in stage:
            if seq and seq[-1][0] == i:
                seq[-1] = (i, seq[-1][1] + c)
            else:
                seq.append((i, c))
    return seq


def cross(a, b):
    return jnp.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                      a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                      a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def make_run(method, attitude, steps, dt):
    """run(M0, R0, inertia) -> (M, R) after ``steps`` steps (R passed through without attitude).
    The reference axis r is fixed from MOMENTS (a discrete choice; the map is smooth in the
    inertia near it)."""
    r = int(np.argsort(MOMENTS, kind="stable")[1])
    axes = [(r + 1) % 3, (r + 2) % 3]
    n_flows = 3 if attitude else 2
    seq = flatten(gammas(method), n_flows)
    (first, c0), cm, inner = seq[0], seq[-1][1], seq[1:-1]

    def flow(i, tau, z, inertia):
        # z: (blocks, 3), block 0 = M, blocks 1..3 = the rows of R.
        if i < 2:
            k = axes[i]
            a = 1.0 / inertia[k] - 1.0 / inertia[r]
            angle = (tau * a) * z[0, k]
            s, cm1 = jnp.sin(angle), -2.0 * jnp.sin(0.5 * angle) ** 2
            ii, jj = (k + 1) % 3, (k + 2) % 3
            vi, vj = z[:, ii], z[:, jj]
            z = z.at[:, ii].set(vi + (cm1 * vi + s * vj))
            return z.at[:, jj].set(vj + (cm1 * vj - s * vi))
        # The Casimir turn exp(−v̂) on the rows of R, v = τ M / I_r (|M| > 0 assumed).
        v = (tau / inertia[r]) * z[0]
        th2 = v @ v
        th = jnp.sqrt(th2)
        A, B = jnp.sin(th) / th, 2.0 * jnp.sin(0.5 * th) ** 2 / th2
        x = z[1:]
        w = cross(v[None, :], x)
        u = cross(v[None, :], w)
        return z.at[1:].set(x + (B * u - A * w))

    def run(m0, r0, inertia):
        z = jnp.concatenate([m0[None, :], r0], axis=0) if attitude else m0[None, :]
        h = dt
        z = flow(first, c0 * h, z, inertia)

        def body(_, z):
            for i, c in inner:
                z = flow(i, c * h, z, inertia)
            return flow(first, (cm + c0) * h, z, inertia)

        z = jax.lax.fori_loop(0, steps - 1, body, z)
        for i, c in inner:
            z = flow(i, c * h, z, inertia)
        z = flow(first, cm * h, z, inertia)
        return z[0], (z[1:] if attitude else r0)

    return run


def make_jacobian(run, attitude):
    """(M0, R0, inertia) -> (J (e, e), Jp (e, 3)) in lieflow's layout: e = 3 (δM) or 6 (δM, ξ)."""
    def hat(x):
        z = jnp.zeros(())
        return jnp.array([[z, -x[2], x[1]], [x[2], z, -x[0]], [-x[1], x[0], z]])

    if not attitude:
        def jac(m0, r0, inertia):
            jm, ji = jax.jacfwd(lambda m, i: run(m, r0, i)[0], argnums=(0, 1))(m0, inertia)
            return jm, ji
        return jac

    def jac(m0, r0, inertia):
        # R0 (1 + ξ̂0) has the first derivative of R0 exp(ξ̂0) at ξ0 = 0 (all jacfwd uses).
        def f(m, xi, i):
            out = run(m, r0 @ (jnp.eye(3) + hat(xi)), i)
            return out, out[1]  # R(T) as aux: from the same pass, no extra primal run
        ((dm_m, dm_x, dm_i), (dr_m, dr_x, dr_i)), rr = jax.jacfwd(
            f, argnums=(0, 1, 2), has_aux=True)(m0, jnp.zeros(3), inertia)

        def xi_of(dr):  # dr (3, 3, k) -> (3, k): ξ = (Rᵀ δR)ᵛ per direction
            w = jnp.einsum("ji,jlk->ilk", rr, dr)
            return jnp.stack([w[2, 1], w[0, 2], w[1, 0]])

        top = jnp.concatenate([dm_m, dm_x], axis=1)
        bottom = jnp.concatenate([xi_of(dr_m), xi_of(dr_x)], axis=1)
        return jnp.concatenate([top, bottom], axis=0), jnp.concatenate([dm_i, xi_of(dr_i)])
    return jac


def compiled(fn, *args):
    """jax.jit(fn) compiled for ``args``, and the seconds the compilation took."""
    t0 = time.perf_counter()
    c = jax.jit(fn).lower(*args).compile()
    return c, time.perf_counter() - t0


def ready(out):
    return jax.tree_util.tree_map(lambda a: a.block_until_ready(), out)


def case(method, attitude, steps):
    body = lf.RigidBody(MOMENTS.tolist())
    R0 = np.asarray(lf.lie.so3_exp(ATT0))
    att = R0 if attitude else None

    def lieflow_run(sensitivity):
        return lf.integrate(body, M0, DT, steps, method=method, attitude=att, save_every=steps,
                            sensitivity=sensitivity)

    run = make_run(method, attitude, steps, DT)
    args = (jnp.asarray(M0), jnp.asarray(R0), jnp.asarray(MOMENTS))
    plain_c, plain_compile = compiled(run, *args)
    jac_c, jac_compile = compiled(make_jacobian(run, attitude), *args)

    # Agreement: the same discrete map on both sides.
    ref = lieflow_run(True)
    m, rr = ready(plain_c(*args))
    J, Jp = ready(jac_c(*args))
    d_state = float(np.max(np.abs(np.asarray(m) - ref.final_state)))
    if attitude:
        d_state = max(d_state, float(np.max(np.abs(np.asarray(rr) - ref.final_attitude))))

    def rel(a, b):
        return float(np.max(np.abs(np.asarray(a) - b)) / np.max(np.abs(b)))

    d_jac, d_par = rel(J, ref.final_jacobian), rel(Jp, ref.final_parameter_jacobian)

    calls = {
        "lieflow plain": lambda: lieflow_run(False),
        "lieflow sens": lambda: lieflow_run(True),
        "JAX plain": lambda: ready(plain_c(*args)),
        "JAX jacfwd": lambda: ready(jac_c(*args)),
    }
    times = {name: [] for name in calls}
    for _ in range(REPEATS):  # interleaved
        for name, fn in calls.items():
            t0 = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - t0)
    med = {name: statistics.median(t) for name, t in times.items()}
    return med, (plain_compile, jac_compile), (d_state, d_jac, d_par)


def main():
    if not HAVE_JAX:
        print("sensitivity_jax.py: JAX is not installed (pip install \"jax[cpu]\"); skipped.")
        return 0
    jax.config.update("jax_enable_x64", True)
    print(environment(jax=jax.__version__, backend=jax.default_backend()))
    print(f"RigidBody({MOMENTS.tolist()}), M0 = {M0.tolist()}, dt = {DT}, median of {REPEATS} "
          f"interleaved calls; k = tangent directions (state + 3 moments)")
    head = (f"{'method':11s} {'attitude':8s} {'k':>2s} {'steps':>6s} {'lf plain':>9s} "
            f"{'lf sens':>9s} {'JAX plain':>9s} {'JAX jac':>9s} {'lf s/p':>7s} {'JAX j/p':>7s} "
            f"{'JAXj/lfs':>8s} {'JAXp/lfp':>8s} {'compile p/j':>12s}")
    print("times in ms")
    print(head)
    agreement = []
    for method in ("splitting", "splitting4"):
        for attitude in (False, True):
            for steps in STEPS:
                med, (cp, cj), diffs = case(method, attitude, steps)
                ms = {k: v * 1e3 for k, v in med.items()}
                k = (6 if attitude else 3) + 3
                print(f"{method:11s} {('yes' if attitude else 'no'):8s} {k:2d} {steps:6d} "
                      f"{ms['lieflow plain']:9.3f} {ms['lieflow sens']:9.3f} "
                      f"{ms['JAX plain']:9.3f} {ms['JAX jacfwd']:9.3f} "
                      f"{ms['lieflow sens'] / ms['lieflow plain']:7.1f} "
                      f"{ms['JAX jacfwd'] / ms['JAX plain']:7.1f} "
                      f"{ms['JAX jacfwd'] / ms['lieflow sens']:8.1f} "
                      f"{ms['JAX plain'] / ms['lieflow plain']:8.1f} "
                      f"{cp:5.2f}/{cj:5.2f} s", flush=True)
                agreement.append((method, attitude, steps) + diffs)
    print("agreement with lieflow (final state: max abs; Jacobians: max abs / max |lieflow's|)")
    print(f"{'method':11s} {'attitude':8s} {'steps':>6s} {'state':>9s} {'d z/d z0':>9s} "
          f"{'d z/d I':>9s}")
    for method, attitude, steps, ds, dj, dp in agreement:
        print(f"{method:11s} {('yes' if attitude else 'no'):8s} {steps:6d} {ds:9.1e} {dj:9.1e} "
              f"{dp:9.1e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
