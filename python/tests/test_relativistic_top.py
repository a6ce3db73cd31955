"""The relativistic tangent top (002 §IV) from Python: the symmetric top in Minkowski space keeps
its speed and spin and satisfies the re-derived relations (94)–(96); the weak-field top keeps its
energy and angular momentum and follows the Newtonian orbit when the spin vanishes; the top on a
curved static space-time over a surface (002 (97)-(103)) keeps its energy, p_theta and Killing
momenta, pickles, and rejects bad surfaces; the static-field top (002 (115)-(117)) in the plane
and over a surface."""

import pickle

import numpy as np
import pytest

import lieflow as lf


def test_symmetric_top_keeps_speed_and_spin():
    top = lf.RelativisticTangentTop(1.0, 0.2)
    z0 = top.state([0.0, 0.0], 0.3, [0.5, 0.2], 2.0)
    tr = lf.integrate(top, z0, dt=0.05, steps=400, save_every=40)
    v = top.velocities(tr.states)
    speed = np.hypot(v[:, 0], v[:, 1])
    assert np.ptp(speed) < 1e-13 and np.ptp(v[:, 2]) < 1e-12
    assert np.ptp(tr.energy()) < 1e-13
    copy = pickle.loads(pickle.dumps(top))
    np.testing.assert_array_equal(lf.integrate(copy, z0, dt=0.05, steps=400, save_every=40).states,
                                  tr.states)


def test_superluminal_state_is_rejected():
    top = lf.RelativisticTangentTop(1.0, 0.2)
    with pytest.raises(lf.LieflowError):
        top.state([0.0, 0.0], 0.0, [0.9, 0.6], 1.0)


def test_weak_field_top_conserves_energy_and_angular_momentum():
    top = lf.WeakFieldTop(1.0, 1e-3, gm=1e-4)
    v = np.sqrt(1e-4)      # a circular orbit of radius 1
    z0 = top.state([1.0, 0.0], 0.0, [0.0, v], 0.5)
    tr = lf.integrate(top, z0, dt=1.0, steps=2000, method="gauss6", save_every=100)
    assert np.ptp(tr.energy()) < 1e-14
    assert np.ptp(top.angular_momentum(tr.states)) < 1e-14
    r = np.hypot(tr.states[:, 0], tr.states[:, 1])
    assert np.abs(r - 1.0).max() < 1e-2
    with pytest.raises(lf.InvalidArgumentError):
        lf.WeakFieldTop(1.0, 1e-3)


def test_symmetric_top_on_a_sphere_conserves_energy_p_theta_and_j_z():
    # 002 (97)-(103): the top on -dt^2 + g over the unit sphere; gauss6 keeps p_theta and the
    # affine Killing momentum J_z to round-off, the energy to ~1e-14; v and s stay constant.
    top = lf.RelativisticTangentTop(1.0, 0.2, surface=lf.surfaces.Sphere(1.0))
    z0 = top.state([1.2, 0.3], 0.5, [0.3, 0.4], 2.0)
    tr = lf.integrate(top, z0, dt=0.02, steps=2000, method="gauss6", save_every=100)
    assert np.ptp(tr.energy()) < 1e-12
    assert np.ptp(tr.states[:, 5]) < 1e-14
    inv = top.invariants(tr.states)
    assert inv.shape == (len(tr.states), 2)             # p_theta, J_z
    assert np.ptp(inv, axis=0).max() < 1e-12
    j = top.killing_momenta(tr.states)
    assert j.shape == (len(tr.states), 3)
    assert np.ptp(j, axis=0).max() < 1e-10
    vs = top.speed_and_spin(tr.states)
    assert np.ptp(vs, axis=0).max() < 1e-12 and 0.4 < vs[0, 0] < 0.6
    # The centre moves: the run is not trivial.
    assert np.ptp(tr.states[:, 1]) > 0.5


