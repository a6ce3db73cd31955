"""lieflow.integrate: the driver (save_every, batches, chunks, attitude, progress, Ctrl-C, every
error path) and the integrated dynamics of each system against independent references (the exact
rigid-body solution, scipy's DOP853 at rtol 1e-12, conservation laws)."""

import os
import sys
import time
import warnings

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.integrate import solve_ivp

import lieflow as lf

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])


@pytest.fixture(scope="module")
def body():
    return lf.RigidBody(inertia=I)


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


# ---------------------------------------------------------------- driver


def test_trajectory_shape_and_times(body):
    tr = lf.integrate(body, M0, dt=0.01, steps=1000, method="splitting", save_every=100)
    assert isinstance(tr, lf.Trajectory) and len(tr) == 11 and not tr.batched
    assert tr.states.shape == (11, 3) and tr.attitude is None and tr.final_attitude is None
    np.testing.assert_allclose(tr.t, np.arange(11) * 1.0, atol=1e-15)
    np.testing.assert_array_equal(tr.states[0], M0)
    np.testing.assert_array_equal(tr.final_state, tr.states[-1])
    assert tr.system is body and tr.method == "splitting" and tr.dt == 0.01
    assert tr.save_every == 100 and "RigidBody" in repr(tr)
    assert tr.energy().shape == (11,) and tr.casimirs().shape == (11, 1)


def test_default_method_is_splitting(body):
    a = lf.integrate(body, M0, dt=0.01, steps=50)
    b = lf.integrate(body, M0, dt=0.01, steps=50, method="splitting")
    assert a.method == "splitting" and a.states.shape == (51, 3)
    np.testing.assert_array_equal(a.states, b.states)


@pytest.mark.parametrize("steps, save_every", [(10, 3), (9, 3), (5, 7), (1, 1)])
def test_save_every_semantics(body, steps, save_every):
    every = lf.integrate(body, M0, dt=0.05, steps=steps, method="splitting4")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tr = lf.integrate(body, M0, dt=0.05, steps=steps, method="splitting4",
                          save_every=save_every)
    # Only the start kept (save_every beyond steps) is worth a warning.
    assert len(caught) == (save_every > steps)
    k = steps // save_every + 1
    assert tr.states.shape == (k, 3)
    np.testing.assert_allclose(tr.t, np.arange(k) * save_every * 0.05)
    np.testing.assert_allclose(tr.states, every.states[::save_every][:k], atol=1e-14)
    # The final state is the state after all steps, saved or not.
    np.testing.assert_allclose(tr.final_state, every.states[-1], atol=1e-14)


