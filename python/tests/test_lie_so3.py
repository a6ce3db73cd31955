"""lieflow.lie SO(3)/so(3) and SE(3) bindings: values against scipy, shapes, batches, errors."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.linalg import expm, logm
from scipy.spatial.transform import Rotation

import lieflow as lf
from lieflow import lie

rng = np.random.default_rng(0)


def hat_np(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def se3_hat_np(xi):
    m = np.zeros((4, 4))
    m[:3, :3] = hat_np(xi[:3])
    m[:3, 3] = xi[3:]
    return m


def random_rigid(b):
    return lie.se3_exp(rng.normal(size=(b, 6)))


# ---------------------------------------------------------------- so(3)


def test_hat_vee_cross_product_and_batch():
    u, v = rng.normal(size=(2, 3))
    assert np.allclose(lie.hat(u) @ v, np.cross(u, v), atol=1e-15)
    ws = rng.normal(size=(5, 3))
    hs = lie.hat(ws)
    assert hs.shape == (5, 3, 3)
    assert np.array_equal(hs[2], hat_np(ws[2]))
    assert np.array_equal(lie.vee(hs), ws)
    assert lie.vee(lie.hat(u)).shape == (3,)
    # hat(u × v) = [hat u, hat v]
    hu, hv = lie.hat(u), lie.hat(v)
    assert np.allclose(lie.hat(np.cross(u, v)), hu @ hv - hv @ hu, atol=1e-14)


def test_exp_matches_scipy_rotation_single_and_batch():
    ws = rng.normal(size=(50, 3)) * 3
    rs = lie.so3_exp(ws)
    assert rs.shape == (50, 3, 3)
    assert np.allclose(rs, Rotation.from_rotvec(ws).as_matrix(), atol=1e-14)
    one = lie.so3_exp(ws[7])
    assert one.shape == (3, 3)
    assert np.array_equal(one, rs[7])
    # integer array-likes are accepted
    assert np.allclose(lie.so3_exp([0, 0, 1]), Rotation.from_rotvec([0, 0, 1]).as_matrix())


def test_exp_tiny_and_huge_angles():
    for scale in [1e-12, 1e-9, 1e-4, 1e2, 1e3]:
        w = rng.normal(size=3)
        w *= scale / np.linalg.norm(w)
        r = lie.so3_exp(w)
        assert np.linalg.norm(r.T @ r - np.eye(3)) < 1e-14
        assert np.allclose(r, expm(hat_np(w)), atol=1e-13 * (1 + scale))


def test_log_matches_scipy_and_inverts_exp():
    ws = rng.normal(size=(100, 3))
    ws *= (rng.uniform(0, np.pi, 100) / np.linalg.norm(ws, axis=1))[:, None]
    rs = Rotation.from_rotvec(ws).as_matrix()
    logs = lie.so3_log(rs)
    assert logs.shape == (100, 3)
    assert np.allclose(logs, Rotation.from_matrix(rs).as_rotvec(), atol=1e-12)
    assert np.allclose(logs, ws, atol=1e-13)
    assert np.allclose(lie.so3_log(rs, strict=True), ws, atol=1e-13)


@pytest.mark.parametrize("delta", [1e-6, 1e-10])
def test_log_near_pi(delta):
    a = rng.normal(size=3)
    a /= np.linalg.norm(a)
    w = a * (np.pi - delta)
    assert np.allclose(lie.so3_log(lie.so3_exp(w)), w, atol=1e-13)
    assert np.allclose(lie.so3_log(lie.so3_exp(w), strict=True), w, atol=1e-13)


def test_log_at_pi_returns_one_of_two_or_raises_when_strict():
    r = np.diag([-1.0, 1.0, -1.0])
    w = lie.so3_log(r)
    assert np.allclose(np.abs(w), [0, np.pi, 0], atol=1e-15)
    assert np.allclose(lie.so3_exp(w), r, atol=1e-15)
    with pytest.raises(lf.NoUniqueLogError, match="not unique"):
        lie.so3_log(r, strict=True)
    with pytest.raises(lf.NoUniqueLogError, match=r"R\[1\]"):
        lie.so3_log(np.stack([np.eye(3), r]), strict=True)


def test_cayley_round_trip_and_closed_form():
    ws = rng.normal(size=(20, 3)) * 4
    rs = lie.so3_cayley(ws)
    for w, r in zip(ws, rs):
        h = hat_np(w) / 2
        assert np.allclose(r, np.linalg.solve(np.eye(3) - h, np.eye(3) + h), atol=1e-14)
    assert np.allclose(lie.so3_cayley_inv(rs), ws, atol=1e-12)
    with pytest.raises(lf.InvalidArgumentError, match=r"1 \+ tr R"):
        lie.so3_cayley_inv(np.diag([1.0, -1.0, -1.0]))


@pytest.mark.parametrize("side", ["right", "left"])
def test_jacobians_finite_differences_and_inverse(side):
    fn = getattr(lie, f"so3_jacobian_{side}")
    w = rng.normal(size=3) * 1.5
    r = lie.so3_exp(w)
    h = 1e-5
    fd = np.zeros((3, 3))
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        d = (lie.so3_exp(w + e) - lie.so3_exp(w - e)) / (2 * h)
        m = r.T @ d if side == "right" else d @ r.T
        fd[:, i] = lie.vee((m - m.T) / 2)  # skew to O(h²)
    j = fn(w)
    assert np.allclose(j, fd, atol=1e-8)
    assert np.allclose(fn(w, inverse=True) @ j, np.eye(3), atol=1e-13)
    batch = fn(np.stack([w, 2 * w]), inverse=True)
    assert batch.shape == (2, 3, 3)
    with pytest.raises(lf.InvalidArgumentError, match="singular"):
        fn([2 * np.pi, 0, 0], inverse=True)


@settings(max_examples=200, deadline=None)
@given(arrays(np.float64, (4, 3), elements=st.floats(-50, 50)))
def test_random_vectors_give_rotations_that_round_trip(ws):
    rs = lie.so3_exp(ws)
    for r in rs:
        assert np.linalg.norm(r.T @ r - np.eye(3)) < 1e-13
        assert abs(np.linalg.det(r) - 1) < 1e-13
    logs = lie.so3_log(rs)
    assert np.all(np.linalg.norm(logs, axis=1) <= np.pi + 1e-12)
    assert np.allclose(lie.so3_exp(logs), rs, atol=1e-12)
    # inside the injectivity radius log∘exp is the identity
    inside = np.linalg.norm(ws, axis=1) < np.pi - 1e-6
    assert np.allclose(logs[inside], ws[inside], atol=1e-9)


# ---------------------------------------------------------------- SE(3)


def test_se3_exp_log_match_scipy():
    xis = rng.normal(size=(30, 6))
    gs = lie.se3_exp(xis)
    assert gs.shape == (30, 4, 4)
    for xi, g in zip(xis, gs):
        assert np.allclose(g, expm(se3_hat_np(xi)), atol=1e-12)
    small = xis * (2.5 / np.linalg.norm(xis[:, :3], axis=1))[:, None]
    logs = lie.se3_log(lie.se3_exp(small))
    assert np.allclose(logs, small, atol=1e-12)
    g = lie.se3_exp(small[0])
    assert np.allclose(se3_hat_np(lie.se3_log(g)), logm(g).real, atol=1e-9)
    assert lie.se3_log(g).shape == (6,)
    # pure translation
    assert np.allclose(lie.se3_exp([0, 0, 0, 1, 2, 3]), [[1, 0, 0, 1], [0, 1, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]])


def test_se3_adjoint_identities():
    g, h = random_rigid(2)
    ad_g, ad_h = lie.se3_Ad(g), lie.se3_Ad(h)
    assert ad_g.shape == (6, 6)
    assert np.allclose(lie.se3_Ad(lie.se3_compose(g, h)), ad_g @ ad_h, atol=1e-12)
    xi = rng.normal(size=6)
    assert np.allclose(lie.se3_exp(ad_g @ xi), g @ lie.se3_exp(xi) @ np.linalg.inv(g), atol=1e-11)
    assert np.allclose(lie.se3_Ad(np.stack([g, h])), np.stack([ad_g, ad_h]))


def test_se3_compose_inverse_and_broadcast():
    gs = random_rigid(4)
    g = gs[0]
    assert np.allclose(lie.se3_inverse(g), np.linalg.inv(g), atol=1e-13)
    assert np.allclose(lie.se3_inverse(gs), np.linalg.inv(gs), atol=1e-13)
    assert np.allclose(lie.se3_compose(gs, gs), gs @ gs, atol=1e-13)
    assert np.allclose(lie.se3_compose(g, gs), g @ gs, atol=1e-13)
    assert np.allclose(lie.se3_compose(gs, g), gs @ g, atol=1e-13)
    assert lie.se3_compose(g, g).shape == (4, 4)
    with pytest.raises(lf.ShapeError, match="same length"):
        lie.se3_compose(gs, gs[:2])


def test_se3_log_at_half_turn():
    g = np.eye(4)
    g[:3, :3] = np.diag([1.0, -1.0, -1.0])
    g[:3, 3] = [1, 2, 3]
    assert np.allclose(lie.se3_exp(lie.se3_log(g)), g, atol=1e-14)
    with pytest.raises(lf.NoUniqueLogError):
        lie.se3_log(g, strict=True)


# ---------------------------------------------------------------- errors

VEC3 = ["hat", "so3_exp", "so3_cayley", "so3_jacobian_right", "so3_jacobian_left"]
MAT3 = ["vee", "so3_log", "so3_cayley_inv"]
MAT4 = ["se3_log", "se3_Ad", "se3_inverse"]


@pytest.mark.parametrize("name", VEC3 + ["se3_exp"])
def test_vector_inputs_reject_bad_shape_and_nan(name):
    fn = getattr(lie, name)
    d = 6 if name == "se3_exp" else 3
    for bad in [np.zeros(d + 1), np.zeros((2, d, 1)), np.zeros((2, d - 1)), 1.0]:
        with pytest.raises(lf.ShapeError, match="expected"):
            fn(bad)
    x = np.zeros((3, d))
    x[1, 2] = np.nan
    # named by its item and its entry there, not by a flat index (5 or 8)
    with pytest.raises(lf.NonFiniteError, match=r"\[1\] contains .* at index 2$"):
        fn(x)
    with pytest.raises(lf.NonFiniteError):
        fn(np.full(d, np.inf))


@pytest.mark.parametrize("name", MAT3 + MAT4 + ["se3_compose"])
def test_matrix_inputs_reject_bad_shape_nan_and_non_members(name):
    fn = getattr(lie, name)
    k = 3 if name in MAT3 else 4
    call = (lambda m: fn(m, np.eye(4))) if name == "se3_compose" else fn
    with pytest.raises(lf.ShapeError):
        call(np.eye(k + 1))
    with pytest.raises(lf.ShapeError):
        call(np.zeros(k))
    bad = np.eye(k)
    bad[0, 1] = np.nan
    with pytest.raises(lf.NonFiniteError):
        call(bad)
    not_member = np.eye(k)
    not_member[0, 0] = 1.1  # not skew / not orthogonal
    if name == "vee":
        not_member = hat_np([1.0, 2.0, 3.0]) + np.eye(3) * 1e-3
    with pytest.raises(lf.NotInGroupError):
        call(not_member)
    if name != "vee":
        reflection = np.eye(k)
        reflection[2, 2] = -1
        with pytest.raises(lf.NotInGroupError, match="det R"):
            call(reflection)
    if k == 4:
        last_row = np.eye(4)
        last_row[3, 0] = 1e-3
        with pytest.raises(lf.NotInGroupError, match="last row"):
            call(last_row)


def test_batch_error_names_the_element():
    rs = lie.so3_exp(rng.normal(size=(3, 3)))
    rs[2, 0, 0] += 1e-3
    with pytest.raises(lf.NotInGroupError, match=r"R\[2\]"):
        lie.so3_log(rs)
    with pytest.raises(lf.NotInGroupError, match=r"^h \(R\)"):
        lie.se3_compose(np.eye(4), np.diag([1.0, 1.0, -1.0, 1.0]))


def test_large_batch_runs_in_parallel_and_matches_scipy():
    ws = rng.normal(size=(20_000, 3))
    assert np.allclose(lie.so3_exp(ws), Rotation.from_rotvec(ws).as_matrix(), atol=1e-14)


def test_non_contiguous_and_empty_batches():
    ws = rng.normal(size=(6, 6))[:, ::2]  # strided view, shape (6, 3)
    assert np.array_equal(lie.so3_exp(ws), lie.so3_exp(np.ascontiguousarray(ws)))
    rs = lie.so3_exp(ws)
    assert np.array_equal(lie.so3_log(np.asfortranarray(rs)), lie.so3_log(rs))
    assert np.array_equal(lie.hat(np.asfortranarray(ws)), lie.hat(ws))
    assert lie.so3_exp(np.zeros((0, 3))).shape == (0, 3, 3)
    assert lie.se3_log(np.zeros((0, 4, 4))).shape == (0, 6)


def test_se3_compose_broadcasts_and_accepts_empty_batches():
    g = lie.se3_exp([0.1, 0.2, 0.3, 1.0, 2.0, 3.0])
    hs = lie.se3_exp(np.random.default_rng(0).standard_normal((4, 6)))
    np.testing.assert_allclose(lie.se3_compose(g, hs), g @ hs, atol=1e-14)
    for args in [(g, np.zeros((0, 4, 4))), (np.zeros((0, 4, 4)), g)]:
        assert lie.se3_compose(*args).shape == (0, 4, 4)


def test_a_square_array_of_vectors_is_read_as_rows_with_a_warning():
    import warnings
    w = np.array([0.1, 0.2, 0.3])
    with pytest.warns(lf.LieflowWarning, match=r"w of shape \(3, 3\) is read as 3 items"):
        r = lf.lie.so3_exp(lf.lie.hat(w))
    assert r.shape == (3, 3, 3)
    with pytest.warns(lf.LieflowWarning, match=r"xi of shape \(6, 6\)"):
        lf.lie.se3_exp(np.zeros((6, 6)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lf.lie.so3_exp(w)
        lf.lie.so3_exp(np.zeros((4, 3)))
        lf.lie.so3_log(np.eye(3))                            # a (3, 3) item: not ambiguous
