"""lieflow.System, the one base class: the protocol every system class inherits (methods, fields,
state parsing, invariants), pickling, the resumable native run, and the driver bugs the one
mechanics core ended (chunk-independent results, absolute error times, the caller's spelling)."""

import pickle

import numpy as np
import pytest

import lieflow as lf

pot = lf.potentials
M0 = np.array([1.0, 0.5, -0.3])


def rotation(w):
    return lf.lie.so3_exp(np.asarray(w, float))


def systems():
    """One instance of every system class with an initial state and a method."""
    x0 = np.diag([1.2, 1.0, 0.8]) + 0.05 * np.arange(9.0).reshape(3, 3) / 9
    p0 = 0.1 * np.array([[0.0, 1.0, -0.5], [0.3, 0.1, 0.4], [-0.2, 0.6, 0.0]])
    return [
        (lf.RigidBody([1, 2, 3]), M0, "splitting4"),
        (lf.RigidBody(np.diag([3.0, 1.0, 2.0])), M0, "lgvi"),
        (lf.GeneralizedRigidBody([1.0, 2.0, 3.0, 4.0]), np.arange(1.0, 7.0) / 6, "isospectral"),
        (lf.HeavyTop([1, 2, 3], 0.7, chi=[0.2, -0.3, 1.0]), (M0, [0.1, 0.2, np.sqrt(0.95)]),
         "splitting"),
        (lf.SphericalPendulum(2.0, 1.5, 9.81), None, "splitting6"),
        (lf.PseudoRigidBody(3, pot.SaintVenantKirchhoff(1.0, 2.0) + pot.Volumetric(0.5)),
         (x0, p0), "verlet4"),
        (lf.PseudoRigidBody(3, pot.SaintVenantKirchhoff(1.0, 2.0), check_det=False), (x0, p0),
         "reduced"),
        (lf.Pendulum(1.0, 1.0, 9.81), [1.2, 0.3], "gauss6"),
        (lf.SphereParticle(2.0, 1.5, 9.81), None, "rattle"),
        (lf.RollingDisk(1.0, 0.5, 0.125, 0.0625, spring=0.4), None, "nonholonomic"),
    ]


def initial(system, state0):
    """The given state, or one built by the system from spherical or rolling coordinates."""
    if state0 is not None:
        return state0
    if isinstance(system, lf.RollingDisk):
        return system.state([0.1, -0.2, 0.3, 0.7], 2.0, 0.5)
    pendulum = lf.SphericalPendulum(2.0, 1.5, 9.81)
    z = pendulum.state_from_spherical(0.8, 0.1, 0.3, 1.2)
    return z if isinstance(system, lf.SphericalPendulum) else system.from_spherical(z)


@pytest.mark.parametrize("system, state0, method", systems())
def test_pickling_round_trip_gives_identical_trajectories(system, state0, method):
    state0 = initial(system, state0)
    copy = pickle.loads(pickle.dumps(system))
    assert type(copy) is type(system) and repr(copy) == repr(system)
    assert copy.methods() == system.methods() and copy.state_dim == system.state_dim
    a = lf.integrate(system, state0, dt=0.01, steps=200, method=method, save_every=10)
    b = lf.integrate(copy, state0, dt=0.01, steps=200, method=method, save_every=10)
    np.testing.assert_array_equal(a.states, b.states)


@pytest.mark.parametrize("system, state0, method", systems())
def test_every_system_speaks_the_protocol(system, state0, method):
    assert isinstance(system, lf.System)
    assert method in system.methods() and type(system).methods() == system.methods()
    z, batched = system._normalize_state(initial(system, state0))
    assert z.shape == (1, system.state_dim) and not batched
    views = system._fields(z[0])
    assert list(views) == system.fields
    assert sum(np.asarray(v).size for v in views.values()) >= system.state_dim
    c = system.invariants(np.stack([z[0], z[0]]))
    names = system.invariant_names
    assert len(names) == c.shape[-1] == len(set(names)) and all(names)
    assert c.shape[0] == 2 and np.array_equal(c, system.casimirs(np.stack([z[0], z[0]])))
    tr = lf.integrate(system, z[0], dt=0.01, steps=50, method=method, save_every=10)
    inv = tr.invariants()
    if inv.size:
        assert np.abs(inv - inv[0]).max() < 1e-12 * max(1.0, np.abs(inv).max())
    assert type(system).__name__ in repr(system)


