"""The library's exceptions. Each carries the data that explains it and a message naming the fix.

One tree: :class:`LowerLimbError` is the base of every error the library raises on
purpose; :class:`InputError` (also a ``ValueError``) is the user's mistake and
:class:`SolverError` (also a ``RuntimeError``) a numerical failure.

There is exactly one ``SolverError`` per package boundary. ``solvers`` is
domain-free and must never import ``lowerlimb``, so it has its own base error,
:class:`solvers.SolverError`; the calibration catches it where it calls a solver
and raises this :class:`SolverError` ``from`` it, copying its ``method`` and
``x``. Deriving this class from ``solvers.SolverError`` instead would make
``import lowerlimb.errors`` load CasADi (``solvers`` imports it) and would leak
the backend's type through the library's API; wrapping keeps every error a
user of ``lowerlimb`` sees under :class:`LowerLimbError` (qpsolvers' rule: no
abstraction leakage).
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from lowerlimb.conventions import FloatArray


class LowerLimbError(Exception):
    """Base class of every error the library raises on purpose."""


class InputError(LowerLimbError, ValueError):
    """Bad user input: the message says what is wrong and how to fix it."""


class MissingColumnError(InputError):
    """A required column is absent from a trial file."""

    def __init__(
        self, column: str, available: Sequence[str], path: str = "", *, two_legs: bool = False
    ) -> None:
        self.column = column
        self.available = list(available)
        self.path = path
        self.two_legs = two_legs
        where = f" in {path}" if path else ""
        sensors = (
            "pelvis and left_/right_ thigh, shank, foot (two legs)"
            if two_legs
            else "pelvis, thigh, shank, foot"
        )
        like = _column_like(column, self.available)
        unit = _OWN_UNIT.get("time" if column == "time" else column.rsplit("_", 2)[-2], "")
        sided = _side_named(self.available)
        if sided is not None:
            like = None
            hint = (
                f" (the file names a leg's sensors as {sided[0]!r}: name them {sided[1]!r}, "
                f"left_/right_ before the sensor, for one leg or two)"
            )
        elif like and _annotated_name(like) == column:
            hint = f" (the file has {like!r}: give it in {unit} as {column!r})"
        else:
            hint = f" (the file has {like!r}: rename it {column!r}{', in s' if column == 'time' else ''})"
        hint = hint if like or sided else ""
        super().__init__(
            f"missing column '{column}'{where}{hint}; a trial needs time and "
            f"<sensor>_acc_x..z, <sensor>_gyr_x..z for {sensors} "
            f"(see docs/formats.md, trial CSV)"
        )


#: A trial column's own name (a close name of this form is another required column, not a misspelling).
_TRIAL_COLUMN = re.compile(r"time|((left|right)_)?(pelvis|thigh|shank|foot)_(acc|gyr|mag)_[xyz]")


#: The trial CSV's own unit of each quantity (docs/formats.md), as the errors name it.
_OWN_UNIT = {"time": "s", "acc": "m/s²", "gyr": "rad/s", "mag": "µT"}


def _annotated_name(header_cell: str) -> str:
    """A header cell without a trailing ``[unit]`` or ``(unit)`` (``thigh_acc_x [g]`` → ``thigh_acc_x``)."""
    return re.split(r"\s*[\[(]", header_cell, maxsplit=1)[0]


#: A leg's sensor column named with another side mark: ``l_thigh_acc_x``, ``thigh_left_acc_x``.
_SIDE_PREFIX = re.compile(r"(?P<side>l|r|lt|rt|lft|rgt)_(?P<rest>(thigh|shank|foot)_(acc|gyr|mag)_[xyz])")
_SIDE_SUFFIX = re.compile(
    r"(?P<sensor>thigh|shank|foot)_(?P<side>l|r|left|right)_(?P<rest>(acc|gyr|mag)_[xyz])"
)


def _side_named(available: Sequence[str]) -> tuple[str, str] | None:
    """A column of the file that marks a leg's side otherwise, and its trial-format name.

    ``l_thigh_acc_x`` and ``thigh_left_acc_x`` are ``left_thigh_acc_x`` (``None``: no such column).
    """
    for cell in available:
        m = _SIDE_PREFIX.fullmatch(cell)
        if m is not None:
            side = "left" if m["side"].startswith("l") else "right"
            return cell, f"{side}_{m['rest']}"
        m = _SIDE_SUFFIX.fullmatch(cell)
        if m is not None:
            side = "left" if m["side"].startswith("l") else "right"
            return cell, f"{side}_{m['sensor']}_{m['rest']}"
    return None


def _column_like(column: str, available: Sequence[str]) -> str | None:
    """The file's column that is most likely ``column`` misnamed (``time_s``, ``thigh_accel_x``), or None."""
    others = [a for a in available if a and not _TRIAL_COLUMN.fullmatch(a)]
    annotated = [a for a in others if a != column and _annotated_name(a) == column]
    if annotated:
        return annotated[0]
    if column == "time":
        named = [a for a in others if a in ("t", "timestamp") or a.startswith("time")]
        return named[0] if named else None
    close = difflib.get_close_matches(column, others, n=1, cutoff=0.8)
    return close[0] if close else None


