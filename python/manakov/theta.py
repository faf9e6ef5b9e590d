"""Riemann theta functions with half-integer characteristics, (34)-(36).

Convention (the paper's (36) with characteristics, as in python-flint/FLINT)::

    theta[a;b](z, tau) = sum_{n in Z^g} exp( i pi (n + a/2)^T tau (n + a/2)
                                            + 2 pi i (n + a/2)^T (z + b/2) ),

with ``a, b`` in ``{0, 1}^g``; ``theta[0;0]`` is the paper's (36). The ``4^g``
characteristics are numbered in FLINT's order: the index of ``[a; b]`` has the
bits ``a_1 ... a_g b_1 ... b_g``, most significant first (for g = 2:
``8 a1 + 4 a2 + 2 b1 + b2``), which is the order of ``acb_mat.theta`` in
python-flint (``tau.theta(z)`` with ``z`` a g x 1 column; output a 1 x 4^g row).

The values are computed as ``theta = exp(L) * Omega`` with the real exponent
``L = pi (Im z)^T (Im tau)^{-1} (Im z) >= 0``; ``|Omega|`` is bounded by a
constant depending on ``tau`` only. ``log_scale=True`` returns ``(Omega, L)``,
which never overflows; the default returns ``theta`` itself and raises
``OverflowError`` when a value does not fit in a double.

NaN policy: NaN or infinite entries in ``z`` or ``tau`` raise ``ValueError``;
the functions never return NaN or infinity.

The paper's table (35) is carried as printed in :data:`PAPER_TABLE_35`; its
2 x 2 arrays ``[[x1, x2], [y1, y2]]`` are read as ``a = (x1, x2)`` (top row),
``b = (y1, y2)`` (bottom row), see :data:`PAPER_CHARACTERISTICS` and
docs/theta.md.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence
from typing import Any, Literal, Union, overload

import numpy as np
import numpy.typing as npt

from . import _core

__all__ = [
    "CHARACTERISTICS",
    "DEFAULT_TOL",
    "MAX_SECONDS_PER_POINT",
    "PAPER_CHARACTERISTICS",
    "PAPER_TABLE_35",
    "char_index",
    "characteristics",
    "parity",
    "theta",
    "theta_all",
    "theta_jet",
]

#: Default truncation tolerance: absolute error bound on every normalised value
#: ``Omega = theta * exp(-L)`` (and on its z-derivatives at the reduced point)
#: from the omitted terms of the series (a proven bound, docs/theta.md). Below
#: the rounding error of the sum, so rounding (~1e-16 relative to the largest
#: value) dominates the total error.
DEFAULT_TOL = 1e-15

#: Largest estimated cost of one point in seconds (Rust ``MAX_SECONDS_PER_POINT``):
#: above it ``tau`` is refused with a ValueError that gives the estimate. The
#: estimate is ``terms * t_term + rows * t_row`` with per-genus constants fitted on
#: this package's timings (docs/theta.md, "Cost budget"); it errs high.
MAX_SECONDS_PER_POINT = 1.0

#: Largest exponent whose exp is a finite double.
_LOG_MAX = math.log(np.finfo(np.float64).max)

Characteristic = tuple[tuple[int, ...], tuple[int, ...]]
#: A complex array of theta values (or derivatives).
ComplexArray = npt.NDArray[np.complex128]
#: ``L`` of ``theta = exp(L) * Omega``: a float for one point, else an array.
LogScale = Union[float, npt.NDArray[np.float64]]
#: One value per point: a Python complex for a single point, else an array.
ComplexOut = Union[complex, ComplexArray]
CharLike = Union[None, int, str, Sequence[Sequence[int]]]


def characteristics(g: int = 2) -> list[Characteristic]:
    r"""The ``4^g`` half-integer characteristics ``(a, b)`` in FLINT's order.

    The characteristic ``[a; b]`` labels the series (the paper's (36) with
    characteristics, (35))

    .. math:: \theta[a;b](z,\tau)=\sum_{n\in\mathbb Z^g}
              e^{i\pi (n+a/2)^T\tau(n+a/2)+2\pi i(n+a/2)^T(z+b/2)},
              \qquad a, b \in \{0, 1\}^g.

    Entry ``i`` has ``a = bits 2g-1 .. g`` and ``b = bits g-1 .. 0`` of ``i``
    (most significant first), matching python-flint's ``acb_mat.theta``.

    Parameters
    ----------
    g : int, optional
        The genus, 1 to 6 (default 2).

    Returns
    -------
    list of (tuple of int, tuple of int)
        ``4^g`` pairs ``(a, b)`` of 0/1 tuples of length g; entry ``i`` is the
        characteristic of output ``i`` of :func:`theta_all`.

    Raises
    ------
    TypeError
        ``g`` is not an integer.
    ValueError
        ``g`` is outside 1..6.

    Examples
    --------
    >>> import manakov
    >>> chars = manakov.characteristics(2)
    >>> len(chars), chars[0], chars[9]
    (16, ((0, 0), (0, 0)), ((1, 0), (0, 1)))
    """
    g = operator.index(g)
    if not 1 <= g <= 6:
        raise ValueError(f"genus must be in 1..6, got {g}")
    out = []
    for idx in range(4**g):
        bits = [(idx >> (2 * g - 1 - k)) & 1 for k in range(2 * g)]
        out.append((tuple(bits[:g]), tuple(bits[g:])))
    return out


#: The 16 genus-2 characteristics ``(a, b)`` in FLINT's order.
CHARACTERISTICS: list[Characteristic] = characteristics(2)

#: The paper's table (35) exactly as printed: label -> the 2 x 2 array
#: ``((x1, x2), (y1, y2))`` written under theta[...]. Verified against the curve
#: in tests/test_theta_quotients.py: it holds in a suitable canonical basis
#: (docs/errata.md, row (34)-(35); docs/theta_quotients.md).
PAPER_TABLE_35: dict[str, tuple[tuple[int, int], tuple[int, int]]] = {
    "theta23": ((0, 0), (1, 1)),
    "theta31": ((1, 0), (1, 1)),
    "theta12": ((1, 0), (0, 0)),
    "theta14": ((1, 1), (1, 1)),
    "theta24": ((0, 1), (1, 1)),
    "theta34": ((0, 1), (0, 0)),
    "theta0": ((1, 1), (0, 0)),
    "theta": ((0, 0), (0, 0)),
}

#: Table (35) as characteristics: top row = ``a``, bottom row = ``b`` (the
#: Weber/Rosenhain reading). With it, theta31 and theta24 are odd, the other
#: six even.
PAPER_CHARACTERISTICS: dict[str, Characteristic] = {
    label: (tuple(rows[0]), tuple(rows[1])) for label, rows in PAPER_TABLE_35.items()
}


def char_index(a: Sequence[int], b: Sequence[int]) -> int:
    """FLINT index of the characteristic ``[a; b]`` of (35)-(36).

    ``index = sum_k 2^(2g-1-k) c_k`` with ``c = (a_1, ..., a_g, b_1, ..., b_g)``:
    the bits ``a_1..a_g b_1..b_g``, most significant first (for g = 2,
    ``8 a1 + 4 a2 + 2 b1 + b2``). Inverse of :func:`characteristics`.

    Parameters
    ----------
    a, b : sequence of int
        The two halves of the characteristic, entries 0 or 1, of the same
        length g in 1..6.

    Returns
    -------
    int
        The index in ``0 .. 4^g - 1``.

    Raises
    ------
    ValueError
        Lengths differ or are outside 1..6, or an entry is not 0 or 1 (booleans
        are refused).
    TypeError
        ``a`` or ``b`` is not a sequence.

    Examples
    --------
    >>> import manakov
    >>> manakov.char_index((1, 0), (0, 1))
    9
    """
    a_t, b_t = tuple(a), tuple(b)
    if len(a_t) != len(b_t) or not 1 <= len(a_t) <= 6:
        raise ValueError(f"a and b must have the same length g in 1..6, got {a_t!r}, {b_t!r}")
    idx = 0
    for bit in a_t + b_t:
        if isinstance(bit, (bool, np.bool_)) or bit not in (0, 1):
            raise ValueError(f"characteristic entries must be 0 or 1, got {bit!r}")
        idx = 2 * idx + int(bit)
    return idx


def parity(char: CharLike, g: int = 2) -> int:
    """``+1`` for an even, ``-1`` for an odd characteristic: ``(-1)^{a.b}``.

    From the series (36) with characteristics, substituting ``n -> -n - a``:
    ``theta[a;b](-z) = (-1)^{a.b} theta[a;b](z)``; in genus 2, 10 are even and
    6 odd (the odd ones vanish at ``z = 0``).

    Parameters
    ----------
    char : None, int, str or (a, b)
        As in :func:`theta`: None for ``[0; 0]``, a FLINT index, a label of the
        paper's table (35) (genus 2) or a pair ``(a, b)``.
    g : int, optional
        The genus (default 2).

    Returns
    -------
    int
        ``+1`` or ``-1``.

    Raises
    ------
    ValueError
        Unknown characteristic (index out of range, unknown label, bad pair) or
        ``g`` outside 1..6.
    TypeError
        ``g`` is not an integer.

    Examples
    --------
    >>> import manakov
    >>> manakov.parity(((1, 0), (1, 0))), manakov.parity(((1, 1), (1, 1)))
    (-1, 1)
    """
    idx = _resolve_char(char, g)
    a, b = characteristics(g)[idx]
    return -1 if sum(x * y for x, y in zip(a, b)) % 2 else 1


def _resolve_char(char: CharLike, g: int) -> int:
    # The genus first: 4**g of a huge g is itself seconds of work.
    g = operator.index(g)
    if not 1 <= g <= 6:
        raise ValueError(f"genus must be in 1..6, got {g}")
    n = 4**g
    if char is None:
        return 0
    if isinstance(char, str):
        if g != 2 or char not in PAPER_CHARACTERISTICS:
            raise ValueError(
                f"unknown characteristic label {char!r}; genus-2 labels of (35): "
                f"{sorted(PAPER_CHARACTERISTICS)}"
            )
        return char_index(*PAPER_CHARACTERISTICS[char])
    if isinstance(char, (int, np.integer)) and not isinstance(char, (bool, np.bool_)):
        if not 0 <= int(char) < n:
            raise ValueError(f"characteristic index must be in 0..{n - 1}, got {char}")
        return int(char)
    try:
        a, b = char  # type: ignore[misc]
        idx = char_index(a, b)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"characteristic must be None, an index, a (35) label or a pair (a, b) of "
            f"0/1 sequences of length {g}; got {char!r}"
        ) from exc
    if len(tuple(a)) != g:
        raise ValueError(f"characteristic {char!r} has length {len(tuple(a))}, tau has genus {g}")
    return idx


def _prepare(
    z: npt.ArrayLike, tau: npt.ArrayLike
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128], tuple[int, ...], int]:
    tau_a = _as_complex("tau", tau)
    if tau_a.ndim == 0:
        tau_a = tau_a.reshape(1, 1)
    if tau_a.ndim != 2 or tau_a.shape[0] != tau_a.shape[1]:
        raise ValueError(f"tau must have shape (g, g), got {tau_a.shape}")
    g = tau_a.shape[0]
    if not 1 <= g <= 6:
        raise ValueError(f"tau has shape {tau_a.shape}: the genus must be in 1..6")
    if isinstance(z, np.ndarray):
        _check_batch_fits(z.shape, g)  # before the conversion copies z
    z_a = _as_complex("z", z)
    if z_a.ndim == 0 or z_a.shape[-1] != g:
        raise ValueError(f"z must have shape (..., {g}) for tau of genus {g}, got {z_a.shape}")
    lead = z_a.shape[:-1]
    # The binding reads any strides (and copies z itself): no contiguous copy here.
    z2 = z_a.reshape(-1, g)
    return z2, np.ascontiguousarray(tau_a), lead, g


def _check_batch_fits(shape: tuple[int, ...], g: int) -> None:
    """MemoryError before any copy if the ``4^g`` values of every point cannot be held.

    A ``numpy.empty`` of the output's size only reserves address space (freed at
    once), so this costs nothing when it fits; it spares converting a huge ``z``
    to complex first and then failing on the output.
    """
    if len(shape) == 0 or shape[-1] != g:
        return  # the shape error is raised by the caller
    npts = math.prod(shape[:-1])
    try:
        np.empty((npts, 4**g), dtype=np.complex128)
    except (MemoryError, ValueError) as exc:
        raise MemoryError(
            f"{npts} points of genus {g} need {npts * 4**g * 16 / 2**30:.3g} GiB for the "
            f"values alone: {exc}"
        ) from None


def _as_complex(what: str, x: npt.ArrayLike) -> npt.NDArray[np.complex128]:
    """``x`` as a complex128 array (a copy or a read-only view: never modified)."""
    try:
        return np.asarray(x, dtype=np.complex128)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what} must be numeric (convertible to complex128): {exc}") from exc


def _check_tol(tol: float) -> float:
    arr = np.asarray(tol)
    if arr.ndim != 0 or arr.dtype.kind not in "fiu":
        raise ValueError(f"tol must be a real number in (0, 1), got {tol!r}")
    value = float(arr)
    if not 0.0 < value < 1.0:
        raise ValueError(f"tol must be in (0, 1), got {value}")
    return value


def _jet(
    z2: npt.NDArray[np.complex128],
    tau_a: npt.NDArray[np.complex128],
    lead: tuple[int, ...],
    g: int,
    tol: float,
    order: int,
    scaled: bool,
    parallel: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Core call; with ``scaled`` the arrays hold theta itself (scaled in Rust)."""
    vals, grad, hess, log, finite = _core.theta_jet(
        z2, tau_a, _check_tol(tol), order, scaled, bool(parallel)
    )
    if not finite:
        raise OverflowError(
            f"theta overflows float64 (log of the exponential factor up to "
            f"{float(np.max(log)):.6g}, double range ends at {_LOG_MAX:.6g}); use log_scale=True"
        )
    n = 4**g
    return (
        vals.reshape(lead + (n,)),
        grad.reshape(lead + (n, grad.shape[2])),
        hess.reshape(lead + (n, hess.shape[2], hess.shape[3])),
        log.reshape(lead),
    )


