"""A whole study: which trials still need work, running them on a backend, and the study tables.

:func:`run_study` is ``lowerlimb batch`` in typed form; :func:`process_study` is the
same returning a pandas DataFrame. The contract (docs/formats.md, "Many trials"):
one output folder per trial, ``batch.csv`` with one row per trial, the per-subject
and per-task summaries; a failed trial is recorded and the others go on; a re-run
skips every trial whose record matches its input hash and whose files are those the record
lists (``force`` redoes them).
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lowerlimb.errors import InputError
from lowerlimb.io.result_files import OUTPUT_FILES, check_outputs
from lowerlimb.methods import CALIBRATION_METHODS, CENTRE_FORMS, ORIENTATION_FILTERS

from .manifest import StudyTrial, read_study
from .params import BatchParams
from .progress import StudyProgress
from .record import (
    FAILED_DIR,
    MARKER,
    TrialJob,
    TrialOutcome,
    files_intact,
    input_hash,
    read_record,
    remove_quietly,
    write_record,
)
from .summary import write_study_tables

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["StudyResult", "process_study", "run_study"]


@dataclass
class StudyResult:
    """What :func:`run_study` did.

    Attributes:
        outcomes: one per trial, in manifest order.
        out: the study's output folder.
        processed: trials processed in this run (the others were up to date).
        wall_s: wall time of the run, s.
        files: the study tables written.
    """

    outcomes: list[TrialOutcome]
    out: Path
    processed: int = 0
    wall_s: float = 0.0
    files: list[Path] = field(default_factory=list)

    @property
    def failed(self) -> list[TrialOutcome]:
        """The failed trials."""
        return [o for o in self.outcomes if o.status == "failed"]

    def rows(self) -> list[dict[str, Any]]:
        """``batch.csv``'s rows, in manifest order."""
        return [o.row() for o in self.outcomes]


def run_study(
    source: str | os.PathLike[str],
    out: str | os.PathLike[str],
    params: BatchParams | None = None,
    *,
    scheduler: Any = None,
    quiet: bool = True,
    worker: Callable[[TrialJob], TrialOutcome] | None = None,
) -> StudyResult:
    """Process every trial of a manifest or folder that is not up to date, and write the study tables.

    Args:
        source: a manifest CSV or a folder of trial CSVs (:func:`read_study`).
        out: the study's output folder (created).
        params: options (:class:`BatchParams`).
        scheduler: ``None`` for the local process pool, or a Dask scheduler address,
            ``distributed.Client`` or cluster.
        quiet: no progress on stderr.
        worker: the function run per trial, a module-level function (default
            :func:`~lowerlimb.batch.worker.run_trial`, imported only when there is work).

    Raises:
        FileNotFoundError: ``source`` does not exist.
        ManifestError: the manifest is unusable (nothing is processed).
        InputError: bad options, ``out`` is a file, a scheduler address that is not
            ``[tcp://]HOST:PORT``, or the Dask scheduler is unusable.
    """
    t0 = time.perf_counter()
    p = _checked(params or BatchParams())
    if scheduler is not None:
        from .dask_cluster import check_scheduler_address

        check_scheduler_address(scheduler)
    trials = read_study(source, p, exclude=out)
    root = Path(out)
    if root.exists() and not root.is_dir():
        raise InputError(f"{root} is a file; give a folder for --out")
    created = not root.exists()
    root.mkdir(parents=True, exist_ok=True)
    outcomes: dict[str, TrialOutcome] = {}
    jobs: list[TrialJob] = []
    for trial in trials:
        outcome, job = _plan(trial, root, p)
        if outcome is not None:
            outcomes[trial.name] = outcome
        if job is not None:
            jobs.append(job)
    result = StudyResult([], root)
    last_write = [time.perf_counter()]

    finished: list[str] = []
    unusable = False

    def finish(outcome: TrialOutcome) -> None:
        finished.append(outcome.name)
        outcomes[outcome.name] = outcome
        _record(root, outcome)
        progress.update(outcome)
        if time.perf_counter() - last_write[0] > p.summary_every_s:
            write_study_tables(root, [outcomes[t.name].row() for t in trials if t.name in outcomes])
            last_write[0] = time.perf_counter()

    with StudyProgress(len(jobs), skipped=len(trials) - len(jobs), quiet=quiet) as progress:
        try:
            if not jobs:
                pass
            elif scheduler is None:
                from .local_pool import run_local

                workers = max(1, min(p.workers or os.cpu_count() or 1, len(jobs)))
                run_local(
                    worker or _default_worker(), jobs, workers=workers, on_done=finish, retries=p.retries
                )
            else:
                from .dask_cluster import run_dask

                run_dask(worker or _default_worker(), jobs, scheduler=scheduler, on_done=finish)
        except InputError:
            unusable = not finished  # the scheduler: nothing ran, nothing is written
            if unusable and created:
                shutil.rmtree(root, ignore_errors=True)
            raise
        finally:
            result.outcomes = [outcomes[t.name] for t in trials if t.name in outcomes]
            if not unusable:
                result.files = write_study_tables(root, result.rows())
    result.processed = len(jobs)
    result.wall_s = time.perf_counter() - t0
    return result


