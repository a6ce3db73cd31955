"""Adversarial checks of runs with sensitivity=True (issue 26 against the trust standards of
issue 29): one lifted system in two threads at once (and batches on the pool), an exception of
a user callable in one thread only, Ctrl-C in the middle of a lifted run (and right after a
native call returned), round-off along long runs, and hostile arguments — each a typed error or
a consistent result, never a panic, a NaN or a changed input."""

import json
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import lieflow as lf

# The module (lf.integrate is its function).
lf_integrate = sys.modules["lieflow.integrate"]

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([0.3, -0.8, 1.1])
X0 = np.array([[1.3, 0.1, -0.05], [0.02, 1.1, 0.08], [-0.03, 0.05, 0.9]])
P0 = np.array([[0.1, -0.5, 0.2], [0.6, 0.05, -0.3], [-0.1, 0.4, 0.02]])
Z_PRB = np.concatenate([X0.ravel(), P0.ravel()])
OMEGA = np.block([[np.zeros((9, 9)), np.eye(9)], [-np.eye(9), np.zeros((9, 9))]])


def user_body(hessian=None):
    """The free body as a user Lie–Poisson system with Python callables (and its Hessian)."""
    return lf.LiePoisson("so3", lambda mu: 0.5 * float(mu @ (mu / I)), gradient=lambda mu: mu / I,
                         hessian=hessian or (lambda mu, d: d / I))


def prb():
    return lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0)
                              + lf.potentials.Volumetric(0.5, 1.4))


CASES = {
    "RigidBody": (lf.RigidBody(I), M0, dict(method="splitting4"), 2000),
    "RigidBody-exact-attitude": (lf.RigidBody(I), M0,
                                 dict(method="exact", attitude=lf.lie.so3_exp([0.4, -0.7, 0.3])),
                                 2000),
    "HeavyTop": (lf.HeavyTop(I, 0.7, chi=[0.2, -0.3, 1.0]),
                 np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8]), dict(), 2000),
    "LiePoisson-user": (user_body(), M0, dict(method="midpoint"), 150),
    "PseudoRigidBody": (prb(), Z_PRB, dict(method="verlet4"), 300),
}


def assert_same_run(a, b):
    for name in ("t", "states", "final_state", "jacobian", "final_jacobian",
                 "parameter_jacobian", "final_parameter_jacobian", "attitude", "final_attitude"):
        x, y = getattr(a, name), getattr(b, name)
        if x is None or y is None:
            assert x is None and y is None, name
        else:
            np.testing.assert_array_equal(x, y, err_msg=name)
    assert a.t_final == b.t_final


def assert_partial_is_a_fresh_run(part, system, dt, save_every, method, **kw):
    """A partial of a lifted run: states, Jacobians and parameter Jacobians of as many samples,
    every one (and the finals) bit for bit those of a fresh run of as many steps."""
    k = len(part.t)
    assert part.status == -1
    assert part.states.shape[-2] == k and part.jacobian.shape[-3] == k
    assert part.parameter_jacobian.shape[-3] == k
    steps = round((part.t_final - part.t0) / dt)
    if steps == 0:
        np.testing.assert_array_equal(part.final_state, part.initial_state)
        identity = np.broadcast_to(np.eye(part.jacobian.shape[-1]), part.final_jacobian.shape)
        np.testing.assert_array_equal(part.final_jacobian, identity)
        return
    fresh = lf.integrate(system, part.initial_state, dt, steps, method=method,
                         save_every=save_every, sensitivity=True, **kw)
    assert_same_run(part, fresh)


# 1. Two threads on one lifted system.

