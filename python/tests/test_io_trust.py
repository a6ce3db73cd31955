"""Trust in lieflow's files (issue 29): ``lf.load`` calls nothing but the allow-listed
constructors of lieflow (a hostile ``system_spec`` is a FileFormatError naming its entry, never
a call, a hang or gigabytes), and a damaged file is a FileFormatError, never changed numbers
(checksums, and the metadata checked against the data)."""

import json
import os
import subprocess
import sys
import textwrap
import time
import warnings

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
    assert result["peak"] < 1 << 30, result       # 240 MB alone, 600 MB seen under load
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
HOLD_CALLABLES = {"ucan", "usep", "ulp", "uep", "frc", "callable", "revolution", "graph",
                  "metric"}


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
            ("lie-poisson-right", lf.LiePoisson("se3", np.eye(6), side="right")),
            ("euler-poincare", lf.EulerPoincare(("so", 4), inertia=np.diag(np.arange(1.0, 7.0)),
                                                side="right")),
            ("charged", lf.TangentTop(lf.surfaces.Torus(2.0, 0.7), 1.0, 0.5)
             .magnetic_analogue(0.3)),
            ("int32-array", lf.RigidBody(np.array([1, 2, 3], dtype=np.int32))),
            ("frame-top-flat", lf.FrameTop(lf.spaces.Euclidean(3), 1.0, [1.0, 2.0, 3.0])),
            ("frame-top-hyperbolic", lf.FrameTop(lf.spaces.Hyperbolic(3, radius=2.0), 1.0,
                                                 np.diag([1.0, 2.0, 3.0])))]
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
        elif module == "lieflow.pseudo_rigid":
            assert isinstance(obj, type) and issubclass(obj, lf.System), name
            assert getattr(lf.pseudo_rigid, attr) is obj and attr in lf.pseudo_rigid.__all__, name
        elif module in ("lieflow.potentials", "lieflow.surfaces", "lieflow.spaces"):
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


# --- 4. a damaged file is a FileFormatError, never changed numbers -----------------------


def as_format_1(ds):
    """`ds` as a format-1 Dataset (no checksums), as a Dataset edited by hand is loaded."""
    ds = ds.copy()
    ds.attrs.pop("lieflow_checksums", None)
    ds.attrs.pop("sampling", None)
    ds.attrs["lieflow_format"] = 1
    return ds


def load1(ds):
    """lf.load of a format-1 Dataset (its warning that it cannot be verified expected)."""
    with pytest.warns(UserWarning, match="format 1, without checksums"):
        return lf.load(ds)


def heavy_top_batch(steps=40, every=4):
    hv = lf.HeavyTop([1.0, 2.0, 3.0], 0.7)
    state0 = (np.stack([M0, 2 * M0]), np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]))
    return lf.integrate(hv, state0, dt=0.01, steps=steps, save_every=every, attitude=np.eye(3))


def test_files_carry_format_2_checksums_and_sampling(tmp_path):
    traj = heavy_top_batch()
    ds = traj.to_xarray()
    assert lio.FORMAT == 2 and ds.attrs["lieflow_format"] == 2
    sums = json.loads(ds.attrs["lieflow_checksums"])
    assert sums["algorithm"] == "sha256"
    assert set(sums["variables"]) == {str(v) for v in ds.variables}
    assert ds.attrs["sampling"] == "grid"
    traj.save(tmp_path / "run.nc")
    with warnings.catch_warnings():
        warnings.simplefilter("error")           # a format-2 file loads without a warning
        back = lf.load(tmp_path / "run.nc")
    np.testing.assert_array_equal(back.states, traj.states)
    t_eval = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, t_eval=[0.0, 0.05, 0.3])
    assert t_eval.to_xarray().attrs["sampling"] == "irregular"


