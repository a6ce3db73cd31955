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
