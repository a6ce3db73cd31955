"""lieflow.lie rotation interop (issue 15): quaternions, Euler angles and scipy Rotation objects,
against scipy.spatial.transform.Rotation: random batches, all 24 sequence spellings, gimbal lock,
both quaternion orders, leading axes, and the typed errors."""

import sys
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import lieflow as lf
from lieflow import lie

rng = np.random.default_rng(15)

AXES = ["XYX", "XYZ", "XZX", "XZY", "YXY", "YXZ", "YZX", "YZY", "ZXY", "ZXZ", "ZYX", "ZYZ"]
SEQS = AXES + [s.lower() for s in AXES]


def random_rotations(*shape):
    return lie.so3_exp(rng.normal(size=(int(np.prod(shape)), 3)) * 2).reshape(*shape, 3, 3)


def angle_diff(a, b):
    """a − b wrapped to (−π, π] (so that ±π compare equal)."""
    return np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b))))


def scipy_euler(R, seq):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Rotation.from_matrix(R).as_euler(seq)


# ---------------------------------------------------------------- quaternions


def test_quarter_turn_about_z():
    R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    s = np.sqrt(0.5)
    assert np.allclose(lie.to_quaternion(R), [s, 0, 0, s], atol=1e-16)
    assert np.allclose(lie.to_quaternion(R, scalar_first=False), [0, 0, s, s], atol=1e-16)
    assert np.allclose(lie.from_quaternion([s, 0, 0, s]), R, atol=1e-16)
    assert np.allclose(lie.to_euler(R, "xyz"), [0, 0, np.pi / 2], atol=1e-15)
    assert np.allclose(lie.to_euler(R, "ZYX"), [np.pi / 2, 0, 0], atol=1e-15)
    assert np.allclose(lie.from_euler([0, 0, np.pi / 2], "XYZ"), R, atol=1e-15)


def test_to_quaternion_matches_scipy_canonical_both_orders():
    R = random_rotations(200)
    q = lie.to_quaternion(R)
    assert q.shape == (200, 4)
    ref = Rotation.from_matrix(R)
    assert np.allclose(q, ref.as_quat(canonical=True, scalar_first=True), atol=1e-15)
    assert np.allclose(lie.to_quaternion(R, scalar_first=False), ref.as_quat(canonical=True),
                       atol=1e-15)
    assert np.all(q[:, 0] >= 0)
    assert np.allclose(np.linalg.norm(q, axis=-1), 1, atol=1e-15)
    # half turns (w = 0): the first non-zero of x, y, z is positive, as scipy's canonical form
    for axis in np.eye(3):
        Rh = 2 * np.outer(axis, axis) - np.eye(3)
        assert np.array_equal(lie.to_quaternion(Rh), np.concatenate([[0.0], axis]))


def test_from_quaternion_matches_scipy_and_normalises():
    q = rng.normal(size=(100, 4)) * 10.0 ** rng.uniform(-5, 5, size=(100, 1))
    R = lie.from_quaternion(q)
    assert R.shape == (100, 3, 3)
    ref = Rotation.from_quat(q, scalar_first=True).as_matrix()
    assert np.allclose(R, ref, atol=1e-15)
    assert np.allclose(lie.from_quaternion(q[:, [1, 2, 3, 0]], scalar_first=False), R, atol=0)
    assert np.allclose(lie.from_quaternion(-q), R, atol=1e-15)      # q and −q
    # any finite scale, including 1e300 and 1e-300
    for s in (1e300, 1e-300, -1e200):
        assert np.allclose(lie.from_quaternion(q[0] * s), R[0], atol=1e-15)


def test_quaternion_round_trips():
    R = random_rotations(100)
    assert np.allclose(lie.from_quaternion(lie.to_quaternion(R)), R, atol=1e-15)
    q = rng.normal(size=(100, 4))
    qn = q / np.linalg.norm(q, axis=-1, keepdims=True)
    qn *= np.where(qn[:, :1] < 0, -1, 1)
    assert np.allclose(lie.to_quaternion(lie.from_quaternion(q)), qn, atol=1e-15)


# ---------------------------------------------------------------- Euler angles


