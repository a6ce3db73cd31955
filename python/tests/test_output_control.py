"""lieflow.integrate: output and control as scipy users expect (issue 15) — t0, t_eval (states at
given times by shortened steps), events (zeros located on the method's own trajectory),
the partial trajectory of a failed or interrupted run, and concatenation of continued runs.
Checked on the free rigid body against its exact solution."""

import numpy as np
import pytest
from scipy.optimize import brentq

import lieflow as lf
from lieflow import potentials as pot

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
METHODS = [("splitting", 1e-3, 2e-6), ("splitting4", 1e-2, 1e-7), ("splitting6", 1e-2, 1e-9),
           ("isospectral", 1e-3, 2e-6), ("lgvi", 1e-3, 2e-6), ("rk4", 1e-2, 1e-7)]


@pytest.fixture(scope="module")
def body():
    return lf.RigidBody(inertia=I)


def exact_zeros(body, t1, component=1):
    """Zeros of M_component(t) of the exact solution in (0, t1), with their directions."""
    f = lambda t: body.exact_solution(M0, t)[component]
    grid = np.linspace(0.0, t1, 20001)
    v = body.exact_solution(M0, grid)[:, component]
    out = []
    for k in np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:])):
        out.append((brentq(f, grid[k], grid[k + 1], xtol=1e-15, rtol=1e-15),
                    1.0 if v[k + 1] > v[k] else -1.0))
    return out


def g_m2(t, state):
    return state[1]


# ---------------------------------------------------------------- t0


def test_t0_offsets_the_times_only(body):
    a = lf.integrate(body, M0, dt=0.01, steps=300, save_every=30)
    b = lf.integrate(body, M0, dt=0.01, steps=300, save_every=30, t0=12.5)
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_allclose(b.t, 12.5 + a.t, rtol=0, atol=1e-13)
    assert (a.t0, b.t0, b.t[0]) == (0.0, 12.5, 12.5) and b.t_final == b.t[-1]
    assert abs(b.t_final - 15.5) < 1e-13 and b.status == 0 and b.t_events is None
    np.testing.assert_array_equal(b.initial_state, M0)
    x = np.diag([1.0, 1.5, 2.0])
    prb = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    with pytest.raises(lf.LeftDomainError, match=r"t = 10\.786.*step 786"):
        lf.integrate(prb, (x, -x), dt=1e-3, steps=2000, t0=10.0)
    for bad, exc in [("1", TypeError), (np.nan, lf.InvalidArgumentError), (True, TypeError)]:
        with pytest.raises(exc, match="t0"):
            lf.integrate(body, M0, dt=0.01, steps=3, t0=bad)


# ---------------------------------------------------------------- t_eval


@pytest.mark.parametrize("method, dt, tol", METHODS)
def test_t_eval_against_the_exact_solution(body, method, dt, tol):
    rng = np.random.default_rng(3)
    t_eval = np.sort(rng.uniform(0, 10, 50))
    r0 = np.eye(3)
    tr = lf.integrate(body, M0, dt=dt, steps=round(10 / dt), method=method, t_eval=t_eval,
                      attitude=r0)
    np.testing.assert_array_equal(tr.t, t_eval)
    assert tr.states.shape == (50, 3) and tr.attitude.shape == (50, 3, 3)
    assert tr.save_every is None and tr.status == 0
    np.testing.assert_allclose(tr.states, body.exact_solution(M0, t_eval), atol=tol)
    if method != "rk4":
        # The shortened steps are steps of the method: the Casimir, the spatial momentum and
        # the group are kept to round-off at every output time.
        c = tr.casimirs()[:, 0]
        assert np.abs(c / c[0] - 1).max() < 1e-13
        pi = tr.spatial_momentum()
        assert np.abs(pi - M0).max() < 1e-12
        rtr = np.einsum("kji,kjl->kil", tr.attitude, tr.attitude)
        assert np.abs(rtr - np.eye(3)).max() < 1e-13
    # The run goes on on its grid: the final state is that of the run without t_eval.
    plain = lf.integrate(body, M0, dt=dt, steps=round(10 / dt), method=method, attitude=r0,
                         save_every=round(10 / dt))
    np.testing.assert_array_equal(tr.final_state, plain.final_state)
    np.testing.assert_array_equal(tr.final_attitude, plain.final_attitude)
    assert tr.t_final == pytest.approx(10.0, abs=1e-12)


