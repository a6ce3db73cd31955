"""The exact free rigid body motion with its attitude: ``RigidBody.exact_solution(M0, t,
attitude=R0)`` against scipy's DOP853 (rtol = atol = 1e-14) on the 12-dimensional (M, R)
equations, its invariants (R in SO(3), R M, |M|, H), the group property, large times, the method
``exact`` through ``lf.integrate`` (chunking included) and the heavy top's ``exact_splitting*``."""

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import lieflow as lf

R0 = Rotation.from_rotvec([0.4, -0.2, 0.1]).as_matrix()


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def dop853(inertia, m0, r0, times):
    """(M, R) at `times` by DOP853 on dM/dt = M x Omega, dR/dt = R hat(Omega), Omega = J^-1 M."""
    jinv = np.linalg.inv(np.diag(inertia) if np.ndim(inertia) == 1 else np.asarray(inertia))

    def rhs(t, y):
        m, r = y[:3], y[3:].reshape(3, 3)
        w = jinv @ m
        return np.concatenate([np.cross(m, w), (r @ hat(w)).ravel()])

    y0 = np.concatenate([m0, np.asarray(r0).ravel()])
    with warnings.catch_warnings():  # scipy raises rtol = 1e-14 to 2.2e-14
        warnings.filterwarnings("ignore", "At least one element of `rtol` is too small")
        sol = solve_ivp(rhs, (0.0, times[-1]), y0, method="DOP853", rtol=1e-14, atol=1e-14,
                        t_eval=times)
    assert sol.success
    return sol.y[:3].T, sol.y[3:].T.reshape(-1, 3, 3)


CASES = [
    ("I = (1, 2, 3)", [1.0, 2.0, 3.0], [1.0, 0.5, -0.3]),
    ("major axis", [1.0, 2.0, 3.0], [0.2, 1.0, 0.9]),
    ("minor axis", [1.0, 2.0, 3.0], [-0.9, 1.0, 0.2]),
    # e2 = M1^2 - M3^2 / 3: k' ~ 3e-5 and on the separatrix (to rounding)
    ("near the separatrix", [1.0, 2.0, 3.0], [0.3, -1.0, 0.3 * np.sqrt(3.0) * (1 + 1e-9)]),
    ("on the separatrix", [1.0, 1.25, 1.953125], [0.6, 1.0, 0.5]),
    ("polar axis p", [1.0, 2.9, 3.0], [0.05, 0.3, 1.0]),
    ("symmetric I1 = I2", [1.0, 1.0, 3.0], [0.6, -0.2, 0.7]),
    ("symmetric I2 = I3", [1.0, 3.0, 3.0], [0.6, -0.2, 0.7]),
    ("nearly symmetric", [1.0, 1.0 + 1e-7, 3.0], [0.6, -0.2, 0.7]),
    ("steady, middle axis", [1.0, 2.0, 3.0], [0.0, -1.3, 0.0]),
    ("inertia matrix", [[2.0, 0.3, 0.0], [0.3, 1.0, 0.1], [0.0, 0.1, 3.0]], [1.0, 0.5, -0.3]),
]


@pytest.mark.parametrize("name, inertia, m0", CASES, ids=[c[0] for c in CASES])
def test_against_dop853(name, inertia, m0):
    body = lf.RigidBody(inertia)
    t = np.array([0.5, 3.0, 10.0, 25.0])
    m_ref, r_ref = dop853(inertia, np.array(m0), R0, t)
    m, r = body.exact_solution(m0, t, attitude=R0)
    assert m.shape == (4, 3) and r.shape == (4, 3, 3)
    err = max(np.abs(m - m_ref).max(), np.abs(r - r_ref).max())
    print(f"{name}: max error against DOP853 to t = 25: {err:.2e}")
    assert err < 2e-12
    # Without the attitude: the same momenta (the old behaviour).
    np.testing.assert_allclose(body.exact_solution(m0, t), m, rtol=0, atol=1e-14)


@pytest.mark.parametrize("name, inertia, m0", CASES, ids=[c[0] for c in CASES])
def test_invariants_to_round_off(name, inertia, m0):
    body = lf.RigidBody(inertia)
    t = np.array([0.1, 1.0, 1e2, 1e4, 1e6, -3e3])
    m, r = body.exact_solution(m0, t, attitude=R0)
    assert np.abs(np.einsum("kji,kjl->kil", r, r) - np.eye(3)).max() < 2e-15
    assert np.abs(np.linalg.det(r) - 1.0).max() < 2e-15
    scale = max(np.linalg.norm(m0), 1.0)
    spatial = np.einsum("kij,kj->ki", r, m)
    assert np.abs(spatial - R0 @ np.array(m0)).max() < 2e-15 * scale
    assert np.abs(np.linalg.norm(m, axis=-1) - np.linalg.norm(m0)).max() < 2e-15 * scale
    energy = body.energy(m)
    assert np.abs(energy - body.energy(m0)).max() < 2e-15 * scale**2


def test_group_property():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = np.array([1.0, 0.5, -0.3])
    for s, t in [(0.7, 1.9), (3.3, -1.2), (1e3, 2.5)]:
        ms, rs = body.exact_solution(m0, s, attitude=R0)
        m2, r2 = body.exact_solution(ms, t, attitude=rs)
        m1, r1 = body.exact_solution(m0, s + t, attitude=R0)
        err = max(np.abs(m2 - m1).max(), np.abs(r2 - r1).max())
        assert err < 1e-15 * (1 + 2 * (abs(s) + abs(t))), (s, t, err)


