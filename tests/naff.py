"""A test-side NAFF (Laskar's numerical analysis of fundamental frequencies).

Independent of the package: numpy only. For samples ``x_k = x(k dt)``:

1. window ``w_k = sin²(π k/(N−1))^p`` (Hann for ``p = 1``; ``p = 2`` is the
   Hann² window of Laskar's frequency-map papers, whose side lobes fall as
   ``1/(Δν T)⁵``, so that weak lines next to strong ones keep their place);
2. the peak of ``|FFT(w x)|`` (≥ 4× zero padding, to a length the FFT
   factors fast), parabolic interpolation;
3. refinement: Newton's method on ``φ'(ν) = 0``, ``φ(ν) = |S(ν)|²``,
   ``S(ν) = Σ_k w_k x_k e^{−2πiν t_k}`` (first and second derivatives are
   sums of the same kind), which finds the maximum to roundoff;
4. the line's complex amplitude by windowed projection, subtracted, and
   back to 2 until the largest remaining peak is below ``rel_threshold`` of
   the first;
5. a polishing pass: each frequency is refined again on the residual plus its
   own line, and the amplitudes are refitted jointly (weighted least squares).

For a real signal the search runs over ``ν ≥ 0`` and each line is the pair
``c e^{2πiνt} + c̄ e^{−2πiνt}``.
"""

from __future__ import annotations

import numpy as np
from scipy.fft import next_fast_len


def window(n: int, p: int = 1) -> np.ndarray:
    k = np.arange(n)
    return np.sin(np.pi * k / (n - 1)) ** (2 * p)


