"""Periodic and relative periodic orbits by shooting on a method's own map (docs/periodic_orbits.md).

``periodic_orbit(system, state0, period)`` finds the orbit of the method's map through (near)
``state0`` that closes after ``period``: the run the method computes closes to round-off, its
monodromy matrix comes from the exact tangent maps of ``integrate(..., sensitivity=True)``, and
its Floquet multipliers are split into the trivial ones (the flow, the energy, the invariants)
and those of the motion across the orbit.
"""

from __future__ import annotations

import numpy as np

from ._lieflow import InvalidArgumentError, System, _periodic_orbit
from .integrate import _check_method, _check_system, _count, _real, _step, integrate

__all__ = ["PeriodicOrbit", "periodic_orbit"]

#: The method's steps per period when ``dt`` is not given.
DEFAULT_STEPS = 1000


class PeriodicOrbit:
    """A periodic orbit of a method's map (``lieflow.periodic_orbit``).

    Attributes:
        system: the system.
        method: the method whose map it is.
        state0: the orbit's point on the phase hyperplane through the guess, (d,).
        period: the period T.
        steps: the method's steps per period; ``dt`` = T / steps.
        energy: the energy of ``state0``.
        monodromy: M = ∂z(T)/∂z(0) of the method's map, (d, d).
        multipliers: the eigenvalues of M (complex, by descending modulus).
        trivial: which multipliers are trivial (bool, (d,)): the flow's, the energy's and the
            invariants' (``system.invariants``), equal to 1 up to the method's error.
        normal_multipliers: the multipliers of the motion across the orbit on the level set of
            the conserved quantities (complex, by descending modulus; empty for one degree of
            freedom).
        stable: every normal multiplier has modulus at most 1 + 1e-6 (spectral stability).
        residual: max abs(z(T) − z(0)) of the method's run, absolute.
        iterations: the Gauss–Newton iterations taken.
        attitude: the initial attitude R(0) of a relative orbit, else None.
        drift: for a relative orbit, the rotation vector ω of g = R(T) R(0)ᵀ (3,) (a rotation of
            space by abs(ω) ≤ π about ω; for the free rigid body about the spatial momentum,
            by Montgomery's angle modulo 2π), else None.
    """

    __slots__ = ("system", "method", "state0", "period", "steps", "energy", "monodromy",
                 "multipliers", "trivial", "normal_multipliers", "stable", "residual",
                 "iterations", "attitude", "drift")

    def __init__(self, system, method, attitude, fields):
        self.system = system
        self.method = method
        self.attitude = attitude
        self.state0 = fields["state0"]
        self.period = fields["period"]
        self.steps = fields["steps"]
        self.energy = fields["energy"]
        self.monodromy = fields["monodromy"]
        self.multipliers = fields["multipliers"]
        self.trivial = fields["trivial"]
        self.normal_multipliers = fields["normal"]
        self.stable = fields["stable"]
        self.residual = fields["residual"]
        self.iterations = fields["iterations"]
        self.drift = fields["drift"]
        for a in (self.state0, self.monodromy, self.multipliers, self.trivial,
                  self.normal_multipliers, self.drift, self.attitude):
            if a is not None:
                a.flags.writeable = False

    @property
    def dt(self) -> float:
        """The method's step on the orbit, ``period / steps``."""
        return self.period / self.steps

    @property
    def drift_angle(self):
        """abs(ω) of ``drift`` signed by its direction against the system's spatial momentum
        where the system has one (``RigidBody``, ``HeavyTop``, …), else abs(ω); None for an
        orbit that is not relative."""
        if self.drift is None:
            return None
        w = self.drift
        angle = float(np.linalg.norm(w))
        spatial = getattr(self.system, "spatial_momentum", None)
        if spatial is not None:
            pi = np.asarray(spatial(self.state0, self.attitude), dtype=float)
            if float(w @ pi) < 0:
                angle = -angle
        return angle

    def trajectory(self, steps=None, *, periods=1, save_every=1):
        """The orbit as a ``Trajectory`` over ``periods`` periods.

        Args:
            steps: steps per period (default: the orbit's own, so the run is the one shot and
                closes to ``residual``; another number gives the same orbit to the method's
                accuracy at that step).
            periods: how many periods (an integer >= 1).
            save_every: as in ``integrate``.
        """
        n = self.steps if steps is None else _count("steps", steps)
        k = _count("periods", periods)
        return integrate(self.system, self.state0, self.period / n, n * k, method=self.method,
                         save_every=save_every, attitude=self.attitude)

    def __repr__(self):
        normal = ", ".join(f"{m:.6g}" for m in self.normal_multipliers)
        drift = "" if self.drift is None else f", drift_angle={self.drift_angle:.10g}"
        return (f"PeriodicOrbit({type(self.system).__name__}, method={self.method!r}, "
                f"period={self.period:.15g}, energy={self.energy:.10g}, steps={self.steps}, "
                f"stable={self.stable}, normal_multipliers=[{normal}], "
                f"residual={self.residual:.2e}{drift})")