def test_batch_equals_single_runs(body):
    m0 = np.array([[1.0, 0.5, -0.3], [0.2, -1.0, 0.4], [0.0, 0.0, 2.0], [3.0, 1.0, 1.0]])
    for method in ["splitting6", "isospectral", "rk4"]:
        tr = lf.integrate(body, m0, dt=0.02, steps=300, method=method, save_every=7)
        assert tr.batched and tr.states.shape == (4, 300 // 7 + 1, 3)
        assert tr.energy().shape == (4, 43) and tr.casimirs().shape == (4, 43, 1)
        for i, m in enumerate(m0):
            one = lf.integrate(body, m, dt=0.02, steps=300, method=method, save_every=7)
            np.testing.assert_array_equal(tr.states[i], one.states)
            np.testing.assert_array_equal(tr.final_state[i], one.final_state)


def test_empty_batch(body):
    tr = lf.integrate(body, np.zeros((0, 3)), dt=0.1, steps=5)
    assert tr.states.shape == (0, 6, 3)


@pytest.mark.parametrize("chunk_steps, save_every", [(7, 3), (3, 10), (1, 1), (12, 4), (5, 23)])
def test_chunked_equals_one_run(body, chunk_steps, save_every):
    kw = dict(dt=0.01, steps=100, method="splitting6", save_every=save_every, attitude=np.eye(3))
    one = lf.integrate(body, M0, **kw)
    chunked = lf.integrate(body, M0, chunk_steps=chunk_steps, **kw)
    assert chunked.states.shape == one.states.shape
    assert chunked.attitude.shape == one.attitude.shape
    np.testing.assert_allclose(chunked.states, one.states, atol=1e-14)
    np.testing.assert_allclose(chunked.attitude, one.attitude, atol=1e-14)
    np.testing.assert_allclose(chunked.final_state, one.final_state, atol=1e-14)
    np.testing.assert_allclose(chunked.final_attitude, one.final_attitude, atol=1e-14)


def test_continue_from_final_state(body):
    full = lf.integrate(body, M0, dt=0.01, steps=200, method="lgvi", attitude=np.eye(3))
    half = lf.integrate(body, M0, dt=0.01, steps=100, method="lgvi", attitude=np.eye(3))
    rest = lf.integrate(body, half.final_state, dt=0.01, steps=100, method="lgvi",
                        attitude=half.final_attitude)
    np.testing.assert_allclose(rest.states, full.states[100:], atol=1e-13)


class Recording:
    """A duck-typed system (the protocol only) that records (steps, time) of each native call."""

    def __init__(self, inner):
        self.inner, self.calls = inner, []

    def __getattr__(self, name):
        return getattr(self.inner, name)

    def _start(self, *args, **kwargs):
        run, calls = self.inner._start(*args, **kwargs), self.calls

        class Run:
            method = run.method

            def advance(self, steps):
                calls.append((steps, run.time))
                return run.advance(steps)

            def state(self):
                return run.state()

        return Run()


def test_default_chunking_splits_long_runs(body, monkeypatch):
    monkeypatch.setattr(sys.modules["lieflow.integrate"], "CHUNK_WORK", 1000)
    monkeypatch.setattr(sys.modules["lieflow.integrate"], "MIN_CHUNK_STEPS", 100)
    rec = Recording(body)
    tr = lf.integrate(rec, np.tile(M0, (4, 1)), dt=0.01, steps=1000, save_every=100)
    assert rec.calls == [(250, k * 2.5) for k in range(4)] and tr.states.shape == (4, 11, 3)
    one = lf.integrate(body, np.tile(M0, (4, 1)), dt=0.01, steps=1000, save_every=100)
    np.testing.assert_allclose(tr.states, one.states, atol=1e-14)
    rec = Recording(body)
    tr = lf.integrate(rec, M0, dt=0.01, steps=2500, save_every=700)   # cap 1000 < save_every
    assert [n for n, _ in rec.calls] == [1000, 1000, 500] and len(tr) == 4
    rec = Recording(body)
    lf.integrate(rec, np.tile(M0, (50, 1)), dt=0.01, steps=250, save_every=1)
    assert [n for n, _ in rec.calls] == [100, 100, 50]  # MIN_CHUNK_STEPS for big batches


def test_progress_bar_tqdm_and_fallback(body, capsys, monkeypatch):
    pytest.importorskip("tqdm")
    lf.integrate(body, M0, dt=0.01, steps=100, progress=True, chunk_steps=30)
    assert "100/100" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)     # import fails: plain stderr line
    lf.integrate(body, M0, dt=0.01, steps=100, progress=True, chunk_steps=30)
    err = capsys.readouterr().err
    assert "RigidBody splitting: 30/100 steps" in err and "100/100 steps (100.0%)" in err
    lf.integrate(body, M0, dt=0.01, steps=100)
    assert capsys.readouterr().err == ""


def test_ctrl_c_stops_a_long_run(interrupted):
    """SIGINT during a long integration: KeyboardInterrupt between chunks, promptly."""
    out, err, code, _ = interrupted(
        "import signal, sys, lieflow as lf\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "body = lf.RigidBody([1, 2, 3])\n"
        "print('start', flush=True)\n"
        "lf.integrate(body, [1, .5, -.3], dt=1e-3, steps=10**11, save_every=10**11)\n"
        "print('finished', flush=True)\n"
    )
    assert "KeyboardInterrupt" in err and "finished" not in out
    assert code != 0


# ---------------------------------------------------------------- errors


