"""Trajectories as xarray Datasets and NetCDF files.

``Trajectory.to_xarray()`` gives a :class:`xarray.Dataset`; ``Trajectory.save(path)`` writes it to
a NetCDF file and ``lieflow.load`` reads it back as a ``Trajectory`` whose ``system`` is rebuilt,
so that a run can be continued from its ``final_state`` (:func:`read` gives its parts). This
module works on any object with a Trajectory's attributes and never imports the class: the
driver (``lieflow.integrate``) builds the Trajectory. Needs xarray and a NetCDF-4 backend
(``pip install lieflow[io]``: netCDF4).

Layout of the Dataset (format 2):

* coordinates ``time`` (the sample times, absolute) and, for a batch, ``member`` (0..b-1);
* ``states`` (``[member,] time, component``): the samples in the system's flat layout;
* one variable per named field of the system (``M``, ``Gamma``, ``X``, ...) with dimensions
  ``FIELD_component`` (vectors) or ``FIELD_row``, ``FIELD_col`` (matrices);
* ``energy`` (``[member,] time``) and ``invariants`` (``[member,] time, invariant``);
* ``attitude`` (``[member,] time, attitude_row, attitude_col``) when the run carried one;
* ``initial_state``, ``final_state`` (and ``initial_attitude``, ``final_attitude``);
* for runs with events, ``t_events_I`` (``event_I``) and ``state_events_I``
  (``event_I, component``) per event function I;
* attributes: ``system`` (its repr), ``system_class``, one ``system_<parameter>`` per number,
  string or numeric list among the constructor arguments, ``system_spec`` (how to rebuild the
  system, as JSON), ``method`` (or ``methods``, a JSON list, for a joined run), ``dt``,
  ``save_every``, ``t0``, ``t_final``, ``status``, ``sampling`` (``"grid"``: the samples are at
  ``t0 + j * save_every * dt``, after them the time of a terminal event; ``"irregular"``:
  ``t_eval`` runs and joined runs whose grids do not line up), ``lieflow_version``,
  ``lieflow_format`` and ``lieflow_checksums``.

``lieflow_checksums`` (JSON) holds the SHA-256 digest of every variable and coordinate (its
name, dimensions, dtype, shape and values in C order, little-endian) and one of all other
attributes (strings as text, numbers as the float64 hex of their values, so that it does not
depend on the NetCDF backend). :func:`read` verifies them, for a file and for a Dataset that
carries them (``to_xarray`` writes them, so a Dataset changed after it is refused), and checks
the metadata against the data (see :func:`read`): a damaged file is a FileFormatError naming
what failed, never changed numbers. Format 1 (lieflow before the checksums) had neither
``sampling`` nor ``lieflow_checksums``; such a file still loads, with a ``UserWarning`` that it
cannot be verified, and with the metadata checked against the data (a run with ``save_every``
on the grid). A Dataset built or edited by hand loads as format 1 (``lieflow_format = 1``, no
checksums).

A system is stored as data: its class and constructor arguments (None, booleans, numbers,
strings, numeric arrays, complex numbers, lists and tuples, and other lieflow objects such as
potentials and surfaces, in the same form), never as code. Loading calls only the entries of
:data:`ALLOWED_CALLS` (the constructors of lieflow's systems, its potentials and surfaces, and
``operator.add`` for a sum of potentials), within the :data:`SPEC_LIMITS`; any other name or
value is a FileFormatError naming its place in the spec (e.g. ``system_spec.args[1].call``).
A system built from Python callables (``lf.Canonical``, ``lf.Forced`` with a force function,
``Callable`` potentials) can be stored only pickled, with ``allow_pickle=True`` on both
``save`` and ``load`` (as ``numpy.load``): loading a pickle runs code from the file, so pass it
only for files you trust.
"""

from __future__ import annotations

import base64
import hashlib
import importlib
import inspect
import json
import math
import numbers
import os
import re
import warnings

from typing import TYPE_CHECKING, Any

import numpy as np

from ._lieflow import InvalidArgumentError, LieflowError, System, __version__

if TYPE_CHECKING:
    import xarray

__all__ = ["ALLOWED_CALLS", "FileFormatError", "FORMAT", "SPEC_LIMITS", "read", "save",
           "to_xarray"]

#: The version of the file layout written by :func:`save`; :func:`read` reads every version
#: up to it (format 1 without checksums, with a warning).
FORMAT = 2


class FileFormatError(LieflowError):
    """A file that is not a lieflow trajectory, is damaged, or was written in a newer format."""


def _xarray():
    try:
        import xarray
    except ImportError:
        raise ImportError("lieflow's NetCDF and xarray output needs xarray and a NetCDF "
                          "backend: pip install lieflow[io]") from None
    return xarray


def _engine():
    """The NetCDF-4 backend for xarray: netCDF4 (the reference library), else h5netcdf with
    h5py; an ImportError saying what to install otherwise. (NetCDF-3, xarray's scipy backend,
    cannot store the UTF-8 attributes lieflow writes.)"""
    import importlib.util

    if importlib.util.find_spec("netCDF4") is not None:
        return "netcdf4"
    if all(importlib.util.find_spec(m) is not None for m in ("h5netcdf", "h5py")):
        return "h5netcdf"
    raise ImportError("lieflow's NetCDF files need a NetCDF-4 backend for xarray: "
                      "pip install lieflow[io] (netCDF4), or h5netcdf with h5py")


# --- systems as data -----------------------------------------------------------------------

