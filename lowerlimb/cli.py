"""The ``lowerlimb`` command line (DESIGN.md: simulate, calibrate, demo, view).

Exit status: 0 success, 2 bad input (one line on stderr naming the problem and
the fix, no traceback, no partial output), 1 internal error (one line; set
``LOWERLIMB_DEBUG=1`` for the traceback), 130 interrupted.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NoReturn

from . import __version__
from .errors import InputError, LowerLimbError

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2


class UsageError(InputError):
    """A command-line mistake (unknown option, bad value)."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit status 2."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{message}; see '{self.prog} --help'")


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} must be positive")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command."""
    from .simulation import MOTIONS

    parser = _Parser(prog="lowerlimb", description="Wearable IMU motion capture of the human leg.")
    parser.add_argument("--version", action="version", version=f"lowerlimb {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("simulate", help="simulate a four-IMU leg trial with known truth")
    p.add_argument("--motion", choices=MOTIONS, default="walk", help="motion to simulate (default: walk)")
    p.add_argument("--duration", type=_positive_float, default=60.0, help="trial length, s (default: 60)")
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
    p.add_argument(
        "--side", choices=("left", "right"), default="left", help="instrumented leg (default: left)"
    )
    p.add_argument("--rate", type=_positive_float, default=100.0, help="sampling rate, Hz (default: 100)")
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

    p = sub.add_parser("calibrate", help="calibrate a trial: sensor positions, knee axis, angles, URDF")
    p.add_argument("trial", type=Path, metavar="TRIAL.csv", help="trial CSV (DESIGN.md format)")
    p.add_argument(
        "--out",
        required=True,
        type=Path,
        help="output directory (created; must not hold a calibration)",
    )
    p.add_argument(
        "--side", choices=("left", "right"), default="left", help="instrumented leg (default: left)"
    )
    p.add_argument(
        "--method",
        choices=("casadi", "gn", "dwpso", "gwo"),
        default="casadi",
        help="joint-constraint solver (default: casadi)",
    )
    p.add_argument(
        "--filter",
        choices=("mahony", "ftecf", "madgwick"),
        default="mahony",
        help="orientation filter (default: mahony)",
    )
    p.add_argument("--height", type=_positive_float, default=1.75, help="subject height, m (default: 1.75)")
    p.add_argument("--mass", type=_positive_float, default=75.0, help="subject mass, kg (default: 75)")
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

    p = sub.add_parser("demo", help="simulate a walk, calibrate it and report against the truth")
    p.add_argument(
        "--out",
        type=Path,
        default=Path("lowerlimb_demo"),
        help="output directory (default: ./lowerlimb_demo)",
    )
    p.add_argument("--duration", type=_positive_float, default=30.0, help="walk length, s (default: 30)")
    p.add_argument("--seed", type=int, default=1, help="random seed (default: 1)")

    p = sub.add_parser("view", help="meshcat animation of a calibrated trial")
    p.add_argument("dir", type=Path, metavar="DIR", help="output directory of 'lowerlimb calibrate'")
    p.add_argument("--open", action="store_true", help="also open the view in a web browser")
    return parser


# ---------------------------------------------------------------- atomic outputs


def write_atomically(path: Path, write: Callable[[Path], None]) -> None:
    """Write a file through a temporary sibling, then rename: no half-written file on failure."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"directory {parent} does not exist; create it or choose another --out")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def populate_directory(out: Path, fill: Callable[[Path], None]) -> None:
    """Create ``out`` with everything ``fill`` writes into a staging directory, or nothing at all."""
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise InputError(f"{out} already exists and is not empty; choose a new --out directory")
    parent = out.resolve().parent
    if not parent.is_dir():
        raise InputError(f"directory {parent} does not exist; create it or choose another --out")
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=parent))
    try:
        fill(staging)
        if out.exists():
            out.rmdir()
        os.replace(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


# ---------------------------------------------------------------- commands


def cmd_simulate(args: argparse.Namespace) -> int:
    """``lowerlimb simulate``."""
    from .output import write_angles_csv, write_positions_csv
    from .simulation import Artefacts, ImuNoise, simulate

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
        write_atomically(truth, lambda p: _write_text(p, json.dumps(sim.truth, indent=2)))
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


def cmd_calibrate(args: argparse.Namespace) -> int:
    """``lowerlimb calibrate``."""
    from .pipeline import run_calibrate

    run_calibrate(args)
    return EXIT_OK


def cmd_demo(args: argparse.Namespace) -> int:
    """``lowerlimb demo``."""
    from .demo import run_demo

    run_demo(args)
    return EXIT_OK


def cmd_view(args: argparse.Namespace) -> int:
    """``lowerlimb view``."""
    from .view import run_view

    run_view(args)
    return EXIT_OK


COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "simulate": cmd_simulate,
    "calibrate": cmd_calibrate,
    "demo": cmd_demo,
    "view": cmd_view,
}


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``lowerlimb`` console script; returns the exit status."""
    # The work is many small matrix products: BLAS threads only fight over the
    # cores (measured up to 20x slower on 2 cores). Set before numpy loads.
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    try:
        args = build_parser().parse_args(argv)
        if args.command is None:
            raise UsageError(
                "no command given; choose simulate, calibrate, demo or view (see 'lowerlimb --help')"
            )
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            # third-party deprecation notices (pyzmq via meshcat…) are not the user's business
            warnings.filterwarnings("ignore", category=DeprecationWarning)
            warnings.filterwarnings("ignore", category=PendingDeprecationWarning)
            warnings.filterwarnings("ignore", category=FutureWarning)
            warnings.formatwarning = _format_warning  # type: ignore[assignment]
            return COMMANDS[args.command](args)
    except (InputError, FileNotFoundError, IsADirectoryError, PermissionError) as e:
        print(f"lowerlimb: error: {_one_line(e)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("lowerlimb: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # a bug or a solver failure, not the user's input
        if os.environ.get("LOWERLIMB_DEBUG"):
            raise
        kind = "internal error" if isinstance(e, LowerLimbError) else f"internal error ({type(e).__name__})"
        print(
            f"lowerlimb: {kind}: {_one_line(e)}; rerun with LOWERLIMB_DEBUG=1 for the traceback "
            f"and report it",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


def _write_text(path: Path, text: str) -> None:
    path.write_text(text, encoding="utf-8")


def _one_line(e: BaseException) -> str:
    text = str(e) or type(e).__name__
    return " ".join(text.split())


def _format_warning(message: Warning | str, category: type[Warning], *_: object, **__: object) -> str:
    return f"lowerlimb: warning: {message}\n"


if __name__ == "__main__":
    sys.exit(main())