@pytest.mark.parametrize("seq", SEQS)
def test_to_euler_matches_scipy(seq):
    R = random_rotations(200)
    a = lie.to_euler(R, seq)
    assert a.shape == (200, 3)
    ref = scipy_euler(R, seq)
    assert np.allclose(angle_diff(a, ref), 0, atol=1e-12)
    # ranges (scipy's)
    assert np.all(np.abs(a[:, [0, 2]]) <= np.pi)
    if seq[0].lower() == seq[2].lower():
        assert np.all((a[:, 1] >= 0) & (a[:, 1] <= np.pi))
    else:
        assert np.all(np.abs(a[:, 1]) <= np.pi / 2)
    # round trip R → angles → R
    assert np.allclose(lie.from_euler(a, seq), R, atol=1e-13)


@pytest.mark.parametrize("seq", SEQS)
def test_from_euler_matches_scipy(seq):
    angles = rng.uniform(-7, 7, size=(100, 3))       # any values, not only the principal range
    R = lie.from_euler(angles, seq)
    assert np.allclose(R, Rotation.from_euler(seq, angles).as_matrix(), atol=1e-15)


@pytest.mark.parametrize("seq", SEQS)
def test_gimbal_lock_like_scipy(seq):
    proper = seq[0].lower() == seq[2].lower()
    middles = [0.0, np.pi] if proper else [np.pi / 2, -np.pi / 2]
    for b in middles:
        for inside in (0.0, 3e-8):      # exactly at the lock, and inside scipy's 1e-7 band
            ang = np.array([[0.3, b + inside * (1 if b <= 0 else -1), 0.5],
                            [-2.0, b, 2.9], [np.pi, b, 0.0]])
            R = lie.from_euler(ang, seq)
            a = lie.to_euler(R, seq)
            assert np.all(np.isfinite(a))
            assert np.array_equal(a[:, 2], np.zeros(3)), a        # the third angle is zero
            with pytest.warns(UserWarning, match="Gimbal lock"):
                ref = Rotation.from_matrix(R).as_euler(seq)
            assert np.allclose(angle_diff(a, ref), 0, atol=1e-12)
            atol = 1e-14 if inside == 0 else 1e-6
            assert np.allclose(lie.from_euler(a, seq), R, atol=atol)


def test_no_warning_at_gimbal_lock():
    R = lie.from_euler([0.3, np.pi / 2, 0.5], "xyz")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lie.to_euler(R, "xyz")


def test_intrinsic_is_extrinsic_reversed():
    angles = rng.uniform(-3, 3, size=(50, 3))
    assert np.allclose(lie.from_euler(angles, "XYZ"), lie.from_euler(angles[:, ::-1], "zyx"),
                       atol=1e-15)
    R = random_rotations(50)
    assert np.allclose(angle_diff(lie.to_euler(R, "XYZ"), lie.to_euler(R, "zyx")[:, ::-1]), 0,
                       atol=1e-13)
    # XYZ intrinsic is Rx @ Ry @ Rz
    a, b, c = 0.4, -1.1, 2.7
    Rx, Ry, Rz = (lie.so3_exp(t * e) for t, e in zip((a, b, c), np.eye(3)))
    assert np.allclose(lie.from_euler([a, b, c], "XYZ"), Rx @ Ry @ Rz, atol=1e-15)
    assert np.allclose(lie.from_euler([a, b, c], "xyz"), Rz @ Ry @ Rx, atol=1e-15)


# ---------------------------------------------------------------- shapes, scipy objects


def test_leading_axes_and_single_items():
    R = random_rotations(2, 3, 4)
    q = lie.to_quaternion(R)
    assert q.shape == (2, 3, 4, 4)
    assert np.array_equal(q[1, 2, 3], lie.to_quaternion(R[1, 2, 3]))
    assert lie.from_quaternion(q).shape == (2, 3, 4, 3, 3)
    a = lie.to_euler(R, "ZXZ")
    assert a.shape == (2, 3, 4, 3)
    assert lie.from_euler(a, "ZXZ").shape == (2, 3, 4, 3, 3)
    assert lie.to_quaternion(np.zeros((0, 3, 3))).shape == (0, 4)
    assert lie.from_euler(np.zeros((0, 3)), "xyz").shape == (0, 3, 3)
    # array-likes (nested lists, ints)
    assert np.allclose(lie.from_quaternion([1, 0, 0, 0]), np.eye(3))
    assert np.allclose(lie.to_euler(np.eye(3).tolist(), "xyz"), 0)


