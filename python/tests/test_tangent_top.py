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


# --- the metric (47) and the Lagrangian of the top, and MetricSurface.check_frame (issue 25) ---

TOPS = [
    ("plane", lambda: lf.TangentTop(S.Plane(), 1.3, 0.5), [0.2, -0.1]),
    ("sphere", lambda: lf.TangentTop(S.Sphere(1.2), 0.9, 0.4), [1.0, 0.3]),
    ("hyperbolic", lambda: lf.TangentTop(S.HyperbolicPlane(), 1.0, 0.7), [0.1, 1.3]),
    ("torus", lambda: lf.TangentTop(S.Torus(2.0, 0.7), 1.1, 0.6), [0.9, 0.4]),
    ("embedded anisotropic sphere",
     lambda: lf.TangentTop(S.Sphere(1.2), 0.9, [[0.3, 0.05], [0.05, 0.2]], embedded=True),
     [1.0, 0.3]),
]


@pytest.mark.parametrize("name, make, x", TOPS, ids=[t[0] for t in TOPS])
def test_lagrangian_is_the_metric_form_and_its_legendre_map_is_the_hamiltonians(name, make, x):
    top = make()
    theta, xdot, thetadot = 0.7, np.array([0.3, -0.4]), 1.1
    etadot = np.array([*xdot, thetadot])
    g = top.metric(x, theta)
    assert g.shape == (3, 3) and np.all(np.linalg.eigvalsh(g) > 0)
    np.testing.assert_allclose(g, g.T, atol=0)
    lag = top.lagrangian(x, theta, xdot, thetadot)
    assert lag == pytest.approx(0.5 * etadot @ g @ etadot, rel=1e-14)
    # p = dL/d(etadot) by central differences (exact for a quadratic up to round-off) is the
    # momentum of `state`, and the Hamiltonian's velocities of that state are etadot again.
    eps = 1e-4
    p = []
    for k in range(3):
        e = eps * np.eye(3)[k]
        up, dn = etadot + e, etadot - e
        p.append((top.lagrangian(x, theta, up[:2], up[2]) - top.lagrangian(x, theta, dn[:2], dn[2]))
                 / (2 * eps))
    z = np.asarray(top.state(x, theta, xdot, thetadot))
    np.testing.assert_allclose(z[3:], p, atol=1e-11)
    np.testing.assert_allclose(top.velocities(z), etadot, atol=1e-13)
    assert top.energy(z) == pytest.approx(lag, rel=1e-13)      # a purely kinetic Lagrangian


@pytest.mark.parametrize("name, make, x", TOPS, ids=[t[0] for t in TOPS])
def test_euler_lagrange_equations_of_the_lagrangian_hold_along_a_motion(name, make, x):
    # d/dt p = dL/d(eta): the position derivatives of L (the metric's, the connection's and, for
    # the embedded anisotropic top, theta's) against the rate of p along a gauss6 motion.
    top = make()
    h = 2.5e-3
    z0 = top.state(x, 0.7, [0.3, -0.4], 1.1)
    tr = lf.integrate(top, z0, dt=h / 10, steps=40, method="gauss6", save_every=10)
    pdot = (tr.p[0] - 8 * tr.p[1] + 8 * tr.p[3] - tr.p[4]) / (12 * h)
    eta, etadot = tr.states[2, :3], top.velocities(tr.states[2])
    eps = 1e-5
    dL = []
    for k in range(3):
        up, dn = eta + eps * np.eye(3)[k], eta - eps * np.eye(3)[k]
        dL.append((top.lagrangian(up[:2], up[2], etadot[:2], etadot[2])
                   - top.lagrangian(dn[:2], dn[2], etadot[:2], etadot[2])) / (2 * eps))
    np.testing.assert_allclose(pdot, dL, atol=1e-8)


@pytest.mark.parametrize("surface, x", [(S.Sphere(1.2), [1.0, 0.3]), (S.HyperbolicPlane(), [0.1, 1.3]),
                                        (S.Quadric(0.8, -0.5), [0.3, -0.4])])
