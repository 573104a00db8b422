"""``lowerlimb simulate``: a four-IMU leg trial with known truth."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from pathlib import Path

from lowerlimb.cli._common import EXIT_OK, positive_float
from lowerlimb.errors import InputError


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``simulate`` and its options."""
    from lowerlimb.simulation import MOTIONS

    p = subparsers.add_parser(
        "simulate", help="simulate a four-IMU leg trial (or a seven-IMU walk, --side both) with known truth"
    )
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
        "beside it as <stem>_angles.csv (deg) and <stem>_positions.csv (m); with --side both also "
        "<stem>_events.csv and <stem>_gait.json",
    )
    p.add_argument(
        "--side",
        choices=("left", "right", "both"),
        default="left",
        help="instrumented leg; both: a seven-IMU walk (pelvis and both legs, opposite phase, "
        "feet still on the ground in stance) (default: left)",
    )
    p.add_argument("--rate", type=positive_float, default=100.0, help="sampling rate, Hz (default: 100)")
    p.add_argument(
        "--noise",
        choices=("realistic", "none"),
        default="realistic",
        help="realistic: gyro 0.015 rad/s, acc 0.08 m/s², gyro bias 0.01 rad/s; none: ideal",
    )
    p.add_argument(
        "--soft-tissue",
        action="store_true",
        help="let sensors slide with joint angles (one leg only; not with --side both)",
    )
    p.add_argument(
        "--artefacts",
        choices=("none", "real"),
        default="none",
        help="real: heel-strike impacts, wobbling tissue, skin motion, clock/scale errors; "
        "also with --side both (all seven sensors) (default: none)",
    )
    p.add_argument("--no-mag", action="store_true", help="omit magnetometer columns")
    p.add_argument(
        "--uniform-field",
        action="store_true",
        help="with --side both: one uniform magnetic field instead of a lab's, whose field varies "
        "near the floor as real labs' do (the one-leg simulator's field is always uniform)",
    )
    p.add_argument(
        "--pace-changes",
        action="store_true",
        help="with --side both: the walker speeds up and slows down (step length ±15-25 %%) and "
        "changes step width (±20-40 %%) over 1.5-3 minutes, at constant cadence",
    )
    p.add_argument(
        "--pace",
        choices=("normal", "slow", "shuffle"),
        default="normal",
        help="with --side both: normal (1.0-1.3 m/s), slow (0.55-0.85 m/s, longer stance: "
        "older adults, many clinical studies) or shuffle (0.4-0.7 m/s, short strides, flat "
        "foot contact and a weak push-off, as in Parkinson's disease) (default: normal)",
    )
    p.add_argument(
        "--stops",
        type=int,
        default=0,
        help="with --side both: the walker stops this many times, spread over the walk, and stands "
        "still in double support before walking on, as between the passes of a clinical walk "
        "(default: 0)",
    )
    p.add_argument(
        "--stop-s",
        type=positive_float,
        default=None,
        help="with --stops: each stop's standing time, s (default: 3)",
    )
    p.add_argument(
        "--treadmill",
        action="store_true",
        help="with --side both: walk straight on a treadmill whose belt carries the walker back to "
        "one spot of the lab (the sensors' lab-frame signals while the belt starts, the lab's field "
        "where they are in the lab and the drive motor's; stride length and speed relative to the belt)",
    )
    p.add_argument(
        "--turns",
        action="store_true",
        help="with --side both: walk straight passes of 6 s with a 180° turn about between them, as "
        "on a gait lab's walkway (each stance foot pivoting on the floor while flat)",
    )
    p.add_argument(
        "--force", action="store_true", help="replace existing files (default: refuse to overwrite)"
    )


