"""The case table, the one classifier and the subprocess runner of the fuzz suite.

Every call runs in a worker subprocess (two by default, one per core), so that an abort
(SIGABRT on a failed allocation, SIGKILL, a hang) is seen as an outcome instead of killing the
test run. The parent sends case numbers one at a time; when a worker dies or overruns its time
limit the case in flight is classified `abort`/`timeout` and a fresh worker takes the rest.
Both sides build the same deterministic table from examples.py and catalogue.py.
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
import select
import subprocess
import sys
import threading
import time
import warnings
import zlib
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .allowlist import INFINITE_OK, allowed
from .catalogue import CATALOGUE, FuzzRaised, applies, contract_for, numeric_variant
from .examples import FRESH, RECEIVERS, SPECS, SURFACE_POINT, V3, X3, Lazy, Spec

TESTS_DIR = Path(__file__).resolve().parent.parent
BAD = {b.name: b for b in CATALOGUE}
OUTCOMES = ["ok", "typed-error", "wrong-type", "panic", "abort", "timeout", "silent-nan",
            "mutated", "accepted-bad", "wrong-result", "rejected-valid", "harness", "allowed", "missing"]
FAILING = {"wrong-type", "panic", "abort", "timeout", "silent-nan", "mutated", "accepted-bad",
           "wrong-result", "rejected-valid", "harness"}
NONFINITE_BADS = {"nan", "inf", "-inf", "int-nan", "fn-returns-nan"}


@dataclass(frozen=True)
class Case:
    spec: int          # index into SPECS
    arg: int           # index of the argument replaced, -1 for the valid call
    bad: str           # catalogue name, "valid", or "numeric#k"

    @property
    def key(self):
        return f"{self.spec}:{self.arg}:{self.bad}"


def _crc(*parts) -> int:
    return zlib.crc32("\x1f".join(map(str, parts)).encode())


def build_cases(tier: str = "quick", total: int = 50_000) -> list[Case]:
    """The case table. full: every (callable, argument, applicable bad value) plus numeric fuzz
    up to `total`; quick: every valid call plus a rotating sample of each argument's bad values
    (every bad value is used somewhere) and two numeric draws per numeric argument."""
    det, numeric_slots = [], []
    for si, spec in enumerate(SPECS):
        det.append(Case(si, -1, "valid"))
        for ai, arg in enumerate(spec.args):
            bads = [b for b in CATALOGUE if applies(b, arg) and contract_for(b, arg) != "skip"]
            if tier == "quick":
                bads = [b for b in bads if b.quick]
                k = 3 if spec.slow else 9
                if len(bads) > k:
                    off = _crc(spec.id, arg.name) % len(bads)
                    step = max(1, len(bads) // k)
                    bads = [bads[(off + j * step) % len(bads)] for j in range(k)]
            det.extend(Case(si, ai, b.name) for b in bads)
            if arg.kind in ("vec", "bcast", "mat", "skew", "rot", "gl", "se3", "float"):
                numeric_slots.append((si, ai))
    if tier == "quick":
        per = {si: (1 if SPECS[si].slow else 2) for si, _ in numeric_slots}
    else:
        per_slot = max(1, math.ceil((total - len(det)) / max(1, len(numeric_slots))))
        per = {si: (max(1, per_slot // 20) if SPECS[si].slow else per_slot) for si, _ in numeric_slots}
    num = [Case(si, ai, f"numeric#{k}") for si, ai in numeric_slots for k in range(per[si])]
    cases = det + num
    if tier == "full" and len(cases) > total:
        cases = det + num[: max(0, total - len(det))]
    return cases


# ---------------------------------------------------------------- the call and the classifier

class Missing(Exception):
    """The callable or one of its example values does not exist in this version of lieflow."""


def _resolve_target(target: str, lf, cache):
    if target == "integrate":
        return lf.integrate
    if target.startswith("use:"):
        ctor = _resolve_target(target[4:], lf, cache)
        return lambda *a, **k: _exercise(ctor(*a, **k), target, lf)
    if target.startswith("@"):
        key, _, attr = target[1:].partition(".")
        if key not in cache or key in FRESH:
            try:
                cache[key] = RECEIVERS[key](lf)
            except Exception as e:       # the receiver cannot be built: API absent here
                cache[key] = Missing(f"receiver {key}: {type(e).__name__}: {e}")
        recv = cache[key]
        if isinstance(recv, Missing):
            raise recv
        if not hasattr(recv, attr):
            raise Missing(f"{type(recv).__name__}.{attr}")
        return getattr(recv, attr)
    obj = lf
    for part in target.split("."):
        if not hasattr(obj, part):
            raise Missing(target)
        obj = getattr(obj, part)
    return obj


def _exercise(obj, target, lf):
    """What a constructor of Python-callable-backed objects is fuzzed through: their use."""
    if target.startswith("use:ensemble."):      # a lazy Dataset: computed here, in this process
        ds = obj.compute(scheduler="sync")
        return {**{k: v.values for k, v in ds.variables.items()}, "attrs": dict(ds.attrs)}
    if "potentials" in target:
        return obj.value(X3), obj.gradient(X3), obj.hessian(X3, V3)
    if target.endswith("spaces.Riemannian"):     # through a top on it: state and two steps
        x, v = np.array([0.3, -0.2, 0.5]), np.array([0.4, 0.1, -0.3])
        top = lf.FrameTop(obj, 1.3, [2.0, 3.0, 4.0])
        z = top.state(x, np.eye(3), v, [0.7, -0.4, 1.1])
        return obj.reference_frame(x), lf.integrate(top, z, dt=0.05, steps=2).final_state
    key = {"Revolution": "revolution", "Graph": "graph", "MetricSurface": "metric"}[target.split(".")[-1]]
    x = SURFACE_POINT[key]
    return obj.curvature(x), obj.metric(x), obj.frame(x), obj.connection(x)


def _value(v, lf, cache):
    if isinstance(v, Lazy):
        k = ("lazy", id(v))
        if k not in cache:
            try:
                cache[k] = v.make(lf)
            except Exception as e:
                cache[k] = Missing(f"example value: {type(e).__name__}: {e}")
        v = cache[k]
        if isinstance(v, Missing):
            raise v
    if isinstance(v, (np.ndarray, list, tuple, dict)):
        return copy.deepcopy(v)
    return v


def _snapshot(values):
    out = []
    for v in values:
        if isinstance(v, np.ndarray) and v.dtype != object:
            # a read-only array (e.g. a 1e10-row broadcast view) cannot be mutated through the
            # buffer protocol; copying it would allocate what the call under test must refuse
            out.append(("a", v.copy()) if v.flags.writeable else None)
        elif isinstance(v, (list, tuple)):
            try:
                out.append(("l", copy.deepcopy(v)))
            except Exception:
                out.append(None)
        else:
            out.append(None)
    return out


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        try:
            a, b = np.asarray(a), np.asarray(b)
            if a.shape != b.shape:
                return False
            if a.dtype.kind in "fc" or b.dtype.kind in "fc":
                return bool(np.array_equal(a, b, equal_nan=True))
            return bool(np.array_equal(a, b))
        except Exception:
            return False
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    try:
        return bool(a == b) or (isinstance(a, float) and isinstance(b, float) and math.isnan(a)
                                and math.isnan(b))
    except Exception:
        return False


def _mutated(values, snaps) -> bool:
    for v, s in zip(values, snaps):
        if s is None:
            continue
        if not _same(v, s[1]):
            return True
    return False


def _nonfinite(x, depth=0) -> bool:
    """Whether a result holds NaN or inf anywhere (arrays, numbers, containers, lieflow objects)."""
    if depth > 4:
        return False
    if isinstance(x, bool) or x is None or isinstance(x, (str, bytes)):
        return False
    if isinstance(x, (int, np.integer)):
        return False
    if isinstance(x, (float, complex, np.floating, np.complexfloating)):
        return not np.isfinite(x)
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "fc":
            return not bool(np.isfinite(x).all())
        if x.dtype == object:
            return any(_nonfinite(y, depth + 1) for y in x.ravel()[:64])
        return False
    if isinstance(x, dict):
        return any(_nonfinite(y, depth + 1) for y in list(x.values())[:64])
    if isinstance(x, (list, tuple)):
        return any(_nonfinite(y, depth + 1) for y in x[:64])
    mod = type(x).__module__ or ""
    if mod.startswith("lieflow"):
        for name in dir(x):
            if name.startswith("_") or name in INFINITE_OK:
                continue
            try:
                y = getattr(x, name)
            except Exception:
                continue
            if callable(y):
                continue
            if _nonfinite(y, depth + 1):
                return True
    return False


def _equal_results(a, b, depth=0) -> bool:
    if depth > 4:
        return True
    if isinstance(a, (np.ndarray, float, int, np.floating)) or isinstance(b, (np.ndarray,)):
        try:
            a, b = np.asarray(a), np.asarray(b)
            return a.shape == b.shape and bool(np.allclose(a, b, rtol=1e-12, atol=0, equal_nan=True))
        except Exception:
            return _same(a, b)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal_results(a[k], b[k], depth + 1) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_equal_results(x, y, depth + 1) for x, y in zip(a, b))
    if type(a) is type(b) and (type(a).__module__ or "").startswith("lieflow"):
        return True      # objects (systems, potentials): built without error is all we check
    if type(a) is type(b) and type(a).__module__ == "matplotlib.animation":
        # lieflow.plot.animate: animations have no value equality; the same frames are.
        return _equal_results(list(a.new_frame_seq()), list(b.new_frame_seq()), depth + 1)
    return _same(a, b)


def _names_argument(msg: str, name: str) -> bool:
    return re.search(r"(?<![A-Za-z0-9_])" + re.escape(name) + r"(?![A-Za-z0-9_])", msg) is not None


def describe(case: Case) -> str:
    spec = SPECS[case.spec]
    if case.arg < 0:
        return f"{spec.id}(valid example)"
    return f"{spec.id}({spec.args[case.arg].name}=<{case.bad}>)"


def run_case(case: Case, lf, cache, override=None) -> dict:
    """Make the call of `case` in this process and classify it (except abort/timeout, which the
    parent sees)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return _run_case(case, lf, cache, override)
        finally:
            if "matplotlib.pyplot" in sys.modules:     # lieflow.plot's figures
                sys.modules["matplotlib.pyplot"].close("all")


