"""The relativistic tangent top (002 §IV) from Python: the symmetric top in Minkowski space keeps
its speed and spin and satisfies the re-derived relations (94)–(96); the weak-field top keeps its
energy and angular momentum and follows the Newtonian orbit when the spin vanishes; the top on a
curved static space-time over a surface (002 (97)-(103)) keeps its energy, p_theta and Killing
momenta, pickles, and rejects bad surfaces."""

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


def test_symmetric_top_on_a_sphere_conserves_energy_p_theta_and_j_z():
    # 002 (97)-(103): the top on -dt^2 + g over the unit sphere; gauss6 keeps p_theta and the
    # affine Killing momentum J_z to round-off, the energy to ~1e-14; v and s stay constant.
    top = lf.RelativisticTangentTop(1.0, 0.2, surface=lf.surfaces.Sphere(1.0))
    z0 = top.state([1.2, 0.3], 0.5, [0.3, 0.4], 2.0)
    tr = lf.integrate(top, z0, dt=0.02, steps=2000, method="gauss6", save_every=100)
    assert np.ptp(tr.energy()) < 1e-12
    assert np.ptp(tr.states[:, 5]) < 1e-14
    inv = top.invariants(tr.states)
    assert inv.shape == (len(tr.states), 2)             # p_theta, J_z
    assert np.ptp(inv, axis=0).max() < 1e-12
    j = top.killing_momenta(tr.states)
    assert j.shape == (len(tr.states), 3)
    assert np.ptp(j, axis=0).max() < 1e-10
    vs = top.speed_and_spin(tr.states)
    assert np.ptp(vs, axis=0).max() < 1e-12 and 0.4 < vs[0, 0] < 0.6
    # The centre moves: the run is not trivial.
    assert np.ptp(tr.states[:, 1]) > 0.5


def test_surface_top_pickles_and_reproduces_the_run():
    top = lf.RelativisticTangentTop(1.0, 0.2, lf.surfaces.HyperbolicPlane())
    copy = pickle.loads(pickle.dumps(top))
    assert "HyperbolicPlane" in repr(copy)
    z0 = top.state([0.1, 1.0], 0.0, [0.4, 0.2], 1.3)
    a = lf.integrate(top, z0, dt=0.05, steps=40).states
    b = lf.integrate(copy, z0, dt=0.05, steps=40).states
    np.testing.assert_array_equal(a, b)
    # On the Plane it is the Minkowski top.
    plane = lf.RelativisticTangentTop(1.0, 0.2, surface=lf.surfaces.Plane())
    flat = lf.RelativisticTangentTop(1.0, 0.2)
    z0 = flat.state([0.0, 0.0], 0.3, [0.5, 0.2], 2.0)
    np.testing.assert_allclose(lf.integrate(plane, z0, dt=0.05, steps=40).states,
                               lf.integrate(flat, z0, dt=0.05, steps=40).states, atol=1e-13)
    np.testing.assert_allclose(flat.killing_momenta(z0), plane.killing_momenta(z0), atol=1e-15)


def test_bad_surface_arguments_are_rejected():
    with pytest.raises(TypeError):
        lf.RelativisticTangentTop(1.0, 0.2, surface="sphere")
    with pytest.raises(TypeError):
        lf.RelativisticTangentTop(1.0, 0.2, surface=lf.TangentTop(lf.surfaces.Plane(), 1.0, 1.0))
    with pytest.raises(lf.InvalidArgumentError):   # anisotropic body: Minkowski plane only
        lf.RelativisticTangentTop(1.0, (0.1, 0.0, 0.2), surface=lf.surfaces.Sphere(1.0))
    top = lf.RelativisticTangentTop(1.0, 0.2, surface=lf.surfaces.Sphere(2.0))
    with pytest.raises(lf.InvalidArgumentError):   # v = R |dtheta/dt| = 1.2
        top.state([1.0, 0.0], 0.0, [0.6, 0.0], 1.0)
    with pytest.raises(lf.InvalidArgumentError):   # outside the chart 0 < theta < pi
        top.state([-0.1, 0.0], 0.0, [0.1, 0.0], 1.0)


def test_surface_from_callables_matches_the_sphere_and_raises_their_errors():
    S = lf.surfaces

    def metric(t, p):
        return [[1.0, 0.0], [0.0, np.sin(t) ** 2]]

    def frame(t, p):
        if t > 1.5:
            raise RuntimeError("frame failed")
        return [[1.0, 0.0], [0.0, 1.0 / np.sin(t)]]

    python = lf.RelativisticTangentTop(1.0, 0.2, S.MetricSurface(metric, frame, None))
    native = lf.RelativisticTangentTop(1.0, 0.2, S.Sphere(1.0))
    z0 = native.state([1.0, 0.3], 0.5, [0.2, 0.3], 1.5)
    a = lf.integrate(python, z0, dt=0.02, steps=20).states
    b = lf.integrate(native, z0, dt=0.02, steps=20).states
    np.testing.assert_allclose(a, b, atol=1e-7)
    with pytest.raises(RuntimeError, match="frame failed"):
        python.state([1.6, 0.0], 0.0, [0.1, 0.0], 1.0)


