"""Writers and readers of the output tables (docs/formats.md) ``angles.csv`` and ``positions.csv``."""

from __future__ import annotations

import os

import numpy as np

from ..conventions import ANGLE_COLUMNS, POSITION_COLUMNS, FloatArray
from ..errors import InputError

#: Unit of the ``time`` column of every output table.
TIME_UNIT = "s"
#: Unit of every ``angles.csv`` column but time.
ANGLE_UNIT = "deg"
#: Unit of every ``positions.csv`` column but time (pelvis sensor frame).
POSITION_UNIT = "m"


def write_angles_csv(path: str | os.PathLike[str], time_s: FloatArray, angles_rad: FloatArray) -> None:
    """Write ``angles.csv``: time (s) and the 9 ISB joint angles in DEGREES.

    Args:
        path: file to write.
        time_s: (N,) sample times, s.
        angles_rad: (N, 9) joint angles, rad, in :data:`ANGLE_COLUMNS` order.
    """
    data = np.column_stack([time_s, np.rad2deg(angles_rad)])
    np.savetxt(path, data, delimiter=",", header=",".join(ANGLE_COLUMNS), comments="", fmt="%.6f")


def write_positions_csv(path: str | os.PathLike[str], time_s: FloatArray, positions_m: FloatArray) -> None:
    """Write ``positions.csv``: time (s), pelvis→foot sensor and hip→ankle centre vectors (m).

    Args:
        path: file to write.
        time_s: (N,) sample times, s.
        positions_m: (N, 6) vectors in the pelvis sensor frame, m, in
            :data:`POSITION_COLUMNS` order.
    """
    data = np.column_stack([time_s, positions_m])
    np.savetxt(path, data, delimiter=",", header=",".join(POSITION_COLUMNS), comments="", fmt="%.7f")


def read_table(path: str | os.PathLike[str], columns: tuple[str, ...]) -> FloatArray:
    """Read an output table, checking its header; returns (N, len(columns)).

    Raises:
        InputError: when the header differs from ``columns``.
    """
    with open(path, encoding="utf-8") as f:
        header = f.readline().strip().split(",")
    if tuple(header) != columns:
        raise InputError(f"{path} has columns {header}, expected {list(columns)}")
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
