"""``lowerlimb import xsens|csv``: vendor recordings → the trial CSV (docs/formats.md).

::

    lowerlimb import xsens DIR --map pelvis=ID,thigh=ID,shank=ID,foot=ID --side left --out trial.csv
                         [--mag-field-ut 50] [--max-gap 0.1] [--force]
    lowerlimb import csv FILE --mapping MAP.json --out trial.csv [--max-gap 0.1] [--force]

A two-leg map (``pelvis, left_thigh, …, right_foot``) writes the two-leg trial
CSV. The output is written atomically and never replaces an existing file
unless ``--force`` is given. Bad input raises :class:`InputError`, which
``lowerlimb.cli.main`` turns into one line on stderr and exit status 2.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from lowerlimb.errors import InputError


def _map_argument(text: str) -> dict[str, str]:
    """Parse ``pelvis=ID,thigh=ID,…`` into ``{segment: ID}``."""
    out: dict[str, str] = {}
    for item in filter(None, (p.strip() for p in text.split(","))):
        segment, sep, sensor_id = item.partition("=")
        if not sep or not segment.strip() or not sensor_id.strip():
            raise argparse.ArgumentTypeError(f"'{item}' is not SEGMENT=ID (e.g. pelvis=00B40B91)")
        if segment.strip() in out:
            raise argparse.ArgumentTypeError(f"segment '{segment.strip()}' is given twice")
        out[segment.strip()] = sensor_id.strip()
    return out


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} must be positive")
    return value


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add ``import`` (with ``xsens`` and ``csv``) to the ``lowerlimb`` sub-commands."""
    p = subparsers.add_parser("import", help="read vendor recordings (Xsens, mapped CSV) into a trial CSV")
    sub = p.add_subparsers(dest="vendor", metavar="FORMAT", parser_class=type(p), required=True)

    x = sub.add_parser("xsens", help="Xsens MT Manager text exports, one file per sensor")
    x.add_argument("directory", type=Path, metavar="DIR", help="folder of the exports (<name>_<ID>.txt)")
    x.add_argument(
        "--map",
        required=True,
        type=_map_argument,
        metavar="SEGMENT=ID,…",
        help="sensor ID of each segment: pelvis, thigh, shank, foot (one leg) or pelvis, "
        "left_thigh, left_shank, left_foot, right_thigh, right_shank, right_foot (two legs)",
    )
    x.add_argument(
        "--side", choices=("left", "right"), help="instrumented leg of a one-leg map (default: left)"
    )
    x.add_argument(
        "--mag-field-ut",
        type=_positive,
        default=None,
        metavar="UT",
        help="local magnetic field at the MT calibration, µT: Xsens Mag unit 1 = this (default: 50)",
    )

    c = sub.add_parser("csv", help="any per-column CSV, through a JSON mapping of columns and units")
    c.add_argument("file", type=Path, metavar="FILE", help="the vendor CSV")
    c.add_argument("--mapping", required=True, type=Path, metavar="MAP.json", help="column/unit mapping")
    for q in (x, c):
        q.add_argument(
            "--max-gap",
            type=_positive,
            default=None,
            metavar="S",
            help="longest run of missing samples filled by interpolation, s; a longer one is refused "
            "(default: lowerlimb.io.ImportParams.max_gap_s, 0.1)",
        )

    for q in (x, c):
        q.add_argument("--out", required=True, type=Path, help="trial CSV to write")
        q.add_argument("--force", action="store_true", help="replace --out if it exists")
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``lowerlimb import``; return the exit status (errors are raised as InputError)."""
    from lowerlimb.io import ImportedRecording, load_mapped_csv, load_xsens
    from lowerlimb.io.atomic import write_atomically
    from lowerlimb.io.params import XSENS_MAG_FIELD_UT, ImportParams

    out = Path(args.out)
    if out.is_dir():
        raise InputError(f"--out {out} is a directory; give the path of the trial CSV to write")
    if out.exists() and not args.force:
        raise InputError(f"{out} already exists; choose another --out or pass --force to replace it")
    rec: ImportedRecording
    params = ImportParams() if args.max_gap is None else ImportParams(max_gap_s=args.max_gap)
    if args.vendor == "xsens":
        two_leg = any(k.startswith(("left_", "right_")) for k in args.map)
        if two_leg and args.side is not None:
            raise InputError("--side is for a one-leg map; a two-leg map names left_… and right_… sensors")
        mag = XSENS_MAG_FIELD_UT if args.mag_field_ut is None else args.mag_field_ut
        rec = load_xsens(args.directory, args.map, side=args.side, mag_field_ut=mag, params=params)
    else:
        rec = load_mapped_csv(args.file, args.mapping, params=params)
    write_atomically(out, rec.to_csv)
    legs = "both legs" if rec.two_leg else f"{rec.side} leg"
    rate = (rec.n_samples - 1) / float(rec.time_s[-1] - rec.time_s[0])
    print(
        f"wrote {out} ({rec.n_samples} samples at {rate:.4g} Hz, {legs}, "
        f"{'with' if rec.mag is not None else 'no'} magnetometer, {rec.n_filled} samples filled)"
    )
    if not rec.two_leg and rec.side != "left":
        # the one-leg trial CSV's columns (pelvis, thigh, shank, foot) carry no side, and
        # calibrate takes such a trial for the left leg unless told
        print(f"  its columns name no side: calibrate it with --side {rec.side} (else: the left leg)")
    return 0
