"""Reading array-likes of real numbers strictly (the one rule of lieflow's Python layer): bool,
int and float values only — a string, a complex, a datetime or an object numpy cannot read is a
TypeError naming the argument, never a silent conversion."""

import numbers

import numpy as np

from ._text import brief


def real_array(what, value):
    """``value`` as a numpy array of real numbers (not yet copied or converted to float64: a
    caller checks its shape first, so that a huge broadcast view is refused, not copied), or
    TypeError naming ``what``."""
    expected = f"invalid {what}: expected an array-like of real numbers (bool, int or float)"
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{expected}, got a {type(value).__name__}")
    if value is None:
        raise TypeError(f"{expected}, got None")
    try:
        a = np.asarray(value)
    except (ValueError, TypeError) as e:
        raise TypeError(f"{expected}, got a {type(value).__name__} that numpy cannot read as "
                        f"an array: {e}") from None
    if a.dtype.kind == "O":
        # None (and anything else that is not a number) would become NaN in float64.
        for x in a.flat:
            if not isinstance(x, numbers.Real):
                raise TypeError(f"{expected}, got a {type(value).__name__} containing a "
                                f"{type(x).__name__} {brief(x, 40)}")
        try:
            a = a.astype(np.float64)
        except (ValueError, TypeError):
            raise TypeError(f"{expected}, got an object array") from None
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{expected}, got a {type(value).__name__} (numpy dtype {a.dtype})")
    return a