@pytest.mark.parametrize("kw, exc, match", [
    (dict(dt=0.0), lf.InvalidArgumentError, "dt"),
    (dict(dt=-0.1), lf.InvalidArgumentError, "dt"),
    (dict(dt=np.nan), lf.InvalidArgumentError, "dt"),
    (dict(dt=np.inf), lf.InvalidArgumentError, "dt"),
    (dict(dt="x"), TypeError, "dt"),
    (dict(steps=0), lf.InvalidArgumentError, "steps"),
    (dict(steps=-3), lf.InvalidArgumentError, "steps"),
    (dict(steps=2.5), TypeError, "steps"),
    (dict(steps=True), TypeError, "steps"),
    (dict(save_every=0), lf.InvalidArgumentError, "save_every"),
    (dict(chunk_steps=0), lf.InvalidArgumentError, "chunk_steps"),
    (dict(method="euler"), lf.UnsupportedMethodError, "supported methods: splitting, "),
    (dict(method=3), TypeError, "method"),
])
def test_bad_arguments(body, kw, exc, match):
    args = dict(dt=0.01, steps=10) | kw
    with pytest.raises(exc, match=match):
        lf.integrate(body, M0, **args)


@pytest.mark.parametrize("state0, exc", [
    ([1.0, 2.0], lf.ShapeError),
    (np.zeros((2, 4)), lf.ShapeError),
    (np.zeros((2, 2, 3)), lf.ShapeError),
    ([1.0, np.nan, 0.0], lf.NonFiniteError),
    ([[1.0, 0.0, 0.0], [np.inf, 0.0, 0.0]], lf.NonFiniteError),
])
def test_bad_states(body, state0, exc):
    with pytest.raises(exc):
        lf.integrate(body, state0, dt=0.01, steps=10)


def test_unsupported_method_lists_supported():
    top = lf.HeavyTop(I, 1.0)
    z = top.state(M0, [0.0, 0.0, 1.0])
    with pytest.raises(lf.UnsupportedMethodError,
                       match="splitting, splitting4, splitting6, splitting8, processed6, .*, lgvi, rk4"):
        lf.integrate(top, z, dt=0.01, steps=10, method="isospectral")
    with pytest.raises(lf.UnsupportedMethodError, match="isospectral, rk4"):
        lf.integrate(lf.GeneralizedRigidBody([1, 2, 3, 4]), np.ones(6), dt=0.01, steps=10,
                     method="splitting")
    with pytest.raises(lf.UnsupportedMethodError, match=r"dmv10, rk4.*\(did you mean \"rk4\"\?\)"):
        lf.integrate(lf.RigidBody(I), M0, dt=0.01, steps=10, method="rk5")
    with pytest.raises(lf.UnsupportedMethodError) as e:
        lf.integrate(lf.RigidBody(I), M0, dt=0.01, steps=10, method="verlet")
    assert "did you mean" not in str(e.value) and "reduced" not in str(e.value)
    # The default method is the system's own first method (it was "splitting" for every system).
    for system, z0 in [(lf.GeneralizedRigidBody([1, 2, 3, 4]), np.ones(6)),
                       (lf.PseudoRigidBody(2), (np.eye(2), np.ones((2, 2))))]:
        tr = lf.integrate(system, z0, dt=0.01, steps=10)
        assert tr.method == system.methods()[0] and len(tr) == 11


def test_bad_attitudes(body):
    with pytest.raises(lf.NotInGroupError, match="SO\\(3\\)"):
        lf.integrate(body, M0, dt=0.01, steps=10, attitude=2 * np.eye(3))
    with pytest.raises(lf.NotInGroupError, match="det"):
        lf.integrate(body, M0, dt=0.01, steps=10, attitude=-np.eye(3))
    with pytest.raises(lf.NonFiniteError):
        lf.integrate(body, M0, dt=0.01, steps=10, attitude=np.full((3, 3), np.nan))
    with pytest.raises(lf.ShapeError):
        lf.integrate(body, M0, dt=0.01, steps=10, attitude=np.eye(2))
    with pytest.raises(lf.ShapeError):
        lf.integrate(body, M0, dt=0.01, steps=10, attitude=np.tile(np.eye(3), (2, 1, 1)))
    with pytest.raises(lf.ShapeError):
        lf.integrate(body, np.tile(M0, (3, 1)), dt=0.01, steps=10,
                     attitude=np.tile(np.eye(3), (2, 1, 1)))
    with pytest.raises(lf.InvalidArgumentError, match="carries no attitude"):
        lf.integrate(lf.SphericalPendulum(), lf.SphericalPendulum().state_from_spherical(1, 0),
                     dt=0.01, steps=10, attitude=np.eye(3))


