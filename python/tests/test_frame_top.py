"""002 §V: the tangent Euler top on R^3, S^3 and H^3 (lf.FrameTop). Each claim by a second route:
the SO(4) rigid body of lf.LiePoisson, the Killing momenta from positions, velocities and frames,
Poisson brackets by differentiating along the isometries' flows, the rank of the integrals."""

import pickle

import numpy as np
import pytest

import lieflow as lf

INERTIA = np.array([[2.0, 0.3, -0.1], [0.3, 3.1, 0.2], [-0.1, 0.2, 4.2]])
M = 1.3


def rot(w):
    return lf.lie.so3_exp(np.asarray(w, float))


def start(space):
    """A point, a tangent velocity (ambient) on `space`."""
    r = space.radius
    if space.ambient_dim == 3:
        return np.array([0.3, -0.2, 1.0]), np.array([0.4, 0.1, -0.3])
    if space.curvature > 0:
        x = np.array([0.5, -0.3, 0.6, 0.2])
        x *= r / np.linalg.norm(x)
        a = np.array([0.2, 0.5, -0.1, 0.4])
        return x, a - (a @ x) / r**2 * x
    xs = np.array([0.6, -0.4, 0.9])
    x = np.concatenate([[np.sqrt(r**2 + xs @ xs)], xs])
    vs = np.array([0.3, 0.2, -0.5])
    return x, np.concatenate([[xs @ vs / x[0]], vs])


SPACES = [lf.spaces.Euclidean(3), lf.spaces.Sphere(3, radius=1.7),
          lf.spaces.Hyperbolic(3, radius=1.4)]


def state(top):
    x, v = start(top.space)
    return top.state(x, rot([0.4, -0.7, 0.3]), v, [0.7, -0.4, 1.1])


@pytest.mark.parametrize("space", SPACES, ids=repr)
def test_state_views_killing_momenta_and_integrals(space):
    top = lf.FrameTop(space, M, INERTIA)
    x, v = start(space)
    R = rot([0.4, -0.7, 0.3])
    z = top.state(x, R, v, [0.7, -0.4, 1.1])
    np.testing.assert_allclose(top.position(z), x, atol=1e-14)
    np.testing.assert_allclose(top.velocity(z), v, atol=1e-14)
    np.testing.assert_allclose(top.frame(z), R, atol=1e-14)
    np.testing.assert_allclose(top.angular_velocity(z), [0.7, -0.4, 1.1], atol=1e-14)
    # The frame e = Ê(x) R.
    g = z[:16].reshape(4, 4)
    e = g[1:, 1:] if space.ambient_dim == 3 else g[:, 1:]
    np.testing.assert_allclose(e, space.reference_frame(x) @ R, atol=1e-14)
    # The Killing momenta from x, ẋ, e and Π = 𝕀ω (a second route).
    pi = INERTIA @ [0.7, -0.4, 1.1]
    J = top.killing_momenta(z)
    if space.ambient_dim == 3:
        p = M * v
        np.testing.assert_allclose(J, np.concatenate([np.cross(x, p) + R @ pi, p]), atol=1e-13)
    else:
        hat = lambda w: np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        K = M * (np.outer(v, x) - np.outer(x, v)) + e @ hat(pi) @ e.T
        np.testing.assert_allclose(J[:3], [K[3, 2], K[1, 3], K[2, 1]], atol=1e-13)
        np.testing.assert_allclose(J[3:], K[1:, 0] / space.radius, atol=1e-13)
    # Along the exact flow: H, T, H − T, the Casimirs and J kept (H³: a short run, g grows like
    # e^{d/r}).
    dt, steps = (5e-3, 1000) if space.curvature < 0 else (0.05, 2000)
    traj = lf.integrate(top, z, dt=dt, steps=steps, save_every=100)
    for f in (traj.energy(), top.translational_energy(traj.states),
              top.rotational_energy(traj.states)):
        np.testing.assert_allclose(f, f[0], rtol=1e-12)
    inv = traj.invariants()
    np.testing.assert_allclose(inv, np.broadcast_to(inv[0], inv.shape), rtol=1e-11, atol=1e-11)
    assert pickle.loads(pickle.dumps(top)).space == space
    assert {space: 1}[pickle.loads(pickle.dumps(space))] == 1     # hashable, equal by value


