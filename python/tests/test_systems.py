"""The Lie–Poisson system classes (000 §3–§5) and lieflow.elliptic: constructors, observables
against numpy re-computations of their formulas, the exact rigid-body solution against scipy, and
every error path."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy import special
from scipy.integrate import solve_ivp

import lieflow as lf

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])


def random_rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def euler(inertia):
    return lambda t, m: np.cross(m, m / inertia)


# ---------------------------------------------------------------- elliptic


def test_elliptic_matches_scipy():
    rng = np.random.default_rng(0)
    u = rng.uniform(-50, 50, 200)
    m = rng.uniform(0, 0.999, 200)
    sn, cn, dn = lf.elliptic.ellipj(u, m)
    ssn, scn, sdn, ph = special.ellipj(u, m)
    np.testing.assert_allclose(sn, ssn, atol=1e-12)
    np.testing.assert_allclose(cn, scn, atol=1e-12)
    np.testing.assert_allclose(dn, sdn, atol=1e-12)
    np.testing.assert_allclose(lf.elliptic.ellipk(m), special.ellipk(m), rtol=1e-13)
    phi = rng.uniform(-10, 10, 200)
    np.testing.assert_allclose(lf.elliptic.ellipf(phi, m), special.ellipkinc(phi, m), rtol=1e-12)


def test_elliptic_broadcast_and_scalars():
    sn, cn, dn = lf.elliptic.ellipj(0.3, 0.5)
    assert np.ndim(sn) == 0 and abs(sn**2 + cn**2 - 1) < 1e-15
    assert isinstance(lf.elliptic.ellipk(0.25), float)
    sn, _, _ = lf.elliptic.ellipj(np.zeros((4, 1)), np.linspace(0, 0.9, 3))
    assert sn.shape == (4, 3)


@pytest.mark.parametrize("m", [1.0, -0.1, np.nan])
def test_elliptic_rejects_bad_parameter(m):
    with pytest.raises(lf.InvalidArgumentError, match="0 ≤ m < 1"):
        lf.elliptic.ellipk(m)


def test_elliptic_errors():
    with pytest.raises(lf.NonFiniteError):
        lf.elliptic.ellipj(np.inf, 0.5)
    with pytest.raises(lf.ShapeError, match="broadcast"):
        lf.elliptic.ellipf(np.zeros(3), np.zeros(4))


# ---------------------------------------------------------------- RigidBody


def test_rigid_body_basics():
    body = lf.RigidBody(inertia=I)
    assert isinstance(body, lf.LiePoissonSystem)
    assert body.state_dim == 3 and body.has_attitude
    assert lf.RigidBody.methods() == body.methods() == [
        "splitting", "splitting4", "splitting6", "splitting8", "processed6", "processed8",
        "processed10", "isospectral", "lgvi", "dmv", "dmv4", "dmv6", "dmv8", "dmv10", "rk4", "rkmk4",
        "exact"]
    np.testing.assert_array_equal(body.moments, I)
    assert body.frame is None
    assert "RigidBody" in repr(body)


def test_rigid_body_observables():
    rng = np.random.default_rng(1)
    body = lf.RigidBody([1.0, 2.0, 3.0])
    m = rng.standard_normal((4, 5, 3))
    np.testing.assert_allclose(body.energy(m), 0.5 * np.sum(m * m / I, axis=-1), rtol=1e-14)
    np.testing.assert_allclose(body.casimirs(m), np.sum(m * m, axis=-1, keepdims=True), rtol=1e-14)
    np.testing.assert_allclose(body.angular_velocity(m), m / I, rtol=1e-15)
    assert isinstance(body.energy(M0), float)
    r = np.stack([random_rotation(rng) for _ in range(5)])
    np.testing.assert_allclose(body.spatial_momentum(m, r), np.einsum("kij,bkj->bki", r, m),
                               atol=1e-14)
    np.testing.assert_allclose(body.spatial_momentum(M0, np.eye(3)), M0)
    np.testing.assert_array_equal(body._fields(m)["M"], m)


def test_rigid_body_matrix_inertia():
    """A (3, 3) SPD inertia: the same physics in a rotated body frame."""
    rng = np.random.default_rng(2)
    q = random_rotation(rng)
    body = lf.RigidBody(q @ np.diag(I) @ q.T)
    np.testing.assert_allclose(np.sort(body.moments), I, rtol=1e-12)
    qf = body.frame
    np.testing.assert_allclose(qf @ np.diag(body.moments) @ qf.T, q @ np.diag(I) @ q.T,
                               atol=1e-12)
    m = rng.standard_normal((6, 3))
    ref = lf.RigidBody(I)
    np.testing.assert_allclose(body.energy(m @ q.T), ref.energy(m), rtol=1e-12)
    np.testing.assert_allclose(body.angular_velocity(m @ q.T), (m / I) @ q.T, atol=1e-12)
    t = np.linspace(0, 5, 7)
    np.testing.assert_allclose(body.exact_solution(q @ M0, t), ref.exact_solution(M0, t) @ q.T,
                               atol=1e-10)


def sn_cn_dn_solution(t):
    """Independent closed form for I = (1, 2, 3), M0 = (1, 0.5, -0.3) from scipy.special.

    |M|²/2H lies in (I1, I2), so M1 keeps its sign and carries dn: M1 = s a1 dn u,
    M2 = a2 sn u, M3 = a3 cn u, u = u0 + λt. Substituting into Ṁ = M × I⁻¹M (d_ij = 1/I_i − 1/I_j)
    gives a2 λ = s a1 a3 d13, a3 λ = s a1 a2 d12, s a1 m λ = a2 a3 d23, and the invariants fix
    a3² = (2H − |M|²/I1)/(1/I3 − 1/I1), a1² = |M|² − a3², a2² = a3² d13/d12."""
    i1, i2, i3 = I
    d12, d13, d23 = 1 / i1 - 1 / i2, 1 / i1 - 1 / i3, 1 / i2 - 1 / i3
    mu2, two_h = M0 @ M0, np.sum(M0**2 / I)
    a3s = (two_h - mu2 / i1) / (1 / i3 - 1 / i1)
    a1s = mu2 - a3s
    a2s = a3s * d13 / d12
    a1, a2, a3 = np.sqrt([a1s, a2s, a3s])
    s = np.sign(M0[0])
    lam = s * a1 * a3 * d13 / a2
    m = a2s * d23 / (a1s * d13)
    u0 = special.ellipkinc(np.arctan2(M0[1] / a2, M0[2] / a3), m)
    sn, cn, dn, _ = special.ellipj(u0 + lam * t, m)
    return np.stack([s * a1 * dn, a2 * sn, a3 * cn], axis=-1)


def test_exact_solution_against_scipy_ellipj_and_dop853():
    body = lf.RigidBody(I)
    t = np.linspace(0, 30, 61)
    exact = body.exact_solution(M0, t)
    assert exact.shape == (61, 3)
    np.testing.assert_allclose(exact[0], M0, atol=1e-14)
    # Satisfies Euler's equation: an independent scipy.special closed form ...
    np.testing.assert_allclose(exact, sn_cn_dn_solution(t), atol=1e-12)
    # ... and DOP853 at rtol 1e-12.
    ref = solve_ivp(euler(I), (0, 30), M0, method="DOP853", t_eval=t, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(exact, ref.y.T, atol=1e-9)


# DOP853's error estimate divides 0/0 on steady rotations (M0 on a principal axis): harmless.
@pytest.mark.filterwarnings("ignore:invalid value encountered in scalar divide:RuntimeWarning")
@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(0.5, 4.0), min_size=3, max_size=3),
       st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3))
def test_exact_solution_random_bodies(inertia, m0):
    inertia, m0 = np.array(inertia), np.array(m0)
    if np.linalg.norm(m0) < 1e-3:
        return
    body = lf.RigidBody(inertia)
    try:
        m = body.exact_solution(m0, np.array([0.0, 1.0, 2.0]))
    except lf.InvalidArgumentError as e:  # the separatrix, where the modulus is 1
        assert "separatrix" in str(e)
        return
    ref = solve_ivp(euler(inertia), (0, 2), m0, method="DOP853", t_eval=[0.0, 1.0, 2.0],
                    rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(m, ref.y.T, atol=1e-7 * max(1.0, np.abs(m0).max()))


def test_exact_solution_shapes():
    body = lf.RigidBody(I)
    assert body.exact_solution(M0, 1.0).shape == (3,)
    assert body.exact_solution(np.stack([M0, 2 * M0]), [0.0, 1.0, 2.0]).shape == (2, 3, 3)
    with pytest.raises(lf.ShapeError):
        body.exact_solution(M0, np.zeros((2, 2)))
    with pytest.raises(lf.ShapeError):
        body.exact_solution([1.0, 2.0], [0.0])
    with pytest.raises(lf.NonFiniteError):
        body.exact_solution(M0, [np.nan])


@pytest.mark.parametrize("inertia, exc", [
    ([1.0, 0.0, 3.0], lf.InvalidArgumentError),
    ([1.0, -2.0, 3.0], lf.InvalidArgumentError),
    ([1.0, 2.0], lf.ShapeError),
    ([[1.0, 2.0], [2.0, 1.0]], lf.ShapeError),
    ([1.0, np.nan, 3.0], lf.InvalidArgumentError),
    ([[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], lf.InvalidArgumentError),   # not symmetric
    ([[1, 0, 0], [0, -1, 0], [0, 0, 1]], lf.InvalidArgumentError),    # not positive definite
    ([[1, 0, 0], [0, np.inf, 0], [0, 0, 1]], lf.NonFiniteError),
])
def test_rigid_body_bad_inertia(inertia, exc):
    with pytest.raises(exc):
        lf.RigidBody(inertia)


def test_observable_errors():
    body = lf.RigidBody(I)
    with pytest.raises(lf.ShapeError, match=r"\(\.\.\., 3\)"):
        body.energy(np.zeros((2, 4)))
    with pytest.raises(lf.NonFiniteError):
        body.casimirs([1.0, np.nan, 0.0])
    with pytest.raises(lf.ShapeError, match="broadcast"):
        body.spatial_momentum(np.zeros((2, 3)), np.tile(np.eye(3), (3, 1, 1)))
    with pytest.raises(lf.ShapeError):
        body.spatial_momentum(M0, np.eye(2))
    so4 = lf.GeneralizedRigidBody([1.0, 2.0, 3.0, 4.0])
    with pytest.raises(lf.ShapeError, match=r"\(\.\.\., 6\)"):
        so4.matrix(np.zeros(5))
    with pytest.raises(lf.NonFiniteError):
        so4.matrix(np.full(6, np.nan))


# ---------------------------------------------------------------- GeneralizedRigidBody


def skew(rng, n):
    a = rng.standard_normal((n, n))
    return a - a.T


def test_generalized_rigid_body():
    rng = np.random.default_rng(3)
    j = np.array([1.0, 2.0, 3.0, 4.5])
    body = lf.GeneralizedRigidBody(j)
    assert body.n == 4 and body.state_dim == 6 and not body.has_attitude
    assert lf.GeneralizedRigidBody.methods() == ["isospectral", "rk4", "rkmk4"]
    np.testing.assert_array_equal(body.moments, j)
    m = np.stack([skew(rng, 4) for _ in range(3)])
    z = body.state(m)
    assert z.shape == (3, 6)
    np.testing.assert_allclose(z[0], [m[0][i, k] for i in range(4) for k in range(i + 1, 4)])
    np.testing.assert_allclose(body.matrix(z), m, atol=1e-15)
    np.testing.assert_allclose(body._fields(z)["M"], m, atol=1e-15)
    d = j[:, None] + j[None, :]
    omega = m / d
    np.testing.assert_allclose(body.energy(z), 0.25 * np.einsum("bij,bij->b", m, omega),
                               rtol=1e-13)
    mtm = np.einsum("bji,bjk->bik", m, m)
    c = np.stack([0.5 * np.trace(mtm, axis1=1, axis2=2),
                  0.5 * np.trace(mtm @ mtm, axis1=1, axis2=2)], axis=-1)
    np.testing.assert_allclose(body.casimirs(z), c, rtol=1e-13)


def test_generalized_rigid_body_matrix_j_and_so3():
    """At n = 3 with J_i + J_j = I_k the energy is the rigid body's (same physics)."""
    rng = np.random.default_rng(4)
    j = np.array([2.5, 1.5, 0.5])          # J2+J3 = I1 = 2, J1+J3 = I2 = 3, J1+J2 = I3 = 4
    q = random_rotation(rng)
    body = lf.GeneralizedRigidBody(q @ np.diag(j) @ q.T)
    np.testing.assert_allclose(np.sort(body.moments), np.sort(j), atol=1e-12)
    w = M0
    hat = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    z = body.state(q @ hat @ q.T)
    assert abs(body.energy(z) - lf.RigidBody([2.0, 3.0, 4.0]).energy(w)) < 1e-13


