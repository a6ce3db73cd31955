"""lf.PseudoRigidBody, lf.potentials and the reduced maps (issue 5)."""

import numpy as np
import pytest

import lieflow as lf

pot = lf.potentials

X0 = np.diag([1.3, 1.0, 0.8]) + 0.05 * np.arange(9.0).reshape(3, 3) % 0.2
P0 = np.array([[0.0, 0.5, 0.1], [-0.2, 0.1, 0.3], [0.1, -0.4, 0.0]])


def elastic():
    return pot.SaintVenantKirchhoff(0.7, 1.3) + pot.Volumetric(0.4, 1.4)


def run(body, state0, dt, steps, save_every=1, method="verlet"):
    z0, batched = body._normalize_state(state0)
    states, att, zf, attf = body._run(z0, None, dt, steps, save_every, method)
    assert att is None and attf is None
    return states if batched else states[0]


def test_potentials_values_gradients_and_sums():
    X = X0
    h = pot.Harmonic(2.0)
    assert np.isclose(h.value(X), np.sum(X * X))
    np.testing.assert_allclose(h.gradient(X), 2.0 * X)
    s = h + elastic()
    assert "Harmonic" in repr(s) and "Volumetric" in repr(s)
    eps = 1e-6
    E = np.zeros((3, 3))
    E[0, 1] = eps
    fd = (s.value(X + E) - s.value(X - E)) / (2 * eps)
    assert abs(fd - s.gradient(X)[0, 1]) < 1e-6
    assert pot.Zero().value(X) == 0.0


def test_free_body_is_a_straight_line_and_state_layout():
    body = lf.PseudoRigidBody(3)
    states = run(body, (X0, P0), 0.01, 100, 100)
    assert states.shape == (2, 18)
    f = body._fields(states)
    np.testing.assert_allclose(f["X"][-1], X0 + P0, atol=1e-13)
    np.testing.assert_allclose(f["P"][-1], P0, atol=1e-15)
    assert body.state_dim == 18 and body.methods() == ["verlet", "verlet4", "verlet6", "reduced"]


def test_invariants_all_methods_and_batches():
    body = lf.PseudoRigidBody(3, potential=elastic())
    batch = (np.stack([X0, X0 * 1.1]), np.stack([P0, -P0]))
    for m in body.methods():
        s = run(body, batch, 1e-3, 2000, 500, method=m)
        assert s.shape == (2, 5, 18)
        E = body.energy(s)
        assert E.shape == (2, 5) and np.max(np.abs(E - E[:, :1])) < 1e-4
        L, G = body.angular_momentum(s), body.circulation(s)
        assert L.shape == (2, 5, 3, 3)
        np.testing.assert_allclose(L, L[:, :1].repeat(5, 1), atol=1e-12)
        np.testing.assert_allclose(G, G[:, :1].repeat(5, 1), atol=1e-12)
        C = body.casimirs(s)
        assert C.shape == (2, 5, 2)
        np.testing.assert_allclose(C, C[:, :1].repeat(5, 1), rtol=1e-12)
        a = body.singular_values(s)
        assert a.shape == (2, 5, 3) and np.all(np.diff(a, axis=-1) <= 0)


def test_full_and_reduced_agree():
    body = lf.PseudoRigidBody(3, potential=elastic())
    ref = run(body, (X0, P0), 1e-3, 500, 500, "verlet6")[-1]
    red = run(body, (X0, P0), 1e-3, 500, 500, "reduced")[-1]
    assert np.max(np.abs(ref - red)) < 1e-5


