"""Trust in lieflow's files (issue 29): ``lf.load`` calls nothing but the allow-listed
constructors of lieflow (a hostile ``system_spec`` is a FileFormatError naming its entry, never
a call, a hang or gigabytes)."""

import json
import os
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import lieflow as lf
from lieflow import io as lio

xr = pytest.importorskip("xarray")

M0 = np.array([1.0, 0.5, -0.3])


def small_run():
    return lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, steps=3)


def forge(ds):
    """`ds` with valid checksums again after an edit, as a forger would make it (formats
    without checksums: unchanged)."""
    seal = getattr(lio, "_seal", None)
    return seal(ds) if seal is not None else ds


def hostile_file(tmp_path, spec, name="evil.nc"):
    """A trajectory file whose system_spec is `spec` (JSON text or data), checksums forged."""
    ds = small_run().to_xarray()
    ds.attrs["system_spec"] = spec if isinstance(spec, str) else json.dumps(spec)
    path = tmp_path / name
    forge(ds).to_netcdf(path)
    return path


# --- 1. a system spec calls nothing but lieflow's constructors ----------------------------


def test_reproducer_a_spec_cannot_run_a_shell_command(tmp_path):
    """Issue 29's reproducer: lieflow.io:os.system named in the spec of a saved file."""
    marker = tmp_path / "pwned"
    path = hostile_file(tmp_path, {"call": "lieflow.io:os.system",
                                   "args": [f"touch {marker}"]})
    with pytest.raises(lf.FileFormatError, match=r"system_spec\.call.*'lieflow\.io:os\.system'"):
        lf.load(path)
    assert not marker.exists()


def test_a_hostile_call_nested_in_an_allowed_one_is_refused_before_any_call(tmp_path):
    marker = tmp_path / "pwned"
    spec = {"call": "lieflow:PseudoRigidBody",
            "args": [3, {"call": "lieflow.io:os.system", "args": [f"touch {marker}"]}]}
    with pytest.raises(lf.FileFormatError, match=r"system_spec\.args\[1\]\.call"):
        lf.load(hostile_file(tmp_path, spec))
    assert not marker.exists()


ESCAPES = [
    ("lieflow:__builtins__", []),                              # dunder attributes
    ("lieflow.io:__class__", []),
    ("lieflow:RigidBody.__init__", []),
    ("lieflow:__loader__", []),
    ("lieflow.io:importlib.import_module", ["os"]),            # module escapes
    ("lieflow.integrate:np.load", ["/etc/passwd"]),
    ("lieflowx:system", ["true"]),
    ("lieflow.io:_resolve", ["os:system"]),                    # private lieflow functions
    ("lieflow.io:_decode", [{}]),
    ("lieflow.io:_build", [None]),
    ("lieflow.io:_allowed", ["os:system"]),
    ("lieflow.integrate:_attach_partial", [1, 2, 3, 4]),
    ("lieflow:_lieflow", []),
    ("lieflow:io.os.system", ["true"]),                        # getattr chains
    ("lieflow:RigidBody.__reduce__", []),
    ("lieflow.potentials:Harmonic.__self__", []),
    ("lieflow:integrate.__globals__", []),
    ("lieflow:integrate", [None, None, 0.1]),                  # public, not a constructor
    ("lieflow:load", ["/etc/passwd"]),
    ("lieflow.potentials:Callable", ["print", "print"]),       # needs callables: not data
    ("lieflow.surfaces:Graph", ["print"]),
    ("lieflow:Canonical", ["print", None, 1]),
    ("operator:attrgetter", ["__class__"]),                    # other operators
    ("operator:mul", ["a", 1 << 40]),
    ("operator:call", ["print"]),
    ("operator:add.__self__", []),
    ("builtins:eval", ["1"]),
    ("os:system", ["true"]),
    ("", []),
    (":", []),
]


@pytest.mark.parametrize("name,args", ESCAPES, ids=[e[0] or "empty" for e in ESCAPES])
def test_only_allow_listed_callables_may_be_named(tmp_path, name, args):
    spec = {"call": name, "args": args}
    with pytest.raises(lf.FileFormatError, match=r"system_spec\.call: .*not a lieflow callable"):
        lf.load(hostile_file(tmp_path, spec))


def test_the_sum_of_potentials_takes_two_potentials_only(tmp_path):
    h = {"call": "lieflow.potentials:Harmonic", "args": [1.0]}
    for args in (["a" * 1000, "b"], [[1] * 10, [2]], [h], [h, h, h], [h, 1.0]):
        spec = {"call": "lieflow:PseudoRigidBody",
                "args": [3, {"call": "operator:add", "args": args}]}
        with pytest.raises(lf.FileFormatError,
                           match=r"system_spec\.args\[1\]: operator:add adds two potentials"):
            lf.load(hostile_file(tmp_path, spec))
    # two potentials: a valid sum
    spec = {"call": "lieflow:PseudoRigidBody",
            "args": [3, {"call": "operator:add", "args": [h, h]}, True, False]}
    system = lio._build(lio._parse_spec(json.dumps(spec)))
    assert repr(system) == repr(lf.PseudoRigidBody(3, lf.potentials.Harmonic(1.0)
                                                   + lf.potentials.Harmonic(1.0)))