def test_on_the_three_sphere_it_is_the_so4_rigid_body_of_lie_poisson():
    top = lf.FrameTop(lf.spaces.Sphere(3, radius=1.7), M, INERTIA)
    z = state(top)
    J = top.group_inertia()
    coords = lambda m: m[..., [0, 0, 0, 1, 1, 2], [1, 2, 3, 2, 3, 3]]
    lp = lf.LiePoisson(("so", 4), np.linalg.inv(J))
    g0 = z[:16].reshape(4, 4)
    a = lf.integrate(top, z, dt=0.01, steps=1000, save_every=100)
    b = lf.integrate(lp, coords(top.group_momentum(z)), dt=0.01, steps=1000, save_every=100,
                     method="rkmk4", attitude=g0)
    np.testing.assert_allclose(coords(top.group_momentum(a.states)), b.states, atol=1e-9)
    np.testing.assert_allclose(a.states[:, :16].reshape(-1, 4, 4), b.attitude, atol=1e-9)
    # The frame top's Killing momenta are the Noether momentum g M gᵀ of LiePoisson's run:
    # K = [[0, −r J_Pᵀ], [r J_P, hat(J_Π)]].
    i, j = [0, 0, 0, 1, 1, 2], [1, 2, 3, 2, 3, 3]
    Mb = np.zeros((len(b.states), 4, 4))
    Mb[:, i, j], Mb[:, j, i] = b.states, -b.states
    K = b.attitude @ Mb @ np.swapaxes(b.attitude, -1, -2)
    J = top.killing_momenta(a.states)
    r = top.space.radius
    want = np.stack([-r * J[:, 3], -r * J[:, 4], -r * J[:, 5], -J[:, 2], J[:, 1], -J[:, 0]], axis=1)
    np.testing.assert_allclose(K[:, i, j], want, atol=1e-9)
    with pytest.raises(lf.InvalidArgumentError, match="3-sphere"):
        lf.FrameTop(lf.spaces.Euclidean(3), M, INERTIA).group_inertia()


def _brackets_and_rank(top, z):
    """On S³: the Poisson brackets of the Cartan pair of Killing momenta and the rank of the six
    integrals (H, T, C₁, C₂, J_P1, J_Π1) along the 12 tangent directions of T*SO(4), by central
    differences. {F, ⟨J, a⟩} is dF along the isometry flow g ↦ exp(τâ) g (μ fixed)."""
    r = top.space.radius

    def hat4(w, u):
        a = np.zeros((4, 4))
        a[1:, 1:] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
        a[1:, 0], a[0, 1:] = u / r, -u / r
        return a

    def expm(a):
        w, v = np.linalg.eig(a)
        return (v @ np.diag(np.exp(w)) @ np.linalg.inv(v)).real

    def with_g(z, g):
        y = z.copy()
        y[:16] = g.ravel()
        return y

    def funcs(y):
        inv = top.invariants(y)
        J = top.killing_momenta(y)
        return np.array([top.energy(y), top.translational_energy(y), inv[0], inv[1], J[3], J[0]])

    g = z[:16].reshape(4, 4)
    e = np.eye(3)
    h = 1e-5

    def bracket(f, a):   # {f, ⟨J, a⟩}: d/dτ f(exp(τâ) g)
        return (f(with_g(z, expm(h * a) @ g)) - f(with_g(z, expm(-h * a) @ g))) / (2 * h)

    J = lambda k: (lambda y: top.killing_momenta(y)[k])
    # ⟨J, a⟩ for a = (Ω-part, v-part): J_P1 ↔ a = (0, e1) up to a positive factor, J_Π1 ↔ (e1, 0).
    commuting = bracket(J(0), hat4(0 * e[0], e[0]))        # {J_Π1, J_P1}
    not_commuting = bracket(J(4), hat4(0 * e[0], e[0]))    # {J_P2, J_P1}
    cols = []
    for k in range(12):
        zp, zm = z.copy(), z.copy()
        if k < 6:
            a = hat4(e[k] if k < 3 else 0 * e[0], e[k - 3] if k >= 3 else 0 * e[0])
            zp, zm = with_g(z, g @ expm(h * a)), with_g(z, g @ expm(-h * a))
        else:
            zp[16 + k - 6] += h
            zm[16 + k - 6] -= h
        cols.append((funcs(zp) - funcs(zm)) / (2 * h))
    return commuting, not_commuting, np.linalg.svd(np.array(cols).T, compute_uv=False)


