"""Writing a benchmark's tables: ``<name>.json`` and ``<name>.md`` in the results folder."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np


def write_results(out: Path, name: str, data: Any, md: str) -> None:
    """Write ``data`` as ``<out>/<name>.json`` (numpy numbers as floats), ``md`` as ``.md``; print ``md``."""
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{name}.json").write_text(json.dumps(data, indent=1, default=float))
    (out / f"{name}.md").write_text(md)
    print(md)


def real_data_main(
    doc: str | None, name: str, run: Callable[[Path], Any], markdown: Callable[[Any], str]
) -> None:
    """The command line of a real-data benchmark: ``--data DIR --out DIR``, then run and write."""
    root = Path(__file__).resolve().parents[1]
    ap = argparse.ArgumentParser(description=doc.splitlines()[0] if doc else None)
    ap.add_argument("--data", type=Path, default=root.parent / "shared" / "data")
    ap.add_argument("--out", type=Path, default=root / "benchmarks" / "results")
    args = ap.parse_args()
    res = run(args.data)
    write_results(args.out, name, res, markdown(res))


def cell(x: Any, fmt: str = ".1f") -> str:
    """A table cell: ``x`` formatted, or ``–`` for None, NaN or inf."""
    return "–" if x is None or not np.isfinite(x) else format(x, fmt)


def sim_gait_cells(s: dict[str, Any]) -> str:
    """The gait cells of a row pooled over simulated two-leg walks (``gait.summarise_simulation``).

    ``lengths | stride % | step width mm | initial contact ms | worst knee ° | worst angle °``.
    """
    lengths = " / ".join(
        f"{cell(v['median_abs'], '.0f')} ({cell(v['worst_abs'], '.0f')})" for v in s["lengths_mm"].values()
    )
    return (
        f"{lengths} | {cell(s['stride_length_pct']['median_abs'])} | "
        f"{cell(s['step_width_mm']['median_abs'], '.0f')} | {cell(s['initial_contact_ms']['median_abs'])} | "
        f"{cell(s['worst_knee_rmse_deg'])} | {cell(s['worst_angle_rmse_deg'])}"
    )


def real_gait_cells(s: dict[str, Any], sides: tuple[str, ...]) -> str:
    """``length errors | stride % | step width mm | knee flexion °`` cells of a row on the real walk."""
    le = " / ".join(f"{v:+.0f}" for side in sides for v in s["length_err_mm"][side])
    stride, width = s["stride_length_pct"].get("median_abs"), s["step_width_mm"].get("median_abs")
    knees = " / ".join(cell(v) for v in s["knee_flexion_rmse_deg"])
    return f"{le} | {cell(stride)} | {cell(width, '.0f')} | {knees}"
