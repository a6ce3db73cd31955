"""Work–precision of the free rigid body WITH its attitude at T = 100 (issue 14): every lieflow
method from Python and from Rust, scipy's DOP853 and RK45, and the Strang splitting written as a
Python user would and compiled by numba.

Problem: I = (1, 2, 3), M0 = (1, 0.5, -0.3), R0 = identity, T = 100; the error is the max-norm of
(M(T), R(T)) minus a reference: lieflow's exact flow (`RigidBody.exact_solution(M0, T,
attitude=R0)`) when it exists, cross-checked against DOP853 at rtol = atol = 1e-14 (else that run
is the reference). Python times are the best of repeats of one `lf.integrate` call (saving only
the final state), so they include the per-call overhead; Rust times come from
`benches/examples/rigid_body_work_precision.rs` (whole `integrate` calls, best of repeats).

    pip install numba            # optional: the numba curve
    python benches/python/rigid_body_attitude_work_precision.py [--rust] [--plot FIG.png]
"""

import argparse
import subprocess
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, time_to

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
R0 = np.eye(3)
T = 100.0
ROOT = Path(__file__).resolve().parents[2]


def euler(t, y):
    m, r = y[:3], y[3:].reshape(3, 3)
    om = m / I
    return np.concatenate([np.cross(m, om), (r @ lf.lie.hat(om)).ravel()])


def reference(body):
    y0 = np.concatenate([M0, R0.ravel()])
    dop = solve_ivp(euler, (0, T), y0, method="DOP853", rtol=1e-14, atol=1e-14).y[:, -1]
    try:
        m, r = body.exact_solution(M0, T, attitude=R0)
    except TypeError:
        print("reference: DOP853 at rtol = atol = 1e-14 (no exact flow with attitude)")
        return dop
    exact = np.concatenate([np.asarray(m).ravel(), np.asarray(r).ravel()])
    print(f"reference: the exact flow; DOP853(1e-14) differs by {np.abs(exact - dop).max():.1e}")
    return exact


def numba_strang():
    """lieflow's `splitting` with the attitude, as a Python user would write it, compiled by
    numba (T = ½|M|²/I_r + ½ a_p M_p² + ½ a_q M_q², flows p, q, Casimir, q, p); or None."""
    try:
        from numba import njit
    except ImportError:
        return None

    @njit(fastmath=False)
    def axis(m, r, k, tau, a):
        i, j = (k + 1) % 3, (k + 2) % 3
        angle = tau * a * m[k]
        s, c = np.sin(angle), np.cos(angle)
        mi, mj = m[i], m[j]
        m[i] = c * mi + s * mj
        m[j] = c * mj - s * mi
        for row in range(3):
            ri, rj = r[row, i], r[row, j]
            r[row, i] = ri * c + rj * s
            r[row, j] = rj * c - ri * s

    @njit(fastmath=False)
    def casimir(m, r, tau, inv_ir):
        # R ↦ R exp(τ M̂ / I_r) by Rodrigues, in place, no temporaries
        w0, w1, w2 = m[0] * tau * inv_ir, m[1] * tau * inv_ir, m[2] * tau * inv_ir
        t2 = w0 * w0 + w1 * w1 + w2 * w2
        th = np.sqrt(t2)
        if th < 1e-4:
            a, b = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0), 0.5 - t2 / 24.0 * (1.0 - t2 / 30.0)
        else:
            a, b = np.sin(th) / th, (1.0 - np.cos(th)) / t2
        # e = 1 + a K + b K², K = ŵ
        e00, e11, e22 = 1.0 - b * (w1 * w1 + w2 * w2), 1.0 - b * (w0 * w0 + w2 * w2), \
            1.0 - b * (w0 * w0 + w1 * w1)
        e01, e10 = -a * w2 + b * w0 * w1, a * w2 + b * w0 * w1
        e02, e20 = a * w1 + b * w0 * w2, -a * w1 + b * w0 * w2
        e12, e21 = -a * w0 + b * w1 * w2, a * w0 + b * w1 * w2
        for row in range(3):
            x, y, z = r[row, 0], r[row, 1], r[row, 2]
            r[row, 0] = x * e00 + y * e10 + z * e20
            r[row, 1] = x * e01 + y * e11 + z * e21
            r[row, 2] = x * e02 + y * e12 + z * e22

    @njit(fastmath=False)
    def run(m0, r0, inertia, h, steps):
        m, r = m0.copy(), r0.copy()
        ref = np.argsort(inertia)[1]
        p, q = (ref + 1) % 3, (ref + 2) % 3
        ap, aq = 1.0 / inertia[p] - 1.0 / inertia[ref], 1.0 / inertia[q] - 1.0 / inertia[ref]
        for k in range(steps):
            axis(m, r, p, 0.5 * h, ap)
            axis(m, r, q, 0.5 * h, aq)
            casimir(m, r, h, 1.0 / inertia[ref])
            axis(m, r, q, 0.5 * h, aq)
            axis(m, r, p, 0.5 * h, ap)
        return np.concatenate((m, r.ravel()))

    run(M0, R0, I, 0.1, 2)          # compile outside the timing
    return run


