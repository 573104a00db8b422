"""Accelerometer offsets seen at rest: the specific force's norm against gravity.

A sensor at rest reads gravity, 9.78–9.83 m/s² depending on latitude and altitude. A bias or
scale error of its accelerometer shows at rest as a norm that is off by the error's component
along the standing vertical (the components across it do not show). In the joint constraint
(Hu et al. 2021 eq. 3) a constant bias sits beside the centripetal term ``ω×(ω×c)``, which a
slowly turning segment keeps small, so the fitted centre moves by about ``b / ω²``: on the
real walk, random biases of 0.1 m/s² moved a thigh's length by several centimetres
(``benchmarks/results/acc_bias.md``). The joint fit cannot separate such a bias from the
centre (left free, it is unidentifiable from walking), so the check only warns.
"""

from __future__ import annotations

import numpy as np

from ..conventions import GRAVITY_MPS2, FloatArray

__all__ = ["AccelerometerOffsetWarning", "rest_gravity_offsets", "rest_gravity_notes"]


class AccelerometerOffsetWarning(UserWarning):
    """An accelerometer at rest reads a norm far from gravity (a bias or scale error)."""


def rest_gravity_offsets(acc: dict[str, FloatArray], still: slice) -> dict[str, float]:
    """``{sensor: ‖mean specific force at rest‖ − 9.81}``, m/s².

    Args:
        acc: ``{sensor: (N, 3)}`` specific force, sensor frame, m/s².
        still: the samples of the standing start.
    """
    return {s: float(np.linalg.norm(np.mean(a[still], axis=0))) - GRAVITY_MPS2 for s, a in acc.items()}


def rest_gravity_notes(offsets: dict[str, float], limit_mps2: float) -> list[str]:
    """One message per sensor whose rest offset exceeds ``limit_mps2`` in size (m/s²)."""
    return [
        f"the {sensor} accelerometer reads {GRAVITY_MPS2 + off:.2f} m/s² at rest, {off:+.2f} m/s² from "
        f"gravity: a bias or scale error of that size moves the joint centres by centimetres in "
        f"walking (only its part along the vertical shows at rest); calibrate the accelerometer "
        f"(e.g. six still orientations) or check its unit and range setting"
        for sensor, off in offsets.items()
        if abs(off) > limit_mps2
    ]
