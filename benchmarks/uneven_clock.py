"""Uneven sample times: dropped packets and jittered stamps, resampled as the trial CSV is read.

Wireless IMUs drop packets, and loggers that stamp samples on arrival give steps that wander
around the period. A trial CSV whose steps vary by more than a quarter of the median is put on a
constant clock as it is read (:mod:`lowerlimb.io.uneven_clock`: a cubic spline through the
stamped samples, clipped to each column's range). Each row makes the trial uneven, writes it as a
two-leg trial CSV, reads it back with ``BilateralTrial.from_csv`` (what ``lowerlimb calibrate``
does) and runs the two-leg pipeline:

- *dropped*: that share of the rows removed at random (first and last kept), one row at a time
  or in runs of up to five rows (50 ms, under the 0.1 s longest gap bridged);
- *jitter*: each sample taken at its stamp plus a uniform error within ± that share of the
  period (first and last exact); the signal at those times is the recorded one interpolated
  band-limited (``resample_poly`` ×10, then linear between the 1 ms samples);
- *linear*: the same uneven trial resampled by linear interpolation (``np.interp``) in the
  benchmark before it is read, for comparison with the spline.

Scored as ``saturation.py`` scores: simulated seven-IMU walks (``simulate_bilateral``, seeds
201–203, 60 s) against their truth (thigh / shank lengths, stride length, step width, initial
contact, worst knee angle and worst angle RMSE over both legs); the real walk of ``gait/``
(Xsens MTw, 100 Hz) against Vicon (lengths, stride length, step width, knee flexion). *signal
error*: RMS over the seven foot, shank and thigh gyros of the resampled trial against the even
one, rad/s (the real walk; the simulated walks give the same order).

    python benchmarks/uneven_clock.py --data ../shared/data --out benchmarks/results
"""

from __future__ import annotations

import sys
import tempfile
import warnings
from dataclasses import replace
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
from scipy.signal import resample_poly

from lowerlimb.conventions import SIDES
from lowerlimb.io import load_xsens
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.uneven_clock import UnevenClockWarning

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bilateral_gait  # noqa: E402
import gait as gait_benchmark  # noqa: E402
from _realwalk import IDS, load_vicon, raw_dir  # noqa: E402
from _results import cell, real_data_main, real_gait_cells, sim_gait_cells  # noqa: E402

SIM_SEEDS = (201, 202, 203)
#: (label, share of rows dropped, longest run dropped (rows), jitter (share of the period),
#: resampled linearly in the benchmark before reading)
ROWS: tuple[tuple[str, float, int, float, bool], ...] = (
    ("even (as recorded)", 0.0, 0, 0.0, False),
    ("1 % dropped, single rows", 0.01, 1, 0.0, False),
    ("5 % dropped, runs of 1-5 rows", 0.05, 5, 0.0, False),
    ("5 % dropped, runs of 1-5 rows, linear", 0.05, 5, 0.0, True),
    ("jitter ±20 %", 0.0, 0, 0.2, False),
    ("jitter ±20 %, linear", 0.0, 0, 0.2, True),
    ("jitter ±20 %, 2 % dropped", 0.02, 3, 0.2, False),
)
GYROS = ("left_thigh", "left_shank", "left_foot", "right_thigh", "right_shank", "right_foot")


def _dropped_rows(n: int, share: float, longest: int, rng: np.random.Generator) -> np.ndarray:
    """(n,) mask of the rows kept: about ``share`` of them removed in runs of 1 … ``longest``."""
    keep = np.ones(n, dtype=bool)
    while share and (~keep).mean() < share:
        start = int(rng.integers(1, n - longest - 1))
        keep[start : start + int(rng.integers(1, longest + 1))] = False
    return keep


def _at(trial: BilateralTrial, times: np.ndarray) -> dict[str, dict[str, np.ndarray]]:
    """Every signal of ``trial`` at ``times`` (band-limited ×10, then linear)."""
    t = trial.time_s
    fine = t[0] + np.arange(10 * t.size - 9) * (t[1] - t[0]) / 10

    def one(x: np.ndarray) -> np.ndarray:
        up = resample_poly(x, 10, 1, axis=0, padtype="line")[: fine.size]
        return np.column_stack([np.interp(times, fine, c) for c in up.T])

    out = {"acc": {s: one(x) for s, x in trial.acc.items()}, "gyr": {s: one(x) for s, x in trial.gyr.items()}}
    if trial.mag is not None:
        out["mag"] = {s: one(x) for s, x in trial.mag.items()}
    return out


def uneven(trial: BilateralTrial, row: tuple[str, float, int, float, bool], seed: int) -> BilateralTrial:
    """The trial made uneven as the row says, written as CSV and read back (and resampled)."""
    _, share, longest, jitter, linear = row
    rng = np.random.default_rng(seed)
    t = trial.time_s
    times = t.copy()
    if jitter:
        times[1:-1] += rng.uniform(-jitter, jitter, t.size - 2) * (t[1] - t[0])
    sig = _at(trial, times) if jitter else {"acc": trial.acc, "gyr": trial.gyr, "mag": trial.mag}
    keep = _dropped_rows(t.size, share, longest, rng)
    out_t = times[keep]

    def pick(group: dict[str, np.ndarray] | None) -> dict[str, np.ndarray] | None:
        if group is None:
            return None
        if linear:  # back on the even clock, linearly, in the benchmark
            return {s: np.column_stack([np.interp(t, out_t, c) for c in x[keep].T]) for s, x in group.items()}
        return {s: x[keep] for s, x in group.items()}

    made = BilateralTrial(
        t if linear else out_t, pick(sig["acc"]), pick(sig["gyr"]), pick(sig.get("mag")), source=trial.source
    )
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "trial.csv"
        made.to_csv(path)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            back = BilateralTrial.from_csv(path)
    resampled = any(issubclass(w.category, UnevenClockWarning) for w in caught)
    return replace(back, source=f"{trial.source} ({'resampled' if resampled else 'even'})")