@pytest.mark.parametrize("case", list(CASES))
def test_two_threads_and_a_threaded_batch_on_one_lifted_system_are_the_sequential_runs(case):
    """The same system object integrated with sensitivity=True from three Python threads at
    once (two single runs, one batch whose members run on the pool with the GIL released, or on
    the calling thread for Python callables): each result equals the sequential run bit for bit,
    and a batch member its single run."""
    system, z0, kw, steps = CASES[case]
    starts = [z0, z0 * 1.05]
    batch = np.stack([z0 * (1 + 0.03 * i) for i in range(4)])
    seq = [lf.integrate(system, z, 0.01, steps, save_every=25, sensitivity=True, **kw)
           for z in starts]
    seq_batch = lf.integrate(system, batch, 0.01, steps, save_every=25, sensitivity=True, **kw)
    member = lf.integrate(system, batch[2], 0.01, steps, save_every=25, sensitivity=True, **kw)
    np.testing.assert_array_equal(seq_batch.jacobian[2], member.jacobian)
    np.testing.assert_array_equal(seq_batch.parameter_jacobian[2], member.parameter_jacobian)
    for _ in range(2):
        out = {}

        def single(i):
            out[i] = lf.integrate(system, starts[i], 0.01, steps, save_every=25,
                                  sensitivity=True, **kw)

        def batched():
            out["batch"] = lf.integrate(system, batch, 0.01, steps, save_every=25,
                                        sensitivity=True, threads=2, **kw)

        threads = [threading.Thread(target=single, args=(i,)) for i in range(2)]
        threads.append(threading.Thread(target=batched))
        [t.start() for t in threads]
        [t.join() for t in threads]
        assert_same_run(out[0], seq[0])
        assert_same_run(out[1], seq[1])
        assert_same_run(out["batch"], seq_batch)


@pytest.mark.parametrize("method,save_every", [("midpoint", 1), ("rkmk4", 7), ("rk4", 3)])
def test_a_user_hessian_raising_in_one_thread_ends_only_that_threads_lifted_run(method,
                                                                               save_every):
    """Thread A's Hessian raises once (a transient failure) while thread B integrates the same
    LiePoisson object: A alone gets the error, with a partial whose states and (parameter)
    Jacobians have as many samples and equal a fresh run of as many steps; B's run is the
    sequential one bit for bit."""
    calls = [0]

    def hessian(mu, d):
        if threading.current_thread().name == "A":
            calls[0] += 1
            if calls[0] == 300:
                raise RuntimeError("A's hessian")
        time.sleep(0)                     # let the other thread in between calls
        return d / I

    system = user_body(hessian)
    reference_b = lf.integrate(system, M0 * 1.1, 0.01, 150, method=method,
                               save_every=save_every, sensitivity=True)
    calls[0] = -10**9
    out = {}

    def run(z, steps):
        name = threading.current_thread().name
        try:
            out[name] = lf.integrate(system, z, 0.01, steps, method=method,
                                     save_every=save_every, sensitivity=True)
        except RuntimeError as e:
            out[name] = e

    calls[0] = 0
    a = threading.Thread(target=run, args=(M0, 400), name="A")
    b = threading.Thread(target=run, args=(M0 * 1.1, 150), name="B")
    a.start(), b.start(), a.join(), b.join()
    assert isinstance(out["A"], RuntimeError) and str(out["A"]) == "A's hessian"
    assert calls[0] == 300
    assert_same_run(out["B"], reference_b)
    part = out["A"].partial
    assert part.t_final > 0
    calls[0] = -10**9                       # no more failures
    assert_partial_is_a_fresh_run(part, system, 0.01, save_every, method)


