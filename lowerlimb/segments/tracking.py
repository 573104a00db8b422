"""From sensor orientations to segment motion: consistent headings, segment frames, ISB angles.

The two passes (see :mod:`lowerlimb.segments.heading`): the joint constraints make the
headings of adjacent sensors consistent; the segment frames are built at the
standing reference (:mod:`lowerlimb.segments.frames`); a second heading pass adds
the range-of-motion prior, which needs those frames; the frames are rebuilt and
the Z-X-Y angles computed (:mod:`lowerlimb.segments.angles`).

Observability (documented limitation): with 6-axis data, a sensor that
neither rotates nor accelerates horizontally relative to its neighbour (a
planted foot in squats, a still pelvis in knee lifts) has an unobservable
heading; only the prior then holds it. A magnetometer (9-axis filters) or a
few steps of walking in the trial removes the limitation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..conventions import SENSORS, FloatArray
from .angles import compute_joint_angles
from .frames import SegmentFrames, mean_quaternion, segment_frames
from .heading import HeadingCorrection, correct_headings, rotate_about_vertical

if TYPE_CHECKING:
    from ..calibration import LegCalibration

#: Weight (m/s²)² of the shared magnetic heading when orientations are 9-axis.
MAG_HEADING_WEIGHT = 10.0


@dataclass(frozen=True)
class SegmentMotion:
    """Segment kinematics of a trial.

    Attributes:
        frames: segment frames in the sensor frames.
        sensor_quat_wxyz: ``{sensor: (N, 4)}`` heading-corrected sensor orientations.
        segment_quat_wxyz: ``{segment: (N, 4)}`` segment orientations in one earth frame.
        angles_rad: (N, 9) ISB joint angles, angles.csv order, rad.
        heading: the heading corrections applied.
    """

    frames: SegmentFrames
    sensor_quat_wxyz: dict[str, FloatArray]
    segment_quat_wxyz: dict[str, FloatArray]
    angles_rad: FloatArray
    heading: HeadingCorrection


def track_segments(
    quat_wxyz: dict[str, FloatArray],
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    calibration: LegCalibration,
    *,
    rate_hz: float,
    reference: slice,
    side: str,
    shared_heading: bool = False,
    range_of_motion_prior: bool = True,
    R_sensor_pelvis: FloatArray | None = None,
    quat_smoothed: dict[str, FloatArray] | None = None,
    mag: dict[str, FloatArray] | None = None,
) -> SegmentMotion:
    """Segment orientations and ISB angles from per-sensor orientations.

    Args:
        quat_wxyz: ``{sensor: (N, 4)}`` filter orientations, sensor → earth (heading
            arbitrary per sensor for 6-axis filters).
        acc: ``{sensor: (N, 3)}`` specific force, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity with the bias removed, rad/s.
        calibration: the joint calibration (convert a simulator truth dict with
            :meth:`LegCalibration.from_dict <lowerlimb.calibration.LegCalibration.from_dict>`).
        rate_hz: sampling rate, Hz.
        reference: samples of the standing reference posture.
        side: ``"left"`` or ``"right"``.
        shared_heading: True when the orientations share one heading already
            (9-axis filters): adds :data:`MAG_HEADING_WEIGHT`.
        range_of_motion_prior: run the second, prior-regularised heading pass.
        R_sensor_pelvis: (3, 3) pelvis segment frame in the pelvis sensor given from
            outside (two legs: one pelvis for both); default: from this leg's thigh.
        mag: ``{sensor: (N, 3)}`` the magnetometer, used with ``shared_heading``: the
            field seen from two adjacent sensors measures their relative heading
            (:func:`~lowerlimb.segments.heading.correct_headings`); ``None``: the
            filters' own headings are trusted instead.
        quat_smoothed: ``{sensor: (N, 4)}`` the same orientations with a smoothed
            inclination (forward and backward filter passes), or ``None``. The heading
            corrections are found on ``quat_wxyz`` and applied to these: on the forward
            pass the standing reference is the one a causal run gives (found on the
            smoothed ones they moved the real walk's one-leg pelvis frame by 1.3°, and
            6-axis squats' and sit-to-stands' ankles either way).
    """
    w_common = MAG_HEADING_WEIGHT if shared_heading else 0.0

    def applied(qc: dict[str, FloatArray], corr: HeadingCorrection) -> dict[str, FloatArray]:
        """The corrections on the two-pass orientations (``qc``, the corrected input, without them)."""
        if quat_smoothed is None:
            return qc
        smoothed = quat_smoothed
        return {s: rotate_about_vertical(np.asarray(smoothed[s], float), corr.delta_rad[s]) for s in SENSORS}

    qc, corr = correct_headings(
        quat_wxyz, acc, gyr, calibration, rate_hz, common_heading_weight=w_common, mag=mag
    )
    qc = applied(qc, corr)
    frames = segment_frames(
        calibration, {s: mean_quaternion(qc[s][reference]) for s in SENSORS}, side, R_sensor_pelvis
    )
    if range_of_motion_prior:
        qc, corr = correct_headings(
            quat_wxyz,
            acc,
            gyr,
            calibration,
            rate_hz,
            R_sensor_segment=frames.R_sensor_segment,
            common_heading_weight=w_common,
            mag=mag,
        )
        qc = applied(qc, corr)
        frames = segment_frames(
            calibration, {s: mean_quaternion(qc[s][reference]) for s in SENSORS}, side, R_sensor_pelvis
        )
    seg = frames.segment_quaternions(qc)
    angles = compute_joint_angles(seg, side)
    return SegmentMotion(frames, qc, seg, np.asarray(angles), corr)
