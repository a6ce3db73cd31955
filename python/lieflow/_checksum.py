"""The checksums of lieflow's file format 2 (``lieflow_checksums``): SHA-256 of every variable
and of the attributes, written by ``_seal`` and verified by ``_verify`` (see :mod:`lieflow.io`)."""

from __future__ import annotations

import hashlib
import json

import numpy as np

from ._errors import FileFormatError
from ._text import brief

_CHECKSUMS = "lieflow_checksums"


def _variable_digest(name, var):
    """SHA-256 of a variable: its name, dimensions, dtype (kind and size; little-endian),
    shape and values (C order); of a text variable (the labels of the ``invariant`` axis), its
    name, dimensions and strings."""
    a = np.asarray(var.values)
    if a.dtype.kind in "UO" and a.ndim == 1 and all(isinstance(s, str) for s in a):
        text = json.dumps([name, list(var.dims), "text", [str(s) for s in a]])
        return hashlib.sha256(text.encode("utf-8")).hexdigest()
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
        raise FileFormatError(f"attribute {name!r}: {brief(value, 60)} is neither text nor numbers")
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
