"""BIDS-motion export: ``_motion.tsv``, ``_channels.tsv``, ``_motion.json`` and ``_channels.json``.

Follows the BIDS specification's Motion chapter
(``modality-specific-files/motion.md``): one tracking system per file set
named ``sub-<label>[_ses-<label>]_task-<label>_tracksys-<label>_<suffix>``;
``_motion.tsv`` has NO header row, one column per row of ``_channels.tsv``
(same order), ``n/a`` for missing values; ``_channels.tsv`` has the REQUIRED
columns ``name, component, type, tracked_point, units`` and the recommended
``reference_frame``, whose levels ``_channels.json`` describes; ``_motion.json``
has the REQUIRED ``SamplingFrequency``, ``TaskName`` and
``TrackingSystemName`` and the recommended channel counts.

Channels written:

* ``LATENCY`` — time since the first sample, s (our time column).
* ``JNTANG`` — joint angles in deg, ``component`` = the axis of the Z-X-Y
  decomposition: flexion/dorsiflexion ``z``, adduction/inversion ``x``,
  internal rotation ``y``; ``tracked_point`` = the joint (``left_knee``);
  ``reference_frame`` = ``proximal_segment`` (ISB: x anterior, y superior, z right).
* ``POS`` — our position vectors in m, ``component`` x/y/z of the pelvis
  sensor frame; ``tracked_point`` = the end point (``left_foot_sensor``,
  ``left_ankle_centre``); ``reference_frame`` names the origin.
* ``ORNT`` — sensor orientations as quaternions (``quat_w, quat_x, quat_y,
  quat_z``, units ``n/a``) in the ``global`` ENU earth frame.
"""

from __future__ import annotations

import csv
import json
import os
import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from .. import __version__
from ..conventions import JOINT_DOF_NAMES, SENSORS, FloatArray
from ..errors import InputError, ShapeError
from ..io.time_axis import rate_from_stamps
from .names import split_side

#: REQUIRED columns of ``_channels.tsv`` then the recommended ``reference_frame``.
CHANNEL_COLUMNS: tuple[str, ...] = ("name", "component", "type", "tracked_point", "units", "reference_frame")

#: Axis of each degree of freedom in our Z-X-Y decomposition (BIDS ``component``).
DOF_COMPONENT: dict[str, str] = {
    dof: axis for names in JOINT_DOF_NAMES.values() for dof, axis in zip(names, ("z", "x", "y"), strict=True)
}

#: Position vector stem -> (tracked point without side, reference frame origin without side).
POSITION_POINTS: dict[str, tuple[str, str]] = {
    "pelvis_to_foot": ("foot_sensor", "pelvis_sensor"),
    "hip_to_ankle": ("ankle_centre", "hip_centre"),
}

_LABEL = re.compile(r"^[0-9A-Za-z]+$")


@dataclass(frozen=True)
class BidsChannel:
    """One row of ``_channels.tsv`` (fields as the BIDS column names)."""

    name: str
    component: str
    type: str
    tracked_point: str
    units: str
    reference_frame: str


@dataclass(frozen=True)
class BidsMotionFiles:
    """The files :func:`write_bids_motion` wrote and the channels in column order."""

    motion_tsv: Path
    channels_tsv: Path
    motion_json: Path
    channels_json: Path
    channels: tuple[BidsChannel, ...]


def angle_channel(name: str, side: str = "left") -> BidsChannel:
    """The ``JNTANG`` channel of one ``angles.csv`` column (``"left_knee_flexion"`` or unprefixed).

    Raises:
        InputError: when ``name`` is not one of our angle names.
    """
    s, base = split_side(name, side)
    if base not in DOF_COMPONENT:
        raise InputError(f"'{name}' is not a lowerlimb angle; use the angles.csv column names")
    return BidsChannel(
        name, DOF_COMPONENT[base], "JNTANG", f"{s}_{base.split('_')[0]}", "deg", "proximal_segment"
    )


