"""All-or-nothing writes: a file through a temporary sibling, a folder through a staging folder.

Nothing is committed (renamed into place) after SIGINT or SIGTERM
(:func:`lowerlimb.io.interrupts.check_interrupted`), and what was staged is
removed. Files and folders get the permissions the user's umask gives.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path

from lowerlimb.errors import InputError
from lowerlimb.io.interrupts import check_interrupted

__all__ = [
    "check_new_directory",
    "check_new_files",
    "check_writable_parent",
    "default_dir_mode",
    "populate_directory",
    "write_atomically",
    "write_files_atomically",
    "write_text",
]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def default_dir_mode() -> int:
    """The permissions a new folder gets under the user's umask (``mkdtemp`` gives 0700)."""
    return 0o777 & ~_umask()


def check_writable_parent(path: Path, option: str = "--out") -> Path:
    """Return the folder ``path`` would be created in, or raise when it is missing or read-only.

    Raises:
        InputError: the parent folder does not exist, is not a folder, or is not writable.
    """
    parent = Path(path).parent if str(Path(path).parent) else Path(".")
    if parent.exists() and not parent.is_dir():
        raise InputError(f"{parent} is a file, not a directory; choose another {option}")
    if not parent.is_dir():
        raise InputError(f"directory {parent} does not exist; create it or choose another {option}")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"directory {parent} is not writable; choose another {option}")
    return parent


def write_atomically(path: Path, write: Callable[[Path], None]) -> None:
    """Write a file through a temporary sibling, then rename: no half-written file on failure."""
    write_files_atomically({Path(path): write}, overwrite=True)


def check_new_files(paths: Mapping[str, Path] | list[Path], *, overwrite: bool = False) -> None:
    """Refuse targets naming one file, a folder, or (unless ``overwrite``) an existing file.

    Also checks that every parent folder exists and is writable.

    Args:
        paths: the files to create; a mapping names each one by its option (``--out``).
        overwrite: allow replacing existing files.

    Raises:
        InputError: naming the file and the fix.
    """
    named = dict(paths) if isinstance(paths, Mapping) else {str(p): Path(p) for p in paths}
    seen: dict[Path, str] = {}
    for option, p in named.items():
        path = Path(p)
        key = path.resolve()
        if key in seen:
            raise InputError(f"{option} and {seen[key]} both name {path}; give two different files")
        seen[key] = option
        check_writable_parent(path, option.split(" ")[0] if option.startswith("-") else "path")
        if path.is_dir():
            raise InputError(f"{path} is a directory; give a file name for {option}")
        if path.exists() and not overwrite:
            raise InputError(f"{path} already exists; choose another name or pass --force to replace it")


def write_files_atomically(
    writers: Mapping[Path, Callable[[Path], None]], *, overwrite: bool = False
) -> None:
    """Write several files, all or none: each through a temporary sibling, renamed once all are written.

    Args:
        writers: file -> function writing that file's content to the path it is given.
        overwrite: allow replacing existing files (checked before writing anything).

    Raises:
        InputError: see :func:`check_new_files`.
    """
    check_new_files(list(writers), overwrite=overwrite)
    mode = 0o666 & ~_umask()
    staged: list[tuple[str, Path]] = []
    committed: list[Path] = []
    try:
        for path, write in writers.items():
            parent = check_writable_parent(Path(path))
            fd, tmp = tempfile.mkstemp(prefix=f".{Path(path).name}.", dir=parent)
            os.close(fd)
            staged.append((tmp, Path(path)))
            write(Path(tmp))
            os.chmod(tmp, mode)
        check_interrupted()
        for tmp, path in staged:
            existed = path.exists()
            os.replace(tmp, path)
            if not existed:
                committed.append(path)
    except BaseException:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
        for path in committed:  # new files of a failed batch; replaced ones cannot be restored
            path.unlink(missing_ok=True)
        raise


def check_new_directory(out: Path) -> None:
    """Raise unless ``out`` is absent or an empty directory, in a writable folder.

    Raises:
        InputError: ``out`` exists and is a file or a non-empty directory, or
            its parent is missing or read-only.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out} is an existing file, not a folder; choose a new --out directory")
    if out.exists() and any(out.iterdir()):
        raise InputError(f"{out} already exists and is not empty; choose a new --out directory")
    check_writable_parent(out.resolve() if str(out) else out)


def populate_directory(out: Path, fill: Callable[[Path], None]) -> None:
    """Create ``out`` with everything ``fill`` writes into a staging directory, or nothing at all.

    The staging folder is removed on any failure, Ctrl-C or SIGTERM; the
    folder gets the permissions of the user's umask (``mkdtemp`` makes it 0700).
    """
    out = Path(out)
    check_new_directory(out)
    parent = out.resolve().parent
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=parent))
    try:
        fill(staging)
        os.chmod(staging, default_dir_mode())
        check_interrupted()
        if out.exists():
            out.rmdir()
        os.replace(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


def write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` as UTF-8."""
    Path(path).write_text(text, encoding="utf-8")