def rust_rows():
    out = subprocess.run(["cargo", "run", "--release", "-q", "-p", "lieflow-benches", "--example",
                          "rigid_body_work_precision"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    rows = []
    for line in out.splitlines()[1:]:
        _, method, steps, sec, err = line.split(",")
        rows.append((f"Rust {method}", int(steps), float(sec), float(err)))
    return rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--rust", action="store_true", help="also run the Rust example")
    parser.add_argument("--plot", default=None, help="save the work-precision figure here")
    args = parser.parse_args()
    print(environment())
    body = lf.RigidBody(inertia=I)
    ref = reference(body)
    rows = []
    for method in ("RK45", "DOP853"):
        for tol in 10.0 ** -np.arange(4, 14):
            sec, sol = best_time(lambda: solve_ivp(euler, (0, T), np.concatenate([M0, R0.ravel()]),
                                                   method=method, rtol=tol, atol=tol * 1e-2),
                                 repeats=2, budget=0.2)
            rows.append((f"scipy {method}", tol, sec, np.abs(sol.y[:, -1] - ref).max()))
    steps_list = [25 * 2**k for k in range(12)]
    for method in body.methods():
        for steps in steps_list:
            try:
                sec, tr = best_time(lambda: lf.integrate(body, M0, dt=T / steps, steps=steps,
                                                         method=method, save_every=steps,
                                                         attitude=R0), budget=0.2)
            except lf.LieflowError:         # a step too large for an iteration
                continue
            z = np.concatenate([tr.final_state, tr.final_attitude.ravel()])
            err = np.abs(z - ref).max()
            rows.append((f"lieflow {method}", steps, sec, err))
            if sec > 0.03 or err < 1e-13:
                break
    run = numba_strang()
    if run is not None:
        for steps in steps_list:
            sec, z = best_time(lambda: run(M0, R0, I, T / steps, steps), budget=0.2)
            rows.append(("numba Strang loop", steps, sec, np.abs(z - ref).max()))
            if sec > 0.03:
                break
    if args.rust:
        rows += rust_rows()

    names = list(dict.fromkeys(r[0] for r in rows))
    print(f"\n{'method':28s} {'setting':>10s} {'time [µs]':>11s} {'error':>9s}")
    for name, setting, sec, err in rows:
        print(f"{name:28s} {setting:>10.3g} {sec * 1e6:11.1f} {err:9.1e}")
    base = {target: time_to([(e, s) for n, _, s, e in rows if n == "scipy DOP853"], target)
            for target in (1e-8, 1e-12)}
    print("\n| method | time to 1e-8 | time to 1e-12 | DOP853 / method at 1e-8 |")
    print("|---|---|---|---|")
    for name in names:
        pts = [(e, s) for n, _, s, e in rows if n == name]
        t8, t12 = time_to(pts, 1e-8), time_to(pts, 1e-12)
        cell = lambda t: "—" if t is None else f"{t * 1e6:.1f} µs"  # noqa: E731
        ratio = f"{base[1e-8] / t8:.0f}×" if t8 and base[1e-8] else "—"
        print(f"| {name} | {cell(t8)} | {cell(t12)} | {ratio} |")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(8, 6))
        # Points with error ≤ 1 (a blown-up run says nothing), in order of cost up to the first
        # that is no better than the one before (round-off: the rest says nothing either); from
        # Rust the best methods only (dashed); `exact` is at round-off at every step size (its
        # cost is in the table).
        rust_shown = ("Rust dmv10", "Rust dmv8", "Rust processed8")
        shown = [n for n in names if (not n.startswith("Rust") or n in rust_shown)
                 and not n.endswith("exact")]
        results = {}
        for n in shown:
            pts = []
            for e, s in sorted(((e, s) for m, _, s, e in rows if m == n and 0 < e <= 1),
                               key=lambda p: p[1]):
                pts.append((e, s))
                if len(pts) > 1 and e >= pts[-2][0]:
                    break
            if pts:
                results[n] = ([e for e, _ in pts], [s for _, s in pts])
        lf.plot.work_precision(results, ax=ax)
        colours = plt.get_cmap("tab20").colors
        for k, line in enumerate(ax.get_lines()):
            line.set_color(colours[k % len(colours)])
            if line.get_label().startswith("Rust"):
                line.set_linestyle("--")
        ax.axvline(1e-8, color="0.6", lw=0.8, ls=":")
        ax.axvline(1e-12, color="0.6", lw=0.8, ls=":")
        ax.set_title("Free rigid body with attitude, T = 100: error vs wall time")
        ax.legend(fontsize=7, ncol=2)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"saved {args.plot}")


if __name__ == "__main__":
    main()
