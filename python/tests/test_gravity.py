"""lf.potentials.SelfGravity and lf.pseudo_rigid.index_symbols: the self-gravity of a homogeneous
ellipsoid (Chandrasekhar, EFE ch. 3) against scipy (Carlson's R_F, R_D, quadrature) and finite
differences; pickling; typed errors."""

import pickle

import numpy as np
import pytest
from scipy import integrate, special

import lieflow as lf

pot = lf.potentials
index_symbols = lf.pseudo_rigid.index_symbols

SHAPES = [
    (1.3, 1.0, 0.7),
    (0.7, 1.3, 1.0),
    (3.0, 2.0, 1.0),
    (1.0, 1.0, 0.6),
    (2.0, 1.0, 1.0),
    (1.0, 0.1, 0.05),
    (1.0, 1.0 + 1e-9, 0.5),
    (0.8, 0.8, 0.8),
]


def ref_a(a):
    a = np.asarray(a, float)
    a2 = a**2
    return np.array([2 / 3 * a.prod() * special.elliprd(a2[(i + 1) % 3], a2[(i + 2) % 3], a2[i])
                     for i in range(3)])


def ref_aij(a, i, j):
    a = np.asarray(a, float)

    def f(u):
        return 1.0 / ((a[i] ** 2 + u) * (a[j] ** 2 + u) * np.sqrt(np.prod(a**2 + u)))

    # u = e^s on a finite range (the tails are below 1e-17 relative, see gravity.rs)
    lo, hi = np.log(np.min(a**2)) - 42, np.log(np.max(a**2)) + 30
    val, _ = integrate.quad(lambda s: f(np.exp(s)) * np.exp(s), lo, hi, epsabs=0, epsrel=1e-13,
                            limit=400)
    return a.prod() * val


@pytest.mark.parametrize("a", SHAPES)
def test_index_symbols_against_scipy(a):
    A, Aij = index_symbols(a)
    assert A.shape == (3,) and Aij.shape == (3, 3)
    np.testing.assert_allclose(A, ref_a(a), rtol=1e-14)
    assert abs(A.sum() - 2.0) < 1e-15
    np.testing.assert_array_equal(Aij, Aij.T)
    for i in range(3):
        for j in range(i, 3):
            assert Aij[i, j] == pytest.approx(ref_aij(a, i, j), rel=1e-11)
    # 3 A_ii + sum_{j != i} A_ij = 2 / a_i^2
    a = np.asarray(a)
    np.testing.assert_allclose(3 * np.diag(Aij) + Aij.sum(axis=1) - np.diag(Aij), 2 / a**2, rtol=1e-14)


def test_index_symbols_of_a_sphere_and_other_inputs():
    A, Aij = index_symbols([2.0, 2.0, 2.0])
    np.testing.assert_allclose(A, 2 / 3, rtol=1e-15)
    np.testing.assert_allclose(Aij, 2 / (5 * 4.0), rtol=1e-15)
    # lists, tuples, int arrays, non-contiguous views
    base = index_symbols(np.array([1.3, 1.0, 0.7]))
    for a in ([1.3, 1.0, 0.7], (1.3, 1.0, 0.7), np.array([[1.3, 0], [1.0, 0], [0.7, 0]])[:, 0]):
        r = index_symbols(a)
        np.testing.assert_array_equal(r[0], base[0])
        np.testing.assert_array_equal(r[1], base[1])
    A, _ = index_symbols(np.array([3, 2, 1]))
    np.testing.assert_allclose(A, ref_a([3.0, 2.0, 1.0]), rtol=1e-14)


def test_index_symbols_typed_errors():
    with pytest.raises(lf.ShapeError):
        index_symbols([1.0, 2.0])
    with pytest.raises(lf.ShapeError):
        index_symbols(np.ones((2, 3)))
    with pytest.raises(lf.NonFiniteError):
        index_symbols([1.0, np.nan, 1.0])
    with pytest.raises(lf.InvalidArgumentError):
        index_symbols([1.0, -1.0, 1.0])
    with pytest.raises(lf.InvalidArgumentError):
        index_symbols([1.0, 0.0, 1.0])
    with pytest.raises(lf.InvalidArgumentError):  # axis ratio below 2**-250
        index_symbols([1.0, 1.0, 1e-80])
    with pytest.raises(lf.InvalidArgumentError):  # A_ij ~ 1/a^2 overflows
        index_symbols([1e-160, 1e-160, 1e-160])
    with pytest.raises(lf.ArgumentTypeError):
        index_symbols("abc")
    with pytest.raises(lf.ArgumentTypeError):
        index_symbols([1.0, 1.0j, 1.0])


# ------------------------------------------------------------------------------------------------
# The potential


def gl_plus(rng, s):
    q1, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    q2, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    X = q1 @ np.diag(s) @ q2.T
    if np.linalg.det(X) < 0:
        X[0] = -X[0]
    return X


def u_ref(X, G, rho):
    s = np.linalg.svd(X, compute_uv=False)
    return -4 * np.pi * G * rho * special.elliprf(*(s**2))


def central(f, X, V, h):
    # Richardson extrapolation of two central differences (fourth order)
    d = lambda h: (f(X + h * V) - f(X - h * V)) / (2 * h)  # noqa: E731
    return (4 * d(h / 2) - d(h)) / 3