def test_surface_top_pickles_and_reproduces_the_run():
    top = lf.RelativisticTangentTop(1.0, 0.2, lf.surfaces.HyperbolicPlane())
    copy = pickle.loads(pickle.dumps(top))
    assert "HyperbolicPlane" in repr(copy)
    z0 = top.state([0.1, 1.0], 0.0, [0.4, 0.2], 1.3)
    a = lf.integrate(top, z0, dt=0.05, steps=40).states
    b = lf.integrate(copy, z0, dt=0.05, steps=40).states
    np.testing.assert_array_equal(a, b)
    # On the Plane it is the Minkowski top.
    plane = lf.RelativisticTangentTop(1.0, 0.2, surface=lf.surfaces.Plane())
    flat = lf.RelativisticTangentTop(1.0, 0.2)
    z0 = flat.state([0.0, 0.0], 0.3, [0.5, 0.2], 2.0)
    np.testing.assert_allclose(lf.integrate(plane, z0, dt=0.05, steps=40).states,
                               lf.integrate(flat, z0, dt=0.05, steps=40).states, atol=1e-13)
    np.testing.assert_allclose(flat.killing_momenta(z0), plane.killing_momenta(z0), atol=1e-15)


def test_bad_surface_arguments_are_rejected():
    with pytest.raises(TypeError):
        lf.RelativisticTangentTop(1.0, 0.2, surface="sphere")
    with pytest.raises(TypeError):
        lf.RelativisticTangentTop(1.0, 0.2, surface=lf.TangentTop(lf.surfaces.Plane(), 1.0, 1.0))
    with pytest.raises(lf.ShapeError):             # neither tr I, (3,) nor (2, 2)
        lf.RelativisticTangentTop(1.0, (0.1, 0.0), surface=lf.surfaces.Sphere(1.0))
    top = lf.RelativisticTangentTop(1.0, 0.2, surface=lf.surfaces.Sphere(2.0))
    with pytest.raises(lf.InvalidArgumentError):   # v = R |dtheta/dt| = 1.2
        top.state([1.0, 0.0], 0.0, [0.6, 0.0], 1.0)
    with pytest.raises(lf.InvalidArgumentError):   # outside the chart 0 < theta < pi
        top.state([-0.1, 0.0], 0.0, [0.1, 0.0], 1.0)


def test_surface_from_callables_matches_the_sphere_and_raises_their_errors():
    S = lf.surfaces

    def metric(t, p):
        return [[1.0, 0.0], [0.0, np.sin(t) ** 2]]

    def frame(t, p):
        if t > 1.5:
            raise RuntimeError("frame failed")
        return [[1.0, 0.0], [0.0, 1.0 / np.sin(t)]]

    python = lf.RelativisticTangentTop(1.0, 0.2, S.MetricSurface(metric, frame, None))
    native = lf.RelativisticTangentTop(1.0, 0.2, S.Sphere(1.0))
    z0 = native.state([1.0, 0.3], 0.5, [0.2, 0.3], 1.5)
    a = lf.integrate(python, z0, dt=0.02, steps=20).states
    b = lf.integrate(native, z0, dt=0.02, steps=20).states
    np.testing.assert_allclose(a, b, atol=1e-7)
    with pytest.raises(RuntimeError, match="frame failed"):
        python.state([1.6, 0.0], 0.0, [0.1, 0.0], 1.0)


def test_weak_field_top_methods_and_pickling():
    # methods() on the class and pickling pass the constructor arguments positionally
    assert lf.WeakFieldTop.methods()[0] == "gauss4"
    top = lf.WeakFieldTop(1.0, 1e-3, gm=1e-4)
    copy = pickle.loads(pickle.dumps(top))
    assert repr(copy) == repr(top) and copy.methods() == top.methods()


# --- the relations (94)-(96) of the symmetric top (issue 25) ---

@pytest.mark.parametrize("surface, x", [(None, [0.3, -0.2]), (lf.surfaces.Sphere(1.3), [1.1, 0.4]),
                                        (lf.surfaces.HyperbolicPlane(), [0.2, 1.1])])
def test_relations_94_to_96_are_the_legendre_map_and_the_energy(surface, x):
    # The states come from the Legendre map of the Lagrangian (002 (93) / (103)) and the energy
    # from the Hamiltonian; (94)-(96) are the closed forms in (v, J = p_theta) and (v, s).
    top = lf.RelativisticTangentTop(1.0, 0.2, surface)
    for xdot, thetadot in ([0.3, -0.2], 2.5), ([0.05, 0.1], -1.2), ([-0.35, 0.3], 0.4):
        z = np.asarray(top.state(x, 0.4, xdot, thetadot))
        (v, s), j = top.speed_and_spin(z), z[5]
        if surface is None:
            p = np.hypot(z[3], z[4])
            assert s == pytest.approx(thetadot, abs=1e-14)
        else:   # |p_x - p_theta alpha| in the inverse metric
            pi = z[3:5] - j * np.asarray(surface.connection(x))
            p = np.sqrt(pi @ np.linalg.solve(surface.metric(x), pi))
        assert top.momentum_94(v, j) == pytest.approx(p, rel=1e-12)
        assert top.spin_rate_95(v, j) == pytest.approx(s, rel=1e-12)
        assert top.energy_96(v, s) == pytest.approx(top.energy(z), rel=1e-13)
    # They map over broadcast leading axes.
    vs = np.array([[0.1], [0.5]])
    assert top.momentum_94(vs, [0.2, 0.3, 0.4]).shape == (2, 3)
    np.testing.assert_allclose(top.energy_96(vs, 2.0)[:, 0],
                               [top.energy_96(0.1, 2.0), top.energy_96(0.5, 2.0)], rtol=0)
    assert isinstance(top.spin_rate_95(0.5, 0.3), float)


