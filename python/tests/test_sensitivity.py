"""Issue 26: ``lf.integrate(..., sensitivity=True)``, the Jacobians of the method's own discrete
map (the tangent lift run by the same method). Each against central differences of the same
method; the Verlet Jacobians symplectic; batches as single runs; typed refusals."""

import numpy as np
import scipy.linalg
import pytest

import lieflow as lf

X0 = np.array([[1.3, 0.1, -0.05], [0.02, 1.1, 0.08], [-0.03, 0.05, 0.9]])
P0 = np.array([[0.1, -0.5, 0.2], [0.6, 0.05, -0.3], [-0.1, 0.4, 0.02]])
# Semi-axes well apart, for the reduced coordinates (distinct a_i).
X_APART = np.array([[1.6, 0.1, -0.05], [0.02, 1.1, 0.08], [-0.03, 0.05, 0.7]])
OMEGA = np.block([[np.zeros((9, 9)), np.eye(9)], [-np.eye(9), np.zeros((9, 9))]])


def body():
    return lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0)
                              + lf.potentials.Volumetric(0.5, 1.4))


def differences(system, z0, method, dt, steps, h=1e-5):
    """Central differences of the final state in each initial component."""
    d = len(z0)
    jac = np.empty((d, d))
    for j in range(d):
        hj = h * max(1.0, abs(z0[j]))
        e = np.zeros(d)
        e[j] = hj
        end = [lf.integrate(system, z0 + s * e, dt, steps, method=method).final_state
               for s in (1, -1)]
        jac[:, j] = (end[0] - end[1]) / (2 * hj)
    return jac


@pytest.mark.parametrize("method", ["verlet", "verlet4"])
def test_pseudo_rigid_body_verlet_jacobians_are_the_methods_derivative_and_symplectic(method):
    prb = body()
    assert prb.sensitivity_methods() == ["verlet", "verlet4", "verlet6", "reduced"]
    z0 = np.concatenate([X0.ravel(), P0.ravel()])
    traj = lf.integrate(prb, z0, 0.05, 40, method=method, save_every=10, sensitivity=True)
    plain = lf.integrate(prb, z0, 0.05, 40, method=method, save_every=10)
    np.testing.assert_array_equal(traj.states, plain.states)
    assert traj.jacobian.shape == (5, 18, 18)
    np.testing.assert_array_equal(traj.jacobian[0], np.eye(18))
    np.testing.assert_array_equal(traj.jacobian[-1], traj.final_jacobian)
    fd = differences(prb, z0, method, 0.05, 40)
    np.testing.assert_allclose(traj.final_jacobian, fd, atol=1e-8 * np.abs(fd).max())
    for J in traj.jacobian:
        assert np.abs(J.T @ OMEGA @ J - OMEGA).max() < 1e-12 * max(1.0, np.abs(J).max()) ** 2


def test_the_reduced_flows_jacobians_are_the_methods_derivative_and_symplectic():
    """Method ``reduced`` (001 §7): the directions travel in the reduced coordinates and come
    back as (δX, δP); against differences of the method (its parameter Jacobian below)."""
    def build(t):
        return lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(t[0], t[1])
                                  + lf.potentials.Volumetric(t[2], t[3]))

    theta = np.array([1.0, 2.0, 0.5, 1.4])
    z0 = np.concatenate([X_APART.ravel(), P0.ravel()])
    traj = lf.integrate(build(theta), z0, 0.02, 25, method="reduced", sensitivity=True)
    np.testing.assert_array_equal(
        traj.states, lf.integrate(build(theta), z0, 0.02, 25, method="reduced").states)
    J = traj.final_jacobian
    fd = differences(build(theta), z0, "reduced", 0.02, 25)
    np.testing.assert_allclose(J, fd, atol=1e-8 * np.abs(fd).max())
    assert np.abs(J.T @ OMEGA @ J - OMEGA).max() < 1e-12 * np.abs(J).max() ** 2


TOPS = [
    (lf.RigidBody([1.0, 2.0, 3.0]), np.array([0.3, -0.8, 1.1])),
    (lf.HeavyTop([1.0, 2.0, 3.0], 0.7, chi=[0.2, -0.3, 1.0]),
     np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8])),
]