def test_format_1_loads_with_a_warning_and_the_format_must_match_the_checksums(tmp_path):
    traj = heavy_top_batch()
    back = load1(as_format_1(traj.to_xarray()))
    np.testing.assert_array_equal(back.states, traj.states)
    assert back.save_every == 4 and back.dt == 0.01
    ds = traj.to_xarray()
    ds.attrs["lieflow_format"] = 1
    with pytest.raises(lf.FileFormatError, match="claims format 1 but carries checksums"):
        lf.load(ds)
    ds = traj.to_xarray()
    del ds.attrs["lieflow_checksums"]
    with pytest.raises(lf.FileFormatError, match="claims format 2 but carries no checksums"):
        lf.load(ds)


def test_a_changed_dataset_fails_its_checksums_naming_what_changed():
    traj = heavy_top_batch()
    ds = traj.to_xarray()
    ds["states"].values[1, 3, 2] += 1e-12
    with pytest.raises(lf.FileFormatError, match="variable 'states' does not match its SHA-256"):
        lf.load(ds)
    ds = traj.to_xarray()
    ds.coords["time"] = ds["time"] + 1.0
    with pytest.raises(lf.FileFormatError, match="variable 'time' does not match"):
        lf.load(ds)
    ds = traj.to_xarray()
    ds.attrs["dt"] = 0.02
    with pytest.raises(lf.FileFormatError, match="attributes .* do not match"):
        lf.load(ds)
    ds = traj.to_xarray()
    ds["extra"] = ("time", np.zeros(ds.sizes["time"]))
    with pytest.raises(lf.FileFormatError, match="'extra' is not covered by its checksums"):
        lf.load(ds)
    ds = traj.to_xarray().drop_vars("energy")
    with pytest.raises(lf.FileFormatError, match="'energy' listed in its checksums is missing"):
        lf.load(ds)
    ds = traj.to_xarray()
    ds.attrs["lieflow_checksums"] = ds.attrs["lieflow_checksums"][:-5]
    with pytest.raises(lf.FileFormatError, match="lieflow_checksums cannot be read"):
        lf.load(ds)


# Each cross-check on a format-1 Dataset (no checksums to catch the edit first).

def edited(traj, edit):
    ds = as_format_1(traj.to_xarray())
    edit(ds)
    return ds


def _set(name, value):
    def edit(ds):
        ds.attrs[name] = value
    return edit


def _var(name, f):
    def edit(ds):
        ds[name] = (ds[name].dims, f(ds[name].values.copy()))
    return edit


def _swap_times(ds):
    t = ds["time"].values.copy()
    t[[2, 3]] = t[[3, 2]]
    ds.coords["time"] = t


