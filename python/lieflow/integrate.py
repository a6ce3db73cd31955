"""Integration driver: ``integrate(system, state0, dt=..., steps=..., method=...)`` -> ``Trajectory``.

Pure presentation and control around the native systems (subclasses of ``lieflow.System``, or
any object speaking the protocol below): argument checks, chunking of long runs so that Ctrl-C is
honoured promptly (Python handles signals between native calls; the native work runs with the GIL
released), an optional progress bar, and the assembly of the ``Trajectory``. The chunks resume
one native run (``Integration``): validation happens once, the clock and the steppers live for
the whole run, and the result does not depend on the chunking.

Protocol a system implements (``lieflow.System`` implements it once for every system):
``methods()`` (the first is the default), ``state_dim``, ``_normalize_state(state0) -> (z0 (b, d),
batched)``, ``_start(z0, attitude0, dt, method | None, save_every, *, t0, threads, steps) -> run``
(``steps``: the total, so that a trajectory that cannot be kept is refused first) with
``run.method`` (the name), ``run.advance(steps) -> (states (b, k, d), attitude (b, k, 3, 3) |
None)`` (the states saved in those steps) and ``run.state() -> (z (b, d), attitude (b, 3, 3) |
None)``, vectorised ``energy``
and ``invariants``/``casimirs``; optionally ``_fields(states) -> dict`` of named views and further
observables ``NAME(states)``. ``t_eval``, ``events`` and the exact ``err.partial`` of a failed run
use more of the run (``lieflow.Integration`` has it all): ``save_at``, ``set_events``,
``events_found``, ``ended``, ``stopped_by``, ``steps_done``, ``steps_to``, ``finish``,
``take_partial``, ``checked_state``.
"""

import numbers
import operator
import sys

import numpy as np

from ._lieflow import InvalidArgumentError, NonFiniteError, ShapeError, System

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


def _sample_times(t0, dt, save_every, k):
    """The times of the first k samples of a run saving every ``save_every``-th step."""
    return t0 + np.arange(k) * (save_every * dt)


def _check_system(system):
    """TypeError unless ``system`` speaks the protocol (a ``lieflow.System`` instance or alike)."""
    if isinstance(system, System):
        return
    if isinstance(system, type):
        raise TypeError(f"expected a lieflow system, got the class {system.__name__}; make one "
                        f"first, e.g. {system.__name__}(...)")
    if not all(callable(getattr(system, a, None)) for a in ("_normalize_state", "_start")):
        raise TypeError(f"expected a lieflow system (e.g. lf.RigidBody([1, 2, 3])), got "
                        f"{type(system).__name__} {system!r:.60}")


def _attitude(attitude, b, batched):
    """The initial attitude as a (b, 3, 3) float64 array (one (3, 3) is shared by a batch).

    The one array argument read here rather than natively: its type is checked by the rule of
    every native array argument (real numbers only, a TypeError otherwise)."""
    expected = "invalid attitude: expected an array-like of real numbers (bool, int or float)"
    try:
        a = np.asarray(attitude)
    except ValueError as e:                      # a ragged nested list
        raise TypeError(f"{expected}, got a {type(attitude).__name__} that numpy cannot read "
                        f"as an array: {e}") from None
    if isinstance(attitude, (str, bytes)) or a.dtype.kind not in "biuf":
        raise TypeError(f"{expected}, got a {type(attitude).__name__} (numpy dtype {a.dtype})")
    a = a.astype(np.float64, copy=False)
    if not (a.shape == (3, 3) or batched and a.shape == (b, 3, 3)):
        expected = f"(3, 3) or ({b}, 3, 3)" if batched else "(3, 3)"
        raise ShapeError(f"attitude has the wrong shape: expected {expected}, got {a.shape}")
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):     # named by its member and its entry (not by its place in the state)
        *k, i, j = bad[0]
        member = f"batch member {k[0]}: " if k else ""
        raise NonFiniteError(f"{member}attitude contains a non-finite value (NaN or inf) at "
                             f"({i}, {j})")
    if a.shape == (3, 3):
        out = np.empty((b, 3, 3))
        out[...] = a
        return out
    return np.ascontiguousarray(a)


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
                        f"{value!r:.60}")
    value = float(value)
    if not -np.inf < value < np.inf:
        raise InvalidArgumentError(f"invalid {name}: expected a finite number, got {value!r}")
    return value