#: Everything a ``system_spec`` may call, as "module:qualname": the constructors of the lieflow
#: systems that can be stored as data, the factories of the potentials and surfaces they take,
#: and ``operator:add`` (a sum of potentials, ``Potential.__add__``'s reduction). :func:`read`
#: calls nothing else: a spec naming another callable, or holding anything but None, booleans,
#: numbers, strings, numeric arrays, complex numbers, lists, tuples and calls of these, is a
#: FileFormatError. The systems built from Python callables (``Canonical``, ``Separable``, the
#: ``Callable`` potential, the ``Revolution``, ``Graph`` and ``MetricSurface`` surfaces, a
#: ``Forced`` force function) are never data and are not listed.
ALLOWED_CALLS = frozenset({
    "lieflow:ChargedParticle",
    "lieflow:Forced",
    "lieflow:GeneralizedRigidBody",
    "lieflow:HeavyTop",
    "lieflow:LiePoisson",
    "lieflow:Pendulum",
    "lieflow:PseudoRigidBody",
    "lieflow:RelativisticTangentTop",
    "lieflow:RigidBody",
    "lieflow:RollingDisk",
    "lieflow:RollingDisks",
    "lieflow:RollingSpheres",
    "lieflow:SphereParticle",
    "lieflow:SphericalPendulum",
    "lieflow:TangentTop",
    "lieflow:WeakFieldTop",
    "lieflow.potentials:Harmonic",
    "lieflow.potentials:SaintVenantKirchhoff",
    "lieflow.potentials:SelfGravity",
    "lieflow.potentials:Stretch",
    "lieflow.potentials:Volumetric",
    "lieflow.potentials:Zero",
    "lieflow.surfaces:HyperbolicPlane",
    "lieflow.surfaces:Plane",
    "lieflow.surfaces:Quadric",
    "lieflow.surfaces:Sphere",
    "lieflow.surfaces:Torus",
    "operator:add",
})

#: Limits of a system spec, checked before anything is allocated for it or called: its JSON
#: text (characters), the nesting of its JSON lists and objects, its JSON values (array entries
#: and the lists holding them included), the entries of all its arrays, the dimensions of one
#: array, and the magnitude of an integer. A lieflow system's spec is a few hundred
#: characters; its arrays are inertia tensors and the like (the largest, a LiePoisson
#: Hamiltonian on so(10), 45 x 45 = 2025 entries). The entries are limited because a
#: constructor may cost more than its arguments: ``GeneralizedRigidBody(J)`` allocates dense
#: (m, m) matrices for m = len(J), 178 MB for m = 1770 and 14 GB for m = 16290. A system above
#: the limits is saved only pickled (``allow_pickle=True``).
SPEC_LIMITS = {"chars": 1 << 20, "depth": 100, "values": 1 << 14, "entries": 2048, "ndim": 8,
               "int": 2**63 - 1}

_SUM = "operator:add"
_DTYPE = re.compile(r"[<>|=]?(b1|[iu][1248]|f(2|4|8|12|16))")


class _NotData(Exception):
    """A value that cannot be written as data (a Python callable, an unknown object)."""


