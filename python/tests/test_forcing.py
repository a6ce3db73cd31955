"""lf.Forced (issue 15): external torques and forces, Rayleigh damping and double-bracket
dissipation, checked against scipy's adaptive DOP853 on the forced equations, by observed
orders, by the energy decrease and Casimirs of the dissipation, and for its errors."""

import pickle

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lieflow as lf

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def body_torque(t, z):
    """A constant body torque plus a time-dependent one (module level: it pickles)."""
    return np.array([0.3, -0.2, 0.25 * np.cos(2 * t)])


def drag_torque(t, z):
    return np.array([0.3, -0.2, 0.0]) - 0.2 * z[:3]


def reference_body(torque, t_end, with_attitude=True):
    """The forced Euler equations (with Rdot = R hat(Omega)) by DOP853 at rtol 1e-13."""

    def f(t, y):
        m = y[:3]
        w = m / I
        dm = np.cross(m, w) + torque(t, y)
        if not with_attitude:
            return dm
        r = y[3:].reshape(3, 3)
        return np.concatenate([dm, (r @ hat(w)).ravel()])

    y0 = np.concatenate([M0, np.eye(3).ravel()]) if with_attitude else M0
    sol = solve_ivp(f, (0, t_end), y0, method="DOP853", rtol=1e-13, atol=1e-13)
    return sol.y[:, -1]


def test_constant_body_torque_against_an_adaptive_reference():
    body = lf.Forced(lf.RigidBody(inertia=I), body_torque, depends_on_block=False)
    ref = reference_body(body_torque, 5.0)
    traj = lf.integrate(body, M0, attitude=np.eye(3), dt=0.01, steps=500, method="splitting6",
                        save_every=500)
    assert np.abs(traj.states[-1] - ref[:3]).max() < 1e-10
    assert np.abs(traj.attitude[-1] - ref[3:].reshape(3, 3)).max() < 1e-10
    r = traj.attitude[-1]
    assert np.abs(r.T @ r - np.eye(3)).max() < 1e-13


@pytest.mark.parametrize("method,order", [("splitting", 2), ("splitting4", 4), ("lgvi", 2),
                                          ("isospectral4", 4)])
def test_observed_orders_with_a_momentum_dependent_torque(method, order):
    body = lf.Forced(lf.RigidBody(inertia=I), drag_torque)
    ref = reference_body(drag_torque, 2.0, with_attitude=False)
    errors = []
    for dt in (0.04, 0.02):
        steps = round(2.0 / dt)
        traj = lf.integrate(body, M0, dt=dt, steps=steps, method=method, save_every=steps)
        errors.append(np.linalg.norm(traj.states[-1] - ref))
    assert np.log2(errors[0] / errors[1]) == pytest.approx(order, abs=0.3)


def test_heavy_top_with_a_torque():
    top = lf.HeavyTop([1.0, 2.0, 3.0], 0.5, [0.0, 0.0, 1.0])
    forced = lf.Forced(top, body_torque)
    g0 = np.array([0.0, 0.6, 0.8])

    def f(t, y):
        m, g = y[:3], y[3:]
        w = m / I
        return np.concatenate([np.cross(m, w) + 0.5 * np.cross(g, [0, 0, 1.0])
                               + body_torque(t, y), np.cross(g, w)])

    ref = solve_ivp(f, (0, 3.0), np.concatenate([M0, g0]), method="DOP853", rtol=1e-13,
                    atol=1e-13).y[:, -1]
    traj = lf.integrate(forced, (M0, g0), dt=0.01, steps=300, method="splitting4",
                        save_every=300)
    assert np.abs(traj.states[-1] - ref).max() < 1e-8
    # The torque does not act on Gamma: |Gamma| stays 1.
    assert abs(np.linalg.norm(traj.states[-1][3:]) - 1) < 1e-14


