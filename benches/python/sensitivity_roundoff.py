"""Round-off in the Jacobians of long sensitivity runs (issue 26): does it random-walk, or drift?

A. The free rigid body with `exact` (I = 1, 2, 3, M0 = (0.3, -0.8, 1.1), dt = 0.1).
   A1. The lifted run of N steps against one jump of length N·dt: `exact`'s tangent stepper
       evaluates the closed form at t = N·dt from the state its run started from (it composes
       nothing), so the two agree bit for bit and nothing accumulates with N.
   A2. The same Jacobian composed step by step, as a composing method would: N one-step runs
       chained by the chain rule (J ← Dφ_dt(z_n) J, ∂z/∂I ← Dφ_dt ∂z/∂I + ∂φ_dt/∂I), against the
       one jump. The exact flow's Jacobian grows linearly in t (the shear of the phase), and a
       random walk of the round-off in the conserved quantities gives a phase error like
       ε N^1.5 (Brouwer's law), hence a relative error of J like ε N^1.5 as well; a linear drift
       would give N^2. Also the structure the exact flow keeps whatever the phase: the Casimir
       and the energy pulled back, ∇C(z_N)ᵀ J_N = ∇C(z_0)ᵀ for C = |M|²/2 and C = H (relative to
       |∇C(z_N)| |J_N|), for the chain and for the jump. Then the chain's drift traced to its
       cause: one evaluation of the elliptic formula M = (σa₁ cn u, a₂ sn u, εa₃ dn u) from a
       fresh M₀, |M(t)|² against |M₀|² over many M₀ on the orbit (a mean away from 0 is a bias
       per evaluation, which composed evaluations add up linearly; M(t) is evaluated relative to
       its base point, so M(0) = M₀ bit for bit).
   A3. The closed form alone at large t: J(t) against J(t/2 at z(t/2)) · J(t/2), t up to 1e7.
B. Symplectic Verlet on the pseudo-rigid body (n = 3, canonical (X, P), Ω the standard form):
   ‖JᵀΩJ − Ω‖_max along one run (dt = 0.05), for a harmonic potential (10⁷ steps; linear
   flow, ‖J‖ bounded: a random walk gives √N, a bias N) and for SVK + volumetric (10⁶ steps
   of a regular motion near X = I, ‖J‖ ~ N; it turns chaotic before 10⁷, ‖J‖ ~ 1e12): each
   step's rounding δ_k enters the defect as J_kᵀΩδ_kJ_k, so a random walk gives
   ε(Σ‖J_k‖⁴)^½ ~ N^2.5 and a bias N^3. One run's slope is a noisy
   measure of a random walk (its value wanders over decades), so each case ends with an
   ensemble: the same run with dt moved by 1e-13…3e-12 relative.
C. The heavy top's splitting (a Lagrange top I = (1, 1, 2), χ = e₃, integrable, dt = 0.05,
   10⁷ steps): the Lie–Poisson analogue J B(z₀) Jᵀ = B(z_N) and the Casimirs |Γ|², M·Γ
   pulled back, ∇C(z_N)ᵀJ = ∇C(z₀)ᵀ. The pull-back identities see step k's rounding δJ_k of
   the Jacobian as ∇C(z_k)ᵀδJ_k (~ε k: a random walk gives N^1.5, a bias N^2), but the
   push-forward J B(z₀) Jᵀ sees it amplified by the rest of the run on both sides,
   D_{N←k} δJ_k B(z₀) J_Nᵀ ~ ε k (N − k) N: a random walk gives N^3.5, a bias N^4. Which
   one it is shows directly: the same run with dt moved by 1e-13…3e-12 relative (other
   roundings, the same motion) flips the defect's sign when it is a random walk, not when it
   is a bias.

Slopes are least-squares fits of log10(defect envelope) on log10(N) over the decades up to the
end (the envelope: the largest defect so far, so that a random walk's returns towards 0 do not
hide its size).

    python benches/python/sensitivity_roundoff.py [--quick]
"""

import sys
import time

import numpy as np

import lieflow as lf
from timing import environment

QUICK = "--quick" in sys.argv
EPS = np.finfo(float).eps


def slope(ns, values):
    """The least-squares slope of log10(values) on log10(ns), over values > 0."""
    ns, values = np.asarray(ns, float), np.asarray(values, float)
    ok = values > 0
    return np.polyfit(np.log10(ns[ok]), np.log10(values[ok]), 1)[0]


def envelope(values):
    return np.maximum.accumulate(np.asarray(values, float))


