"""The metadata of a stored trajectory checked against its data (:func:`lieflow.io.read`): the
method(s), dimensions and shapes, the attributes, the events, the sample times and the grid."""

from __future__ import annotations

import json
import math

import numpy as np

from ._errors import FileFormatError
from ._text import brief


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
            raise FileFormatError(f"the method {brief(name, 60)} is not one of the methods of "
                                  f"{type(system).__name__}: {known}")


def _check_parameters(attrs, system, directions=None, attitude=False):
    """FileFormatError unless the stored Jacobians' parameter names are ``system.parameters``
    and their ``directions`` (when given) those of the system's tangent lift."""
    if "parameters" in attrs and _parameter_names(attrs) != list(system.parameters):
        raise FileFormatError(f"the parameter Jacobian is along {_parameter_names(attrs)}, but "
                              f"{type(system).__name__} has the parameters "
                              f"{list(system.parameters)}")
    if directions is None:
        return
    lift = system._tangent(attitude)
    if lift is None or lift[1].directions != directions:
        want = "no tangent maps" if lift is None else f"{lift[1].directions} directions"
        raise FileFormatError(f"the Jacobians have {directions} directions; "
                              f"{type(system).__name__}{' with an attitude' if attitude else ''} "
                              f"has {want}")


def _parameter_names(attrs):
    text = attrs["parameters"]
    try:
        if not isinstance(text, str) or len(text) > 1 << 16:
            raise ValueError("not a short JSON text")
        names = json.loads(text)
    except (ValueError, RecursionError) as e:
        raise FileFormatError(f"the attribute parameters is not a JSON list of names: "
                              f"{e}") from e
    if not (isinstance(names, list) and all(isinstance(n, str) for n in names)):
        raise FileFormatError(f"the attribute parameters is not a list of names: {brief(text, 60)}")
    return names


