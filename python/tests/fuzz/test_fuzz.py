"""The fuzz suite of issue 16 as tests.

Quick tier (default, part of `pytest python/tests`): every valid example plus a rotating sample of
bad values per argument and numeric draws, ~5,000 calls in two worker subprocesses.
Full tier (~50,000 calls): `LIEFLOW_FUZZ=full pytest python/tests/fuzz`, or
`python python/tests/fuzz --full` which also writes the summary table to docs/fuzz.md.

One test per failing-outcome group (= an item of issue 16): it fails with reproducers when any
result falls into the group, unless allow-listed (allowlist.ALLOWED). Groups listed in
allowlist.KNOWN_FAILING are xfail(strict=False) until their fix lands.
"""

import inspect
import os
import time

import pytest

import lieflow as lf

from .allowlist import KNOWN_FAILING
from .catalogue import CATALOGUE
from .core import SPECS, Case, annotate, build_cases, describe, run_case, run_cases, summarize
from .examples import CONSTRUCTORS, RECEIVERS, _has_dask

TIER = os.environ.get("LIEFLOW_FUZZ", "quick")
TIMEOUT = float(os.environ.get("LIEFLOW_FUZZ_TIMEOUT", "5" if TIER == "quick" else "10"))

GROUPS = (["panic", "abort-alloc", "mutated", "rejected-valid", "wrong-result", "harness"]
          + [f"silent-nan:{m}" for m in ("integrate", "lie", "pseudo_rigid", "systems")]
          + sorted({b.group for b in CATALOGUE if b.group.startswith("accepted-")} | {"accepted-other"})
          + [f"wrong-type:{e}" for e in ("ValueError", "TypeError-unnamed", "OverflowError",
                                         "MemoryError", "integrate-system", "other")])


@pytest.fixture(scope="module")
def fuzz_run():
    cases = build_cases(TIER)
    t = time.monotonic()
    results = run_cases(list(range(len(cases))), tier=TIER, workers=int(os.environ.get(
        "LIEFLOW_FUZZ_WORKERS", "2")), timeout=TIMEOUT)
    elapsed = time.monotonic() - t
    per_module, groups = summarize(cases, results)
    return cases, results, per_module, groups, elapsed


def _param(g):
    marks = [pytest.mark.xfail(reason=KNOWN_FAILING[g], strict=False)] if g in KNOWN_FAILING else []
    return pytest.param(g, marks=marks, id=g)


@pytest.mark.parametrize("group", [_param(g) for g in GROUPS])
def test_no_failures_in_group(fuzz_run, group):
    cases, results, per_module, groups, elapsed = fuzz_run
    bad = groups.get(group, [])
    lines = [f"{r['desc']} -> {r['o']}: {r['d']}" for r in bad[:25]]
    assert not bad, f"{len(bad)} result(s) in {group}:\n" + "\n".join(lines)


def test_no_unknown_failure_groups(fuzz_run):
    groups = fuzz_run[3]
    assert set(groups) <= set(GROUPS), sorted(set(groups) - set(GROUPS))


def test_every_callable_was_called(fuzz_run):
    cases, results = fuzz_run[0], fuzz_run[1]
    missing = sorted({SPECS[c.spec].id for i, c in enumerate(cases)
                      if c.arg < 0 and results[i]["o"] == "missing"})
    assert not missing, missing


# --- the table covers every public callable (found by introspection) ---

SKIP = {  # public names that are not callables to fuzz, with the reason
    "lieflow.System": "abstract base class (no constructor); its methods are fuzzed on every system",
    "lieflow.LiePoissonSystem": "alias of System",
    "lieflow.Integration": "made by System._start only; advance/state are fuzzed on a run",
    "lieflow.Trajectory": "made by integrate only; its methods are fuzzed on a trajectory",
    "lieflow.LyapunovSpectrum": "made by lyapunov; a record (attributes only)",
    "lieflow.RollingDisksEquilibrium": "made by RollingDisks.relative_equilibria; state is fuzzed",
    "lieflow.pseudo_rigid.RelativeEquilibrium": "made by relative_equilibria; motion/stability fuzzed",
    "lieflow.pseudo_rigid.Stability": "a record (no methods)",
    "lieflow.pseudo_rigid.Verdict": "a record (no methods)",
    "lieflow.potentials.Potential": "made by the potential constructors; methods fuzzed on each",
    "lieflow.surfaces.Surface": "made by the surface constructors; methods fuzzed on each",
    "lieflow.spaces.Space": "made by Euclidean, Sphere, Hyperbolic; methods fuzzed on a sphere",
    "lieflow.continuation.Branch": "made by follow; its methods are fuzzed on a branch",
    "lieflow.continuation.SpecialPoint": "made by follow; a record (attributes only)",
    "lieflow.PeriodicOrbit": "made by periodic_orbit; trajectory is fuzzed on an orbit",
    "lieflow.pseudo_rigid.NormalMode": "made by RelativeEquilibrium.normal_modes; a record",
    "lieflow.continuation.PeriodicBranch": "made by periodic_family; plot is fuzzed on a branch",
    "lieflow.continuation.PeriodicSpecialPoint": "made by periodic_family; a record",
}
CLASS_RECEIVER = {**CONSTRUCTORS, "Integration": "run", "Trajectory": "traj",
                  "RollingDisksEquilibrium": "rdeq", "RelativeEquilibrium": "releq",
                  "Potential": "harmonic", "Surface": "sphere", "Branch": "branch", "Space": "s3",
                  "PeriodicOrbit": "porb", "PeriodicBranch": "pbranch"}