def _encode(value):
    """`value` as JSON-ready data; _NotData when it holds code."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, numbers.Complex):
        return {"complex": [value.real, value.imag]}
    if isinstance(value, np.ndarray):
        if not _DTYPE.fullmatch(value.dtype.str):
            raise _NotData(f"an array of dtype {value.dtype}")
        return {"array": value.tolist(), "dtype": value.dtype.str}
    if isinstance(value, (list, tuple)):
        items = [_encode(v) for v in value]
        return items if isinstance(value, list) else {"tuple": items}
    name = _allowed_name(value)
    if name is None:
        raise _NotData(f"{type(value).__name__} {value!r:.60}")
    return {"call": name, "args": [_encode(a) for a in value.__reduce__()[1]]}


def _allowed_name(value):
    """The entry of ALLOWED_CALLS whose call rebuilds `value` (by its ``__reduce__``), or
    None."""
    if not type(value).__module__.startswith("lieflow"):
        return None
    try:
        fn = value.__reduce__()[0]
    except Exception:        # an object that does not pickle is not data
        return None
    module, name = getattr(fn, "__module__", None), getattr(fn, "__qualname__", None)
    if module == "_operator":
        module = "operator"
    spelled = f"{module}:{name}"
    return spelled if spelled in ALLOWED_CALLS and _allowed(spelled) is fn else None


def _allowed(name):
    """The callable of an entry of ALLOWED_CALLS."""
    module, _, attr = name.partition(":")
    return getattr(importlib.import_module(module), attr)


class _Call:
    """A call in a parsed spec: an entry of ALLOWED_CALLS, its parsed arguments and where it
    stands in the spec (for messages)."""

    __slots__ = ("name", "args", "path")

    def __init__(self, name, args, path):
        self.name, self.args, self.path = name, args, path


class _Budget:
    """The JSON values and array entries a spec may still hold."""

    def __init__(self):
        self.left = {"values": SPEC_LIMITS["values"], "entries": SPEC_LIMITS["entries"]}

    def take(self, n, path, what="values"):
        self.left[what] -= n
        if self.left[what] < 0:
            raise FileFormatError(f"{path}: the system spec holds more than "
                                  f"{SPEC_LIMITS[what]} {what}{' of arrays' * (what == 'entries')}"
                                  f"; lieflow's systems have far fewer (lieflow.io.SPEC_LIMITS)")


def _parse_spec(text, where="system_spec"):
    """The spec `text` (JSON) checked and parsed into a tree of _Call, arrays and plain values;
    nothing is called. FileFormatError naming the offending entry otherwise."""
    if not isinstance(text, str):
        raise FileFormatError(f"{where}: expected a JSON string, got {type(text).__name__}")
    if len(text) > SPEC_LIMITS["chars"]:
        raise FileFormatError(f"{where}: {len(text)} characters, more than the limit of "
                              f"{SPEC_LIMITS['chars']} for a system spec")
    try:
        data = json.loads(text)
    except RecursionError as e:
        raise FileFormatError(f"{where}: nested too deeply to parse (at most "
                              f"{SPEC_LIMITS['depth']} levels)") from e
    except ValueError as e:
        raise FileFormatError(f"{where}: not valid JSON: {e}") from e
    if not (isinstance(data, dict) and "call" in data):
        raise FileFormatError(f"{where}: expected a call of a lieflow system's constructor "
                              f"({{\"call\": ..., \"args\": [...]}}), got {_show(data)}")
    return _parse(data, where, 0, _Budget())


def _show(value):
    return f"{type(value).__name__} {json.dumps(value)[:60]}"


def _parse(data, path, depth, budget):
    budget.take(1, path)
    if depth > SPEC_LIMITS["depth"]:
        raise FileFormatError(f"{path}: nested deeper than {SPEC_LIMITS['depth']} levels")
    if data is None or isinstance(data, (bool, str, float)):
        return data
    if isinstance(data, int):
        if abs(data) > SPEC_LIMITS["int"]:
            raise FileFormatError(f"{path}: an integer of {len(str(abs(data)))} digits is out "
                                  f"of range (at most 2**63 - 1 in magnitude)")
        return data
    if isinstance(data, list):
        return [_parse(v, f"{path}[{i}]", depth + 1, budget) for i, v in enumerate(data)]
    assert isinstance(data, dict), type(data)         # what json.loads makes
    keys = set(data)
    if keys == {"call", "args"}:
        name = data["call"]
        if not isinstance(name, str) or name not in ALLOWED_CALLS:
            raise FileFormatError(
                f"{path}.call: {name!r:.80} is not a lieflow callable that rebuilds systems "
                f"(a system spec may call only the entries of lieflow.io.ALLOWED_CALLS)")
        args = data["args"]
        if not isinstance(args, list):
            raise FileFormatError(f"{path}.args: expected a list of arguments, got "
                                  f"{_show(args)}")
        return _Call(name, [_parse(v, f"{path}.args[{i}]", depth + 2, budget)
                            for i, v in enumerate(args)], path)
    if keys == {"tuple"}:
        items = data["tuple"]
        if not isinstance(items, list):
            raise FileFormatError(f"{path}.tuple: expected a list, got {_show(items)}")
        return tuple(_parse(v, f"{path}.tuple[{i}]", depth + 2, budget)
                     for i, v in enumerate(items))
    if keys == {"complex"}:
        parts = data["complex"]
        if not (isinstance(parts, list) and len(parts) == 2
                and all(isinstance(p, (int, float)) and not isinstance(p, bool)
                        for p in parts)):
            raise FileFormatError(f"{path}.complex: expected [real, imag], got {_show(parts)}")
        try:
            return complex(*parts)
        except OverflowError as e:
            raise FileFormatError(f"{path}.complex: {e}") from e
    if keys == {"array", "dtype"}:
        return _parse_array(data, path, budget)
    raise FileFormatError(
        f"{path}: an entry with the keys {sorted(keys)!r:.80}; expected one of "
        f"{{call, args}}, {{array, dtype}}, {{tuple}}, {{complex}}")


def _parse_array(data, path, budget):
    """The numeric array of an {"array", "dtype"} entry, its shape and entries counted before
    it is made."""
    spelled = data["dtype"]
    if not (isinstance(spelled, str) and _DTYPE.fullmatch(spelled)):
        raise FileFormatError(f"{path}.dtype: {spelled!r:.40} is not the dtype of a numeric "
                              f"array (booleans, integers or floats, e.g. '<f8')")
    dtype = np.dtype(spelled)
    top = data["array"]
    level, shape = [top], []
    while level and isinstance(level[0], list):
        n = len(level[0])
        if not all(isinstance(v, list) and len(v) == n for v in level):
            raise FileFormatError(f"{path}.array: ragged (its lists at depth {len(shape)} "
                                  f"differ in length or mix lists and numbers)")
        shape.append(n)
        if len(shape) > SPEC_LIMITS["ndim"]:
            raise FileFormatError(f"{path}.array: more than {SPEC_LIMITS['ndim']} dimensions")
        budget.take(len(level) * n, f"{path}.array")
        level = [x for v in level for x in v]
    budget.take(len(level), f"{path}.array", "entries")
    kinds = {"b": (bool,), "i": (int,), "u": (int,), "f": (int, float)}[dtype.kind]
    for x in level:
        if not isinstance(x, kinds) or (isinstance(x, bool) and dtype.kind != "b"):
            raise FileFormatError(f"{path}.array: an entry {_show(x)} in an array of dtype "
                                  f"{dtype} (expected {' or '.join(k.__name__ for k in kinds)})")
    try:
        out = np.array(top, dtype=dtype)
    except (OverflowError, ValueError) as e:
        raise FileFormatError(f"{path}.array: not representable as {dtype}: {e}") from e
    if out.shape != tuple(shape):
        raise FileFormatError(f"{path}.array: of shape {out.shape}, expected {tuple(shape)}")
    return out


def _build(node):
    """The object of a parsed spec: the allowed calls made, innermost first."""
    if isinstance(node, list):
        return [_build(v) for v in node]
    if isinstance(node, tuple):
        return tuple(_build(v) for v in node)
    if not isinstance(node, _Call):
        return node
    args = [_build(a) for a in node.args]
    if node.name == _SUM:
        from .potentials import Potential

        if len(args) != 2 or not all(isinstance(a, Potential) for a in args):
            raise FileFormatError(
                f"{node.path}: operator:add adds two potentials, got "
                f"({', '.join(type(a).__name__ for a in args)})")
    try:
        return _allowed(node.name)(*args)
    except Exception as e:
        raise FileFormatError(f"{node.path}: {node.name} refused the arguments stored for it: "
                              f"{type(e).__name__}: {e}") from e


def _decode(data, where="system_spec"):
    """The system of a spec already parsed from JSON (tests; :func:`read` parses the text)."""
    return _build(_parse_spec(json.dumps(data), where))


def _parameters(system):
    """{name: value} of the constructor arguments that are numbers, strings or numeric lists."""
    try:
        args = system.__reduce__()[1]
        names = list(inspect.signature(type(system)).parameters)
    except Exception:
        return {}
    out = {}
    for name, value in zip(names, args):
        if isinstance(value, (bool, np.bool_)):
            out[name] = int(value)
        elif isinstance(value, (numbers.Real, str)):
            out[name] = value
        elif isinstance(value, (list, tuple, np.ndarray)):
            a = np.asarray(value)
            if a.dtype.kind in "iuf" and a.ndim >= 1 and a.size:
                out[name] = a.astype(np.float64).ravel()
    return out


def _path(path):
    """`path` as a str: TypeError (naming the argument) unless a str or os.PathLike."""
    try:
        return os.fspath(path)
    except TypeError:
        raise TypeError(f"invalid path: expected a str or os.PathLike, got "
                        f"{type(path).__name__} {path!r:.60}") from None


# --- checksums -----------------------------------------------------------------------------

_CHECKSUMS = "lieflow_checksums"


def _variable_digest(name, var):
    """SHA-256 of a variable: its name, dimensions, dtype (kind and size; little-endian),
    shape and values (C order)."""
    a = np.asarray(var.values)
    if a.dtype.kind not in "biuf":
        raise FileFormatError(f"variable {name!r}: of dtype {a.dtype}; a lieflow trajectory "
                              f"holds numbers only")
    a = np.ascontiguousarray(a.astype(a.dtype.newbyteorder("<"), copy=False))
    head = json.dumps([name, list(var.dims), f"{a.dtype.kind}{a.dtype.itemsize}",
                       list(a.shape)])
    h = hashlib.sha256(head.encode("utf-8"))
    h.update(b"\0")
    h.update(a.tobytes())
    return h.hexdigest()


def _attribute_form(name, value):
    """An attribute in a form that does not depend on how the NetCDF backend returns it:
    strings as str, numbers as the float64 hex of their values (a scalar as one value)."""
    if isinstance(value, bytes):
        try:
            return ["s", value.decode("utf-8")]
        except UnicodeDecodeError as e:
            raise FileFormatError(f"attribute {name!r}: not UTF-8 text") from e
    if isinstance(value, str):
        return ["s", str(value)]
    a = np.atleast_1d(np.asarray(value))
    if a.dtype.kind not in "biuf":
        raise FileFormatError(f"attribute {name!r}: {value!r:.60} is neither text nor numbers")
    return ["n", [float(x).hex() for x in a.astype(np.float64).ravel()]]


def _attributes_digest(attrs):
    form = [[k, _attribute_form(k, attrs[k])] for k in sorted(attrs) if k != _CHECKSUMS]
    return hashlib.sha256(json.dumps(form).encode("utf-8")).hexdigest()


def _seal(ds):
    """Adds the checksums of every variable, coordinate and attribute of `ds` (format 2)."""
    ds.attrs.pop(_CHECKSUMS, None)
    sums = {"algorithm": "sha256",
            "variables": {str(k): _variable_digest(str(k), v) for k, v in ds.variables.items()},
            "attributes": _attributes_digest(ds.attrs)}
    ds.attrs[_CHECKSUMS] = json.dumps(sums, sort_keys=True)
    return ds


def _verify(ds, where):
    """FileFormatError naming the first variable or the attributes whose checksum fails."""
    text = ds.attrs[_CHECKSUMS]
    damaged = f"{where} is damaged"
    try:
        if not isinstance(text, str) or len(text) > 200 * len(ds.variables) + 1000:
            raise ValueError("not a short JSON text")
        sums = json.loads(text)
        ok = (isinstance(sums, dict) and set(sums) == {"algorithm", "variables", "attributes"}
              and sums["algorithm"] == "sha256" and isinstance(sums["variables"], dict)
              and all(isinstance(v, str) for v in sums["variables"].values())
              and isinstance(sums["attributes"], str))
        if not ok:
            raise ValueError("not the layout lieflow writes")
    except (ValueError, RecursionError) as e:
        raise FileFormatError(f"{damaged}: its attribute {_CHECKSUMS} cannot be read "
                              f"({e})") from e
    listed, present = set(sums["variables"]), {str(k) for k in ds.variables}
    if listed - present:
        raise FileFormatError(f"{damaged}: the variable {sorted(listed - present)[0]!r} listed "
                              f"in its checksums is missing")
    if present - listed:
        raise FileFormatError(f"{damaged} or was changed: the variable "
                              f"{sorted(present - listed)[0]!r} is not covered by its "
                              f"checksums")
    for name in sorted(listed):
        if _variable_digest(name, ds.variables[name]) != sums["variables"][name]:
            raise FileFormatError(f"{damaged}: the variable {name!r} does not match its "
                                  f"SHA-256 checksum (its values, dtype, shape or dimensions "
                                  f"changed)")
    if _attributes_digest(ds.attrs) != sums["attributes"]:
        raise FileFormatError(f"{damaged}: its attributes (the system, method, dt, times, ...) "
                              f"do not match their SHA-256 checksum")


# --- Trajectory <-> Dataset ----------------------------------------------------------------

def _field_dims(name, shape):
    if len(shape) == 0:
        return ()
    if len(shape) == 1:
        return (f"{name}_component",)
    if len(shape) == 2:
        return (f"{name}_row", f"{name}_col")
    return tuple(f"{name}_{i}" for i in range(len(shape)))


_RESERVED = {"states", "energy", "invariants", "attitude", "initial_state", "final_state",
             "initial_attitude", "final_attitude", "time", "member"}


def to_xarray(traj: Any, *, observables: bool = True) -> xarray.Dataset:
    """The trajectory as an :class:`xarray.Dataset` (layout in the module docstring), with
    the checksums :func:`read` verifies: ``lf.load(ds)`` (and ``lf.load`` of
    ``ds.to_netcdf(path)``) refuses a Dataset changed after this call.

    Parameters
    ----------
    traj : lieflow.Trajectory
        A trajectory from :func:`lieflow.integrate`.
    observables : bool
        Include ``energy`` and ``invariants`` (computed from the states).

    Returns
    -------
    xarray.Dataset
    """
    return _seal(_dataset(traj, observables))


def _dataset(traj, observables):
    """The Dataset of `traj` without checksums."""
    xr = _xarray()
    lead = ("member",) if traj.batched else ()
    ds = xr.Dataset(coords={"time": ("time", np.asarray(traj.t, dtype=np.float64))})
    if traj.batched:
        ds = ds.assign_coords(member=("member", np.arange(traj.states.shape[0])))
    ds["states"] = (lead + ("time", "component"), np.asarray(traj.states))
    for name, value in traj._fields().items():
        if name in _RESERVED:
            continue
        value = np.asarray(value)
        ds[name] = (lead + ("time",) + _field_dims(name, value.shape[len(lead) + 1:]), value)
    if observables and len(traj.t):
        ds["energy"] = (lead + ("time",), np.asarray(traj.energy(), dtype=np.float64))
        inv = np.asarray(traj.invariants(), dtype=np.float64)
        head = inv.shape[:len(lead) + 1]      # (-1 cannot size an empty batch's)
        ds["invariants"] = (lead + ("time", "invariant"),
                            inv.reshape(head + (math.prod(inv.shape[len(head):]),)))
    square = ("attitude_row", "attitude_col")
    if traj.attitude is not None:
        ds["attitude"] = (lead + ("time",) + square, np.asarray(traj.attitude))
    for name in ("initial_state", "final_state"):
        value = getattr(traj, name)
        if value is not None:
            ds[name] = (lead + ("component",), np.asarray(value))
    for name in ("initial_attitude", "final_attitude"):
        value = getattr(traj, name)
        if value is not None:
            ds[name] = (lead + square, np.asarray(value))
    if traj.t_events is not None and traj.state_events is not None:
        for i, te in enumerate(traj.t_events):
            ds[f"t_events_{i}"] = (f"event_{i}",), np.asarray(te, dtype=np.float64)
            ds[f"state_events_{i}"] = ((f"event_{i}", "component"),
                                       np.asarray(traj.state_events[i]))
            if traj.attitude_events is not None:
                ds[f"attitude_events_{i}"] = ((f"event_{i}",) + square,
                                              np.asarray(traj.attitude_events[i]))
    ds.attrs.update(_attributes(traj))
    return ds


def _attributes(traj):
    attrs = {"lieflow_format": FORMAT, "lieflow_version": __version__,
             "system": repr(traj.system), "system_class": type(traj.system).__name__}
    for name, value in _parameters(traj.system).items():
        attrs[f"system_{name}"] = value
    try:
        spec = json.dumps(_encode(traj.system))
        _parse_spec(spec)           # within the limits read() applies, or stored pickled only
        attrs["system_spec"] = spec
    except (_NotData, FileFormatError):
        pass
    if isinstance(traj.method, str):
        attrs["method"] = traj.method
    else:
        attrs["methods"] = json.dumps(list(traj.method))
    for name in ("dt", "save_every", "t0", "t_final"):
        value = getattr(traj, name)
        if value is not None:
            attrs[name] = value
    attrs["status"] = int(traj.status)
    if traj.t_events is not None:
        attrs["event_functions"] = len(traj.t_events)
    on_grid = None not in (traj.dt, traj.save_every, traj.t0, traj.t_final) and \
        _grid_error(np.asarray(traj.t, dtype=np.float64), traj.t0, traj.dt, traj.save_every,
                    int(traj.status), traj.t_final) is None
    attrs["sampling"] = "grid" if on_grid else "irregular"
    return attrs


def save(traj: Any, path: str | os.PathLike[str], *, allow_pickle: bool = False) -> None:
    """Writes the trajectory to a NetCDF file at `path` (the Dataset of :func:`to_xarray`,
    with its checksums).

    Parameters
    ----------
    traj : lieflow.Trajectory
        The trajectory to save.
    path : str or os.PathLike
        The file to write (replaced if it exists).
    allow_pickle : bool
        Store a system that cannot be written as data (one built from Python callables)
        pickled; :func:`load` then needs ``allow_pickle=True`` as well.

    Raises
    ------
    ImportError
        xarray or a NetCDF-4 backend (netCDF4, or h5netcdf with h5py) is not installed.
    lieflow.InvalidArgumentError
        The system holds Python callables and ``allow_pickle`` is False, or it cannot be
        pickled; the trajectory is inconsistent (e.g. times not increasing, a method its
        system does not have), so that :func:`read` would refuse the file.
    """
    path = _path(path)
    engine = _engine()
    ds = _dataset(traj, True)
    if "system_spec" not in ds.attrs:
        if not allow_pickle:
            raise InvalidArgumentError(
                f"invalid system: {traj.system!r:.80} holds Python callables (or arrays beyond "
                f"lieflow.io.SPEC_LIMITS) and cannot be stored as data; pass allow_pickle=True "
                f"to store it pickled (lf.load then needs allow_pickle=True too)")
        try:
            import cloudpickle as pickler  # type: ignore[import-untyped]
        except ImportError:
            import pickle as pickler
        try:
            blob = pickler.dumps(traj.system)
        except Exception as e:
            raise InvalidArgumentError(f"invalid system: cannot pickle {traj.system!r:.80}: "
                                       f"{e}") from None
        ds.attrs["system_pickle"] = base64.b64encode(blob).decode("ascii")
    try:
        _arguments(ds)
        _check_method(ds.attrs, traj.system)
    except FileFormatError as e:
        raise InvalidArgumentError(f"invalid trajectory: lf.load would refuse its file: "
                                   f"{e}") from None
    _seal(ds).to_netcdf(path, engine=engine)


def read(path: str | os.PathLike[str] | xarray.Dataset, *,
         allow_pickle: bool = False) -> dict[str, Any]:
    """The parts of a trajectory written by ``Trajectory.save`` (or of a Dataset of
    ``to_xarray``): the keyword arguments of ``lieflow.Trajectory`` (``system`` rebuilt,
    ``method``, ``t``, ``states``, ``attitude``, ``final_state``, ``final_attitude``, ``dt``,
    ``save_every``, ``t_final``, ``status``, ``t0``, ``initial_state``, ``initial_attitude`` and
    the events). ``lieflow.load(path)`` is ``Trajectory(**read(path))``.

    What is checked, in this order, before the system is rebuilt: for a file, that its header
    declares no more data than the file holds (before xarray opens it); the format; that the
    system spec is data naming only :data:`ALLOWED_CALLS` (within :data:`SPEC_LIMITS`); the
    checksums (format 2; a format-1 file has none and loads with a ``UserWarning``); the
    metadata against the data (dimensions and shapes, finite increasing times on the grid
    ``t0 + j * save_every * dt`` when ``sampling`` is ``"grid"``, ``t_final``, the initial and final
    states against the first and last samples, ``status``, ``dt``, ``save_every``, the events).
    Then the system is built and the method checked against ``system.methods()``.

    Parameters
    ----------
    path : str, os.PathLike or xarray.Dataset
        The NetCDF file (or an already opened Dataset).
    allow_pickle : bool
        Allow rebuilding a system stored pickled (runs code from the file: only for files you
        trust).

    Returns
    -------
    dict

    Raises
    ------
    ImportError
        xarray or a NetCDF-4 backend (netCDF4, or h5netcdf with h5py) is not installed.
    FileNotFoundError
        No file at `path`.
    lieflow.FileFormatError
        Not a lieflow trajectory file, a damaged one (a checksum fails, the metadata
        contradict the data), one in a newer format, a system spec that is not data of
        allowed calls; a pickled system without ``allow_pickle``.
    """
    xr = _xarray()
    if isinstance(path, xr.Dataset):
        ds, where = path, "the dataset"
    else:
        path = _path(path)
        if not os.path.exists(path):
            raise FileNotFoundError(f"no such file: {path!r}")
        ds, where = _open(xr, path, _engine()), repr(path)
    version = ds.attrs.get("lieflow_format")
    if version is None:
        raise FileFormatError(f"{where} is not a lieflow trajectory (it has no lieflow_format "
                              f"attribute; Trajectory.save writes one)")
    if isinstance(version, np.ndarray) and version.size == 1:
        version = version.reshape(())[()]
    if not isinstance(version, numbers.Integral) or not 1 <= int(version) <= FORMAT:
        raise FileFormatError(
            f"{where} was written by lieflow {ds.attrs.get('lieflow_version', '?')!s:.40} in "
            f"format {version!s:.40}; lieflow {__version__} reads formats 1 to {FORMAT}: "
            f"upgrade lieflow")
    sealed = _CHECKSUMS in ds.attrs
    if int(version) == 1 and sealed:
        raise FileFormatError(f"{where} is damaged: it claims format 1 but carries checksums "
                              f"({_CHECKSUMS}), which only format 2 has")
    if int(version) >= 2 and not sealed:
        raise FileFormatError(
            f"{where} is damaged or was changed: it claims format {int(version)} but carries "
            f"no checksums ({_CHECKSUMS}); Trajectory.save and to_xarray always write them "
            f"(a Dataset edited by hand: drop the checksums and set lieflow_format to 1)")
    try:
        if "states" not in ds.variables or "time" not in ds.variables:
            raise FileFormatError("it has no states or no time coordinate")
        plan = _system_plan(ds.attrs, allow_pickle)
        if sealed:
            _verify(ds, where)
        else:
            warnings.warn(f"{where} is in lieflow's format 1, without checksums: damage to it "
                          f"cannot be detected (save it again with Trajectory.save to add "
                          f"them)", UserWarning, stacklevel=2)
        args = _arguments(ds)
    except FileFormatError as e:
        if not str(e).startswith(where):
            e.args = (f"{where}: {e}",)
        raise
    except Exception as e:
        raise FileFormatError(f"{where} is damaged: {type(e).__name__}: {e}") from e
    try:
        system = plan() if callable(plan) else _build(plan)
        if not callable(plan) and not isinstance(system, System):
            raise FileFormatError(f"system_spec: builds a {type(system).__name__}, not a "
                                  f"lieflow system")
        _check_method(ds.attrs, system)
    except FileFormatError as e:
        e.args = (f"{where}: {e}",)
        raise
    return dict(system=system, **args)


def _open(xr, path, engine):
    """The Dataset of the NetCDF file `path`, loaded; its declared sizes are checked against
    the file's size first (xarray reads a coordinate when it opens the file)."""
    try:
        _check_sizes(path, engine)
        with xr.open_dataset(path, engine=engine, decode_cf=False) as f:
            return f.load()
    except FileFormatError:
        raise
    except Exception as e:
        raise FileFormatError(f"cannot read {path!r} as a NetCDF file (damaged, or not "
                              f"NetCDF): {type(e).__name__}: {e}") from e