def test_metric_47_in_the_surfaces_terms(surface, x):
    # g_AB = [[m g + I a a^T, I a], [I a^T, I]], a the connection 1-form: the cross terms carry
    # +I a (002 (47) prints -I a; its (45) has the slip).
    m, inertia, theta = 0.9, 0.4, 0.7
    g = lf.TangentTop(surface, m, inertia).metric(x, theta)
    alpha = np.array(surface.connection(x))
    assert np.abs(alpha).max() > 0.05
    np.testing.assert_allclose(g[:2, 2], inertia * alpha, atol=1e-15)
    np.testing.assert_allclose(g[2, 2], inertia, atol=0)
    np.testing.assert_allclose(g[:2, :2], m * surface.metric(x) + inertia * np.outer(alpha, alpha),
                               atol=1e-15)
    np.testing.assert_allclose(lf.TangentTop(S.Plane(), m, inertia).metric([0.3, 0.2], theta),
                               np.diag([m, m, inertia]), atol=0)


def test_metric_and_lagrangian_refuse_points_outside_the_chart_and_raise_callable_errors():
    top = lf.TangentTop(S.Sphere(1.0), 1.0, 0.5)
    with pytest.raises(lf.InvalidArgumentError):
        top.metric([0.0, 0.3], 0.0)
    with pytest.raises(lf.InvalidArgumentError):
        top.lagrangian([4.0, 0.3], 0.0, [0.1, 0.2], 0.3)
    with pytest.raises(lf.InvalidArgumentError):
        top.lagrangian([1.0, 0.3], 0.0, [1e200, 0.2], 0.3)       # L beyond the float range
    with pytest.raises(lf.NonFiniteError):
        top.metric([1.0, 0.3], np.nan)

    def failing_metric(t, p):
        raise RuntimeError("metric failed")

    bad = lf.TangentTop(S.MetricSurface(failing_metric, sphere_frame, inside), 1.0, 0.5)
    with pytest.raises(RuntimeError, match="metric failed"):
        bad.metric([1.0, 0.3], 0.0)
    with pytest.raises(RuntimeError, match="metric failed"):
        bad.lagrangian([1.0, 0.3], 0.0, [0.1, 0.2], 0.3)


def frame_defect(metric, frame, x):
    """max over a, b of abs(g(E_a, E_b) - delta_ab), from the callables in numpy."""
    g, e = np.asarray(metric(*x), float), np.asarray(frame(*x), float)
    return np.abs(e @ g @ e.T - np.eye(2)).max()


def euclidean_frame(t, p):
    return [[1.0, 0.0], [0.0, 1.0]]


def flipped_frame(t, p):
    return [[0.0, 1.0 / np.sin(t)], [1.0, 0.0]]


def test_check_frame_of_a_metric_surface():
    good = S.MetricSurface(sphere_metric, sphere_frame, inside)
    for x in ([1.2, 0.4], [0.3, -2.0], [2.9, 5.0]):
        assert good.check_frame(x) is None and good.check_frame(x, tol=1e-15) is None
    # Orthonormal for the Euclidean metric, not for the sphere's (except on the equator).
    euclid = S.MetricSurface(sphere_metric, euclidean_frame, inside)
    assert euclid.check_frame([np.pi / 2, 0.3]) is None
    with pytest.raises(lf.InvalidArgumentError, match="frame"):
        euclid.check_frame([1.0, 0.3])
    with pytest.raises(lf.InvalidArgumentError, match="oriented"):
        S.MetricSurface(sphere_metric, flipped_frame, inside).check_frame([1.0, 0.3])
    # The tolerance against the defect computed in numpy, on frames scaled by 1 + s.
    for s in (1e-9, 1e-7, 1e-5):
        def scaled(t, p, s=s):
            return (1 + s) * np.asarray(sphere_frame(t, p))

        surface = S.MetricSurface(sphere_metric, scaled, inside)
        defect = frame_defect(sphere_metric, scaled, (1.0, 0.3))
        assert defect == pytest.approx(2 * s, rel=1e-3)
        surface.check_frame([1.0, 0.3], tol=1.01 * defect)
        with pytest.raises(lf.InvalidArgumentError):
            surface.check_frame([1.0, 0.3], tol=0.99 * defect)
    with pytest.raises(lf.InvalidArgumentError, match="domain"):
        good.check_frame([-1.0, 0.3])
    with pytest.raises(lf.InvalidArgumentError, match="tol"):
        good.check_frame([1.0, 0.3], tol=np.nan)
    with pytest.raises(lf.InvalidArgumentError, match="MetricSurface"):
        S.Sphere(1.0).check_frame([1.0, 0.3])

    def failing_frame(t, p):
        raise RuntimeError("frame failed")

    with pytest.raises(RuntimeError, match="frame failed"):
        S.MetricSurface(sphere_metric, failing_frame, inside).check_frame([1.0, 0.3])
