"""Hardening of the Python boundary (issue 16): one guard per class of bad input.

- array arguments (`ArrayIn`, crates/py/src/convert.rs): real numbers only, a TypeError otherwise;
- output and input buffers of mapped/batched calls (`lieflow::check::zeros`): refused with an
  InvalidArgumentError naming the argument and the size instead of aborting the process;
- `lf.integrate` arguments (python/lieflow/integrate.py): TypeError for wrong types;
- states on SO(3)/S² and constructor sizes (core checks): no NaN, no non-rotation, no Γ = 0.
"""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lieflow as lf

BAD_ARRAYS = [
    pytest.param(np.array([1 + 2j, 0, 0]), "dtype complex128", id="complex-array"),
    pytest.param([1j, 0, 0], "dtype complex128", id="complex-list"),
    pytest.param(np.array(["2020-01-01"] * 3, dtype="datetime64[D]"), "datetime64", id="datetime"),
    pytest.param(np.zeros(3, dtype="m8[s]"), "timedelta64", id="timedelta"),
    pytest.param("abc", "got a str", id="str"),
    pytest.param(b"abc", "got a bytes", id="bytes"),
    pytest.param(np.array(["1", "2", "3"]), "dtype <U1", id="str-array"),
    pytest.param(np.array([1.0, 2.0, 3.0], dtype=object), "dtype object", id="object-array"),
    pytest.param([1.0, None, 3.0], "ragged or holds non-numbers", id="list-with-None"),
    pytest.param([[1.0, 2.0], [3.0]], "cannot read as an array", id="ragged"),
    pytest.param(None, "got None", id="None"),
]


def _named(exc, name):
    """pyo3 names the argument in a note (Python >= 3.11 keeps notes on exceptions), which
    ArgumentTypeError's message repeats."""
    if sys.version_info < (3, 11):
        return True
    return (f"while processing '{name}'" in exc.__notes__
            and str(exc).startswith(f"argument '{name}': expected"))


@pytest.mark.parametrize("bad, came", BAD_ARRAYS)
def test_array_arguments_accept_real_numbers_only(bad, came):
    calls = [
        ("w", lambda: lf.lie.so3_exp(bad)),                             # batched (batch.rs)
        ("states", lambda: lf.RigidBody([1, 2, 3]).energy(bad)),         # mapped (items.rs)
        ("X", lambda: lf.pseudo_rigid.bi_inertia(bad)),                  # a matrix (convert::mat)
        ("xi", lambda: lf.lie.so_exp(bad)),                              # so(n) batches
        ("Gamma", lambda: lf.HeavyTop([1, 2, 3], 1.0).state([1, 2, 3], Gamma=bad)),
    ]
    for name, call in calls:
        if bad is None and name == "Gamma":
            continue                     # an optional argument: None means "not given"
        with pytest.raises(TypeError, match="expected an array-like of real numbers") as info:
            call()
        assert came in str(info.value), (name, str(info.value))
        assert not isinstance(info.value, ValueError)
        assert isinstance(info.value, lf.ArgumentTypeError)
        assert _named(info.value, name), (name, str(info.value))


@pytest.mark.parametrize("good", [
    [True, False, False], np.array([1, 0, 0], dtype=np.int32), np.array([1, 0, 0], np.uint8),
    np.array([1, 0, 0], np.float32), np.array([1, 0, 0], np.float16), (1, 0, 0),
    np.array([1.0, 0, 0], dtype=">f8"), np.array([1.0, 9.0, 0, 9.0, 0, 9.0])[::2],
])
def test_real_array_likes_are_cast_to_float64(good):
    np.testing.assert_array_equal(lf.lie.so3_exp(good), lf.lie.so3_exp(np.array([1.0, 0, 0])))


def test_scalars_and_0d_arrays_still_work():
    assert lf.elliptic.ellipj(0.3, 0.5) == lf.elliptic.ellipj(np.float64(0.3), np.float32(0.5))
    assert np.allclose(lf.elliptic.ellipj(np.array(0.3), False), lf.elliptic.ellipj(0.3, 0.0))
    with pytest.raises(TypeError, match="complex"):
        lf.elliptic.ellipj(0.3 + 0j, 0.5)