def _jacobians(ds, var, dims, lead, b, k, d):
    """The Jacobians of a run with sensitivities (none: {}), their layout checked: e ≤ d, or
    d + 3 with an attitude (left-trivialised directions; the system's lift fixes e, checked by
    ``_check_parameters`` once the system is rebuilt); the parameter Jacobians zero-wide
    when the system has no parameters (then not stored)."""
    names = ("jacobian", "final_jacobian", "parameter_jacobian", "final_parameter_jacobian")
    present = [n for n in names if n in ds.variables]
    if not present and "parameters" not in ds.attrs:
        return {}
    if "jacobian" not in ds.variables or "parameters" not in ds.attrs:
        raise FileFormatError(f"the Jacobians of a run with sensitivities are incomplete: it has "
                              f"{present} and {'an' if 'parameters' in ds.attrs else 'no'} "
                              f"attribute parameters")
    e = ds.variables["jacobian"].shape[-1]
    with_attitude = "initial_attitude" in ds.variables or "attitude" in ds.variables
    if not 0 < e <= d + (3 if with_attitude else 0):
        raise FileFormatError(f"the Jacobians have {e} directions; with states of {d} "
                              f"components{' and an attitude' if with_attitude else ''} "
                              f"expected at most {d + (3 if with_attitude else 0)}")
    p = len(_parameter_names(ds.attrs))
    jac, par = ("tangent", "direction"), ("tangent", "parameter")
    layout = {"jacobian": (lead + ("time",) + jac, b + (k, e, e)),
              "final_jacobian": (lead + jac, b + (e, e))}
    if p:
        layout["parameter_jacobian"] = (lead + ("time",) + par, b + (k, e, p))
        layout["final_parameter_jacobian"] = (lead + par, b + (e, p))
    if set(present) != set(layout):
        raise FileFormatError(f"the Jacobians of a run with sensitivities along {p} parameters "
                              f"are {sorted(layout)}; the file has {sorted(present)}")
    out = {}
    for name, (want_dims, want_shape) in layout.items():
        x = var(name)
        if dims(name) != want_dims or x.shape != want_shape or x.dtype.kind != "f":
            raise FileFormatError(f"the variable {name} has dimensions {dims(name)} of shape "
                                  f"{x.shape} ({x.dtype}); expected {want_dims} of shape "
                                  f"{want_shape} (floats)")
        if not np.all(np.isfinite(x)):
            raise FileFormatError(f"the variable {name} holds non-finite values")
        out[name] = x
    if not p:
        out["parameter_jacobian"] = np.zeros(b + (k, e, 0))
        out["final_parameter_jacobian"] = np.zeros(b + (e, 0))
    return out


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
        raise FileFormatError(f"the attribute methods is not a list of names: {brief(text, 60)}")
    return names


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
        raise FileFormatError(f"the attribute {name} is {brief(value, 60)}; expected "
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
    # The attitude's size n (an n×n group element: 3 for the rotations of the SO(3) bodies, n for
    # SO(n), 4 for SE(3)), read from the file and then held to every attitude variable.
    n = next((ds.variables[v].shape[-1] for v in ("initial_attitude", "attitude")
              if v in ds.variables and ds.variables[v].ndim >= 2), 3)
    expected = {"time": (("time",), (k,)),
                "states": (lead + ("time", "component"), b + (k, d)),
                "initial_state": (lead + ("component",), b + (d,)),
                "final_state": (lead + ("component",), b + (d,)),
                "attitude": (lead + ("time",) + square, b + (k, n, n)),
                "initial_attitude": (lead + square, b + (n, n)),
                "final_attitude": (lead + square, b + (n, n)),
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
        raise FileFormatError(f"the attribute method is {brief(a['method'], 60)}; expected a name")

    events = _events(ds, var, dims, batched, d, status)
    jacobians = _jacobians(ds, var, dims, lead, b, k, d)
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
    if jacobians and k:
        # The first sample at t0 is the start (J = I, ∂z/∂θ = 0); the last at t_final the end.
        jac, pjac = jacobians["jacobian"], jacobians["parameter_jacobian"]
        if t0 is not None and t[0] == t0 and not (
                np.array_equal(jac[..., 0, :, :], np.broadcast_to(np.eye(jac.shape[-1]),
                                                                  jac[..., 0, :, :].shape))
                and not np.any(pjac[..., 0, :, :])):
            raise FileFormatError("the Jacobian at the first sample (t0) is not the identity")
        if t_final is not None and t[-1] == t_final:
            exact = sampling == "grid" and status != 1
            for name in ("jacobian", "parameter_jacobian"):
                x, last = jacobians[f"final_{name}"], jacobians[name][..., -1, :, :]
                same = np.array_equal(x, last) if exact else np.allclose(x, last, rtol=1e-9,
                                                                         atol=1e-9)
                if not same:
                    raise FileFormatError(f"final_{name} differs from the last sample of {name}, "
                                          f"which is at the same time t = {t_final!r}")
    for te in events.get("t_events", []):
        lo = -math.inf if t0 is None else t0 - _tol(t0, t0)
        hi = math.inf if t_final is None else t_final + _tol(t_final, t_final)
        if te.size and not (np.all(np.isfinite(te)) and np.all(np.diff(te) >= 0)
                            and te[0] >= lo and te[-1] <= hi):
            raise FileFormatError(f"event times {brief(te, 80)} are not increasing times within "
                                  f"[t0, t_final] = [{t0!r}, {t_final!r}]")

    return dict(method=a["method"] if "method" in a else tuple(_methods(a)), t=t,
                states=states, attitude=var("attitude"), final_state=var("final_state"),
                final_attitude=var("final_attitude"), dt=dt, save_every=save_every,
                t_final=t_final, status=status, t0=t0, initial_state=var("initial_state"),
                initial_attitude=var("initial_attitude"), **events, **jacobians)


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
            size = ds.variables["initial_attitude"].shape[-1]
            layout[f"attitude_events_{i}"] = ((e, "attitude_row", "attitude_col"), size)
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
        raise FileFormatError(f"the attribute sampling is {brief(sampling, 40)}; expected "
                              f"'grid' or 'irregular'")
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
