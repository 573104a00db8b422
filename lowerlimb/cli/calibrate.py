"""``lowerlimb calibrate``: sensor positions, knee axis, angles, positions, URDF and report of a trial."""

from __future__ import annotations

import argparse
from pathlib import Path

from lowerlimb.cli._common import EXIT_OK, add_outputs, add_side, chosen_outputs, positive_float
from lowerlimb.methods import CALIBRATION_METHODS, ORIENTATION_FILTERS


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``calibrate``; its method and filter choices come from :mod:`lowerlimb.methods`."""
    p = subparsers.add_parser(
        "calibrate", help="calibrate a trial: sensor positions, knee axis, angles, URDF"
    )
    p.add_argument("trial", type=Path, metavar="TRIAL.csv", help="trial CSV (docs/formats.md)")
    p.add_argument(
        "--out",
        required=True,
        type=Path,
        help="output directory (created; must not hold a calibration)",
    )
    add_side(p)
    p.add_argument(
        "--method",
        choices=tuple(CALIBRATION_METHODS),
        default="casadi",
        help="joint-constraint solver (default: casadi)",
    )
    p.add_argument(
        "--filter",
        choices=tuple(ORIENTATION_FILTERS),
        default="mahony",
        help="orientation filter (default: mahony)",
    )
    p.add_argument("--height", type=positive_float, default=1.75, help="subject height, m (default: 1.75)")
    p.add_argument("--mass", type=positive_float, default=75.0, help="subject mass, kg (default: 75)")
    p.add_argument("--no-mag", action="store_true", help="ignore magnetometer columns (6-axis fusion)")
    p.add_argument(
        "--calibration",
        type=Path,
        metavar="CALIBRATION.json",
        help="reuse the joint calibration of an earlier trial with the same sensor placements "
        "(calibrate a walk or the 'mixed' motion once, then squats, knee lifts…) instead of "
        "calibrating this trial",
    )
    p.add_argument(
        "--s2j",
        type=Path,
        metavar="S2J.json",
        help="fitted time-varying segment-to-joint model (Lee & Lee 2022 M2/M3) for these sensor "
        "placements; default: constant vectors from this calibration",
    )
    p.add_argument(
        "--no-side-check",
        action="store_true",
        help="do not refuse a trial whose calibrated hip lies on the other side of the pelvis sensor "
        "(for a pelvis sensor that is not on the sacrum)",
    )
    p.add_argument(
        "--no-order-check",
        action="store_true",
        help="do not refuse a trial whose thigh/shank or shank/foot columns look swapped",
    )
    add_outputs(p)


def run(args: argparse.Namespace) -> int:
    """Build :class:`~lowerlimb.outputs.CalibrateOptions` from the arguments and run it."""
    from lowerlimb.outputs import CalibrateOptions, run_calibrate

    run_calibrate(
        CalibrateOptions(
            trial=args.trial,
            out=args.out,
            side=args.side,
            method=args.method,
            filter_name=args.filter,
            height_m=args.height,
            mass_kg=args.mass,
            use_mag=not args.no_mag,
            calibration=args.calibration,
            s2j=args.s2j,
            side_check=not args.no_side_check,
            order_check=not args.no_order_check,
            outputs=chosen_outputs(args),
        )
    )
    return EXIT_OK