def test_relations_94_to_96_refuse_what_they_do_not_cover():
    top = lf.RelativisticTangentTop(1.0, 0.2)
    for f in (top.momentum_94, top.spin_rate_95, top.energy_96):
        with pytest.raises(lf.InvalidArgumentError, match="v"):
            f(1.0, 0.3)                                        # v = c
        with pytest.raises(lf.InvalidArgumentError, match="v"):
            f([0.2, -0.1], 0.3)
        with pytest.raises(lf.NonFiniteError):
            f(0.5, np.nan)
        with pytest.raises(lf.ShapeError):
            f([0.1, 0.2], [0.1, 0.2, 0.3])
    with pytest.raises(lf.InvalidArgumentError, match="p_theta"):
        top.momentum_94(0.5, 1e300)                            # |p| beyond the float range
    aniso = lf.RelativisticTangentTop(1.0, (0.1, 0.02, 0.2))
    with pytest.raises(lf.InvalidArgumentError, match="symmetric"):
        aniso.momentum_94(0.5, 0.3)


def test_relation_94_does_not_fix_the_speed_for_fast_spin():
    # 002 concludes from (94) that |p| determines v. v -> |p| is monotone only for
    # kappa = J^2 / (2 I0 m) below 7.34: found here by bisection on the monotonicity of (94)
    # sampled finely on [0, 1), then three speeds with one |p| at kappa = 10.
    top = lf.RelativisticTangentTop(1.0, 2.0)          # m = 1, I0 = tr I / 2 = 1
    v = np.linspace(0.0, 1.0 - 1e-9, 200_001)

    def monotone(kappa):
        return bool(np.all(np.diff(top.momentum_94(v, np.sqrt(2 * kappa))) > 0))

    lo, hi = 1.0, 10.0
    assert monotone(lo) and not monotone(hi)
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if monotone(mid) else (lo, mid)
    assert abs(lo - 7.34) < 5e-3, lo
    p = top.momentum_94(v, np.sqrt(20.0))
    falling = v[1:][np.diff(p) < 0]
    assert 0.90 < falling[0] < 0.92 and 0.97 < falling[-1] < 0.98
    p0 = 0.5 * (p.max(where=v < falling[0], initial=0) + p.min(where=v > falling[-1], initial=np.inf))
    speeds = v[1:][np.diff(np.sign(p - p0)) != 0]
    assert len(speeds) == 3 and speeds[0] < falling[0] < speeds[1] < falling[-1] < speeds[2]


# --- issue 25, 002 §IV leftovers: (102) the anisotropic top on a surface, (91)-(92) the spin
# with a prescribed centre motion, (104)-(114) frame independence ---

MOMENTS = (0.2, 0.05, 0.08)          # (I11, I12, I22), integral xi xi^T dm
TENSOR = [[0.2, 0.05], [0.05, 0.08]]


