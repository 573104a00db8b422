"""Deterministic sensor errors of the realism profile: clock offset and jitter, scale and misalignment.

A sensor whose clock runs ahead by ``τ`` stamps at ``t`` the value it sampled at
``t + τ + j`` (``j`` white jitter); the simulator resamples the clean signals
at those instants with a cubic spline (clamped to the recording). Its
accelerometer and gyro read ``M · x`` with ``M = diag(1 + s) (I + E)``:
``s`` per-axis scale-factor errors, ``E`` off-diagonal axis misalignment.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from ..conventions import SENSORS, FloatArray
from .artefacts import Artefacts


@dataclass
class SensorErrors:
    """Per-sensor errors drawn for one simulation.

    Attributes:
        clock_offset_s: ``{sensor: float}`` constant clock offset, s.
        sample_time_error_s: ``{sensor: (N,)}`` offset plus jitter of every sample, s.
        acc_matrix: ``{sensor: (3, 3)}`` accelerometer scale × misalignment.
        gyr_matrix: ``{sensor: (3, 3)}`` gyro scale × misalignment.
    """

    clock_offset_s: dict[str, float]
    sample_time_error_s: dict[str, FloatArray]
    acc_matrix: dict[str, FloatArray]
    gyr_matrix: dict[str, FloatArray]


def _matrix(rng: np.random.Generator, scale_std: float, mis_std: float) -> FloatArray:
    E = mis_std * rng.normal(size=(3, 3))
    np.fill_diagonal(E, 0.0)
    return np.asarray(np.diag(1.0 + scale_std * rng.normal(size=3)) @ (np.eye(3) + E))


def draw_sensor_errors(
    params: Artefacts, n: int, rng: np.random.Generator, sensors: Sequence[str] = SENSORS
) -> SensorErrors:
    """Draw the clock, scale and misalignment errors of ``sensors`` (in that order) for ``n`` samples."""
    offset, times, acc_m, gyr_m = {}, {}, {}, {}
    for sensor in sensors:
        offset[sensor] = float(params.clock_offset_std_s * rng.normal())
        times[sensor] = offset[sensor] + params.clock_jitter_std_s * rng.normal(size=n)
        acc_m[sensor] = _matrix(rng, params.acc_scale_std, params.misalignment_std_rad)
        gyr_m[sensor] = _matrix(rng, params.gyr_scale_std, params.misalignment_std_rad)
    return SensorErrors(offset, times, acc_m, gyr_m)


def resample_at(t: FloatArray, x: FloatArray, time_error_s: FloatArray) -> FloatArray:
    """Values (N, 3) of ``x`` (N, 3) sampled on ``t`` (N,), read at ``t + time_error_s`` (clamped)."""
    if not np.any(time_error_s):
        return x.copy()
    tq = np.clip(t + time_error_s, t[0], t[-1])
    return np.asarray(CubicSpline(t, x, axis=0)(tq))
