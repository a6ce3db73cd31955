"""Integration driver: ``integrate(system, state0, dt=..., steps=..., method=...)`` -> ``Trajectory``.

The loop around one native run (``lieflow.Integration``): chunks, so that Ctrl-C is honoured
promptly (Python handles signals between native calls; the native work runs with the GIL
released), and an optional progress bar. Everything else is the native run's: it reads and
checks every argument once (``System._start``), owns the clock, and returns with each chunk the
times of its samples, the current state and the time of the final state (``_chunk``); the
result does not depend on the chunking.

Protocol a system implements (``lieflow.System`` implements it once for every system):
``methods()`` (the first is the default), ``_start(state0, attitude, dt, method | None,
save_every, *, t0, threads, steps, t_eval, single) -> run`` with ``run.method`` (the name),
``run.members``, ``run._initial()``, ``run._chunk(steps, t=None)`` (module ``lieflow.integrate``
reads its tuple), ``run._partial()``, ``run._head()``, vectorised ``energy`` and
``invariants``/``casimirs``; optionally ``_fields(states) -> dict`` of named views and further
observables ``NAME(states)``. A run that has only ``advance(steps) -> (states (b, k, d),
attitude | None)`` and ``state()`` is driven through them (every ``save_every``-th state; no
``t_eval``, no events). ``t_eval`` and ``events`` use more of the run: ``set_events``,
``steps_to``.
"""

import math
import numbers
import operator
import sys
import warnings

import numpy as np

from ._lieflow import (InvalidArgumentError, LieflowWarning, NonFiniteError, ShapeError,
                       System, UnsupportedMethodError)
from ._arrays import real_array
from .trajectory import Trajectory, load
from ._text import brief

__all__ = ["integrate", "load", "Trajectory", "CHUNK_WORK", "MIN_CHUNK_STEPS"]

#: Steps x bodies per native call. Between two calls Python checks for Ctrl-C and updates the
#: progress bar; at 5 ns (rigid bodies in SIMD lanes) to 1 us per body-step a chunk takes well
#: under a second. The chunking
#: depends only on the arguments (not on timings), so a run is reproducible bit for bit.
CHUNK_WORK = 200_000
#: Minimal steps per native call for large batches: each call costs ~1 us per body (stepper
#: set-up, buffers), which 250 steps amortise.
MIN_CHUNK_STEPS = 250


#: Counts are passed to native code as 64-bit integers.
_MAX_COUNT = 2**63 - 1


def _count(name, value):
    """An integer >= 1: TypeError for another type (bools and floats included),
    InvalidArgumentError for an integer < 1."""
    try:
        if type(value) is bool:
            raise TypeError
        n = value if type(value) is int else operator.index(value)
    except TypeError:
        raise TypeError(
            f"invalid {name}: expected an integer >= 1, got {type(value).__name__} {value!r}"
        ) from None
    if n < 1:
        raise InvalidArgumentError(f"invalid {name}: expected an integer >= 1, got {n}")
    if n > _MAX_COUNT:
        raise InvalidArgumentError(f"invalid {name}: expected an integer <= 2**63 - 1, got {n}")
    return n


def _real(value):
    """Whether `value` is a real number (bool excluded) or a 0-d numpy array of one; the common
    float and int first (the ABC check of numbers.Real costs a microsecond)."""
    if type(value) is float or type(value) is int:
        return True
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
    return ok or (isinstance(value, np.ndarray) and value.shape == ()
                  and value.dtype.kind in "iuf")


def _step(dt):
    """The time step as a float: TypeError unless a real number (str, bool, complex and arrays
    of size > 1 refused), InvalidArgumentError unless finite and > 0."""
    ok = _real(dt)
    if not ok:
        raise TypeError(f"invalid dt: expected a real number > 0, got {type(dt).__name__} {dt!r}")
    dt = float(dt)
    if not (0 < dt < np.inf):
        raise InvalidArgumentError(f"invalid dt: expected a finite number > 0, got {dt!r}")
    return dt


def _check_method(method):
    """TypeError unless ``method`` is None or a name."""
    if method is not None and not isinstance(method, str):
        raise TypeError(f"invalid method: expected a name (str), got {type(method).__name__} "
                        f"{method!r}")