def test_a_user_hessian_raising_in_a_batch_leaves_a_consistent_partial():
    """A batch of a system that calls Python (its members on the calling thread): member 1's
    Hessian raises; the partial has states and Jacobians of the same samples for every member,
    each a fresh run's."""
    def hessian(mu, d):
        if mu[0] > 5.0:
            raise ZeroDivisionError("member 1")
        return d / I

    system = user_body(hessian)
    batch = np.stack([M0, [6.0, 0.0, 0.1], M0 * 0.5])
    with pytest.raises(ZeroDivisionError, match="member 1") as info:
        lf.integrate(system, batch, 0.01, 50, method="midpoint", sensitivity=True)
    part = info.value.partial
    assert part.states.shape[:2] == part.jacobian.shape[:2] == part.parameter_jacobian.shape[:2]
    assert part.states.shape[0] == 3
    for i in (0, 2):
        sub = lf.Trajectory(system, part.method, part.t, part.states[i], None,
                            part.final_state[i], None, part.dt, part.save_every,
                            t_final=part.t_final, status=-1, t0=part.t0,
                            initial_state=part.initial_state[i], jacobian=part.jacobian[i],
                            final_jacobian=part.final_jacobian[i],
                            parameter_jacobian=part.parameter_jacobian[i],
                            final_parameter_jacobian=part.final_parameter_jacobian[i])
        assert_partial_is_a_fresh_run(sub, system, 0.01, 1, "midpoint")


# 2. Ctrl-C in a lifted run.

CHILD = r"""
import json, signal, sys, time
import numpy as np
import lieflow as lf
signal.signal(signal.SIGINT, signal.default_int_handler)
kind = sys.argv[1]
I = np.array([1.0, 2.0, 3.0])
X0 = np.array([[1.3, 0.1, -0.05], [0.02, 1.1, 0.08], [-0.03, 0.05, 0.9]])
P0 = np.array([[0.1, -0.5, 0.2], [0.6, 0.05, -0.3], [-0.1, 0.4, 0.02]])
system, z0, method, save_every, steps = {
    "native": (lf.RigidBody(I), [0.3, -0.8, 1.1], "splitting", 1000, 10**10),
    "python": (lf.LiePoisson("so3", lambda mu: 0.5 * float(mu @ (mu / I)),
                             gradient=lambda mu: mu / I, hessian=lambda mu, d: d / I),
               [0.3, -0.8, 1.1], "midpoint", 1, 10**7),
    # 23 directions: a lifted step does ~40 times a plain step's work.
    "pseudo-rigid": (lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0)
                                        + lf.potentials.Volumetric(0.5, 1.4)),
                     np.concatenate([X0.ravel(), P0.ravel()]), "verlet6", 100, 10**7),
}[kind]
dt = 1e-3
print("start", flush=True)
try:
    lf.integrate(system, z0, dt, steps, method=method, save_every=save_every, sensitivity=True)
except KeyboardInterrupt as e:
    caught = time.time()
    p = e.partial
    k = len(p.t)
    n = round((p.t_final - p.t0) / dt)
    same = n > 0 and all(np.array_equal(getattr(p, a), getattr(fresh, a)) for fresh in
                         [lf.integrate(system, z0, dt, n, method=method, save_every=save_every,
                                       sensitivity=True)]
                         for a in ("t", "states", "final_state", "jacobian", "final_jacobian",
                                   "parameter_jacobian", "final_parameter_jacobian"))
    g_final = p.vjp(np.ones(p.states.shape[-1]))
    g_every = p.vjp(np.ones(p.states.shape))
    want = (p.final_jacobian.sum(axis=0), p.jacobian.sum(axis=(0, 1)))
    print(json.dumps({
        "caught": caught, "steps": n, "samples": k, "status": p.status,
        "jacobians": len(p.jacobian), "parameter_jacobians": len(p.parameter_jacobian),
        "same": bool(same),
        "vjp": bool(np.allclose(g_final[0], want[0], rtol=1e-14, atol=0)
                    and np.allclose(g_every[0], want[1], rtol=1e-12, atol=0)
                    and np.all(np.isfinite(g_every[1])))}), flush=True)
"""


