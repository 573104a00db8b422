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

from ..conventions import FloatArray
from ..errors import InputError
from ..io.trial import check_unique_columns
from .comparison import Comparison
from .errors import NoCommonColumnsError
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

    Empty cells and ``nan`` become NaN.

    Args:
        path: the CSV file.
        what: how to name the file in error messages ("reference", "angles.csv").

    Raises:
        FileNotFoundError: the file does not exist.
        InputError: not UTF-8 text, no header, no ``time`` column, a column named twice,
            unreadable numbers, or no rows.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{what} {path} does not exist; give the path of an existing CSV file")
    rows = _csv_rows(path, what)
    if not rows or "time" not in [h.strip() for h in rows[0]]:
        raise InputError(f"{what} {path} has no header with a 'time' column; add a header row 'time,…'")
    header = [h.strip() for h in rows[0]]
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
) -> Table:
    """Read a reference CSV (:func:`read_time_table`), check its columns, then its time column.

    Args:
        path: the CSV file: ``time`` in s and columns named as ours (deg, m).
        our_columns: our quantity names; at least one must be in the reference (optional).
        time_s: (N,) our sample times, s, to quote our time step in an error (optional).
        params: thresholds; defaults to :class:`AgreementParams`.

    Raises:
        FileNotFoundError: the file does not exist.
        InputError: as :func:`read_time_table`.
        NoCommonColumnsError: none of its columns is in ``our_columns``.
        TimeAxisError: a time that is not finite or not strictly increasing.
        ReferenceTimeUnitError: time steps that look like ms.
    """
    table = read_time_table(path, "reference")
    if our_columns is not None and not any(c in our_columns for c in table.columns):
        raise NoCommonColumnsError(list(table.columns), list(our_columns), str(path))
    check_reference_time(table.time_s, time_s=time_s, path=str(path), params=params)
    return table


def read_calibrate_outputs(
    directory: str | os.PathLike[str],
) -> tuple[FloatArray, dict[str, FloatArray], dict[str, str]]:
    """Our quantities from a ``calibrate`` output folder on one time axis.

    Reads ``angles.csv`` (deg) and ``positions.csv`` (m), whichever exist;
    both must share the same ``time`` column when both exist.

    Returns:
        ``(time_s, values, units)``: (N,) s; name -> (N,) values; name -> unit.

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
    return time_s, values, units


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
