"""Read Xsens MT Manager text exports (one file per sensor) into a trial.

Format: lines starting with ``//`` are comments, one of them
``// Update Rate: 100.0Hz`` (or ``100,0Hz``); then a header such as
``PacketCounter,SampleTimeFine,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z,Mag_X,Mag_Y,Mag_Z,Quat_q0,…``
(comma, tab or semicolon separated) and one row per packet. Columns are found
by name, in any letter case: ``PacketCounter``, ``Acc_X..Z`` (m/s², specific force) and
``Gyr_X..Z`` (rad/s) are required, ``Mag_X..Z`` is optional; other columns
are ignored. A semicolon- or tab-separated export whose numbers hold a comma uses the
comma as decimal mark (a locale's export, ``3,148749``); every number of such a file
must then use it (a ``.`` in one is refused as a mix). The file of a sensor is the one
whose name contains its ID (e.g. ``S02-Trial-Walk-1-000_00B40B91.txt``).

Choices:

- ``PacketCounter`` is a 16-bit counter: it is unwrapped (+65536 at each
  wrap), and the sensors are aligned on the packets they all recorded. Each
  sensor's counter is placed within half a wrap of the first sensor's.
- A packet missing from a sensor (no row, or an empty Acc/Gyr cell) is filled
  by linear interpolation between its neighbours; a cell that reads ``nan`` or
  ``inf`` is not a missing packet but a corrupt value, refused naming the line. A run of missing packets
  longer than :attr:`ImportParams.max_gap_s` is refused; a warning is issued
  when more than :attr:`ImportParams.warn_fill_fraction` of the samples were
  filled. Empty Mag cells (a magnetometer sampled below the update rate) are
  interpolated the same way.
- Time = (counter − first common counter) / update rate, s. The update rate
  must be positive and at most the largest
  :attr:`InputBounds.rate_hz <lowerlimb.io.bounds.InputBounds.rate_hz>`; a
  counter cell must be a whole number from 0 to :data:`MAX_COUNTER`.
- A file that is not UTF-8 text (a Latin-1 ``°`` in a comment line, a binary
  file) is refused naming the file (:func:`~lowerlimb.io.text_file.read_text`).
- Mag is exported in Xsens normalised units, where 1 is the magnitude of the
  local field at the MT magnetic calibration; it is multiplied by
  ``mag_field_ut`` (default :data:`~lowerlimb.io.params.XSENS_MAG_FIELD_UT`,
  50 µT). When only some files have Mag, Mag is dropped with a warning.
"""

from __future__ import annotations

import math
import os
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError
from lowerlimb.io.trial import ImuTrial

from .bounds import INPUT_BOUNDS
from .errors import ColumnNotFoundError, MappingError, PacketGapError, SensorFileError
from .params import XSENS_MAG_FIELD_UT, ImportParams
from .recording import ImportedRecording, sensor_layout
from .text_file import read_text

#: Period of the Xsens 16-bit packet counter.
COUNTER_PERIOD = 65536
#: Largest PacketCounter value accepted (a 32-bit counter); a larger cell is corrupt.
MAX_COUNTER = 2**32 - 1
#: Extensions of MT Manager text exports.
EXPORT_SUFFIXES = (".txt", ".csv")

_RATE = re.compile(r"update\s*rate\s*:\s*([0-9]*[.,]?[0-9]+)\s*hz", re.IGNORECASE)
#: What to do about a required column that is missing (an MT Manager export has no mapping).
_COLUMN_FIX = "export the recording again from MT Manager with PacketCounter, Acc and Gyr enabled"


class RepeatedPacketsWarning(UserWarning):
    """A packet number repeated with other readings: the first kept, the repeats dropped."""


def _warn_changed_repeats(path: str, data: FloatArray, keep: np.ndarray) -> None:
    """Warn when a repeated packet (``~keep``) carries other Acc/Gyr readings than the one kept."""
    repeats = np.flatnonzero(~keep)
    if not repeats.size:
        return
    kept_index = np.maximum.accumulate(np.where(keep, np.arange(keep.size), 0))
    changed = int(np.sum(np.any(data[repeats, 1:7] != data[kept_index[repeats], 1:7], axis=1)))
    if changed:
        warnings.warn(
            RepeatedPacketsWarning(
                f"{path}: {changed} PacketCounter value(s) repeat with other readings; kept the first of "
                f"each (if the counter skipped rather than repeated, that sensor is one sample off "
                f"from there: export the recording again)"
            ),
            stacklevel=3,
        )


