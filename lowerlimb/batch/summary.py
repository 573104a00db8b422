"""The study tables: ``batch.csv`` (one row per trial) and the per-subject and per-task summaries.

Per subject: segment lengths, mean ± SD across the subject's processed trials. Per
task: each angle's range, mean ± SD across the task's processed trials. Every
table is also written as Parquet when pyarrow is installed.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lowerlimb.conventions import ANGLE_COLUMNS
from lowerlimb.io.atomic import write_atomically, write_text

from .record import BATCH_COLUMNS

__all__ = [
    "LENGTH_COLUMNS",
    "RANGE_COLUMNS",
    "group_summary",
    "write_study_tables",
    "write_table",
]

#: Key results summarised per subject.
LENGTH_COLUMNS: tuple[str, ...] = ("thigh_length_mm", "shank_length_mm")
#: Key results summarised per task.
RANGE_COLUMNS: tuple[str, ...] = tuple(f"{n}_range_deg" for n in ANGLE_COLUMNS[1:])


def group_summary(rows: Sequence[Mapping[str, Any]], by: str, columns: Sequence[str]) -> list[dict[str, Any]]:
    """Mean and SD (ddof 1; NaN for one trial) of ``columns`` per value of ``by``, over processed trials.

    A two-leg trial's row has each leg's value under ``left_<col>`` / ``right_<col>``; where
    ``<col>`` itself is absent, the trial counts with the mean of its legs (as its segment
    lengths do in ``batch.csv``), so that its angle ranges are not left out of its task.

    Returns:
        One row per group, sorted: ``{by, "trials", "<col>_mean", "<col>_sd", …}``.
    """
    groups: dict[str, list[Mapping[str, Any]]] = {}
    for row in rows:
        if row.get("status") in ("ok", "warning"):
            groups.setdefault(str(row.get(by, "")), []).append(row)
    out = []
    for key in sorted(groups):
        members = groups[key]
        summary: dict[str, Any] = {by: key, "trials": len(members)}
        for c in columns:
            values = np.array([_trial_value(r, c) for r in members], dtype=float)
            values = values[np.isfinite(values)]
            summary[f"{c}_mean"] = round(float(values.mean()), 3) if values.size else math.nan
            summary[f"{c}_sd"] = round(float(values.std(ddof=1)), 3) if values.size > 1 else math.nan
        out.append(summary)
    return out


def write_study_tables(out: Path, rows: Sequence[Mapping[str, Any]]) -> list[Path]:
    """Write ``batch.csv``, ``study_subjects.csv`` and ``study_tasks.csv`` (and ``.parquet``) into ``out``.

    Returns:
        The files written.
    """
    tables: dict[str, tuple[Sequence[Mapping[str, Any]], list[str]]] = {
        "batch": (list(rows), batch_columns(rows)),
        "study_subjects": _with_columns(group_summary(rows, "subject", LENGTH_COLUMNS)),
        "study_tasks": _with_columns(group_summary(rows, "task", RANGE_COLUMNS)),
    }
    written = []
    for name, (table, columns) in tables.items():
        written += write_table(out / name, table, columns)
    return written


def batch_columns(rows: Iterable[Mapping[str, Any]]) -> list[str]:
    """``batch.csv``'s columns: :data:`BATCH_COLUMNS`, then every key result in first-seen order."""
    columns = list(BATCH_COLUMNS)
    for row in rows:
        columns += [c for c in row if c not in columns]
    return columns


def write_table(stem: Path, rows: Sequence[Mapping[str, Any]], columns: Sequence[str]) -> list[Path]:
    """Write ``stem.csv`` (atomically), and ``stem.parquet`` when pyarrow is installed."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(columns), extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    csv_path = stem.with_suffix(".csv")
    write_atomically(csv_path, lambda tmp: write_text(tmp, buf.getvalue()))
    written = [csv_path]
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return written
    data = {c: [_cell(r.get(c)) for r in rows] for c in columns}
    parquet_path = stem.with_suffix(".parquet")
    table = pa.table({c: pa.array(v, type=_arrow_type(v, pa)) for c, v in data.items()})
    write_atomically(parquet_path, lambda tmp: pq.write_table(table, tmp))
    written.append(parquet_path)
    return written


def _with_columns(rows: list[dict[str, Any]]) -> tuple[list[dict[str, Any]], list[str]]:
    return rows, (list(rows[0]) if rows else [])


def _trial_value(row: Mapping[str, Any], column: str) -> float:
    """``row[column]``, else the mean of the legs' ``left_``/``right_`` values (two-leg rows), else NaN."""
    value = _number(row.get(column))
    if math.isfinite(value):
        return value
    legs = [_number(row.get(f"{side}_{column}")) for side in ("left", "right")]
    legs = [v for v in legs if math.isfinite(v)]
    return float(np.mean(legs)) if legs else math.nan


def _number(v: Any) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _cell(v: Any) -> Any:
    return None if v == "" else v


def _arrow_type(values: list[Any], pa: Any) -> Any:
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, int | float) and not isinstance(v, bool) for v in present):
        return pa.float64() if any(isinstance(v, float) for v in present) else pa.int64()
    return pa.string()
