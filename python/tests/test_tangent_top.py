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


# --- surfaces from Python callables (module level, so that they pickle) ---

A, B = 2.0, 0.7


def torus_r(s):
    return A + B * np.cos(s), -B * np.sin(s), -B * np.cos(s), B * np.sin(s)


def torus_z(s):
    return B * np.sin(s), B * np.cos(s), -B * np.sin(s), -B * np.cos(s)


def saddle(x, y):
    return 0.5 * (0.8 * x * x - 0.5 * y * y), 0.8 * x, -0.5 * y, 0.8, 0.0, -0.5, 0, 0, 0, 0


def sphere_metric(t, p):
    return [[1.0, 0.0], [0.0, np.sin(t) ** 2]]


def sphere_frame(t, p):
    return [[1.0, 0.0], [0.0, 1.0 / np.sin(t)]]


def inside(t, p):
    return 0.0 < t < np.pi


def run(top, x0, method="gauss4", steps=40):
    z0 = top.state(x0, 0.3, [0.4, -0.3], 0.9)
    return lf.integrate(top, z0, dt=0.02, steps=steps, method=method, save_every=10)


@pytest.mark.parametrize("python, native, x0, tol", [
    (S.Revolution(torus_r, torus_z, (-np.pi, np.pi)), S.Torus(A, B), [0.9, 0.4], 1e-13),
    (S.Graph(saddle), S.Quadric(0.8, -0.5), [0.3, -0.4], 1e-13),
    (S.MetricSurface(sphere_metric, sphere_frame, inside), S.Sphere(1.0), [1.2, 0.4], 1e-7),
])
def test_surfaces_from_callables_match_the_built_ins(python, native, x0, tol):
    assert python.curvature(x0) == pytest.approx(native.curvature(x0), abs=1e-7)
    np.testing.assert_allclose(python.metric(x0), native.metric(x0), atol=1e-13)
    np.testing.assert_allclose(python.connection(x0), native.connection(x0), atol=1e-9)
    a = run(lf.TangentTop(python, 1.0, 0.6), x0)
    b = run(lf.TangentTop(native, 1.0, 0.6), x0)
    np.testing.assert_allclose(a.states, b.states, atol=tol)
    copy = pickle.loads(pickle.dumps(lf.TangentTop(python, 1.0, 0.6)))
    np.testing.assert_allclose(run(copy, x0).states, a.states, atol=0)


def test_callable_errors_are_raised_and_wrong_returns_rejected():
    def bad_profile(s):
        if s > 0.5:
            raise RuntimeError("profile failed")
        return torus_r(s)

    top = lf.TangentTop(S.Revolution(bad_profile, torus_z, (-np.pi, np.pi)), 1.0, 0.6)
    z0 = top.state([0.2, 0.0], 0.0, [2.0, 0.0], 0.0)
    with pytest.raises(RuntimeError, match="profile failed"):
        lf.integrate(top, z0, dt=0.01, steps=100, method="gauss4")
    with pytest.raises(RuntimeError, match="profile failed"):
        top.state([1.0, 0.0], 0.0, [0.0, 0.0], 0.0)
    short = S.Graph(lambda x, y: (0.0, 0.0, 0.0))
    with pytest.raises(lf.ShapeError):
        short.metric([0.1, 0.2])
    with pytest.raises(TypeError):
        S.Graph(3.0)
    with pytest.raises(lf.InvalidArgumentError):
        S.Revolution(torus_r, torus_z, (1.0, 0.0))


# --- the embedded top (002 §II.D) and the charged particle (§III.B) ---

