"""Matrix Lie groups and algebras (bindings of ``lieflow::lie``).

All functions take numpy float64 arrays (or array-likes) and return new arrays; see each
function's docstring for the equation it implements.

Rotation interop (scipy's conventions): ``to_quaternion``/``from_quaternion``,
``to_euler``/``from_euler`` (native, over any leading axes) and ``to_scipy``/``from_scipy``
(``scipy.spatial.transform.Rotation`` objects; scipy is optional and imported on use).
"""

from . import _lieflow
from ._lieflow import ArgumentTypeError as _ArgumentTypeError
from ._reexport import reexport as _reexport

__all__ = sorted(_reexport(_lieflow.lie, globals()) + ["from_scipy", "to_scipy"])


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
    """The rotations ``R`` as a ``scipy.spatial.transform.Rotation``.

    Args:
        R: (3, 3) or (..., 3, 3) rotation matrices (checked: ‖RᵀR − I‖_F and abs(det R − 1)
            at most 1e-10).
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
