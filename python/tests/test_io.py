"""Trajectories as xarray Datasets and NetCDF files (issue 13): ``Trajectory.to_xarray``,
``Trajectory.save`` and ``lf.load`` — the round trip is exact for every kind of run, the system
is rebuilt (so a run continues bit for bit from the loaded final state), systems are stored as
data (never code unless ``allow_pickle``), and bad files give clear errors."""

import json

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import lieflow as lf
from lieflow import potentials as pot

xr = pytest.importorskip("xarray")

M0 = np.array([1.0, 0.5, -0.3])


def osc_h(q, p):
    return 0.5 * float(q @ q + p @ p)


def runs():
    """(name, system, integrate kwargs) covering the kinds of trajectory."""
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    svk = pot.SaintVenantKirchhoff(1.0, 2.0) + pot.Volumetric(0.5, 1.4)
    X0 = np.diag([1.3, 1.0, 0.8])
    P0 = lf.lie.hat([0.1, 0.3, 1.0]) @ X0
    g = lambda t, s: s[1]  # noqa: E731
    g.direction, g.terminal = -1.0, True
    return [
        ("rigid body", rb, dict(state0=M0, dt=0.01, steps=105, save_every=10)),
        ("attitude", rb, dict(state0=M0, dt=0.01, steps=50, attitude=np.eye(3))),
        ("batch", rb, dict(state0=np.stack([M0, 2 * M0, -M0]), dt=0.01, steps=20,
                           save_every=3, attitude=np.eye(3))),
        ("t_eval", rb, dict(state0=M0, dt=0.01, t_eval=[0.0, 0.123, 0.5])),
        ("events", rb, dict(state0=M0, dt=0.01, steps=600, events=g, attitude=np.eye(3))),
        ("heavy top", lf.HeavyTop([1.0, 2.0, 3.0], 0.7),
         dict(state0=(M0, [0.0, 0.6, 0.8]), dt=0.01, steps=30, method="splitting4")),
        ("pseudo-rigid", lf.PseudoRigidBody(3, potential=svk),
         dict(state0=(X0, P0), dt=0.01, steps=20, method="verlet4")),
        ("tangent top", lf.TangentTop(lf.surfaces.Sphere(1.0), 1.0, 0.5),
         dict(state0=[0.3, 0.2, 0.1, 0.4, -0.2, 0.3], dt=0.01, steps=20)),
        ("rolling disks", lf.RollingDisks(1.0, 0.7, 0.3 + 0.1j, [-0.2, 0.25], 1.0, 1.5, 0.8, 0.6),
         dict(state0=[0.1, 0.2, 0.5, -0.3], dt=0.01, steps=20)),
        ("damped pendulum", lf.Forced(lf.Pendulum(1.0, 1.0, 9.81), damping=0.3),
         dict(state0=[1.0, 0.0], dt=0.01, steps=30)),
    ]


