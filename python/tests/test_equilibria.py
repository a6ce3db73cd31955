"""Relative equilibria of pseudo-rigid bodies and their stability from Python (001 §8):
augmented/amended potentials against finite differences and each other, the admissible
directions (8.6), the three solvers, the motion against the integrator, and the two stability
verdicts against simulations."""

import numpy as np
import pytest

import lieflow as lf

pr = lf.pseudo_rigid
pot = lf.potentials


def e(i, j, n=3):
    m = np.zeros((n, n))
    m[i, j], m[j, i] = 1.0, -1.0
    return m


SVK = pot.SaintVenantKirchhoff(1.0, 1.0)


def test_augmented_gradient_is_the_derivative_and_vanishes_at_an_equilibrium():
    rng = np.random.default_rng(3)
    x = np.diag([1.3, 1.0, 0.8]) + 0.05 * rng.standard_normal((3, 3))
    xi, eta = 0.4 * e(0, 1) + 0.1 * e(1, 2), 0.2 * e(0, 2)
    g = pr.augmented_gradient(x, xi, eta, SVK)
    v = rng.standard_normal((3, 3))
    h = 1e-6
    fd = (pr.augmented_potential(x + h * v, xi, eta, SVK)
          - pr.augmented_potential(x - h * v, xi, eta, SVK)) / (2 * h)
    assert abs(fd - np.sum(g * v)) < 1e-7 * max(1.0, abs(fd))
    # U_aug = U - |xi X - X eta|^2 / 2 (the quadratic form of B_X, 001 (6.25)).
    w = xi @ x - x @ eta
    assert abs(pr.augmented_potential(x, xi, eta, SVK) - (SVK.value(x) - 0.5 * np.sum(w * w))) < 1e-13
    (r,) = [q for q in pr.relative_equilibria(SVK, velocities=(0.5 * e(0, 1), 0.9 * e(0, 1)),
                                              bounds=(0.05, 3.0), starts=5)
            if q.shape[0] > q.shape[1]]
    assert np.abs(pr.augmented_gradient(np.diag(r.shape), r.xi, r.eta, SVK)).max() < 1e-12


def test_amended_and_augmented_potentials_are_legendre_partners():
    x = np.diag([1.4, 1.0, 0.7])
    xi, eta = 0.3 * e(0, 1), -0.2 * e(0, 1)
    lam, gam = pr.bi_inertia_apply(x, xi, eta)
    u = SVK.value(x)
    # V + U_aug = 2U at lam + gam = B_X(xi + eta).
    assert abs(pr.amended_potential(x, lam, gam, SVK) + pr.augmented_potential(x, xi, eta, SVK)
               - 2 * u) < 1e-13


def test_directions_satisfy_8_6_and_include_disjoint_plane_sums_for_n_4():
    for a in ([3.0, 2.0, 1.0], [4.0, 3.0, 2.0, 1.0]):
        dirs = pr.equilibrium_directions(a)
        b = np.array(a)
        for d in dirs:
            lam, gam = pr.bi_inertia_apply(np.diag(b), d["xi"], d["eta"])
            assert np.abs(d["xi"] @ lam - lam @ d["xi"]).max() < 1e-12
            assert np.abs(d["eta"] @ gam - gam @ d["eta"]).max() < 1e-12
        if len(a) == 4:
            assert any(len(d["planes"]) == 2 for d in dirs)


def test_solvers_agree_and_motion_solves_the_equations():
    xi, eta = 0.5 * e(0, 1), 0.9 * e(0, 1)
    found = pr.relative_equilibria(SVK, velocities=(xi, eta), bounds=(0.05, 3.0), starts=5)
    assert len(found) >= 1
    r = found[0]
    assert max(r.residuals.values()) < 1e-10
    # The shape solver finds the same velocities back (and their sign/Dedekind partners).
    by_shape = pr.relative_equilibria(SVK, shape=r.shape, plane=(0, 1))
    assert any(np.allclose(q.xi, xi) and np.allclose(q.eta, eta) for q in by_shape)
    # The momenta solver finds the same shape back.
    by_momenta = pr.relative_equilibria(SVK, momenta=(r.L, r.Gamma), bounds=(0.05, 3.0), starts=5)
    assert any(np.allclose(q.shape, r.shape, atol=1e-8) for q in by_momenta)
    # The motion is a solution: verlet4 from (X0, P0) follows it.
    t = np.linspace(0.0, 10.0, 11)
    X, P = r.motion(t)
    assert X.shape == (11, 3, 3) and P.shape == (11, 3, 3)
    body = lf.PseudoRigidBody(3, SVK)
    tr = lf.integrate(body, (X[0], P[0]), dt=0.01, steps=1000, method="verlet4", save_every=100)
    assert np.abs(tr.X - X).max() < 1e-8 and np.abs(tr.P - P).max() < 1e-8
    np.testing.assert_allclose(tr.energy(), r.energy, rtol=1e-12)
    np.testing.assert_allclose(tr.angular_momentum()[-1], r.L, atol=1e-12)


