"""Ctrl-C and SIGTERM that are never swallowed, and never let a half-done run write its outputs.

Python turns SIGINT into :class:`KeyboardInterrupt` wherever the main thread
happens to be. When that is inside a third-party optional import that catches
``BaseException``, the interrupt is lost and the run goes on to write every
output with exit 0. SIGTERM, by default, kills the process without running any
``finally``, so a staging folder is left behind.

:func:`install_signal_handlers` (the command line calls it first thing)
records each signal and raises :class:`Interrupted` (a ``KeyboardInterrupt``);
:func:`check_interrupted` raises it again if a recorded signal was swallowed.
The all-or-nothing writers (:mod:`lowerlimb.io.atomic`) call it before they
commit, so an interrupted run never commits its outputs.
"""

from __future__ import annotations

import signal
from types import FrameType

__all__ = ["Interrupted", "check_interrupted", "install_signal_handlers", "received_signal"]

_received: list[int] = []


class Interrupted(KeyboardInterrupt):  # noqa: N818 (a KeyboardInterrupt, named as the user sees it)
    """SIGINT or SIGTERM arrived; carries the signal number.

    Attributes:
        signum: the signal received (``signal.SIGINT`` or ``signal.SIGTERM``).
    """

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(signal.Signals(signum).name)

    @property
    def exit_status(self) -> int:
        """The shell's convention: 128 + the signal number (130 for Ctrl-C, 143 for SIGTERM)."""
        return 128 + self.signum


def _handler(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    raise Interrupted(signum)


def install_signal_handlers() -> None:
    """Turn SIGINT and SIGTERM into :class:`Interrupted`, and remember them (main thread only)."""
    _received.clear()
    for signum in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(signum) is not signal.SIG_IGN:  # an inherited "ignore" (nohup, `&`) stays
            signal.signal(signum, _handler)


def received_signal() -> int | None:
    """The first signal recorded since :func:`install_signal_handlers`, or None."""
    return _received[0] if _received else None


def check_interrupted() -> None:
    """Raise :class:`Interrupted` again when a signal arrived, even if something swallowed it.

    Raises:
        Interrupted: a recorded SIGINT or SIGTERM.
    """
    if _received:
        raise Interrupted(_received[0])
