"""Implausible segment lengths: warn and fall back on the anthropometric template.

The joint constraints fix the hip centre in the thigh frame and the ankle centre
in the shank frame; their distance to the knee axis is the thigh and shank
length. A trial that hardly moves the hip (or a disturbed recording) can put the
hip centre next to the knee axis: a 2 cm thigh, from which no segment frame and
no position can be built. Rather than refuse the whole trial, the length is
checked against de Leva 1996 (scaled by stature) and, outside
``[min_ratio, max_ratio]`` times the template, that one centre is replaced by
the template: the knee centre plus the template length along the segment's long
axis, taken as the standing vertical (gravity at the reference posture, in
that sensor's frame, made perpendicular to the knee axis). The other frame's
centre (hip in the pelvis frame, ankle in the foot frame) is kept. A warning
names the joint, the calibrated length and what was used instead; the note is
kept in the calibration's warnings (calibration.json).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace

import numpy as np

from ..calibration.fit_band import segment_lengths_m
from ..calibration.leg import LegCalibration
from ..conventions import FloatArray
from .anthropometry import segment_inertias

__all__ = ["CalibrationFallbackWarning", "FallbackParams", "segment_lengths", "with_plausible_lengths"]


class CalibrationFallbackWarning(UserWarning):
    """A calibrated segment length was implausible; the anthropometric template was used."""


@dataclass(frozen=True)
class FallbackParams:
    """Bounds of a plausible segment length, as fractions of the de Leva template.

    Attributes:
        min_ratio: shortest plausible length over the template.
        max_ratio: longest plausible length over the template.
    """

    min_ratio: float = 0.6
    max_ratio: float = 1.5


def segment_lengths(calibration: LegCalibration) -> tuple[float, float]:
    """Thigh and shank length of a calibration, m: hip and ankle centres to the knee axis line."""
    return segment_lengths_m(calibration)


def _along_vertical(knee: FloatArray, axis: FloatArray, up: FloatArray, length: float) -> FloatArray:
    u = np.asarray(up, dtype=float)
    j = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    v = u - u.dot(j) * j
    return np.asarray(knee, dtype=float) + length * v / np.linalg.norm(v)


def with_plausible_lengths(
    calibration: LegCalibration,
    up_in_sensor: dict[str, FloatArray],
    *,
    height_m: float,
    params: FallbackParams | None = None,
) -> LegCalibration:
    """The calibration with an implausible thigh or shank replaced by the template (module docstring).

    Args:
        calibration: the joint calibration.
        up_in_sensor: ``{"thigh": (3,), "shank": (3,)}`` the upward vertical in each
            sensor frame at the standing reference (mean accelerometer direction).
        height_m: stature, m (scales the template).
        params: the plausible range (defaults: :class:`FallbackParams`).

    Returns:
        The same calibration when both lengths are plausible, else a copy with the
        offending centre replaced and a note in that joint's warnings.

    Warns:
        CalibrationFallbackWarning: once per replaced centre.
    """
    p = params or FallbackParams()
    template = segment_inertias(height_m)
    thigh, shank = segment_lengths(calibration)
    k = calibration.knee
    out = calibration
    for joint, length, segment, knee_c, axis in (
        ("hip", thigh, "thigh", k.center_in_parent_sensor, k.axis_in_parent_sensor),
        ("ankle", shank, "shank", k.center_in_child_sensor, k.axis_in_child_sensor),
    ):
        expected = template[segment].length_m
        if p.min_ratio * expected <= length <= p.max_ratio * expected:
            continue
        sign = 1.0 if joint == "hip" else -1.0  # the hip is above the knee, the ankle below
        center = _along_vertical(knee_c, axis, sign * up_in_sensor[segment], expected)
        note = (
            f"{joint}: the calibrated {segment} is {length * 1000:.0f} mm long, outside the plausible "
            f"{p.min_ratio * expected * 1000:.0f}–{p.max_ratio * expected * 1000:.0f} mm for a "
            f"{height_m:.2f} m subject; fell back on the de Leva {segment} ({expected * 1000:.0f} mm) "
            f"along the standing vertical of the {segment} sensor; record more {joint} motion or "
            f"reuse a calibration (--calibration)"
        )
        warnings.warn(note, CalibrationFallbackWarning, stacklevel=2)
        jc = getattr(out, joint)
        jc = replace(
            jc,
            center_in_child_sensor=center if joint == "hip" else jc.center_in_child_sensor,
            center_in_parent_sensor=center if joint == "ankle" else jc.center_in_parent_sensor,
            warnings=[*jc.warnings, note],
        )
        out = replace(out, **{joint: jc})
    return out
