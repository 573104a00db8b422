"""Errors of the agreement analysis; each names the problem and the fix."""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import InputError


class AlignmentError(InputError):
    """The time offset cannot be estimated (no overlap, nothing varies)."""


class NoCommonColumnsError(InputError):
    """The reference shares no quantity with our outputs."""

    def __init__(self, reference_columns: Sequence[str], our_columns: Sequence[str], path: str = "") -> None:
        self.reference_columns = list(reference_columns)
        self.our_columns = list(our_columns)
        where = f"{path} " if path else "the reference "
        super().__init__(
            f"{where}has no column named as in angles.csv/positions.csv (it has "
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
            f"{ours_s[0]:g}–{ours_s[1]:g} s: no overlap; put both on one clock (or use --align-time "
            f"for offsets up to the search window)"
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