def test_degenerate_cases_are_reported():
    with pytest.raises(lf.InvalidArgumentError):
        pr.relative_equilibria(SVK, shape=[1.2, 1.0, 0.8])   # no plane
    with pytest.raises(lf.DegenerateStratumError):
        pr.relative_equilibria(SVK, shape=[1.0, 1.0, 0.8], plane=(0, 1))
    with pytest.raises(lf.InvalidArgumentError):   # a force off the plane cannot be balanced
        pr.relative_equilibria(SVK, shape=[1.5, 1.2, 0.5], plane=(0, 1))


@pytest.mark.parametrize("w, l, stable", [(0.5, 0.9, True), (0.3, 0.5, False)])
def test_stability_verdicts_agree_with_simulation(w, l, stable):
    found = pr.relative_equilibria(SVK, velocities=(w * e(0, 1), l * e(0, 1)),
                                   bounds=(0.05, 3.0), starts=5)
    r = max(found, key=lambda q: q.shape[0])
    s = r.stability()
    assert s.spectral.stable == stable and s.spectral.conclusive != stable
    assert s.energy_momentum.stable == stable
    if stable:
        assert s.energy_momentum.conclusive and np.all(s.energy_momentum.eigenvalues.real > 0)
    else:
        assert s.spectral.max_real_part > 0.1
    X, P = r.motion([0.0])
    rng = np.random.default_rng(1)
    X0 = X[0] + 1e-4 * rng.standard_normal((3, 3))
    body = lf.PseudoRigidBody(3, SVK, check_det=False)
    tr = lf.integrate(body, (X0, P[0]), dt=0.01, steps=20_000, method="verlet4", save_every=100)
    dev = np.abs(tr.singular_values() - np.sort(r.shape)[::-1]).max()
    assert (dev < 1e-3) == stable, dev


def test_stretch_potential_family_in_one_plane():
    st = pot.Stretch(1.0)
    found = pr.relative_equilibria(st, shape=[1.5, 1.2, 1.0], plane=(0, 1))
    assert len(found) == 4 and all(q.residuals["motion"] < 1e-12 for q in found)
    speeds = sorted((round(abs(q.xi[0, 1]), 12), round(abs(q.eta[0, 1]), 12)) for q in found)
    assert speeds[0] == speeds[1]      # ± signs of the same rotation


# --- Hessians of the augmented and amended potentials (001 (8.11)-(8.12)) ---

HESSIAN_POTENTIALS = [
    pot.SaintVenantKirchhoff(0.7, 1.3),
    pot.Harmonic(0.8) + pot.Volumetric(0.4, 1.4),
    pot.Stretch(1.1),
]


def _skew(rng, n, s=1.0):
    m = s * rng.standard_normal((n, n))
    return 0.5 * (m - m.T)


def _principal(rng, n):
    while True:
        x = np.diag(1.0 + 0.3 * np.arange(n)) + 0.15 * rng.standard_normal((n, n))
        sv = np.linalg.svd(x, compute_uv=False)
        if np.linalg.det(x) > 0 and np.min(-np.diff(sv)) > 0.1 and sv[-1] > 0.3:
            return x


def _fd_amended_gradient(x, lam, gam, p, h=1e-4):
    """Central-difference gradient of amended_potential (tr pairing), O(h^4) five-point rule."""
    g = np.zeros_like(x)
    for idx in np.ndindex(*x.shape):
        e = np.zeros_like(x)
        e[idx] = h
        f = [pr.amended_potential(x + k * e, lam, gam, p) for k in (-2, -1, 1, 2)]
        g[idx] = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * h)
    return g


@pytest.mark.parametrize("n", [2, 3, 4])
@pytest.mark.parametrize("p", HESSIAN_POTENTIALS, ids=["svk", "harmonic+gas", "stretch"])
def test_augmented_hessian_is_the_derivative_of_augmented_gradient(n, p):
    rng = np.random.default_rng(10 + n)
    x = _principal(rng, n)
    xi, eta, v = _skew(rng, n, 0.8), _skew(rng, n, 0.8), rng.standard_normal((n, n))
    hv = pr.augmented_hessian(x, xi, eta, p, V=v)
    h = 1e-5
    fd = (pr.augmented_gradient(x + h * v, xi, eta, p)
          - pr.augmented_gradient(x - h * v, xi, eta, p)) / (2 * h)
    assert hv.shape == (n, n)
    assert np.linalg.norm(hv - fd) < 1e-7 * np.linalg.norm(fd)
    m = pr.augmented_hessian(x, xi, eta, p)
    assert m.shape == (n * n, n * n)
    np.testing.assert_allclose(m, m.T, atol=1e-12 * np.abs(m).max())
    # Row-major vec basis: M @ vec(V) = vec(D^2[V]).
    np.testing.assert_allclose(m @ v.ravel(), hv.ravel(), atol=1e-12 * np.abs(hv).max())