def test_the_spec_must_build_a_system(tmp_path):
    for spec in ({"call": "lieflow.potentials:Harmonic", "args": [1.0]},
                 {"call": "lieflow.surfaces:Plane", "args": []}):
        with pytest.raises(lf.FileFormatError, match="system_spec: .*not a lieflow system"):
            lf.load(hostile_file(tmp_path, spec))
    for text in ("[]", "3", '"RigidBody"', "null", '{"array": [1], "dtype": "<f8"}'):
        with pytest.raises(lf.FileFormatError, match="system_spec: expected a call"):
            lf.load(hostile_file(tmp_path, text))


RB = "lieflow:RigidBody"
BAD_ARGUMENTS = [
    # (argument, the entry named, what the message says)
    ({"array": [1, 2, 3], "dtype": "O"}, r"args\[0\]\.dtype", "not the dtype of a numeric"),
    ({"array": [1, 2, 3], "dtype": "|O"}, r"args\[0\]\.dtype", "numeric"),
    ({"array": [1, 2, 3], "dtype": "<U3"}, r"args\[0\]\.dtype", "numeric"),
    ({"array": [1, 2, 3], "dtype": "V8"}, r"args\[0\]\.dtype", "numeric"),
    ({"array": [1, 2, 3], "dtype": "<c16"}, r"args\[0\]\.dtype", "numeric"),
    ({"array": [1, 2, 3], "dtype": "(1000000000,)f8"}, r"args\[0\]\.dtype", "numeric"),
    ({"array": [1, 2, 3], "dtype": "[('a', 'O')]"}, r"args\[0\]\.dtype", "numeric"),
    ({"array": [1, 2, 3], "dtype": 8}, r"args\[0\]\.dtype", "numeric"),
    ({"array": ["1", "2", "3"], "dtype": "<f8"}, r"args\[0\]\.array", "an entry"),
    ({"array": [1, None, 3], "dtype": "<f8"}, r"args\[0\]\.array", "an entry"),
    ({"array": [1.5, 2, 3], "dtype": "<i8"}, r"args\[0\]\.array", "an entry"),
    ({"array": [[1, 2], [3]], "dtype": "<f8"}, r"args\[0\]\.array", "ragged"),
    ({"array": [[1, 2], 3], "dtype": "<f8"}, r"args\[0\]\.array", "ragged"),
    ({"array": [2 ** 64], "dtype": "<i8"}, r"args\[0\]", "out of range|not representable"),
    ({"array": [[[[[[[[[1]]]]]]]]], "dtype": "<f8"}, r"args\[0\]\.array", "dimensions"),
    ({"array": [1, 2, 3], "dtype": "<f8", "shape": [3]}, r"args\[0\]", "keys"),
    ({"call": RB, "args": [], "kwargs": {"inertia": [1, 2, 3]}}, r"args\[0\]", "keys"),
    ({"__class__": "x"}, r"args\[0\]", "keys"),
    ({}, r"args\[0\]", "keys"),
    ({"complex": ["a", 1]}, r"args\[0\]\.complex", "expected \\[real, imag\\]"),
    ({"complex": [1, 2, 3]}, r"args\[0\]\.complex", "expected \\[real, imag\\]"),
    ({"tuple": {"a": 1}}, r"args\[0\]\.tuple", "expected a list"),
    ({"call": RB, "args": {"inertia": 1}}, r"args\[0\]\.args", "expected a list"),
    ({"call": RB, "args": ["abc"]}, r"args\[0\]", "refused the arguments"),
    (2 ** 70, r"args\[0\]", "out of range"),
    ("inertia", r"system_spec", "refused the arguments"),
]


@pytest.mark.parametrize("arg,where,what", BAD_ARGUMENTS,
                         ids=[f"{i}" for i in range(len(BAD_ARGUMENTS))])
def test_arguments_of_other_types_are_refused_naming_the_entry(tmp_path, arg, where, what):
    spec = {"call": RB, "args": [arg]}
    with pytest.raises(lf.FileFormatError, match=rf"system_spec(\.|:).*{where}.*(?s:.*){what}"
                       if where != "system_spec" else what) as info:
        lf.load(hostile_file(tmp_path, spec))
    assert "system_spec" in str(info.value)


