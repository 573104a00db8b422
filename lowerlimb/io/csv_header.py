"""Where a trial CSV's header row is, and whether its data rows match it.

Files written by other software carry lines before the header: comment lines (``# exported by
…``), Excel's ``sep=,`` line, blank lines. They are skipped, as comment lines among the data
rows are (numpy's reader skips ``#`` lines). The header is the first other line.

A data row with more values than the header names shifts every later column of that row (numpy's
reader, told which columns to read, does not see it): :func:`ragged_row` finds such a row, and
the reader then names it. A trailing empty cell (a comma at the end of every row) is allowed, and
so is a header ending with a comma over rows that do not.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass

from lowerlimb.errors import InputError

from .errors import UnreadableFileError
from .text_file import BINARY_MAGIC

__all__ = ["HeaderLine", "RaggedRow", "header_line", "is_skipped_line", "ragged_row", "row_fits"]

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
        comments: the ``#`` comment lines skipped before it, ``#`` and spaces stripped.
    """

    index: int
    text: str
    comments: tuple[str, ...] = ()


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
        comments: list[str] = []
        with open(path, newline="", encoding="utf-8-sig") as f:
            for index, line in enumerate(f):
                if line.strip().startswith("#"):
                    comments.append(line.strip().lstrip("#").strip())
                if is_skipped_line(line) or (index == 0 and _SEP_LINE.fullmatch(line)):
                    continue
                return HeaderLine(index, line.rstrip("\r\n"), tuple(comments))
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


def row_fits(n_values: int, last_empty: bool, header: list[str]) -> bool:
    """Whether a data row of ``n_values`` values (its last one empty or not) fits the header.

    One value per column; one more, empty, is a trailing comma; one fewer is a row whose
    writer left out the value of an unnamed last column (a header ending with a comma).
    """
    n = len(header)
    return n_values == n or (n_values == n + 1 and last_empty) or (n_values == n - 1 and header[-1] == "")


def ragged_row(path: str, head: HeaderLine, header: list[str]) -> RaggedRow | None:
    """The first data row whose number of values does not fit the header (:func:`row_fits`), or ``None``.

    Values are counted by commas, or by the csv module where the file has quoted cells (a
    quoted comma is no separator).
    """
    with open(path, "rb") as f:
        raw = f.read()
    data = raw.split(b"\n")[head.index + 1 :]
    lines = [ln for ln in data if ln.strip() and not ln.lstrip().startswith(b"#")]
    if b'"' in raw:
        rows = list(csv.reader(ln.decode("utf-8", "replace") for ln in lines))
        counts = [(len(r), not r or not r[-1].strip()) for r in rows]
    else:
        counts = [(ln.count(b",") + 1, ln.rstrip().endswith(b",")) for ln in lines]
    for k, (n, last_empty) in enumerate(counts):
        if not row_fits(n, last_empty, header):
            return RaggedRow(k + 1, n, len(header), k == len(lines) - 1)
    return None
