"""lieflow.lie group verbs: the same verbs for SO(3) (so3_*), SE(3) (se3_*) and SO(n) (so_*),
each against its definition (finite differences of exp for Ad, ad and the Jacobians), the
aliases of the old names, and typed errors."""

import numpy as np
import pytest

import lieflow as lf
from lieflow import lie

rng = np.random.default_rng(3)
H = 1e-6


def so_group(n):
    """The verbs of SO(n) in the shape every group shares: algebra elements as coordinates."""
    d = n * (n - 1) // 2
    return dict(
        dim=d,
        exp=lambda c: lie.so_exp(lie.so_hat(c)),
        log=lambda g: lie.so_vee(lie.so_log(g)),
        compose=lie.so_compose,
        inverse=lie.so_inverse,
        matrix=lambda g: g,
        hat=lie.so_hat,
        vee=lie.so_vee,
        Ad=lambda g, c: lie.so_vee(lie.so_Ad(g, lie.so_hat(c))),
        ad=lambda a, b: lie.so_vee(lie.so_ad(lie.so_hat(a), lie.so_hat(b))),
        ad_star=lambda a, m: lie.so_vee(lie.so_ad_star(lie.so_hat(a), lie.so_hat(m))),
        jl=lambda c, inverse=False: lie.so_jacobian_left(lie.so_hat(c), inverse=inverse),
        jr=lambda c, inverse=False: lie.so_jacobian_right(lie.so_hat(c), inverse=inverse),
        act=lie.so_act,
        point=n,
    )


SO3 = dict(
    dim=3,
    exp=lie.so3_exp,
    log=lie.so3_log,
    compose=lie.so3_compose,
    inverse=lie.so3_inverse,
    matrix=lambda g: g,
    hat=lie.so3_hat,
    vee=lie.so3_vee,
    Ad=lie.so3_Ad,
    ad=lie.so3_ad,
    ad_star=lie.so3_ad_star,
    jl=lie.so3_jacobian_left,
    jr=lie.so3_jacobian_right,
    act=lie.so3_act,
    point=3,
)

SE3 = dict(
    dim=6,
    exp=lie.se3_exp,
    log=lie.se3_log,
    compose=lie.se3_compose,
    inverse=lie.se3_inverse,
    matrix=lambda g: g,
    hat=lie.se3_hat,
    vee=lie.se3_vee,
    Ad=lie.se3_Ad,
    ad=lie.se3_ad,
    ad_star=lie.se3_ad_star,
    jl=lie.se3_jacobian_left,
    jr=lie.se3_jacobian_right,
    act=lie.se3_act,
    point=3,
)

GROUPS = {"SO(3)": SO3, "SE(3)": SE3, "SO(2)": so_group(2), "SO(4)": so_group(4), "SO(5)": so_group(5)}


def small(d):
    """A random algebra element with norm 1 (inside every domain, |ξ| < π)."""
    x = rng.normal(size=d)
    return x / np.linalg.norm(x)


@pytest.mark.parametrize("name", GROUPS)
def test_every_verb_against_its_definition(name):
    G = GROUPS[name]
    d = G["dim"]
    xi, eta, mu = small(d), rng.normal(size=d), rng.normal(size=d)
    g, h = G["exp"](rng.normal(size=d)), G["exp"](rng.normal(size=d))
    gm = G["matrix"]
    # Group axioms in the matrix representation, exp/log round trip.
    np.testing.assert_allclose(gm(G["compose"](g, h)), gm(g) @ gm(h), atol=1e-13)
    np.testing.assert_allclose(gm(G["compose"](g, G["inverse"](g))), np.eye(gm(g).shape[0]), atol=1e-13)
    np.testing.assert_allclose(G["log"](G["exp"](xi)), xi, atol=1e-13)
    # act is a left action.
    x = rng.normal(size=G["point"])
    np.testing.assert_allclose(G["act"](g, G["act"](h, x)), G["act"](G["compose"](g, h), x), atol=1e-12)
    # hat and vee are inverse; exp(hat ξ) is the matrix exponential.
    np.testing.assert_allclose(G["vee"](G["hat"](xi)), xi, atol=0)
    # Ad_g ξ = d/dt g exp(tξ) g⁻¹ and ad_ξ η = d/dt Ad_exp(tξ) η.
    gi = gm(G["inverse"](g))
    fd = (gm(g) @ gm(G["exp"](H * xi)) @ gi - gm(g) @ gm(G["exp"](-H * xi)) @ gi) / (2 * H)
    np.testing.assert_allclose(G["hat"](G["Ad"](g, xi)), fd, atol=1e-8)
    fd = (G["Ad"](G["exp"](H * xi), eta) - G["Ad"](G["exp"](-H * xi), eta)) / (2 * H)
    np.testing.assert_allclose(G["ad"](xi, eta), fd, atol=1e-8)
    # ⟨ad*_ξ μ, η⟩ = ⟨μ, ad_ξ η⟩ (coordinates are orthonormal for every pairing here).
    assert abs(G["ad_star"](xi, mu) @ eta - mu @ G["ad"](xi, eta)) < 1e-12
    # Jacobians against differences of exp; J_r(−ξ) = J_l(ξ); inverses.
    e, ei = gm(G["exp"](xi)), np.linalg.inv(gm(G["exp"](xi)))
    jl, jr = G["jl"](xi), G["jr"](xi)
    for k in range(d):
        dk = np.eye(d)[k] * H
        de = (gm(G["exp"](xi + dk)) - gm(G["exp"](xi - dk))) / (2 * H)
        np.testing.assert_allclose(ei @ de, G["hat"](jr[:, k]), atol=1e-8)
        np.testing.assert_allclose(de @ ei, G["hat"](jl[:, k]), atol=1e-8)
    np.testing.assert_allclose(G["jr"](-xi), jl, atol=1e-14)
    np.testing.assert_allclose(G["jl"](xi, inverse=True) @ jl, np.eye(d), atol=1e-12)
    np.testing.assert_allclose(G["jr"](xi, inverse=True) @ jr, np.eye(d), atol=1e-12)
    assert e.shape == gm(g).shape