def _run_case(case: Case, lf, cache, override=None) -> dict:
    spec: Spec = SPECS[case.spec]
    try:
        fn = _resolve_target(spec.target, lf, cache)
        values = [_value(a.value, lf, cache) for a in spec.args]
    except Missing as e:
        return {"o": "missing", "d": str(e)[:200]}
    contract = "valid"
    finite_in = True
    if case.arg >= 0:
        arg = spec.args[case.arg]
        if override is not None:
            values[case.arg] = override
            contract = "neutral"
        elif case.bad.startswith("numeric#"):
            k = int(case.bad.split("#")[1])
            rng = np.random.default_rng(_crc(spec.id, arg.name, k))
            values[case.arg] = numeric_variant(values[case.arg], arg, rng)
            contract = "neutral"
        else:
            bad = BAD[case.bad]
            values[case.arg] = bad.make(values[case.arg], arg)
            contract = contract_for(bad, arg)
            finite_in = bad.name not in NONFINITE_BADS
    snaps = _snapshot(values)
    pos, kw = [], {}
    for a, v in zip(spec.args, values):
        if a.kw:
            kw[a.name] = v
        else:
            pos.append(v)
    exc = None
    try:
        out = fn(*pos, **kw)
    except BaseException as e:  # noqa: BLE001 (PanicException derives from BaseException)
        if isinstance(e, (KeyboardInterrupt, SystemExit)):
            raise
        exc = e
        out = None
    mutated = _mutated(values, snaps)
    if exc is not None:
        name = type(exc).__name__
        msg = f"{name}: {exc}"[:300]
        if name == "PanicException":
            return {"o": "panic", "d": msg, "e": name}
        if mutated:
            return {"o": "mutated", "d": msg, "e": name}
        if contract == "valid":
            if spec.args and isinstance(exc, TypeError) and re.search(
                    r"unexpected keyword argument|positional argument", str(exc)):
                return {"o": "missing", "d": "signature differs in this version: " + msg, "e": name}
            return {"o": "rejected-valid", "d": msg, "e": name}
        if isinstance(exc, FuzzRaised):
            return {"o": "typed-error" if contract == "raise" else "wrong-type", "d": msg, "e": name}
        if isinstance(exc, lf.LieflowError):
            return {"o": "typed-error", "d": msg, "e": name}
        if isinstance(exc, TypeError):
            argname = spec.args[case.arg].name if case.arg >= 0 else ""
            # pyo3 names a parameter whose extraction failed in a note (Python >= 3.11:
            # "while processing 'tol'"), not in the message
            text = " ".join([str(exc), *getattr(exc, "__notes__", [])])
            if argname and _names_argument(text, argname):
                return {"o": "typed-error", "d": msg, "e": name}
            return {"o": "wrong-type", "d": msg, "e": "TypeError-unnamed"}
        return {"o": "wrong-type", "d": msg, "e": name}
    if mutated:
        return {"o": "mutated", "d": "an input array changed", "e": ""}
    if out is NotImplemented:      # binary operators refuse by the Python protocol
        return {"o": "typed-error", "d": "NotImplemented", "e": ""}
    nonfinite = _nonfinite(out)
    if contract in ("refuse", "raise"):
        return {"o": "accepted-bad", "d": "returned normally" + (" (non-finite)" if nonfinite else ""),
                "e": ""}
    if nonfinite and finite_in:
        return {"o": "silent-nan", "d": "finite input, non-finite output", "e": ""}
    if contract == "same":
        bkey = ("baseline", case.spec)
        if bkey not in cache:
            try:
                base_fn = _resolve_target(spec.target, lf, cache)   # afresh: FRESH receivers
                cache[bkey] = ("ok", base_fn(*[_value(a.value, lf, cache) for a in spec.args if not a.kw],
                                        **{a.name: _value(a.value, lf, cache) for a in spec.args
                                           if a.kw}))
            except BaseException as e:  # noqa: BLE001
                cache[bkey] = ("err", repr(e))
        kind, base = cache[bkey]
        if kind == "ok" and not _equal_results(out, base):
            return {"o": "wrong-result", "d": "result differs from the valid call's", "e": ""}
    return {"o": "ok", "d": "", "e": ""}