def test_pseudo_rigid_body_with_a_force_matrix():
    A = np.array([[0.0, 0.2, 0.0], [0.1, 0.0, -0.1], [0.0, 0.3, 0.1]])

    def force(t, z):
        return np.sin(t) * A - 0.1 * z[9:].reshape(3, 3)

    body = lf.Forced(lf.PseudoRigidBody(3), force)
    assert body.block == "P"
    X0, P0 = np.diag([1.2, 1.0, 0.8]), np.array([[0, 0.3, 0], [-0.3, 0, 0.1], [0, -0.1, 0]])

    def f(t, y):
        return np.concatenate([y[9:], force(t, y).ravel()])

    ref = solve_ivp(f, (0, 2.0), np.concatenate([X0.ravel(), P0.ravel()]), method="DOP853",
                    rtol=1e-13, atol=1e-13).y[:, -1]
    errors = []
    for dt in (0.05, 0.025):
        steps = round(2.0 / dt)
        traj = lf.integrate(body, (X0, P0), dt=dt, steps=steps, method="verlet4",
                            save_every=steps)
        errors.append(np.abs(traj.states[-1] - ref).max())
    assert errors[1] < 1e-7
    assert np.log2(errors[0] / errors[1]) == pytest.approx(4, abs=0.3)


def test_double_bracket_dissipation_ends_on_the_major_axis():
    body = lf.Forced(lf.RigidBody(inertia=I), dissipation=0.5)
    assert body.terms == ["double-bracket dissipation"]
    traj = lf.integrate(body, M0, dt=0.05, steps=4000, save_every=10)
    c = traj.invariants()[:, 0]
    assert np.abs(c - c[0]).max() < 1e-13 * c[0]  # |M|^2 kept exactly
    e = traj.energy()
    assert np.all(np.diff(e) <= 1e-15)  # decreasing at every sample
    assert np.abs(traj.states[-1][:2]).max() < 1e-8  # M along e3, the major axis
    assert e[-1] == pytest.approx(c[0] / (2 * I[2]), abs=1e-12)


def test_double_bracket_rate_is_bkmr():
    """dH/dt = -alpha |M x Omega|^2 at the initial state, from one short step."""
    alpha, h = 0.3, 1e-5
    body = lf.Forced(lf.RigidBody(inertia=I), dissipation=alpha)
    traj = lf.integrate(body, M0, dt=h, steps=1, method="splitting6")
    rate = (traj.energy()[-1] - traj.energy()[0]) / h
    expected = -alpha * np.sum(np.cross(M0, M0 / I) ** 2)
    assert rate == pytest.approx(expected, rel=1e-3)


def test_double_bracket_on_a_user_lie_poisson_system():
    kirchhoff = lf.LiePoisson("se3", np.diag([1.0, 0.5, 0.25, 1.0, 0.8, 0.6]))
    body = lf.Forced(kirchhoff, dissipation=1.0)
    z0 = np.array([0.3, -0.5, 0.8, 1.0, 0.4, -0.6])
    traj = lf.integrate(body, z0, dt=0.02, steps=2000, save_every=100)
    cas = traj.invariants()
    assert np.abs(cas - cas[0]).max() < 1e-13
    assert traj.energy()[-1] < 0.999 * traj.energy()[0]


