"""Chaos indicators: Lyapunov exponents (``lyapunov``) and Poincaré sections
(``poincare_section``); see docs/chaos.md.

``lyapunov`` is the loop around one native computation (``lieflow._Lyapunov``, the binding of
``lieflow::analysis::lyapunov``): chunks of segments, so that Ctrl-C is noticed between native
calls (the native work runs with the GIL released, unless the system calls Python);
``err.partial`` carries the spectrum of the segments done before an exception.
``poincare_section`` is one ``lieflow.integrate`` run with a terminal event.
"""

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ._lieflow import InvalidArgumentError, NonFiniteError, UnsupportedMethodError, _Lyapunov
from .integrate import CHUNK_WORK, _check_method, _check_system, _count, _real, integrate
from ._text import brief

__all__ = ["lyapunov", "LyapunovSpectrum", "poincare_section"]


@dataclass(frozen=True, eq=False)
class LyapunovSpectrum:
    """The Lyapunov spectrum of a run (``lieflow.lyapunov``).

    Attributes:
        exponents: the e exponents at the end of the run, sorted descending (e the number of
            directions of the system's tangent lift: the state's length, less 6 per SO(3)
            block).
        times: the end time of every segment (segments,), increasing; the run starts at t = 0.
        running: the estimate after every segment (segments, e): column i is the i-th column of
            the QR (the i-th fastest growth, a continuous curve in time); its last row, sorted,
            is ``exponents`` (estimates of exponents equal in the limit, such as the zeros of a
            Hamiltonian system, may cross at finite times).
        state: the state at the end of the run (d,), the same as ``lieflow.integrate``'s with
            the same method and step, bit for bit.
    """

    exponents: np.ndarray
    times: np.ndarray
    running: np.ndarray
    state: np.ndarray

    def __repr__(self):
        t = float(self.times[-1]) if len(self.times) else 0.0
        ex = np.array2string(self.exponents, precision=4, separator=", ")
        return f"LyapunovSpectrum(exponents={ex}, t={t:g}, segments={len(self.times)})"


def _spectrum(run):
    exponents, times, running, state = run.result()
    for a in (exponents, times, running, state):
        a.setflags(write=False)
    return LyapunovSpectrum(exponents, times, running, state)