def group_of(case: Case, res: dict) -> str:
    """The issue-16 item a failing result belongs to (the xfail/allow-list unit)."""
    o = res["o"]
    spec = SPECS[case.spec]
    if o == "panic":
        return "panic"
    if o in ("abort", "timeout"):
        return "abort-alloc"
    if o == "silent-nan":
        if spec.module == "integrate":
            return "silent-nan:integrate"
        if spec.module == "lie":
            return "silent-nan:lie"
        if spec.module in ("pseudo_rigid", "potentials"):
            return "silent-nan:pseudo_rigid"
        return "silent-nan:systems"
    if o == "accepted-bad":
        if case.bad == "fn-raises":
            return "accepted-conversion"
        if spec.args[case.arg].kind == "rot":
            return "accepted-nonrotation"
        return BAD[case.bad].group if case.bad in BAD else "accepted-other"
    if o == "wrong-type":
        e = res.get("e", "")
        if spec.target == "integrate" and case.arg == 0:
            return "wrong-type:integrate-system"
        if e in ("ValueError", "TypeError-unnamed", "OverflowError", "MemoryError"):
            return f"wrong-type:{e}"
        return "wrong-type:other"
    return o      # mutated, wrong-result, rejected-valid


# ---------------------------------------------------------------- worker (child process)