def test_integrability_on_the_three_sphere_six_integrals_in_involution_of_rank_six():
    top = lf.FrameTop(lf.spaces.Sphere(3, radius=1.7), M, INERTIA)
    z = state(top)
    commuting, not_commuting, sv = _brackets_and_rank(top, z)
    assert abs(commuting) < 1e-8
    assert abs(not_commuting) > 1e-2
    assert sv[-1] > 1e-3 * sv[0], sv
    # 002 §V lists "the total angular momentum and one of its components" among the integrals:
    # on S³ no component of the spin (parallel transported, in space e Π) is conserved, while
    # Π·P is.
    traj = lf.integrate(top, z, dt=0.05, steps=2000, save_every=100)
    g = traj.states[:, :16].reshape(-1, 4, 4)
    spin = np.einsum("kij,kj->ki", g[:, :, 1:], traj.states[:, 16:19])
    assert np.ptp(spin, axis=0).max() > 0.1
    c1 = np.einsum("ki,ki->k", traj.states[:, 16:19], traj.states[:, 19:22])
    np.testing.assert_allclose(c1, c1[0], rtol=1e-12)


def test_euclidean_space_a_free_particle_and_a_free_rigid_body():
    top = lf.FrameTop(lf.spaces.Euclidean(3), M, INERTIA)
    x, v = start(top.space)
    R = rot([0.4, -0.7, 0.3])
    z = top.state(x, R, v, [0.7, -0.4, 1.1])
    traj = lf.integrate(top, z, dt=0.3, steps=10, save_every=10)
    np.testing.assert_allclose(top.position(traj.final_state), x + 3.0 * v, atol=1e-13)
    body = lf.RigidBody(INERTIA)
    rb = lf.integrate(body, INERTIA @ [0.7, -0.4, 1.1], dt=0.3, steps=10, save_every=10,
                      method="exact", attitude=R)
    np.testing.assert_allclose(top.frame(traj.final_state), rb.attitude[-1], atol=1e-12)


def test_bad_input_is_refused_with_typed_errors():
    top = lf.FrameTop(lf.spaces.Sphere(3), M, [1.0, 2.0, 3.0])
    with pytest.raises(lf.InvalidArgumentError, match="not a point"):
        top.state([1.0, 0.1, 0, 0], np.eye(3), [0, 1.0, 0, 0], [0, 0, 1.0])
    with pytest.raises(lf.InvalidArgumentError, match="tangent"):
        top.state([1.0, 0, 0, 0], np.eye(3), [0.5, 1.0, 0, 0], [0, 0, 1.0])
    with pytest.raises(lf.NotInGroupError):
        top.state([1.0, 0, 0, 0], 2 * np.eye(3), [0, 1.0, 0, 0], [0, 0, 1.0])
    with pytest.raises(lf.ShapeError):
        top.state([1.0, 0, 0], np.eye(3), [0, 1.0, 0], [0, 0, 1.0])
    with pytest.raises(lf.InvalidArgumentError, match="n = 4"):
        lf.spaces.Sphere(4)
    with pytest.raises(lf.InvalidArgumentError):
        lf.spaces.Hyperbolic(3, radius=-1.0)
    with pytest.raises(lf.InvalidArgumentError, match="x₀ > 0"):
        lf.FrameTop(lf.spaces.Hyperbolic(3), M, [1.0, 2.0, 3.0]).state(
            [-1.0, 0, 0, 0], np.eye(3), [0, 1.0, 0, 0], [0, 0, 1.0])
    with pytest.raises(lf.ShapeError):
        lf.FrameTop(lf.spaces.Sphere(3), M, np.eye(4))
    z = top.state([1.0, 0, 0, 0], np.eye(3), [0, 1.0, 0, 0], [0, 0, 1.0])
    z[0] = 2.0     # g no longer in SO(4)
    with pytest.raises(lf.NotInGroupError):
        lf.integrate(top, z, dt=0.1, steps=1)