def assert_same(a, b):
    """Every attribute of two trajectories equal (arrays bit for bit)."""
    assert type(a.system) is type(b.system) and repr(a.system) == repr(b.system)
    assert (a.method, a.dt, a.save_every, a.t0, a.t_final, a.status) == \
           (b.method, b.dt, b.save_every, b.t0, b.t_final, b.status)
    for name in ("t", "states", "attitude", "final_state", "final_attitude", "initial_state",
                 "initial_attitude"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert np.asarray(x).dtype == np.asarray(y).dtype == np.float64, name
            np.testing.assert_array_equal(x, y, err_msg=name)
    for name in ("t_events", "state_events", "attitude_events"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert len(x) == len(y)
            for u, v in zip(x, y):
                np.testing.assert_array_equal(u, v, err_msg=name)


@pytest.mark.parametrize("name,system,kw", runs(), ids=[r[0] for r in runs()])
def test_save_load_round_trip_is_exact(tmp_path, name, system, kw):
    kw = dict(kw)
    traj = lf.integrate(system, kw.pop("state0"), **kw)
    path = tmp_path / "run.nc"
    traj.save(path)
    back = lf.load(path)
    assert_same(traj, back)
    assert_same(traj, lf.load(traj.to_xarray()))
    if name == "events":
        assert traj.status == 1 and len(back.t_events[0]) == 1


@pytest.mark.parametrize("name,system,kw", runs()[:3] + runs()[5:7],
                         ids=[r[0] for r in runs()[:3] + runs()[5:7]])
def test_a_loaded_run_continues_bit_for_bit(tmp_path, name, system, kw):
    """A run continued from the loaded file equals the continuation of the original."""
    kw = dict(kw)
    state0 = kw.pop("state0")
    first = lf.integrate(system, state0, **kw)
    kw.pop("attitude", None)
    first.save(tmp_path / "first.nc")
    loaded = lf.load(tmp_path / "first.nc")
    assert loaded.system is not system and repr(loaded.system) == repr(system)
    runs = [lf.integrate(t.system, t.final_state, attitude=t.final_attitude, t0=t.t_final, **kw)
            for t in (first, loaded)]
    assert_same(*runs)
    assert runs[1].t0 == first.t_final


def test_to_xarray_layout_fields_and_attributes():
    hv = lf.HeavyTop([1.0, 2.0, 3.0], 0.7)
    batch = (np.stack([M0, 2 * M0]), np.array([[0.0, 0.6, 0.8], [0.6, 0.0, 0.8]]))
    traj = lf.integrate(hv, batch, dt=0.01, steps=40, save_every=4)
    ds = traj.to_xarray()
    assert ds["states"].dims == ("member", "time", "component")
    assert ds.sizes == {"member": 2, "time": 11, "component": 6, "M_component": 3,
                        "Gamma_component": 3, "invariant": ds.sizes["invariant"]}
    np.testing.assert_array_equal(ds["time"], traj.t)
    np.testing.assert_array_equal(ds["member"], [0, 1])
    np.testing.assert_array_equal(ds["M"], traj.M)
    np.testing.assert_array_equal(ds["Gamma"], traj.Gamma)
    np.testing.assert_array_equal(ds["energy"], traj.energy())
    np.testing.assert_array_equal(ds["invariants"], traj.invariants())
    assert list(ds["invariant"].values) == ["|Γ|²", "M·Γ"] == traj.invariant_names
    assert ds["energy"].dims == ("member", "time")
    a = ds.attrs
    assert a["system"] == repr(hv) and a["system_class"] == "HeavyTop"
    assert a["method"] == traj.method and a["dt"] == 0.01 and a["save_every"] == 4
    assert a["lieflow_version"] == lf.__version__ and a["lieflow_format"] == lf.io.FORMAT
    np.testing.assert_array_equal(a["system_inertia"], [1.0, 2.0, 3.0])
    assert a["system_mgl"] == 0.7
    assert json.loads(a["system_spec"])["call"] == "lieflow:HeavyTop"
    assert "energy" not in traj.to_xarray(observables=False)
    # a pseudo-rigid body's fields are matrices
    prb = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    x = np.diag([1.2, 1.0, 0.9])
    ds = lf.integrate(prb, (x, 0 * x), dt=0.01, steps=5).to_xarray()
    assert ds["X"].dims == ("time", "X_row", "X_col")
    np.testing.assert_array_equal(ds["X"][0], x)


@settings(max_examples=15, deadline=None)
@given(b=st.integers(0, 3), steps=st.integers(1, 30), every=st.integers(1, 7),
       t0=st.floats(-1e3, 1e3, allow_nan=False))
def test_round_trip_property(tmp_path_factory, b, steps, every, t0):
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    state0 = M0 if b == 0 else np.outer(np.arange(1, b + 1), M0)
    traj = lf.integrate(rb, state0, dt=0.02, steps=steps, save_every=every, t0=t0)
    path = tmp_path_factory.mktemp("p") / "run.nc"
    traj.save(path)
    assert_same(traj, lf.load(path))


# --- systems from Python callables: data or, on request, a pickle ---


def test_a_system_with_callables_is_stored_only_pickled_on_request(tmp_path):
    sys = lf.Canonical(osc_h, dof=1)
    traj = lf.integrate(sys, [1.0, 0.0], dt=0.05, steps=10)
    path = tmp_path / "osc.nc"
    with pytest.raises(lf.InvalidArgumentError, match="allow_pickle=True") as caught:
        traj.save(path)
    # The system is named whole or visibly shortened, never cut mid-token.
    named = str(caught.value).split("invalid system: ")[1].split(" holds Python callables")[0]
    assert named == repr(sys) or (named.endswith("…") and repr(sys).startswith(named[:-1]))
    assert not path.exists()
    traj.save(path, allow_pickle=True)
    with pytest.raises(lf.FileFormatError, match="pickled.*allow_pickle=True"):
        lf.load(path)
    back = lf.load(path, allow_pickle=True)
    np.testing.assert_array_equal(back.states, traj.states)
    np.testing.assert_array_equal(back.energy(), traj.energy())


def test_a_spec_never_calls_anything_outside_lieflow(tmp_path):
    traj = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, steps=3)
    ds = traj.to_xarray()
    ds.attrs["system_spec"] = json.dumps({"call": "os:system", "args": ["echo pwned"]})
    path = tmp_path / "evil.nc"
    ds.to_netcdf(path)
    with pytest.raises(lf.FileFormatError, match="not a lieflow callable"):
        lf.load(path)


# --- bad files ---


def test_bad_files_give_clear_errors(tmp_path):
    traj = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, steps=3)
    with pytest.raises(FileNotFoundError, match="no such file"):
        lf.load(tmp_path / "missing.nc")
    junk = tmp_path / "junk.nc"
    junk.write_bytes(b"this is not a NetCDF file" * 10)
    with pytest.raises(lf.FileFormatError, match="cannot read.*NetCDF"):
        lf.load(junk)
    good = tmp_path / "good.nc"
    traj.save(good)
    cut = tmp_path / "cut.nc"
    cut.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    with pytest.raises(lf.FileFormatError):
        lf.load(cut)
    ds = traj.to_xarray()
    ds.attrs["lieflow_format"] = lf.io.FORMAT + 1
    ds.attrs["lieflow_version"] = "9.0.0"
    newer = tmp_path / "newer.nc"
    ds.to_netcdf(newer)
    with pytest.raises(lf.FileFormatError,
                       match=rf"lieflow 9\.0\.0 in format {lf.io.FORMAT + 1}.*upgrade"):
        lf.load(newer)
    other = tmp_path / "other.nc"
    xr.Dataset({"x": ("t", np.arange(3.0))}).to_netcdf(other)
    with pytest.raises(lf.FileFormatError, match="not a lieflow trajectory"):
        lf.load(other)
    ds = traj.to_xarray().drop_vars("states")
    with pytest.raises(lf.FileFormatError, match="no states"):
        lf.load(ds)
    assert issubclass(lf.FileFormatError, lf.LieflowError)


