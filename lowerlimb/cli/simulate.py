"""``lowerlimb simulate``: a four-IMU leg trial with known truth."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from lowerlimb.cli._common import EXIT_OK, add_side, positive_float
from lowerlimb.errors import InputError


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``simulate`` and its options."""
    from lowerlimb.simulation import MOTIONS

    p = subparsers.add_parser("simulate", help="simulate a four-IMU leg trial with known truth")
    p.add_argument("--motion", choices=MOTIONS, default="walk", help="motion to simulate (default: walk)")
    p.add_argument("--duration", type=positive_float, default=60.0, help="trial length, s (default: 60)")
    p.add_argument(
        "--seed",
        type=int,
        default=0,
        help="random seed for placements, motion and noise (default: 0)",
    )
    p.add_argument("--out", required=True, type=Path, help="trial CSV to write")
    p.add_argument(
        "--truth",
        type=Path,
        help="truth JSON to write (calibration.json schema); true angles and positions go "
        "beside it as <stem>_angles.csv (deg) and <stem>_positions.csv (m)",
    )
    add_side(p)
    p.add_argument("--rate", type=positive_float, default=100.0, help="sampling rate, Hz (default: 100)")
    p.add_argument(
        "--noise",
        choices=("realistic", "none"),
        default="realistic",
        help="realistic: gyro 0.015 rad/s, acc 0.08 m/s², gyro bias 0.01 rad/s; none: ideal",
    )
    p.add_argument("--soft-tissue", action="store_true", help="let sensors slide with joint angles")
    p.add_argument(
        "--artefacts",
        choices=("none", "real"),
        default="none",
        help="real: heel-strike impacts, wobbling tissue, skin motion, clock/scale errors (default: none)",
    )
    p.add_argument("--no-mag", action="store_true", help="omit magnetometer columns")


def run(args: argparse.Namespace) -> int:
    """Simulate and write the trial CSV (and the truth files)."""
    from lowerlimb.io.atomic import write_atomically, write_text
    from lowerlimb.io.tables import write_angles_csv, write_positions_csv
    from lowerlimb.simulation import Artefacts, ImuNoise, simulate

    noise = ImuNoise() if args.noise == "realistic" else ImuNoise.none()
    sim = simulate(
        args.motion,
        args.duration,
        args.seed,
        side=args.side,
        rate_hz=args.rate,
        noise=noise,
        soft_tissue=args.soft_tissue,
        with_mag=not args.no_mag,
        artefacts=Artefacts.real_walk() if args.artefacts == "real" else None,
    )
    for target in [args.out] + ([args.truth] if args.truth else []):
        parent = Path(target).parent
        if str(parent) and not parent.is_dir():
            raise InputError(f"directory {parent} does not exist; create it or choose another path")
    write_atomically(args.out, sim.trial.to_csv)
    if args.truth:
        truth = Path(args.truth)
        write_atomically(truth, lambda p: write_text(p, json.dumps(sim.truth, indent=2)))
        stem = truth.with_suffix("")
        write_atomically(
            Path(f"{stem}_angles.csv"),
            lambda p: write_angles_csv(p, sim.trial.time_s, sim.angles_rad),
        )
        write_atomically(
            Path(f"{stem}_positions.csv"),
            lambda p: write_positions_csv(p, sim.trial.time_s, sim.positions_m),
        )
    print(
        f"wrote {args.out} ({sim.trial.n_samples} samples at {args.rate:g} Hz, {args.motion}, "
        f"{args.side} leg){' and ' + str(args.truth) if args.truth else ''}"
    )
    return EXIT_OK
