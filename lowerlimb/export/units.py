"""Units sidecars for our CSV tables: ``angles.units.json`` / ``positions.units.json``.

A sidecar maps every column of its table to a unit string, so that no file
leaves units to guessing: ``time`` is ``s``, every ``angles.csv`` column
``deg``, every ``positions.csv`` column ``m`` (pelvis sensor frame).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from ..errors import InputError
from ..io.tables import ANGLE_UNIT, POSITION_UNIT, TIME_UNIT

#: Unit of every non-time column, per table kind.
TABLE_UNITS: dict[str, str] = {"angles": ANGLE_UNIT, "positions": POSITION_UNIT}
#: What the values of each table kind are.
TABLE_DESCRIPTIONS: dict[str, str] = {
    "angles": "ISB joint angles, Z-X-Y (flexion, adduction, internal rotation), clinical signs, "
    "zero = standing reference posture",
    "positions": "vectors expressed in the pelvis sensor frame",
}


def table_units(columns: Sequence[str], kind: str) -> dict[str, str]:
    """Column -> unit of an ``angles`` or ``positions`` table (``time`` -> ``s``).

    Raises:
        InputError: when ``kind`` is neither ``"angles"`` nor ``"positions"``.
    """
    if kind not in TABLE_UNITS:
        raise InputError(f"table kind must be one of {', '.join(TABLE_UNITS)}, got {kind!r}")
    return {c: (TIME_UNIT if c == "time" else TABLE_UNITS[kind]) for c in columns}


def write_units_sidecar(
    path: str | os.PathLike[str], columns: Sequence[str] | Mapping[str, str], kind: str | None = None
) -> dict[str, str]:
    """Write ``<table>.units.json``: ``{"format", "table", "description", "units": {column: unit}}``.

    Args:
        path: sidecar to write, e.g. ``DIR/angles.units.json``.
        columns: the table's header (with ``kind``) or an explicit column -> unit map.
        kind: ``"angles"`` or ``"positions"`` when ``columns`` is a header.

    Returns:
        The column -> unit map written.

    Raises:
        InputError: a header without a valid ``kind``.
    """
    if isinstance(columns, Mapping):
        units = dict(columns)
    else:
        if kind is None:
            raise InputError("give kind='angles' or 'positions' with a list of columns")
        units = table_units(columns, kind)
    doc: dict[str, object] = {"format": "lowerlimb-units/1"}
    if kind is not None:
        doc["table"] = f"{kind}.csv"
        doc["description"] = TABLE_DESCRIPTIONS.get(kind, "")
    doc["units"] = units
    Path(path).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return units