# ------------------------------------------------- allocation: subprocesses, so an abort fails


def _run(code, memory=6 << 30):
    """Runs `code` in a child limited to `memory` bytes of address space (so that a regression
    fails the allocation instead of exhausting the machine); returns (returncode, stderr)."""
    prelude = textwrap.dedent(f"""
        import resource
        resource.setrlimit(resource.RLIMIT_AS, ({memory}, {memory}))
        import numpy as np, lieflow as lf
    """)
    p = subprocess.run([sys.executable, "-c", prelude + textwrap.dedent(code)],
                       capture_output=True, text=True, timeout=120)
    return p.returncode, p.stderr


HUGE = {
    "so3_exp": ("lf.lie.so3_exp(np.broadcast_to(np.zeros(3), (10**10, 3)))", "w"),
    "so_exp": ("lf.lie.so_exp(np.broadcast_to(np.zeros((3, 3)), (10**10, 3, 3)))", "xi"),
    "se3_compose": ("lf.lie.se3_compose(np.eye(4), np.broadcast_to(np.eye(4), (10**10, 4, 4)))",
                    "h"),
    "hat_n": ("lf.lie.hat_n(np.broadcast_to(np.zeros(3), (10**10, 3)))", "c"),
    "energy": ("lf.RigidBody([1, 2, 3]).energy(np.broadcast_to(np.ones(3), (10**10, 3)))",
               "states"),
    "spatial_momentum": ("lf.RigidBody([1, 2, 3]).spatial_momentum(np.ones(3), "
                         "np.broadcast_to(np.eye(3), (10**10, 3, 3)))", "states, attitude"),
    "ellipj": ("lf.elliptic.ellipj(np.broadcast_to(np.zeros(1), (10**11,)), 0.5)", "u, m"),
    "GeneralizedRigidBody": ("lf.GeneralizedRigidBody(np.ones(10**5))", "J"),
    "PseudoRigidBody": ("lf.PseudoRigidBody(10**5)", "n"),
    "integrate_batch": ("lf.integrate(lf.RigidBody([1, 2, 3]), "
                        "np.broadcast_to(np.ones(3), (10**10, 3)), dt=0.01, steps=1)", "state0"),
    "run_steps": ("lf.RigidBody([1, 2, 3])._run(np.ones((1, 3)), None, 0.01, 10**12, 1, None)",
                  "steps"),
}


@pytest.mark.parametrize("name", HUGE)
def test_oversized_outputs_are_refused_not_aborted(name):
    code, arg = HUGE[name]
    rc, err = _run(f"""
        try:
            {code}
        except lf.InvalidArgumentError as e:
            print(e, file=__import__("sys").stderr)
            raise SystemExit(3)
    """)
    assert rc == 3, err[-2000:]          # an abort is rc -6, a kill -9, a panic rc 1
    assert _names(err, arg) and ("exceed" in err or "memory" in err or "allocate" in err), err


def _names(err, arg):
    """The error names the argument: "invalid a, b:" from a mapped function, or "invalid argument
    'a'" when the size is refused while the argument is read."""
    return f"invalid {arg}:" in err or any(f"invalid argument '{a}'" in err
                                           for a in arg.split(", "))


def test_oversized_within_the_cap_is_refused_by_memory():
    """3·10⁹ floats (22 GiB) is within the entry cap: the allocation itself must fail cleanly
    (here under a 6 GiB address-space limit; without one, by the available-memory check)."""
    rc, err = _run("""
        try:
            lf.lie.hat_n(np.broadcast_to(np.zeros(3), (10**9, 3)))
        except lf.InvalidArgumentError as e:
            print(e, file=__import__("sys").stderr)
            raise SystemExit(3)
    """)
    assert rc == 3 and _names(err, "c"), err[-2000:]


# ------------------------------------------------------------ lf.integrate's own arguments


@pytest.fixture
def body():
    return lf.RigidBody([1, 2, 3])


@pytest.mark.parametrize("system, match", [
    ("rb", "expected a lieflow system"),
    (None, "expected a lieflow system"),
    (np.zeros(3), "expected a lieflow system"),
    (lf.RigidBody, "got the class RigidBody"),
])
def test_integrate_wants_a_system(system, match):
    with pytest.raises(TypeError, match=match):
        lf.integrate(system, [1, 0.5, -0.3], dt=0.01, steps=2)


