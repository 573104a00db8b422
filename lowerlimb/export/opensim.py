"""OpenSim writers: joint angles as a ``.mot`` and sensor orientations as an OpenSense ``.sto``.

Joint angles → Rajagopal 2015 / gait2392 coordinates
-----------------------------------------------------
Checked against the joint definitions in ``Rajagopal_2015.osim`` (OpenSense
example model; ``tests/test_export_opensim.py`` rebuilds its joint rotations
from the XML and decomposes them with our conventions). Both the model's
body frames and our ISB segment frames are x anterior, y superior, z right
for both legs.

* ``hip_{r,l}`` is a CustomJoint whose three rotations are body-fixed about
  z, x, y of the pelvis frame — the same Z-X-Y Cardan sequence as ours. On
  the left, the model multiplies adduction and rotation by −1 (its
  LinearFunction coefficients), exactly as our ``JOINT_AXIS_SIGNS`` do, so
  ``hip_flexion_*``, ``hip_adduction_*`` and ``hip_rotation_*`` equal our
  hip flexion, adduction and internal rotation, with the same clinical signs,
  on both sides.
* ``walker_knee_{r,l}`` has one coordinate, ``knee_angle_*`` (+ = flexion),
  about an axis 4° off the femur's z axis, with internal rotation and
  adduction *coupled to it by splines* (about +6.5° internal rotation and +1°
  adduction at 29° flexion). Our ``knee_flexion`` goes to ``knee_angle_*``;
  our knee adduction and internal rotation have no coordinate and are not
  written.
* ``ankle_{r,l}`` is a pin joint about an oblique talocrural axis;
  ``ankle_angle_*`` + = dorsiflexion (0.3 rad reads as 16.8° dorsiflexion,
  −2.2° inversion, −2.7° internal rotation in our decomposition). Our
  ``ankle_dorsiflexion`` goes to it.
* ``subtalar_{r,l}`` is a pin joint about the oblique subtalar axis;
  ``subtalar_angle_*`` + = inversion, but it also turns the foot inward
  (0.3 rad reads as 13.3° inversion, 10.8° internal rotation, −3.4°
  dorsiflexion). Our ``ankle_inversion`` (about the floating anterior axis) is
  written as ``subtalar_angle_*``: an approximation. Our
  ``ankle_internal_rotation`` has no coordinate of its own and is not written.
* ``mtp_angle_*``, the pelvis and the lumbar coordinates are not written
  (no sensor measures them); OpenSim keeps their defaults.

Zero: our angles are zero in the standing reference posture; the model's
coordinates are zero with all body frames parallel. Expect constant offsets
(segment frame definitions differ): compare with ``lowerlimb compare
--remove-offset`` or subtract a standing value.

========================  =========================  =====  =====================
lowerlimb (angles.csv)    OpenSim coordinate         sign   exact?
========================  =========================  =====  =====================
hip_flexion               hip_flexion_{r,l}          +1     yes (same Z-X-Y)
hip_adduction             hip_adduction_{r,l}        +1     yes
hip_internal_rotation     hip_rotation_{r,l}         +1     yes
knee_flexion              knee_angle_{r,l}           +1     axis 4° off; coupled
knee_adduction            —                                 no coordinate
knee_internal_rotation    —                                 no coordinate (spline)
ankle_dorsiflexion        ankle_angle_{r,l}          +1     oblique axis
ankle_inversion           subtalar_angle_{r,l}       +1     oblique axis, approx.
ankle_internal_rotation   —                                 no coordinate
========================  =========================  =====  =====================

Orientations → OpenSense
------------------------
OpenSense reads a quaternion table (``DataType=Quaternion``), one column per
IMU frame named ``<body>_imu`` (``pelvis_imu``, ``femur_l_imu``,
``tibia_l_imu``, ``calcn_l_imu`` …), each cell ``w,x,y,z`` of the sensor →
world rotation. OpenSim's world is y up (x forward, z right), while ours is
ENU, z up. OpenSense's IMU tools carry a ``sensor_to_opensim_rotations``
setting that pre-multiplies every orientation; its usual value for z-up
IMU data is −90° about x (``-1.5707963 0 0``), which maps z (up) → y, y
(north) → −z and keeps x (east). :func:`write_orientations_sto` applies that
same rotation by default (``world="opensim"``): set
``sensor_to_opensim_rotations`` to ``0 0 0`` when you use its file. With
``world="enu"`` the quaternions are written as estimated and the usual −90°
setting applies. The heading is arbitrary either way: OpenSense's IMU placer
aligns it with ``base_imu_label`` (pelvis) and ``base_heading_axis``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ..conventions import FloatArray, quat_multiply
from ..errors import InputError, ShapeError
from .names import split_side

#: Our angle name -> (OpenSim coordinate stem, sign). Coordinate = ``<stem>_<r|l>``,
#: value = sign × our angle (degrees). Verified against Rajagopal_2015.osim.
OPENSIM_COORDINATES: dict[str, tuple[str, float]] = {
    "hip_flexion": ("hip_flexion", 1.0),
    "hip_adduction": ("hip_adduction", 1.0),
    "hip_internal_rotation": ("hip_rotation", 1.0),
    "knee_flexion": ("knee_angle", 1.0),
    "ankle_dorsiflexion": ("ankle_angle", 1.0),
    "ankle_inversion": ("subtalar_angle", 1.0),
}
#: Our angles that have no coordinate in the Rajagopal/gait2392 models.
UNMAPPED_ANGLES: tuple[str, ...] = ("knee_adduction", "knee_internal_rotation", "ankle_internal_rotation")

#: Our sensor -> OpenSense IMU frame stem (``pelvis_imu`` has no side).
OPENSENSE_IMUS: dict[str, str] = {"pelvis": "pelvis", "thigh": "femur", "shank": "tibia", "foot": "calcn"}

#: Rotation from our ENU (z-up) earth frame to OpenSim's y-up world: −90° about x, ``w, x, y, z``.
Q_OPENSIM_FROM_ENU: FloatArray = np.array([np.sqrt(0.5), -np.sqrt(0.5), 0.0, 0.0])

_SIDE_SUFFIX = {"left": "l", "right": "r"}


@dataclass(frozen=True)
class OpenSimTable:
    """What an OpenSim writer wrote.

    Attributes:
        path: the file.
        columns: column labels after ``time``, in file order.
        not_written: input names that have no OpenSim counterpart (skipped).
    """

    path: str
    columns: tuple[str, ...]
    not_written: tuple[str, ...] = ()


def opensim_coordinate(angle: str, side: str = "left") -> tuple[str, float] | None:
    """OpenSim coordinate name and sign of one of our angle columns, or None when unmapped.

    Args:
        angle: ``angles.csv`` column, e.g. ``"knee_flexion"`` or ``"right_knee_flexion"``.
        side: side of unprefixed names.

    Raises:
        InputError: when ``angle`` is not one of our angle names.
    """
    s, base = split_side(angle, side)
    if base in UNMAPPED_ANGLES:
        return None
    if base not in OPENSIM_COORDINATES:
        known = ", ".join(list(OPENSIM_COORDINATES) + list(UNMAPPED_ANGLES))
        raise InputError(f"'{angle}' is not a lowerlimb angle; use one of {known} (optionally left_/right_)")
    stem, sign = OPENSIM_COORDINATES[base]
    return f"{stem}_{_SIDE_SUFFIX[s]}", sign


def write_mot(
    path: str | os.PathLike[str],
    time_s: ArrayLike,
    angles_deg: Mapping[str, ArrayLike],
    side: str = "left",
    *,
    name: str = "lowerlimb_angles",
) -> OpenSimTable:
    """Write joint angles as an OpenSim motion file (``.mot``, Storage version 1).

    Format: a name line, ``version=1``, ``nRows=<N>``, ``nColumns=<1+C>``
    (time included), ``inDegrees=yes``, ``endheader``, then a tab-separated
    header ``time <coordinates…>`` and N rows. Names and signs follow
    :data:`OPENSIM_COORDINATES` (module docstring); angles without a
    coordinate are skipped and listed in the result. NaN is written as
    ``NaN``, which OpenSim reads.

    Args:
        path: file to write (``.mot``).
        time_s: (N,) sample times, s, strictly increasing.
        angles_deg: our angle name -> (N,) angle, DEGREES, clinical signs
            (``angles.csv`` columns; ``left_``/``right_`` prefixes for two legs).
        side: side of unprefixed names (``"left"`` or ``"right"``).
        name: the first header line (the table's name in OpenSim).

    Returns:
        The coordinates written and the angles skipped.

    Raises:
        InputError: an unknown angle name, no mappable angle, or non-increasing time.
        ShapeError: an angle's length differs from ``time_s``.
    """
    t = _time(time_s)
    labels: list[str] = []
    cols: list[FloatArray] = []
    skipped: list[str] = []
    for angle, values in angles_deg.items():
        mapped = opensim_coordinate(angle, side)
        if mapped is None:
            skipped.append(angle)
            continue
        coordinate, sign = mapped
        if coordinate in labels:
            raise InputError(f"two inputs map to {coordinate}; pass each angle once")
        labels.append(coordinate)
        cols.append(sign * _series(values, t.size, angle))
    if not labels:
        raise InputError("none of the given angles has an OpenSim coordinate; pass hip, knee or ankle angles")
    data = np.column_stack([t, *cols])
    header = [name, "version=1", f"nRows={t.size}", f"nColumns={data.shape[1]}", "inDegrees=yes", "endheader"]
    _write_rows(path, header, ["time", *labels], [[_num(v) for v in row] for row in data])
    return OpenSimTable(str(path), tuple(labels), tuple(skipped))


def write_orientations_sto(
    path: str | os.PathLike[str],
    time_s: ArrayLike,
    quats_wxyz: Mapping[str, ArrayLike],
    side: str = "left",
    *,
    world: Literal["opensim", "enu"] = "opensim",
) -> OpenSimTable:
    """Write sensor orientations as an OpenSense quaternion table (``.sto``, version 3).

    Format: ``DataRate=<Hz>``, ``DataType=Quaternion``, ``version=3``,
    ``OpenSimVersion=4.5``, ``nRows=<N>``, ``nColumns=<1+S>`` (time
    included), ``endheader``, a tab-separated header ``time <imu…>`` and N
    rows whose cells are ``w,x,y,z``. IMU labels: pelvis → ``pelvis_imu``,
    thigh → ``femur_<l|r>_imu``, shank → ``tibia_<l|r>_imu``, foot →
    ``calcn_<l|r>_imu``.

    Args:
        path: file to write (``.sto``).
        time_s: (N,) sample times, s, strictly increasing.
        quats_wxyz: sensor name (``pelvis``, ``thigh``, ``shank``, ``foot``, or
            ``left_thigh`` … for two legs) -> (N, 4) orientation ``w, x, y, z``
            rotating sensor-frame vectors into our ENU earth frame.
        side: side of unprefixed leg sensors.
        world: ``"opensim"`` rotates the earth frame to OpenSim's y-up world
            (``q_os = q_x(−90°) ⊗ q``; then use ``sensor_to_opensim_rotations
            = 0 0 0``); ``"enu"`` writes ``q`` unchanged (then the usual
            ``-1.5707963 0 0``).

    Returns:
        The IMU labels written.

    Raises:
        InputError: an unknown sensor name, a duplicate IMU, non-increasing time or a bad ``world``.
        ShapeError: an orientation array is not (N, 4).
    """
    if world not in ("opensim", "enu"):
        raise InputError(f"world must be 'opensim' or 'enu', got {world!r}")
    t = _time(time_s)
    labels: list[str] = []
    cells: list[list[str]] = []
    for sensor, q in quats_wxyz.items():
        label = opensense_imu_label(sensor, side)
        if label in labels:
            raise InputError(f"two sensors map to {label}; pass each sensor once")
        arr = np.asarray(q, dtype=float)
        if arr.shape != (t.size, 4):
            raise ShapeError(
                f"orientation of '{sensor}' has shape {arr.shape}, expected ({t.size}, 4) w,x,y,z"
            )
        arr = arr / np.linalg.norm(arr, axis=1, keepdims=True)
        if world == "opensim":
            arr = quat_multiply(Q_OPENSIM_FROM_ENU, arr)
        labels.append(label)
        cells.append([",".join(_num(v, 9) for v in row) for row in arr])
    if not labels:
        raise InputError("no orientations given; pass at least the pelvis and one leg sensor")
    rate = (t.size - 1) / (t[-1] - t[0])
    header = [
        f"DataRate={rate:.6f}",
        "DataType=Quaternion",
        "version=3",
        "OpenSimVersion=4.5",
        f"nRows={t.size}",
        f"nColumns={len(labels) + 1}",
        "endheader",
    ]
    rows = [[_num(t[i]), *(c[i] for c in cells)] for i in range(t.size)]
    _write_rows(path, header, ["time", *labels], rows)
    return OpenSimTable(str(path), tuple(labels))


def opensense_imu_label(sensor: str, side: str = "left") -> str:
    """OpenSense IMU frame label of one of our sensors (``"left_shank"`` -> ``"tibia_l_imu"``).

    Raises:
        InputError: when ``sensor`` is not one of ours.
    """
    s, base = split_side(sensor, side)
    if base not in OPENSENSE_IMUS:
        raise InputError(
            f"'{sensor}' is not a lowerlimb sensor; use pelvis, thigh, shank, foot (optionally left_/right_)"
        )
    if base == "pelvis":
        return "pelvis_imu"
    return f"{OPENSENSE_IMUS[base]}_{_SIDE_SUFFIX[s]}_imu"


def _time(time_s: ArrayLike) -> FloatArray:
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError(
            "time must be (N,) finite and strictly increasing with N >= 2; sort it and drop repeats"
        )
    return t


def _series(values: ArrayLike, n: int, name: str) -> FloatArray:
    v = np.asarray(values, dtype=float)
    if v.shape != (n,):
        raise ShapeError(f"'{name}' has shape {v.shape}, expected ({n},) like time")
    return v


def _num(v: float, digits: int = 8) -> str:
    return "NaN" if not np.isfinite(v) else f"{v:.{digits}g}"


def _write_rows(
    path: str | os.PathLike[str], header: list[str], labels: list[str], rows: list[list[str]]
) -> None:
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write("\n".join(header) + "\n")
        f.write("\t".join(labels) + "\n")
        for row in rows:
            f.write("\t".join(row) + "\n")