def rigid_body_exact():
    I = np.array([1.0, 2.0, 3.0])
    rb = lf.RigidBody(I)
    z0 = np.array([0.3, -0.8, 1.1])
    dt = 0.1

    print("A1. exact: the lifted run of N steps against one jump of N·dt")
    for n in [10**3, 10**5, 10**7]:
        run = lf.integrate(rb, z0, dt, n, method="exact", save_every=n, sensitivity=True)
        jump = lf.integrate(rb, z0, dt * n, 1, method="exact", sensitivity=True)
        same = (np.array_equal(run.final_jacobian, jump.final_jacobian)
                and np.array_equal(run.final_parameter_jacobian, jump.final_parameter_jacobian))
        print(f"   N = {n:8d}  |J| = {np.abs(jump.final_jacobian).max():9.3e}  "
              f"bit for bit: {same}")

    def pulled_back(z, J):
        """max over C in (|M|²/2, H) of |∇C(z)ᵀJ − ∇C(z0)ᵀ| / (|∇C(z)| |J|)."""
        worst = 0.0
        for grad in (lambda m: m, lambda m: m / I):
            g, g0 = grad(z), grad(z0)
            worst = max(worst, np.abs(g @ J - g0).max()
                        / (np.abs(g).max() * np.abs(J).max()))
        return worst

    top = 10**5 if QUICK else 10**6
    print(f"A2. exact composed step by step (N one-step runs, chain rule) against one jump, "
          f"dt = {dt}")
    print(f"   {'N':>8s} {'|J|':>9s} {'rel. err J':>10s} {'rel. err dz/dI':>14s} "
          f"{'state err':>9s} {'|M|² err':>9s} {'C pulled back: chain':>20s} {'jump':>9s}")
    z, J = z0.copy(), np.eye(3)
    P = np.zeros((3, 3))
    marks = {int(10 ** (k / 2)) for k in range(2, 2 * int(np.log10(top)) + 1)}
    rows = []
    t_start = time.time()
    for n in range(1, top + 1):
        step = lf.integrate(rb, z, dt, 1, method="exact", sensitivity=True)
        z = step.final_state
        J = step.final_jacobian @ J
        P = step.final_jacobian @ P + step.final_parameter_jacobian
        if n in marks:
            jump = lf.integrate(rb, z0, dt * n, 1, method="exact", sensitivity=True)
            Jj, Pj = jump.final_jacobian, jump.final_parameter_jacobian
            err = np.abs(J - Jj).max() / np.abs(Jj).max()
            perr = np.abs(P - Pj).max() / np.abs(Pj).max()
            zerr = np.abs(z - jump.final_state).max() / np.abs(z0).max()
            rows.append((n, err, perr, zerr, pulled_back(z, J), pulled_back(jump.final_state, Jj)))
            drift = (z @ z - z0 @ z0) / (z0 @ z0)
            print(f"   {n:8d} {np.abs(Jj).max():9.3e} {err:10.2e} {perr:14.2e} {zerr:9.2e} "
                  f"{drift:9.1e} {rows[-1][4]:20.2e} {rows[-1][5]:9.2e}")
    table = np.array(rows)
    tail = table[:, 0] >= 100

    def fit(column):
        return slope(table[tail, 0], envelope(table[:, column])[tail])

    print(f"   slopes over N ≥ 100: J {fit(1):.2f}, dz/dI {fit(2):.2f}, state {fit(3):.2f}, "
          f"C pulled back (chain) {fit(4):.2f} (random walk 1.5, 1.5, 1.5, 0.5; a bias 2, 2, 2, 1)"
          f" ({time.time() - t_start:.0f} s)")

    # The cause of the chain's N² (module docs): one evaluation of the elliptic formula of M.
    rng = np.random.default_rng(0)
    on_orbit = np.array([rb.exact_solution(z0, t) for t in rng.uniform(0, 100, 20000)])
    for t in (0.0, dt):
        after = np.array([rb.exact_solution(m, t) for m in on_orbit])
        rel = (np.sum(after**2, 1) - np.sum(on_orbit**2, 1)) / (z0 @ z0) / EPS
        exact = np.mean(np.all(after == on_orbit, 1)) * 100
        print(f"   one evaluation of M(t) at t = {t}: |M(t)|²/|M0|² − 1 = ({rel.mean():+.2f} ± "
              f"{rel.std():.2f}) ε (mean ± std over 20000 M0 on the orbit)"
              + (f"; M(0) = M0 bit for bit for {exact:.0f}%" if t == 0 else ""))

    print("A3. exact: J(t) against J(t/2 at z(t/2)) J(t/2) (the closed form's own round-off)")
    for t in [1e1, 1e3, 1e5, 1e7]:
        one = lf.integrate(rb, z0, t, 1, method="exact", sensitivity=True)
        half = lf.integrate(rb, z0, t / 2, 1, method="exact", sensitivity=True)
        rest = lf.integrate(rb, half.final_state, t / 2, 1, method="exact", sensitivity=True)
        J2 = rest.final_jacobian @ half.final_jacobian
        err = np.abs(J2 - one.final_jacobian).max() / np.abs(one.final_jacobian).max()
        print(f"   t = {t:7.0e}  |J| = {np.abs(one.final_jacobian).max():9.3e}  "
              f"rel. difference {err:9.2e}  (ε·t = {EPS * t:8.1e})")


