"""The two-leg output tables of docs/formats.md ("Two legs"): ``angles.csv`` and ``positions.csv``."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from ..conventions import ANGLE_COLUMNS, POSITION_COLUMNS, SIDES, FloatArray

__all__ = [
    "BILATERAL_ANGLE_COLUMNS",
    "BILATERAL_POSITION_COLUMNS",
    "write_bilateral_angles_csv",
    "write_bilateral_positions_csv",
    "write_bilateral_tables",
]

#: ``time``, then ``left_<angle>`` and ``right_<angle>`` for the nine single-leg angle names (degrees).
BILATERAL_ANGLE_COLUMNS: tuple[str, ...] = ("time",) + tuple(
    f"{side}_{name}" for side in SIDES for name in ANGLE_COLUMNS[1:]
)

_P2F = POSITION_COLUMNS[1:4]
_H2A = POSITION_COLUMNS[4:7]
#: ``time``, the pelvis→foot and hip→ankle vectors of each leg, and left foot → right foot (m,
#: pelvis sensor frame).
BILATERAL_POSITION_COLUMNS: tuple[str, ...] = (
    ("time",)
    + tuple(f"{side}_{c}" for side in SIDES for c in _P2F)
    + tuple(f"{side}_{c}" for side in SIDES for c in _H2A)
    + tuple(f"left_foot_to_right_foot_{a}" for a in "xyz")
)


def write_bilateral_angles_csv(
    path: str | os.PathLike[str], time_s: FloatArray, angles_rad: FloatArray
) -> None:
    """Write a two-leg ``angles.csv``: ``time`` (s) and (N, 18) angles in rad (degrees on disk)."""
    np.savetxt(
        os.fspath(path),
        np.column_stack([time_s, np.rad2deg(angles_rad)]),
        delimiter=",",
        header=",".join(BILATERAL_ANGLE_COLUMNS),
        comments="",
        fmt="%.6f",
    )


def write_bilateral_positions_csv(
    path: str | os.PathLike[str], time_s: FloatArray, positions_m: FloatArray
) -> None:
    """Write a two-leg ``positions.csv``: ``time`` (s) and (N, 15) vectors, m, pelvis sensor frame."""
    np.savetxt(
        os.fspath(path),
        np.column_stack([time_s, positions_m]),
        delimiter=",",
        header=",".join(BILATERAL_POSITION_COLUMNS),
        comments="",
        fmt="%.7f",
    )


def write_bilateral_tables(
    directory: str | os.PathLike[str],
    time_s: FloatArray,
    angles_rad: FloatArray,
    positions_m: FloatArray,
    tables: Sequence[str] = ("angles", "positions"),
) -> None:
    """Write ``angles.csv`` and/or ``positions.csv`` (``tables``) of a two-leg trial into ``directory``.

    Args:
        directory: an existing folder.
        time_s: (N,) sample times, s.
        angles_rad: (N, 18) joint angles, rad, in :data:`BILATERAL_ANGLE_COLUMNS` order (degrees on disk).
        positions_m: (N, 15) vectors in the pelvis sensor frame, m, in
            :data:`BILATERAL_POSITION_COLUMNS` order.
        tables: which of ``"angles"``, ``"positions"`` to write.
    """
    d = os.fspath(directory)
    if "angles" in tables:
        write_bilateral_angles_csv(os.path.join(d, "angles.csv"), time_s, angles_rad)
    if "positions" in tables:
        write_bilateral_positions_csv(os.path.join(d, "positions.csv"), time_s, positions_m)