class FilledPacketsWarning(UserWarning):
    """More than a small fraction of the samples were filled by interpolation."""


@dataclass
class XsensExport:
    """One parsed MT Manager text export.

    Attributes:
        path: the file.
        rate_hz: update rate from the ``// Update Rate`` comment, Hz.
        counter: (M,) unwrapped packet counter of the rows with Acc and Gyr.
        acc: (M, 3) specific force, sensor frame, m/s².
        gyr: (M, 3) angular velocity, sensor frame, rad/s.
        mag: (M, 3) magnetic field, sensor frame, Xsens normalised units (NaN
            where a row has none), or None when the file has no Mag columns.
    """

    path: str
    rate_hz: float
    counter: np.ndarray
    acc: FloatArray
    gyr: FloatArray
    mag: FloatArray | None


def unwrap_counter(counter: np.ndarray) -> np.ndarray:
    """Unwrap a 16-bit packet counter: (M,) raw values 0..65535 → (M,) int64, increasing at wraps."""
    c = np.asarray(counter, dtype=np.int64)
    steps = np.diff(c)
    wraps = np.concatenate([[0], np.cumsum(steps < -COUNTER_PERIOD // 2)])[: c.size]
    return c + COUNTER_PERIOD * wraps


def find_sensor_file(directory: Path, sensor_id: str) -> Path:
    """The one export in ``directory`` whose name contains ``sensor_id`` (as a whole hex token).

    Raises:
        SensorFileError: no file, or several files, for the ID.
    """
    token = re.compile(rf"(?<![0-9A-Z]){re.escape(sensor_id)}(?![0-9A-Z])", re.IGNORECASE)
    hits = sorted(
        p for p in directory.iterdir() if p.suffix.lower() in EXPORT_SUFFIXES and token.search(p.stem)
    )
    if not hits:
        raise SensorFileError(
            sensor_id,
            [],
            f"no file in {directory} has sensor ID {sensor_id} in its name; check the ID "
            f"(MT Manager names exports <name>_<ID>.txt) or export that sensor",
        )
    if len(hits) > 1:
        names = ", ".join(p.name for p in hits)
        raise SensorFileError(
            sensor_id,
            [str(p) for p in hits],
            f"{len(hits)} files in {directory} have sensor ID {sensor_id} in their name ({names}); "
            f"keep one recording per directory",
        )
    return hits[0]


def _index(header: list[str]) -> dict[str, int]:
    """``{column name in lower case: index}`` of ``header`` (the first of names equal but for case)."""
    index: dict[str, int] = {}
    for i, h in enumerate(header):
        index.setdefault(h.lower(), i)
    return index


def _columns(header: list[str], names: list[str]) -> list[int] | None:
    """Indices of ``names`` in ``header`` (any letter case), or None when any is absent."""
    index = _index(header)
    return [index[n.lower()] for n in names] if all(n.lower() in index for n in names) else None


def _required(header: list[str], names: list[str], path: str) -> list[int]:
    index = _index(header)
    for n in names:
        if n.lower() not in index:
            raise ColumnNotFoundError(n, header, path, fix=_COLUMN_FIX)
    return [index[n.lower()] for n in names]


def _cell(cells: list[str], i: int, column: str, where: str, comma_decimal: bool) -> float:
    """One cell as a number; NaN for an empty one (a missing packet or Mag sample).

    Raises:
        InputError: text that is not a number, a written ``nan`` or ``inf``, or a ``.`` in a
            file whose decimal mark is ``,`` (``comma_decimal``).
    """
    text = cells[i].strip() if i < len(cells) else ""
    if not text:
        return np.nan
    if comma_decimal:
        if "." in text:
            raise InputError(
                f"{where}: {column} is {text!r}, with '.' although the file's other numbers use ',' as "
                f"decimal mark; export it again from MT Manager with one decimal mark"
            )
        text = text.replace(",", ".")
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{where}: {column} is not a number ({text!r}); fix or remove the row") from None
    if not math.isfinite(value):
        fix = (
            "fix or remove the row"
            if column.lower() == "packetcounter"
            else "empty the cell (a missing sample, filled by interpolation) or remove the row"
        )
        raise InputError(f"{where}: {column} is {cells[i].strip()!r}, not a measured value; {fix}")
    return value


def parse_xsens_export(path: str | os.PathLike[str]) -> XsensExport:
    """Parse one MT Manager text export.

    Raises:
        FileNotFoundError: when ``path`` does not exist.
        NotTextError: a folder, a binary file, or not UTF-8 text.
        ColumnNotFoundError: no PacketCounter, Acc_X..Z or Gyr_X..Z column.
        InputError: no update rate or one out of range, no header, a bad cell, a counter
            that is not a packet number, or one that runs backwards.
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"export not found: {path}")
    text = read_text(
        path,
        "an MT Manager text export",
        export_fix="export it again from MT Manager as text",
        folder_fix="move it out of the folder of exports, leaving one export file per sensor ID",
    )
    lines = text.splitlines()
    body = next((i for i, line in enumerate(lines) if line.strip() and not line.startswith("//")), None)
    if body is None:
        raise InputError(f"{path} has no header row; export it again from MT Manager")
    rate = _update_rate(path, lines[:body])
    delim = max(",\t;", key=lines[body].count)
    header = [h.strip() for h in lines[body].split(delim)]
    i_mag = _columns(header, ["Mag_X", "Mag_Y", "Mag_Z"])
    wanted = (
        _required(header, ["PacketCounter"], path)
        + _required(header, ["Acc_X", "Acc_Y", "Acc_Z"], path)
        + _required(header, ["Gyr_X", "Gyr_Y", "Gyr_Z"], path)
        + (i_mag or [])
    )
    data_rows = [
        (k, line.split(delim))
        for k, line in enumerate(lines[body + 1 :], start=body + 2)
        if line.strip() and not line.startswith("//")
    ]
    # the decimal mark is ',' when a cell read holds one (never with ',' between cells)
    comma_decimal = delim != "," and any(
        "," in cells[i] for _, cells in data_rows for i in wanted if i < len(cells)
    )
    rows = []
    line_no = []
    for k, cells in data_rows:
        rows.append([_cell(cells, i, header[i], f"{path} line {k}", comma_decimal) for i in wanted])
        line_no.append(k)
    data = np.array(rows, dtype=float).reshape(-1, len(wanted))
    if not np.all(np.isfinite(data[:, 0])):
        k = int(np.flatnonzero(~np.isfinite(data[:, 0]))[0])
        raise InputError(f"{path} data row {k + 1} has no PacketCounter; fix or remove the row")
    raw_counter = data[:, 0]
    bad = np.flatnonzero((raw_counter < 0) | (raw_counter > MAX_COUNTER) | (raw_counter % 1 != 0))
    if bad.size:
        k = int(bad[0])
        raise InputError(
            f"{path} line {line_no[k]}: PacketCounter {raw_counter[k]:.10g} is not a packet number "
            f"(a whole number from 0 to {MAX_COUNTER}); fix or remove the row"
        )
    ok = np.all(np.isfinite(data[:, 1:7]), axis=1)
    counter = unwrap_counter(data[:, 0].astype(np.int64))[ok]
    data = data[ok]
    step = np.diff(counter)
    if np.any(step < 0):
        k = int(np.flatnonzero(step < 0)[0])
        raise InputError(
            f"{path}: PacketCounter runs backwards ({counter[k]} then {counter[k + 1]}); "
            f"export the recording again or sort the rows"
        )
    keep = np.concatenate([[True], step > 0])[: counter.size]  # drop repeated packets
    _warn_changed_repeats(path, data, keep)
    data, counter = data[keep], counter[keep]
    if counter.size < 2:
        raise InputError(f"{path} has {counter.size} packet(s) with Acc and Gyr; export a longer recording")
    return XsensExport(
        path=path,
        rate_hz=rate,
        counter=counter,
        acc=data[:, 1:4],
        gyr=data[:, 4:7],
        mag=data[:, 7:10] if i_mag is not None else None,
    )


def _update_rate(path: str, comments: list[str]) -> float:
    """The rate of the last ``// Update Rate: …Hz`` line of ``comments`` (``.`` or ``,`` decimal), Hz.

    Raises:
        InputError: no such line, or a rate that is not positive or above the largest
            :attr:`InputBounds.rate_hz <lowerlimb.io.bounds.InputBounds.rate_hz>`.
    """
    rates = [float(m.group(1).replace(",", ".")) for line in comments if (m := _RATE.search(line))]
    if not rates:
        raise InputError(
            f"{path} has no '// Update Rate: …Hz' comment line; export with the header comments "
            f"enabled (MT Manager export option) or add the line"
        )
    hi = INPUT_BOUNDS.rate_hz[1]
    if not 0 < rates[-1] <= hi:
        raise InputError(
            f"{path} says '// Update Rate: {rates[-1]:g}Hz', not a sampling rate (0 < rate ≤ {hi:g} Hz); "
            f"correct the line to the rate the sensors recorded at, or export again from MT Manager"
        )
    return rates[-1]


def _check_rates(exports: dict[str, XsensExport], params: ImportParams) -> float:
    rates = {s: e.rate_hz for s, e in exports.items()}
    lo, hi = min(rates.values()), max(rates.values())
    if hi > lo * (1.0 + params.rate_tolerance):
        listing = ", ".join(f"{s} {r:g} Hz" for s, r in rates.items())
        raise InputError(
            f"the sensors were recorded at different update rates ({listing}); "
            f"export all sensors of one recording session at one rate"
        )
    return lo


def _align(exports: dict[str, XsensExport]) -> tuple[int, int]:
    """Shift counters to the first sensor's wrap; return the common (first, last) packet."""
    ref = next(iter(exports.values())).counter[0]
    for e in exports.values():
        e.counter = e.counter + COUNTER_PERIOD * int(round((ref - e.counter[0]) / COUNTER_PERIOD))
    first = max(int(e.counter[0]) for e in exports.values())
    last = min(int(e.counter[-1]) for e in exports.values())
    if last - first < 1:
        listing = ", ".join(f"{s} {e.counter[0]}–{e.counter[-1]}" for s, e in exports.items())
        raise InputError(
            f"the sensor files share no packets (PacketCounter ranges: {listing}); "
            f"map files of one recording session"
        )
    return first, last


def _fill(
    sensor: str, e: XsensExport, grid: np.ndarray, rate_hz: float, params: ImportParams
) -> tuple[FloatArray, FloatArray, FloatArray | None, int]:
    """Interpolate one sensor onto the common packet grid; refuse gaps over ``max_gap_s``."""
    inside = (e.counter >= grid[0]) & (e.counter <= grid[-1])
    c = e.counter[inside]
    step = np.diff(c)
    if step.size and step.max() - 1 > params.max_gap_s * rate_hz:
        k = int(np.argmax(step))
        raise PacketGapError(
            sensor, (c[k] + 1 - grid[0]) / rate_hz, (step[k] - 1) / rate_hz, params.max_gap_s, importer=True
        )

    def interp(x: FloatArray, at: np.ndarray) -> FloatArray:
        return np.column_stack([np.interp(grid, at, x[:, j]) for j in range(3)])

    acc, gyr = interp(e.acc[inside], c), interp(e.gyr[inside], c)
    mag = None
    if e.mag is not None:
        m = e.mag[inside]
        ok = np.all(np.isfinite(m), axis=1)
        if ok.sum() >= 2:
            mag = interp(m[ok], c[ok])
    return acc, gyr, mag, int(grid.size - c.size)


def load_xsens(
    directory: str | os.PathLike[str],
    mapping: Mapping[str, str],
    *,
    side: str | None = None,
    mag_field_ut: float = XSENS_MAG_FIELD_UT,
    params: ImportParams | None = None,
) -> ImportedRecording:
    """Read the MT Manager exports of one recording, one leg or two legs.

    Args:
        directory: folder holding one export per sensor, named with the sensor ID.
        mapping: ``{segment: sensor ID}`` with the segments ``pelvis, thigh, shank, foot``
            or the two-leg names ``pelvis, left_thigh, …, right_foot``; may also hold
            ``"side"`` (single leg).
        side: instrumented leg of a single-leg mapping (default: ``mapping["side"]``,
            else ``"left"``).
        mag_field_ut: µT per Xsens normalised magnetometer unit (the local field
            magnitude at the MT magnetic calibration).
        params: thresholds (default :class:`ImportParams`).

    Returns:
        The aligned recording (time from 0 s, m/s², rad/s, µT) with the number of
        filled packets per segment.

    Raises:
        FileNotFoundError: the directory does not exist.
        MappingError: unknown or missing segment, a sensor ID used twice, a bad side.
        SensorFileError: no file, or two files, for a sensor ID.
        ColumnNotFoundError: a required column is missing.
        PacketGapError: too many consecutive packets are missing.
        InputError: rates that disagree, no common packet range, bad cells.
    """
    params = params or ImportParams()
    folder = Path(directory)
    if not folder.is_dir():
        raise FileNotFoundError(f"directory not found: {folder}; give the folder of the MT Manager exports")
    if not (np.isfinite(mag_field_ut) and mag_field_ut > 0):
        raise InputError(f"mag_field_ut must be a positive field strength in µT, got {mag_field_ut}")
    ids = {k: str(v).strip() for k, v in mapping.items() if k != "side"}
    side = _resolve_side(side, mapping.get("side"))
    layout = sensor_layout(ids, "map")
    seen: dict[str, str] = {}
    for segment in layout:
        sid = ids[segment].upper()
        if not sid:
            raise MappingError(f"map.{segment}", "empty sensor ID; give the ID printed on the sensor")
        if sid in seen:
            raise MappingError(
                f"map.{segment}", f"sensor {sid} is also mapped to {seen[sid]}; give each segment its own"
            )
        seen[sid] = segment
    exports = {s: parse_xsens_export(find_sensor_file(folder, ids[s])) for s in layout}
    rate = _check_rates(exports, params)
    first, last = _align(exports)
    grid = np.arange(first, last + 1)
    acc, gyr, mag, filled = {}, {}, {}, {}
    for s, e in exports.items():
        acc[s], gyr[s], m, filled[s] = _fill(s, e, grid, rate, params)
        if m is not None:
            mag[s] = m * mag_field_ut
    if mag and len(mag) < len(layout):
        lacking = ", ".join(s for s in layout if s not in mag)
        warnings.warn(f"no Mag data for {lacking}; the trial is written without magnetometer", stacklevel=2)
    total = sum(filled.values())
    if total > params.warn_fill_fraction * grid.size * len(layout):
        warnings.warn(
            f"{total} of {grid.size * len(layout)} samples were missing packets filled by "
            f"interpolation ({', '.join(f'{s} {n}' for s, n in filled.items() if n)})",
            FilledPacketsWarning,
            stacklevel=2,
        )
    return ImportedRecording(
        time_s=(grid - first) / rate,
        acc=acc,
        gyr=gyr,
        mag=mag if len(mag) == len(layout) else None,
        side=None if len(layout) == 7 else side,
        source=str(folder),
        filled=filled,
    )


def _resolve_side(side: str | None, in_mapping: object) -> str:
    if side is not None and in_mapping is not None and side != in_mapping:
        raise MappingError("side", f"side {side!r} disagrees with the mapping's side {in_mapping!r}")
    chosen = side if side is not None else in_mapping if in_mapping is not None else "left"
    if chosen not in ("left", "right"):
        raise MappingError("side", f"side must be left or right, got {chosen!r}")
    return str(chosen)


def read_xsens(
    directory: str | os.PathLike[str],
    mapping: Mapping[str, str],
    *,
    side: str | None = None,
    mag_field_ut: float = XSENS_MAG_FIELD_UT,
    params: ImportParams | None = None,
) -> ImuTrial:
    """Read a single-leg recording from MT Manager exports into a validated :class:`ImuTrial`.

    Same arguments as :func:`load_xsens` (``mapping`` with ``pelvis, thigh, shank, foot``).
    A two-leg mapping raises :class:`InputError`: use :func:`load_xsens` and
    :meth:`ImportedRecording.to_csv`.

    Raises:
        FileNotFoundError, MappingError, SensorFileError, ColumnNotFoundError,
        PacketGapError, InputError: as :func:`load_xsens`, plus any problem of
        :meth:`ImuTrial.validate`.
    """
    return load_xsens(directory, mapping, side=side, mag_field_ut=mag_field_ut, params=params).to_trial()