@pytest.mark.parametrize("j, exc", [
    ([1.0], lf.ShapeError),
    ([1.0, -1.0, 2.0], lf.InvalidArgumentError),
    ([0.0, 0.0, 1.0], lf.InvalidArgumentError),
    ([1.0, np.nan], lf.NonFiniteError),
    (np.ones((2, 2, 2)), lf.ShapeError),
    ([[1.0, 0.3], [0.0, 1.0]], lf.InvalidArgumentError),
])
def test_generalized_rigid_body_bad_j(j, exc):
    with pytest.raises(exc):
        lf.GeneralizedRigidBody(j)


def test_generalized_state_rejects_non_skew():
    body = lf.GeneralizedRigidBody([1.0, 2.0, 3.0])
    with pytest.raises(lf.NotInGroupError):
        body.state(np.eye(3))
    with pytest.raises(lf.ShapeError):
        body.state(np.zeros((4, 4)))


# ---------------------------------------------------------------- HeavyTop


def test_heavy_top():
    rng = np.random.default_rng(5)
    top = lf.HeavyTop([1.0, 2.0, 3.0], 0.7, chi=[0.0, 2.0, 0.0])
    assert top.state_dim == 6 and top.has_attitude and top.mgl == 0.7
    np.testing.assert_allclose(top.chi, [0.0, 1.0, 0.0])
    assert lf.HeavyTop.methods() == ["splitting", "splitting4", "splitting6", "splitting8",
                                     "processed6", "processed8", "processed10", "lgvi", "rk4",
                                     "exact_splitting", "exact_splitting4", "exact_splitting6"]
    np.testing.assert_array_equal(lf.HeavyTop(I, 1.0).chi, [0.0, 0.0, 1.0])
    m, g = rng.standard_normal((5, 3)), rng.standard_normal((5, 3))
    z = top.state(m, g)
    np.testing.assert_array_equal(z, np.concatenate([m, g], axis=1))
    np.testing.assert_allclose(top.energy(z), 0.5 * np.sum(m * m / I, 1) + 0.7 * g[:, 1],
                               rtol=1e-14)
    np.testing.assert_allclose(top.casimirs(z), np.stack([np.sum(g * g, 1), np.sum(m * g, 1)], 1),
                               rtol=1e-14)
    r = random_rotation(rng)
    zr = top.state(m[0], attitude=r)
    np.testing.assert_array_equal(zr[3:], r[2])             # Gamma = R^T e3
    np.testing.assert_allclose(top.spatial_momentum(zr, r), r @ m[0], atol=1e-15)
    f = top._fields(z)
    np.testing.assert_array_equal(f["M"], m)
    np.testing.assert_array_equal(f["Gamma"], g)
    zz, batched = top._normalize_state((m[0], g[0]))
    assert not batched and zz.shape == (1, 6)
    zz, batched = top._normalize_state((m, g))
    assert batched and zz.shape == (5, 6)


