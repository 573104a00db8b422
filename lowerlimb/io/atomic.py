"""All-or-nothing writes: a file through a temporary sibling, a folder through a staging folder."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

from lowerlimb.errors import InputError

__all__ = ["check_new_directory", "populate_directory", "write_atomically", "write_text"]


def write_atomically(path: Path, write: Callable[[Path], None]) -> None:
    """Write a file through a temporary sibling, then rename: no half-written file on failure."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"directory {parent} does not exist; create it or choose another --out")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def check_new_directory(out: Path) -> None:
    """Raise unless ``out`` is absent or an empty directory.

    Raises:
        InputError: ``out`` exists and is a file or a non-empty directory.
    """
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise InputError(f"{out} already exists and is not empty; choose a new --out directory")


def populate_directory(out: Path, fill: Callable[[Path], None]) -> None:
    """Create ``out`` with everything ``fill`` writes into a staging directory, or nothing at all."""
    out = Path(out)
    check_new_directory(out)
    parent = out.resolve().parent
    if not parent.is_dir():
        raise InputError(f"directory {parent} does not exist; create it or choose another --out")
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=parent))
    try:
        fill(staging)
        if out.exists():
            out.rmdir()
        os.replace(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


def write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` as UTF-8."""
    Path(path).write_text(text, encoding="utf-8")