def check_arguments(args: argparse.Namespace) -> dict[str, Path]:
    """Check every argument before simulating; return the files to write, named by option.

    Raises:
        InputError: an out-of-range duration, rate or seed, two targets naming the
            same file, a missing or read-only folder, or an existing file without ``--force``.
    """
    from lowerlimb.io.atomic import check_new_files
    from lowerlimb.io.bounds import INPUT_BOUNDS, check_range

    b = INPUT_BOUNDS
    check_range("--duration", args.duration, b.duration_s, "s", "the trial length")
    check_range("--rate", args.rate, b.rate_hz, "Hz", "the sampling rate")
    if args.duration * args.rate > b.max_samples:
        raise InputError(
            f"--duration {args.duration:g} s at --rate {args.rate:g} Hz makes "
            f"{args.duration * args.rate:.3g} samples, more than {b.max_samples}; shorten the trial"
        )
    if not 0 <= args.seed <= b.max_seed:
        raise InputError(f"--seed {args.seed} is out of range; give an integer from 0 to {b.max_seed}")
    _check_two_leg_options(args)
    targets = {"--out": Path(args.out)}
    if args.truth:
        truth = Path(args.truth)
        stem = truth.with_suffix("")
        targets["--truth"] = truth
        targets["--truth (its angles)"] = Path(f"{stem}_angles.csv")
        targets["--truth (its positions)"] = Path(f"{stem}_positions.csv")
        if args.side == "both":
            targets["--truth (its events)"] = Path(f"{stem}_events.csv")
            targets["--truth (its gait)"] = Path(f"{stem}_gait.json")
    check_new_files(targets, overwrite=args.force)
    return targets


def _check_two_leg_options(args: argparse.Namespace) -> None:
    """Refuse options the seven-IMU walk does not simulate.

    Raises:
        InputError: ``--side both`` with another motion, soft tissue, or too short;
            ``--pace-changes``, ``--pace``, ``--stops``, ``--treadmill`` or ``--turns``
            without ``--side both``; more stops than one per 10 s; stops on a treadmill;
            turns with stops or on a treadmill.
    """
    if args.stop_s is not None and not args.stops:
        raise InputError(
            f"--stop-s {args.stop_s:g} is the length of each --stops stop; add --stops N or drop it"
        )
    if args.stop_s is not None and not math.isfinite(args.stop_s):
        raise InputError(
            f"--stop-s {args.stop_s:g} is not a finite time; give each stop's length in s, e.g. 3"
        )
    if args.side != "both":
        two_leg_only = (
            ("--pace-changes", args.pace_changes),
            (f"--pace {args.pace}", args.pace != "normal"),
            (f"--stops {args.stops}", args.stops != 0),
            ("--treadmill", args.treadmill),
            ("--turns", args.turns),
        )
        for flag, used in two_leg_only:
            if used:
                raise InputError(f"{flag} is a seven-IMU walk option; add --side both or drop it")
        return
    if args.motion != "walk":
        raise InputError(
            f"--side both simulates walking only, not --motion {args.motion}; "
            "drop --motion or use --side left"
        )
    if args.soft_tissue:
        raise InputError(
            "--side both does not simulate --soft-tissue; use --artefacts real for non-rigid "
            "sensors on both legs, or simulate one leg (--side left)"
        )
    if args.duration < 6.0:
        raise InputError(f"--side both needs at least 6 s of walk, not --duration {args.duration:g}")
    if not 0 <= args.stops <= args.duration / 10.0:
        raise InputError(
            f"--stops {args.stops} is out of range for a {args.duration:g} s walk; give 0 to "
            f"{int(args.duration / 10.0)} (one stop per 10 s of walk at most)"
        )
    if args.treadmill and args.stops:
        raise InputError("--treadmill walks have no --stops; drop one of them")
    if args.stops:
        from lowerlimb.simulation.bilateral_walk import STILL_S
        from lowerlimb.simulation.pauses import PauseParams

        stops = PauseParams(count=args.stops, pause_s=stop_s(args))
        longest = stops.longest_pause_s(args.duration, STILL_S)
        if stops.pause_s > longest:
            fits = f"give --stop-s at most {longest:.3g}, or " if longest > 0 else "give "
            raise InputError(
                f"--stops {args.stops} of --stop-s {stops.pause_s:g} do not fit in "
                f"--duration {args.duration:g} "
                f"(the walker must walk {stops.min_walk_after_s:g} s after the last stop); {fits}--duration "
                f"{math.ceil(stops.needed_duration_s(STILL_S))} or more"
            )
    if args.turns and (args.treadmill or args.stops):
        raise InputError("--turns walks have no --stops and no --treadmill; drop one of them")


def stop_s(args: argparse.Namespace) -> float:
    """Each stop's standing time, s: ``--stop-s``, or :class:`PauseParams`' default when not given."""
    from lowerlimb.simulation.pauses import PauseParams

    return float(PauseParams().pause_s if args.stop_s is None else args.stop_s)