@pytest.mark.parametrize("kw, name", [
    (dict(dt="0.01"), "dt"), (dict(dt=b"1"), "dt"), (dict(dt=[0.01]), "dt"),
    (dict(dt=0.01j), "dt"), (dict(dt=True), "dt"), (dict(dt=None), "dt"),
    (dict(steps="3"), "steps"), (dict(steps=3.0), "steps"), (dict(steps=None), "steps"),
    (dict(steps=np.float64(3)), "steps"), (dict(save_every="1"), "save_every"),
    (dict(save_every=1.5), "save_every"), (dict(chunk_steps="10"), "chunk_steps"),
    (dict(threads=2.0), "threads"), (dict(method=b"rk4"), "method"),
])
def test_integrate_argument_types(body, kw, name):
    args = dict(dt=0.01, steps=3) | kw
    with pytest.raises(TypeError, match=f"invalid {name}"):
        lf.integrate(body, [1, 0.5, -0.3], **args)


def test_integrate_accepts_numpy_numbers(body):
    tr = lf.integrate(body, [1, 0.5, -0.3], dt=np.float32(0.01), steps=np.int64(4),
                      save_every=np.uint8(2))
    assert tr.states.shape == (3, 3) and tr.dt == pytest.approx(0.01)
    tr = lf.integrate(body, [1, 0.5, -0.3], dt=np.array(0.01), steps=2)
    assert tr.t[-1] == pytest.approx(0.02)


# ------------------------------------------------------- states on SO(3) and S², sizes of n


@pytest.fixture
def top():
    return lf.HeavyTop([1, 2, 3], 1.0)


@pytest.mark.parametrize("kw, exc, match", [
    (dict(Gamma=[0, 0, np.nan]), lf.NonFiniteError, "non-finite"),
    (dict(Gamma=[0, 0, 0]), lf.InvalidArgumentError, "Γ = 0"),
    (dict(attitude=np.full((3, 3), np.nan)), lf.NonFiniteError, "attitude"),
    (dict(attitude=np.zeros((3, 3))), lf.NotInGroupError, "attitude is not in SO"),
    (dict(attitude=2 * np.eye(3)), lf.NotInGroupError, "attitude is not in SO"),
    (dict(attitude=np.diag([1.0, 1.0, -1.0])), lf.NotInGroupError, "det"),
    (dict(attitude=np.stack([np.eye(3), np.zeros((3, 3))])), lf.NotInGroupError, "attitude"),
])
def test_heavy_top_state_refuses_what_integrate_refuses(top, kw, exc, match):
    with pytest.raises(exc, match=match):
        top.state([1.0, 2.0, 3.0], **kw)


def test_heavy_top_state_accepts_rotations(top):
    r = lf.lie.so3_exp([0.3, -0.2, 0.5])
    np.testing.assert_array_equal(top.state([1, 2, 3], attitude=r), np.r_[1, 2, 3, r[2]])
    np.testing.assert_array_equal(top.state([1, 2, 3], Gamma=[0, 0, 2.0]), [1, 2, 3, 0, 0, 2])


def test_integrate_heavy_top_refuses_gamma_zero(top):
    with pytest.raises(lf.InvalidArgumentError, match="Γ = 0"):
        lf.integrate(top, ([1.0, 0.5, -0.3], [0.0, 0.0, 0.0]), dt=0.01, steps=2)
    with pytest.raises(lf.InvalidArgumentError, match="batch member 1"):
        lf.integrate(top, np.array([[1, 0.5, -0.3, 0, 0, 1], [1, 0.5, -0.3, 0, 0, 0.0]]),
                     dt=0.01, steps=2)


@pytest.mark.parametrize("attitude, exc", [
    (np.full((3, 3), np.nan), lf.NonFiniteError), (np.zeros((3, 3)), lf.NotInGroupError),
    (2 * np.eye(3), lf.NotInGroupError), (np.diag([1.0, 1.0, -1.0]), lf.NotInGroupError),
    (np.eye(3) * 1j, TypeError), ([[1, 0, 0], [0, 1]], TypeError), ("abc", TypeError),
])
def test_integrate_attitude_must_be_a_rotation(attitude, exc):
    with pytest.raises(exc):
        lf.integrate(lf.RigidBody([1, 2, 3]), [1, 0.5, -0.3], dt=0.01, steps=2, attitude=attitude)


