"""Read a user's text file whole, refusing a folder, a binary or compressed file and non-UTF-8 text.

The vendor importers read their files through :func:`read_text`, so that a wrong file
is one :class:`~lowerlimb.io.errors.NotTextError` naming the file and the fix, never
a ``UnicodeDecodeError`` or ``IsADirectoryError``.
"""

from __future__ import annotations

import os

from .errors import NotTextError

__all__ = ["BINARY_MAGIC", "read_text"]

#: The first bytes of files that are not text: gzip, zip, xlsx (zip), 7z, bzip2, xz.
BINARY_MAGIC: dict[bytes, str] = {
    b"\x1f\x8b": "gzip-compressed",
    b"PK\x03\x04": "a zip archive (or an Excel .xlsx file)",
    b"7z\xbc\xaf": "a 7-Zip archive",
    b"BZh": "bzip2-compressed",
    b"\xfd7zXZ": "xz-compressed",
}
#: Bytes of the file's start searched for a NUL byte (text never holds one).
_SNIFF_BYTES = 65536
#: The UTF-8 byte-order mark some Windows programs write first.
_BOM = b"\xef\xbb\xbf"


def read_text(
    path: str,
    what: str,
    *,
    export_fix: str = "export it again as text",
    folder_fix: str = "give the file itself",
) -> str:
    """The whole file as text, decoded as UTF-8 (a leading byte-order mark is dropped).

    Args:
        path: an existing path (callers raise their own ``FileNotFoundError`` first).
        what: what the file should be, for the messages, e.g. ``"an MT Manager text export"``.
        export_fix: what to do about a binary or compressed file.
        folder_fix: what to do about a folder in the file's place.

    Raises:
        NotTextError: ``path`` is a folder (or not a regular file), starts like a binary or
            compressed file, holds a NUL byte, or is not UTF-8 (the message gives the first
            bad byte, its offset and line, and says to save the file as UTF-8).
    """
    if os.path.isdir(path):
        raise NotTextError(path, "folder", f"{path} is a folder, not {what}; {folder_fix}")
    if not os.path.isfile(path):
        raise NotTextError(
            path, "special", f"{path} is not a regular file (a device or a pipe), not {what}; give a file"
        )
    with open(path, "rb") as f:
        raw = f.read()
    for magic, kind in BINARY_MAGIC.items():
        if raw.startswith(magic):
            raise NotTextError(path, "binary", f"{path} is {kind}, not {what}; decompress it or {export_fix}")
    if b"\x00" in raw[:_SNIFF_BYTES]:
        raise NotTextError(path, "binary", f"{path} is a binary file, not {what}; {export_fix}")
    start = len(_BOM) if raw.startswith(_BOM) else 0
    try:
        return raw[start:].decode("utf-8")
    except UnicodeDecodeError as e:
        offset = start + e.start
        line = raw.count(b"\n", 0, offset) + 1
        raise NotTextError(
            path,
            "encoding",
            f"{path} is not UTF-8 text (byte {raw[offset]:#04x} at offset {offset}, line {line}; "
            f"e.g. a '°' or 'µ' saved as Latin-1/Windows-1252); save it as UTF-8 (in the software "
            f"that wrote it, or a text editor)",
            offset=offset,
        ) from None
