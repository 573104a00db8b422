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
