"""The calibrated leg: a :class:`LegModel` built from the calibration and the segment frames.

Segment origins sit at the proximal joint centre (thigh: hip, shank: knee,
foot: ankle); the pelvis keeps the template's hip offset. The knee centre is
taken on the calibrated axis, in the plane through the hip centre normal to
the axis (any point of the axis is a valid hinge centre, docs/methods.md on eq. 16),
and the same shift along the axis is applied in the shank sensor. Because the
segment frames are the ones the joint angles are computed in, the model's
joint coordinates reproduce the measured relative orientations exactly, and
its forward kinematics is Lee & Lee 2022 eq. 2–3.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..conventions import FloatArray
from ..segments.frames import SegmentFrames
from .geometry import LegGeometry, transform, translation
from .leg_model import LegModel

if TYPE_CHECKING:
    from ..calibration import LegCalibration


def knee_center_pair(calibration: LegCalibration) -> tuple[FloatArray, FloatArray]:
    """Knee centre (3,) in the thigh and in the shank sensor, on the axis level with the hip centre."""
    knee, hip = calibration.knee, calibration.hip
    a_t = np.asarray(knee.axis_in_parent_sensor, dtype=float)
    a_s = np.asarray(knee.axis_in_child_sensor, dtype=float)
    a_t, a_s = a_t / np.linalg.norm(a_t), a_s / np.linalg.norm(a_s)
    c_t = np.asarray(knee.center_in_parent_sensor, dtype=float)
    c_s = np.asarray(knee.center_in_child_sensor, dtype=float)
    shift = float((np.asarray(hip.center_in_child_sensor, dtype=float) - c_t) @ a_t)
    # the two centres are one point only up to a shift along the axis; keep their
    # common offset and move both by the same amount
    return c_t + shift * a_t, c_s + shift * a_s


def calibrated_geometry(
    calibration: LegCalibration,
    frames: SegmentFrames,
    *,
    height_m: float = 1.75,
    mass_kg: float = 75.0,
) -> LegGeometry:
    """The subject's :class:`LegGeometry` from a joint calibration and segment frames."""
    geo = LegGeometry.from_anthropometry(frames.side, height_m, mass_kg)
    R = frames.R_sensor_segment
    c_hip_p = np.asarray(calibration.hip.center_in_parent_sensor, dtype=float)
    c_hip_t = np.asarray(calibration.hip.center_in_child_sensor, dtype=float)
    c_knee_t, c_knee_s = knee_center_pair(calibration)
    c_ank_s = np.asarray(calibration.ankle.center_in_parent_sensor, dtype=float)
    c_ank_f = np.asarray(calibration.ankle.center_in_child_sensor, dtype=float)

    hip_origin = geo.joint_origins["hip"][:3, 3]
    geo.sensor_placements = {
        "pelvis": transform(R["pelvis"].T, hip_origin - R["pelvis"].T @ c_hip_p),
        "thigh": transform(R["thigh"].T, -R["thigh"].T @ c_hip_t),
        "shank": transform(R["shank"].T, -R["shank"].T @ c_knee_s),
        "foot": transform(R["foot"].T, -R["foot"].T @ c_ank_f),
    }
    geo.joint_origins["knee"] = translation(R["thigh"].T @ (c_knee_t - c_hip_t))
    geo.joint_origins["ankle"] = translation(R["shank"].T @ (c_ank_s - c_knee_s))
    geo.knee_axis_in_thigh = R["thigh"].T @ np.asarray(calibration.knee.axis_in_parent_sensor, dtype=float)
    geo.knee_axis_in_thigh /= np.linalg.norm(geo.knee_axis_in_thigh)
    return geo


def chain_positions(
    model: LegModel,
    angles_rad: FloatArray,
    s2j: Mapping[str, tuple[FloatArray, FloatArray]] | None = None,
) -> FloatArray:
    """Pelvis→foot sensor and hip→ankle centre vectors (N, 6) in the pelvis sensor frame, m.

    Forward kinematics of the calibrated chain at each sample (pelvis fixed at
    the world origin: only relative positions are observable from IMUs),
    Lee & Lee 2022 eq. 2–3.

    Args:
        model: the calibrated leg (its sensor placements give the segment frames).
        angles_rad: (N, 9) ISB joint angles, rad.
        s2j: optional time-varying segment-to-joint vectors ``{joint: (s_prox
            (N, 3), s_dist (N, 3))}`` in the parent/child sensor frames, m (e.g.
            :meth:`lowerlimb.s2j.S2JModel.predict`). Applied by updating the
            Pinocchio sensor placements and joint origins before each forward
            kinematics; the hip origin in the pelvis stays fixed.
    """
    m, d = model.model, model.data
    fids = {s: model.frame_id(f"imu_{s}") for s in ("pelvis", "thigh", "shank", "foot")}
    hip_j = m.getJointId("hip_flexion")
    knee_j = m.getJointId("knee_flexion")
    ank_j = m.getJointId("ankle_dorsiflexion")
    geo = model.geometry
    R = {s: geo.sensor_placements[s][:3, :3] for s in fids}  # sensor -> segment
    hip_origin = geo.joint_origins["hip"][:3, 3]
    saved = {s: pin.SE3(m.frames[f].placement) for s, f in fids.items()}
    saved_knee, saved_ankle = pin.SE3(m.jointPlacements[knee_j]), pin.SE3(m.jointPlacements[ank_j])
    q = pin.neutral(m)
    n = angles_rad.shape[0]
    out = np.empty((n, 6))
    try:
        for k in range(n):
            if s2j is not None:
                hp, hd = s2j["hip"][0][k], s2j["hip"][1][k]
                kp, kd = s2j["knee"][0][k], s2j["knee"][1][k]
                ap, ad = s2j["ankle"][0][k], s2j["ankle"][1][k]
                t_thigh = -R["thigh"] @ hd
                t_shank = -R["shank"] @ kd
                m.frames[fids["pelvis"]].placement = pin.SE3(R["pelvis"], hip_origin - R["pelvis"] @ hp)
                m.frames[fids["thigh"]].placement = pin.SE3(R["thigh"], t_thigh)
                m.frames[fids["shank"]].placement = pin.SE3(R["shank"], t_shank)
                m.frames[fids["foot"]].placement = pin.SE3(R["foot"], -R["foot"] @ ad)
                m.jointPlacements[knee_j] = pin.SE3(np.eye(3), R["thigh"] @ kp + t_thigh)
                m.jointPlacements[ank_j] = pin.SE3(np.eye(3), R["shank"] @ ap + t_shank)
            q[model.n_root_q :] = angles_rad[k]
            pin.forwardKinematics(m, d, q)
            P = pin.updateFramePlacement(m, d, fids["pelvis"])
            F = pin.updateFramePlacement(m, d, fids["foot"])
            Rt = P.rotation.T
            out[k, :3] = Rt @ (F.translation - P.translation)
            out[k, 3:] = Rt @ (d.oMi[ank_j].translation - d.oMi[hip_j].translation)
    finally:
        for s, f in fids.items():
            m.frames[f].placement = saved[s]
        m.jointPlacements[knee_j], m.jointPlacements[ank_j] = saved_knee, saved_ankle
    return out
