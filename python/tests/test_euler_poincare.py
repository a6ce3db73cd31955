"""lf.EulerPoincare (issue 24, 000 §4): the built-in bodies from their Lagrangians (the free rigid
body and the generalized rigid body from their inertia, the heavy top from l(Omega, Gamma) with
the vector action), a quartic Lagrangian against scipy's DOP853 on its Euler–Poincaré equation,
the Legendre transform inverted to round-off, the right system as the mirror of the left, a
callable action against the built-in one, the diamond against its definition, and the errors."""

import pickle

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lieflow as lf

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
MGL, CHI = 0.7, np.array([0.0, 0.6, 0.8])
C = 0.4
K = np.array([0.3, -0.2, 0.5])


# --- module-level callables (they pickle by reference) ---

def top_l(w, g):
    return 0.5 * float(w @ (I * w)) - MGL * float(g @ CHI)


def top_dl(w, g):
    return I * w, -MGL * CHI


def quartic(w, odd=0.0):
    n2 = float(w @ w)
    return 0.5 * float(w @ (I * w)) + 0.25 * C * n2 * n2 + odd * n2 * float(K @ w) / 3


def quartic_grad(w, odd=0.0):
    n2 = float(w @ w)
    return I * w + C * n2 * w + odd * (2 * w * float(K @ w) + n2 * K) / 3


def quartic_hess(w):
    return np.diag(I) + C * (float(w @ w) * np.eye(3) + 2 * np.outer(w, w))


def odd_l(w):
    return quartic(w, 0.5)


def odd_grad(w):
    return quartic_grad(w, 0.5)


def odd_l_mirror(w):
    return quartic(w, -0.5)


def odd_grad_mirror(w):
    return quartic_grad(w, -0.5)


def cross_action(xi, a):
    return np.cross(xi, a)


def test_the_free_rigid_body_comes_out_of_its_inertia():
    ep = lf.EulerPoincare("so3", inertia=np.diag(I))
    assert (ep.dim, ep.parameter_dim, ep.side) == (3, 0, "left")
    assert ep.is_quadratic
    exact = lf.integrate(lf.RigidBody(I), M0, dt=0.01, steps=1000, method="exact").states
    run = lf.integrate(ep, M0, dt=0.01, steps=1000, method="rkmk4").states
    np.testing.assert_allclose(run, exact, atol=1e-8)
    # The default, the discrete Euler–Poincaré method (order 2), and its order-6 composition.
    assert ep.methods()[0] == "variational"
    run = lf.integrate(ep, M0, dt=0.01, steps=1000).states
    np.testing.assert_allclose(run, exact, atol=1e-4)
    run = lf.integrate(ep, M0, dt=0.01, steps=1000, method="variational6").states
    np.testing.assert_allclose(run, exact, atol=1e-11)
    # Legendre both ways: mu = I xi.
    np.testing.assert_array_equal(ep.state(M0 / I), M0)
    np.testing.assert_allclose(ep.velocity(M0), M0 / I, rtol=1e-15)
    assert ep.energy(M0) == pytest.approx(0.5 * M0 @ (M0 / I), rel=1e-15)


def test_the_generalized_rigid_body_comes_out_of_its_mass_matrix():
    # l = <Omega, J Omega + Omega J>/2 with the pairing tr(A^T B)/2 of so(n): in the e_ij
    # coordinates the inertia is diagonal with entries J_i + J_j (i < j).
    j = np.array([1.0, 1.5, 2.5, 4.0])
    n = len(j)
    inertia = np.diag([j[a] + j[b] for a in range(n) for b in range(a + 1, n)])
    ep = lf.EulerPoincare(("so", n), inertia=inertia)
    body = lf.GeneralizedRigidBody(j)
    m0 = np.array([0.3, -0.2, 0.5, 0.1, 0.4, -0.6])
    a = lf.integrate(ep, m0, dt=0.01, steps=1000, method="rk4").states
    b = lf.integrate(body, m0, dt=0.01, steps=1000, method="rk4").states
    np.testing.assert_allclose(a, b, atol=1e-12)