def _out(x: np.ndarray, lead: tuple[int, ...]) -> Any:
    """Scalar out for a single point when the result is one number."""
    if lead == () and x.ndim == 0:
        return x[()]
    return x


@overload
def theta_all(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    *,
    tol: float = ...,
    log_scale: Literal[False] = ...,
    parallel: bool = ...,
) -> ComplexArray: ...
@overload
def theta_all(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    *,
    tol: float = ...,
    log_scale: Literal[True],
    parallel: bool = ...,
) -> tuple[ComplexArray, LogScale]: ...
def theta_all(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    *,
    tol: float = DEFAULT_TOL,
    log_scale: bool = False,
    parallel: bool = True,
) -> ComplexArray | tuple[ComplexArray, LogScale]:
    r"""All ``4^g`` theta functions with half-integer characteristics at once.

    .. math:: \theta[a;b](z,\tau)=\sum_{n\in\mathbb Z^g}
              e^{i\pi (n+a/2)^T\tau(n+a/2)+2\pi i(n+a/2)^T(z+b/2)}

    (the paper's (36) with characteristics, (35); ``[0; 0]`` is (36) itself).

    Parameters
    ----------
    z : array_like, shape (..., g)
        Points; any leading shape. Complex.
    tau : array_like, shape (g, g)
        Period matrix: symmetric (to 1e-12 relative), ``Im tau`` positive definite.
    tol : float, optional
        Absolute truncation error allowed on the normalised values (proven bound).
    log_scale : bool, optional
        If True return ``(Omega, L)`` with ``theta = Omega * exp(L)``,
        ``L = pi Im(z)^T Im(tau)^{-1} Im(z)`` of shape ``(...)``.
    parallel : bool, optional
        Split batches of at least 4096 points over threads (rayon's pool, size
        from ``RAYON_NUM_THREADS``, default all cores). ``False`` keeps the
        computation on one core. The values do not depend on it.

    Returns
    -------
    ndarray, shape (..., 4^g)
        The values in FLINT's order (index bits ``a1..ag b1..bg``, most
        significant first; see :data:`CHARACTERISTICS`).

    Raises
    ------
    ValueError
        Non-numeric input; wrong shapes (genus 0 or above 6 included);
        non-finite entries; non-symmetric tau; ``Im tau`` not positive definite
        (the message gives the smallest eigenvalue) or not factorisable in
        double precision; ``Im tau`` so ill-conditioned that more than 2e8
        terms, or an estimated 1 s of work, would be needed per point
        (:data:`MAX_SECONDS_PER_POINT`; large genus); ``|Re z|`` or ``|(Im tau)^-1 Im z|`` beyond
        4.5e15 (no fractional digit left: theta is not determined) or ``L``
        overflowing; ``tol`` not a real number in (0, 1).
    OverflowError
        A value exceeds the double range and ``log_scale`` is False.
    MemoryError
        The batch's outputs do not fit in memory (checked before any work).
    KeyboardInterrupt
        Ctrl-C: a batch checks for signals about every millisecond of work and
        stops within a few milliseconds (a single point costs at most
        :data:`MAX_SECONDS_PER_POINT` by the cost estimate).

    Notes
    -----
    Zero-size batches work like numpy: ``z`` of shape ``(0, g)`` gives a result
    of shape ``(0, 4^g)``. Inputs of any numeric dtype, order and strides are
    converted to complex128 and never modified.

    Examples
    --------
    >>> import numpy as np, manakov
    >>> tau = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
    >>> th = manakov.theta_all([0.2 + 0.1j, 0.7 - 0.3j], tau)
    >>> th.shape
    (16,)
    """
    z2, tau_a, lead, g = _prepare(z, tau)
    vals, _, _, log = _jet(z2, tau_a, lead, g, tol, 0, not log_scale, parallel)
    if log_scale:
        return vals, _out(log, lead)
    return vals