def test_the_field_tuple_form_is_the_flat_state():
    top = lf.HeavyTop([1, 2, 3], 0.7)
    g = [0.1, 0.2, np.sqrt(0.95)]
    z, _ = top._normalize_state((M0, g))
    np.testing.assert_array_equal(z[0], np.concatenate([M0, g]))
    zz, batched = top._normalize_state(([M0, M0], [g, g]))
    assert batched and zz.shape == (2, 6)
    # Two flat 6-vectors are a batch, not a pair (M, Gamma).
    zz, batched = top._normalize_state([np.concatenate([M0, g])] * 2)
    assert batched and zz.shape == (2, 6)
    so4 = lf.GeneralizedRigidBody([1.0, 2.0, 3.0, 4.0])
    assert so4.fields == ["M"] and so4._fields(np.arange(6.0))["M"].shape == (4, 4)


def test_integration_resumes_one_native_run():
    body = lf.RigidBody([1, 2, 3])
    z0, _ = body._normalize_state(M0)
    run = body._start(z0, None, 0.01, "splitting", 10, threads=1)
    parts = [run.advance(n)[0] for n in (7, 13, 25, 55)]
    assert [p.shape[1] for p in parts] == [0, 2, 2, 6] and run.time == pytest.approx(1.0)
    one = lf.integrate(body, M0, dt=0.01, steps=100, method="splitting", save_every=10)
    np.testing.assert_array_equal(np.concatenate(parts, axis=1)[0], one.states[1:])
    np.testing.assert_array_equal(run.state()[0][0], one.final_state)
    with pytest.raises(lf.InvalidArgumentError, match="steps"):
        run.advance(0)


def test_threads_argument_gives_the_same_batch():
    body = lf.RigidBody([1, 2, 3])
    batch = M0 * np.linspace(0.5, 1.5, 6)[:, None]
    runs = [lf.integrate(body, batch, dt=0.01, steps=300, save_every=30, threads=t)
            for t in (None, 1, 2)]
    for r in runs[1:]:
        np.testing.assert_array_equal(r.states, runs[0].states)
    with pytest.raises(lf.InvalidArgumentError, match="threads"):
        lf.integrate(body, batch, dt=0.01, steps=10, threads=0)


def test_rk4_attitude_run_does_not_depend_on_chunking():
    # RK4 lets the attitude drift off SO(3); each chunk used to re-validate it and blame the
    # user's valid input. Validation is now once per run, and chunks resume the same run.
    top = lf.HeavyTop([1, 1, 0.4], 1.0)
    r0 = rotation([0.5, 0.0, 0.0])
    state = top.state([0.0, 0.0, 8.0], attitude=r0)
    kw = dict(dt=1e-3, steps=2_000_000, method="rk4", attitude=r0, save_every=1000)
    chunked = lf.integrate(top, state, **kw)
    one = lf.integrate(top, state, chunk_steps=2_000_000, **kw)
    np.testing.assert_array_equal(chunked.states, one.states)
    np.testing.assert_array_equal(chunked.attitude, one.attitude)
    r = chunked.final_attitude
    assert np.abs(r.T @ r - np.eye(3)).max() > 1e-12   # RK4 does drift: it was not re-projected


def test_left_domain_names_the_absolute_step_and_time_in_python_spelling():
    x = np.diag([1.0, 1.5, 2.0])
    body = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    # X(t) = X0 (cos t − sin t) leaves GL+(3) at t = π/4 ≈ 0.7854: step 786 with dt = 1e-3.
    for method in ["verlet", "verlet6"]:
        for chunk in [100, 10_000]:
            with pytest.raises(lf.LeftDomainError) as e:
                lf.integrate(body, (x, -x), dt=1e-3, steps=2000, method=method,
                             chunk_steps=chunk)
            msg = str(e.value)
            assert "t = 0.786" in msg and "step 786" in msg, msg
            assert "check_det=False" in msg and "check_det = false" not in msg
    gas = lf.PseudoRigidBody(3, potential=pot.Volumetric(0.1))
    with pytest.raises(lf.LeftDomainError, match="volumetric") as e:   # a step jumps det X < 0
        lf.integrate(gas, (x, -30 * x), dt=0.05, steps=20)
    assert "check_det" not in str(e.value) and "t = 0.05:" in str(e.value)


def test_batch_errors_name_the_member():
    body = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    x = np.diag([1.0, 1.5, 2.0])
    xs = np.stack([x, x, x])
    ps = np.stack([0 * x, -x, 0 * x])
    with pytest.raises(lf.LeftDomainError, match="batch member 1: "):   # t = π/4; the others π/2
        lf.integrate(body, (xs, ps), dt=1e-3, steps=1000)