def test_constraint_errors():
    p = lf.SphericalPendulum()
    z = p.state_from_spherical([0.5, 1.0, 1.5], 0.0)
    z[2, 0] += 0.1
    with pytest.raises(lf.InvalidArgumentError, match=r"batch member 2: .*\|q\| = 1"):
        lf.integrate(p, z, dt=0.01, steps=10)
    with pytest.raises(lf.InvalidArgumentError, match=r"\|q\| = 1"):
        lf.integrate(p, [0, 0, -2.0, 0, 0, 0], dt=0.01, steps=10)
    with pytest.raises(lf.InvalidArgumentError, match=r"q·L = 0"):
        lf.integrate(p, [0, 0, -1.0, 0, 0, 1.0], dt=0.01, steps=10)
    top = lf.HeavyTop(I, 1.0)
    with pytest.raises(lf.InvalidArgumentError, match="Γ must equal"):
        lf.integrate(top, top.state(M0, [1.0, 0, 0]), dt=0.01, steps=10, attitude=np.eye(3))


def test_solver_failures_are_typed_errors():
    """Absurd steps: the implicit solvers report non-convergence, RK4 the blow-up."""
    body = lf.RigidBody(I)
    for method in ["isospectral", "lgvi"]:
        with pytest.raises(lf.ConvergenceError, match="did not converge"):
            lf.integrate(body, [100.0, 50.0, -30.0], dt=10.0, steps=100, method=method)
    with pytest.raises(lf.LeftDomainError, match="non-finite"):
        lf.integrate(body, [100.0, 50.0, -30.0], dt=10.0, steps=100, method="rk4")


def test_trajectory_forwarding(body):
    tr = lf.integrate(body, M0, dt=0.01, steps=100, save_every=10)
    np.testing.assert_allclose(tr.angular_velocity(), tr.states / I)
    np.testing.assert_array_equal(tr.M, tr.states)
    assert "angular_velocity" in dir(tr) and "M" in dir(tr)
    with pytest.raises(AttributeError):
        tr.no_such_observable
    with pytest.raises(AttributeError):
        tr._private
    with pytest.raises(lf.InvalidArgumentError, match="attitude"):
        tr.spatial_momentum()


# ---------------------------------------------------------------- dynamics


@pytest.mark.parametrize("method, dt, tol", [
    ("splitting", 1e-3, 1e-5), ("splitting4", 1e-2, 1e-7), ("splitting6", 1e-2, 1e-9),
    ("isospectral", 1e-3, 1e-5), ("lgvi", 1e-3, 1e-5), ("rk4", 1e-2, 1e-7),
])
def test_rigid_body_against_exact_solution(body, method, dt, tol):
    tr = lf.integrate(body, M0, dt=dt, steps=round(10 / dt), method=method,
                      save_every=round(1 / dt))
    np.testing.assert_allclose(tr.states, body.exact_solution(M0, tr.t), atol=tol)


@pytest.mark.parametrize("method, order", [("splitting", 2), ("splitting4", 4),
                                           ("splitting6", 6), ("rk4", 4)])
def test_observed_order(body, method, order):
    exact = body.exact_solution(M0, 10.0)
    errs = [np.abs(lf.integrate(body, M0, dt=10 / n, steps=n, method=method,
                                save_every=n).final_state - exact).max() for n in (50, 100)]
    assert abs(np.log2(errs[0] / errs[1]) - order) < 0.3


@pytest.mark.parametrize("method", ["splitting", "splitting6", "isospectral", "lgvi"])
def test_rigid_body_conservation(body, method):
    r0 = rotation([1, 2, 3], 0.7)
    tr = lf.integrate(body, M0, dt=0.01, steps=20000, method=method, save_every=100, attitude=r0)
    c = tr.casimirs()[:, 0]
    assert np.abs(c / c[0] - 1).max() < 1e-13
    e = tr.energy()
    assert np.abs(e / e[0] - 1).max() < 1e-3                 # bounded, no drift
    pi = tr.spatial_momentum()
    assert np.abs(pi - pi[0]).max() < 1e-12
    rtr = np.einsum("kji,kjl->kil", tr.attitude, tr.attitude)
    assert np.abs(rtr - np.eye(3)).max() < 1e-13
    assert np.allclose(np.linalg.det(tr.attitude), 1.0, atol=1e-13)