CROSS_CHECKS = [
    ("dt 0.5 with times spaced 0.01", _set("dt", 0.5), r"t\[1\] = .* is not t0 \+ 1"),
    ("save_every", _set("save_every", 2), r"t\[1\] = .* is not t0 \+ 1"),
    ("t0", _set("t0", 0.001), r"is not t0 \+ 0|precedes t0"),
    ("t_final after the run", _set("t_final", 0.5), r"t_final = 0\.5 is not|samples, but a run"),
    ("t_final off the grid", _set("t_final", 0.405), r"t_final = 0\.405 is not t0 \+ n \* dt"),
    ("t_final before the last sample", _set("t_final", 0.2), "after t_final"),
    ("status", _set("status", 7), "status is 7"),
    ("status 1 without events", _set("status", 1), "status 1 .* no events"),
    ("dt 0", _set("dt", 0.0), "dt is 0.0; expected a finite time step"),
    ("dt negative", _set("dt", -0.01), "dt is -0.01"),
    ("dt nan", _set("dt", float("nan")), "dt is nan"),
    ("dt text", _set("dt", "0.01"), "dt is '0.01'; expected a real number"),
    ("save_every 0", _set("save_every", 0), "save_every is 0; expected >= 1"),
    ("save_every real", _set("save_every", 4.0), "save_every is 4.0; expected an integer"),
    ("t0 inf", _set("t0", float("inf")), "t0 is inf"),
    ("method", _set("method", "verlet"), "method 'verlet' is not one of the methods of HeavyTop"),
    ("methods of a joined run", lambda ds: (ds.attrs.pop("method"), ds.attrs.__setitem__(
        "methods", '["splitting", "rattle"]')), "method 'rattle' is not one of"),
    ("methods not a list", lambda ds: (ds.attrs.pop("method"), ds.attrs.__setitem__(
        "methods", '{"a": 1}')), "methods is not a list of names"),
    ("no method", lambda ds: ds.attrs.pop("method"), "names no method"),
    ("valid methods", lambda ds: (ds.attrs.pop("method"), ds.attrs.__setitem__(
        "methods", '["splitting", "rk4"]')), None),
    ("initial_state", _var("initial_state", lambda x: x + 1e-15), "initial_state differs"),
    ("final_state", _var("final_state", lambda x: x * 2), "final_state differs"),
    ("initial_attitude", _var("initial_attitude", lambda x: -x), "initial_attitude differs"),
    ("times not increasing", _swap_times, "not increasing"),
    ("time nan", lambda ds: ds.coords.__setitem__("time", np.r_[ds["time"].values[:-1], np.nan]),
     "not all finite"),
    ("member coordinate", lambda ds: ds.coords.__setitem__("member", [1, 0]), "member"),
    ("states dims", lambda ds: ds.__setitem__("states", (("member", "time", "comp"),
                                                          ds["states"].values)),
     "states has dimensions"),
    ("final_state shape", lambda ds: ds.__setitem__(
        "final_state", (("member", "c3"), ds["final_state"].values[:, :3])),
     "final_state has dimensions"),
    ("attitude dims", lambda ds: ds.__setitem__("attitude", (("member", "time", "r", "c"),
                                                             ds["attitude"].values)),
     "attitude has dimensions"),
    ("energy dims", lambda ds: ds.__setitem__("energy", (("time", "member"),
                                                         ds["energy"].values.T)),
     "energy has dimensions|expected .*'time'.* first"),
    ("states as integers", _var("states", lambda x: x.astype(np.int64)), "expected floats"),
    ("sampling", _set("sampling", "sometimes"), "sampling is 'sometimes'"),
    ("sampling grid without save_every", lambda ds: (ds.attrs.pop("save_every"),
                                                     ds.attrs.__setitem__("sampling", "grid")),
     "sampling 'grid' needs"),
]


@pytest.mark.parametrize("name,edit,what", CROSS_CHECKS, ids=[c[0] for c in CROSS_CHECKS])
def test_the_metadata_are_checked_against_the_data(name, edit, what):
    traj = heavy_top_batch()          # 40 steps of 0.01 saving every 4th: 11 samples
    ds = edited(traj, edit)
    if what is None:                  # a valid edit: loads
        load1(ds)
        return
    with pytest.raises(lf.FileFormatError, match=what), warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        lf.load(ds)


def _events_run():
    g = lambda t, s: s[1]  # noqa: E731
    g.direction, g.terminal = -1.0, True
    return lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, steps=600, events=g,
                        save_every=7, attitude=np.eye(3))


def _late_event(ds):
    """The terminal event (the last sample) moved 0.5 after the sample before it."""
    late = float(ds["time"].values[-2]) + 0.5
    ds.coords["time"] = np.r_[ds["time"].values[:-1], late]
    ds.attrs["t_final"] = late


def test_event_cross_checks():
    traj = _events_run()
    assert traj.status == 1 and traj.t[-1] == traj.t_final
    load1(as_format_1(traj.to_xarray()))
    for edit, what in [
            (_set("event_functions", 2), "no variable t_events_1"),
            (_set("t_final", float(traj.t[-1]) + 0.001), "not the time of the terminal event"),
            (_late_event, "more than save_every \\* dt"),
            (_var("t_events_0", lambda x: x + 10.0), "event times"),
            (lambda ds: ds.__setitem__("state_events_0", (("event_0", "x"),
                                                          ds["state_events_0"].values)),
             "state_events_0 has dimensions"),
            (_var("final_state", lambda x: x + 1.0), "final_state differs")]:
        with pytest.raises(lf.FileFormatError, match=what), warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            lf.load(edited(traj, edit))


