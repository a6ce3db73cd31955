"""Periodic and relative periodic orbits by shooting on a method's own map (docs/periodic_orbits.md).

``periodic_orbit(system, state0, period)`` finds the orbit of the method's map through (near)
``state0`` that closes after ``period``: the run the method computes closes to round-off, its
monodromy matrix comes from the exact tangent maps of ``integrate(..., sensitivity=True)``, and
its Floquet multipliers are split into the trivial ones (the flow, the energy, the invariants)
and those of the motion across the orbit.
"""

from __future__ import annotations

import numpy as np

from ._lieflow import InvalidArgumentError, System, _periodic_family, _periodic_orbit
from .integrate import _check_method, _check_system, _count, _real, _step, integrate

__all__ = ["PeriodicBranch", "PeriodicOrbit", "PeriodicSpecialPoint", "periodic_family",
           "periodic_orbit"]

#: The method's steps per period when ``dt`` is not given.
DEFAULT_STEPS = 1000


class PeriodicOrbit:
    r"""A periodic orbit of a method's map (``lieflow.periodic_orbit``).

    Attributes:
        system: the system.
        method: the method whose map it is.
        state0: the orbit's point on the phase hyperplane through the guess, (d,).
        period: the period T.
        steps: the method's steps per period; ``dt`` = T / steps.
        energy: the energy of ``state0``.
        monodromy: :math:`M = \partial z(T)/\partial z(0)` of the method's map, (d, d).
        multipliers: the eigenvalues of M (complex, by descending modulus).
        trivial: which multipliers are trivial (bool, (d,)): the flow's, the energy's, the
            invariants' (``system.invariants``) and a relative orbit's symmetry directions
            (equal to 1 for a periodic orbit, up to the method's error); the others are the
            normal multipliers.
        normal_multipliers: the multipliers of the motion across the orbit on the level set of
            the conserved quantities (complex, by descending modulus; empty for one degree of
            freedom).
        stable: every normal multiplier has modulus at most 1 + 1e-6 (spectral stability).
        residual: max abs(z(T) − z(0)) of the method's run, absolute.
        iterations: the Gauss–Newton iterations taken.
        levels: the levels the orbit keeps: the invariants (``system.invariants``), then for a
            relative orbit of the system's symmetry its momentum map.
        tangent: the tangent of the orbit's family at these levels,
            :math:`(\delta z, \delta T, \delta\zeta)` of unit length ((d + 1 + dim g,),
            :math:`\zeta` only for a relative orbit of the system's symmetry),
            the direction in which the energy grows.
        attitude: the initial attitude R(0) of a relative orbit, else None.
        drift: for a relative orbit of a body with an attitude, the rotation vector
            :math:`\omega` of :math:`g = R(T) R(0)^\top` (3,) (a rotation of space by
            :math:`|\omega| \le \pi` about :math:`\omega`; for the free rigid body about the
            spatial momentum, by Montgomery's angle modulo :math:`2\pi`); for a relative orbit
            of the system's symmetry, :math:`\zeta` with :math:`z(T) = \exp(\zeta) \cdot z(0)`
            (for ``PseudoRigidBody`` :math:`\xi \oplus \eta` in the :math:`e_{ij}` coordinates
            of ``lie.vee_n``); else None.
    """

    __slots__ = ("system", "method", "state0", "period", "steps", "energy", "monodromy",
                 "multipliers", "trivial", "normal_multipliers", "stable", "residual",
                 "iterations", "attitude", "drift", "levels", "tangent")

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
        self.levels = fields["levels"]
        self.tangent = fields["tangent"]
        for a in (self.state0, self.monodromy, self.multipliers, self.trivial,
                  self.normal_multipliers, self.drift, self.attitude, self.levels, self.tangent):
            if a is not None:
                a.flags.writeable = False

    @property
    def dt(self) -> float:
        """The method's step on the orbit, ``period / steps``."""
        return self.period / self.steps

    @property
    def drift_angle(self):
        r""":math:`|\omega|` of ``drift`` signed by its direction against the system's spatial
        momentum where the system has one (``RigidBody``, ``HeavyTop``, …), else
        :math:`|\omega|`; None for an orbit that is not relative."""
        if self.drift is None:
            return None
        w = self.drift
        angle = float(np.linalg.norm(w))
        spatial = getattr(self.system, "spatial_momentum", None)
        if self.attitude is None:
            return None
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
        angle = self.drift_angle
        drift = "" if self.drift is None else (
            f", drift={np.array2string(self.drift, precision=6)}" if angle is None
            else f", drift_angle={angle:.10g}")
        return (f"PeriodicOrbit({type(self.system).__name__}, method={self.method!r}, "
                f"period={self.period:.15g}, energy={self.energy:.10g}, steps={self.steps}, "
                f"stable={self.stable}, normal_multipliers=[{normal}], "
                f"residual={self.residual:.2e}{drift})")


