"""The subject-specific description of one leg, and its URDF (written and read with yourdfpy).

A :class:`LegGeometry` holds everything that the calibration estimates or the
anthropometric tables supply: joint origins, the knee axis, the IMU placements
and the segment inertias. :meth:`LegGeometry.to_urdf_string` writes the chain

``pelvis → hip (Z-X-Y) → thigh → knee (axis-X-Y) → shank → ankle (Z-X-Y) → foot``

with fixed links ``imu_pelvis``, ``imu_thigh``, ``imu_shank``, ``imu_foot``.
Each anatomical joint is three revolute joints named as the angle columns of
``angles.csv`` (e.g. ``hip_flexion``, ``hip_adduction``,
``hip_internal_rotation``) whose axes carry the signs of
:data:`lowerlimb.conventions.JOINT_AXIS_SIGNS`, so the joint coordinates ARE the
clinical ISB angles in radians. The pelvis is the root link; Pinocchio adds a
free-flyer joint when it loads the model.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass, field, replace
from xml.etree import ElementTree

import numpy as np
import yourdfpy

from ..conventions import (
    JOINT_AXIS_SIGNS,
    JOINT_DOF_NAMES,
    JOINTS,
    SENSORS,
    FloatArray,
    check_side,
)
from ..errors import InputError
from .anthropometry import SegmentInertia, ankle_height_m, hip_spacing_m, segment_inertias

#: Segment that carries each sensor.
SENSOR_SEGMENT = {"pelvis": "pelvis", "thigh": "thigh", "shank": "shank", "foot": "foot"}
#: (parent segment, child segment) of each anatomical joint.
JOINT_SEGMENTS = {
    "hip": ("pelvis", "thigh"),
    "knee": ("thigh", "shank"),
    "ankle": ("shank", "foot"),
}

#: Anatomical ranges of motion (rad) used as URDF joint limits, per joint (flex, add, rot).
JOINT_LIMITS_RAD: dict[str, tuple[tuple[float, float], ...]] = {
    "hip": ((-0.6, 2.4), (-0.8, 0.6), (-0.9, 0.9)),
    "knee": ((-0.3, 2.7), (-0.4, 0.4), (-0.7, 0.7)),
    "ankle": ((-0.9, 0.6), (-0.7, 0.7), (-0.6, 0.6)),
}

#: MuJoCo's URDF extension: keep the fixed IMU links and the visuals as bodies and geoms.
MUJOCO_COMPILER = (
    '<mujoco><compiler fusestatic="false" discardvisual="false" balanceinertia="false"/></mujoco>'
)

_TINY_MASS = 1e-4
_TINY_INERTIA = 1e-8


def translation(p: object) -> FloatArray:
    """4x4 homogeneous transform of a pure translation ``p`` (3,), m."""
    T = np.eye(4)
    T[:3, 3] = np.asarray(p, dtype=float)
    return T


def transform(R: object, p: object) -> FloatArray:
    """4x4 homogeneous transform from a rotation (3, 3) and a translation (3,)."""
    T = np.eye(4)
    T[:3, :3] = np.asarray(R, dtype=float)
    T[:3, 3] = np.asarray(p, dtype=float)
    return T


#: Numbers smaller than this in a URDF are written as 0 (round-off such as -3e-18), m or rad.
URDF_ZERO_BELOW = 1e-12
#: Significant digits of the numbers in a URDF (relative 1e-12: far below the 1e-9 m round trip).
URDF_DIGITS = 12


def _format_number(text: str) -> str:
    """One URDF attribute number: near-zeros and ``-0.0`` as ``0``, else ``URDF_DIGITS`` digits."""
    x = float(text)
    if abs(x) < URDF_ZERO_BELOW:
        return "0"
    return f"{x:.{URDF_DIGITS}g}"


def pretty_urdf(text: str) -> str:
    """Indent a URDF, one element per line, with round-off near-zeros written as 0.

    Args:
        text: URDF XML.

    Returns:
        The same robot, pretty-printed, with an XML declaration.
    """
    root = ElementTree.fromstring(text.split("?>", 1)[1] if text.lstrip().startswith("<?xml") else text)
    for element in root.iter():
        for key, value in element.attrib.items():
            parts = value.split()
            try:
                element.attrib[key] = " ".join(_format_number(p) for p in parts) if parts else value
            except ValueError:
                continue  # a name, not numbers
    ElementTree.indent(root, space="  ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ElementTree.tostring(root, encoding="unicode") + "\n"


@dataclass
class LegGeometry:
    """Subject-specific parameters of one leg, all in SI units.

    Attributes:
        side: ``"left"`` or ``"right"``.
        height_m, mass_kg: subject stature and body mass used for inertias.
        joint_origins: ``{"hip"|"knee"|"ankle": (4, 4)}`` pose of the joint frame
            (child segment frame at zero angles) in the parent segment frame;
            its translation is the joint centre, m.
        knee_axis_in_thigh: (3,) unit knee flexion axis in the knee joint frame
            (= thigh frame rotated by the knee origin), pointing to the right.
        sensor_placements: ``{sensor: (4, 4)}`` pose of each IMU frame in its
            segment frame (rotation maps sensor to segment coordinates).
        inertias: de Leva segment inertias (see :mod:`lowerlimb.model.anthropometry`).
    """

    side: str
    height_m: float
    mass_kg: float
    joint_origins: dict[str, FloatArray]
    knee_axis_in_thigh: FloatArray
    sensor_placements: dict[str, FloatArray]
    inertias: dict[str, SegmentInertia] = field(repr=False)

    @classmethod
    def from_anthropometry(
        cls, side: str = "left", height_m: float = 1.75, mass_kg: float = 75.0
    ) -> LegGeometry:
        """Template leg scaled from stature and mass (de Leva 1996); IMUs at segment origins."""
        side = check_side(side)
        inert = segment_inertias(height_m, mass_kg)
        lateral = 1.0 if side == "right" else -1.0
        origins = {
            "hip": translation([0.0, 0.0, lateral * 0.5 * hip_spacing_m(height_m)]),
            "knee": translation([0.0, -inert["thigh"].length_m, 0.0]),
            "ankle": translation([0.0, -inert["shank"].length_m, 0.0]),
        }
        sensors = {s: np.eye(4) for s in SENSORS}
        return cls(side, height_m, mass_kg, origins, np.array([0.0, 0.0, 1.0]), sensors, inert)

    def copy(self) -> LegGeometry:
        """Deep copy (arrays copied)."""
        return replace(
            self,
            joint_origins={k: v.copy() for k, v in self.joint_origins.items()},
            knee_axis_in_thigh=self.knee_axis_in_thigh.copy(),
            sensor_placements={k: v.copy() for k, v in self.sensor_placements.items()},
        )

    # ------------------------------------------------------------------ URDF

    def to_robot(self) -> yourdfpy.Robot:
        """The yourdfpy ``Robot`` of this leg (see the module docstring for its structure).

        Stages: the pelvis link; per joint, its three revolute DOFs with their
        intermediate links and the distal segment (:meth:`_joint_chain`); per
        sensor, an IMU link on a fixed joint (:meth:`_imu_link`, :meth:`_imu_joint`).
        """
        side = check_side(self.side)
        links: list[yourdfpy.Link] = [self._segment_link("pelvis")]
        joints: list[yourdfpy.Joint] = []
        for joint in JOINTS:
            chain_links, chain_joints = self._joint_chain(joint, side)
            links += chain_links
            joints += chain_joints
        for sensor in SENSORS:
            links.append(self._imu_link(sensor))
            joints.append(self._imu_joint(sensor))
        return yourdfpy.Robot(
            name=f"lowerlimb_{side}", links=links, joints=joints, materials=[_SEGMENT_MATERIAL, _IMU_MATERIAL]
        )

    def _segment_link(self, name: str) -> yourdfpy.Link:
        """A body segment: its de Leva inertia and a simple visual (cylinder, box)."""
        inertia = self.inertias[name]
        return yourdfpy.Link(
            name=name,
            inertial=yourdfpy.Inertial(
                origin=translation(inertia.com_m),
                mass=inertia.mass_kg,
                inertia=inertia.inertia_kgm2,
            ),
            visuals=[self._segment_visual(name)],
        )

    def _segment_visual(self, name: str) -> yourdfpy.Visual:
        """Thigh and shank: a cylinder along −y; foot: a box; pelvis: a box."""
        L = self.inertias[name].length_m
        if name in ("thigh", "shank"):
            origin = transform(_rx90(), [0.0, -0.5 * L, 0.0])
            radius = 0.045 if name == "thigh" else 0.035
            geometry = yourdfpy.Geometry(cylinder=yourdfpy.Cylinder(radius=radius, length=L))
        elif name == "foot":
            h = ankle_height_m(self.height_m)
            origin = translation([0.5 * L - 0.22 * L, -0.5 * h, 0.0])
            geometry = yourdfpy.Geometry(box=yourdfpy.Box(np.array([L, h, 0.09])))
        else:
            origin = translation([0.0, 0.05, 0.0])
            geometry = yourdfpy.Geometry(box=yourdfpy.Box(np.array([0.12, 0.12, 0.25])))
        return yourdfpy.Visual(
            name=f"{name}_visual", origin=origin, geometry=geometry, material=_SEGMENT_MATERIAL
        )

    def _joint_axes(self, joint: str, side: str) -> list[FloatArray]:
        """The three DOF axes of a joint (flexion, adduction, rotation) with the side's signs."""
        signs = JOINT_AXIS_SIGNS[side][joint]
        if joint == "knee":
            # knee flexion is a negative rotation about the right-pointing axis
            first_axis = signs[0] * _unit(self.knee_axis_in_thigh)
        else:
            first_axis = signs[0] * np.array([0.0, 0.0, 1.0])
        return [first_axis, signs[1] * np.array([1.0, 0.0, 0.0]), signs[2] * np.array([0.0, 1.0, 0.0])]

    def _joint_chain(self, joint: str, side: str) -> tuple[list[yourdfpy.Link], list[yourdfpy.Joint]]:
        """Three revolute DOFs of a joint, two massless intermediate links and the distal segment."""
        parent, child = JOINT_SEGMENTS[joint]
        axes = self._joint_axes(joint, side)
        names = JOINT_DOF_NAMES[joint]
        chain = [parent, f"{names[0]}_link", f"{names[1]}_link", child]
        links: list[yourdfpy.Link] = []
        joints: list[yourdfpy.Joint] = []
        for k, dof in enumerate(names):
            lo, hi = JOINT_LIMITS_RAD[joint][k]
            joints.append(
                yourdfpy.Joint(
                    name=dof,
                    type="revolute",
                    parent=chain[k],
                    child=chain[k + 1],
                    origin=self.joint_origins[joint] if k == 0 else np.eye(4),
                    axis=axes[k],
                    limit=yourdfpy.Limit(effort=400.0, velocity=30.0, lower=lo, upper=hi),
                )
            )
            if k < 2:
                links.append(yourdfpy.Link(name=chain[k + 1], inertial=_tiny_inertial()))
            else:
                links.append(self._segment_link(child))
        return links, joints

    def _imu_link(self, sensor: str) -> yourdfpy.Link:
        """A massless IMU link with a small box visual."""
        return yourdfpy.Link(
            name=f"imu_{sensor}",
            inertial=_tiny_inertial(),
            visuals=[
                yourdfpy.Visual(
                    name=f"imu_{sensor}_visual",
                    origin=np.eye(4),
                    geometry=yourdfpy.Geometry(box=yourdfpy.Box(np.array([0.04, 0.03, 0.015]))),
                    material=_IMU_MATERIAL,
                )
            ],
        )

    def _imu_joint(self, sensor: str) -> yourdfpy.Joint:
        """The fixed joint placing an IMU on its segment."""
        return yourdfpy.Joint(
            name=f"imu_{sensor}_joint",
            type="fixed",
            parent=SENSOR_SEGMENT[sensor],
            child=f"imu_{sensor}",
            origin=self.sensor_placements[sensor],
        )

    def to_urdf_string(self) -> str:
        """URDF XML of this leg (yourdfpy writer)."""
        urdf = yourdfpy.URDF(robot=self.to_robot(), build_scene_graph=False, load_meshes=False)
        raw = urdf.write_xml_string()
        text = raw.decode("utf-8") if isinstance(raw, bytes) else str(raw)
        # MuJoCo merges fixed links (the IMUs, the pelvis) into their parents unless told not to
        end = text.rfind("</robot>")
        return pretty_urdf(text[:end] + MUJOCO_COMPILER + text[end:])

    def write_urdf(self, path: str | os.PathLike[str]) -> None:
        """Write the URDF to ``path``."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.to_urdf_string())

    @classmethod
    def from_urdf(
        cls, source: str | os.PathLike[str], *, height_m: float = 1.75, mass_kg: float = 75.0
    ) -> LegGeometry:
        """Read a leg written by :meth:`to_urdf_string` (a path or an XML string).

        Inertias are read back from the file; ``height_m``/``mass_kg`` are kept
        for reference only.

        Raises:
            InputError: when the URDF is not a lowerlimb leg (missing joints/links).
        """
        text = str(source)
        if text.lstrip().startswith("<"):
            urdf = yourdfpy.URDF.load(io.BytesIO(text.encode()), build_scene_graph=False, load_meshes=False)
        else:
            urdf = yourdfpy.URDF.load(os.fspath(source), build_scene_graph=False, load_meshes=False)
        robot = urdf.robot
        jmap = {j.name: j for j in robot.joints}
        lmap = {lk.name: lk for lk in robot.links}
        needed = [n for j in JOINTS for n in JOINT_DOF_NAMES[j]] + [f"imu_{s}_joint" for s in SENSORS]
        missing = [n for n in needed if n not in jmap]
        if missing:
            raise InputError(
                f"URDF is not a lowerlimb leg: joint '{missing[0]}' is missing; "
                f"export it with lowerlimb (LegGeometry.write_urdf)"
            )
        side = "right" if robot.name.endswith("right") else "left"
        origins = {j: np.array(jmap[JOINT_DOF_NAMES[j][0]].origin, dtype=float) for j in JOINTS}
        sign = JOINT_AXIS_SIGNS[side]["knee"][0]
        knee_axis = sign * _unit(np.array(jmap["knee_flexion"].axis, dtype=float))
        sensors = {s: np.array(jmap[f"imu_{s}_joint"].origin, dtype=float) for s in SENSORS}
        inert = segment_inertias(height_m, mass_kg)
        for seg in ("pelvis", "thigh", "shank", "foot"):
            link = lmap.get(seg)
            if link is not None and link.inertial is not None:
                inert[seg] = SegmentInertia(
                    inert[seg].length_m,
                    float(link.inertial.mass),
                    np.array(link.inertial.origin, dtype=float)[:3, 3],
                    np.array(link.inertial.inertia, dtype=float),
                )
        return cls(side, height_m, mass_kg, origins, knee_axis, sensors, inert)


def _unit(v: FloatArray) -> FloatArray:
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise InputError("the knee axis has zero length; give a unit vector pointing right")
    return np.asarray(v, dtype=float) / n


_SEGMENT_MATERIAL = yourdfpy.Material(name="segment", color=yourdfpy.Color(np.array([0.7, 0.7, 0.75, 1.0])))
_IMU_MATERIAL = yourdfpy.Material(name="imu", color=yourdfpy.Color(np.array([1.0, 0.5, 0.0, 1.0])))


def _tiny_inertial() -> yourdfpy.Inertial:
    """The inertial of a massless link (Pinocchio and MuJoCo want a positive mass)."""
    return yourdfpy.Inertial(origin=np.eye(4), mass=_TINY_MASS, inertia=_TINY_INERTIA * np.eye(3))


def _rx90() -> FloatArray:
    """Rotation taking a URDF cylinder (along z) to lie along y."""
    return np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
