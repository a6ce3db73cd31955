"""The docs extension that links docstring citations to the bibliography (docs/_ext/citations.py).

The extension is imported by its path and run on sample docstring lines; no Sphinx build needed.
"""

import importlib.util
import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _load():
    path = DOCS / "_ext" / "citations.py"
    spec = importlib.util.spec_from_file_location("lieflow_docs_citations", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


citations = _load()
link = citations.link_citations


CASES = [  # (docstring line, the line with its citation linked)
    ("The reduced field (001 (7.25)).", "The reduced field (:ref:`001 (7.25) <ref-001>`)."),
    ("Connections 001 (2.21)–(2.22), and", "Connections :ref:`001 (2.21)–(2.22) <ref-001>`, and"),
    ("See 001 §3.2 and 000 Theorem 4.3.",
     "See :ref:`001 §3.2 <ref-001>` and :ref:`000 Theorem 4.3 <ref-000>`."),
    ("the metric 002 (47): x", "the metric :ref:`002 (47) <ref-002>`: x"),
    ("field, 001 Prop. 4.2 (5.5)", "field, :ref:`001 <ref-001>` Prop. 4.2 (5.5)"),
    ("the Lagrangian (003 (8))", "the Lagrangian (:ref:`003 (8) <ref-003>`)"),
    ("dmv10 (Hairer & Vilmart 2006), rk4",
     "dmv10 (:ref:`Hairer & Vilmart 2006 <ref-hairer-vilmart-2006>`), rk4"),
    ("after Celledoni et al. (2008).",
     "after :ref:`Celledoni et al. (2008) <ref-celledoni-fasso-safstrom-zanna-2008>`."),
    ("(Blanes–Casas–Murua processed splittings",
     "(:ref:`Blanes–Casas–Murua <ref-blanes-casas-murua-2006>` processed splittings"),
    ("by Carlson's R_J", "by :ref:`Carlson <ref-carlson-1995>`'s R_J"),
    ("(Modin & Viviani, eq. (9))", "(:ref:`Modin & Viviani <ref-modin-viviani-2020>`, eq. (9))"),
    ("the LGVI of Lee, Leok & McClamroch",
     "the LGVI of :ref:`Lee, Leok & McClamroch <ref-lee-leok-mcclamroch-2007>`"),
    ("(EFE ch. 3 §21)", "(:ref:`EFE <ref-chandrasekhar-1969>` ch. 3 §21)"),
]


@pytest.mark.parametrize(("line", "expected"), CASES)
def test_citations_become_refs(line, expected):
    assert link([line]) == [expected]


@pytest.mark.parametrize(
    "line",
    [
        "A plain sentence with no citation, 3 (4.1) and x001 (6.9), 0.001 (2).",
        "``001 (6.9)`` stays a literal, as does `Carlson` and :math:`001 (6.9)`.",
        "An already linked :ref:`001 (6.9) <ref-001>` is not linked twice.",
        "*Hairer & Vilmart 2006* in emphasis stays as it is.",
    ],
)
def test_lines_without_a_linkable_citation_are_unchanged(line):
    assert link([line]) == [line]


def test_blocks_titles_and_wrapped_citations():
    lines = [
        "Title with 001 (6.9)",
        "--------------------",
        "",
        "Example::",
        "",
        "    x = f(001 (6.9))",
        "",
        ".. math::",
        "",
        "   000 (4.1) = 1",
        "",
        ">>> g(002 (47))",
        "",
        "Text after the blocks cites 001",
        "    (3.4) on two lines.",
    ]
    out = link(lines)
    assert len(out) == len(lines)
    assert out[:13] == lines[:13]
    assert out[13:] == ["Text after the blocks cites :ref:`001",
                        "    (3.4) <ref-001>` on two lines."]


def test_process_docstring_edits_in_place_and_tolerates_odd_input():
    lines = ["See 003 §2.2.", "", "Args:", "    x: as in 001 (3.20)."]
    citations.process_docstring(None, "function", "f", None, {}, lines)
    assert lines == ["See :ref:`003 §2.2 <ref-003>`.", "", "Args:",
                     "    x: as in :ref:`001 (3.20) <ref-001>`."]
    odd = ["``unclosed literal 001 (6.9)", "`", "*", "::", "   ", "\t001 (1)"]
    before = list(odd)
    citations.process_docstring(None, "module", "m", None, {}, odd)
    assert len(odd) == len(before)
    empty = []
    citations.process_docstring(None, "module", "m", None, {}, empty)
    assert empty == []


def test_every_linked_label_is_defined_in_sources_md():
    text = (DOCS / "sources.md").read_text(encoding="utf-8")
    defined = set(re.findall(r"^\((ref-[\w-]+)\)=$", text, flags=re.M))
    linked = set(citations.AUTHORS) | {f"ref-00{i}" for i in range(4)}
    assert not linked - defined, f"linked, not defined in sources.md: {sorted(linked - defined)}"
    # and every label the module can emit is one of these
    out = "\n".join(link([f"{tag} (1.1)" for tag in ("000", "001", "002", "003")]))
    assert set(re.findall(r"<(ref-[\w-]+)>", out)) <= defined


def test_each_bibliography_entry_says_what_it_is_used_for():
    text = (DOCS / "sources.md").read_text(encoding="utf-8")
    bibliography = text[text.index("## Bibliography"):]
    entries = re.split(r"^\(ref-[\w-]+\)=$", bibliography, flags=re.M)[1:]
    assert len(entries) >= 4
    for entry in entries:
        assert "Used for:" in entry