def position_channel(name: str, side: str = "left") -> BidsChannel:
    """The ``POS`` channel of one ``positions.csv`` column.

    Raises:
        InputError: when ``name`` is not one of our position names.
    """
    stem, _, axis = name.rpartition("_")
    if axis not in ("x", "y", "z"):
        raise InputError(f"'{name}' is not a lowerlimb position; use the positions.csv column names")
    if stem == "left_foot_to_right_foot":
        return BidsChannel(name, axis, "POS", "right_foot_sensor", "m", "left_foot_sensor")
    s, base = split_side(stem, side)
    if base not in POSITION_POINTS:
        raise InputError(f"'{name}' is not a lowerlimb position; use the positions.csv column names")
    point, origin = POSITION_POINTS[base]
    origin = origin if origin == "pelvis_sensor" else f"{s}_{origin}"
    return BidsChannel(name, axis, "POS", f"{s}_{point}", "m", origin)


def orientation_channels(sensor: str, side: str = "left") -> list[BidsChannel]:
    """The four ``ORNT`` quaternion channels (w, x, y, z) of one sensor.

    Raises:
        InputError: when ``sensor`` is not one of ours.
    """
    s, base = split_side(sensor, side)
    if base not in SENSORS:
        raise InputError(f"'{sensor}' is not a lowerlimb sensor; use pelvis, thigh, shank, foot")
    point = "pelvis_sensor" if base == "pelvis" else f"{s}_{base}_sensor"
    return [BidsChannel(f"{sensor}_quat_{c}", f"quat_{c}", "ORNT", point, "n/a", "global") for c in "wxyz"]


def write_bids_motion(
    directory: str | os.PathLike[str],
    time_s: ArrayLike,
    *,
    subject: str,
    task: str,
    tracksys: str = "imu",
    session: str | None = None,
    angles_deg: Mapping[str, ArrayLike] | None = None,
    positions_m: Mapping[str, ArrayLike] | None = None,
    quats_wxyz: Mapping[str, ArrayLike] | None = None,
    side: str = "left",
    task_description: str | None = None,
) -> BidsMotionFiles:
    """Write one BIDS-motion tracking system (four files) into ``directory``.

    Args:
        directory: an existing folder (typically ``sub-<label>/motion/``).
        time_s: (N,) sample times, s, strictly increasing.
        subject: BIDS subject label (letters and digits only).
        task: BIDS task label (letters and digits), also written as ``TaskName``.
        tracksys: tracking-system label (letters and digits).
        session: optional session label.
        angles_deg: ``angles.csv`` column -> (N,) joint angle, deg.
        positions_m: ``positions.csv`` column -> (N,) position component, m, pelvis sensor frame.
        quats_wxyz: sensor name -> (N, 4) orientation ``w, x, y, z``, sensor -> ENU earth.
        side: side of unprefixed (one-leg) names.
        task_description: optional ``TaskDescription``.

    Returns:
        The four paths and the channels in column order (a LATENCY channel first).

    Raises:
        InputError: a bad label, an unknown column, no data, a missing folder, bad time.
        ShapeError: an array whose length differs from ``time_s``.
    """
    for what, label in (("subject", subject), ("task", task), ("tracksys", tracksys), ("session", session)):
        if label is not None and not _LABEL.match(label):
            raise InputError(
                f"BIDS {what} label {label!r} must be letters and digits only; drop '-', '_', spaces"
            )
    d = Path(directory)
    if not d.is_dir():
        raise InputError(f"directory {d} does not exist; create it (e.g. sub-{subject}/motion) first")
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError(
            "time must be (N,) finite and strictly increasing with N >= 2; sort it and drop repeats"
        )
    channels = [BidsChannel("latency", "n/a", "LATENCY", "n/a", "s", "n/a")]
    columns: list[FloatArray] = [t - t[0]]
    for name, v in (angles_deg or {}).items():
        channels.append(angle_channel(name, side))
        columns.append(_series(v, t.size, name))
    for name, v in (positions_m or {}).items():
        channels.append(position_channel(name, side))
        columns.append(_series(v, t.size, name))
    for sensor, q in (quats_wxyz or {}).items():
        arr = np.asarray(q, dtype=float)
        if arr.shape != (t.size, 4):
            raise ShapeError(
                f"orientation of '{sensor}' has shape {arr.shape}, expected ({t.size}, 4) w,x,y,z"
            )
        channels.extend(orientation_channels(sensor, side))
        columns.extend(arr.T)
    if len(channels) == 1:
        raise InputError("no angles, positions or orientations given; pass at least one")
    names = [c.name for c in channels]
    if len(set(names)) != len(names):
        raise InputError("two channels share a name; pass each quantity once")

    stem = f"sub-{subject}" + (f"_ses-{session}" if session else "") + f"_task-{task}_tracksys-{tracksys}"
    files = BidsMotionFiles(
        motion_tsv=d / f"{stem}_motion.tsv",
        channels_tsv=d / f"{stem}_channels.tsv",
        motion_json=d / f"{stem}_motion.json",
        channels_json=d / f"{stem}_channels.json",
        channels=tuple(channels),
    )
    data = np.column_stack(columns)
    with open(files.motion_tsv, "w", encoding="utf-8", newline="") as f:
        for row in data:
            f.write("\t".join("n/a" if not np.isfinite(v) else f"{v:.8g}" for v in row) + "\n")
    with open(files.channels_tsv, "w", encoding="utf-8", newline="") as f:
        w = csv.writer(f, delimiter="\t", lineterminator="\n")
        w.writerow(CHANNEL_COLUMNS)
        for c in channels:
            w.writerow([asdict(c)[k] for k in CHANNEL_COLUMNS])
    files.motion_json.write_text(
        json.dumps(_motion_sidecar(t, channels, task, tracksys, task_description), indent=2) + "\n",
        encoding="utf-8",
    )
    files.channels_json.write_text(json.dumps(_channels_sidecar(channels), indent=2) + "\n", encoding="utf-8")
    return files


