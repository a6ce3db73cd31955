"""User-defined systems (issue 15): lf.Canonical, lf.Separable and lf.LiePoisson from Python
callables (and LiePoisson's native quadratic path) against the built-in systems and closed forms;
Casimirs of the orbit-preserving methods; observed orders; errors of the callables (exceptions
re-raised naming the step, NaN -> NonFiniteError, wrong shapes -> ShapeError); pickling."""

import pickle

import numpy as np
import pytest

import lieflow as lf

INERTIA = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])


# --- module-level callables (native code calls them; they pickle by reference) ---

def osc_h(q, p):
    return 0.5 * float(p @ p + q @ q)


def osc_grad(q, p):
    return q, p


def pend_h(q, p):
    return 0.5 * p[0] ** 2 - 9.81 * np.cos(q[0])


def pend_u(q):
    return -9.81 * np.cos(q[0])


def pend_du(q):
    return np.array([9.81 * np.sin(q[0])])


def rb_h(m):
    return 0.5 * float(np.sum(m * m / INERTIA))


def rb_grad(m):
    return m / INERTIA


def casimir(m):
    return float(m @ m)


def returns_nan(*args):
    return np.full(3, np.nan)


def returns_short(q, p):
    return q


def returns_str(q, p):
    return "no"


def fails_below(q, p):
    if q[0] < -0.5:
        raise ZeroDivisionError("q below -0.5")
    return q, p


def so_constants(n):
    """Structure constants of so(n) in the e_ij basis from lf.lie (independent of the system)."""
    d = n * (n - 1) // 2
    basis = [lf.lie.hat_n(np.eye(d)[i]) for i in range(d)]
    return np.array([[lf.lie.vee_n(lf.lie.ad(a, b)) for b in basis] for a in basis])


def kirchhoff_matrix():
    a, c = np.diag([1.0, 0.7, 0.4]), np.diag([2.0, 1.5, 1.2])
    b = np.array([[0.1, 0.02, 0.0], [0.02, -0.05, 0.03], [0.0, 0.03, 0.08]])
    return np.block([[a, b], [b.T, c]])


# --- Lie–Poisson ---

@pytest.mark.parametrize("method", ["rkmk4", "rk4"])
def test_so3_reproduces_the_rigid_body_with_the_same_method(method):
    body = lf.RigidBody(INERTIA)
    ref = lf.integrate(body, M0, dt=0.01, steps=2000, method=method, save_every=50).states
    for sys in (lf.LiePoisson("so3", np.diag(1 / INERTIA)), lf.LiePoisson("so3", rb_h, rb_grad)):
        got = lf.integrate(sys, M0, dt=0.01, steps=2000, method=method, save_every=50).states
        np.testing.assert_allclose(got, ref, atol=1e-13, rtol=0)
    assert lf.LiePoisson("so3", rb_h).energy(M0) == pytest.approx(body.energy(M0), rel=1e-15)


@pytest.mark.parametrize("method, order", [("rkmk4", 4), ("midpoint", 2), ("midpoint4", 4)])
def test_so3_orbit_methods_against_the_exact_solution(method, order):
    body = lf.RigidBody(INERTIA)
    sys = lf.LiePoisson("so3", rb_h, rb_grad)
    exact = body.exact_solution(M0, 2.0)
    err = [np.abs(lf.integrate(sys, M0, dt=2.0 / n, steps=n, method=method).final_state
                  - exact).max() for n in (50, 100)]
    assert abs(np.log2(err[0] / err[1]) - order) < 0.2, err
    tr = lf.integrate(sys, M0, dt=0.05, steps=5000, method=method, save_every=50)
    c = tr.invariants()[:, 0]
    assert np.abs(c / c[0] - 1).max() < 5e-14


