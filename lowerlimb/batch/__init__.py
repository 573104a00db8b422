"""Many trials at once: a manifest or folder in, one result folder per trial and the study tables out.

:func:`process_study` (a pandas DataFrame) and :func:`run_study` (typed) run a
study on a local process pool or a Dask cluster (docs/formats.md, "Many trials").
"""

from .manifest import ManifestError, StudyTrial, read_study
from .params import BatchParams
from .record import TrialOutcome
from .study import StudyResult, process_study, run_study

__all__ = [
    "BatchParams",
    "ManifestError",
    "StudyResult",
    "StudyTrial",
    "TrialOutcome",
    "process_study",
    "read_study",
    "run_study",
]