def test_no_netcdf4_backend_is_a_clear_import_error(tmp_path, monkeypatch):
    import importlib.util

    traj = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.01, steps=3)
    saved = tmp_path / "saved.nc"
    traj.save(saved)
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name in ("netCDF4", "h5py") else real(name, *a))
    with pytest.raises(ImportError, match=r"NetCDF-4 backend.*pip install lieflow\[io\]"):
        traj.save(tmp_path / "x.nc")
    assert not (tmp_path / "x.nc").exists()
    with pytest.raises(ImportError, match="NetCDF-4 backend"):
        lf.load(saved)


# --- runs with sensitivities (issue 26): the Jacobians are saved, checked, joined ---

def _sensitivity_run(attitude=True, **kw):
    body = lf.RigidBody([1.0, 2.0, 3.0])
    R0 = lf.lie.so3_exp([0.4, -0.7, 0.3]) if attitude else None
    return lf.integrate(body, [0.3, -0.8, 1.1], 0.01, 100, save_every=10, attitude=R0,
                        sensitivity=True, **kw)


@pytest.mark.parametrize("attitude", [False, True])
def test_jacobians_are_saved_and_loaded_exactly(tmp_path, attitude):
    traj = _sensitivity_run(attitude)
    ds = traj.to_xarray()
    assert ds["jacobian"].dims == ("time", "tangent", "direction")
    assert ds["parameter_jacobian"].dims == ("time", "tangent", "parameter")
    assert json.loads(ds.attrs["parameters"]) == ["I1", "I2", "I3"]
    traj.save(tmp_path / "sens.nc")
    back = lf.load(tmp_path / "sens.nc")
    for name in ("jacobian", "final_jacobian", "parameter_jacobian", "final_parameter_jacobian"):
        np.testing.assert_array_equal(getattr(back, name), getattr(traj, name), err_msg=name)
    np.testing.assert_array_equal(back.vjp(np.ones(traj.final_jacobian.shape[-1]))[1],
                                  traj.vjp(np.ones(traj.final_jacobian.shape[-1]))[1])


