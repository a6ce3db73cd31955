"""Two rolling disks (003 §1) from Python: conservation, positions, the relative equilibria and
their stability, pickling."""

import pickle

import numpy as np
import pytest

import lieflow as lf


def pair(**kw):
    return lf.RollingDisks(1.0, 0.7, 0.3 + 0.1j, [-0.2, 0.25], 1.0, 1.5, 0.8, 0.6, **kw)


def test_energy_momentum_and_positions():
    d = pair()
    z0 = d.state([0.3, -1.1], [0.7, 0.2])
    tr = lf.integrate(d, z0, dt=0.02, steps=5000, method="gauss6", save_every=50)
    assert tr.theta.shape == (101, 2) and tr.thetadot.shape == (101, 2) and tr.phi.shape == (101,)
    np.testing.assert_allclose(tr.thetadot[0], [0.7, 0.2], atol=1e-14)
    assert np.ptp(tr.energy()) < 1e-13 and np.ptp(d.angular_momentum(tr.states)) < 1e-14
    pos = d.positions(tr.states)
    c, x, p = pos["centres"], pos["masses"], pos["contact"]
    np.testing.assert_allclose(np.linalg.norm(p - c[:, 0], axis=-1), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(p - c[:, 1], axis=-1), 0.7, atol=1e-14)
    np.testing.assert_allclose(1.0 * x[:, 0] + 1.5 * x[:, 1], 0.0, atol=1e-14)   # centre of mass
    # the contact point turns with phi
    np.testing.assert_allclose(np.arctan2(*(p - c[:, 0])[:, ::-1].T), np.angle(np.exp(1j * tr.phi)),
                               atol=1e-12)
    copy = pickle.loads(pickle.dumps(d))
    assert repr(copy) == repr(d) and copy.methods()[0] == "gauss4"


@pytest.mark.parametrize("c", [0.0, 0.9])
def test_relative_equilibria(c):
    d = pair(rolling_constant=c)
    eqs = d.relative_equilibria()
    assert len(eqs) >= 2 and any(e.stable for e in eqs) and not all(e.stable for e in eqs)
    assert [e.theta1 for e in eqs] == sorted(e.theta1 for e in eqs)
    assert d.relative_equilibria(rolling_constant=c)[0].theta1 == eqs[0].theta1
    for e in eqs:
        z = np.array(e.state(1.0))
        pos = d.positions(z)
        a, b = pos["masses"] - pos["contact"]
        assert abs(a[0] * b[1] - a[1] * b[0]) < 1e-13          # X1, X2 and P collinear
        np.testing.assert_allclose(pos["contact"], e.contact_point, atol=1e-15)
        assert e.angular_velocity_range == (0.0, np.inf) and not e.degenerate
        assert (e.curvature < 0) == e.stable
        omega = 1.0 if e.stable else 0.2                         # (unstable: round-off grows)
        tr = lf.integrate(d, e.state(omega), dt=0.01, steps=5000, method="gauss6", save_every=100)
        shape = tr.theta[:, 0] - tr.phi
        assert np.abs(shape - shape[0]).max() < 1e-9
        kick = e.state(1.0)
        kick[0] += 1e-4
        tr = lf.integrate(d, kick, dt=0.02, steps=10_000, method="gauss6", save_every=10)
        dev = np.abs(tr.theta[:, 0] - tr.phi - (e.theta1 - 0.0)).max()
        if e.stable:
            assert dev < 2e-4
        else:
            assert dev > 1e-2


def test_bad_input():
    with pytest.raises(lf.InvalidArgumentError):
        lf.RollingDisks(1.0, 0.7, 1.3, 0.0, 1.0, 1.0, 2.0, 1.0)       # |gamma1| > r1
    with pytest.raises(lf.InvalidArgumentError):
        lf.RollingDisks(1.0, 0.7, 0.0, 0.0, 1.0, -1.0, 1.0, 1.0)
    with pytest.raises(TypeError):
        lf.RollingDisks(1.0, 0.7, "x", 0.0, 1.0, 1.0, 1.0, 1.0)
    with pytest.raises(lf.InvalidArgumentError):
        pair().relative_equilibria(theta1_range=(1.0, 0.0))
