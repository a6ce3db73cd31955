"""Trajectories as xarray Datasets and NetCDF files.

``Trajectory.to_xarray()`` gives a :class:`xarray.Dataset`; ``Trajectory.save(path)`` writes it to
a NetCDF file and ``lieflow.load`` reads it back as a ``Trajectory`` whose ``system`` is rebuilt,
so that a run can be continued from its ``final_state`` (:func:`read` gives its parts). This
module works on any object with a Trajectory's attributes and never imports the class: the
driver (``lieflow.integrate``) builds the Trajectory. Needs xarray and a NetCDF-4 backend
(``pip install lieflow[io]``: netCDF4).

Layout of the Dataset (format 1):

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
  system, as JSON), ``method``, ``dt``, ``save_every``, ``t0``, ``t_final``, ``status``,
  ``lieflow_version`` and ``lieflow_format``.

A system is stored as data: its class and constructor arguments (numbers, strings, arrays and
other lieflow objects such as potentials and surfaces), never as code. A system built from
Python callables (``lf.Canonical``, ``lf.Forced`` with a force function, ``Callable``
potentials) can be stored only pickled, with ``allow_pickle=True`` on both ``save`` and
``load`` (as ``numpy.load``): loading a pickle runs code from the file, so pass it only for
files you trust.
"""

from __future__ import annotations

import base64
import importlib
import inspect
import json
import numbers
import operator
import os

from typing import TYPE_CHECKING, Any

import numpy as np

from ._lieflow import InvalidArgumentError, LieflowError, __version__

if TYPE_CHECKING:
    import xarray

__all__ = ["FileFormatError", "FORMAT", "read", "save", "to_xarray"]

#: The version of the file layout written by :func:`save`; :func:`read` reads every version
#: up to it.
FORMAT = 1


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

#: Callables outside lieflow that may appear in a system's reduction (sums of potentials).
_OPERATORS = {"add": operator.add, "mul": operator.mul, "sub": operator.sub,
              "neg": operator.neg, "truediv": operator.truediv}


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
        if value.dtype.kind not in "biuf":
            raise _NotData(f"an array of dtype {value.dtype}")
        return {"array": value.tolist(), "dtype": value.dtype.str}
    if isinstance(value, (list, tuple)):
        items = [_encode(v) for v in value]
        return items if isinstance(value, list) else {"tuple": items}
    reduce = getattr(type(value), "__reduce__", None)
    fn = callable(reduce) and _lieflow_callable_name(value)
    if fn:
        _, args = value.__reduce__()[:2]
        return {"call": fn, "args": [_encode(a) for a in args]}
    raise _NotData(f"{type(value).__name__} {value!r:.60}")


def _lieflow_callable_name(value):
    """'module:name' of the callable that rebuilds `value`, when it is lieflow's or an operator."""
    if not type(value).__module__.startswith("lieflow"):
        return None
    try:
        fn = value.__reduce__()[0]
    except Exception:
        return None
    module, name = getattr(fn, "__module__", "") or "", getattr(fn, "__qualname__", "")
    if module.startswith("lieflow") and _resolve(f"{module}:{name}") is fn:
        return f"{module}:{name}"
    if module in ("_operator", "operator") and _OPERATORS.get(name) is fn:
        return f"operator:{name}"
    return None


def _resolve(name):
    """The callable 'module:qualname' names: lieflow's own or an operator, nothing else."""
    module, _, qualname = name.partition(":")
    if module == "operator" and qualname in _OPERATORS:
        return _OPERATORS[qualname]
    if not (module == "lieflow" or module.startswith("lieflow.")):
        raise FileFormatError(f"the system spec names {name!r}, which is not a lieflow callable")
    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