def test_attitude_matches_reconstruction_ode(body):
    """Ṙ = R hat(Ω) with Ω = I⁻¹M, solved with Euler's equation by DOP853."""
    def f(t, y):
        m, r = y[:3], y[3:].reshape(3, 3)
        w = m / I
        hat = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        return np.concatenate([np.cross(m, w), (r @ hat).ravel()])
    r0 = rotation([0, 1, 1], 0.3)
    ref = solve_ivp(f, (0, 5), np.concatenate([M0, r0.ravel()]), method="DOP853", rtol=1e-12,
                    atol=1e-13).y[:, -1]
    tr = lf.integrate(body, M0, dt=5e-3, steps=1000, method="splitting6", attitude=r0,
                      save_every=1000)
    np.testing.assert_allclose(tr.final_attitude, ref[3:].reshape(3, 3), atol=1e-9)
    np.testing.assert_allclose(tr.final_state, ref[:3], atol=1e-9)


def test_matrix_inertia_integrates_in_the_given_frame(body):
    q = rotation([1, -1, 2], 1.1)
    rotated = lf.RigidBody(q @ np.diag(I) @ q.T)
    a = lf.integrate(rotated, q @ M0, dt=0.01, steps=500, method="splitting4", save_every=50)
    b = lf.integrate(body, M0, dt=0.01, steps=500, method="splitting4", save_every=50)
    np.testing.assert_allclose(a.states, b.states @ q.T, atol=1e-12)


def test_heavy_top_against_dop853():
    top = lf.HeavyTop([1.0, 2.0, 3.0], 0.8, chi=[0.3, 0.2, 1.0])
    chi = np.array([0.3, 0.2, 1.0]) / np.linalg.norm([0.3, 0.2, 1.0])

    def f(t, y):
        m, g = y[:3], y[3:]
        w = m / np.array([1.0, 2.0, 3.0])
        return np.concatenate([np.cross(m, w) + 0.8 * np.cross(g, chi), np.cross(g, w)])

    g0 = rotation([1, 0, 0], 0.4)[2]
    z0 = top.state(M0, g0)
    ref = solve_ivp(f, (0, 5), z0, method="DOP853", rtol=1e-12, atol=1e-13).y[:, -1]
    for method in ["splitting6", "rk4"]:
        tr = lf.integrate(top, z0, dt=5e-3, steps=1000, method=method, save_every=1000)
        np.testing.assert_allclose(tr.final_state, ref, atol=1e-8)
    tr = lf.integrate(top, (M0, g0), dt=0.01, steps=5000, method="splitting", save_every=50)
    c = tr.casimirs()
    assert np.abs(c - c[0]).max() < 1e-12
    assert np.ptp(tr.energy()) < 1e-3


def test_heavy_top_matrix_inertia():
    q = rotation([2, 1, -1], 0.8)
    chi = np.array([0.2, 0.1, 1.0])
    a = lf.HeavyTop(q @ np.diag(I) @ q.T, 0.6, chi=q @ chi)
    b = lf.HeavyTop(I, 0.6, chi=chi)
    np.testing.assert_allclose(np.sort(a.moments), I, rtol=1e-12)
    g0 = rotation([1, 0, 0], 0.4)[2]
    ta = lf.integrate(a, (q @ M0, q @ g0), dt=0.01, steps=300, method="splitting4", save_every=30)
    tb = lf.integrate(b, (M0, g0), dt=0.01, steps=300, method="splitting4", save_every=30)
    np.testing.assert_allclose(ta.M, tb.M @ q.T, atol=1e-12)
    np.testing.assert_allclose(ta.Gamma, tb.Gamma @ q.T, atol=1e-12)
    np.testing.assert_allclose(ta.energy(), tb.energy(), atol=1e-13)


def test_lagrange_top_and_attitude():
    top = lf.HeavyTop([2.0, 2.0, 1.0], 1.5)
    r0 = rotation([1, 1, 0], 0.5)
    z0 = top.state(M0, attitude=r0)
    for method in ["splitting4", "lgvi"]:
        tr = lf.integrate(top, z0, dt=0.01, steps=3000, method=method, save_every=30, attitude=r0)
        assert np.ptp(tr.M[:, 2]) < 1e-12                          # M3 of the Lagrange top
        np.testing.assert_allclose(tr.Gamma, tr.attitude[:, 2, :], atol=1e-12)   # Γ = Rᵀe3
        vertical = tr.spatial_momentum()[:, 2]
        assert np.ptp(vertical) < 1e-12


