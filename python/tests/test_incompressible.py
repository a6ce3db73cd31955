"""The incompressible pseudo-rigid body: lf.PseudoRigidBody(n, potential, incompressible=True)
(det X = det X0 held by RATTLE and its compositions rattle4, rattle6)."""

import pickle

import numpy as np
import pytest

import lieflow as lf

pot = lf.potentials

rng = np.random.default_rng(12)
X0 = np.diag([1.4, 1.15, 0.9]) + 0.15 * rng.uniform(-1, 1, (3, 3))
P_RAW = 0.8 * rng.uniform(-1, 1, (3, 3))


def body(n=3, potential=None):
    potential = potential or pot.SaintVenantKirchhoff(1.0, 2.0)
    return lf.PseudoRigidBody(n, potential, incompressible=True)


def cof(X):
    return np.linalg.det(X) * np.linalg.inv(X).T


def test_construction_attributes_methods_and_repr():
    b = body()
    assert b.incompressible and b.check_det and b.n == 3
    assert b.methods() == ["rattle", "rattle4", "rattle6"]
    # On the class (and for a compressible body) the methods of the free body.
    assert lf.PseudoRigidBody.methods() == ["verlet", "verlet4", "verlet6", "reduced"]
    free = lf.PseudoRigidBody(3, pot.Harmonic(1.0))
    assert not free.incompressible and free.methods() == lf.PseudoRigidBody.methods()
    # check_det is always on for an incompressible body.
    assert lf.PseudoRigidBody(3, pot.Harmonic(1.0), check_det=False, incompressible=True).check_det
    assert "incompressible=True" in repr(b) and "incompressible=False" in repr(free)
    assert "rattle4" in lf.PseudoRigidBody.__doc__
    with pytest.raises(TypeError):
        b.methods(1)


def test_project_momentum_gives_a_volume_preserving_momentum():
    b = body()
    P = b.project_momentum(X0, P_RAW)
    assert P.shape == (3, 3)
    C = cof(X0)
    assert abs(np.sum(C * P)) < 1e-15 * np.linalg.norm(C) * np.linalg.norm(P)
    assert abs(np.trace(np.linalg.solve(X0, P))) < 1e-14
    # P_RAW - P is along cof X (an orthogonal projection), and projecting again changes nothing.
    D = P_RAW - P
    np.testing.assert_allclose(D, np.sum(D * C) / np.sum(C * C) * C, atol=1e-15)
    np.testing.assert_allclose(b.project_momentum(X0, P), P, atol=1e-15)
    with pytest.raises(lf.NotInGroupError):
        b.project_momentum(np.diag([-1.0, 1.0, 1.0]), P_RAW)
    with pytest.raises(lf.ShapeError):
        b.project_momentum(X0, np.zeros((2, 2)))
    with pytest.raises(lf.NonFiniteError):
        b.project_momentum(X0, np.full((3, 3), np.nan))


def test_integrate_keeps_det_momenta_and_energy():
    b = body()
    P0 = b.project_momentum(X0, P_RAW)
    d0 = np.linalg.det(X0)
    for method in b.methods():
        tr = lf.integrate(b, (X0, P0), dt=0.01, steps=2000, method=method, save_every=100)
        X, P = tr.states[:, :9].reshape(-1, 3, 3), tr.states[:, 9:].reshape(-1, 3, 3)
        dets = np.linalg.det(X)
        assert np.max(np.abs(dets - d0)) < 1e-13 * d0, method
        rates = [abs(np.sum(cof(x) * p)) / (np.linalg.norm(cof(x)) * np.linalg.norm(p))
                 for x, p in zip(X, P)]
        assert max(rates) < 1e-13, method
        L, G = b.angular_momentum(tr.states), b.circulation(tr.states)
        np.testing.assert_allclose(L, np.broadcast_to(L[0], L.shape), atol=1e-12)
        np.testing.assert_allclose(G, np.broadcast_to(G[0], G.shape), atol=1e-12)
        inv = tr.invariants()
        assert inv.shape == (21, 3)
        np.testing.assert_allclose(inv[:, 2], d0, rtol=1e-13)
        E = tr.energy()
        assert np.max(np.abs(E - E[0])) < 1e-3 * abs(E[0]), method
    # The default method is rattle.
    assert lf.integrate(b, (X0, P0), dt=0.01, steps=2).method == "rattle"


def test_a_state_that_changes_the_volume_is_refused():
    b = body()
    with pytest.raises(lf.InvalidArgumentError, match="project_momentum"):
        lf.integrate(b, (X0, P_RAW), dt=0.01, steps=10)
    # Verlet and the reduced flows are not methods of the incompressible body.
    P0 = b.project_momentum(X0, P_RAW)
    with pytest.raises(lf.UnsupportedMethodError):
        lf.integrate(b, (X0, P0), dt=0.01, steps=10, method="verlet")
    # The compressible body takes any momentum.
    free = lf.PseudoRigidBody(3, pot.SaintVenantKirchhoff(1.0, 2.0))
    assert lf.integrate(free, (X0, P_RAW), dt=0.01, steps=10).states.shape == (11, 18)


def test_orders_2_4_6():
    b = body()
    P0 = b.project_momentum(X0, P_RAW)

    def end(method, steps):
        return lf.integrate(b, (X0, P0), dt=1.0 / steps, steps=steps, method=method,
                            save_every=steps).states[-1]

    ref = end("rattle6", 1280)
    for method, p, k in [("rattle", 2, 40), ("rattle4", 4, 20), ("rattle6", 6, 10)]:
        e1, e2 = (np.linalg.norm(end(method, s) - ref) for s in (k, 2 * k))
        assert abs(np.log2(e1 / e2) - p) < 0.3, (method, e1, e2)


def test_n_2_batches_and_pickling():
    b = body(2, pot.Harmonic(1.5))
    X = np.array([[1.2, 0.3], [-0.1, 0.8]])
    P = b.project_momentum(X, np.array([[0.2, -0.5], [0.7, 0.1]]))
    batch = (np.stack([X, 1.1 * X]), np.stack([P, -P]))
    tr = lf.integrate(b, batch, dt=0.01, steps=500, method="rattle4", save_every=100)
    dets = np.linalg.det(tr.states[..., :4].reshape(2, -1, 2, 2))
    np.testing.assert_allclose(dets, dets[:, :1].repeat(dets.shape[1], 1), rtol=1e-13)
    copy = pickle.loads(pickle.dumps(b))
    assert copy.incompressible and repr(copy) == repr(b) and copy.methods() == b.methods()
    again = lf.integrate(copy, batch, dt=0.01, steps=500, method="rattle4", save_every=100)
    np.testing.assert_array_equal(again.states, tr.states)
