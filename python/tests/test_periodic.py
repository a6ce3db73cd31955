"""lf.periodic_orbit: periodic and relative periodic orbits by shooting (issue 27).

Checked against closed forms (the free rigid body's period 4K(k)/λ, Montgomery's drift angle)
and an independent linearisation (Mathieu's equation across the harmonic orbits of two coupled
oscillators, integrated by scipy), plus the errors of bad input.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lieflow as lf

I = np.array([1.0, 2.0, 3.0])


def closed_form_period(m):
    """4K(k)/λ (Landau–Lifshitz §37), axes 1 and 3 exchanged below the separatrix."""
    l2 = m @ m
    e2 = m @ (m / I)
    i1, i2, i3 = (I[0], I[1], I[2]) if l2 > e2 * I[1] else (I[2], I[1], I[0])
    lam = np.sqrt((i3 - i2) * (l2 - e2 * i1) / (i1 * i2 * i3))
    k2 = (i2 - i1) * (e2 * i3 - l2) / ((i3 - i2) * (l2 - e2 * i1))
    return 4 * lf.elliptic.ellipk(k2) / lam


ORBITS = [np.array(m) for m in ([1.0, 0.3, 0.2], [0.2, 0.3, 1.0], [0.25, 1.0, 0.3])]


@pytest.mark.parametrize("m0", ORBITS, ids=["least-axis", "largest-axis", "near-separatrix"])
@pytest.mark.parametrize("method,dt", [("exact", 2.0), ("dmv10", 0.05)])
def test_free_body_period_is_the_closed_form(m0, method, dt):
    body = lf.RigidBody(I)
    exact = closed_form_period(m0)
    orbit = lf.periodic_orbit(body, m0, 1.03 * exact, method=method, dt=dt)
    assert abs(orbit.period - exact) <= 1e-10 * exact
    assert orbit.residual <= 1e-13
    assert orbit.trivial.all() and orbit.normal_multipliers.size == 0 and orbit.stable
    # The monodromy: one Jordan block and a simple one at 1.
    n = orbit.monodromy - np.eye(3)
    assert np.abs(n).max() > 0.1 and np.abs(n @ n).max() <= 1e-9 * np.abs(n).max() ** 2
    traj = orbit.trajectory()
    np.testing.assert_allclose(traj.states[-1], orbit.state0, atol=1e-13)
    assert traj.t[-1] == pytest.approx(orbit.period, rel=1e-15)


def test_fix_period_finds_the_energy_of_a_given_period():
    body = lf.RigidBody(I)
    m0 = ORBITS[0]
    target = 1.01 * closed_form_period(m0)
    orbit = lf.periodic_orbit(body, m0, target, method="exact", dt=2.0, fix="period")
    assert orbit.period == target
    assert abs(closed_form_period(orbit.state0) - target) <= 1e-10 * target
    # The Casimir of the guess is kept; its energy is not.
    assert orbit.state0 @ orbit.state0 == pytest.approx(m0 @ m0, rel=1e-13)
    assert orbit.energy != pytest.approx(body.energy(m0), rel=1e-6)


def solid_angle(body, m0, period, n=4000):
    """Λ = ∮(1 − cos ϑ) dφ of M(t)/‖M‖ about the principal axis the orbit circles, oriented by
    the motion: the periodic trapezoidal rule on the exact solution."""
    t = np.arange(n) * period / n
    m = body.exact_solution(m0, t)
    l = np.linalg.norm(m0)
    pole = 0 if np.all(m[:, 0] * m0[0] > 0) else 2
    a, b = (pole + 1) % 3, (pole + 2) % 3
    w = m / I
    mdot = np.cross(m, w)
    phidot = (m[:, a] * mdot[:, b] - m[:, b] * mdot[:, a]) / (m[:, a] ** 2 + m[:, b] ** 2)
    s = np.sign(m0[pole])
    return np.sum((1 - s * m[:, pole] / l) * phidot * s) * period / n


@pytest.mark.parametrize("m0", ORBITS + [np.array([-0.3, 1.0, -0.25])])
@pytest.mark.parametrize("method,dt", [("exact", 2.0), ("dmv10", 0.05)])
def test_relative_orbit_drift_is_montgomery_s_angle(m0, method, dt):
    body = lf.RigidBody(I)
    r0 = lf.lie.so3_exp([0.4, -0.7, 0.3])
    t = closed_form_period(m0)
    orbit = lf.periodic_orbit(body, m0, t, method=method, dt=dt, attitude=r0)
    pi = r0 @ orbit.state0
    expected = 2 * orbit.energy * orbit.period / np.linalg.norm(pi) - solid_angle(
        body, orbit.state0, orbit.period)
    # ω ∥ π, and its angle is Montgomery's modulo 2π.
    w = orbit.drift
    assert np.linalg.norm(np.cross(w, pi)) <= 1e-12 * np.linalg.norm(pi)
    diff = np.mod(orbit.drift_angle - expected, 2 * np.pi)
    assert min(diff, 2 * np.pi - diff) <= 1e-9
    # The attitude's run ends at g R(0).
    traj = orbit.trajectory()
    np.testing.assert_allclose(traj.attitude[-1], lf.lie.so3_exp(w) @ r0, atol=1e-12)


def coupled(omega, beta):
    """½‖p‖² + ½x² + ½ω²y² + ½βx²y²: the orbits y = 0 are harmonic (period 2π); across them
    Mathieu's equation δÿ + (ω² + βA²cos²t)δy = 0."""
    w2 = omega * omega

    def potential(q):
        return 0.5 * (q[0] ** 2 + w2 * q[1] ** 2 + beta * q[0] ** 2 * q[1] ** 2)

    def gradient(q):
        x, y = q
        return [x + beta * x * y * y, w2 * y + beta * x * x * y]

    def hessian(q, v):
        x, y = q
        return [(1 + beta * y * y) * v[0] + 2 * beta * x * y * v[1],
                2 * beta * x * y * v[0] + (w2 + beta * x * x) * v[1]]

    return lf.Separable(1.0, potential, gradient, dof=2, hessian=hessian)