def test_anisotropic_top_on_a_surface_takes_the_tensor_and_conserves_energy_and_j_z():
    # 002 (102): a (2, 2) or (3,) second-moment tensor on a surface; theta is not cyclic (no
    # p_theta among the invariants, and it varies); the energy and J_z are kept by gauss6.
    S = lf.surfaces
    top = lf.RelativisticTangentTop(1.0, TENSOR, S.Sphere(1.0))
    same = lf.RelativisticTangentTop(1.0, MOMENTS, S.Sphere(1.0))
    z0 = np.asarray(top.state([1.2, 0.3], 0.5, [0.3, 0.4], 2.0))
    np.testing.assert_array_equal(z0, same.state([1.2, 0.3], 0.5, [0.3, 0.4], 2.0))
    tr = lf.integrate(top, z0, dt=0.02, steps=2000, method="gauss6", save_every=100)
    assert np.ptp(tr.energy()) < 1e-12
    inv = top.invariants(tr.states)
    assert inv.shape == (len(tr.states), 1) and np.ptp(inv) < 1e-12           # J_z
    assert np.ptp(top.killing_momenta(tr.states), axis=0).max() < 1e-9
    assert np.ptp(tr.states[:, 5]) > 1e-3                                      # p_theta varies
    copy = pickle.loads(pickle.dumps(top))
    np.testing.assert_array_equal(lf.integrate(copy, z0, dt=0.02, steps=50).states,
                                  lf.integrate(top, z0, dt=0.02, steps=50).states)
    # On the Plane it is the Minkowski top of 002 (90) (a second kernel).
    plane = lf.RelativisticTangentTop(1.0, TENSOR, S.Plane())
    flat = lf.RelativisticTangentTop(1.0, MOMENTS)
    z0 = flat.state([0.0, 0.0], 0.3, [0.5, 0.2], 2.0)
    np.testing.assert_allclose(lf.integrate(plane, z0, dt=0.05, steps=40).states,
                               lf.integrate(flat, z0, dt=0.05, steps=40).states, atol=1e-13)
    # L: the tensor's term is there (it differs from the symmetric top of the same trace).
    sym = lf.RelativisticTangentTop(1.0, 0.28, S.Sphere(1.0))
    args = ([1.2, 0.3], 0.5, [0.3, 0.4], 2.0)
    assert abs(top.lagrangian(*args) - sym.lagrangian(*args)) > 1e-3
    with pytest.raises(lf.InvalidArgumentError, match="symmetric"):
        lf.RelativisticTangentTop(1.0, [[0.2, 0.05], [0.0, 0.08]], S.Sphere(1.0))
    with pytest.raises(lf.ShapeError):
        lf.RelativisticTangentTop(1.0, [0.2, 0.05], S.Sphere(1.0))
    with pytest.raises(lf.NonFiniteError):
        lf.RelativisticTangentTop(1.0, [[np.nan, 0.0], [0.0, 0.1]], S.Sphere(1.0))
    with pytest.raises(lf.InvalidArgumentError):                               # not semidefinite
        lf.RelativisticTangentTop(1.0, [[0.1, 0.2], [0.2, 0.1]], S.Sphere(1.0))
    # The frame is called for an anisotropic body: a callable's exception comes back unchanged.

    def metric(t, p):
        return [[1.0, 0.0], [0.0, np.sin(t) ** 2]]

    def frame(t, p):
        if t > 1.5:
            raise RuntimeError("frame failed")
        return [[1.0, 0.0], [0.0, 1.0 / np.sin(t)]]

    python = lf.RelativisticTangentTop(1.0, TENSOR, S.MetricSurface(metric, frame, None))
    with pytest.raises(RuntimeError, match="frame failed"):
        python.state([1.6, 0.0], 0.0, [0.1, 0.0], 1.0)
    with pytest.raises(RuntimeError, match="frame failed"):
        lf.integrate(python, python.state([1.45, 0.0], 0.0, [0.3, 0.0], 1.0), dt=0.05, steps=100)


def _euler_lagrange_theta(top, u):
    """theta'' of L(theta, thetadot) = top.lagrangian(0, theta, u, thetadot) with xdot = u held
    fixed, by finite differences of L only: L_ww theta'' + L_wtheta thetadot = L_theta. L is
    quadratic in thetadot, so its thetadot-differences with a large step are exact."""
    def L(th, w):
        return top.lagrangian([0.0, 0.0], th, u, w)

    def d_theta(f, th, h=1e-3):                     # 4th-order central difference
        return (8 * (f(th + h) - f(th - h)) - (f(th + 2 * h) - f(th - 2 * h))) / (12 * h)

    def rhs(t, y):
        th, w = y
        hw = 0.5
        l_ww = (L(th, w + hw) + L(th, w - hw) - 2 * L(th, w)) / hw**2
        l_wth = d_theta(lambda a: (L(a, w + hw) - L(a, w - hw)) / (2 * hw), th)
        l_th = d_theta(lambda a: L(a, w), th)
        return [w, (l_th - l_wth * w) / l_ww]
    return rhs