def test_rk4_does_not_keep_the_casimir():
    tr = lf.integrate(lf.LiePoisson("so3", rb_h, rb_grad), M0, dt=0.05, steps=5000,
                      method="rk4", save_every=50)
    c = tr.invariants()[:, 0]
    assert np.abs(c / c[0] - 1).max() > 1e-10


def test_se3_casimirs_are_kept_and_paths_agree():
    z0 = np.array([0.3, -0.5, 0.8, 1.0, 0.4, -0.6])
    native = lf.LiePoisson("se3", kirchhoff_matrix())
    assert native.fields == ["M", "Gamma"] and native.is_quadratic
    for method in ("rkmk4", "midpoint", "midpoint4"):
        tr = lf.integrate(native, z0, dt=0.02, steps=5000, method=method, save_every=50)
        c = tr.invariants()
        assert np.abs(c / c[0] - 1).max() < 1e-13, method
        assert np.allclose(c[0], [z0[3:] @ z0[3:], z0[:3] @ z0[3:]])
    python = lf.LiePoisson("se3", kirchhoff_h)
    a = lf.integrate(native, z0, dt=0.01, steps=300).states
    b = lf.integrate(python, z0, dt=0.01, steps=300).states
    np.testing.assert_allclose(a, b, atol=1e-10)


def kirchhoff_h(mu):
    return 0.5 * float(mu @ kirchhoff_matrix() @ mu)


def test_so_n_structure_constants_equal_the_built_in_algebra():
    n = 4
    c = so_constants(n)
    j = np.array([1.0, 2.0, 3.0, 4.5])
    w = np.array([1 / (j[a] + j[b]) for a in range(n) for b in range(a + 1, n)])
    builtin = lf.LiePoisson(("so", n), np.diag(w))
    np.testing.assert_array_equal(builtin.structure_constants(), c)
    generic = lf.LiePoisson(c, np.diag(w))
    body = lf.GeneralizedRigidBody(j)
    z0 = np.array([0.3, -0.2, 0.5, 0.1, 0.4, -0.6])
    for method in ("rkmk4", "midpoint", "midpoint4", "rk4"):
        x = lf.integrate(builtin, z0, dt=0.01, steps=1000, method=method).states
        y = lf.integrate(generic, z0, dt=0.01, steps=1000, method=method).states
        np.testing.assert_allclose(x, y, atol=1e-12, rtol=0)
    x = lf.integrate(body, z0, dt=0.01, steps=1000, method="rkmk4").states
    y = lf.integrate(builtin, z0, dt=0.01, steps=1000, method="rkmk4").states
    np.testing.assert_allclose(x, y, atol=1e-12, rtol=0)
    assert builtin.invariants(z0) == pytest.approx(body.invariants(z0), rel=1e-15)
    assert generic.invariants(z0).shape == (0,)


def test_lie_poisson_arguments():
    with pytest.raises(lf.InvalidArgumentError):
        lf.LiePoisson("so4", np.eye(3))
    with pytest.raises(lf.InvalidArgumentError):
        lf.LiePoisson(("so", 1), np.eye(1))
    with pytest.raises(lf.ShapeError):
        lf.LiePoisson("so3", np.eye(4))
    with pytest.raises(lf.InvalidArgumentError, match="symmetric"):
        lf.LiePoisson("so3", np.array([[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]]))
    with pytest.raises(lf.InvalidArgumentError, match="gradient"):
        lf.LiePoisson("so3", np.eye(3), rb_grad)
    with pytest.raises(TypeError, match="hamiltonian"):
        lf.LiePoisson("so3", "H")
    with pytest.raises(lf.ShapeError):
        lf.LiePoisson(np.zeros((2, 2)), np.eye(2))
    bad = so_constants(3).copy()
    bad[0, 1, 2] = -bad[0, 1, 2]
    with pytest.raises(lf.InvalidArgumentError, match="antisymmetric"):
        lf.LiePoisson(bad, np.eye(3))
    with pytest.raises(TypeError, match="casimirs"):
        lf.LiePoisson("so3", rb_h, casimirs=[1.0])
    sys = lf.LiePoisson("so3", rb_h, casimirs=[casimir, rb_h])
    np.testing.assert_allclose(sys.invariants(M0), [M0 @ M0, rb_h(M0)])
    assert lf.LiePoisson.methods() == ["rkmk4", "midpoint", "midpoint4", "rk4"]


