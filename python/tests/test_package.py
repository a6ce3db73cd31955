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
    assert "lieflow" in capsys.readouterr().out
    assert list(tmp_path.iterdir()) == []


def test_shape_error_from_binding():
    with pytest.raises(lf.ShapeError, match=r"expected \(3,\)"):
        lf.lie.hat([1.0, 2.0])