def test_weak_field_top_methods_and_pickling():
    # methods() on the class and pickling pass the constructor arguments positionally
    assert lf.WeakFieldTop.methods()[0] == "gauss4"
    top = lf.WeakFieldTop(1.0, 1e-3, gm=1e-4)
    copy = pickle.loads(pickle.dumps(top))
    assert repr(copy) == repr(top) and copy.methods() == top.methods()


# --- the relations (94)-(96) of the symmetric top (issue 25) ---

@pytest.mark.parametrize("surface, x", [(None, [0.3, -0.2]), (lf.surfaces.Sphere(1.3), [1.1, 0.4]),
                                        (lf.surfaces.HyperbolicPlane(), [0.2, 1.1])])
def test_relations_94_to_96_are_the_legendre_map_and_the_energy(surface, x):
    # The states come from the Legendre map of the Lagrangian (002 (93) / (103)) and the energy
    # from the Hamiltonian; (94)-(96) are the closed forms in (v, J = p_theta) and (v, s).
    top = lf.RelativisticTangentTop(1.0, 0.2, surface)
    for xdot, thetadot in ([0.3, -0.2], 2.5), ([0.05, 0.1], -1.2), ([-0.35, 0.3], 0.4):
        z = np.asarray(top.state(x, 0.4, xdot, thetadot))
        (v, s), j = top.speed_and_spin(z), z[5]
        if surface is None:
            p = np.hypot(z[3], z[4])
            assert s == pytest.approx(thetadot, abs=1e-14)
        else:   # |p_x - p_theta alpha| in the inverse metric
            pi = z[3:5] - j * np.asarray(surface.connection(x))
            p = np.sqrt(pi @ np.linalg.solve(surface.metric(x), pi))
        assert top.momentum_94(v, j) == pytest.approx(p, rel=1e-12)
        assert top.spin_rate_95(v, j) == pytest.approx(s, rel=1e-12)
        assert top.energy_96(v, s) == pytest.approx(top.energy(z), rel=1e-13)
    # They map over broadcast leading axes.
    vs = np.array([[0.1], [0.5]])
    assert top.momentum_94(vs, [0.2, 0.3, 0.4]).shape == (2, 3)
    np.testing.assert_allclose(top.energy_96(vs, 2.0)[:, 0],
                               [top.energy_96(0.1, 2.0), top.energy_96(0.5, 2.0)], rtol=0)
    assert isinstance(top.spin_rate_95(0.5, 0.3), float)


def test_relations_94_to_96_refuse_what_they_do_not_cover():
    top = lf.RelativisticTangentTop(1.0, 0.2)
    for f in (top.momentum_94, top.spin_rate_95, top.energy_96):
        with pytest.raises(lf.InvalidArgumentError, match="v"):
            f(1.0, 0.3)                                        # v = c
        with pytest.raises(lf.InvalidArgumentError, match="v"):
            f([0.2, -0.1], 0.3)
        with pytest.raises(lf.NonFiniteError):
            f(0.5, np.nan)
        with pytest.raises(lf.ShapeError):
            f([0.1, 0.2], [0.1, 0.2, 0.3])
    with pytest.raises(lf.InvalidArgumentError, match="p_theta"):
        top.momentum_94(0.5, 1e300)                            # |p| beyond the float range
    aniso = lf.RelativisticTangentTop(1.0, (0.1, 0.02, 0.2))
    with pytest.raises(lf.InvalidArgumentError, match="symmetric"):
        aniso.momentum_94(0.5, 0.3)


def test_relation_94_does_not_fix_the_speed_for_fast_spin():
    # 002 concludes from (94) that |p| determines v. v -> |p| is monotone only for
    # kappa = J^2 / (2 I0 m) below 7.34: found here by bisection on the monotonicity of (94)
    # sampled finely on [0, 1), then three speeds with one |p| at kappa = 10.
    top = lf.RelativisticTangentTop(1.0, 2.0)          # m = 1, I0 = tr I / 2 = 1
    v = np.linspace(0.0, 1.0 - 1e-9, 200_001)

    def monotone(kappa):
        return bool(np.all(np.diff(top.momentum_94(v, np.sqrt(2 * kappa))) > 0))

    lo, hi = 1.0, 10.0
    assert monotone(lo) and not monotone(hi)
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if monotone(mid) else (lo, mid)
    assert abs(lo - 7.34) < 5e-3, lo
    p = top.momentum_94(v, np.sqrt(20.0))
    falling = v[1:][np.diff(p) < 0]
    assert 0.90 < falling[0] < 0.92 and 0.97 < falling[-1] < 0.98
    p0 = 0.5 * (p.max(where=v < falling[0], initial=0) + p.min(where=v > falling[-1], initial=np.inf))
    speeds = v[1:][np.diff(np.sign(p - p0)) != 0]
    assert len(speeds) == 3 and speeds[0] < falling[0] < speeds[1] < falling[-1] < speeds[2]