# --- canonical and separable systems ---

def test_canonical_oscillator_closed_form_and_orders():
    sys = lf.Canonical(osc_h, osc_grad, dof=1)
    assert sys.dof == 1 and sys.fields == ["q", "p"] and not sys.finite_differences
    t = 4.0
    exact = np.array([np.cos(t), -np.sin(t)])
    for method, order in [("midpoint", 2), ("gauss4", 4), ("gauss6", 6)]:
        err = [np.abs(lf.integrate(sys, [1.0, 0.0], dt=t / n, steps=n, method=method)
                      .final_state - exact).max() for n in (20, 40)]
        assert abs(np.log2(err[0] / err[1]) - order) < 0.2, (method, err)
    tr = lf.integrate(sys, [1.0, 0.0], dt=0.1, steps=20000, save_every=100)
    assert np.abs(tr.energy() - 0.5).max() < 1e-13


def test_canonical_pendulum_by_finite_differences():
    pend = lf.Pendulum(1.0, 1.0, 9.81)
    fd = lf.Canonical(pend_h, dof=1)
    assert fd.finite_differences
    ref = lf.integrate(pend, [1.2, 0.0], dt=0.01, steps=500, method="gauss4").states
    got = lf.integrate(fd, [1.2, 0.0], dt=0.01, steps=500, method="gauss4").states
    np.testing.assert_allclose(got, ref, atol=1e-9)
    exact = pend.exact_solution(1.2, 5.0)
    got = lf.integrate(fd, [1.2, 0.0], dt=0.01, steps=500, method="gauss6").final_state
    np.testing.assert_allclose(got, exact, atol=1e-9)


@pytest.mark.parametrize("mass", [1.0, [1.0], [[1.0]]])
def test_separable_equals_the_pendulum(mass):
    pend = lf.Pendulum(1.0, 1.0, 9.81)
    sys = lf.Separable(mass, pend_u, pend_du, dof=1)
    for method in ("verlet", "gauss4", "rk4"):
        ref = lf.integrate(pend, [1.2, 0.0], dt=0.01, steps=1000, method=method).states
        got = lf.integrate(sys, [1.2, 0.0], dt=0.01, steps=1000, method=method).states
        np.testing.assert_allclose(got, ref, atol=1e-12, rtol=0)
    exact = pend.exact_solution(1.2, 2.0)
    for method, order in [("verlet", 2), ("verlet4", 4), ("verlet6", 6)]:
        err = [np.abs(lf.integrate(sys, [1.2, 0.0], dt=2.0 / n, steps=n, method=method)
                      .final_state - exact).max() for n in (40, 80)]
        assert abs(np.log2(err[0] / err[1]) - order) < 0.3, (method, err)


def test_separable_arguments():
    with pytest.raises(TypeError, match="dof"):
        lf.Separable(1.0, pend_u)
    with pytest.raises(lf.InvalidArgumentError):
        lf.Separable(-1.0, pend_u, dof=1)
    with pytest.raises(lf.InvalidArgumentError, match="positive definite"):
        lf.Separable([[1.0, 2.0], [2.0, 1.0]], pend_u)
    with pytest.raises(lf.ShapeError):
        lf.Separable([1.0, 2.0], pend_u, dof=3)
    with pytest.raises(TypeError, match="potential"):
        lf.Separable(1.0, 2.0, dof=1)
    with pytest.raises(lf.InvalidArgumentError):
        lf.Canonical(osc_h, dof=0)
    with pytest.raises(TypeError, match="dof"):
        lf.Canonical(osc_h)
    assert lf.Separable.methods()[:3] == ["verlet", "verlet4", "verlet6"]
    assert lf.Canonical.methods() == ["gauss4", "gauss6", "midpoint", "rk4"]


