"""Ensembles of trajectories on Dask: many initial states, or one system per parameter value.

:func:`integrate` splits a batch of initial states into chunks of members and runs one Dask
task per chunk; :func:`sweep` runs one task per parameter value, each integrating the system
``make_system(value)``. Both return a lazy :class:`xarray.Dataset` backed by Dask arrays:
nothing runs until ``.compute()``, ``.load()`` or ``.persist()``.

Every task is one native batch run, that of ``lieflow.integrate(..., threads=1)``: the
native run releases the GIL, so the tasks of Dask's local threaded scheduler run in parallel,
and one thread per task does not oversubscribe the cores of a ``dask.distributed`` worker. The
members of a batch are independent, so the results equal those of one
``lieflow.integrate(system, state0, ...)`` call bit for bit, whatever the chunking and wherever
the tasks run.

Which scheduler runs the tasks is Dask's usual rule, decided when the Dataset is computed: the
active ``dask.distributed`` ``Client`` if there is one, otherwise the local threaded scheduler
(or whatever ``scheduler=`` or ``dask.config`` says). See ``docs/ensembles.md``.

Dask and xarray are optional dependencies (``pip install lieflow[ensemble]``); they are imported
when a function of this module is called, not when ``lieflow`` is imported.
"""

from __future__ import annotations

import numbers
import operator
import sys
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np

from ._lieflow import InvalidArgumentError, ShapeError, __version__
from .integrate import _MAX_COUNT, _check_method, _check_system, _count, _step, _time
from .integrate import integrate as _integrate
from ._text import brief

if TYPE_CHECKING:  # pragma: no cover
    import xarray
    from numpy.typing import ArrayLike

__all__ = ["integrate", "sweep", "default_chunks", "TASKS_PER_CORE"]

#: Tasks per core of the default chunking: a few, so that the cores stay busy to the end when
#: tasks take unequal times (a worker that dies loses little) while the per-task cost (about a
#: millisecond with ``dask.distributed``) stays negligible.
TASKS_PER_CORE = 4


def _require():
    """(dask, dask.array, xarray), or an ImportError that says how to install them."""
    try:
        import dask
        import dask.array as da
        import xarray as xr
    except ImportError as e:
        raise ImportError(
            f"lieflow.ensemble needs dask and xarray ({e}); install them with "
            f"`pip install lieflow[ensemble]` (dask[array], distributed, xarray)") from e
    return dask, da, xr


def _cores() -> int:
    """The cores the tasks will run on, by Dask's choice of scheduler: the worker threads of
    the current ``dask.distributed`` client if there is one (and ``dask.config`` names no other
    scheduler), else the local cores (``num_workers`` of ``dask.config``, or
    ``dask.system.CPU_COUNT``)."""
    import dask
    from dask.system import CPU_COUNT

    named = dask.config.get("scheduler", None)
    dist = sys.modules.get("distributed")   # a client exists only if distributed was imported
    if dist is not None and named in (None, "distributed", "dask.distributed"):
        try:
            client = dist.Client.current(allow_global=True)
        except ValueError:                   # no client
            client = None
        if client is not None and not getattr(client, "asynchronous", False):
            try:
                n = sum(client.nthreads().values())
            except Exception:                # a client that cannot answer: the local rule
                n = 0
            if n > 0:
                return n
    return max(1, int(dask.config.get("num_workers", None) or CPU_COUNT))


