"""RollingSpheres (003 §2) from Python: construction, fields, observables, invariants, pickling."""

import pickle

import numpy as np
import pytest

import lieflow as lf


def spheres():
    i1 = [[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]]
    i2 = [[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]]
    return lf.RollingSpheres(0.7, 1.3, [0.1, -0.2, 0.15], [-0.3, 0.2, 0.4], 2.0, 3.5, i1, i2)


def rot(w):
    w = np.asarray(w, dtype=float)
    t = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / t
    return np.eye(3) + np.sin(t) * k + (1 - np.cos(t)) * k @ k


def start(sys):
    u = np.array([0.2, 0.9, -0.3])
    return sys.state(rot([0.3, -0.5, 0.9]), rot([-1.2, 0.4, 0.2]), u / np.linalg.norm(u),
                     [1.1, -0.6, 0.8], [-0.4, 0.9, 0.5])


def test_fields_invariants_and_observables():
    sys = spheres()
    assert sys.methods()[0] == "midpoint"
    assert set(sys.fields) >= {"z1", "z2", "u", "Omega1", "Omega2"}
    traj = lf.integrate(sys, start(sys), dt=0.02, steps=2000, save_every=20)
    k = len(traj.t)
    assert traj.z1.shape == (k, 3, 3) and traj.u.shape == (k, 3) and traj.Omega2.shape == (k, 3)
    z = traj.z1
    assert np.abs(np.einsum("kji,kjl->kil", z, z) - np.eye(3)).max() < 1e-13
    assert np.abs(np.linalg.norm(traj.u, axis=1) - 1).max() < 1e-13
    e = traj.energy()
    assert np.abs(e - e[0]).max() < 1e-4 * e[0]
    j = sys.angular_momentum(traj.states)
    assert np.abs(j - j[0]).max() < 1e-12 * np.linalg.norm(j[0])
    assert np.allclose(traj.invariants(), j, rtol=0, atol=1e-13)
    p = sys.spatial_momenta(traj.states)
    assert np.allclose(p.sum(axis=1), j, atol=1e-12)
    # Rolling: u̇ from (10) matches the differences of u; contact on both spheres.
    assert sys.udot(traj.states).shape == (k, 3)
    c = sys.contact_point(traj.states)
    a = sys.centres(traj.states)
    assert np.allclose(np.linalg.norm(c - a[:, 0], axis=1), 0.7)
    assert np.allclose(np.linalg.norm(c - a[:, 1], axis=1), 1.3)
    m = np.array([2.0, 3.5])
    x = sys.centres_of_mass(traj.states)
    assert np.abs(np.einsum("k,ikj->ij", m, x)).max() < 1e-13
    assert sys.accelerations(traj.states).shape == (k, 2, 3)
    assert sys.body_momenta(traj.states).shape == (k, 2, 3)


def test_planar_state_and_pickle():
    i1 = np.diag([0.4, 0.3, 0.25])
    i2 = np.diag([0.9, 1.1, 0.7])
    sys = lf.RollingSpheres(0.8, 1.2, [0.2, -0.1, 0.0], [-0.3, 0.25, 0.0], 1.5, 2.5, i1, i2)
    z0 = sys.planar_state([0.3, -1.1], 0.7, [1.0, -0.4])
    traj = lf.integrate(sys, z0, dt=0.01, steps=500, save_every=500)
    planar = sys.to_planar(traj.states[-1], 1e-12)
    assert len(planar) == 5
    clone = pickle.loads(pickle.dumps(sys))
    assert np.allclose(clone.energy(np.asarray(z0)), sys.energy(np.asarray(z0)))


def test_bad_input():
    i = np.eye(3)
    with pytest.raises(lf.InvalidArgumentError):
        lf.RollingSpheres(1.0, 1.0, [1.5, 0, 0], [0, 0, 0], 1.0, 1.0, i, i)
    with pytest.raises(lf.InvalidArgumentError):
        lf.RollingSpheres(-1.0, 1.0, [0, 0, 0], [0, 0, 0], 1.0, 1.0, i, i)
    sys = spheres()
    with pytest.raises(lf.NotInGroupError):
        sys.state(np.eye(3) * 1.1, np.eye(3), [0, 0, 1], [0, 0, 0], [0, 0, 0])


# --- the Lagrangian (8) and the curvature of §2.2 (issue 25) ---

I1 = np.array([[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]])
I2 = np.array([[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]])


