"""An exception from user code ends the run it came from, in its own thread, with a consistent
partial result (issue 29 §2): no step is taken twice, nothing is swallowed, the partial trajectory
restarts the same motion, and Ctrl-C reaches a run with Python callables at once."""

import json
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import lieflow as lf

M0 = [1.0, 0.5, -0.3]


def torque_of(t):
    return np.array([0.3, -0.2, 0.25 * np.cos(2 * t)])


class FailsOnce:
    """A torque that raises `exc` at its `at`-th call and counts its calls."""

    def __init__(self, at, exc):
        self.at, self.exc, self.calls = at, exc, 0

    def __call__(self, t, s):
        self.calls += 1
        if self.calls == self.at:
            raise self.exc
        return torque_of(t)


def ok_torque(t, s):
    return torque_of(t)


def assert_restarts_the_same_motion(part, system, dt, save_every, method=None):
    """The partial's samples, t_final and final_state belong together: a fresh run of as many
    steps ends at its final state bit for bit, its samples are the fresh run's, and a restart
    from it at t_final continues that motion (to round-off: its clock counts from t_final)."""
    steps = round((part.t_final - part.t0) / dt)
    assert part.t_final == pytest.approx(part.t0 + steps * dt, abs=1e-12)
    fresh = lf.integrate(system, part.initial_state, dt=dt, steps=steps, save_every=save_every,
                         method=method)
    np.testing.assert_array_equal(part.final_state, fresh.final_state)
    np.testing.assert_array_equal(part.states, fresh.states)
    np.testing.assert_array_equal(part.t, fresh.t)
    whole = lf.integrate(system, part.initial_state, dt=dt, steps=steps + 30, method=method)
    rest = lf.integrate(system, part.final_state, dt=dt, steps=30, t0=part.t_final,
                        method=method)
    np.testing.assert_allclose(rest.final_state, whole.final_state, rtol=0, atol=1e-13)


def test_an_exception_raised_once_ends_the_run_at_its_step():
    # The reproducer: the torque raises once, at its 500th call (step 250 of the
    # Strang-kicked splitting, two force evaluations a step). Before: the step was replayed, the
    # run went on to step 2000 (4020 calls) and the partial was inconsistent.
    rb = lf.RigidBody([1, 2, 3])
    torque = FailsOnce(500, OSError("transient"))
    forced = lf.Forced(rb, torque, depends_on_block=False)
    with pytest.raises(OSError, match="transient") as info:
        lf.integrate(forced, M0, dt=0.01, steps=2000, save_every=10)
    assert torque.calls == 500
    notes = " ".join(info.value.__notes__)
    assert "in step 250 of splitting" in notes and "to step 249" in notes, notes
    part = info.value.partial
    assert part.status == -1 and len(part.t) == 25 and part.t_final == pytest.approx(2.49)
    assert_restarts_the_same_motion(part, lf.Forced(rb, ok_torque, depends_on_block=False),
                                    0.01, 10)


@pytest.mark.parametrize("exc", [SystemExit(3), MemoryError("no room"),
                                 KeyboardInterrupt(), ZeroDivisionError("zero")])
@pytest.mark.parametrize("save_every", [1, 7, 100])
def test_every_exception_type_reaches_the_caller_unchanged(exc, save_every):
    rb = lf.RigidBody([1, 2, 3])
    torque = FailsOnce(301, exc)
    forced = lf.Forced(rb, torque, depends_on_block=False)
    with pytest.raises(type(exc)) as info:
        lf.integrate(forced, M0, dt=0.01, steps=1000, save_every=save_every)
    assert info.value is exc and torque.calls == 301
    part = info.value.partial
    assert part.t_final == pytest.approx(1.50)     # call 301: the first kick of step 151
    assert_restarts_the_same_motion(part, lf.Forced(rb, ok_torque, depends_on_block=False),
                                    0.01, save_every)


def test_a_gradient_of_the_wrong_shape_once_is_an_error_whatever_save_every():
    calls = [0]

    def grad(mu):
        calls[0] += 1
        return np.zeros(4) if calls[0] == 40 else mu / np.array([1.0, 2.0, 3.0])

    def h(mu):
        return 0.5 * float(mu @ (mu / np.array([1.0, 2.0, 3.0])))

    for save_every in (1, 7):
        calls[0] = 0
        lp = lf.LiePoisson("so3", h, grad)
        with pytest.raises(lf.ShapeError, match=r"expected \(3,\), got \(4,\), in step 10 of"):
            lf.integrate(lp, M0, dt=0.01, steps=200, save_every=save_every)
        assert calls[0] == 40