def test_the_heavy_top_comes_out_of_its_lagrangian():
    top = lf.EulerPoincare("so3", top_l, gradient=top_dl, action="vector")
    assert (top.dim, top.parameter_dim) == (3, 3)
    g0 = np.array([0.3, -0.2, np.sqrt(0.87)])
    z0 = top.state(M0 / I, g0)
    np.testing.assert_allclose(z0, np.concatenate([M0, g0]), rtol=1e-15)
    ht = lf.HeavyTop(I, MGL, chi=CHI)
    a = lf.integrate(top, z0, dt=0.01, steps=1000, method="rk4").states
    b = lf.integrate(ht, z0, dt=0.01, steps=1000, method="rk4").states
    np.testing.assert_allclose(a, b, atol=1e-11)
    assert top.energy(z0) == pytest.approx(ht.energy(z0), abs=1e-14)
    # The diamond of dl/dGamma = -mgl chi with Gamma is the gravity torque mgl Gamma x chi,
    # and <b <> a, eta> = -<b, eta.a> with eta.a = eta x a.
    np.testing.assert_allclose(top.diamond(-MGL * CHI, g0), MGL * np.cross(g0, CHI), atol=1e-15)
    rng = np.random.default_rng(3)
    for _ in range(5):
        b, a, eta = rng.normal(size=(3, 3))
        assert top.diamond(b, a) @ eta == pytest.approx(-b @ np.cross(eta, a), abs=1e-14)
    # The Casimirs |Gamma|^2 and M.Gamma kept to round-off by the coadjoint methods.
    tr = lf.integrate(top, z0, dt=0.01, steps=2000)
    assert np.abs(tr.invariants() - tr.invariants()[0]).max() < 1e-13


def test_a_callable_action_is_the_built_in_one():
    builtin = lf.EulerPoincare("so3", top_l, gradient=top_dl, action="vector")
    given = lf.EulerPoincare("so3", top_l, gradient=top_dl, action=cross_action, parameter_dim=3)
    z0 = builtin.state(M0 / I, [0.3, -0.2, np.sqrt(0.87)])
    a = lf.integrate(builtin, z0, dt=0.01, steps=300, method="rk4").states
    b = lf.integrate(given, z0, dt=0.01, steps=300, method="rk4").states
    np.testing.assert_allclose(a, b, atol=1e-13)