def test_jacobians_of_a_system_without_parameters_round_trip(tmp_path):
    pend = lf.Pendulum(1.0, 1.0, 9.81)
    traj = lf.integrate(pend, [0.3, 0.1], 0.05, 40, method="gauss6", save_every=10,
                        sensitivity=True)
    assert traj.parameter_jacobian.shape == (5, 2, 0)
    traj.save(tmp_path / "pend.nc")
    back = lf.load(tmp_path / "pend.nc")
    np.testing.assert_array_equal(back.jacobian, traj.jacobian)
    assert back.parameter_jacobian.shape == (5, 2, 0)


def _unsealed(ds):
    """A Dataset edited by hand: format 1, no checksums (loads with a UserWarning)."""
    ds.attrs.pop("lieflow_checksums")
    ds.attrs["lieflow_format"] = 1
    return ds


def test_damaged_or_inconsistent_jacobians_are_refused(tmp_path):
    traj = _sensitivity_run()
    ds = traj.to_xarray()
    ds["jacobian"].values[3, 0, 0] += 1e-9
    with pytest.raises(lf.FileFormatError, match="jacobian"):
        lf.load(ds)
    cases = {
        "final_jacobian differs": lambda d: d["final_jacobian"].values.__setitem__((0, 0), 7.0),
        "identity": lambda d: d["jacobian"].values.__setitem__((0, 0, 1), 0.5),
        "parameters": lambda d: d.attrs.__setitem__("parameters", json.dumps(["a", "b", "c"])),
        "along 3 parameters": lambda d: d.__delitem__("parameter_jacobian"),
        "non-finite": lambda d: d["parameter_jacobian"].values.__setitem__((2, 0, 0), np.nan),
    }
    for match, damage in cases.items():
        ds = _unsealed(traj.to_xarray())
        damage(ds)
        with pytest.warns(UserWarning, match="format 1"), \
                pytest.raises(lf.FileFormatError, match=match.split()[0]):
            lf.load(ds)


@pytest.mark.parametrize("attitude", [False, True])
def test_concatenated_runs_join_their_jacobians_by_the_chain_rule(attitude):
    body = lf.RigidBody([1.0, 2.0, 3.0])
    R0 = lf.lie.so3_exp([0.4, -0.7, 0.3]) if attitude else None
    whole = lf.integrate(body, [0.3, -0.8, 1.1], 0.01, 100, save_every=10, attitude=R0,
                         sensitivity=True)
    a = lf.integrate(body, [0.3, -0.8, 1.1], 0.01, 40, save_every=10, attitude=R0,
                     sensitivity=True)
    b = lf.integrate(body, a.final_state, 0.01, 60, save_every=10, t0=a.t_final,
                     attitude=a.final_attitude, sensitivity=True)
    joined = lf.Trajectory.concatenate([a, b])
    np.testing.assert_allclose(joined.t, whole.t, rtol=1e-15)
    for name in ("jacobian", "final_jacobian", "parameter_jacobian", "final_parameter_jacobian"):
        np.testing.assert_allclose(getattr(joined, name), getattr(whole, name), rtol=1e-12,
                                   atol=1e-12, err_msg=name)
    plain = lf.integrate(body, a.final_state, 0.01, 60, save_every=10, t0=a.t_final,
                         attitude=a.final_attitude)
    with pytest.raises(lf.InvalidArgumentError, match="some parts only"):
        lf.Trajectory.concatenate([a, plain])


def test_a_batch_with_jacobians_round_trips(tmp_path):
    body = lf.RigidBody([1.0, 2.0, 3.0])
    z0 = np.array([[0.3, -0.8, 1.1], [0.5, 0.2, -0.9]])
    traj = lf.integrate(body, z0, 0.01, 50, save_every=10, attitude=np.eye(3), sensitivity=True)
    assert traj.jacobian.shape == (2, 6, 6, 6)
    traj.save(tmp_path / "batch.nc")
    back = lf.load(tmp_path / "batch.nc")
    for name in ("jacobian", "final_jacobian", "parameter_jacobian", "final_parameter_jacobian"):
        np.testing.assert_array_equal(getattr(back, name), getattr(traj, name), err_msg=name)
