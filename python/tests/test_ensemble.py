"""lieflow.ensemble: Dask ensembles and parameter sweeps as lazy xarray Datasets.

Threaded scheduler (Dask's default without a client) and a real dask.distributed LocalCluster
(2 worker processes x 1 thread, one per module): results equal one lf.integrate batch bit for
bit; nothing runs before compute; bad input raises lf.integrate's typed errors before any task
exists; a killed worker's tasks are run again; Ctrl-C cancels the submitted tasks.
"""

import math
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

pytest.importorskip("dask")
pytest.importorskip("dask.array")
distributed = pytest.importorskip("distributed")
pytest.importorskip("xarray")

import lieflow as lf  # noqa: E402
from lieflow import ensemble  # noqa: E402

BODY = lf.RigidBody([1.0, 2.0, 3.0])


def members(b, seed=0):
    return np.random.default_rng(seed).standard_normal((b, 3))


def rotations(b, seed=1):
    """b random rotations (QR of Gaussian matrices, det fixed to +1)."""
    q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((b, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0] *= -1
    return q


def assert_equal_to_batch(ds, traj):
    """The computed Dataset `ds` equals the batch Trajectory `traj` bit for bit."""
    assert np.array_equal(ds.time.values, traj.t)
    assert np.array_equal(ds.member.values, np.arange(traj.states.shape[0]))
    assert np.array_equal(ds.states.values, traj.states)
    assert np.array_equal(ds.energy.values, traj.energy())
    assert np.array_equal(ds.invariants.values, traj.invariants())
    assert np.array_equal(ds.final_state.values, traj.final_state)
    if traj.attitude is not None:
        assert np.array_equal(ds.attitude.values, traj.attitude)
        assert np.array_equal(ds.final_attitude.values, traj.final_attitude)
    else:
        assert "attitude" not in ds


@pytest.fixture
def calls(monkeypatch):
    """Counts the native batch runs of the tasks (threaded scheduler: same process)."""
    n = []
    real = ensemble._integrate_chunk

    def counting(**kwargs):
        n.append(len(kwargs["z"]))
        return real(**kwargs)

    monkeypatch.setattr(ensemble, "_integrate_chunk", counting)
    return n


@pytest.fixture(autouse=True)
def _no_default_client():
    # The cluster's client is never the default one: threaded tests run threaded in any order.
    yield
    with pytest.raises(ValueError):
        distributed.Client.current(allow_global=True)


# ------------------------------------------------------------------ threaded (no client)

@pytest.mark.parametrize("chunks", [None, 1, 4, 5, 13, 100])
def test_threaded_equals_batch_bit_for_bit(chunks):
    m = members(13)
    ds = ensemble.integrate(BODY, m, 0.01, 27, save_every=4, chunks=chunks)   # 27 % 4 != 0
    traj = lf.integrate(BODY, m, 0.01, 27, save_every=4)
    c = min(chunks or ensemble.default_chunks(13), 13)
    assert ds.states.data.numblocks[0] == math.ceil(13 / c)
    assert_equal_to_batch(ds.compute(), traj)


def test_lazy_until_compute_one_run_per_chunk(calls):
    m = members(10)
    ds = ensemble.integrate(BODY, m, 0.01, 20, save_every=5, chunks=3)
    assert calls == []                                  # nothing ran
    import dask.array as da
    for name in ("states", "energy", "invariants", "final_state"):
        assert isinstance(ds[name].data, da.Array)
    assert ds.states.dims == ("member", "time", "component")
    assert ds.energy.dims == ("member", "time")
    assert ds.invariants.dims == ("member", "time", "invariant")
    assert ds.final_state.dims == ("member", "component")
    assert ds.states.shape == (10, 5, 3) and ds.invariants.shape == (10, 5, 1)
    ds.compute()
    assert sorted(calls) == [1, 3, 3, 3]                 # one native batch per chunk, once
    assert dict(ds.attrs) == {"system": repr(BODY), "method": "splitting", "dt": 0.01,
                              "save_every": 5, "t0": 0.0, "steps": 20,
                              "lieflow_version": lf.__version__}


def test_t0_method_and_per_member_attitude():
    m, r = members(7), rotations(7)
    ds = ensemble.integrate(BODY, m, 0.02, 15, "splitting4", 3, chunks=3, t0=1.25, attitude=r)
    traj = lf.integrate(BODY, m, 0.02, 15, method="splitting4", save_every=3, attitude=r,
                        t0=1.25)
    assert ds.attrs["method"] == "splitting4" and ds.attrs["t0"] == 1.25
    assert ds.attitude.dims == ("member", "time", "attitude_row", "attitude_col")
    assert_equal_to_batch(ds.compute(), traj)
    shared = ensemble.integrate(BODY, m, 0.02, 15, chunks=2, attitude=np.eye(3)).compute()
    assert_equal_to_batch(shared, lf.integrate(BODY, m, 0.02, 15, attitude=np.eye(3)))


def _h(q, p):
    return 0.5 * float(q @ q + p @ p)


def _dh(q, p):
    return q, p


@pytest.mark.parametrize("system, state", [
    (lf.Pendulum(1.0, 1.0, 9.81), np.array([[0.3, 0.0], [1.0, -0.5], [2.0, 0.1]])),  # 0 inv.
    (lf.HeavyTop([1.0, 2.0, 3.0], 0.7), np.array([[1.0, 0.5, -0.3, 0.0, 0.6, 0.8]] * 3)),
    (lf.Canonical(_h, _dh, 1), np.array([[0.3, 0.1], [-0.2, 0.4], [1.0, 0.0]])),   # callables
])
def test_other_systems(system, state):
    ds = ensemble.integrate(system, state, 0.01, 12, save_every=4, chunks=2).compute()
    assert_equal_to_batch(ds, lf.integrate(system, state, 0.01, 12, save_every=4))
    assert ds.attrs["method"] == system.methods()[0]


def test_single_state_and_empty_ensemble():
    ds = ensemble.integrate(BODY, [1.0, 0.5, -0.3], 0.01, 10).compute()
    assert ds.states.shape == (1, 11, 3)
    single = lf.integrate(BODY, [1.0, 0.5, -0.3], 0.01, 10)
    assert np.array_equal(ds.states.values[0], single.states)
    empty = ensemble.integrate(BODY, np.zeros((0, 3)), 0.01, 10, save_every=5).compute()
    assert empty.states.shape == (0, 3, 3) and empty.energy.shape == (0, 3)


def test_default_chunks_rule():
    assert ensemble.TASKS_PER_CORE == 4
    assert ensemble.default_chunks(100, cores=2) == 13           # ceil(100 / 8)
    assert ensemble.default_chunks(5, cores=2) == 1
    assert ensemble.default_chunks(0, cores=2) == 1
    assert ensemble.default_chunks(100_000, cores=2) == 12_500
    import dask
    with dask.config.set(num_workers=3):
        assert ensemble.default_chunks(120) == 10                 # local threads: 3


BAD = {  # name: (keyword changes, the expected error; the same as lf.integrate's)
    "system-class": ({"system": lf.RigidBody}, TypeError),
    "system-str": ({"system": "RigidBody"}, TypeError),
    "dt-zero": ({"dt": 0.0}, lf.InvalidArgumentError),
    "dt-nan": ({"dt": float("nan")}, lf.InvalidArgumentError),
    "dt-str": ({"dt": "0.01"}, TypeError),
    "steps-zero": ({"steps": 0}, lf.InvalidArgumentError),
    "steps-float": ({"steps": 10.0}, TypeError),
    "steps-too-many": ({"steps": 10**12}, lf.InvalidArgumentError),   # memory of the samples
    "save_every-zero": ({"save_every": 0}, lf.InvalidArgumentError),
    "method-unknown": ({"method": "euler"}, lf.UnsupportedMethodError),
    "method-int": ({"method": 3}, TypeError),
    "t0-inf": ({"t0": float("inf")}, lf.InvalidArgumentError),
    "states-nan": ({"states": np.where(np.arange(18).reshape(6, 3) == 16, np.nan, 1.0)},
                   lf.NonFiniteError),
    "states-shape": ({"states": np.ones((6, 2))}, lf.ShapeError),
    "states-complex": ({"states": np.ones((6, 3), complex)}, TypeError),
    "attitude-shape": ({"attitude": np.eye(4)}, lf.ShapeError),
    "attitude-member": ({"attitude": np.concatenate([rotations(4), 2 * rotations(2)])},
                        lf.NotInGroupError),
    "attitude-pendulum": ({"system": lf.Pendulum(1.0, 1.0, 9.81), "states": np.ones((6, 2)),
                           "attitude": np.eye(3)}, lf.InvalidArgumentError),
    "state-constraint-member": ({"system": lf.SphericalPendulum(), "states": np.array(
        [[0, 0, -1.0, 0, 0, 0]] * 4 + [[0, 0, -2.0, 0, 0, 0]] * 2)}, lf.InvalidArgumentError),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_typed_errors_before_any_task(case, calls, monkeypatch):
    changes, expected = BAD[case]
    args = dict(system=BODY, states=members(6), dt=0.01, steps=10, method=None, save_every=1,
                t0=0.0, attitude=None)
    args.update(changes)
    built = []
    import dask
    monkeypatch.setattr(dask, "delayed", lambda *a, **k: built.append(1))
    with pytest.raises(expected) as err:
        ensemble.integrate(args.pop("system"), args.pop("states"), args.pop("dt"),
                           args.pop("steps"), **args, chunks=2)
    assert built == [] and calls == []                   # no task was even built
    a = {"system": BODY, "states": members(6), "dt": 0.01, "steps": 10, **changes}
    with pytest.raises(Exception) as ref:                # lf.integrate raises the same type
        lf.integrate(a.pop("system"), a.pop("states"), **a)
    assert type(err.value) is type(ref.value), (err.value, ref.value)
    if case in ("attitude-member", "state-constraint-member"):
        assert "member 4" in str(err.value)              # named by its index in the ensemble


@pytest.mark.parametrize("chunks, expected", [(0, lf.InvalidArgumentError), (2.0, TypeError),
                                               ("2", TypeError), (True, TypeError)])
def test_bad_chunks(chunks, expected, calls):
    with pytest.raises(expected, match="chunks"):
        ensemble.integrate(BODY, members(4), 0.01, 10, chunks=chunks)
    assert calls == []


def test_one_task_too_large_is_refused_in_the_driver():
    # 100 members x 2e7 samples x 3 > 2^32 entries in one task: refused, naming the chunks;
    # one member per task fits (the whole lazy Dataset is never held by one process)
    with pytest.raises(lf.InvalidArgumentError, match="chunks=100"):
        ensemble.integrate(BODY, members(100), 0.01, 20_000_000, chunks=100)
    ds = ensemble.integrate(BODY, members(100), 0.01, 20_000_000, chunks=1)
    assert ds.states.shape == (100, 20_000_001, 3)


def _explodes(q, p):
    if abs(q[0]) > 1.2:
        raise RuntimeError("left the box")
    return q, p


def test_run_error_is_raised_by_compute_naming_the_members():
    system = lf.Canonical(_h, _explodes, 1)
    state = np.array([[0.1, 0.0], [0.2, 0.0], [0.3, 0.0], [0.0, 1.5]])   # member 3 leaves
    ds = ensemble.integrate(system, state, 0.1, 30, chunks=2)             # no error yet
    for _ in range(5):   # concurrent tasks of one system: the error is never taken by the other
        with pytest.raises(RuntimeError, match="left the box") as err:
            ds.compute()
        assert any("members 2 to 3" in n for n in getattr(err.value, "__notes__", []))


def test_errors_name_the_member_by_its_index_in_the_ensemble():
    m = members(10)
    m[7] = [1e155, 2e155, 1e155]          # overflows in the first step
    for chunks in (6, 1, 10):             # member 7 is member 1 of its task, alone, or member 7
        with pytest.raises(lf.LeftDomainError, match=r"^batch member 7: RigidBody state"):
            ensemble.integrate(BODY, m, 0.01, 10, chunks=chunks).compute()
    # a NaN in a state: its member and its entry there (not the flat index 63 of (X, P))
    body = lf.PseudoRigidBody(3, lf.potentials.Harmonic(1.0))
    X, P = np.tile(np.eye(3), (10, 1, 1)), np.zeros((10, 3, 3))
    P[7, 0, 1] = np.nan
    expected = r"^batch member 7: P contains a non-finite value \(NaN or inf\) at \(0, 1\)$"
    with pytest.raises(lf.NonFiniteError, match=expected):
        ensemble.integrate(body, (X, P), 0.01, 10, chunks=3)
    with pytest.raises(lf.NonFiniteError, match=expected):
        lf.integrate(body, (X, P), 0.01, 10)
    m = members(10)
    m[7, 2] = np.inf
    expected = r"^batch member 7: state0 contains a non-finite value \(NaN or inf\) at index 2$"
    with pytest.raises(lf.NonFiniteError, match=expected):
        ensemble.integrate(BODY, m, 0.01, 10, chunks=3)
    r = rotations(10)
    r[7, 1, 2] = np.nan                   # not "state ... at index 8" of the lifted state
    expected = r"^batch member 7: attitude contains a non-finite value \(NaN or inf\) at \(1, 2\)$"
    with pytest.raises(lf.NonFiniteError, match=expected):
        ensemble.integrate(BODY, members(10), 0.01, 10, chunks=3, attitude=r)
    with pytest.raises(lf.NonFiniteError, match=expected):
        lf.integrate(BODY, members(10), 0.01, 10, attitude=r)
    # observables of a (member, time) array name the item by both indices
    states = np.ones((10, 4, 3))
    states[7, 2, 1] = np.nan
    with pytest.raises(lf.NonFiniteError, match=r"^states\[7, 2\] contains .* at index 1$"):
        BODY.energy(states)
    # an observable of a task's states that overflows: its item, and the member it belongs to
    m = members(10)
    m[7] = [1e155, 2e155, 1e155]          # its energy overflows, its tiny steps do not
    with pytest.raises(lf.InvalidArgumentError, match=r"^invalid states\[1, 0\]: state: ") as e:
        ensemble.integrate(BODY, m, 1e-160, 2, chunks=6).compute()
    assert "states[i, j] is sample j of member 6 + i" in e.value.__notes__[-1]


def test_a_duck_typed_system_is_refused_before_any_task(calls):
    class Duck:        # speaks lf.integrate's protocol, but a task runs System._run
        _normalize_state, _start = BODY._normalize_state, BODY._start

    with pytest.raises(TypeError, match="expected a lieflow.System"):
        ensemble.integrate(Duck(), members(4), 0.01, 10)
    assert calls == []


def test_threaded_ctrl_c_stops_promptly(calls):
    # 64 tasks of 1000 bodies x 2·10^4 steps: a task ends well within the 1 s below on a slow
    # machine (~0.2 s at 10 ns per body-step), and the whole run outlasts the 0.3 s before the
    # interrupt on a fast one (~2 s at 1.5 ns per body-step with two threads).
    m = members(64_000)
    ds = ensemble.integrate(BODY, m, 0.01, 20_000, save_every=20_000, chunks=1000)
    t = _interrupted_compute(ds.compute, after=0.3)
    assert t < 2.0                                      # not the whole run
    time.sleep(1.0)                                     # the running tasks end their chunk
    started = len(calls)
    time.sleep(0.5)
    assert len(calls) == started < 64                   # and no further task starts


def _interrupted_compute(compute, after, before=None):
    """Runs compute() in the main thread, delivers SIGINT after `after` s (calling `before()`
    first, in the timer's thread); asserts that a KeyboardInterrupt ended it, returns the
    seconds from the start to the interrupt."""
    state = {"inside": True, "late": False}

    def handler(signum, frame):
        if state["inside"]:
            raise KeyboardInterrupt
        state["late"] = True

    main = threading.main_thread().ident

    def interrupt():
        if before is not None:
            before()
        signal.pthread_kill(main, signal.SIGINT)

    timer = threading.Timer(after, interrupt)
    old = signal.signal(signal.SIGINT, handler)
    try:
        t = time.monotonic()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            try:
                compute()
            finally:
                state["inside"] = False
        t = time.monotonic() - t
    finally:
        timer.cancel()
        timer.join()
        signal.signal(signal.SIGINT, old)
    assert not state["late"]
    return t


# ------------------------------------------------------------------ sweeps (threaded)

def test_sweep_scalars_equal_single_runs():
    values = [2.5, 3.0, 4.0]
    state = [1.0, 0.5, -0.3]
    ds = ensemble.sweep(lambda i3: lf.RigidBody([1.0, 2.0, i3]), values, state, 0.01, 30,
                        save_every=7, t0=0.5)
    assert ds.states.dims == ("param", "time", "component")
    assert list(ds.param.values) == values and "param_value" not in ds
    assert ds.attrs["method"] == "splitting" and ds.attrs["make_system"] == (
        "test_sweep_scalars_equal_single_runs.<locals>.<lambda>")
    ds = ds.compute()
    for v in values:
        traj = lf.integrate(lf.RigidBody([1.0, 2.0, v]), state, 0.01, 30, save_every=7, t0=0.5)
        one = ds.sel(param=v)
        assert np.array_equal(one.states.values, traj.states)
        assert np.array_equal(one.energy.values, traj.energy())
        assert np.array_equal(one.invariants.values, traj.invariants())
        assert np.array_equal(one.final_state.values, traj.final_state)
        assert np.array_equal(ds.time.values, traj.t)


def test_sweep_vectors_and_objects():
    inertias = np.array([[1.0, 2.0, 3.0], [1.0, 2.0, 5.0]])
    ds = ensemble.sweep(lf.RigidBody, inertias, [1.0, 0.5, -0.3], 0.01, 10, "rk4").compute()
    assert list(ds.param.values) == [0, 1]
    assert ds.param_value.dims == ("param", "param_dim_0")
    assert np.array_equal(ds.param_value.values, inertias)
    for i, inertia in enumerate(inertias):
        traj = lf.integrate(lf.RigidBody(inertia), [1.0, 0.5, -0.3], 0.01, 10, method="rk4")
        assert np.array_equal(ds.states.values[i], traj.states)
    kw = [{"mass": 1.0, "length": 1.0, "g": 9.81}, {"mass": 2.0, "length": 0.5, "g": 9.81}]
    ds = ensemble.sweep(lambda k: lf.Pendulum(**k), kw, [0.3, 0.0], 0.01, 10).compute()
    assert list(ds.param.values) == [0, 1] and ds.param_value.values[1] == repr(kw[1])
    assert ds.invariants.shape == (2, 11, 0)


def test_sweep_bad_input_before_any_task():
    made = []

    def make(i3):
        made.append(i3)
        return lf.RigidBody([1.0, 2.0, i3])

    state = [1.0, 0.5, -0.3]
    cases = [
        (lambda: ensemble.sweep(3, [1.0], state, 0.01, 10), TypeError),
        (lambda: ensemble.sweep(make, 3.0, state, 0.01, 10), TypeError),
        (lambda: ensemble.sweep(make, "abc", state, 0.01, 10), TypeError),
        (lambda: ensemble.sweep(make, [], state, 0.01, 10), lf.InvalidArgumentError),
        (lambda: ensemble.sweep(make, [3.0, 4.0], state, 0.0, 10), lf.InvalidArgumentError),
        (lambda: ensemble.sweep(make, [3.0, 4.0], state, 0.01, 0), lf.InvalidArgumentError),
        (lambda: ensemble.sweep(make, [3.0, 4.0], state, 0.01, 10, "x"),
         lf.UnsupportedMethodError),
        (lambda: ensemble.sweep(make, [3.0, 4.0], [1.0, 2.0], 0.01, 10), lf.ShapeError),
        (lambda: ensemble.sweep(make, [3.0, 4.0], [1.0, np.nan, 2.0], 0.01, 10),
         lf.NonFiniteError),
        (lambda: ensemble.sweep(make, [3.0, 4.0], members(2), 0.01, 10),
         lf.InvalidArgumentError),
        (lambda: ensemble.sweep(make, [-1.0, 4.0], state, 0.01, 10), lf.InvalidArgumentError),
        (lambda: ensemble.sweep(lambda p: "no system", [1.0], state, 0.01, 10), TypeError),
    ]
    for call, expected in cases:
        with pytest.raises(expected):
            call()
    assert made == [3.0] * 4 + [-1.0]     # only params[0], in the driver, after the arguments


def test_sweep_error_of_a_later_value_at_compute():
    ds = ensemble.sweep(lambda i3: lf.RigidBody([1.0, 2.0, i3]), [3.0, -1.0],
                        [1.0, 0.5, -0.3], 0.01, 10)
    with pytest.raises(lf.InvalidArgumentError) as err:
        ds.compute()
    assert any("params[1] = -1.0" in n for n in err.value.__notes__)


# ------------------------------------------------------------------ without dask

def test_lieflow_imports_without_dask_and_says_how_to_install():
    code = textwrap.dedent("""
        import sys
        for name in ("dask", "distributed", "xarray"):
            sys.modules[name] = None          # as if not installed
        import lieflow as lf
        assert "dask" not in [m for m in sys.modules if sys.modules[m] is not None]
        try:
            lf.ensemble.integrate(lf.RigidBody([1, 2, 3]), [[1.0, 0.5, -0.3]], 0.01, 10)
        except ImportError as e:
            print(e)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stderr
    assert "pip install lieflow[ensemble]" in out.stdout


# ------------------------------------------------------------------ dask.distributed

@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=50)
    c = distributed.Client(cluster, set_as_default=False)
    try:
        yield c
    finally:
        c.close()
        cluster.close()


def scheduler_tasks(client):
    return client.run_on_scheduler(lambda dask_scheduler: (len(dask_scheduler.tasks),
                                                           dask_scheduler.transition_counter))


def processing(client):
    return sum(len(v) for v in client.processing().values())


def idle(client, timeout=10.0):
    """Waits until the scheduler holds no task (released futures are forgotten asynchronously);
    returns (tasks, transition counter)."""
    deadline = time.monotonic() + timeout
    while scheduler_tasks(client)[0] and time.monotonic() < deadline:
        time.sleep(0.05)
    return scheduler_tasks(client)


def test_distributed_equals_batch_bit_for_bit(client):
    m, r = members(50), rotations(50)
    with client.as_current():
        assert ensemble.default_chunks(50) == 7           # ceil(50 / (4 x 2 worker threads))
        ds = ensemble.integrate(BODY, m, 0.01, 40, save_every=6, attitude=r)
        assert ds.states.data.numblocks[0] == 8
        out = ds.compute()
    assert_equal_to_batch(out, lf.integrate(BODY, m, 0.01, 40, save_every=6, attitude=r))


def test_distributed_bad_input_submits_nothing(client):
    before = idle(client)
    assert before[0] == 0
    with client.as_current():
        for kwargs, expected in [({"method": "euler"}, lf.UnsupportedMethodError),
                                 ({"states": np.ones((6, 2))}, lf.ShapeError),
                                 ({"dt": -1.0}, lf.InvalidArgumentError),
                                 ({"attitude": 2 * rotations(6)}, lf.NotInGroupError)]:
            args = {"states": members(6), "dt": 0.01, **kwargs}
            with pytest.raises(expected):
                ensemble.integrate(BODY, args.pop("states"), args.pop("dt"), 10, **args)
        with pytest.raises(lf.InvalidArgumentError):
            ensemble.sweep(lambda i3: lf.RigidBody([1.0, 2.0, i3]), [-1.0], [1.0, 0.5, -0.3],
                           0.01, 10)
    assert scheduler_tasks(client) == before              # no task, no transition
    assert len(client.who_has()) == 0


def test_distributed_sweep(client):
    values = [2.5, 3.0, 4.0, 6.0]
    state = [1.0, 0.5, -0.3]
    with client.as_current():
        ds = ensemble.sweep(lambda i3: lf.RigidBody([1.0, 2.0, i3]), values, state, 0.01, 50,
                            save_every=10).compute()
    for v in values:
        traj = lf.integrate(lf.RigidBody([1.0, 2.0, v]), state, 0.01, 50, save_every=10)
        assert np.array_equal(ds.states.sel(param=v).values, traj.states)
        assert np.array_equal(ds.final_state.sel(param=v).values, traj.final_state)


def _long_ensemble(b=48_000, steps=1500, chunks=6000):
    """8 tasks of 6000 bodies x `steps` steps: ~0.3-1 s each for 1500 steps."""
    m = members(b, seed=3)
    return m, ensemble.integrate(BODY, m, 0.01, steps, save_every=500, chunks=chunks)


def test_distributed_worker_killed_mid_run(client):
    m, ds = _long_ensemble()
    pids = client.run(os.getpid)
    future = client.compute(ds)
    deadline = time.monotonic() + 30
    busy = {}
    while not busy and time.monotonic() < deadline:   # a worker in the middle of a task
        busy = {w: ts for w, ts in client.processing().items() if ts}
        time.sleep(0.05)
    assert busy, "no task started"
    time.sleep(0.2)
    victim = next(iter(busy))
    os.kill(pids[victim], signal.SIGKILL)
    out = future.result(timeout=120)                   # the lost tasks ran again: no hang
    traj = lf.integrate(BODY, m, 0.01, 1500, save_every=500)
    assert_equal_to_batch(out, traj)
    client.wait_for_workers(2, timeout=60)
    assert pids[victim] not in client.run(os.getpid).values()
    del future


def test_distributed_ctrl_c_cancels_the_tasks(client):
    client.wait_for_workers(2, timeout=60)
    _, ds = _long_ensemble(steps=4000)      # ~4 s of work on 2 workers: interrupted at 0.5 s
    busy = []
    with client.as_current():
        _interrupted_compute(ds.compute, after=0.5, before=lambda: busy.append(processing(client)))
    assert busy[0] > 0                                 # tasks were running when Ctrl-C came
    deadline = time.monotonic() + 5
    while processing(client) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert processing(client) == 0                     # the scheduler cancelled them
    assert idle(client, timeout=5)[0] == 0             # and forgot them
    with client.as_current():                          # the cluster works on
        small = ensemble.integrate(BODY, members(5), 0.01, 10).compute()
    assert_equal_to_batch(small, lf.integrate(BODY, members(5), 0.01, 10))