@pytest.mark.parametrize("system, M", [(lf.RigidBody([1, 2, 3]), [1.0, 2.0, 3.0]),
                                       (lf.HeavyTop([1, 2, 3], 1.0), [1.0, 2, 3, 0, 0, 1])])
def test_spatial_momentum_needs_a_rotation(system, M):
    for bad, exc in [(2 * np.eye(3), lf.NotInGroupError), (np.zeros((3, 3)), lf.NotInGroupError),
                     (np.diag([1.0, 1.0, -1.0]), lf.NotInGroupError),
                     (np.full((3, 3), np.nan), lf.NonFiniteError)]:
        with pytest.raises(exc):
            system.spatial_momentum(M, bad)
    r = lf.lie.so3_exp([0.3, -0.2, 0.5])
    np.testing.assert_allclose(system.spatial_momentum(M, r), r @ np.asarray(M)[:3], atol=1e-15)


def test_spatial_momentum_reads_drifted_rk4_attitudes():
    """rk4 does not keep SO(3): its attitudes drift (~1e-6 here) and observables still read them."""
    body = lf.RigidBody([1, 2, 3])
    tr = lf.integrate(body, [1, 0.5, -0.3], dt=0.05, steps=20000, save_every=1000, method="rk4",
                      attitude=np.eye(3))
    drift = np.linalg.norm(tr.attitude[-1].T @ tr.attitude[-1] - np.eye(3))
    assert 1e-10 < drift < 1e-3
    assert tr.spatial_momentum().shape == (21, 3)


@pytest.mark.parametrize("call", [
    lambda: lf.pseudo_rigid.bi_inertia(np.eye(1)),
    lambda: lf.pseudo_rigid.bi_connection(np.eye(1), np.eye(1)),
    lambda: lf.pseudo_rigid.locked_inertia(np.eye(1)),
    lambda: lf.pseudo_rigid.bi_inertia_eigen(np.eye(1)),
])
def test_pseudo_rigid_needs_n_at_least_2(call):
    with pytest.raises(lf.ShapeError, match="n ≥ 2"):
        call()


def test_int_broadcast_views_are_refused_before_the_float64_copy():
    """A non-float64 array is copied to float64: that copy is checked like every buffer."""
    rc, err = _run("""
        try:
            lf.lie.so3_exp(np.broadcast_to(np.zeros(3, dtype=np.int64), (10**10, 3)))
        except lf.InvalidArgumentError as e:
            print(e, e.__notes__, file=__import__("sys").stderr)
            raise SystemExit(3)
    """)
    assert rc == 3 and "exceeds" in err and "while processing 'w'" in err, err[-2000:]


@pytest.mark.parametrize("kw", [dict(steps=10**12), dict(steps=2**62, save_every=7)])
def test_trajectories_that_cannot_be_kept_are_refused_before_running(kw):
    rc, err = _run(f"""
        try:
            lf.integrate(lf.RigidBody([1, 2, 3]), [1, .5, -.3], dt=0.01, **{kw!r})
        except lf.InvalidArgumentError as e:
            print(e, file=__import__("sys").stderr)
            raise SystemExit(3)
    """)
    assert rc == 3 and "invalid steps: the" in err, err[-2000:]


@pytest.mark.parametrize("name", ["steps", "save_every", "chunk_steps", "threads"])
def test_integrate_counts_beyond_64_bits(body, name):
    with pytest.raises(lf.InvalidArgumentError, match=f"invalid {name}: .*2\\*\\*63"):
        lf.integrate(body, [1, 0.5, -0.3], **(dict(dt=0.01, steps=3) | {name: 2**70}))