def test_to_scipy_and_from_scipy():
    R = random_rotations(20)
    rot = lie.to_scipy(R)
    assert isinstance(rot, Rotation) and len(rot) == 20
    assert np.allclose(rot.as_matrix(), R, atol=1e-15)
    assert np.allclose(lie.from_scipy(rot), R, atol=1e-15)
    one = lie.to_scipy(R[0])
    assert one.single and np.allclose(lie.from_scipy(one), R[0], atol=1e-15)
    assert lie.from_scipy(one).shape == (3, 3)
    ref = Rotation.random(7, rng=np.random.default_rng(1))
    assert np.allclose(lie.from_scipy(ref), ref.as_matrix(), atol=1e-15)
    assert np.allclose(lie.to_quaternion(lie.from_scipy(ref)), ref.as_quat(canonical=True,
                       scalar_first=True), atol=1e-15)
    assert lie.from_scipy(lie.to_scipy(np.zeros((0, 3, 3)))).shape == (0, 3, 3)
    assert set(["to_scipy", "from_scipy", "to_quaternion", "from_quaternion", "to_euler",
                "from_euler"]) <= set(lie.__all__)


def test_scipy_missing_is_an_import_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy.spatial.transform", None)
    with pytest.raises(ImportError, match="needs scipy"):
        lie.to_scipy(np.eye(3))
    with pytest.raises(ImportError, match="needs scipy"):
        lie.from_scipy(object())
    # the native conversions need no scipy
    assert np.allclose(lie.from_quaternion([1, 0, 0, 0]), np.eye(3))


# ---------------------------------------------------------------- errors


def test_typed_errors():
    R = random_rotations(3)
    with pytest.raises(lf.ShapeError):
        lie.to_quaternion(np.eye(4))
    with pytest.raises(lf.ShapeError):
        lie.to_euler(np.eye(3)[:, :2], "xyz")
    with pytest.raises(lf.ShapeError):
        lie.from_quaternion([1.0, 0.0, 0.0])
    with pytest.raises(lf.ShapeError):
        lie.from_euler([0.1, 0.2], "xyz")
    bad = R.copy()
    bad[1] *= 2.0
    with pytest.raises(lf.NotInGroupError):
        lie.to_quaternion(bad)
    with pytest.raises(lf.NotInGroupError):
        lie.to_euler(np.diag([-1.0, 1.0, 1.0]), "xyz")
    with pytest.raises(lf.NotInGroupError):
        lie.to_scipy(2 * np.eye(3))
    with pytest.raises(lf.NonFiniteError):
        lie.from_quaternion([1.0, np.nan, 0.0, 0.0])
    with pytest.raises(lf.NonFiniteError):
        lie.from_euler([0.1, np.inf, 0.0], "xyz")
    with pytest.raises(lf.InvalidArgumentError, match="zero quaternion"):
        lie.from_quaternion(np.zeros(4))
    with pytest.raises(lf.InvalidArgumentError, match="from_euler"):
        lie.from_euler([1e300, 0.0, 0.0], "xyz")
    for seq in ["", "xy", "xyzx", "xxy", "xYz", "abc", "XY Z", "xyz "]:
        with pytest.raises(lf.InvalidArgumentError, match="proper-Euler"):
            lie.to_euler(R, seq)
        with pytest.raises(lf.InvalidArgumentError, match="Tait–Bryan"):
            lie.from_euler([0.1, 0.2, 0.3], seq)
    with pytest.raises(TypeError, match="seq"):
        lie.to_euler(R, 3)
    with pytest.raises(lf.ArgumentTypeError, match="rotation"):
        lie.from_scipy(np.eye(3))
    with pytest.raises(lf.ArgumentTypeError):
        lie.to_quaternion(np.eye(3) + 0.5j)