def test_prescribed_motion_91_92_against_the_euler_lagrange_equation():
    # 002 (91)-(92): with the centre in straight uniform motion (u = (0.6, 0), ydot = 0) the spin
    # keeps E = F(theta) thetadot^2 / 2, so thetadot = sqrt(2E/F(theta)) and thetadot'' = -V'(theta)
    # with V = -E/F. The Euler-Lagrange equation of the top's own L (differences of
    # RelativisticTangentTop.lagrangian), integrated by scipy, is the second route.
    from scipy.integrate import solve_ivp
    top = lf.RelativisticTangentTop(1.0, [[0.12, 0.0], [0.0, 0.04]])   # long axis = body E1
    u = [0.6, 0.0]
    th0, w0 = 0.3, 2.0
    energy = 0.5 * top.prescribed_inertia(th0, u) * w0**2
    sol = solve_ivp(_euler_lagrange_theta(top, u), (0.0, 8.0), [th0, w0], method="DOP853",
                    rtol=1e-12, atol=1e-12, dense_output=True)
    assert sol.success
    th, w = sol.y
    assert th[-1] - th0 > 2 * np.pi                                  # several half-turns
    rate = top.prescribed_spin_rate(th, energy, u)
    err = np.abs(w - rate).max()
    print(f"(92) vs the Euler-Lagrange run: max |thetadot - sqrt(2E/F)| = {err:.1e}")
    assert err < 1e-8
    # theta'' = -V'(theta): the potential's derivative by differences against the EL equation.
    thg = np.linspace(0.0, np.pi, 7)
    h = 1e-4
    dv = (top.prescribed_potential(thg + h, energy, u)
          - top.prescribed_potential(thg - h, energy, u)) / (2 * h)
    acc = np.array([_euler_lagrange_theta(top, u)(0.0, [a, r])[1]
                    for a, r in zip(thg, top.prescribed_spin_rate(thg, energy, u))])
    assert np.abs(acc + dv).max() < 1e-6
    assert np.allclose(0.5 * rate**2 + top.prescribed_potential(th, energy, u), 0.0, atol=1e-15)
    # Faster and slower: the spin is fastest with the long axis along u (theta = 0 mod pi: the
    # smaller second moment across the motion) and slowest broadside, by
    # sqrt(F_max / F_min) = sqrt((I + gamma^2 v^2 I11) / (I + gamma^2 v^2 I22)).
    gam2 = 1 / (1 - 0.36)
    th, w = sol.sol(np.linspace(0.0, 8.0, 400_001))
    ratio = w.max() / w.min()
    want = np.sqrt((0.16 + gam2 * 0.36 * 0.12) / (0.16 + gam2 * 0.36 * 0.04))
    print(f"spin rate max/min along the run {ratio:.6f}, predicted {want:.6f}")
    assert abs(ratio - want) < 1e-6
    fast = np.mod(th[np.argmax(w)], np.pi)
    slow = np.mod(th[np.argmin(w)], np.pi)
    assert min(fast, np.pi - fast) < 0.05 and abs(slow - np.pi / 2) < 0.05
    # The classical limit spins uniformly: the modulation vanishes as v -> 0.
    f = top.prescribed_inertia(np.linspace(0, np.pi, 50), [1e-3, 0.0])
    assert np.ptp(f) / f.mean() < 1e-6
    # Vectorised over broadcast axes; errors.
    assert top.prescribed_inertia(np.zeros((3, 1)), [[0.1, 0.0], [0.2, 0.0]]).shape == (3, 2)
    with pytest.raises(lf.InvalidArgumentError, match="speed"):
        top.prescribed_inertia(0.0, [0.8, 0.7])
    with pytest.raises(lf.InvalidArgumentError, match="energy"):
        top.prescribed_spin_rate(0.0, -1.0, u)
    with pytest.raises(lf.NonFiniteError):
        top.prescribed_potential(np.nan, 1.0, u)
    with pytest.raises(lf.ShapeError):
        top.prescribed_inertia(0.0, [0.1, 0.0, 0.0])