@pytest.mark.parametrize("system,z0", TOPS, ids=["RigidBody", "HeavyTop"])
def test_every_sensitivity_method_of_the_tops_against_differences(system, z0):
    """The splittings (the default first, processed ones included) and rk4: the Jacobian of the
    method's map against central differences of the same method."""
    methods = system.sensitivity_methods()
    assert methods[0] == system.methods()[0] and "rk4" in methods
    for method in methods:
        traj = lf.integrate(system, z0, 0.02, 100, method=method, save_every=100,
                            sensitivity=True)
        fd = differences(system, z0, method, 0.02, 100)
        np.testing.assert_allclose(traj.final_jacobian, fd, atol=1e-8 * np.abs(fd).max(),
                                   err_msg=method)


@pytest.mark.parametrize("system,z0", TOPS, ids=["RigidBody", "HeavyTop"])
def test_a_batch_of_jacobians_is_its_members_runs(system, z0):
    traj = lf.integrate(system, z0, 0.02, 100, save_every=100, sensitivity=True)
    batch = lf.integrate(system, np.stack([z0, 1.1 * z0]), 0.02, 100,
                         save_every=50, sensitivity=True)
    assert batch.jacobian.shape == (2, 3, len(z0), len(z0))
    np.testing.assert_array_equal(batch.jacobian[0, -1], traj.final_jacobian)


def test_t_eval_with_sensitivity_is_the_shortened_steps_derivative():
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    z0 = np.array([0.3, -0.8, 1.1])
    traj = lf.integrate(rb, z0, 0.1, 10, method="rk4", t_eval=[0.25, 0.55], sensitivity=True)
    assert traj.jacobian.shape == (2, 3, 3)
    fd = np.empty((3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = 1e-6
        a = lf.integrate(rb, z0 + e, 0.1, 10, method="rk4", t_eval=[0.25, 0.55]).states[1]
        b = lf.integrate(rb, z0 - e, 0.1, 10, method="rk4", t_eval=[0.25, 0.55]).states[1]
        fd[:, j] = (a - b) / 2e-6
    np.testing.assert_allclose(traj.jacobian[1], fd, atol=1e-8)


def test_sensitivity_refuses_what_it_cannot_do_with_typed_errors():
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    z0 = [0.3, -0.8, 1.1]
    with pytest.raises(lf.UnsupportedMethodError, match="available for"):
        lf.integrate(body(), np.concatenate([X0.ravel(), P0.ravel()]), 0.1, 10,
                     method="splitting", sensitivity=True)
    with pytest.raises(lf.ShapeError, match="attitude"):
        lf.integrate(rb, z0, 0.1, 10, attitude=np.eye(4), sensitivity=True)
    with pytest.raises(lf.InvalidArgumentError, match="events"):
        lf.integrate(rb, z0, 0.1, 10, method="rk4", events=lambda t, z: z[0], sensitivity=True)
    bare = lf.LiePoisson("so3", lambda mu: 0.5 * float(mu @ mu), gradient=lambda mu: mu)
    with pytest.raises(lf.InvalidArgumentError, match="no tangent maps"):
        lf.integrate(bare, z0, 0.1, 10, sensitivity=True)
    assert bare.sensitivity_methods() == []
    disks = lf.RollingDisks(1.0, 0.7, 0.3 + 0.1j, [-0.2, 0.25], 1.0, 1.5, 0.8, 0.6)
    assert disks.sensitivity_methods() == disks.methods()
    disk = lf.RollingDisk(1.0, 0.5, 0.125, 0.0625, spring=0.4)
    assert disk.sensitivity_methods() == ["nonholonomic"]
    assert disk.parameters == ["spring", "tilt"]
    with pytest.raises(TypeError, match="sensitivity"):
        lf.integrate(rb, z0, 0.1, 10, method="rk4", sensitivity="yes")
    inc = lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0), incompressible=True)
    assert inc.sensitivity_methods() == ["rattle", "rattle4", "rattle6"]
    plain = lf.integrate(rb, z0, 0.1, 10, method="rk4")
    assert plain.jacobian is None and plain.final_jacobian is None


