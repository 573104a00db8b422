r"""``CsvMapping``: how to read one vendor's per-column CSV (a small JSON file).

Schema (``format`` is optional; unknown keys are refused so that typos surface)::

    {
      "format": "lowerlimb-csv-mapping/1",
      "delimiter": ",",              # optional, one character (default ","; "\t" for tabs)
      "decimal": ".",                # optional, "." or "," (default ".")
      "time": {"column": "Timestamp", "unit": "ms"},     # unit: s, ms, us, ns
      "resample_hz": 100,            # optional: linear interpolation onto a uniform clock,
                                     #   within InputBounds.rate_hz (20 to 2000 Hz)
      "side": "left",                # optional, single leg only (default left)
      "sensors": {
        "pelvis": {
          "acc": {"columns": ["AccX", "AccY", "AccZ"], "unit": "g"},        # m/s^2 or g
          "gyr": {"columns": ["GyrX", "GyrY", "GyrZ"], "unit": "deg/s"},    # rad/s or deg/s
          "mag": {"columns": ["MagX", "MagY", "MagZ"], "unit": "uT"}        # optional: uT, nT, mT, gauss
        },
        "thigh": {…}, "shank": {…}, "foot": {…}
      }
    }

``sensors`` holds either ``pelvis, thigh, shank, foot`` or the two-leg names
``pelvis, left_thigh, left_shank, left_foot, right_thigh, right_shank,
right_foot``. ``mag`` must be given for every sensor or for none. Every key,
also inside ``time`` and the ``acc``/``gyr``/``mag`` entries, is checked, and
each source column may feed one signal only (the time column included): a
column named twice is a copy-paste slip that would make two axes, or two
sensors, read the same data.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..conventions import SENSORS
from .bounds import INPUT_BOUNDS
from .errors import ColumnReusedError, MappingError
from .recording import sensor_layout
from .text_file import read_text
from .trial import one_side_prefix
from .units import QUANTITY_UNITS, TIME_UNITS

MAPPING_FORMAT = "lowerlimb-csv-mapping/1"
_TOP_KEYS = {"format", "delimiter", "decimal", "time", "resample_hz", "side", "sensors"}
#: The keys of ``time`` and of one ``acc``/``gyr``/``mag`` entry.
_TIME_KEYS = ("column", "unit")
_QUANTITY_KEYS = ("columns", "unit")


@dataclass(frozen=True)
class ColumnTriple:
    """The x, y, z column names of one quantity and the unit they are in."""

    columns: tuple[str, str, str]
    unit: str


@dataclass(frozen=True)
class CsvMapping:
    """A parsed and checked CSV mapping (see the module docstring for the JSON schema).

    Attributes:
        time_column: name of the time column.
        time_unit: one of :data:`~lowerlimb.io.units.TIME_UNITS`.
        sensors: ``{sensor: {"acc"|"gyr"|"mag": ColumnTriple}}``.
        delimiter: field separator, one character.
        decimal: decimal mark, ``"."`` or ``","``.
        resample_hz: uniform output rate, Hz, or None to keep the source clock (put on its own
            constant rate when its steps vary, :mod:`lowerlimb.io.uneven_clock`).
        side: instrumented leg (single-leg mappings), or None.
    """

    time_column: str
    time_unit: str
    sensors: dict[str, dict[str, ColumnTriple]]
    delimiter: str = ","
    decimal: str = "."
    resample_hz: float | None = None
    side: str | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> CsvMapping:
        """Check a mapping read from JSON.

        Raises:
            MappingError: naming the first bad field (a wrong type, an unknown key, a unit or
                ``resample_hz`` out of range); :class:`ColumnReusedError` for a source column
                mapped twice.
        """
        if not isinstance(data, Mapping):
            raise MappingError("(top level)", "the mapping must be a JSON object")
        stray = sorted(set(data) - _TOP_KEYS)
        if stray:
            raise MappingError(stray[0], f"unknown key; the keys are {', '.join(sorted(_TOP_KEYS))}")
        if data.get("format", MAPPING_FORMAT) != MAPPING_FORMAT:
            raise MappingError("format", f"expected {MAPPING_FORMAT!r}, got {data['format']!r}")
        delimiter = _text(data, "delimiter", ",")
        decimal = _text(data, "decimal", ".")
        if len(delimiter) != 1:
            raise MappingError("delimiter", f"give one character (e.g. ',' ';' '\\t'), got {delimiter!r}")
        if decimal not in (".", ","):
            raise MappingError("decimal", f"give '.' or ',', got {decimal!r}")
        if decimal == delimiter:
            raise MappingError("decimal", f"the decimal mark {decimal!r} is also the delimiter")
        time = data.get("time")
        if not isinstance(time, Mapping):
            raise MappingError("time", 'give {"column": NAME, "unit": "s"|"ms"|"us"|"ns"}')
        _known_keys(time, _TIME_KEYS, "time")
        time_column = _text(time, "column", None, "time.column")
        time_unit = _unit(time, "time.unit", TIME_UNITS)
        resample = _resample_hz(data.get("resample_hz"))
        side = data.get("side")
        if side is not None and side not in ("left", "right"):
            raise MappingError("side", f"give 'left' or 'right', got {side!r}")
        sensors_in = data.get("sensors")
        if not isinstance(sensors_in, Mapping) or not sensors_in:
            raise MappingError("sensors", "give an object {segment: {acc: …, gyr: …[, mag: …]}}")
        sensors_in, named, side = _one_prefixed_leg(sensors_in, side)
        layout = sensor_layout(sensors_in, "sensors")
        if side is not None and len(layout) == 7:
            raise MappingError("side", "a two-leg mapping has no side; remove it")
        sensors = {s: _sensor(sensors_in[s], f"sensors.{named.get(s, s)}") for s in layout}
        with_mag = [s for s in layout if "mag" in sensors[s]]
        if with_mag and len(with_mag) != len(layout):
            lacking = next(s for s in layout if "mag" not in sensors[s])
            raise MappingError(f"sensors.{lacking}.mag", "give mag for every sensor or for none")
        _check_columns_once(time_column, sensors)
        return cls(
            time_column=time_column,
            time_unit=time_unit,
            sensors=sensors,
            delimiter=delimiter,
            decimal=decimal,
            resample_hz=resample,
            side=side,
        )

    @classmethod
    def from_json(cls, path: str | os.PathLike[str]) -> CsvMapping:
        """Read and check a mapping JSON file.

        Raises:
            FileNotFoundError: when ``path`` does not exist.
            NotTextError: ``path`` is a folder, a binary file or not UTF-8.
            MappingError: a file over :attr:`InputBounds.max_json_bytes`, invalid (or too
                deeply nested) JSON, or a bad field.
        """
        path = os.fspath(path)
        if not os.path.exists(path):
            raise FileNotFoundError(f"mapping file not found: {path}")
        if os.path.isfile(path) and os.path.getsize(path) > INPUT_BOUNDS.max_json_bytes:
            raise MappingError(
                "(file)",
                f"{path} holds {os.path.getsize(path)} bytes, more than a mapping ever needs "
                f"({INPUT_BOUNDS.max_json_bytes}); give the mapping JSON, not the data",
            )
        text = read_text(path, "a CSV mapping (JSON)", export_fix="give the mapping JSON file")
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise MappingError("(file)", f"{path} is not valid JSON ({e}); fix the syntax") from None
        except RecursionError:
            raise MappingError("(file)", f"{path} nests its JSON too deeply; give a mapping JSON") from None
        return cls.from_dict(data)


def _one_prefixed_leg(sensors: Mapping[str, Any], side: Any) -> tuple[Mapping[str, Any], dict[str, str], Any]:
    """One leg named with its side's two-leg names (``pelvis, right_thigh, …``) as that leg.

    Returns:
        (the sensors under single-leg names, {single-leg name: name as given}, the side);
        the inputs and ``{}`` for any other set of names.

    Raises:
        MappingError: a ``side`` other than the one the names give.
    """
    prefix = one_side_prefix([f"{n}_" for n in sensors])
    if prefix is None or set(sensors) != {"pelvis", *(f"{prefix}_{p}" for p in SENSORS[1:])}:
        return sensors, {}, side
    if side is not None and side != prefix:
        raise MappingError("side", f"the sensors are named as the {prefix} leg's; give {prefix!r} or no side")
    named = {n.removeprefix(f"{prefix}_"): n for n in sensors}
    return {single: sensors[n] for single, n in named.items()}, named, prefix


def _text(d: Mapping[str, Any], key: str, default: str | None, field: str | None = None) -> str:
    value = d.get(key, default)
    if not isinstance(value, str) or not value:
        raise MappingError(field or key, f"give a non-empty string, got {value!r}")
    return value


def _unit(d: Mapping[str, Any], field: str, units: Mapping[str, float]) -> str:
    unit = d.get("unit")
    if not isinstance(unit, str):
        what = "missing" if unit is None else f"give the unit as a string, not {unit!r}"
        raise MappingError(field, f"{what}; use one of {', '.join(units)}")
    if unit not in units:
        raise MappingError(field, f"unknown unit {unit!r}; use one of {', '.join(units)}")
    return unit


def _known_keys(d: Mapping[str, Any], keys: tuple[str, ...], field: str) -> None:
    """Refuse a key of the object at ``field`` that is not one of ``keys`` (a typo would be ignored)."""
    stray = sorted(str(k) for k in d if k not in keys)
    if stray:
        raise MappingError(f"{field}.{stray[0]}", f"unknown key; the keys are {', '.join(keys)}")


def _resample_hz(value: Any) -> float | None:
    """``resample_hz`` as a float within :attr:`InputBounds.rate_hz`, or None when not given."""
    if value is None:
        return None
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not math.isfinite(value)
        or value <= 0
    ):
        raise MappingError("resample_hz", f"give a positive rate in Hz, got {value!r}")
    lo, hi = INPUT_BOUNDS.rate_hz
    if not lo <= value <= hi:
        raise MappingError(
            "resample_hz", f"{value:g} Hz is out of range; give a sampling rate from {lo:g} to {hi:g} Hz"
        )
    return float(value)


def _check_columns_once(time_column: str, sensors: Mapping[str, Mapping[str, ColumnTriple]]) -> None:
    """Refuse a source column mapped twice (time column included).

    Raises:
        ColumnReusedError: naming the column and the mapping fields of its two uses.
    """
    seen = {time_column: "time.column"}
    for sensor, quantities in sensors.items():
        for q, triple in quantities.items():
            for axis, column in enumerate(triple.columns):
                field = f"sensors.{sensor}.{q}.columns[{axis}]"
                if column in seen:
                    raise ColumnReusedError(column, seen[column], field)
                seen[column] = field


def _sensor(d: Any, field: str) -> dict[str, ColumnTriple]:
    if not isinstance(d, Mapping):
        raise MappingError(field, "give an object {acc: …, gyr: …[, mag: …]}")
    stray = sorted(set(d) - set(QUANTITY_UNITS))
    if stray:
        raise MappingError(f"{field}.{stray[0]}", "unknown quantity; use acc, gyr and optionally mag")
    out = {}
    for q in QUANTITY_UNITS:
        if q not in d:
            if q == "mag":
                continue
            raise MappingError(f"{field}.{q}", f'missing; give {{"columns": [X, Y, Z], "unit": …}} for {q}')
        entry = d[q]
        if not isinstance(entry, Mapping):
            raise MappingError(f"{field}.{q}", 'give {"columns": [X, Y, Z], "unit": …}')
        _known_keys(entry, _QUANTITY_KEYS, f"{field}.{q}")
        cols = entry.get("columns")
        if (
            not isinstance(cols, (list, tuple))
            or len(cols) != 3
            or not all(isinstance(c, str) and c for c in cols)
        ):
            raise MappingError(f"{field}.{q}.columns", f"give three column names [X, Y, Z], got {cols!r}")
        out[q] = ColumnTriple(
            (cols[0], cols[1], cols[2]), _unit(entry, f"{field}.{q}.unit", QUANTITY_UNITS[q])
        )
    return out
