"""The one catalogue of bad values.

A Bad is (name, kinds it applies to, make(valid, arg) -> value, contract, flags):

  contract "refuse"   the call must raise (a typed error); returning normally is *accepted-bad*
           "neutral"  either a finite result or a typed error (no panic/abort/NaN/wrong type)
           "same"     the value means the same as the valid one: the result must equal the
                      valid call's (non-contiguous, Fortran-ordered, read-only, list input)
           "raise"    a Python callable that raises: its exception must come out unchanged
  risky    may allocate huge memory or run long: full tier only unless `quick`
  group    the issue-16 item an accepted-bad result of this value belongs to

Numeric fuzz (the hypothesis-style strategies): `numeric_variant(valid, arg, rng)` draws finite
values of the argument's kind at scales from 1e-300 to 1e300; the contract is "neutral", and a
non-finite result from these finite inputs is *silent NaN*.
"""

from __future__ import annotations

import datetime
import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

NUMERIC = ("vec", "bcast", "mat", "skew", "rot", "gl", "se3")
MATRIX = ("mat", "skew", "rot", "gl", "se3")
ANY = NUMERIC + ("float", "int", "str", "bool", "obj", "fn")
HUGE = 10**10          # virtual batch size of broadcast views: ~10^11 floats, never allocatable


@dataclass(frozen=True)
class Bad:
    name: str
    kinds: tuple
    make: Callable[[Any, Any], Any]
    contract: str = "refuse"
    group: str = "other"
    risky: bool = False
    quick: bool = True      # part of the quick tier's rotation


def arr(v):
    if isinstance(v, np.ndarray):
        return v.copy()
    a = np.array(v)
    return a if a.dtype.kind == "c" else a.astype(float)