@pytest.mark.parametrize("kind", ["native", "python", "pseudo-rigid"])
def test_ctrl_c_mid_lifted_run_leaves_a_partial_of_a_fresh_run_within_a_second(kind):
    """SIGINT at a random moment of a long lifted run: KeyboardInterrupt within a second (for
    the pseudo-rigid body too: before, a native call of a lifted run took the plain run's
    200 000 steps, 4.5 s of work, and Ctrl-C waited for it), its partial with as many Jacobians
    and parameter Jacobians as states, each a fresh run's bit for bit, and vjp on it."""
    rng = np.random.default_rng(len(kind))
    p = subprocess.Popen([sys.executable, "-c", CHILD, kind], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(0.4 + 0.4 * rng.random())
        sent = time.time()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
    assert out.strip(), err
    r = json.loads(out)
    assert r["caught"] - sent < 1.0, r
    assert r["steps"] > 0 and r["status"] == -1, r
    assert r["samples"] == r["jacobians"] == r["parameter_jacobians"], r
    assert r["same"] and r["vjp"], r


@pytest.mark.parametrize("save_every", [1, 5])
def test_keyboard_interrupt_from_a_user_hessian_leaves_a_consistent_partial(save_every):
    """Ctrl-C as it reaches a run with Python callables (raised inside the Hessian): the
    partial's Jacobians are those of a fresh run of its steps, and vjp works on it."""
    calls = [0]

    def hessian(mu, d):
        calls[0] += 1
        if calls[0] == 250:
            raise KeyboardInterrupt
        return d / I

    system = user_body(hessian)
    with pytest.raises(KeyboardInterrupt) as info:
        lf.integrate(system, M0, 0.01, 1000, method="rkmk4", save_every=save_every,
                     sensitivity=True)
    part = info.value.partial
    calls[0] = -10**9
    assert_partial_is_a_fresh_run(part, system, 0.01, save_every, "rkmk4")
    grad, _ = part.vjp(np.ones((len(part.t), 3)))
    np.testing.assert_allclose(grad, part.jacobian.sum(axis=(0, 1)), rtol=1e-13)


class Alarm:
    """SIGALRM raising KeyboardInterrupt after `seconds`, as Ctrl-C would (main thread)."""

    def __init__(self, seconds):
        self.seconds = seconds

    def __enter__(self):
        def interrupt(*_):
            raise KeyboardInterrupt
        self.old = signal.signal(signal.SIGALRM, interrupt)
        signal.setitimer(signal.ITIMER_REAL, self.seconds)

    def __exit__(self, *exc):
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, self.old)


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs SIGALRM")
@pytest.mark.parametrize("sensitivity", [False, True])
def test_ctrl_c_during_a_run_in_one_native_call_keeps_the_initial_sample(sensitivity):
    """A run that fits in one native call (here forced by chunk_steps) is interrupted: Python
    raises KeyboardInterrupt as the call returns, its result lost, so the partial is the run's
    start. Before, that partial had no sample at all (t, states and Jacobians empty); now it
    holds the initial sample, the identity as its Jacobian, t_final = t0, and vjp works."""
    if sensitivity:
        system, z0, method, steps = prb(), Z_PRB, "verlet6", 30_000     # ~0.7 s of work
    else:
        system, z0, method, steps = lf.RigidBody(I), M0, "splitting", 30_000_000  # ~0.6 s
    with Alarm(0.05):
        with pytest.raises(KeyboardInterrupt) as info:
            lf.integrate(system, z0, 1e-3, steps, method=method, save_every=1000,
                         chunk_steps=10**9, sensitivity=sensitivity)
    part = info.value.partial
    assert part.status == -1 and len(part.t) == 1 and part.states.shape == (1, len(z0))
    np.testing.assert_array_equal(part.states[0], z0)
    np.testing.assert_array_equal(part.final_state, z0)
    assert part.t_final == part.t0 == part.t[0] == 0.0
    if sensitivity:
        e = len(z0)
        assert part.jacobian.shape == (1, e, e) and part.parameter_jacobian.shape == (1, e, 4)
        np.testing.assert_array_equal(part.final_jacobian, np.eye(e))
        np.testing.assert_array_equal(part.final_parameter_jacobian, 0.0)
        grad, gp = part.vjp(np.arange(e, dtype=float))
        np.testing.assert_array_equal(grad, np.arange(e))
        np.testing.assert_array_equal(gp, 0.0)


