"""``lowerlimb calibrate``: sensor positions, knee axis, angles, positions, URDF and report of a trial."""

from __future__ import annotations

import argparse
from pathlib import Path

from lowerlimb.cli._common import EXIT_OK, add_outputs, add_side, chosen_outputs, positive_float
from lowerlimb.errors import InputError
from lowerlimb.export.formats import EXPORT_FORMATS
from lowerlimb.methods import CALIBRATION_METHODS, CENTRE_FORMS, ORIENTATION_FILTERS
from lowerlimb.side_by_side import set_enabled


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
    p.set_defaults(side=None)  # "not given": a two-leg trial refuses --side; one leg defaults to left
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
        help="do not refuse a trial whose thigh/shank or shank/foot columns look swapped "
        "(with two legs, also a segment's left_* and right_* columns)",
    )
    p.add_argument(
        "--no-sign-check",
        action="store_true",
        help="do not refuse a trial in which a sensor turns about the vertical against its "
        "neighbours (the sign of its accelerometer or gyro inverted)",
    )
    p.add_argument(
        "--one-core",
        action="store_true",
        help="work in this process alone: by default, where the machine has two cores, the right leg "
        "of a two-leg trial and one of the report's figures are computed in a second process beside "
        "this one (the results are the same)",
    )
    p.add_argument(
        "--no-clock-sync",
        action="store_true",
        help="do not estimate the sensors' clock offsets from the joints (by default, offsets that "
        "explain the joints' mismatch are removed before calibrating and recorded in calibration.json)",
    )
    p.add_argument(
        "--centre-form",
        choices=CENTRE_FORMS,
        default="norm",
        help="the joint constraint that decides the hip and knee centres: 'norm' (default, Hu et al. "
        "2021 eq. 3) or 'aligned' (the 3-D constraint in gyro-aligned frames; unbiased by the low-pass "
        "on the simulator, mixed on a real walk: docs/limits.md)",
    )
    p.add_argument(
        "--hip-in-pelvis-form",
        choices=CENTRE_FORMS,
        default="aligned",
        help="the constraint that decides the hip centre in the pelvis sensor when --centre-form is "
        "'norm': 'aligned' (default; the pelvis barely turns and the norm form misplaces it by "
        "centimetres to decimetres) or 'norm' (the form of the other centres)",
    )
    p.add_argument(
        "--thigh-twist",
        action="store_true",
        help="undo each thigh sensor's turn about the femur with hip flexion, found where the knee axes "
        "from the thigh and the shank sensor disagree at standing (recorded in calibration.json; exact "
        "on the simulator, on a real walk better knee angles but longer thighs: docs/limits.md)",
    )
    p.add_argument(
        "--export",
        action="append",
        choices=tuple(EXPORT_FORMATS),
        default=[],
        help="also write: "
        + "; ".join(f"{k}: {v}" for k, v in EXPORT_FORMATS.items())
        + " (repeat for several)",
    )
    p.add_argument(
        "--causal",
        action="store_true",
        help="run each orientation filter forward in time only, as in real time (default: forward "
        "and backward, the inclination from both passes: an offline estimate without the filter's lag)",
    )
    p.add_argument(
        "--reference",
        type=Path,
        metavar="REFERENCE.csv",
        help="reference CSV ('time' in s and columns named as in angles.csv (deg) / positions.csv (m)); "
        "adds its agreement (RMSE, bias, limits of agreement, r, CMC, Bland-Altman plots) to report.html",
    )
    add_outputs(p)


def run(args: argparse.Namespace) -> int:
    """Build :class:`~lowerlimb.outputs.CalibrateOptions` from the arguments and run it."""
    from lowerlimb.outputs import CalibrateOptions, run_calibrate

    two_legs, prefixed = _layout(args.trial, args.side)
    if two_legs and args.side is not None:
        raise InputError(
            f"{args.trial} is a two-leg trial (pelvis, left_*, right_* sensors): both legs are "
            f"calibrated, so --side {args.side} does not apply; drop --side (or import one leg "
            f"as a four-sensor trial)"
        )
    options = CalibrateOptions(
        trial=args.trial,
        out=args.out,
        side=args.side or prefixed or "left",
        method=args.method,
        filter_name=args.filter,
        height_m=args.height,
        mass_kg=args.mass,
        use_mag=not args.no_mag,
        calibration=args.calibration,
        s2j=args.s2j,
        side_check=not args.no_side_check,
        order_check=not args.no_order_check,
        sign_check=not args.no_sign_check,
        clock_sync=not args.no_clock_sync,
        centre_form=args.centre_form,
        hip_in_pelvis_form=args.hip_in_pelvis_form,
        thigh_twist=args.thigh_twist,
        exports=tuple(args.export),
        reference=args.reference,
        outputs=chosen_outputs(args),
        smooth_orientation=not args.causal,
        parallel_legs=not args.one_core,
    )
    if args.one_core:
        set_enabled(False)  # the report's figures too
    if two_legs:
        from lowerlimb.outputs_bilateral import run_calibrate_bilateral

        run_calibrate_bilateral(options)
    else:
        run_calibrate(options)
    return EXIT_OK


def _layout(path: Path, side: str | None) -> tuple[bool, str | None]:
    """Whether the trial is a two-leg one, and the side a one-leg header's prefixed names give.

    Two legs: the header names the seven two-leg sensors (docs/formats.md, "Two legs"). The
    side: ``None`` unless the header names one side's ``left_*`` or ``right_*`` sensors only.
    An unreadable or empty file is left to the single-leg path, which reports it.

    Raises:
        InputError: the header mixes single-leg and two-leg sensor names, or names one side
            and ``side`` is the other.
    """
    from lowerlimb.io.bilateral_trial import read_header, trial_layout
    from lowerlimb.io.trial import leg_side

    try:
        header = read_header(path)
    except (OSError, ValueError):  # InputError and UnicodeDecodeError are ValueErrors
        return False, None
    if trial_layout(header) == "two_legs":
        return True, None
    return False, leg_side(header, side, str(path))