def worker_main(tier: str, total: int):
    import resource

    limit = int(os.environ.get("LIEFLOW_FUZZ_MEM", str(6 << 30)))
    try:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (ValueError, OSError):
        pass
    import warnings

    warnings.simplefilter("ignore")
    import lieflow as lf

    cases = build_cases(tier, total)
    cache: dict = {}
    out = sys.stdout
    print(json.dumps({"ready": True}), file=out, flush=True)
    for line in sys.stdin:
        i = int(line)
        try:
            res = run_case(cases[i], lf, cache)
        except MemoryError as e:
            res = {"o": "wrong-type", "d": f"MemoryError: {e}"[:300], "e": "MemoryError"}
        except Exception as e:  # a harness error is reported, never hidden
            res = {"o": "harness", "d": f"{type(e).__name__}: {e}"[:300], "e": "harness"}
        res["i"] = i
        print(json.dumps(res), file=out, flush=True)


# ---------------------------------------------------------------- parent: scheduling

class Worker:
    def __init__(self, python, tier, total, errpath):
        env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1",
                   RAYON_NUM_THREADS="1", RUST_BACKTRACE="0", PYTHONFAULTHANDLER="0")
        code = (f"import sys; sys.path.insert(0, {str(TESTS_DIR)!r}); "
                f"from fuzz.core import worker_main; worker_main({tier!r}, {total})")
        self.err = open(errpath, "w+b")
        self.p = subprocess.Popen([python, "-c", code], stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, stderr=self.err, env=env,
                                  cwd=str(TESTS_DIR), bufsize=0)
        self.buf = b""
        line = self.readline(120.0)
        if line is None or b"ready" not in line:
            raise RuntimeError(f"fuzz worker did not start: {self.stderr_tail()}")

    def readline(self, timeout):
        deadline = time.monotonic() + timeout
        while b"\n" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            r, _, _ = select.select([self.p.stdout], [], [], left)
            if not r:
                return None
            chunk = os.read(self.p.stdout.fileno(), 65536)
            if not chunk:
                return b""          # EOF: the worker died
            self.buf += chunk
        line, _, self.buf = self.buf.partition(b"\n")
        return line

    def stderr_tail(self):
        try:
            self.err.flush()
            self.err.seek(0)
            lines = [ln for ln in self.err.read().decode(errors="replace").splitlines() if ln.strip()]
            return " | ".join(lines[-2:])[:300]
        except Exception:
            return ""

    def kill(self):
        try:
            self.p.kill()
            self.p.wait(timeout=10)
        except Exception:
            pass
        self.err.close()


