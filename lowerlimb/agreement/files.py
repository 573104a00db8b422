"""Reading a ``calibrate`` output folder and a reference CSV; writing ``agreement.csv``/``.json``.

Nothing here imports the command line; :mod:`lowerlimb.cli.compare` calls these.
"""

from __future__ import annotations

import codecs
import csv
import io
import json
import math
import os
from collections.abc import Collection
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..conventions import SIDES, FloatArray
from ..errors import InputError
from ..io.trial import check_unique_columns
from .columns import no_common_columns_error, reference_header
from .comparison import Comparison
from .params import AgreementParams
from .reference_checks import check_reference_time

#: Output tables of ``calibrate`` and the unit of every non-time column in each.
OUTPUT_TABLE_UNITS: dict[str, str] = {"angles.csv": "deg", "positions.csv": "m"}

#: Columns of ``agreement.csv``, in order.
AGREEMENT_COLUMNS: tuple[str, ...] = (
    "quantity",
    "unit",
    "n",
    "rmse",
    "bias",
    "sd_diff",
    "loa_lower",
    "loa_upper",
    "pearson_r",
    "cmc",
    "offset_removed",
)


@dataclass(frozen=True)
class Table:
    """A CSV table with a ``time`` column.

    Attributes:
        path: file it came from.
        time_s: (N,) time column, s.
        columns: name -> (N,) values (NaN for empty cells).
    """

    path: Path
    time_s: FloatArray
    columns: dict[str, FloatArray]


def read_time_table(path: str | os.PathLike[str], what: str) -> Table:
    """Read a comma-separated table whose header has a ``time`` column.

    Header names are read in any case, with our units' annotations dropped (``Time (s)`` is
    ``time``: :func:`~lowerlimb.agreement.columns.reference_header`). Empty cells and ``nan``
    become NaN.

    Args:
        path: the CSV file.
        what: how to name the file in error messages ("reference", "angles.csv").

    Raises:
        FileNotFoundError: the file does not exist.
        InputError: a directory, not UTF-8 text, no header, no ``time`` column, a column in
            another unit than s/deg/m, separated by ``;``, a column named twice, unreadable
            numbers, or no rows.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{what} {path} is a directory, not a CSV file; give the path of a CSV file")
    if not path.is_file():
        raise FileNotFoundError(f"{what} {path} does not exist; give the path of an existing CSV file")
    rows = _csv_rows(path, what)
    header = reference_header(rows[0], str(path), what) if rows else []
    if "time" not in header:
        raise InputError(f"{what} {path} has no header with a 'time' column; add a header row 'time,…'")
    check_unique_columns([h for h in header if h], f"{what} {path}")
    body = [r for r in rows[1:] if any(c.strip() for c in r)]
    if not body:
        raise InputError(f"{what} {path} has a header but no data rows; export the samples too")
    data = np.full((len(body), len(header)), np.nan)
    for i, r in enumerate(body):
        if len(r) > len(header):
            raise InputError(f"{what} {path} row {i + 2} has more cells than the header; fix the delimiter")
        for j, cell in enumerate(r):
            cell = cell.strip()
            if cell:
                try:
                    data[i, j] = float(cell)
                except ValueError:
                    raise InputError(
                        f"{what} {path} row {i + 2} column '{header[j]}' holds '{cell}', not a number; "
                        f"write numbers only (empty for missing)"
                    ) from None
    itime = header.index("time")
    cols = {h: data[:, j] for j, h in enumerate(header) if j != itime and h}
    return Table(path=path, time_s=data[:, itime], columns=cols)


def read_reference_table(
    path: str | os.PathLike[str],
    *,
    our_columns: Collection[str] | None = None,
    time_s: FloatArray | None = None,
    params: AgreementParams | None = None,
    result: CalibrateOutputs | None = None,
    side: str | None = None,
) -> Table:
    """Read a reference CSV (:func:`read_time_table`), check its columns, then its time column.

    Args:
        path: the CSV file: ``time`` in s and columns named as ours (deg, m).
        our_columns: our quantity names; at least one must be in the reference (optional).
        time_s: (N,) our sample times, s, to quote our time step in an error (optional).
        params: thresholds; defaults to :class:`AgreementParams`.
        result: the result folder compared with, to name why no column is ours (its leg, its
            missing tables: :func:`~lowerlimb.agreement.columns.no_common_columns_error`).
        side: the leg compared with when there is no ``result`` yet (``calibrate --reference``).

    Raises:
        FileNotFoundError: the file does not exist.
        InputError: as :func:`read_time_table`.
        NoCommonColumnsError: none of its columns is in ``our_columns``.
        TimeAxisError: a time that is not finite or not strictly increasing.
        ReferenceTimeUnitError: time steps that look like ms.
    """
    table = read_time_table(path, "reference")
    if our_columns is not None and not any(c in our_columns for c in table.columns):
        raise no_common_columns_error(
            list(table.columns),
            list(our_columns),
            str(path),
            directory="" if result is None else str(result.directory),
            side=side if result is None else result.side,
            missing_tables=() if result is None else result.missing_tables,
        )
    check_reference_time(table.time_s, time_s=time_s, path=str(path), params=params)
    return table


@dataclass(frozen=True)
class CalibrateOutputs:
    """Our quantities from a ``calibrate`` output folder, on one time axis.

    Attributes:
        directory: the folder.
        time_s: (N,) sample times, s.
        values: name -> (N,) values (angles in deg, positions in m).
        units: name -> unit (``"deg"``, ``"m"``).
        side: the result's leg: ``"left"`` or ``"right"`` (one leg, from ``calibration.json``),
            ``"both"`` (two legs: its columns are ``left_*``/``right_*``), or None (unknown).
        missing_tables: the tables of :data:`OUTPUT_TABLE_UNITS` not in the folder.
    """

    directory: Path
    time_s: FloatArray
    values: dict[str, FloatArray]
    units: dict[str, str]
    side: str | None
    missing_tables: tuple[str, ...]


def read_result(directory: str | os.PathLike[str]) -> CalibrateOutputs:
    """Read ``angles.csv`` (deg) and ``positions.csv`` (m) of a ``calibrate`` output folder, whichever exist.

    Both must share the same ``time`` column when both exist.

    Raises:
        FileNotFoundError: the folder does not exist.
        InputError: it holds neither table, or their time columns differ.
    """
    d = Path(directory)
    if not d.is_dir():
        raise FileNotFoundError(f"{d} is not a directory; pass the output folder of 'lowerlimb calibrate'")
    tables = [
        (read_time_table(d / name, name), unit)
        for name, unit in OUTPUT_TABLE_UNITS.items()
        if (d / name).is_file()
    ]
    if not tables:
        raise InputError(
            f"{d} holds neither angles.csv nor positions.csv; pass the output folder of 'lowerlimb calibrate'"
        )
    time_s = tables[0][0].time_s
    values: dict[str, FloatArray] = {}
    units: dict[str, str] = {}
    for table, unit in tables:
        if table.time_s.shape != time_s.shape or not np.allclose(table.time_s, time_s, atol=1e-6):
            raise InputError(
                f"{d}: angles.csv and positions.csv have different time columns; re-run calibrate"
            )
        for name, v in table.columns.items():
            values[name] = v
            units[name] = unit
    missing = tuple(name for name in OUTPUT_TABLE_UNITS if not (d / name).is_file())
    side = "both" if any(n.startswith(("left_", "right_")) for n in values) else _one_leg_side(d)
    return CalibrateOutputs(d, time_s, values, units, side, missing)


def read_calibrate_outputs(
    directory: str | os.PathLike[str],
) -> tuple[FloatArray, dict[str, FloatArray], dict[str, str]]:
    """``(time_s, values, units)`` of :func:`read_result`: (N,) s; name -> (N,) values; name -> unit.

    Raises:
        FileNotFoundError: the folder does not exist.
        InputError: it holds neither table, or their time columns differ.
    """
    r = read_result(directory)
    return r.time_s, r.values, r.units


def _one_leg_side(directory: Path) -> str | None:
    """The ``side`` of a one-leg folder's ``calibration.json``; None when it is absent or unreadable."""
    try:
        side = json.loads((directory / "calibration.json").read_text(encoding="utf-8")).get("side")
    except (OSError, ValueError, AttributeError):
        return None
    return side if side in SIDES else None


