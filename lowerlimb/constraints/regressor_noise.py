"""The white noise that the gyro carries into the regressors ω and α of the joint constraints.

The spherical residual (Hu et al. 2021, eq. 7) multiplies the joint centre by
``K = [ω]×[ω]× + [α]×``, built from the *measured* (filtered) gyro ω and its
Savitzky–Golay derivative α. Gyro white noise there is noise in the regressors,
which biases a least-squares fit (errors in variables;
:mod:`lowerlimb.calibration.noise_correction` removes the bias). Its size
follows from two measurable things:

1. the gyro's white-noise standard deviation per axis, from the still start:
   ``σ = std(Δω) / √2`` over first differences, which removes slow sway and
   drift (the variance of the difference of two independent white samples is
   2σ²);
2. the linear filter chain of the calibration, the zero-phase Butterworth
   low-pass (:func:`~lowerlimb.constraints.prefilter.lowpass`) followed, for
   α, by the Savitzky–Golay derivative
   (:func:`~lowerlimb.constraints.angular_acceleration.angular_acceleration`).
   White noise through a linear filter with impulse response ``h`` has the
   standard deviation ``σ ‖h‖₂`` (e.g. Papoulis & Pillai 2002, *Probability,
   Random Variables and Stochastic Processes*, §9-2); ``h`` is obtained by
   filtering a unit impulse.

At 100 Hz and σ = 0.015 rad/s (the simulator's default), α's noise is about
0.5 rad/s² per axis at an 18 Hz cut-off and 0.75 rad/s² unfiltered.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.constraints.angular_acceleration import angular_acceleration
from lowerlimb.constraints.prefilter import lowpass

__all__ = ["white_noise_std", "filter_noise_gains"]

#: Length of the unit impulse whose response gives the gains, s (the filters' responses decay within it).
_IMPULSE_S = 20.0


def white_noise_std(gyr_still: ArrayLike) -> float | None:
    """White-noise standard deviation per axis of a gyro at rest, rad/s.

    Args:
        gyr_still: (M, 3) angular velocity during a still period, rad/s.

    Returns:
        ``mean over axes of std(Δω) / √2``, or ``None`` with fewer than 10 samples.
    """
    g = np.asarray(gyr_still, dtype=float)
    if g.ndim != 2 or g.shape[0] < 10:
        return None
    return float(np.mean(np.std(np.diff(g, axis=0), axis=0)) / np.sqrt(2.0))


@lru_cache(maxsize=256)
def filter_noise_gains(
    rate_hz: float, cutoff_hz: float | None, window_s: float, polyorder: int
) -> tuple[float, float]:
    """Standard deviation of the filtered gyro and of α per unit white gyro noise.

    Args:
        rate_hz: sampling rate, Hz.
        cutoff_hz: low-pass cut-off, Hz (``None``: unfiltered).
        window_s: Savitzky–Golay window of α, s.
        polyorder: Savitzky–Golay polynomial order.

    Returns:
        ``(‖h_ω‖₂, ‖h_α‖₂)``: the gyro's gain (dimensionless, ≤ 1) and α's gain, 1/s.
    """
    n = int(round(_IMPULSE_S * rate_hz)) | 1
    impulse = np.zeros((n, 3))
    impulse[n // 2] = 1.0
    h = lowpass(impulse, rate_hz, cutoff_hz)
    h_alpha = angular_acceleration(h, rate_hz, window_s=window_s, polyorder=polyorder)
    return float(np.linalg.norm(h[:, 0])), float(np.linalg.norm(h_alpha[:, 0]))
