"""Uneven sample times: a trial whose time steps vary is put on a constant clock when it is read.

Wireless IMUs drop packets (a step of two or three sample periods), and many loggers stamp each
sample with the time the host received it (steps that wander around the period). Every stage
after the reader assumes a constant rate: the calibration differentiates the gyros, the filters
integrate them, the gait events are sample features. A trial CSV whose steps vary by more than
:attr:`ClockParams.jitter_tolerance` of their median is therefore resampled, as it is read, onto
the constant clock ``t₀ + k·T`` by a cubic spline through the stamped samples (the stamps taken
as the times the samples were measured), and :class:`UnevenClockWarning` says so once. The spline
is clipped to each column's recorded range, so that a sensor cut at its range stays at it
(:mod:`lowerlimb.io.saturation` finds the cut afterwards). On the real walk of the shared data
resampled at times jittered by ±20 % of the period, a cubic spline restores the foot gyro with a
third of the error of linear interpolation (0.004 against 0.012 rad/s RMS; ``benchmarks/uneven_clock.py``).

``T`` is the recorder's period, fitted to the stamps against their sample numbers (a dropped
packet skips a number and does not lengthen it; jitter averages out; :func:`sample_index`). A step
longer than :attr:`ClockParams.max_gap_s` is refused (:class:`~lowerlimb.io.errors.PacketGapError`):
interpolating across it would invent motion. A time column that is not finite, not increasing or
not in seconds, and signals with NaN, are left as they are for the trial's own checks, which name
them.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from ..conventions import FloatArray
from ..errors import TimeAxisError
from .errors import PacketGapError
from .params import ImportParams

__all__ = [
    "CLOCK_PARAMS",
    "ClockParams",
    "ClockRepair",
    "UnevenClockWarning",
    "nominal_step",
    "refuse_batched_stamps",
    "sample_index",
    "to_uniform_clock",
]


class UnevenClockWarning(UserWarning):
    """The trial's time steps varied; it was resampled onto a constant clock."""


@dataclass(frozen=True)
class ClockParams:
    """Thresholds of :func:`to_uniform_clock`.

    Attributes:
        jitter_tolerance: largest deviation of one time step from the median step, as a fraction
            of the median, of a trial taken as recorded at a constant rate.
        batch_share: a time column that repeats, with different readings, in at least this
            share of its steps is taken as stamped in batches (:func:`refuse_batched_stamps`).
        max_gap_s: longest step bridged by interpolation, s (the importers' limit,
            :attr:`~lowerlimb.io.params.ImportParams.max_gap_s`).
    """

    jitter_tolerance: float = 0.25
    batch_share: float = 0.1
    max_gap_s: float = ImportParams.max_gap_s


#: The defaults.
CLOCK_PARAMS = ClockParams()


@dataclass(frozen=True)
class ClockRepair:
    """What :func:`to_uniform_clock` did to an uneven time column.

    Attributes:
        rate_hz: the constant rate the trial was resampled to, Hz (``1 / T``).
        n_source: rows as recorded.
        n_uniform: rows after resampling.
        min_step_s: shortest recorded step, s.
        max_step_s: longest recorded step, s.
        n_gaps: steps that skip a sample number (missing samples bridged, :func:`sample_index`).
        n_uneven: steps more than ``jitter_tolerance`` off the median step.
        jitter_tolerance: :attr:`ClockParams.jitter_tolerance` of the run.
    """

    rate_hz: float
    n_source: int
    n_uniform: int
    min_step_s: float
    max_step_s: float
    n_gaps: int
    n_uneven: int
    jitter_tolerance: float

    def message(self) -> str:
        """One line for the user: what varied and what was done."""
        gaps = (
            f", {self.n_gaps} gap{'s' * (self.n_gaps > 1)} of missing samples bridged" if self.n_gaps else ""
        )
        return (
            f"time steps vary from {self.min_step_s:.4g} s to {self.max_step_s:.4g} s "
            f"({self.n_uneven} of {self.n_source - 1} steps more than "
            f"{100 * self.jitter_tolerance:.0f} % off the median){gaps}: resampled to a constant "
            f"{self.rate_hz:.4g} Hz by cubic spline interpolation ({self.n_source} → {self.n_uniform} rows)"
        )


