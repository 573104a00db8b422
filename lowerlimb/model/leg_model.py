"""``LegModel``: one leg as a Pinocchio model whose joint coordinates are the ISB angles.

The model is built from a :class:`~lowerlimb.model.geometry.LegGeometry` through
its URDF, so what Pinocchio computes and what the exported URDF describes can
never disagree. Sensor placements and joint origins are changed in place on the
Pinocchio model; a new knee axis rebuilds it (a revolute joint's axis is part of
its type in Pinocchio).

Configuration layout (free-flyer root): ``q = [p_pelvis (3), quat_xyzw (4),
9 joint angles in rad in angles.csv order]``.
"""

from __future__ import annotations

import os

import numpy as np
import pinocchio as pin

from ..conventions import JOINT_DOF_NAMES, JOINTS, SENSORS, FloatArray, quat_from_matrix
from ..errors import InputError
from .geometry import LegGeometry

#: Names of the 9 revolute joints, in configuration order.
DOF_NAMES: tuple[str, ...] = tuple(n for j in JOINTS for n in JOINT_DOF_NAMES[j])


class LegModel:
    """One leg in Pinocchio.

    Args:
        geometry: the subject-specific leg.
        root_joint: Pinocchio joint attaching the pelvis to the world; a free
            flyer by default (the simulator uses a composite joint instead).
    """

    def __init__(self, geometry: LegGeometry, root_joint: pin.JointModel | None = None) -> None:
        self.geometry = geometry.copy()
        self._root = root_joint
        self._build()

    # ------------------------------------------------------------ construction

    @classmethod
    def from_template(cls, side: str = "left", height_m: float = 1.75, mass_kg: float = 75.0) -> LegModel:
        """Anthropometric template (de Leva 1996) with IMUs at the segment origins."""
        return cls(LegGeometry.from_anthropometry(side, height_m, mass_kg))

    @classmethod
    def from_urdf(cls, source: str | os.PathLike[str]) -> LegModel:
        """Load a leg URDF written by lowerlimb (path or XML string)."""
        return cls(LegGeometry.from_urdf(source))

    def _build(self) -> None:
        root = self._root if self._root is not None else pin.JointModelFreeFlyer()
        self.model: pin.Model = pin.buildModelFromXML(self.geometry.to_urdf_string(), root)
        self.data: pin.Data = self.model.createData()
        self._frame_ids = {f.name: i for i, f in enumerate(self.model.frames)}
        self._joint_ids = {n: self.model.getJointId(n) for n in DOF_NAMES}
        self.n_root_q = self.model.nq - len(DOF_NAMES)
        self.n_root_v = self.model.nv - len(DOF_NAMES)

    @property
    def side(self) -> str:
        """``"left"`` or ``"right"``."""
        return self.geometry.side

    def frame_id(self, name: str) -> int:
        """Pinocchio frame index of ``name`` (e.g. ``"imu_thigh"``, ``"shank"``).

        Raises:
            InputError: for an unknown frame, listing the known ones.
        """
        if name not in self._frame_ids:
            raise InputError(f"unknown frame '{name}'; frames are {sorted(self._frame_ids)}")
        return self._frame_ids[name]

    # ------------------------------------------------------------ parameters

    def sensor_placement(self, sensor: str) -> pin.SE3:
        """Pose of the IMU frame in its segment frame."""
        return pin.SE3(self.model.frames[self.frame_id(f"imu_{sensor}")].placement)

    def set_sensor_placement(self, sensor: str, placement: pin.SE3 | FloatArray) -> None:
        """Set the pose (SE3 or 4x4) of an IMU in its segment frame; no rebuild needed."""
        T = placement.homogeneous if isinstance(placement, pin.SE3) else np.asarray(placement, float)
        self.geometry.sensor_placements[sensor] = T.copy()
        self.model.frames[self.frame_id(f"imu_{sensor}")].placement = pin.SE3(T)

    def joint_origin(self, joint: str) -> pin.SE3:
        """Pose of a joint frame (child segment at zero angles) in its parent segment frame."""
        return pin.SE3(self.model.jointPlacements[self._joint_ids[JOINT_DOF_NAMES[joint][0]]])

    def set_joint_origin(self, joint: str, placement: pin.SE3 | FloatArray) -> None:
        """Set a joint origin (SE3 or 4x4) in its parent segment frame; no rebuild needed."""
        T = placement.homogeneous if isinstance(placement, pin.SE3) else np.asarray(placement, float)
        self.geometry.joint_origins[joint] = T.copy()
        self.model.jointPlacements[self._joint_ids[JOINT_DOF_NAMES[joint][0]]] = pin.SE3(T)

    @property
    def knee_axis_in_thigh(self) -> FloatArray:
        """(3,) unit knee flexion axis in the knee joint frame, pointing right."""
        return self.geometry.knee_axis_in_thigh.copy()

    def set_knee_axis(self, axis: FloatArray) -> None:
        """Set the knee axis (3,) in the knee joint frame (pointing right); rebuilds the model."""
        a = np.asarray(axis, dtype=float)
        self.geometry.knee_axis_in_thigh = a / np.linalg.norm(a)
        self._build()

    # ------------------------------------------------------------ kinematics

    def configuration(self, angles_rad: FloatArray, pelvis_pose: pin.SE3 | None = None) -> FloatArray:
        """Configuration ``q`` (nq,) from the 9 joint angles (rad) and the pelvis pose in the world.

        Only valid for the default free-flyer root.
        """
        q = pin.neutral(self.model)
        if pelvis_pose is not None:
            q[:3] = pelvis_pose.translation
            w, x, y, z = quat_from_matrix(pelvis_pose.rotation)
            q[3:7] = [x, y, z, w]
        q[self.n_root_q :] = np.asarray(angles_rad, dtype=float)
        return q

    def frame_poses(self, q: FloatArray, frames: list[str] | tuple[str, ...]) -> dict[str, pin.SE3]:
        """World poses of the named frames at configuration ``q`` (forward kinematics)."""
        pin.framesForwardKinematics(self.model, self.data, np.asarray(q, dtype=float))
        return {f: pin.SE3(self.data.oMf[self.frame_id(f)]) for f in frames}

    def joint_center_world(self, joint: str) -> FloatArray:
        """(3,) world position of a joint centre after the last forward kinematics, m."""
        return np.array(self.data.oMi[self._joint_ids[JOINT_DOF_NAMES[joint][0]]].translation)

    # ------------------------------------------------------------ sensor-frame views

    def joint_center_in_sensor(self, joint: str, sensor: str) -> FloatArray:
        """(3,) joint centre in a sensor frame (docs/conventions.md: sensor origin → centre), m.

        ``sensor`` must be the joint's parent or child sensor; the child's value
        is the zero-posture one (exact for any posture at a hinge or spherical joint).
        """
        from .geometry import JOINT_SEGMENTS

        parent, child = JOINT_SEGMENTS[joint]
        T_seg_sensor = self.geometry.sensor_placements[sensor]
        if sensor == parent:
            c_seg = self.geometry.joint_origins[joint][:3, 3]
        elif sensor == child:
            c_seg = np.zeros(3)
        else:
            raise InputError(f"sensor '{sensor}' is not attached to the {joint}")
        R, p = T_seg_sensor[:3, :3], T_seg_sensor[:3, 3]
        return np.asarray(R.T @ (c_seg - p))

    def knee_axis_in_sensor(self, sensor: str) -> FloatArray:
        """(3,) knee axis (pointing right) in the thigh or shank sensor frame."""
        axis_joint = self.geometry.knee_axis_in_thigh
        T_knee = self.geometry.joint_origins["knee"]
        if sensor == "thigh":
            axis_seg = T_knee[:3, :3] @ axis_joint
        elif sensor == "shank":
            axis_seg = axis_joint
        else:
            raise InputError(f"the knee axis is defined in the thigh or shank sensor, not '{sensor}'")
        return np.asarray(self.geometry.sensor_placements[sensor][:3, :3].T @ axis_seg)

    def calibration_dict(self, method: str = "truth") -> dict[str, object]:
        """The model's joint parameters in the ``calibration.json`` schema (docs/formats.md)."""
        joints: dict[str, object] = {}
        from ..conventions import JOINT_SENSORS

        for joint in JOINTS:
            parent, child, kind = JOINT_SENSORS[joint]
            entry: dict[str, object] = {
                "type": kind,
                "parent_sensor": parent,
                "child_sensor": child,
            }
            if kind == "hinge":
                entry["axis_in_parent_sensor"] = self.knee_axis_in_sensor(parent).tolist()
                entry["axis_in_child_sensor"] = self.knee_axis_in_sensor(child).tolist()
            entry["center_in_parent_sensor"] = self.joint_center_in_sensor(joint, parent).tolist()
            entry["center_in_child_sensor"] = self.joint_center_in_sensor(joint, child).tolist()
            entry["rms_residual"] = 0.0
            joints[joint] = entry
        sensors = {
            s: {
                "segment": s,
                "position_in_segment": self.geometry.sensor_placements[s][:3, 3].tolist(),
                "quat_wxyz_in_segment": quat_from_matrix(self.geometry.sensor_placements[s][:3, :3]).tolist(),
            }
            for s in SENSORS
        }
        return {
            "format": "lowerlimb-calibration/1",
            "side": self.side,
            "method": method,
            "joints": joints,
            "sensors": sensors,
        }

    # ------------------------------------------------------------ export

    def to_urdf_string(self) -> str:
        """URDF XML of the current model."""
        return self.geometry.to_urdf_string()

    def write_urdf(self, path: str | os.PathLike[str]) -> None:
        """Write the current model as a URDF file."""
        self.geometry.write_urdf(path)