def periodic_orbit(system, state0, period, *, method=None, dt=None, fix="energy", relative=False,
                   attitude=None, tol=1e-10, max_iter=30):
    """Finds a periodic orbit of ``method``'s map near ``state0`` with period near ``period``.

    The orbit is a fixed point of the method's map over N = round(period / dt) steps of size
    T / N (the step follows the period): the run closes to round-off. A conservative system's
    periodic orbits come in families along the energy and the levels of its invariants; the
    shooting keeps the guess's invariants (``system.invariants``), fixes its energy (``fix=
    "energy"``, the period is found) or the period (``fix="period"``, the energy is found), and
    pins the phase on the hyperplane through ``state0`` across the flow. Gauss–Newton iteration
    with the monodromy matrix of the method's tangent map (exact to round-off; the period's
    column from two plain runs), quadratically convergent.

    Args:
        system: a system object whose method has tangent maps (``system.sensitivity_methods()``).
        state0: a guess of a point of the orbit (d,).
        period: a guess of the period (fix="energy") or the period (fix="period"), > 0.
        method: one of ``system.sensitivity_methods()`` (default: the system's default method
            if it is one, else the first of them). A method that keeps the invariants (the
            Lie–Poisson and symplectic ones) has periodic orbits in the same families as the
            flow; a method that does not (``rk4``) may have none through the guess's levels.
        dt: the step's size on the guess: N = max(1, round(period / dt)) steps per period
            (default: 1000 steps per period).
        fix: "energy" (keep the guess's energy) or "period".
        relative: also compute the drift of the attitude over the period (a relative periodic
            orbit: the state returns, the attitude R(T) = g R(0)); for systems that carry an
            attitude (``RigidBody``, ``HeavyTop``, ``LiePoisson`` on so(3) with an attitude).
            Implied by ``attitude``.
        attitude: R(0) (3, 3) of a relative orbit (default with ``relative=True``: the
            identity).
        tol: the iteration's tolerance on the update (relative to the state's size and the
            period); it goes on while the update decreases.
        max_iter: Gauss–Newton iterations allowed.

    Returns:
        A ``PeriodicOrbit``.

    Raises:
        TypeError (a wrong type), InvalidArgumentError (period <= 0, a method without tangent
        maps, a state with an attitude block, a guess at an equilibrium, relative for a system
        without an attitude, fix not "energy"/"period"), ShapeError, NotInGroupError
        (attitude), ConvergenceError (no orbit near the guess: the iteration failed or settled
        on a point that is not periodic), and the errors of the runs.
    """
    if not isinstance(system, System):
        _check_system(system)
        raise TypeError(f"expected a lieflow.System, got {type(system).__name__}")
    if not _real(period):
        raise TypeError(f"invalid period: expected a real number > 0, got "
                        f"{type(period).__name__} {period!r}")
    period = float(period)
    _check_method(method)
    if method is None:
        default = system.methods()[0]
        lifted = system.sensitivity_methods()
        method = default if default in lifted or not lifted else lifted[0]
    if not isinstance(fix, str):
        raise TypeError(f"invalid fix: expected \"energy\" or \"period\", got "
                        f"{type(fix).__name__} {fix!r}")
    if dt is None:
        steps = DEFAULT_STEPS
    else:
        dt = _step(dt)
        if not (0 < period < np.inf):
            raise InvalidArgumentError(f"invalid period: expected a finite time > 0, got {period}")
        steps = max(1, round(period / dt))
    if not isinstance(relative, (bool, np.bool_)):
        raise TypeError(f"invalid relative: expected True or False, got "
                        f"{type(relative).__name__} {relative!r}")
    if attitude is None and relative:
        attitude = np.eye(3)
    fields = _periodic_orbit(system, state0, period, method, steps, fix, tol, _count(
        "max_iter", max_iter), attitude)
    if attitude is not None:
        attitude = np.array(attitude, dtype=float)
    return PeriodicOrbit(system, method, attitude, fields)