def sample_index(time_s: FloatArray) -> tuple[np.ndarray, float]:
    """Each stamp's sample number on the recorder's clock, and its period.

    The sample numbers are ``round((t - t₀) / T)`` with ``T`` the least-squares slope of the (N,)
    stamps, s, against them, fitted on the first 16 stamps starting from the mean of the
    steps within ±50 % of their median, then on 1.5 times as many until all are in (a dropped
    packet skips a number; jitter within a fifth of a period does not move one, and the numbers
    come out right with any share of single or runs of dropped packets: tested on 200 random
    clocks with up to 5 % dropped). The period returned is then the span over its sample numbers,
    so that the clock ``t₀ + k·T`` ends on the last stamp.

    Returns:
        ((N,) sample numbers from 0, the period T, s).
    """
    t = np.asarray(time_s, dtype=float)
    dt = np.diff(t)
    med = float(np.median(dt))
    step, start = float(np.mean(dt[np.abs(dt - med) <= 0.5 * med])), float(t[0])
    n = min(t.size, 16)
    while True:
        # numbered from the fitted line, not from the first stamp, whose own jitter (up to a
        # fifth of a period) would otherwise tilt every later number (40 stamps at 50 Hz with
        # ±0.19 periods of jitter: 30 numbers off by one)
        index = np.rint((t[:n] - start) / step)
        index -= index[0]
        step, start = (float(v) for v in np.polyfit(index, t[:n], 1))
        if n == t.size:
            index = np.rint((t - start) / step)
            index -= index[0]
            return index, float((t[-1] - t[0]) / index[-1])  # the span over its periods
        n = min(t.size, n + n // 2)


def nominal_step(time_s: FloatArray) -> float:
    """The recorder's period T, s, of the (N,) stamps (:func:`sample_index`)."""
    return sample_index(time_s)[1]


def _spline(time_s: FloatArray, x: FloatArray, grid: FloatArray) -> FloatArray:
    """(M, C) cubic spline through the (N, C) samples ``x`` at ``time_s``, at ``grid``, within their range."""
    y = np.clip(np.asarray(CubicSpline(time_s, x, axis=0)(grid), dtype=float), x.min(axis=0), x.max(axis=0))
    # on a recorded sample's time, its value exactly (a held, cut reading stays at the range)
    near = np.clip(np.searchsorted(time_s, grid), 1, time_s.size - 1)
    near -= grid - time_s[near - 1] < time_s[near] - grid
    on = np.abs(time_s[near] - grid) < 1e-6 * np.median(np.diff(time_s))
    y[on] = x[near[on]]
    return y


def _resamplable(time_s: FloatArray, signals: Sequence[FloatArray], params: ClockParams) -> bool:
    """True when the time is finite, increasing, in seconds and uneven, and the signals finite."""
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.shape[0] < 3 or not np.all(np.isfinite(t)):
        return False
    dt = np.diff(t)
    if np.any(dt <= 0):
        return False
    med = float(np.median(dt))
    if med >= params.max_gap_s:  # not seconds, or too slow a recorder: the trial's checks say which
        return False
    if np.max(np.abs(dt - med)) <= params.jitter_tolerance * med:
        return False
    return all(np.asarray(x).shape[0] == t.shape[0] and np.all(np.isfinite(x)) for x in signals)


def to_uniform_clock(
    time_s: FloatArray, signals: Sequence[FloatArray], params: ClockParams = CLOCK_PARAMS
) -> tuple[FloatArray, list[FloatArray], ClockRepair | None]:
    """Resample signals stamped at uneven times onto the constant clock ``t₀ + k·T`` (a clipped cubic spline).

    Args:
        time_s: (N,) sample times, s.
        signals: arrays of shape (N, C) sampled at ``time_s`` (any units).
        params: thresholds.

    Returns:
        ((M,) times, s, the (M, C) signals interpolated at them, the repair); the inputs
        unchanged and ``None`` when the steps are even, or when the time or the signals have a
        problem the trial's own checks name (not finite, not increasing, not seconds).

    Raises:
        PacketGapError: a step longer than ``params.max_gap_s``.

    Warns:
        UnevenClockWarning: once, with :meth:`ClockRepair.message`, when it resampled.
    """
    if not _resamplable(time_s, signals, params):
        return np.asarray(time_s, dtype=float), [np.asarray(x, dtype=float) for x in signals], None
    t = np.asarray(time_s, dtype=float)
    dt = np.diff(t)
    k = int(np.argmax(dt))
    if dt[k] > params.max_gap_s:
        raise PacketGapError("the trial", float(t[k] - t[0]), float(dt[k]), params.max_gap_s)
    index, step = sample_index(t)
    med = float(np.median(dt))
    grid = t[0] + step * np.arange(int(np.floor((t[-1] - t[0]) / step + 1e-6)) + 1)
    out = [_spline(t, np.asarray(x, dtype=float), grid) for x in signals]
    repair = ClockRepair(
        rate_hz=1.0 / step,
        n_source=int(t.shape[0]),
        n_uniform=int(grid.shape[0]),
        min_step_s=float(dt.min()),
        max_step_s=float(dt.max()),
        n_gaps=int(np.count_nonzero(np.diff(index) >= 2)),
        n_uneven=int(np.count_nonzero(np.abs(dt - med) > params.jitter_tolerance * med)),
        jitter_tolerance=params.jitter_tolerance,
    )
    warnings.warn(repair.message(), UnevenClockWarning, stacklevel=2)
    return grid, out, repair


def refuse_batched_stamps(
    time_s: FloatArray, signals: Sequence[FloatArray], params: ClockParams = CLOCK_PARAMS
) -> None:
    """Refuse a never-decreasing (N,) time, s, that repeats in many steps where the (N, C) readings differ.

    That is a logger stamping samples in batches as they arrive, not duplicated rows: dropping
    duplicates (the fix for a repeated row) would drop samples. A few repeats are left to the
    time's own check.

    Raises:
        TimeAxisError: naming the first repeat and how many there are.
    """
    dt = np.diff(np.asarray(time_s, dtype=float))
    same = np.flatnonzero(dt == 0)
    if not same.size or np.any(dt < 0):
        return
    differ = same[np.any([np.any(x[same] != x[same + 1], axis=1) for x in signals], axis=0)]
    if differ.size >= params.batch_share * dt.size:
        k = int(differ[0])
        raise TimeAxisError(
            f"time repeats with different readings in {differ.size} of {dt.size} steps (first at data rows "
            f"{k + 1} and {k + 2}, {time_s[k]:.6g} s): samples stamped in batches as they arrived, or times "
            f"written with too few digits? give each sample its own time (its sample number divided by "
            f"the rate)"
        )
