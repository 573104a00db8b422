"""The still period at the start of a recording (and at its end), and the gyroscope bias measured over it.

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
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import maximum_filter1d, uniform_filter1d

from lowerlimb.conventions import FloatArray

BoolArray = NDArray[np.bool_]

__all__ = [
    "STILL_ACC_STD_MPS2",
    "STILL_GYRO_RPS",
    "SUSTAINED_MOTION_S",
    "StillPeriod",
    "detect_still_period",
    "gyro_bias",
    "initial_still_samples",
]

#: Moving-average gyro norm below which a sample counts as still, rad/s.
STILL_GYRO_RPS = 0.1
#: Moving standard deviation of the accelerometer norm below which a sample is still, m/s².
STILL_ACC_STD_MPS2 = 0.2
#: Motion lasting longer than this ends the standing start (a step, the walk), s; briefer
#: motion (a weight shift, a glance) only drops its own samples from the bias window.
SUSTAINED_MOTION_S = 0.5
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
        quiet: (M,) bool, the still samples of the whole standing start (the bias window;
            ``M`` is where sustained motion begins), or ``None``: the first ``n_samples``.
        end_samples: length of the run of still samples that ends the recording, shortened
            by 0.1 s (0 when it ends moving): the gyro bias window of a recording that does
            not start still (:func:`gyro_bias`).
    """

    n_samples: int
    rate_hz: float
    quiet: BoolArray | None = field(default=None, compare=False, repr=False)
    end_samples: int = 0

    def samples(self, min_duration_s: float = 0.5) -> int:
        """``n`` such that samples ``[0, n)`` are still, or 0 when shorter than ``min_duration_s``."""
        return self._at_least(self.n_samples, min_duration_s)

    def end(self, min_duration_s: float = 0.5) -> int:
        """``n`` such that the last ``n`` samples are still, or 0 when shorter than ``min_duration_s``."""
        return self._at_least(self.end_samples, min_duration_s)

    def bias_end(self, start_min_s: float, end_min_s: float | None) -> int:
        """Samples of the still end that give the gyro bias (0: none).

        The still end's :meth:`end` (at least ``end_min_s``) when there is no still start
        of ``start_min_s``; else, or with ``end_min_s`` ``None``, 0.
        """
        if end_min_s is None or self.samples(start_min_s):
            return 0
        return self.end(end_min_s)

    def _at_least(self, n: int, min_duration_s: float) -> int:
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
    n_end = n_total - 1 - int(moving[-1]) if moving.size else n_total
    margin = int(round(_MARGIN_S * rate_hz))
    quiet = _quiet_stand(still, rate_hz, margin)
    return StillPeriod(n_still - margin, float(rate_hz), quiet, end_samples=max(n_end - margin, 0))


def _quiet_stand(still: BoolArray, rate_hz: float, margin: int) -> BoolArray:
    """(M,) still samples before the first sustained motion, each ``margin`` from a moving one."""
    moving = (~still).astype(np.int8)
    edges = np.flatnonzero(np.diff(np.concatenate(([0], moving, [0]))))
    starts, ends = edges[::2], edges[1::2]
    long_runs = np.flatnonzero(ends - starts > SUSTAINED_MOTION_S * rate_hz)
    end = int(starts[long_runs[0]]) if long_runs.size else len(still)
    near_motion = maximum_filter1d(moving, 2 * margin + 1, mode="nearest") > 0 if margin > 0 else ~still
    return np.asarray(~near_motion[:end], dtype=bool)


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


def gyro_bias(gyr: ArrayLike, n_still: int, quiet: BoolArray | None = None, n_end: int = 0) -> FloatArray:
    """Mean gyro reading over the still start, (3,) rad/s; without one, over the still end.

    A recording cut so that it starts in motion, which ends standing, has its bias
    measured over that end: on the real walk of ``gait/`` the sensors' biases were
    1-2 °/s, the same at the start and the end within 0.1 °/s on the feet, and cut
    mid-stride its stride lengths came out 2.9 % off median with no bias removed,
    1.8 % with the end's (``benchmarks/results/cut_start.md``).

    Args:
        gyr: (N, 3) gyro signal, rad/s.
        n_still: still samples at the start (0: no still start).
        quiet: the quiet stand (:attr:`StillPeriod.quiet`); when it holds at least
            ``n_still`` samples the mean is taken over them, else over the first ``n_still``.
        n_end: still samples at the end (:meth:`StillPeriod.end`), used when ``n_still``
            is 0; both 0: no bias (zeros).
    """
    g = np.asarray(gyr, dtype=float)
    if n_still <= 0:
        return np.asarray(g[-n_end:].mean(axis=0), dtype=float) if n_end > 0 else np.zeros(3)
    if quiet is not None and int(np.count_nonzero(quiet)) >= n_still:
        return np.asarray(g[: len(quiet)][quiet].mean(axis=0), dtype=float)
    return np.asarray(g[:n_still].mean(axis=0), dtype=float)
