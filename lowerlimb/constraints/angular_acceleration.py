"""Angular acceleration from gyroscope samples: a Savitzky–Golay derivative.

Hu et al. 2021 (eq. 2) need the angular acceleration α of every sensor but do
not say how to get it ("defined by [19]"). Raw finite differences amplify the
gyro's white noise by about ``rate_hz`` (≈ 1 rad/s² per axis at 100 Hz for
0.015 rad/s noise), and noise in α is noise in the *regressors* of the
spherical problem, which biases the joint centres towards the sensors
(errors in variables). Two steps keep it small:

1. the gyro (and accelerometer) are first low-passed at a cut-off adapted to
   the motion's bandwidth (:mod:`lowerlimb.constraints.prefilter`);
2. α is the derivative of a local Savitzky–Golay polynomial fit.

Window choice (documented default): ``window_s = 0.07`` s and
``polyorder = 4`` (7 samples at 100 Hz; at least ``polyorder + 1`` = 5
samples at low rates, where the fit becomes the 5-point stencil). A degree-4
fit is exact for quartic motion, so on the already band-limited signal its
bias is negligible up to ~15 Hz at 100 Hz, while its own noise gain matters
little after the low-pass. On the simulator (noise-free walking) a degree-2
fit of the same length (the least-squares slope) biased the ankle centre
several times more than the degree-4 fit.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.signal import savgol_filter

from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError, ShapeError

__all__ = ["DEFAULT_WINDOW_S", "DEFAULT_POLYORDER", "angular_acceleration", "smooth", "window_length"]

#: Default Savitzky–Golay window, seconds.
DEFAULT_WINDOW_S = 0.07
#: Default Savitzky–Golay polynomial order.
DEFAULT_POLYORDER = 4


def window_length(rate_hz: float, window_s: float, polyorder: int) -> int:
    """Odd number of samples closest to ``window_s`` at ``rate_hz``, at least ``polyorder + 1``.

    Args:
        rate_hz: sampling rate, Hz (> 0).
        window_s: requested window, seconds (> 0).
        polyorder: polynomial order of the Savitzky–Golay fit (>= 0).

    Returns:
        The window length in samples: odd, ``>= polyorder + 1`` (and >= 3).

    Raises:
        InputError: if ``rate_hz`` or ``window_s`` is not positive, or ``polyorder`` < 0.
    """
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"rate_hz must be a positive number of samples per second, got {rate_hz}")
    if not (np.isfinite(window_s) and window_s > 0):
        raise InputError(f"window_s must be a positive duration in seconds, got {window_s}")
    if polyorder < 0:
        raise InputError(f"polyorder must be >= 0, got {polyorder}")
    n = int(round(window_s * rate_hz))
    n = max(n, polyorder + 1, 3)
    if n % 2 == 0:
        n += 1
    return n


def _check_signal(x: ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ShapeError(f"{name} must have shape (N, 3), got {arr.shape}")
    return arr


def angular_acceleration(
    gyr: ArrayLike,
    rate_hz: float,
    *,
    window_s: float = DEFAULT_WINDOW_S,
    polyorder: int = DEFAULT_POLYORDER,
) -> FloatArray:
    """Angular acceleration α = dω/dt by a Savitzky–Golay derivative (input to Hu 2021 eq. 2).

    Args:
        gyr: (N, 3) angular velocity of the sensor in its own frame, rad/s,
            evenly sampled.
        rate_hz: sampling rate, Hz.
        window_s: length of the local polynomial fit, seconds (rounded to an odd
            number of samples, at least ``polyorder + 1``).
        polyorder: degree of the local polynomial.

    Returns:
        (N, 3) angular acceleration in the same sensor frame, rad/s². The ends
        use the polynomial fitted to the first/last window (``mode="interp"``).

    Raises:
        ShapeError: if ``gyr`` is not (N, 3).
        InputError: for a non-positive rate or window, or fewer samples than the window.
    """
    w = _check_signal(gyr, "gyr")
    n = window_length(rate_hz, window_s, polyorder)
    if w.shape[0] < n:
        raise InputError(
            f"need at least {n} samples to differentiate the gyro with a {window_s} s window, "
            f"got {w.shape[0]}; record a longer trial"
        )
    return np.asarray(
        savgol_filter(w, n, polyorder, deriv=1, delta=1.0 / rate_hz, axis=0, mode="interp"),
        dtype=float,
    )


def smooth(
    x: ArrayLike,
    rate_hz: float,
    *,
    window_s: float = DEFAULT_WINDOW_S,
    polyorder: int = DEFAULT_POLYORDER,
) -> FloatArray:
    """Savitzky–Golay smoothing of a (N, 3) signal with the same window as :func:`angular_acceleration`.

    Args:
        x: (N, 3) signal (any unit), evenly sampled.
        rate_hz: sampling rate, Hz.
        window_s: length of the local polynomial fit, seconds.
        polyorder: degree of the local polynomial.

    Returns:
        (N, 3) smoothed signal, same unit and frame.

    Raises:
        ShapeError: if ``x`` is not (N, 3).
        InputError: for a non-positive rate or window, or fewer samples than the window.
    """
    arr = _check_signal(x, "signal")
    n = window_length(rate_hz, window_s, polyorder)
    if arr.shape[0] < n:
        raise InputError(f"need at least {n} samples to smooth with a {window_s} s window")
    return np.asarray(savgol_filter(arr, n, polyorder, axis=0, mode="interp"), dtype=float)