def test_seed_91_cross_term_sign():
    # 002 (91) prints -2 I3 sin cos; with I12 = integral xi1 xi2 dm and E1 = cos theta e_x +
    # sin theta e_y (002 (41)) the top's L has +2 I12 sin cos.
    top = lf.RelativisticTangentTop(1.0, (0.1, 0.03, 0.05))
    v, th = 0.6, 0.7
    gam = 1 / np.sqrt(1 - v**2)
    s, c = np.sin(th), np.cos(th)
    ours = 0.15 * gam + gam**3 * v**2 * (0.1 * s**2 + 2 * 0.03 * s * c + 0.05 * c**2)
    seed = 0.15 * gam + gam**3 * v**2 * (0.1 * s**2 - 2 * 0.03 * s * c + 0.05 * c**2)
    l2 = top.lagrangian([0, 0], th, [v, 0], 1.0) - top.lagrangian([0, 0], th, [v, 0], 0.0)
    assert top.prescribed_inertia(th, [v, 0]) == pytest.approx(ours, rel=1e-14)
    assert 2 * l2 == pytest.approx(ours, rel=1e-13) and abs(2 * l2 - seed) > 1e-2


def test_frame_change_leaves_the_motion_unchanged():
    # 002 (104)-(114): turning the reference frame by beta(x) (theta -> theta - beta,
    # alpha -> alpha + d beta) changes nothing physical; (114)'s extra term v^T [A + w, B] v
    # vanishes as the bracket is skew. The anisotropic top on the sphere from the built-in frame
    # and from a MetricSurface (Python callables) with the frame turned by beta(x).
    def beta(t, p):
        return 0.6 * np.sin(2 * t) + 0.5 * np.cos(p), np.array([1.2 * np.cos(2 * t), -0.5 * np.sin(p)])

    def metric(t, p):
        return [[1.0, 0.0], [0.0, np.sin(t) ** 2]]

    def frame(t, p):
        b = beta(t, p)[0]
        e = np.array([[1.0, 0.0], [0.0, 1.0 / np.sin(t)]])
        return np.array([[np.cos(b), np.sin(b)], [-np.sin(b), np.cos(b)]]) @ e

    S = lf.surfaces
    native, turned = S.Sphere(1.0), S.MetricSurface(metric, frame, None)
    turned.check_frame([1.1, 0.4])
    a = lf.RelativisticTangentTop(1.0, TENSOR, native)
    b = lf.RelativisticTangentTop(1.0, TENSOR, turned)
    x, th, xd, w = [1.1, 0.4], 0.7, np.array([0.25, 0.3]), 1.6
    bv, db = beta(*x)
    assert abs(bv) > 0.5
    assert b.lagrangian(x, th - bv, xd, w - db @ xd) == pytest.approx(a.lagrangian(x, th, xd, w),
                                                                       abs=1e-12)
    ta = lf.integrate(a, a.state(x, th, xd, w), dt=0.02, steps=200, method="gauss6", save_every=20)
    tb = lf.integrate(b, b.state(x, th - bv, xd, w - db @ xd), dt=0.02, steps=200,
                      method="gauss6", save_every=20)
    np.testing.assert_allclose(ta.states[:, :2], tb.states[:, :2], atol=1e-8)
    turn = np.array([beta(*q)[0] for q in tb.states[:, :2]])
    np.testing.assert_allclose(tb.states[:, 2] + turn, ta.states[:, 2], atol=1e-8)
    np.testing.assert_allclose(tb.energy(), ta.energy(), atol=1e-10)
    assert np.ptp(ta.states[:, 1]) > 0.1


# --- issue 25, 002 (115)-(117): the top on the static space-time -exp(2 phi) dt^2 + dx^2 ---

def test_static_field_top_conserves_energy_spin_and_angular_momentum():
    # A point mass strong enough that the weak-field (118) would not do (phi = -0.15 at r = 1).
    top = lf.StaticFieldTop(1.0, 0.2, gm=0.15)
    z0 = top.state([1.0, 0.0], 0.3, [0.05, 0.38], 1.2)
    tr = lf.integrate(top, z0, dt=0.02, steps=5000, method="gauss6", save_every=50)
    assert np.ptp(tr.energy()) < 1e-12
    inv = top.invariants(tr.states)
    assert inv.shape == (len(tr.states), 2) and np.ptp(inv, axis=0).max() < 1e-13
    np.testing.assert_array_equal(inv[:, 1], top.angular_momentum(tr.states))
    r = np.hypot(tr.states[:, 0], tr.states[:, 1])
    assert np.ptp(r) > 0.05                                # the orbit is not trivial
    np.testing.assert_allclose(top.velocities(z0), [0.05, 0.38, 1.2], atol=1e-13)
    copy = pickle.loads(pickle.dumps(top))
    assert repr(copy) == repr(top) and copy.methods() == top.methods() == lf.StaticFieldTop.methods()
    np.testing.assert_array_equal(lf.integrate(copy, z0, dt=0.02, steps=30).states,
                                  lf.integrate(top, z0, dt=0.02, steps=30).states)


