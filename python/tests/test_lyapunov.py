"""lf.lyapunov and lf.poincare_section (docs/chaos.md): exact exponents of a linear saddle,
the symplectic pairing, integrable tops against a generic one at the same energy (checked by an
independent estimate: two nearby plain runs), crossings on the section, and bad input."""

import numpy as np
import pytest

import lieflow as lf


def saddle():
    """H = p q: q' = q, p' = -p (exponents +-1)."""
    return lf.Canonical(lambda q, p: q[0] * p[0], lambda q, p: np.array([p, q]), dof=1,
                        hessian=lambda q, p, dq, dp: np.array([dp, dq]))


def henon_heiles():
    def u(q):
        x, y = q
        return 0.5 * (x * x + y * y) + x * x * y - y ** 3 / 3

    def grad(q):
        x, y = q
        return [x + 2 * x * y, y + x * x - y * y]

    def hess(q, v):
        x, y = q
        return [(1 + 2 * y) * v[0] + 2 * x * v[1], 2 * x * v[0] + (1 - 2 * y) * v[1]]

    return lf.Separable(1.0, u, grad, dof=2, hessian=hess)


def hh_state(e, y, py):
    px = np.sqrt(2 * (e - (0.5 * y * y - y ** 3 / 3)) - py * py)
    return np.array([0.0, y, px, py])


def top_state(inertia, chi, e):
    """Gamma = (0.6, 0, 0.8), M along (0.8, 0.5, -0.6) (M . Gamma = 0) scaled to energy e."""
    gamma, d = np.array([0.6, 0.0, 0.8]), np.array([0.8, 0.5, -0.6])
    chi = np.asarray(chi, float) / np.linalg.norm(chi)
    s = np.sqrt((e - gamma @ chi) / (0.5 * d @ (d / np.asarray(inertia, float))))
    return np.concatenate([s * d, gamma])


TOPS = {"lagrange": ([1, 1, 2], [0, 0, 1]), "kovalevskaya": ([2, 2, 1], [1, 0, 0]),
        "generic": ([1, 2, 3], [1, 1, 1])}


