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
* for runs with ``sensitivity=True``, ``jacobian`` (``[member,] time, tangent, direction``),
  ``final_jacobian`` (``[member,] tangent, direction``) and, when the system has parameters,
  ``parameter_jacobian`` (``[member,] time, tangent, parameter``) and
  ``final_parameter_jacobian``; the attribute ``parameters`` (a JSON list) names them;
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

from ._checksum import (_CHECKSUMS, _attribute_form, _attributes_digest,  # noqa: F401
                        _seal, _variable_digest, _verify)
from ._errors import FileFormatError
from ._lieflow import InvalidArgumentError, System, __version__
from ._text import brief
from ._metadata import (_EPS, _arguments, _attr, _check_method, _check_parameters,
                        _check_times,  # noqa: F401
                        _events, _grid_error, _methods, _tol)
from ._netcdf import (_MAX_COMPRESSION, _check_sizes, _declared, _engine,  # noqa: F401
                      _open, _xarray)

if TYPE_CHECKING:
    import xarray

__all__ = ["ALLOWED_CALLS", "FileFormatError", "FORMAT", "SPEC_LIMITS", "read", "save",
           "to_xarray"]

#: The version of the file layout written by :func:`save`; :func:`read` reads every version
#: up to it (format 1 without checksums, with a warning).
FORMAT = 2


# --- systems as data -----------------------------------------------------------------------

