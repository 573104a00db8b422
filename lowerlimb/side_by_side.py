"""Two independent pieces of work on two cores: the second in a forked child while this one runs the first.

Used where a run has two large pieces that share nothing: the two legs of a seven-IMU trial
(:mod:`lowerlimb.bilateral.leg_runner`), a leg's coherent-band and widened-band fits
(:func:`lowerlimb.calibration.leg.calibrate_leg`: the widened one started beside and dropped
where no cap binds, :class:`Beside`) and the report's two grids of time plots
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
from typing import Any, Generic, TypeVar, cast

__all__ = ["Beside", "possible", "set_enabled", "side_by_side"]

A = TypeVar("A")
B = TypeVar("B")

_enabled = True


def set_enabled(enabled: bool) -> None:
    """Allow (the default) or forbid side-by-side work in this process."""
    global _enabled
    _enabled = bool(enabled)


def _threads() -> int:
    """Threads of this process, those started outside :mod:`threading` too (pytest-xdist's, execnet's)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return threading.active_count()


def possible() -> bool:
    """Whether this process may fork a child for a piece of work (module docstring)."""
    return (
        _enabled
        and sys.platform.startswith("linux")
        and (os.cpu_count() or 1) >= 2
        and "fork" in multiprocessing.get_all_start_methods()
        and not multiprocessing.current_process().daemon
        and _threads() == 1
    )


def _child(conn: Any, other_end: Any, work: Callable[[], Any]) -> None:
    """In the forked child: run ``work`` and send ``(value, stderr text)``, or ``None`` when it failed."""
    set_enabled(False)  # no grandchildren
    other_end.close()  # else a send the parent no longer reads blocks forever instead of failing
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


class Beside(Generic[B]):
    """``work`` started in a forked child where :func:`possible`; its value taken, or the child dropped.

    Use it as a context manager: leaving the block drops a child whose value was not taken.
    While the child runs, this process starts no other (nothing nested).

    Args:
        work: the piece of work; its value must pickle, or it is run again here.
        parallel: False never starts a child (:meth:`value` runs ``work`` here).
    """

    def __init__(self, work: Callable[[], B], parallel: bool = True) -> None:
        self._work = work
        self._child: Any = None
        self._receive: Any = None
        if not (parallel and possible()):
            return
        context = multiprocessing.get_context("fork")
        receive, send = context.Pipe(duplex=False)
        child = context.Process(target=_child, args=(send, receive, work), daemon=True)
        try:
            child.start()
        except (OSError, AssertionError):  # no process could be made: run here when asked
            receive.close()
            send.close()
            return
        send.close()
        self._child, self._receive = child, receive
        set_enabled(False)  # the two cores are busy

    def value(self) -> B:
        """The child's value (its stderr printed here), or ``work()`` run here where it failed or none ran.

        Raises:
            Whatever ``work`` raises, from this process.
        """
        if self._child is not None:
            sent = None
            with contextlib.suppress(Exception):  # the child died, or its value does not unpickle
                sent = self._receive.recv()
            self._close(finished=sent is not None)
            if sent is not None:
                value, text = sent
                if text:
                    sys.stderr.write(text)
                return cast(B, value)
        return self._work()

    def cancel(self) -> None:
        """Drop the child (its work is not needed)."""
        if self._child is not None:
            self._close(finished=False)

    def _close(self, finished: bool) -> None:
        self._receive.close()
        self._child.join(timeout=5.0 if finished else 0.0)
        if self._child.is_alive():  # not needed, or hanging on: SIGKILL (a handler may catch SIGTERM)
            self._child.kill()
            self._child.join()
        self._child = self._receive = None
        set_enabled(True)

    def __enter__(self) -> Beside[B]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.cancel()


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
    with Beside(second, parallel) as beside:
        value = first()
        return value, beside.value()
