"""Readings held over several rows: a sensor recorded at a lower rate and padded to the table's rate.

A trial table often merges sensors streamed at different rates, or is resampled to a common rate
by repeating each sensor's last reading (pandas ``ffill``, a logger's sample-and-hold). Its time
column then says 100 Hz while a sensor's readings change at 50 Hz, in steps. The calibration
differentiates the gyros (angular acceleration) and filters the accelerometers, and the foot
tracks integrate them: a step is a spike there. On the real walk of the shared data, all seven
sensors held over two rows (50 Hz padded to 100 Hz) put the step width 40 mm off (13 mm as
recorded) and the stride length 2.9 % (0.8 %); one sensor held moved its leg's lengths by 7 mm.

A reading is *held* when all six accelerometer and gyro values of a sensor equal those of the
row before. Only rows in which the sensor turns faster than :attr:`HeldParams.min_rate_rps`
count: a moving sensor's noise changes the last digit of every value from one row to the next,
while a still sensor exported with few digits may repeat a row honestly.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["HELD_PARAMS", "HeldParams", "HeldSamplesWarning", "held_fractions", "warn_held_samples"]


class HeldSamplesWarning(UserWarning):
    """A sensor's readings repeat the previous row in many of the rows in which it moves."""


@dataclass(frozen=True)
class HeldParams:
    """Thresholds of the held-reading check (module docstring).

    Attributes:
        min_rate_rps: a row counts when the sensor's gyro norm exceeds this, rad/s.
        min_rows: fewer counted rows than this are not judged.
        max_fraction: warn when more than this share of the counted rows repeats the row before.
    """

    min_rate_rps: float = 1.0
    min_rows: int = 50
    max_fraction: float = 0.1


#: The defaults.
HELD_PARAMS = HeldParams()


def held_fractions(
    acc: Mapping[str, ArrayLike], gyr: Mapping[str, ArrayLike], params: HeldParams = HELD_PARAMS
) -> dict[str, float]:
    """``{sensor: share of its moving rows that repeat the row before}`` (sensors with enough moving rows).

    Args:
        acc: ``{sensor: (N, 3)}`` specific force, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity, rad/s.
        params: thresholds.
    """
    out: dict[str, float] = {}
    for sensor in acc:
        if sensor not in gyr:
            continue
        x = np.hstack([np.asarray(acc[sensor], dtype=float), np.asarray(gyr[sensor], dtype=float)])
        moving = np.linalg.norm(x[1:, 3:], axis=1) > params.min_rate_rps
        if int(moving.sum()) < params.min_rows:
            continue
        same = np.all(x[1:] == x[:-1], axis=1)
        out[sensor] = float(same[moving].mean())
    return out


def warn_held_samples(
    acc: Mapping[str, ArrayLike],
    gyr: Mapping[str, ArrayLike],
    rate_hz: float,
    params: HeldParams = HELD_PARAMS,
) -> None:
    """One :class:`HeldSamplesWarning` per sensor whose moving rows repeat too often, with the fix."""
    for sensor, fraction in held_fractions(acc, gyr, params).items():
        if fraction <= params.max_fraction:
            continue
        own = rate_hz * (1.0 - fraction)
        warnings.warn(
            f"the {sensor} readings repeat the row before in {100 * fraction:.0f} % of the rows in which "
            f"it moves: it looks recorded at about {own:.3g} Hz and held to the table's {rate_hz:.3g} Hz, "
            f"and the calibration and the foot tracks see steps there; give the trial at the sensors' "
            f"own rate (lowerlimb reads 50 Hz trials) or interpolate instead of repeating readings",
            HeldSamplesWarning,
            stacklevel=3,
        )
