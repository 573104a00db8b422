"""Every convention of the library, defined once and tested in ``tests/test_conventions.py``.

Units
    SI inside: m, s, rad, m/s², rad/s. Degrees only in angle CSV output and
    reports, and then the name says so (``*_deg``).

IMU signals
    Accelerometer = specific force in the sensor frame: ``f = R^T (a - g)``
    with ``g = (0, 0, -9.81)`` in the earth frame, so a sensor at rest reads
    +9.81 m/s² along its "up". Gyroscope = angular velocity of the sensor,
    in its own frame, rad/s.

Quaternions
    Order ``w, x, y, z`` (scalar first), Hamilton product. A sensor
    orientation ``q`` rotates sensor-frame vectors into the earth frame:
    ``v_earth = q ⊗ v_sensor ⊗ q*``. Arrays of quaternions have shape (..., 4).

Earth frame
    ENU: x east, y north, z up. For 6-axis estimates the heading is arbitrary.

Segment frames (ISB)
    x anterior, y superior (proximal), z to the subject's right, for both
    sides. The knee axis is reported as a unit vector pointing to the right.

Joint angles
    ``R_prox_dist = R_z(s_f·flexion) R_x(s_a·adduction) R_y(s_r·rotation)``
    (Hu et al. 2021 eq. 39, corrected as in docs/methods.md), with per-joint/per-side
    signs :data:`JOINT_AXIS_SIGNS` chosen so that the clinical signs hold on
    both sides: hip and knee flexion +, ankle dorsiflexion +,
    adduction/inversion +, internal rotation +. Zero = the standing
    reference posture.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
Side = Literal["left", "right"]

#: Standard gravity used by the simulator and the filters, m/s².
GRAVITY_MPS2 = 9.81
#: Largest plausible angular-rate norm, rad/s (≈ 2000 °/s, the full scale of common
#: IMUs): a gyro whose readings exceed it is taken to be in deg/s.
MAX_GYRO_RAD_S = 35.0
#: An accelerometer whose median norm is below this, m/s², is taken to be in g.
MIN_MEDIAN_ACC_MPS2 = 3.0
#: Gravitational acceleration in the ENU earth frame, m/s².
GRAVITY_ENU = np.array([0.0, 0.0, -GRAVITY_MPS2])

SIDES: tuple[str, ...] = ("left", "right")
SENSORS: tuple[str, ...] = ("pelvis", "thigh", "shank", "foot")
JOINTS: tuple[str, ...] = ("hip", "knee", "ankle")
#: (parent sensor, child sensor, joint type) of each joint.
JOINT_SENSORS: dict[str, tuple[str, str, str]] = {
    "hip": ("pelvis", "thigh", "spherical"),
    "knee": ("thigh", "shank", "hinge"),
    "ankle": ("shank", "foot", "spherical"),
}
#: Segment carrying each sensor, proximal to distal.
SEGMENTS: tuple[str, ...] = ("pelvis", "thigh", "shank", "foot")

#: Names of the three degrees of freedom of each joint, in Z-X-Y order.
JOINT_DOF_NAMES: dict[str, tuple[str, str, str]] = {
    "hip": ("hip_flexion", "hip_adduction", "hip_internal_rotation"),
    "knee": ("knee_flexion", "knee_adduction", "knee_internal_rotation"),
    "ankle": ("ankle_dorsiflexion", "ankle_inversion", "ankle_internal_rotation"),
}
#: Columns of ``angles.csv`` (angles in degrees).
ANGLE_COLUMNS: tuple[str, ...] = ("time",) + tuple(n for j in JOINTS for n in JOINT_DOF_NAMES[j])
#: Columns of ``positions.csv`` (metres, pelvis sensor frame).
POSITION_COLUMNS: tuple[str, ...] = (
    "time",
    "pelvis_to_foot_x",
    "pelvis_to_foot_y",
    "pelvis_to_foot_z",
    "hip_to_ankle_x",
    "hip_to_ankle_y",
    "hip_to_ankle_z",
)

#: Signs (s_f, s_a, s_r) multiplying (flexion, adduction, rotation) to give the
#: rotation angles about the segment z, x, y axes (z right, x anterior, y up).
#: Derivation (right side): a positive rotation about +z swings the distal
#: segment forward, i.e. hip flexion and ankle dorsiflexion but knee
#: extension; about +x it moves the distal end medially (adduction,
#: inversion); about +y it turns the toes medially (internal rotation). On
#: the left side "medial" is +z, which flips adduction and rotation.
JOINT_AXIS_SIGNS: dict[str, dict[str, tuple[float, float, float]]] = {
    "right": {"hip": (1.0, 1.0, 1.0), "knee": (-1.0, 1.0, 1.0), "ankle": (1.0, 1.0, 1.0)},
    "left": {"hip": (1.0, -1.0, -1.0), "knee": (-1.0, -1.0, -1.0), "ankle": (1.0, -1.0, -1.0)},
}


def check_side(side: str) -> Side:
    """Return ``side`` if it is ``"left"`` or ``"right"``.

    Raises:
        ValueError: for any other value.
    """
    if side not in SIDES:
        raise ValueError(f"side must be 'left' or 'right', got {side!r}")
    return side  # type: ignore[return-value]


# --------------------------------------------------------------------------- quaternions


def quat_normalize(q: ArrayLike) -> FloatArray:
    """Unit quaternion(s) ``w, x, y, z``; shape (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quat_conjugate(q: ArrayLike) -> FloatArray:
    """Conjugate (inverse of a unit quaternion), shape (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_multiply(p: ArrayLike, q: ArrayLike) -> FloatArray:
    """Hamilton product ``p ⊗ q`` of ``w, x, y, z`` quaternions, broadcast over (..., 4)."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


def quat_to_matrix(q: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) of unit quaternions (..., 4) ``w, x, y, z``.

    ``R @ v_sensor = v_earth`` for a sensor orientation ``q``.
    """
    q = quat_normalize(q)
    w, x, y, z = np.moveaxis(q, -1, 0)
    R = np.empty(q.shape[:-1] + (3, 3))
    R[..., 0, 0] = 1 - 2 * (y * y + z * z)
    R[..., 0, 1] = 2 * (x * y - w * z)
    R[..., 0, 2] = 2 * (x * z + w * y)
    R[..., 1, 0] = 2 * (x * y + w * z)
    R[..., 1, 1] = 1 - 2 * (x * x + z * z)
    R[..., 1, 2] = 2 * (y * z - w * x)
    R[..., 2, 0] = 2 * (x * z - w * y)
    R[..., 2, 1] = 2 * (y * z + w * x)
    R[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def quat_from_matrix(R: ArrayLike) -> FloatArray:
    """Unit quaternions (..., 4) ``w, x, y, z`` with ``w >= 0`` from rotation matrices (..., 3, 3).

    Shepperd's method: the largest of the four squared components is taken
    first, so the result is accurate for every rotation.
    """
    R = np.asarray(R, dtype=float)
    m00, m11, m22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    tr = m00 + m11 + m22
    cand = np.stack([tr, m00, m11, m22], axis=-1)
    k = np.argmax(cand, axis=-1)
    s = np.sqrt(np.maximum(1.0 + 2.0 * np.take_along_axis(cand, k[..., None], -1)[..., 0] - tr, 1e-300))
    # s = 2 |largest component|
    r21, r12 = R[..., 2, 1], R[..., 1, 2]
    r02, r20 = R[..., 0, 2], R[..., 2, 0]
    r10, r01 = R[..., 1, 0], R[..., 0, 1]
    h = 0.5 * s
    d = 2.0 * s
    q0 = np.stack([h, (r21 - r12) / d, (r02 - r20) / d, (r10 - r01) / d], -1)
    q1 = np.stack([(r21 - r12) / d, h, (r01 + r10) / d, (r02 + r20) / d], -1)
    q2 = np.stack([(r02 - r20) / d, (r01 + r10) / d, h, (r12 + r21) / d], -1)
    q3 = np.stack([(r10 - r01) / d, (r02 + r20) / d, (r12 + r21) / d, h], -1)
    q = np.where(
        (k == 0)[..., None],
        q0,
        np.where((k == 1)[..., None], q1, np.where((k == 2)[..., None], q2, q3)),
    )
    q = quat_normalize(q)
    return np.where(q[..., :1] < 0, -q, q)


def quat_rotate(q: ArrayLike, v: ArrayLike) -> FloatArray:
    """Rotate vectors ``v`` (..., 3) by unit quaternions ``q`` (..., 4): ``q ⊗ v ⊗ q*``."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    u = q[..., 1:]
    w = q[..., :1]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def quat_from_rotvec(rotvec: ArrayLike) -> FloatArray:
    """Quaternions (..., 4) from rotation vectors (..., 3) = axis · angle (rad)."""
    rv = np.asarray(rotvec, dtype=float)
    angle = np.linalg.norm(rv, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(half)/angle, with its limit 1/2 at zero
    k = np.where(angle > 1e-12, np.sin(half) / np.where(angle > 1e-12, angle, 1.0), 0.5 - angle**2 / 48)
    return np.concatenate([np.cos(half), k * rv], axis=-1)


def quat_to_rotvec(q: ArrayLike) -> FloatArray:
    """Rotation vectors (..., 3), angle in [0, π], of unit quaternions (..., 4)."""
    q = quat_normalize(q)
    q = np.where(q[..., :1] < 0, -q, q)
    s = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., :1])
    k = np.where(s > 1e-12, angle / np.where(s > 1e-12, s, 1.0), 2.0)
    return k * q[..., 1:]


