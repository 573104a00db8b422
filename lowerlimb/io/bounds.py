"""Plausibility bounds of every user input, in one params dataclass, and the checks that use them.

A value outside these bounds is refused at the boundary (the command line,
:func:`lowerlimb.outputs.run_calibrate`, the JSON readers) before anything is
computed, with one :class:`~lowerlimb.errors.InputError` naming the value and
the accepted range. The bounds are deliberately wide: they catch impossible
values (an ankle 1000 m from its sensor, a height of ``inf``), not unusual ones.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..conventions import GRAVITY_MPS2
from ..errors import InputError

__all__ = ["INPUT_BOUNDS", "InputBounds", "check_range", "check_vectors"]


@dataclass(frozen=True)
class InputBounds:
    """Accepted ranges of the user's inputs.

    Attributes:
        max_center_m: largest distance from a sensor to a joint centre (a
            calibration's centres, an S2J model's vectors), m. A sensor sits on
            the segment it measures, so real values are below ~0.6 m.
        height_m: (min, max) subject stature, m.
        mass_kg: (min, max) subject mass, kg.
        duration_s: (min, max) length of a simulated trial, s.
        rate_hz: (min, max) sampling rate, Hz: of a simulated trial, and the
            ``resample_hz`` of a CSV mapping; the max also bounds the update rate of
            an Xsens export and the source clock of an imported CSV.
        max_samples: most samples of a simulated trial (duration × rate).
        max_seed: largest random seed (seeds are 0 … max_seed).
        min_motion_gyro_std_rps: a trial whose thigh, shank or foot gyro varies
            less than this (standard deviation of the angular-rate magnitude,
            rad/s) holds no motion to calibrate from.
        moving_acc_std_mps2: a sensor whose gyro shows no motion while its accelerometer's
            magnitude varies more than this (standard deviation, m/s²) moved: its gyro is in the
            wrong unit or columns (a still sensor's varies by its noise, 0.01–0.1 m/s²; a
            walking thigh's by 1–3 m/s²).
        max_json_bytes: largest calibration or S2J JSON file read, bytes.
        max_sample_abs: largest magnitude of one accelerometer (m/s²) or gyro (rad/s)
            sample of a trial: beyond every body-worn sensor's range in any unit
            (1000 g, 10 000 deg/s), so a larger one is a glitch in the file.
        max_median_acc_mps2: largest median accelerometer magnitude of one sensor over
            a trial, m/s². A body-worn accelerometer reads about gravity most of the
            time, even on a walking foot, so a median far above it (4 g) is not an
            accelerometer in m/s²: gyro columns mapped as accelerometer, or cm/s², mm/s².
    """

    max_center_m: float = 1.0
    height_m: tuple[float, float] = (0.5, 2.6)
    mass_kg: tuple[float, float] = (10.0, 400.0)
    duration_s: tuple[float, float] = (2.0, 4.0 * 3600.0)
    rate_hz: tuple[float, float] = (20.0, 2000.0)
    max_samples: int = 2_000_000
    max_seed: int = 2**32 - 1
    min_motion_gyro_std_rps: float = 0.05
    moving_acc_std_mps2: float = 0.5
    max_json_bytes: int = 200_000_000
    max_sample_abs: float = 1.0e4
    max_median_acc_mps2: float = 4.0 * GRAVITY_MPS2


#: The bounds used unless a caller passes others.
INPUT_BOUNDS = InputBounds()


def check_range(name: str, value: float, bounds: tuple[float, float], unit: str, hint: str = "") -> float:
    """Return ``value`` as a float, or raise when it is not finite or outside ``bounds``.

    Args:
        name: what the value is, as the user named it (e.g. ``"--height"``).
        value: the value.
        bounds: (min, max), inclusive, in ``unit``.
        unit: the unit, for the message.
        hint: what the value means, e.g. ``"the subject's height"``.

    Raises:
        InputError: naming the value and the accepted range.
    """
    lo, hi = bounds
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number in {unit}, got {value!r}") from None
    if not (math.isfinite(x) and lo <= x <= hi):
        what = f" ({hint})" if hint else ""
        raise InputError(
            f"{name} {value:g} {unit} is out of range{what}; give a value from {lo:g} to {hi:g} {unit}"
        )
    return x


def check_vectors(where: str, vectors: Iterable[tuple[str, Any]], max_norm_m: float) -> None:
    """Refuse a non-finite vector or one longer than ``max_norm_m`` (a sensor-to-joint vector).

    Args:
        where: the file or object holding the vectors, for the message.
        vectors: (name, (…, 3) array-like in m) pairs.
        max_norm_m: the largest accepted length, m (:attr:`InputBounds.max_center_m`).

    Raises:
        InputError: naming the vector and its value.
    """
    for name, v in vectors:
        try:
            x = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{where}: {name} is not a list of numbers ({v!r:.60})") from None
        if x.size == 0 or x.shape[-1] != 3:
            raise InputError(f"{where}: {name} must hold 3 numbers (x, y, z in m), got shape {x.shape}")
        if not np.all(np.isfinite(x)):
            raise InputError(f"{where}: {name} holds a NaN or infinite value; it must be finite metres")
        biggest = float(np.max(np.abs(x)))
        norm = biggest if biggest > max_norm_m else float(np.max(np.linalg.norm(x.reshape(-1, 3), axis=1)))
        if norm > max_norm_m:
            raise InputError(
                f"{where}: {name} lies {norm:.4g} m from its sensor, beyond the plausible "
                f"{max_norm_m:g} m (a sensor sits on the segment it measures); check the units (m) "
                f"or recalibrate"
            )