class NonFiniteValueError(InputError):
    """NaN or infinite sample in a signal."""

    def __init__(self, column: str, row: int) -> None:
        self.column = column
        self.row = row
        super().__init__(
            f"column '{column}' has a NaN or infinite value at data row {row}; "
            f"fill or cut the gap before calibrating"
        )


class SampleGlitchError(InputError):
    """A finite sample far beyond any sensor's range (a corrupt value in the file)."""

    def __init__(self, column: str, row: int, value: float) -> None:
        self.column = column
        self.row = row
        self.value = value
        super().__init__(
            f"column '{column}' reads {value:.3g} at data row {row}, beyond any sensor's range; "
            f"fix or cut that sample before calibrating"
        )


class TimeAxisError(InputError):
    """The time column is not strictly increasing or not evenly sampled."""


class UnitError(InputError):
    """A signal's magnitude suggests the wrong unit (deg/s gyro, g accelerometer)."""

    def __init__(self, signal: str, value: float, message: str) -> None:
        self.signal = signal
        self.value = value
        super().__init__(message)


class TooShortError(InputError):
    """Too few samples for the requested computation."""

    def __init__(self, duration_s: float, required_s: float) -> None:
        self.duration_s = duration_s
        self.required_s = required_s
        super().__init__(
            f"the trial lasts {duration_s:.2f} s but at least {required_s:.1f} s are needed; "
            f"record a longer trial"
        )


class ShapeError(InputError):
    """An array argument has the wrong shape or mismatched length."""


class SolverError(LowerLimbError, RuntimeError):
    """A numerical solver failed (wraps :class:`solvers.SolverError` and CasADi/IPOPT errors, chained).

    Attributes:
        method: the solver that failed (e.g. ``"casadi_lsq/gauss_newton"``), or ``""``.
        x: (n,) the point at which it failed, when known.
    """

    def __init__(self, message: str, *, method: str = "", x: FloatArray | None = None) -> None:
        self.method = method
        self.x = x
        super().__init__(message)


class MissingDependencyError(LowerLimbError, ImportError):
    """An optional dependency a feature needs is not installed.

    Attributes:
        package: the missing distribution (``"pandas"``).
        feature: what needs it.
        extra: the ``lowerlimb[<extra>]`` that installs it.
    """

    def __init__(self, package: str, feature: str, extra: str) -> None:
        self.package = package
        self.feature = feature
        self.extra = extra
        super().__init__(
            f"{feature} needs {package}, which is not installed; "
            f"pip install '{package}' (or 'lowerlimb[{extra}]')"
        )
