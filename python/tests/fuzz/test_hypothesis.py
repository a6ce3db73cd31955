"""Hypothesis over the numeric arguments of the example table (in process: fixed small shapes,
finite float64 values of every magnitude, including subnormals and ±1.8e308). Same classifier and
groups as the case table: no panic, no silent NaN from this finite input, no wrong exception type.
Examples per argument: 6 in the quick tier, 60 with LIEFLOW_FUZZ=full."""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import lieflow as lf

from .allowlist import KNOWN_FAILING
from .catalogue import numeric_variant
from .core import SPECS, Case, Lazy, describe, group_of, run_case

N = 60 if os.environ.get("LIEFLOW_FUZZ") == "full" else 6
KINDS = ("vec", "bcast", "mat", "skew", "gl", "rot", "float")
TARGETS = [(si, ai) for si, s in enumerate(SPECS) if not s.slow and s.module != "integrate"
           for ai, a in enumerate(s.args) if a.kind in KINDS and not isinstance(a.value, Lazy)]
FINITE = st.floats(allow_nan=False, allow_infinity=False, width=64)


def strategy(arg):
    if arg.kind == "float":
        return FINITE.map(abs) if arg.positive else FINITE
    if arg.kind == "rot":
        return st.integers(0, 2**32 - 1).map(
            lambda seed: numeric_variant(arg.value, arg, np.random.default_rng(seed)))
    shape = np.shape(arg.value)
    s = hnp.arrays(np.float64, shape, elements=FINITE)
    if arg.kind == "skew":
        s = s.map(lambda z: np.triu(z, 1) - np.triu(z, 1).T)
    return s


@pytest.fixture(scope="module")
def hyp_results():
    cache, out = {}, []
    for si, ai in TARGETS:
        arg = SPECS[si].args[ai]
        case = Case(si, ai, "hypothesis")

        @settings(max_examples=N, deadline=None, database=None, derandomize=True,
                  suppress_health_check=list(HealthCheck))
        @given(strategy(arg))
        def check(value):
            res = run_case(case, lf, cache, override=value)
            if res["o"] not in ("ok", "typed-error", "missing"):
                out.append((case, res, value))

        check()
    return out


def _param(g):
    marks = [pytest.mark.xfail(reason=KNOWN_FAILING[g], strict=False)] if g in KNOWN_FAILING else []
    return pytest.param(g, marks=marks, id=g)


HGROUPS = ["panic", "mutated", "harness", "silent-nan:lie", "silent-nan:pseudo_rigid",
           "silent-nan:systems", "wrong-type:ValueError", "wrong-type:TypeError-unnamed",
           "wrong-type:other"]


@pytest.mark.parametrize("group", [_param(g) for g in HGROUPS])
def test_hypothesis_group(hyp_results, group):
    bad = [(c, r, v) for c, r, v in hyp_results if group_of(c, r) == group]
    lines = [f"{describe(c)} = {np.array2string(np.asarray(v), precision=3)} -> {r['o']}: {r['d']}"
             for c, r, v in bad[:10]]
    assert not bad, f"{len(bad)} example(s) in {group}:\n" + "\n".join(lines)


def test_hypothesis_no_other_groups(hyp_results):
    assert {group_of(c, r) for c, r, _ in hyp_results} <= set(HGROUPS)