#: Everything a ``system_spec`` may call, as "module:qualname": the constructors of the lieflow
#: systems that can be stored as data, the factories of the potentials and surfaces they take,
#: and ``operator:add`` (a sum of potentials, ``Potential.__add__``'s reduction). :func:`read`
#: calls nothing else: a spec naming another callable, or holding anything but None, booleans,
#: numbers, strings, numeric arrays, complex numbers, lists, tuples and calls of these, is a
#: FileFormatError. The systems built from Python callables (``Canonical``, ``Separable``, the
#: ``Callable`` potential, the ``Revolution``, ``Graph`` and ``MetricSurface`` surfaces, the
#: ``Riemannian`` space, a ``Forced`` force function) are never data and are not listed.
ALLOWED_CALLS = frozenset({
    "lieflow:ChargedParticle",
    "lieflow:EulerPoincare",
    "lieflow:Forced",
    "lieflow:FrameTop",
    "lieflow:GeneralizedRigidBody",
    "lieflow:HeavyTop",
    "lieflow:LiePoisson",
    "lieflow:Pendulum",
    "lieflow:PseudoRigidBody",
    "lieflow.pseudo_rigid:RightReduced",
    "lieflow:RelativisticTangentTop",
    "lieflow:RigidBody",
    "lieflow:RollingDisk",
    "lieflow:RollingDisks",
    "lieflow:RollingSpheres",
    "lieflow:SphereParticle",
    "lieflow:SphericalPendulum",
    "lieflow:StaticFieldTop",
    "lieflow:TangentTop",
    "lieflow:WeakFieldTop",
    "lieflow.potentials:Harmonic",
    "lieflow.potentials:SaintVenantKirchhoff",
    "lieflow.potentials:SelfGravity",
    "lieflow.potentials:Stretch",
    "lieflow.potentials:Volumetric",
    "lieflow.potentials:Zero",
    "lieflow.spaces:Euclidean",
    "lieflow.spaces:Hyperbolic",
    "lieflow.spaces:Sphere",
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
        raise _NotData(f"{type(value).__name__} {brief(value, 60)}")
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
                f"{path}.call: {brief(name, 80)} is not a lieflow callable that rebuilds systems "
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
        f"{path}: an entry with the keys {brief(sorted(keys), 80)}; expected one of "
        f"{{call, args}}, {{array, dtype}}, {{tuple}}, {{complex}}")


def _parse_array(data, path, budget):
    """The numeric array of an {"array", "dtype"} entry, its shape and entries counted before
    it is made."""
    spelled = data["dtype"]
    if not (isinstance(spelled, str) and _DTYPE.fullmatch(spelled)):
        raise FileFormatError(f"{path}.dtype: {brief(spelled, 40)} is not the dtype of a numeric "
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
                        f"{type(path).__name__} {brief(path, 60)}") from None


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
             "initial_attitude", "final_attitude", "time", "member", "jacobian",
             "final_jacobian", "parameter_jacobian", "final_parameter_jacobian"}


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
    """The Dataset of `traj` without checksums (its arrays copies: editing the Dataset leaves
    the trajectory as it was)."""
    xr = _xarray()
    lead = ("member",) if traj.batched else ()
    ds = xr.Dataset(coords={"time": ("time", np.array(traj.t, dtype=np.float64))})
    if traj.batched:
        ds = ds.assign_coords(member=("member", np.arange(traj.states.shape[0])))
    ds["states"] = (lead + ("time", "component"), np.array(traj.states))
    for name, value in traj._fields().items():
        if name in _RESERVED:
            continue
        value = np.array(value)
        ds[name] = (lead + ("time",) + _field_dims(name, value.shape[len(lead) + 1:]), value)
    if observables and len(traj.t):
        ds["energy"] = (lead + ("time",), np.array(traj.energy(), dtype=np.float64))
        inv = np.array(traj.invariants(), dtype=np.float64)
        head = inv.shape[:len(lead) + 1]      # (-1 cannot size an empty batch's)
        ds["invariants"] = (lead + ("time", "invariant"),
                            inv.reshape(head + (math.prod(inv.shape[len(head):]),)))
        ds = ds.assign_coords(invariant=("invariant", traj.invariant_names))
    square = ("attitude_row", "attitude_col")
    if traj.attitude is not None:
        ds["attitude"] = (lead + ("time",) + square, np.array(traj.attitude))
    for name in ("initial_state", "final_state"):
        value = getattr(traj, name)
        if value is not None:
            ds[name] = (lead + ("component",), np.array(value))
    for name in ("initial_attitude", "final_attitude"):
        value = getattr(traj, name)
        if value is not None:
            ds[name] = (lead + square, np.array(value))
    if traj.t_events is not None and traj.state_events is not None:
        for i, te in enumerate(traj.t_events):
            ds[f"t_events_{i}"] = (f"event_{i}",), np.array(te, dtype=np.float64)
            ds[f"state_events_{i}"] = ((f"event_{i}", "component"),
                                       np.array(traj.state_events[i]))
            if traj.attitude_events is not None:
                ds[f"attitude_events_{i}"] = ((f"event_{i}",) + square,
                                              np.array(traj.attitude_events[i]))
    if getattr(traj, "jacobian", None) is not None:
        jac = ("tangent", "direction")
        ds["jacobian"] = (lead + ("time",) + jac, np.array(traj.jacobian))
        ds["final_jacobian"] = (lead + jac, np.array(traj.final_jacobian))
        names = list(traj.system.parameters)
        ds.attrs["parameters"] = json.dumps(names)
        if names:     # (a dimension of length 0 is an unlimited one in NetCDF-4)
            par = ("tangent", "parameter")
            ds["parameter_jacobian"] = (lead + ("time",) + par,
                                        np.array(traj.parameter_jacobian))
            ds["final_parameter_jacobian"] = (lead + par,
                                              np.array(traj.final_parameter_jacobian))
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
                f"invalid system: {brief(traj.system, 80)} holds Python callables (or arrays "
                f"beyond lieflow.io.SPEC_LIMITS) and cannot be stored as data; pass allow_pickle=True "
                f"to store it pickled (lf.load then needs allow_pickle=True too)")
        try:
            import cloudpickle as pickler  # type: ignore[import-untyped]
        except ImportError:
            import pickle as pickler
        try:
            blob = pickler.dumps(traj.system)
        except Exception as e:
            raise InvalidArgumentError(f"invalid system: cannot pickle {brief(traj.system, 80)}: "
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
        jac = ds.variables.get("jacobian")
        _check_parameters(ds.attrs, system, None if jac is None else jac.shape[-1],
                          "initial_attitude" in ds.variables or "attitude" in ds.variables)
    except FileFormatError as e:
        e.args = (f"{where}: {e}",)
        raise
    return dict(system=system, **args)


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