def test_t_eval_grid_times_chunks_and_batches(body):
    every = lf.integrate(body, M0, dt=0.01, steps=200, method="splitting4")
    t_eval = [0.0, 0.3, 0.305, 1.0, 1.999, 2.0]
    tr = lf.integrate(body, M0, dt=0.01, steps=200, method="splitting4", t_eval=t_eval)
    for k, step in [(0, 0), (1, 30), (3, 100), (5, 200)]:
        np.testing.assert_array_equal(tr.states[k], every.states[step])
    assert tr.t_final == 2.0 and tr.t[-1] == tr.t_final
    chunked = lf.integrate(body, M0, dt=0.01, steps=200, method="splitting4", t_eval=t_eval,
                           chunk_steps=7)
    np.testing.assert_array_equal(chunked.states, tr.states)
    m0 = np.array([M0, [0.2, -1.0, 0.4], [0.0, 0.3, 2.0]])
    batch = lf.integrate(body, m0, dt=0.01, steps=200, method="splitting4", t_eval=t_eval)
    assert batch.states.shape == (3, 6, 3)
    for i, m in enumerate(m0):
        one = lf.integrate(body, m, dt=0.01, steps=200, method="splitting4", t_eval=t_eval)
        np.testing.assert_array_equal(batch.states[i], one.states)
    empty = lf.integrate(body, np.zeros((0, 3)), dt=0.01, steps=200, t_eval=t_eval)
    assert empty.states.shape == (0, 6, 3)


def test_t_eval_without_steps_ends_at_its_last_time(body):
    t_eval = np.linspace(1.0, 3.2345, 7)
    tr = lf.integrate(body, M0, dt=0.01, t_eval=t_eval, method="splitting6", t0=1.0)
    np.testing.assert_array_equal(tr.t, t_eval)
    assert tr.t_final == 3.2345 and tr.status == 0
    np.testing.assert_array_equal(tr.final_state, tr.states[-1])
    np.testing.assert_allclose(tr.states, body.exact_solution(M0, t_eval - 1.0), atol=1e-10)
    one = lf.integrate(body, M0, dt=0.01, t_eval=[0.0])
    assert len(one) == 1 and one.t_final == 0.0
    np.testing.assert_array_equal(one.final_state, M0)


@pytest.mark.parametrize("kw, exc, match", [
    (dict(t_eval=[0.5, 0.2]), lf.InvalidArgumentError, "strictly increasing"),
    (dict(t_eval=[0.5, 0.5]), lf.InvalidArgumentError, "strictly increasing"),
    (dict(t_eval=[-0.1, 0.5]), lf.InvalidArgumentError, "precede t0"),
    (dict(t_eval=[0.5, 1.5]), lf.InvalidArgumentError, "pass the end"),
    (dict(t_eval=[0.5, np.nan]), lf.NonFiniteError, "t_eval"),
    (dict(t_eval=[]), lf.ShapeError, "t_eval"),
    (dict(t_eval=[[0.1, 0.2]]), lf.ShapeError, "t_eval"),
    (dict(t_eval=["a"]), TypeError, "t_eval"),
    (dict(t_eval=[1 + 1j]), TypeError, "t_eval"),
    (dict(t_eval=[0.5], save_every=10), lf.InvalidArgumentError, "save_every"),
    (dict(t_eval=[1e300], steps=None), lf.InvalidArgumentError, "steps"),
    (dict(steps=None), TypeError, "steps"),
])
def test_t_eval_errors(body, kw, exc, match):
    args = dict(dt=0.01, steps=100) | kw
    with pytest.raises(exc, match=match):
        lf.integrate(body, M0, **args)


# ---------------------------------------------------------------- events


@pytest.mark.parametrize("method, dt, tol", [("splitting6", 1e-2, 1e-10), ("rk4", 5e-3, 1e-8),
                                             ("splitting", 1e-3, 1e-5), ("lgvi", 1e-3, 1e-5)])
