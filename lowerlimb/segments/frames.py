"""Anatomical segment frames from the joint-constraint calibration and the standing reference.

Hu et al. 2021 §4.1 (eq. 30–37) builds the thigh and shank frames from the hip
centre, the knee axis and the ankle centre, and the pelvis and foot frames from
the reference posture. The library makes these choices (documented because the
paper leaves them open):

* **Thigh** (in the thigh sensor): z = the calibrated knee axis (pointing
  right) — the primary axis, so knee flexion is exactly about it; y = from the
  knee centre to the hip centre, made orthogonal to z; x = y × z (anterior).
  The knee centre's position along the axis does not change this frame.
* **Pelvis, shank, foot**: docs/conventions.md defines zero angles as the standing
  reference posture, so at the reference every segment frame has the thigh
  frame's orientation in the earth frame. Each one is therefore the thigh frame
  at the reference, carried by its own sensor:
  ``R_sensor_segment = R_earth_sensor(ref)^T R_earth_thigh(ref)``.
  The shank's z is then the knee axis seen from the shank (a hinge keeps it),
  which makes knee ad/abduction and rotation zero for a pure hinge.

``R_sensor_segment`` maps segment coordinates to sensor coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..conventions import SEGMENTS, FloatArray, quat_from_matrix, quat_to_matrix
from ..errors import InputError

if TYPE_CHECKING:
    from ..calibration import LegCalibration


@dataclass(frozen=True)
class SegmentFrames:
    """Orientation of each anatomical segment frame in its sensor frame.

    Attributes:
        R_sensor_segment: ``{segment: (3, 3)}`` rotation mapping segment to sensor coordinates.
        side: ``"left"`` or ``"right"``.
    """

    R_sensor_segment: dict[str, FloatArray]
    side: str

    def segment_quaternions(self, quat_wxyz: dict[str, FloatArray]) -> dict[str, FloatArray]:
        """Segment orientations (N, 4) in the earth frame from sensor orientations (N, 4)."""
        out = {}
        for seg in SEGMENTS:
            R = quat_to_matrix(quat_wxyz[seg]) @ self.R_sensor_segment[seg]
            out[seg] = quat_from_matrix(R)
        return out


def thigh_frame_in_sensor(
    hip_center: FloatArray, knee_center: FloatArray, knee_axis: FloatArray
) -> FloatArray:
    """Thigh segment axes in the thigh sensor frame (Hu et al. eq. 30–33, z primary).

    Args:
        hip_center: (3,) hip centre in the thigh sensor frame, m.
        knee_center: (3,) a point on the knee axis in the thigh sensor frame, m.
        knee_axis: (3,) knee axis in the thigh sensor frame, pointing right.

    Returns:
        (3, 3) ``R_sensor_thigh`` whose columns are the thigh x, y, z axes.

    Raises:
        InputError: when the hip centre lies on the knee axis (degenerate calibration).
    """
    z = np.asarray(knee_axis, dtype=float)
    z = z / np.linalg.norm(z)
    d = np.asarray(hip_center, dtype=float) - np.asarray(knee_center, dtype=float)
    y = d - d.dot(z) * z
    n = float(np.linalg.norm(y))
    if n < 0.05:
        raise InputError(
            "the hip centre is within 5 cm of the knee axis: the calibration is degenerate; "
            "record a trial with more hip and knee motion"
        )
    y /= n
    x = np.cross(y, z)
    return np.column_stack([x, y, z])


def segment_frames(
    calibration: LegCalibration,
    reference_quat_wxyz: dict[str, FloatArray],
    side: str,
    R_sensor_pelvis: FloatArray | None = None,
) -> SegmentFrames:
    """Segment frames of the four segments.

    Args:
        calibration: the joint calibration (joint centres and knee axes in sensor frames).
        reference_quat_wxyz: ``{sensor: (4,)}`` sensor orientations (sensor → earth)
            averaged over the standing reference posture.
        side: ``"left"`` or ``"right"``.
        R_sensor_pelvis: (3, 3) a pelvis segment frame given from outside (columns x
            anterior, y up, z right, in the pelvis sensor frame), e.g. the one pelvis of
            both legs (:mod:`lowerlimb.bilateral.pelvis`); the hip angles are then not zero
            at the reference. Default: the thigh frame at the reference (one leg).
    """
    hip, knee = calibration.hip, calibration.knee
    R_thigh = thigh_frame_in_sensor(
        hip.center_in_child_sensor, knee.center_in_parent_sensor, knee.axis_in_parent_sensor
    )
    R_earth_thigh_ref = quat_to_matrix(reference_quat_wxyz["thigh"]) @ R_thigh
    out = {"thigh": R_thigh}
    for seg in ("pelvis", "shank", "foot"):
        out[seg] = quat_to_matrix(reference_quat_wxyz[seg]).T @ R_earth_thigh_ref
    if R_sensor_pelvis is not None:
        out["pelvis"] = np.asarray(R_sensor_pelvis, dtype=float)
    return SegmentFrames(out, side)


def mean_quaternion(quat_wxyz: FloatArray) -> FloatArray:
    """Average orientation (4,) of a (N, 4) set (Markley's eigenvector method)."""
    q = np.asarray(quat_wxyz, dtype=float)
    M = q.T @ q
    w, v = np.linalg.eigh(M)
    m = v[:, -1]
    return m if m[0] >= 0 else -m
