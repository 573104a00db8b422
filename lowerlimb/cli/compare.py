"""``lowerlimb compare DIR REFERENCE.csv --out DIR2 [--align-time] [--remove-offset]``.

docs/formats.md, "Agreement with a reference". DIR is a ``calibrate`` output folder
(``angles.csv`` in degrees, ``positions.csv`` in metres); REFERENCE.csv has
``time`` and any columns named as ours, in the same units. DIR2 gets
``agreement.csv``, ``agreement.json`` (the time offset applied and the method)
and Bland–Altman plots ``bland_altman_angles.png`` / ``bland_altman_positions.png``.
Everything is written into a staging folder that is renamed to DIR2 at the
end, so bad input leaves nothing behind.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

#: Plot file per unit group.
PLOT_FILES: dict[str, tuple[str, str]] = {
    "deg": ("bland_altman_angles.png", "Joint angles: lowerlimb vs reference"),
    "m": ("bland_altman_positions.png", "Positions: lowerlimb vs reference"),
}


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``compare`` sub-command to ``subparsers`` (from ``add_subparsers``)."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "compare", help="agreement of a calibrated trial with a reference (Bland–Altman, RMSE, r, CMC)"
    )
    p.add_argument("dir", type=Path, metavar="DIR", help="output directory of 'lowerlimb calibrate'")
    p.add_argument(
        "reference",
        type=Path,
        metavar="REFERENCE.csv",
        help="reference CSV: 'time' (s) and columns named as in angles.csv (deg) / positions.csv (m)",
    )
    p.add_argument("--out", required=True, type=Path, help="output directory (created; must not exist)")
    p.add_argument(
        "--align-time",
        action="store_true",
        help="estimate the clock offset of the reference by cross-correlation (±2 s) and apply it",
    )
    p.add_argument(
        "--remove-offset",
        action="store_true",
        help="remove each quantity's constant offset (mean difference) before the statistics",
    )
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``lowerlimb compare``; returns the exit status (0). Bad input raises ``InputError``."""
    from lowerlimb.agreement import compare_series, plot_bland_altman
    from lowerlimb.agreement.files import (
        agreement_summary,
        read_reference_table,
        read_result,
        write_agreement_csv,
        write_agreement_json,
    )
    from lowerlimb.errors import InputError
    from lowerlimb.io.atomic import populate_directory

    out = Path(args.out)
    if out.exists():
        raise InputError(f"{out} already exists; choose a new --out directory")
    result = read_result(args.dir)
    time_s, ours, units = result.time_s, result.values, result.units
    ref = read_reference_table(args.reference, our_columns=list(ours), time_s=time_s, result=result)
    comparison = compare_series(
        time_s,
        ours,
        units,
        ref.time_s,
        ref.columns,
        align_time=args.align_time,
        remove_offset=args.remove_offset,
    )
    plots: list[str] = []

    def fill(staging: Path) -> None:
        write_agreement_csv(staging / "agreement.csv", comparison)
        for unit, (name, title) in PLOT_FILES.items():
            idx = [i for i, s in enumerate(comparison.quantities) if s.unit == unit]
            if idx:
                plot_bland_altman(
                    staging / name,
                    [comparison.quantities[i] for i in idx],
                    [comparison.series[i] for i in idx],
                    title=title,
                )
                plots.append(name)
        summary = agreement_summary(
            comparison,
            inputs={"dir": str(args.dir), "reference": str(args.reference)},
            plots=list(plots),
        )
        write_agreement_json(staging / "agreement.json", summary)

    populate_directory(out, fill)
    worst = max(comparison.quantities, key=lambda s: s.rmse)
    shift = f", reference shifted by {comparison.time_offset_s:+.3f} s" if comparison.alignment else ""
    print(
        f"wrote {out} ({len(comparison.quantities)} quantities{shift}; largest RMSE "
        f"{worst.rmse:.3g} {worst.unit} in {worst.quantity})"
    )
    return 0