def test_static_field_top_limits_flat_and_weak_field():
    # phi = 0: the flat RelativisticTangentTop. Weak field and slow motion (phi, G ~ eps^2,
    # v ~ eps): L = L(118) - m + O(eps^4), the difference 16 times smaller as eps halves.
    flat = lf.RelativisticTangentTop(1.3, 0.25)
    zero = lf.StaticFieldTop(1.3, 0.25, g=(0.0, 0.0))
    z0 = flat.state([0.2, 0.1], 0.4, [0.5, -0.3], 2.5)
    np.testing.assert_allclose(lf.integrate(zero, z0, dt=0.05, steps=100).states,
                               lf.integrate(flat, z0, dt=0.05, steps=100).states, atol=1e-13)
    args = ([0.2, 0.1], 0.4, [0.5, -0.3], 2.5)
    assert zero.lagrangian(*args) == pytest.approx(flat.lagrangian(*args), abs=1e-15)

    def diff(eps):
        st = lf.StaticFieldTop(1.0, 0.3, gm=0.8 * eps**2)
        wf = lf.WeakFieldTop(1.0, 0.3, gm=0.8 * eps**2)
        a = ([1.0, 0.3], 0.4, [0.8 * eps, -0.5 * eps], 1.1)
        return abs(st.lagrangian(*a) - (wf.lagrangian(*a) - 1.0))
    ratio = diff(0.02) / diff(0.01)
    print(f"(117) -> (118): L difference ratio on halving eps {ratio:.2f}")
    assert abs(ratio - 16) < 1


def test_static_field_top_rejects_bad_input():
    with pytest.raises(lf.InvalidArgumentError):
        lf.StaticFieldTop(1.0, 0.2)                         # no potential
    with pytest.raises(lf.InvalidArgumentError):
        lf.StaticFieldTop(1.0, 0.2, gm=1.0, g=(0.0, 1.0))   # two
    top = lf.StaticFieldTop(1.0, 0.2, gm=0.5)
    with pytest.raises(lf.InvalidArgumentError, match="light"):
        top.state([1.0, 0.0], 0.0, [0.0, 0.7], 1.0)         # exp(phi) = 0.61 < 0.7
    with pytest.raises(lf.InvalidArgumentError):
        top.state([0.0, 0.0], 0.0, [0.1, 0.0], 1.0)         # at the point mass
    with pytest.raises(lf.NonFiniteError):
        top.lagrangian([np.nan, 0.0], 0.0, [0.1, 0.0], 1.0)


# --- 002 (115)-(117) with a curved spatial metric: the top on -exp(2 phi) dt^2 + g ---

def test_static_field_top_on_a_sphere_conserves_energy_p_theta_and_j_z():
    # phi = 0.2 theta (a uniform field of the chart, symmetric about the z axis): the energy,
    # p_theta and J_z are conserved, J_x and J_y are not; the top pickles with its surface.
    top = lf.StaticFieldTop(1.0, 0.2, g=(0.2, 0.0), surface=lf.surfaces.Sphere(1.0))
    z0 = top.state([1.2, 0.3], 0.5, [0.1, 0.8], 2.0)
    np.testing.assert_allclose(top.velocities(z0), [0.1, 0.8, 2.0], atol=1e-13)
    tr = lf.integrate(top, z0, dt=0.02, steps=5000, method="gauss6", save_every=50)
    assert np.ptp(tr.energy()) < 1e-12
    inv = top.invariants(tr.states)
    assert inv.shape == (len(tr.states), 2) and np.ptp(inv, axis=0).max() < 1e-13   # p_theta, J_z
    j = top.killing_momenta(tr.states)
    assert j.shape == (len(tr.states), 3)
    np.testing.assert_array_equal(j[:, 2], inv[:, 1])
    assert np.ptp(j[:, 0]) > 0.05                                  # the field breaks J_x
    assert np.ptp(tr.states[:, 0]) > 0.1                           # and moves the latitude
    copy = pickle.loads(pickle.dumps(top))
    assert repr(copy) == repr(top) and "Sphere" in repr(copy)
    assert copy.methods() == top.methods() == lf.StaticFieldTop.methods()
    np.testing.assert_array_equal(lf.integrate(copy, z0, dt=0.02, steps=30).states,
                                  lf.integrate(top, z0, dt=0.02, steps=30).states)