def test_events_located_against_the_exact_zeros(body, method, dt, tol):
    zeros = exact_zeros(body, 20.0)
    assert len(zeros) >= 4

    def up(t, s):
        return s[1]

    def down(t, s):
        return s[1]

    up.direction, down.direction = 1, -1.0
    tr = lf.integrate(body, M0, dt=dt, steps=round(20 / dt), method=method, save_every=100,
                      events=[g_m2, up, down])
    assert tr.status == 0 and len(tr.t_events) == 3 and tr.t_final == pytest.approx(20.0)
    t_all = tr.t_events[0]
    exact = np.array([z for z, _ in zeros])
    assert t_all.shape == exact.shape
    err = np.abs(t_all - exact).max()
    print(f"{method} dt = {dt}: max |t_event - t_exact| = {err:.2e}")
    assert err < tol
    rising = np.array([d > 0 for _, d in zeros])
    np.testing.assert_array_equal(tr.t_events[1], t_all[rising])
    np.testing.assert_array_equal(tr.t_events[2], t_all[~rising])
    # The event states are states of the method at the zero of its own trajectory.
    s = tr.state_events[0]
    assert s.shape == (len(zeros), 3) and np.abs(s[:, 1]).max() < 1e-13
    if method != "rk4":
        assert np.abs(body.casimirs(s)[:, 0] / body.casimirs(M0)[0] - 1).max() < 1e-13
    np.testing.assert_allclose(s, body.exact_solution(M0, t_all), atol=100 * tol)
    # Events do not change the trajectory.
    plain = lf.integrate(body, M0, dt=dt, steps=round(20 / dt), method=method, save_every=100)
    np.testing.assert_array_equal(tr.states, plain.states)


def test_terminal_events_end_the_run(body):
    zeros = exact_zeros(body, 20.0)
    falling = [z for z, d in zeros if d < 0]
    g = lambda t, s: s[1]
    g.terminal, g.direction = 2, -1
    tr = lf.integrate(body, M0, dt=0.01, steps=2000, method="splitting6", save_every=10,
                      events=[g_m2, g])
    assert tr.status == 1 and abs(tr.t_final - falling[1]) < 1e-10
    assert tr.t[-1] == tr.t_final and len(tr.t_events[1]) == 2
    np.testing.assert_array_equal(tr.states[-1], tr.final_state)
    np.testing.assert_array_equal(tr.final_state, tr.state_events[1][-1])
    assert np.all(np.diff(tr.t[:-1]) == pytest.approx(0.1))
    assert len(tr.t_events[0]) == sum(z <= tr.t_final + 1e-9 for z, _ in zeros)
    # terminal=True (a single callable), with t_eval: the samples before the event only.
    h = lambda t, s: s[2]
    h.terminal = True
    t_eval = np.arange(0, 20, 0.05) + 0.001
    tr = lf.integrate(body, M0, dt=0.01, steps=2000, method="splitting6", t_eval=t_eval,
                      events=h)
    first = exact_zeros(body, 20.0, component=2)[0][0]
    assert tr.status == 1 and abs(tr.t_final - first) < 1e-10
    np.testing.assert_array_equal(tr.t, t_eval[t_eval <= tr.t_final])
    np.testing.assert_array_equal(tr.final_state, tr.state_events[0][0])
    # With steps=None and t_eval: the event comes first.
    tr2 = lf.integrate(body, M0, dt=0.01, method="splitting6", t_eval=t_eval, events=h)
    np.testing.assert_array_equal(tr2.states, tr.states)
    assert tr2.t_final == tr.t_final


def test_events_with_attitude_and_tolerance(body):
    r0 = np.eye(3)
    tr = lf.integrate(body, M0, dt=0.01, steps=500, method="splitting6", attitude=r0,
                      events=g_m2)
    r = tr.attitude_events[0]
    assert r.shape == (len(tr.t_events[0]), 3, 3)
    assert np.abs(np.einsum("kji,kjl->kil", r, r) - np.eye(3)).max() < 1e-13
    exact = exact_zeros(body, 5.0)[0][0]
    loose = lf.integrate(body, M0, dt=0.01, steps=500, method="splitting6", events=g_m2,
                         event_tol=1e-4)
    assert 0 < abs(loose.t_events[0][0] - exact) < 1e-4


