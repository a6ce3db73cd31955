"""lf.potentials: the Stretch potential and the Hessians D²U(X)[V] (Potential.hessian)."""

import pickle

import numpy as np
import pytest

import lieflow as lf

pot = lf.potentials


def gl_plus(rng, n):
    """A matrix of GL+(n) with singular values in [0.5, 2] (random rotations)."""
    q1, _ = np.linalg.qr(rng.standard_normal((n, n)))
    q2, _ = np.linalg.qr(rng.standard_normal((n, n)))
    X = q1 @ np.diag(rng.uniform(0.5, 2.0, n)) @ q2.T
    if np.linalg.det(X) < 0:
        X[0] = -X[0]
    return X


def stretch_value(X, k):
    return 0.5 * k * np.sum((np.linalg.svd(X, compute_uv=False) - 1.0) ** 2)


def stretch_gradient(X, k):
    u, s, vt = np.linalg.svd(X)
    return k * (X - u @ vt)


def central(f, X, V, h=1e-5):
    return (f(X + h * V) - f(X - h * V)) / (2 * h)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_stretch_value_gradient_hessian_against_numpy(n):
    rng = np.random.default_rng(n)
    k = 1.7
    s = pot.Stretch(k)
    for _ in range(3):
        X, V = gl_plus(rng, n), rng.standard_normal((n, n))
        assert np.isclose(s.value(X), stretch_value(X, k), rtol=1e-12, atol=1e-14)
        G = s.gradient(X)
        np.testing.assert_allclose(G, stretch_gradient(X, k), rtol=1e-10, atol=1e-12)
        fd_value = central(lambda Y: stretch_value(Y, k), X, V)
        assert abs(np.sum(G * V) - fd_value) < 1e-8 * max(1.0, abs(fd_value))
        H = s.hessian(X, V)
        fd_grad = central(lambda Y: stretch_gradient(Y, k), X, V)
        assert np.linalg.norm(H - fd_grad) < 1e-8 * np.linalg.norm(H)
    # Zero with zero gradient at rotations.
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    assert abs(s.value(Q)) < 1e-24
    assert np.linalg.norm(s.gradient(Q)) < 1e-13


def test_stretch_checks_and_pickles():
    with pytest.raises(lf.LieflowError):
        pot.Stretch(0.0)
    s = pot.Stretch(2.5) + pot.Harmonic(0.3)
    X = np.diag([1.2, 0.9, 1.1])
    X[0, 1] = 0.2
    V = np.arange(9.0).reshape(3, 3) / 9
    t = pickle.loads(pickle.dumps(s))
    assert repr(t) == repr(s) == "Stretch(2.5) + Harmonic(0.3)"
    assert t.value(X) == s.value(X)
    np.testing.assert_array_equal(t.hessian(X, V), s.hessian(X, V))
    with pytest.raises(lf.ShapeError):
        s.hessian(X, np.zeros((2, 2)))


@pytest.mark.parametrize(
    "p",
    [
        pot.Harmonic(1.3),
        pot.SaintVenantKirchhoff(0.7, 1.3),
        pot.Volumetric(0.4, 1.4),
        pot.Volumetric(0.4, 1.0),
        pot.Stretch(0.8) + pot.SaintVenantKirchhoff(0.2, 0.5),
    ],
    ids=repr,
)
def test_hessians_of_the_built_ins_match_finite_differences_and_are_symmetric(p):
    rng = np.random.default_rng(7)
    X, V, W = gl_plus(rng, 3), rng.standard_normal((3, 3)), rng.standard_normal((3, 3))
    H = p.hessian(X, V)
    fd = central(p.gradient, X, V)
    assert np.linalg.norm(H - fd) < 1e-8 * np.linalg.norm(H)
    assert np.isclose(np.sum(W * H), np.sum(V * p.hessian(X, W)), rtol=1e-12)


def test_callable_hessian_given_or_by_finite_differences():
    k = 1.9
    X = np.array([[1.2, 0.1, 0.0], [0.0, 0.9, 0.2], [0.1, 0.0, 1.1]])
    V = np.array([[0.3, -1.0, 0.2], [0.5, 0.0, 0.4], [-0.7, 0.1, 1.0]])
    exact = pot.Harmonic(k).hessian(X, V)
    np.testing.assert_allclose(exact, k * V, rtol=1e-15)

    calls = []

    def hessian(X_, V_):
        calls.append((X_.shape, V_.shape))
        return k * V_

    given = pot.Callable(lambda Y: 0.5 * k * np.sum(Y * Y), lambda Y: k * Y, hessian)
    np.testing.assert_allclose(given.hessian(X, V), exact, rtol=1e-15)
    assert calls == [((3, 3), (3, 3))]
    # Pickled with its hessian (module-level functions pickle; lambdas do not).
    assert len(given.__reduce__()[1]) == 3

    # A gradient with curvature: U = (k/4)‖X‖⁴, ∇U = k‖X‖²X, D²U[V] = k(‖X‖²V + 2⟨X,V⟩X).
    fallback = pot.Callable(lambda Y: 0.25 * k * np.sum(Y * Y) ** 2, lambda Y: k * np.sum(Y * Y) * Y)
    quartic = k * (np.sum(X * X) * V + 2 * np.sum(X * V) * X)
    err = np.linalg.norm(fallback.hessian(X, V) - quartic) / np.linalg.norm(quartic)
    assert err < 1e-6
    harmonic_fd = pot.Callable(lambda Y: 0.5 * k * np.sum(Y * Y), lambda Y: k * Y)
    np.testing.assert_allclose(harmonic_fd.hessian(X, V), exact, rtol=1e-6, atol=1e-8)
    np.testing.assert_array_equal(harmonic_fd.hessian(X, np.zeros((3, 3))), np.zeros((3, 3)))
    assert len(harmonic_fd.__reduce__()[1]) == 2


def test_callable_hessian_errors_are_raised():
    X = np.eye(3)
    wrong = pot.Callable(lambda Y: 0.0, lambda Y: Y, lambda Y, V: np.zeros(2))
    with pytest.raises(lf.ShapeError):
        wrong.hessian(X, X)
    failing = pot.Callable(lambda Y: 0.0, lambda Y: Y, lambda Y, V: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        failing.hessian(X, X)
    with pytest.raises(TypeError):
        pot.Callable(lambda Y: 0.0, lambda Y: Y, 1.0)