def test_user_systems_never_call_a_function_twice_for_one_step():
    # Side effects happen once: a Hamiltonian system whose gradient logs its calls. gauss4
    # iterates, so compare the calls of a failing run with those of a clean run of as many steps.
    log = []

    def grad(q, p):
        log.append(float(q[0]))
        if len(log) == 1000:
            raise ValueError("once")
        return np.array([q, p])

    def h(q, p):
        return 0.5 * float(q @ q + p @ p)

    with pytest.raises(ValueError, match="once") as info:
        lf.integrate(lf.Canonical(h, grad, dof=1), [1.0, 0.0], dt=0.01, steps=5000,
                     save_every=50)
    part, failed = info.value.partial, list(log)
    steps = round(part.t_final / 0.01)
    log.clear()
    lf.integrate(lf.Canonical(h, grad, dof=1), [1.0, 0.0], dt=0.01, steps=steps, save_every=50)
    # The clean run's calls are the failing run's calls up to the failing step.
    assert failed[:len(log)] == log and len(failed) <= len(log) + 20


def test_an_exception_in_one_thread_is_raised_in_that_thread():
    # Two threads integrate the same Forced object; thread A's torque raises once (a transient
    # failure), early in A's long run, while B's shorter run goes on. Before: the exception
    # waited in a slot of the system object, and B's run took it when it ended.
    rb = lf.RigidBody([1, 2, 3])
    calls_in_a = [0]

    def torque(t, s):
        if threading.current_thread().name == "A":
            calls_in_a[0] += 1
            if calls_in_a[0] == 100:
                raise RuntimeError("A's failure")
        time.sleep(0)                  # let the other thread run between calls
        return torque_of(t)

    forced = lf.Forced(rb, torque, depends_on_block=False)
    for _ in range(10):
        calls_in_a[0] = 0
        outcome = {}

        def run(steps):
            try:
                lf.integrate(forced, M0, dt=0.01, steps=steps, save_every=10)
                outcome[threading.current_thread().name] = "ok"
            except RuntimeError as e:
                outcome[threading.current_thread().name] = str(e)

        a = threading.Thread(target=run, args=(900,), name="A")
        b = threading.Thread(target=run, args=(300,), name="B")
        a.start(), b.start(), a.join(), b.join()
        assert outcome == {"A": "A's failure", "B": "ok"}
        assert calls_in_a[0] == 100


def test_a_batch_stops_at_the_first_member_whose_callable_raises():
    # Members run one after the other on the calling thread; after member 1's exception no
    # callable is called again (member 2 never starts), and Ctrl-C is not delayed by the rest.
    calls = []

    def torque(t, s):
        calls.append(t)
        if s[0] > 5.0 and t > 0.505:
            raise RuntimeError("member 1")
        return torque_of(t)

    forced = lf.Forced(lf.RigidBody([1, 2, 3]), torque, depends_on_block=False)
    with pytest.raises(RuntimeError, match="member 1") as info:
        lf.integrate(forced, [M0, [6.0, 0.0, 0.1], M0], dt=0.01, steps=100)
    assert len(calls) == 200 + 102          # member 0 whole, member 1 to the end of step 51
    part = info.value.partial
    assert part.states.shape == (3, 1, 3) and part.t_final == 0.0


def test_an_event_function_that_raises_ends_the_run_with_a_consistent_partial():
    body = lf.RigidBody([1, 2, 3])
    calls = [0]

    def g(t, s):
        calls[0] += 1
        if calls[0] == 77:
            raise LookupError("event")
        return s[2]

    with pytest.raises(LookupError, match="event") as info:
        lf.integrate(body, M0, dt=0.01, steps=500, events=g)
    part = info.value.partial
    assert calls[0] == 77 and part.t_final == pytest.approx(0.75)
    assert_restarts_the_same_motion(part, body, 0.01, 1)


