# The state is called l, as in the paper: E741 does not apply.
# ruff: noqa: E741
"""Shared argument checks and result guards: the bottom of the import graph.

Every public module imports from here; this module imports nothing of the
package, so imports run one way (``top → reduction → curve → _checks``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def state_dim(n: int) -> int:
    """Length ``n(n-1)/2`` of the so(n) state vector (the strict upper triangle of l).

    Parameters
    ----------
    n : int

    Returns
    -------
    int
    """
    return n * (n - 1) // 2


def _n_from_dim(m: int) -> int:
    n = int(round((1 + math.sqrt(1 + 8 * m)) / 2))
    if state_dim(n) != m or n < 2:
        raise ValueError(f"last axis of length {m} is not n(n-1)/2 for any n")
    return n


def _float_array(x: Any, what: str) -> np.ndarray:
    arr = np.asarray(x)
    if np.iscomplexobj(arr):
        raise ValueError(f"{what} must be real, got a complex array")
    # Only booleans, integers and floats are numbers: numpy would also convert
    # strings ('1' -> 1.0), bytes, datetimes and objects.
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"{what} must be a real numeric array, got dtype {arr.dtype}")
    arr = arr.astype(np.float64, copy=False)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be finite; it contains NaN or infinity")
    return arr


def _states(l: Any, m: int, what: str = "l") -> tuple[np.ndarray, tuple[int, ...]]:
    """``l`` as a C-contiguous (N, m) float array and its leading shape."""
    arr = _float_array(l, what)
    if arr.ndim == 0 or arr.shape[-1] != m:
        raise ValueError(f"{what} must have shape (..., {m}), got {arr.shape}")
    lead = arr.shape[:-1]
    return np.ascontiguousarray(arr.reshape(-1, m)), lead


def _finite_result(values: np.ndarray, cause: str = "this l: rescale l") -> np.ndarray:
    """Raise instead of returning an overflowed (inf/NaN) result from finite input."""
    if not np.all(np.isfinite(values)):
        raise ValueError(f"the result overflows (inf or NaN) for {cause}")
    return values


def _out(values: np.ndarray, lead: tuple[int, ...]) -> Any:
    """Reshape per-state results back to the leading shape; 0-d → scalar."""
    values = _finite_result(values)
    res = values.reshape(lead + values.shape[1:])
    return res[()] if res.ndim == 0 else res
