"""The discrete Moser-Veselov methods of the rigid body (dmv and the preprocessed dmv4 ... dmv10)
through lf.integrate with the attitude, against scipy's DOP853 (rtol = atol = 1e-14) on Euler's
equation with dR/dt = R hat(Omega), at T = 100 (I = (1, 2, 3), M0 = (1, 0.5, -0.3))."""

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lieflow as lf

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
T = 100.0
DMV = ["dmv", "dmv4", "dmv6", "dmv8", "dmv10"]


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def rhs(t, y):
    m, r = y[:3], y[3:].reshape(3, 3)
    w = m / I
    return np.concatenate([np.cross(m, w), (r @ hat(w)).ravel()])


@pytest.fixture(scope="module")
def reference():
    # scipy raises an rtol below 100 eps to 2.2e-14 (with a warning); the error at T = 100 is
    # ~1e-12, below every tolerance here but the one at round-off.
    y0 = np.concatenate([M0, np.eye(3).ravel()])
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "At least one element of `rtol` is too small")
        sol = solve_ivp(rhs, (0.0, T), y0, method="DOP853", rtol=1e-14, atol=1e-14)
    assert sol.success
    return sol.y[:3, -1], sol.y[3:, -1].reshape(3, 3)


def test_methods_are_listed():
    methods = lf.RigidBody([1, 2, 3]).methods()
    at = methods.index("lgvi")
    assert methods[at + 1:at + 6] == DMV


# dt and a bound of the error against DOP853 (max over M and R; measured 1.6e-3, 5.6e-6,
# 2.5e-8, 1.0e-9, 4.9e-12 and 3.4e-13, the last at the accuracy of the reference).
@pytest.mark.parametrize("method, dt, tol", [
    ("dmv", 0.01, 4e-3), ("dmv4", 0.05, 1.2e-5), ("dmv6", 0.1, 5e-8), ("dmv8", 0.2, 2e-9),
    ("dmv10", 0.25, 1e-11), ("dmv10", 0.1, 2e-12)])
def test_against_dop853(reference, method, dt, tol):
    m_ref, r_ref = reference
    body = lf.RigidBody(I)
    traj = lf.integrate(body, M0, dt=dt, steps=round(T / dt), method=method, save_every=100,
                        attitude=np.eye(3))
    err = max(np.abs(traj.final_state - m_ref).max(), np.abs(traj.final_attitude - r_ref).max())
    print(f"{method} dt = {dt}: max error against DOP853 at T = 100: {err:.2e}")
    assert err < tol
    # What the methods keep: |M|, R M, R in SO(3), and the energy.
    r = traj.attitude
    assert np.abs(np.einsum("kji,kjl->kil", r, r) - np.eye(3)).max() < 1e-14
    spatial = np.einsum("kij,kj->ki", r, traj.states)
    np.testing.assert_allclose(spatial, np.broadcast_to(M0, spatial.shape), rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(traj.states, axis=-1),
                               np.full(len(traj.states), np.linalg.norm(M0)), rtol=0, atol=1e-14)
    np.testing.assert_allclose(traj.energy(), body.energy(M0), rtol=1e-14, atol=0)


@pytest.mark.parametrize("method", DMV)
def test_chunks_do_not_change_the_states(method):
    body = lf.RigidBody(I)
    kw = dict(dt=0.1, steps=1000, method=method, save_every=10, attitude=np.eye(3))
    one = lf.integrate(body, M0, **kw)
    chunked = lf.integrate(body, M0, chunk_steps=37, **kw)
    np.testing.assert_array_equal(chunked.states, one.states)
    np.testing.assert_array_equal(chunked.attitude, one.attitude)


def test_too_large_steps_are_typed_errors():
    body = lf.RigidBody(I)
    with pytest.raises(lf.InvalidArgumentError, match="dt"):
        lf.integrate(body, M0, dt=50.0, steps=2, method="dmv10")
    with pytest.raises(lf.ConvergenceError):
        lf.integrate(body, M0, dt=2.0, steps=2, method="dmv", attitude=np.eye(3))