# --- errors of the callables ---

@pytest.mark.parametrize("method", ["gauss4", "midpoint", "rk4"])
def test_an_exception_is_re_raised_naming_the_step(method):
    sys = lf.Canonical(osc_h, fails_below, dof=1)
    with pytest.raises(ZeroDivisionError, match="q below") as info:
        lf.integrate(sys, [1.0, 0.0], dt=0.01, steps=1000, method=method)
    notes = " ".join(getattr(info.value, "__notes__", []))
    assert f"of {method}" in notes and "in step 21" in notes, notes
    # The system is usable afterwards (nothing stale is left).
    assert sys.energy([1.0, 0.0]) == 0.5
    lf.integrate(sys, [1.0, 0.0], dt=0.01, steps=10, method=method)


def test_an_exception_at_the_initial_state():
    def du(q):
        raise KeyError("no force")

    sys = lf.Separable(1.0, pend_u, du, dof=1)
    with pytest.raises(KeyError, match="no force") as info:
        lf.integrate(sys, [0.1, 0.0], dt=0.01, steps=10)
    assert "at the initial state of verlet" in " ".join(info.value.__notes__)
    with pytest.raises(KeyError):
        sys._run(np.array([[0.1, 0.0]]), None, 0.01, 10, 1, None)

    def h(m):
        raise ValueError("H failed")

    with pytest.raises(ValueError, match="H failed"):
        lf.LiePoisson("so3", h).energy(M0)


def test_nan_and_wrong_shapes_are_typed_errors():
    sys = lf.LiePoisson("so3", rb_h, returns_nan)
    with pytest.raises(lf.NonFiniteError, match=r"returns_nan.*entry \[0\] = NaN, in step 1 of "
                                                r"rkmk4"):
        lf.integrate(sys, M0, dt=0.01, steps=10)
    with pytest.raises(lf.ShapeError, match=r"returns_short.*expected \(2, 1\), got \(1,\), "
                                            r"in step 1 of gauss4"):
        lf.integrate(lf.Canonical(osc_h, returns_short, dof=1), [1.0, 0.0], dt=0.1, steps=3)
    with pytest.raises(TypeError):
        lf.integrate(lf.Canonical(osc_h, returns_str, dof=1), [1.0, 0.0], dt=0.1, steps=3)
    with pytest.raises(lf.NonFiniteError):
        lf.LiePoisson("so3", lambda m: float("nan")).energy(M0)
    with pytest.raises(lf.ShapeError):
        lf.LiePoisson("so3", lambda m: m).energy(M0)


def test_batches_run_single_threaded_and_in_order():
    sys = lf.LiePoisson("so3", rb_h, rb_grad)
    z0 = np.stack([M0, 2 * M0, -M0])
    tr = lf.integrate(sys, z0, dt=0.01, steps=100, threads=4)
    for k in range(3):
        one = lf.integrate(sys, z0[k], dt=0.01, steps=100).states
        np.testing.assert_array_equal(tr.states[k], one)


def test_pickling_and_repr():
    for sys, z0 in [(lf.Canonical(osc_h, osc_grad, dof=1), [1.0, 0.0]),
                    (lf.Separable([[2.0]], pend_u, pend_du), [0.3, 0.0]),
                    (lf.LiePoisson("so3", rb_h, rb_grad, casimirs=[casimir]), M0),
                    (lf.LiePoisson(("so", 4), np.eye(6)), np.arange(6.0) / 6),
                    (lf.LiePoisson("se3", np.eye(6), side="right"), np.arange(6.0) / 6)]:
        copy = pickle.loads(pickle.dumps(sys))
        assert repr(copy) == repr(sys)
        a = lf.integrate(sys, z0, dt=0.01, steps=50).states
        b = lf.integrate(copy, z0, dt=0.01, steps=50).states
        np.testing.assert_array_equal(a, b)
    assert repr(lf.Canonical(osc_h, dof=1)).startswith("Canonical(hamiltonian=<function osc_h")


