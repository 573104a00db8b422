"""Writers of the gait outputs of docs/formats.md: ``events.csv``, ``stationary.csv`` and ``gait.json``."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from lowerlimb.gait.events import GaitEvents
from lowerlimb.gait.one_leg import LegGait
from lowerlimb.gait.parameters import GaitParameters

__all__ = [
    "EVENTS_COLUMNS",
    "STATIONARY_COLUMNS",
    "write_events_csv",
    "write_gait_json",
    "write_leg_gait",
    "write_stationary_csv",
]

#: Columns of ``events.csv`` (docs/formats.md, "Two legs"); ``event`` is ``initial_contact`` or ``toe_off``.
EVENTS_COLUMNS = ("time", "side", "event")


def write_events_csv(events: GaitEvents, path: str | Path) -> Path:
    """Write ``time, side, event`` rows sorted by time (time in s, 6 decimals)."""
    path = Path(path)
    lines = [",".join(EVENTS_COLUMNS)]
    lines += [f"{t:.6f},{side},{name}" for t, side, name in events.table()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


#: Columns of ``stationary.csv``: one row per foot-stationary period, times in s.
STATIONARY_COLUMNS = ("side", "start", "end")


def write_stationary_csv(events: GaitEvents, path: str | Path) -> Path:
    """Write each foot's stationary periods as ``side, start, end`` rows sorted by start (s, 6 decimals).

    ``end`` is the time of the period's last stationary sample; a leg without a foot IMU
    has no rows.
    """
    path = Path(path)
    rows = []
    for se in events.sides():
        if se.stationary is None:
            continue
        rows += [(se.start_time_s + a, se.start_time_s + b, se.side) for a, b in se.stationary.intervals_s()]
    lines = [",".join(STATIONARY_COLUMNS)]
    lines += [f"{side},{a:.6f},{b:.6f}" for a, b, side in sorted(rows)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _finite(x: Any) -> Any:
    """NaN/inf → None (JSON null), recursively."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_finite(v) for v in x]
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def write_gait_json(parameters: GaitParameters, path: str | Path) -> Path:
    """Write :meth:`GaitParameters.to_dict` as ``gait.json`` (NaN written as ``null``)."""
    path = Path(path)
    path.write_text(json.dumps(_finite(parameters.to_dict()), indent=2) + "\n", encoding="utf-8")
    return path


#: The files of a leg's gait (:func:`write_leg_gait`), in the order written.
LEG_GAIT_FILES = ("events.csv", "stationary.csv", "gait.json")


def write_leg_gait(gait: LegGait, directory: str | Path) -> list[str]:
    """Write one leg's ``events.csv``, ``stationary.csv`` and ``gait.json`` into ``directory``.

    Returns:
        The names written (:data:`LEG_GAIT_FILES`).
    """
    d = Path(directory)
    write_events_csv(gait.events, d / "events.csv")
    write_stationary_csv(gait.events, d / "stationary.csv")
    (d / "gait.json").write_text(json.dumps(_finite(gait.to_dict()), indent=2) + "\n", encoding="utf-8")
    return list(LEG_GAIT_FILES)