def test_parameter_jacobians_of_the_tops_against_rebuilt_systems():
    """∂z/∂θ along `system.parameters` against central differences of systems built with the
    parameter moved (χ moved without its normalisation: mgl scaled by |χ + h e_j|)."""
    chi = np.array([0.2, -0.3, 1.0]) / np.linalg.norm([0.2, -0.3, 1.0])
    ht = lf.HeavyTop([1.0, 2.0, 3.0], 0.7, chi=chi)
    assert ht.parameters == ["I1", "I2", "I3", "mgl", "chi1", "chi2", "chi3"]
    assert lf.RigidBody([1.0, 2.0, 3.0]).parameters == ["I1", "I2", "I3"]
    assert body().parameters == ["lambda", "mu", "kappa", "gamma"]
    z0 = np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8])
    traj = lf.integrate(ht, z0, 0.05, 40, save_every=20, sensitivity=True)
    assert traj.parameter_jacobian.shape == (3, 6, 7)
    np.testing.assert_array_equal(traj.parameter_jacobian[0], 0.0)

    def build(theta):
        c = theta[4:]
        return lf.HeavyTop(theta[:3], theta[3] * np.linalg.norm(c), chi=c)

    theta = np.concatenate([[1.0, 2.0, 3.0, 0.7], chi])
    h = 1e-6
    for m in range(7):
        e = np.zeros(7)
        e[m] = h
        fd = (lf.integrate(build(theta + e), z0, 0.05, 40).final_state
              - lf.integrate(build(theta - e), z0, 0.05, 40).final_state) / (2 * h)
        np.testing.assert_allclose(traj.final_parameter_jacobian[:, m], fd, atol=1e-7,
                                   err_msg=ht.parameters[m])


def test_vjp_is_the_gradient_of_a_loss():
    """The gradient of L = Σ_k |z_k − target_k|² (every sample) and of a final-state loss, from
    traj.vjp, against differences of L in z0 and in the moments."""
    z0 = np.array([0.3, -0.8, 1.1])
    target = np.array([[0.3, -0.8, 1.1], [0.5, -0.6, 1.0], [0.7, -0.3, 0.9]])

    def run(z, inertia):
        return lf.integrate(lf.RigidBody(inertia), z, 0.05, 40, save_every=20,
                            sensitivity=True)

    def loss(traj):
        return np.sum((traj.states - target) ** 2)

    traj = run(z0, [1.0, 2.0, 3.0])
    gz, gp = traj.vjp(2 * (traj.states - target))
    h = 1e-6
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        fd = (loss(run(z0 + e, [1.0, 2.0, 3.0])) - loss(run(z0 - e, [1.0, 2.0, 3.0]))) / (2 * h)
        assert abs(gz[j] - fd) < 1e-7
        fd = (loss(run(z0, np.array([1.0, 2.0, 3.0]) + e))
              - loss(run(z0, np.array([1.0, 2.0, 3.0]) - e))) / (2 * h)
        assert abs(gp[j] - fd) < 1e-7
    gz, gp = traj.vjp(np.array([1.0, 0.0, 0.0]))
    np.testing.assert_allclose(gz, traj.final_jacobian[0])
    np.testing.assert_allclose(gp, traj.final_parameter_jacobian[0])
    with pytest.raises(lf.ShapeError):
        traj.vjp(np.ones(4))
    with pytest.raises(lf.InvalidArgumentError, match="sensitivity=True"):
        lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), z0, 0.05, 4).vjp(np.ones(3))
    # A batch: one gradient per member.
    batch = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), np.stack([z0, z0]), 0.05, 40,
                         save_every=20, sensitivity=True)
    gz2, gp2 = batch.vjp(np.ones((2, 3)))
    assert gz2.shape == (2, 3) and gp2.shape == (2, 3)


