"""The ``lowerlimb`` command line: one module per command (docs/architecture.md).

Each command module has ``add_parser(subparsers)`` and ``run(args) -> int``;
:data:`COMMAND_MODULES` lists them. The CLI is the top of the import graph:
nothing in the library imports it.

Exit status: 0 success, 2 bad input (one line on stderr naming the problem and
the fix, no traceback, no partial output), 1 internal error (one line; set
``LOWERLIMB_DEBUG=1`` for the traceback), 130 interrupted.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from types import ModuleType

from lowerlimb import __version__
from lowerlimb.cli import batch, calibrate, compare, demo, import_, simulate, view
from lowerlimb.cli._common import EXIT_BAD_INPUT, EXIT_INTERNAL, EXIT_OK, Parser, UsageError
from lowerlimb.errors import InputError, LowerLimbError

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "EXIT_INTERNAL", "EXIT_OK", "UsageError", "build_parser", "main"]

#: The commands, in ``--help`` order: name -> module with ``add_parser`` and ``run``.
COMMAND_MODULES: dict[str, ModuleType] = {
    "simulate": simulate,
    "calibrate": calibrate,
    "batch": batch,
    "demo": demo,
    "view": view,
    "import": import_,
    "compare": compare,
}

#: name -> ``run(args) -> exit status``.
COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    name: module.run for name, module in COMMAND_MODULES.items()
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command."""
    parser = Parser(prog="lowerlimb", description="Wearable IMU motion capture of the human leg.")
    parser.add_argument("--version", action="version", version=f"lowerlimb {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    for module in COMMAND_MODULES.values():
        module.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``lowerlimb`` console script; returns the exit status."""
    # The work is many small matrix products: BLAS threads only fight over the
    # cores (measured up to 20x slower on 2 cores). Set before numpy loads.
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    try:
        args = build_parser().parse_args(argv)
        if args.command is None:
            raise UsageError(
                f"no command given; choose {', '.join(COMMAND_MODULES)} (see 'lowerlimb --help')"
            )
        # Before the command's heavy imports: Ctrl-C or SIGTERM from here on is recorded, and
        # an interrupt swallowed by a third-party import is raised again before any output is
        # committed (lowerlimb.io.interrupts).
        from lowerlimb.io.interrupts import check_interrupted, install_signal_handlers

        if _in_main_thread():
            install_signal_handlers()
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            # third-party deprecation notices (pyzmq via meshcat…) are not the user's business
            warnings.filterwarnings("ignore", category=DeprecationWarning)
            warnings.filterwarnings("ignore", category=PendingDeprecationWarning)
            warnings.filterwarnings("ignore", category=FutureWarning)
            # numpy's floating-point notices ("invalid value encountered…") name no input and no
            # fix; the checks refuse the inputs that cause them
            warnings.filterwarnings("ignore", category=RuntimeWarning)
            warnings.formatwarning = _format_warning  # type: ignore[assignment]
            check_interrupted()  # a signal swallowed while loading the command
            return COMMANDS[args.command](args)
    except (InputError, FileNotFoundError, IsADirectoryError, PermissionError) as e:
        print(f"lowerlimb: error: {_one_line(e)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as e:
        signum = getattr(e, "signum", None)
        print(f"lowerlimb: interrupted{f' ({e})' if signum else ''}", file=sys.stderr)
        return 128 + (signum or 2)
    except Exception as e:  # a bug or a solver failure, not the user's input
        if os.environ.get("LOWERLIMB_DEBUG"):
            raise
        kind = "internal error" if isinstance(e, LowerLimbError) else f"internal error ({type(e).__name__})"
        print(
            f"lowerlimb: {kind}: {_one_line(e)}; rerun with LOWERLIMB_DEBUG=1 for the traceback "
            f"and report it",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


def _in_main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def _one_line(e: BaseException) -> str:
    text = str(e) or type(e).__name__
    return " ".join(text.split())


def _format_warning(message: Warning | str, category: type[Warning], *_: object, **__: object) -> str:
    return f"lowerlimb: warning: {message}\n"