def _phasor(nu: float, n: int, dt: float, block: int = 1024) -> np.ndarray:
    """``e^{2πiν k dt}``, ``k = 0 … n−1``, as the outer product of two short
    tables (``k = q B + r``): ``n`` complex products instead of ``n`` complex
    exponentials, with the rounding of the direct form (each factor's phase
    is one product ``2πν × (multiple of dt)``; the product adds an ulp)."""
    r = np.exp(2j * np.pi * nu * (np.arange(block) * dt))
    q = np.exp(2j * np.pi * nu * (np.arange(-(-n // block)) * (block * dt)))
    return np.multiply.outer(q, r).ravel()[:n]


def _sums(m: np.ndarray, nu: float, dt: float):
    """``S``, ``S'``, ``S''`` at ``ν`` from ``m = [y, y t, y t²]``.

    For a real ``y`` the three sums are one real matrix product with the
    phasors' (cos, sin) pairs (BLAS, one pass over them)."""
    e = _phasor(nu, m.shape[1], dt)
    if np.isrealobj(m):
        cs = m @ e.view(float).reshape(-1, 2)
        r = cs[:, 0] - 1j * cs[:, 1]
    else:
        r = m @ np.conj(e)
    return r[0], r[1] * (-2j * np.pi), r[2] * (-4 * np.pi**2)


def refine(y: np.ndarray, t: np.ndarray, nu0: float, T: float, iters: int = 12) -> float:
    """Newton's method for the maximum of ``|Σ y e^{−2πiνt}|²`` near ``nu0``
    (``y`` already windowed, ``t = k dt``); steps are limited to a quarter of
    the main lobe."""
    nu = nu0
    cap = 0.25 / T
    dt = t[1] - t[0]
    m = np.stack([y, y * t, y * t * t])
    for _ in range(iters):
        s0, s1, s2 = _sums(m, nu, dt)
        d1 = 2 * np.real(np.conj(s0) * s1)
        d2 = 2 * (abs(s1) ** 2 + np.real(np.conj(s0) * s2))
        if d2 >= 0:  # not concave here: step uphill by the cap
            step = cap * np.sign(d1)
        else:
            step = float(np.clip(-d1 / d2, -cap, cap))
        nu += step
        # Newton converges quadratically: once a step is below 1e-9/T the
        # next would be ~1e-18/T, below the roundoff of ν itself.
        if abs(step) < 1e-9 / T:
            break
    return float(nu)


def _fit_line(nu: float, c: complex, n: int, dt: float, real: bool) -> np.ndarray:
    """Samples of the line ``c e^{2πiνt}`` (with its conjugate for a real signal)."""
    e = _phasor(nu, n, dt)
    if not real:
        return c * e
    return (c.real * e.real - c.imag * e.imag) * (1.0 if nu == 0.0 else 2.0)


def _fit(resid: np.ndarray, w: np.ndarray, nu: float, dt: float, real: bool):
    """The line at ``ν``: its complex amplitude by windowed projection
    ``Σ w y e^{−2πiνt} / Σ w`` and its samples (one table of phasors for both)."""
    e = _phasor(nu, resid.size, dt)
    if not real:
        c = complex(((w * resid) @ np.conj(e)) / w.sum())
        return c, c * e
    cos, sin = (w * resid) @ e.view(float).reshape(-1, 2)
    c = complex(cos, -sin) / w.sum()
    # Re(c e) without a complex temporary.
    return c, (c.real * e.real - c.imag * e.imag) * (1.0 if nu == 0.0 else 2.0)


def naff(
    x: np.ndarray,
    dt: float,
    *,
    max_lines: int = 40,
    rel_threshold: float = 1e-6,
    p: int = 2,
    polish: bool = True,
    per_sweep: int = 8,
) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies and amplitudes of the lines of ``x`` (largest first).

    Parameters
    ----------
    x : array, real or complex, shape (N,)
        Samples at ``t = k dt``.
    dt : float
    max_lines : int
    rel_threshold : float
        Stop when the largest remaining peak is below this fraction of the
        largest line.
    p : int
        Power of the Hann window.
    polish : bool
        Refine every line once more at the end (step 5).
    per_sweep : int
        Lines taken from one spectrum before it is recomputed.

    Returns
    -------
    nu : ndarray
        Frequencies (cycles per unit time; ``≥ 0`` for a real signal).
    amp : ndarray
        Amplitudes ``|c|`` of the lines ``c e^{2πiνt}``.
    """
    x = np.asarray(x)
    real = not np.iscomplexobj(x)
    n = x.size
    t = np.arange(n) * dt
    T = t[-1]
    w = window(n, p)
    # At least 4× zero padding, to a length the FFT factors fast.
    pad = next_fast_len(4 * n, real=real)
    freqs = np.fft.rfftfreq(pad, dt) if real else np.fft.fftfreq(pad, dt)
    resid = x.astype(complex) if not real else x.astype(float)
    nus: list[float] = []
    cs: list[complex] = []
    first = None
    done = False
    while not done and len(nus) < max_lines:
        F = np.abs(np.fft.rfft(resid * w, pad) if real else np.fft.fft(resid * w, pad))
        # The largest local maxima of this spectrum, a few main lobes apart
        # (the window's main lobe is 2(p+1)/T wide), are refined in one sweep.
        is_max = (F > np.roll(F, 1)) & (F >= np.roll(F, -1))
        cand = np.flatnonzero(is_max)
        cand = cand[np.argsort(-F[cand])]
        if first is None:
            first = F[cand[0]] / w.sum()
        picked: list[int] = []
        for k in cand:
            if F[k] / w.sum() < rel_threshold * first or len(picked) == per_sweep:
                break
            if all(abs(freqs[k] - freqs[j]) > 4 * (p + 1) / T for j in picked):
                picked.append(int(k))
        if not picked:
            break
        for k in picked:
            # Parabolic interpolation of log|F| on three bins (a real
            # signal's spectrum is even: bin −1 is bin 1).
            a, b, c = (np.log(max(F[abs(k + j) % F.size], 1e-300)) for j in (-1, 0, 1))
            den = a - 2 * b + c
            off = 0.5 * (a - c) / den if den != 0 else 0.0
            nu0 = freqs[k] + off / (pad * dt)
            if real and (k == 0 or abs(nu0) < 0.5 / T):
                nu = 0.0
            else:
                nu = refine(resid * w, t, nu0, T)
                if real:
                    nu = abs(nu)
            if any(abs(nu - m) < 0.5 / T for m in nus):
                done = True  # the same line again: leakage floor reached
                break
            amp, line = _fit(resid, w, nu, dt, real)
            nus.append(nu)
            cs.append(amp)
            resid = resid - line
    if polish:
        # Each line again on the residual plus itself: the leakage of lines
        # found after it no longer pulls it.
        for i, nu in enumerate(nus):
            own = resid + _fit_line(nu, cs[i], n, dt, real)
            if nu != 0.0:
                nu = abs(refine(own * w, t, nu, T)) if real else refine(own * w, t, nu, T)
            cs[i], line = _fit(own, w, nu, dt, real)
            nus[i] = nu
            resid = own - line
    amps = np.abs(np.array(cs))
    order = np.argsort(-amps)
    return np.array(nus)[order], amps[order]
