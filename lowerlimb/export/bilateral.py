"""Exports of a processed two-leg trial (:class:`~lowerlimb.bilateral.process.BilateralResult`).

The same files as for one leg (:mod:`lowerlimb.export.result`), with both legs in each:
``angles.mot`` carries the ``_l`` and ``_r`` OpenSim coordinates, ``orientations.sto``
the seven OpenSense IMUs (``pelvis_imu``, ``femur_l_imu``, …), and the BIDS-motion
channels are named after the two-leg ``angles.csv`` / ``positions.csv`` columns. Each
leg's orientations are the ones its angles were computed from (sensor → ENU, after the
heading correction); the one pelvis sensor is taken from the left leg, whose pelvis
heading both legs share.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..conventions import SENSORS, SIDES, FloatArray
from ..io.bilateral_tables import BILATERAL_ANGLE_COLUMNS, BILATERAL_POSITION_COLUMNS
from .bids import write_bids_motion
from .opensim import write_mot, write_orientations_sto
from .result import BIDS_SUBJECT, bids_task, run_writers, write_units_sidecars

if TYPE_CHECKING:
    from ..bilateral.process import BilateralResult

__all__ = ["write_bilateral_exports", "write_bilateral_units_sidecars"]


def write_bilateral_units_sidecars(
    directory: Path, tables: Iterable[str] = ("angles", "positions")
) -> list[str]:
    """Write ``<table>.units.json`` for the two-leg ``angles.csv`` / ``positions.csv``; returns the names."""
    columns = {"angles": BILATERAL_ANGLE_COLUMNS, "positions": BILATERAL_POSITION_COLUMNS}
    return write_units_sidecars(directory, tables, columns)


def write_bilateral_exports(result: BilateralResult, directory: Path, formats: Iterable[str]) -> list[str]:
    """Write the files of each export format (``opensim``, ``bids``) into ``directory``; returns their names.

    Raises:
        InputError: an unknown format.
    """
    return run_writers(_WRITERS, result, directory, formats)


def _angles_deg(result: BilateralResult) -> dict[str, FloatArray]:
    """Two-leg ``angles.csv`` column -> (N,) angle, deg."""
    deg = np.rad2deg(result.angles_rad)
    return {c: deg[:, k] for k, c in enumerate(BILATERAL_ANGLE_COLUMNS[1:])}


def _quats(result: BilateralResult) -> dict[str, FloatArray]:
    """Two-leg sensor name -> (N, 4) orientation, sensor → ENU, scalar first."""
    out = {"pelvis": result.legs["left"].motion.sensor_quat_wxyz["pelvis"]}
    for side in SIDES:
        q = result.legs[side].motion.sensor_quat_wxyz
        out |= {f"{side}_{s}": q[s] for s in SENSORS[1:]}
    return out


def _write_opensim(result: BilateralResult, directory: Path) -> list[str]:
    t = result.trial.time_s
    write_mot(directory / "angles.mot", t, _angles_deg(result), name="angles")
    write_orientations_sto(directory / "orientations.sto", t, _quats(result))
    return ["angles.mot", "orientations.sto"]


def _write_bids(result: BilateralResult, directory: Path) -> list[str]:
    source = Path(getattr(result.trial, "source", "") or "")
    task = bids_task(source)
    positions = {c: result.positions_m[:, k] for k, c in enumerate(BILATERAL_POSITION_COLUMNS[1:])}
    files = write_bids_motion(
        directory,
        result.trial.time_s,
        subject=BIDS_SUBJECT,
        task=task,
        angles_deg=_angles_deg(result),
        positions_m=positions,
        quats_wxyz=_quats(result),
        task_description=f"lowerlimb calibrate of {source.name or 'a trial'}, both legs",
    )
    return [p.name for p in (files.motion_tsv, files.channels_tsv, files.motion_json, files.channels_json)]


_WRITERS = {"opensim": _write_opensim, "bids": _write_bids}
