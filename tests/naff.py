"""A test-side NAFF (Laskar's numerical analysis of fundamental frequencies).

Independent of the package: numpy only. For samples ``x_k = x(k dt)``:

1. window ``w_k = sin²(π k/(N−1))^p`` (Hann for ``p = 1``; ``p = 2`` is the
   Hann² window of Laskar's frequency-map papers, whose side lobes fall as
   ``1/(Δν T)⁵``, so that weak lines next to strong ones keep their place);
2. the peak of ``|FFT(w x)|`` (4× zero padding), parabolic interpolation;
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


def window(n: int, p: int = 1) -> np.ndarray:
    k = np.arange(n)
    return np.sin(np.pi * k / (n - 1)) ** (2 * p)


def _sums(y: np.ndarray, t: np.ndarray, nu: float):
    """``S``, ``S'``, ``S''`` at ``ν`` (dot products: BLAS, one pass each)."""
    ye = y * np.exp(-2j * np.pi * nu * t)
    s0 = ye.sum()
    s1 = (ye.real @ t + 1j * (ye.imag @ t)) * (-2j * np.pi)
    t2 = t * t
    s2 = (ye.real @ t2 + 1j * (ye.imag @ t2)) * (-4 * np.pi**2)
    return s0, s1, s2


def refine(y: np.ndarray, t: np.ndarray, nu0: float, T: float, iters: int = 12) -> float:
    """Newton's method for the maximum of ``|Σ y e^{−2πiνt}|²`` near ``nu0``
    (``y`` already windowed); steps are limited to a quarter of the main lobe."""
    nu = nu0
    cap = 0.25 / T
    for _ in range(iters):
        s0, s1, s2 = _sums(y, t, nu)
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


def _line(t: np.ndarray, nu: float, c: complex, real: bool) -> np.ndarray:
    e = np.exp(2j * np.pi * nu * t)
    if not real:
        return c * e
    return (c * e).real * (1.0 if nu == 0.0 else 2.0)


def _amplitude(y: np.ndarray, t: np.ndarray, w: np.ndarray, nu: float) -> complex:
    """Windowed projection ``Σ w y e^{−2πiνt} / Σ w`` (the line's complex amplitude)."""
    return complex((w * y * np.exp(-2j * np.pi * nu * t)).sum() / w.sum())


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
    pad = 4 * n
    freqs = np.fft.fftfreq(pad, dt)
    resid = x.astype(complex) if not real else x.astype(float)
    nus: list[float] = []
    cs: list[complex] = []
    first = None
    done = False
    while not done and len(nus) < max_lines:
        F = np.abs(np.fft.fft(resid * w, pad))
        if real:
            F = np.where(freqs >= 0, F, 0.0)
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
            # Parabolic interpolation of log|F| on three bins.
            a, b, c = (np.log(max(F[(k + j) % pad], 1e-300)) for j in (-1, 0, 1))
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
            amp = _amplitude(resid, t, w, nu)
            nus.append(nu)
            cs.append(amp)
            resid = resid - _line(t, nu, amp, real)
    if polish:
        # Each line again on the residual plus itself: the leakage of lines
        # found after it no longer pulls it.
        for i, nu in enumerate(nus):
            own = resid + _line(t, nu, cs[i], real)
            if nu != 0.0:
                nu = abs(refine(own * w, t, nu, T)) if real else refine(own * w, t, nu, T)
            cs[i] = _amplitude(own, t, w, nu)
            nus[i] = nu
            resid = own - _line(t, nu, cs[i], real)
    amps = np.abs(np.array(cs))
    order = np.argsort(-amps)
    return np.array(nus)[order], amps[order]
