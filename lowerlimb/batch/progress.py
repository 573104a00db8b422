"""Progress of a study on stderr: a bar with trials done, failed and the time left; or one line per trial.

A rich progress bar when ``rich`` is installed and stderr is a terminal; else one
line per finished trial (for logs); nothing in quiet mode.
"""

from __future__ import annotations

import sys
import time
from typing import Any

from .record import TrialOutcome

__all__ = ["StudyProgress"]


class StudyProgress:
    """Counts finished trials and shows them; use as a context manager."""

    def __init__(self, total: int, *, skipped: int = 0, quiet: bool = False) -> None:
        self.total = total
        self.skipped = skipped
        self.done = 0
        self.failed = 0
        self.quiet = quiet
        self._t0 = time.perf_counter()
        self._bar: Any = None
        self._task: Any = None

    def __enter__(self) -> StudyProgress:
        if self.quiet:
            return self
        if self.skipped:
            print(f"lowerlimb batch: {self.skipped} trial(s) already done, skipped", file=sys.stderr)
        if self.total and sys.stderr.isatty():
            try:
                from rich.progress import (
                    BarColumn,
                    MofNCompleteColumn,
                    Progress,
                    TextColumn,
                    TimeElapsedColumn,
                    TimeRemainingColumn,
                )
            except ImportError:
                return self
            self._bar = Progress(
                TextColumn("trials"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("[red]{task.fields[failed]} failed"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                transient=False,
            )
            self._bar.start()
            self._task = self._bar.add_task("trials", total=self.total, failed=0)
        return self

    def update(self, outcome: TrialOutcome) -> None:
        """Count one finished trial."""
        self.done += 1
        self.failed += outcome.status == "failed"
        if self.quiet:
            return
        if self._bar is not None:
            self._bar.update(self._task, advance=1, failed=self.failed)
            if outcome.status == "failed":
                self._bar.console.print(f"[red]failed[/red] {outcome.trial}: {outcome.reason}")
            return
        left = self.eta_s()
        eta = f", ETA {left:.0f} s" if left is not None else ""
        line = f"[{self.done}/{self.total}, {self.failed} failed{eta}] {outcome.trial}: {outcome.status}"
        if outcome.status != "ok":
            line += f" ({outcome.reason})"
        print(line, file=sys.stderr, flush=True)

    def eta_s(self) -> float | None:
        """Seconds left at the mean rate so far, or ``None`` before the first trial."""
        if not self.done:
            return None
        return (time.perf_counter() - self._t0) / self.done * (self.total - self.done)

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.stop()