def test_lagrangian_8_is_the_kinetic_energy_of_the_two_bodies():
    sys = spheres()
    z0 = np.asarray(start(sys))
    # The kinetic energy of the bodies themselves: their centres of mass move at the rates of
    # `centres_of_mass` (5-point differences along an rkmk4 motion), and they turn with the
    # spatial angular velocities z_k Omega_k about them (inertia tensor tr(I_k) 1 - I_k).
    h = 2.5e-3
    tr = lf.integrate(sys, z0, dt=h / 10, steps=40, method="rkmk4", save_every=10)
    x = sys.centres_of_mass(tr.states)
    xdot = (x[0] - 8 * x[1] + 8 * x[3] - x[4]) / (12 * h)
    z = tr.states[2]
    kinetic = 0.5 * (2.0 * xdot[0] @ xdot[0] + 3.5 * xdot[1] @ xdot[1])
    for i, om in ((I1, z[21:24]), (I2, z[24:27])):
        kinetic += 0.5 * om @ ((np.trace(i) * np.eye(3) - i) @ om)
    lag = sys.lagrangian(z)
    assert isinstance(lag, float)
    assert sys.scale * lag == pytest.approx(kinetic, rel=1e-9)
    # The completed square of the module docs (the system's energy) is the same number.
    assert sys.scale * lag == pytest.approx(sys.energy(z), rel=1e-13)
    np.testing.assert_allclose(sys.lagrangian(tr.states), sys.energy(tr.states) / sys.scale,
                               rtol=1e-13)
    # dL/dOmega_k with du/dt from (10) (differences in the state's Omega_k) is z_k^T P_k, the
    # spatial momenta P_k = dL/d(z_k Omega_k) in body axes.
    eps = 1e-6
    P = sys.spatial_momenta(z)
    for k, (block, zk) in enumerate(((slice(21, 24), z[0:9]), (slice(24, 27), z[9:18]))):
        grad = []
        for e in np.eye(3):
            up, dn = z.copy(), z.copy()
            up[block] += eps * e
            dn[block] -= eps * e
            grad.append((sys.lagrangian(up) - sys.lagrangian(dn)) / (2 * eps))
        np.testing.assert_allclose(sys.scale * np.array(grad), zk.reshape(3, 3).T @ P[k],
                                   atol=1e-8)


def velocity_pairs(seed):
    rng = np.random.default_rng(seed)
    return rng.standard_normal((2, 3)), rng.standard_normal((2, 3))


def test_curvature_closed_form_equals_the_bracket_of_the_flows():
    sys = spheres()
    a1, a2 = sys.alphas
    tr = lf.integrate(sys, start(sys), dt=0.05, steps=60, save_every=20)
    for seed, z in enumerate(tr.states):
        om, omt = velocity_pairs(seed)
        closed = sys.curvature(z, om, omt)
        brackets = sys.curvature_by_brackets(z, om, omt)
        assert closed.shape == brackets.shape == (3,)
        assert np.abs(closed).max() > 0.05
        np.testing.assert_allclose(brackets, closed, rtol=0, atol=1e-8 * np.abs(closed).max())
        # 003 §2.2's formula, alpha1 alpha2 u x ((z1 W1 - z2 W2) x (z1 W1~ - z2 W2~)).
        z1, z2, u = z[0:9].reshape(3, 3), z[9:18].reshape(3, 3), z[18:21]
        d = z1 @ om[0] - z2 @ om[1]
        dt = z1 @ omt[0] - z2 @ omt[1]
        np.testing.assert_allclose(closed, a1 * a2 * np.cross(u, np.cross(d, dt)), atol=1e-14)
        # Antisymmetric in the two fields; zero for parallel ones.
        np.testing.assert_allclose(sys.curvature(z, omt, om), -closed, atol=1e-15)
        np.testing.assert_allclose(sys.curvature_by_brackets(z, om, 2 * om), 0, atol=1e-9)
    # A coarse step is a worse bracket (error ~ s^4): the two routes are independent.
    z, (om, omt) = tr.states[1], velocity_pairs(9)
    errors = [np.abs(sys.curvature_by_brackets(z, om, omt, s=s) - sys.curvature(z, om, omt)).max()
              for s in (0.04, 0.02)]
    assert 1e-7 < errors[1] < 1e-3 and 10 < errors[0] / errors[1] < 20


def test_curvature_maps_leading_axes_and_refuses_bad_input():
    sys = spheres()
    z = np.asarray(start(sys))
    om, omt = velocity_pairs(1)
    both = sys.curvature(np.stack([z, z]), np.stack([om, omt]), omt)
    assert both.shape == (2, 3)
    np.testing.assert_allclose(both[0], sys.curvature(z, om, omt), atol=0)
    np.testing.assert_allclose(both[1], 0, atol=1e-15)
    assert sys.curvature_by_brackets(np.stack([z, z]), om, omt).shape == (2, 3)
    with pytest.raises(lf.InvalidArgumentError):
        sys.curvature_by_brackets(z, om, omt, s=0.0)
    with pytest.raises(lf.ShapeError):
        sys.curvature(z, om[0], omt)
    with pytest.raises(lf.NonFiniteError):
        sys.curvature(z, om * np.nan, omt)
    bad = z.copy()
    bad[:9] *= 1.1                                      # z1 not a rotation
    with pytest.raises(lf.NotInGroupError):
        sys.curvature(bad, om, omt)
    with pytest.raises(lf.NotInGroupError):
        sys.lagrangian(bad)
