"""Accelerometer offsets seen at rest: the specific force's norm against gravity.

A sensor at rest reads gravity, 9.78–9.83 m/s² depending on latitude and altitude. A bias or
scale error of its accelerometer shows at rest as a norm that is off by the error's component
along the standing vertical (the components across it do not show). In the joint constraint
(Hu et al. 2021 eq. 3) a constant bias sits beside the centripetal term ``ω×(ω×c)``, which a
slowly turning segment keeps small, so the fitted centre moves by about ``b / ω²``: on the
real walk, random biases of 0.1 m/s² moved a thigh's length by several centimetres
(``benchmarks/results/acc_bias.md``). The joint fit cannot separate such a bias from the
centre when it is left free (unidentifiable from walking: the fit's condition number is
10⁻³ and it finds biases of 3.5 m/s² on the real walk), but every sensor at rest reads the
same gravity, so the differences of their rest norms are sensor errors.
:func:`vertical_offsets_removed` takes each accelerometer's rest offset off along its
standing vertical (``CalibrationOptions.rest_gravity_correction``, off): a common offset of
all sensors (local gravity) changes nothing, and what lies across the vertical stays. On
seven-IMU simulated walks with biases it returns the segment lengths to the unbiased walk's;
on the real walk it trades the thighs −10 / +29 for −23 / +16 mm and the left hip-to-ankle
distance 23 for 40 mm, so it stays an option.
"""

from __future__ import annotations

import numpy as np

from ..conventions import GRAVITY_MPS2, FloatArray

__all__ = [
    "AccelerometerOffsetWarning",
    "rest_gravity_notes",
    "rest_gravity_offsets",
    "vertical_offsets_removed",
]


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


def vertical_offsets_removed(
    acc: dict[str, FloatArray], still: slice
) -> tuple[dict[str, FloatArray], dict[str, float]]:
    """Each accelerometer with its rest offset taken off along its standing vertical.

    Args:
        acc: ``{sensor: (N, 3)}`` specific force, sensor frame, m/s².
        still: the samples of the standing start.

    Returns:
        ``({sensor: (N, 3)}`` the corrected signals, m/s², ``{sensor: offset}`` removed, m/s²).
    """
    offsets = rest_gravity_offsets(acc, still)
    out = {}
    for s, a in acc.items():
        m = np.mean(a[still], axis=0)
        out[s] = a - offsets[s] * m / np.linalg.norm(m)
    return out, offsets