def cubic_h(mu):
    return float(0.5 * mu @ mu + 0.2 * np.sum(mu**3) / 3)


def cubic_grad(mu):
    return mu + 0.2 * mu**2


def cubic_h_mirror(mu):
    return cubic_h(-mu)


def cubic_grad_mirror(mu):
    return -cubic_grad(-mu)


@pytest.mark.parametrize("method", ["rkmk4", "midpoint", "rk4"])
def test_a_right_invariant_system_is_the_left_one_of_the_inverse_motion(method):
    # 000 Theorems 4.3-4.4 by the mirror g -> g^{-1}: the right system of H from mu0 is the
    # negated left system of H(-mu) from -mu0, bit for bit; not the left system of H.
    right = lf.LiePoisson("so3", cubic_h, cubic_grad, side="right")
    mirror = lf.LiePoisson("so3", cubic_h_mirror, cubic_grad_mirror)
    left = lf.LiePoisson("so3", cubic_h, cubic_grad)
    assert (right.side, left.side) == ("right", "left")
    r = lf.integrate(right, M0, dt=0.01, steps=200, method=method).states
    m = lf.integrate(mirror, -M0, dt=0.01, steps=200, method=method).states
    np.testing.assert_array_equal(r, -m)
    l_ = lf.integrate(left, M0, dt=0.01, steps=200, method=method).states
    assert np.abs(r[-1] - l_[-1]).max() > 1e-3
    # The rigid body reduced from the right: d M/dt = Omega x M, the spatial frame's sign.
    body = lf.LiePoisson("so3", np.diag(1 / INERTIA), side="right")
    z = lf.integrate(body, M0, dt=1e-3, steps=1).states
    np.testing.assert_allclose((z[1] - z[0]) / 1e-3, np.cross(M0 / INERTIA, M0), atol=1e-2)


def test_side_is_checked():
    with pytest.raises(lf.InvalidArgumentError, match="expected \"left\" or \"right\""):
        lf.LiePoisson("so3", np.eye(3), side="up")
    with pytest.raises(lf.ArgumentTypeError, match="side"):
        lf.LiePoisson("so3", np.eye(3), side=1)
    with pytest.raises(lf.InvalidArgumentError, match="left-invariant"):
        lf.Forced(lf.LiePoisson("so3", np.eye(3), side="right"), dissipation=0.1)


def grad_raising(q, p):
    """The oscillator's gradient, raising once q turns negative (at t = π/2 from (q0, 0), where
    p = −q0: the message tells the runs apart)."""
    if q[0] < 0.0:
        raise ValueError(f"gradient raised at p = {p[0]:.1f}")
    return q, p


def test_concurrent_runs_of_one_system_keep_their_own_exceptions():
    """Three threads integrating the same callable system, all failing: each raises its own
    exception with its own step (the system's exception slot is taken by the run that filled
    it, not by another thread's run)."""
    import threading

    sys = lf.Canonical(osc_h, grad_raising, dof=1)
    for _ in range(5):
        out = {}

        def run(q0):
            try:
                lf.integrate(sys, [q0, 0.0], dt=0.01, steps=2000, chunk_steps=7)
            except ValueError as e:
                out[q0] = (str(e), e.partial.t_final)

        threads = [threading.Thread(target=run, args=(q0,)) for q0 in (1.0, 2.0, 3.0)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert sorted(out) == [1.0, 2.0, 3.0]
        for q0, (msg, t_final) in out.items():
            assert f"raised at p = {-q0:.1f}" in msg, (q0, msg)
            assert abs(t_final - np.pi / 2) < 0.02