def _decode(data):
    if isinstance(data, list):
        return [_decode(v) for v in data]
    if not isinstance(data, dict):
        return data
    if "tuple" in data:
        return tuple(_decode(v) for v in data["tuple"])
    if "complex" in data:
        return complex(*data["complex"])
    if "array" in data:
        return np.array(data["array"], dtype=np.dtype(data["dtype"]))
    if "call" in data:
        return _resolve(data["call"])(*[_decode(a) for a in data["args"]])
    raise FileFormatError(f"unknown entry in the system spec: {sorted(data)}")


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
    """The trajectory as an :class:`xarray.Dataset` (layout in the module docstring).

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
        ds["invariants"] = (lead + ("time", "invariant"), inv.reshape(inv.shape[:len(lead) + 1]
                                                                      + (-1,)))
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
        attrs["system_spec"] = json.dumps(_encode(traj.system))
    except _NotData:
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
    return attrs


def save(traj: Any, path: str | os.PathLike[str], *, allow_pickle: bool = False) -> None:
    """Writes the trajectory to a NetCDF file at `path` (the Dataset of :func:`to_xarray`).

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
        pickled.
    """
    path = _path(path)
    engine = _engine()
    ds = to_xarray(traj)
    if "system_spec" not in ds.attrs:
        if not allow_pickle:
            raise InvalidArgumentError(
                f"invalid system: {traj.system!r:.80} holds Python callables and cannot be "
                f"stored as data; pass allow_pickle=True to store it pickled (lf.load then "
                f"needs allow_pickle=True too)")
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
    ds.to_netcdf(path, engine=engine)


def read(path: str | os.PathLike[str] | xarray.Dataset, *,
         allow_pickle: bool = False) -> dict[str, Any]:
    """The parts of a trajectory written by ``Trajectory.save`` (or of a Dataset of
    ``to_xarray``): the keyword arguments of ``lieflow.Trajectory`` (``system`` rebuilt,
    ``method``, ``t``, ``states``, ``attitude``, ``final_state``, ``final_attitude``, ``dt``,
    ``save_every``, ``t_final``, ``status``, ``t0``, ``initial_state``, ``initial_attitude`` and
    the events). ``lieflow.load(path)`` is ``Trajectory(**read(path))``.

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
        Not a lieflow trajectory file, a damaged one, or one in a newer format; a pickled
        system without ``allow_pickle``.
    """
    xr = _xarray()
    if isinstance(path, xr.Dataset):
        ds = path
    else:
        path = _path(path)
        if not os.path.exists(path):
            raise FileNotFoundError(f"no such file: {path!r}")
        engine = _engine()
        try:
            with xr.open_dataset(path, engine=engine) as f:
                ds = f.load()
        except Exception as e:
            raise FileFormatError(f"cannot read {path!r} as a NetCDF file (damaged, or not "
                                  f"NetCDF): {type(e).__name__}: {e}") from e
    where = "the dataset" if isinstance(path, xr.Dataset) else repr(path)
    version = ds.attrs.get("lieflow_format")
    if version is None:
        raise FileFormatError(f"{where} is not a lieflow trajectory (it has no lieflow_format "
                              f"attribute; Trajectory.save writes one)")
    if not isinstance(version, numbers.Integral) or not 1 <= int(version) <= FORMAT:
        raise FileFormatError(
            f"{where} was written by lieflow {ds.attrs.get('lieflow_version', '?')} in format "
            f"{version}; lieflow {__version__} reads formats 1 to {FORMAT}: upgrade lieflow")
    try:
        return _arguments(ds, allow_pickle)
    except FileFormatError:
        raise
    except Exception as e:
        raise FileFormatError(f"{where} is damaged: {type(e).__name__}: {e}") from e


def _system(attrs, allow_pickle):
    if "system_spec" in attrs:
        return _decode(json.loads(attrs["system_spec"]))
    if "system_pickle" in attrs:
        if not allow_pickle:
            raise FileFormatError(
                f"the system {attrs.get('system', '?')!s:.80} is stored pickled; loading it "
                f"runs code from the file: pass allow_pickle=True if you trust it")
        import pickle

        return pickle.loads(base64.b64decode(attrs["system_pickle"]))
    raise FileFormatError("the file does not say how to rebuild its system (no system_spec)")


def _arguments(ds, allow_pickle):
    a = ds.attrs
    system = _system(a, allow_pickle)

    def var(name):
        return np.asarray(ds[name].values) if name in ds.variables else None

    states = var("states")
    t = var("time")
    if states is None or t is None:
        raise FileFormatError("the dataset has no states or no time coordinate")
    if states.shape[-2] != t.shape[0]:
        raise FileFormatError(f"states of shape {states.shape} do not match {t.shape[0]} times")
    method = a["method"] if "method" in a else tuple(json.loads(a["methods"]))
    events = {}
    if "event_functions" in a:
        n = int(a["event_functions"])
        events["t_events"] = [var(f"t_events_{i}") for i in range(n)]
        events["state_events"] = [var(f"state_events_{i}") for i in range(n)]
        if "initial_attitude" in ds.variables:
            events["attitude_events"] = [var(f"attitude_events_{i}") for i in range(n)]

    def attr(name, kind):
        return kind(a[name]) if name in a else None

    return dict(system=system, method=method, t=t, states=states, attitude=var("attitude"),
                final_state=var("final_state"), final_attitude=var("final_attitude"),
                dt=attr("dt", float), save_every=attr("save_every", int),
                t_final=attr("t_final", float), status=int(a.get("status", 0)),
                t0=attr("t0", float), initial_state=var("initial_state"),
                initial_attitude=var("initial_attitude"), **events)