def test_the_methods_of_the_mechanics_core_from_python():
    # Gauss–Legendre on the canonical pendulum: orders 2, 4, 6 against the elliptic solution.
    pendulum = lf.Pendulum()
    exact = pendulum.exact_solution(1.2, 2.0)
    for method, order, n in [("midpoint", 2, 200), ("gauss4", 4, 20), ("gauss6", 6, 10)]:
        err = [np.abs(lf.integrate(pendulum, [1.2, 0.0], dt=2.0 / k, steps=k,
                                   method=method).final_state - exact).max() for k in (n, 2 * n)]
        assert abs(np.log2(err[0] / err[1]) - order) < 0.2, (method, err)
    # RATTLE keeps the sphere and the tangency; the rolling disk keeps its constraints.
    particle = lf.SphereParticle(2.0, 1.5)
    z = particle.from_spherical(lf.SphericalPendulum(2.0, 1.5).state_from_spherical(0.8, 0, 0, 1.5))
    tr = lf.integrate(particle, z, dt=0.01, steps=10_000, save_every=100)
    q, p = tr.q, tr.p
    assert np.abs(np.linalg.norm(q, axis=1) - 1.5).max() < 1e-13
    assert np.abs(np.einsum("ki,ki->k", q, p)).max() < 1e-12
    disk = lf.RollingDisk(1.0, 0.5, 0.125, 0.0625, spring=0.4, tilt=0.1)
    tr = lf.integrate(disk, disk.state([0, 0, 0, 0.7], 2.0, 0.5), dt=0.01, steps=10_000,
                      save_every=100)
    assert disk.constraint_residual(tr.states).max() < 1e-13


def _system_classes():
    return sorted((c for c in vars(lf).values()
                   if isinstance(c, type) and issubclass(c, lf.System) and c is not lf.System),
                  key=lambda c: c.__name__)


def _documented_methods(doc):
    """The method names of a class docstring's "Methods:" sentence, in order (parenthesised
    remarks dropped; the sentence ends at the first period outside parentheses)."""
    import re
    start = re.search(r"\bMethods?:", doc)
    assert start, "no 'Methods:' in the docstring"
    text, depth, out = doc[start.end():], 0, []
    for i, ch in enumerate(text):
        depth += (ch == "(") - (ch == ")")
        if depth == 0 and ch == "." and (i + 1 == len(text) or text[i + 1].isspace()):
            break
        if depth == 0 and ch != ")":
            out.append(ch)
    return re.findall(r"[a-z][a-z0-9_]*", "".join(out))


@pytest.mark.parametrize("cls", [c for c in _system_classes() if c is not lf.Forced],
                         ids=lambda c: c.__name__)
def test_the_docstring_lists_the_catalog_of_its_class(cls):
    # The "Methods:" sentence names every method of the class's catalog, the default first,
    # in the catalog's order (Forced's follow the system it wraps: its docstring gives the rule).
    assert _documented_methods(cls.__doc__) == cls.methods()


def test_the_method_list_of_a_forced_system_is_the_rule_of_its_docstring():
    forced = lf.Forced(lf.HeavyTop([1, 2, 3], 0.5, [0, 0, 1]), lambda t, z: np.zeros(3))
    free = [m for m in lf.HeavyTop.methods() if m in ("splitting", "lgvi")]
    assert forced.methods()[:3] == [free[0], free[0] + "4", free[0] + "6"]
    assert lf.Forced.methods() == lf.Forced(lf.Pendulum(), damping=0.1).methods()


def test_the_base_class_has_no_method_list_of_its_own():
    assert callable(lf.System.methods)       # autodoc and getattr still see it
    with pytest.raises(TypeError, match="base class"):
        lf.System.methods()
    with pytest.raises(TypeError, match="no arguments"):
        lf.RigidBody.methods(1)


def test_a_whole_run_is_refused_once_the_run_has_moved():
    body = lf.RigidBody([1, 2, 3])
    run = body._start(np.array([1.0, 0.5, -0.3]), None, 0.1, None, 1)
    run._chunk(2)
    with pytest.raises(lf.InvalidArgumentError, match="from its start"):
        run._whole(1)
    whole = body._start(np.array([1.0, 0.5, -0.3]), None, 0.1, None, 1)._whole(2)
    traj = lf.integrate(body, np.array([1.0, 0.5, -0.3]), dt=0.1, steps=2, chunk_steps=1)
    assert np.array_equal(whole[1], traj.states) and np.array_equal(whole[0], traj.t)
