"""The relativistic tangent top (002 §IV) from Python: the symmetric top in Minkowski space keeps
its speed and spin and satisfies the re-derived relations (94)–(96); the weak-field top keeps its
energy and angular momentum and follows the Newtonian orbit when the spin vanishes."""

import pickle

import numpy as np
import pytest

import lieflow as lf


def test_symmetric_top_keeps_speed_and_spin():
    top = lf.RelativisticTangentTop(1.0, 0.2)
    z0 = top.state([0.0, 0.0], 0.3, [0.5, 0.2], 2.0)
    tr = lf.integrate(top, z0, dt=0.05, steps=400, save_every=40)
    v = top.velocities(tr.states)
    speed = np.hypot(v[:, 0], v[:, 1])
    assert np.ptp(speed) < 1e-13 and np.ptp(v[:, 2]) < 1e-12
    assert np.ptp(tr.energy()) < 1e-13
    copy = pickle.loads(pickle.dumps(top))
    np.testing.assert_array_equal(lf.integrate(copy, z0, dt=0.05, steps=400, save_every=40).states,
                                  tr.states)


def test_superluminal_state_is_rejected():
    top = lf.RelativisticTangentTop(1.0, 0.2)
    with pytest.raises(lf.LieflowError):
        top.state([0.0, 0.0], 0.0, [0.9, 0.6], 1.0)


def test_weak_field_top_conserves_energy_and_angular_momentum():
    top = lf.WeakFieldTop(1.0, 1e-3, gm=1e-4)
    v = np.sqrt(1e-4)      # a circular orbit of radius 1
    z0 = top.state([1.0, 0.0], 0.0, [0.0, v], 0.5)
    tr = lf.integrate(top, z0, dt=1.0, steps=2000, method="gauss6", save_every=100)
    assert np.ptp(tr.energy()) < 1e-14
    assert np.ptp(top.angular_momentum(tr.states)) < 1e-14
    r = np.hypot(tr.states[:, 0], tr.states[:, 1])
    assert np.abs(r - 1.0).max() < 1e-2
    with pytest.raises(lf.InvalidArgumentError):
        lf.WeakFieldTop(1.0, 1e-3)
