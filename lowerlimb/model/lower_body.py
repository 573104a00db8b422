"""One URDF of the lower body: a pelvis, a lumped upper body and both legs, on a z-up (REP 103) base.

:func:`lower_body_urdf` writes the tree

``base_link (REP 103: x forward, y left, z up) ─fixed→ pelvis (ISB: x anterior, y up, z right)``
``pelvis ─fixed→ trunk`` (head, arms and trunk above the pelvis, de Leva 1996, :mod:`.trunk`)
``pelvis → left_hip (Z-X-Y) → left_thigh → left_knee → left_shank → left_ankle → left_foot``
``pelvis → right_hip … → right_foot``

Each leg is built by :meth:`LegGeometry.to_robot` (so its three revolute DOFs per
joint carry :data:`lowerlimb.conventions.JOINT_AXIS_SIGNS`, and the joint
coordinates are the clinical ISB angles in radians on both sides) and renamed
with its side: joints ``left_hip_flexion`` … ``right_ankle_internal_rotation``
(the ``angles.csv`` two-leg columns), links ``left_thigh`` …, and the IMU frames,
fixed links named after the seven-sensor trial columns:

``imu_pelvis, imu_left_thigh, imu_left_shank, imu_left_foot, imu_right_thigh,
imu_right_shank, imu_right_foot``.

The base is the root link: Pinocchio adds its free flyer there and MuJoCo welds
it to the world, and since its z axis is up, both tools' default gravity
(0, 0, −9.81) is right. The pelvis frame is the left leg's; the right leg's hip
is moved into it through the pelvis sensor, which both legs share.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace

import numpy as np
import yourdfpy

from ..conventions import JOINT_DOF_NAMES, JOINTS, SENSORS, SIDES, FloatArray
from .anthropometry import ankle_height_m
from .geometry import MUJOCO_COMPILER, LegGeometry, transform, translation
from .joint_limits import LIMITS_SOURCE_COMMENT, joint_limits
from .trunk import TrunkInertia, trunk_inertia

#: The root link, REP 103 axes (x forward, y left, z up), at the pelvis origin (mid-hip).
BASE_LINK = "base_link"
#: The seven sensors of a two-leg trial, in the trial CSV's order.
LOWER_BODY_SENSORS: tuple[str, ...] = ("pelvis",) + tuple(
    f"{side}_{s}" for side in SIDES for s in SENSORS if s != "pelvis"
)
#: The fixed IMU link of each sensor.
IMU_LINKS: dict[str, str] = {s: f"imu_{s}" for s in LOWER_BODY_SENSORS}
#: The 18 revolute joints, in configuration order (left leg, then right leg).
LOWER_BODY_DOF_NAMES: tuple[str, ...] = tuple(
    f"{side}_{dof}" for side in SIDES for j in JOINTS for dof in JOINT_DOF_NAMES[j]
)
#: Rotation (3, 3) mapping pelvis (ISB) coordinates to base (REP 103) coordinates.
R_BASE_PELVIS: FloatArray = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])

_NUMERIC_ATTRIBUTES = frozenset(
    "xyz rpy size radius length value ixx ixy ixz iyy iyz izz effort velocity lower upper rgba".split()
)


@dataclass
class LowerBodyGeometry:
    """Both legs of one subject and the body they hang from.

    Attributes:
        left, right: the two legs; each leg's ``pelvis`` sensor placement is the
            pose of the one shared pelvis sensor in that leg's pelvis frame.
        height_m, mass_kg: stature and body mass (pelvis and trunk inertias, joint efforts).
    """

    left: LegGeometry
    right: LegGeometry
    height_m: float
    mass_kg: float

    @classmethod
    def from_anthropometry(cls, height_m: float = 1.75, mass_kg: float = 75.0) -> LowerBodyGeometry:
        """Template lower body scaled from stature and mass (de Leva 1996); IMUs at segment origins."""
        return cls(
            LegGeometry.from_anthropometry("left", height_m, mass_kg),
            LegGeometry.from_anthropometry("right", height_m, mass_kg),
            height_m,
            mass_kg,
        )

    @property
    def trunk(self) -> TrunkInertia:
        """The upper body lumped on the ``trunk`` link."""
        return trunk_inertia(self.height_m, self.mass_kg)

    def right_pelvis_in_left_pelvis(self) -> FloatArray:
        """(4, 4) pose of the right leg's pelvis frame in the left leg's (identity for templates)."""
        T_l = self.left.sensor_placements["pelvis"]
        T_r = self.right.sensor_placements["pelvis"]
        return np.asarray(T_l @ np.linalg.inv(T_r))

    def hip_origin(self, side: str) -> FloatArray:
        """(4, 4) hip joint frame of one side in the left leg's pelvis frame; translation = hip centre, m."""
        if side == "left":
            return np.asarray(self.left.joint_origins["hip"])
        return np.asarray(self.right_pelvis_in_left_pelvis() @ self.right.joint_origins["hip"])

    # ------------------------------------------------------------------ URDF

    def to_robot(self) -> yourdfpy.Robot:
        """The yourdfpy ``Robot``: base, pelvis (+ its IMU), trunk, then each leg renamed by side."""
        left_robot = self.left.to_robot()
        pelvis = next(lk for lk in left_robot.links if lk.name == "pelvis")
        pelvis_imu = [lk for lk in left_robot.links if lk.name == "imu_pelvis"]
        links = [_massless(BASE_LINK), _with_collision(pelvis, self._pelvis_collision()), *pelvis_imu]
        joints = [
            yourdfpy.Joint(
                name="base_to_pelvis",
                type="fixed",
                parent=BASE_LINK,
                child="pelvis",
                origin=transform(R_BASE_PELVIS, np.zeros(3)),
            ),
            next(j for j in left_robot.joints if j.name == "imu_pelvis_joint"),
        ]
        trunk_link, trunk_joint = self._trunk()
        links.append(trunk_link)
        joints.append(trunk_joint)
        limits = joint_limits(self.mass_kg)
        for side, leg in (("left", self.left), ("right", self.right)):
            leg_links, leg_joints = _side_chain(leg, side, self.hip_origin(side), limits)
            links += leg_links
            joints += leg_joints
        return yourdfpy.Robot(
            name="lowerlimb_lower_body", links=links, joints=joints, materials=left_robot.materials
        )

    def _pelvis_collision(self) -> yourdfpy.Collision:
        """A box from the hip centres up to the omphalion, as wide as the hips plus a thigh."""
        L = self.left.inertias["pelvis"].length_m
        spacing = float(np.linalg.norm(self.hip_origin("left")[:3, 3] - self.hip_origin("right")[:3, 3]))
        size = np.array([L, L, spacing + 2.0 * _radius("thigh", self.left)])
        return yourdfpy.Collision(
            name="pelvis_collision",
            origin=translation([0.0, 0.5 * L, 0.0]),
            geometry=yourdfpy.Geometry(box=yourdfpy.Box(size)),
        )

    def _trunk(self) -> tuple[yourdfpy.Link, yourdfpy.Joint]:
        """The lumped upper body on a fixed joint at the top of the pelvis segment."""
        trunk = self.trunk
        inertia = trunk.inertia
        torso = 0.6 * trunk.height_m
        head_r = 0.2 * trunk.height_m
        collisions = [
            yourdfpy.Collision(
                name="trunk_collision",
                origin=translation([0.0, 0.5 * torso, 0.0]),
                geometry=yourdfpy.Geometry(
                    box=yourdfpy.Box(np.array([0.11 * self.height_m, torso, 0.8 * trunk.shoulder_width_m]))
                ),
            ),
            yourdfpy.Collision(
                name="head_collision",
                origin=translation([0.0, trunk.height_m - head_r, 0.0]),
                geometry=yourdfpy.Geometry(sphere=yourdfpy.Sphere(radius=head_r)),
            ),
        ]
        link = yourdfpy.Link(
            name="trunk",
            inertial=yourdfpy.Inertial(
                origin=translation(inertia.com_m), mass=inertia.mass_kg, inertia=inertia.inertia_kgm2
            ),
            collisions=collisions,
        )
        joint = yourdfpy.Joint(
            name="pelvis_to_trunk",
            type="fixed",
            parent="pelvis",
            child="trunk",
            origin=translation([0.0, self.left.inertias["pelvis"].length_m, 0.0]),
        )
        return link, joint

    def to_urdf_string(self) -> str:
        """The URDF XML: pretty-printed, with comments on the conventions, the trunk and the limits."""
        urdf = yourdfpy.URDF(robot=self.to_robot(), build_scene_graph=False, load_meshes=False)
        raw = urdf.write_xml_string()
        text = raw.decode("utf-8") if isinstance(raw, bytes) else str(raw)
        return _pretty(text, self._comments())

    def write_urdf(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_urdf_string` to ``path``."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.to_urdf_string())

    def _comments(self) -> dict[str, str]:
        trunk = self.trunk
        pelvis = self.left.inertias["pelvis"]
        legs = sum(
            leg.inertias[s].mass_kg for leg in (self.left, self.right) for s in ("thigh", "shank", "foot")
        )
        return {
            "header": (
                f" lowerlimb lower body, {self.height_m:g} m, {self.mass_kg:g} kg. Root link {BASE_LINK}: "
                "ROS REP 103 axes (x forward, y left, z up), so the default gravity (0 0 -9.81) is right; "
                "segment links use ISB axes (x anterior, y superior, z right). Revolute joints "
                "<side>_<angle> are the clinical ISB angles in rad (flexion, adduction, internal rotation "
                "positive on both sides; Z-X-Y). IMU frames (fixed links): "
                + ", ".join(IMU_LINKS.values())
                + ". Inertias: de Leva 1996 (J Biomech 29:1223), Table 4, male. "
            ),
            "trunk": (
                f" Upper body (head, arms, upper and middle trunk) lumped on one fixed link: "
                f"{trunk.inertia.mass_kg:.2f} kg = {100 * trunk.mass_fraction:.2f} % of body mass "
                "(de Leva 1996: head 6.94, upper trunk 15.96, middle trunk 16.33, 2 x (upper arm 2.71, "
                "forearm 1.62, hand 0.61) %), arms hanging. Pelvis = de Leva lower trunk "
                f"{pelvis.mass_kg:.2f} kg; legs {legs:.2f} kg. "
            ),
            "limits": LIMITS_SOURCE_COMMENT,
        }


def lower_body_urdf(left: LegGeometry, right: LegGeometry, *, height_m: float, mass_kg: float) -> str:
    """URDF XML of one model with a pelvis, the upper body and both legs (see the module docstring).

    Args:
        left: the calibrated (or template) left leg.
        right: the right leg; its pelvis sensor is the left leg's.
        height_m: stature, m (pelvis and trunk inertias).
        mass_kg: body mass, kg (pelvis and trunk inertias, joint effort limits).

    Raises:
        ValueError: when a leg is given on the wrong side, or height/mass are implausible.
    """
    if left.side != "left" or right.side != "right":
        raise ValueError(f"give the left leg first and the right leg second (got {left.side}, {right.side})")
    return LowerBodyGeometry(left, right, height_m, mass_kg).to_urdf_string()


# ---------------------------------------------------------------------- helpers


def _side_chain(
    leg: LegGeometry, side: str, hip_origin: FloatArray, limits: dict[str, tuple[float, float]]
) -> tuple[list[yourdfpy.Link], list[yourdfpy.Joint]]:
    """One leg's links and joints (:meth:`LegGeometry.to_robot`) renamed ``<side>_…``, without its pelvis."""
    robot = leg.to_robot()
    own = {lk.name for lk in robot.links} - {"pelvis", "imu_pelvis"}

    def rename(name: str) -> str:
        if name not in own:
            return name
        return f"imu_{side}_{name[4:]}" if name.startswith("imu_") else f"{side}_{name}"

    links = [
        _with_collision(
            replace(
                lk, name=rename(lk.name), visuals=[replace(v, name=f"{side}_{v.name}") for v in lk.visuals]
            ),
            _segment_collision(leg, lk.name),
        )
        for lk in robot.links
        if lk.name in own
    ]
    joints: list[yourdfpy.Joint] = []
    for j in robot.joints:
        if j.child not in own:
            continue
        new = replace(j, parent=rename(j.parent), child=rename(j.child))
        if j.type == "revolute":
            effort, velocity = limits[j.name]
            new = replace(
                new, name=f"{side}_{j.name}", limit=replace(j.limit, effort=effort, velocity=velocity)
            )
            if j.name == JOINT_DOF_NAMES["hip"][0]:
                new = replace(new, origin=np.array(hip_origin, dtype=float))
        else:
            new = replace(new, name=f"imu_{side}_{j.name[4:]}")
        joints.append(new)
    return links, joints


def _radius(segment: str, leg: LegGeometry) -> float:
    """Collision radius of a thigh or shank, m: a fraction of its length."""
    return (0.12 if segment == "thigh" else 0.09) * leg.inertias[segment].length_m


def _segment_collision(leg: LegGeometry, segment: str) -> yourdfpy.Collision | None:
    """Thigh and shank: cylinders clear of the joints; foot: a box from heel to toe; else none."""
    if segment in ("thigh", "shank"):
        L = leg.inertias[segment].length_m
        geometry = yourdfpy.Geometry(cylinder=yourdfpy.Cylinder(radius=_radius(segment, leg), length=0.8 * L))
        rx90 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
        origin = transform(rx90, [0.0, -0.5 * L, 0.0])
    elif segment == "foot":
        L = leg.inertias["foot"].length_m
        h = ankle_height_m(leg.height_m)
        geometry = yourdfpy.Geometry(box=yourdfpy.Box(np.array([L, h, 0.38 * L])))
        origin = translation([0.5 * L - 0.22 * L, -0.5 * h, 0.0])
    else:
        return None
    return yourdfpy.Collision(name=f"{leg.side}_{segment}_collision", origin=origin, geometry=geometry)


def _with_collision(link: yourdfpy.Link, collision: yourdfpy.Collision | None) -> yourdfpy.Link:
    return link if collision is None else replace(link, collisions=[*link.collisions, collision])


def _massless(name: str) -> yourdfpy.Link:
    """A link with the tiny positive inertia that Pinocchio and MuJoCo accept."""
    return yourdfpy.Link(
        name=name, inertial=yourdfpy.Inertial(origin=np.eye(4), mass=1e-4, inertia=1e-8 * np.eye(3))
    )


def _format_number(text: str) -> str:
    """``'-3.1e-18'`` → ``'0'``, ``'0.30000000000000004'`` → ``'0.3'`` (12 significant digits)."""
    x = float(text)
    if abs(x) < 1e-12:
        return "0"
    return f"{x:.12g}"


def _pretty(text: str, comments: dict[str, str]) -> str:
    """Indented XML with tidy numbers, the comments and MuJoCo's compiler options."""
    root = ET.fromstring(text)
    for element in root.iter():
        for key, value in element.attrib.items():
            if key in _NUMERIC_ATTRIBUTES:
                try:
                    element.set(key, " ".join(_format_number(v) for v in value.split()))
                except ValueError:
                    continue
    children = list(root)
    first_joint = next(i for i, c in enumerate(children) if c.tag == "joint")
    trunk = next(i for i, c in enumerate(children) if c.tag == "link" and c.get("name") == "trunk")
    root.insert(first_joint, ET.Comment(comments["limits"]))
    root.insert(trunk, ET.Comment(comments["trunk"]))
    root.insert(0, ET.Comment(comments["header"]))
    # MuJoCo merges fixed links (the IMUs, the pelvis, the trunk) into their parents unless told not to
    root.append(ET.fromstring(MUJOCO_COMPILER))
    ET.indent(root, space="  ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