def test_with_an_attitude_the_directions_are_left_trivialised():
    """RigidBody with attitude, the default splitting: jacobian (k, 6, 6) over (M, xi) with
    dR = R hat(xi); against central differences (R0 moved as R0 exp(h e_j), the final R read as
    (R^T dR)^vee); the states and attitudes are the plain run's; the moments' column too."""
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    R0 = lf.lie.so3_exp([0.4, -0.7, 0.3])
    M0 = np.array([0.3, -0.8, 1.1])
    assert rb.sensitivity_methods(attitude=True) == rb.methods()
    traj = lf.integrate(rb, M0, 0.05, 40, attitude=R0, save_every=20, sensitivity=True)
    plain = lf.integrate(rb, M0, 0.05, 40, attitude=R0, save_every=20)
    np.testing.assert_array_equal(traj.attitude, plain.attitude)
    np.testing.assert_array_equal(traj.states, plain.states)
    assert traj.jacobian.shape == (3, 6, 6) and traj.parameter_jacobian.shape == (3, 6, 3)

    def end(M, R, inertia=(1.0, 2.0, 3.0)):
        t = lf.integrate(lf.RigidBody(list(inertia)), M, 0.05, 40, attitude=R)
        return t.final_state, t.final_attitude

    def column(plus, minus, h):
        (mp, rp), (mm, rm) = plus, minus
        a = 0.5 * (rp + rm)
        w = a.T @ (rp - rm) / (2 * h)
        return np.concatenate([(mp - mm) / (2 * h), [w[2, 1], w[0, 2], w[1, 0]]])

    h = 1e-6
    for j in range(6):
        e = np.zeros(3)
        if j < 3:
            e[j] = h
            fd = column(end(M0 + e, R0), end(M0 - e, R0), h)
        else:
            e[j - 3] = h
            fd = column(end(M0, R0 @ lf.lie.so3_exp(e)), end(M0, R0 @ lf.lie.so3_exp(-e)), h)
        np.testing.assert_allclose(traj.final_jacobian[:, j], fd, atol=1e-7)
    e = np.array([h, 0.0, 0.0])
    fd = column(end(M0, R0, np.array([1.0, 2.0, 3.0]) + e),
                end(M0, R0, np.array([1.0, 2.0, 3.0]) - e), h)
    np.testing.assert_allclose(traj.final_parameter_jacobian[:, 0], fd, atol=1e-7)


def test_rk4_with_an_attitude_reads_the_attitude_by_its_polar_factor():
    """RigidBody with attitude and rk4 (its own lift: directions ambient on R, which RK4 leaves
    SO(3)): jacobian (k, 6, 6) over (M, xi) against central differences, the final attitudes
    read by their polar factors U (xi = log(U0^T U) / h); the moments' columns too; the states
    and attitudes the plain run's, bit for bit."""
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    R0 = lf.lie.so3_exp([0.4, -0.7, 0.3])
    M0 = np.array([0.3, -0.8, 1.1])
    run = dict(method="rk4", attitude=R0)
    traj = lf.integrate(rb, M0, 0.2, 40, save_every=20, sensitivity=True, **run)
    plain = lf.integrate(rb, M0, 0.2, 40, save_every=20, **run)
    np.testing.assert_array_equal(traj.states, plain.states)
    np.testing.assert_array_equal(traj.attitude, plain.attitude)
    assert traj.jacobian.shape == (3, 6, 6) and traj.parameter_jacobian.shape == (3, 6, 3)
    R = plain.final_attitude
    assert np.linalg.norm(R.T @ R - np.eye(3)) > 1e-6     # off SO(3): the polar read matters

    def polar(R):
        u, _, vt = np.linalg.svd(R)
        return u @ vt

    U0 = polar(R)

    def end(M, R, inertia=(1.0, 2.0, 3.0)):
        t = lf.integrate(lf.RigidBody(list(inertia)), M, 0.2, 40, method="rk4", attitude=R)
        return t.final_state, lf.lie.so3_log(U0.T @ polar(t.final_attitude))

    def column(plus, minus, h):
        return np.concatenate([(plus[0] - minus[0]) / (2 * h), (plus[1] - minus[1]) / (2 * h)])

    h = 1e-6
    fd = np.empty((6, 6))
    for j in range(6):
        e = np.zeros(3)
        e[j % 3] = h
        if j < 3:
            fd[:, j] = column(end(M0 + e, R0), end(M0 - e, R0), h)
        else:
            fd[:, j] = column(end(M0, R0 @ lf.lie.so3_exp(e)),
                              end(M0, R0 @ lf.lie.so3_exp(-e)), h)
    np.testing.assert_allclose(traj.final_jacobian, fd, rtol=0, atol=1e-7)
    inertia = np.array([1.0, 2.0, 3.0])
    for m in range(3):
        e = np.eye(3)[m] * h
        fd = column(end(M0, R0, inertia + e), end(M0, R0, inertia - e), h)
        np.testing.assert_allclose(traj.final_parameter_jacobian[:, m], fd, rtol=0, atol=1e-7)


@pytest.mark.parametrize("method,x0,dt,steps", [("verlet4", X0, 0.05, 40),
                                                 ("reduced", X_APART, 0.02, 25)])
