"""One trial's line of ``batch.csv``, its input hash, and the records that make a run resumable.

A finished trial leaves a record: inside its output folder (:data:`MARKER`, written in
the same atomic rename as the outputs, so a folder with a record is complete; it keeps
each output file's size and SHA-256), or, for a failed trial, ``DIR/.failed/<name>.json``.
A re-run reads them back instead of processing again when the input hash still matches
and, for a folder, its files are still those written.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from lowerlimb import __version__
from lowerlimb.io.atomic import write_atomically, write_text
from lowerlimb.io.file_hash import file_sha256

from .manifest import StudyTrial
from .params import BatchParams

__all__ = [
    "BATCH_COLUMNS",
    "FAILED_DIR",
    "MARKER",
    "STATUSES",
    "TrialJob",
    "TrialOutcome",
    "file_digests",
    "files_intact",
    "input_hash",
    "read_record",
    "write_record",
]

#: Name of the record inside a trial's output folder.
MARKER = ".batch.json"
#: Folder (inside the study's output folder) of the failed trials' records.
FAILED_DIR = ".failed"
#: Values of ``status``.
STATUSES: tuple[str, ...] = ("ok", "warning", "failed")
#: First columns of ``batch.csv``; the key results follow.
BATCH_COLUMNS: tuple[str, ...] = (
    "trial",
    "status",
    "reason",
    "wall_s",
    "cpu_s",
    "peak_rss_mb",
    "subject",
    "task",
    "side",
    "folder",
)


@dataclass(frozen=True)
class TrialJob:
    """One unit of work: a trial, the study's options, where to write, and its input hash.

    Attributes:
        trial: the trial.
        params: the study's options.
        out: the study's output folder (the trial's folder is ``out / trial.name``).
        digest: its input hash (:func:`input_hash`).
        attempt: 1, then 2… when run again after its worker process died.
    """

    trial: StudyTrial
    params: BatchParams
    out: Path
    digest: str
    attempt: int = 1


@dataclass
class TrialOutcome:
    """What processing one trial gave.

    Attributes:
        name: output folder name.
        trial: the trial as the manifest gives it.
        status: ``ok``, ``warning`` (processed; ``reason`` lists the warnings) or ``failed``.
        reason: one line: the warnings, or why the trial failed; ``""`` when ok.
        wall_s: wall time of reading, processing and writing, s.
        cpu_s: CPU time of the process that ran it, over this trial, s.
        peak_rss_mb: peak resident memory of the process that ran it so far, MB
            (NaN where the platform does not tell).
        subject: subject identifier.
        task: task identifier.
        side: instrumented leg.
        results: key results (:func:`lowerlimb.batch.worker.key_results`).
        input_hash: hash of the inputs and options it was computed from.
        failure: ``"input"`` (the trial or its options are bad: a re-run gives the same),
            ``"internal"`` (a bug or solver failure), ``"died"`` (the worker process died);
            ``""`` when not failed.
        attempts: times it was run in this session.
        skipped: taken from an earlier run's record, not processed now.
        files: the output folder's files as written, name -> ``[size in bytes, SHA-256]``
            (:func:`file_digests`; ``{}`` when failed): a re-run redoes the trial when one differs.
    """

    name: str
    trial: str
    status: str
    reason: str = ""
    wall_s: float = 0.0
    cpu_s: float = math.nan
    peak_rss_mb: float = math.nan
    subject: str = ""
    task: str = ""
    side: str = ""
    results: dict[str, float] = field(default_factory=dict)
    input_hash: str = ""
    failure: str = ""
    attempts: int = 1
    skipped: bool = False
    files: dict[str, list[int | str]] = field(default_factory=dict)

    @classmethod
    def failed(
        cls, trial: StudyTrial, reason: str, failure: str, digest: str, wall_s: float = 0.0
    ) -> TrialOutcome:
        """A failed outcome of ``trial``."""
        return cls(
            trial.name,
            trial.label,
            "failed",
            " ".join(reason.split()),
            wall_s,
            math.nan,
            math.nan,
            trial.subject,
            trial.task,
            trial.side,
            {},
            digest,
            failure,
        )

    def row(self) -> dict[str, Any]:
        """Its ``batch.csv`` row: :data:`BATCH_COLUMNS`, then the key results."""
        row: dict[str, Any] = {
            "trial": self.trial,
            "status": self.status,
            "reason": self.reason,
            "wall_s": round(self.wall_s, 3),
            "cpu_s": round(self.cpu_s, 3),
            "peak_rss_mb": round(self.peak_rss_mb, 1),
            "subject": self.subject,
            "task": self.task,
            "side": self.side,
            "folder": self.name if self.status != "failed" else "",
        }
        row.update(self.results)
        return row

    def to_dict(self) -> dict[str, Any]:
        """The record's JSON document."""
        return {"lowerlimb": __version__, **asdict(self)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> TrialOutcome:
        """Read back :meth:`to_dict`."""
        keys = set(cls.__dataclass_fields__)
        return cls(**{k: v for k, v in d.items() if k in keys})


def input_hash(trial: StudyTrial, params: BatchParams) -> str:
    """SHA-256 of the trial file, the reused calibration file, the row's values and the options.

    Raises:
        OSError: a file cannot be read (the caller records the trial as failed).
    """
    h = hashlib.sha256()
    key = {
        "version": __version__,
        "side": trial.side,
        "height_m": trial.height_m,
        "mass_kg": trial.mass_kg,
        **params.processing_key(),
    }
    h.update(json.dumps(key, sort_keys=True).encode())
    for path in (trial.path, trial.calibration):
        if path is None:
            continue
        h.update(b"\0file\0")
        with open(path, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                h.update(chunk)
    return h.hexdigest()


def file_digests(folder: Path) -> dict[str, list[int | str]]:
    """Each file of ``folder`` (not its record :data:`MARKER`): name -> ``[size in bytes, SHA-256]``.

    Raises:
        OSError: a file cannot be read.
    """
    return {
        f.name: [f.stat().st_size, file_sha256(f)]
        for f in sorted(folder.iterdir())
        if f.is_file() and f.name != MARKER
    }


def files_intact(folder: Path, files: dict[str, list[int | str]]) -> bool:
    """Whether every file of ``files`` (:func:`file_digests`) is in ``folder`` with that size and hash.

    ``False`` for an empty ``files`` (a record written before they were kept) and for a
    file that cannot be read.
    """
    if not files:
        return False
    try:
        for name, (size, digest) in files.items():
            path = folder / name
            if path.stat().st_size != size or file_sha256(path) != digest:
                return False
    except (OSError, ValueError, TypeError):
        return False
    return True


def write_record(path: Path, outcome: TrialOutcome) -> None:
    """Write a record atomically."""
    text = json.dumps(outcome.to_dict(), indent=1)
    write_atomically(path, lambda tmp: write_text(tmp, text))


def read_record(path: Path) -> TrialOutcome | None:
    """A record, or ``None`` when it is absent or unreadable (the trial is then processed again)."""
    try:
        return TrialOutcome.from_dict(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError):
        return None


def remove_quietly(path: Path) -> None:
    """Remove a file if it exists."""
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass
