"""FileFormatError, the error of :mod:`lieflow.io`: defined below the private modules that
raise it (``_netcdf``, ``_checksum``, ``_metadata``) and named as lieflow.io's own."""

from ._lieflow import LieflowError


class FileFormatError(LieflowError):
    """A file that is not a lieflow trajectory, is damaged, or was written in a newer format."""

    __module__ = "lieflow.io"