@pytest.mark.parametrize("where", ["split", "join"])
def test_ctrl_c_while_the_result_is_assembled_still_gives_a_partial(monkeypatch, where):
    """Ctrl-C after the last native call, while the Jacobians are split out of the lifted
    states (or the chunks joined): the KeyboardInterrupt carries the whole run as its partial
    (status -1), not nothing. Simulated by the first assembly raising it."""
    name = {"split": "_split_lifted", "join": "_trajectory"}[where]
    real = getattr(lf_integrate, name)
    raised = []

    def once(*args, **kw):
        if not raised:
            raised.append(True)
            raise KeyboardInterrupt
        return real(*args, **kw)

    system = lf.HeavyTop(I, 0.7, chi=[0.2, -0.3, 1.0])
    z0 = np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8])
    whole = lf.integrate(system, z0, 0.01, 3000, save_every=100, sensitivity=True,
                         chunk_steps=700)
    monkeypatch.setattr(lf_integrate, name, once)
    with pytest.raises(KeyboardInterrupt) as info:
        lf.integrate(system, z0, 0.01, 3000, save_every=100, sensitivity=True, chunk_steps=700)
    part = info.value.partial
    assert part is not None and part.status == -1
    assert part.jacobian.shape == whole.jacobian.shape
    for a in ("states", "jacobian", "parameter_jacobian", "final_jacobian"):
        np.testing.assert_array_equal(getattr(part, a), getattr(whole, a))


# 3. Round-off along long runs (the long measurement: benches/python/sensitivity_roundoff.py).