def test_spherical_pendulum_against_spherical_coordinates():
    """000 §5.1.1 with θ from the downward vertical: θ̈ = sinθ cosθ φ̇² − (g/l) sinθ,
    ml² sin²θ φ̇ = L3."""
    p = lf.SphericalPendulum(mass=1.3, length=0.7, g=9.81)
    th0, thd0, phd0 = 0.9, 0.2, 1.5

    def f(t, y):
        th, ph, thd, phd = y
        return [thd, phd, np.sin(th) * np.cos(th) * phd**2 - 9.81 / 0.7 * np.sin(th),
                -2 * thd * phd * np.cos(th) / np.sin(th)]

    ref = solve_ivp(f, (0, 3), [th0, 0.0, thd0, phd0], method="DOP853", rtol=1e-12, atol=1e-13,
                    t_eval=[3.0]).y[:, -1]
    z0 = p.state_from_spherical(th0, 0.0, thd0, phd0)
    zr = p.state_from_spherical(*ref)
    for method in ["splitting4", "splitting6", "rk4"]:
        tr = lf.integrate(p, z0, dt=1e-3, steps=3000, method=method, save_every=3000)
        np.testing.assert_allclose(tr.final_state, zr, atol=1e-8)
    tr = lf.integrate(p, z0, dt=0.01, steps=5000, method="splitting", save_every=50)
    assert np.ptp(tr.vertical_momentum()) < 1e-12
    assert np.abs(tr.casimirs() - [1.0, 0.0]).max() < 1e-12
    assert np.ptp(tr.energy()) < 1e-2 * abs(tr.energy()[0])
    assert tr.q.shape == (101, 3) and tr.L.shape == (101, 3)


def test_generalized_rigid_body_isospectral():
    rng = np.random.default_rng(7)
    for n in (4, 5):
        body = lf.GeneralizedRigidBody(np.arange(1.0, n + 1))
        a = rng.standard_normal((n, n))
        z0 = body.state(a - a.T)
        tr = lf.integrate(body, z0, dt=0.01, steps=2000, method="isospectral", save_every=100)
        c = tr.casimirs()
        assert np.abs(c / c[0] - 1).max() < 1e-12
        ev = np.sort(np.abs(np.linalg.eigvals(tr.M)), axis=-1)
        assert np.abs(ev - ev[0]).max() < 1e-11
        fine = lf.integrate(body, z0, dt=0.002, steps=10000, method="rk4", save_every=500)
        np.testing.assert_allclose(tr.states, fine.states, atol=1e-3 * np.abs(z0).max())


# ---------------------------------------------------------------- robustness


CASES = [
    (lambda i: lf.RigidBody(i), lambda m, system, r0: m, ["splitting", "splitting4", "splitting6",
                                                   "isospectral", "lgvi", "rk4"]),
    (lambda i: lf.HeavyTop(i, 0.5, chi=[0.1, 0.2, 1.0]),
     lambda m, system, r0: system.state(m, attitude=r0),
     ["splitting", "splitting4", "splitting6", "lgvi", "rk4"]),
]


@settings(max_examples=40, deadline=None)
@given(inertia=st.lists(st.floats(0.2, 5.0), min_size=3, max_size=3),
       m=st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
       dt=st.floats(1e-4, 0.05), case=st.integers(0, 1), seed=st.integers(0, 2**31),
       method_index=st.integers(0, 5))
def test_random_valid_inputs_never_give_nan(inertia, m, dt, case, seed, method_index):
    make, state, methods = CASES[case]
    rng = np.random.default_rng(seed)
    system = make(np.array(inertia))
    method = methods[method_index % len(methods)]
    r0 = rotation(rng.standard_normal(3) + 0.1, rng.uniform(0, 3))
    z0 = state(np.array(m), system, r0)
    tr = lf.integrate(system, z0, dt=dt, steps=200, method=method, save_every=10, attitude=r0)
    assert np.all(np.isfinite(tr.states)) and np.all(np.isfinite(tr.attitude))
    assert np.all(np.isfinite(tr.energy())) and np.all(np.isfinite(tr.casimirs()))