def test_event_errors(body):
    calls = []

    def raising(t, s):
        calls.append(t)
        if t > 0.5:
            raise ZeroDivisionError("from g")
        return 1.0

    with pytest.raises(ZeroDivisionError, match="from g") as e:
        lf.integrate(body, M0, dt=0.01, steps=100, events=raising, save_every=10)
    p = e.value.partial
    assert p.status == -1 and abs(p.t_final - 0.5) < 1e-12 and len(p) == 6
    with pytest.raises(lf.NonFiniteError, match="event function 0"):
        lf.integrate(body, M0, dt=0.01, steps=10, events=lambda t, s: np.nan)
    with pytest.raises(TypeError):
        lf.integrate(body, M0, dt=0.01, steps=10, events=lambda t, s: [1.0])
    with pytest.raises(TypeError):
        lf.integrate(body, M0, dt=0.01, steps=10, events=lambda t, s: "x")
    with pytest.raises(TypeError, match="events"):
        lf.integrate(body, M0, dt=0.01, steps=10, events=[g_m2, 1.0])
    bad = lambda t, s: s[1]
    bad.terminal = -1
    with pytest.raises(lf.InvalidArgumentError, match="terminal"):
        lf.integrate(body, M0, dt=0.01, steps=10, events=bad)
    bad.terminal, bad.direction = 1, "up"
    with pytest.raises(TypeError, match="direction"):
        lf.integrate(body, M0, dt=0.01, steps=10, events=bad)
    for d in (np.inf, -np.inf, np.nan):      # a direction is a finite number (its sign)
        bad.direction = d
        with pytest.raises(lf.InvalidArgumentError, match="direction: expected a finite number"):
            lf.integrate(body, M0, dt=0.01, steps=10, events=bad)
        run = body._start(np.array([M0]), None, 0.01, None, 1)
        with pytest.raises(lf.InvalidArgumentError, match="expected a finite number"):
            run.set_events([g_m2], [d], [0], 0.0)
    with pytest.raises(lf.ShapeError, match=r"t_eval .*expected \(k,\) with k ≥ 1"):
        body._start(np.array([M0]), None, 0.01, None, 1).save_at([])   # as t_eval=[] is
    with pytest.raises(lf.InvalidArgumentError, match="batch"):
        lf.integrate(body, np.tile(M0, (2, 1)), dt=0.01, steps=10, events=g_m2)
    with pytest.raises(lf.InvalidArgumentError, match="event_tol"):
        lf.integrate(body, M0, dt=0.01, steps=10, events=g_m2, event_tol=-1.0)


# ---------------------------------------------------------------- partial trajectories


def test_left_domain_error_carries_the_partial_trajectory():
    # X(t) = X0 (cos t − sin t) leaves GL+(3) at t = π/4: found in step 786 with dt = 1e-3.
    x = np.diag([1.0, 1.5, 2.0])
    prb = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    for chunk in (100, 10_000):
        with pytest.raises(lf.LeftDomainError, match=r"t = 0\.786.*step 786") as e:
            lf.integrate(prb, (x, -x), dt=1e-3, steps=2000, save_every=100, chunk_steps=chunk)
        p = e.value.partial
        assert isinstance(p, lf.Trajectory) and p.status == -1
        np.testing.assert_allclose(p.t, np.arange(8) * 0.1, atol=1e-14)
        assert p.t_final == pytest.approx(0.785, abs=1e-12)
        xf = p.final_state[:9].reshape(3, 3)
        assert np.linalg.det(xf) > 0
        np.testing.assert_allclose(xf, x * (np.cos(0.785) - np.sin(0.785)), atol=1e-6)
        assert any("err.partial" in n and "step 785" in n for n in e.value.__notes__)
    # t_eval: the samples before the failure.
    with pytest.raises(lf.LeftDomainError) as e:
        lf.integrate(prb, (x, -x), dt=1e-3, steps=2000, t_eval=np.linspace(0, 2, 9))
    p = e.value.partial
    np.testing.assert_array_equal(p.t, [0.0, 0.25, 0.5, 0.75])
    # A gas that collapses past det X = 0 in one step.
    gas = lf.PseudoRigidBody(3, potential=pot.Volumetric(0.1))
    with pytest.raises(lf.LeftDomainError, match="volumetric") as e:
        lf.integrate(gas, (x, -30 * x), dt=0.05, steps=20)
    p = e.value.partial
    assert len(p) == 1 and p.t_final == 0.0
    np.testing.assert_array_equal(p.final_state, p.states[0])
    # A batch: the trajectory up to the last completed native call.
    xs, ps = np.stack([x, x]), np.stack([0 * x, -x])
    with pytest.raises(lf.LeftDomainError, match="batch member 1") as e:
        lf.integrate(prb, (xs, ps), dt=1e-3, steps=1000, save_every=50, chunk_steps=300)
    p = e.value.partial
    assert p.states.shape == (2, 13, 18) and p.t_final == pytest.approx(0.6)