def test_parameter_jacobian_of_the_pseudo_rigid_body_along_its_potential_constants(
        method, x0, dt, steps):
    def build(t):
        return lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(t[0], t[1])
                                  + lf.potentials.Volumetric(t[2], t[3]))

    theta = np.array([1.0, 2.0, 0.5, 1.4])
    z0 = np.concatenate([x0.ravel(), P0.ravel()])
    traj = lf.integrate(build(theta), z0, dt, steps, method=method, sensitivity=True)
    assert traj.parameter_jacobian.shape == (steps + 1, 18, 4)
    h = 1e-6
    for m in range(4):
        e = np.zeros(4)
        e[m] = h
        fd = (lf.integrate(build(theta + e), z0, dt, steps, method=method).final_state
              - lf.integrate(build(theta - e), z0, dt, steps, method=method).final_state) / (2 * h)
        np.testing.assert_allclose(traj.final_parameter_jacobian[:, m], fd, atol=1e-7)


def _quartic(q):
    return 0.25 * float(np.sum(q**4)) + 0.5 * q[0] * q[1]


def _quartic_gradient(q):
    return q**3 + 0.5 * np.array([q[1], q[0]])


def _quartic_hessian(q, v):
    return 3 * q**2 * v + 0.5 * np.array([v[1], v[0]])


@pytest.mark.parametrize("method", ["verlet4", "gauss6", "midpoint", "rk4"])
def test_a_user_separable_system_with_its_hessian(method):
    """lf.Separable with gradient and hessian callables: every method's exact Jacobians (vs
    differences; the Verlet and Gauss methods symplectic, the implicit ones through the
    implicit-function theorem); without the hessian no lift."""
    sys = lf.Separable([1.0, 2.0], _quartic, gradient=_quartic_gradient, hessian=_quartic_hessian)
    assert sys.sensitivity_methods() == sys.methods()
    assert lf.Separable([1.0, 2.0], _quartic, gradient=_quartic_gradient).sensitivity_methods() == []
    z0 = np.array([0.7, -0.4, 0.3, 0.5])
    traj = lf.integrate(sys, z0, 0.05, 60, method=method, sensitivity=True)
    np.testing.assert_array_equal(traj.final_state, lf.integrate(sys, z0, 0.05, 60,
                                                                  method=method).final_state)
    fd = differences(sys, z0, method, 0.05, 60)
    np.testing.assert_allclose(traj.final_jacobian, fd, atol=1e-8 * np.abs(fd).max())
    J = traj.final_jacobian
    omega = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.eye(2), np.zeros((2, 2))]])
    defect = np.abs(J.T @ omega @ J - omega).max() / max(1.0, np.abs(J).max()) ** 2
    assert defect > 1e-9 if method == "rk4" else defect < 1e-12

    def failing(q, v):
        raise ZeroDivisionError("hessian fails")

    bad = lf.Separable([1.0, 2.0], _quartic, gradient=_quartic_gradient, hessian=failing)
    with pytest.raises(ZeroDivisionError, match="hessian fails"):
        lf.integrate(bad, z0, 0.05, 5, sensitivity=True)


def test_an_exception_mid_run_leaves_a_partial_in_the_systems_terms():
    """A callable raising at the 4th step: err.partial is the system's trajectory (its own
    states, attitudes none, Jacobians) up to the last good step, not the lift's layout; a
    string attitude is a TypeError."""
    calls = {"n": 0}

    def hessian(q, v):
        calls["n"] += 1
        if calls["n"] > 40:
            raise ZeroDivisionError("hessian fails late")
        return _quartic_hessian(q, v)

    sys = lf.Separable([1.0, 2.0], _quartic, gradient=_quartic_gradient, hessian=hessian)
    z0 = np.array([0.7, -0.4, 0.3, 0.5])
    with pytest.raises(ZeroDivisionError) as info:
        lf.integrate(sys, z0, 0.05, 50, sensitivity=True)
    p = info.value.partial
    assert p.states.shape[1] == 4 and p.jacobian.shape[1:] == (4, 4)
    np.testing.assert_array_equal(p.initial_state, z0)
    np.testing.assert_array_equal(p.jacobian[0], np.eye(4))
    with pytest.raises(TypeError, match="attitude"):
        lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), [0.3, -0.8, 1.1], 0.1, 10,
                     attitude="R", sensitivity=True)


