"""Read a vendor's per-column CSV into a trial through a :class:`~lowerlimb.io.csv_mapping.CsvMapping`.

The mapping JSON (schema in :mod:`lowerlimb.io.csv_mapping`) names the time
column and its unit, the x, y, z columns of each sensor's acc, gyr and
(optionally) mag with their units, the delimiter and decimal mark, and
optionally ``resample_hz`` and ``side``.

Choices:

- Time is shifted to start at 0 s (absolute clocks such as epoch
  nanoseconds become relative).
- Without ``resample_hz`` the source clock is kept and must already be
  uniform (``ImuTrial.validate`` checks it). With ``resample_hz`` every
  signal is linearly interpolated onto ``0, 1/rate, …`` up to the last
  source sample; the source time must increase, and an interval between two
  source samples longer than :attr:`ImportParams.max_gap_s` is refused
  (interpolating across it would invent motion).
- Units are converted with the factors of :mod:`lowerlimb.io.units`. A time
  unit that makes the source clock faster than
  :attr:`InputBounds.rate_hz <lowerlimb.io.bounds.InputBounds.rate_hz>` allows
  is refused as a wrong ``time.unit`` (ms data declared ``us``) when the trial
  is not resampled or would be too short; one that makes it slower than
  :data:`~lowerlimb.io.trial.MIN_RATE_HZ` (ms data declared ``s``, epoch ns
  declared ``ms``) is refused too. A gyro unit that puts the gyro beyond
  :data:`~lowerlimb.conventions.MAX_GYRO_RAD_S` (deg/s data declared ``rad/s``)
  or an accelerometer unit that puts its median magnitude below
  :data:`~lowerlimb.conventions.MIN_MEDIAN_ACC_MPS2` (g data declared ``m/s^2``)
  is refused when another unit of the mapping fits (:func:`check_signal_units`).
  Each message names the unit that fits and says to set it in the mapping, as
  the data are right and the mapping is not.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from lowerlimb.conventions import MAX_GYRO_RAD_S, MIN_MEDIAN_ACC_MPS2, FloatArray
from lowerlimb.errors import InputError, NonFiniteValueError, TooShortError, UnitError
from lowerlimb.io.trial import MIN_DURATION_S, MIN_RATE_HZ, ImuTrial, unreadable_csv

from .bounds import INPUT_BOUNDS
from .csv_mapping import CsvMapping
from .errors import ColumnNotFoundError, PacketGapError
from .mag_cells import bridged_magnetometer
from .params import ImportParams
from .recording import ImportedRecording
from .text_file import read_text
from .time_axis import require_increasing
from .uneven_clock import ClockParams, to_uniform_clock
from .units import ACC_UNITS, GYR_UNITS, QUANTITY_UNITS, TIME_UNITS


def _as_mapping(mapping: CsvMapping | Mapping[str, Any] | str | os.PathLike[str]) -> CsvMapping:
    if isinstance(mapping, CsvMapping):
        return mapping
    if isinstance(mapping, Mapping):
        return CsvMapping.from_dict(mapping)
    return CsvMapping.from_json(mapping)


def _read_columns(path: str, m: CsvMapping, names: list[str]) -> FloatArray:
    """(N, len(names)) floats of the named columns; empty cells are NaN.

    Raises:
        NotTextError: a folder, a binary file or non-UTF-8 text.
        InputError: an empty file, a cell the csv module cannot read, a non-numeric cell, a
            named column the header holds twice, or a last row cut short (an interrupted recording).
        ColumnNotFoundError: a name not in the header.
    """
    text = read_text(path, "a CSV file", export_fix="export the recording as CSV text")
    try:
        rows = [
            r
            for r in csv.reader(io.StringIO(text, newline=""), delimiter=m.delimiter)
            if any(c.strip() for c in r)
        ]
    except csv.Error as e:
        raise unreadable_csv(path, e) from None
    if not rows:
        raise InputError(f"{path} is empty; give a CSV with a header row")
    header = [h.strip() for h in rows[0]]
    for n in names:
        if n not in header:
            raise ColumnNotFoundError(n, header, path)
        if header.count(n) > 1:
            at = " and ".join(str(i + 1) for i, h in enumerate(header) if h == n)
            raise InputError(
                f"{path} has the column {n!r} {header.count(n)} times in its header (columns {at}); "
                f"the mapping reads columns by name, so rename or delete all but one"
            )
    _refuse_interrupted_last_row(path, rows)
    idx = [header.index(n) for n in names]
    out = np.full((len(rows) - 1, len(names)), np.nan)
    for r, row in enumerate(rows[1:]):
        for j, i in enumerate(idx):
            text = row[i].strip() if i < len(row) else ""
            if not text:
                continue
            try:
                out[r, j] = float(text.replace(",", ".") if m.decimal == "," else text)
            except ValueError:
                raise InputError(
                    f"{path} data row {r + 1}: column '{names[j]}' is not a number ({text!r}); "
                    f"fix the cell, or the delimiter/decimal of the mapping"
                ) from None
    return out


def _refuse_interrupted_last_row(path: str, rows: list[list[str]]) -> None:
    """Refuse a last row shorter than the header when the row before it is not (a recording cut off).

    Rows that are all short (a writer that leaves out trailing empty cells) are not refused.

    Raises:
        InputError: naming the row, its number of values and the header's.
    """
    width = len(rows[0])
    if len(rows) >= 2 and len(rows[-1]) < width and (len(rows) == 2 or len(rows[-2]) >= width):
        raise InputError(
            f"{path}: the last data row {len(rows) - 1} has {len(rows[-1])} of {width} values: an "
            f"interrupted recording? delete that row"
        )


def check_time_unit(time_s: FloatArray, m: CsvMapping) -> None:
    """Refuse a ``time.unit`` that makes the source clock implausibly fast or slow.

    The clock is refused when its median step gives a rate below :data:`MIN_RATE_HZ`
    (ms data declared ``s``, epoch nanoseconds declared ``ms``), or above
    :attr:`InputBounds.rate_hz <lowerlimb.io.bounds.InputBounds.rate_hz>` while the
    trial is either not resampled or shorter than :data:`MIN_DURATION_S` (ms data
    declared ``us``; a fast source resampled to a plausible rate is fine).

    Args:
        time_s: (N,) source times converted with ``m.time_unit``, s, starting at 0.
        m: the mapping (its ``time_unit`` and ``resample_hz``).

    Raises:
        UnitError: naming ``time.unit``, the rate it gives, and the unit to set in the
            mapping when one gives a rate within ``InputBounds.rate_hz``.
    """
    steps = np.diff(time_s)
    med = float(np.median(steps)) if steps.size else 0.0
    lo, hi = INPUT_BOUNDS.rate_hz
    if med > 1.0 / MIN_RATE_HZ:
        _slow_time_unit(med, m)
    if not med > 0 or 1.0 / med <= hi:
        return
    duration = float(time_s[-1])
    if m.resample_hz is not None and duration >= MIN_DURATION_S:
        return
    raw_step = med / TIME_UNITS[m.time_unit]
    fits = [
        (u, 1.0 / (raw_step * f))
        for u, f in TIME_UNITS.items()
        if f > TIME_UNITS[m.time_unit] and lo <= 1.0 / (raw_step * f) <= hi
    ]
    fix = (
        f'if the time column is in {fits[0][0]}, set "unit": "{fits[0][0]}" in the mapping\'s "time" '
        f"(a rate of {fits[0][1]:.4g} Hz)"
        if fits
        else 'check the mapping\'s time unit, or add "resample_hz" to the mapping to resample the trial'
    )
    raise UnitError(
        "time.unit",
        1.0 / med,
        f"time steps of {raw_step:.4g} {m.time_unit} give a rate of {1.0 / med:.4g} Hz and a "
        f"{duration:.3g} s trial, faster than the {hi:g} Hz a trial may have; {fix}",
    )


def _slow_time_unit(med: float, m: CsvMapping) -> None:
    """Refuse a clock whose median step ``med`` (s) is too long, naming the shorter unit that fits."""
    raw_step = med / TIME_UNITS[m.time_unit]
    lo, hi = INPUT_BOUNDS.rate_hz
    shorter = sorted(
        ((u, f) for u, f in TIME_UNITS.items() if f < TIME_UNITS[m.time_unit]), key=lambda uf: -uf[1]
    )
    fits = [(u, 1.0 / (raw_step * f)) for u, f in shorter if lo <= 1.0 / (raw_step * f) <= hi]
    fix = (
        f'if the time column is in {fits[0][0]}, set "unit": "{fits[0][0]}" in the mapping\'s "time" '
        f"(a rate of {fits[0][1]:.4g} Hz)"
        if fits
        else 'check the "unit" of the mapping\'s "time" (s, ms, us or ns), or map a column of times'
    )
    numbers = "; if it holds sample numbers, map a column of times instead" if raw_step == 1 and fits else ""
    raise UnitError(
        "time.unit",
        1.0 / med,
        f"time steps of {raw_step:.4g} {m.time_unit} give a rate of {1.0 / med:.4g} Hz, slower than the "
        f"{MIN_RATE_HZ:g} Hz a trial may have; {fix}{numbers}",
    )


def check_signal_units(acc: Mapping[str, FloatArray], gyr: Mapping[str, FloatArray], m: CsvMapping) -> None:
    """Refuse a gyro or accelerometer unit of the mapping that another of its units would fix.

    The checks are those of ``ImuTrial.validate`` (a gyro beyond :data:`MAX_GYRO_RAD_S`,
    an accelerometer median magnitude below :data:`MIN_MEDIAN_ACC_MPS2`), made here
    where the fix is known: the data are right and the mapping's ``unit`` is not.
    Anything no other unit fixes is left to ``ImuTrial.validate``.

    Args:
        acc: ``{sensor: (N, 3)}`` specific force converted with the mapping's unit, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity converted with the mapping's unit, rad/s.
        m: the mapping.

    Raises:
        UnitError: naming the sensor, its values in the declared unit, and the unit to set.
    """
    for sensor, quantities in m.sensors.items():
        unit = quantities["gyr"].unit
        peak = float(np.max(np.linalg.norm(gyr[sensor], axis=1)))  # rad/s
        if peak > MAX_GYRO_RAD_S:
            raw = peak / GYR_UNITS[unit]
            for other, f in GYR_UNITS.items():
                if f != GYR_UNITS[unit] and raw * f <= MAX_GYRO_RAD_S:
                    raise UnitError(
                        f"sensors.{sensor}.gyr.unit",
                        peak,
                        f"{sensor} gyro values up to {raw:.0f} {unit} are beyond a gyro's range "
                        f'({MAX_GYRO_RAD_S:g} rad/s) and look like {other}; set "unit": "{other}" '
                        f'in the mapping\'s {sensor} "gyr"',
                    )
        unit = quantities["acc"].unit
        median = float(np.median(np.linalg.norm(acc[sensor], axis=1)))  # m/s²
        if median < MIN_MEDIAN_ACC_MPS2:
            raw = median / ACC_UNITS[unit]
            for other, f in ACC_UNITS.items():
                if (
                    f != ACC_UNITS[unit]
                    and MIN_MEDIAN_ACC_MPS2 <= raw * f <= INPUT_BOUNDS.max_median_acc_mps2
                ):
                    raise UnitError(
                        f"sensors.{sensor}.acc.unit",
                        median,
                        f"{sensor} accelerometer median magnitude {raw:.3g} {unit} is too small for "
                        f'gravity and looks like {other}; set "unit": "{other}" in the mapping\'s '
                        f'{sensor} "acc"',
                    )


def resample_uniform(
    time_s: FloatArray, data: FloatArray, rate_hz: float, max_gap_s: float, names: list[str]
) -> tuple[FloatArray, FloatArray]:
    """Linear interpolation onto a uniform clock.

    Args:
        time_s: (N,) source times, s, strictly increasing, starting at 0.
        data: (N, C) samples (any units).
        rate_hz: output rate, Hz.
        max_gap_s: longest source interval bridged, s.
        names: C column names (for messages).

    Returns:
        ((M,) times ``k / rate_hz`` up to ``time_s[-1]``, (M, C) interpolated samples).

    Raises:
        NonFiniteValueError: a NaN or empty cell in ``data``.
        TimeAxisError: non-increasing source time.
        PacketGapError: a source interval longer than ``max_gap_s``.
    """
    bad = np.argwhere(~np.isfinite(data))
    if bad.size:
        raise NonFiniteValueError(names[bad[0][1]], int(bad[0][0]) + 1)
    require_increasing(time_s, fix="sort the rows and drop duplicates before resampling")
    dt = np.diff(time_s)
    if dt.size and dt.max() > max_gap_s:
        k = int(np.argmax(dt))
        raise PacketGapError("the recording", float(time_s[k]), float(dt[k]), max_gap_s, importer=True)
    n = int(np.floor(time_s[-1] * rate_hz + 1e-9)) + 1
    grid = np.arange(n) / rate_hz
    return grid, np.column_stack([np.interp(grid, time_s, data[:, j]) for j in range(data.shape[1])])


def load_mapped_csv(
    path: str | os.PathLike[str],
    mapping: CsvMapping | Mapping[str, Any] | str | os.PathLike[str],
    *,
    params: ImportParams | None = None,
) -> ImportedRecording:
    """Read a per-column vendor CSV, one leg or two legs.

    Args:
        path: the CSV file.
        mapping: a :class:`CsvMapping`, its JSON dict, or the path of the JSON file.
        params: thresholds (default :class:`ImportParams`).

    Returns:
        The recording in trial units (time from 0 s, m/s², rad/s, µT).

    Raises:
        FileNotFoundError: the CSV or mapping file does not exist.
        MappingError: a bad mapping field.
        ColumnNotFoundError: a mapped column is not in the CSV header.
        NotTextError: the CSV (or the mapping file) is a folder, a binary file or not UTF-8.
        UnitError: a ``time.unit`` that makes the clock implausibly fast or slow
            (:func:`check_time_unit`), or a gyro or accelerometer unit that another unit would
            fix (:func:`check_signal_units`).
        NonFiniteValueError: an empty or non-finite time cell, or bad samples when resampling.
        TimeAxisError, PacketGapError: bad time when resampling.
        InputError: an empty file, a non-numeric cell, a mapped column twice in the header, or a
            last row cut short.
    """
    params = params or ImportParams()
    m = _as_mapping(mapping)
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"CSV file not found: {path}")
    names = [m.time_column]
    for quantities in m.sensors.values():
        for q in QUANTITY_UNITS:
            if q in quantities:
                names += list(quantities[q].columns)
    raw = _read_columns(path, m, names)
    if raw.shape[0] < 2:
        raise TooShortError(0.0, MIN_DURATION_S)
    t = raw[:, 0] * TIME_UNITS[m.time_unit]
    bad_t = np.flatnonzero(~np.isfinite(t))
    if bad_t.size:
        raise NonFiniteValueError(m.time_column, int(bad_t[0]) + 1)
    t = t - t[0]
    check_time_unit(t, m)
    layout = [(sensor, q) for sensor, qs in m.sensors.items() for q in QUANTITY_UNITS if q in qs]
    data, layout = _bridged_mag(t, raw[:, 1:], layout, params)
    if m.resample_hz is not None:
        t, data = resample_uniform(t, data, m.resample_hz, params.max_gap_s, names[1:])
    else:  # uneven steps onto the recorder's own constant clock, as a trial CSV's
        try:
            t, (data,), _ = to_uniform_clock(t, [data], ClockParams(max_gap_s=params.max_gap_s))
        except PacketGapError as e:
            raise PacketGapError("the recording", e.start_s, e.length_s, e.limit_s, importer=True) from None
    signals: dict[str, dict[str, FloatArray]] = {q: {} for q in QUANTITY_UNITS}
    for k, (sensor, q) in enumerate(layout):
        factor = QUANTITY_UNITS[q][m.sensors[sensor][q].unit]
        signals[q][sensor] = np.ascontiguousarray(data[:, 3 * k : 3 * k + 3] * factor)
    check_signal_units(signals["acc"], signals["gyr"], m)
    return ImportedRecording(
        time_s=t,
        acc=signals["acc"],
        gyr=signals["gyr"],
        mag=signals["mag"] or None,
        side=None if len(m.sensors) == 7 else (m.side or "left"),
        source=path,
    )


def _bridged_mag(
    time_s: FloatArray, data: FloatArray, layout: list[tuple[str, str]], params: ImportParams
) -> tuple[FloatArray, list[tuple[str, str]]]:
    """The magnetometer's empty cells bridged, or its columns dropped (:mod:`~lowerlimb.io.mag_cells`).

    ``data``: (N, 3·len(layout)), a block of three columns per ``(sensor, quantity)`` of
    ``layout``. Returns the data and the layout left.
    """
    blocks = {sensor: k for k, (sensor, q) in enumerate(layout) if q == "mag"}
    if not blocks:
        return data, layout
    mag = bridged_magnetometer(time_s, {s: data[:, 3 * k : 3 * k + 3] for s, k in blocks.items()}, params)
    if mag is not None:
        out = data.copy()
        for s, k in blocks.items():
            out[:, 3 * k : 3 * k + 3] = mag[s]
        return out, layout
    kept = [k for k, (_, q) in enumerate(layout) if q != "mag"]
    return data[:, [3 * k + j for k in kept for j in range(3)]], [layout[k] for k in kept]


def read_mapped_csv(
    path: str | os.PathLike[str],
    mapping: CsvMapping | Mapping[str, Any] | str | os.PathLike[str],
    *,
    params: ImportParams | None = None,
) -> ImuTrial:
    """Read a single-leg per-column vendor CSV into a validated :class:`ImuTrial`.

    Same arguments as :func:`load_mapped_csv`. A two-leg mapping raises
    :class:`InputError`: use :func:`load_mapped_csv` and :meth:`ImportedRecording.to_csv`.

    Raises:
        FileNotFoundError, MappingError, ColumnNotFoundError, InputError: as
        :func:`load_mapped_csv`, plus any problem of :meth:`ImuTrial.validate`.
    """
    return load_mapped_csv(path, mapping, params=params).to_trial()