def _times(t_eval):
    """t_eval as a 1-D float64 array of finite, strictly increasing times (TypeError for
    anything but real numbers, ShapeError unless 1-D and non-empty)."""
    expected = "invalid t_eval: expected a 1-D array-like of real numbers (bool, int or float)"
    if isinstance(t_eval, (str, bytes)):
        raise TypeError(f"{expected}, got a {type(t_eval).__name__}")
    try:
        a = np.asarray(t_eval)
    except (ValueError, TypeError) as e:
        raise TypeError(f"{expected}, got a {type(t_eval).__name__} that numpy cannot read as "
                        f"an array: {e}") from None
    if a.dtype.kind == "O":
        try:
            a = a.astype(np.float64)
        except (ValueError, TypeError):
            raise TypeError(f"{expected}, got an object array") from None
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{expected}, got a {type(t_eval).__name__} (numpy dtype {a.dtype})")
    if a.ndim != 1 or a.size == 0:
        raise ShapeError(f"t_eval has the wrong shape: expected (k,) with k >= 1, got {a.shape}")
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not np.all(np.isfinite(a)):
        raise NonFiniteError(f"t_eval contains a non-finite value (NaN or inf) at index "
                             f"{int(np.argmin(np.isfinite(a)))}")
    bad = np.flatnonzero(np.diff(a) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InvalidArgumentError(f"invalid t_eval: expected strictly increasing times, got "
                                   f"t_eval[{i}] = {a[i]!r} after {a[i - 1]!r}")
    return a


def _events(events):
    """(functions, directions, terminal counts) of ``events``: a callable or a list of them,
    each with optional attributes ``terminal`` (bool or int >= 0) and ``direction`` (a real
    number), as in scipy."""
    fns = [events] if callable(events) else events
    if not isinstance(fns, (list, tuple)) or not all(callable(f) for f in fns):
        raise TypeError(f"invalid events: expected a callable g(t, state) or a list of them, got "
                        f"{type(events).__name__} {events!r:.60}")
    directions, terminal = [], []
    for i, f in enumerate(fns):
        d = getattr(f, "direction", 0.0)
        if d is None:
            d = 0.0
        if isinstance(d, bool) or not isinstance(d, numbers.Real):
            raise TypeError(f"invalid events[{i}].direction: expected a real number, got "
                            f"{type(d).__name__} {d!r:.60}")
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
                                f"got {type(n).__name__} {n!r:.60}") from None
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


def _grid_tol(t, t0):
    """Round-off of grid times near t (the native driver's rule)."""
    return 8 * np.finfo(float).eps * max(abs(t), abs(t0))