def test_irregular_runs_round_trip_in_both_formats(tmp_path):
    """t_eval runs, joined runs whose grids do not line up, partial runs and empty ones: the
    writer marks them 'irregular' (or 'grid') so that every trajectory it writes loads."""
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    a = lf.integrate(rb, M0, dt=0.01, steps=7, save_every=3)
    b = lf.integrate(rb, a.final_state, dt=0.01, steps=10, save_every=3, t0=a.t_final)
    joined = lf.Trajectory.concatenate([a, b])
    c = lf.integrate(rb, M0, dt=0.01, steps=9, save_every=3)
    d = lf.integrate(rb, c.final_state, dt=0.01, steps=9, save_every=3, t0=c.t_final)
    aligned = lf.Trajectory.concatenate([c, d])
    runs = {
        "t_eval": lf.integrate(rb, M0, dt=0.01, t_eval=[0.0, 0.013, 0.5]),
        "t_eval from later": lf.integrate(rb, M0, dt=0.01, steps=60, t_eval=[0.013, 0.5, 0.6]),
        "joined": joined,
        "joined on the grid": aligned,
        "empty batch": lf.integrate(rb, np.zeros((0, 3)), dt=0.01, steps=5),
        "remainder": lf.integrate(rb, M0, dt=0.01, steps=10, save_every=4),
        "events": _events_run(),
        "far from 0": lf.integrate(rb, M0, dt=1e-3, steps=50, save_every=7, t0=1e6 + 0.1),
    }
    for name, traj in runs.items():
        traj.save(tmp_path / "run.nc")
        back = lf.load(tmp_path / "run.nc")
        np.testing.assert_array_equal(back.t, traj.t, err_msg=name)
        np.testing.assert_array_equal(back.states, traj.states, err_msg=name)
        assert (back.t_final, back.t0, back.dt, back.save_every, back.status) == \
            (traj.t_final, traj.t0, traj.dt, traj.save_every, traj.status), name
        back = load1(as_format_1(traj.to_xarray()) if name not in ("joined",) else
                     _with_sampling(as_format_1(traj.to_xarray()), "irregular"))
        np.testing.assert_array_equal(back.states, traj.states, err_msg=name)
    assert joined.to_xarray().attrs["sampling"] == "irregular"
    assert aligned.to_xarray().attrs["sampling"] == "grid"
    # a format-1 file of a joined run off the grid: refused, saying how to load it
    with pytest.raises(lf.FileFormatError, match=r"t\[3\] = 0\.07 is not .*sampling'\] = "
                       r"'irregular'"), warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        lf.load(as_format_1(joined.to_xarray()))


def _with_sampling(ds, value):
    ds.attrs["sampling"] = value
    return ds


def test_a_partial_run_round_trips(tmp_path):
    calls = []

    def boom(t, s):
        calls.append(t)
        if len(calls) > 30:
            raise RuntimeError("stop")
        return 1.0

    with pytest.raises(RuntimeError) as info:
        lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, steps=100, save_every=4,
                     events=boom)
    partial = info.value.partial
    assert partial.status == -1
    partial.save(tmp_path / "partial.nc")
    back = lf.load(tmp_path / "partial.nc")
    np.testing.assert_array_equal(back.states, partial.states)
    assert back.t_final == partial.t_final and back.status == -1


def test_save_refuses_a_trajectory_its_file_could_not_be_read_back_from(tmp_path):
    traj = small_run()
    broken = lf.Trajectory(traj.system, traj.method, traj.t[::-1].copy(), traj.states,
                           None, traj.final_state, None, traj.dt, 1, t0=0.0)
    with pytest.raises(lf.InvalidArgumentError, match="lf.load would refuse .*not increasing"):
        broken.save(tmp_path / "x.nc")
    assert not (tmp_path / "x.nc").exists()
    wrong = lf.Trajectory(traj.system, "verlet", traj.t, traj.states, None, traj.final_state,
                          None, traj.dt, 1, t0=0.0, t_final=traj.t_final)
    with pytest.raises(lf.InvalidArgumentError, match="method 'verlet' is not one of"):
        wrong.save(tmp_path / "x.nc")