def _one(v, x):
    a = arr(v)
    a = a.astype(complex if a.dtype.kind == "c" else float)
    if a.ndim == 0:
        return np.float64(x)
    a.flat[a.size // 2] = x
    return a


def _noncontig(v):
    a = arr(v)
    big = np.zeros(a.shape + (2,), dtype=a.dtype)
    big[..., 0] = a
    return big[..., 0]


def _ragged(v):
    a = arr(v)
    if a.ndim == 0:
        return [[1.0, 2.0], [3.0]]
    if a.ndim == 1:
        if a.size == 2:          # [[x], [y]] would be a regular (2, 1) array
            return [[a[0]], [a[1], a[1]]]
        return [list(a[:-1]), [a[-1]]] if a.size > 2 else [[1.0, 2.0], [3.0]]
    rows = a.tolist()
    rows[-1] = rows[-1][:-1]
    return rows


def _wrong_last(v):
    a = arr(v)
    if a.ndim == 0:
        return np.array([float(a), 1.0])
    if a.ndim >= 2 and a.shape[-1] == a.shape[-2]:
        return np.concatenate([a, np.ones(a.shape[:-1] + (1,))], axis=-1)   # not square
    return np.concatenate([a, np.ones(a.shape[:-1] + (1,))], axis=-1)


def _wrong_big_square(v):
    a = arr(v)
    n = a.shape[-1] + 2
    return np.eye(n) * 1.1


def _drop(v):
    a = arr(v)
    return a[..., 0] if a.ndim >= 1 else a


def _fn_nan(*a, **k):
    return float("nan")


def _fn_str(*a, **k):
    return "not a number"


class FuzzRaised(RuntimeError):
    """Raised by the fuzz suite's own Python callables: must come out of native code unchanged."""


def _fn_raise(*a, **k):
    raise FuzzRaised("raised by the fuzz callable")


def _fn_short(*a, **k):
    return [1.0]


def _huge_size(v, arg):
    a = arr(v)
    if arg.kind in MATRIX:
        n = 400
        return np.diag(np.arange(1.0, n + 1)) if arg.kind != "skew" else (
            np.triu(np.ones((n, n)), 1) - np.triu(np.ones((n, n)), 1).T)
    return np.ones(10**5)


def _not_rotation(v, arg):
    return 2.0 * np.eye(arr(v).shape[-1])


def _reflection(v, arg):
    a = arr(v).copy()
    a[..., :, 0] *= -1.0
    return a


def _near(v, arg):
    return arr(v) * (1.0 + 1e-3)


def _not_skew(v, arg):
    return arr(v) + np.eye(arr(v).shape[-1])


def _swap(v, arg):
    a = arr(v)
    return a[::-1].copy()


CATALOGUE: list[Bad] = [
    # non-finite
    Bad("nan", NUMERIC + ("float",), lambda v, a: _one(v, math.nan), group="accepted-nan"),
    Bad("inf", NUMERIC + ("float",), lambda v, a: _one(v, math.inf), group="accepted-nan"),
    Bad("-inf", NUMERIC + ("float",), lambda v, a: _one(v, -math.inf), group="accepted-nan"),
    # scales (finite: any NaN/inf out is silent NaN)
    Bad("x1e300", NUMERIC + ("float",), lambda v, a: arr(v) * 1e300, "neutral"),
    Bad("x1e160", NUMERIC + ("float",), lambda v, a: arr(v) * 1e160, "neutral"),
    Bad("x1e16", NUMERIC + ("float",), lambda v, a: arr(v) * 1e16, "neutral"),
    Bad("x1e-170", NUMERIC + ("float",), lambda v, a: arr(v) * 1e-170, "neutral"),
    Bad("x1e-300", NUMERIC + ("float",), lambda v, a: arr(v) * 1e-300, "neutral"),
    Bad("x1e-310", NUMERIC + ("float",), lambda v, a: arr(v) * 1e-310, "neutral"),
    Bad("max-float", NUMERIC + ("float",), lambda v, a: _one(v, 1.7976931348623157e308), "neutral"),
    Bad("zeros", NUMERIC, lambda v, a: np.zeros_like(arr(v)), "neutral"),
    Bad("negated", NUMERIC, lambda v, a: -arr(v), "neutral"),
    # dtypes
    Bad("complex", NUMERIC + ("float",), lambda v, a: arr(v) + 0.5j, group="accepted-complex"),
    Bad("complex-0j", NUMERIC + ("float",), lambda v, a: arr(v).astype(complex), "neutral"),
    Bad("datetime64", NUMERIC + ("float",), lambda v, a: np.full(arr(v).shape, np.datetime64(
        "2020-01-01", "s")), group="accepted-complex"),
    Bad("timedelta64", NUMERIC, lambda v, a: np.full(arr(v).shape, np.timedelta64(5, "s")),
        group="accepted-complex"),
    Bad("object-array", NUMERIC, lambda v, a: arr(v).astype(object), "neutral"),
    Bad("object-with-None", NUMERIC, lambda v, a: np.array(
        [None] + [0.0] * (max(arr(v).size, 1) - 1), dtype=object).reshape(arr(v).shape or ()),
        group="accepted-conversion"),
    Bad("bool-array", NUMERIC, lambda v, a: arr(v).astype(bool), "neutral"),
    Bad("float32", NUMERIC + ("float",), lambda v, a: arr(v).astype(np.float32), "neutral"),
    Bad("float16", NUMERIC, lambda v, a: arr(v).astype(np.float16), "neutral"),
    Bad("longdouble", NUMERIC, lambda v, a: arr(v).astype(np.longdouble), "neutral"),
    Bad("int-array", NUMERIC, lambda v, a: np.round(arr(v) * 10).astype(np.int64), "neutral"),
    Bad("str-array", NUMERIC, lambda v, a: arr(v).astype(str), group="accepted-conversion"),
    Bad("bytes", NUMERIC + ("float", "int", "str"), lambda v, a: b"1.0", group="accepted-conversion"),
    Bad("string", ANY, lambda v, a: "abc", group="accepted-conversion"),
    Bad("numeric-string", NUMERIC + ("float", "int"), lambda v, a: "0.01", group="accepted-str-scalar"),
    Bad("None", ANY + ("path",), lambda v, a: None, group="accepted-conversion"),
    Bad("object()", ANY + ("path",), lambda v, a: object(), group="accepted-conversion"),
    Bad("dict", NUMERIC + ("float", "int", "obj"), lambda v, a: {"a": 1.0}, group="accepted-conversion"),
    Bad("datetime", ("float", "int", "obj"), lambda v, a: datetime.datetime(2020, 1, 1),
        group="accepted-conversion"),
    # shapes
    Bad("ragged", NUMERIC, lambda v, a: _ragged(v), group="accepted-shape"),
    Bad("wrong-last-axis", NUMERIC, lambda v, a: _wrong_last(v), group="accepted-shape"),
    Bad("dropped-axis", NUMERIC, lambda v, a: _drop(v), group="accepted-shape"),
    Bad("extra-axis", NUMERIC, lambda v, a: arr(v)[..., None], group="accepted-shape"),
    Bad("bigger-square", MATRIX, lambda v, a: _wrong_big_square(v), "neutral"),
    Bad("empty", NUMERIC, lambda v, a: np.zeros(0), group="accepted-shape"),
    Bad("empty-batch", NUMERIC, lambda v, a: np.zeros((0,) + arr(v).shape), "neutral"),
    Bad("batch", NUMERIC, lambda v, a: np.stack([arr(v), arr(v)]), "neutral"),
    Bad("scalar", NUMERIC, lambda v, a: 1.0, group="accepted-shape"),
    Bad("array-for-scalar", ("float", "int"), lambda v, a: np.array([1.0, 2.0]),
        group="accepted-shape"),
    Bad("0-d-array", ("float",), lambda v, a: np.array(float(v)), "neutral"),
    Bad("list-1", ("float",), lambda v, a: [float(v)], "neutral"),
    # same values, other layouts: the result must equal the valid call's
    Bad("non-contiguous", NUMERIC, lambda v, a: _noncontig(v), "same"),
    Bad("fortran", NUMERIC, lambda v, a: np.asfortranarray(arr(v)) if arr(v).ndim >= 2 else arr(v),
        "same"),
    Bad("read-only", NUMERIC, lambda v, a: _readonly(v), "same"),
    Bad("list", NUMERIC, lambda v, a: arr(v).tolist(), "same"),
    Bad("np-float", ("float",), lambda v, a: np.float64(v), "same"),
    Bad("np-int", ("int",), lambda v, a: np.int64(v), "same"),
    # sizes: huge virtual sizes (nothing may be allocated for them), huge real sizes
    Bad("broadcast-1e10", NUMERIC, lambda v, a: np.broadcast_to(arr(v), (HUGE,) + arr(v).shape),
        group="abort-alloc", risky=True),
    Bad("broadcast-1e6", NUMERIC, lambda v, a: np.broadcast_to(arr(v), (10**6,) + arr(v).shape),
        "neutral", risky=True, quick=False),
    Bad("huge-size", NUMERIC, _huge_size, "neutral", risky=True, quick=False),
    Bad("n=60", ("gl", "mat"), lambda v, a: np.diag(np.arange(1.0, 61.0)), "neutral", risky=True,
        quick=False),
    # numbers of the wrong sort
    Bad("zero", ("float", "int"), lambda v, a: 0 if a.kind == "int" else 0.0, "refuse-if-positive",
        group="accepted-range"),
    Bad("negative", ("float", "int"), lambda v, a: -v if v else -1, "refuse-if-positive",
        group="accepted-range"),
    Bad("1e300", ("float",), lambda v, a: 1e300, "neutral"),
    Bad("1e-300", ("float",), lambda v, a: 1e-300, "neutral"),
    Bad("complex-scalar", ("float", "int"), lambda v, a: complex(v, 1.0), group="accepted-complex"),
    Bad("bool", ("float", "int"), lambda v, a: True, "neutral"),
    Bad("fraction", ("int",), lambda v, a: 2.5, group="accepted-conversion"),
    Bad("int-as-float", ("int",), lambda v, a: float(v), "neutral"),
    Bad("int-nan", ("int",), lambda v, a: math.nan, group="accepted-nan"),
    Bad("2**70", ("int",), lambda v, a: 2**70, group="accepted-range", risky=True),
    Bad("10**12", ("int",), lambda v, a: 10**12, "neutral", risky=True),
    Bad("-2**70", ("int",), lambda v, a: -(2**70), group="accepted-range"),
    # options, flags, objects
    Bad("unknown-name", ("str",), lambda v, a: "no-such-option", group="accepted-conversion"),
    Bad("empty-string", ("str",), lambda v, a: "", group="accepted-conversion"),
    Bad("int-for-str", ("str",), lambda v, a: 1, group="accepted-conversion"),
    Bad("str-for-bool", ("bool",), lambda v, a: "yes", "neutral"),
    Bad("int-for-bool", ("bool",), lambda v, a: 2, "neutral"),
    Bad("np-bool", ("bool",), lambda v, a: np.bool_(v), "neutral"),
    Bad("float-for-obj", ("obj", "fn", "path"), lambda v, a: 1.0, group="accepted-conversion"),
    Bad("wrong-object", ("obj",), lambda v, a: np.eye(3), group="accepted-conversion"),
    Bad("tuple-1", ("obj",), lambda v, a: (1.0,), group="accepted-conversion"),
    Bad("fn-returns-nan", ("fn",), lambda v, a: _fn_nan, group="accepted-nan"),
    Bad("fn-returns-str", ("fn",), lambda v, a: _fn_str, group="accepted-conversion"),
    Bad("fn-returns-short", ("fn",), lambda v, a: _fn_short, group="accepted-shape"),
    Bad("fn-raises", ("fn",), lambda v, a: _fn_raise, "raise"),
    # attitudes, skew and group elements
    Bad("not-rotation-2I", ("rot",), _not_rotation, group="accepted-nonrotation"),
    Bad("reflection", ("rot",), _reflection, group="accepted-nonrotation"),
    Bad("near-rotation", ("rot",), _near, group="accepted-nonrotation"),
    Bad("not-skew", ("skew",), _not_skew, group="accepted-nonskew"),
    Bad("swapped", ("vec",), _swap, "neutral"),
]

for _b in CATALOGUE:
    assert _b.contract in ("refuse", "neutral", "same", "raise", "refuse-if-positive"), _b


def _readonly(v):
    a = arr(v).copy()
    a.setflags(write=False)
    return a


def contract_for(bad: Bad, arg) -> str:
    """The contract of a bad value at an argument (some depend on the argument's kind/flags)."""
    c = bad.contract
    if arg.kind == "bool" and c != "same":
        return "neutral"    # flags follow Python truthiness; only crashes and wrong types count
    if c == "refuse-if-positive":
        return "refuse" if arg.positive else "neutral"
    if arg.kind == "rot" and bad.name in ("x1e300", "x1e160", "x1e16", "x1e-170", "x1e-300",
                                          "x1e-310", "max-float", "zeros", "negated"):
        return "refuse"     # not a rotation any more (det -1 for `negated` at n = 3)
    if arg.kind == "bcast" and bad.name in ("dropped-axis", "extra-axis", "empty", "scalar",
                                            "wrong-last-axis", "ragged"):
        return "neutral" if bad.name != "ragged" else "refuse"
    if arg.complex_ok and bad.name in ("complex", "complex-0j", "complex-scalar"):
        return "neutral"
    if arg.complex_ok and bad.name in ("wrong-last-axis", "swapped"):
        return "skip"       # a complex point has no axes to reshape (its 2-vector form is fuzzed)
    if bad.name == "None" and arg.opt:
        return "skip"       # None is a valid value there
    return c


def applies(bad: Bad, arg) -> bool:
    if arg.kind not in bad.kinds:
        return False
    if bad.name == "scalar" and arg.kind == "bcast":
        return False
    return True


# --- numeric fuzz: finite values of each kind at every scale (hypothesis-style) ---

def _scale(rng):
    r = rng.random()
    if r < 0.15:
        return 1.0
    if r < 0.25:
        return 0.0 if rng.random() < 0.3 else 1e-310
    return 10.0 ** rng.uniform(-300, 300)


def numeric_variant(valid, arg, rng):
    a = arr(valid)
    shape = a.shape
    s = _scale(rng)
    special = rng.random() < 0.2
    if arg.kind == "rot":
        n = shape[-1]
        q, r = np.linalg.qr(rng.standard_normal((n, n)))
        q = q * np.sign(np.diag(r))
        if np.linalg.det(q) < 0:
            q[:, 0] *= -1
        return q
    if arg.kind == "se3":
        g = np.eye(4)
        q, r = np.linalg.qr(rng.standard_normal((3, 3)))
        q = q * np.sign(np.diag(r))
        if np.linalg.det(q) < 0:
            q[:, 0] *= -1
        g[:3, :3] = q
        g[:3, 3] = rng.standard_normal(3) * s
        return g
    if arg.kind == "float":
        x = float(rng.standard_normal() * s)
        return abs(x) if arg.positive else x
    z = rng.standard_normal(shape) * s
    if special:       # a few exact special values mixed in: 0, ±1, ±max, tiny
        picks = np.array([0.0, 1.0, -1.0, 1e308, -1e308, 5e-324, 1e-300])
        mask = rng.random(shape) < 0.3
        z = np.where(mask, picks[rng.integers(0, len(picks), shape)], z)
    if arg.kind == "skew":
        z = np.triu(z, 1)
        z = z - np.swapaxes(z, -1, -2)
    elif arg.kind == "gl" and rng.random() < 0.7:
        # near a diagonal of positive entries (det > 0) at scale s
        n = shape[-1]
        z = np.diag(np.abs(rng.standard_normal(n)) + 0.1) * s + 0.1 * z
    return z


def hyp_arrays(arg, valid):
    """The same numeric fuzz as a hypothesis strategy (used by test_hypothesis.py)."""
    from hypothesis import strategies as st

    return st.integers(0, 2**32 - 1).map(
        lambda seed: numeric_variant(valid, arg, np.random.default_rng(seed)))
