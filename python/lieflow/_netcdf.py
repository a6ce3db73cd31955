"""lieflow.io's access to NetCDF: xarray and the NetCDF-4 backend, imported on call, and a file
opened only after its header's declared sizes are checked against its size."""

from __future__ import annotations

import math
import os

import numpy as np

from ._errors import FileFormatError


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