def test_large_time_against_composed_steps():
    """t = 1e4 in one evaluation and in 10^4 steps of size 1: they agree to the phase drift of
    the composed steps (each step's rounding changes the frequency by ~eps omega), ~1e-10."""
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = np.array([1.0, 0.5, -0.3])
    m, r = m0, R0
    for _ in range(10_000):
        m, r = body.exact_solution(m, 1.0, attitude=r)
    m1, r1 = body.exact_solution(m0, 1e4, attitude=R0)
    err = max(np.abs(m - m1).max(), np.abs(r - r1).max())
    print(f"t = 1e4: one evaluation vs 10^4 composed steps: {err:.2e}")
    assert err < 1e-9
    assert abs(np.linalg.norm(m) / np.linalg.norm(m0) - 1) < 5e-14


def test_shapes_and_broadcasting():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = np.array([1.0, 0.5, -0.3])
    m, r = body.exact_solution(m0, 1.0, attitude=R0)
    assert m.shape == (3,) and r.shape == (3, 3)
    batch = np.stack([m0, 2 * m0])
    m, r = body.exact_solution(batch, [0.0, 1.0, 2.0], attitude=R0)
    assert m.shape == (2, 3, 3) and r.shape == (2, 3, 3, 3)
    np.testing.assert_allclose(m[:, 0], batch, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r[:, 0], np.broadcast_to(R0, (2, 3, 3)), rtol=0, atol=1e-15)
    rots = np.stack([R0, np.eye(3)])
    m, r = body.exact_solution(m0, 2.0, attitude=rots)
    assert m.shape == (2, 3) and r.shape == (2, 3, 3)
    np.testing.assert_allclose(r[1], body.exact_solution(m0, 2.0, attitude=np.eye(3))[1])
    with pytest.raises(lf.NotInGroupError):
        body.exact_solution(m0, 1.0, attitude=2 * np.eye(3))
    with pytest.raises(lf.ShapeError):
        body.exact_solution(m0, 1.0, attitude=np.eye(2))
    with pytest.raises(lf.ShapeError):
        body.exact_solution(m0, np.zeros((2, 2)), attitude=R0)
    with pytest.raises(lf.InvalidArgumentError):
        body.exact_solution(m0, 1e15, attitude=R0)


def test_exact_method_through_integrate():
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m0 = np.array([1.0, 0.5, -0.3])
    assert "exact" in body.methods() and "exact" in lf.RigidBody.methods()
    kw = dict(dt=0.05, steps=4000, method="exact", save_every=40, attitude=R0)
    traj = lf.integrate(body, m0, **kw)
    m, r = body.exact_solution(m0, traj.t, attitude=R0)
    err = max(np.abs(traj.states - m).max(), np.abs(traj.attitude - r).max())
    assert err < 1e-12, err
    # Chunks do not change the states (the reference state is renewed at the retractions).
    chunked = lf.integrate(body, m0, chunk_steps=37, **kw)
    np.testing.assert_array_equal(chunked.states, traj.states)
    np.testing.assert_array_equal(chunked.attitude, traj.attitude)
    # T = 100 in one step, against DOP853.
    m_ref, r_ref = dop853([1.0, 2.0, 3.0], m0, R0, np.array([100.0]))
    one = lf.integrate(body, m0, dt=100.0, steps=1, method="exact", attitude=R0)
    err = max(np.abs(one.final_state - m_ref[0]).max(), np.abs(one.final_attitude - r_ref[0]).max())
    print(f"exact, T = 100 in one step: error against DOP853 {err:.2e}")
    assert err < 2e-12


def test_heavy_top_exact_splittings():
    top = lf.HeavyTop([1.0, 2.0, 3.0], 1.0, [0.0, 0.0, 1.0])
    methods = top.methods()
    assert methods[-3:] == ["exact_splitting", "exact_splitting4", "exact_splitting6"]
    assert methods == lf.HeavyTop.methods()
    z0 = top.state([40.0, 80.0, 400.0], attitude=R0)
    ref = lf.integrate(top, z0, dt=0.1 / 2000, steps=2000, method="exact_splitting6").final_state
    for method, plain, order, n in [("exact_splitting", "splitting", 2, 50),
                                    ("exact_splitting4", "splitting4", 4, 25),
                                    ("exact_splitting6", "splitting6", 6, 20)]:
        e = [np.abs(lf.integrate(top, z0, dt=0.1 / k, steps=k, method=method).final_state
                    - ref).max() for k in (n, 2 * n)]
        assert abs(np.log2(e[0] / e[1]) - order) < 0.3, (method, e)
        # |Gamma| = 1 and M . Gamma to round-off over 10^4 steps.
        traj = lf.integrate(top, z0, dt=1e-3, steps=10_000, method=method, save_every=100)
        c = traj.invariants()
        c0 = top.invariants(z0)
        assert np.abs(c[:, 0] - 1.0).max() < 5e-13
        assert np.abs(c[:, 1] / c0[1] - 1.0).max() < 5e-13
        # More accurate than the Lie-Poisson splitting with 6 times the steps (a step costs
        # 5.0-5.3 of its steps, benches/integrators.rs).
        p = np.abs(lf.integrate(top, z0, dt=0.1 / (6 * n), steps=6 * n, method=plain).final_state
                   - ref).max()
        print(f"{method} ({n} steps) {e[0]:.2e} vs {plain} ({6 * n} steps) {p:.2e}")
        assert e[0] < p
