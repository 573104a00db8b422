"""Small signal helpers shared by the gait modules (input checks, zero-phase low-pass, runs)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.signal import butter, sosfiltfilt

from lowerlimb.conventions import FloatArray
from lowerlimb.gait.errors import GaitSignalError


def as_signal(x: ArrayLike, name: str, n: int | None = None) -> FloatArray:
    """``x`` as a finite (N, 3) float array (N = ``n`` when given), else :class:`GaitSignalError`."""
    a = np.asarray(x, dtype=float)
    expected = f"({n if n is not None else 'N'}, 3)"
    if a.ndim != 2 or a.shape[1] != 3 or (n is not None and a.shape[0] != n) or a.shape[0] < 2:
        raise GaitSignalError(name, a.shape, expected)
    if not np.all(np.isfinite(a)):
        raise GaitSignalError(name, a.shape, expected + " without NaN or infinite values")
    return a


def lowpass(x: FloatArray, cutoff_hz: float, rate_hz: float) -> FloatArray:
    """Zero-phase 2nd-order Butterworth low-pass along axis 0 (unchanged above Nyquist)."""
    if cutoff_hz >= 0.5 * rate_hz or x.shape[0] < 16:
        return x.copy()
    sos = butter(2, cutoff_hz, fs=rate_hz, output="sos")
    return np.asarray(sosfiltfilt(sos, x, axis=0), dtype=float)


def parabolic_vertex(x: FloatArray, k: int) -> float:
    """Sub-sample position of the extremum of ``x`` at ``k`` (parabola through k-1, k, k+1)."""
    if k <= 0 or k >= x.shape[0] - 1:
        return float(k)
    a, b, c = x[k - 1], x[k], x[k + 1]
    den = a - 2.0 * b + c
    return float(k) if abs(den) < 1e-12 else float(k + 0.5 * (a - c) / den)


def runs(mask: FloatArray | np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges ``[start, stop)`` of the True runs of a boolean array."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(int))
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(), strict=True))