@overload
def theta(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    char: CharLike = ...,
    *,
    derivs: Sequence[int] = ...,
    tol: float = ...,
    log_scale: Literal[False] = ...,
    parallel: bool = ...,
) -> ComplexOut: ...
@overload
def theta(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    char: CharLike = ...,
    *,
    derivs: Sequence[int] = ...,
    tol: float = ...,
    log_scale: Literal[True],
    parallel: bool = ...,
) -> tuple[ComplexOut, LogScale]: ...
def theta(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    char: CharLike = None,
    *,
    derivs: Sequence[int] = (),
    tol: float = DEFAULT_TOL,
    log_scale: bool = False,
    parallel: bool = True,
) -> ComplexOut | tuple[ComplexOut, LogScale]:
    r"""One theta function ``theta[a;b](z, tau)`` or one of its z-derivatives.

    .. math:: \theta[a;b](z,\tau)=\sum_{n\in\mathbb Z^g}
              e^{i\pi (n+a/2)^T\tau(n+a/2)+2\pi i(n+a/2)^T(z+b/2)}

    (the paper's (36) with characteristics, (35); ``char=None`` is (36) itself).
    Derivatives are the series differentiated term by term:
    ``d/dz_k -> 2 pi i (n + a/2)_k``.

    Parameters
    ----------
    z : array_like, shape (..., g)
        Points; any leading shape.
    tau : array_like, shape (g, g)
        Period matrix (symmetric, ``Im tau`` positive definite).
    char : None, int, str or (a, b), optional
        The characteristic: None for ``[0; 0]`` (the paper's (36)); an index in
        FLINT's order; a label of the paper's table (35) (``"theta12"``, ...,
        top row = a); or a pair ``(a, b)`` of 0/1 sequences of length g.
    derivs : sequence of int, optional
        Coordinates to differentiate in: ``()`` the value, ``(k,)`` for
        ``d/dz_k``, ``(k, l)`` for ``d^2/dz_k dz_l`` (at most 2).
    tol : float, optional
        Absolute truncation error on normalised values (see :func:`theta_all`).
    log_scale : bool, optional
        If True return ``(Omega, L)`` with result ``= Omega * exp(L)``.
    parallel : bool, optional
        Split batches of at least 4096 points over threads (rayon's pool, size
        from ``RAYON_NUM_THREADS``, default all cores). ``False`` keeps the
        computation on one core. The values do not depend on it.

    Returns
    -------
    complex or ndarray of shape (...)
        The value (or derivative) at each point; a Python complex for a single
        point. With ``log_scale`` a pair ``(Omega, L)``, result ``= Omega * exp(L)``,
        ``L = pi Im(z)^T Im(tau)^{-1} Im(z)`` (float or ndarray of shape (...)).

    Raises
    ------
    ValueError
        Bad ``z``, ``tau`` or ``tol`` (see :func:`theta_all`), unknown ``char``,
        ``derivs`` with more than 2 entries or an entry outside 0..g-1.
    TypeError
        ``derivs`` is not a sequence of integers.
    OverflowError
        A value exceeds the double range and ``log_scale`` is False.
    MemoryError
        The batch's outputs do not fit in memory (checked before any work).
    KeyboardInterrupt
        Ctrl-C: a batch checks for signals about every millisecond of work and
        stops within a few milliseconds (a single point costs at most
        :data:`MAX_SECONDS_PER_POINT` by the cost estimate).

    Examples
    --------
    >>> import numpy as np, manakov
    >>> tau = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
    >>> z = np.array([0.2 + 0.1j, 0.7 - 0.3j])
    >>> print(np.round(manakov.theta(z, tau), 8))
    (0.87999796-0.04222314j)
    >>> print(np.round(manakov.theta(z, tau, ((1, 0), (1, 0))), 8))
    (-0.430963-0.11159507j)
    >>> print(abs(manakov.theta(np.zeros(2), tau, ((1, 0), (1, 0)))) < 1e-15)  # odd: zero at 0
    True
    """
    z2, tau_a, lead, g = _prepare(z, tau)
    idx = _resolve_char(char, g)
    try:
        d = tuple(operator.index(k) for k in derivs)
    except TypeError as exc:
        raise TypeError(f"derivs must be a sequence of integers, got {derivs!r}") from exc
    if len(d) > 2 or any(not 0 <= k < g for k in d):
        raise ValueError(f"derivs must list at most 2 coordinates in 0..{g - 1}, got {derivs!r}")
    vals, grad, hess, log = _jet(z2, tau_a, lead, g, tol, len(d), not log_scale, parallel)
    if len(d) == 0:
        out = vals[..., idx]
    elif len(d) == 1:
        out = grad[..., idx, d[0]]
    else:
        out = hess[..., idx, d[0], d[1]]
    if log_scale:
        return _out(np.asarray(out), lead), _out(log, lead)
    return _out(np.asarray(out), lead)


