"""The equations of motion of 001 from Python (issue 25): the Riemann field (3.20), E (4.8), the
Euler–Lagrange field of Prop. 4.2 (at n = 3 its vector form (5.5)), the reduced Hamiltonian (7.24)
and the reduced field (7.25)–(7.28).

Every formula is checked by a second route: finite differences in time along a motion of the full
system (PseudoRigidBody, verlet6, whose error is far below the differences'), finite differences
of an energy (E = dK/dA, Hamilton's equations of the reduced H), the full Hamiltonian, and the
general n-dimensional form against the n = 3 fast path."""

import numpy as np
import pytest

import lieflow as lf

pr = lf.pseudo_rigid
pot = lf.potentials
H = 2.5e-3        # the time step of the 5-point differences (error ~ H^4)


def elastic():
    return pot.SaintVenantKirchhoff(0.7, 1.3) + pot.Volumetric(0.4, 1.4)


def start(n, seed):
    """(X, P) with distinct singular values (about 1.5, 1.2, ...) and a generic momentum."""
    rng = np.random.default_rng(seed)
    q1, _ = np.linalg.qr(rng.standard_normal((n, n)))
    q2, _ = np.linalg.qr(rng.standard_normal((n, n)))
    q1 *= np.sign(np.linalg.det(q1))
    q2 *= np.sign(np.linalg.det(q2))
    X = q1 @ np.diag(1.5 - 0.3 * np.arange(n)) @ q2.T
    return X, 0.4 * rng.standard_normal((n, n))


def motion(body, X0, P0):
    """X(t), P(t) at t = 0, H, 2H, 3H, 4H (verlet6 with step H/10)."""
    tr = lf.integrate(body, (X0, P0), dt=H / 10, steps=40, method="verlet6", save_every=10)
    return tr.X, tr.P


def d_dt(f):
    """The 5-point central difference at the middle of f(0), ..., f(4H) (stacked on axis 0)."""
    f = np.asarray(f)
    return (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * H)