#: The largest ratio of compressed to stored data a file may claim for its compressed
#: variables (lieflow writes none; a trajectory compresses far less).
_MAX_COMPRESSION = 100


def _check_sizes(path, engine):
    """FileFormatError when the variables of the file declare more bytes than it can hold
    (a damaged or forged header, e.g. a dimension of 2**31 with compressed chunks never
    written, would otherwise make xarray allocate and fill them): read from the header only,
    by the backend's own library, before xarray opens the file."""
    size = os.path.getsize(path)
    declared = 0.0
    for shape, itemsize, packed in _declared(path, engine):
        declared += math.prod(shape) * itemsize / (_MAX_COMPRESSION if packed else 1)
    if declared > size + (1 << 20):
        raise FileFormatError(f"{path!r} is damaged: its variables declare {declared:.3g} bytes "
                              f"of data, more than its {size} bytes can hold")


def _declared(path, engine):
    """(shape, bytes per value, compressed?) of every variable of the root group."""
    if engine == "netcdf4":
        import netCDF4

        with netCDF4.Dataset(path) as f:
            return [(v.shape, getattr(np.dtype(v.dtype), "itemsize", 0) or 8,
                     any((v.filters() or {}).get(k)
                         for k in ("zlib", "szip", "zstd", "bzip2", "blosc")))
                    for v in f.variables.values()]
    import h5py

    with h5py.File(path, "r") as f:
        return [(v.shape or (), v.dtype.itemsize or 8, v.id.get_create_plist().get_nfilters() > 0)
                for v in f.values() if isinstance(v, h5py.Dataset)]