@pytest.mark.parametrize("n", [2, 3, 4])
@pytest.mark.parametrize("p", HESSIAN_POTENTIALS, ids=["svk", "harmonic+gas", "stretch"])
def test_amended_hessian_against_finite_differences_of_the_amended_potential(n, p):
    rng = np.random.default_rng(20 + n)
    x = _principal(rng, n)
    lam, gam, v = _skew(rng, n), _skew(rng, n), rng.standard_normal((n, n))
    hv = pr.amended_hessian(x, lam, gam, p, V=v)
    h = 1e-4
    fd = (_fd_amended_gradient(x + h * v, lam, gam, p)
          - _fd_amended_gradient(x - h * v, lam, gam, p)) / (2 * h)
    assert np.linalg.norm(hv - fd) < 1e-5 * np.linalg.norm(fd)
    m = pr.amended_hessian(x, lam, gam, p)
    np.testing.assert_allclose(m, m.T, atol=1e-11 * np.abs(m).max())
    np.testing.assert_allclose(m @ v.ravel(), hv.ravel(), atol=1e-12 * np.abs(hv).max())
    # The amended Hessian is the augmented one at xi + eta = B_X^{-1}(lam + gam) plus a
    # positive semidefinite term.
    xi, eta = pr.bi_inertia_solve(x, lam, gam)
    d = m - pr.augmented_hessian(x, xi, eta, p)
    ev = np.linalg.eigvalsh(0.5 * (d + d.T))
    assert ev.min() > -1e-10 * ev.max()


def test_hessians_reject_bad_input():
    x = np.diag([1.3, 1.0, 0.8])
    with pytest.raises(lf.ShapeError):
        pr.augmented_hessian(x, e(0, 1), e(0, 2), SVK, V=np.zeros((2, 2)))
    with pytest.raises(lf.DegenerateStratumError):
        pr.amended_hessian(np.eye(3), e(0, 1), e(0, 2), SVK)


def test_n4_equilibrium_with_two_disjoint_planes_is_judged_and_simulated():
    # An (8.18) combination: rotation in the planes (1,2) and (3,4) at once.
    xi, eta = 0.3 * e(0, 1, 4) + 0.5 * e(2, 3, 4), 0.5 * e(0, 1, 4) + 0.9 * e(2, 3, 4)
    found = pr.relative_equilibria(SVK, velocities=(xi, eta), bounds=(0.05, 3.0), starts=4)
    r = found[0]
    assert max(r.residuals.values()) < 1e-12 and len(set(np.round(r.shape, 6))) == 4
    s = r.stability()
    assert not s.spectral.stable and s.spectral.max_real_part > 0.2
    X, P = r.motion([0.0])
    body = lf.PseudoRigidBody(4, SVK, check_det=False)
    X0 = X[0] + 1e-4 * np.random.default_rng(2).standard_normal((4, 4))
    tr = lf.integrate(body, (X0, P[0]), dt=0.01, steps=10_000, method="verlet4", save_every=100)
    assert np.abs(tr.singular_values() - np.sort(r.shape)[::-1]).max() > 1e-2   # it leaves


def test_coincident_solutions_found_beside_principal_ones_are_named_in_a_warning():
    with pytest.warns(UserWarning, match="coincident semi-axes"):
        found = pr.relative_equilibria(SVK, velocities=(0.6 * e(0, 1), 0.4 * e(0, 1)),
                                       bounds=(0.05, 3.0), starts=5)
    assert found and all(len(set(np.round(q.shape, 8))) == 3 for q in found)


def test_verdict_reprs_speak_python_and_name_the_deciding_number():
    s = lf.ellipsoids.jacobi(0.6).stability()
    em, sp = s.energy_momentum, s.spectral
    assert (em.kind, sp.kind) == ("energy_momentum", "spectral")
    # The Hessian's verdict rests on its smallest eigenvalue, the spectrum's on its largest
    # real part.
    assert em.min_real_part == pytest.approx(np.min(em.eigenvalues.real))
    assert em.min_real_part > 0 and em.stable and em.conclusive
    assert sp.max_real_part == pytest.approx(np.max(sp.eigenvalues.real), abs=1e-15)
    r_em, r_sp = repr(em), repr(sp)
    assert "stable=True" in r_em and "conclusive=True" in r_em and "min_eigenvalue=" in r_em
    assert "max_real_part" not in r_em
    assert "stable=True" in r_sp and "conclusive=False" in r_sp and "max_real_part=" in r_sp
    assert "true" not in repr(s) and "false" not in repr(s)