def _gyro_error(even: BilateralTrial, back: BilateralTrial) -> float:
    n = min(even.time_s.size, back.time_s.size)
    return float(np.sqrt(np.mean([np.mean((even.gyr[s][:n] - back.gyr[s][:n]) ** 2) for s in GYROS])))


def _sim_row(gait: ModuleType, row: tuple[str, float, int, float, bool]) -> dict[str, Any]:
    trials, resampled = [], []

    def transform(tr: BilateralTrial, seed: int) -> BilateralTrial:
        back = uneven(tr, row, seed)
        resampled.append(back.source.endswith("(resampled)"))
        return back

    for seed in SIM_SEEDS:
        trials.append(gait.score_simulation(seed, 60.0, transform=lambda tr, s=seed: transform(tr, s)))
    pooled = gait.summarise_simulation(trials)
    by_angle = pooled["angle_rmse_deg"]["worst"]
    return {
        "resampled": sum(resampled),
        "lengths_mm": {k: pooled["joints"][k] for k in gait.LENGTH_LABELS},
        "stride_length_pct": pooled["stride_length_pct"],
        "step_width_mm": pooled["step_width_mm"],
        "initial_contact_ms": pooled["initial_contact"],
        "worst_angle_rmse_deg": max(max(v.values()) for v in by_angle.values()),
        "worst_knee_rmse_deg": max(v[k] for v in by_angle.values() for k in v if k.startswith("knee")),
    }


def _real_row(
    base: BilateralTrial, vicon: dict[str, Any], row: tuple[str, float, int, float, bool]
) -> dict[str, Any]:
    trial = uneven(base, row, seed=7)
    scored = bilateral_gait.score_real_walk(trial, vicon)
    del scored["result"]
    return {
        "resampled": trial.source.endswith("(resampled)"),
        "rows": int(trial.time_s.size),
        "gyro_error_rps": _gyro_error(base, trial),
        **scored,
    }


def run(data: Path) -> dict[str, Any]:
    """Every row on the simulated walks and on the real walk."""
    rec = load_xsens(raw_dir(data), IDS)
    base = BilateralTrial(rec.time_s, rec.acc, rec.gyr, rec.mag, source="real walk")
    vicon = load_vicon(data)
    rows = []
    for row in ROWS:
        print(f"uneven_clock: {row[0]}", file=sys.stderr)
        rows.append(
            {
                "label": row[0],
                "dropped": row[1],
                "longest_run": row[2],
                "jitter": row[3],
                "linear": row[4],
                "simulated": _sim_row(gait_benchmark, row),
                "real": _real_row(base, vicon, row),
            }
        )
    return {"seeds": SIM_SEEDS, "rows": rows}


def _sim_line(r: dict[str, Any]) -> str:
    s = r["simulated"]
    return f"| {r['label']} | {s['resampled']} / {len(SIM_SEEDS)} | {sim_gait_cells(s)} |"


def _real_line(r: dict[str, Any]) -> str:
    s = r["real"]
    resampled = "yes" if s["resampled"] else "no"
    return (
        f"| {r['label']} | {resampled} | {cell(s['gyro_error_rps'], '.4f')} | {real_gait_cells(s, SIDES)} |"
    )


def markdown(res: dict[str, Any]) -> str:
    """The two tables."""
    seeds = ", ".join(map(str, res["seeds"]))
    return "\n".join(
        [
            "# Uneven sample times: dropped packets and jittered stamps",
            "",
            "Generated by `benchmarks/uneven_clock.py` (definitions in its docstring). Each trial made "
            "uneven, written as a two-leg trial CSV and read back: a trial whose time steps vary by more "
            "than 25 % of the median is resampled onto a constant clock by a cubic spline clipped to "
            "each column's range (`lowerlimb.io.uneven_clock`, with one warning). *linear*: resampled "
            "with `np.interp` by the benchmark before it is read, for comparison.",
            "",
            f"## Simulated seven-IMU walks (seeds {seeds}, 60 s), against the truth",
            "",
            "| trial | resampled | thigh / shank length error mm, median (worst) | stride length % "
            "| step width mm | initial contact ms | worst knee angle RMSE ° | worst angle RMSE ° |",
            "|---|---|---|---|---|---|---|---|",
            *[_sim_line(r) for r in res["rows"]],
            "",
            "## Real walk (Xsens MTw, 100 Hz), against Vicon",
            "",
            "| trial | resampled | gyro error rad/s RMS | length error mm, left thigh / shank, right "
            "thigh / shank | stride length % | step width mm | knee flexion RMSE ° left / right |",
            "|---|---|---|---|---|---|---|",
            *[_real_line(r) for r in res["rows"]],
            "",
        ]
    )


def main() -> None:
    real_data_main(__doc__, "uneven_clock", run, markdown)


if __name__ == "__main__":
    main()