@settings(max_examples=15, deadline=None)
@given(n=st.integers(3, 5), seed=st.integers(0, 2**31), dt=st.floats(1e-4, 0.05),
       method=st.sampled_from(lf.GeneralizedRigidBody.methods()))
def test_random_so_n_body_never_gives_nan(n, seed, dt, method):
    rng = np.random.default_rng(seed)
    body = lf.GeneralizedRigidBody(rng.uniform(0.3, 3.0, n))
    z0 = rng.uniform(-2, 2, n * (n - 1) // 2)
    tr = lf.integrate(body, z0, dt=dt, steps=100, method=method, save_every=10)
    assert np.all(np.isfinite(tr.states)) and np.all(np.isfinite(tr.casimirs()))


@settings(max_examples=15, deadline=None)
@given(theta=st.floats(0.01, 3.1), thd=st.floats(-3, 3), phd=st.floats(-3, 3),
       dt=st.floats(1e-4, 0.02), method=st.sampled_from(lf.SphericalPendulum.methods()))
def test_random_pendulum_never_gives_nan(theta, thd, phd, dt, method):
    p = lf.SphericalPendulum()
    tr = lf.integrate(p, p.state_from_spherical(theta, 0.0, thd, phd), dt=dt, steps=200,
                      method=method, save_every=20)
    assert np.all(np.isfinite(tr.states))


def test_integration_releases_the_gil():
    # A Python thread counts while one long native call runs. With the GIL released it counts at
    # its free rate; were the GIL held, it could only run for the few ms of a switch interval.
    import threading

    counter, stop = [0], threading.Event()

    def count():
        while not stop.is_set():
            counter[0] += 1

    body = lf.RigidBody([1.0, 2.0, 3.0])
    t = threading.Thread(target=count)
    t.start()
    try:
        time.sleep(0.02)
        c0, t0 = counter[0], time.perf_counter()
        time.sleep(0.1)
        rate = (counter[0] - c0) / (time.perf_counter() - t0)
        c0, t0 = counter[0], time.perf_counter()
        steps = 5_000_000
        lf.integrate(body, M0, dt=1e-5, steps=steps, method="rk4", save_every=steps,
                     chunk_steps=steps)
        seconds = time.perf_counter() - t0
        during = counter[0] - c0
    finally:
        stop.set()
        t.join()
    assert seconds > 0.05 and during > 0.15 * rate * seconds, (seconds, during, rate)


def test_save_every_beyond_steps_warns_that_only_the_start_is_kept():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    with pytest.warns(lf.LieflowWarning, match=r"save_every = 100 exceeds steps = 10"):
        traj = lf.integrate(body, [1.0, 0.5, -0.3], 0.01, 10, save_every=100)
    assert len(traj) == 1 and traj.t_final == pytest.approx(0.1)
    assert issubclass(lf.LieflowWarning, UserWarning)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lf.integrate(body, [1.0, 0.5, -0.3], 0.01, 10, save_every=10)   # the last kept: quiet


def test_t_span_ends_exactly_at_t1_in_equal_steps_no_longer_than_dt():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = [1.0, 0.5, -0.3]
    traj = lf.integrate(body, m0, 0.03, t_span=(0.5, 1.5))      # 1/0.03 = 33.3: 34 steps
    assert len(traj) == 35 and traj.dt == pytest.approx(1 / 34, rel=1e-15)
    assert traj.t[0] == 0.5 and traj.t_final == pytest.approx(1.5, abs=1e-15)
    same = lf.integrate(body, m0, 1 / 34, 34, t0=0.5)
    np.testing.assert_array_equal(traj.states, same.states)
    # A span that dt divides: that many steps of dt exactly.
    assert len(lf.integrate(body, m0, 0.1, t_span=(0, 1))) == 11
    with pytest.raises(lf.InvalidArgumentError, match="t_span"):
        lf.integrate(body, m0, 0.1, 10, t_span=(0, 1))
    with pytest.raises(lf.InvalidArgumentError, match="t_span"):
        lf.integrate(body, m0, 0.1, t0=0.0, t_span=(0, 1))
    with pytest.raises(lf.InvalidArgumentError, match="t0 < t1"):
        lf.integrate(body, m0, 0.1, t_span=(1, 1))
    with pytest.raises(TypeError, match="t_span"):
        lf.integrate(body, m0, 0.1, t_span=1.0)
    with pytest.raises(TypeError, match=r"t_span\[1\]"):
        lf.integrate(body, m0, 0.1, t_span=(0, "1"))


def test_a_step_that_resolves_the_rotation_badly_warns_once_per_run():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = [1.0, 0.5, -0.3]                                  # |Ω| = 1.0356
    with pytest.warns(lf.LieflowWarning, match=r"103\.\d* rad per step.*dt <= 1\.51") as rec:
        traj = lf.integrate(body, m0, 100.0, 100, method="splitting4")
    assert len(rec) == 1
    # The run is still returned as asked (and its energy error shows why).
    assert np.ptp(traj.energy()) > 0.1
    # The batch's fastest member decides; the exact flow never warns; a resolved step is quiet.
    with pytest.warns(lf.LieflowWarning, match="rad per step"):
        lf.integrate(body, np.array([[0.01, 0, 0], [2.0, 0, 0]]), 1.0, 5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lf.integrate(body, m0, 100.0, 10, method="exact")
        lf.integrate(body, m0, 0.5, 10)
        lf.integrate(body, np.array([[0.01, 0, 0], [1.0, 0, 0]]), 1.0, 5)
    # Numbers in the message are short at any exponent (no 1.4530000000000006e+153).
    with pytest.warns(lf.LieflowWarning, match=r"by 1\.453e\+98 rad .* take dt <= 1\.08e-100$"):
        with pytest.raises(lf.LeftDomainError):       # such a step cannot be taken at all
            lf.integrate(body, [1.453e100, 0, 0], 0.01, 1, method="splitting")
    # The heavy top: its pendulum frequency √(mgl|Γ|/I_min) counts too.
    with pytest.warns(lf.LieflowWarning, match="rad per step"):
        lf.integrate(lf.HeavyTop([1.0, 1.0, 0.5], 50.0), [0, 0, 0, 0, 0, 1.0], 0.2, 5)


def test_warnings_point_at_the_user_s_line_whatever_lieflow_calls_in_between():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = [1.0, 0.5, -0.3]
    calls = [lambda: lf.integrate(body, m0, 100.0, 3),
             # integrate calls itself on the tangent lift: two of lieflow's frames between
             lambda: lf.integrate(body, m0, 100.0, 3, sensitivity=True),
             lambda: lf.RigidBody([1.0, 1.0, 5.0]),
             lambda: lf.lie.so3_exp(lf.lie.so3_hat([0.1, 0.2, 0.3])),
             lambda: lf.integrate(body, np.eye(3), 0.01, 2)]
    for call in calls:
        with pytest.warns(lf.LieflowWarning) as rec:
            call()
        assert {w.filename for w in rec} == {__file__}, [(w.filename, w.message) for w in rec]


def test_moments_no_body_has_are_accepted_with_a_warning():
    with pytest.warns(lf.LieflowWarning, match="I3 exceeds the sum of the other two"):
        body = lf.RigidBody([1.0, 1.0, 5.0])
    assert list(body.moments) == [1.0, 1.0, 5.0]
    with pytest.warns(lf.LieflowWarning, match="I1 exceeds"):
        lf.HeavyTop([3.0, 1.0, 1.5], 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lf.RigidBody([1.0, 1.0, 2.0])                         # a flat body: equality
        lf.RigidBody(np.diag([1.0, 2.0, 3.0]))


def test_a_square_state0_is_read_as_a_batch_with_a_warning():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    with pytest.warns(lf.LieflowWarning, match=r"state0 of shape \(3, 3\) is read as a batch"):
        traj = lf.integrate(body, np.eye(3), 0.01, 10)
    assert traj.states.shape == (3, 11, 3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lf.integrate(body, np.eye(3)[:2], 0.01, 10)          # (2, 3): a batch, unambiguous
        traj = lf.integrate(body, [1.0, 0.5, -0.3], 0.01, 2)
        traj.energy()                                         # (3, 3) states inside: quiet
        lf.integrate(lf.HeavyTop([1, 2, 3], 1.0), (np.ones(3), np.ones(3)), 0.01, 2)