def write_agreement_csv(path: str | os.PathLike[str], comparison: Comparison) -> None:
    """Write ``agreement.csv``: one row per quantity, :data:`AGREEMENT_COLUMNS`; NaN as ``nan``."""
    with open(path, "w", encoding="utf-8", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(AGREEMENT_COLUMNS)
        for s in comparison.quantities:
            row = asdict(s)
            w.writerow([_cell(row[c]) for c in AGREEMENT_COLUMNS])


def agreement_summary(comparison: Comparison, **extra: object) -> dict[str, object]:
    """The JSON summary of a comparison (``agreement.json``): offset applied, method, quantities."""
    a = comparison.alignment
    p = comparison.params
    return {
        "format": "lowerlimb-agreement/1",
        "time_offset_s": comparison.time_offset_s,
        "time_offset_meaning": "added to the reference time stamps to put them on lowerlimb's clock",
        "time_alignment": None if a is None else {**asdict(a), "method": "cross-correlation, mean Pearson r"},
        "remove_offset": comparison.remove_offset,
        "difference": "lowerlimb - reference",
        "limits_of_agreement": f"bias ± {p.loa_z} SD of the difference (ddof={p.sd_ddof})",
        "cmc": "Ferrari et al. 2010 eq. 2, G=2 waveforms, N=1 cycle; null when undefined",
        "resampling": "reference linearly interpolated onto lowerlimb's time stamps over the overlap",
        "quantities": [s.to_dict() for s in comparison.quantities],
        "skipped_quantities": list(comparison.skipped),
        "ignored_reference_columns": list(comparison.ignored_reference_columns),
        "params": asdict(p),
        **extra,
    }


def write_agreement_json(path: str | os.PathLike[str], summary: dict[str, object]) -> None:
    """Write ``agreement.json`` (strict JSON: NaN written as null)."""
    Path(path).write_text(json.dumps(_finite(summary), indent=2) + "\n", encoding="utf-8")


def _csv_rows(path: Path, what: str) -> list[list[str]]:
    """The rows of a CSV file read as UTF-8 (a BOM allowed); other text is refused by name."""
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        offset = e.start + (len(codecs.BOM_UTF8) if data.startswith(codecs.BOM_UTF8) else 0)
        line = data.count(b"\n", 0, offset) + 1
        raise InputError(
            f"{what} {path} is not UTF-8 text (byte {data[offset]:#04x} at offset {offset}, line "
            f"{line}); save it as UTF-8 (e.g. 'CSV UTF-8' in Excel)"
        ) from None
    if "\x00" in text:
        raise InputError(f"{what} {path} is a binary file, not a CSV; export it as comma-separated text")
    try:
        return list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as e:
        raise InputError(
            f"{what} {path} is not a readable CSV ({e}); export it as comma-separated text"
        ) from None


def _cell(v: object) -> object:
    if isinstance(v, float):
        return "nan" if not math.isfinite(v) else repr(v)
    return v


def _finite(obj: object) -> object:
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite(v) for v in obj]
    return obj
