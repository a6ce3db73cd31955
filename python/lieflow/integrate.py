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
observables ``NAME(states)``.
"""

import numbers
import operator
import sys

import numpy as np

from ._lieflow import InvalidArgumentError, ShapeError

__all__ = ["integrate", "Trajectory", "CHUNK_WORK", "MIN_CHUNK_STEPS"]

#: Steps x bodies per native call. Between two calls Python checks for Ctrl-C and updates the
#: progress bar; at 30 ns - 1 us per body-step a chunk takes well under a second. The chunking
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
        if isinstance(value, bool):
            raise TypeError
        n = operator.index(value)
    except TypeError:
        raise TypeError(
            f"invalid {name}: expected an integer >= 1, got {type(value).__name__} {value!r}"
        ) from None
    if n < 1:
        raise InvalidArgumentError(f"invalid {name}: expected an integer >= 1, got {n}")
    if n > _MAX_COUNT:
        raise InvalidArgumentError(f"invalid {name}: expected an integer <= 2**63 - 1, got {n}")
    return n


def _step(dt):
    """The time step as a float: TypeError unless a real number (str, bool, complex and arrays
    of size > 1 refused), InvalidArgumentError unless finite and > 0."""
    ok = isinstance(dt, numbers.Real) and not isinstance(dt, bool)
    if not ok and isinstance(dt, np.ndarray) and dt.shape == () and dt.dtype.kind in "iuf":
        ok = True  # a 0-d numpy array of a real number
    if not ok:
        raise TypeError(f"invalid dt: expected a real number > 0, got {type(dt).__name__} {dt!r}")
    dt = float(dt)
    if not (np.isfinite(dt) and dt > 0):
        raise InvalidArgumentError(f"invalid dt: expected a finite number > 0, got {dt!r}")
    return dt


def _check_system(system):
    """TypeError unless ``system`` speaks the protocol (a ``lieflow.System`` instance or alike)."""
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
    if a.shape == (3, 3):
        return np.ascontiguousarray(np.broadcast_to(a, (b, 3, 3)))
    if batched and a.shape == (b, 3, 3):
        return np.ascontiguousarray(a)
    expected = f"(3, 3) or ({b}, 3, 3)" if batched else "(3, 3)"
    raise ShapeError(f"attitude has the wrong shape: expected {expected}, got {a.shape}")


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


def integrate(system, state0, dt, steps, method=None, save_every=1, attitude=None,
              progress=False, chunk_steps=None, threads=None):
    """Integrates ``system`` from ``state0`` by ``steps`` fixed steps of size ``dt``.

    Args:
        system: a system object, e.g. ``RigidBody([1, 2, 3])``.
        state0: an initial state in the system's layout (for ``RigidBody`` the momentum M (3,);
            a tuple with one array per field, e.g. ``(M, Gamma)`` or ``(X, P)``, also works), or
            a batch of them along a leading axis; a batch runs in parallel on all cores.
        dt: the time step (> 0).
        steps: the number of steps (>= 1).
        method: one of ``system.methods()`` (default: the first, the system's own default).
        save_every: keep every ``save_every``-th state (and the initial one): the trajectory has
            ``steps // save_every + 1`` samples at t = j * save_every * dt.
        attitude: for systems on SO(3): the initial attitude R (3, 3) (shared by a batch) or one
            per batch member (b, 3, 3); it is then integrated along.
        progress: show a progress bar (tqdm if installed, else a line on stderr).
        chunk_steps: steps per native call (default: ``CHUNK_WORK // batch size``, at least
            ``MIN_CHUNK_STEPS``). Ctrl-C is noticed between calls. Results do not depend on it.
        threads: threads for a batch (default: all cores).

    Returns:
        A ``Trajectory``.

    Raises:
        TypeError (``system`` not a system; ``dt`` not a real number; ``steps``, ``save_every``,
        ``chunk_steps``, ``threads`` not integers; ``method`` not a str),
        InvalidArgumentError (dt <= 0 or non-finite, steps < 1, save_every < 1, state
        constraints), UnsupportedMethodError (lists the system's methods), ShapeError,
        NonFiniteError, NotInGroupError (attitude), ConvergenceError, LeftDomainError (naming the
        time from the start of the run); KeyboardInterrupt on Ctrl-C.
    """
    # Every argument's type and range in one place, before any native call.
    _check_system(system)
    steps = _count("steps", steps)
    save_every = _count("save_every", save_every)
    dt = _step(dt)
    if method is not None and not isinstance(method, str):
        raise TypeError(f"invalid method: expected a name (str), got {type(method).__name__} "
                        f"{method!r}")
    z, batched = system._normalize_state(state0)
    b = z.shape[0]
    att = None if attitude is None else _attitude(attitude, b, batched)
    if chunk_steps is None:
        cap = max(MIN_CHUNK_STEPS, CHUNK_WORK // max(b, 1))
    else:
        cap = _count("chunk_steps", chunk_steps)
    if threads is not None:
        threads = _count("threads", threads)

    # `steps`: the native side refuses, before any step, a trajectory that cannot be kept.
    run = system._start(z, att, dt, method, save_every, threads=threads, steps=steps)
    method = run.method
    states, atts = [z[:, None, :]], [None if att is None else att[:, None]]
    bar = _Progress(steps, progress, f"{type(system).__name__} {method}")
    try:
        done = 0
        while done < steps:
            n = min(cap, steps - done)
            s, a = run.advance(n)
            states.append(s)
            atts.append(a)
            done += n
            bar.update(n)
    finally:
        bar.close()

    z, att = run.state()
    states = np.concatenate(states, axis=1)
    attitudes = None if att is None else np.concatenate(atts, axis=1)
    t = np.arange(states.shape[1]) * (save_every * dt)
    if not batched:
        states, z = states[0], z[0]
        if att is not None:
            attitudes, att = attitudes[0], att[0]
    return Trajectory(system, method, t, states, attitudes, z, att, dt, save_every)


class Trajectory:
    """A computed trajectory.

    Attributes:
        system, method, dt, save_every: as passed to ``integrate``.
        t: (k,) sample times.
        states: (k, d) samples, or (b, k, d) for a batch.
        attitude: (k, 3, 3) / (b, k, 3, 3) attitudes, or None.
        final_state, final_attitude: the state after all steps (also when ``steps`` is not a
            multiple of ``save_every``); pass them to ``integrate`` to continue.
        Named views from the system (e.g. ``M``, ``Gamma``, ``q``, ``L``) as attributes.

    Methods ``energy()`` and ``casimirs()``, and every observable of the system:
    ``traj.NAME(...)`` is ``system.NAME(traj.states, ...)`` (with the attitude passed as well for
    observables such as ``spatial_momentum`` that need it).
    """

    def __init__(self, system, method, t, states, attitude, final_state, final_attitude, dt,
                 save_every):
        self.system = system
        self.method = method
        self.t = t
        self.states = states
        self.attitude = attitude
        self.final_state = final_state
        self.final_attitude = final_attitude
        self.dt = dt
        self.save_every = save_every
        self._field_cache = None

    @property
    def batched(self):
        """Whether the states carry a leading batch axis."""
        return self.states.ndim == 3

    def __len__(self):
        """The number of samples k."""
        return len(self.t)

    def __repr__(self):
        return (f"<Trajectory {type(self.system).__name__} method={self.method!r} "
                f"states{self.states.shape} t=[{self.t[0]:g}, {self.t[-1]:g}]>")

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
