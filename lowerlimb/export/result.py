"""Exports of a processed trial (:class:`~lowerlimb.pipeline.TrialResult`) into a result folder.

:func:`write_exports` is what ``calibrate --export opensim|bids`` runs;
:func:`write_units_sidecars` writes the units sidecars of ``angles.csv`` and
``positions.csv``, which every result folder has. The orientations exported are
the ones the pipeline computes its angles from: the filter orientations after the
heading correction (``TrialResult.motion.sensor_quat_wxyz``), sensor → ENU earth.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..conventions import ANGLE_COLUMNS, POSITION_COLUMNS, FloatArray
from ..errors import InputError
from ..pipeline import TrialResult
from .bids import write_bids_motion
from .formats import EXPORT_FORMATS
from .opensim import write_mot, write_orientations_sto
from .units import write_units_sidecar

#: BIDS subject label of a ``calibrate`` export (rename the files to your own labels).
BIDS_SUBJECT = "01"
#: BIDS task label when the trial's file name gives none.
BIDS_DEFAULT_TASK = "trial"


def check_export_formats(formats: Iterable[str]) -> tuple[str, ...]:
    """The formats without repeats, in :data:`EXPORT_FORMATS` order.

    Raises:
        InputError: an unknown format.
    """
    wanted = set(formats)
    unknown = sorted(wanted - set(EXPORT_FORMATS))
    if unknown:
        raise InputError(
            f"unknown export format {', '.join(unknown)}; use one of {', '.join(EXPORT_FORMATS)}"
        )
    return tuple(f for f in EXPORT_FORMATS if f in wanted)


def write_units_sidecars(
    directory: Path,
    tables: Iterable[str] = ("angles", "positions"),
    columns: Mapping[str, Sequence[str]] | None = None,
) -> list[str]:
    """Write ``<table>.units.json`` beside each of ``tables`` (angles, positions); returns the names.

    ``columns`` maps a table to its header (default: the one-leg ``angles.csv`` /
    ``positions.csv`` columns).
    """
    columns = columns or {"angles": ANGLE_COLUMNS, "positions": POSITION_COLUMNS}
    names = []
    for table in tables:
        write_units_sidecar(directory / f"{table}.units.json", columns[table], table)
        names.append(f"{table}.units.json")
    return names


def write_exports(result: TrialResult, directory: Path, formats: Iterable[str]) -> list[str]:
    """Write the files of each export format into ``directory``; returns their names.

    Raises:
        InputError: an unknown format.
    """
    return run_writers(_WRITERS, result, directory, formats)


def run_writers(
    writers: Mapping[str, Callable[[Any, Path], list[str]]],
    result: Any,
    directory: Path,
    formats: Iterable[str],
) -> list[str]:
    """Run the writer of each checked format on ``result``; returns the names of the files written.

    Raises:
        InputError: an unknown format.
    """
    written: list[str] = []
    for f in check_export_formats(formats):
        written += writers[f](result, directory)
    return written


def write_opensim(result: TrialResult, directory: Path) -> list[str]:
    """``angles.mot`` (OpenSim coordinates, deg) and ``orientations.sto`` (OpenSim's y-up world)."""
    side = result.trial.side
    write_mot(directory / "angles.mot", result.trial.time_s, _angles_deg(result), side, name="angles")
    write_orientations_sto(
        directory / "orientations.sto", result.trial.time_s, result.motion.sensor_quat_wxyz, side
    )
    return ["angles.mot", "orientations.sto"]


def bids_task(source: str | Path) -> str:
    """BIDS task label of a trial file: its stem in letters and digits, else :data:`BIDS_DEFAULT_TASK`."""
    return re.sub(r"[^0-9A-Za-z]", "", Path(source).stem) or BIDS_DEFAULT_TASK


def write_bids(result: TrialResult, directory: Path) -> list[str]:
    """BIDS-motion files of one tracking system ``imu``: angles, positions and orientations.

    Subject :data:`BIDS_SUBJECT`; task = the trial file's stem with everything but
    letters and digits removed (:data:`BIDS_DEFAULT_TASK` when nothing is left).
    """
    task = bids_task(result.trial.source)
    positions = {c: result.positions_m[:, k] for k, c in enumerate(POSITION_COLUMNS[1:])}
    files = write_bids_motion(
        directory,
        result.trial.time_s,
        subject=BIDS_SUBJECT,
        task=task,
        angles_deg=_angles_deg(result),
        positions_m=positions,
        quats_wxyz=result.motion.sensor_quat_wxyz,
        side=result.trial.side,
        task_description=f"lowerlimb calibrate of {Path(result.trial.source).name or 'a trial'}, "
        f"{result.trial.side} leg",
    )
    return [p.name for p in (files.motion_tsv, files.channels_tsv, files.motion_json, files.channels_json)]


def _angles_deg(result: TrialResult) -> dict[str, FloatArray]:
    deg = np.rad2deg(result.angles_rad)
    return {c: deg[:, k] for k, c in enumerate(ANGLE_COLUMNS[1:])}


_WRITERS = {"opensim": write_opensim, "bids": write_bids}
