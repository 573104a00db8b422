"""The still period at the start of a recording, and the gyroscope bias measured over it.

One detector for the whole library: :func:`detect_still_period` runs once per
trial (:meth:`lowerlimb.io.trial.ImuTrial.still_period`) and its
:class:`StillPeriod` is handed on to the calibration's gyro-bias removal, the
reused calibration's bias and the standing reference posture, each with its
own shortest accepted duration. (The orientation filters still find their own
per-sensor rest for their initial state: docs/limits.md.)

Every trial should start with ≥ 1 s of standing still (docs/formats.md). A constant
gyro bias of ~0.01 rad/s enters the hinge residual directly and the
spherical residual through ω×(ω×c), so it is estimated as the mean gyro
reading over the initial still period and subtracted before the residuals
are formed.

Still detection (choices the paper leaves open): a sample is still when, for
every sensor given, the 0.1 s moving average of ‖ω‖ is below 0.1 rad/s and
the 0.1 s moving standard deviation of ‖a‖ is below 0.2 m/s². The still
period is the run of still samples from the first sample, shortened by 0.1 s
(the onset of motion is gradual), and used only when at least
``min_duration_s`` long.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.ndimage import uniform_filter1d

from lowerlimb.conventions import FloatArray

__all__ = [
    "STILL_ACC_STD_MPS2",
    "STILL_GYRO_RPS",
    "StillPeriod",
    "detect_still_period",
    "gyro_bias",
    "initial_still_samples",
]

#: Moving-average gyro norm below which a sample counts as still, rad/s.
STILL_GYRO_RPS = 0.1
#: Moving standard deviation of the accelerometer norm below which a sample is still, m/s².
STILL_ACC_STD_MPS2 = 0.2
_WINDOW_S = 0.1
_MARGIN_S = 0.1


def _moving_mean(x: FloatArray, n: int) -> FloatArray:
    return np.asarray(uniform_filter1d(x, n, mode="nearest"), dtype=float)


@dataclass(frozen=True)
class StillPeriod:
    """The still run at the start of a recording, detected once.

    Attributes:
        n_samples: length of the run of still samples from the first one,
            shortened by 0.1 s (may be ≤ 0 when the start moves).
        rate_hz: sampling rate, Hz.
    """

    n_samples: int
    rate_hz: float

    def samples(self, min_duration_s: float = 0.5) -> int:
        """``n`` such that samples ``[0, n)`` are still, or 0 when shorter than ``min_duration_s``."""
        n = self.n_samples
        return n if n >= max(2, int(round(min_duration_s * self.rate_hz))) else 0


def detect_still_period(gyrs: Sequence[ArrayLike], accs: Sequence[ArrayLike], rate_hz: float) -> StillPeriod:
    """The run of samples at the start during which every sensor is still.

    Args:
        gyrs: gyroscope signals, each (N, 3), rad/s.
        accs: accelerometer signals, each (N, 3), m/s² (may be empty).
        rate_hz: sampling rate, Hz.
    """
    gl = [np.asarray(g, dtype=float) for g in gyrs]
    n_total = gl[0].shape[0]
    win = max(3, int(round(_WINDOW_S * rate_hz)))
    still = np.ones(n_total, dtype=bool)
    for g in gl:
        still &= _moving_mean(np.linalg.norm(g, axis=1), win) < STILL_GYRO_RPS
    for a in accs:
        an = np.linalg.norm(np.asarray(a, dtype=float), axis=1)
        mean = _moving_mean(an, win)
        std = np.sqrt(np.maximum(_moving_mean((an - mean) ** 2, win), 0.0))
        still &= std < STILL_ACC_STD_MPS2
    moving = np.flatnonzero(~still)
    n_still = int(moving[0]) if moving.size else n_total
    return StillPeriod(n_still - int(round(_MARGIN_S * rate_hz)), float(rate_hz))


def initial_still_samples(
    gyrs: Sequence[ArrayLike],
    accs: Sequence[ArrayLike],
    rate_hz: float,
    *,
    min_duration_s: float = 0.5,
) -> int:
    """Number of samples at the start during which every sensor is still (0 if too short).

    Shorthand for ``detect_still_period(gyrs, accs, rate_hz).samples(min_duration_s)``.

    Args:
        gyrs: gyroscope signals, each (N, 3), rad/s.
        accs: accelerometer signals, each (N, 3), m/s² (may be empty).
        rate_hz: sampling rate, Hz.
        min_duration_s: shortest accepted still period, s.

    Returns:
        ``n`` such that samples ``[0, n)`` are still, or 0 when the still period
        is shorter than ``min_duration_s``.
    """
    return detect_still_period(gyrs, accs, rate_hz).samples(min_duration_s)


def gyro_bias(gyr: ArrayLike, n_still: int) -> FloatArray:
    """Mean gyro reading over the first ``n_still`` samples, (3,) rad/s (zeros if ``n_still`` is 0)."""
    g = np.asarray(gyr, dtype=float)
    if n_still <= 0:
        return np.zeros(3)
    return np.asarray(g[:n_still].mean(axis=0), dtype=float)