@pytest.mark.parametrize("call, name", [
    (lambda: lf.RigidBody(np.array([1, 2, 3j])), "inertia"),
    (lambda: lf.GeneralizedRigidBody("abc"), "J"),
    (lambda: lf.integrate(lf.RigidBody([1, 2, 3]), "abc", dt=0.01, steps=2), "state0"),
    (lambda: lf.integrate(lf.HeavyTop([1, 2, 3], 1.0), ([1, 2, 3], [0, 0, 1j]), dt=0.01,
                          steps=2), "Gamma"),
])
def test_arrays_read_inside_a_call_are_named_too(call, name):
    with pytest.raises(lf.ArgumentTypeError) as info:
        call()
    assert _named(info.value, name), str(info.value)


def test_huge_multiples_of_rotations_are_not_rotations():
    """RᵀR overflows to NaN off the diagonal for 1e160·R: NaN is a defect, not a pass."""
    r = 1e160 * lf.lie.so3_exp([0.1, 0.2, 0.3])
    with pytest.raises(lf.NotInGroupError):
        lf.integrate(lf.RigidBody([1, 2, 3]), [1, 0.5, -0.3], dt=0.01, steps=2, attitude=r)
    with pytest.raises(lf.NotInGroupError):
        lf.HeavyTop([1, 2, 3], 1.0).state([1, 2, 3], attitude=r)
    with pytest.raises(lf.NotInGroupError):
        lf.RigidBody([1, 2, 3]).spatial_momentum([1, 2, 3], r)


# --- numbers and small fixed-size arrays (convert.rs: Real, Reals, RealMatrix, Int) ---

def _sphere_body():
    return lf.RollingSpheres(0.7, 1.3, [0.1, -0.2, 0.15], [-0.3, 0.2, 0.4], 2.0, 3.5,
                             np.diag([1.0, 1.2, 1.4]), np.diag([2.0, 2.1, 2.2]))


COMPLEX_SCALARS = [
    pytest.param(np.complex128(1 + 1j), id="np.complex128"),
    pytest.param(np.complex64(1 + 1j), id="np.complex64"),
    pytest.param(np.array(1 + 1j), id="0-d-complex"),
    pytest.param(1 + 1j, id="complex"),
    pytest.param(1 + 0j, id="complex-0j"),
]


@pytest.mark.parametrize("z", COMPLEX_SCALARS)
@pytest.mark.parametrize("call, name", [
    (lambda z: lf.TangentTop(lf.surfaces.Plane(), z, 1.0), "mass"),
    (lambda z: lf.HeavyTop([1, 2, 3], z), "mgl"),
    (lambda z: lf.surfaces.Sphere(z), "radius"),
    (lambda z: lf.lie.is_rotation(np.eye(3), tol=z), "tol"),
    (lambda z: lf.potentials.Harmonic(z), "k"),
])
def test_real_parameters_refuse_complex_numbers(z, call, name):
    with pytest.raises(lf.ArgumentTypeError, match="expected a real number") as info:
        call(z)
    assert _named(info.value, name) or sys.version_info < (3, 11) or (
        str(info.value).startswith(f"argument '{name}'")), str(info.value)


@pytest.mark.parametrize("bad, exc", [
    ("1.0", lf.ArgumentTypeError), (b"1", lf.ArgumentTypeError), (None, lf.ArgumentTypeError),
    (np.array([1.0, 2.0]), lf.ArgumentTypeError), (np.datetime64("2020-01-01"), lf.ArgumentTypeError),
    (10**400, lf.InvalidArgumentError),
])
def test_real_parameters_refuse_non_numbers(bad, exc):
    with pytest.raises(exc) as info:
        lf.surfaces.Sphere(bad)
    assert "radius" in str(info.value), str(info.value)


@pytest.mark.parametrize("good", [2.0, 2, np.float32(2.0), np.int64(2), np.array(2.0), np.float64(2)])
def test_real_parameters_accept_real_numbers(good):
    assert lf.surfaces.Sphere(good).metric([1.0, 0.3]).shape == (2, 2)


@pytest.mark.parametrize("x", [np.array([1.0 + 1j, 0.3]), [1j, 0.3], "ab", b"ab", None])
def test_fixed_size_points_refuse_non_reals(x):
    with pytest.raises(lf.ArgumentTypeError) as info:
        lf.surfaces.Sphere(1.0).metric(x)
    assert _named(info.value, "x"), str(info.value)