def test_a_header_declaring_more_data_than_the_file_holds_is_refused_before_allocating(
        tmp_path):
    netCDF4 = pytest.importorskip("netCDF4")
    path = tmp_path / "huge.nc"
    with netCDF4.Dataset(path, "w") as f:
        f.createDimension("time", 2**31)
        f.createDimension("component", 4)
        f.createVariable("time", "f8", ("time",), zlib=True, chunksizes=(1024,))
        f.createVariable("states", "f8", ("time", "component"), zlib=True,
                         chunksizes=(1024, 4))
        f.lieflow_format = 2
    assert path.stat().st_size < 1 << 20
    with pytest.raises(lf.FileFormatError, match="declare .* bytes of data, more than"):
        lf.load(path)


def test_ensemble_datasets_are_not_trajectory_files(tmp_path):
    pytest.importorskip("dask")
    ds = lf.ensemble.integrate(lf.RigidBody([1.0, 2.0, 3.0]), np.stack([M0, 2 * M0]), dt=0.01,
                               steps=4).compute()
    ds.to_netcdf(tmp_path / "ens.nc")
    with pytest.raises(lf.FileFormatError, match="not a lieflow trajectory"):
        lf.load(tmp_path / "ens.nc")


# --- the byte-flip sweep -----------------------------------------------------------------

WORKER = textwrap.dedent("""
    import hashlib, json, sys, warnings
    import numpy as np
    from lieflow import io as lio

    def digest(parts):
        h = hashlib.sha256()
        for key in sorted(parts):
            value = parts[key]
            values = value if isinstance(value, list) else [value]
            h.update(key.encode())
            for v in values:
                if isinstance(v, np.ndarray):
                    h.update(f"{v.dtype.str}{v.shape}".encode())
                    h.update(np.ascontiguousarray(v).tobytes())
                elif key == "system":
                    h.update(f"{type(v).__name__}{v!r}".encode())
                else:
                    h.update(repr(v).encode())
        return h.hexdigest()

    warnings.simplefilter("error")       # a damaged file must not load as format 1 either
    for line in sys.stdin:
        try:
            out = {"digest": digest(lio.read(line.strip()))}
        except lio.FileFormatError as e:
            out = {"error": "FileFormatError", "message": str(e)[:300]}
        except BaseException as e:
            out = {"error": type(e).__name__, "message": str(e)[:300]}
        print(json.dumps(out), flush=True)
""")


class Worker:
    """A subprocess that loads the files it is given, one per line, and answers with the
    digest of what it read or the error; a crash or a hang of it is an outcome too."""

    def __init__(self):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
        self.proc = subprocess.Popen([sys.executable, "-c", WORKER], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True, env=env)

    def load(self, path, timeout=30.0):
        import select

        self.proc.stdin.write(f"{path}\n")
        self.proc.stdin.flush()
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        if not ready:
            self.proc.kill()
            return {"error": "hang"}
        line = self.proc.stdout.readline()
        if not line:
            return {"error": f"crash (exit {self.proc.wait()})"}
        return json.loads(line)

    def close(self):
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait(timeout=30)