def _hh_h(q, p):
    x, y = q
    return 0.5 * float(p @ p + x * x + y * y) + x * x * y - y**3 / 3


def _hh_gradient(q, p):
    x, y = q
    return [x + 2 * x * y, y + x * x - y * y], p


def _hh_hessian(q, p, dq, dp):
    x, y = q
    return [(1 + 2 * y) * dq[0] + 2 * x * dq[1], 2 * x * dq[0] + (1 - 2 * y) * dq[1]], dp


@pytest.mark.parametrize("method", ["gauss4", "gauss6", "midpoint", "rk4"])
def test_a_user_canonical_system_with_its_hessian(method):
    """lf.Canonical with gradient and hessian callables (Hénon–Heiles): every method's exact
    Jacobian (Gauss through the implicit-function theorem) against differences, symplectic for
    the Gauss methods; a failing hessian's exception raised; without it no lift."""
    sys = lf.Canonical(_hh_h, _hh_gradient, dof=2, hessian=_hh_hessian)
    assert sys.sensitivity_methods() == sys.methods()
    assert lf.Canonical(_hh_h, _hh_gradient, dof=2).sensitivity_methods() == []
    z0 = np.array([0.3, -0.2, 0.25, 0.31])
    traj = lf.integrate(sys, z0, 0.1, 50, method=method, sensitivity=True, save_every=25)
    assert traj.jacobian.shape == (3, 4, 4)
    fd = differences(sys, z0, method, 0.1, 50)
    np.testing.assert_allclose(traj.final_jacobian, fd, atol=1e-8 * np.abs(fd).max())
    J = traj.final_jacobian
    omega = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.eye(2), np.zeros((2, 2))]])
    defect = np.abs(J.T @ omega @ J - omega).max() / max(1.0, np.abs(J).max()) ** 2
    assert defect > 1e-9 if method == "rk4" else defect < 1e-12

    def failing(q, p, dq, dp):
        raise ZeroDivisionError("hessian fails")

    bad = lf.Canonical(_hh_h, _hh_gradient, dof=2, hessian=failing)
    with pytest.raises(ZeroDivisionError, match="hessian fails"):
        lf.integrate(bad, z0, 0.1, 5, method=method, sensitivity=True)
    nan = lf.Canonical(_hh_h, _hh_gradient, dof=2, hessian=lambda q, p, dq, dp: [[np.nan] * 2] * 2)
    with pytest.raises(lf.NonFiniteError, match="hessian"):
        lf.integrate(nan, z0, 0.1, 5, method=method, sensitivity=True)


def _on_manifold(system, z0, eps):
    """A curve through z0 on the system's constraint manifold, at parameter eps."""
    w = eps * np.array([0.3, -0.5, 0.4])
    if isinstance(system, (lf.SphericalPendulum, lf.SphereParticle)):
        R = lf.lie.so3_exp(w)
        return np.concatenate([R @ z0[:3], R @ z0[3:]])
    # The incompressible body: (X e^{εA}, P e^{εA}), tr A = 0, keeps det X and <cof X, P> = 0.
    A = eps * np.array([[0.2, 0.5, -0.1], [0.3, -0.4, 0.2], [0.1, -0.3, 0.2]])
    E = scipy.linalg.expm(A)
    return np.concatenate([(z0[:9].reshape(3, 3) @ E).ravel(), (z0[9:].reshape(3, 3) @ E).ravel()])


def _constrained_cases():
    pend = lf.SphericalPendulum(1.0, 1.2, 9.81)
    particle = lf.SphereParticle(2.0, 1.5, 9.81)
    inc = lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0), incompressible=True)
    X = np.array([[1.3, 0.1, -0.05], [0.02, 1.1, 0.08], [-0.03, 0.05, 0.9]])
    P = np.array([[0.1, -0.5, 0.2], [0.6, 0.05, -0.3], [-0.1, 0.4, 0.02]])
    C = np.linalg.det(X) * np.linalg.inv(X).T
    P = P - np.sum(C * P) / np.sum(C * C) * C
    return [(pend, np.asarray(pend.state_from_spherical(0.8, 0.1, 0.3, 1.2))),
            (particle, np.array([0.0, 0.9, 1.2, 0.4, 1.2, -0.9])),
            (inc, np.concatenate([X.ravel(), P.ravel()]))]


