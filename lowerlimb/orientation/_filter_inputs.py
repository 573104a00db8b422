"""Inputs of the compiled filter loops, prepared the same way for every filter.

Each ``<name>_filter`` passes its loop the bias-corrected gyro, the
accelerometer and the magnetometer as contiguous float64 arrays (an empty
(0, 3) magnetometer and ``use_mag = False`` for 6-axis), the sample interval
and the initial quaternion, then the filter's own parameters.
"""

from __future__ import annotations

import numpy as np

from lowerlimb.conventions import FloatArray
from lowerlimb.orientation.initialisation import InitialState


def loop_inputs(
    gyr: FloatArray, acc: FloatArray, mag: FloatArray | None, rate_hz: float, initial: InitialState
) -> tuple[FloatArray, FloatArray, FloatArray, bool, float, FloatArray, bool]:
    """``(gyr, acc, mag, use_mag, dt, q0, lowpass_up)``: the first seven arguments of every filter loop.

    The gyro bias of ``initial`` is subtracted; ``q0`` is its orientation
    before the first sample (sensor -> ENU); ``lowpass_up`` starts an earth-frame
    accelerometer low-pass at gravity (``initial.lowpass_from_gravity``).
    """
    return (
        np.ascontiguousarray(np.asarray(gyr, dtype=np.float64) - initial.gyr_bias_rad_s),
        np.ascontiguousarray(acc, dtype=np.float64),
        np.zeros((0, 3)) if mag is None else np.ascontiguousarray(mag, dtype=np.float64),
        mag is not None,
        1.0 / rate_hz,
        np.asarray(initial.quat_wxyz, dtype=np.float64),
        bool(initial.lowpass_from_gravity),
    )


def magnetic_reference(initial: InitialState) -> tuple[float, float]:
    """``(norm, dip_rad)`` of the undisturbed field at the start; 0 for an unknown value.

    A zero norm turns the loops' magnetic disturbance tests off.
    """
    return (
        initial.mag_norm if np.isfinite(initial.mag_norm) else 0.0,
        initial.mag_dip_rad if np.isfinite(initial.mag_dip_rad) else 0.0,
    )