def test_for_n_greater_than_three_the_spin_is_the_free_rigid_body_on_so_n():
    """002 §V's counting for n > 3, made concrete for n = 4: the top on S⁴ is the left-invariant
    body on SO(5) with ℓ = ½ m r²|u|² + ½⟨Ω, 𝕀Ω⟩, and its spin block obeys exactly the free rigid
    body on so(4) (lf.GeneralizedRigidBody, Manakov's inertia Π = JΩ + ΩJ of a mass
    distribution), whatever the translation block does: the top is integrable exactly when that
    body is (Manakov's is; the curvature shift 𝕀⁻¹ − κ/m keeps it Manakov)."""
    m, r, J = 1.3, 1.7, np.array([0.7, 1.1, 1.6, 2.3])
    pairs = [(i, j) for i in range(5) for j in range(i + 1, 5)]
    inertia = [m * r * r if i == 0 else J[i - 1] + J[j - 1] for i, j in pairs]
    top = lf.LiePoisson(("so", 5), np.diag(1 / np.array(inertia)))
    mu0 = np.random.default_rng(1).standard_normal(10)
    a = lf.integrate(top, mu0, dt=0.01, steps=2000, save_every=200)
    b = lf.integrate(lf.GeneralizedRigidBody(J), mu0[4:], dt=0.01, steps=2000, save_every=200,
                     method="rk4")
    np.testing.assert_allclose(a.states[:, 4:], b.states, atol=1e-9)
    # The shifted operator 1/(J_i + J_j) − c is again Manakov's sectional form
    # (b_i − b_j)/(a_i − a_j) with a = J², b = J − cJ².
    c = 0.37
    aa, bb = J**2, J - c * J**2
    for i, j in pairs[4:]:
        i, j = i - 1, j - 1
        assert 1 / (J[i] + J[j]) - c == pytest.approx((bb[i] - bb[j]) / (aa[i] - aa[j]), rel=1e-13)


# ---- the top on a Riemannian chart (lf.spaces.Riemannian) ----

R3 = 1.3


def stereo_metric(y1, y2, y3):
    """S^3(R3) in the stereographic chart from its south pole: g = 4 R3^2 / (1 + |y|^2)^2."""
    lam = 2 * R3 / (1 + y1 * y1 + y2 * y2 + y3 * y3)
    return lam * lam * np.eye(3)


def stereo_frame(y1, y2, y3):
    return (1 + y1 * y1 + y2 * y2 + y3 * y3) / (2 * R3) * np.eye(3)


def stereo(y):
    s = y @ y
    return R3 * np.concatenate([[(1 - s) / (1 + s)], 2 * y / (1 + s)])


def stereo_jacobian(y):
    s = y @ y
    d = (1 + s) ** 2
    top = -4 * R3 * y / d
    rest = 2 * R3 * ((1 + s) * np.eye(3) - 2 * np.outer(y, y)) / d
    return np.vstack([top, rest])


def test_on_a_stereographic_chart_of_the_three_sphere_the_same_motion():
    """The chart's top (metric and frame as callables) against FrameTop on Sphere(3): the centre
    and the body axes in R^4, the angular velocity and T agree to the differences' accuracy;
    H - T and Pi.Pi are kept to round-off, T oscillates without drift."""
    chart = lf.FrameTop(lf.spaces.Riemannian(stereo_metric, stereo_frame), M, INERTIA)
    assert chart.methods() == ["midpoint", "midpoint4", "midpoint6", "rkmk4", "rk4"]
    group = lf.FrameTop(lf.spaces.Sphere(3, radius=R3), M, INERTIA)
    y0, yd0, R0 = np.array([0.3, -0.2, 0.5]), np.array([0.4, 0.1, -0.3]), rot([0.4, -0.7, 0.3])
    w0 = [0.7, -0.4, 1.1]
    z0 = chart.state(y0, R0, yd0, w0)
    assert z0.shape == (18,)
    np.testing.assert_allclose(chart.position(z0), y0)
    np.testing.assert_allclose(chart.velocity(z0), yd0, atol=1e-12)
    np.testing.assert_allclose(chart.frame(z0), R0)
    x0 = stereo(y0)
    J = stereo_jacobian(y0)
    axes = J @ chart.space.reference_frame(y0) @ R0
    g0 = group.state(x0, group.space.reference_frame(x0).T @ axes, J @ yd0, w0)
    a = lf.integrate(chart, z0, dt=0.05, steps=20, method="midpoint6")
    b = lf.integrate(group, g0, dt=0.05, steps=20)
    ya = chart.position(a.states)
    np.testing.assert_allclose(np.array([stereo(y) for y in ya]), group.position(b.states),
                               atol=1e-8)
    got = np.array([stereo_jacobian(y) @ chart.space.reference_frame(y) @ r
                    for y, r in zip(ya, chart.frame(a.states))])
    want = group.space.reference_frame(group.position(b.final_state)) @ group.frame(b.final_state)
    np.testing.assert_allclose(got[-1], want, atol=1e-8)
    np.testing.assert_allclose(chart.angular_velocity(a.states), group.angular_velocity(b.states),
                               atol=1e-12)
    np.testing.assert_allclose(chart.translational_energy(a.states),
                               group.translational_energy(b.states), rtol=1e-8)
    inv = chart.invariants(a.states)
    np.testing.assert_allclose(inv, np.broadcast_to(inv[0], inv.shape), rtol=1e-13)
    np.testing.assert_allclose(chart.rotational_energy(a.states),
                               group.rotational_energy(b.states), rtol=1e-13)