def mathieu_multipliers(omega, beta, amplitude):
    def f(t, y):
        return [y[1], -(omega ** 2 + beta * amplitude ** 2 * np.cos(t) ** 2) * y[0]]
    cols = [solve_ivp(f, (0, 2 * np.pi), e, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
            for e in ([1.0, 0.0], [0.0, 1.0])]
    return np.linalg.eigvals(np.array(cols).T)


@pytest.mark.parametrize("method,dt", [("gauss6", 0.03), ("verlet4", 0.003)])
def test_normal_multipliers_are_mathieu_s(method, dt):
    omega, beta = 1.3, 0.4
    sys = coupled(omega, beta)
    guess = np.array([0.8, 0.01, 0.0, 0.005])
    before = guess.copy()
    orbit = lf.periodic_orbit(sys, guess, 6.0, method=method, dt=dt)
    np.testing.assert_array_equal(guess, before)
    z = orbit.state0
    reference = mathieu_multipliers(omega, beta, np.hypot(z[0], z[2]))
    got = orbit.normal_multipliers
    assert got.shape == (2,) and orbit.trivial.sum() == 2 and orbit.stable
    assert np.abs(np.sort_complex(got) - np.sort_complex(reference)).max() <= 1e-9
    assert abs(orbit.period - 2 * np.pi) <= 1e-9


def test_an_unstable_orbit_is_reported_unstable():
    # ω² + βA²/2 = 1: Mathieu's first resonance tongue (parametric resonance) at A = 0.8.
    sys = coupled(np.sqrt(1 - 0.8 * 0.64 / 2), 0.8)
    orbit = lf.periodic_orbit(sys, [0.8, 0.0, 0.0, 0.0], 6.3, method="gauss6", dt=0.03)
    mods = np.abs(orbit.normal_multipliers)
    assert not orbit.stable and mods.max() > 1.01
    assert np.prod(mods) == pytest.approx(1.0, rel=1e-9)   # a symplectic pair μ, 1/μ


def test_a_raising_callable_ends_the_solve_with_its_exception():
    class Boom(Exception):
        pass

    calls = []

    def hessian(q, v):
        calls.append(1)
        if len(calls) > 500:
            raise Boom("from the Hessian")
        return v

    sys = lf.Separable(1.0, lambda q: 0.5 * float(q @ q), lambda q: q, dof=1, hessian=hessian)
    with pytest.raises(Boom, match="from the Hessian"):
        lf.periodic_orbit(sys, [1.0, 0.0], 6.0, method="verlet", dt=0.1)
    assert len(calls) == 501


def test_bad_input_is_refused():
    body = lf.RigidBody(I)
    m0 = np.array([1.0, 0.3, 0.2])
    with pytest.raises(lf.InvalidArgumentError, match="period"):
        lf.periodic_orbit(body, m0, -1.0)
    with pytest.raises(TypeError, match="period"):
        lf.periodic_orbit(body, m0, "10")
    with pytest.raises(lf.InvalidArgumentError, match="fix"):
        lf.periodic_orbit(body, m0, 10.0, fix="time")
    with pytest.raises(lf.InvalidArgumentError, match="dt"):
        lf.periodic_orbit(body, m0, 10.0, dt=0.0)
    with pytest.raises(lf.UnsupportedMethodError):
        lf.periodic_orbit(body, m0, 10.0, method="nope")
    with pytest.raises(lf.ShapeError):
        lf.periodic_orbit(body, [1.0, 0.3], 10.0)
    with pytest.raises(lf.InvalidArgumentError, match="one initial state"):
        lf.periodic_orbit(body, np.stack([m0, m0]), 10.0)
    with pytest.raises(lf.InvalidArgumentError, match="equilibrium"):
        lf.periodic_orbit(body, [1.0, 0.0, 0.0], 10.0)
    with pytest.raises(lf.NotInGroupError):
        lf.periodic_orbit(body, m0, 10.0, method="exact", dt=2.0, attitude=2 * np.eye(3))
    with pytest.raises(lf.InvalidArgumentError, match="attitude"):
        lf.periodic_orbit(lf.Pendulum(), [1.0, 0.0], 6.0, relative=True)
    with pytest.raises(TypeError):
        lf.periodic_orbit("body", m0, 10.0)


def test_normal_modes_and_the_lyapunov_orbit_of_a_jacobi_ellipsoid():
    jacobi = lf.ellipsoids.jacobi(0.6)
    modes = jacobi.normal_modes()
    # The co-moving spectrum: a stable Jacobi figure has only imaginary pairs.
    freqs = np.array([m.frequency for m in modes])
    assert len(modes) == 4 and np.all(np.diff(freqs) > 0)
    ev = np.sort(jacobi.stability().spectral.eigenvalues.imag)
    np.testing.assert_allclose(freqs, ev[ev > 0], rtol=1e-12)
    assert all(abs(m.eigenvalue.real) <= 1e-12 * m.frequency for m in modes)
    mode = modes[0]
    assert mode.period == pytest.approx(2 * np.pi / mode.frequency)
    assert mode.vector.shape == (18,) and mode.vector.dtype == np.complex128
    orbit = lf.periodic_orbit.from_mode(jacobi, 0, 1e-3, method="rattle6", dt=mode.period / 100)
    assert orbit.stable and orbit.residual <= 1e-12
    assert orbit.period == pytest.approx(mode.period, rel=1e-5)
    assert orbit.normal_multipliers.shape == (6,)
    np.testing.assert_allclose(np.abs(orbit.normal_multipliers), 1.0, atol=1e-9)
    # ζ ≈ T·(Ω ⊕ 0): a turn about the rotation axis, no internal rotation.
    velocity = np.concatenate([lf.lie.vee_n(jacobi.xi), lf.lie.vee_n(jacobi.eta)])
    np.testing.assert_allclose(orbit.drift, orbit.period * velocity, atol=1e-4)
    # Its run returns to exp(ζ)·z(0): X(T) = e^ξ X(0) e^{-η}.
    traj = orbit.trajectory()
    x0, xt = orbit.state0[:9].reshape(3, 3), traj.states[-1][:9].reshape(3, 3)
    g = lf.lie.so_exp(lf.lie.hat_n(orbit.drift[:3]))
    h = lf.lie.so_exp(lf.lie.hat_n(orbit.drift[3:]))
    np.testing.assert_allclose(xt, g @ x0 @ h.T, atol=1e-12)
    with pytest.raises(lf.InvalidArgumentError, match="mode"):
        lf.periodic_orbit.from_mode(jacobi, 4, 1e-3)


def test_a_family_crosses_mathieu_s_tongues_and_locates_them():
    # ω² + βA²/2 = 4 at A = √10 ≈ 3.16 (the second tongue, a multiplier through +1 over the
    # period 2π: cos²t has period π).
    omega, beta = 1.2, 0.8
    sys = coupled(omega, beta)
    start = lf.periodic_orbit(sys, [0.3, 0.0, 0.0, 0.0], 6.3, method="gauss6", dt=0.1)
    branch = lf.continuation.periodic_family(sys, start, max_points=16, step=0.1, max_step=0.3)
    assert len(branch) == 16 and branch.parameter == "energy"
    assert np.all(np.diff(branch.energies) > 0)
    np.testing.assert_allclose(branch.periods, 2 * np.pi, rtol=1e-9)   # isochronous in x
    first = branch.special_points[0]
    assert first.kind == "tangent" and not first.orbit.stable
    amplitude = np.hypot(first.orbit.state0[0], first.orbit.state0[2])
    # The first tongue crossed: Mathieu's multiplier through +1 at this amplitude.
    mu = mathieu_multipliers(omega, beta, amplitude)
    assert np.abs(mu).max() > 1
    inside = mathieu_multipliers(omega, beta, amplitude * (1 - 2e-3))
    assert np.abs(inside).max() == pytest.approx(1.0, abs=1e-9)
    # Stable where Mathieu is, along the branch.
    for orbit in branch.points[::3]:
        a = np.hypot(orbit.state0[0], orbit.state0[2])
        assert orbit.stable == (np.abs(mathieu_multipliers(omega, beta, a)).max() <= 1 + 1e-6)


def test_a_stretch_body_lyapunov_orbit_converges_where_its_update_stagnates():
    # Its equations hold to 3e-14 while the minimum-norm update stalls at 1.6e-9 (round-off
    # along the family's near-null directions): an orbit, not a ConvergenceError.
    st = lf.potentials.Stretch(1.0)
    eq = [q for q in lf.pseudo_rigid.relative_equilibria(st, shape=[2.85, 0.35, 1.0], plane=(0, 1))
          if q.xi[0, 1] > 0][0]
    modes = eq.normal_modes()
    assert eq.stability().spectral.stable and len(modes) == 5
    orbit = lf.periodic_orbit.from_mode(eq, 0, 1e-3, method="verlet4", dt=modes[0].period / 800)
    assert orbit.residual <= 1e-12 and orbit.stable
    # Across the orbit the other modes turn by e^{±iω_k T}, to the amplitude's and the
    # method's error.
    mu = orbit.normal_multipliers
    assert mu.shape == (8,) and orbit.trivial.sum() == 10
    for m in modes[1:]:
        w = np.exp(1j * m.frequency * orbit.period)
        assert np.abs(mu - w).min() <= 5e-3 and np.abs(mu - w.conjugate()).min() <= 5e-3


def test_a_period_doubling_along_a_family_is_located_and_named():
    # ½‖p‖² + ½x² + ½ω²y² + βxy²: across the harmonic orbits x = A cos t the motion obeys
    # δÿ + (ω² + 2βA cos t)δy = 0, whose coefficient has the orbit's period 2π: a multiplier
    # through −1 where the amplitude opens the tongue at ω = 1/2.
    omega, beta = 0.6, 0.5
    w2 = omega * omega

    def potential(q):
        return 0.5 * (q[0] ** 2 + w2 * q[1] ** 2) + beta * q[0] * q[1] ** 2

    def gradient(q):
        x, y = q
        return [x + beta * y * y, w2 * y + 2 * beta * x * y]

    def hessian(q, v):
        x, y = q
        return [v[0] + 2 * beta * y * v[1], 2 * beta * y * v[0] + (w2 + 2 * beta * x) * v[1]]

    sys = lf.Separable(1.0, potential, gradient, dof=2, hessian=hessian)
    start = lf.periodic_orbit(sys, [0.05, 0.0, 0.0, 0.0], 6.3, method="gauss6", dt=0.05)
    branch = lf.continuation.periodic_family(sys, start, max_points=14, step=0.02, max_step=0.05)
    first = branch.special_points[0]
    assert first.kind == "period_doubling", branch.special_points
    amplitude = np.hypot(first.orbit.state0[0], first.orbit.state0[2])

    def hill(a):
        def f(t, y):
            return [y[1], -(w2 + 2 * beta * a * np.cos(t)) * y[0]]
        cols = [solve_ivp(f, (0, 2 * np.pi), e, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
                for e in ([1.0, 0.0], [0.0, 1.0])]
        return np.linalg.eigvals(np.array(cols).T)

    # The tongue's edge: on the circle just before, a real pair below −1 just after.
    assert np.abs(hill(amplitude * (1 - 5e-3))).max() == pytest.approx(1.0, abs=1e-8)
    after = hill(amplitude * (1 + 5e-3))
    assert np.abs(after).max() > 1 and np.all(np.abs(after.imag) < 1e-9) and after.real.min() < -1


def test_the_jacobi_ellipsoid_s_first_lyapunov_families():
    # a₂/a₁ = 0.6 (benches/python/jacobi_lyapunov_family.py prints and draws both families).
    jacobi = lf.ellipsoids.jacobi(0.6)
    modes = jacobi.normal_modes()

    def family(k, points):
        start = lf.periodic_orbit.from_mode(jacobi, k, 1e-3, method="rattle6",
                                            dt=modes[k].period / 60)
        return lf.continuation.periodic_family(jacobi.body, start, max_points=points)

    # Mode 0: stable all along (as the linear analysis says at its start), up to its end on a
    # Riemann ellipsoid of type I with the same momentum and circulation, E = −15.1227717
    # (scipy's least squares on the co-moving field, in the bench): there the continuation
    # passes through and turns back.
    first = family(0, 40)
    assert first.end.startswith("turned back"), first
    assert first.stable.all() and not first.special_points
    assert max(np.abs(np.abs(o.normal_multipliers) - 1).max() for o in first.points) <= 1e-9
    assert np.all(np.diff(first.energies) > 0) and np.all(np.diff(first.periods) < 0)
    assert first.energies[-1] == pytest.approx(-15.1227717, abs=1e-3)
    # Mode 1: stable up to a period doubling: a normal multiplier through −1 (the bisection
    # locates it to 2⁻¹² of the step: ≈ 6e-5 in energy).
    second = family(1, 12)
    assert [sp.kind for sp in second.special_points] == ["period_doubling"], second
    sp = second.special_points[0]
    assert sp.value == pytest.approx(-14.85149, abs=2e-4)
    assert second.stable[:sp.index + 1].all() and not second.stable[sp.index + 1:].any()
    real = sp.orbit.normal_multipliers[np.abs(sp.orbit.normal_multipliers.imag) < 1e-9]
    assert real.size == 2 and np.abs(real + 1).max() <= 1e-2


def test_a_krein_collision_along_a_family_is_located_and_named():
    # H = H₁(1 + κC) + (ω₂/2)(p₂² + q₂²) − (ω₃/2)(p₃² + q₃²), H₁ = ½(q₁² + p₁²), C = q₂q₃ − p₂p₃:
    # the orbits x₁ = A cos t (period 2π, E = H₁) carry the normal system of
    # H₂₃ + c·C with c = κE, autonomous: eigenvalues ±i(ω̄ ± √(δ² − c²)), ω̄ = (ω₂ + ω₃)/2,
    # δ = (ω₂ − ω₃)/2. The two oscillators have opposite Krein signatures: at c = δ their
    # multipliers collide (at e^{±2πiω̄} = ±i) and leave the circle as a quadruplet.
    w2, w3, kappa = 1.3, 1.2, 1.0
    mean, half = (w2 + w3) / 2, (w2 - w3) / 2

    def parts(q, p):
        return 0.5 * (q[0] ** 2 + p[0] ** 2), q[1] * q[2] - p[1] * p[2]

    def hamiltonian(q, p):
        h1, c = parts(q, p)
        return (h1 * (1 + kappa * c) + 0.5 * w2 * (q[1] ** 2 + p[1] ** 2)
                - 0.5 * w3 * (q[2] ** 2 + p[2] ** 2))

    def gradient(q, p):
        h1, c = parts(q, p)
        k = kappa * h1
        return ([q[0] * (1 + kappa * c), w2 * q[1] + k * q[2], -w3 * q[2] + k * q[1]],
                [p[0] * (1 + kappa * c), w2 * p[1] - k * p[2], -w3 * p[2] - k * p[1]])

    def hessian(q, p, dq, dp):
        h1, c = parts(q, p)
        dc = dq[1] * q[2] + q[1] * dq[2] - dp[1] * p[2] - p[1] * dp[2]
        k, dk = kappa * h1, kappa * (q[0] * dq[0] + p[0] * dp[0])
        return ([dq[0] * (1 + kappa * c) + q[0] * kappa * dc,
                 w2 * dq[1] + dk * q[2] + k * dq[2], -w3 * dq[2] + dk * q[1] + k * dq[1]],
                [dp[0] * (1 + kappa * c) + p[0] * kappa * dc,
                 w2 * dp[1] - dk * p[2] - k * dp[2], -w3 * dp[2] - dk * p[1] - k * dp[1]])

    sys = lf.Canonical(hamiltonian, gradient, dof=3, hessian=hessian)
    start = lf.periodic_orbit(sys, [0.2, 0, 0, 0, 0, 0], 2 * np.pi, method="gauss6",
                              dt=2 * np.pi / 60)
    branch = lf.continuation.periodic_family(sys, start, stop=0.07, max_points=20)
    assert [sp.kind for sp in branch.special_points] == ["krein"], branch
    sp = branch.special_points[0]
    # Located on the unstable side within 2⁻¹² of the secant (≈ 4e-6 in energy).
    assert 0.05 <= sp.value <= 0.05 + 5e-6
    # The multipliers on both sides against the closed form (gauss6, 60 steps: ~1e-8).
    for orbit in branch.points:
        root = np.sqrt(complex(half ** 2 - (kappa * orbit.energy) ** 2))
        exact = np.exp(2j * np.pi * np.array([mean + root, mean - root]))
        exact = np.concatenate([exact, exact.conj()])
        got = orbit.normal_multipliers
        assert np.abs(got[:, None] - exact[None, :]).min(axis=0).max() <= 1e-6, orbit
        assert orbit.stable == (orbit.energy < 0.05)
    mu = sp.orbit.normal_multipliers
    assert np.all(np.abs(mu.imag) > 0.99) and np.abs(np.abs(mu) - 1).max() < 1e-2
    assert np.abs(mu).max() > 1 + 1e-6


def test_ctrl_c_ends_a_family_between_orbits(interrupted):
    """SIGINT during a native continuation: KeyboardInterrupt after the orbit in progress."""
    out, err, code, waited = interrupted(
        "import signal, lieflow as lf\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "j = lf.ellipsoids.jacobi(0.6)\n"
        "start = lf.periodic_orbit.from_mode(j, 1, 1e-3, method='rattle6',"
        " dt=j.normal_modes()[1].period / 100)\n"
        "print('start', flush=True)\n"
        "lf.continuation.periodic_family(j.body, start, max_points=1000, step=1e-4,"
        " max_step=1e-4)\n"
        "print('finished', flush=True)\n"
    )
    assert "KeyboardInterrupt" in err and "finished" not in out, err
    assert code != 0
    print(f"ended {waited:.1f} s after SIGINT")