def test_heavy_top_errors():
    with pytest.raises(lf.InvalidArgumentError, match="mgl"):
        lf.HeavyTop(I, -1.0)
    with pytest.raises(lf.InvalidArgumentError, match="chi"):
        lf.HeavyTop(I, 1.0, chi=[0.0, 0.0, 0.0])
    with pytest.raises(lf.ShapeError, match="chi"):
        lf.HeavyTop(I, 1.0, chi=[1.0, 2.0])
    with pytest.raises(lf.NonFiniteError):
        lf.HeavyTop(I, 1.0, chi=[1.0, np.nan, 0.0])
    with pytest.raises(lf.InvalidArgumentError):
        lf.HeavyTop([0.0, 1.0, 1.0], 1.0)
    top = lf.HeavyTop(I, 1.0)
    with pytest.raises(lf.InvalidArgumentError, match="exactly one"):
        top.state(M0)
    with pytest.raises(lf.InvalidArgumentError, match="exactly one"):
        top.state(M0, [0, 0, 1], attitude=np.eye(3))
    with pytest.raises(lf.ShapeError):
        top._normalize_state(M0)
    with pytest.raises(lf.NonFiniteError):
        top._normalize_state((M0, [0, np.nan, 1]))
    with pytest.raises(lf.ShapeError, match="Gamma"):
        top._normalize_state((M0, [0.0, 1.0]))
    z, batched = top._normalize_state((np.ones(6), np.zeros(6)))     # two flat states: a batch
    assert batched and z.shape == (2, 6)


