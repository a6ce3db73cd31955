"""lieflow.pseudo_rigid bindings (001 §2–§6): values against numpy re-computations of the
source formulas, identities between the functions, and every error path."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import lieflow as lf
from lieflow import pseudo_rigid as pr


def random_gl_plus(rng, n):
    x = rng.standard_normal((n, n)) + 0.5 * np.eye(n)
    if np.linalg.det(x) < 0:
        x[0] *= -1
    return x


def random_skew(rng, n):
    a = rng.standard_normal((n, n))
    return a - a.T


def vee(xi):
    n = xi.shape[0]
    return np.array([xi[i, j] for i in range(n) for j in range(i + 1, n)])


def hat(c, n):
    m = np.zeros((n, n))
    k = 0
    for i in range(n):
        for j in range(i + 1, n):
            m[i, j], m[j, i] = c[k], -c[k]
            k += 1
    return m


def pairing(a, b):
    return 0.5 * np.trace(a.T @ b)


def setup(seed, n):
    rng = np.random.default_rng(seed)
    return rng, random_gl_plus(rng, n), random_skew(rng, n), random_skew(rng, n), rng.standard_normal((n, n))


@settings(max_examples=40, deadline=None)
@given(n=st.integers(2, 5), seed=st.integers(0, 2**32 - 1))
def test_inertia_tensors_and_bi_inertia(n, seed):
    _, x, xi, eta, _ = setup(seed, n)
    q, p = x @ x.T, x.T @ x
    np.testing.assert_allclose(pr.left_inertia(x, xi), q @ xi + xi @ q, atol=1e-10)
    np.testing.assert_allclose(pr.right_inertia(x, xi), p @ xi + xi @ p, atol=1e-10)
    top, bottom = pr.bi_inertia_apply(x, xi, eta)
    np.testing.assert_allclose(top, q @ xi + xi @ q - 2 * x @ eta @ x.T, atol=1e-10)
    np.testing.assert_allclose(bottom, -2 * x.T @ xi @ x + p @ eta + eta @ p, atol=1e-10)
    b = pr.bi_inertia(x)
    d = n * (n - 1) // 2
    assert b.shape == (2 * d, 2 * d)
    np.testing.assert_allclose(b, b.T, atol=1e-10)
    np.testing.assert_allclose(b @ np.concatenate([vee(xi), vee(eta)]),
                               np.concatenate([vee(top), vee(bottom)]), atol=1e-10)
    np.testing.assert_allclose(b, pr.locked_inertia(x), atol=1e-10)
    np.testing.assert_allclose(b[:d, :d], pr.locked_inertia(x, "left"), atol=1e-10)
    np.testing.assert_allclose(b[d:, d:], pr.locked_inertia(x, "right"), atol=1e-10)
    v = pr.vertical_vector(x, xi, eta)
    np.testing.assert_allclose(v, xi @ x + x @ eta.T, atol=1e-12)
    qf = pr.bi_inertia_quadratic_form(x, xi, eta)
    assert qf == pytest.approx(np.sum(v * v), rel=1e-9)
    vals, vecs = pr.bi_inertia_eigen(x)
    np.testing.assert_allclose(b @ vecs, vecs * vals, atol=1e-9 * np.abs(vals).max())
    np.testing.assert_allclose(vals, np.linalg.eigvalsh(b), atol=1e-9 * vals.max())


@settings(max_examples=40, deadline=None)
@given(n=st.integers(2, 5), seed=st.integers(0, 2**32 - 1))
def test_solve_and_connections(n, seed):
    _, x, lam, gam, y = setup(seed, n)
    a = np.linalg.svd(x, compute_uv=False)
    if np.min(-np.diff(a)) < 1e-3 * a[0]:
        return
    xi, eta = pr.bi_inertia_solve(x, lam, gam)
    dense = np.linalg.solve(pr.bi_inertia(x), np.concatenate([vee(lam), vee(gam)]))
    d = n * (n - 1) // 2
    np.testing.assert_allclose(vee(xi), dense[:d], atol=1e-7 * max(1, np.abs(dense).max()))
    np.testing.assert_allclose(vee(eta), dense[d:], atol=1e-7 * max(1, np.abs(dense).max()))
    # (6.19), (2.16), (2.17)
    w = pr.bi_connection(x, pr.vertical_vector(x, lam, gam))
    np.testing.assert_allclose(w[0], lam, atol=1e-6)
    np.testing.assert_allclose(w[1], gam, atol=1e-6)
    np.testing.assert_allclose(pr.left_connection(x, lam @ x), lam, atol=1e-9)
    np.testing.assert_allclose(pr.right_connection(x, x @ gam.T), gam, atol=1e-9)
    # Horizontal parts: (2.20), (2.21), (6.6), and (6.23).
    for action in ["left", "right", "two-sided"]:
        h = pr.horizontal_part(x, y, action=action)
        if action != "right":
            np.testing.assert_allclose(h @ x.T, x @ h.T, atol=1e-9)
        if action != "left":
            np.testing.assert_allclose(h.T @ x, x.T @ h, atol=1e-9)
    np.testing.assert_allclose(pr.horizontal_part(x, y), pr.horizontal_part(x, y, "two-sided"))
    xi_h, eta_h = pr.bi_connection(x, pr.horizontal_part(x, y))
    assert np.abs(xi_h).max() < 1e-6 and np.abs(eta_h).max() < 1e-6


def test_momenta_body_coordinates_energy_riemann():
    rng = np.random.default_rng(7)
    n = 4
    x, v = random_gl_plus(rng, n), rng.standard_normal((n, n))
    big_l = pr.angular_momentum(x, v)
    gamma = pr.circulation(x, v)
    np.testing.assert_allclose(big_l, v @ x.T - x @ v.T, atol=1e-12)
    np.testing.assert_allclose(gamma, v.T @ x - x.T @ v, atol=1e-12)
    r, a, s, om, adot, la = pr.to_body(x, v)
    x2, v2 = pr.from_body(r, a, s, om, adot, la)
    np.testing.assert_allclose(x2, x, atol=1e-12)
    np.testing.assert_allclose(v2, v, atol=1e-9)
    amat = np.diag(a)
    # (2.32)
    np.testing.assert_allclose(r.T @ big_l @ r, om @ amat @ amat + amat @ amat @ om - 2 * amat @ la @ amat,
                               atol=1e-9)
    np.testing.assert_allclose(s.T @ gamma @ s, la @ amat @ amat + amat @ amat @ la - 2 * amat @ om @ amat,
                               atol=1e-9)
    k = pr.kinetic_energy(x, v)
    assert k == pytest.approx(0.5 * np.sum(v * v))
    k45 = 0.5 * np.trace(np.diag(adot) ** 2 - amat @ amat @ (om @ om + la @ la) + 2 * om @ amat @ la @ amat)
    assert k45 == pytest.approx(k, rel=1e-9)
    q, nn = pr.riemann_variables(x, v)
    np.testing.assert_allclose(q, x @ x.T)
    np.testing.assert_allclose(nn, x @ v.T)
    np.testing.assert_allclose(0.5 * (-big_l + v @ x.T + x @ v.T), nn, atol=1e-12)  # (3.10)
    # (9.1): {Q_ij, N_kl} for f = Q_01, g = N_10: δ_il Q_jk + δ_jl Q_ik with (i,j,k,l) = (0,1,1,0).
    e = lambda i, j: np.eye(n)[[i]].T @ np.eye(n)[[j]]  # noqa: E731
    z = np.zeros((n, n))
    got = pr.riemann_bracket(q, nn, e(0, 1), z, z, e(1, 0))
    assert got == pytest.approx(q[1, 1])


def test_stratum_dimensions_n3():
    for a, dims, iso in [([3, 2, 1], (6, 3), "(Z2)^2"), ([2, 2, 1], (5, 4), "S(O(2)×O(1))"),
                         ([1, 1, 1], (3, 6), "SO(3)")]:
        info = pr.stratum(np.diag(np.array(a, dtype=float)))
        assert (info["dim_vertical"], info["dim_horizontal"]) == dims
        assert info["isotropy"] == iso


def test_works_at_identity():
    x = np.eye(3)
    xi = hat([0.1, 0.2, 0.3], 3)
    np.testing.assert_allclose(pr.left_inertia(x, xi), 2 * xi)
    np.testing.assert_allclose(pr.left_connection(x, xi), xi, atol=1e-14)
    assert pr.bi_inertia(x).shape == (6, 6)
    h = pr.horizontal_part(x, xi)  # xi is vertical at I
    assert np.abs(h).max() < 1e-14


def test_errors():
    x = np.diag([3.0, 2.0, 1.0])
    xi = hat([0.1, 0.2, 0.3], 3)
    y = np.ones((3, 3))
    neg = np.diag([1.0, 1.0, -1.0])
    nan = x.copy()
    nan[0, 1] = np.nan
    calls = [
        lambda X: pr.left_inertia(X, xi), lambda X: pr.right_inertia(X, xi), pr.bi_inertia,
        lambda X: pr.bi_inertia_apply(X, xi, xi), lambda X: pr.bi_inertia_solve(X, xi, xi),
        pr.bi_inertia_eigen, lambda X: pr.bi_inertia_quadratic_form(X, xi, xi),
        lambda X: pr.left_connection(X, y), lambda X: pr.right_connection(X, y),
        lambda X: pr.bi_connection(X, y), lambda X: pr.vertical_vector(X, xi, xi),
        lambda X: pr.horizontal_part(X, y), pr.locked_inertia,
        lambda X: pr.angular_momentum(X, y), lambda X: pr.circulation(X, y),
        lambda X: pr.to_body(X, y), lambda X: pr.kinetic_energy(X, y), pr.stratum,
        lambda X: pr.riemann_variables(X, y),
    ]
    for f in calls:
        with pytest.raises(lf.NotInGroupError, match="det X"):
            f(neg)
        with pytest.raises(lf.NonFiniteError):
            f(nan)
        with pytest.raises(lf.ShapeError):
            f(np.ones((2, 3)))
        f(x)  # and the good input works
    with pytest.raises(lf.ShapeError):
        pr.left_inertia(x, np.zeros((2, 2)))
    with pytest.raises(lf.NotInGroupError):
        pr.left_inertia(x, np.eye(3))  # not skew
    with pytest.raises(lf.ShapeError):
        pr.bi_connection(x, np.ones((2, 2)))
    with pytest.raises(lf.InvalidArgumentError):
        pr.horizontal_part(x, y, action="up")
    for f in [lambda: pr.bi_inertia_solve(np.eye(3), xi, xi), lambda: pr.bi_connection(np.eye(3), y),
              lambda: pr.to_body(np.diag([2.0, 2.0, 1.0]), y)]:
        with pytest.raises(lf.DegenerateStratumError, match="gap"):
            f()
    with pytest.raises(lf.InvalidArgumentError):
        pr.from_body(np.eye(3), [1.0, -1.0, 1.0], np.eye(3), xi, [0, 0, 0], xi)
    with pytest.raises(lf.NotInGroupError):
        pr.from_body(np.eye(3), [1.0, 1.0, 1.0], np.eye(3), np.eye(3), [0, 0, 0], xi)
    with pytest.raises(lf.ShapeError):
        pr.from_body(np.eye(3), [1.0, 1.0, 1.0], np.eye(3), xi, [0, 0], xi)
    with pytest.raises(lf.ShapeError):
        pr.riemann_bracket(np.eye(3), np.eye(2), np.eye(3), np.eye(3), np.eye(3), np.eye(3))


def test_dense_outputs_refuse_sizes_that_cannot_be_allocated():
    # B_X at n = 200 would hold (200·199)² ≈ 1.6e9 entries (12.7 GB): a typed error, not an abort.
    x = np.eye(200)
    for f in [pr.bi_inertia, pr.bi_inertia_eigen]:
        with pytest.raises(lf.InvalidArgumentError, match="entries"):
            f(x)
    with pytest.raises(lf.InvalidArgumentError, match="entries"):
        pr.locked_inertia(x, "two-sided")
    assert pr.bi_inertia(np.eye(4)).shape == (12, 12)


def _items(out):
    return out if isinstance(out, tuple) else (out,)


def test_functions_map_leading_axes_item_by_item():
    """The one vectorisation rule: a stack of items gives each item's result, bit for bit, and a
    single X broadcasts over a stack of velocities; 300 items cross the parallel threshold."""
    rng = np.random.default_rng(11)
    n = 3
    X = np.stack([random_gl_plus(rng, n) for _ in range(6)]).reshape(2, 3, n, n)
    V = rng.standard_normal((2, 3, n, n))
    xi = np.stack([random_skew(rng, n) for _ in range(6)]).reshape(2, 3, n, n)
    eta = np.stack([random_skew(rng, n) for _ in range(6)]).reshape(2, 3, n, n)
    calls = {
        pr.left_inertia: (X, xi), pr.right_inertia: (X, xi), pr.bi_inertia: (X,),
        pr.bi_inertia_apply: (X, xi, eta), pr.bi_inertia_eigen: (X,),
        pr.bi_inertia_quadratic_form: (X, xi, eta), pr.left_connection: (X, V),
        pr.right_connection: (X, V), pr.bi_connection: (X, V),
        pr.vertical_vector: (X, xi, eta), pr.horizontal_part: (X, V), pr.locked_inertia: (X,),
        pr.angular_momentum: (X, V), pr.circulation: (X, V), pr.to_body: (X, V),
        pr.kinetic_energy: (X, V), pr.riemann_variables: (X, V),
    }
    for f, args in calls.items():
        batch = _items(f(*args))
        for i in range(2):
            for j in range(3):
                one = _items(f(*(a[i, j] for a in args)))
                assert len(one) == len(batch), f.__name__
                for b, o in zip(batch, one):
                    assert np.shape(b)[:2] == (2, 3), f.__name__
                    assert np.array_equal(b[i, j], o), f.__name__
    # Round trips through the body frame and the reduced state, batched.
    body = pr.to_body(X, V)
    Xb, Vb = pr.from_body(*body)
    np.testing.assert_allclose(Xb, X, atol=1e-12)
    np.testing.assert_allclose(Vb, V, atol=1e-12)
    # One X against 300 velocities (the parallel path): broadcast as numpy's.
    Vs = rng.standard_normal((300, n, n))
    ke = pr.kinetic_energy(X[0, 0], Vs)
    assert ke.shape == (300,)
    np.testing.assert_allclose(ke, 0.5 * np.einsum("bij,bij->b", Vs, Vs), rtol=1e-14)
    with pytest.raises(lf.ShapeError, match="broadcast"):
        pr.angular_momentum(X, V[:1, :2])
    bad = X.copy()
    bad[1, 2] = -bad[1, 2]  # det < 0 for n = 3
    with pytest.raises(lf.NotInGroupError, match=r"X\[1, 2\]"):
        pr.bi_inertia(bad)
