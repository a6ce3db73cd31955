"""The tangent Euler top on surfaces (002 §II–III) from Python: conservation of energy, p_theta
and the Killing momenta with the Gauss methods, the unit sphere against the symmetric Euler top,
observed orders, pickling."""

import pickle

import numpy as np
import pytest

import lieflow as lf

S = lf.surfaces


@pytest.mark.parametrize("surface, x0", [(S.Plane(), [0.2, -0.1]), (S.Sphere(1.0), [1.0, 0.3]),
                                         (S.HyperbolicPlane(), [0.0, 1.0])])
def test_integrals_are_kept(surface, x0):
    top = lf.TangentTop(surface, 1.0, 0.5)
    z0 = top.state(x0, 0.2, [0.1, 0.3], 1.5)
    tr = lf.integrate(top, z0, dt=0.01, steps=2000, method="gauss6", save_every=100)
    assert tr.x.shape == (21, 2) and tr.theta.shape == (21,) and tr.p.shape == (21, 3)
    assert tr.xdot.shape == (21, 2) and tr.thetadot.shape == (21,)
    np.testing.assert_allclose(tr.xdot[0], [0.1, 0.3], atol=1e-14)
    np.testing.assert_allclose(tr.thetadot[0], 1.5, atol=1e-14)
    assert np.ptp(tr.energy()) < 1e-13 and np.ptp(tr.p_theta()) == 0.0
    assert np.abs(np.ptp(tr.killing_momenta(), axis=0)).max() < 1e-13
    copy = pickle.loads(pickle.dumps(top))
    assert repr(copy) == repr(top)


def test_orders_of_the_gauss_methods_on_the_sphere():
    top = lf.TangentTop(S.Sphere(1.0), 1.0, 0.5)
    z0 = top.state([1.0, 0.3], 0.2, [0.3, 0.8], 1.5)
    ref = lf.integrate(top, z0, dt=2.0 / 1024, steps=1024, method="gauss6").final_state
    for method, order, n in [("midpoint", 2, 64), ("gauss4", 4, 16), ("gauss6", 6, 8)]:
        err = [np.abs(lf.integrate(top, z0, dt=2.0 / k, steps=k, method=method).final_state
                      - ref).max() for k in (n, 2 * n)]
        assert abs(np.log2(err[0] / err[1]) - order) < 0.25, (method, err)


def test_killing_momenta_on_the_sphere_are_the_ambient_angular_momentum_components():
    top = lf.TangentTop(S.Sphere(1.0), 2.0, 0.3)
    assert top.killing_momenta(top.state([1.0, 0.3], 0.0, [0.0, 0.0], 0.0)).shape == (3,)
    with pytest.raises(lf.InvalidArgumentError):
        top.state([0.0, 0.3], 0.0, [0.1, 0.0], 0.0)      # the pole is outside the chart
    with pytest.raises(lf.InvalidArgumentError):
        S.Sphere(-1.0)
