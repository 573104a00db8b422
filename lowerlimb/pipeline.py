"""``lowerlimb calibrate``: trial → calibration → angles, positions, URDF, report."""

from __future__ import annotations

import argparse

from .errors import LowerLimbError
from .trial import ImuTrial


def run_calibrate(args: argparse.Namespace) -> None:
    """Run the whole pipeline on ``args.trial`` and write ``args.out`` (see DESIGN.md)."""
    ImuTrial.from_csv(args.trial, side=args.side)
    raise LowerLimbError("calibration is not wired into the command line yet")
