"""Worker functions for the batch tests, importable by the worker processes (import as ``batch_workers``)."""

from __future__ import annotations

import os

from lowerlimb.batch.record import TrialJob, TrialOutcome
from lowerlimb.batch.worker import run_trial


def dies_on_killer(job: TrialJob) -> TrialOutcome:
    """Like ``run_trial``, but the process dies (as if killed) on a trial named ``killer``."""
    if job.trial.name == "killer":
        os._exit(9)
    return run_trial(job)


def reports_paths(job: TrialJob) -> TrialOutcome:
    """A failed outcome whose reason is ``trial|calibration|output folder``, the paths the worker got."""
    paths = (job.trial.path, job.trial.calibration, job.out)
    return TrialOutcome.failed(job.trial, "|".join(str(p) for p in paths), "internal", job.digest)