def _check_system(system):
    """TypeError unless ``system`` speaks the protocol (a ``lieflow.System`` instance or alike)."""
    if isinstance(system, System):
        return
    if isinstance(system, type):
        raise TypeError(f"expected a lieflow system, got the class {system.__name__}; make one "
                        f"first, e.g. {system.__name__}(...)")
    if not all(callable(getattr(system, a, None)) for a in ("_normalize_state", "_start")):
        raise TypeError(f"expected a lieflow system (e.g. lf.RigidBody([1, 2, 3])), got "
                        f"{type(system).__name__} {brief(system, 60)}")


class _Progress:
    """tqdm if importable, else a line on stderr rewritten in place; nothing when disabled."""

    def __init__(self, total, enabled, desc):
        self.total, self.done, self.bar, self.enabled = total, 0, None, enabled
        if not enabled:
            return
        try:
            from tqdm.auto import tqdm
        except ImportError:
            self.desc = desc
            self._line()
        else:
            self.bar = tqdm(total=total, unit="step", desc=desc)

    def _line(self):
        pct = 100.0 * self.done / self.total
        sys.stderr.write(f"\r{self.desc}: {self.done}/{self.total} steps ({pct:5.1f}%)")
        sys.stderr.flush()

    def update(self, n):
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
        elif self.enabled:
            self._line()

    def close(self):
        if self.bar is not None:
            self.bar.close()
        elif self.enabled:
            sys.stderr.write("\n")
            sys.stderr.flush()


def _time(name, value):
    """A time as a float: TypeError unless a real number, InvalidArgumentError unless finite."""
    if not _real(value):
        raise TypeError(f"invalid {name}: expected a real number, got {type(value).__name__} "
                        f"{brief(value, 60)}")
    value = float(value)
    if not -np.inf < value < np.inf:
        raise InvalidArgumentError(f"invalid {name}: expected a finite number, got {value!r}")
    return value


def _warn_square(system, state0):
    """A LieflowWarning for a (d, d) state0 of a system of d values: read as a batch of d
    states (one per row), though one state in matrix form may have been meant."""
    d = system.state_dim
    if d > 1 and isinstance(state0, (np.ndarray, list)):
        try:
            shape = np.shape(state0)
        except ValueError:          # ragged
            return
        if shape == (d, d):
            warnings.warn(f"state0 of shape ({d}, {d}) is read as a batch of {d} states of "
                          f"{type(system).__name__} (one per row; a state has shape ({d},)); "
                          f"if a batch is meant, silence this with warnings.filterwarnings("
                          f"\"ignore\", \"state0 of shape\", lieflow.LieflowWarning)",
                          LieflowWarning, stacklevel=3)


def _span(t_span, dt, steps, t0):
    """(t0, dt, steps) of ``t_span = (t0, t1)``: n = ceil((t1 - t0)/dt) equal steps of
    (t1 - t0)/n <= dt (n = round((t1 - t0)/dt) where that ratio is an integer to 1e-9)."""
    if steps is not None or t0 is not None:
        raise InvalidArgumentError("invalid t_span: give either t_span = (t0, t1) or steps "
                                   "(and t0), not both")
    if isinstance(t_span, (str, bytes)) or not hasattr(t_span, "__len__") or len(t_span) != 2:
        raise TypeError(f"invalid t_span: expected (t0, t1), got {type(t_span).__name__} "
                        f"{brief(t_span, 60)}")
    start, end = _time("t_span[0]", t_span[0]), _time("t_span[1]", t_span[1])
    dt = _step(dt)
    if not end > start:
        raise InvalidArgumentError(f"invalid t_span: expected t0 < t1, got ({start!r}, {end!r})")
    ratio = (end - start) / dt
    n = round(ratio) if abs(ratio - round(ratio)) <= 1e-9 * ratio else math.ceil(ratio)
    return start, (end - start) / max(n, 1), max(n, 1)


def _times(t_eval):
    """t_eval as a 1-D float64 array of finite times (TypeError for anything but real numbers,
    ShapeError unless 1-D and non-empty); the native run checks their order and range."""
    a = real_array("t_eval", t_eval)
    if a.ndim != 1 or a.size == 0:
        raise ShapeError(f"t_eval has the wrong shape: expected (k,) with k >= 1, got {a.shape}")
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not np.all(np.isfinite(a)):
        raise NonFiniteError(f"t_eval contains a non-finite value (NaN or inf) at index "
                             f"{int(np.argmin(np.isfinite(a)))}")
    return a