def test_rayleigh_damping_of_the_pendulum_against_scipy():
    c = 0.4
    pend = lf.Forced(lf.Pendulum(), damping=c)
    assert pend.methods()[0] == "midpoint"

    def f(t, y):
        return [y[1], -9.81 * np.sin(y[0]) - c * y[1]]

    ref = solve_ivp(f, (0, 2.0), [1.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    traj = lf.integrate(pend, [1.0, 0.0], dt=0.01, steps=200, method="midpoint6",
                        save_every=1)
    assert np.abs(traj.states[-1] - ref).max() < 1e-9
    assert np.all(np.diff(traj.energy()) <= 1e-12)


def test_rayleigh_damping_matrix_on_a_user_separable_system():
    C = np.array([[0.3, 0.1], [0.1, 0.2]])
    osc = lf.Separable(1.0, lambda q: 0.5 * q @ q, lambda q: q, dof=2)
    damped = lf.Forced(osc, damping=C)
    z0 = np.array([1.0, -0.5, 0.2, 0.4])

    def f(t, y):
        return np.concatenate([y[2:], -y[:2] - C @ y[2:]])

    ref = solve_ivp(f, (0, 3.0), z0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    traj = lf.integrate(damped, z0, dt=0.01, steps=300, method="verlet4", save_every=300)
    assert np.abs(traj.states[-1] - ref).max() < 1e-9


def test_forced_systems_pickle_and_repr():
    body = lf.Forced(lf.RigidBody(inertia=I), body_torque, depends_on_block=False)
    again = pickle.loads(pickle.dumps(body))
    a = lf.integrate(body, M0, dt=0.01, steps=50, method="splitting4")
    b = lf.integrate(again, M0, dt=0.01, steps=50, method="splitting4")
    assert np.array_equal(a.states, b.states)
    assert repr(body).startswith("Forced(system=RigidBody(")
    assert isinstance(body.system, lf.RigidBody)
    assert lf.Forced.methods() == ["midpoint", "midpoint4", "midpoint6", "verlet", "verlet4",
                                   "verlet6"]


def test_the_default_block_is_the_momentum():
    assert lf.Forced(lf.Pendulum(), lambda t, z: np.zeros(1)).block == "p"
    assert lf.Forced(lf.HeavyTop([1, 2, 3], 0.5, [0, 0, 1]), body_torque).block == "M"
    assert lf.Forced(lf.Pendulum(), damping=0.1).block is None


def test_a_batch_runs_member_after_member():
    body = lf.Forced(lf.RigidBody(inertia=I), body_torque)
    batch = np.stack([M0, 2 * M0])
    traj = lf.integrate(body, batch, dt=0.01, steps=100, method="splitting4", save_every=100)
    one = lf.integrate(body, 2 * M0, dt=0.01, steps=100, method="splitting4", save_every=100)
    assert np.array_equal(traj.states[1], one.states)


def _spheres():
    """Two rolling spheres (any will do for the argument checks)."""
    return lf.RollingSpheres(1.0, 1.0, [0.0] * 3, [0.0] * 3, 1.0, 1.0, 0.1 * np.eye(3),
                             0.1 * np.eye(3))


def test_errors():
    body = lf.RigidBody(inertia=I)
    with pytest.raises(lf.InvalidArgumentError, match="none was given"):
        lf.Forced(body)
    with pytest.raises(lf.InvalidArgumentError, match="no Rayleigh damping"):
        lf.Forced(body, damping=1.0)
    with pytest.raises(lf.InvalidArgumentError, match="attitude"):
        lf.integrate(lf.Forced(body, dissipation=1.0), M0, attitude=np.eye(3), dt=0.1, steps=1)
    with pytest.raises(lf.InvalidArgumentError, match="no block"):
        lf.Forced(body, body_torque, block="P")
    with pytest.raises(lf.InvalidArgumentError, match="curved block"):
        spheres = _spheres()
        lf.Forced(spheres, lambda t, z: np.zeros(3), block="u")
    with pytest.raises(lf.ArgumentTypeError, match="callable"):
        lf.Forced(body, 3.0)
    with pytest.raises(lf.ArgumentTypeError, match="depends_on_block"):
        lf.Forced(body, body_torque, depends_on_block="yes")
    with pytest.raises(lf.ArgumentTypeError, match="'block'"):
        lf.Forced(body, body_torque, block=3)
    with pytest.raises(lf.ArgumentTypeError, match="dissipation"):
        lf.Forced(body, dissipation="strong")
    with pytest.raises(lf.InvalidArgumentError, match="none of the momentum blocks"):
        lf.Forced(_spheres(), body_torque)
    with pytest.raises(lf.ArgumentTypeError, match="lieflow system"):
        lf.Forced("RigidBody", body_torque)
    with pytest.raises(lf.InvalidArgumentError, match="positive semi-definite"):
        lf.Forced(lf.Separable(1.0, lambda q: 0.0, dof=2), damping=[[1.0, 2.0], [0.0, 1.0]])
    with pytest.raises(lf.ShapeError, match=r"expected \(3,\), got \(4,\), in step 1"):
        lf.integrate(lf.Forced(body, lambda t, z: np.zeros(4)), M0, dt=0.1, steps=3)
    with pytest.raises(lf.NonFiniteError, match="in step 1"):
        lf.integrate(lf.Forced(body, lambda t, z: np.array([np.nan, 0, 0])), M0, dt=0.1,
                     steps=3)


def test_an_exception_of_the_force_names_its_step_and_keeps_the_partial_run():
    def force(t, z):
        if t > 0.5:
            raise RuntimeError("boom")
        return np.zeros(3)

    with pytest.raises(RuntimeError, match="boom") as info:
        lf.integrate(lf.Forced(lf.RigidBody(inertia=I), force), M0, dt=0.1, steps=10)
    assert any("step 6 of splitting" in n for n in info.value.__notes__)
    assert info.value.partial.t[-1] == pytest.approx(0.5)