def run_cases(cases_idx, *, python=None, tier="quick", total=50_000, workers=2, timeout=20.0,
              progress=None, tmpdir=None) -> dict:
    """Run the cases numbered `cases_idx` of build_cases(tier, total) in `workers` subprocesses;
    returns {index: result dict}."""
    python = python or sys.executable
    tmpdir = Path(tmpdir or os.environ.get("TMPDIR", "/tmp"))
    shards = [cases_idx[w::workers] for w in range(workers)]
    results: dict = {}
    lock = threading.Lock()
    done = [0]

    def drive(shard, w):
        k = 0
        errpath = tmpdir / f"lieflow-fuzz-{os.getpid()}-{w}.err"
        wk = None
        while k < len(shard):
            if wk is None:
                wk = Worker(python, tier, total, errpath)
            i = shard[k]
            wk.p.stdin.write(f"{i}\n".encode())
            wk.p.stdin.flush()
            line = wk.readline(timeout)
            if line is None:
                res = {"o": "timeout", "d": f"no answer in {timeout:g} s", "e": ""}
                wk.kill()
                wk = None
            elif line == b"":
                rc = wk.p.wait()
                res = {"o": "abort", "d": f"exit {rc}: {wk.stderr_tail()}", "e": ""}
                wk.kill()
                wk = None
            else:
                res = json.loads(line)
            res["i"] = i
            with lock:
                results[i] = res
                done[0] += 1
                if progress:
                    progress(done[0], len(cases_idx))
            k += 1
        if wk is not None:
            wk.p.stdin.close()
            wk.kill()
        try:
            errpath.unlink()
        except OSError:
            pass

    threads = [threading.Thread(target=drive, args=(s, w), daemon=True) for w, s in enumerate(shards)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return results


def annotate(cases, results):
    """Each result with what it was (spec id, argument, bad value, module, group, description),
    so that saved runs render without the table they were made with."""
    for i, res in results.items():
        case = cases[int(i)]
        spec = SPECS[case.spec]
        arg = spec.args[case.arg].name if case.arg >= 0 else ""
        o = res["o"]
        if o in FAILING and allowed(spec.id, arg, case.bad, o):
            o = "allowed"
        res.update(sid=spec.id, arg=arg, bad=case.bad, m=spec.module, c=o, desc=describe(case),
                   g=group_of(case, res) if o in FAILING else "")
    return results


def summarize(cases, results):
    """Counts per (module, outcome class) and the failing results per group."""
    if cases is not None:
        annotate(cases, results)
    per_module = defaultdict(Counter)
    groups = defaultdict(list)
    for res in results.values():
        per_module[res["m"]][res["c"]] += 1
        if res["g"]:
            groups[res["g"]].append(res)
    return per_module, groups
