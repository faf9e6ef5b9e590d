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

    Examples
    --------
    >>> from manakov.top import state_dim
    >>> state_dim(4), state_dim(5)
    (6, 10)
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
    """``l`` as a C-contiguous (N, m) float array and its leading shape.

    The one wording of a function that broadcasts over leading axes (see
    ``docs/conventions.md``); :func:`_one_state` is that of one that does not.
    """
    arr = _float_array(l, what)
    _last_axis(arr, m, what)
    lead = arr.shape[:-1]
    return np.ascontiguousarray(arr.reshape(-1, m)), lead


def _last_axis(arr: np.ndarray, m: int, what: str) -> None:
    """The shape check of :func:`_states` alone (for callers that take NaN)."""
    if arr.ndim == 0 or arr.shape[-1] != m:
        raise ValueError(
            f"{what} must have shape (..., {m}) (states on the last axis), got shape {arr.shape}"
        )


def _one_state(l: Any, m: int, what: str, func: str, instead: str | None = None) -> np.ndarray:
    """``l`` as one real, finite state of shape (m,), for ``func``, which takes one.

    The one wording of a function that does not broadcast over leading axes
    (``docs/conventions.md``), naming what to use for many states when there is
    such a function.
    """
    arr = _float_array(l, what)
    if arr.shape != (m,):
        more = f"; for many states use {instead}" if instead else ""
        raise ValueError(
            f"{what} must be one state of shape ({m},), got shape {arr.shape}: {func} takes "
            f"one state and does not broadcast over leading axes{more}"
        )
    return np.array(arr, dtype=np.float64, order="C")


#: Significant digits of a computed number in a message or a report (as in the
#: core's messages): enough to recognise it, no more than a computed double
#: carries after a few operations.
MESSAGE_DIGITS = 10


def _show(x: Any, digits: int = MESSAGE_DIGITS) -> str:
    """``x`` (real or complex) to ``digits`` significant digits, like ``%g``, with a
    real or imaginary part below the last digit shown of the other left out as
    rounding noise (``3.19+7e-32j`` prints ``3.19``); NaN prints ``nan``."""
    z = complex(x)
    if not (math.isfinite(z.real) and math.isfinite(z.imag)):
        return str(z.real) if z.imag == 0 else str(z)
    cut = abs(z) * 10.0 ** (-digits)
    re = z.real if abs(z.real) > cut else 0.0
    im = z.imag if abs(z.imag) > cut else 0.0
    if im == 0.0:
        return f"{re:.{digits}g}"
    if re == 0.0:
        return f"{im:.{digits}g}j"
    return f"{re:.{digits}g}{im:+.{digits}g}j"


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


#: Largest ``|ν t|`` (cycles) whose fractional part a double still holds
#: (2^52): beyond it the angle is not determined to any digit.
MAX_PHASE = 4.5e15


def _angles(t: Any, frequencies: Any) -> np.ndarray:
    """``(ν t) mod 1`` for real finite ``t``; ValueError where it is not determined."""
    tt = _float_array(t, "t")[..., None]
    with np.errstate(over="ignore", invalid="ignore"):
        phase = tt * np.asarray(frequencies, dtype=float)
    if not np.all(np.abs(phase) <= MAX_PHASE):
        worst = float(np.max(np.abs(np.nan_to_num(phase, nan=np.inf))))
        raise ValueError(
            f"the angles nu t are not determined in double precision: |nu t| reaches "
            f"{worst:.3g} cycles, beyond {MAX_PHASE:.2g} (or the frequencies are not finite)"
        )
    return np.mod(phase, 1.0)
