"""FileFormatError, the error of :mod:`lieflow.io`: defined below the private modules that
raise it (``_netcdf``, ``_checksum``, ``_metadata``) and named as lieflow.io's own; and
LieflowWarning, the category of lieflow's warnings."""

from ._lieflow import LieflowError


class FileFormatError(LieflowError):
    """A file that is not a lieflow trajectory, is damaged, or was written in a newer format."""

    __module__ = "lieflow.io"


class LieflowWarning(UserWarning):
    """A warning of lieflow: the reading it chose of ambiguous input, or a setting that makes a
    result empty or inaccurate. Each names what it saw and how to silence it;
    ``warnings.filterwarnings("ignore", category=lieflow.LieflowWarning)`` silences all."""

    __module__ = "lieflow"