@pytest.mark.parametrize("x", [[], [1.0], [1.0, 0.3, 0.2], np.zeros((1, 2)), np.zeros((0, 2))])
def test_fixed_size_points_of_the_wrong_length_are_shape_errors_naming_the_argument(x):
    with pytest.raises(lf.ShapeError) as info:
        lf.surfaces.Plane().metric(x=x)
    if sys.version_info >= (3, 11):
        assert str(info.value).startswith("argument 'x' has the wrong shape: expected (2,)"), \
            str(info.value)


def test_fixed_size_vectors_and_matrices_refuse_complex():
    with pytest.raises(lf.ArgumentTypeError) as info:
        lf.RollingSpheres(0.7, 1.3, [0.1, -0.2, 0.15j], [-0.3, 0.2, 0.4], 2.0, 3.5,
                          np.eye(3), np.eye(3))
    assert _named(info.value, "gamma1"), str(info.value)
    s = _sphere_body()
    with pytest.raises(lf.ArgumentTypeError) as info:
        s.state(np.eye(3) + 0j * np.eye(3) + 1e-3j, np.eye(3), [0, 0, 1], [1, 0, 0], [0, 1, 0])
    assert _named(info.value, "z1"), str(info.value)
    with pytest.raises(lf.ShapeError, match="z2"):
        s.state(np.eye(3), np.eye(2), [0, 0, 1], [1, 0, 0], [0, 1, 0])


def test_rolling_disks_points_may_be_complex_but_not_anything():
    args = dict(r1=1.0, r2=0.5, m1=1.0, m2=2.0, inertia1=0.7, inertia2=0.3)
    a = lf.RollingDisks(gamma1=0.1 + 0.2j, gamma2=[0.0, -0.1], **args)
    b = lf.RollingDisks(gamma1=[0.1, 0.2], gamma2=np.complex128(-0.1j), **args)
    assert a.state([0.1, 0.2], [0.3, 0.4]) == pytest.approx(b.state([0.1, 0.2], [0.3, 0.4]))
    for bad in (np.zeros((0, 2)), np.array(["1", "2"]), [[0.1, 0.2]]):
        with pytest.raises((lf.ShapeError, lf.ArgumentTypeError)) as info:
            lf.RollingDisks(gamma1=[0.1, 0.2], gamma2=bad, **args)
        assert "gamma2" in str(info.value) + " ".join(getattr(info.value, "__notes__", [])), \
            str(info.value)


@pytest.mark.parametrize("n, exc", [(2**70, lf.InvalidArgumentError), (-(2**70), lf.InvalidArgumentError),
                                    (2.5, lf.ArgumentTypeError), (float("nan"), lf.ArgumentTypeError),
                                    ("3", lf.ArgumentTypeError)])
def test_integer_parameters_out_of_range_or_not_ints(n, exc):
    with pytest.raises(exc) as info:
        lf.PseudoRigidBody(n)
    if sys.version_info >= (3, 11):
        assert "argument 'n'" in str(info.value), str(info.value)


def test_integer_parameters_accept_numpy_ints():
    assert lf.PseudoRigidBody(np.int64(3)).state_dim == lf.PseudoRigidBody(3).state_dim


# --- input size before any cast or copy (ArrayIn) ---

@pytest.mark.parametrize("dtype", [float, np.float32, int, ">f8"])
@pytest.mark.parametrize("fn, base", [
    (lambda a: lf.lie.hat_n(a), np.zeros(6)), (lambda a: lf.lie.so3_exp(a), np.zeros(3)),
    (lambda a: lf.lie.so3_cayley(a), np.zeros(3)), (lambda a: lf.lie.so_exp(a), np.zeros((3, 3))),
    (lambda a: lf.lie.se3_compose(a, np.eye(4)), np.eye(4)),
])
def test_broadcast_inputs_are_size_checked_before_any_copy(fn, base, dtype):
    a = np.broadcast_to(base.astype(dtype), (10**10,) + base.shape)
    with pytest.raises(lf.InvalidArgumentError, match="exceeds the limit"):
        fn(a)


def test_a_float64_strided_view_is_borrowed_not_copied():
    big = np.zeros((4, 3, 2))
    big[..., 0] = [[0.1, 0.2, 0.3]] * 4
    view = big[..., 0]
    assert not view.flags.c_contiguous
    assert np.allclose(lf.lie.so3_exp(view), lf.lie.so3_exp(np.ascontiguousarray(view)))


