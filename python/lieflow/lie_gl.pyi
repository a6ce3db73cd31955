# Stub fragment for the GL+(n) functions of lieflow.lie (crates/py/src/lie/gl.rs); the lead
# merges it into lie.pyi / _lieflow.pyi.
from typing import TypedDict

import numpy as np
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]

class GLStratum(TypedDict):
    singular_values: F64
    multiplicities: list[int]
    min_gap: float
    tol: float
    principal: bool

def svd_coordinates(X: ArrayLike) -> tuple[F64, F64, F64]:
    """SVD coordinates (R, a, S) with X = R @ diag(a) @ S.T, R, S in SO(n) (001 (2.4))."""

def from_svd(R: ArrayLike, a: ArrayLike, S: ArrayLike) -> F64:
    """X = R @ diag(a) @ S.T (001 (2.6))."""

def polar(X: ArrayLike) -> tuple[F64, F64]:
    """Polar decomposition X = R @ P, R in SO(n), P symmetric positive definite."""

def stratum(X: ArrayLike, tol: float = 1e-8) -> GLStratum:
    """Coincidences of the singular values of X (001 §6.1, (9.2))."""
