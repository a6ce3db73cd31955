import pytest

import lieflow as lf


def test_error_hierarchy():
    for name in ["NotInGroupError", "ShapeError", "NonFiniteError", "DegenerateStratumError",
                 "NoUniqueLogError", "InvalidArgumentError", "UnsupportedMethodError",
                 "ConvergenceError", "LeftDomainError"]:
        cls = getattr(lf, name)
        assert issubclass(cls, lf.LieflowError)
    assert issubclass(lf.LieflowError, ValueError)


def test_demo_runs_and_writes_nothing_unasked(tmp_path, monkeypatch, capsys):
    from lieflow.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["demo"]) == 0
    out = capsys.readouterr().out
    assert "lieflow" in out
    # It says what it simulates and in which units.
    assert "SaintVenantKirchhoff(1, 2) + Volumetric(0.5, 1.4)" in out and "units:" in out
    assert list(tmp_path.iterdir()) == []


def test_shape_error_from_binding():
    with pytest.raises(lf.ShapeError, match=r"expected \(3,\)"):
        lf.lie.hat([1.0, 2.0])


def _public_docstrings():
    """(name, docstring) of every public callable and class of lieflow and its submodules."""
    import inspect
    seen = set()
    modules = [lf] + [getattr(lf, m) for m in dir(lf)
                      if inspect.ismodule(getattr(lf, m)) and not m.startswith("_")]
    for mod in modules:
        for name in dir(mod):
            if name.startswith("_"):
                continue
            obj = getattr(mod, name)
            if id(obj) in seen or not (callable(obj) or inspect.isclass(obj)):
                continue
            seen.add(id(obj))
            yield f"{mod.__name__}.{name}", inspect.getdoc(obj) or ""
            if inspect.isclass(obj):
                for attr in dir(obj):
                    if not attr.startswith("_"):
                        member = getattr(obj, attr, None)
                        doc = inspect.getdoc(member) if member is not None else None
                        if doc and doc != inspect.getdoc(type(member)):
                            yield f"{mod.__name__}.{name}.{attr}", doc


def test_docstrings_name_only_exceptions_that_exist():
    import builtins
    import re
    wrong = []
    for name, doc in _public_docstrings():
        for exc in set(re.findall(r"\b([A-Z][A-Za-z]*(?:Error|Exception|Warning|Interrupt))\b", doc)):
            if not (hasattr(lf, exc) or hasattr(builtins, exc)):
                wrong.append(f"{name}: {exc}")
    assert not wrong, wrong


def test_each_system_s_docstring_lists_its_methods():
    """The "Methods:" paragraph of every system's docstring names exactly ``methods()`` (the
    incompressible body's methods are listed there too; Forced describes a pattern)."""
    import inspect
    import re
    systems = [c for c in vars(lf).values() if inspect.isclass(c) and issubclass(c, lf.System)
               and c not in (lf.System, lf.Forced)]
    every = set().union(*(c.methods() for c in systems))
    for cls in systems:
        doc = inspect.getdoc(cls)
        found = re.search(r"Methods?:", doc)
        assert found, cls.__name__
        paragraph = doc[found.start():].split("\n\n")[0]
        tokens = set(re.findall(r"\b[a-z][a-z0-9_]*\b", paragraph))
        listed = set(cls.methods())
        if cls is lf.PseudoRigidBody:
            listed |= set(lf.PseudoRigidBody(3, incompressible=True).methods())
        assert listed <= tokens, (cls.__name__, listed - tokens)
        # A name with an order digit (splitting8, dmv10, gauss6) is a method name: it must be
        # one of this system's.
        numbered = {t for t in tokens & every if re.search(r"\d$", t)}
        assert numbered <= listed, (cls.__name__, numbered - listed)


def test_brief_reprs_are_cut_at_a_separator_and_marked():
    from lieflow._text import brief
    assert brief([1, 2, 3], 60) == "[1, 2, 3]"
    b = brief(list(range(100)), 40)
    assert len(b) <= 40 and b.endswith("…")
    # Cut after a separator: the last number shown is whole.
    assert b[:-1].rstrip().endswith(",")
    assert brief("x" * 100, 20) == repr("x" * 100)[:19] + "…"  # no separator: cut, marked


def test_docstrings_write_formulas_as_math():
    """Formulas in the public docstrings are reST math (``:math:`R^\\top e_3```, ``.. math::``),
    rendered on the API pages, not plain-text or Unicode pseudo-math (``R^T e3``,
    ``ad*_{dH/dmu}``, ``I^{-1} M``, ``Rᵀe₃``, ``‖M‖``) outside of them."""
    import re
    plain = re.compile(r"\^T\b|\^-?1\b|\^\{-1\}|\b[Aa]d\*_|[ᵀ‖⁻¹₀₁₂₃₄₅₆₇₈₉]")
    literal = re.compile(r":math:`[^`]*`|``.*?``|`[^`]*`", re.S)
    wrong = []
    for name, doc in _public_docstrings():
        lines, prose, block = doc.splitlines(), [], None
        for line in lines:  # drop the bodies of ``.. math::`` directives and literal blocks
            indent = len(line) - len(line.lstrip())
            if block is not None and (not line.strip() or indent > block):
                continue
            block = indent if line.rstrip().endswith("::") else None
            prose.append(line)
        for hit in plain.finditer(literal.sub("", "\n".join(prose))):
            wrong.append(f"{name}: {hit.group(0)!r}")
    assert not wrong, wrong