def aligned(frames):
    """SVD frames (k, n, n) with their column signs made continuous with the middle one: the
    frames of X = R A S^T are fixed up to R -> R D, S -> S D (D diagonal, entries +-1), which
    conjugates the body momenta by D."""
    ref = frames[len(frames) // 2]
    return [np.sign(np.diag(ref.T @ f)) for f in frames]


def bracket(x, y):
    return x @ y - y @ x


def skew_unit(n, i, j):
    e = np.zeros((n, n))
    e[i, j], e[j, i] = 1.0, -1.0
    return e


def embed(m, size=4):
    """An n x n block in the top left corner of size x size zeros."""
    out = np.zeros((size, size))
    out[: m.shape[0], : m.shape[1]] = m
    return out


# ---------------------------------------------------------------- the Riemann field (3.20)

@pytest.mark.parametrize("n, potential", [(3, elastic()), (3, pot.SelfGravity(1.0, 1.0)),
                                          (4, pot.Harmonic(0.8) + pot.Stretch(1.1))])
def test_riemann_field_is_the_rate_of_Q_and_N_along_a_motion(n, potential):
    body = lf.PseudoRigidBody(n, potential)
    X, P = motion(body, *start(n, 1))
    Q, N = pr.riemann_variables(X, P)
    Qdot, Ndot = pr.riemann_vector_field(Q[2], N[2], potential)
    np.testing.assert_allclose(Qdot, d_dt(Q), atol=1e-8)
    np.testing.assert_allclose(Ndot, d_dt(N), atol=1e-8)
    # The closed form at the real X (not Q^(1/2)): dN/dt = V V^T + X (dV/dt)^T, dV/dt = -dU/dX.
    x, v = X[2], P[2]
    np.testing.assert_allclose(Qdot, v @ x.T + x @ v.T, atol=1e-12)
    np.testing.assert_allclose(Ndot, v @ v.T - x @ potential.gradient(x).T, atol=1e-11)
    # Leading axes map item by item; the free body by default.
    Qd, Nd = pr.riemann_vector_field(Q[:3], N[:3], potential)
    assert Qd.shape == Nd.shape == (3, n, n)
    np.testing.assert_allclose(Nd[2], Ndot, atol=1e-15)
    np.testing.assert_allclose(pr.riemann_vector_field(Q[2], N[2])[1],
                               N[2].T @ np.linalg.solve(Q[2], N[2]), atol=1e-12)


def u_value(X):
    return 0.5 * float(np.sum(np.asarray(X) ** 2))


def u_gradient(X):
    return np.asarray(X, float)


class Refused(RuntimeError):
    pass


def u_raises(X):
    raise Refused("from the potential")


def test_riemann_field_refuses_bad_Q_and_calls_a_callable_potential():
    X, P = start(3, 2)
    Q, N = pr.riemann_variables(X, P)
    with pytest.raises(lf.NotInGroupError):
        pr.riemann_vector_field(Q + [[0, 1, 0], [0, 0, 0], [0, 0, 0]], N)     # not symmetric
    with pytest.raises(lf.NotInGroupError):
        pr.riemann_vector_field(-Q, N)                                         # not positive
    with pytest.raises(lf.ShapeError):
        pr.riemann_vector_field(Q, N[:2])
    with pytest.raises(lf.InvalidArgumentError):
        pr.riemann_vector_field(embed(Q) + np.diag([0, 0, 0, 1.0]), embed(N),
                                pot.SelfGravity(1.0, 1.0))                     # n = 3 only
    mine = pot.Callable(u_value, u_gradient)
    for a, b in zip(pr.riemann_vector_field(Q, N, mine), pr.riemann_vector_field(Q, N, pot.Harmonic(1.0))):
        np.testing.assert_allclose(a, b, atol=1e-14)
    with pytest.raises(Refused):
        pr.riemann_vector_field(Q, N, pot.Callable(u_value, u_raises))


# ---------------------------------------------------------------- E (4.8) and Prop. 4.2

def body_velocities(n, seed):
    rng = np.random.default_rng(seed)
    a = 1.6 - 0.25 * np.arange(n) + 0.05 * rng.random(n)
    w, l = rng.standard_normal((2, n, n))
    return a, w - w.T, l - l.T, rng.standard_normal(n)


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_e_term_is_dK_dA_at_fixed_velocities(n):
    a, Omega, Lambda, adot = body_velocities(n, n)
    eye = np.eye(n)

    def K(a):   # the kinetic energy (4.5) = tr(V^T V)/2 of V from the body coordinates
        X, V = pr.from_body(eye, a, eye, Omega, adot, Lambda)
        return pr.kinetic_energy(X, V)

    eps = 1e-5
    fd = [(K(a + eps * e) - K(a - eps * e)) / (2 * eps) for e in eye]
    np.testing.assert_allclose(pr.e_term(a, Omega, Lambda), fd, atol=1e-8)


def test_e_term_and_lagrange_field_n3_fast_path_agree_with_the_general_form():
    # At n = 3 both functions go through the vector forms (5.4)/(5.5); at n = 4 through the
    # matrix forms (4.8)/(4.11). A 3-dimensional body embedded in 4 dimensions (zero rows and
    # columns of Omega and Lambda) has the same E and equations in its 3 x 3 block.
    a, Omega, Lambda, _ = body_velocities(3, 7)
    a4 = np.append(a, 0.5)
    U = pot.Harmonic(0.9)      # dU/da_i = 0.9 a_i: no coupling to a_4
    e3 = pr.e_term(a, Omega, Lambda)
    e4 = pr.e_term(a4, embed(Omega), embed(Lambda))
    np.testing.assert_allclose(e4, np.append(e3, 0.0), rtol=1e-14, atol=1e-14)
    f3 = pr.lagrange_vector_field(a, Omega, Lambda, U)
    f4 = pr.lagrange_vector_field(a4, embed(Omega), embed(Lambda), U)
    for k in ("p_Omega", "p_Lambda", "p_Omegadot", "p_Lambdadot"):
        np.testing.assert_allclose(f4[k], embed(f3[k]), atol=1e-14, err_msg=k)
    for k in ("E", "addot"):
        np.testing.assert_allclose(f4[k][:3], f3[k], atol=1e-14, err_msg=k)
    np.testing.assert_allclose(f3["addot"], e3 - 0.9 * a, atol=1e-14)


@pytest.mark.parametrize("n, potential", [(3, elastic()), (4, pot.Harmonic(0.8) + pot.Stretch(1.1))])
def test_lagrange_field_along_a_motion(n, potential):
    body = lf.PseudoRigidBody(n, potential)
    X, P = motion(body, *start(n, 3))
    R, a, S, Omega, adot, Lambda = pr.to_body(X, P)
    L, G = pr.angular_momentum(X, P), pr.circulation(X, P)
    f = pr.lagrange_vector_field(a[2], Omega[2], Lambda[2], potential)
    # (4.15) = (2.32): the body momenta are R^T L R and S^T Gamma S.
    np.testing.assert_allclose(f["p_Omega"], R[2].T @ L[2] @ R[2], atol=1e-12)
    np.testing.assert_allclose(f["p_Lambda"], S[2].T @ G[2] @ S[2], atol=1e-12)
    # (4.11a): the acceleration of the singular values.
    np.testing.assert_allclose(f["addot"], d_dt(adot), atol=1e-7)
    # (4.11b), (4.11c): the rates of R^T L R and S^T Gamma S (frames made continuous).
    d = aligned(R)
    pO = [dk[:, None] * (r.T @ l @ r) * dk for dk, r, l in zip(d, R, L)]
    pL = [dk[:, None] * (s.T @ g @ s) * dk for dk, s, g in zip(d, S, G)]
    np.testing.assert_allclose(f["p_Omegadot"], d_dt(pO), atol=1e-7)
    np.testing.assert_allclose(f["p_Lambdadot"], d_dt(pL), atol=1e-7)
    # E is (4.8) and addot = E - dU/dA.
    np.testing.assert_allclose(f["E"], pr.e_term(a[2], Omega[2], Lambda[2]), atol=1e-14)
    grad = np.diag(potential.gradient(np.diag(a[2])))
    np.testing.assert_allclose(f["addot"], f["E"] - grad, atol=1e-12)


def test_lagrange_field_maps_leading_axes_and_refuses_bad_input():
    a, Omega, Lambda, _ = body_velocities(3, 11)
    one = pr.lagrange_vector_field(a, Omega, Lambda)
    two = pr.lagrange_vector_field(np.stack([a, a]), Omega, Lambda)
    assert two["p_Omega"].shape == (2, 3, 3) and two["addot"].shape == (2, 3)
    np.testing.assert_allclose(two["E"][1], one["E"], atol=0)
    np.testing.assert_allclose(one["addot"], one["E"], atol=0)      # the free body
    for f in (pr.e_term, pr.lagrange_vector_field):
        with pytest.raises(lf.NotInGroupError):
            f(a, Omega + np.eye(3), Lambda)
        with pytest.raises(lf.InvalidArgumentError):
            f([1.0, 0.0, 0.5], Omega, Lambda)
        with pytest.raises(lf.ShapeError):
            f(a[:2], Omega, Lambda)
        with pytest.raises(lf.NonFiniteError):
            f(a, Omega, Lambda * np.nan)


# ---------------------------------------------------------------- the reduced system (§7)

KEYS = ("a", "p_a", "p_Omega", "p_Lambda")


def reduced(X, P):
    r = pr.reduce(X, P)
    return [r[k] for k in KEYS]


@pytest.mark.parametrize("n, potential", [(3, elastic()), (4, pot.Harmonic(0.8) + pot.Stretch(1.1))])
def test_reduced_hamiltonian_is_the_full_one(n, potential):
    X, P = start(n, 5)
    body = lf.PseudoRigidBody(n, potential)
    state = np.concatenate([X.ravel(), P.ravel()])
    h = pr.reduced_hamiltonian(*reduced(X, P), potential)
    assert isinstance(h, float)
    assert abs(h - body.energy(state)) < 1e-12 * abs(h)
    X2, P2 = start(n, 6)
    both = pr.reduced_hamiltonian(*[np.stack(p) for p in zip(reduced(X, P), reduced(X2, P2))],
                                  potential)
    assert both.shape == (2,) and both[0] == h


@pytest.mark.parametrize("n, potential", [(3, elastic()), (4, pot.Harmonic(0.8) + pot.Stretch(1.1))])
def test_reduced_field_is_hamiltons_equations_of_the_reduced_hamiltonian(n, potential):
    a, p_a, mu, nu = reduced(*start(n, 4))
    f = pr.reduced_vector_field(a, p_a, mu, nu, potential)

    def Hr(a=a, p_a=p_a, mu=mu, nu=nu):
        return pr.reduced_hamiltonian(a, p_a, mu, nu, potential)

    eps = 1e-6
    eye = np.eye(n)
    dH_dp = [(Hr(p_a=p_a + eps * e) - Hr(p_a=p_a - eps * e)) / (2 * eps) for e in eye]
    dH_da = [(Hr(a=a + eps * e) - Hr(a=a - eps * e)) / (2 * eps) for e in eye]
    np.testing.assert_allclose(f["a"], dH_dp, atol=1e-8)           # (7.28)
    np.testing.assert_allclose(f["p_a"], -np.array(dH_da), atol=1e-7)
    # The velocities Omega = dH/dmu, Lambda = dH/dnu in the pairing sum_{i<j} x_ij y_ij, and the
    # Lie-Poisson equations (7.25)-(7.27) d(mu)/dt = [mu, Omega], d(nu)/dt = [nu, Lambda].
    Omega, Lambda = np.zeros((n, n)), np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1, n):
            e = eps * skew_unit(n, i, j)
            Omega += skew_unit(n, i, j) * (Hr(mu=mu + e) - Hr(mu=mu - e)) / (2 * eps)
            Lambda += skew_unit(n, i, j) * (Hr(nu=nu + e) - Hr(nu=nu - e)) / (2 * eps)
    np.testing.assert_allclose(f["p_Omega"], bracket(mu, Omega), atol=1e-7)
    np.testing.assert_allclose(f["p_Lambda"], bracket(nu, Lambda), atol=1e-7)
    # The same velocities by the closed-form inverse of the bi-inertia tensor (7.9).
    O2, L2 = pr.bi_inertia_solve(np.diag(a), mu, nu)
    np.testing.assert_allclose(Omega, O2, atol=1e-7)
    np.testing.assert_allclose(Lambda, L2, atol=1e-7)