def test_huge_and_deep_specs_are_refused_quickly_without_allocating(tmp_path):
    limits = lio.SPEC_LIMITS
    deep = "[" * 200_000 + "]" * 200_000
    cases = [
        (deep, "nested|characters"),                                    # json RecursionError
        ('{"call": "lieflow:RigidBody", "args": [' + "[" * 150 + "]" * 150 + "]}",
         "nested deeper"),
        (json.dumps({"call": RB, "args": [" " * (limits["chars"] + 1)]}), "characters"),
        (json.dumps({"call": RB, "args": [{"array": [0] * (limits["values"] + 1),
                                           "dtype": "<f8"}]}), "more than 16384 values"),
        (json.dumps({"call": RB, "args": [{"array": [0] * (limits["entries"] + 1),
                                           "dtype": "<f8"}]}), "more than 2048 entries"),
        (json.dumps({"call": RB, "args": [{"array": [0] * 1500, "dtype": "<f8"},
                                          {"array": [0] * 1500, "dtype": "<f8"}]}),
         "more than 2048 entries"),
        (json.dumps({"call": RB, "args": [[[]] * (limits["values"] + 1)]}), "more than"),
        ('{"call": "lieflow:RigidBody", "args": [' + "1" * 5000 + "]}", "not valid JSON"),
        ('{"call": "lieflow:RigidBody", "args": [1, 2', "not valid JSON"),
    ]
    for text, what in cases:
        path = hostile_file(tmp_path, text)
        start = time.perf_counter()
        with pytest.raises(lf.FileFormatError, match=what):
            lf.load(path)
        assert time.perf_counter() - start < 5
    # deep nesting handed to the parser directly (no file): still a FileFormatError
    with pytest.raises(lf.FileFormatError, match="nested"):
        lio._parse_spec("[" * 1_000_000)
    with pytest.raises(lf.FileFormatError, match="nested"):
        lio._parse_spec('{"call": "lieflow:RigidBody", "args": ' + "[" * 1_000_000)


