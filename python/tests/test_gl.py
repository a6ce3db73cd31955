"""lieflow.lie GL+(n) bindings: SVD coordinates, from_svd, polar, stratum (001 (2.4), §6.1)."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import lieflow as lf


def random_gl_plus(rng, n):
    x = rng.standard_normal((n, n))
    if np.linalg.det(x) < 0:
        x[0] *= -1
    return x


def random_rotation(rng, n):
    return lf.lie.polar(random_gl_plus(rng, n))[0]


def assert_rotation(r):
    n = r.shape[0]
    np.testing.assert_allclose(r.T @ r, np.eye(n), atol=1e-12)
    assert np.linalg.det(r) > 0


@settings(max_examples=50, deadline=None)
@given(n=st.integers(1, 7), seed=st.integers(0, 2**32 - 1))
def test_svd_coordinates_round_trip(n, seed):
    rng = np.random.default_rng(seed)
    x = random_gl_plus(rng, n)
    r, a, s = lf.lie.svd_coordinates(x)
    assert r.shape == (n, n) and a.shape == (n,) and s.shape == (n, n)
    assert_rotation(r)
    assert_rotation(s)
    assert np.all(np.diff(a) <= 0) and a[-1] > 0
    np.testing.assert_allclose(r @ np.diag(a) @ s.T, x, atol=1e-12)
    np.testing.assert_allclose(lf.lie.from_svd(r, a, s), x, atol=1e-12)
    # a backward-stable SVD gets each singular value to ε‖X‖ absolute, not relative
    sv = np.linalg.svd(x, compute_uv=False)
    np.testing.assert_allclose(a, sv, rtol=1e-12, atol=1e-14 * sv[0])


def test_polar():
    rng = np.random.default_rng(1)
    x = random_gl_plus(rng, 4)
    r, p = lf.lie.polar(x)
    assert_rotation(r)
    np.testing.assert_allclose(p, p.T, atol=1e-13)
    assert np.all(np.linalg.eigvalsh(p) > 0)
    np.testing.assert_allclose(r @ p, x, atol=1e-12)


def test_stratum():
    rng = np.random.default_rng(2)
    g, h = random_rotation(rng, 3), random_rotation(rng, 3)
    st3 = lf.lie.stratum(g @ np.diag([2.0, 2.0, 1.0]) @ h.T)
    assert st3["multiplicities"] == [2, 1]
    assert not st3["principal"]
    assert st3["min_gap"] < 1e-12
    p = lf.lie.stratum(np.diag([3.0, 2.0, 1.0]))
    assert p["principal"] and p["multiplicities"] == [1, 1, 1]
    assert p["min_gap"] == pytest.approx(1.0)
    # A looser tolerance merges close values.
    assert lf.lie.stratum(np.diag([1.0, 0.999, 0.5]), tol=1e-2)["multiplicities"] == [2, 1]


def test_errors():
    with pytest.raises(lf.ShapeError):
        lf.lie.svd_coordinates(np.ones((2, 3)))
    with pytest.raises(lf.ShapeError):
        lf.lie.polar(np.ones(3))
    with pytest.raises(lf.NonFiniteError):
        lf.lie.svd_coordinates(np.array([[1.0, np.nan], [0.0, 1.0]]))
    with pytest.raises(lf.NotInGroupError, match="det X"):
        lf.lie.svd_coordinates(np.diag([1.0, -1.0]))
    with pytest.raises(lf.NotInGroupError):
        lf.lie.polar(np.zeros((3, 3)))
    with pytest.raises(lf.NotInGroupError):
        lf.lie.stratum(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(lf.InvalidArgumentError):
        lf.lie.stratum(np.eye(2), tol=-1.0)
    with pytest.raises(lf.InvalidArgumentError):
        lf.lie.from_svd(np.eye(2), [1.0, 0.0], np.eye(2))
    with pytest.raises(lf.NotInGroupError):
        lf.lie.from_svd(np.diag([1.0, -1.0]), [1.0, 1.0], np.eye(2))
    with pytest.raises(lf.ShapeError):
        lf.lie.from_svd(np.eye(2), [1.0, 1.0, 1.0], np.eye(2))
    with pytest.raises(lf.NonFiniteError):
        lf.lie.from_svd(np.eye(2), [1.0, np.inf], np.eye(2))