def _events(events):
    """(functions, directions, terminal counts) of ``events``: a callable or a list of them,
    each with optional attributes ``terminal`` (bool or int >= 0) and ``direction`` (a real
    number), as in scipy."""
    fns = [events] if callable(events) else events
    if not isinstance(fns, (list, tuple)) or not all(callable(f) for f in fns):
        raise TypeError(f"invalid events: expected a callable g(t, state) or a list of them, got "
                        f"{type(events).__name__} {brief(events, 60)}")
    directions, terminal = [], []
    for i, f in enumerate(fns):
        d = getattr(f, "direction", 0.0)
        if d is None:
            d = 0.0
        if isinstance(d, bool) or not isinstance(d, numbers.Real):
            raise TypeError(f"invalid events[{i}].direction: expected a real number, got "
                            f"{type(d).__name__} {brief(d, 60)}")
        d = float(d)
        if not np.isfinite(d):
            raise InvalidArgumentError(f"invalid events[{i}].direction: expected a finite number "
                                       f"(its sign: > 0 rising, < 0 falling, 0 both), got {d}")
        n = getattr(f, "terminal", False)
        if n is None:
            n = False
        if isinstance(n, (bool, np.bool_)):
            n = int(bool(n))
        else:
            try:
                n = operator.index(n)
            except TypeError:
                raise TypeError(f"invalid events[{i}].terminal: expected a bool or an int >= 0, "
                                f"got {type(n).__name__} {brief(n, 60)}") from None
            if not 0 <= n <= _MAX_COUNT:
                raise InvalidArgumentError(f"invalid events[{i}].terminal: expected a bool or an "
                                           f"int >= 0, got {n}")
        directions.append(d)
        terminal.append(n)
    return list(fns), directions, terminal


def _native(run, name, argument):
    """The output-control method `name` of a native run (TypeError for a duck-typed system's run
    that has none)."""
    fn = getattr(run, name, None)
    if fn is None:
        raise TypeError(f"invalid {argument}: the runs of this system do not support it (its "
                        f"_start returned a {type(run).__name__} without .{name})")
    return fn