def defects_along(system, z0, method, dt, n, samples, defect):
    """One lifted run of n steps, the defect after ~`samples` log-spaced step counts (saved
    with t_eval at grid times: the grid states themselves, bit for bit); (step counts, defects,
    states, Jacobians, seconds)."""
    t = time.time()
    steps = np.unique(np.concatenate([np.round(np.logspace(0, np.log10(n), samples)),
                                      10 ** np.arange(int(np.log10(n)) + 1)]).astype(int))
    traj = lf.integrate(system, z0, dt, n, method=method, t_eval=steps * dt, sensitivity=True)
    values = [defect(traj.states[k], traj.jacobian[k]) for k in range(len(steps))]
    return steps, np.array(values), traj.states, traj.jacobian, time.time() - t


SHIFTS = (0.0, 1e-13, 3e-13, 1e-12, 3e-12)


def ensemble(system, z0, method, dt, n, *defects):
    """The same run of n steps with dt·(1 + r), r in SHIFTS (other roundings, the same motion
    to 3e-12·N·dt in time): for each `defect(state, J)` (an array), its signed entry where the
    first run's is largest, in each run. A random walk's values scatter around 0 with both
    signs; a bias keeps one sign and one size."""
    ends = [(t.final_state, t.final_jacobian) for t in
            (lf.integrate(system, z0, dt * (1 + r), n, method=method, save_every=n,
                          sensitivity=True) for r in SHIFTS)]
    out = []
    for defect in defects:
        values = [defect(z, J) for z, J in ends]
        at = np.unravel_index(np.abs(values[0]).argmax(), values[0].shape)
        out.append([v[at] for v in values])
    return out


def pseudo_rigid_verlet():
    A = np.array([[0.3, 0.1, -0.05], [0.02, 0.1, 0.08], [-0.03, 0.05, -0.1]])
    P0 = np.array([[0.1, -0.5, 0.2], [0.6, 0.05, -0.3], [-0.1, 0.4, 0.02]])
    omega = np.block([[np.zeros((9, 9)), np.eye(9)], [-np.eye(9), np.zeros((9, 9))]])
    n = 10**6 if QUICK else 10**7
    # (name, |J| bounded, system, X0 = I + s A, P0 = s P, steps). The SVK motion is regular to
    # 10⁶ steps only: between 10⁶ and 10⁷ it turns chaotic (|J| ~ 1e12 at 10⁷, from s = 0.1 or
    # s = 1), and then the defect relative to |J|² is all that can be compared (5.5e-14).
    cases = [("harmonic (linear)", True,
              lf.PseudoRigidBody(3, lf.potentials.Harmonic(1.0), check_det=False), 1.0, n),
             ("SVK + volumetric", False,
              lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0)
                                 + lf.potentials.Volumetric(0.5, 1.4)), 0.1, min(n, 10**6))]
    print("B. verlet on the pseudo-rigid body, dt = 0.05: |JᵀΩJ − Ω|_max")
    for name, bounded, prb, s, n in cases:
        z0 = np.concatenate([(np.eye(3) + s * A).ravel(), (s * P0).ravel()])
        ns, raw, _, jacs, secs = defects_along(
            prb, z0, "verlet", 0.05, n, 300,
            lambda z, J: np.abs(J.T @ omega @ J - omega).max())
        norms = np.array([np.abs(J).max() for J in jacs])
        env = envelope(raw)
        print(f"   {name}, X0 = I + {s} A, {n:.0e} steps ({secs:.0f} s)")

        def model(k, norm):
            # The random walk's size: ε(Σ_k |J_k|⁴)^½, |J_k| ≈ |J_N| k/N when J grows.
            return EPS * np.sqrt(k) * (1.0 if bounded else norm ** 2 / np.sqrt(5))

        for k in (10**3, 10**4, 10**5, 10**6, 10**7):
            if k <= n:
                i = int(np.searchsorted(ns, k))
                print(f"     N = {k:8d}  |J| = {norms[i]:9.3e}  defect {raw[i]:9.2e}  "
                      f"(max so far {env[i]:9.2e} = {env[i] / max(1, norms[i]) ** 2:8.1e} |J|², "
                      f"= {env[i] / model(k, norms[i]):5.2f} × the random walk's size)")
        tail = ns >= n // 100
        print(f"     one run's slopes over the last two decades: defect "
              f"{slope(ns[tail], env[tail]):.2f}, |J| {slope(ns[tail], envelope(norms)[tail]):.2f}")
        t = time.time()
        values, = ensemble(prb, z0, "verlet", 0.05, n, lambda z, J: J.T @ omega @ J - omega)
        print(f"     its largest entry at N = {n:.0e} with dt·(1 + r), r = {SHIFTS}: "
              + ", ".join(f"{v:+.1e}" for v in values)
              + f"; rms = {np.sqrt(np.mean(np.square(values))) / model(n, norms[-1]):.2f} × the "
              f"random walk's size ({time.time() - t:.0f} s)")


