"""Where a trial CSV's header row is, and whether its data rows match it.

Files written by other software carry lines before the header: comment lines (``# exported by
…``), Excel's ``sep=,`` line, blank lines. They are skipped, as comment lines among the data
rows are (numpy's reader skips ``#`` lines). The header is the first other line.

A data row with more values than the header names shifts every later column of that row (numpy's
reader, told which columns to read, does not see it): :func:`ragged_row` finds such a row, and
the reader then names it. A trailing empty cell (a comma at the end of every row) is allowed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from lowerlimb.errors import InputError

from .errors import UnreadableFileError
from .text_file import BINARY_MAGIC

__all__ = ["HeaderLine", "RaggedRow", "header_line", "is_skipped_line", "ragged_row"]

#: Excel's first line naming the separator (``sep=,``).
_SEP_LINE = re.compile(r"\s*sep=.\s*", re.IGNORECASE)
#: The UTF-16 byte-order marks (little and big endian).
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
#: Bytes read to find the header (a preamble longer than this is not a trial CSV).
_HEAD_BYTES = 65536


def is_skipped_line(line: str) -> bool:
    """Whether a line before the header (or among the data rows) is skipped: blank or a comment."""
    s = line.strip()
    return not s or s.startswith("#")


@dataclass(frozen=True)
class HeaderLine:
    """The header row of a CSV file.

    Attributes:
        index: number of lines before it (skipped: blank, ``#`` comments, Excel's ``sep=``).
        text: the header line itself (its line break stripped).
    """

    index: int
    text: str


def header_line(path: str) -> HeaderLine:
    """The first line that is not blank, a ``#`` comment or Excel's ``sep=`` line.

    Raises:
        InputError: a binary, compressed, UTF-16 or non-UTF-8 file, or one with no header line;
            :class:`~lowerlimb.io.errors.UnreadableFileError` for a file the user may not read.
    """
    try:
        with open(path, "rb") as f:
            head = f.read(_HEAD_BYTES)
    except PermissionError:
        raise UnreadableFileError(
            path, f"cannot read {path} (permission denied); give yourself read access (chmod u+r {path})"
        ) from None
    for magic, what in BINARY_MAGIC.items():
        if head.startswith(magic):
            raise InputError(f"{path} is {what}, not a trial CSV; decompress or export it as CSV text")
    if head.startswith(_UTF16_BOMS):
        raise InputError(f"{path} is UTF-16 text (Excel's 'Unicode Text'); save the trial CSV as UTF-8")
    if b"\x00" in head:
        raise InputError(f"{path} is a binary file, not a trial CSV; export the recording as CSV text")
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            for index, line in enumerate(f):
                if is_skipped_line(line) or (index == 0 and _SEP_LINE.fullmatch(line)):
                    continue
                return HeaderLine(index, line.rstrip("\r\n"))
    except UnicodeDecodeError as e:
        raise InputError(
            f"{path} is not UTF-8 text (byte {e.object[e.start]:#04x} at offset {e.start}); "
            f"save the trial CSV as UTF-8"
        ) from None
    raise InputError(f"{path} is empty; give a trial CSV with a header row")


@dataclass(frozen=True)
class RaggedRow:
    """A data row whose number of values differs from the header's.

    Attributes:
        row_no: the data row, counted from 1 after the header (skipped lines not counted).
        n_values: its number of values.
        n_columns: the header's number of columns.
        last: whether it is the file's last data row.
    """

    row_no: int
    n_values: int
    n_columns: int
    last: bool


def ragged_row(path: str, header: HeaderLine, n_columns: int) -> RaggedRow | None:
    """The first data row with more or fewer values than ``n_columns`` (``None``: none, or quoted cells).

    Values are counted by commas, so a file with quoted cells is not checked here (the csv
    module's reader checks it). One more value than the header's, empty, is allowed (a
    trailing comma).
    """
    with open(path, "rb") as f:
        raw = f.read()
    if b'"' in raw:
        return None
    lines = [
        ln for ln in raw.split(b"\n")[header.index + 1 :] if ln.strip() and not ln.lstrip().startswith(b"#")
    ]
    for k, line in enumerate(lines):
        n = line.count(b",") + 1
        if n == n_columns or (n == n_columns + 1 and line.rstrip().endswith(b",")):
            continue
        return RaggedRow(k + 1, n, n_columns, k == len(lines) - 1)
    return None
