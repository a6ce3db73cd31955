"""The task pages of the user guide (docs/guide/tasks/*.md) run as they stand.

Each page holds one script, written as one or more ```python blocks that run in sequence; this
test joins a page's blocks in order and executes them as one script, in a fresh temporary
directory (the files the script saves go there), with matplotlib's Agg backend and lieflow's
warnings turned into errors. Code shown but not meant to run (the cluster part of the ensembles
page) is fenced as ```{code-block} python and is not executed. A page whose optional
dependencies are missing is skipped.
"""

import re
import warnings
from pathlib import Path

import pytest

import lieflow as lf

TASKS = Path(__file__).resolve().parents[2] / "docs" / "guide" / "tasks"
PAGES = sorted(p for p in TASKS.glob("*.md") if p.name != "index.md")
BLOCK = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)

# The optional packages a page needs, by what its script imports or calls.
NEEDS = [
    (re.compile(r"^\s*(import|from) (matplotlib|dask|distributed|xarray|netCDF4)\b", re.M), None),
    (re.compile(r"\blf\.plot\b|\.plot\("), ["matplotlib"]),
    (re.compile(r"\blf\.ensemble\b"), ["dask", "distributed", "xarray"]),
    (re.compile(r"\.save\(|\blf\.load\(|\.to_xarray\("), ["xarray", "netCDF4"]),
]


def script(page):
    """The page's ```python blocks, in order, as one script."""
    return "\n".join(BLOCK.findall(page.read_text(encoding="utf-8")))


def requirements(source):
    needed = set()
    for pattern, modules in NEEDS:
        for match in pattern.finditer(source):
            needed.update(modules or [match.group(2)])
    return sorted(needed)


def test_every_task_page_is_tested():
    names = {p.stem for p in PAGES}
    assert names == {"simulate", "choose_method", "check_invariants", "equilibria",
                     "continuation", "own_system", "ensembles", "save_load"}
    for page in PAGES:
        assert script(page).strip(), f"{page.name} has no ```python block"


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_task_page_runs(page, tmp_path, monkeypatch):
    source = script(page)
    needed = requirements(source)
    for module in needed:
        pytest.importorskip(module)
    plt = None
    if "matplotlib" in needed:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

    monkeypatch.chdir(tmp_path)
    code = compile(source, str(page), "exec")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", lf.LieflowWarning)
            exec(code, {"__name__": "__main__", "__file__": str(page)})
    finally:
        if plt is not None:
            plt.close("all")
    if "Client(" in source:     # the script closes its own dask client
        distributed = pytest.importorskip("distributed")
        with pytest.raises(ValueError):
            distributed.Client.current()
