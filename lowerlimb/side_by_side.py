"""Two independent pieces of work on two cores: the second in a forked child while this one runs the first.

Used where a run has two large pieces that share nothing: the two legs of a seven-IMU trial
(:mod:`lowerlimb.bilateral.leg_runner`) and the report's two grids of time plots
(:mod:`lowerlimb.viz.report`). The child returns its value pickled, and what it printed on
stderr, which this process prints after the first piece's lines, so the terminal reads as
it did one after the other. The values are the same either way.

The work runs one piece after the other instead where side by side is not safe or not
possible (:func:`possible`): fewer than two cores, no ``fork`` start method or not Linux
(macOS's ``fork`` is unsafe with its system libraries), a process that already runs other
threads (a Dask worker: ``fork`` copies no thread but the calling one and can deadlock on
their locks), a daemonic process (which may not have children), work nested in side-by-side
work, in the child or here (two cores, two processes), or a process that turned it off (:func:`set_enabled`;
``lowerlimb calibrate --one-core``, and every ``batch`` worker, whose trials already fill the
cores). A child that fails, in any way, leaves its piece to be run again here, so an error is
raised from this process, with its own type and data, as without the child.
"""

from __future__ import annotations

import contextlib
import io
import multiprocessing
import os
import sys
import threading
from collections.abc import Callable
from typing import Any, TypeVar

__all__ = ["possible", "set_enabled", "side_by_side"]

A = TypeVar("A")
B = TypeVar("B")

_enabled = True


def set_enabled(enabled: bool) -> None:
    """Allow (the default) or forbid side-by-side work in this process."""
    global _enabled
    _enabled = bool(enabled)


def possible() -> bool:
    """Whether this process may fork a child for a piece of work (module docstring)."""
    return (
        _enabled
        and sys.platform.startswith("linux")
        and (os.cpu_count() or 1) >= 2
        and "fork" in multiprocessing.get_all_start_methods()
        and threading.active_count() == 1
        and not multiprocessing.current_process().daemon
    )


def _child(conn: Any, work: Callable[[], Any]) -> None:
    """In the forked child: run ``work`` and send ``(value, stderr text)``, or ``None`` when it failed."""
    set_enabled(False)  # no grandchildren
    try:
        text = io.StringIO()
        with contextlib.redirect_stderr(text):
            value = work()
        conn.send((value, text.getvalue()))
    except BaseException:  # noqa: BLE001 - any failure: the parent runs the work again to raise it
        with contextlib.suppress(BaseException):
            conn.send(None)
    finally:
        conn.close()


def side_by_side(first: Callable[[], A], second: Callable[[], B], parallel: bool = True) -> tuple[A, B]:
    """``(first(), second())``, ``second`` in a forked child while this process runs ``first``.

    Args:
        first: runs here.
        second: runs in the child when :func:`possible` (else here, after ``first``); its
            value must pickle, or it is run again here.
        parallel: False runs both here, one after the other.

    Raises:
        Whatever ``first`` raises, then whatever ``second`` raises, from this process.
    """
    if not (parallel and possible()):
        return first(), second()
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    child = context.Process(target=_child, args=(send, second), daemon=True)
    try:
        child.start()
    except (OSError, AssertionError):  # no process could be made: one after the other
        receive.close()
        send.close()
        return first(), second()
    send.close()
    sent = None
    try:
        set_enabled(False)  # the two cores are busy: ``first`` runs its own work one after the other
        try:
            value = first()
        finally:
            set_enabled(True)
        with contextlib.suppress(EOFError, OSError):  # else the child died without a word
            sent = receive.recv()
    finally:
        receive.close()
        child.join(timeout=None if sent is not None else 0.0)
        if child.is_alive():  # ``first`` raised, or the child hangs on
            child.terminate()
            child.join()
    if sent is None:
        return value, second()
    other, text = sent
    if text:
        sys.stderr.write(text)
    return value, other