def integrate(system, state0, dt, steps=None, method=None, save_every=1, attitude=None,
              progress=False, chunk_steps=None, threads=None, *, t0=None, t_span=None,
              t_eval=None, events=None, event_tol=0.0, sensitivity=False):
    r"""Integrates ``system`` from ``state0`` by ``steps`` fixed steps of size ``dt``.

    Args:
        system: a system object, e.g. ``RigidBody([1, 2, 3])``.
        state0: an initial state in the system's layout (for ``RigidBody`` the momentum M (3,);
            a tuple with one array per field, e.g. ``(M, Gamma)`` or ``(X, P)``, also works), or
            a batch of them along a leading axis; a batch runs in parallel on all cores.
        dt: the time step (> 0).
        steps: the number of steps (>= 1); may be None with ``t_eval``, whose last time is then
            the end of the run.
        method: one of ``system.methods()`` (default: the first, the system's own default).
        save_every: keep every ``save_every``-th state (and the initial one): the trajectory has
            ``steps // save_every + 1`` samples at t = t0 + j * save_every * dt.
        attitude: the initial configuration g of a system on a matrix group, integrated along:
            a rotation R (3, 3) for the SO(3) bodies, an (n, n) element of SO(n) or a homogeneous
            (4, 4) element of SE(3) for ``LiePoisson``/``EulerPoincare`` on those algebras;
            shared by a batch, or one per batch member (b, n, n).
        progress: show a progress bar (tqdm if installed, else a line on stderr).
        chunk_steps: steps per native call (default: ``CHUNK_WORK // batch size``, at least
            ``MIN_CHUNK_STEPS``; with ``sensitivity=True`` both divided by 1 + k, the k
            directions of the lift). Ctrl-C is noticed between calls. Results do not depend on
            it.
        threads: threads for a batch (default: all cores).
        t0: the time of ``state0`` (default 0); every time of the run is absolute.
        t_span: ``(t0, t1)`` instead of ``steps`` and ``t0`` (scipy's ``solve_ivp`` habit): the
            run takes :math:`n = \lceil (t_1 - t_0)/dt \rceil` equal steps of
            :math:`(t_1 - t_0)/n \le dt` and ends exactly at t1 (``traj.dt`` is that step).
        t_eval: save the states at exactly these times (1-D, strictly increasing, within
            [t0, t0 + steps * dt]) instead of every ``save_every``-th state: ``traj.t`` is
            ``t_eval``. The run still steps with ``dt`` on the grid t0 + k * dt; a time between
            two grid times is reached by one shortened step of the method (of size t - t_k,
            from the grid state before it; a step of another size, not an interpolation, so
            the state keeps what the method keeps), and the run goes on on its grid. With
            ``steps=None`` the run ends at ``t_eval[-1]`` (with a last shortened step there),
            as scipy's ``t_span = (t0, t_eval[-1])``; with ``steps`` given it ends at
            t0 + steps * dt (``final_state``) whatever ``t_eval``.
        events: a function ``g(t, state) -> float`` or a list of them (scipy's ``events``),
            evaluated on the state after every step (``state`` as in ``traj.states``, without
            the attitude); optional attributes ``terminal`` (True, or the number of occurrences
            that ends the run) and ``direction`` (> 0: only zeros where g rises, < 0: falls,
            0: both). A sign change between two steps is located by taking that step again from
            its start with shortened step sizes (Brent's method on the step size, to round-off
            in t plus ``event_tol``), never by interpolation: the state at an event is a state
            of the method. A g exactly 0 at a step is an event there; a start at g = 0 is not.
            Single initial states only (a batch is an InvalidArgumentError).
        event_tol: an absolute tolerance in time (>= 0) added to round-off when locating events.
        sensitivity: also compute the Jacobian :math:`\partial z_k/\partial z_0` of the
            method's own discrete map at every sample (``traj.jacobian``, (k, d, d)) and its
            derivative along the system's
            parameters (``traj.parameter_jacobian``, (k, d, p), columns ``system.parameters``);
            exact to round-off, not finite differences: the run integrates the system's tangent
            lift with the same method (about d + p + 1 times the work of the plain run);
            ``traj.vjp(cotangent)`` gives the gradient of a loss. With an attitude, d counts its
            three left-trivialised directions (:math:`\delta R = R \hat\xi`) in place of R's
            nine entries (rk4, which leaves SO(3), reads the final ones through R's polar
            factor). Available
            where the system gives the derivatives its method needs
            (``system.sensitivity_methods(attitude=...)``); not yet with events.

    Returns:
        A ``Trajectory``. With events, ``traj.t_events`` and ``traj.state_events`` list the
        events of each function; a terminal event ends the run there (``traj.status == 1``,
        ``final_state`` the event's state, which is also the last sample unless ``t_eval``
        gives the samples; then the samples are those of ``t_eval`` up to the event).

    Raises:
        TypeError (``system`` not a system; ``dt``, ``t0`` not real numbers; ``steps``,
        ``save_every``, ``chunk_steps``, ``threads`` not integers; ``method`` not a str;
        ``t_eval`` not real numbers; ``events`` not callables),
        InvalidArgumentError (dt <= 0 or non-finite, steps < 1, save_every < 1, state
        constraints, t_eval unsorted or outside the run, save_every with t_eval, events for a
        batch), UnsupportedMethodError (lists the system's methods), ShapeError,
        NonFiniteError (also a non-finite value of an event function), NotInGroupError
        (attitude), ConvergenceError, LeftDomainError (naming the absolute step and time);
        KeyboardInterrupt on Ctrl-C; an exception raised by an event function. An exception
        raised during the run carries the trajectory computed so far as ``err.partial`` (a
        ``Trajectory`` with ``status == -1``).
    """
    if not isinstance(system, System):
        _check_system(system)
    _warn_square(system, state0)
    if t_span is not None:
        t0, dt, steps = _span(t_span, dt, steps, t0)
    elif t0 is None:
        t0 = 0.0
    if sensitivity is not False:
        if sensitivity is not True:
            if not isinstance(sensitivity, np.bool_):
                raise TypeError(f"invalid sensitivity: expected True or False, got "
                                f"{type(sensitivity).__name__} {sensitivity!r}")
            sensitivity = bool(sensitivity)      # numpy's bool, e.g. of a comparison
        if sensitivity:
            return _with_sensitivity(system, state0, dt, steps, method, save_every, attitude,
                                     progress, chunk_steps, threads, t0, t_eval, events)
    if steps is None and t_eval is None:
        raise TypeError("invalid steps: expected an integer >= 1, got NoneType None (steps may be "
                        "None only with t_eval, whose last time is then the end of the run)")
    times = ev = None
    if t_eval is not None:
        times = _times(t_eval)
    if events is not None:
        ev = _events(events)
    if event_tol.__class__ is not float or event_tol != 0.0:
        event_tol = _time("event_tol", event_tol)
        if event_tol < 0:
            raise InvalidArgumentError(f"invalid event_tol: expected a time >= 0, got "
                                       f"{event_tol!r}")
    # Every other argument is read and checked once, natively (`steps`: a trajectory that
    # cannot be kept is refused before any step).
    run = system._start(state0, attitude, dt, method, save_every, t0, threads, steps, None, times,
                        ev is not None)
    if not hasattr(run, "_chunk"):
        run = _Plain(run, system, state0, attitude, dt, t0, save_every)
    if times is None and steps is not None and run.save_every > steps:
        warnings.warn(f"save_every = {run.save_every} exceeds steps = {steps}: the trajectory "
                      f"holds only the initial state (the last one is traj.final_state); pass "
                      f"save_every <= steps", LieflowWarning, stacklevel=2)
    if chunk_steps is None:
        cap = max(MIN_CHUNK_STEPS, CHUNK_WORK // max(run.members, 1))
    else:
        cap = _count("chunk_steps", chunk_steps)
    if ev is None and times is None and not progress and steps <= cap and hasattr(run, "_whole"):
        # A plain run that fits in one native call: its trajectory's arrays in that call.
        try:
            t, states, att, z, za, t_final, z0, za0 = run._whole(steps)
        except BaseException as e:
            _attach_partial(e, system, run, [], None, None)
            raise
        whole = (system, run.method, t, states, att, z, za, run.dt, run.save_every)
        rest = dict(t_final=t_final, t0=run.t0, initial_state=z0, initial_attitude=za0)
        try:
            return Trajectory(*whole, **rest)
        except BaseException as e:
            # Ctrl-C after the run: the whole run is the partial.
            _attach(e, lambda: Trajectory(*whole, status=-1, **rest), steps)
            raise
    if ev is not None:
        _native(run, "set_events", "events")(*ev, float(event_tol))
    chunk = run._chunk
    total = steps if steps is not None else _native(run, "steps_to", "t_eval")(float(times[-1]))
    # One tuple per native call, appended in one statement so that Ctrl-C between two leaves
    # the list consistent (`_chunk`: times, states, attitudes, state after, attitude after,
    # steps done, end time or None, (t_final, t_final unsnapped), events or None).
    chunks = []
    bar = _Progress(total, True, f"{type(system).__name__} {run.method}") if progress else None
    try:
        done = 0
        ended = None
        while done < total and ended is None:
            c = chunk(min(cap, total - done))
            chunks.append(c)
            ended = c[6]
            if bar is not None:
                bar.update(c[5] - done)
            done = c[5]
        if steps is None and ended is None:
            c = chunk(None, float(times[-1]))
            chunks.append(c)
    except BaseException as e:
        _attach_partial(e, system, run, chunks, times, ev)
        raise
    finally:
        if bar is not None:
            bar.close()
    try:
        stopped = run.stopped_by if ev is not None else None
        return _trajectory(system, run, chunks, times, 1 if stopped is not None else 0, ev)
    except BaseException as e:
        # Ctrl-C while the chunks are joined: the run's chunks are the partial.
        _attach_partial(e, system, run, chunks, times, ev)
        raise


def _with_sensitivity(system, state0, dt, steps, method, save_every, attitude, progress,
                      chunk_steps, threads, t0, t_eval, events):
    """``integrate(..., sensitivity=True)``: the run of the tangent lift, split into the states
    (and attitudes) and their Jacobians (see ``integrate``)."""
    name = type(system).__name__
    if events is not None:
        raise InvalidArgumentError("invalid events: sensitivity=True is not available with "
                                   "events yet")
    with_attitude = attitude is not None
    methods = system.sensitivity_methods(with_attitude)
    if not methods:
        what = " with an attitude" if with_attitude else ""
        raise InvalidArgumentError(f"invalid sensitivity: {name} has no tangent maps{what} yet "
                                   f"({name}.sensitivity_methods() is empty)")
    if method is None:
        method = system.methods()[0]
    if not isinstance(method, str):
        raise TypeError(f"invalid method: expected a str, got {type(method).__name__} {method!r}")
    if method not in methods:
        raise UnsupportedMethodError(
            f"unsupported method {method!r} with sensitivity=True: the tangent maps of {name} are "
            f"available for {methods} (method=...)")
    # The lift of this method's runs (a Runge–Kutta method's directions are ambient on SO(3)).
    lifted, layout = system._tangent(with_attitude, method)
    z0, batched = system._normalize_state(state0)
    d = z0.shape[1]
    a = None
    if with_attitude:
        a = real_array("attitude", attitude)
        if a.ndim == 2:
            a = np.broadcast_to(a, (z0.shape[0],) + a.shape)
        if a.ndim != 3 or a.shape[0] != z0.shape[0] or a.shape[1:] != (3, 3):
            raise ShapeError(f"attitude has the wrong shape: expected (3, 3) or "
                             f"({z0.shape[0]}, 3, 3), got {np.shape(attitude)}")
        a = a.astype(np.float64)
        bad = np.argwhere(~np.isfinite(a))
        if len(bad):
            # Named as the attitude (the plain run's words), not as an entry of the state the
            # lift's seed is made of.
            k, i, j = bad[0]
            member = f"batch member {k}: " if batched else ""
            raise NonFiniteError(f"{member}attitude contains a non-finite value (NaN or inf) at "
                                 f"({i}, {j})")
        z0 = np.concatenate([z0, a.reshape(z0.shape[0], 9)], axis=1)
    seeds = layout.seed(z0 if batched else z0[0])
    if chunk_steps is None:
        # A lifted step does the work of about 1 + k plain steps (k = e + p directions): so
        # many fewer steps per native call keep Ctrl-C as prompt as in a plain run.
        per_step = 1 + layout.directions + len(layout.parameters)
        chunk_steps = max(1, MIN_CHUNK_STEPS // per_step,
                          CHUNK_WORK // (per_step * max(z0.shape[0], 1)))
    try:
        traj = integrate(lifted, seeds, dt, steps, method, save_every, None, progress,
                         chunk_steps, threads, t0=t0, t_eval=t_eval)
    except BaseException as e:
        # The partial trajectory of the lifted run, in the system's own terms (never the
        # lift's layout: without its conversion no partial).
        partial = getattr(e, "partial", None)
        if partial is not None:
            e.partial = None
            _attach(e, lambda: _split_lifted(system, partial, layout, d, a, batched))
        raise
    try:
        return _split_lifted(system, traj, layout, d, a, batched)
    except BaseException as e:
        # Ctrl-C while the Jacobians are split out: the whole run is the partial.
        _attach(e, lambda: _split_lifted(system, traj, layout, d, a, batched, status=-1))
        raise


def _attach(err, partial, steps=None):
    """Sets ``err.partial`` to ``partial()`` unless the error carries one already (and the note
    naming it when ``steps`` is given); never hides the error behind one of the partial's."""
    if getattr(err, "partial", None) is not None:
        return
    try:
        p = partial()
        err.partial = p
        if steps is not None and hasattr(err, "add_note"):
            err.add_note(f"the trajectory computed before this (to step {steps}, "
                         f"t = {p.t_final:g}) is err.partial")
    except Exception:
        pass


def _split_lifted(system, traj, layout, d, attitude0, batched, status=None):
    """The Trajectory of ``system`` (states, attitudes, Jacobians) from one of its tangent lift
    (``d``: the system's state size; ``attitude0``: (b, 3, 3) when the run carries one;
    ``status``: the lifted trajectory's unless given)."""
    states, jac, pjac = layout.split(traj.states)
    final, final_jac, final_pjac = layout.split(traj.final_state)
    z0 = layout.split(traj.initial_state)[0][..., :d]
    att = final_att = att0 = None
    if attitude0 is not None:
        att = states[..., d:].reshape(states.shape[:-1] + (3, 3))
        final_att = final[..., d:].reshape(final.shape[:-1] + (3, 3))
        att0 = attitude0 if batched else attitude0[0]
        states, final = states[..., :d], final[..., :d]
    return Trajectory(system, traj.method, traj.t, states, att, final, final_att, traj.dt,
                      traj.save_every, t_final=traj.t_final,
                      status=traj.status if status is None else status, t0=traj.t0,
                      initial_state=z0, initial_attitude=att0, jacobian=jac,
                      final_jacobian=final_jac, parameter_jacobian=pjac,
                      final_parameter_jacobian=final_pjac)


def _trajectory(system, run, parts, times, status, ev):
    """The Trajectory of the native calls `parts` (``_chunk`` tuples), the last one ending it."""
    if len(parts) == 1:
        t, states, attitudes = parts[0][:3]
    else:
        t = np.concatenate([c[0] for c in parts])
        states = np.concatenate([c[1] for c in parts], axis=1)
        attitudes = (None if parts[0][2] is None
                     else np.concatenate([c[2] for c in parts], axis=1))
    last = parts[-1]
    z, att = last[3], last[4]
    t_final = last[7][0] if status >= 0 else last[7][1]
    z0, att0 = run._initial()
    t_events = state_events = attitude_events = None
    if ev is not None:
        n, d = len(ev[0]), z0.shape[1]
        hits = [h for c in parts for h in (c[8] or ())]
        t_events = [np.array([h[1] for h in hits if h[0] == i], dtype=float) for i in range(n)]
        state_events = [np.array([h[2] for h in hits if h[0] == i], dtype=float).reshape(-1, d)
                        for i in range(n)]
        if att0 is not None:
            attitude_events = [np.array([h[3] for h in hits if h[0] == i], dtype=float)
                               .reshape((-1,) + att0.shape[-2:]) for i in range(n)]
    if not run.batched:
        states, z, z0 = states[0], z[0], z0[0]
        if att0 is not None:
            attitudes, att, att0 = attitudes[0], att[0], att0[0]
    save_every = None if times is not None else run.save_every
    return Trajectory(system, run.method, t, states, attitudes, z, att, run.dt, save_every,
                      t_final=t_final, status=status, t_events=t_events,
                      state_events=state_events, attitude_events=attitude_events, t0=run.t0,
                      initial_state=z0, initial_attitude=att0)


def _attach_partial(err, system, run, chunks, times, ev):
    """Attaches the trajectory computed before `err` as ``err.partial`` and a note naming it.

    A single native run whose native call failed (also by an exception of a Python callable it
    called, KeyboardInterrupt included) knows its last checked state exactly (the step before
    the one that failed) and the states that call saved (``_partial``); otherwise (Ctrl-C
    between calls, batches, plain runs) the trajectory ends after the last completed call."""
    try:
        p = run._partial() if hasattr(run, "_partial") else None
        parts = list(chunks) + ([p] if p is not None else [])
        if not parts:
            parts = [run._head()]
        traj = _trajectory(system, run, parts, times, -1, ev)
        err.partial = traj
        if hasattr(err, "add_note"):
            err.add_note(f"the trajectory computed before this (to step {parts[-1][5]}, "
                         f"t = {traj.t_final:g}) is err.partial")
    except Exception:        # never hide the original error behind one of the partial's
        pass


class _Plain:
    """A run that has only ``advance`` and ``state`` (see the module docs), with what
    ``integrate`` reads of a native run."""

    def __init__(self, run, system, state0, attitude, dt, t0, save_every):
        self.run, self.method, self.done, self.first = run, run.method, 0, True
        self.z0, self.batched = system._normalize_state(state0)
        self.members = self.z0.shape[0]
        self.att0 = (None if attitude is None else
                     np.array(np.broadcast_to(np.asarray(attitude, dtype=float),
                                              (self.members,) + np.shape(attitude)[-2:])))
        self.t0, self.dt, self.save_every = float(t0), float(dt), int(save_every)

    def _initial(self):
        return self.z0, self.att0

    def _chunk(self, steps, t=None):
        if t is not None:
            raise TypeError(f"invalid t_eval: the runs of this system do not support it (its "
                            f"_start returned a {type(self.run).__name__} without ._chunk)")
        s, a = self.run.advance(steps)
        k0 = self.done // self.save_every + 1
        self.done += steps
        z, za = self.run.state()
        if self.first:
            self.first, k0 = False, k0 - 1
            s = np.concatenate([self.z0[:, None], s], axis=1)
            a = None if a is None else np.concatenate([self.att0[:, None], a], axis=1)
        t = self.t0 + np.arange(k0, k0 + s.shape[1]) * (self.save_every * self.dt)
        t_final = self.t0 + self.done * self.dt
        if self.done % self.save_every == 0:
            t_final = float(t[-1])
        return (t, s, a, z, za, self.done, None, (t_final, t_final), None)

    def _head(self):
        t = np.array([self.t0])
        a = None if self.att0 is None else self.att0[:, None]
        return (t, self.z0[:, None], a, self.z0, self.att0, 0, None, (self.t0, self.t0), None)
