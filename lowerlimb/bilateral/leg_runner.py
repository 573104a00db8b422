"""Both legs of a seven-IMU trial through the single-leg pipeline, side by side on two cores.

The two legs share nothing until the one-pelvis stage, so the right leg runs in a forked
child process while the parent runs the left one: a 5-minute simulated two-leg walk's legs
took 6.0 s one after the other and 3.4 s side by side on a 2-core machine
(``benchmarks/results/bilateral_speed.md``). The child returns its result (pickled), the
warnings it raised (as ``(text, category)``, :class:`LegWarning`) and what it printed on
stderr, which the parent prints after the left leg's lines, so the terminal reads as it did
one leg after the other. The numbers are the same either way (the pipeline is deterministic
and single-threaded).

The legs run one after the other instead when side by side is not safe or not possible
(:func:`side_by_side_possible`): fewer than two cores, no ``fork`` start method or not Linux
(macOS's ``fork`` is unsafe with its system libraries), a process that already runs other
threads (a Dask worker: ``fork`` copies no thread but the calling one and can deadlock on
their locks), or a daemonic process (which may not have children). A child that fails, in
any way, leaves the leg to be run again in the parent, so a user's mistake is raised there
as the same one-line error, with its own type and data, as without the child.
"""

from __future__ import annotations

import contextlib
import io
import multiprocessing
import os
import sys
import threading
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["LegWarning", "run_two_legs", "side_by_side_possible"]


@dataclass(frozen=True)
class LegWarning:
    """A warning one leg raised, kept to be issued again naming the leg.

    Attributes:
        message: its text.
        category: its class.
    """

    message: str
    category: type[Warning]


LegRun = Callable[[str], tuple[Any, list[LegWarning]]]
"""Runs one leg (``"left"`` or ``"right"``): its result and its warnings."""


def recorded(caught: list[warnings.WarningMessage]) -> list[LegWarning]:
    """The caught warnings as :class:`LegWarning` records (picklable, whatever the class)."""
    return [LegWarning(str(w.message), w.category) for w in caught]


def side_by_side_possible() -> bool:
    """Whether this process may fork a child to run a leg (module docstring)."""
    return (
        sys.platform.startswith("linux")
        and (os.cpu_count() or 1) >= 2
        and "fork" in multiprocessing.get_all_start_methods()
        and threading.active_count() == 1
        and not multiprocessing.current_process().daemon
    )


def _child(conn: Any, run: LegRun, side: str) -> None:
    """In the forked child: run ``side`` and send ``(result, warnings, stderr text)``, or ``None``."""
    try:
        text = io.StringIO()
        with contextlib.redirect_stderr(text):
            result, caught = run(side)
        conn.send((result, caught, text.getvalue()))
    except BaseException:  # noqa: BLE001 - any failure: the parent runs the leg again to raise it
        with contextlib.suppress(BaseException):
            conn.send(None)
    finally:
        conn.close()


def run_two_legs(run: LegRun, parallel: bool = True) -> dict[str, tuple[Any, list[LegWarning]]]:
    """``{"left": run("left"), "right": run("right")}``, the right leg in a child when possible.

    Args:
        run: runs one leg and returns its result and warnings; it must not depend on the
            other leg's result.
        parallel: False runs the legs one after the other in this process.

    Raises:
        Whatever ``run`` raises, from this process: the left leg's first, then the right's.
    """
    if not (parallel and side_by_side_possible()):
        return {side: run(side) for side in ("left", "right")}
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    child = context.Process(target=_child, args=(send, run, "right"), daemon=True)
    try:
        child.start()
    except (OSError, AssertionError):  # no process could be made: one after the other
        return {side: run(side) for side in ("left", "right")}
    send.close()
    sent = None
    try:
        left = run("left")
        with contextlib.suppress(EOFError, OSError):  # else the child died without a word
            sent = receive.recv()
    finally:
        receive.close()
        child.join(timeout=None if sent is not None else 0.0)
        if child.is_alive():  # the left leg raised, or the child hangs on
            child.terminate()
            child.join()
    if sent is None:
        return {"left": left, "right": run("right")}
    result, caught, text = sent
    if text:
        sys.stderr.write(text)
    return {"left": left, "right": (result, caught)}