def test_callable_potential_matches_builtin_and_reraises():
    body_c = lf.PseudoRigidBody(3, potential=pot.Callable(lambda X: np.sum(X * X), lambda X: 2 * X))
    body_h = lf.PseudoRigidBody(3, potential=pot.Harmonic(2.0))
    sc = run(body_c, (X0, P0), 1e-2, 50, 50)
    sh = run(body_h, (X0, P0), 1e-2, 50, 50)
    np.testing.assert_allclose(sc, sh, atol=1e-14)
    bad = lf.PseudoRigidBody(3, potential=pot.Callable(lambda X: 1.0, lambda X: 1 / 0))
    with pytest.raises(ZeroDivisionError):
        run(bad, (X0, P0), 1e-2, 5)
    wrong = lf.PseudoRigidBody(3, potential=pot.Callable(lambda X: 1.0, lambda X: np.zeros(2)))
    with pytest.raises(lf.ShapeError):
        run(wrong, (X0, P0), 1e-2, 5)
    with pytest.raises(TypeError):
        pot.Callable(1.0, lambda X: X)


def test_leaving_gl_plus_names_the_time():
    x = np.diag([1.0, 1.5, 2.0])
    body = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    for m in ["verlet", "reduced"]:
        with pytest.raises(lf.LeftDomainError, match=r"t = 0\.78"):
            run(body, (x, -x), 1e-3, 2000, method=m)
    free = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0), check_det=False)
    assert run(free, (x, -x), 1e-3, 2000).shape == (2001, 18)
    gas = lf.PseudoRigidBody(3, potential=pot.Volumetric(0.1), check_det=False)
    assert gas.check_det