def test_the_largest_allowed_arguments_allocate_little():
    """Every allowed constructor given the largest arrays and integers the limits let through
    (and sizes that are dimensions: so(64) has 2016 components, so(10) 45): an error or a
    system, in well under a gigabyte and a few seconds (in a subprocess, whose peak memory is
    measured). GeneralizedRigidBody(J) allocates dense (m, m) matrices for m = len(J): the
    limit on array entries is what keeps it small."""
    code = textwrap.dedent("""
        import json, resource
        import lieflow as lf
        from lieflow import io as lio
        n = lio.SPEC_LIMITS["entries"]
        big = {"array": [1.0 + 1e-6 * i for i in range(n)], "dtype": "<f8"}
        so64 = {"array": [1.0 + 1e-6 * i for i in range(64 * 63 // 2)], "dtype": "<f8"}
        square = {"array": [[1.0] * 45] * 45, "dtype": "<f8"}
        cube = {"array": [[[1.0] * 12] * 12] * 12, "dtype": "<f8"}
        zero = {"call": "lieflow.potentials:Zero", "args": []}
        huge = 2 ** 63 - 1
        arguments = [[big], [so64], [huge], [big, huge], [huge, big], [square], [cube],
                     [10 ** 5], [10 ** 9, zero], [700, zero], [3000, zero, False, True],
                     ["so", huge], [{"tuple": ["so", 100000]}, square],
                     [{"tuple": ["so", 2000]}, square], [{"tuple": ["so", 10]}, square],
                     [huge] * 8, [10 ** 6] * 8]
        outcomes = {}
        for args in arguments:
            parsed = lio._parse_spec(json.dumps({"call": "lieflow:RigidBody", "args": args}))
            for name in sorted(lio.ALLOWED_CALLS):
                try:
                    lio._build(lio._Call(name, parsed.args, "system_spec"))
                    outcome = "built"
                except lf.FileFormatError:
                    outcome = "refused"
                outcomes[outcome] = outcomes.get(outcome, 0) + 1
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        print(json.dumps({"peak": peak, "outcomes": outcomes}))
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["peak"] < 1 << 29, result
    assert result["outcomes"]["refused"] > 0 and result["outcomes"]["built"] > 0, result


def test_a_spec_is_parsed_before_anything_is_called(monkeypatch):
    """A hostile entry late in the spec: the allowed calls before it are not made either."""
    calls = []
    real = lio._allowed
    monkeypatch.setattr(lio, "_allowed", lambda name: calls.append(name) or real(name))
    spec = {"call": "lieflow:Forced",
            "args": [{"call": "lieflow:RigidBody", "args": [[1.0, 2.0, 3.0]]}, None, None, None,
                     {"call": "os:system", "args": ["true"]}]}
    with pytest.raises(lf.FileFormatError, match=r"system_spec\.args\[4\]\.call"):
        lio._parse_spec(json.dumps(spec))
    assert calls == []


# --- the allow-list: complete (every system stored as data round-trips), and constructors only


def _receivers():
    """The receivers of the fuzz table that are systems, potentials or surfaces."""
    from fuzz.examples import FORCED_STATES, RECEIVER_MODULE, RECEIVERS, SYSTEMS, USER_STATES

    keys = (list(SYSTEMS) + list(USER_STATES) + list(FORCED_STATES)
            + [k for k, m in RECEIVER_MODULE.items() if m in ("potentials", "surfaces")])
    return {k: RECEIVERS[k] for k in keys}


#: Receivers of the fuzz table built from Python callables: never data (saved pickled only).
HOLD_CALLABLES = {"ucan", "usep", "ulp", "frc", "callable", "revolution", "graph", "metric"}


def _stored_objects(lf_module):
    """(key, system) for every system of the fuzz table and every potential and surface of it
    inside a system that takes one."""
    out = []
    for key, make in _receivers().items():
        obj = make(lf_module)
        if isinstance(obj, lf.System):
            out.append((key, obj))
        elif isinstance(obj, lf.potentials.Potential):
            out.append((key, lf.PseudoRigidBody(3, obj)))
            out.append((key + "-incompressible", lf.PseudoRigidBody(3, obj, incompressible=True)))
        elif isinstance(obj, lf.surfaces.Surface):
            out.append((key, lf.TangentTop(obj, 1.0, 0.5)))
            out.append((key + "-relativistic", lf.RelativisticTangentTop(1.0, 0.2, obj)))
    out += [("forced-damped", lf.Forced(lf.Pendulum(1.0, 1.0, 9.81), damping=0.3)),
            ("forced-dissipation", lf.Forced(lf.RigidBody([1.0, 2.0, 3.0]), dissipation=0.5)),
            ("lie-poisson-so4", lf.LiePoisson(("so", 4), np.eye(6))),
            ("charged", lf.TangentTop(lf.surfaces.Torus(2.0, 0.7), 1.0, 0.5)
             .magnetic_analogue(0.3)),
            ("int32-array", lf.RigidBody(np.array([1, 2, 3], dtype=np.int32)))]
    return out


def _names(spec):
    """The callables a spec names."""
    if isinstance(spec, list):
        return set().union(*map(_names, spec)) if spec else set()
    if isinstance(spec, dict):
        out = {spec["call"]} if "call" in spec else set()
        return out.union(*(_names(v) for v in spec.values()))
    return set()


def test_every_system_stored_as_data_round_trips_and_the_allow_list_is_complete():
    used = set()
    for key, system in _stored_objects(lf):
        try:
            data = lio._encode(system)
        except lio._NotData:
            assert key.split("-")[0] in HOLD_CALLABLES, f"{key}: {system!r} is not data"
            continue
        assert key.split("-")[0] not in HOLD_CALLABLES, key
        names = _names(data)
        assert names <= lio.ALLOWED_CALLS, (key, names - lio.ALLOWED_CALLS)
        used |= names
        back = lio._build(lio._parse_spec(json.dumps(data)))
        assert type(back) is type(system) and repr(back) == repr(system), key
        assert lio._encode(back) == data, key
        assert back.methods() == system.methods(), key
    # every entry is needed by some system of the table: none is there only to be called
    assert used == lio.ALLOWED_CALLS, sorted(lio.ALLOWED_CALLS - used)


def test_every_allowed_entry_is_a_constructor():
    assert isinstance(lio.ALLOWED_CALLS, frozenset)
    for name in lio.ALLOWED_CALLS:
        module, _, attr = name.partition(":")
        assert "." not in attr and not attr.startswith("_"), name
        obj = lio._allowed(name)
        if module == "lieflow":
            assert isinstance(obj, type) and issubclass(obj, lf.System), name
            assert getattr(lf, attr) is obj and attr in lf.__all__, name
        elif module in ("lieflow.potentials", "lieflow.surfaces"):
            mod = getattr(lf, module.split(".")[1])
            assert attr in mod.__all__ and getattr(mod, attr) is obj, name
            assert attr[0].isupper() and obj.__doc__, name     # a documented factory
        else:
            assert name == "operator:add", name


def test_a_saved_file_of_each_kind_of_stored_system_loads(tmp_path):
    """A few systems through real files (the spec round trip above covers them all)."""
    for system, state in ((lf.LiePoisson(("so", 4), np.eye(6)), [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]),
                          (lf.Forced(lf.RigidBody([1.0, 2.0, 3.0]), dissipation=0.5), M0)):
        traj = lf.integrate(system, state, dt=0.01, steps=5)
        traj.save(tmp_path / "run.nc")
        back = lf.load(tmp_path / "run.nc")
        assert repr(back.system) == repr(system)
        np.testing.assert_array_equal(back.states, traj.states)