# --- no silent NaN from finite input: the last line of defence of vectorised results ---

def test_vectorised_results_are_never_non_finite_for_finite_input():
    body = _sphere_body()
    with pytest.raises(lf.LieflowError):
        body.angular_momentum(np.full(body.state_dim, 1.7e308))


def test_legitimate_infinity_is_not_refused():
    eqs = lf.RollingDisks(1.0, 0.5, 0.1 + 0.2j, -0.1j, 1.0, 2.0, 0.7, 0.3).relative_equilibria()
    for e in eqs:
        lo, hi = e.angular_velocity_range
        assert lo <= hi


# --- small accepted-bad cases ---

def _inside(x1, x2):
    return 0.0 < x1 < np.pi


def _sphere_metric(x1, x2):
    return np.diag([1.0, np.sin(x1) ** 2])


def _sphere_frame(x1, x2):
    return np.diag([1.0, 1.0 / np.sin(x1)])


@pytest.mark.parametrize("ret", ["yes", float("nan"), 1.0, [True], None])
def test_metric_surface_domain_must_return_a_bool(ret):
    s = lf.surfaces.MetricSurface(_sphere_metric, _sphere_frame, lambda x1, x2: ret)
    with pytest.raises(TypeError, match="domain.*must return a bool"):
        s.metric([1.0, 0.3])


@pytest.mark.parametrize("ret", [True, np.bool_(True)])
def test_metric_surface_domain_bools_work(ret):
    s = lf.surfaces.MetricSurface(_sphere_metric, _sphere_frame, lambda x1, x2: ret)
    assert s.metric([1.0, 0.3]).shape == (2, 2)
    s = lf.surfaces.MetricSurface(_sphere_metric, _sphere_frame, lambda x1, x2: np.bool_(False))
    with pytest.raises(lf.InvalidArgumentError):
        s.metric([1.0, 0.3])


@pytest.mark.parametrize("k", [3, 4, 5])
def test_heavy_top_spatial_momentum_checks_the_whole_state(k):
    z = np.array([1.0, 2.0, 3.0, 0.0, 0.0, 1.0])
    z[k] = -np.inf
    with pytest.raises(lf.NonFiniteError, match="states"):
        lf.HeavyTop([1, 2, 3], 1.0).spatial_momentum(z, np.eye(3))


@pytest.mark.parametrize("tol", [float("nan"), float("inf"), -1e-9])
def test_rolling_spheres_to_planar_refuses_bad_tolerances(tol):
    s = _sphere_body()
    z = s.planar_state([0.1, 0.2], 0.3, [0.4, 0.5])
    assert len(s.to_planar(z)) == 5
    with pytest.raises(lf.InvalidArgumentError, match="tol"):
        s.to_planar(z, tol=tol)


def test_relative_equilibria_plane_must_be_a_pair():
    # a tuple of the wrong length gave pyo3's bare ValueError (found by the fuzz suite)
    with pytest.raises(lf.ShapeError, match="plane"):
        lf.pseudo_rigid.relative_equilibria(lf.potentials.Harmonic(1.0), shape=[3.0, 2.0, 1.0],
                                            plane=(0,))


def test_a_batch_whose_runs_do_not_fit_is_refused_not_aborted():
    # Each member of a relativistic top's batch holds a stepper of about 5 KiB, more than the
    # up-front estimate per member: under an address-space limit a batch of 10⁶ (≈ 5 GiB) used
    # to abort the process in an allocation. The memory its runs take is now watched as they are
    # built (check::BuildBudget, which also reads `ulimit -v`).
    code = (
        "import resource, numpy as np, lieflow as lf\n"
        "resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))\n"
        "top = lf.RelativisticTangentTop(1.0, 0.5)\n"
        "z = np.tile(top.state([0.1, 0.2], 0.0, [0.1, 0.0], 1.0), (10**6, 1))\n"
        "try:\n"
        "    lf.integrate(top, z, dt=0.01, steps=2)\n"
        "    print('ran')\n"
        "except lf.InvalidArgumentError as e:\n"
        "    print('refused:', e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.startswith("refused: invalid state0: the 1000000 members need about"), \
        out.stdout