def test_ctrl_c_carries_the_partial_trajectory(interrupted):
    out, err, _, _ = interrupted(
        "import signal, lieflow as lf, numpy as np\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "body = lf.RigidBody([1, 2, 3])\n"
        "print('start', flush=True)\n"
        "try:\n"
        "    lf.integrate(body, [1, .5, -.3], dt=1e-3, steps=10**11, save_every=10**6)\n"
        "except KeyboardInterrupt as e:\n"
        "    p = e.partial\n"
        "    again = lf.integrate(body, [1, .5, -.3], dt=1e-3, steps=round(p.t_final / 1e-3),\n"
        "                         save_every=10**6)\n"
        "    print(p.status, len(p), p.t_final, np.abs(again.final_state - p.final_state).max(),\n"
        "          any('err.partial' in n for n in e.__notes__), flush=True)\n",
        after=1.0)
    status, k, t_final, diff, noted = out.split()
    assert status == "-1" and int(k) >= 1 and float(t_final) > 0 and noted == "True", err
    assert float(diff) < 1e-12


# ---------------------------------------------------------------- concatenation


@pytest.mark.parametrize("save_every", [10, 7])
def test_concatenation_equals_a_single_run(body, save_every):
    kw = dict(dt=0.01, method="splitting6", save_every=save_every, attitude=np.eye(3),
              events=g_m2)
    whole = lf.integrate(body, M0, steps=700, **kw)
    a = lf.integrate(body, M0, steps=300, **kw)
    b = lf.integrate(body, a.final_state, steps=400, t0=a.t_final,
                     **(kw | dict(attitude=a.final_attitude)))
    both = lf.Trajectory.concatenate([a, b])
    assert both.method == "splitting6" and both.t_final == pytest.approx(7.0, abs=1e-12)
    np.testing.assert_allclose(both.final_state, whole.final_state, atol=1e-13)
    np.testing.assert_allclose(both.final_attitude, whole.final_attitude, atol=1e-13)
    np.testing.assert_allclose(both.t_events[0], whole.t_events[0], atol=1e-12)
    np.testing.assert_allclose(both.state_events[0], whole.state_events[0], atol=1e-13)
    if save_every == 10:        # the seam is a sample: kept once
        np.testing.assert_allclose(both.t, whole.t, atol=1e-12)
        np.testing.assert_allclose(both.states, whole.states, atol=1e-13)
        np.testing.assert_allclose(both.attitude, whole.attitude, atol=1e-13)
    else:                       # 300 = 42·7 + 6: the continuation's samples are its own
        assert len(both) == len(a) + len(b)
        assert both.t[len(a)] == a.t_final and np.all(np.diff(both.t) > 0)
    # Three parts, t_eval, and the continuation from t_final.
    t_eval = np.linspace(0, 7, 15)
    one = lf.integrate(body, M0, dt=0.01, method="splitting6", t_eval=t_eval)
    p1 = lf.integrate(body, M0, dt=0.01, method="splitting6", t_eval=t_eval[:5])
    p2 = lf.integrate(body, p1.final_state, dt=0.01, method="splitting6", t0=p1.t_final,
                      t_eval=t_eval[4:10])
    p3 = lf.integrate(body, p2.final_state, dt=0.01, method="splitting6", t0=p2.t_final,
                      t_eval=t_eval[9:])
    joined = lf.Trajectory.concatenate([p1, p2, p3])
    np.testing.assert_array_equal(joined.t, t_eval)
    np.testing.assert_allclose(joined.states, one.states, atol=1e-12)


def test_concatenation_errors(body):
    a = lf.integrate(body, M0, dt=0.01, steps=100)
    late = lf.integrate(body, a.final_state, dt=0.01, steps=100, t0=a.t_final + 0.5)
    other = lf.integrate(body, M0, dt=0.01, steps=100, t0=a.t_final)
    elsewhere = lf.integrate(lf.RigidBody([1, 2, 4]), a.final_state, dt=0.01, steps=10,
                             t0=a.t_final)
    with pytest.raises(lf.InvalidArgumentError, match="not where the one before ended"):
        lf.Trajectory.concatenate([a, late])
    with pytest.raises(lf.InvalidArgumentError, match="final state"):
        lf.Trajectory.concatenate([a, other])
    with pytest.raises(lf.InvalidArgumentError, match="another system"):
        lf.Trajectory.concatenate([a, elsewhere])
    with pytest.raises(lf.InvalidArgumentError, match="nothing"):
        lf.Trajectory.concatenate([])
    with pytest.raises(TypeError):
        lf.Trajectory.concatenate([a, 1])
    same = lf.integrate(lf.RigidBody(I), a.final_state, dt=0.02, steps=10, t0=a.t_final)
    joined = lf.Trajectory.concatenate([a, same])      # an equal system, another step
    assert joined.dt is None and len(joined) == 111