def _system_plan(attrs, allow_pickle):
    """How to rebuild the system: a parsed spec (_build makes it) or, for a pickle, a function
    that unpickles it. Nothing is called here."""
    if "system_spec" in attrs:
        return _parse_spec(attrs["system_spec"])
    if "system_pickle" in attrs:
        if not allow_pickle:
            raise FileFormatError(
                f"the system {attrs.get('system', '?')!s:.80} is stored pickled; loading it "
                f"runs code from the file: pass allow_pickle=True if you trust it")
        import pickle

        blob = attrs["system_pickle"]

        def unpickle():
            try:
                return pickle.loads(base64.b64decode(blob))
            except Exception as e:
                raise FileFormatError(f"cannot unpickle the system: {type(e).__name__}: "
                                      f"{e}") from e
        return unpickle
    raise FileFormatError("the file does not say how to rebuild its system (no system_spec)")


def _check_method(attrs, system):
    """FileFormatError unless the method (or each of the methods of a joined run) is one of
    ``system.methods()``."""
    if "method" in attrs:
        names = [attrs["method"]]
    else:
        names = _methods(attrs)
    known = list(system.methods())
    for name in names:
        if not isinstance(name, str) or name not in known:
            raise FileFormatError(f"the method {name!r:.60} is not one of the methods of "
                                  f"{type(system).__name__}: {known}")


