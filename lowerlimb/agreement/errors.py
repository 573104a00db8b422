"""Errors of the agreement analysis; each names the problem and the fix."""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import InputError, UnitError
from ..io.time_axis import guess_time_unit


class AlignmentError(InputError):
    """The time offset cannot be estimated (no overlap, nothing varies)."""


class NoCommonColumnsError(InputError):
    """The reference shares no quantity with our outputs."""

    def __init__(
        self,
        reference_columns: Sequence[str],
        our_columns: Sequence[str],
        path: str = "",
        *,
        message: str | None = None,
    ) -> None:
        """``message``: a more specific text (the other leg, a missing table) than "rename them"."""
        self.reference_columns = list(reference_columns)
        self.our_columns = list(our_columns)
        where = f"{path} " if path else "the reference "
        super().__init__(
            message
            or f"{where}has no column named as in angles.csv/positions.csv (it has "
            f"{', '.join(self.reference_columns) or 'none'}); rename its columns to ours, e.g. "
            f"{', '.join(self.our_columns[:3])}"
        )


class NoTimeOverlapError(InputError):
    """Our time axis and the reference's do not overlap."""

    def __init__(self, ours_s: tuple[float, float], reference_s: tuple[float, float]) -> None:
        self.ours_s = ours_s
        self.reference_s = reference_s
        super().__init__(
            f"the reference covers {reference_s[0]:g}–{reference_s[1]:g} s but lowerlimb covers "
            f"{ours_s[0]:g}–{ours_s[1]:g} s: no overlap; put both on one clock, time in s ('lowerlimb "
            f"compare --align-time' finds offsets up to its search window)"
        )


class EmptyReferenceError(InputError):
    """No common quantity has enough valid (finite) reference samples."""

    def __init__(self, columns: Sequence[str], min_samples: int) -> None:
        self.columns = list(columns)
        self.min_samples = min_samples
        super().__init__(
            f"the reference columns {', '.join(self.columns)} have fewer than {min_samples} finite "
            f"values overlapping lowerlimb's time axis (NaN or empty); fill them or remove them"
        )


class TooLittleTimeOverlapError(InputError):
    """Our time span and the reference's overlap over too small a part of the shorter one."""

    def __init__(
        self,
        ours_s: tuple[float, float],
        reference_s: tuple[float, float],
        overlap_s: float,
        min_fraction: float,
    ) -> None:
        self.ours_s = ours_s
        self.reference_s = reference_s
        self.overlap_s = overlap_s
        self.min_fraction = min_fraction
        shorter = min(ours_s[1] - ours_s[0], reference_s[1] - reference_s[0])
        super().__init__(
            f"the reference covers {reference_s[0]:g}–{reference_s[1]:g} s but lowerlimb covers "
            f"{ours_s[0]:g}–{ours_s[1]:g} s: they overlap for only {overlap_s:.3g} s, "
            f"{100 * overlap_s / shorter:.0f} % of the shorter (at least {100 * min_fraction:.0f} % "
            f"needed); put both on one clock, time in s (or cut the reference to the trial)"
        )


class ReferenceTimeUnitError(UnitError):
    """The reference's time steps are too long for seconds: its time looks like ms, µs or ns."""

    def __init__(self, median_step: float, our_step_s: float | None = None, path: str = "") -> None:
        self.median_step = median_step
        self.our_step_s = our_step_s
        self.path = path
        where = f"reference {path}" if path else "the reference"
        ours = "" if our_step_s is None else f"; lowerlimb's are {our_step_s:.4g} s"
        guess = guess_time_unit(median_step)
        unit, divisor = ("milliseconds", "1000") if guess is None else (guess.unit, guess.divisor)
        super().__init__(
            "time",
            median_step,
            f"{where} has time steps of {median_step:.4g} (a rate of {1.0 / median_step:.3g} Hz if in s"
            f"{ours}): its time looks like {unit}; give the reference's time in seconds "
            f"(divide its time column by {divisor})",
        )


class ReferenceUnitError(UnitError):
    """A reference column's magnitude suggests radians (not deg) or millimetres (not m)."""

    def __init__(
        self, column: str, unit: str, reference_size: float, our_size: float, guessed_unit: str, fix: str
    ) -> None:
        self.column = column
        self.unit = unit
        self.reference_size = reference_size
        self.our_size = our_size
        self.guessed_unit = guessed_unit
        measure = "spans" if unit == "deg" else "has an RMS of"
        super().__init__(
            column,
            reference_size,
            f"the reference column '{column}' {measure} {reference_size:.3g} where lowerlimb's "
            f"{measure} {our_size:.3g} {unit}: it looks like {guessed_unit}; give the reference in "
            f"{'degrees' if unit == 'deg' else 'metres'} ({fix})",
        )