def quat_angle(p: ArrayLike, q: ArrayLike) -> FloatArray:
    """Angle (rad, in [0, π]) of the rotation between orientations ``p`` and ``q`` (..., 4)."""
    d = np.abs(np.sum(quat_normalize(p) * quat_normalize(q), axis=-1))
    return 2.0 * np.arccos(np.clip(d, 0.0, 1.0))


def quat_make_continuous(q: ArrayLike) -> FloatArray:
    """Flip signs along axis 0 of a (N, 4) series so consecutive quaternions have positive dot."""
    q = np.array(q, dtype=float)
    dots = np.sum(q[1:] * q[:-1], axis=-1)
    flips = np.concatenate([[1.0], np.cumprod(np.where(dots < 0, -1.0, 1.0))])
    return q * flips[:, None]


# --------------------------------------------------------------------------- rotations


def rot_x(angle: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) about x by ``angle`` rad."""
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rot_y(angle: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) about y by ``angle`` rad."""
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_z(angle: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) about z by ``angle`` rad."""
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def matrix_from_euler_zxy(z: ArrayLike, x: ArrayLike, y: ArrayLike) -> FloatArray:
    """``R = R_z(z) R_x(x) R_y(y)``, shape (..., 3, 3), angles in rad (Hu 2021 eq. 39 fixed)."""
    return rot_z(z) @ rot_x(x) @ rot_y(y)


def euler_zxy_from_matrix(R: ArrayLike) -> FloatArray:
    """Angles (..., 3) = (z, x, y) rad with ``R = R_z(z) R_x(x) R_y(y)``.

    ``x`` is in [-π/2, π/2]; ``z`` and ``y`` in (-π, π]. At the gimbal lock
    ``|x| = π/2`` (Hu et al. eq. 41–42) only ``z ± y`` is defined: ``y`` is
    set to 0 and the whole rotation goes into ``z``.
    """
    R = np.asarray(R, dtype=float)
    cx = np.hypot(R[..., 0, 1], R[..., 1, 1])
    x = np.arctan2(R[..., 2, 1], cx)
    lock = cx < 1e-9
    z = np.where(lock, np.arctan2(R[..., 1, 0], R[..., 0, 0]), np.arctan2(-R[..., 0, 1], R[..., 1, 1]))
    y = np.where(lock, 0.0, np.arctan2(-R[..., 2, 0], R[..., 2, 2]))
    return np.stack([z, x, y], axis=-1)


def joint_angles_from_matrix(R_prox_dist: ArrayLike, joint: str, side: str) -> FloatArray:
    """Clinical joint angles (..., 3) rad = (flexion, adduction, internal rotation).

    Args:
        R_prox_dist: (..., 3, 3) orientation of the distal segment frame in the
            proximal segment frame (maps distal coordinates to proximal).
        joint: ``"hip"``, ``"knee"`` or ``"ankle"``.
        side: ``"left"`` or ``"right"``.
    """
    signs = np.array(JOINT_AXIS_SIGNS[check_side(side)][joint])
    return euler_zxy_from_matrix(R_prox_dist) * signs


def matrix_from_joint_angles(angles: ArrayLike, joint: str, side: str) -> FloatArray:
    """Inverse of :func:`joint_angles_from_matrix`: (..., 3) rad -> (..., 3, 3)."""
    a = np.asarray(angles, dtype=float) * np.array(JOINT_AXIS_SIGNS[check_side(side)][joint])
    return matrix_from_euler_zxy(a[..., 0], a[..., 1], a[..., 2])


def skew(v: ArrayLike) -> FloatArray:
    """Skew-symmetric matrices (..., 3, 3) with ``skew(v) @ u = v × u``."""
    v = np.asarray(v, dtype=float)
    z = np.zeros_like(v[..., 0])
    return np.stack(
        [
            np.stack([z, -v[..., 2], v[..., 1]], -1),
            np.stack([v[..., 2], z, -v[..., 0]], -1),
            np.stack([-v[..., 1], v[..., 0], z], -1),
        ],
        -2,
    )
