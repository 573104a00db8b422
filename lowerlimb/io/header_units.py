"""Unit annotations in a trial CSV's header: ``pelvis_acc_x [m/s^2]`` is read as ``pelvis_acc_x``.

Exports often write each column's unit after its name, in brackets or parentheses. Where that
unit is the trial CSV's own for the column (docs/formats.md: time in s, accelerometers in m/s²,
gyros in rad/s, magnetometers in µT) the annotation is dropped as the header is read. Any other
unit (``[g]``, ``(deg/s)``) stays in the name, so the column is missing and the error names the
conversion to make (:class:`~lowerlimb.errors.MissingColumnError`). The magnetometer is
optional, so a magnetometer column in another unit would not be missed: it is refused by
:func:`check_mag_units` instead of leaving the trial 6-axis without a word.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from lowerlimb.errors import InputError

__all__ = ["OWN_UNITS", "check_mag_units", "without_own_unit"]

#: The trial CSV's own unit of each quantity, as headers write it (normalised: lower case, no
#: spaces, ``²`` as ``^2``, ``µ``/``μ`` as ``u``).
OWN_UNITS: dict[str, frozenset[str]] = {
    "time": frozenset({"s", "sec", "secs", "second", "seconds"}),
    "acc": frozenset({"m/s^2", "m/s2", "ms^-2", "m*s^-2", "m·s^-2", "m/s/s", "m.s^-2", "m/sec^2"}),
    "gyr": frozenset({"rad/s", "rad/sec", "rads^-1", "rad*s^-1", "rad·s^-1", "rad.s^-1"}),
    "mag": frozenset({"ut", "microtesla"}),
}

_ANNOTATED = re.compile(r"(?P<name>[^\[\(]*?)\s*(?:\[(?P<bracket>[^\]]*)\]|\((?P<paren>[^)]*)\))\s*")
_SIGNAL = re.compile(r".*_(?P<q>acc|gyr|mag)_[xyz]")


def _normalised(unit: str) -> str:
    u = unit.strip().lower().replace(" ", "").replace("²", "^2").replace("⁻", "^-").replace("¹", "1")
    return u.replace("µ", "u").replace("μ", "u")


def _quantity(name: str) -> str | None:
    if name == "time":
        return "time"
    m = _SIGNAL.fullmatch(name)
    return m["q"] if m else None


def without_own_unit(name: str) -> str:
    """A header cell (stripped, lower case) without a trailing annotation of its column's own unit.

    ``"thigh_gyr_x [rad/s]"`` → ``"thigh_gyr_x"``; ``"thigh_gyr_x [deg/s]"`` and names that are not
    trial columns are returned as given.
    """
    m = _ANNOTATED.fullmatch(name)
    if m is None:
        return name
    base = m["name"]
    q = _quantity(base)
    unit = _normalised(m["bracket"] if m["bracket"] is not None else m["paren"])
    return base if q is not None and unit in OWN_UNITS[q] else name


def check_mag_units(header: Sequence[str], path: str) -> None:
    """Refuse a magnetometer column annotated with another unit than µT (``thigh_mag_x [mG]``).

    Args:
        header: the header's column names (:func:`without_own_unit` applied).
        path: the file, for the message.

    Raises:
        InputError: naming the column, its unit and the fix.
    """
    for cell in header:
        m = _ANNOTATED.fullmatch(cell)
        if m is not None and _quantity(m["name"]) == "mag":
            unit = m["bracket"] if m["bracket"] is not None else m["paren"]
            raise InputError(
                f"{path} has the column '{cell}': give the magnetometer in µT as '{m['name']}' "
                f"(1 G = 100 µT, 1 mG = 0.1 µT, 1 nT = 0.001 µT), or delete the magnetometer columns "
                f"(unit '{unit}' is not the trial's)"
            )