def _run_two_legs(args: argparse.Namespace, targets: dict[str, Path]) -> None:
    """Simulate the seven-IMU walk and write the trial and truth files, all or none."""
    from lowerlimb.io.atomic import write_files_atomically, write_text
    from lowerlimb.io.bilateral_tables import write_bilateral_angles_csv, write_bilateral_positions_csv
    from lowerlimb.simulation import Artefacts, ImuNoise, simulate_bilateral
    from lowerlimb.simulation.magnetic_field import LAB_FIELD
    from lowerlimb.simulation.pauses import PauseParams
    from lowerlimb.simulation.treadmill import TreadmillParams
    from lowerlimb.simulation.turns import TurnParams

    noise = ImuNoise() if args.noise == "realistic" else ImuNoise.none()
    sim = simulate_bilateral(
        args.duration,
        args.seed,
        rate_hz=args.rate,
        noise=noise,
        with_mag=not args.no_mag,
        artefacts=Artefacts.real_walk() if args.artefacts == "real" else None,
        lab_field=None if args.uniform_field else LAB_FIELD,
        pace_changes=args.pace_changes,
        pace=args.pace,
        stops=PauseParams(count=args.stops, pause_s=stop_s(args)) if args.stops else None,
        treadmill=TreadmillParams() if args.treadmill else None,
        turns=TurnParams() if args.turns else None,
    )
    t = sim.trial.time_s
    writers: dict[Path, Callable[[Path], None]] = {targets["--out"]: sim.trial.to_csv}
    if args.truth:
        rows = sorted(
            (float(x), side, name)
            for side, foot in sim.feet.items()
            for name, times in (
                ("initial_contact", foot.events.initial_contact_s),
                ("toe_off", foot.events.toe_off_s),
            )
            for x in times
        )
        events = "time,side,event\n" + "".join(f"{x:.6f},{s},{n}\n" for x, s, n in rows)
        writers[targets["--truth"]] = lambda p: write_text(p, json.dumps(sim.truth, indent=2))
        writers[targets["--truth (its angles)"]] = lambda p: write_bilateral_angles_csv(p, t, sim.angles_rad)
        writers[targets["--truth (its positions)"]] = lambda p: write_bilateral_positions_csv(
            p, t, sim.positions_m
        )
        writers[targets["--truth (its events)"]] = lambda p: write_text(p, events)
        writers[targets["--truth (its gait)"]] = lambda p: write_text(
            p, json.dumps(sim.truth["gait"], indent=2)
        )
    write_files_atomically(writers, overwrite=args.force)
    print(
        f"wrote {args.out} ({sim.trial.n_samples} samples at {args.rate:g} Hz, walk, both legs"
        f"{', real-walk artefacts' if sim.artefacts is not None else ''}"
        f"{f', {args.stops} stops of {stop_s(args):g} s' if args.stops else ''}"
        f"{', on a treadmill' if args.treadmill else ''}"
        f"{', straight passes and turns about' if args.turns else ''})"
        f"{' and ' + str(args.truth) if args.truth else ''}"
    )


def run(args: argparse.Namespace) -> int:
    """Simulate and write the trial CSV (and the truth files), all or none, never overwriting unasked."""
    from lowerlimb.io.atomic import write_files_atomically, write_text
    from lowerlimb.io.interrupts import check_interrupted
    from lowerlimb.io.tables import write_angles_csv, write_positions_csv
    from lowerlimb.simulation import Artefacts, ImuNoise, simulate

    targets = check_arguments(args)
    check_interrupted()
    if args.side == "both":
        _run_two_legs(args, targets)
        return EXIT_OK
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
    writers: dict[Path, Callable[[Path], None]] = {targets["--out"]: sim.trial.to_csv}
    if args.truth:
        writers[targets["--truth"]] = lambda p: write_text(p, json.dumps(sim.truth, indent=2))
        writers[targets["--truth (its angles)"]] = lambda p: write_angles_csv(
            p, sim.trial.time_s, sim.angles_rad
        )
        writers[targets["--truth (its positions)"]] = lambda p: write_positions_csv(
            p, sim.trial.time_s, sim.positions_m
        )
    write_files_atomically(writers, overwrite=args.force)
    print(
        f"wrote {args.out} ({sim.trial.n_samples} samples at {args.rate:g} Hz, {args.motion}, "
        f"{args.side} leg){' and ' + str(args.truth) if args.truth else ''}"
    )
    return EXIT_OK