def public_callables():
    out = []
    for modname in ("", ".lie", ".pseudo_rigid", ".potentials", ".spaces", ".surfaces", ".elliptic",
                    ".ellipsoids", ".continuation", ".plot",
                    *((".ensemble",) if _has_dask() else ())):
        mod = eval("lf" + modname)
        for name in getattr(mod, "__all__", None) or dir(mod):
            if name.startswith("_"):
                continue
            obj = getattr(mod, name)
            if inspect.ismodule(obj) or not callable(obj):
                continue
            if inspect.isclass(obj) and issubclass(obj, BaseException):
                continue
            full = f"lieflow{modname}.{name}"
            if inspect.isclass(obj):
                if full not in SKIP:
                    out.append((full, modname.lstrip(".") or None, name))
                for meth in dir(obj):
                    if meth.startswith("_") and meth != "__add__":
                        continue
                    attr = inspect.getattr_static(obj, meth, None)
                    if isinstance(attr, property) or type(attr).__name__ == "getset_descriptor":
                        continue
                    if callable(getattr(obj, meth, None)) and not (obj is lf.System and meth):
                        out.append((f"{full}.{meth}", "method", (name, meth)))
            else:
                out.append((full, modname.lstrip(".") or None, name))
    return out


def test_table_covers_every_public_callable():
    targets = {s.target.removeprefix("use:") for s in SPECS}
    method_targets = {(k, t.split(".", 1)[1]) for t in targets if t.startswith("@")
                      for k in [t[1:].split(".")[0]]}
    uncovered = []
    for full, where, name in public_callables():
        if where == "method":
            cls, meth = name
            if cls in ("System", "LiePoissonSystem"):
                continue
            keys = [k for k, v in CLASS_RECEIVER.items() if k == cls]
            recv = CLASS_RECEIVER.get(cls)
            if recv is None or (recv, meth) not in method_targets:
                # a method of a class with several receivers (Potential, Surface): any will do
                if not any(t[1] == meth for t in method_targets):
                    uncovered.append(full)
            del keys
        else:
            target = name if where is None else f"{where}.{name}"
            if name == "integrate":
                target = "integrate"
            if target not in targets:
                uncovered.append(full)
    assert not uncovered, uncovered
    assert set(RECEIVERS) >= set(CONSTRUCTORS.values())


# --- issue 29 'Smaller': the full tier's failures outside the allow-list, one call each ---

def _classified(spec_id, arg, bad):
    """The outcome class of one fuzz call, made in this process (the allow-list applied)."""
    si = next(i for i, s in enumerate(SPECS) if s.id == spec_id)
    case = Case(si, next(i for i, a in enumerate(SPECS[si].args) if a.name == arg), bad)
    return annotate([case], {"0": run_case(case, lf, {})})["0"]["c"]


@pytest.mark.parametrize("spec_id, arg, bad", [
    ("ellipsoids.maclaurin", "G", "numeric#7"),   # a huge G: residuals["force"] was inf
    ("plot.animate", "every", "np-int"),       # animations compared by their frames
    ("plot.animate", "every", "2**70"),        # refused like every count of the API
    ("run.set_events", "directions", "inf"),   # a direction is a finite number
    ("run.save_at", "t_eval", "empty"),        # refused, as lf.integrate(t_eval=[]) is
    ("ellipsoids.riemann_s", "f", "inf"),      # f = inf is Dedekind's family (allowed)
    ("run.save_at", "t_eval", "wrong-last-axis"),   # one more output time is valid (allowed)
])
def test_issue29_findings(spec_id, arg, bad):
    assert _classified(spec_id, arg, bad) in ("ok", "typed-error", "allowed")