def _methods(attrs):
    text = attrs.get("methods")
    if text is None:
        raise FileFormatError("the file names no method (no attribute method or methods)")
    try:
        if not isinstance(text, str) or len(text) > 1 << 16:
            raise ValueError("not a short JSON text")
        names = json.loads(text)
    except (ValueError, RecursionError) as e:
        raise FileFormatError(f"the attribute methods is not a JSON list of names: {e}") from e
    if not (isinstance(names, list) and names and all(isinstance(n, str) for n in names)):
        raise FileFormatError(f"the attribute methods is not a list of names: {text!r:.60}")
    return names
# --- the metadata against the data ---------------------------------------------------------

_EPS = np.finfo(np.float64).eps


def _attr(attrs, name, kind):
    """Attribute `name` as a Python float or int (kind "real", "int"), or None when absent;
    FileFormatError when it is not one number of that kind."""
    if name not in attrs:
        return None
    value = attrs[name]
    a = np.asarray(value) if not isinstance(value, (str, bytes)) else None
    kinds = "iu" if kind == "int" else "iuf"
    if a is None or a.dtype.kind not in kinds or a.size != 1:
        raise FileFormatError(f"the attribute {name} is {value!r:.60}; expected "
                              f"{'an integer' if kind == 'int' else 'a real number'}")
    v = a.reshape(())[()]
    return int(v) if kind == "int" else float(v)


