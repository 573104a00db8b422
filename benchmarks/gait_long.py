"""Step width, step length and stride length over long seven-IMU walks: does anything drift?

The 60 s walks of ``gait.py`` cannot show an error that grows with the walk. This benchmark
simulates 5-minute seven-IMU walks (``simulate_bilateral``, realistic noise, the lab's
magnetic field, a gently bending path), runs the two-leg pipeline once per configuration of
how the two feet's tracks are put in one frame (the default; the standing anchor only,
``GaitParams.chain_drift_knot_s=None``; and the most overlapping left stride's heading,
``pair_yaw_at_mid_time=False``) and scores every stride against the simulator's truth, per
minute:

- step width error, mm (median of the signed errors in that minute);
- step length error, mm (median of the absolute errors: the legs' errors have opposite signs);
- stride length error, % (median).

Usage: ``python benchmarks/gait_long.py [--seeds 201 202 203] [--minutes 5] [--name gait_long]
[--pace-changes]``; writes ``benchmarks/results/<name>.{md,json}`` (``gait_long_10min`` holds
``--minutes 10 --seeds 11 201``; ``gait_long_pace`` holds ``--pace-changes --seeds 11 201 202``:
the walker speeds up and slows down, so a chain whose error follows the step length would show
as drift).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from lowerlimb.bilateral import process_bilateral_trial
from lowerlimb.bilateral.gait import analyse_gait
from lowerlimb.gait import GaitParams
from lowerlimb.simulation import simulate_bilateral

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _results import write_results  # noqa: E402
from gait import matched_strides  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = {
    "chain drift removed (default)": GaitParams(),
    "standing anchor only": GaitParams(chain_drift_knot_s=None),
    "overlap heading, anchor only": GaitParams(pair_yaw_at_mid_time=False, chain_drift_knot_s=None),
}


def _errors(sim: Any, res: Any) -> np.ndarray:
    """(K, 4) rows ``(start s, step width mm, step length mm, stride length %)`` of matched strides."""
    rows = [
        (
            st.start_s,
            1000.0 * (c.step_width_m - st.step_width_m),
            1000.0 * (c.step_length_m - st.step_length_m),
            100.0 * (c.stride_length_m / st.stride_length_m - 1.0),
        )
        for st, c in matched_strides(sim, res)
    ]
    return np.asarray(rows, dtype=float).reshape(-1, 4)


def _drift_removed(res: Any) -> float | None:
    """The largest drift between the feet's tracks that the chain removed, m (``None``: none)."""
    gp = res.gait.parameters
    return None if gp is None or gp.track_drift is None else gp.track_drift.max_m


def one_walk(seed: int, minutes: float, pace_changes: bool = False) -> dict[str, Any]:
    sim = simulate_bilateral(60.0 * minutes, seed, pace_changes=pace_changes)
    out: dict[str, Any] = {"seed": seed, "minutes": minutes, "pace_changes": pace_changes}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        legs = process_bilateral_trial(sim.trial).legs  # the configurations differ in the gait stage only
    for name, gp in CONFIGS.items():
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = SimpleNamespace(gait=analyse_gait(legs, gp))
        err = _errors(sim, res)
        per_min = []
        for m in range(int(np.ceil(minutes))):
            sel = (err[:, 0] >= 60.0 * m) & (err[:, 0] < 60.0 * (m + 1))
            med = np.nanmedian(err[sel, 1:], axis=0) if sel.any() else np.full(3, np.nan)
            step_abs = float(np.nanmedian(np.abs(err[sel, 2]))) if sel.any() else float("nan")
            per_min.append(
                {
                    "minute": m + 1,
                    "n": int(sel.sum()),
                    "width_mm": med[0],
                    "step_mm": med[1],
                    "step_abs_mm": step_abs,
                    "stride_pct": med[2],
                }
            )
        out[name] = {
            "per_minute": per_min,
            "width_median_abs_mm": float(np.nanmedian(np.abs(err[:, 1]))),
            "width_worst_abs_mm": float(np.nanmax(np.abs(err[:, 1]))),
            "step_median_abs_mm": float(np.nanmedian(np.abs(err[:, 2]))),
            "step_worst_abs_mm": float(np.nanmax(np.abs(err[:, 2]))),
            "track_drift_max_m": _drift_removed(res),
            "gait_analysis_s": time.perf_counter() - t0,
        }
    return out


def markdown(rows: list[dict[str, Any]], pace_changes: bool = False) -> str:
    walk = (
        "a gently bending path, and a walker who speeds up and slows down (step length ±15–25 %, "
        "step width ±20–40 % over 1.5–3 minutes, `pace_changes=True`)"
        if pace_changes
        else "a gently bending path"
    )
    L = [
        "# Long seven-IMU walks: gait parameters minute by minute",
        "",
        "Generated by `benchmarks/gait_long.py`: `simulate_bilateral` walks (realistic noise, the lab's",
        f"field, {walk}), each run with three ways of putting the two feet's tracks in",
        "one frame: the default (heading at each right stride's mid-time, the standing anchor, and the",
        "slow drift between the tracks removed with the calibrated chain, `GaitParams.chain_drift_knot_s`);",
        "the standing anchor only (`chain_drift_knot_s=None`, the previous default); and, before that,",
        "the most overlapping left stride's heading (`pair_yaw_at_mid_time=False`). Per minute: median",
        "signed step width error, median |step length error| (mm; the two legs' step length errors",
        "have opposite signs when the tracks drift along the walk) and median stride length error (%)",
        "against the simulator's truth.",
        "",
        "| seed | feet in one frame | "
        + " | ".join(f"min {m['minute']}" for m in rows[0][next(iter(CONFIGS))]["per_minute"])
        + " | width median / worst abs | step length median / worst abs | drift removed |",
        "|---" * (2 + len(rows[0][next(iter(CONFIGS))]["per_minute"]) + 3) + "|",
    ]
    for r in rows:
        for name in CONFIGS:
            c = r[name]
            cells = " | ".join(
                f"{m['width_mm']:+.0f} / {m['step_abs_mm']:.0f} / {m['stride_pct']:+.1f}"
                for m in c["per_minute"]
            )
            width = f"{c['width_median_abs_mm']:.0f} / {c['width_worst_abs_mm']:.0f} mm"
            step = f"{c['step_median_abs_mm']:.0f} / {c['step_worst_abs_mm']:.0f} mm"
            drift = "–" if c["track_drift_max_m"] is None else f"{1000 * c['track_drift_max_m']:.0f} mm"
            L.append(f"| {r['seed']} | {name} | {cells} | {width} | {step} | {drift} |")
    L += ["", "Cells: step width mm (signed) / step length mm (absolute) / stride length %.", ""]
    return "\n".join(L)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[201, 202, 203])
    ap.add_argument("--minutes", type=float, default=5.0)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--name", default="gait_long", help="results file stem")
    ap.add_argument(
        "--pace-changes",
        action="store_true",
        help="the walker speeds up and slows down (step length ±15–25 %%) and changes step width "
        "(±20–40 %%) over 1.5–3 minutes (simulate_bilateral(pace_changes=True))",
    )
    args = ap.parse_args()
    rows = [one_walk(s, args.minutes, args.pace_changes) for s in args.seeds]
    write_results(args.out, args.name, rows, markdown(rows, args.pace_changes))


if __name__ == "__main__":
    main()