def integrate(system, state0, dt, steps=None, method=None, save_every=1, attitude=None,
              progress=False, chunk_steps=None, threads=None, *, t0=0.0, t_eval=None,
              events=None, event_tol=0.0):
    """Integrates ``system`` from ``state0`` by ``steps`` fixed steps of size ``dt``.

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
        attitude: for systems on SO(3): the initial attitude R (3, 3) (shared by a batch) or one
            per batch member (b, 3, 3); it is then integrated along.
        progress: show a progress bar (tqdm if installed, else a line on stderr).
        chunk_steps: steps per native call (default: ``CHUNK_WORK // batch size``, at least
            ``MIN_CHUNK_STEPS``). Ctrl-C is noticed between calls. Results do not depend on it.
        threads: threads for a batch (default: all cores).
        t0: the time of ``state0`` (default 0); every time of the run is absolute.
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
    # Every argument's type and range in one place, before any native call.
    _check_system(system)
    if steps is None and t_eval is None:
        raise TypeError("invalid steps: expected an integer >= 1, got NoneType None (steps may be "
                        "None only with t_eval, whose last time is then the end of the run)")
    if steps is not None:
        steps = _count("steps", steps)
    save_every = _count("save_every", save_every)
    dt = _step(dt)
    t0 = _time("t0", t0)
    _check_method(method)
    times = None if t_eval is None else _times(t_eval)
    if times is not None and save_every != 1:
        raise InvalidArgumentError("invalid save_every: t_eval gives the output times; leave "
                                   "save_every at 1")
    ev = None if events is None else _events(events)
    event_tol = _time("event_tol", event_tol)
    if event_tol < 0:
        raise InvalidArgumentError(f"invalid event_tol: expected a time >= 0, got {event_tol!r}")
    z, batched = system._normalize_state(state0)
    b = z.shape[0]
    if ev is not None and batched:
        raise InvalidArgumentError(f"invalid events: events are located in a single run, got a "
                                   f"batch of {b} initial states; integrate the members one by one")
    att = None if attitude is None else _attitude(attitude, b, batched)
    if chunk_steps is None:
        cap = max(MIN_CHUNK_STEPS, CHUNK_WORK // max(b, 1))
    else:
        cap = _count("chunk_steps", chunk_steps)
    if threads is not None:
        threads = _count("threads", threads)
    if times is not None:
        if times[0] < t0 - _grid_tol(times[0], t0):
            raise InvalidArgumentError(f"invalid t_eval: the times must not precede t0 = {t0!r}, "
                                       f"got {times[0]!r}")
        if steps is not None:
            end = t0 + steps * dt
            if times[-1] > end + _grid_tol(end, t0):
                raise InvalidArgumentError(f"invalid t_eval: the times must not pass the end "
                                           f"t0 + steps * dt = {end!r}, got {times[-1]!r}")

    # `steps`: the native side refuses, before any step, a trajectory that cannot be kept (with
    # t_eval, `save_at` checks the states it keeps).
    run = system._start(z, att, dt, method, save_every, t0=t0, threads=threads,
                        steps=steps if times is None else None)
    method = run.method
    if times is not None:
        _native(run, "save_at", "t_eval")(times)
    if ev is not None:
        _native(run, "set_events", "events")(*ev, event_tol)
    total = steps if steps is not None else _native(run, "steps_to", "t_eval")(float(times[-1]))

    # One entry per native call, appended in one statement so that Ctrl-C between two leaves
    # the list consistent: (states, attitudes, events, state after, attitude after, steps done,
    # end time or None).
    chunks = []
    ctx = _Context(system, method, dt, save_every, t0, times, ev, z, att, batched)
    bar = _Progress(total, progress, f"{type(system).__name__} {method}")
    try:
        done, ended = 0, None
        while done < total and ended is None:
            n = min(cap, total - done)
            s, a = run.advance(n)
            hits = run.events_found() if ev is not None else ()
            ended = run.ended if ev is not None else None
            after = done + n if ended is None else run.steps_done
            chunks.append((s, a, hits) + run.state() + (after, ended))
            bar.update(after - done)
            done = after
        if steps is None and ended is None:
            s, a = run.finish(float(times[-1]))
            hits = run.events_found() if ev is not None else ()
            ended = run.ended
            chunks.append((s, a, hits) + run.state() + (done, ended))
    except BaseException as e:
        _attach_partial(e, ctx, run, chunks)
        raise
    finally:
        bar.close()
    stopped = getattr(run, "stopped_by", None) if ev is not None else None
    return ctx.trajectory(chunks, status=1 if stopped is not None else 0)


class _Context:
    """What a Trajectory is built from besides the native chunks."""

    def __init__(self, system, method, dt, save_every, t0, times, ev, z0, att0, batched):
        self.system, self.method, self.dt, self.save_every = system, method, dt, save_every
        self.t0, self.times, self.ev, self.batched = t0, times, ev, batched
        self.z0, self.att0 = z0, att0

    def trajectory(self, chunks, status, extra=None, final=None):
        """The Trajectory of `chunks` (plus `extra` (states, attitudes, events) saved by a failed
        call, and `final` (z, att, steps done, end time) instead of the last chunk's)."""
        times, every, dt, t0 = self.times, self.save_every, self.dt, self.t0
        parts = list(chunks) + ([] if extra is None else [extra + (None,) * 4])
        if final is None:
            final = chunks[-1][3:7] if chunks else (self.z0, self.att0, 0, None)
        z, att, done, ended = final
        states = [c[0] for c in parts]
        atts = [c[1] for c in parts]
        if times is None:
            states.insert(0, self.z0[:, None, :])
            atts.insert(0, None if self.att0 is None else self.att0[:, None])
        d = self.z0.shape[1]
        states = np.concatenate(states, axis=1) if states else np.zeros((self.z0.shape[0], 0, d))
        attitudes = None
        if self.att0 is not None:
            attitudes = (np.concatenate(atts, axis=1) if atts
                         else np.zeros((self.z0.shape[0], 0, 3, 3)))
        k = states.shape[1]
        if times is not None:
            if self.z0.shape[0] == 0:       # an empty batch saves nothing natively
                k = len(times) if status == 0 else 0
                states = np.zeros((0, k, d))
                attitudes = None if self.att0 is None else np.zeros((0, k, 3, 3))
            t = times[:k].copy()
        else:
            terminated = status == 1
            grid = k - 1 if terminated else k
            t = _sample_times(t0, dt, every, grid)
            if terminated:
                t = np.append(t, ended)
        # The time of the final state: the last sample's when it is the final state (so that a
        # run continued from it with t0=traj.t_final starts exactly at traj.t[-1]).
        if ended is not None:
            t_final = ended
        else:
            t_final = t0 + done * dt
            if times is not None and k and status == 0 and \
                    abs(times[k - 1] - t_final) <= _grid_tol(t_final, t0):
                t_final = float(times[k - 1])
            elif times is None and done % every == 0 and k:
                t_final = float(t[-1])
        t_events = state_events = attitude_events = None
        if self.ev is not None:
            n = len(self.ev[0])
            hits = [h for c in parts for h in c[2]]
            t_events = [np.array([h[1] for h in hits if h[0] == i], dtype=float)
                        for i in range(n)]
            state_events = [np.array([h[2] for h in hits if h[0] == i], dtype=float)
                            .reshape(-1, d) for i in range(n)]
            if self.att0 is not None:
                attitude_events = [np.array([h[3] for h in hits if h[0] == i], dtype=float)
                                   .reshape(-1, 3, 3) for i in range(n)]
        if not self.batched:
            states, z = states[0], z[0]
            if att is not None:
                attitudes, att = attitudes[0], att[0]
        return Trajectory(self.system, self.method, t, states, attitudes, z, att, dt,
                          every if times is None else None, t_final=t_final, status=status,
                          t_events=t_events, state_events=state_events,
                          attitude_events=attitude_events, t0=t0,
                          initial_state=self.z0 if self.batched else self.z0[0],
                          initial_attitude=(None if self.att0 is None else
                                            self.att0 if self.batched else self.att0[0]))


def _attach_partial(err, ctx, run, chunks):
    """Attaches the trajectory computed before `err` as ``err.partial`` and a note naming it.

    A single native run whose native call failed (also by an exception of a Python callable it
    called, KeyboardInterrupt included) knows its last checked state exactly (the step before
    the one that failed) and the states that call saved; otherwise (Ctrl-C between calls,
    batches, duck-typed runs) the trajectory ends after the last completed call, whose samples,
    final state and time the chunks hold together."""
    try:
        extra = final = None
        native = (not ctx.batched and hasattr(run, "take_partial")
                  and hasattr(run, "checked_state"))
        p = run.take_partial() if native else None
        if p is not None:
            hits = run.events_found() if ctx.ev is not None else ()
            extra = (p[0], p[1], hits)
            final = run.checked_state() + (run.steps_done, None)
        traj = ctx.trajectory(chunks, status=-1, extra=extra, final=final)
        err.partial = traj
        steps = final[2] if final is not None else (chunks[-1][5] if chunks else 0)
        if hasattr(err, "add_note"):
            err.add_note(f"the trajectory computed before this (to step {steps}, "
                         f"t = {traj.t_final:g}) is err.partial")
    except Exception:        # never hide the original error behind one of the partial's
        pass


class Trajectory:
    """A computed trajectory.

    Attributes:
        system, method, dt: as passed to ``integrate``.
        save_every: as passed to ``integrate`` (None when ``t_eval`` gave the times).
        t: (k,) sample times (absolute: from ``t0``; ``t_eval`` when given).
        states: (k, d) samples, or (b, k, d) for a batch.
        attitude: (k, 3, 3) / (b, k, 3, 3) attitudes, or None.
        final_state, final_attitude: the state after all steps (also when ``steps`` is not a
            multiple of ``save_every``; a terminal event's state); pass them to ``integrate``
            with ``t0=traj.t_final`` to continue.
        t0, t_final: the times of the initial and the final state.
        initial_state, initial_attitude: the state the run started from.
        status: 0 the run reached its end, 1 a terminal event ended it, -1 it failed (the
            ``partial`` trajectory of an exception), as scipy's.
        t_events, state_events: with ``events``, one array per event function of the times
            (n_i,) and the states (n_i, d) of its zeros (``attitude_events`` (n_i, 3, 3) with an
            attitude); None without events.
        Named views from the system (e.g. ``M``, ``Gamma``, ``q``, ``L``) as attributes.

    Methods ``energy()`` and ``casimirs()``, ``to_xarray()`` and ``save(path)`` (read back with
    ``lf.load(path)``), and every observable of the system:
    ``traj.NAME(...)`` is ``system.NAME(traj.states, ...)`` (with the attitude passed as well for
    observables such as ``spatial_momentum`` that need it). ``Trajectory.concatenate([a, b])``
    joins a run and its continuation.
    """

    def __init__(self, system, method, t, states, attitude, final_state, final_attitude, dt,
                 save_every, *, t_final=None, status=0, t_events=None, state_events=None,
                 attitude_events=None, t0=None, initial_state=None, initial_attitude=None):
        self.system = system
        self.method = method
        self.t = t
        self.states = states
        self.attitude = attitude
        self.final_state = final_state
        self.final_attitude = final_attitude
        self.dt = dt
        self.save_every = save_every
        self.t_final = t_final if t_final is not None else (float(t[-1]) if len(t) else None)
        self.status = status
        self.t_events = t_events
        self.state_events = state_events
        self.attitude_events = attitude_events
        self.t0 = t0 if t0 is not None else (float(t[0]) if len(t) else None)
        self.initial_state = initial_state
        self.initial_attitude = initial_attitude
        self._field_cache = None

    @classmethod
    def concatenate(cls, trajectories):
        """One trajectory from a run and its continuations: each must start where the one
        before ended (its ``t0`` equal to the previous ``t_final`` and its initial state equal
        to the previous ``final_state``, as ``integrate(system, traj.final_state, ...,
        t0=traj.t_final)`` gives) on the same system. A sample repeated at the seam (the first
        of a continuation is the last of the one before when that was its final state) is kept
        once; events are joined per event function (None unless every part has the same number
        of event functions). ``method``, ``dt`` and ``save_every`` are the parts' common values
        (a tuple of the methods, None for dt and save_every, where they differ).

        Raises:
            TypeError (not Trajectories), InvalidArgumentError (nothing to join, other systems,
            batch or state shapes, attitudes that come and go, a part that does not start where
            the one before ended).
        """
        expected = "invalid trajectories: expected a list of Trajectory objects"
        if isinstance(trajectories, (str, bytes, dict)):
            raise TypeError(f"{expected}, got a {type(trajectories).__name__}")
        try:
            parts = list(trajectories)
        except TypeError:
            raise TypeError(f"{expected}, got a {type(trajectories).__name__}") from None
        bad = [type(p).__name__ for p in parts if not isinstance(p, Trajectory)]
        if bad:
            raise TypeError(f"{expected}, got one of type {bad[0]}")
        if not parts:
            raise InvalidArgumentError("invalid trajectories: nothing to concatenate")
        first = parts[0]
        for i, (a, b) in enumerate(zip(parts, parts[1:]), start=1):
            where = f"invalid trajectories: part {i}"
            same = a.system is b.system or (type(a.system) is type(b.system)
                                            and repr(a.system) == repr(b.system))
            if not same:
                raise InvalidArgumentError(f"{where} integrates another system ({b.system!r:.60} "
                                           f"after {a.system!r:.60})")
            if a.states.shape[:-2] != b.states.shape[:-2] or a.states.shape[-1] != b.states.shape[-1]:
                raise InvalidArgumentError(f"{where} has states of shape {b.states.shape} after "
                                           f"{a.states.shape}")
            if (a.attitude is None) != (b.attitude is None):
                raise InvalidArgumentError(f"{where}: an attitude in one part only")
            t_a, t_b = a.t_final, b.t0
            tol = 16 * np.finfo(float).eps * max(abs(t_a), abs(t_b)) + 1e-9 * min(a.dt, b.dt)
            if t_a is None or t_b is None or not abs(t_b - t_a) <= tol:
                raise InvalidArgumentError(f"{where} starts at t = {t_b!r}, not where the one "
                                           f"before ended (t = {t_a!r}); continue a run with "
                                           f"integrate(system, traj.final_state, ..., "
                                           f"t0=traj.t_final)")
            if b.initial_state is not None and not np.array_equal(b.initial_state, a.final_state):
                raise InvalidArgumentError(f"{where} does not start from the final state of the "
                                           f"one before")
            if (b.initial_attitude is not None and a.final_attitude is not None
                    and not np.array_equal(b.initial_attitude, a.final_attitude)):
                raise InvalidArgumentError(f"{where} does not start from the final attitude of "
                                           f"the one before")
        t, states, atts = [first.t], [first.states], [first.attitude]
        for a, b in zip(parts, parts[1:]):
            drop = (len(a.t) and len(b.t) and b.t[0] <= a.t[-1]
                    + 16 * np.finfo(float).eps * max(abs(a.t[-1]), 1.0) + 1e-9 * b.dt)
            s = 1 if drop else 0
            t.append(b.t[s:])
            states.append(b.states[..., s:, :])
            if b.attitude is not None:
                atts.append(b.attitude[..., s:, :, :])
        axis = states[0].ndim - 2
        last = parts[-1]

        def common(name):
            values = [getattr(p, name) for p in parts]
            return values[0] if all(v == values[0] for v in values) else None

        methods = [p.method for p in parts]
        method = methods[0] if all(m == methods[0] for m in methods) else tuple(methods)
        events = {}
        counts = {None if p.t_events is None else len(p.t_events) for p in parts}
        if len(counts) == 1 and None not in counts:
            n = counts.pop()
            events["t_events"] = [np.concatenate([p.t_events[i] for p in parts]) for i in range(n)]
            events["state_events"] = [np.concatenate([p.state_events[i] for p in parts])
                                      for i in range(n)]
            if all(p.attitude_events is not None for p in parts):
                events["attitude_events"] = [np.concatenate([p.attitude_events[i] for p in parts])
                                             for i in range(n)]
        return cls(first.system, method, np.concatenate(t), np.concatenate(states, axis=axis),
                   None if first.attitude is None else np.concatenate(atts, axis=axis),
                   last.final_state, last.final_attitude, common("dt"), common("save_every"),
                   t_final=last.t_final, status=last.status, t0=first.t0,
                   initial_state=first.initial_state, initial_attitude=first.initial_attitude,
                   **events)

    @property
    def batched(self):
        """Whether the states carry a leading batch axis."""
        return self.states.ndim == 3

    def __len__(self):
        """The number of samples k."""
        return len(self.t)

    def __repr__(self):
        span = f"t=[{self.t[0]:g}, {self.t[-1]:g}]" if len(self.t) else "t=[]"
        return (f"<Trajectory {type(self.system).__name__} method={self.method!r} "
                f"states{self.states.shape} {span}>")

    def energy(self):
        """The energy at every sample: (k,) or (b, k)."""
        return np.asarray(self.system.energy(self.states))

    def invariants(self):
        """The invariants the system's geometric methods keep, at every sample: (k, c) or
        (b, k, c)."""
        return np.asarray(self.system.invariants(self.states))

    def casimirs(self):
        """The same as ``invariants()`` (the Casimirs of the Lie–Poisson systems)."""
        return self.invariants()

    def to_xarray(self, *, observables=True):
        """The trajectory as an ``xarray.Dataset``: coordinates ``time`` (and ``member`` for a
        batch), ``states``, the named fields (``M``, ``Gamma``, ``X``, ...), ``energy`` and
        ``invariants`` (unless ``observables=False``), the attitude, the initial and final
        states, events; attributes the system and its parameters, the method, dt, save_every,
        times and the lieflow version (layout: :mod:`lieflow.io`). Needs xarray."""
        from .io import to_xarray

        return to_xarray(self, observables=observables)

    def save(self, path, *, allow_pickle=False):
        """Writes the trajectory to the NetCDF file `path` (read it with ``lf.load(path)``;
        the round trip is exact). A system built from Python callables is stored only with
        ``allow_pickle=True`` (see :func:`lieflow.io.save`). Needs xarray and a NetCDF backend
        (``pip install lieflow[io]``)."""
        from .io import save

        save(self, path, allow_pickle=allow_pickle)

    def _fields(self):
        if self._field_cache is None:
            fields = getattr(self.system, "_fields", None)
            self._field_cache = dict(fields(self.states)) if fields is not None else {}
        return self._field_cache

    def __getattr__(self, name):
        # Only called for names that are not regular attributes.
        if name.startswith("_") or "system" not in self.__dict__:
            raise AttributeError(name)
        fields = self._fields()
        if name in fields:
            return fields[name]
        fn = getattr(self.system, name, None)
        if not callable(fn):
            raise AttributeError(
                f"'Trajectory' has no attribute {name!r} (nor has {type(self.system).__name__})")
        if name in getattr(self.system, "_attitude_observables", ()):
            if self.attitude is None:
                def needs_attitude(*args, **kwargs):
                    raise InvalidArgumentError(
                        f"invalid state: {name} needs the attitude; integrate with attitude=R0")
                return needs_attitude
            return lambda *args, **kwargs: fn(self.states, self.attitude, *args, **kwargs)
        return lambda *args, **kwargs: fn(self.states, *args, **kwargs)

    def __dir__(self):
        names = set(super().__dir__()) | set(self._fields())
        names |= {n for n in dir(self.system) if not n.startswith("_")}
        return sorted(names)


def load(path, *, allow_pickle=False):
    """Reads a trajectory written by ``Trajectory.save`` (or a Dataset of
    ``Trajectory.to_xarray()``), its system rebuilt from the file, so that
    ``lf.integrate(traj.system, traj.final_state, ..., t0=traj.t_final)`` continues the run.
    The round trip is exact. ``allow_pickle=True`` allows a system stored pickled (a system
    built from Python callables; loading runs code from the file, so only for files you
    trust). Needs xarray and a NetCDF-4 backend (``pip install lieflow[io]``).

    Raises:
        ImportError (no xarray or NetCDF-4 backend), FileNotFoundError, FileFormatError (not a
        lieflow trajectory file, damaged, a newer format, a pickled system without
        ``allow_pickle``).
    """
    from .io import read

    return Trajectory(**read(path, allow_pickle=allow_pickle))