def _motion_sidecar(
    t: FloatArray, channels: list[BidsChannel], task: str, tracksys: str, description: str | None
) -> dict[str, object]:
    counts: dict[str, int] = {}
    for c in channels:
        counts[c.type] = counts.get(c.type, 0) + 1
    points = {c.tracked_point for c in channels if c.tracked_point != "n/a"}
    sidecar: dict[str, object] = {
        "SamplingFrequency": round(rate_from_stamps(t), 6),
        "SamplingFrequencyEffective": (t.size - 1) / float(t[-1] - t[0]),
        "TaskName": task,
        "TrackingSystemName": f"lowerlimb ({tracksys})",
        "MotionChannelCount": len(channels),
        "RecordingDuration": float(t[-1] - t[0]),
        **{f"{k}ChannelCount": v for k, v in sorted(counts.items())},
        "TrackedPointsCount": len(points),
        "MissingValues": "n/a",
        "RotationRule": "right-hand",
        "RotationOrder": "ZXY",
        "SoftwareVersions": f"lowerlimb {__version__}",
    }
    if description:
        sidecar["TaskDescription"] = description
    return sidecar


_FRAME_DESCRIPTIONS: dict[str, str] = {
    "proximal_segment": "ISB segment frame of the joint's proximal segment: x anterior, y superior, z right; "
    "angles are the Z-X-Y (flexion, adduction, internal rotation) decomposition, clinical signs",
    "global": "earth frame ENU: x east, y north, z up (heading arbitrary without magnetometer); "
    "quaternions rotate sensor-frame vectors into it",
    "pelvis_sensor": "origin and axes of the pelvis sensor",
}


def _channels_sidecar(channels: list[BidsChannel]) -> dict[str, object]:
    levels: dict[str, dict[str, str]] = {}
    for c in channels:
        rf = c.reference_frame
        if rf == "n/a" or rf in levels:
            continue
        desc = _FRAME_DESCRIPTIONS.get(
            rf, f"origin at the {rf.replace('_', ' ')}, axes of the pelvis sensor frame"
        )
        levels[rf] = {"RotationRule": "right-hand", "RotationOrder": "ZXY", "Description": desc}
        if rf == "proximal_segment":
            levels[rf]["SpatialAxes"] = "ASR"
    return {
        "reference_frame": {"Description": "frame the channel's values are expressed in", "Levels": levels}
    }


def _series(values: ArrayLike, n: int, name: str) -> FloatArray:
    v = np.asarray(values, dtype=float)
    if v.shape != (n,):
        raise ShapeError(f"'{name}' has shape {v.shape}, expected ({n},) like time")
    return v