@pytest.mark.parametrize("n, potential", [(3, elastic()), (4, pot.Harmonic(0.8) + pot.Stretch(1.1))])
def test_reduced_field_is_the_rate_of_the_reduced_motion(n, potential):
    body = lf.PseudoRigidBody(n, potential)
    X, P = motion(body, *start(n, 8))
    parts = [pr.reduce(x, p) for x, p in zip(X, P)]
    d = aligned([r["R"] for r in parts])
    f = pr.reduced_vector_field(*[parts[2][k] for k in KEYS], potential)
    for k in ("a", "p_a"):
        np.testing.assert_allclose(f[k], d_dt([r[k] for r in parts]), atol=1e-7, err_msg=k)
    for k in ("p_Omega", "p_Lambda"):
        series = [dk[:, None] * r[k] * dk for dk, r in zip(d, parts)]
        np.testing.assert_allclose(f[k], d_dt(series), atol=1e-7, err_msg=k)
    # The reduced motion conserves the reduced Hamiltonian.
    hs = [pr.reduced_hamiltonian(*[r[k] for k in KEYS], potential) for r in parts]
    assert np.ptp(hs) < 1e-12


def test_reduced_functions_refuse_bad_input_and_raise_a_callables_exception():
    a, p_a, mu, nu = reduced(*start(3, 9))
    for f in (pr.reduced_hamiltonian, pr.reduced_vector_field):
        with pytest.raises(lf.DegenerateStratumError):
            f([1.0, 1.0, 0.5], p_a, mu, nu)
        with pytest.raises(lf.InvalidArgumentError):
            f([1.0, -1.0, 0.5], p_a, mu, nu)
        with pytest.raises(lf.NotInGroupError):
            f(a, p_a, mu + np.eye(3), nu)
        with pytest.raises(lf.ShapeError):
            f(a, p_a[:2], mu, nu)
        with pytest.raises(Refused):
            f(a, p_a, mu, nu, pot.Callable(u_raises, u_gradient) if f is pr.reduced_hamiltonian
              else pot.Callable(u_value, u_raises))
        with pytest.raises(TypeError, match="potential"):
            f(a, p_a, mu, nu, "harmonic")
    mine = pr.reduced_vector_field(a, p_a, mu, nu, pot.Callable(u_value, u_gradient))
    ref = pr.reduced_vector_field(a, p_a, mu, nu, pot.Harmonic(1.0))
    for k in KEYS:
        np.testing.assert_allclose(mine[k], ref[k], atol=1e-14)
    assert pr.reduced_hamiltonian(a, p_a, mu, nu) == pytest.approx(
        0.5 * p_a @ p_a + pr.reduced_hamiltonian(a, 0 * p_a, mu, nu), rel=1e-14)
