"""The trials of a study: a manifest CSV (one row per trial) or every trial CSV of a folder.

Manifest columns (docs/formats.md, "Many trials"): ``trial`` (path, relative to the
manifest), optional ``side``, ``subject``, ``task``, ``height_m``, ``mass_kg`` and
``calibration`` (an earlier ``calibration.json`` to reuse, relative to the manifest).
Other columns are ignored. Each trial gets an output folder named after its path
relative to the manifest (``s01/walk.csv`` → ``s01__walk``).
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from lowerlimb.errors import InputError
from lowerlimb.io.bilateral_trial import read_header, trial_layout
from lowerlimb.io.bounds import INPUT_BOUNDS
from lowerlimb.io.trial import one_side_prefix

from .params import BatchParams

__all__ = ["MANIFEST_COLUMNS", "RESULT_MARKERS", "ManifestError", "StudyTrial", "read_study"]

#: Columns a manifest may have; ``trial`` is required.
MANIFEST_COLUMNS: tuple[str, ...] = ("trial", "side", "subject", "task", "height_m", "mass_kg", "calibration")

#: Files that make a sub-folder of a study folder a result (of ``batch``: ``batch.csv``, a trial's
#: record; of ``calibrate``: ``calibration.json``): its CSVs are outputs, not trials.
RESULT_MARKERS: tuple[str, ...] = ("batch.csv", ".batch.json", "calibration.json")
#: Files of a folder that are not trials.
_NOT_TRIALS = frozenset({"batch.csv", "manifest.csv", "study_subjects.csv", "study_tasks.csv"})


class ManifestError(InputError):
    """The manifest cannot be used; ``row`` is its 1-based data row (0: the file or header)."""

    def __init__(self, path: str | os.PathLike[str], problem: str, row: int = 0) -> None:
        self.path = os.fspath(path)
        self.problem = problem
        self.row = row
        where = f"{self.path}, row {row}" if row else self.path
        super().__init__(f"{where}: {problem}")


@dataclass(frozen=True)
class StudyTrial:
    """One trial of a study.

    Attributes:
        name: its output folder name (unique in the study).
        path: the trial CSV.
        label: the trial as the manifest gives it (``batch.csv``'s ``trial`` column).
        side: instrumented leg, ``both`` for a two-leg (seven-sensor) trial.
        subject: subject identifier, ``""`` when unknown.
        task: task identifier, ``""`` when unknown.
        height_m: subject stature, m.
        mass_kg: subject mass, kg.
        calibration: an earlier ``calibration.json`` to reuse, or ``None``.
    """

    name: str
    path: Path
    label: str
    side: str
    subject: str = ""
    task: str = ""
    height_m: float = 1.75
    mass_kg: float = 75.0
    calibration: Path | None = None


def read_study(
    source: str | os.PathLike[str],
    params: BatchParams | None = None,
    *,
    exclude: str | os.PathLike[str] | None = None,
) -> list[StudyTrial]:
    """The trials of a manifest CSV, or of every ``*.csv`` under a folder (sorted).

    In a folder, a trial in a sub-folder takes the sub-folder's name as its subject;
    files under ``exclude`` (the study's output folder, when it lies inside) and in
    sub-folders holding one of :data:`RESULT_MARKERS` (earlier results) are not trials.

    Raises:
        FileNotFoundError: ``source`` does not exist.
        ManifestError: no ``trial`` column, text that is not UTF-8, a bad ``side`` (``both``
            for a one-leg trial, ``left``/``right`` for a two-leg one) or a
            ``height_m``/``mass_kg`` outside the CLI's ``--height``/``--mass`` range, the same
            trial twice, two trials with the same folder name, a trial or calibration file that
            does not exist, another separator than a comma, or no trial (outside ``exclude``
            and result folders).
    """
    p = params or BatchParams()
    src = Path(source)
    skip = Path(exclude).resolve() if exclude is not None else None
    if not src.exists():
        raise FileNotFoundError(f"manifest or folder not found: {src}")
    folder: _ResultFolders | None = None  # a folder's result folders (none in a manifest)
    if src.is_dir():
        results = folder = _ResultFolders(src)
        rows = [
            {"trial": f.relative_to(src).as_posix(), "subject": _subject_of(f.relative_to(src))}
            for f in sorted(src.rglob("*.csv"))
            if f.name not in _NOT_TRIALS
            and not any(part.startswith(".") for part in f.relative_to(src).parts)
            and not (skip is not None and f.resolve().is_relative_to(skip))
            and not results.holds(f)
        ]
        base = src
    else:
        rows = _read_rows(src)
        base = src.parent
    trials = [_trial_of(row, k, base, src, p) for k, row in enumerate(rows, start=1)]
    if not trials and folder is not None:
        out_inside = skip is not None and skip.is_relative_to(src.resolve()) and any(skip.rglob("*.csv"))
        if out_inside:
            raise ManifestError(
                src, f"no trial found outside --out {exclude}; give an --out folder outside the study folder"
            )
        if folder.found:
            raise ManifestError(
                src,
                f"no trial found outside result folders ({', '.join(folder.found[:3])}); give the folder "
                "of the trial CSVs, not of results",
            )
    if not trials:
        raise ManifestError(
            src, "no trial found; list trial CSVs in a 'trial' column or give a folder of them"
        )
    _check_unique(trials, src)
    if folder is None:
        _check_paths(rows, base, src)
    return trials


class _ResultFolders:
    """Which sub-folders of a study folder are results (of ``batch`` or ``calibrate``): they hold no trial.

    A folder is a result when it holds one of :data:`RESULT_MARKERS`; ``found`` lists
    the result folders met (relative to the study folder), outermost first.
    """

    def __init__(self, root: Path) -> None:
        self.root = root
        self.found: list[str] = []
        self._known: dict[Path, bool] = {}

    def holds(self, file: Path) -> bool:
        """Whether ``file`` lies in a result folder below the study folder."""
        parents = [d for d in file.relative_to(self.root).parents if d != Path(".")]
        return any(self._is_result(self.root / d) for d in reversed(parents))

    def _is_result(self, folder: Path) -> bool:
        if folder not in self._known:
            self._known[folder] = any((folder / name).is_file() for name in RESULT_MARKERS)
            if self._known[folder]:
                self.found.append(folder.relative_to(self.root).as_posix())
        return self._known[folder]


def _subject_of(relative: Path) -> str:
    return relative.parts[0] if len(relative.parts) > 1 else ""


def _read_rows(path: Path) -> list[dict[str, str]]:
    try:
        return _read_utf8_rows(path)
    except UnicodeDecodeError as e:
        raise ManifestError(
            path, f"byte {e.start} is not UTF-8 text; save the manifest as UTF-8 (Excel: 'CSV UTF-8')"
        ) from None


def _read_utf8_rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8-sig") as f:
        reader = csv.DictReader(f)
        header = [h.strip() for h in (reader.fieldnames or [])]
        if "trial" not in header:
            _check_separator(path, reader.fieldnames or [])
            raise ManifestError(
                path,
                f"no 'trial' column (columns: {', '.join(header) or 'none'}); "
                f"a manifest has the columns {', '.join(MANIFEST_COLUMNS)} (only 'trial' is required)",
            )
        rows = []
        for row in reader:
            clean = {(k or "").strip(): (v or "").strip() for k, v in row.items() if isinstance(v, str)}
            rows.append(clean)
        return rows


#: Separators a spreadsheet may save a "CSV" with, and their names in messages.
_OTHER_SEPARATORS: dict[str, str] = {";": "';'", "\t": "tabs", "|": "'|'"}


def _check_separator(path: Path, fieldnames: Sequence[str]) -> None:
    """Refuse a manifest whose header is one cell holding ``trial`` and another separator.

    Raises:
        ManifestError: naming the separator.
    """
    line = ",".join(fieldnames)
    for sep, name in _OTHER_SEPARATORS.items():
        if "trial" in (cell.strip() for cell in line.split(sep)):
            raise ManifestError(path, f"the manifest is separated by {name}; save it comma-separated")


def _check_paths(rows: Sequence[dict[str, str]], base: Path, src: Path) -> None:
    """Refuse a manifest naming a trial or calibration file that does not exist (before any work).

    Raises:
        ManifestError: the first such row, and how many more there are.
    """
    missing = [
        (k, column, row[column])
        for k, row in enumerate(rows, start=1)
        for column in ("trial", "calibration")
        if row.get(column) and not (base / row[column]).is_file()
    ]
    if not missing:
        return
    k, column, cell = missing[0]
    what = "trial file" if column == "trial" else "calibration"
    problem = "is a folder" if (base / cell).is_dir() else "not found"
    more = f" (and {len(missing) - 1} more missing)" if len(missing) > 1 else ""
    raise ManifestError(
        src,
        f"{what} {cell} {problem} (looked for {(base / cell).absolute()}){more}; fix the manifest's "
        "paths, relative to its folder",
        k,
    )


def _layout(path: Path) -> tuple[bool | None, str | None]:
    """Whether the trial has two legs, and the side its one leg's ``left_*``/``right_*`` names give.

    ``(None, None)`` for a trial that cannot be read (reported when it is processed).
    """
    try:
        header = read_header(path)
        return trial_layout(header) == "two_legs", one_side_prefix(header)
    except (OSError, ValueError):  # reported when the trial is read
        return None, None


def _trial_of(row: dict[str, str], k: int, base: Path, src: Path, p: BatchParams) -> StudyTrial:
    label = row.get("trial", "")
    if not label:
        raise ManifestError(src, "empty 'trial' cell; give the trial CSV's path", k)
    given = row.get("side", "")
    two_legs, prefixed = _layout(base / label)
    if two_legs and given not in ("", "both"):
        raise ManifestError(
            src,
            f"side {given!r}, but {label} is a two-leg trial (pelvis, left_*, right_* sensors) and both "
            "legs are calibrated; write both or leave the side empty",
            k,
        )
    if two_legs is False and given == "both":
        raise ManifestError(
            src, f"side 'both', but {label} has one leg's sensors; write left or right (or leave it empty)", k
        )
    if prefixed is not None and given in ("left", "right") and given != prefixed:
        raise ManifestError(
            src,
            f"side {given!r}, but {label} names the {prefixed} leg's sensors ({prefixed}_thigh, "
            f"{prefixed}_shank, {prefixed}_foot); write {prefixed} or leave the side empty",
            k,
        )
    side = "both" if two_legs else given or prefixed or p.default_side
    if side not in ("left", "right", "both"):
        raise ManifestError(src, f"side {side!r}; use left or right (both: a two-leg trial)", k)
    calibration = row.get("calibration") or ""
    b = INPUT_BOUNDS
    return StudyTrial(
        name=_folder_name(label),
        path=base / label,
        label=label,
        side=side,
        subject=row.get("subject", ""),
        task=row.get("task", ""),
        height_m=_in_range(row.get("height_m"), "height_m", p.default_height_m, b.height_m, src, k),
        mass_kg=_in_range(row.get("mass_kg"), "mass_kg", p.default_mass_kg, b.mass_kg, src, k),
        calibration=base / calibration if calibration else None,
    )


def _in_range(
    text: str | None, column: str, default: float, bounds: tuple[float, float], src: Path, k: int
) -> float:
    """The cell as a number within ``bounds`` (the CLI's ``--height`` / ``--mass`` range), or the default."""
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ManifestError(src, f"{column} {text!r} is not a positive number", k)
    lo, hi = bounds
    if not lo <= value <= hi:
        unit = column.rsplit("_", 1)[-1]
        raise ManifestError(src, f"{column} {text} is outside {lo:g}–{hi:g} {unit}; give it in {unit}", k)
    return value


def _folder_name(label: str) -> str:
    """The trial's output folder: its path's parts joined by ``__``, never hidden.

    (``.failed`` holds the failed trials' records.)
    """
    parts = [part for part in Path(label).with_suffix("").parts if part not in ("", ".", "..", "/")]
    name = "__".join(parts).replace(" ", "_").lstrip(".")
    return name or "trial"


def _check_unique(trials: Sequence[StudyTrial], src: Path) -> None:
    seen: dict[str, str] = {}
    for k, t in enumerate(trials, start=1):
        key = t.name.lower()  # case-insensitive file systems
        if key in seen:
            if seen[key] == t.label:
                raise ManifestError(
                    src,
                    f"the same trial twice would share the output folder {t.name!r}; list each trial once",
                    k,
                )
            raise ManifestError(
                src,
                f"{seen[key]!r} and {t.label!r} map to the same output folder {t.name!r}; rename one of "
                "the two files",
                k,
            )
        seen[key] = t.label