def test_a_saddle_has_its_exponents_exactly():
    h = 0.01
    s = lf.lyapunov(saddle(), [0.3, -0.7], dt=h, steps=300, method="gauss4",
                    renormalise_every=7)
    r = (1 + h / 2 + h * h / 12) / (1 - h / 2 + h * h / 12)   # gauss4's stability function
    assert s.exponents.shape == (2,) and s.running.shape == (43, 2) and s.times.shape == (43,)
    np.testing.assert_allclose(s.running, np.tile([np.log(r) / h, -np.log(r) / h], (43, 1)),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.exponents, [1, -1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(s.times, np.minimum(np.arange(1, 44) * 0.07, 3.0), atol=1e-13)
    assert "LyapunovSpectrum(exponents=[ 1., -1.]" in repr(s)
    with pytest.raises(Exception):
        s.exponents[0] = 0.0              # frozen, read-only arrays


def test_henon_heiles_pairs_its_exponents():
    s = lf.lyapunov(henon_heiles(), hh_state(1 / 6, -0.1, 0.1), dt=0.05, steps=20_000)
    assert s.exponents[0] > 0.03
    assert abs(s.exponents[0] + s.exponents[3]) < 0.1 * s.exponents[0]
    assert abs(s.exponents.sum()) < 1e-12
    low = lf.lyapunov(henon_heiles(), hh_state(0.01, 0.05, 0.0), dt=0.05, steps=20_000)
    assert low.exponents[0] < 0.02


def divergence_rate(top, z0, dt, t_end, delta=1e-10):
    """An independent estimate of the largest exponent: the growth rate of the distance of two
    nearby plain runs (a least-squares slope of its logarithm before it saturates)."""
    steps = int(round(t_end / dt))
    z1 = z0 + delta * np.array([1, -1, 1, 0, 0, 0]) / np.sqrt(3)
    a = lf.integrate(top, z0, dt=dt, steps=steps, save_every=100)
    b = lf.integrate(top, z1, dt=dt, steps=steps, save_every=100)
    dist = np.linalg.norm(a.states - b.states, axis=1)
    keep = (a.t > 10) & (dist < 1e-3)
    return np.polyfit(a.t[keep], np.log(dist[keep]), 1)[0]


def test_integrable_tops_have_zero_exponents_and_a_generic_one_does_not():
    results = {}
    for name, (inertia, chi) in TOPS.items():
        top = lf.HeavyTop(inertia, 1.0, chi)
        z0 = top_state(inertia, chi, 2.0)
        assert top.energy(z0) == pytest.approx(2.0, abs=1e-12)
        s = lf.lyapunov(top, z0, dt=0.01, steps=100_000)
        results[name] = s
        assert abs(s.exponents.sum()) < 1e-10
        assert abs(s.exponents[0] + s.exponents[5]) < 0.15 * s.exponents[0]
        # The final state is the plain run's, bit for bit.
        plain = lf.integrate(top, z0, dt=0.01, steps=100_000, save_every=100_000)
        np.testing.assert_array_equal(s.state, plain.final_state)
    for name in ("lagrange", "kovalevskaya"):
        s = results[name]
        lam = s.running.max(axis=1)
        at = lambda t: lam[np.searchsorted(s.times, t - 1e-9)]   # noqa: E731
        assert s.exponents[0] < 0.015 and at(1000) < 0.5 * at(100)
        # Roughly log t / t.
        assert 0.3 < at(1000) / (np.log(1000) / 1000) < 3
    generic = results["generic"]
    assert generic.exponents[0] > 0.08
    assert np.all(np.abs(generic.exponents[1:5]) < 0.02)
    # An independent estimate: two nearby plain runs separate at about the same rate.
    inertia, chi = TOPS["generic"]
    rate = divergence_rate(lf.HeavyTop(inertia, 1.0, chi), top_state(inertia, chi, 2.0), 0.01,
                           400)
    assert 0.5 * generic.exponents[0] < rate < 2 * generic.exponents[0]


def test_a_poincare_section_of_the_generic_top_fills_an_area():
    """The chaotic orbit's section (Gamma_1 = 0, rising) spreads where a Kovalevskaya orbit's
    lies on curves: the spread of M3 at the crossings differs clearly."""
    inertia, chi = TOPS["generic"]
    t, z = lf.poincare_section(lf.HeavyTop(inertia, 1.0, chi), top_state(inertia, chi, 2.0),
                               lambda z: z[3], crossings=200, dt=0.01)
    assert z.shape == (200, 6) and np.all(np.diff(t) > 0)
    assert np.max(np.abs(z[:, 3])) < 1e-12


def test_poincare_section_of_a_harmonic_oscillator():
    """q = cos t crosses q = 0 falling at t = pi/2 + 2 pi k, rising at 3 pi/2 + 2 pi k; the
    crossings' states lie on the section to round-off and keep the energy."""
    osc = lf.Separable(1.0, lambda q: 0.5 * q[0] ** 2, lambda q: q, dof=1)
    for direction, first in ((-1, np.pi / 2), (1, 3 * np.pi / 2)):
        t, z = lf.poincare_section(osc, [1.0, 0.0], lambda z: z[0], direction=direction,
                                   crossings=5, method="gauss6", dt=0.01)
        np.testing.assert_allclose(t, first + 2 * np.pi * np.arange(5), rtol=0, atol=1e-9)
        assert np.max(np.abs(z[:, 0])) < 1e-14
        np.testing.assert_allclose(z[:, 1], direction * 1.0, atol=1e-9)   # p = q'
    t, z = lf.poincare_section(osc, [1.0, 0.0], lambda z: z[0], direction=0, crossings=4,
                               dt=0.01)
    np.testing.assert_allclose(t, np.pi / 2 + np.pi * np.arange(4), atol=1e-4)   # verlet
    assert np.all(np.diff(t) > 0)


def test_poincare_section_warns_with_too_few_crossings():
    osc = lf.Separable(1.0, lambda q: 0.5 * q[0] ** 2, lambda q: q, dof=1)
    with pytest.warns(RuntimeWarning, match="found 1 of 10 crossings"):
        t, z = lf.poincare_section(osc, [1.0, 0.0], lambda z: z[0], direction=-1, crossings=10,
                                   dt=0.01, max_steps=500)
    assert t.shape == (1,) and z.shape == (1, 2)


def test_bad_input():
    top = lf.HeavyTop([1, 2, 3], 1.0, [1, 1, 1])
    z0 = np.array([0.3, -0.5, 0.9, 0.6, 0.0, 0.8])
    keep = z0.copy()
    with pytest.raises(lf.InvalidArgumentError, match="dt"):
        lf.lyapunov(top, z0, dt=0.0, steps=10)
    with pytest.raises(lf.InvalidArgumentError, match="dt"):
        lf.lyapunov(top, z0, dt=-1.0, steps=10)
    with pytest.raises(TypeError, match="dt"):
        lf.lyapunov(top, z0, dt="0.1", steps=10)
    with pytest.raises(lf.InvalidArgumentError, match="steps"):
        lf.lyapunov(top, z0, dt=0.01, steps=0)
    with pytest.raises(TypeError, match="steps"):
        lf.lyapunov(top, z0, dt=0.01, steps=1.5)
    with pytest.raises(lf.InvalidArgumentError, match="renormalise_every"):
        lf.lyapunov(top, z0, dt=0.01, steps=10, renormalise_every=0)
    with pytest.raises(lf.ShapeError):
        lf.lyapunov(top, z0[:5], dt=0.01, steps=10)
    with pytest.raises(lf.ShapeError):
        lf.lyapunov(top, np.stack([z0, z0]), dt=0.01, steps=10)
    bad = z0.copy()
    bad[1] = np.nan
    with pytest.raises(lf.NonFiniteError):
        lf.lyapunov(top, bad, dt=0.01, steps=10)
    with pytest.raises(lf.UnsupportedMethodError):
        lf.lyapunov(top, z0, dt=0.01, steps=10, method="splittin")
    with pytest.raises(TypeError, match="method"):
        lf.lyapunov(top, z0, dt=0.01, steps=10, method=3)
    with pytest.raises(TypeError):
        lf.lyapunov(lf.HeavyTop, z0, dt=0.01, steps=10)
    # A system without tangent maps (no Hessian).
    osc = lf.Separable(1.0, lambda q: 0.5 * q[0] ** 2, lambda q: q, dof=1)
    with pytest.raises(lf.InvalidArgumentError, match="tangent maps"):
        lf.lyapunov(osc, [1.0, 0.0], dt=0.01, steps=10)
    # Poincaré sections.
    with pytest.raises(TypeError, match="dt"):
        lf.poincare_section(top, z0, lambda z: z[3])
    with pytest.raises(TypeError, match="section"):
        lf.poincare_section(top, z0, 3.0, dt=0.01)
    with pytest.raises(lf.InvalidArgumentError, match="crossings"):
        lf.poincare_section(top, z0, lambda z: z[3], dt=0.01, crossings=0)
    with pytest.raises(TypeError, match="direction"):
        lf.poincare_section(top, z0, lambda z: z[3], dt=0.01, direction="up")
    with pytest.raises(lf.NonFiniteError):
        lf.poincare_section(top, z0, lambda z: np.nan, dt=0.01)
    np.testing.assert_array_equal(z0, keep)


def test_a_section_function_that_raises_stops_the_run():
    top = lf.HeavyTop([1, 2, 3], 1.0, [1, 1, 1])

    def boom(z):
        raise ZeroDivisionError("boom")

    with pytest.raises(ZeroDivisionError):
        lf.poincare_section(top, [0.3, -0.5, 0.9, 0.6, 0.0, 0.8], boom, dt=0.01)


def test_an_error_during_the_run_carries_the_partial_spectrum():
    """A Hessian that raises after some steps: the error, with the spectrum of the segments done
    before it as err.partial."""
    calls = {"n": 0}

    def hess(q, v):
        calls["n"] += 1
        if calls["n"] > 500:
            raise ZeroDivisionError("late")
        return v

    osc = lf.Separable(1.0, lambda q: 0.5 * q[0] ** 2, lambda q: q, dof=1, hessian=hess)
    with pytest.raises(ZeroDivisionError) as info:
        lf.lyapunov(osc, [1.0, 0.0], dt=0.01, steps=10_000)
    partial = info.value.partial
    assert isinstance(partial, lf.LyapunovSpectrum) and 0 < len(partial.times) < 1000