def test_embedded_sphere_top_is_the_rigid_body():
    # On the sphere of radius R, the embedded top with Euler tensor diag(I11, I22) is the free
    # rigid body about the centre with moments (I11 + I22, m R^2 + I22, m R^2 + I11) in the
    # frame (n, E1, E2).
    r, m, i11, i22 = 1.4, 0.9, 0.5, 0.2
    top = lf.TangentTop(S.Sphere(r), m, np.diag([i11, i22]), embedded=True)
    np.testing.assert_allclose(top.tensor, np.diag([i11, i22]))
    z0 = top.state([1.1, 0.3], 0.4, [0.5, -0.3], 0.8)
    tr = lf.integrate(top, z0, dt=0.005, steps=1200, method="gauss6", save_every=100)
    frame = top.ambient_frame(tr.states)                 # rows c, E1, E2
    q = np.stack([frame[:, 0] / r, frame[:, 1], frame[:, 2]], axis=-1)
    np.testing.assert_allclose(q[0].T @ q[0], np.eye(3), atol=1e-14)
    moments = np.array([i11 + i22, m * r * r + i22, m * r * r + i11])
    v = top.velocities(z0)
    cdot = (frame[0, 0] - top.ambient_frame(top.state([1.1 - 1e-6 * v[0], 0.3 - 1e-6 * v[1]],
                                                      0.4, [0, 0], 0))[0]) / 1e-6
    spin = z0[5] / (i11 + i22)
    omega = np.array([spin, -cdot @ frame[0, 2] / r, cdot @ frame[0, 1] / r])
    body = lf.RigidBody(moments)
    rb = lf.integrate(body, moments * omega, dt=0.005, steps=1200, method="splitting6",
                      save_every=100, attitude=q[0])
    np.testing.assert_allclose(q, rb.attitude, atol=1e-5)   # cdot by a one-sided difference
    assert np.ptp(tr.p_theta()) > 1e-3                       # the spin is not conserved
    assert np.abs(np.ptp(tr.killing_momenta(), axis=0)).max() < 1e-12
    assert np.ptp(tr.energy()) < 1e-13


def test_magnetic_analogue_follows_the_centre():
    top = lf.TangentTop(S.HyperbolicPlane(), 1.0, 1.0)
    z0 = top.state([0.2, 1.0], 0.3, [0.3, 0.2], 1.0)
    particle = top.magnetic_analogue(z0[5])
    assert isinstance(particle, lf.ChargedParticle) and particle.charge == z0[5]
    np.testing.assert_allclose(particle.potential([0.2, 1.0]), [1.0, 0.0])
    np.testing.assert_allclose(particle.metric([0.2, 2.0]), np.eye(2) / 4)
    w0 = particle.state([0.2, 1.0], top.velocities(z0)[:2])
    a = lf.integrate(top, z0, dt=0.01, steps=500, method="gauss6", save_every=50)
    b = lf.integrate(particle, w0, dt=0.01, steps=500, method="gauss6", save_every=50)
    np.testing.assert_allclose(a.x, b.x, atol=1e-12)
    np.testing.assert_allclose(a.xdot, b.xdot, atol=1e-12)
    np.testing.assert_allclose(a.energy(), b.energy() + z0[5] ** 2 / 2, atol=1e-12)
    np.testing.assert_allclose(a.killing_momenta(), b.killing_momenta(), atol=1e-12)
    copy = pickle.loads(pickle.dumps(particle))
    assert copy.charge == particle.charge and repr(copy) == repr(particle)
    aniso = lf.TangentTop(S.Sphere(1.0), 1.0, [[0.4, 0.1], [0.1, 0.2]], embedded=True)
    with pytest.raises(lf.InvalidArgumentError):
        aniso.magnetic_analogue(1.0)


def test_bad_tops_are_rejected():
    with pytest.raises(lf.InvalidArgumentError):
        lf.TangentTop(S.HyperbolicPlane(), 1.0, 1.0, embedded=True)   # no embedding in R^3
    with pytest.raises(lf.ShapeError):
        lf.TangentTop(S.Plane(), 1.0, np.eye(3))
    with pytest.raises(lf.InvalidArgumentError):
        lf.TangentTop(S.Plane(), 1.0, [[1.0, 2.0], [2.0, 1.0]])       # not positive
    with pytest.raises(lf.InvalidArgumentError):
        lf.TangentTop(S.HyperbolicPlane(), 1.0, 1.0).ambient_frame(np.zeros(6) + 1)


def test_points_next_to_a_coordinate_singularity_are_refused():
    # the frame 1/(R sin theta) and the metric's inverse would overflow (found by the fuzz suite)
    with pytest.raises(lf.InvalidArgumentError):
        S.Sphere(1.0).frame([1e-310, 3e-311])
    with pytest.raises(lf.InvalidArgumentError):
        S.HyperbolicPlane().metric([0.0, 1e-200])
    assert np.isfinite(S.Sphere(1.0).frame([1e-150, 0.0])).all()
