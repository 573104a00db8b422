"""Errors of the vendor importers; each carries the data that explains it and names the fix."""

from __future__ import annotations

import math
from collections.abc import Sequence

from lowerlimb.errors import InputError


class MappingError(InputError):
    """A sensor mapping (``--map`` or a CSV mapping JSON) is wrong; ``field`` names the bad entry."""

    def __init__(self, field: str, message: str) -> None:
        self.field = field
        super().__init__(f"mapping field '{field}': {message}")


class SensorFileError(InputError):
    """No file, or more than one file, holds the recording of one sensor ID."""

    def __init__(self, sensor_id: str, paths: Sequence[str], message: str) -> None:
        self.sensor_id = sensor_id
        self.paths = list(paths)
        super().__init__(message)


class ColumnNotFoundError(InputError):
    """A vendor file lacks a column the mapping or the format requires.

    ``fix`` replaces the default advice (export the column, or fix its name in the mapping),
    e.g. for a format that has no mapping.
    """

    def __init__(self, column: str, available: Sequence[str], path: str, fix: str | None = None) -> None:
        self.column = column
        self.available = list(available)
        self.path = path
        shown = ", ".join(self.available[:20]) + (", …" if len(self.available) > 20 else "")
        super().__init__(
            f"{path} has no column '{column}' (it has: {shown}); "
            f"{fix or 'export it from the vendor software or fix the column name in the mapping'}"
        )


class PacketGapError(InputError):
    """A run of missing packets (or samples) is too long to fill by interpolation.

    Attributes:
        sensor: the sensor (or ``"the trial"``, ``"the recording"``) with the gap.
        start_s: where the gap starts, s from the first sample.
        length_s: the gap, s.
        limit_s: the longest gap that is filled, s.
        importer: the gap was met by ``lowerlimb import`` (whose ``--max-gap`` bridges it), not
            by a trial CSV's reader (which bridges at most a tenth of a second).
    """

    def __init__(
        self, sensor: str, start_s: float, length_s: float, limit_s: float, importer: bool = False
    ) -> None:
        self.sensor = sensor
        self.start_s = start_s
        self.length_s = length_s
        self.limit_s = limit_s
        self.importer = importer
        enough = math.ceil(length_s * 100 + 1e-6) / 100  # s, just over the gap
        bridge = (
            f", or bridge it by interpolation with `lowerlimb import … --max-gap {enough:g}` "
            f"(ImportParams.max_gap_s)"
            if importer
            else ""
        )
        super().__init__(
            f"{sensor} has a gap of {length_s:.3g} s at {start_s:.3f} s, longer than the "
            f"{limit_s:.3g} s that may be filled by interpolation; cut the recording before or "
            f"after the gap{bridge}"
        )


class NotTextError(InputError):
    """A file that must be text is a folder, a device or pipe, a binary or compressed file, or not UTF-8.

    Attributes:
        path: the file.
        problem: ``"folder"``, ``"special"`` (a device or pipe), ``"binary"`` or ``"encoding"``.
        offset: for ``"encoding"``, the byte offset of the first byte that is not UTF-8 (0 for
            UTF-16 or UTF-32 text, named by its byte-order mark); else None.
    """

    def __init__(self, path: str, problem: str, message: str, offset: int | None = None) -> None:
        self.path = path
        self.problem = problem
        self.offset = offset
        super().__init__(message)


class UnreadableFileError(InputError):
    """A file the user may not read (permission denied).

    Attributes:
        path: the file.
    """

    def __init__(self, path: str, message: str) -> None:
        self.path = path
        super().__init__(message)


class ColumnReusedError(MappingError):
    """A mapping feeds one source column into two signals (a copy-paste slip in the mapping).

    Attributes:
        column: the source column.
        first: the mapping field of its first use (e.g. ``"sensors.thigh.acc.columns[0]"``).
        second: the mapping field of its second use.
    """

    def __init__(self, column: str, first: str, second: str) -> None:
        self.column = column
        self.first = first
        self.second = second
        super().__init__(
            second,
            f"column {column!r} is also mapped as {first}; a source column feeds one signal, "
            f"so fix the column name of one of the two",
        )