def process_study(
    manifest: str | os.PathLike[str],
    out: str | os.PathLike[str],
    params: BatchParams | None = None,
    *,
    scheduler: Any = None,
    quiet: bool = True,
    **options: Any,
) -> pd.DataFrame:
    """Process a study (:func:`run_study`) and return ``batch.csv`` as a pandas DataFrame.

    Args:
        manifest: a manifest CSV or a folder of trial CSVs.
        out: the study's output folder.
        params: options (:class:`BatchParams`).
        **options: fields of :class:`BatchParams` overriding ``params``
            (``workers=2, force=True, outputs={"calibration", "angles"}``…).
        scheduler: ``None`` (local pool) or a Dask scheduler address, client or cluster.
        quiet: no progress on stderr.

    Raises:
        InputError: pandas is not installed (``pip install 'lowerlimb[study]'``), an
            unknown option, or any error of :func:`run_study`.
    """
    try:
        import pandas as pd
    except ImportError:
        raise InputError("process_study returns a pandas DataFrame; pip install 'lowerlimb[study]'") from None
    p = params or BatchParams()
    unknown = sorted(set(options) - set(BatchParams.__dataclass_fields__))
    if unknown:
        raise InputError(
            f"unknown option {', '.join(unknown)}; use fields of BatchParams: "
            f"{', '.join(BatchParams.__dataclass_fields__)}"
        )
    if "outputs" in options:
        options["outputs"] = check_outputs(options["outputs"])  # a set, or one string "angles,calibration"
    result = run_study(manifest, out, replace(p, **options), scheduler=scheduler, quiet=quiet)
    from .summary import batch_columns

    rows = result.rows()
    return pd.DataFrame(rows, columns=batch_columns(rows))


def _default_worker() -> Callable[[TrialJob], TrialOutcome]:
    from .worker import run_trial  # the pipeline's imports, only when there is work

    return run_trial


def _checked(p: BatchParams) -> BatchParams:
    if p.method not in CALIBRATION_METHODS:
        raise InputError(
            f"unknown calibration method {p.method!r}; use one of {', '.join(CALIBRATION_METHODS)}"
        )
    if p.filter_name not in ORIENTATION_FILTERS:
        raise InputError(f"unknown filter {p.filter_name!r}; use one of {', '.join(ORIENTATION_FILTERS)}")
    for name, form in (("centre form", p.centre_form), ("hip-in-pelvis form", p.hip_in_pelvis_form)):
        if form not in CENTRE_FORMS:
            raise InputError(f"unknown {name} {form!r}; use one of {', '.join(CENTRE_FORMS)}")
    if p.workers is not None and p.workers < 1:
        raise InputError(f"--workers {p.workers}: give at least 1")
    return replace(p, outputs=check_outputs(p.outputs))


def _plan(trial: StudyTrial, root: Path, p: BatchParams) -> tuple[TrialOutcome | None, TrialJob | None]:
    """An earlier outcome still valid for ``trial`` (then no job), or the job to run."""
    try:
        digest = input_hash(trial, p)
    except OSError as e:
        reason = f"cannot read {e.filename or trial.path}: {e.strerror or e}; fix the manifest's path"
        return TrialOutcome.failed(trial, reason, "input", ""), None
    if not p.force:
        done = read_record(root / trial.name / MARKER)
        if done is not None and done.input_hash == digest and _complete(root / trial.name, p, done):
            done.skipped = True
            return done, None
        failed = read_record(root / FAILED_DIR / f"{trial.name}.json")
        if failed is not None and failed.input_hash == digest and failed.failure == "input":
            failed.skipped = True
            return failed, None
    return None, TrialJob(trial, p, root, digest)


def _complete(folder: Path, p: BatchParams, done: TrialOutcome) -> bool:
    """Whether ``folder`` has every chosen output, each as ``done`` recorded it.

    A two-leg trial (side ``both``) has no ``s2j``; a file whose size or SHA-256 differs
    from the record (truncated, overwritten) makes the folder incomplete.
    """
    names = p.outputs - {"s2j"} if done.side == "both" else p.outputs
    chosen = all((folder / OUTPUT_FILES[name]).is_file() for name in names)
    return chosen and files_intact(folder, done.files)


def _record(root: Path, outcome: TrialOutcome) -> None:
    """Keep a failed trial's record (its folder, if any, is left as it was); drop it once it succeeds."""
    failed = root / FAILED_DIR / f"{outcome.name}.json"
    if outcome.status == "failed":
        failed.parent.mkdir(exist_ok=True)
        write_record(failed, outcome)
    else:
        remove_quietly(failed)
