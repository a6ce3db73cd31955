"""Turn the citations in API docstrings into links to the bibliography of docs/sources.md.

A source-text citation, a tag and a locator (``001 (6.9)``, ``001 §3.2``, ``001 (2.21)–(2.22)``,
``000 Theorem 4.3``), becomes ``:ref:`001 (6.9) <ref-001>```; a name of ``AUTHORS`` (``Hairer &
Vilmart``, ``Celledoni et al.``, ``Carlson``, ``EFE``, ...) a ``:ref:`` to its entry. Left alone:
inline literals, roles and emphasis, section titles, ``.. math::`` and code directives, literal
blocks after ``::`` and doctests. Never raises: a docstring the rules do not fit keeps its text.
"""
import itertools
import re

_S = r"(?:[ \t]+\n?[ \t]*|\n[ \t]*)"  # a space, or a line break: a citation may be wrapped
_EQ, _SEC, _NUM = r"\(\d+(?:\.\d+)*[a-z]?\)", r"§[\dIVX]+(?:\.[\dA-Z]+)*", r"\d+(?:\.\d+)*"
_NAMED = r"(?:Theorems?|Thm\.|Propositions?|Prop\.|Lemma|Corollary|Definition|Example|Section) "
SEED = (rf"(?P<tag>00[0-3]){_S}(?:{_EQ}(?: ?[–-] ?{_EQ})?|{_SEC}(?: ?[–-] ?§?[\dIVX]+(?:\.[\dA-Z]+)*)?"
        rf"|{_NAMED}{_NUM}(?: ?[–-] ?{_NUM})?)")
_AND, _C, _ET_AL = rf"(?:{_S}(?:&|and){_S}|[–-])", rf"(?:,{_S}|[–-])", rf"{_S}et{_S}al\."
AUTHORS = {  # label in sources.md -> the names citing it (an optional year may follow)
    "ref-hairer-lubich-wanner-2006": rf"Hairer,{_S}Lubich{_AND}Wanner|HLW",
    "ref-hairer-vilmart-2006": rf"Hairer{_AND}Vilmart|HV06",
    "ref-celledoni-fasso-safstrom-zanna-2008": rf"Celledoni(?:{_C}Fassò{_C}Säfström{_AND}Zanna|{_ET_AL})",
    "ref-blanes-casas-murua-2006": rf"Blanes{_C}Casas{_AND}Murua|BCM06",
    "ref-lee-leok-mcclamroch-2007": rf"Lee{_C}Leok{_AND}McClamroch",
    "ref-bloch-krishnaprasad-marsden-ratiu-1996": rf"Bloch{_C}Krishnaprasad{_C}Marsden{_AND}Ratiu",
    "ref-bloch-2003": rf"Bloch,{_S}Nonholonomic{_S}Mechanics{_S}and{_S}Control",
    "ref-simo-lewis-marsden-1991": rf"Simo{_C}Lewis{_AND}Marsden",
    "ref-benettin-galgani-giorgilli-strelcyn-1980": rf"Benettin{_ET_AL}",
    "ref-chandrasekhar-1969": r"Chandrasekhar|EFE",
    "ref-andersen-1983": r"RATTLE",
    "ref-henon-heiles-1964": r"Hénon[–-]Heiles",
    "ref-dlmf": r"DLMF",
    **{f"ref-{a}-{b}-{y}".lower(): rf"{a}{_AND}{b}" for a, b, y in map(str.split, (
        "Modin Viviani 2020|Moser Veselov 1991|Kahan Li 1997|Al-Mohy Higham 2009|Lewis Sendov 2001|"
        "Bernardes Viollet 2022|Abramowitz Stegun 1964|McLachlan Perlmutter 2006|Landau Lifshitz 1976"
    ).split("|"))},
    **{f"ref-{a}-{y}".lower(): a for a, y in map(str.split, (
        "Carlson 1995|Yoshida 1990|Suzuki 1990|Munthe-Kaas 1999|Brent 1973|Shepperd 1978|"
        "Montgomery 1991|Manakov 1976|Wong 1970|Guichardet 1984"
    ).split("|"))},
}
_LABELS, _YEAR = list(AUTHORS), rf"(?:{_S}(?:\((?:19|20)\d\d\)|(?:19|20)\d\d))?"
_NAMES = "|".join(rf"(?P<a{i}>(?:{p}){_YEAR})" for i, p in enumerate(AUTHORS.values()))
# Start and end only where reST inline markup may (after a space or an opening mark, before a
# space or a closing mark), so that the role a citation becomes is recognised.
CITATION = re.compile(rf"(?<![^\s(\[{{<'\"–—/:])(?:{SEED}|{_NAMES})(?![^\s.,;:!?)\]}}>'\"–—/-])")
_SPAN = re.compile(r"(?::[\w:+.-]+:)?``.+?``|(?::[\w:+.-]+:)?`[^`]+`_{0,2}|\*\*.+?\*\*|\*[^*\s][^*]*\*",
                   re.S)  # inline literals, roles, interpreted text, links, strong and emphasis
_LITERAL = re.compile(r"\s*\.\. (?:math|code|code-block|sourcecode|highlight|doctest|testcode|"
                      r"testoutput|literalinclude|parsed-literal)::")
_ADORNMENT = re.compile(r"\s*([=\-~^\"'`#*+_.:])\1+\s*$")


def _link(m):
    label, text = f"ref-{m['tag']}" if m["tag"] else _LABELS[int(m.lastgroup[1:])], m.group(0)
    if m["tag"] and re.search(r"\.\s", text):  # autosummary would cut "Prop. 4.2" inside the role
        return f":ref:`{m['tag']} <{label}>`{text[3:]}"
    return f":ref:`{text} <{label}>`"


def _link_text(text):
    """``text`` with its citations linked, outside inline literals, roles and emphasis."""
    cuts = [0] + [i for s in _SPAN.finditer(text) for i in s.span()] + [len(text)]
    return "".join(text[a:b] if k % 2 else CITATION.sub(_link, text[a:b])
                   for k, (a, b) in enumerate(zip(cuts, cuts[1:])))


def _kept(lines):
    """Which lines stay as they are: titles, literal blocks, math and code directives, doctests."""
    kept, block, doctest = [], None, False
    for line, nxt in zip(lines, lines[1:] + [""]):
        text, indent = line.strip(), len(line) - len(line.lstrip())
        if block is not None and (not text or indent > block):
            kept.append(True)
            continue
        block, doctest = None, text.startswith(">>>") or (doctest and bool(text))
        literal = _LITERAL.match(line)
        title = text and _ADORNMENT.match(nxt) and len(nxt.strip()) >= len(text)
        kept.append(bool(literal or doctest or title or _ADORNMENT.match(line)))
        block = indent if literal or (text.endswith("::") and not text.startswith("..")) else None
    return kept


def link_citations(lines):
    """The docstring ``lines`` with their citations linked (as many lines as given)."""
    out = []
    for kept, group in itertools.groupby(zip(_kept(lines), lines), key=lambda pair: pair[0]):
        text = "\n".join(line for _, line in group)
        out += (text if kept else _link_text(text)).split("\n")
    return out


def process_docstring(app, what, name, obj, options, lines):
    """The ``autodoc-process-docstring`` handler: rewrites ``lines`` in place."""
    try:
        new = link_citations(list(lines))
        if len(new) == len(lines):
            lines[:] = new
    except Exception:  # noqa: BLE001  (never fail a build over a docstring)
        pass


def setup(app):
    app.connect("autodoc-process-docstring", process_docstring, priority=600)  # after napoleon
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