def lyapunov(system, state0, *, dt, steps, method=None, renormalise_every=10):
    """The Lyapunov spectrum of ``system`` from ``state0``: all e exponents, by repeated QR
    (Benettin et al. 1980) of the Jacobians of the method's own discrete map.

    The run (``steps`` steps of size ``dt``) is cut into segments of ``renormalise_every``
    steps; over each, the system's tangent lift (the same lift as
    ``integrate(..., sensitivity=True)``, exact to round-off) gives the segment's Jacobian J;
    Q, R = qr(J Q) renormalises the directions, and the logarithms of abs(R_ii) add up to the
    exponents (their sums divided by the elapsed time). The base states are those of the plain
    run. Costs about 2 + e + p plain runs (e directions and the p parameter directions the lift
    carries: a heavy top 15).

    Args:
        system: a system object with tangent maps for ``method``
            (``system.sensitivity_methods()``); without an attitude (the exponents of the
            state's own dynamics).
        state0: one initial state (d,), or one array per field (e.g. ``(M, Gamma)``); no batch.
        dt: the time step (> 0).
        steps: the number of steps (>= 1).
        method: one of ``system.sensitivity_methods()`` (default: the system's default method).
        renormalise_every: steps per segment (>= 1); the last segment is shorter when
            ``steps`` is not a multiple of it. Smaller is safer (J stays far from overflow and
            from losing its small directions), larger costs fewer QRs (negligible next to the
            steps for small e): a segment should grow the directions by much less than 1e150.

    Returns:
        A ``LyapunovSpectrum`` (``exponents``, ``times``, ``running``, ``state``).

    Raises:
        TypeError (``dt`` not a real number, ``steps``/``renormalise_every`` not integers,
        ``method`` not a str), InvalidArgumentError (dt <= 0, steps < 1, renormalise_every < 1,
        a system without tangent maps, state constraints), UnsupportedMethodError (a method
        without tangent maps), ShapeError (a batch, a wrong length), NonFiniteError (NaN or inf
        in ``state0``, or in a segment's Jacobian), the run's errors (LeftDomainError,
        ConvergenceError, an exception raised by a system's callable); KeyboardInterrupt on
        Ctrl-C (noticed between chunks of segments). An exception raised after some segments
        carries their spectrum as ``err.partial``.
    """
    _check_system(system)
    _check_method(method)
    name = type(system).__name__
    methods = system.sensitivity_methods()
    if not methods:
        raise InvalidArgumentError(f"invalid system: {name} has no tangent maps yet "
                                   f"({name}.sensitivity_methods() is empty)")
    if method is not None and method not in methods and method in system.methods():
        raise UnsupportedMethodError(
            f"unsupported method {method!r} for lyapunov: the tangent maps of {name} are "
            f"available for {methods} (method=...)")
    run = _Lyapunov(system, state0, dt, steps, method, renormalise_every)
    every = _count("renormalise_every", renormalise_every)
    # A lifted step does the work of about 2 + e + p plain steps: chunks of about CHUNK_WORK
    # plain steps keep Ctrl-C as prompt as in lf.integrate.
    per_step = 2 + system.state_dim + len(system.parameters)
    chunk = max(1, CHUNK_WORK // (per_step * every))
    try:
        while run.segments_done < run.segments:
            run.advance(chunk)
    except BaseException as e:
        try:
            if run.segments_done > 0 and getattr(e, "partial", None) is None:
                e.partial = _spectrum(run)
                if hasattr(e, "add_note"):
                    e.add_note(f"the spectrum of the segments done before this (to "
                               f"t = {e.partial.times[-1]:g}) is err.partial")
        except Exception:
            pass
        raise
    return _spectrum(run)


def poincare_section(system, state0, section, *, direction=1, crossings=100, method=None,
                     dt=None, max_steps=1_000_000):
    """The crossings of a run with the section g(state) = 0: ``(times, states)``.

    One ``lieflow.integrate`` run with ``section`` as its event (a terminal one after
    ``crossings`` crossings): every crossing is located by taking its step again with shortened
    step sizes (Brent's method on the step size, to round-off in time), never by interpolation,
    so each state is a state of the method, on g = 0 to round-off, and keeps what the method
    keeps (Casimirs, constraints); the run is chunked as ``lieflow.integrate``'s (Ctrl-C
    between chunks).

    Args:
        system: a system object.
        state0: one initial state (d,), or one array per field.
        section: ``g(state) -> float``; the section is g = 0 (``state`` as in
            ``traj.states``).
        direction: > 0 only crossings where g rises (default), < 0 where it falls, 0 both.
        crossings: the number of crossings wanted (>= 1); the run stops at the last.
        method: one of ``system.methods()`` (default: the system's default).
        dt: the time step (> 0): required (None is a TypeError; there is no automatic step).
        max_steps: the most steps taken (>= 1); with fewer crossings by then a
            ``RuntimeWarning`` says so and the crossings found are returned.

    Returns:
        ``(times, states)``: (k,) increasing and (k, d), k = ``crossings`` (fewer at
        ``max_steps``).

    Raises:
        TypeError (``section`` not callable, ``dt`` None or not a real number, ``crossings``,
        ``max_steps`` not integers), the errors of ``lieflow.integrate`` (with ``err.partial``),
        NonFiniteError (a non-finite value of ``section``), an exception raised by
        ``section``.
    """
    _check_system(system)
    if not callable(section):
        raise TypeError(f"invalid section: expected a callable g(state) -> float, got "
                        f"{type(section).__name__} {brief(section, 60)}")
    if dt is None:
        raise TypeError("invalid dt: poincare_section needs a time step dt > 0 (a real number), "
                        "got None")
    crossings = _count("crossings", crossings)
    max_steps = _count("max_steps", max_steps)
    if not _real(direction):
        raise TypeError(f"invalid direction: expected a real number, got "
                        f"{type(direction).__name__} {brief(direction, 60)}")

    def g(t, state):
        v = section(state)
        if type(v) is not float:
            if not _real(v):
                raise TypeError(f"invalid section: section(state) must return a real number, "
                                f"got {type(v).__name__} {brief(v, 60)}")
            v = float(v)
        if not math.isfinite(v):
            raise NonFiniteError(f"the value returned by section contains a non-finite value "
                                 f"(NaN or inf) at t = {t:g}: {v}")
        return v

    g.direction = direction
    g.terminal = crossings
    traj = integrate(system, state0, dt, steps=max_steps, method=method, save_every=max_steps,
                     events=g)
    times = np.asarray(traj.t_events[0], dtype=np.float64)
    d = np.shape(traj.final_state)[-1]
    states = np.asarray(traj.state_events[0], dtype=np.float64).reshape(len(times), d)
    if len(times) < crossings:
        warnings.warn(f"poincare_section found {len(times)} of {crossings} crossings in "
                      f"max_steps = {max_steps} steps (t = {traj.t_final:g}); raise max_steps or "
                      f"check the section", RuntimeWarning, stacklevel=2)
    return times, states