def periodic_orbit(system, state0, period, *, method=None, dt=None, fix="energy", relative=False,
                   attitude=None, drift=None, levels=None, tol=1e-10, max_iter=30):
    r"""Finds a periodic orbit of ``method``'s map near ``state0`` with period near ``period``.

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
        relative: a relative periodic orbit, periodic up to a symmetry. For a system with a
            symmetry lieflow can act with (``PseudoRigidBody`` and its ``RelativeEquilibrium.
            body``: :math:`(X, P) \mapsto (g X h^\top, g P h^\top)`) the shooting solves
            :math:`z(T) = \exp(\zeta) \cdot z(0)` for T and :math:`\zeta` together (momentum map
            fixed, the slice across the orbit of its isotropy group); ``drift`` is
            :math:`\zeta`, and the monodromy and multipliers are those of
            :math:`\exp(-\zeta) \cdot z(T)`. For a body that carries an attitude
            (``RigidBody``, ``HeavyTop``, …) the state returns and the attitude does not:
            :math:`R(T) = g R(0)`, and ``drift`` is g's rotation vector.
            Implied by ``attitude``.
        attitude: R(0) (3, 3) of a relative orbit of a body with an attitude (default with
            ``relative=True``: the identity).
        drift: a guess of :math:`\zeta` for a relative orbit of the system's symmetry
            (default 0; for an orbit about a relative equilibrium with velocity :math:`\xi`,
            about :math:`T\xi`).
        levels: the levels to keep instead of the guess's (as ``PeriodicOrbit.levels``: the
            invariants, then the momentum map of a relative orbit).
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
    fields = _periodic_orbit(system, state0, period, method, steps, fix, tol, _count(
        "max_iter", max_iter), attitude, bool(relative), drift, levels)
    return PeriodicOrbit(system, method, fields["attitude"], fields)


def from_mode(equilibrium, mode, amplitude, *, method=None, dt=None, fix="energy", tol=1e-10,
              max_iter=30):
    r"""The Lyapunov orbit of a normal mode of a relative equilibrium at a small amplitude: the
    start of its Lyapunov family (``lieflow.continuation.periodic_family``).

    The linear motion about the equilibrium in the co-moving frame is
    :math:`\operatorname{Re}(v e^{i\omega t})`; the orbit is shot as a relative periodic orbit
    of ``equilibrium.body`` from
    :math:`z(0) = z_\mathrm{eq} + \mathrm{amplitude} \cdot \operatorname{Re}(v)`,
    :math:`T = 2\pi/\omega` and the drift :math:`T (\xi \oplus \eta)` of the equilibrium's
    velocities, at the energy of z(0) (``fix="energy"``): its period tends to
    :math:`2\pi/\omega` as the
    amplitude shrinks (Lyapunov's centre theorem, for a mode not resonant with the others).

    Args:
        equilibrium: a ``RelativeEquilibrium`` (of ``lieflow.ellipsoids`` or a pseudo-rigid
            body).
        mode: a ``NormalMode`` of ``equilibrium.normal_modes()`` or its index.
        amplitude: the displacement's size relative to the state's (v is unit length in the
            state scaled by its positions' and momenta's sizes), e.g. 1e-3.
        method, dt, fix, tol, max_iter: as in ``periodic_orbit`` (default method: the body's).

    Returns:
        A ``PeriodicOrbit`` (relative: ``drift`` is :math:`\zeta`).
    """
    modes = equilibrium.normal_modes()
    if isinstance(mode, (int, np.integer)) and not isinstance(mode, bool):
        if not 0 <= mode < len(modes):
            raise InvalidArgumentError(f"invalid mode: expected an index in [0, {len(modes)}), "
                                       f"got {mode} (the equilibrium has {len(modes)} "
                                       f"oscillatory normal modes)")
        mode = modes[int(mode)]
    elif not hasattr(mode, "vector"):
        raise TypeError(f"invalid mode: expected a NormalMode or an index, got "
                        f"{type(mode).__name__} {mode!r}")
    if not _real(amplitude):
        raise TypeError(f"invalid amplitude: expected a real number, got "
                        f"{type(amplitude).__name__} {amplitude!r}")
    system = equilibrium.body
    state0 = equilibrium.state + float(amplitude) * mode.vector.real
    period = mode.period
    from .lie import vee_n
    velocity = np.concatenate([vee_n(equilibrium.xi), vee_n(equilibrium.eta)])
    return periodic_orbit(system, state0, period, method=method, dt=dt, fix=fix, relative=True,
                          drift=period * velocity, tol=tol, max_iter=max_iter)


periodic_orbit.from_mode = from_mode  # type: ignore[attr-defined]


class PeriodicSpecialPoint:
    """A special point of a ``PeriodicBranch``.

    Attributes:
        kind: "period_doubling" (a normal multiplier through −1), "tangent" (through +1: a
            fold or branch point of orbits of the same period), "krein" (two pairs of
            multipliers collide on the unit circle and leave it), "fold" (the parameter turns
            back along the branch; not located beyond the points).
        index: the branch point after which it lies.
        value: the parameter's value there (located by bisection for a change of stability).
        orbit: the orbit at the located point (on the unstable side, to 2**-12 of the step).
    """

    __slots__ = ("kind", "index", "value", "orbit")

    def __init__(self, kind, index, value, orbit):
        self.kind, self.index, self.value, self.orbit = kind, index, value, orbit

    def __repr__(self):
        return (f"PeriodicSpecialPoint(kind={self.kind!r}, index={self.index}, "
                f"value={self.value:.10g})")


class PeriodicBranch:
    """A family of periodic orbits (``lieflow.continuation.periodic_family``).

    Attributes:
        points: the orbits (``PeriodicOrbit``) in the order of continuation.
        parameter: "energy" or "period".
        values: the parameter along the branch.
        energies, periods: (k,) arrays.
        stable: (k,) bool: every normal multiplier on or inside the unit circle.
        special_points: the special points (``PeriodicSpecialPoint``) in the order met.
        end: why the continuation stopped.
    """

    __slots__ = ("points", "parameter", "special_points", "end")

    def __init__(self, points, parameter, special_points, end):
        self.points, self.parameter = points, parameter
        self.special_points, self.end = special_points, end

    @property
    def energies(self):
        return np.array([p.energy for p in self.points])

    @property
    def periods(self):
        return np.array([p.period for p in self.points])

    @property
    def values(self):
        return self.energies if self.parameter == "energy" else self.periods

    @property
    def stable(self):
        return np.array([p.stable for p in self.points])

    def __len__(self):
        return len(self.points)

    def plot(self, ax=None, *, x="energy", y="period", **kwargs):
        """Draws y against x ("energy" or "period"): stable orbits solid, unstable dashed,
        special points marked and named. Returns the axes."""
        for name, v in (("x", x), ("y", y)):
            if not isinstance(v, str):
                raise TypeError(f"invalid {name}: expected \"energy\" or \"period\", got "
                                f"{type(v).__name__} {v!r}")
            if v not in ("energy", "period"):
                raise InvalidArgumentError(f"invalid {name}: expected \"energy\" or "
                                           f"\"period\", got {v!r}")
        import matplotlib.pyplot as plt
        if ax is None:
            ax = plt.gca()
        xs = self.energies if x == "energy" else self.periods
        ys = self.energies if y == "energy" else self.periods
        st = self.stable
        color = kwargs.pop("color", "C0")
        for k in range(len(xs) - 1):
            ax.plot(xs[k:k + 2], ys[k:k + 2], "-" if st[k] and st[k + 1] else "--", color=color,
                    **kwargs)
        for sp in self.special_points:
            px = sp.orbit.energy if x == "energy" else sp.orbit.period
            py = sp.orbit.energy if y == "energy" else sp.orbit.period
            ax.plot([px], [py], "o", color="k")
            ax.annotate(sp.kind.replace("_", " "), (px, py), textcoords="offset points",
                        xytext=(5, 5), fontsize=8)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        return ax

    def __repr__(self):
        return (f"PeriodicBranch({len(self.points)} orbits, {self.parameter} "
                f"{self.values[0]:.6g} -> {self.values[-1]:.6g}, "
                f"{len(self.special_points)} special points, end={self.end!r})")


def periodic_family(system, orbit, *, parameter="energy", stop=None, step=0.02,
                    max_step=0.05, max_points=40, direction=1, tol=1e-10):
    """Follows the family of periodic (or relative periodic) orbits through ``orbit``.

    The family at the levels of ``orbit`` (its invariants and momentum, ``orbit.levels``),
    followed natively (``lieflow::analysis::periodic::periodic_family``): a tangent predictor
    (``PeriodicOrbit.tangent``, the null vector of the shooting equations without the
    energy's, in the orbit's unknowns: state, period, drift) and the shooting of
    ``periodic_orbit`` with the pseudo-arclength condition as corrector (which passes folds of
    the energy and of the period); steps grow and shrink with the corrector's success, and an
    orbit the corrector finds too far from the prediction or whose family tangent turned too
    much (another family) is refused for a shorter step. Between consecutive orbits the normal
    multipliers are compared: a change of stability is located by bisection on the secant and
    named by how the multipliers left the unit circle (``PeriodicSpecialPoint.kind``: period
    doubling, tangent, Krein collision); a turn of the parameter is reported as a fold. Where
    the energy and the period turn back together the continuation would retrace the family in
    invariant terms: it ends there (``end`` says where). That is how a family ends on another
    (relative) equilibrium: its orbits shrink onto it, and past it the same orbits return half
    a period on. Every orbit keeps the method and the steps per period of ``orbit``. Ctrl-C
    ends the continuation between orbits (``KeyboardInterrupt``).

    Args:
        system: the system of ``orbit``.
        orbit: a ``PeriodicOrbit`` (e.g. from ``periodic_orbit.from_mode``).
        parameter: "energy" or "period", what ``values``, ``stop`` and folds refer to.
        stop: stop once the parameter passes this value (default: ``max_points`` only).
        step, max_step: the first and the largest step, relative to the state's size.
        max_points: the largest number of orbits.
        direction: +1 to start towards higher energy, −1 lower.
        tol: the shooting's tolerance.

    Returns:
        A ``PeriodicBranch``.
    """
    if not isinstance(parameter, str) or parameter not in ("energy", "period"):
        raise InvalidArgumentError(f"invalid parameter: expected \"energy\" or \"period\", "
                                   f"got {parameter!r}")
    if not isinstance(orbit, PeriodicOrbit):
        raise TypeError(f"invalid orbit: expected a PeriodicOrbit, got {type(orbit).__name__}")
    max_points = _count("max_points", max_points)
    for name, v in (("stop", stop), ("step", step), ("max_step", max_step),
                    ("direction", direction), ("tol", tol)):
        if not (v is None and name == "stop") and not _real(v):
            raise TypeError(f"invalid {name}: expected a real number, got "
                            f"{type(v).__name__} {v!r}")
    start = (orbit.state0, orbit.period, orbit.steps, orbit.energy, orbit.normal_multipliers,
             orbit.residual, orbit.iterations, orbit.drift, orbit.levels, orbit.tangent,
             orbit.attitude)
    found = _periodic_family(system, start, orbit.method, parameter,
                             None if stop is None else float(stop), step, max_step, max_points,
                             direction, tol)
    attitude = orbit.attitude

    def wrap(fields):
        return PeriodicOrbit(system, orbit.method, attitude, fields)

    points = [orbit] + [wrap(f) for f in found["points"]]
    specials = [PeriodicSpecialPoint(kind, index, value, wrap(f))
                for kind, index, value, f in found["special"]]
    return PeriodicBranch(points, parameter, specials, found["end"])