def test_exact_jacobian_of_a_long_run_is_the_one_jump_bit_for_bit():
    """`exact` evaluates the closed form at t = N·dt from the run's start: its Jacobians after
    N steps are those of one jump of N·dt bit for bit (no round-off accumulates with N), and
    the Casimir and the energy pulled back, ∇C(z)ᵀJ = ∇C(z₀)ᵀ, hold to round-off of |J|."""
    rb = lf.RigidBody(I)
    n = 2_000_000
    run = lf.integrate(rb, M0, 0.1, n, method="exact", save_every=n // 4, sensitivity=True)
    jump = lf.integrate(rb, M0, 0.1 * n, 1, method="exact", sensitivity=True)
    np.testing.assert_array_equal(run.final_jacobian, jump.final_jacobian)
    np.testing.assert_array_equal(run.final_parameter_jacobian, jump.final_parameter_jacobian)
    for z, J in zip(run.states, run.jacobian):
        for grad in (lambda m: m, lambda m: m / I):
            assert np.abs(grad(z) @ J - grad(M0)).max() < 1e-14 * np.abs(J).max()


def test_verlet_symplecticity_defect_random_walks():
    """Verlet on the linear (harmonic) pseudo-rigid body, 2·10⁵ steps: |JᵀΩJ − Ω| stays at the
    size of a random walk of the rounding, a few ε√N (measured 0.2–0.4 ε√N to 10⁷ steps;
    a bias per step would reach ~ε N = 4e-11 here)."""
    body = lf.PseudoRigidBody(3, lf.potentials.Harmonic(1.0), check_det=False)
    n = 200_000
    steps = np.array([1000, 10_000, 50_000, 100_000, 200_000])
    traj = lf.integrate(body, Z_PRB, 0.05, n, method="verlet", t_eval=steps * 0.05,
                        sensitivity=True)
    eps = np.finfo(float).eps
    for k, J in zip(steps, traj.jacobian):
        assert np.abs(J).max() < 2.0
        assert np.abs(J.T @ OMEGA @ J - OMEGA).max() < 5 * eps * np.sqrt(k), k


# 4. Hostile inputs.

def test_sensitivity_must_be_a_bool():
    rb = lf.RigidBody(I)
    for bad in ("yes", 1, 0, None, 1.0, [True], np.array([True, False])):
        with pytest.raises(TypeError, match="invalid sensitivity: expected True or False"):
            lf.integrate(rb, M0, 0.1, 10, sensitivity=bad)
    # numpy's bools (e.g. of a comparison) are bools: before, np.True_ was refused as
    # "expected True or False, got bool np.True_".
    on = lf.integrate(rb, M0, 0.1, 10, sensitivity=np.True_)
    assert on.jacobian.shape == (11, 3, 3)
    assert lf.integrate(rb, M0, 0.1, 10, sensitivity=np.False_).jacobian is None


def test_hostile_arguments_are_typed_errors_and_leave_the_callers_arrays_alone():
    rb = lf.RigidBody(I)
    z0 = M0.copy()
    R0 = lf.lie.so3_exp([0.4, -0.7, 0.3])
    kept = (z0.copy(), R0.copy())
    bad = [
        (dict(state0=[np.nan, 0.0, 1.0]), lf.NonFiniteError, "state0 contains a non-finite"),
        (dict(state0=[np.inf, 0.0, 1.0]), lf.NonFiniteError, "state0 contains a non-finite"),
        (dict(state0=np.stack([M0, [0.0, np.nan, 1.0]])), lf.NonFiniteError, "batch member 1"),
        (dict(state0=M0[:2]), lf.ShapeError, "state0 has the wrong shape"),
        (dict(dt=0.0), lf.InvalidArgumentError, "invalid dt"),
        (dict(dt=-0.1), lf.InvalidArgumentError, "invalid dt"),
        (dict(dt=np.inf), lf.InvalidArgumentError, "invalid dt"),
        (dict(dt=np.nan), lf.InvalidArgumentError, "invalid dt"),
        (dict(dt="0.1"), TypeError, "invalid dt"),
        (dict(steps=0), lf.InvalidArgumentError, "invalid steps"),
        (dict(steps=-5), lf.InvalidArgumentError, "invalid steps"),
        (dict(steps=2.5), TypeError, "invalid steps"),
        (dict(steps=10**12), lf.InvalidArgumentError, "exceeds the limit|needs"),
        (dict(save_every=0), lf.InvalidArgumentError, "invalid save_every"),
        (dict(t0=np.nan), lf.InvalidArgumentError, "invalid t0"),
        (dict(attitude=np.eye(4)), lf.ShapeError, "attitude"),
        # Named as the attitude (before: "state0 ... at index 3", the lift's seed's index).
        (dict(attitude=np.full((3, 3), np.nan)), lf.NonFiniteError,
         r"^attitude contains a non-finite value \(NaN or inf\) at \(0, 0\)"),
        (dict(state0=np.stack([M0, M0]),
              attitude=np.stack([np.eye(3), np.full((3, 3), np.inf)])),
         lf.NonFiniteError, r"^batch member 1: attitude contains"),
        (dict(attitude=2 * np.eye(3)), lf.NotInGroupError, r"not in SO\(3\)"),
        (dict(t_eval=[0.5, 0.2]), lf.InvalidArgumentError, "increasing"),
        (dict(t_eval=[0.5, None]), TypeError, "t_eval"),
        (dict(events=lambda t, z: z[0]), lf.InvalidArgumentError, "events"),
        (dict(method="nope"), lf.UnsupportedMethodError, "nope"),
        (dict(method="verlet", attitude=R0), lf.UnsupportedMethodError, "available for"),
    ]
    for kw, error, match in bad:
        args = dict(state0=z0, dt=0.1, steps=10, sensitivity=True)
        args.update(kw)
        with pytest.raises(error, match=match):
            lf.integrate(rb, **args)
    np.testing.assert_array_equal(z0, kept[0])
    np.testing.assert_array_equal(R0, kept[1])
    # Read-only and integer inputs are read, not written.
    ro = M0.copy()
    ro.setflags(write=False)
    att = R0.copy()
    att.setflags(write=False)
    traj = lf.integrate(rb, ro, 0.1, 10, attitude=att, sensitivity=True)
    assert np.isfinite(traj.jacobian).all()
    ints = lf.integrate(rb, np.array([3, -8, 11]), 0.01, 10, sensitivity=True)
    floats = lf.integrate(rb, np.array([3.0, -8.0, 11.0]), 0.01, 10, sensitivity=True)
    np.testing.assert_array_equal(ints.jacobian, floats.jacobian)


def test_save_every_beyond_steps_keeps_the_final_jacobian():
    rb = lf.RigidBody(I)
    for method in ("splitting", "exact", "dmv", "rk4"):
        every = lf.integrate(rb, M0, 0.1, 10, method=method, sensitivity=True)
        sparse = lf.integrate(rb, M0, 0.1, 10, method=method, save_every=100,
                              sensitivity=True)
        assert sparse.jacobian.shape == (1, 3, 3) and sparse.t_final == every.t_final
        np.testing.assert_array_equal(sparse.jacobian[0], np.eye(3))
        np.testing.assert_array_equal(sparse.final_jacobian, every.final_jacobian)
        np.testing.assert_array_equal(sparse.final_parameter_jacobian,
                                      every.final_parameter_jacobian)
        # On the one sample, the cotangent (1, e) is the initial state's own.
        np.testing.assert_array_equal(sparse.vjp(np.ones((1, 3)))[0], np.ones(3))


def test_vjp_refuses_what_it_cannot_use():
    rb = lf.RigidBody(I)
    traj = lf.integrate(rb, M0, 0.1, 10, save_every=5, sensitivity=True)
    batch = lf.integrate(rb, np.stack([M0, M0]), 0.1, 10, save_every=5, sensitivity=True)
    jac = traj.jacobian.copy()
    for c in (np.ones(4), np.ones((2, 3)), np.ones((3, 3, 3)), np.ones((0, 3)), 3.0, True):
        with pytest.raises(lf.ShapeError, match="invalid cotangent"):
            traj.vjp(c)
    for c in (np.ones(3), np.ones((3, 3)), np.ones((1, 3))):
        with pytest.raises(lf.ShapeError, match=r"expected shape \(2, 3\)"):
            batch.vjp(c)
    for c in ([np.nan, 0, 0], [0, np.inf, 0], np.full((3, 3), -np.inf)):
        with pytest.raises(lf.NonFiniteError, match="non-finite"):
            traj.vjp(c)
    # None used to become NaN (a NonFiniteError about a value the caller never passed).
    for c in (None, [1.0, None, 2.0], "abc", [1j, 0, 0], np.ones(3, dtype=complex)):
        with pytest.raises(TypeError, match="invalid cotangent"):
            traj.vjp(c)
    np.testing.assert_array_equal(traj.jacobian, jac)
    c = np.ones((3, 3))
    c.setflags(write=False)
    traj.vjp(c)
    np.testing.assert_array_equal(c, 1.0)


def test_vjp_of_huge_cotangents_is_finite_or_a_typed_error():
    """A gradient beyond the float range is a NonFiniteError (before: inf returned silently);
    one whose sum only overflows on the way (1.5e308 + 1.5e308 − 1.5e308) is computed."""
    rb = lf.RigidBody(I)
    traj = lf.integrate(rb, M0, 0.1, 10, save_every=5, sensitivity=True)
    with pytest.raises(lf.NonFiniteError, match="overflows"):
        traj.vjp(np.full(3, 1e308))
    with pytest.raises(lf.NonFiniteError, match="overflows"):
        traj.vjp(np.full((3, 3), 1e308))
    tiny = lf.integrate(rb, M0, 1e-300, 2, sensitivity=True)     # J ≈ I at every sample
    c = np.zeros((3, 3))
    c[:, 0] = [1.5e308, 1.5e308, -1.5e308]
    grad, gp = tiny.vjp(c)
    assert np.all(np.isfinite(grad)) and np.all(np.isfinite(gp))
    assert grad[0] == pytest.approx(1.5e308, rel=1e-12)
    big = traj.vjp(np.full(3, 1e300))[0]
    np.testing.assert_allclose(big, 1e300 * traj.final_jacobian.sum(axis=0), rtol=1e-15)


SYSTEMS = [
    (lf.RigidBody(I), M0),
    (lf.HeavyTop(I, 0.7, chi=[0.2, -0.3, 1.0]), np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8])),
    (user_body(), M0),
    (prb(), Z_PRB),
]