def test_reduce_reconstruct_and_adjoint_motion():
    r = lf.pseudo_rigid.reduce(X0, P0)
    X, P = lf.pseudo_rigid.reconstruct(r["R"], r["S"], r["a"], r["p_a"], r["p_Omega"], r["p_Lambda"])
    np.testing.assert_allclose(X, X0, atol=1e-12)
    np.testing.assert_allclose(P, P0, atol=1e-12)
    body = lf.PseudoRigidBody(3, potential=elastic())
    s = run(body, (X0, P0), 1e-3, 100, 50)
    f = body._fields(s)
    XT, PT = lf.pseudo_rigid.adjoint_motion(f["X"], f["P"])
    sT = np.concatenate([XT.reshape(-1, 9), PT.reshape(-1, 9)], axis=1)
    np.testing.assert_allclose(body.angular_momentum(sT), body.circulation(s), atol=1e-12)
    with pytest.raises(lf.DegenerateStratumError):
        lf.pseudo_rigid.reduce(np.eye(3), P0)
    with pytest.raises(lf.NotInGroupError):
        lf.pseudo_rigid.reduce(-X0, P0)
    with pytest.raises(lf.InvalidArgumentError):
        lf.pseudo_rigid.reconstruct(np.eye(2), np.eye(2), [1.0, -1.0], [0, 0], np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(lf.ShapeError):
        lf.pseudo_rigid.adjoint_motion(np.zeros((2, 3)), np.zeros((2, 3)))


def test_error_paths():
    body = lf.PseudoRigidBody(3, potential=elastic())
    z0, _ = body._normalize_state((X0, P0))
    for n in [1, -1, 2**32]:  # too small, negative, 2n² overflowing the address space
        with pytest.raises(lf.InvalidArgumentError, match="n"):
            lf.PseudoRigidBody(n)
    with pytest.raises(lf.InvalidArgumentError):
        pot.Harmonic(-1.0)
    with pytest.raises(lf.InvalidArgumentError):
        pot.SaintVenantKirchhoff(-1.0, 1.0)
    with pytest.raises(lf.InvalidArgumentError):
        pot.Volumetric(1.0, 0.5)
    with pytest.raises(lf.ShapeError):
        body._normalize_state((X0, P0, P0))
    with pytest.raises(lf.ShapeError):
        body._normalize_state((X0, np.zeros((2, 2))))
    with pytest.raises(lf.ShapeError):
        body._normalize_state((np.stack([X0, X0]), P0))
    with pytest.raises(lf.ShapeError):
        body._normalize_state(np.zeros(5))
    with pytest.raises(lf.NonFiniteError):
        body._normalize_state((X0, np.full((3, 3), np.nan)))
    with pytest.raises(lf.InvalidArgumentError):
        body._run(z0, None, -1.0, 10, 1, "verlet")
    with pytest.raises(lf.InvalidArgumentError):
        body._run(z0, None, 0.1, 0, 1, "verlet")
    with pytest.raises(lf.InvalidArgumentError):
        body._run(z0, None, 0.1, 10, -1, "verlet")
    with pytest.raises(lf.UnsupportedMethodError, match="verlet, verlet4, verlet6, reduced"):
        body._run(z0, None, 0.1, 10, 1, "nope")
    with pytest.raises(lf.InvalidArgumentError):
        body._run(z0, np.eye(3)[None], 0.1, 10, 1, "verlet")
    with pytest.raises(lf.UnsupportedMethodError):
        body._run(z0, None, 0.1, 10, 1, "rk4")
    with pytest.raises(lf.ShapeError):
        body._run(np.zeros((1, 5)), None, 0.1, 10, 1, "verlet")
    with pytest.raises(lf.NotInGroupError):
        body._run(body._normalize_state((-X0, P0))[0], None, 0.1, 10, 1, "verlet")
    with pytest.raises(lf.DegenerateStratumError):
        body._run(body._normalize_state((np.eye(3), P0))[0], None, 0.1, 10, 1, "reduced")
    for observable in [body.energy, body.casimirs, body.angular_momentum, body.circulation,
                       body.singular_values]:
        with pytest.raises(lf.ShapeError):
            observable(np.zeros((4, 5)))
        with pytest.raises(lf.NonFiniteError):
            observable(np.full(18, np.nan))
    for p in [pot.Harmonic(1.0), elastic(), pot.Volumetric(1.0)]:
        for f in [p.value, p.gradient]:
            with pytest.raises(lf.ShapeError):
                f(np.zeros((3, 2)))
            with pytest.raises(lf.NonFiniteError):
                f(np.full((3, 3), np.nan))
    with pytest.raises(lf.NotInGroupError):
        body.energy(body._normalize_state((-X0, P0))[0])
    with pytest.raises(lf.NotInGroupError):
        pot.Volumetric(1.0).value(-X0)


def test_lf_integrate_trajectory():
    body = lf.PseudoRigidBody(3, potential=elastic())
    traj = lf.integrate(body, (X0, P0), dt=1e-3, steps=1000, method="verlet4", save_every=100)
    assert traj.X.shape == (11, 3, 3) and traj.P.shape == (11, 3, 3) and traj.t.shape == (11,)
    E = traj.energy()
    assert np.max(np.abs(E - E[0])) < 1e-9
    np.testing.assert_allclose(traj.angular_momentum(), traj.angular_momentum()[:1].repeat(11, 0), atol=1e-12)
    assert traj.singular_values().shape == (11, 3) and traj.circulation().shape == (11, 3, 3)


def test_demo_runs(tmp_path, capsys):
    from lieflow.cli import main

    assert main(["demo", "--figure", str(tmp_path / "demo.png")]) == 0
    out = capsys.readouterr().out
    assert "energy" in out and "circulation" in out
    assert (tmp_path / "demo.png").stat().st_size > 10_000


def test_run_t0_offsets_the_exit_time():
    x = np.diag([1.0, 1.5, 2.0])
    body = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    z0, _ = body._normalize_state((x, -x))
    with pytest.raises(lf.LeftDomainError, match=r"t = 10\.78"):
        body._run(z0, None, 1e-3, 2000, 1, "verlet", t0=10.0)


def test_chunked_integrate_names_the_absolute_exit_time():
    # X(t) = X0 (cos t − sin t) leaves GL+(3) at t = π/4; with 100-step chunks the crossing
    # falls in the 8th chunk, and the error must name the time from the start of the run.
    x = np.diag([1.0, 1.5, 2.0])
    body = lf.PseudoRigidBody(3, potential=pot.Harmonic(1.0))
    with pytest.raises(lf.LeftDomainError, match=r"t = 0\.78"):
        lf.integrate(body, (x, -x), dt=1e-3, steps=2000, method="verlet", chunk_steps=100)
