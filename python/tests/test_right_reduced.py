"""001 §2.3–§3: the body reduced by its right SO(n) symmetry (RightReduced), the reduced
Euler–Lagrange equation (3.17), Kelvin's circulation as a loop integral (2.34)–(2.36) and
Guichardet's connection (2.23)–(2.28). Each against an independent route: the full body's
Verlet flow, the Riemann field (3.20), the connections, the pairing with Γ."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lieflow as lf

PR = lf.pseudo_rigid


def elastic():
    return lf.potentials.SaintVenantKirchhoff(1.0, 2.0) + lf.potentials.Volumetric(0.5, 1.4)


def state(n):
    i, j = np.indices((n, n))
    X = np.where(i == j, 1.0 + 0.25 * i, 0.1 * np.sin(i + 2 * j))
    P = 0.3 * np.cos(3 * i + j) + 0.2 * (i - j)
    return X, P


@pytest.mark.parametrize("n", [3, 4])
@pytest.mark.parametrize("method", ["verlet", "verlet4"])
def test_reduced_verlet_reconstructs_the_full_motion_and_keeps_the_circulation(n, method):
    X0, P0 = state(n)
    pot = elastic() if n == 3 else lf.potentials.Harmonic(1.5) + lf.potentials.Volumetric(0.5, 1.4)
    full = lf.PseudoRigidBody(n, pot)
    red = PR.RightReduced(n, pot, reconstruct=True)
    a = lf.integrate(full, np.concatenate([X0.ravel(), P0.ravel()]), dt=0.02, steps=400,
                     method=method, save_every=50)
    b = lf.integrate(red, red.reduce(X0, P0), dt=0.02, steps=400, method=method, save_every=50)
    X, P = red.reconstruct(b.states)
    np.testing.assert_allclose(X, a.states[:, : n * n].reshape(-1, n, n), rtol=0, atol=1e-12)
    np.testing.assert_allclose(P, a.states[:, n * n:].reshape(-1, n, n), rtol=0, atol=1e-11)
    gamma = PR.circulation(X, P)
    np.testing.assert_allclose(gamma, np.broadcast_to(gamma[0], gamma.shape), atol=1e-12)
    # The invariants are the full body's and are kept.
    np.testing.assert_allclose(b.invariants(), a.invariants(), rtol=1e-12)
    inv = b.invariants()
    np.testing.assert_allclose(inv, np.broadcast_to(inv[0], inv.shape), rtol=1e-12)
    # Without X: the same reduced states.
    c = lf.integrate(PR.RightReduced(n, pot), red.reduce(X0, P0)[: 2 * n * n], dt=0.02,
                     steps=400, method=method, save_every=50)
    np.testing.assert_array_equal(c.states, b.states[:, : 2 * n * n])


def test_the_terms_of_3_31():
    X, P = state(3)
    red = PR.RightReduced(3, elastic())
    z = red.reduce(X, P)
    horizontal, locked, u = red.hamiltonian_parts(z)
    assert horizontal + locked + u == pytest.approx(float(red.energy(z)), rel=1e-14)
    Y = PR.horizontal_part(X, P, "right")
    assert horizontal == pytest.approx(0.5 * np.sum(Y * Y), rel=1e-12)
    assert locked == pytest.approx(0.5 * np.sum((P - Y) ** 2), rel=1e-12)
    # Γ_C is conjugate to the circulation of X; L = Nᵀ − N is the angular momentum.
    g_c, g = red.circulation(z), PR.circulation(X, P)
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(g_c).imag),
                               np.sort(np.linalg.eigvals(g).imag), atol=1e-13)
    np.testing.assert_allclose(red.angular_momentum(z), PR.angular_momentum(X, P), atol=1e-14)


def test_reduce_refuses_what_is_not_a_state_and_a_potential_that_is_not_right_invariant():
    red = PR.RightReduced(3)
    with pytest.raises(lf.InvalidArgumentError, match="does not carry X"):
        red.reconstruct(red.reduce(np.eye(3), np.zeros((3, 3))))
    z = red.reduce(np.eye(3), np.zeros((3, 3)))
    z[1] = 0.5
    with pytest.raises(lf.NotInGroupError):
        lf.integrate(red, z, dt=0.1, steps=1)
    # U(X) = X_00² is not invariant under X ↦ Xh.
    skewed = lf.potentials.Callable(lambda X: X[0, 0] ** 2,
                                    lambda X: np.array([[2 * X[0, 0], 0, 0], [0, 0, 0], [0, 0, 0]]),
                                    lambda X, V: np.array([[2 * V[0, 0], 0, 0], [0, 0, 0],
                                                           [0, 0, 0]]))
    red = PR.RightReduced(3, skewed)
    with pytest.raises(lf.InvalidArgumentError, match="U\\(Xh\\) = U\\(X\\)"):
        lf.integrate(red, red.reduce(np.diag([1.0, 1.2, 0.9]), np.zeros((3, 3))), dt=0.1, steps=1)


# --- 001 (3.17) ---

K = 1.5   # lf.potentials.Harmonic(K): U = K/2 tr(XᵀX) = K/2 tr Q


def harmonic_lagrangian(Q, N):
    return 0.5 * float(np.trace(N.T @ np.linalg.solve(Q, N))) - 0.5 * K * float(np.trace(Q))


def harmonic_gradient(Q, N):
    Qi = np.linalg.inv(Q)
    return -0.5 * Qi @ N @ N.T @ Qi - 0.5 * K * np.eye(len(Q)), Qi @ N


def test_3_17_is_the_riemann_field_3_20_with_and_without_a_gradient():
    X, P = state(3)
    Q, N = PR.riemann_variables(X, P)
    # (3.20): dN/dt = NᵀQ⁻¹N − 2Q ∂U/∂Q, dQ/dt = N + Nᵀ.
    expected = N.T @ np.linalg.solve(Q, N) - K * Q
    qd, nd = PR.reduced_euler_lagrange(harmonic_lagrangian, Q, N, gradient=harmonic_gradient)
    np.testing.assert_allclose(qd, N + N.T, atol=1e-15)
    np.testing.assert_allclose(nd, expected, atol=1e-9)
    _, nd = PR.reduced_euler_lagrange(harmonic_lagrangian, Q, N)
    np.testing.assert_allclose(nd, expected, atol=1e-6)


def test_3_17_integrated_is_the_full_motion():
    X0, P0 = state(3)
    Q0, N0 = PR.riemann_variables(X0, P0)

    def field(t, y):
        qd, nd = PR.reduced_euler_lagrange(harmonic_lagrangian, y[:9].reshape(3, 3),
                                           y[9:].reshape(3, 3), gradient=harmonic_gradient)
        return np.concatenate([qd.ravel(), nd.ravel()])

    sol = solve_ivp(field, (0, 1.0), np.concatenate([Q0.ravel(), N0.ravel()]), method="DOP853",
                    rtol=1e-11, atol=1e-12)
    full = lf.PseudoRigidBody(3, lf.potentials.Harmonic(K))
    traj = lf.integrate(full, np.concatenate([X0.ravel(), P0.ravel()]), dt=1e-3, steps=1000,
                        method="verlet6", save_every=1000)
    X, P = traj.states[-1, :9].reshape(3, 3), traj.states[-1, 9:].reshape(3, 3)
    Q, N = PR.riemann_variables(X, P)
    np.testing.assert_allclose(sol.y[:9, -1].reshape(3, 3), Q, atol=1e-8)
    np.testing.assert_allclose(sol.y[9:, -1].reshape(3, 3), N, atol=1e-8)


def test_3_17_raises_the_callables_exception_and_refuses_a_singular_lagrangian():
    Q, N = np.eye(3), np.zeros((3, 3))

    class Boom(Exception):
        pass

    def bad(Q, N):
        raise Boom("inside L")

    with pytest.raises(Boom, match="inside L"):
        PR.reduced_euler_lagrange(bad, Q, N)
    with pytest.raises(lf.InvalidArgumentError, match="not regular"):
        PR.reduced_euler_lagrange(lambda Q, N: float(np.trace(Q)), Q, N)
    with pytest.raises(lf.NotInGroupError):
        PR.reduced_euler_lagrange(harmonic_lagrangian, -np.eye(3), N)


# --- Kelvin's circulation (2.34)–(2.36) ---

def test_loop_circulation_is_kelvins_constant_on_a_simulated_body():
    X0, P0 = state(3)
    body = lf.PseudoRigidBody(3, elastic())
    traj = lf.integrate(body, np.concatenate([X0.ravel(), P0.ravel()]), dt=0.01, steps=2000,
                        save_every=200)
    s = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    # A tilted, off-centre loop of particles (labels), carried by the body.
    labels = np.stack([0.2 + np.cos(s), 0.1 + 0.7 * np.sin(s), 0.3 * np.cos(s) + 0.2 * np.sin(s)],
                      axis=1)
    zeta = PR.loop_area(labels)
    values = []
    for z in traj.states:
        X, P = z[:9].reshape(3, 3), z[9:].reshape(3, 3)
        values.append(PR.loop_circulation(X, P, labels))
        gamma = PR.circulation(X, P)
        assert values[-1] == pytest.approx(0.5 * np.trace(gamma.T @ zeta), abs=1e-13)
    # The loop moved (the body deforms and turns), its circulation did not.
    assert np.ptp(values) < 1e-12 * max(1.0, abs(values[0]))
    assert abs(values[0]) > 1e-2
    # The unit square's area, and a loop needs three points.
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    np.testing.assert_array_equal(PR.loop_area(sq), [[0, 1], [-1, 0]])
    with pytest.raises(lf.ShapeError):
        PR.loop_area(sq[:2])


# --- Guichardet (2.23)–(2.28) ---

@pytest.mark.parametrize("n", [2, 3, 4])
def test_guichardet_of_a_homogeneous_cloud_is_the_left_connection(n):
    X, V = state(n)
    labels = np.concatenate([np.eye(n), -np.eye(n)])    # Σ m u uᵀ = 1 with m = ½
    m = np.full(2 * n, 0.5)
    w = PR.guichardet_connection(m, labels @ X.T, labels @ V.T)
    np.testing.assert_allclose(w, PR.left_connection(X, V), atol=1e-12)
    np.testing.assert_allclose(PR.particle_locked_inertia(m, labels @ X.T),
                               PR.locked_inertia(X, "left"), atol=1e-12)


def test_guichardet_in_three_dimensions_is_the_inertia_tensor_inverse_on_the_angular_momentum():
    rng = np.random.default_rng(3)
    m, x, v = rng.uniform(0.5, 2, 6), rng.standard_normal((6, 3)), rng.standard_normal((6, 3))
    A = lf.inertia_tensor(m, x)
    omega = np.linalg.solve(A, np.sum(m[:, None] * np.cross(x, v), axis=0))
    w = PR.guichardet_connection(m, x, v)
    np.testing.assert_allclose([w[2, 1], w[0, 2], w[1, 0]], omega, atol=1e-12)
    np.testing.assert_allclose(np.linalg.eigvalsh(PR.particle_locked_inertia(m, x)),
                               np.linalg.eigvalsh(A), atol=1e-12)
    with pytest.raises(lf.InvalidArgumentError, match="line"):
        PR.guichardet_connection(m, np.outer(np.arange(6.0), [1, 2, 3]), v)


def test_an_exception_of_the_potential_in_the_start_checks_is_raised_and_does_not_leak():
    """A Callable potential that raises while the start checks evaluate it (the invariance check)
    ends that call with its own exception, not the NaN it left; the next run is clean."""
    class Boom(Exception):
        pass

    calls = [0]

    def u(X):
        calls[0] += 1
        if calls[0] == 1:
            raise Boom("once")
        return 0.5 * float(np.sum(X * X))

    pot = lf.potentials.Callable(u, lambda X: np.asarray(X), lambda X, V: np.asarray(V))
    red = PR.RightReduced(3, pot)
    z = red.reduce(np.diag([1.0, 1.2, 0.9]), np.zeros((3, 3)))
    with pytest.raises(Boom, match="once"):
        lf.integrate(red, z, dt=0.01, steps=10)
    traj = lf.integrate(red, z, dt=0.01, steps=10)
    assert np.isfinite(traj.states).all()