def heavy_top_splitting():
    ht = lf.HeavyTop([1.0, 1.0, 2.0], 0.7, chi=[0.0, 0.0, 1.0])
    g = np.array([0.0, 0.6, 0.8])
    z0 = np.concatenate([[1.0, 0.5, -0.3], g])
    n = 10**6 if QUICK else 10**7

    def hat(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    def tensor(z):
        m, gm = hat(z[:3]), hat(z[3:])
        return np.block([[m, gm], [gm, np.zeros((3, 3))]])

    B0 = tensor(z0)
    casimirs = (lambda v: np.concatenate([np.zeros(3), 2 * v[3:]]),
                lambda v: np.concatenate([v[3:], v[:3]]))

    def defects(z, J):
        """(|J B(z0) Jᵀ − B(z)|, max |∇C(z)ᵀJ − ∇C(z0)ᵀ| over the Casimirs)."""
        return (np.abs(J @ B0 @ J.T - tensor(z)).max(),
                max(np.abs(c(z) @ J - c(z0)).max() for c in casimirs))

    ns, values, _, jacs, secs = defects_along(ht, z0, "splitting", 0.05, n, 300, defects)
    norms = np.array([np.abs(J).max() for J in jacs])
    poisson, cas = envelope(values[:, 0]), envelope(values[:, 1])
    # The random walks' sizes (module docs): ε c³ (Σ k²(N − k)²)^½ N ≈ ε c³ N^3.5 / √30 for
    # the push-forward and ε c (Σ k²)^½ ≈ ε c N^1.5 / √3 for the pull-backs, c = |J_N| / N.
    c = norms / ns

    def walks(i):
        k = ns[i]
        return EPS * c[i]**3 * k**3.5 / np.sqrt(30), EPS * c[i] * k**1.5 / np.sqrt(3)

    print(f"C. the Lagrange top's splitting, dt = 0.05, {n:.0e} steps ({secs:.0f} s): "
          f"|J B(z0) Jᵀ − B(z)| and max |∇C(z)ᵀJ − ∇C(z0)ᵀ| (|Γ|², M·Γ)")
    for k in (10**3, 10**4, 10**5, 10**6, 10**7):
        if k <= n:
            i = int(np.searchsorted(ns, k))
            wp, wc = walks(i)
            print(f"     N = {k:8d}  |J| = {norms[i]:9.3e}  push-forward {values[i, 0]:9.2e} "
                  f"(= {values[i, 0] / norms[i]**2:8.1e} |J|², {poisson[i] / wp:5.2f} × its "
                  f"walk)  pull-back {values[i, 1]:9.2e} (= {values[i, 1] / norms[i]:8.1e} |J|, "
                  f"{cas[i] / wc:5.2f} × its walk)")
    tail = ns >= n // 100
    print(f"     one run's slopes over the last two decades: push-forward "
          f"{slope(ns[tail], poisson[tail]):.2f} (walk 3.5, bias 4), pull-back "
          f"{slope(ns[tail], cas[tail]):.2f} (walk 1.5, bias 2), |J| "
          f"{slope(ns[tail], envelope(norms)[tail]):.2f}")
    t = time.time()
    push, pull = ensemble(ht, z0, "splitting", 0.05, n,
                          lambda z, J: J @ B0 @ J.T - tensor(z),
                          lambda z, J: casimirs[1](z) @ J - casimirs[1](z0))
    wp, wc = walks(len(ns) - 1)
    print(f"     largest entries at N = {n:.0e} with dt·(1 + r), r = {SHIFTS}: push-forward "
          + ", ".join(f"{v:+.1e}" for v in push)
          + f" (walk {wp:.1e}); M·Γ pulled back " + ", ".join(f"{v:+.1e}" for v in pull)
          + f" (walk {wc:.1e}) ({time.time() - t:.0f} s)")


def main():
    print(environment())
    rigid_body_exact()
    pseudo_rigid_verlet()
    heavy_top_splitting()


if __name__ == "__main__":
    main()
