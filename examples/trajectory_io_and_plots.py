"""
Saving, loading, plotting and animating a trajectory
====================================================

A run's results outlive the session: ``Trajectory.to_xarray()`` gives an :class:`xarray.Dataset`
with named variables (the fields ``M`` and ``Gamma``, the energy, the invariants, the attitude)
and attributes (the system and its parameters, the method, the step), ``Trajectory.save`` writes
it to a NetCDF file, and ``lf.load`` reads it back with its system rebuilt, so the run can be
continued from its final state. ``lieflow.plot`` draws the drift of the invariants, the fields
against time, and an animation with one frame per saved sample.

The system is a heavy top integrated with its attitude. Run it with
``python examples/trajectory_io_and_plots.py``.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import lieflow as lf
from lieflow import plot

top = lf.HeavyTop(inertia=[1.0, 1.0, 0.4], mgl=1.0)
R0 = lf.lie.so3_exp(np.array([0.5, 0.0, 0.0]))
z0 = top.state([0.0, 0.25, 3.2], attitude=R0)
traj = lf.integrate(top, z0, dt=0.01, steps=600, method="splitting4", save_every=15,
                    attitude=R0)
ds = traj.to_xarray()
print(ds)

# %%
# Save the run, load it back and continue it from its final state. The round trip is exact,
# and the loaded system is a new object built from the file (class and constructor arguments,
# stored as data, never as code).
with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "top.nc"
    traj.save(path)
    loaded = lf.load(path)
print(loaded.system, "| same states:", np.array_equal(loaded.states, traj.states))
more = lf.integrate(loaded.system, loaded.final_state, dt=0.01, steps=600, method="splitting4",
                    save_every=15, attitude=loaded.final_attitude, t0=loaded.t_final)
whole = lf.Trajectory.concatenate([loaded, more])
print(f"{len(whole)} samples to t = {whole.t_final:g}")

# %%
# The relative drift of the energy and the Casimirs (log scale), and the fields against time.
plot.invariants(whole)
plot.states(whole)
plt.tight_layout()

# %%
# An animation of the body (a box with the top's principal axes, on its axis above the fixed
# point) with the trail of the tip; ``plot.animate(traj, "top.gif")`` would save it as a GIF.
anim = plot.animate(traj, every=2, interval=100)