@overload
def theta_jet(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    char: CharLike = ...,
    *,
    all_chars: bool = ...,
    tol: float = ...,
    log_scale: Literal[False] = ...,
    parallel: bool = ...,
) -> tuple[ComplexOut, ComplexArray, ComplexArray]: ...
@overload
def theta_jet(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    char: CharLike = ...,
    *,
    all_chars: bool = ...,
    tol: float = ...,
    log_scale: Literal[True],
    parallel: bool = ...,
) -> tuple[ComplexOut, ComplexArray, ComplexArray, LogScale]: ...
def theta_jet(
    z: npt.ArrayLike,
    tau: npt.ArrayLike,
    char: CharLike = None,
    *,
    all_chars: bool = False,
    tol: float = DEFAULT_TOL,
    log_scale: bool = False,
    parallel: bool = True,
) -> (
    tuple[ComplexOut, ComplexArray, ComplexArray]
    | tuple[ComplexOut, ComplexArray, ComplexArray, LogScale]
):
    r"""Value, gradient and Hessian in z of theta functions, from one lattice sum.

    With the terms of the paper's (36) with characteristics (35),

    .. math:: E(m) = e^{i\pi m^T\tau m + 2\pi i m^T(z+b/2)}, \quad m = n + a/2,
              \quad \theta[a;b](z,\tau) = \sum_{n\in\mathbb Z^g} E(m),

    ``gradient[..., k] = d theta / d z_k = sum 2 pi i m_k E(m)`` and
    ``hessian[..., k, l] = sum (2 pi i)^2 m_k m_l E(m)``.

    Parameters
    ----------
    z, tau, char, tol, parallel
        As in :func:`theta` and :func:`theta_all`.
    all_chars : bool, optional
        If True ignore ``char`` and return all ``4^g`` characteristics (FLINT
        order) along an axis after the leading ones.
    log_scale : bool, optional
        If True also return ``L``; the three arrays are then normalised by ``exp(-L)``.

    Returns
    -------
    value : complex or ndarray, shape (...) or (..., 4^g)
    gradient : ndarray, shape (..., g) or (..., 4^g, g)
    hessian : ndarray, shape (..., g, g) or (..., 4^g, g, g)
    log_scale : float or ndarray, shape (...)
        Only if ``log_scale`` is True.

    Raises
    ------
    ValueError
        Bad ``z``, ``tau``, ``tol`` (see :func:`theta_all`) or unknown ``char``
        (checked only when ``all_chars`` is False).
    OverflowError
        A value exceeds the double range and ``log_scale`` is False.
    MemoryError
        The batch's outputs do not fit in memory (checked before any work).
    KeyboardInterrupt
        Ctrl-C: a batch checks for signals about every millisecond of work and
        stops within a few milliseconds (a single point costs at most
        :data:`MAX_SECONDS_PER_POINT` by the cost estimate).

    Examples
    --------
    >>> import numpy as np, manakov
    >>> tau = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
    >>> value, grad, hess = manakov.theta_jet([0.2 + 0.1j, 0.7 - 0.3j], tau)
    >>> grad.shape, hess.shape
    ((2,), (2, 2))
    >>> print(np.round(grad, 8))
    [-0.04503725+0.06662608j  0.26901073-1.04891769j]
    """
    z2, tau_a, lead, g = _prepare(z, tau)
    vals, grad, hess, log = _jet(z2, tau_a, lead, g, tol, 2, not log_scale, parallel)
    if not all_chars:
        idx = _resolve_char(char, g)
        vals, grad, hess = vals[..., idx], grad[..., idx, :], hess[..., idx, :, :]
    if log_scale:
        return _out(np.asarray(vals), lead), grad, hess, _out(log, lead)
    return _out(np.asarray(vals), lead), grad, hess
