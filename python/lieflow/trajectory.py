"""The result of ``lieflow.integrate``: the ``Trajectory`` (samples, final state, events, named
views and observables of the system) and ``load``, which reads one back from a file."""

import numpy as np

from ._arrays import real_array
from ._lieflow import InvalidArgumentError
from ._text import brief

__all__ = ["Trajectory", "load"]


class Trajectory:
    r"""A computed trajectory.

    Attributes:
        system, method, dt: as passed to ``integrate``.
        save_every: as passed to ``integrate`` (None when ``t_eval`` gave the times).
        t: (k,) sample times (absolute: from ``t0``; ``t_eval`` when given).
        states: (k, d) samples, or (b, k, d) for a batch.
        attitude: (k, n, n) / (b, k, n, n) attitudes (group elements: n = 3 for rotations), or
            None.
        final_state, final_attitude: the state after all steps (also when ``steps`` is not a
            multiple of ``save_every``; a terminal event's state); pass them to ``integrate``
            with ``t0=traj.t_final`` to continue.
        t0, t_final: the times of the initial and the final state.
        initial_state, initial_attitude: the state the run started from.
        status: 0 the run reached its end, 1 a terminal event ended it, -1 it failed (the
            ``partial`` trajectory of an exception), as scipy's.
        t_events, state_events: with ``events``, one array per event function of the times
            (n_i,) and the states (n_i, d) of its zeros (``attitude_events`` (n_i, n, n) with an
            attitude); None without events.
        jacobian: with ``sensitivity=True``, (k, d, d) (or (b, k, d, d)) the Jacobians
            :math:`\partial z_k/\partial z_0` of the method's own discrete map at the samples
            (``final_jacobian`` at
            the final state); None otherwise.
        parameter_jacobian: with ``sensitivity=True``, (k, d, p) the derivatives
            :math:`\partial z_k/\partial\theta` along
            ``system.parameters`` (``final_parameter_jacobian`` at the final state).
        Named views from the system (e.g. ``M``, ``Gamma``, ``q``, ``L``) as attributes.

    Methods ``energy()`` and ``casimirs()``, ``to_xarray()`` and ``save(path)`` (read back with
    ``lf.load(path)``), and every observable of the system:
    ``traj.NAME(...)`` is ``system.NAME(traj.states, ...)`` (with the attitude passed as well for
    observables such as ``spatial_momentum`` that need it). ``Trajectory.concatenate([a, b])``
    joins a run and its continuation.
    """

    def __init__(self, system, method, t, states, attitude, final_state, final_attitude, dt,
                 save_every, *, t_final=None, status=0, t_events=None, state_events=None,
                 attitude_events=None, t0=None, initial_state=None, initial_attitude=None,
                 jacobian=None, final_jacobian=None, parameter_jacobian=None,
                 final_parameter_jacobian=None):
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
        self.jacobian = jacobian
        self.final_jacobian = final_jacobian
        self.parameter_jacobian = parameter_jacobian
        self.final_parameter_jacobian = final_parameter_jacobian
        self._field_cache = None

    def vjp(self, cotangent):
        r"""The gradient of a loss L of this trajectory with respect to the initial state and the
        system's parameters, from the cotangent :math:`\partial L/\partial z`: (grad_state0 (d,),
        grad_parameters (p,)) with :math:`\mathrm{grad} = \sum_k J_k^\top c_k` over the samples
        (a run with ``sensitivity=True``).

        Args:
            cotangent: (e,) on the final state, or (k, e) on every sample, e the Jacobian's size
                (d; with an attitude, the state's values and the attitude's three
                left-trivialised directions); for a batch (b, e) or (b, k, e), and the gradients
                are (b, e), (b, p).
        Raises:
            TypeError (not real numbers), InvalidArgumentError (a run without
            ``sensitivity=True``), ShapeError, NonFiniteError (a non-finite cotangent, or a
            gradient beyond the float range).
        """
        if self.jacobian is None:
            raise InvalidArgumentError("invalid vjp: this trajectory carries no Jacobians; "
                                       "integrate with sensitivity=True")
        from ._lieflow import NonFiniteError, ShapeError
        c = real_array("cotangent", cotangent)
        if c.size > self.jacobian.size:
            raise ShapeError(f"invalid cotangent: expected shape {self.final_jacobian.shape[:-1]} "
                             f"or {self.jacobian.shape[:-1]}, got {c.shape}")
        c = c.astype(np.float64)
        if not np.all(np.isfinite(c)):
            raise NonFiniteError("invalid cotangent: it contains a non-finite value (NaN or inf)")
        every = self.jacobian.shape[:-1]           # (b,) k, e: a cotangent on every sample
        final = self.final_jacobian.shape[:-1]     # (b,) e: on the final state
        if c.shape == final:
            jacs, rule = (self.final_jacobian, self.final_parameter_jacobian), "...ij,...i->...j"
        elif c.shape == every:
            jacs, rule = (self.jacobian, self.parameter_jacobian), "...kij,...ki->...j"
        else:
            raise ShapeError(f"invalid cotangent: expected shape {final} (the final state) or "
                             f"{every} (every sample), got {c.shape}")
        with np.errstate(over="ignore", invalid="ignore"):
            grads = tuple(np.einsum(rule, j, c) for j in jacs)
            if not all(np.all(np.isfinite(g)) for g in grads):
                # An intermediate sum beyond the float range: again with the cotangent scaled
                # to at most 1, the gradient scaled back.
                s = float(np.max(np.abs(c)))
                grads = tuple(np.einsum(rule, j, c / s) * s for j in jacs)
        if not all(np.all(np.isfinite(g)) for g in grads):
            raise NonFiniteError("invalid cotangent: the gradient J^T c overflows the float "
                                 "range (beyond 1.8e308); scale the loss down")
        return grads

    @classmethod
    def concatenate(cls, trajectories):
        r"""One trajectory from a run and its continuations: each must start where the one
        before ended (its ``t0`` equal to the previous ``t_final`` and its initial state equal
        to the previous ``final_state``, as ``integrate(system, traj.final_state, ...,
        t0=traj.t_final)`` gives) on the same system. A sample repeated at the seam (the first
        of a continuation is the last of the one before when that was its final state) is kept
        once; events are joined per event function (None unless every part has the same number
        of event functions); the Jacobians of runs with ``sensitivity=True`` are joined by the
        chain rule (each continuation's are along its own start), so they stay
        :math:`\partial z/\partial z_0` and :math:`\partial z/\partial\theta` of the whole run. ``method``, ``dt`` and ``save_every`` are the parts' common values
        (a tuple of the methods, None for dt and save_every, where they differ).

        Raises:
            TypeError (not Trajectories), InvalidArgumentError (nothing to join, other systems,
            batch or state shapes, attitudes or Jacobians that come and go, a part that does not
            start where the one before ended).
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
                raise InvalidArgumentError(f"{where} integrates another system ({brief(b.system, 60)} "
                                           f"after {brief(a.system, 60)})")
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
        have = [p.jacobian is not None for p in parts]
        if any(have) and not all(have):
            raise InvalidArgumentError("invalid trajectories: Jacobians (sensitivity=True) in "
                                       "some parts only")
        t, states, atts = [first.t], [first.states], [first.attitude]
        jac, pjac = [first.jacobian], [first.parameter_jacobian]
        jac_end, pjac_end = first.final_jacobian, first.final_parameter_jacobian
        for a, b in zip(parts, parts[1:]):
            drop = (len(a.t) and len(b.t) and b.t[0] <= a.t[-1]
                    + 16 * np.finfo(float).eps * max(abs(a.t[-1]), 1.0) + 1e-9 * b.dt)
            s = 1 if drop else 0
            t.append(b.t[s:])
            states.append(b.states[..., s:, :])
            if b.attitude is not None:
                atts.append(b.attitude[..., s:, :, :])
            if b.jacobian is not None:
                # A continuation's Jacobians are along its own start, the end of the part
                # before: the chain rule joins them (∂z/∂θ gains the start's dependence).
                jb = b.jacobian[..., s:, :, :]
                jac.append(jb @ jac_end[..., None, :, :])
                pjac.append(jb @ pjac_end[..., None, :, :] + b.parameter_jacobian[..., s:, :, :])
                jac_end, pjac_end = (b.final_jacobian @ jac_end,
                                     b.final_jacobian @ pjac_end + b.final_parameter_jacobian)
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
        if all(have):
            events.update(jacobian=np.concatenate(jac, axis=axis), final_jacobian=jac_end,
                          parameter_jacobian=np.concatenate(pjac, axis=axis),
                          final_parameter_jacobian=pjac_end)
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

    @property
    def invariant_names(self):
        """The system's label for each column of ``invariants()`` (``"|M|²"``, ``"M·Γ"``, …)."""
        return list(self.system.invariant_names)

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