def test_static_field_top_on_a_surface_limits():
    # On the Plane: the flat top, the same numbers. phi = 0 on the half-plane: the top of
    # -dt^2 + g, RelativisticTangentTop on that surface.
    flat = lf.StaticFieldTop(1.0, 0.2, gm=0.15)
    plane = lf.StaticFieldTop(1.0, 0.2, gm=0.15, surface=lf.surfaces.Plane())
    z0 = flat.state([1.0, 0.0], 0.3, [0.05, 0.38], 1.2)
    np.testing.assert_array_equal(plane.state([1.0, 0.0], 0.3, [0.05, 0.38], 1.2), z0)
    np.testing.assert_array_equal(lf.integrate(plane, z0, dt=0.02, steps=100).states,
                                  lf.integrate(flat, z0, dt=0.02, steps=100).states)
    # The invariants on the Plane: p_theta and the rotation's Killing momentum x p_y - y p_x + p_theta.
    np.testing.assert_allclose(plane.invariants(z0),
                               [z0[5], flat.angular_momentum(z0) + z0[5]], atol=1e-15)
    H = lf.surfaces.HyperbolicPlane()
    zero = lf.StaticFieldTop(1.0, 0.3, g=(0.0, 0.0), surface=H)
    rtt = lf.RelativisticTangentTop(1.0, 0.3, H)
    args = ([0.1, 1.0], 0.0, [0.4, 0.2], 1.3)
    assert zero.lagrangian(*args) == pytest.approx(rtt.lagrangian(*args), abs=1e-15)
    z0 = rtt.state(*args)
    np.testing.assert_allclose(lf.integrate(zero, z0, dt=0.02, steps=100).states,
                               lf.integrate(rtt, z0, dt=0.02, steps=100).states, atol=1e-12)
    np.testing.assert_allclose(zero.invariants(z0), rtt.invariants(z0), atol=1e-15)


def test_static_field_top_on_a_surface_rejects_bad_input():
    with pytest.raises(TypeError):
        lf.StaticFieldTop(1.0, 0.2, g=(0.1, 0.0), surface="sphere")
    with pytest.raises(lf.InvalidArgumentError):
        lf.StaticFieldTop(1.0, 0.2, surface=lf.surfaces.Sphere(1.0))      # no potential
    top = lf.StaticFieldTop(1.0, 0.2, g=(0.2, 0.0), surface=lf.surfaces.Sphere(2.0))
    with pytest.raises(lf.InvalidArgumentError, match="light"):
        top.state([1.0, 0.0], 0.0, [0.7, 0.0], 1.0)        # v = R |dtheta/dt| = 1.4 > exp(0.2)
    with pytest.raises(lf.InvalidArgumentError, match="chart"):
        top.state([-0.1, 0.0], 0.0, [0.1, 0.0], 1.0)
    with pytest.raises(lf.InvalidArgumentError):
        top.killing_momenta([3.5, 0.0, 0.0, 0.1, 0.0, 0.1])


def test_static_field_top_on_a_surface_from_callables_raises_their_errors():
    def metric(t, p):
        return [[1.0, 0.0], [0.0, np.sin(t) ** 2]]

    def frame(t, p):
        if t > 1.5:
            raise RuntimeError("frame failed")
        return [[1.0, 0.0], [0.0, 1.0 / np.sin(t)]]

    python = lf.StaticFieldTop(1.0, 0.2, g=(0.2, 0.0),
                               surface=lf.surfaces.MetricSurface(metric, frame, None))
    native = lf.StaticFieldTop(1.0, 0.2, g=(0.2, 0.0), surface=lf.surfaces.Sphere(1.0))
    z0 = native.state([1.0, 0.3], 0.5, [0.2, 0.3], 1.5)
    np.testing.assert_allclose(lf.integrate(python, z0, dt=0.02, steps=20).states,
                               lf.integrate(native, z0, dt=0.02, steps=20).states, atol=1e-7)
    assert python.invariants(z0).shape == (1,)             # a surface of callables: p_theta only
    with pytest.raises(RuntimeError, match="frame failed"):
        python.state([1.6, 0.0], 0.0, [0.1, 0.0], 1.0)