@pytest.mark.parametrize("case", range(3), ids=["SphericalPendulum", "SphereParticle",
                                                "PseudoRigidBody-incompressible"])
def test_jacobians_of_constrained_systems_along_their_manifold(case):
    """Systems whose states carry constraints (|q| = 1 and q.L = 0; |q| = l and q.p = 0;
    det X fixed and <cof X, P> = 0): J v for the velocity v of a curve on the manifold against
    central differences along the curve, for each lifted method (splittings and rk4; RATTLE)."""
    system, z0 = _constrained_cases()[case]
    methods = system.sensitivity_methods()
    assert methods == system.methods()
    h = 1e-5
    v = (_on_manifold(system, z0, h) - _on_manifold(system, z0, -h)) / (2 * h)
    for method in methods:
        traj = lf.integrate(system, z0, 0.02, 50, method=method, sensitivity=True, save_every=50)
        ends = [lf.integrate(system, _on_manifold(system, z0, s), 0.02, 50,
                             method=method).final_state for s in (h, -h)]
        fd = (ends[0] - ends[1]) / (2 * h)
        np.testing.assert_allclose(traj.final_jacobian @ v, fd, atol=1e-8 * np.abs(fd).max(),
                                   err_msg=method)


def test_a_hessian_that_runs_another_lifted_integration():
    """A callable that itself integrates with sensitivities (on the same thread, inside the
    outer run's field): each run keeps its own work space, and the outer Jacobian is the one
    without the nested run."""
    inner = lf.Separable([1.0, 2.0], _quartic, gradient=_quartic_gradient,
                         hessian=_quartic_hessian)
    z0 = np.array([0.7, -0.4, 0.3, 0.5])

    def hessian(q, v):
        lf.integrate(inner, z0, 0.05, 3, method="gauss4", sensitivity=True)
        return _quartic_hessian(q, v)

    outer = lf.Separable([1.0, 2.0], _quartic, gradient=_quartic_gradient, hessian=hessian)
    for method in ("gauss4", "verlet"):
        got = lf.integrate(outer, z0, 0.05, 20, method=method, sensitivity=True)
        want = lf.integrate(inner, z0, 0.05, 20, method=method, sensitivity=True)
        np.testing.assert_array_equal(got.final_jacobian, want.final_jacobian)


def _sweep_cases():
    disk = lf.RollingDisk(1.0, 0.5, 0.125, 0.0625, spring=0.4, tilt=0.3)
    particle = lf.SphereParticle(2.0, 1.5, 9.81)
    pend = lf.Pendulum(1.0, 1.0, 9.81)
    return {"gauss6": (pend, [2.5, 0.0]), "midpoint": (pend, [2.5, 0.0]),
            "nonholonomic": (disk, disk.state([0.1, -0.2, 0.3, 0.7], 2.0, 0.5)),
            "rattle": (particle, [0.0, 0.9, 1.2, 0.4, 1.2, -0.9])}


@pytest.mark.parametrize("method", ["gauss6", "midpoint", "rattle", "nonholonomic"])
def test_implicit_methods_with_sensitivities_fail_only_where_the_plain_run_does(method):
    """A dt sweep up to steps where the plain iteration stops converging: the lifted run fails
    exactly where the plain one does (no false failures from the directions: each block of the
    lifted solve is measured against its own scale, the state stops where the plain iteration
    does and the directions then converge at it)."""
    system, z0 = _sweep_cases()[method]
    for dt in (0.01, 0.1, 0.3, 0.6, 1.0, 1.5, 2.0, 2.5):
        outcomes = []
        for sensitivity in (False, True):
            try:
                lf.integrate(system, z0, dt, 50, method=method, sensitivity=sensitivity)
                outcomes.append("ok")
            except lf.ConvergenceError:
                outcomes.append("not converged")
        assert outcomes[0] == outcomes[1], (method, dt, outcomes)


