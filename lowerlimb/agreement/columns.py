"""A reference's header read as our column names, and why none of them is one of a result's.

A reference's header may write names in any case and annotate the unit a column is in
(``Time (s)``, ``KNEE_FLEXION [deg]``): where that unit is ours (s, deg, m) the annotation is
dropped, as for a trial CSV (:mod:`lowerlimb.io.header_units`); another unit (``time [ms]``,
``time_ms``, ``knee_flexion (rad)``) is refused naming the conversion, since values in the wrong
unit would give plausible-looking but meaningless statistics. When no reference column is one
of ours, :func:`no_common_columns_error` names the likely reason: the result holds the other
leg, or lacks the table the reference's columns belong to.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from ..conventions import ANGLE_COLUMNS, POSITION_COLUMNS, SIDES
from ..errors import InputError
from ..io.header_units import OWN_UNITS
from ..io.trial import header_names
from .errors import NoCommonColumnsError

__all__ = ["TABLE_OF_NAME", "no_common_columns_error", "reference_header"]

#: Our table of each one-leg column name (the name without a ``left_``/``right_`` prefix).
TABLE_OF_NAME: dict[str, str] = {c: "angles.csv" for c in ANGLE_COLUMNS[1:]} | {
    c: "positions.csv" for c in POSITION_COLUMNS[1:]
}

#: Units a reference column's annotation may name, normalised, per table: our own unit's
#: spellings, then other units with the fix that converts them.
_OWN = {
    "time": OWN_UNITS["time"],
    "angles.csv": frozenset({"deg", "degree", "degrees", "°"}),
    "positions.csv": frozenset({"m", "metre", "metres", "meter", "meters"}),
}
_MS, _US, _NS = (
    ("milliseconds", "divide by 1000"),
    ("microseconds", "divide by 1e6"),
    ("nanoseconds", "divide by 1e9"),
)
_MIN, _RAD = ("minutes", "multiply by 60"), ("radians", "multiply by 180/π")
_MM, _CM = ("millimetres", "divide by 1000"), ("centimetres", "divide by 100")
_OTHER: dict[str, dict[str, tuple[str, str]]] = {
    "time": {
        "ms": _MS,
        "msec": _MS,
        "milliseconds": _MS,
        "us": _US,
        "µs": _US,
        "microseconds": _US,
        "ns": _NS,
        "nanoseconds": _NS,
        "min": _MIN,
        "minutes": _MIN,
    },
    "angles.csv": {"rad": _RAD, "radians": _RAD},
    "positions.csv": {
        "mm": _MM,
        "millimetres": _MM,
        "millimeters": _MM,
        "cm": _CM,
        "centimetres": _CM,
        "centimeters": _CM,
    },
}
_OUR_UNIT = {"time": "seconds", "angles.csv": "degrees", "positions.csv": "metres"}

_ANNOTATED = re.compile(r"(?P<name>[^\[\(]*?)\s*(?:\[(?P<bracket>[^\]]*)\]|\((?P<paren>[^)]*)\))\s*")
_TIME_SUFFIX = re.compile(r"time_(?P<unit>[a-z]+)")
_SEPARATORS = ((";", "';'"), ("\t", "tabs"), ("|", "'|'"))


def reference_header(cells: Sequence[str], path: str, what: str = "reference") -> list[str]:
    """A reference's header cells as column names: lower case, our units' annotations dropped.

    ``"Time (s)"`` → ``"time"``, ``"KNEE_FLEXION [deg]"`` → ``"knee_flexion"``; ``"time_s"`` is
    ``"time"`` when no column is named ``time``. Names that are none of ours keep their annotation.

    Args:
        cells: the header row's cells.
        path: the file, for the messages.
        what: how to name the file in the messages.

    Raises:
        InputError: a time, angle or position column annotated with another unit than s, deg
            or m (``time [ms]``, ``time_ms``, ``hip_flexion (rad)``), naming the conversion; or,
            when no column is ``time``, a header separated by ``;``, tabs or ``|``.
    """
    names = header_names(cells)
    out: list[str] = []
    for cell, name in zip(cells, names, strict=True):
        m = _ANNOTATED.fullmatch(name)
        if m is not None:
            base = m["name"]
            table = "time" if base == "time" else _table(base)
            if table is not None:
                unit = m["bracket"] if m["bracket"] is not None else m["paren"]
                _check_unit(unit, table, cell, base, path, what)
                name = base
        out.append(name)
    if "time" not in out:
        line = ",".join(cells)
        for sep, label in _SEPARATORS:
            if sep in line and len(cells) <= line.count(sep):
                raise InputError(
                    f"{what} {path} is separated by {label}, not commas; save it comma-separated "
                    f"(with '.' as the decimal mark)"
                )
        for i, name in enumerate(out):
            m = _TIME_SUFFIX.fullmatch(name)
            if m is not None and (m["unit"] in _OWN["time"] or m["unit"] in _OTHER["time"]):
                _check_unit(m["unit"], "time", cells[i], "time", path, what)
                out[i] = "time"
                break
    return out


def no_common_columns_error(
    reference_columns: Sequence[str],
    our_columns: Sequence[str],
    path: str,
    *,
    directory: str = "",
    side: str | None = None,
    missing_tables: Sequence[str] = (),
) -> NoCommonColumnsError:
    """The error for a reference none of whose columns is one of ours, naming the likely reason.

    In order: the result is one leg and the reference names the other (or both, or its own
    with a ``left_``/``right_`` prefix); the result is two legs and the reference names no
    leg; the result lacks the table (``angles.csv``, ``positions.csv``) that the reference's
    columns belong to; otherwise the columns are not ours (:class:`NoCommonColumnsError`).

    Args:
        reference_columns: the reference's column names (not ``time``).
        our_columns: the result's column names.
        path: the reference file, for the message.
        directory: the result folder, for the message (``"the result"`` when empty).
        side: the result's leg: ``"left"``, ``"right"``, ``"both"`` (two legs) or None (unknown).
        missing_tables: the result's tables that are not in its folder.

    Returns:
        The error to raise.
    """
    result = directory or "the result"
    known: list[tuple[str, str | None, str]] = []
    for c in reference_columns:
        leg, table = _side_and_table(c)
        if table is not None:
            known.append((c, leg, table))
    ref_sides = {s for _, s, _ in known}
    shown = ", ".join(c for c, _, _ in known[:3]) + (", …" if len(known) > 3 else "")
    ours = ", ".join(list(our_columns)[:3])
    if known and side != "both" and ref_sides != {None}:
        prefixed = sorted(s for s in ref_sides if s is not None)
        if len(prefixed) == 2:
            what = "both legs"
            fix = "compare it with a two-leg result of the same trial (calibrate the two-leg trial)"
        elif side in SIDES and prefixed[0] != side:
            other = prefixed[0]
            what = f"the {other} leg"
            fix = f"to compare the {other} leg, give the result of a {other}-leg or two-leg trial"
        else:
            leg = prefixed[0]
            what = f"the {leg} leg with a '{leg}_' prefix"
            fix = (
                f"drop the '{leg}_' prefix from the reference's columns"
                if side == leg
                else f"if {result} is the {leg} leg, drop the '{leg}_' prefix from the reference's columns"
            )
        leg_text = f"the {side} leg's" if side in SIDES else "a one-leg"
        return NoCommonColumnsError(
            reference_columns,
            our_columns,
            path,
            message=f"{result} is {leg_text} result (columns {ours}, …) but reference {path} names "
            f"{what} ({shown}); {fix}",
        )
    if known and side == "both" and None in ref_sides:
        return NoCommonColumnsError(
            reference_columns,
            our_columns,
            path,
            message=f"{result} is a two-leg result whose columns name the leg ({ours}, …) but reference "
            f"{path} names no leg ({shown}); prefix the reference's columns with the leg they measure, "
            f"'left_' or 'right_'",
        )
    absent = [t for t in dict.fromkeys(t for _, _, t in known) if t in missing_tables]
    if absent:
        table = absent[0]
        output = table.removesuffix(".csv")
        return NoCommonColumnsError(
            reference_columns,
            our_columns,
            path,
            message=f"{result} has no {table} (reference {path} holds its columns: {shown}); re-run "
            f"calibrate with the {output} output ('--outputs' naming {output}, or no '--outputs')",
        )
    return NoCommonColumnsError(reference_columns, our_columns, path)


def _table(name: str) -> str | None:
    """Our table holding the column ``name`` (with or without a side prefix), or None."""
    return _side_and_table(name)[1]


def _side_and_table(name: str) -> tuple[str | None, str | None]:
    """``(side prefix or None, our table or None)`` of a column name."""
    for side in SIDES:
        if name.startswith(f"{side}_") and name[len(side) + 1 :] in TABLE_OF_NAME:
            return side, TABLE_OF_NAME[name[len(side) + 1 :]]
    return None, TABLE_OF_NAME.get(name)


def _check_unit(unit: str, table: str, cell: str, column: str, path: str, what: str) -> None:
    """Refuse the header cell ``cell`` (column ``column`` in ``unit``) unless ``unit`` is ours (s, deg, m).

    Raises:
        InputError: naming the unit and the conversion to ours.
    """
    u = unit.strip().lower().replace(" ", "")
    if u in _OWN[table]:
        return
    name, fix = _OTHER[table].get(u, (f"'{unit.strip()}'", ""))
    raise InputError(
        f"{what} {path} has the column '{cell.strip()}' in {name}; give it in {_OUR_UNIT[table]} as "
        f"'{column}'" + (f" ({fix})" if fix else "")
    )
