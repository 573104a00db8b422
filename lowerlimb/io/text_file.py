"""Read a user's text file whole, refusing a folder, a binary or compressed file and non-UTF-8 text.

The vendor importers read their files through :func:`read_text`, so that a wrong file
is one :class:`~lowerlimb.io.errors.NotTextError` naming the file and the fix, never
a ``UnicodeDecodeError`` or ``IsADirectoryError``; a file the user may not read is one
:class:`~lowerlimb.io.errors.UnreadableFileError`, never a ``PermissionError``.

UTF-16 and UTF-32 text (a byte-order mark first, e.g. Excel's "Unicode Text") is refused
by name rather than decoded: every file the library reads is UTF-8, and the trial CSV
the importers write is UTF-8 too.
"""

from __future__ import annotations

import os

from .errors import NotTextError, UnreadableFileError

__all__ = ["BINARY_MAGIC", "WIDE_TEXT_BOMS", "read_text"]

#: The first bytes of files that are not text: gzip, zip, xlsx (zip), 7z, bzip2, xz.
BINARY_MAGIC: dict[bytes, str] = {
    b"\x1f\x8b": "gzip-compressed",
    b"PK\x03\x04": "a zip archive (or an Excel .xlsx file)",
    b"7z\xbc\xaf": "a 7-Zip archive",
    b"BZh": "bzip2-compressed",
    b"\xfd7zXZ": "xz-compressed",
}
#: Byte-order marks of text that is not UTF-8 (UTF-32 first: its little-endian mark starts as UTF-16's).
WIDE_TEXT_BOMS: dict[bytes, str] = {
    b"\xff\xfe\x00\x00": "UTF-32",
    b"\x00\x00\xfe\xff": "UTF-32",
    b"\xff\xfe": "UTF-16",
    b"\xfe\xff": "UTF-16",
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
            compressed file, is UTF-16 or UTF-32 text (a byte-order mark first), holds a NUL
            byte, or is not UTF-8 (the message gives the first bad byte, its offset and line,
            and says to save the file as UTF-8).
        UnreadableFileError: the user may not read ``path`` (permission denied).
    """
    if os.path.isdir(path):
        raise NotTextError(path, "folder", f"{path} is a folder, not {what}; {folder_fix}")
    if not os.path.isfile(path):
        raise NotTextError(
            path, "special", f"{path} is not a regular file (a device or a pipe), not {what}; give a file"
        )
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except PermissionError:
        raise UnreadableFileError(
            path,
            f"cannot read {path} (permission denied); give yourself read access (chmod u+r {path})",
        ) from None
    for bom, encoding in WIDE_TEXT_BOMS.items():
        if raw.startswith(bom):
            raise NotTextError(
                path,
                "encoding",
                f"{path} is {encoding} text, not UTF-8; save it as UTF-8 (in the software that wrote it, "
                f"or a text editor)",
                offset=0,
            )
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