def test_a_chart_of_flat_space_with_a_turning_frame_is_the_euclidean_top():
    """A rotating orthonormal frame of flat space: the motion is a free particle and a free rigid
    body whatever the frame (its connection enters the spin's coupling and cancels)."""
    def turning(x1, x2, x3):
        return rot([0.3 * x1, -0.2 * x3, 0.4 * x1 * x2]).T     # rows = the frame vectors

    chart = lf.FrameTop(lf.spaces.Riemannian(lambda *x: np.eye(3), turning), M, INERTIA)
    x, v, R = np.array([0.3, -0.2, 1.0]), np.array([0.4, 0.1, -0.3]), rot([0.4, -0.7, 0.3])
    traj = lf.integrate(chart, chart.state(x, R, v, [0.7, -0.4, 1.1]), dt=0.05, steps=20,
                        method="midpoint4")
    flat = lf.FrameTop(lf.spaces.Euclidean(3), M, INERTIA)
    Q0 = turning(*x).T
    ref = lf.integrate(flat, flat.state(x, Q0 @ R, v, [0.7, -0.4, 1.1]), dt=1.0, steps=1)
    xe = chart.position(traj.final_state)
    np.testing.assert_allclose(xe, x + v, atol=1e-9)
    np.testing.assert_allclose(turning(*xe).T @ chart.frame(traj.final_state),
                               flat.frame(ref.final_state), atol=1e-8)


def within_three(y1, y2, y3):
    return y1 * y1 + y2 * y2 + y3 * y3 < 9.0


def test_a_chart_pickles_refuses_what_it_lacks_and_raises_its_callables_exceptions():
    space = lf.spaces.Riemannian(stereo_metric, stereo_frame, within_three)
    top = lf.FrameTop(space, M, [1.0, 2.0, 3.0])
    again = pickle.loads(pickle.dumps(top))
    z = top.state([0.1, 0.2, 0.3], np.eye(3), [0.1, 0, 0], [0, 0, 1.0])
    np.testing.assert_array_equal(again.state([0.1, 0.2, 0.3], np.eye(3), [0.1, 0, 0],
                                              [0, 0, 1.0]), z)
    assert space == space and space != lf.spaces.Riemannian(stereo_metric, stereo_frame)
    space.check_frame([0.1, 0.2, 0.3])
    with pytest.raises(lf.InvalidArgumentError, match="g\\(Ê_1, Ê_1\\)"):
        lf.spaces.Riemannian(stereo_metric, lambda *y: np.eye(3)).check_frame([0.1, 0.2, 0.3])
    with pytest.raises(lf.InvalidArgumentError, match="check_frame"):
        lf.spaces.Sphere(3).check_frame([0.1, 0.2, 0.3])
    for what in ("killing_momenta", "group_momentum"):
        with pytest.raises(lf.InvalidArgumentError, match="Killing"):
            getattr(top, what)(z)
    with pytest.raises(lf.InvalidArgumentError, match="curvature"):
        space.curvature
    with pytest.raises(lf.InvalidArgumentError, match="outside the chart"):
        top.state([3.0, 0.0, 0.5], np.eye(3), [0.1, 0, 0], [0, 0, 1.0])

    def failing(y1, y2, y3):
        if y1 > 0.15:
            raise ZeroDivisionError("metric fails here")
        return stereo_metric(y1, y2, y3)

    bad = lf.FrameTop(lf.spaces.Riemannian(failing, stereo_frame), M, [1.0, 2.0, 3.0])
    z0 = bad.state([0.1, 0.0, 0.0], np.eye(3), [1.0, 0, 0], [0, 0, 1.0])
    with pytest.raises(ZeroDivisionError, match="fails here"):
        lf.integrate(bad, z0, dt=0.02, steps=20)