def _revolution_profiles():
    return (lambda s: np.array([1 + 0.3 * np.cos(s), -0.3 * np.sin(s), -0.3 * np.cos(s),
                                0.3 * np.sin(s)]),
            lambda s: np.array([0.3 * np.sin(s), 0.3 * np.cos(s), -0.3 * np.sin(s),
                                -0.3 * np.cos(s)]))


def test_callable_surfaces_and_potentials_end_the_run_at_their_failure():
    r, z = _revolution_profiles()
    n = [0]

    def r_failing(s):
        n[0] += 1
        if n[0] == 5000:
            raise ArithmeticError("profile")
        return r(s)

    torus = lf.surfaces.Revolution(r_failing, z, (-np.pi, np.pi))
    tt = lf.TangentTop(torus, 1.0, 0.5)
    z0 = tt.state([0.1, 0.0], 0.0, [0.2, 0.5], 1.0)
    with pytest.raises(ArithmeticError, match="profile") as info:
        lf.integrate(tt, z0, dt=0.01, steps=2000, save_every=20)
    assert n[0] == 5000
    part = info.value.partial
    n[0] = -10**9                            # no more failures
    assert_restarts_the_same_motion(part, tt, 0.01, 20)
    # A callable potential.
    k = [0]

    def value(x):
        return 0.5 * float(np.sum(x * x))

    def gradient(x):
        k[0] += 1
        if k[0] == 123:
            raise FloatingPointError("potential")
        return x

    body = lf.PseudoRigidBody(3, potential=lf.potentials.Callable(value, gradient))
    x0 = (np.diag([1.0, 1.5, 2.0]), np.zeros((3, 3)))
    with pytest.raises(FloatingPointError, match="potential") as info:
        lf.integrate(body, x0, dt=0.01, steps=500, save_every=9)
    assert k[0] == 123
    k[0] = -10**9
    assert_restarts_the_same_motion(info.value.partial, body, 0.01, 9)


def test_a_failed_run_leaves_nothing_behind():
    # After a failure the system and the thread are clean: the next run and a direct call work.
    r, z = _revolution_profiles()
    fail = [True]

    def r_maybe(s):
        if fail[0]:
            raise KeyError("once")
        return r(s)

    tt = lf.TangentTop(lf.surfaces.Revolution(r_maybe, z, (-np.pi, np.pi)), 1.0, 0.5)
    with pytest.raises(KeyError):
        tt.state([0.1, 0.0], 0.0, [0.2, 0.5], 1.0)
    fail[0] = False
    z0 = tt.state([0.1, 0.0], 0.0, [0.2, 0.5], 1.0)
    assert np.isfinite(lf.integrate(tt, z0, dt=0.01, steps=50).final_state).all()


CHILD = r"""
import json, signal, sys, time
import numpy as np
import lieflow as lf
signal.signal(signal.SIGINT, signal.default_int_handler)
kind, save_every = sys.argv[1], int(sys.argv[2])
inertia = np.array([1.0, 2.0, 3.0])
def h(mu):
    return 0.5 * float(mu @ (mu / inertia))
def grad(mu):
    return mu / inertia
system = {"native": lf.RigidBody(inertia),
          "python": lf.LiePoisson("so3", h, grad)}[kind]
m0 = [1.0, 0.5, -0.3]
print("start", flush=True)
try:
    lf.integrate(system, m0, dt=1e-3, steps=10**7 * save_every, save_every=save_every)
except KeyboardInterrupt as e:
    caught = time.time()
    p = e.partial
    steps = round(p.t_final / 1e-3)
    again = lf.integrate(system, m0, dt=1e-3, steps=steps, save_every=save_every)
    print(json.dumps({"caught": caught, "steps": steps, "samples": len(p.t),
                      "same": bool(np.array_equal(again.final_state, p.final_state)
                                   and np.array_equal(again.states, p.states))}), flush=True)
"""


@pytest.mark.parametrize("kind,save_every", [("native", 1000), ("python", 1), ("python", 100),
                                             ("python", 10**6)])
def test_ctrl_c_stops_within_a_second_and_the_partial_equals_a_fresh_run(kind, save_every):
    rng = np.random.default_rng(save_every)
    p = subprocess.Popen([sys.executable, "-c", CHILD, kind, str(save_every)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(0.3 + rng.random())
        sent = time.time()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
    assert out.strip(), err
    r = json.loads(out)
    assert r["caught"] - sent < 1.0, r
    assert r["steps"] > 0 and r["same"], r
