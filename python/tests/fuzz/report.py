"""The full tier's command line and the docs/fuzz.md summary (see __main__.py)."""

from __future__ import annotations

import argparse
import datetime
import json
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

from .allowlist import ALLOWED, ISSUE_ITEMS, KNOWN_FAILING
from .core import OUTCOMES, annotate, build_cases, run_cases, summarize

COLUMNS = [o for o in OUTCOMES]
MODULES = ["lie", "pseudo_rigid", "potentials", "surfaces", "elliptic", "systems", "integrate"]


def _provenance(python: str) -> str:
    try:
        path = subprocess.run([python, "-c", "import lieflow, os; print(os.path.dirname(lieflow.__file__))"],
                              capture_output=True, text=True, timeout=120).stdout.strip()
        rev = subprocess.run(["git", "-C", path, "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", path, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
        return f"lieflow at `{path}`, commit {rev}" + (" + uncommitted changes" if dirty else "")
    except Exception as e:  # noqa: BLE001
        return f"({e})"


def run_label(label, python, tier, total, workers, timeout):
    cases = build_cases(tier, total)
    t0 = time.monotonic()
    last = [0.0]

    def progress(done, n):
        if time.monotonic() - last[0] > 10 or done == n:
            last[0] = time.monotonic()
            print(f"  [{label}] {done}/{n} calls, {time.monotonic() - t0:.0f} s", file=sys.stderr,
                  flush=True)

    results = run_cases(list(range(len(cases))), python=python, tier=tier, total=total,
                        workers=workers, timeout=timeout, progress=progress)
    annotate(cases, results)
    return {"label": label, "python": python, "tier": tier, "total": total,
            "seconds": round(time.monotonic() - t0, 1), "provenance": _provenance(python),
            "date": datetime.datetime.now().isoformat(timespec="seconds"),
            "command": "python python/tests/fuzz " + " ".join(sys.argv[1:]),
            "results": {str(k): v for k, v in results.items()}}


def _table(per_module):
    cols = [c for c in COLUMNS if any(per_module[m][c] for m in per_module)]
    head = "| module | calls | " + " | ".join(cols) + " |"
    lines = [head, "|" + "---|" * (len(cols) + 2)]
    tot = Counter()
    for m in MODULES + sorted(set(per_module) - set(MODULES)):
        if m not in per_module:
            continue
        c = per_module[m]
        tot.update(c)
        lines.append(f"| {m} | {sum(c.values())} | " + " | ".join(str(c[k]) for k in cols) + " |")
    lines.append(f"| **total** | **{sum(tot.values())}** | " + " | ".join(f"**{tot[k]}**" for k in cols) + " |")
    return lines, tot


def render(runs, command):
    out = ["# Fuzz run of the Python API (issue 16)", "",
           "Every public callable of `lieflow` (module functions, constructors and methods of every",
           "class, `lf.integrate` with each system) is called with a valid example and with each bad",
           "value of the catalogue at each argument (wrong shapes, ragged lists, strings, None,",
           "complex, datetime64, object arrays, bool, scales 1e±300, NaN/inf, zero/negative sizes,",
           "empty arrays, broadcast views of 10¹⁰ rows, non-contiguous/Fortran/read-only views,",
           "numeric strings), plus finite numeric fuzz at scales 1e-300…1e300. Every call runs in",
           "a worker subprocess (6 GB address-space limit) so an abort is an outcome.",
           "", "Outcome classes: **ok** finite result; **typed-error** a `LieflowError` subclass or a",
           "`TypeError` naming the argument; **allowed** a failing class listed with its reason in",
           "`python/tests/fuzz/allowlist.py`; **wrong-type** any other exception (bare `ValueError`,",
           "unnamed `TypeError`, `OverflowError`, `AttributeError`); **panic** `PanicException`;",
           "**abort** the worker died; **timeout** no answer within the time limit; **silent-nan**",
           "finite input, NaN/inf in the result; **mutated** an input array changed;",
           "**accepted-bad** a value that must be refused returned normally; **wrong-result** the",
           "same values in another layout gave another result; **rejected-valid** a valid example",
           "raised; **missing** the callable does not exist in that version.", "",
           "Command:", "", "```bash", command, "```", ""]
    totals = {}
    for run in runs:
        results = run["results"]
        per_module, groups = summarize(None, results)
        lines, tot = _table(per_module)
        totals[run["label"]] = tot
        cmd = run.get("command") or (f"python python/tests/fuzz --{run['tier']} --run "
                                     f"{run['label']}={run['python']} --json DIR")
        out += [f"## {run['label']}: {run['tier']} tier, {len(results)} calls, {run['date']}", "",
                f"{run['provenance']}; {run['seconds']:.0f} s with 2 workers; `{cmd}`.", ""]
        out += lines + [""]
        if groups:
            out += ["Failing groups (one reproducer each; xfail reason in allowlist.KNOWN_FAILING):", "",
                    "| group | calls | example |", "|---|---|---|"]
            for g, items in sorted(groups.items(), key=lambda kv: -len(kv[1])):
                r = items[0]
                d = r["d"].replace("|", "\\|").replace("\n", " ")[:140]
                out.append(f"| {g} | {len(items)} | `{r['desc']}` → {r['o']}: {d} |")
            out.append("")
    if len(runs) > 1:
        labels = [r["label"] for r in runs]
        out += ["## Before → now (all modules)", "", "| outcome | " + " | ".join(labels) + " |",
                "|---|" + "---|" * len(labels)]
        for o in COLUMNS:
            if any(totals[lb][o] for lb in labels):
                out.append(f"| {o} | " + " | ".join(str(totals[lb][o]) for lb in labels) + " |")
        out.append("")
    out += ["## Allow-list", ""] + [f"- `{s}` `{a}` `{b}` → {o}: {why}" for s, a, b, o, why in ALLOWED]
    out += ["", "## Groups marked xfail in the quick tier", ""]
    out += [f"- `{g}`: {why}" for g, why in KNOWN_FAILING.items()]
    return "\n".join(out) + "\n"


def main(argv):
    ap = argparse.ArgumentParser(prog="python python/tests/fuzz")
    ap.add_argument("--full", action="store_true", help="the full tier (default: quick)")
    ap.add_argument("--total", type=int, default=50_000)
    ap.add_argument("--run", action="append", default=[], metavar="LABEL=PYTHON")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=30.0)
    ap.add_argument("--json", metavar="DIR", help="keep raw results as DIR/LABEL.json")
    ap.add_argument("--from-json", nargs="*", metavar="FILE", help="render these saved runs only")
    ap.add_argument("--doc", metavar="PATH", help="write the markdown summary here (docs/fuzz.md)")
    a = ap.parse_args(argv)
    tier = "full" if a.full else "quick"
    command = "python python/tests/fuzz " + " ".join(argv)
    if a.from_json:
        runs = [json.loads(Path(f).read_text()) for f in a.from_json]
    else:
        runs = []
        for spec in a.run or [f"now={sys.executable}"]:
            label, _, python = spec.partition("=")
            print(f"fuzz: {label} ({python}), {tier} tier", file=sys.stderr)
            run = run_label(label, python, tier, a.total, a.workers, a.timeout)
            runs.append(run)
            if a.json:
                Path(a.json).mkdir(parents=True, exist_ok=True)
                Path(a.json, f"{label}.json").write_text(json.dumps(run))
    md = render(runs, command)
    if a.doc:
        Path(a.doc).write_text(md)
    print(md)
    return 0
