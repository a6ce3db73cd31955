r"""Matrix Lie groups and algebras (bindings of ``lieflow::lie``).

All functions take numpy float64 arrays (or array-likes) and return new arrays; see each
function's docstring for the equation it implements.

Group verbs: every group has the same verbs under one prefix, ``so3_*`` (SO(3), algebra
vectors w with :math:`\hat w x = w \times x`), ``se3_*`` (SE(3), 4×4 homogeneous matrices,
algebra vectors :math:`(\omega, v)` with the rotation first) and ``so_*`` (SO(n) for any
:math:`n \ge 2`, algebra as skew
matrices, coordinates in the e_ij basis): ``exp``, ``log``, ``compose``, ``inverse``, ``act``,
``Ad``, ``ad``, ``ad_star``, ``hat``, ``vee``, ``jacobian_left``, ``jacobian_right`` (the
Jacobians with ``inverse=True`` for their inverses). Every function is checked: invalid input
raises a typed error (``lieflow.errors``), never returns NaN. :math:`SO(n) \times SO(n)` has ``product_Ad``
and ``product_bracket``.

Aliases (the names before the prefixes, kept working): ``hat`` and ``vee`` of ``so3_hat`` and
``so3_vee``; ``hat_n``, ``vee_n``, ``cayley``, ``cayley_inv``, ``dexp``, ``dexp_inv``, ``Ad``,
``ad`` and ``ad_star`` of ``so_hat``, ``so_vee``, ``so_cayley``, ``so_cayley_inv``,
``so_dexp``, ``so_dexp_inv``, ``so_Ad``, ``so_ad`` and ``so_ad_star``.

Rotation interop (scipy's conventions): ``to_quaternion``/``from_quaternion``,
``to_euler``/``from_euler`` (native, over any leading axes) and ``to_scipy``/``from_scipy``
(``scipy.spatial.transform.Rotation`` objects; scipy is optional and imported on use).
"""

from . import _lieflow
from ._lieflow import ArgumentTypeError as _ArgumentTypeError
from ._reexport import reexport as _reexport

_ALIASES = {
    "hat": "so3_hat",
    "vee": "so3_vee",
    "hat_n": "so_hat",
    "vee_n": "so_vee",
    "cayley": "so_cayley",
    "cayley_inv": "so_cayley_inv",
    "dexp": "so_dexp",
    "dexp_inv": "so_dexp_inv",
    "Ad": "so_Ad",
    "ad": "so_ad",
    "ad_star": "so_ad_star",
}

__all__ = sorted(
    _reexport(_lieflow.lie, globals()) + ["from_scipy", "to_scipy"] + list(_ALIASES)
)


def hat(w):
    """Alias of so3_hat."""
    return so3_hat(w)


def vee(xi):
    """Alias of so3_vee."""
    return so3_vee(xi)


def hat_n(c):
    """Alias of so_hat."""
    return so_hat(c)


def vee_n(xi):
    """Alias of so_vee."""
    return so_vee(xi)


def cayley(xi):
    """Alias of so_cayley."""
    return so_cayley(xi)


def cayley_inv(R):
    """Alias of so_cayley_inv."""
    return so_cayley_inv(R)


def dexp(xi, eta):
    """Alias of so_dexp."""
    return so_dexp(xi, eta)


def dexp_inv(xi, eta):
    """Alias of so_dexp_inv."""
    return so_dexp_inv(xi, eta)


def Ad(g, xi):
    """Alias of so_Ad."""
    return so_Ad(g, xi)


def ad(xi, eta):
    """Alias of so_ad."""
    return so_ad(xi, eta)


def ad_star(xi, mu):
    """Alias of so_ad_star."""
    return so_ad_star(xi, mu)


def _scipy_rotation(function):
    """scipy's Rotation class, or an ImportError saying that `function` needs scipy."""
    try:
        from scipy.spatial.transform import Rotation
    except ImportError as e:
        raise ImportError(
            f"lieflow.lie.{function} needs scipy (scipy.spatial.transform.Rotation), which "
            f"could not be imported ({e}); install it with `pip install scipy`, or use "
            "to_quaternion/from_quaternion, which need no scipy"
        ) from e
    return Rotation


def to_scipy(R):
    r"""The rotations ``R`` as a ``scipy.spatial.transform.Rotation``.

    Args:
        R: (3, 3) or (..., 3, 3) rotation matrices (checked: :math:`\|R^\top R - I\|_F` and
            :math:`|\det R - 1|` at most :math:`10^{-10}`).
    Returns:
        ``Rotation.from_quat(to_quaternion(R, scalar_first=False))``: a single rotation for a
        (3, 3) input, else one of shape R.shape[:-2] (leading axes beyond one need scipy ≥ 1.16).
    Raises:
        ImportError: scipy is not installed. ShapeError, NonFiniteError, NotInGroupError: as
        ``to_quaternion``.
    """
    Rotation = _scipy_rotation("to_scipy")
    return Rotation.from_quat(to_quaternion(R, scalar_first=False))


def from_scipy(rotation):
    """The rotation matrices of a ``scipy.spatial.transform.Rotation``.

    Args:
        rotation: a scipy ``Rotation`` (single or of any shape).
    Returns:
        (3, 3) for a single rotation, else (*rotation.shape, 3, 3):
        ``from_quaternion(rotation.as_quat(), scalar_first=False)``, equal to
        ``rotation.as_matrix()`` to rounding.
    Raises:
        ImportError: scipy is not installed. ArgumentTypeError (a TypeError): ``rotation`` is not
        a scipy ``Rotation``.
    """
    Rotation = _scipy_rotation("from_scipy")
    if not isinstance(rotation, Rotation):
        raise _ArgumentTypeError(
            "argument 'rotation': expected a scipy.spatial.transform.Rotation, got a "
            f"{type(rotation).__name__} (for an array of quaternions or angles use "
            "from_quaternion or from_euler)"
        )
    return from_quaternion(rotation.as_quat(), scalar_first=False)
