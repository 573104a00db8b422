"""Writers of the gait outputs of docs/formats.md: ``events.csv`` and ``gait.json``."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from lowerlimb.gait.events import GaitEvents
from lowerlimb.gait.parameters import GaitParameters

__all__ = ["EVENTS_COLUMNS", "write_events_csv", "write_gait_json"]

#: Columns of ``events.csv`` (docs/formats.md, "Two legs"); ``event`` is ``initial_contact`` or ``toe_off``.
EVENTS_COLUMNS = ("time", "side", "event")


def write_events_csv(events: GaitEvents, path: str | Path) -> Path:
    """Write ``time, side, event`` rows sorted by time (time in s, 6 decimals)."""
    path = Path(path)
    lines = [",".join(EVENTS_COLUMNS)]
    lines += [f"{t:.6f},{side},{name}" for t, side, name in events.table()]
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
