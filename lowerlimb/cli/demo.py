"""``lowerlimb demo``: simulate a walk, calibrate it and report against the truth."""

from __future__ import annotations

import argparse
from pathlib import Path

from lowerlimb.cli._common import EXIT_OK, positive_float


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``demo`` and its options."""
    p = subparsers.add_parser("demo", help="simulate a walk, calibrate it and report against the truth")
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output directory (default: a fresh ./lowerlimb_demo, ./lowerlimb_demo_2, …)",
    )
    p.add_argument("--duration", type=positive_float, default=30.0, help="walk length, s (default: 30)")
    p.add_argument("--seed", type=int, default=1, help="random seed (default: 1)")


def run(args: argparse.Namespace) -> int:
    """Build :class:`~lowerlimb.demo.DemoOptions` from the arguments and run the demo."""
    from lowerlimb.demo import DemoOptions, run_demo

    run_demo(DemoOptions(out=args.out, duration_s=args.duration, seed=args.seed))
    return EXIT_OK