@pytest.mark.parametrize("index", range(len(SYSTEMS)),
                         ids=["RigidBody", "HeavyTop", "LiePoisson-user", "PseudoRigidBody"])
def test_huge_and_tiny_states_and_steps_are_finite_results_or_typed_errors(index):
    """Every lifted method from states scaled by 1e300, 1e150, 1e-300 and with dt = 1e300 or
    1e-300: a LieflowError (never a panic, another exception or a NaN), or a run whose states
    and Jacobians are all finite; the caller's state unchanged."""
    system, z0 = SYSTEMS[index]
    for method in system.sensitivity_methods():
        for scale, dt in ((1e300, 0.01), (1e150, 0.01), (1e-300, 0.01), (1.0, 1e300),
                          (1.0, 1e-300)):
            z = z0 * scale
            kept = z.copy()
            try:
                traj = lf.integrate(system, z, dt, 3, method=method, sensitivity=True)
            except lf.LieflowError as e:
                assert str(e), (method, scale, dt)
            else:
                for a in ("states", "jacobian", "parameter_jacobian", "final_jacobian"):
                    assert np.all(np.isfinite(getattr(traj, a))), (method, scale, dt, a)
            np.testing.assert_array_equal(z, kept)


def test_an_overflowing_jacobian_is_named_as_such():
    """The exact rigid body from |M| = 1e200: M(t) is representable, ∂M/∂I (~ t|M|²) is not.
    The error names the entry of the parameter Jacobian (before: "state contains a non-finite
    value at index 13", an index of the lift's internal layout, while the plain run works)."""
    rb = lf.RigidBody(I)
    z = np.array([1e200, 1e200, -1e200])
    assert np.all(np.isfinite(lf.integrate(rb, z, 0.1, 10, method="exact").final_state))
    with pytest.raises(lf.LeftDomainError,
                       match=r"parameter Jacobian .* at row \d, column 0 \(I1\)"):
        lf.integrate(rb, z, 0.1, 10, method="exact", sensitivity=True)
    # The Jacobian itself beyond the range: the steady rotation about the middle axis, which
    # every step keeps exactly, while J grows like exp(0.29 t) (the unstable equilibrium).
    for method in ("splitting", "exact", "rk4"):
        with pytest.raises(lf.LeftDomainError,
                           match=r"the Jacobian ∂z/∂z₀ .* at row \d, column \d\); the "
                                 r"derivatives outgrew the float range") as info:
            lf.integrate(rb, [0.0, 1.0, 0.0], 1.0, 4000, method=method, sensitivity=True)
        part = info.value.partial
        assert 2400 < part.t_final < 2500
        np.testing.assert_array_equal(part.final_state, [0.0, 1.0, 0.0])
        assert np.all(np.isfinite(part.jacobian)) and np.abs(part.final_jacobian).max() > 1e300
        try:                     # a gradient of J ~ 1e308: finite, or refused as overflowing
            assert np.all(np.isfinite(part.vjp(np.ones(3))[0]))
        except lf.NonFiniteError as e:
            assert "overflows" in str(e)
    # A state that overflows is still named as the state.
    with pytest.raises(lf.LeftDomainError, match=r"state contains a non-finite value .* index"):
        lf.integrate(rb, z, 0.1, 10, method="splitting", sensitivity=True)