def test_single_byte_changes_and_truncations_never_load_changed_numbers(tmp_path):
    """A trajectory file of a few MB, each of 240 single-byte changes (fixed seed; a third in
    the first and last 64 KiB, where HDF5 keeps most of its metadata) and a set of
    truncations on a fresh copy: loading gives the original trajectory bit for bit or a
    FileFormatError; never other numbers, another error, a crash or a hang. Loads run in a
    worker subprocess (HDF5 is C: a crash must not take the test run down)."""
    hv = lf.HeavyTop([1.0, 2.0, 3.0], 0.7)
    rng = np.random.default_rng(29)
    m = rng.standard_normal((12, 3))
    g = np.tile([0.0, 0.0, 1.0], (12, 1))          # Γ = Rᵀe₃ with the attitude R = I
    traj = lf.integrate(hv, (m, g), dt=0.01, steps=3000, save_every=3, attitude=np.eye(3))
    original = tmp_path / "original.nc"
    traj.save(original)
    data = original.read_bytes()
    size = len(data)
    assert 2e6 < size < 8e6, size
    edge = 1 << 16
    offsets = np.r_[rng.integers(0, size, 160), rng.integers(0, edge, 50),
                    rng.integers(size - edge, size, 30)]
    changes = [(int(o), int(rng.integers(1, 256))) for o in offsets]
    cuts = sorted({0, 1, 8, 100, 2048, edge, size // 3, size // 2, size - edge, size - 4096,
                   size - 100, size - 8, size - 1})
    worker = Worker()
    outcomes, bad = {}, []
    try:
        reference = worker.load(original)
        assert "digest" in reference, reference
        cases = [("flip", o, x) for o, x in changes] + [("cut", c, 0) for c in cuts]
        for kind, offset, xor in cases:
            damaged = tmp_path / f"damaged-{kind}-{offset}.nc"
            if kind == "flip":
                b = bytearray(data)
                b[offset] ^= xor
                damaged.write_bytes(bytes(b))
            else:
                damaged.write_bytes(data[:offset])
            out = worker.load(damaged)
            damaged.unlink()
            if "digest" in out:
                result = "identical" if out["digest"] == reference["digest"] else "CHANGED"
            else:
                result = out["error"]
            outcomes.setdefault(kind, {}).setdefault(result, 0)
            outcomes[kind][result] += 1
            if result not in ("identical", "FileFormatError"):
                bad.append((kind, offset, xor, out))
            if result.startswith(("crash", "hang")):
                worker = Worker()         # the one that crashed or hung is dead
    finally:
        worker.close()
    print(f"\nbyte-flip sweep of a {size}-byte file: {outcomes}")
    assert not bad, (outcomes, bad[:10])
    assert sum(outcomes["flip"].values()) == len(changes) >= 200
    assert outcomes["flip"].get("FileFormatError", 0) > 100   # most bytes are checked data


def test_cross_checks_of_irregular_runs():
    """A t_eval run's samples at t0 and at the end equal the initial and final states to
    round-off (a step of size 0, another last step), and are checked to that tolerance."""
    traj = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, t_eval=[0.0, 0.013, 0.5])
    assert traj.t[0] == traj.t0 and traj.t[-1] == traj.t_final
    load1(as_format_1(traj.to_xarray()))
    for name in ("initial_state", "final_state"):
        with pytest.raises(lf.FileFormatError, match=f"{name} differs"), \
                warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            lf.load(edited(traj, _var(name, lambda x: x + 1e-6)))
    with pytest.raises(lf.FileFormatError, match="after t_final"), warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        lf.load(edited(traj, _set("t_final", 0.4)))


def test_a_file_opened_by_xarray_itself_verifies(tmp_path):
    """xarray's default decoding (masks, CF conventions) leaves a lieflow file's values as
    they were written: lf.load of the opened Dataset verifies its checksums."""
    traj = heavy_top_batch()
    traj.save(tmp_path / "run.nc")
    with xr.open_dataset(tmp_path / "run.nc") as ds:
        back = lf.load(ds.load())
    np.testing.assert_array_equal(back.states, traj.states)
    np.testing.assert_array_equal(back.attitude, traj.attitude)


def test_the_invariant_labels_are_checksummed_as_text(tmp_path):
    """The `invariant` coordinate (the system's invariant_names) is the one text variable a
    file holds: it round-trips, a relabelled one is refused, and any other text is refused."""
    traj = heavy_top_batch()
    traj.save(tmp_path / "run.nc")
    with xr.open_dataset(tmp_path / "run.nc") as ds:
        ds = ds.load()
    assert list(ds["invariant"].values) == traj.invariant_names == ["|Γ|²", "M·Γ"]
    swapped = ds.assign_coords(invariant=["M·Γ", "|Γ|²"])
    with pytest.raises(lf.io.FileFormatError, match="invariant"):
        lf.load(swapped)
    texty = ds.assign(note=("invariant", np.array([["a", "b"]], dtype=object)[0]))
    with pytest.raises(lf.io.FileFormatError):
        lf.load(texty)
    grid = ds.assign(note=(("invariant", "x"), np.array([["a"], ["b"]])))
    with pytest.raises(lf.io.FileFormatError):
        lf.load(grid)