def test_a_quartic_lagrangian_against_dop853():
    ep = lf.EulerPoincare("so3", quartic, gradient=quartic_grad, hessian=quartic_hess)
    w0 = np.array([0.8, -0.4, 0.3])
    mu0 = ep.state(w0)
    np.testing.assert_allclose(mu0, quartic_grad(w0), rtol=1e-15)
    np.testing.assert_allclose(ep.velocity(mu0), w0, atol=4 * np.finfo(float).eps)

    def rhs(_, w):
        # (I + C(|w|^2 1 + 2 w w^T)) dw/dt = mu x w, mu = dl/dw: the EP equation in w.
        return np.linalg.solve(quartic_hess(w), np.cross(quartic_grad(w), w))

    ref = solve_ivp(rhs, (0, 10), w0, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
    for method in ("variational6", "rkmk4"):
        end = lf.integrate(ep, mu0, dt=5e-3, steps=2000, save_every=2000,
                           method=method).states[-1]
        np.testing.assert_allclose(end, quartic_grad(ref), atol=1e-9, err_msg=method)
    # Without the Hessian (central differences of the gradient) and without the gradient
    # (central differences of l): the same run to the differences' accuracy.
    exact = lf.integrate(ep, mu0, dt=0.01, steps=50).states
    for fd in (lf.EulerPoincare("so3", quartic, gradient=quartic_grad),
               lf.EulerPoincare("so3", quartic)):
        np.testing.assert_allclose(ep.velocity(mu0), fd.velocity(mu0), atol=1e-9)
        np.testing.assert_allclose(lf.integrate(fd, mu0, dt=0.01, steps=50).states, exact,
                                   atol=1e-9)


@pytest.mark.parametrize("method", ["variational", "rkmk4", "midpoint", "rk4"])
def test_a_right_invariant_lagrangian_is_the_left_one_of_the_inverse_motion(method):
    right = lf.EulerPoincare("so3", odd_l, gradient=odd_grad, side="right")
    mirror = lf.EulerPoincare("so3", odd_l_mirror, gradient=odd_grad_mirror)
    left = lf.EulerPoincare("so3", odd_l, gradient=odd_grad)
    r = lf.integrate(right, M0, dt=0.01, steps=60, method=method).states
    m = lf.integrate(mirror, -M0, dt=0.01, steps=60, method=method).states
    np.testing.assert_allclose(r, -m, atol=1e-14)
    assert np.abs(r[-1] - lf.integrate(left, M0, dt=0.01, steps=60, method=method)
                  .states[-1]).max() > 1e-3
    assert right.side == "right"


def test_the_noether_momentum_is_conserved_along_the_motion():
    # 000 Theorems 4.2-4.4: R M is constant along the free body's motion (left); the right
    # Lagrangian's motion of the same body is (-M, R^T), with Ad*_{R^T}(-M) = -R M; the heavy
    # top keeps only the vertical component (Theorem 4.11).
    r0 = lf.lie.so3_exp([0.2, -0.35, 0.56])
    tr = lf.integrate(lf.RigidBody(I), M0, dt=0.01, steps=2000, save_every=100, attitude=r0)
    left = lf.EulerPoincare("so3", inertia=np.diag(I))
    p = left.noether(tr.states, tr.attitude)
    assert p.shape == (21, 3)
    np.testing.assert_allclose(p, np.broadcast_to(r0 @ M0, p.shape), atol=1e-13)
    right = lf.EulerPoincare("so3", inertia=np.diag(I), side="right")
    q = right.noether(-tr.states, np.swapaxes(tr.attitude, -1, -2))
    np.testing.assert_allclose(q, -p, atol=1e-15)
    top = lf.EulerPoincare("so3", top_l, gradient=top_dl, action="vector")
    z0 = np.concatenate([M0, r0[2]])          # Gamma = R^T e3
    ht = lf.integrate(lf.HeavyTop(I, MGL, chi=CHI), z0, dt=0.01, steps=2000, save_every=100,
                      attitude=r0)
    p = top.noether(ht.states, ht.attitude)
    np.testing.assert_allclose(p[:, 2], p[0, 2], atol=1e-13)
    assert np.abs(p[:, 0] - p[0, 0]).max() > 1e-2
    with pytest.raises(lf.NotInGroupError):
        left.noether(M0, 2 * np.eye(3))
    with pytest.raises(lf.ShapeError):
        left.noether(M0, np.eye(4))
    constants = lf.LiePoisson("so3", np.eye(3)).structure_constants()
    with pytest.raises(lf.InvalidArgumentError, match="no matrix group"):
        lf.EulerPoincare(constants, inertia=np.eye(3)).noether(M0, np.eye(3))


def test_pickling_and_storing():
    for ep, z0 in [(lf.EulerPoincare("so3", inertia=np.diag(I), side="right"), M0),
                   (lf.EulerPoincare("so3", top_l, gradient=top_dl, action="vector"),
                    np.concatenate([M0, [0.0, 0.0, 1.0]]))]:
        copy = pickle.loads(pickle.dumps(ep))
        assert repr(copy) == repr(ep)
        np.testing.assert_array_equal(lf.integrate(copy, z0, dt=0.01, steps=20).states,
                                      lf.integrate(ep, z0, dt=0.01, steps=20).states)


def test_errors():
    with pytest.raises(lf.ArgumentTypeError, match="needs the Lagrangian"):
        lf.EulerPoincare("so3")
    with pytest.raises(lf.InvalidArgumentError, match="not both"):
        lf.EulerPoincare("so3", quartic, inertia=np.eye(3))
    with pytest.raises(lf.InvalidArgumentError, match="positive definite"):
        lf.EulerPoincare("so3", inertia=np.diag([1.0, -1.0, 1.0]))
    with pytest.raises(lf.InvalidArgumentError, match="symmetric"):
        lf.EulerPoincare("so3", inertia=[[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(lf.InvalidArgumentError, match="own derivatives"):
        lf.EulerPoincare("so3", inertia=np.eye(3), gradient=quartic_grad)
    with pytest.raises(lf.InvalidArgumentError, match="unknown action"):
        lf.EulerPoincare("so3", top_l, action="matrix")
    with pytest.raises(lf.InvalidArgumentError, match="parameter_dim"):
        lf.EulerPoincare("so3", top_l, action=cross_action)
    with pytest.raises(lf.InvalidArgumentError, match="vector"):
        lf.EulerPoincare(lf.LiePoisson("so3", np.eye(3)).structure_constants(), top_l,
                         action="vector")
    with pytest.raises(lf.InvalidArgumentError, match="m >= 1"):
        lf.EulerPoincare("so3", top_l, action=cross_action, parameter_dim=0)
    with pytest.raises(lf.InvalidArgumentError, match="not a representation"):
        lf.EulerPoincare("so3", top_l, action=lambda xi, a: a, parameter_dim=2)
    with pytest.raises(lf.NonFiniteError):
        lf.EulerPoincare("so3", inertia=np.diag(I)).velocity([1.0, np.nan, 0.0])
    with pytest.raises(lf.InvalidArgumentError, match="left"):
        lf.EulerPoincare("so3", inertia=np.eye(3), side="up")
    ep = lf.EulerPoincare("so3", inertia=np.diag(I))
    with pytest.raises(lf.InvalidArgumentError, match="no parameter"):
        ep.state(M0, [1.0, 0.0, 0.0])
    with pytest.raises(lf.InvalidArgumentError, match="no parameter"):
        ep.diamond([1.0, 0, 0], [0, 1.0, 0])
    with pytest.raises(lf.ShapeError):
        ep.velocity([1.0, 2.0])
    top = lf.EulerPoincare("so3", top_l, gradient=top_dl, action="vector")
    with pytest.raises(lf.InvalidArgumentError, match="has a parameter"):
        top.state(M0)
    # A Legendre map singular where Newton starts (l = |xi|^4/4 at xi = 0): typed, named.
    flat = lf.EulerPoincare("so3", lambda w: 0.25 * float(w @ w) ** 2)
    with pytest.raises(lf.InvalidArgumentError, match=r"singular at xi = \[0, 0, 0\]"):
        flat.velocity(M0)
    # A gradient returning the wrong thing for a system with a parameter.
    bad = lf.EulerPoincare("so3", top_l, gradient=lambda w, g: I * w, action="vector")
    with pytest.raises(lf.ShapeError, match="pair"):
        lf.integrate(bad, np.concatenate([M0, [0, 0, 1.0]]), dt=0.01, steps=2)


def _se3_element(r, t):
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = r, t
    return g


@pytest.mark.parametrize("algebra, inertia, g0", [
    ("so3", np.diag(I), lf.lie.so3_exp([0.2, -0.35, 0.56])),
    (("so", 4), np.diag([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
     np.linalg.qr(np.arange(16.0).reshape(4, 4) ** 0.5 + np.eye(4))[0]),
    ("se3", np.diag([2.0, 3.0, 4.0, 1.0, 1.5, 2.5]),
     _se3_element(lf.lie.so3_exp([0.2, -0.35, 0.56]), [0.4, -1.2, 0.9])),
])
def test_the_configuration_is_carried_and_keeps_the_noether_momentum(algebra, inertia, g0):
    # With attitude=g0 the configuration g (3, 3), (4, 4) in SO(4) or (4, 4) homogeneous in
    # SE(3) is integrated along; the variational method keeps the Noether momentum
    # (`Trajectory.noether` passes the attitude) and the Casimirs to round-off, and g in its
    # group.
    if np.linalg.det(g0) < 0:
        g0 = g0 @ np.diag([-1.0, 1.0, 1.0, 1.0])
    ep = lf.EulerPoincare(algebra, inertia=inertia)
    mu0 = np.linspace(0.3, -0.6, ep.dim)
    tr = lf.integrate(ep, mu0, dt=0.01, steps=10_000, save_every=1000, attitude=g0)
    n = g0.shape[0]
    assert tr.attitude.shape == (11, n, n)
    p = tr.noether()
    scale = max(1.0, np.abs(tr.attitude).max())
    assert np.abs(p - ep.noether(mu0, g0)).max() < 2e-14 * scale
    assert np.abs(tr.invariants() - tr.invariants()[0]).max() < 1e-13    # the Casimirs
    rot = tr.attitude[..., :3, :3] if n == 4 and algebra == "se3" else tr.attitude
    k = rot.shape[-1]
    assert np.abs(np.swapaxes(rot, -1, -2) @ rot - np.eye(k)).max() < 1e-13
    assert np.abs(tr.attitude[-1] - g0).max() > 0.1         # g moved
    # A wrong size or an element off the group is refused.
    with pytest.raises(lf.ShapeError):
        lf.integrate(ep, mu0, dt=0.01, steps=1, attitude=np.eye(n + 1))
    bad = g0.copy()
    bad[0, 0] += 0.1
    with pytest.raises(lf.NotInGroupError):
        lf.integrate(ep, mu0, dt=0.01, steps=1, attitude=bad)


def test_the_heavy_top_from_its_lagrangian_with_its_attitude():
    # The variational method with the vector action: the heavy top with attitude against the
    # built-in one (a fine splitting8 run), Theorem 4.11's vertical component e3.(R M) kept.
    top = lf.EulerPoincare("so3", top_l, gradient=top_dl, action="vector")
    ht = lf.HeavyTop(I, MGL, chi=CHI)
    r0 = lf.lie.so3_exp([0.2, -0.35, 0.56])
    z0 = top.state(M0 / I, r0[2])              # Gamma = R^T e3, the body's vertical
    ref = lf.integrate(ht, z0, dt=1e-3, steps=5000, save_every=5000, attitude=r0,
                       method="splitting8")
    run = lf.integrate(top, z0, dt=0.02, steps=250, save_every=250, attitude=r0,
                       method="variational6")
    np.testing.assert_allclose(run.states[-1], ref.states[-1], atol=1e-8)
    np.testing.assert_allclose(run.attitude[-1], ref.attitude[-1], atol=1e-8)
    long = lf.integrate(top, z0, dt=0.01, steps=5000, save_every=500, attitude=r0)
    vertical = long.noether()[:, 2]
    assert np.abs(vertical - vertical[0]).max() < 1e-13
    assert np.abs(long.invariants() - long.invariants()[0]).max() < 1e-13


def test_a_trajectory_with_an_se3_configuration_saves_and_loads(tmp_path):
    pytest.importorskip("xarray")
    pytest.importorskip("netCDF4")
    ep = lf.EulerPoincare("se3", inertia=np.diag([2.0, 3.0, 4.0, 1.0, 1.5, 2.5]))
    g0 = _se3_element(np.eye(3), [1.0, 2.0, 3.0])
    tr = lf.integrate(ep, np.linspace(0.3, -0.6, 6), dt=0.01, steps=100, save_every=10,
                      attitude=g0)
    path = tmp_path / "se3.nc"
    tr.save(path)
    back = lf.load(path)
    np.testing.assert_array_equal(back.attitude, tr.attitude)
    assert back.attitude.shape == (11, 4, 4)
    np.testing.assert_array_equal(back.noether(), tr.noether())


def test_inertia_from_a_body():
    # 000 §3.1: 1/2 sum m |w x x|^2 = <w, I w>/2 for point masses; J = sum m x x^T with
    # I = tr(J) 1 - J; the solids' closed forms; (4.1) J_s = R I R^T with R I W = J_s (R W).
    rng = np.random.default_rng(5)
    m, x = rng.uniform(0.2, 2.0, 6), rng.normal(size=(6, 3))
    inertia = lf.inertia_tensor(m, x)
    for w in rng.normal(size=(4, 3)):
        energy = 0.5 * np.sum(m * np.sum(np.cross(w, x) ** 2, axis=1))
        assert energy == pytest.approx(0.5 * w @ inertia @ w, rel=1e-14)
    j = lf.mass_matrix(m, x)
    np.testing.assert_allclose(inertia, np.trace(j) * np.eye(3) - j, atol=1e-14)
    a = np.array([1.0, 0.7, 0.4])
    np.testing.assert_allclose(lf.inertia_tensor(shape="ellipsoid", mass=5.0, semi_axes=a),
                               np.diag([a[1] ** 2 + a[2] ** 2, a[0] ** 2 + a[2] ** 2,
                                        a[0] ** 2 + a[1] ** 2]), rtol=1e-15)
    np.testing.assert_allclose(lf.mass_matrix(shape="box", mass=3.0, semi_axes=[1, 2, 1, 1]),
                               np.diag([1.0, 4.0, 1.0, 1.0]), rtol=1e-15)
    # The 4-ball's second moment m/(n + 2): J of the ellipsoid in R^4.
    np.testing.assert_allclose(lf.mass_matrix(shape="ellipsoid", mass=6.0, semi_axes=np.ones(4)),
                               np.eye(4), rtol=1e-15)
    r = lf.lie.so3_exp(rng.normal(size=(5, 3)))
    js = lf.spatial_inertia(r, inertia)
    assert js.shape == (5, 3, 3)
    w = np.array([0.3, -0.7, 0.2])
    np.testing.assert_allclose(js @ (r @ w)[..., None], (r @ (inertia @ w))[..., None],
                               atol=1e-14)
    np.testing.assert_allclose(lf.spatial_inertia(np.eye(3), [1.0, 2.0, 3.0]), np.diag([1, 2, 3.0]))
    # A body built from its inertia: the same motion as RigidBody with that matrix.
    ep = lf.EulerPoincare("so3", inertia=inertia)
    a1 = lf.integrate(ep, M0, dt=0.01, steps=100, method="rkmk4").states
    a2 = lf.integrate(lf.RigidBody(inertia), M0, dt=0.01, steps=100, method="rkmk4").states
    np.testing.assert_allclose(a1, a2, atol=1e-12)
    with pytest.raises(lf.InvalidArgumentError, match="masses and positions"):
        lf.inertia_tensor()
    with pytest.raises(lf.InvalidArgumentError, match="non-negative"):
        lf.inertia_tensor([1.0, -1.0], np.ones((2, 3)))
    with pytest.raises(lf.ShapeError):
        lf.inertia_tensor([1.0, 1.0], np.ones((2, 2)))
    with pytest.raises(lf.InvalidArgumentError, match="ellipsoid"):
        lf.inertia_tensor(shape="cone", mass=1.0, semi_axes=a)
    with pytest.raises(lf.InvalidArgumentError):
        lf.inertia_tensor(shape="box", mass=-1.0, semi_axes=a)
    with pytest.raises(lf.NotInGroupError):
        lf.spatial_inertia(2 * np.eye(3), inertia)


@pytest.mark.parametrize("method", ["variational", "variational4", "midpoint"])
def test_an_exception_in_the_lagrangian_ends_the_run_at_its_step(method):
    # A gradient that raises once, at its 400th call: the run stops at that step with the
    # exception itself (a note naming the step), the calls of the failing run are those of a
    # clean run up to that step (nothing called twice), and the partial restarts the motion.
    log = []

    def grad(w):
        log.append(float(w[0]))
        if len(log) == 400:
            raise KeyError("once")
        return quartic_grad(w)

    ep = lf.EulerPoincare("so3", quartic, gradient=grad, hessian=quartic_hess)
    with pytest.raises(KeyError, match="once") as info:
        lf.integrate(ep, M0, dt=0.01, steps=2000, save_every=5, method=method)
    notes = " ".join(info.value.__notes__)
    assert f"of {method}" in notes, notes
    part, failed = info.value.partial, list(log)
    assert part.status == -1 and 0 < part.t_final < 20
    steps = round(part.t_final / 0.01)
    log.clear()
    clean = lf.integrate(ep, M0, dt=0.01, steps=steps, save_every=5, method=method)
    assert failed[:len(log)] == log
    np.testing.assert_array_equal(part.final_state, clean.final_state)
    np.testing.assert_array_equal(part.states, clean.states)


def atan_l(w):
    return float(np.sum(w * np.arctan(w) - 0.5 * np.log1p(w * w)))


def atan_grad(w):
    return np.arctan(w)


def test_a_momentum_with_no_velocity_is_a_typed_error():
    # dl/dxi = arctan(xi) is onto (-pi/2, pi/2) only: mu = 1.6 has no velocity; Newton's
    # iterates run off (xi ~ 1e3 after a few steps) and the inversion stops with an error naming
    # the momentum, never a NaN or an endless loop. Inside the range it converges (xi = tan mu).
    ep = lf.EulerPoincare("so3", atan_l, gradient=atan_grad)
    np.testing.assert_allclose(ep.velocity([1.5, 0.2, -0.1]), np.tan([1.5, 0.2, -0.1]),
                               rtol=1e-13)
    with pytest.raises((lf.ConvergenceError, lf.InvalidArgumentError), match="mu") as info:
        ep.velocity([1.6, 0.0, 0.0])
    assert "nan" not in str(info.value).lower()


def test_events_and_ensembles_carry_an_se3_configuration():
    # The attitude's size follows the group everywhere: events (n_i, 4, 4), the Dask ensemble's
    # lazy arrays (b, k, 4, 4) (the review of issue 24: both assumed 3 x 3).
    pytest.importorskip("dask")
    ep = lf.EulerPoincare("se3", inertia=np.diag([2.0, 3.0, 4.0, 1.0, 1.5, 2.5]))
    g0 = _se3_element(np.eye(3), [1.0, 2.0, 3.0])
    mu0 = np.linspace(0.3, -0.6, 6)
    tr = lf.integrate(ep, mu0, dt=0.01, steps=500, attitude=g0,
                      events=[lambda t, z: z[0] - 0.25])
    assert len(tr.t_events[0]) >= 1 and tr.attitude_events[0].shape == (len(tr.t_events[0]), 4, 4)
    ds = lf.ensemble.integrate(ep, np.tile(mu0, (4, 1)), dt=0.01, steps=50, attitude=g0)
    assert ds["attitude"].shape == (4, 51, 4, 4) and ds["final_attitude"].shape == (4, 4, 4)
    direct = lf.integrate(ep, mu0, dt=0.01, steps=50, attitude=g0)
    np.testing.assert_array_equal(ds["attitude"][2].values, direct.attitude)


def test_attitude_refusals_and_a_step_too_large_are_typed_errors():
    # Structure constants have no matrix group: no attitude. A step so large that u leaves the
    # domain of dexp^-1 ends the run with a LeftDomainError naming the step, never NaN.
    c = lf.LiePoisson("so3", np.eye(3)).structure_constants()
    for system in (lf.LiePoisson(c, np.eye(3)), lf.EulerPoincare(c, inertia=np.diag(I))):
        with pytest.raises(lf.InvalidArgumentError, match="no attitude"):
            lf.integrate(system, M0, dt=0.01, steps=1, attitude=np.eye(3))
    ep = lf.EulerPoincare("so3", inertia=np.diag(I))
    with pytest.raises(lf.LeftDomainError, match="step 1"):
        lf.integrate(ep, 100 * M0, dt=1.0, steps=5)