# ---------------------------------------------------------------- SphericalPendulum


def test_spherical_pendulum():
    p = lf.SphericalPendulum(mass=2.0, length=0.5, g=9.0)
    assert (p.mass, p.length, p.g) == (2.0, 0.5, 9.0) and p.state_dim == 6
    assert lf.SphericalPendulum.methods() == ["splitting", "splitting4", "splitting6", "rk4"]
    th, ph, thd, phd = 0.7, 0.3, 0.4, 1.3
    z = p.state_from_spherical(th, ph, thd, phd)
    q = np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), -np.cos(th)])
    qd = (thd * np.array([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), np.sin(th)])
          + phd * np.array([-np.sin(th) * np.sin(ph), np.sin(th) * np.cos(ph), 0.0]))
    ml2 = 2.0 * 0.25
    np.testing.assert_allclose(z, np.concatenate([q, ml2 * np.cross(q, qd)]), atol=1e-15)
    # Energy = kinetic ½ml²|q̇|² + potential mgl q3, and L3 = ml² sin²θ φ̇.
    assert abs(p.energy(z) - (0.5 * ml2 * qd @ qd + 2.0 * 9.0 * 0.5 * q[2])) < 1e-13
    assert abs(p.vertical_momentum(z) - ml2 * np.sin(th) ** 2 * phd) < 1e-15
    np.testing.assert_allclose(p.casimirs(z), [1.0, 0.0], atol=1e-15)
    zs = p.state_from_spherical(np.linspace(0.1, 1, 4)[:, None], np.zeros(5))
    assert zs.shape == (4, 5, 6) and np.all(zs[..., 3:] == 0)
    f = p._fields(zs)
    np.testing.assert_array_equal(f["q"], zs[..., :3])
    np.testing.assert_array_equal(f["L"], zs[..., 3:])


def test_spherical_pendulum_errors():
    for kw in [dict(mass=0.0), dict(length=-1.0), dict(g=-1.0), dict(mass=np.nan)]:
        with pytest.raises(lf.InvalidArgumentError):
            lf.SphericalPendulum(**kw)
    p = lf.SphericalPendulum()
    with pytest.raises(lf.NonFiniteError):
        p.state_from_spherical(np.nan, 0.0)
    with pytest.raises(lf.ShapeError):
        p.state_from_spherical(np.zeros(2), np.zeros(3))
    with pytest.raises(lf.ShapeError):
        p.vertical_momentum(np.zeros(5))