def _arguments(ds):
    """The arrays and numbers of the Trajectory in `ds` (all but the system), checked against
    one another; FileFormatError naming the first contradiction."""
    a = ds.attrs

    def var(name):
        return np.asarray(ds.variables[name].values) if name in ds.variables else None

    def dims(name):
        return tuple(str(d) for d in ds.variables[name].dims)

    t, states = var("time"), var("states")
    if states is None or t is None:
        raise FileFormatError("it has no states or no time coordinate")
    for name, x in (("time", t), ("states", states)):
        if x.dtype.kind != "f":
            raise FileFormatError(f"{name} of dtype {x.dtype}; expected floats")
    if states.ndim not in (2, 3):
        raise FileFormatError(f"states of shape {states.shape}; expected (time, component) or "
                              f"(member, time, component)")
    batched = states.ndim == 3
    lead = ("member",) if batched else ()
    b, (k, d) = states.shape[:-2], states.shape[-2:]
    square = ("attitude_row", "attitude_col")
    expected = {"time": (("time",), (k,)),
                "states": (lead + ("time", "component"), b + (k, d)),
                "initial_state": (lead + ("component",), b + (d,)),
                "final_state": (lead + ("component",), b + (d,)),
                "attitude": (lead + ("time",) + square, b + (k, 3, 3)),
                "initial_attitude": (lead + square, b + (3, 3)),
                "final_attitude": (lead + square, b + (3, 3)),
                "energy": (lead + ("time",), b + (k,))}
    if batched:
        expected["member"] = (("member",), b)
    for name, (want_dims, want_shape) in expected.items():
        if name in ds.variables and (dims(name) != want_dims or
                                     ds.variables[name].shape != want_shape):
            raise FileFormatError(f"the variable {name} has dimensions {dims(name)} of shape "
                                  f"{ds.variables[name].shape}; with states of shape "
                                  f"{states.shape} expected {want_dims} of shape {want_shape}")
    if batched and not np.array_equal(var("member"), np.arange(b[0])):
        raise FileFormatError(f"the member coordinate is not 0 .. {b[0] - 1}")
    if not batched and "member" in ds.variables:
        raise FileFormatError("a member coordinate, but states of one run (time, component)")
    for name in ds.variables:
        vd = dims(name)
        if name != "time" and "time" in vd and vd[:len(lead) + 1] != lead + ("time",):
            raise FileFormatError(f"the variable {name} has dimensions {vd}; expected "
                                  f"{lead + ('time',)} first")
    if "invariants" in ds.variables and dims("invariants")[:-1] != lead + ("time",):
        raise FileFormatError(f"the variable invariants has dimensions {dims('invariants')}; "
                              f"expected {lead + ('time', 'invariant')}")

    dt, save_every = _attr(a, "dt", "real"), _attr(a, "save_every", "int")
    t0, t_final = _attr(a, "t0", "real"), _attr(a, "t_final", "real")
    status = _attr(a, "status", "int")
    status = 0 if status is None else status
    if status not in (-1, 0, 1):
        raise FileFormatError(f"the attribute status is {status}; expected -1 (failed), 0 "
                              f"(completed) or 1 (ended by a terminal event)")
    if dt is not None and not (math.isfinite(dt) and dt > 0):
        raise FileFormatError(f"the attribute dt is {dt!r}; expected a finite time step > 0")
    if save_every is not None and save_every < 1:
        raise FileFormatError(f"the attribute save_every is {save_every}; expected >= 1")
    for name, value in (("t0", t0), ("t_final", t_final)):
        if value is not None and not math.isfinite(value):
            raise FileFormatError(f"the attribute {name} is {value!r}; expected a finite time")
    if "method" not in a:
        _methods(a)
    elif not isinstance(a["method"], str):
        raise FileFormatError(f"the attribute method is {a['method']!r:.60}; expected a name")

    events = _events(ds, var, dims, batched, d, status)
    sampling = _check_times(a, t, t0, t_final, dt, save_every, status)
    for name, when, sample in (("initial_state", t0, 0), ("final_state", t_final, -1),
                               ("initial_attitude", t0, 0), ("final_attitude", t_final, -1)):
        series = "states" if name.endswith("state") else "attitude"
        x, s = var(name), var(series)
        if x is None or s is None or not k or when is None or t[sample] != when:
            continue
        s = s[..., sample, :] if series == "states" else s[..., sample, :, :]
        # A sample on the grid is the state itself; a t_eval sample at t0 or at the end, or a
        # terminal event's, is reached by a step of size 0 or another last step (with the
        # method's processing, reduction, ...): equal to round-off.
        exact = sampling == "grid" and not (sample == -1 and status == 1)
        same = np.array_equal(x, s, equal_nan=True) if exact else \
            np.allclose(x, s, rtol=1e-9, atol=1e-9, equal_nan=True)
        if not same:
            raise FileFormatError(f"{name} differs from the {'first' if sample == 0 else 'last'} "
                                  f"sample of {series}, which is at the same time t = {when!r}")
    for te in events.get("t_events", []):
        lo = -math.inf if t0 is None else t0 - _tol(t0, t0)
        hi = math.inf if t_final is None else t_final + _tol(t_final, t_final)
        if te.size and not (np.all(np.isfinite(te)) and np.all(np.diff(te) >= 0)
                            and te[0] >= lo and te[-1] <= hi):
            raise FileFormatError(f"event times {te!r:.80} are not increasing times within "
                                  f"[t0, t_final] = [{t0!r}, {t_final!r}]")

    return dict(method=a["method"] if "method" in a else tuple(_methods(a)), t=t,
                states=states, attitude=var("attitude"), final_state=var("final_state"),
                final_attitude=var("final_attitude"), dt=dt, save_every=save_every,
                t_final=t_final, status=status, t0=t0, initial_state=var("initial_state"),
                initial_attitude=var("initial_attitude"), **events)