def test_batches_broadcast_a_single_element():
    R = lie.so3_exp(rng.normal(size=(5, 3)))
    x = rng.normal(size=3)
    out = lie.so3_act(R, x)
    assert out.shape == (5, 3)
    np.testing.assert_allclose(out[2], R[2] @ x, atol=1e-15)
    np.testing.assert_allclose(lie.so3_compose(R, R[0])[1], R[1] @ R[0], atol=1e-15)
    g = lie.se3_exp(rng.normal(size=(4, 6)))
    xi = rng.normal(size=(4, 6))
    np.testing.assert_allclose(lie.se3_Ad(g, xi)[3], lie.se3_Ad(g[3]) @ xi[3], atol=1e-13)
    assert lie.se3_jacobian_left(xi).shape == (4, 6, 6)
    np.testing.assert_allclose(lie.so_inverse(lie.so_exp(lie.so_hat(rng.normal(size=(3, 6)))))[1].shape, (4, 4))


def test_aliases_are_the_prefixed_verbs():
    xi, eta = lie.so_hat(rng.normal(size=6)), lie.so_hat(rng.normal(size=6))
    g = lie.so_exp(xi)
    pairs = [
        (lie.hat_n, lie.so_hat, (rng.normal(size=6),)),
        (lie.vee_n, lie.so_vee, (xi,)),
        (lie.cayley, lie.so_cayley, (xi,)),
        (lie.cayley_inv, lie.so_cayley_inv, (g,)),
        (lie.dexp, lie.so_dexp, (xi, eta)),
        (lie.dexp_inv, lie.so_dexp_inv, (0.1 * xi, eta)),
        (lie.Ad, lie.so_Ad, (g, xi)),
        (lie.ad, lie.so_ad, (xi, eta)),
        (lie.ad_star, lie.so_ad_star, (xi, eta)),
        (lie.hat, lie.so3_hat, (rng.normal(size=3),)),
        (lie.vee, lie.so3_vee, (lie.so3_hat(rng.normal(size=3)),)),
    ]
    for old, new, args in pairs:
        assert old.__doc__ == f"Alias of {new.__name__}."
        np.testing.assert_array_equal(old(*args), new(*args))
        assert old.__name__ in lie.__all__ and new.__name__ in lie.__all__


def test_typed_errors_never_nan():
    not_rotation = np.eye(3) * 2.0
    with pytest.raises(lf.NotInGroupError):
        lie.so3_compose(not_rotation, np.eye(3))
    with pytest.raises(lf.NotInGroupError):
        lie.so3_act(not_rotation, [1.0, 0.0, 0.0])
    with pytest.raises(lf.NotInGroupError):
        lie.so_compose(np.eye(4), np.eye(4) * 2.0)
    with pytest.raises(lf.ShapeError):
        lie.so_act(np.eye(4), [1.0, 2.0])
    with pytest.raises(lf.NotInGroupError):
        lie.se3_vee(np.eye(4))
    with pytest.raises(lf.InvalidArgumentError):
        lie.se3_jacobian_left([0.0, 0.0, 2 * np.pi, 1.0, 0.0, 0.0], inverse=True)
    with pytest.raises(lf.InvalidArgumentError):
        lie.so_jacobian_left(lie.so_hat([4.0, 0.0, 0.0, 0.0, 0.0, 0.0]), inverse=True)
    with pytest.raises(lf.NonFiniteError):
        lie.so3_ad([np.nan, 0.0, 0.0], [1.0, 0.0, 0.0])
