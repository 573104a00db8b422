"""The two hips together: are the two calibrated hip centres a plausible pair?

Each leg's joint-constraint calibration finds its hip centre in the shared pelvis
sensor frame on its own. Together they must look like a pelvis: the distance
between them near the hip spacing of de Leva 1996 for the subject's stature
(:func:`lowerlimb.model.anthropometry.hip_spacing_m`), and the right hip to the
right of the left one along the pelvis's medio-lateral axis. That axis is the
pelvis segment frame's z (ISB: to the right) in the pelvis sensor, averaged over
the two legs (with one pelvis, :mod:`lowerlimb.bilateral.pelvis`, both are the shared
frame and the angle is 0; with ``one_pelvis=False`` each leg builds the pelvis frame from
its own thigh at the standing reference and the angle between the two is reported).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ..calibration import LegCalibration
from ..conventions import FloatArray
from ..model.anthropometry import hip_spacing_m

__all__ = ["HipCheck", "HipParams", "HipSpacingWarning", "check_hips"]


class HipSpacingWarning(UserWarning):
    """The two calibrated hip centres do not look like one pelvis."""


@dataclass(frozen=True)
class HipParams:
    """Thresholds of :func:`check_hips`.

    Attributes:
        spacing_tolerance_m: Largest accepted difference between the calibrated hip spacing
            and de Leva's, m (adult hip spacings span about ±3 cm around de Leva's mean; the
            hip centres of joint-constraint calibration carry 1–4 cm of error each).
        min_lateral_fraction: Smallest share of the left→right hip vector that must point to
            the right along the pelvis's medio-lateral axis.
    """

    spacing_tolerance_m: float = 0.08
    min_lateral_fraction: float = 0.5


@dataclass(frozen=True)
class HipCheck:
    """The two hip centres seen together.

    Attributes:
        center_in_pelvis_sensor_m: ``{side: (3,)}`` calibrated hip centre, pelvis sensor frame, m.
        spacing_m: Distance between the two hip centres, m.
        expected_spacing_m: de Leva's hip spacing for the stature, m.
        lateral_m: Component of right minus left hip centre along the pelvis's right axis, m.
        pelvis_axes_angle_deg: Angle between the two legs' pelvis right axes, deg.
        plausible: Both criteria hold.
        reason: What is implausible, or ``""``.
    """

    center_in_pelvis_sensor_m: dict[str, FloatArray]
    spacing_m: float
    expected_spacing_m: float
    lateral_m: float
    pelvis_axes_angle_deg: float
    plausible: bool
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The ``hips`` entry of the two-leg ``calibration.json``."""
        d = asdict(self)
        d["center_in_pelvis_sensor_m"] = {
            k: np.asarray(v).tolist() for k, v in self.center_in_pelvis_sensor_m.items()
        }
        return d


def check_hips(
    left: LegCalibration,
    right: LegCalibration,
    R_pelvis_sensor_segment: dict[str, FloatArray],
    *,
    height_m: float,
    params: HipParams | None = None,
) -> HipCheck:
    """Check the two calibrated hip centres against each other and de Leva's hip spacing.

    Args:
        left: the left leg's calibration (hip centre in the pelvis sensor frame).
        right: the right leg's calibration.
        R_pelvis_sensor_segment: ``{side: (3, 3)}`` each leg's pelvis segment frame in the
            pelvis sensor (columns x anterior, y up, z right).
        height_m: subject stature, m.
        params: thresholds (defaults: :class:`HipParams`).
    """
    p = params or HipParams()
    c = {
        "left": np.asarray(left.hip.center_in_parent_sensor, dtype=float),
        "right": np.asarray(right.hip.center_in_parent_sensor, dtype=float),
    }
    z = {s: np.asarray(R, dtype=float)[:, 2] for s, R in R_pelvis_sensor_segment.items()}
    axis = z["left"] + z["right"]
    axis /= np.linalg.norm(axis)
    cos = float(np.clip(z["left"] @ z["right"], -1.0, 1.0))
    d = c["right"] - c["left"]
    spacing = float(np.linalg.norm(d))
    lateral = float(d @ axis)
    expected = hip_spacing_m(height_m)
    reasons = []
    if abs(spacing - expected) > p.spacing_tolerance_m:
        reasons.append(
            f"the hip centres are {spacing * 100:.1f} cm apart, de Leva's spacing for {height_m:.2f} m "
            f"is {expected * 100:.1f} cm"
        )
    if lateral < p.min_lateral_fraction * spacing:
        reasons.append(
            f"the right hip centre is only {lateral * 100:.1f} cm to the right of the left one "
            f"(of {spacing * 100:.1f} cm)"
        )
    return HipCheck(
        center_in_pelvis_sensor_m=c,
        spacing_m=spacing,
        expected_spacing_m=expected,
        lateral_m=lateral,
        pelvis_axes_angle_deg=float(np.degrees(np.arccos(cos))),
        plausible=not reasons,
        reason="; ".join(reasons),
    )