@pytest.mark.parametrize(
    "s", [(1.4, 0.9, 0.6), (1.0, 1.0, 0.6), (1.3, 0.5, 0.5), (0.8, 0.8, 0.8), (2.0, 0.2, 0.1)]
)
def test_self_gravity_value_gradient_hessian(s):
    G, rho = 0.7, 1.9
    p = pot.SelfGravity(G=G, rho=rho)
    rng = np.random.default_rng(7)
    for _ in range(3):
        X, V, W = gl_plus(rng, s), rng.standard_normal((3, 3)), rng.standard_normal((3, 3))
        assert p.value(X) == pytest.approx(u_ref(X, G, rho), rel=1e-13)
        g = p.gradient(X)
        h = 1e-3 * min(s)
        fd = central(p.value, X, V, h)
        assert abs(np.sum(g * V) - fd) < 1e-8 * np.linalg.norm(g) * np.linalg.norm(V)
        H = p.hessian(X, V)
        fdg = central(p.gradient, X, V, h)
        assert np.linalg.norm(H - fdg) < 1e-7 * np.linalg.norm(H)
        # symmetric: <W, D2U[V]> = <V, D2U[W]>
        HW = p.hessian(X, W)
        scale = np.linalg.norm(W) * np.linalg.norm(H) + np.linalg.norm(V) * np.linalg.norm(HW)
        assert abs(np.sum(W * H) - np.sum(V * HW)) < 1e-13 * scale


def test_self_gravity_sphere_invariance_and_pickling():
    p = pot.SelfGravity(G=2.0, rho=0.5)
    for a in (0.3, 1.0, 4.0):
        assert p.value(a * np.eye(3)) == pytest.approx(-4 * np.pi * 2.0 * 0.5 / a, rel=1e-15)
    rng = np.random.default_rng(3)
    X = gl_plus(rng, (1.2, 0.9, 0.4))
    Q1, Q2 = gl_plus(rng, (1, 1, 1)), gl_plus(rng, (1, 1, 1))
    assert p.value(Q1 @ X @ Q2.T) == pytest.approx(p.value(X), rel=1e-14)
    # the default is G = rho = 1
    assert pot.SelfGravity().value(np.eye(3)) == pytest.approx(-4 * np.pi, rel=1e-15)
    assert repr(p) == "SelfGravity(G=2, rho=0.5)"
    q = pickle.loads(pickle.dumps(p))
    assert repr(q) == repr(p) and q.value(X) == p.value(X)
    s = pickle.loads(pickle.dumps(p + pot.Volumetric(1.0, 1.4)))
    assert s.value(X) == pytest.approx(p.value(X) + pot.Volumetric(1.0, 1.4).value(X), rel=1e-14)


def test_maclaurin_spheroid():
    # Omega^2 / (pi G rho') = 2 (A_1 - A_3 a_3^2 / a_1^2) = 0.37423 at e = 0.81267 (EFE Table IV),
    # from the gradient of the potential (rho' = rho / (a1 a2 a3), the actual density).
    e = 0.81267
    a3 = np.sqrt(1 - e * e)
    g = pot.SelfGravity().gradient(np.diag([1.0, 1.0, a3]))
    w2 = (g[0, 0] - a3 * g[2, 2]) / (np.pi / a3)
    assert w2 == pytest.approx(0.37423, abs=5e-6)
    A, _ = index_symbols([1.0, 1.0, a3])
    assert 2 * (A[0] - A[2] * a3**2) == pytest.approx(w2, rel=1e-13)


def test_self_gravity_integrates_with_pressure():
    # A compressible self-gravitating body (gravity + polytropic pressure): Verlet keeps the energy.
    body = lf.PseudoRigidBody(3, pot.SelfGravity(G=0.1) + pot.Volumetric(1.0, 1.4))
    X0 = np.diag([1.2, 1.0, 0.8])
    P0 = np.array([[0.0, 0.3, 0.0], [-0.3, 0.0, 0.1], [0.0, 0.0, 0.05]])
    traj = lf.integrate(body, np.concatenate([X0.ravel(), P0.ravel()]), dt=1e-3, steps=2000,
                        method="verlet4", save_every=500)
    E = traj.energy()
    assert np.max(np.abs(E - E[0])) < 1e-9 * abs(E[0])


def test_self_gravity_typed_errors():
    for G, rho in ((0.0, 1.0), (-1.0, 1.0), (1.0, 0.0), (np.nan, 1.0), (1.0, np.inf)):
        with pytest.raises(lf.InvalidArgumentError):
            pot.SelfGravity(G=G, rho=rho)
    with pytest.raises(lf.ArgumentTypeError):
        pot.SelfGravity(G="1.0")
    p = pot.SelfGravity()
    for n in (2, 4):
        with pytest.raises(lf.InvalidArgumentError, match="n = 3"):
            p.value(np.eye(n))
        with pytest.raises(lf.InvalidArgumentError):
            p.gradient(np.eye(n))
        with pytest.raises(lf.InvalidArgumentError):
            p.hessian(np.eye(n), np.eye(n))
        with pytest.raises(lf.InvalidArgumentError):
            lf.PseudoRigidBody(n, p)
        with pytest.raises(lf.InvalidArgumentError):
            lf.PseudoRigidBody(n, p + pot.Harmonic(1.0))
    with pytest.raises(lf.NotInGroupError):
        p.value(np.diag([1.0, 1.0, 0.0]))
    with pytest.raises(lf.NotInGroupError):
        p.gradient(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(lf.NonFiniteError):
        p.value(np.diag([1.0, np.nan, 1.0]))
    with pytest.raises(lf.ShapeError):
        p.hessian(np.eye(3), np.eye(2))
