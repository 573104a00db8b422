"""Sensor range: what a cut accelerometer or gyro does to the two-leg results, and whether it is found.

Low-cost IMUs often record at a narrow default range (an MPU-6050 at ±2 g and ±250 °/s); walking
goes beyond it. Each row cuts every sensor's accelerometer and/or gyro of a trial at a range
(``np.clip`` per axis, as a sensor's converter does) and runs the two-leg pipeline
(``process_bilateral_trial``, what ``lowerlimb calibrate`` runs on a seven-sensor CSV):

- *found*: sensors the input check (:mod:`lowerlimb.io.saturation`) reports cut, against the
  sensors whose signal goes beyond the range in at least three places, or for three samples in a
  row or more somewhere where the trial's signals of that kind go beyond it in at least three
  places in all (a range reached once or twice in a whole trial is not reported, by design; one
  reached once on a sensor and often on the others is);
- *cut %*: the largest share of one sensor's samples beyond the range;
- segment lengths (hip and ankle centre to the knee axis) against the truth (simulated) or
  Vicon Plug-in Gait (real), mm; stride length %, step width mm, initial contact ms (simulated)
  and the worst knee angle and the worst angle RMSE of either leg, degrees (simulated: all nine
  angles; real: each knee's flexion, and the worst of knee and
  hip flexion against Vicon);
- *left out*: the default, the cut samples (and 50 ms around them) left out of the hip and
  ankle fits (``CalibrationOptions.saturation_exclusion``); *fitted*: with
  ``saturation_exclusion=False``;
- *restored*: the default, a cut foot accelerometer's lost force given back swing by swing
  from the zero-velocity updates (:mod:`lowerlimb.gait.cut_force`), a cut foot gyro's rotation
  from its rests (:mod:`lowerlimb.gait.cut_rate`), a cut thigh or shank gyro's from the
  parabola through each run's neighbours refined by its joints (:mod:`lowerlimb.gait.cut_segment`);
  *not restored*: with ``GaitParams(cut_restore=False)``; *parabola only*: the thigh's and
  shank's runs at their parabola (``GaitParams(cut_segment_fit=False)``).

Sources: seven-IMU simulated walks (``simulate_bilateral``, seeds 201–203, 60 s, normal pace)
and the real walk (``gait/``, Xsens MTw, which record at ±16 g and ±2000 °/s; its largest
readings are 3.0 g and 460 °/s).

    python benchmarks/saturation.py --data ../shared/data --out benchmarks/results
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import GRAVITY_MPS2, SIDES
from lowerlimb.gait import GaitParams
from lowerlimb.io import load_xsens
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.saturation import trial_saturation

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bilateral_gait  # noqa: E402
import gait as gait_benchmark  # noqa: E402
from _realwalk import IDS, load_vicon, raw_dir  # noqa: E402
from _results import cell, real_data_main, real_gait_cells, sim_gait_cells  # noqa: E402

SIM_SEEDS = (201, 202, 203)
#: (label, accelerometer range in g, gyro range in °/s, cut samples left out, restoration:
#: "all" (the default), "none" (``cut_restore=False``) or "parabola" (``cut_segment_fit=False``));
#: 0: not cut.
ROWS: tuple[tuple[str, float, float, bool, str], ...] = (
    ("as recorded", 0, 0, True, "all"),
    ("±2 g", 2, 0, True, "all"),
    ("±2 g, not restored", 2, 0, True, "none"),
    ("±2 g, fitted", 2, 0, False, "all"),
    ("±4 g", 4, 0, True, "all"),
    ("±8 g", 8, 0, True, "all"),
    ("±250 °/s", 0, 250, True, "all"),
    ("±250 °/s, not restored", 0, 250, True, "none"),
    ("±250 °/s, parabola only", 0, 250, True, "parabola"),
    ("±250 °/s, fitted", 0, 250, False, "all"),
    ("±300 °/s", 0, 300, True, "all"),
    ("±300 °/s, parabola only", 0, 300, True, "parabola"),
    ("±350 °/s", 0, 350, True, "all"),
    ("±350 °/s, parabola only", 0, 350, True, "parabola"),
    ("±500 °/s", 0, 500, True, "all"),
    ("±1000 °/s", 0, 1000, True, "all"),
    ("±2 g, ±250 °/s (MPU-6050 default)", 2, 250, True, "all"),
    ("±2 g, ±250 °/s, not restored", 2, 250, True, "none"),
    ("±2 g, ±250 °/s, parabola only", 2, 250, True, "parabola"),
    ("±4 g, ±500 °/s", 4, 500, True, "all"),
)

#: GaitParams of each restoration.
RESTORATION = {
    "all": GaitParams(),
    "none": GaitParams(cut_restore=False),
    "parabola": GaitParams(cut_segment_fit=False),
}


def _limits(acc_g: float, gyr_dps: float) -> dict[str, float]:
    return {"acc": acc_g * GRAVITY_MPS2, "gyr": float(np.deg2rad(gyr_dps))}


def _beyond(trial: BilateralTrial, limits: dict[str, float]) -> tuple[set[str], float]:
    """Sensors beyond a range, and the largest share of one sensor's samples beyond it.

    Beyond: in ≥ 3 places, or for ≥ 3 samples in a row where its kind goes beyond it in ≥ 3 places in all.
    """
    sensors, share = set(), 0.0
    for kind, signals in (("acc", trial.acc), ("gyr", trial.gyr)):
        if not limits[kind]:
            continue
        held, places = set(), 0
        for name, x in signals.items():
            over = (np.abs(x) > limits[kind]).any(axis=1)
            share = max(share, float(over.mean()))
            runs = int(np.count_nonzero(np.diff(over.astype(int)) == 1) + over[0])
            places += runs
            if runs >= 3:
                sensors.add(f"{name} {kind}")
            if (over[2:] & over[1:-1] & over[:-2]).any():
                held.add(f"{name} {kind}")
        if places >= 3:
            sensors |= held
    return sensors, share


def cut(trial: BilateralTrial, limits: dict[str, float]) -> BilateralTrial:
    """The trial with every accelerometer and gyro clipped at its range (0: not cut)."""

    def clip(signals: dict[str, np.ndarray], limit: float) -> dict[str, np.ndarray]:
        return {k: np.clip(v, -limit, limit) for k, v in signals.items()} if limit else dict(signals)

    return replace(trial, acc=clip(trial.acc, limits["acc"]), gyr=clip(trial.gyr, limits["gyr"]))


def _found(trial: BilateralTrial, limits: dict[str, float], record: dict[str, Any]) -> BilateralTrial:
    cut_trial = cut(trial, limits)
    beyond, share = _beyond(trial, limits)
    found = {f"{s.sensor} {s.signal}" for s in trial_saturation(cut_trial.acc, cut_trial.gyr)}
    record |= {"beyond": sorted(beyond), "found": sorted(found), "cut_share": share}
    return cut_trial


def _sim_row(gait: ModuleType, acc_g: float, gyr_dps: float, left_out: bool, restore: str) -> dict[str, Any]:
    limits = _limits(acc_g, gyr_dps)
    options = CalibrationOptions(saturation_exclusion=left_out)
    gait_params = RESTORATION[restore]
    trials, checks = [], []
    for seed in SIM_SEEDS:
        record: dict[str, Any] = {}
        transform: Callable[[Any], Any] = lambda tr, rec=record: _found(tr, limits, rec)  # noqa: E731
        trials.append(
            gait.score_simulation(
                seed, 60.0, calibration_options=options, gait_params=gait_params, transform=transform
            )
        )
        checks.append(record)
    pooled = gait.summarise_simulation(trials)
    by_angle = pooled["angle_rmse_deg"]["worst"]
    worst = max(max(v.values()) for v in by_angle.values())
    knee = max(v[k] for v in by_angle.values() for k in v if k.startswith("knee"))
    return {
        "found": sum(len(c["found"]) for c in checks),
        "beyond": sum(len(c["beyond"]) for c in checks),
        "missed": sorted({m for c in checks for m in set(c["beyond"]) - set(c["found"])}),
        "false": sorted({m for c in checks for m in set(c["found"]) - set(c["beyond"])}),
        "cut_share": max(c["cut_share"] for c in checks),
        "lengths_mm": {k: pooled["joints"][k] for k in gait.LENGTH_LABELS},
        "stride_length_pct": pooled["stride_length_pct"],
        "step_width_mm": pooled["step_width_mm"],
        "initial_contact_ms": pooled["initial_contact"],
        "worst_angle_rmse_deg": worst,
        "worst_knee_rmse_deg": knee,
    }


def _real_row(
    base: BilateralTrial, vicon: dict[str, Any], row: tuple[str, float, float, bool, str]
) -> dict[str, Any]:
    _, acc_g, gyr_dps, left_out, restore = row
    record: dict[str, Any] = {}
    trial = _found(base, _limits(acc_g, gyr_dps), record)
    scored = bilateral_gait.score_real_walk(
        trial,
        vicon,
        calibration_options=CalibrationOptions(saturation_exclusion=left_out),
        gait_params=RESTORATION[restore],
    )
    del scored["result"]
    return {
        "found": len(record["found"]),
        "beyond": len(record["beyond"]),
        "missed": sorted(set(record["beyond"]) - set(record["found"])),
        "false": sorted(set(record["found"]) - set(record["beyond"])),
        "cut_share": record["cut_share"],
        **scored,
    }


def run(data: Path) -> dict[str, Any]:
    """Every row on the simulated walks and on the real walk."""
    gait = gait_benchmark
    rec = load_xsens(raw_dir(data), IDS)
    base = BilateralTrial(rec.time_s, rec.acc, rec.gyr, rec.mag)
    vicon = load_vicon(data)
    rows = []
    for row in ROWS:
        label, acc_g, gyr_dps, left_out, restore = row
        print(f"saturation: {label}", file=sys.stderr)
        rows.append(
            {
                "label": label,
                "acc_range_g": acc_g,
                "gyr_range_dps": gyr_dps,
                "left_out": left_out,
                "restored": restore,
                "simulated": _sim_row(gait, acc_g, gyr_dps, left_out, restore),
                "real": _real_row(base, vicon, row),
            }
        )
    return {"seeds": SIM_SEEDS, "rows": rows}


def _sim_line(r: dict[str, Any]) -> str:
    s = r["simulated"]
    return (
        f"| {r['label']} | {s['found']} / {s['beyond']} | {100 * s['cut_share']:.1f} | {sim_gait_cells(s)} |"
    )


def _real_line(r: dict[str, Any]) -> str:
    s = r["real"]
    return (
        f"| {r['label']} | {s['found']} / {s['beyond']} | {100 * s['cut_share']:.1f} | "
        f"{real_gait_cells(s, SIDES)} | {cell(s['worst_flexion_rmse_deg'])} |"
    )


def markdown(res: dict[str, Any]) -> str:
    """The two tables and what they say."""
    seeds = ", ".join(map(str, res["seeds"]))
    lines = [
        "# Sensor range: a cut accelerometer or gyro",
        "",
        "Generated by `benchmarks/saturation.py` (definitions in its docstring). Every sensor's "
        "accelerometer and/or gyro cut at the range of the row. *found / beyond*: sensor signals the "
        "input check reports cut, against those that go beyond the range in three places or more, or for "
        "three samples in a row where the trial's signals of that kind go beyond it in three places or more. "
        "*fitted*: the cut samples kept in the hip and ankle fits (`saturation_exclusion=False`); "
        "every other row leaves them out (the default). *not restored*: the cut signals used "
        "as recorded (`GaitParams(cut_restore=False)`); every other row gives a cut foot gyro's swings "
        "the rotation that carries the foot's tilt from rest to rest (`lowerlimb.gait.cut_rate`), a "
        "cut foot accelerometer's swings the force that brings the foot to rest "
        "(`lowerlimb.gait.cut_force`) and a cut thigh or shank gyro's runs the rotation of the parabola "
        "through their neighbours refined by the joints' acceleration norms (`lowerlimb.gait.cut_segment`), "
        "the default; *parabola only*: the thigh's and shank's runs at the parabola "
        "(`GaitParams(cut_segment_fit=False)`). Step width is `–` (null in gait.json) wherever a "
        "foot gyro is cut, restored or not: its turns about gravity are lost and the two feet's "
        "tracks cannot be placed against each other.",
        "",
        f"## Simulated seven-IMU walks (seeds {seeds}, 60 s), against the truth",
        "",
        "| range | found / beyond | cut % (worst sensor) | thigh / shank length error mm, median (worst) "
        "| stride length % | step width mm | initial contact ms | worst knee angle RMSE ° "
        "| worst angle RMSE ° |",
        "|---|---|---|---|---|---|---|---|---|",
        *[_sim_line(r) for r in res["rows"]],
        "",
        "## Real walk (Xsens MTw at ±16 g and ±2000 °/s), against Vicon",
        "",
        "| range | found / beyond | cut % (worst sensor) | length error mm, left thigh / shank, right "
        "thigh / shank | stride length % | step width mm | knee flexion RMSE ° left / right "
        "| worst hip or knee flexion RMSE ° |",
        "|---|---|---|---|---|---|---|---|",
        *[_real_line(r) for r in res["rows"]],
        "",
    ]
    missed = sorted({m for r in res["rows"] for src in ("simulated", "real") for m in r[src]["missed"]})
    false = sorted({m for r in res["rows"] for src in ("simulated", "real") for m in r[src]["false"]})
    lines += [
        f"Sensors beyond a range (as defined above) but not reported: {', '.join(missed) or 'none'}. "
        f"Reported but not beyond: {', '.join(false) or 'none'}.",
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    real_data_main(__doc__, "saturation", run, markdown)


if __name__ == "__main__":
    main()
