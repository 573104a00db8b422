"""``lowerlimb view``: meshcat animation of a calibrated trial."""

from __future__ import annotations

import argparse
from pathlib import Path

from lowerlimb.cli._common import EXIT_OK


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``view`` and its options."""
    p = subparsers.add_parser("view", help="meshcat animation of a calibrated trial")
    p.add_argument("dir", type=Path, metavar="DIR", help="output directory of 'lowerlimb calibrate'")
    p.add_argument("--open", action="store_true", help="also open the view in a web browser")
    p.add_argument(
        "--side",
        choices=("left", "right"),
        default=None,
        help="the leg to show of a two-leg result (default: left)",
    )
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to serve on (default: 127.0.0.1, this computer only; 0.0.0.0 shows the "
        "subject's data to the whole network)",
    )


def run(args: argparse.Namespace) -> int:
    """Serve the animated leg until Ctrl-C or SIGTERM."""
    from lowerlimb.viz.view import run_view

    run_view(args.dir, open_browser=args.open, host=args.host, side=args.side)
    return EXIT_OK
