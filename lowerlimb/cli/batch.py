"""``lowerlimb batch``: every trial of a study, on a local process pool or a Dask cluster."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from lowerlimb.cli._common import EXIT_INTERNAL, EXIT_OK, add_outputs, chosen_outputs
from lowerlimb.methods import CALIBRATION_METHODS, CENTRE_FORMS, ORIENTATION_FILTERS


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``batch`` (docs/formats.md, "Many trials")."""
    p = subparsers.add_parser(
        "batch",
        help="process a study: every trial of a manifest or folder, one output folder each",
        description="Calibrate every trial of a manifest CSV (columns trial, side, subject, task, "
        "height_m, mass_kg, calibration) or of a folder of trial CSVs. Writes one folder per "
        "trial, batch.csv (status ok/warning/failed, reason, wall time, key results) and the "
        "per-subject and per-task summaries. A re-run skips the trials already done. Exit "
        "status 0 when every trial ran, 1 when some failed, 2 for a bad manifest.",
    )
    p.add_argument("source", type=Path, metavar="MANIFEST.csv|DIR", help="manifest CSV or folder of trials")
    p.add_argument("--out", required=True, type=Path, help="output folder of the study (created)")
    p.add_argument("--workers", type=_positive_int, help="local worker processes (default: one per core)")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask cluster (tcp://host:8786) instead of local processes; "
        "needs pip install 'lowerlimb[cluster]' and folders shared by every worker",
    )
    p.add_argument("--force", action="store_true", help="redo the trials already done")
    p.add_argument("--quiet", action="store_true", help="no progress bar or per-trial lines")
    p.add_argument(
        "--method", choices=tuple(CALIBRATION_METHODS), default="casadi", help="joint-constraint solver"
    )
    p.add_argument(
        "--filter", choices=tuple(ORIENTATION_FILTERS), default="mahony", help="orientation filter"
    )
    p.add_argument("--no-mag", action="store_true", help="ignore magnetometer columns (6-axis fusion)")
    p.add_argument(
        "--centre-form",
        choices=CENTRE_FORMS,
        default="norm",
        help="the joint constraint that decides the hip and knee centres (as calibrate --centre-form)",
    )
    p.add_argument(
        "--hip-in-pelvis-form",
        choices=CENTRE_FORMS,
        default="aligned",
        help="the constraint that places the hip centre in the pelvis sensor (as calibrate "
        "--hip-in-pelvis-form)",
    )
    p.add_argument(
        "--thigh-twist",
        action="store_true",
        help="undo each thigh sensor's turn about the femur with hip flexion (as calibrate --thigh-twist)",
    )
    p.add_argument(
        "--causal", action="store_true", help="orientation filters forward only (as calibrate --causal)"
    )
    for flag, what in (
        ("--no-side-check", "a hip on the other side of the pelvis sensor"),
        ("--no-order-check", "sensor columns that look swapped"),
        ("--no-sign-check", "a sensor whose sign looks inverted"),
    ):
        p.add_argument(
            flag, action="store_true", help=f"do not refuse trials for {what} (as calibrate {flag})"
        )
    add_outputs(p)


def run(args: argparse.Namespace) -> int:
    """Run the study; exit status 0 when every trial ran, 1 when some failed (2: raised bad input)."""
    from lowerlimb.batch import BatchParams, run_study

    params = BatchParams(
        method=args.method,
        filter_name=args.filter,
        use_mag=not args.no_mag,
        centre_form=args.centre_form,
        hip_in_pelvis_form=args.hip_in_pelvis_form,
        thigh_twist=args.thigh_twist,
        side_check=not args.no_side_check,
        order_check=not args.no_order_check,
        sign_check=not args.no_sign_check,
        smooth_orientation=not args.causal,
        outputs=chosen_outputs(args),
        workers=args.workers,
        force=args.force,
    )
    result = run_study(args.source, args.out, params, scheduler=args.scheduler, quiet=args.quiet)
    failed = result.failed
    n = len(result.outcomes)
    up_to_date = sum(1 for o in result.outcomes if o.skipped)
    unread = n - result.processed - up_to_date  # failed before running (a missing file)
    print(
        f"lowerlimb batch: {n - len(failed)} of {n} trials done ({result.processed} processed now, "
        f"{up_to_date} up to date{f', {unread} unreadable' if unread else ''}), {len(failed)} failed, "
        f"{result.wall_s:.1f} s; wrote {result.out / 'batch.csv'}",
        file=sys.stderr,
    )
    for o in failed:
        print(f"  failed: {o.trial}: {o.reason}", file=sys.stderr)
    return EXIT_INTERNAL if failed else EXIT_OK


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text} must be at least 1")
    return value