def test_a_user_lie_poisson_system_with_its_hessian_is_the_built_in_body():
    """lf.LiePoisson given hessian= (the free body written as a user system, H quartic-free):
    its Jacobian under rkmk4 and the Lie midpoint equals the built-in RigidBody's (rkmk4) and
    central differences of its own runs (midpoint); without hessian it has no tangent maps."""
    I = np.array([1.0, 2.0, 3.0])
    user = lf.LiePoisson("so3", lambda mu: 0.5 * float(mu @ (mu / I)),
                         gradient=lambda mu: mu / I, hessian=lambda mu, dmu: dmu / I)
    z0 = np.array([0.3, -0.8, 1.1])
    mine = lf.integrate(user, z0, 0.05, 40, method="rkmk4", sensitivity=True)
    ref = lf.integrate(lf.RigidBody(I), z0, 0.05, 40, method="rkmk4", sensitivity=True)
    np.testing.assert_allclose(mine.final_jacobian, ref.final_jacobian, rtol=0, atol=1e-13)
    traj = lf.integrate(user, z0, 0.05, 40, method="midpoint", sensitivity=True)
    h = 1e-6
    for j in range(3):
        e = np.eye(3)[j] * h
        end = [lf.integrate(user, z0 + s * e, 0.05, 40, method="midpoint").final_state
               for s in (1, -1)]
        np.testing.assert_allclose(traj.final_jacobian[:, j], (end[0] - end[1]) / (2 * h),
                                   rtol=0, atol=1e-8)
    bare = lf.LiePoisson("so3", lambda mu: 0.5 * float(mu @ (mu / I)), gradient=lambda mu: mu / I)
    assert bare.sensitivity_methods() == []
    with pytest.raises(lf.InvalidArgumentError, match="hessian"):
        lf.LiePoisson("so3", np.diag(1 / I), hessian=lambda mu, dmu: dmu)


@pytest.mark.parametrize("system, z0, method", [
    (lf.RigidBody([1.0, 2.0, 3.0]), [0.3, -0.8, 1.1], "dmv4"),
    (lf.HeavyTop([1.0, 2.0, 3.0], 0.7, chi=[0.2, -0.3, 1.0]), [1.0, 0.5, -0.3, 0.0, 0.6, 0.8],
     "exact_splitting4"),
])
def test_jacobians_with_the_attitude_round_trip_through_a_file(tmp_path, system, z0, method):
    """A run with the attitude and its Jacobians saved and loaded: the directions (e = d + 3)
    checked against the system's own lift on load."""
    R0 = lf.lie.so3_exp([0.4, -0.7, 0.3])
    z0 = np.array(z0)
    if len(z0) == 6:
        z0[3:] = R0.T @ [0.0, 0.0, 1.0]
    traj = lf.integrate(system, z0, 0.05, 20, method=method, attitude=R0, sensitivity=True,
                        save_every=5)
    path = tmp_path / "run.nc"
    traj.save(path)
    back = lf.load(path)
    np.testing.assert_array_equal(back.jacobian, traj.jacobian)
    np.testing.assert_array_equal(back.parameter_jacobian, traj.parameter_jacobian)


def test_a_user_hessian_that_raises_or_lies_ends_the_run_with_its_error():
    """lf.LiePoisson(hessian=): a callback raising once ends the run with that exception and a
    consistent partial (states and Jacobians of the same samples); a wrong shape or a NaN is a
    typed error naming the callable."""
    I = np.array([1.0, 2.0, 3.0])
    h = lambda mu: 0.5 * float(mu @ (mu / I))
    g = lambda mu: mu / I
    calls = [0]

    def hess(mu, dmu):
        calls[0] += 1
        if calls[0] == 50:
            raise KeyError("boom")
        return dmu / I
    with pytest.raises(KeyError, match="boom") as info:
        lf.integrate(lf.LiePoisson("so3", h, gradient=g, hessian=hess), [0.3, -0.8, 1.1], 0.05,
                     40, method="midpoint", sensitivity=True)
    partial = info.value.partial
    assert partial.jacobian.shape == partial.states.shape + (3,)
    np.testing.assert_array_equal(partial.jacobian[0], np.eye(3))
    with pytest.raises(lf.ShapeError, match="hessian"):
        lf.integrate(lf.LiePoisson("so3", h, gradient=g, hessian=lambda mu, d: np.zeros(2)),
                     [0.3, -0.8, 1.1], 0.05, 4, sensitivity=True)
    with pytest.raises(lf.NonFiniteError, match="hessian"):
        lf.integrate(lf.LiePoisson("so3", h, gradient=g, hessian=lambda mu, d: d * np.nan),
                     [0.3, -0.8, 1.1], 0.05, 4, sensitivity=True)