def _events(ds, var, dims, batched, d, status):
    """The event arrays named by the attribute event_functions, their layout checked."""
    n = _attr(ds.attrs, "event_functions", "int")
    if n is None:
        if status == 1:
            raise FileFormatError("status 1 (ended by a terminal event) but no events")
        return {}
    if batched:
        raise FileFormatError(f"the attribute event_functions is {n}, but events are located "
                              f"in single runs only, not in a batch")
    if not 0 <= n <= len(ds.variables):
        raise FileFormatError(f"the attribute event_functions is {n}, not a count of the event "
                              f"variables")
    if status == 1 and n == 0:
        raise FileFormatError("status 1 (ended by a terminal event) but no event functions")
    with_attitude = "initial_attitude" in ds.variables
    out = {"t_events": [], "state_events": []}
    if with_attitude:
        out["attitude_events"] = []
    for i in range(n):
        e = f"event_{i}"
        layout = {f"t_events_{i}": ((e,), 0), f"state_events_{i}": ((e, "component"), d)}
        if with_attitude:
            layout[f"attitude_events_{i}"] = ((e, "attitude_row", "attitude_col"), 3)
        for name, (want, last) in layout.items():
            if name not in ds.variables:
                raise FileFormatError(f"event_functions is {n} but there is no variable {name}")
            if dims(name) != want or (last and ds.variables[name].shape[-1] != last):
                raise FileFormatError(f"the variable {name} has dimensions {dims(name)} of "
                                      f"shape {ds.variables[name].shape}; expected {want}")
        out["t_events"].append(var(f"t_events_{i}"))
        out["state_events"].append(var(f"state_events_{i}"))
        if with_attitude:
            out["attitude_events"].append(var(f"attitude_events_{i}"))
    return out


def _tol(t, t0):
    """Round-off of a time t of a run that started at t0."""
    return 32 * _EPS * max(abs(t), abs(t0))


def _check_times(a, t, t0, t_final, dt, save_every, status):
    """The sample times against t0, t_final and (on the grid) dt and save_every; the
    sampling ("grid" or "irregular")."""
    k = len(t)
    if not np.all(np.isfinite(t)):
        raise FileFormatError("the sample times are not all finite")
    if k > 1 and not np.all(np.diff(t) > 0):
        j = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise FileFormatError(f"the sample times are not increasing: t[{j + 1}] = "
                              f"{float(t[j + 1])!r} after t[{j}] = {float(t[j])!r}")
    if t0 is not None and t_final is not None and t_final < t0 - _tol(t_final, t0):
        raise FileFormatError(f"t_final = {t_final!r} precedes t0 = {t0!r}")
    if k and t0 is not None and t[0] < t0 - _tol(t[0], t0):
        raise FileFormatError(f"the first sample time {float(t[0])!r} precedes t0 = {t0!r}")
    if k and t_final is not None and t[-1] > t_final + _tol(t[-1], t_final):
        raise FileFormatError(f"the last sample time {float(t[-1])!r} is after t_final = "
                              f"{t_final!r}")
    sampling = a.get("sampling")
    if sampling not in (None, "grid", "irregular"):
        raise FileFormatError(f"the attribute sampling is {sampling!r:.40}; expected 'grid' or "
                              f"'irregular'")
    inferred = sampling is None
    if inferred:             # format 1, or a Dataset made by hand: a run with save_every
        sampling = "grid" if None not in (dt, save_every, t0, t_final) else "irregular"
    if sampling == "grid":
        if None in (dt, save_every, t0, t_final):
            raise FileFormatError("sampling 'grid' needs the attributes dt, save_every, t0 and "
                                  "t_final")
        error = _grid_error(t, t0, dt, save_every, status, t_final)
        if error and inferred:
            error += ("; a run with save_every is taken to be on this grid (a joined run of "
                      "Trajectory.concatenate whose grids do not line up is not: load it with "
                      "ds = xarray.open_dataset(path).load(); ds.attrs['sampling'] = "
                      "'irregular'; lf.load(ds))")
        if error:
            raise FileFormatError(error)
    return sampling


def _grid_error(t, t0, dt, every, status, t_final):
    """What contradicts the rule of a run on the grid (None if nothing): samples at
    t0 + j * every * dt (and after them the time of the terminal event when status is 1), the
    final time t0 + n * dt for an integer n (the event's time when status is 1), with
    n // every + 1 samples when the run completed."""
    k, h = len(t), every * dt
    g = k - 1 if status == 1 else k
    if g < 1:
        return (f"{k} sample times; a run saving every {every}-th step has its initial sample "
                f"{'and the terminal event ' if status == 1 else ''}at least")
    grid = t0 + np.arange(g) * h
    err = np.abs(t[:g] - grid)
    bad = np.flatnonzero(err > 32 * _EPS * np.maximum(abs(t0), np.abs(grid)) + 1e-9 * h)
    if bad.size:
        j = int(bad[0])
        return (f"the sample time t[{j}] = {float(t[j])!r} is not t0 + {j} * save_every * dt "
                f"= {float(grid[j])!r} (t0 = {t0!r}, save_every = {every}, dt = {dt!r})")
    if status == 1:
        if not t[-1] <= t[g - 1] + h + _tol(t[-1], t0):
            return (f"the terminal event's time {float(t[-1])!r} is more than save_every * dt "
                    f"= {h!r} after the sample before it, {float(t[g - 1])!r}")
        if abs(t_final - t[-1]) > _tol(t_final, t0):
            return (f"t_final = {t_final!r} is not the time of the terminal event, the last "
                    f"sample's {float(t[-1])!r}")
        return None
    q = (t_final - t0) / dt
    if not abs(q) < 2.0**63:
        return f"t_final = {t_final!r} is not t0 = {t0!r} plus a count of steps dt = {dt!r}"
    n = round(q)
    if abs(t_final - (t0 + n * dt)) > _tol(t_final, t0) + 1e-9 * dt:
        return (f"t_final = {t_final!r} is not t0 + n * dt for an integer n (t0 = {t0!r}, dt = "
                f"{dt!r})")
    if status == 0 and k != n // every + 1:
        return (f"{k} samples, but a run of {n} steps of dt = {dt!r} saving every {every}-th "
                f"has {n // every + 1} (t0 = {t0!r}, t_final = {t_final!r})")
    if status == -1 and t_final < t[-1] - _tol(t_final, t0):
        return f"t_final = {t_final!r} precedes the last sample, {float(t[-1])!r}"
    return None
