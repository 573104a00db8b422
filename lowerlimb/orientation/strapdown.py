"""Gyro-only attitude (strapdown integration) in a drifting frame of its own.

What it is for: quantities that need a sensor's rotation over a few seconds but
not its attitude in the earth frame, such as carrying two sensors' vectors into
frames that turn only slowly against each other
(:mod:`lowerlimb.calibration.aligned_form`). The frame starts at the sensor's
first sample and drifts with the gyro bias left in the signal (0.01 rad/s
turns it by 0.6° per second); nothing here corrects that.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray, quat_to_matrix
from lowerlimb.orientation._quaternion_nb import put_quat, qintegrate

__all__ = ["strapdown_matrices", "strapdown_quat"]


@njit(cache=True)
def _strapdown(gyr: FloatArray, dt: float) -> FloatArray:  # pragma: no cover - compiled
    n = gyr.shape[0]
    out = np.empty((n, 4))
    w, x, y, z = 1.0, 0.0, 0.0, 0.0
    for i in range(n):
        put_quat(out, i, w, x, y, z)
        if i + 1 < n:  # the trapezoid: the mean rate over the step, not the rate at its start
            gx = 0.5 * (gyr[i, 0] + gyr[i + 1, 0])
            gy = 0.5 * (gyr[i, 1] + gyr[i + 1, 1])
            gz = 0.5 * (gyr[i, 2] + gyr[i + 1, 2])
            w, x, y, z = qintegrate(w, x, y, z, gx, gy, gz, dt)
    return out


def strapdown_quat(gyr: ArrayLike, rate_hz: float) -> FloatArray:
    """Integrate a gyro from the identity: the attitude at each sample's time.

    Each step turns by the mean of its two end samples' rates (the trapezoid). The
    rate at the step's start alone (the rectangle) lags the attitude by half a
    sample, ω·dt/2 (0.9° at 3 rad/s and 100 Hz), and carrying a sensor's specific
    force into the integration frame with that lag put a noise-free squat's hip
    centre 7 mm off in the aligned form (0.1 mm with the trapezoid).

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s (bias removed as far as known).
        rate_hz: sampling rate, Hz.

    Returns:
        (N, 4) unit quaternions ``w, x, y, z`` mapping sensor-frame vectors into the
        integration frame (the sensor's frame at sample 0); the first is the identity.
    """
    g = np.ascontiguousarray(np.asarray(gyr, dtype=float))
    return np.asarray(_strapdown(g, 1.0 / float(rate_hz)), dtype=float)


def strapdown_matrices(gyr: ArrayLike, rate_hz: float) -> FloatArray:
    """:func:`strapdown_quat` as (N, 3, 3) rotation matrices (sensor → integration frame)."""
    return np.asarray(quat_to_matrix(strapdown_quat(gyr, rate_hz)), dtype=float)
