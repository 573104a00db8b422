"""What every command module shares: the one-line usage error, the parser class and argument types."""

from __future__ import annotations

import argparse
from typing import NoReturn

from lowerlimb.errors import InputError

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2


class UsageError(InputError):
    """A command-line mistake (unknown option, bad value)."""


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit status 2."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{message}; see '{self.prog} --help'")


def positive_float(text: str) -> float:
    """An argparse type: a number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} must be positive")
    return value


def add_side(parser: argparse.ArgumentParser) -> None:
    """``--side left|right`` (default left)."""
    parser.add_argument(
        "--side", choices=("left", "right"), default="left", help="instrumented leg (default: left)"
    )


#: Short names of the files of a result folder (``lowerlimb.outputs.OUTPUT_FILES``, kept
#: here too so that ``--help`` imports no computing module; a test checks they agree).
OUTPUT_NAMES: tuple[str, ...] = ("calibration", "angles", "positions", "s2j", "urdf", "report")


def add_outputs(parser: argparse.ArgumentParser) -> None:
    """``--outputs NAME,NAME…`` and ``--no-report``: which files of the result folder to write."""
    parser.add_argument(
        "--outputs",
        type=lambda text: tuple(n.strip() for n in text.split(",") if n.strip()),
        default=OUTPUT_NAMES,
        metavar="NAME,…",
        help=f"files to write, comma-separated among {','.join(OUTPUT_NAMES)} (default: all)",
    )
    parser.add_argument("--no-report", action="store_true", help="do not write report.html (faster)")


def chosen_outputs(args: argparse.Namespace) -> frozenset[str]:
    """The output names chosen by :func:`add_outputs`' arguments (unchecked)."""
    names = set(args.outputs)
    if args.no_report:
        if names == {"report"}:
            raise InputError("--outputs report and --no-report leave nothing to write; drop one of them")
        names.discard("report")
    return frozenset(names)