def default_chunks(members: int, cores: int | None = None) -> int:
    """The default number of members per task of :func:`integrate`.

    ``ceil(members / (TASKS_PER_CORE * cores))`` (at least 1): about ``TASKS_PER_CORE`` tasks
    per core.

    Parameters
    ----------
    members : int
        The number of members of the ensemble.
    cores : int, optional
        The cores to spread the tasks over. Default: the total threads of the workers of the
        current ``dask.distributed`` client if there is one, else the local cores (Dask's
        ``num_workers`` setting if given).

    Returns
    -------
    int
        Members per task.

    Raises
    ------
    TypeError
        ``members`` or ``cores`` not an integer.
    lieflow.InvalidArgumentError
        ``members`` < 0 or ``cores`` < 1.
    """
    if isinstance(members, bool) or not isinstance(members, (numbers.Integral, np.integer)):
        raise TypeError(f"invalid members: expected an integer >= 0, got "
                        f"{type(members).__name__} {brief(members, 60)}")
    members = operator.index(members)
    if not 0 <= members <= _MAX_COUNT:
        raise InvalidArgumentError(f"invalid members: expected an integer in [0, 2**63 - 1], "
                                   f"got {members}")
    cores = _cores() if cores is None else _count("cores", cores)
    return max(1, -(-members // (TASKS_PER_CORE * cores)))


def _note(err: BaseException, text: str) -> None:
    if hasattr(err, "add_note"):
        err.add_note(text)


def _integrate_chunk(system, z, att, dt, steps, method, save_every, t0, lo):
    """One task of :func:`integrate`: the members ``lo ..`` of the ensemble, states ``z``
    (c, d), as one native batch run on one thread (the run of ``lieflow.integrate``, whose
    errors name the members by their index in the ensemble: ``first_member=lo``)."""
    task = f"in the lieflow.ensemble task of members {lo} to {lo + len(z) - 1}"
    try:
        states, attitude, final, final_att = system._run(
            z, att, dt, steps, save_every, method, t0=t0, threads=1, first_member=lo)
    except Exception as e:
        _note(e, task)
        raise
    try:   # the observables of the task's states (c, k, d), whose items are named [i, j]
        out = {"states": states, "energy": np.asarray(system.energy(states), dtype=np.float64),
               "invariants": np.asarray(system.invariants(states), dtype=np.float64),
               "final_state": final}
    except Exception as e:
        _note(e, f"{task}, of its states: states[i, j] is sample j of member {lo} + i")
        raise
    if att is not None:
        out["attitude"] = attitude
        out["final_attitude"] = final_att
    return out


def _sweep_task(make_system, value, index, z0, dt, steps, method, save_every, t0, d, c):
    """One task of :func:`sweep`: ``make_system(value)`` integrated from ``z0`` (d,); the
    arrays carry a leading ``param`` axis of length 1."""
    try:
        system = make_system(value)
        _check_system(system)
        traj = _integrate(system, z0, dt=dt, steps=steps, method=method,
                          save_every=save_every, threads=1, t0=t0, progress=False)
        inv = np.asarray(traj.invariants(), dtype=np.float64)
        if traj.states.shape[-1] != d or inv.shape[-1] != c:
            raise ShapeError(f"make_system(params[{index}]) made a system with states of "
                             f"{traj.states.shape[-1]} components and {inv.shape[-1]} "
                             f"invariants; make_system(params[0]) one with {d} and {c}")
        out = {"states": traj.states[None], "invariants": inv[None],
               "energy": np.asarray(traj.energy(), dtype=np.float64)[None],
               "final_state": traj.final_state[None]}
    except Exception as e:
        _note(e, f"in the lieflow.ensemble.sweep task of params[{index}] = {brief(value, 80)}")
        raise
    return out


def _lazy(dask, da, name, parts, shapes, variables):
    """Dask arrays, one per entry of ``variables`` ({name: trailing shape}), concatenated along
    the first axis over ``parts``: the keyword arguments of the tasks (calls of ``name[0]``),
    whose leading extents are ``shapes``. Every variable reads its block of one task's output,
    so a chunk runs once however many variables are computed."""
    fn, key = name
    tasks = [dask.delayed(fn, pure=True)(**kw, dask_key_name=(key, i))
             for i, kw in enumerate(parts)]
    out = {}
    for var, trailing in variables.items():
        blocks = [da.from_delayed(t[var], shape=(n,) + trailing, dtype=np.float64,
                                  name=f"{var}-{key}-{i}")
                  for i, (t, n) in enumerate(zip(tasks, shapes))]
        out[var] = blocks[0] if len(blocks) == 1 else da.concatenate(blocks, axis=0)
    return out


def _attrs(method, dt, save_every, t0, steps):
    return {"method": method, "dt": dt, "save_every": save_every, "t0": t0, "steps": steps,
            "lieflow_version": __version__}


def integrate(system: Any, state0: ArrayLike, dt: float, steps: int, method: str | None = None,
              save_every: int = 1, *, chunks: int | None = None, t0: float = 0.0,
              attitude: ArrayLike | None = None) -> xarray.Dataset:
    """Integrates an ensemble of initial states as Dask tasks; a lazy :class:`xarray.Dataset`.

    The members are split into chunks of ``chunks`` members, and each chunk becomes one Dask
    task: the native batch run of ``lieflow.integrate(system, state0[chunk], dt=dt,
    steps=steps, method=method, save_every=save_every, threads=1, t0=t0, progress=False)``
    that returns the chunk's states, energy and invariants; its errors name a member by its
    index in the ensemble. The native run releases the GIL, so the tasks run
    in parallel on Dask's threaded scheduler too; one thread per task keeps the cores of
    ``dask.distributed`` workers from being oversubscribed. Nothing runs until the Dataset is
    computed (``.compute()``, ``.load()``, ``.persist()``, or e.g. ``ds.energy.max().compute()``,
    which computes only what it needs).

    The scheduler is Dask's usual choice at compute time: the active ``dask.distributed``
    ``Client`` if there is one (it picks the Dataset up automatically), otherwise the local
    threaded scheduler (``scheduler=`` of ``compute`` or ``dask.config.set`` choose another).
    A worker that dies takes its running tasks with it; the distributed scheduler runs them
    again elsewhere. Ctrl-C during ``.compute()`` with a ``Client`` releases the submitted
    tasks (Dask's ``Client.get`` does so on any exception), so the scheduler cancels them;
    with the threaded scheduler no further task starts. A task that is already running
    finishes its chunk first (a running thread cannot be interrupted), so smaller ``chunks``
    stop sooner.

    Every argument is checked in the calling process before any task is made: all initial
    states (and attitudes) and the method by the native ``system._start`` (which validates
    without stepping), and the size of one task's trajectory by the rule of
    ``lieflow.integrate``. The results equal those of ``lieflow.integrate(system, state0,
    ...)`` bit for bit.

    Parameters
    ----------
    system : lieflow.System
        A system object, e.g. ``lieflow.RigidBody([1, 2, 3])`` (it is pickled into every task
        for ``dask.distributed``; the systems of lieflow pickle).
    state0 : array_like
        The initial states, a batch along a leading axis in the system's layout, as
        ``lieflow.integrate`` takes them (one state is an ensemble of one member).
    dt : float
        The time step (> 0).
    steps : int
        The number of steps (>= 1).
    method : str, optional
        One of ``system.methods()``; default: the system's own (the first).
    save_every : int, default 1
        Keep every ``save_every``-th state and the initial one: ``steps // save_every + 1``
        samples at t0 + j * save_every * dt.
    chunks : int, optional
        Members per task. Default: :func:`default_chunks`, i.e. ``ceil(b / (4 * cores))`` for
        b members, where ``cores`` is the total worker threads of the active
        ``dask.distributed`` client, or the local cores without one: about four tasks per
        core.
    t0 : float, default 0.0
        The time of the initial states; every time is absolute.
    attitude : array_like, optional
        The initial configuration of a system on a matrix group (a rotation (3, 3) for the SO(3)
        bodies, (n, n) in SO(n) or (4, 4) in SE(3) for ``LiePoisson``/``EulerPoincare``), one
        shared by all members or one per member (b, n, n); it is then integrated along.

    Returns
    -------
    xarray.Dataset
        Lazy (Dask-backed) variables ``states`` (``member``, ``time``, ``component``),
        ``energy`` (``member``, ``time``), ``invariants`` (``member``, ``time``,
        ``invariant``) and ``final_state`` (``member``, ``component``), the state after all
        steps (also when ``steps`` is not a multiple of ``save_every``); with an attitude also
        ``attitude`` (``member``, ``time``, ``attitude_row``, ``attitude_col``) and
        ``final_attitude`` (``member``, ``attitude_row``, ``attitude_col``). Coordinates
        ``member`` (0 .. b-1) and ``time`` (the sample times, exactly ``lieflow.integrate``'s
        ``traj.t``). Attributes ``system`` (its repr), ``method`` (the resolved name), ``dt``,
        ``save_every``, ``t0``, ``steps`` and ``lieflow_version``. The names are those of
        ``Trajectory.to_xarray()``.

    Raises
    ------
    ImportError
        Dask or xarray is not installed.
    TypeError
        ``system`` is not a ``lieflow.System``; ``dt`` or ``t0`` not a real number; ``steps``,
        ``save_every`` or ``chunks`` not an integer; ``method`` not a str; ``state0`` or
        ``attitude`` not real numbers.
    lieflow.InvalidArgumentError
        ``dt`` <= 0 or not finite, ``steps``, ``save_every`` or ``chunks`` < 1, a state
        outside the system's domain, an attitude for a system without one, one task's
        trajectory too large to keep (save less often or pass smaller ``chunks``).
    lieflow.UnsupportedMethodError
        ``method`` is not one of ``system.methods()``.
    lieflow.ShapeError
        ``state0`` or ``attitude`` of the wrong shape.
    lieflow.NonFiniteError
        A NaN or infinity in ``state0``.
    lieflow.NotInGroupError
        An attitude that is not a rotation.

    Errors of the run itself (e.g. ``lieflow.ConvergenceError``) are raised by ``.compute()``,
    naming the member by its index in the ensemble, with a note naming the task's members.

    Examples
    --------
    >>> import numpy as np, lieflow as lf
    >>> M = np.random.default_rng(0).standard_normal((1000, 3))
    >>> ds = lf.ensemble.integrate(lf.RigidBody([1, 2, 3]), M, dt=0.01, steps=1000,
    ...                            save_every=100)
    >>> ds = ds.compute()                                  # doctest: +SKIP
    """
    dask, da, xr = _require()
    _check_system(system)
    if not callable(getattr(system, "_run", None)):   # a task runs System._run
        raise TypeError(f"invalid system: expected a lieflow.System (e.g. lf.RigidBody([1, 2, "
                        f"3])), got {type(system).__name__} {brief(system, 60)}, which has no _run")
    steps = _count("steps", steps)
    save_every = _count("save_every", save_every)
    dt = _step(dt)
    t0 = _time("t0", t0)
    _check_method(method)
    if chunks is not None:
        chunks = _count("chunks", chunks)
    # Every member's state (and attitude) and the method, without stepping; the members are
    # named by their index in the ensemble. steps=1 here: the trajectory a task keeps is checked
    # below for one task, not for the whole ensemble, which is never held by one process.
    run = system._start(state0, attitude, dt, method, save_every, t0=t0, threads=None, steps=1)
    method = run.method
    z, att = run._initial()
    b, d = z.shape
    c = max(1, min(chunks if chunks is not None else default_chunks(b), b))
    try:    # the largest task's trajectory: refused here as lieflow.integrate would refuse it
        system._start(z[:c], None if att is None else att[:c], dt, method, save_every, t0=t0,
                      threads=1, steps=steps)
    except InvalidArgumentError as e:
        _note(e, f"in one task of chunks={c} members; pass smaller chunks or save less often")
        raise
    n_inv = np.asarray(system.invariants(z[:1])).shape[-1]
    k = steps // save_every + 1
    t = run._sample_times(steps)      # lieflow.integrate's traj.t
    del run

    from dask.base import tokenize
    token = tokenize("lieflow.ensemble.integrate", __version__, type(system).__name__,
                     repr(system), system, z, att, dt, steps, method, save_every, t0, c)
    bounds = [(lo, min(lo + c, b)) for lo in range(0, b, c)] or [(0, 0)]
    parts = [dict(system=system, z=z[lo:hi], att=None if att is None else att[lo:hi], dt=dt,
                  steps=steps, method=method, save_every=save_every, t0=t0, lo=lo)
             for lo, hi in bounds]
    variables = {"states": (k, d), "energy": (k,), "invariants": (k, n_inv),
                 "final_state": (d,)}
    if att is not None:
        variables.update(attitude=(k,) + att.shape[-2:], final_attitude=att.shape[-2:])
    arrays = _lazy(dask, da, (_integrate_chunk, f"lieflow-ensemble-{token}"), parts,
                   [hi - lo for lo, hi in bounds], variables)
    dims = {"states": ("member", "time", "component"), "energy": ("member", "time"),
            "invariants": ("member", "time", "invariant"),
            "final_state": ("member", "component"),
            "attitude": ("member", "time", "attitude_row", "attitude_col"),
            "final_attitude": ("member", "attitude_row", "attitude_col")}
    return xr.Dataset({v: (dims[v], a) for v, a in arrays.items()},
                      coords={"member": np.arange(b), "time": t,
                              "invariant": list(system.invariant_names)},
                      attrs={"system": repr(system), **_attrs(method, dt, save_every, t0, steps)})


def _param_coords(values: list) -> tuple[np.ndarray, dict]:
    """The ``param`` coordinate and the extra variables (``param_value``) of a sweep."""
    n = len(values)
    try:
        a = np.asarray(values)
    except (ValueError, TypeError):         # ragged
        a = None
    if a is not None and a.dtype.kind in "biuf" and a.ndim == 1:
        return a, {}
    if a is not None and a.dtype.kind in "US" and a.ndim == 1:
        return a, {}
    if a is not None and a.dtype.kind in "biuf":
        dims = ("param",) + tuple(f"param_dim_{i}" for i in range(a.ndim - 1))
        return np.arange(n), {"param_value": (dims, a)}
    return np.arange(n), {"param_value": (("param",), np.array([repr(v) for v in values]))}


def sweep(make_system: Callable[[Any], Any], params: Sequence[Any], state0: ArrayLike,
          dt: float, steps: int, method: str | None = None, save_every: int = 1, *,
          t0: float = 0.0) -> xarray.Dataset:
    """Integrates one initial state for each parameter value as Dask tasks; a lazy
    :class:`xarray.Dataset`.

    One Dask task per value ``p`` of ``params``: it builds ``make_system(p)`` inside the task
    and integrates ``state0`` by ``lieflow.integrate(system, state0, dt=dt, steps=steps,
    method=method, save_every=save_every, threads=1, t0=t0, progress=False)``. The scheduler
    is chosen as for :func:`integrate` (the active ``dask.distributed`` client, else the local
    threaded scheduler). ``make_system`` must be picklable by cloudpickle for
    ``dask.distributed`` (a module-level function, a lambda or a ``functools.partial`` is).

    The arguments are checked in the calling process before any task is made, by building
    ``make_system(params[0])`` and starting its run (without stepping); a later value whose
    system cannot be built or started raises at compute time, with a note naming it.

    Parameters
    ----------
    make_system : callable
        ``make_system(p)`` returns a system for the parameter value ``p``, e.g.
        ``lambda I3: lf.RigidBody([1, 2, I3])``. All systems must share the state layout of
        the first.
    params : sequence
        The parameter values (at least one): real numbers, arrays of one shape (e.g. inertia
        vectors), strings, or any objects ``make_system`` takes.
    state0 : array_like
        One initial state, in the layout of the systems.
    dt : float
        The time step (> 0).
    steps : int
        The number of steps (>= 1).
    method : str, optional
        A method of the systems; default: the first system's own (the first of its
        ``methods()``), used for every value.
    save_every : int, default 1
        Keep every ``save_every``-th state and the initial one.
    t0 : float, default 0.0
        The time of ``state0``; every time is absolute.

    Returns
    -------
    xarray.Dataset
        As :func:`integrate`, with the dimension ``param`` in place of ``member``: lazy
        variables ``states`` (``param``, ``time``, ``component``), ``energy`` (``param``,
        ``time``), ``invariants`` (``param``, ``time``, ``invariant``) and ``final_state``
        (``param``, ``component``). The coordinate ``param`` holds the values when they are
        real numbers or strings; otherwise it is 0 .. n-1 and the variable ``param_value``
        holds them: (``param``, ``param_dim_0``, ...) for arrays of one shape, their reprs for
        other objects. Attributes ``make_system`` (its name), ``system`` (the repr of the
        first system), ``method`` (the resolved name), ``dt``, ``save_every``, ``t0``,
        ``steps`` and ``lieflow_version``.

    Raises
    ------
    ImportError
        Dask or xarray is not installed.
    TypeError
        ``make_system`` not callable or not returning a system; ``params`` not a sequence;
        ``dt`` or ``t0`` not a real number; ``steps`` or ``save_every`` not an integer;
        ``method`` not a str; ``state0`` not real numbers.
    lieflow.InvalidArgumentError
        No parameter values; ``state0`` a batch; ``dt`` <= 0 or not finite; ``steps`` or
        ``save_every`` < 1; a state outside the first system's domain; a trajectory too large
        to keep.
    lieflow.UnsupportedMethodError
        ``method`` is not a method of the first system.
    lieflow.ShapeError
        ``state0`` of the wrong shape.
    lieflow.NonFiniteError
        A NaN or infinity in ``state0``.

    An exception of ``make_system(params[0])`` propagates, with a note naming the value.

    Examples
    --------
    >>> import lieflow as lf
    >>> ds = lf.ensemble.sweep(lambda I3: lf.RigidBody([1.0, 2.0, I3]), [2.5, 3.0, 4.0],
    ...                        [1.0, 0.5, -0.3], dt=0.01, steps=1000, save_every=10)
    >>> ds.energy.sel(param=3.0).compute()                 # doctest: +SKIP
    """
    dask, da, xr = _require()
    if not callable(make_system):
        raise TypeError(f"invalid make_system: expected a callable make_system(p) returning a "
                        f"system, got {type(make_system).__name__} {brief(make_system, 60)}")
    expected = "invalid params: expected a sequence of parameter values"
    if isinstance(params, (str, bytes, dict)) or not hasattr(params, "__iter__"):
        raise TypeError(f"{expected}, got {type(params).__name__} {brief(params, 60)}")
    if isinstance(params, np.ndarray) and params.ndim == 0:
        raise TypeError(f"{expected}, got a 0-d array {brief(params, 60)}")
    values = list(params)
    if not values:
        raise InvalidArgumentError("invalid params: expected at least one parameter value")
    steps = _count("steps", steps)
    save_every = _count("save_every", save_every)
    dt = _step(dt)
    t0 = _time("t0", t0)
    _check_method(method)
    try:
        system = make_system(values[0])
    except Exception as e:
        _note(e, f"raised by make_system(params[0]) with params[0] = {brief(values[0], 80)}")
        raise
    try:
        _check_system(system)
    except TypeError as e:
        raise TypeError(f"invalid make_system: make_system(params[0]) returned no system: "
                        f"{e}") from None
    z, batched = system._normalize_state(state0)
    if batched:
        raise InvalidArgumentError(f"invalid state0: sweep integrates one initial state per "
                                   f"parameter value, got a batch of {z.shape[0]}; use "
                                   f"lieflow.ensemble.integrate for a batch")
    run = system._start(z, None, dt, method, save_every, t0=t0, threads=1, steps=steps)
    method = run.method
    t = run._sample_times(steps)
    del run
    d = z.shape[1]
    n_inv = np.asarray(system.invariants(z)).shape[-1]
    k = steps // save_every + 1
    coord, extra = _param_coords(values)

    from dask.base import tokenize
    token = tokenize("lieflow.ensemble.sweep", __version__, make_system, values, z, dt, steps,
                     method, save_every, t0)
    parts = [dict(make_system=make_system, value=v, index=i, z0=z[0], dt=dt, steps=steps,
                  method=method, save_every=save_every, t0=t0, d=d, c=n_inv)
             for i, v in enumerate(values)]
    arrays = _lazy(dask, da, (_sweep_task, f"lieflow-sweep-{token}"), parts, [1] * len(values),
                   {"states": (k, d), "energy": (k,), "invariants": (k, n_inv),
                    "final_state": (d,)})
    dims = {"states": ("param", "time", "component"), "energy": ("param", "time"),
            "invariants": ("param", "time", "invariant"), "final_state": ("param", "component")}
    data = {v: (dims[v], a) for v, a in arrays.items()}
    data.update(extra)
    name = getattr(make_system, "__qualname__", None) or repr(make_system)
    return xr.Dataset(data, coords={"param": coord, "time": t,
                                    "invariant": list(system.invariant_names)},
                      attrs={"make_system": str(name), "system": repr(system),
                             **_attrs(method, dt, save_every, t0, steps)})
