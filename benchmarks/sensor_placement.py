"""Where a sensor sits on its segment: the same leg with one sensor strapped elsewhere.

A sensor moved by ``r`` (its own frame) on a rigid segment reads the same gyro and the
accelerometer plus ``α × r + ω × (ω × r)`` (α: the gyro's derivative, a Savitzky–Golay filter
of 7 samples). Its joint centres must move by ``−r`` and nothing else may change. Each trial
is calibrated as recorded and with one sensor moved:

- the thigh sensor 8 cm up the thigh and 8 cm down (along its standing up), 5 cm forward
  (up × the knee axis);
- the shank sensor 8 cm up the shank.

Scored: the change of the thigh and shank lengths (``model.fallback.segment_lengths``), mm;
how far the moved sensor's joint centres (hip and knee for the thigh; knee and ankle for the
shank) land from where they were minus ``r``, mm (worst of the two; the knee by its distance
to the axis line, any point of which is a hinge centre); and whether a thigh was replaced by
de Leva's as implausible.

- simulated: rigid one-leg walks (``simulate("walk", 60 s)``, seeds 1–3), default options, with
  the offset applied to the signals as on the real walk, and, to check that transform, with
  the sensor truly placed elsewhere (the same walk simulated with the sensor's placement moved
  8 cm up its segment, scored against the simulator's truth);
- real: each leg of the walk of ``gait/`` as a one-leg trial, with the default options and
  with the knee centre fitted from zero alone (``hinge_centre_start_m=None``, before 0.5.4).

A real sensor wobbles on soft tissue; the wobble's rotation taken about a point 5–8 cm away
adds motion that no strap has, so the real rows bound the dependence on placement from above.

Usage: ``python benchmarks/sensor_placement.py [--data ../shared/data] [--out benchmarks/results]``;
writes ``sensor_placement.{md,json}``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import copy
import sys
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy.signal import savgol_filter

import lowerlimb as ll
from lowerlimb.calibration import CalibrationOptions
from lowerlimb.calibration.geometry import distance_to_line
from lowerlimb.io.trial import ImuTrial
from lowerlimb.model.fallback import segment_lengths
from lowerlimb.simulation import simulate

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _results import real_data_main  # noqa: E402
from real_gait import load_leg  # noqa: E402

SEEDS = (1, 2, 3)
MOVES = (("thigh", "up", 0.08), ("thigh", "up", -0.08), ("thigh", "forward", 0.05), ("shank", "up", 0.08))
CONFIGS = {
    "default": CalibrationOptions(),
    "start at zero alone": CalibrationOptions(hinge_centre_start_m=None),
}


def moved(trial: ImuTrial, sensor: str, r: np.ndarray) -> ImuTrial:
    """``trial`` with ``sensor`` moved by ``r`` (its frame, m) on a rigid segment."""
    w = trial.gyr[sensor]
    alpha = savgol_filter(w, 7, 2, deriv=1, axis=0) * trial.rate_hz
    acc = trial.acc[sensor] + np.cross(alpha, r) + np.cross(w, np.cross(w, r))
    return replace(trial, acc={**trial.acc, sensor: acc})


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _offset(trial: ImuTrial, cal: Any, sensor: str, direction: str, metres: float) -> np.ndarray:
    up = _unit(trial.acc[sensor][:100].mean(axis=0))
    if direction == "up":
        return metres * up
    axis = cal.knee.axis_in_parent_sensor if sensor == "thigh" else cal.knee.axis_in_child_sensor
    return metres * _unit(np.cross(up, axis))


def _calibrate(trial: ImuTrial, options: CalibrationOptions) -> tuple[Any, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = ll.process_trial(trial, calibration_options=options)
    return res.calibration, [str(w.message) for w in caught]


def _centre_miss_mm(base: Any, cal: Any, sensor: str, r: np.ndarray) -> float:
    """Worst miss of the moved sensor's joint centres against base − r, mm."""
    if sensor == "thigh":
        sph = cal.hip.center_in_child_sensor - (base.hip.center_in_child_sensor - r)
        knee = distance_to_line(
            cal.knee.center_in_parent_sensor,
            base.knee.center_in_parent_sensor - r,
            base.knee.axis_in_parent_sensor,
        )
    else:
        sph = cal.ankle.center_in_parent_sensor - (base.ankle.center_in_parent_sensor - r)
        knee = distance_to_line(
            cal.knee.center_in_child_sensor,
            base.knee.center_in_child_sensor - r,
            base.knee.axis_in_child_sensor,
        )
    return 1000.0 * max(float(np.linalg.norm(sph)), float(knee))


def _label(sensor: str, direction: str, metres: float) -> str:
    way = "down" if direction == "up" and metres < 0 else direction
    return f"{sensor} {100 * abs(metres):.0f} cm {way}"


def score(trial: ImuTrial, options: CalibrationOptions) -> list[dict[str, Any]]:
    """One row per move of :data:`MOVES` for one trial."""
    base, _ = _calibrate(trial, options)
    lengths0 = np.array(segment_lengths(base))
    rows = []
    for sensor, direction, metres in MOVES:
        r = _offset(trial, base, sensor, direction, metres)
        cal, messages = _calibrate(moved(trial, sensor, r), options)
        d = 1000.0 * (np.array(segment_lengths(cal)) - lengths0)
        rows.append(
            {
                "move": _label(sensor, direction, metres),
                "thigh_change_mm": float(d[0]),
                "shank_change_mm": float(d[1]),
                "centre_miss_mm": _centre_miss_mm(base, cal, sensor, r),
                "fell_back": any("fell back on the de Leva" in m for m in messages),
            }
        )
        print(rows[-1], flush=True)
    return rows


def relocated(seed: int) -> list[dict[str, Any]]:
    """The walk of ``seed`` simulated again with the thigh, then the shank sensor 8 cm up its segment."""
    base = simulate("walk", 60.0, seed)
    same = simulate("walk", 60.0, seed, geometry=copy.deepcopy(base.model.geometry))
    cal0, _ = _calibrate(same.trial, CalibrationOptions())
    rows = []
    for sensor in ("thigh", "shank"):
        geometry = copy.deepcopy(base.model.geometry)
        T = geometry.sensor_placements[sensor].copy()
        T[:3, 3] += np.array([0.0, 0.08, 0.0])  # segment frame: y up (ISB)
        geometry.sensor_placements[sensor] = T
        sim = simulate("walk", 60.0, seed, geometry=geometry)
        cal, messages = _calibrate(sim.trial, CalibrationOptions())
        r = T[:3, :3].T @ np.array([0.0, 0.08, 0.0])  # the offset in the sensor frame
        d = 1000.0 * (np.array(segment_lengths(cal)) - np.array(segment_lengths(cal0)))
        rows.append(
            {
                "seed": seed,
                "move": f"{sensor} 8 cm up, placed",
                "thigh_change_mm": float(d[0]),
                "shank_change_mm": float(d[1]),
                "centre_miss_mm": _centre_miss_mm(cal0, cal, sensor, r),
                "fell_back": any("fell back on the de Leva" in m for m in messages),
            }
        )
        print(rows[-1], flush=True)
    return rows


def run(data: Path) -> dict[str, Any]:
    """Simulated and real rows (module docstring)."""
    out: dict[str, Any] = {"simulated": [], "real": []}
    for seed in SEEDS:
        for row in score(simulate("walk", 60.0, seed).trial, CalibrationOptions()):
            out["simulated"].append({"seed": seed} | row)
        out["simulated"] += relocated(seed)
    for side in ("left", "right"):
        trial = load_leg(data, side)
        for label, options in CONFIGS.items():
            for row in score(trial, options):
                out["real"].append({"side": side, "knee centre": label} | row)
    return out


def _cells(r: dict[str, Any]) -> str:
    flag = "yes" if r["fell_back"] else "no"
    return f"{r['thigh_change_mm']:+.1f} | {r['shank_change_mm']:+.1f} | {r['centre_miss_mm']:.1f} | {flag} |"


def markdown(res: dict[str, Any]) -> str:
    head = "thigh Δ mm | shank Δ mm | centres miss mm | thigh fell back |"
    lines = [
        "# Where a sensor sits on its segment",
        "",
        "Generated by `benchmarks/sensor_placement.py`: one sensor moved on its segment (the",
        "accelerometer given α × r + ω × (ω × r)); the change of the segment lengths, how far the",
        "moved sensor's joint centres land from where they were minus the offset (worst of its two",
        "joints; the knee by its distance to the axis line), and whether the thigh was replaced by",
        "de Leva's as implausible.",
        "",
        "## Simulated rigid walks (one leg, 60 s)",
        "",
        f"| seed | move | {head}",
        "|---|---|---|---|---|---|",
    ]
    lines += [f"| {r['seed']} | {r['move']} | {_cells(r)}" for r in res["simulated"]]
    lines += [
        "",
        "## Real walk (`gait/`, one-leg trials)",
        "",
        f"| side | knee centre | move | {head}",
        "|---|---|---|---|---|---|---|",
    ]
    lines += [f"| {r['side']} | {r['knee centre']} | {r['move']} | {_cells(r)}" for r in res["real"]]
    lines += [
        "",
        "Rows marked *placed* simulate the walk again with the sensor placed 8 cm higher: there",
        "the lengths change by at most 0.2 mm and the centres follow the sensor within 1 mm, the",
        "thigh's and the shank's alike. The other rows apply the offset to the signals, as on the",
        "real walk; on the simulator that transform is good for the thigh sensor (centres within",
        "1.5 mm, lengths 0.5 mm) and costs 2–3 mm of thigh and 3–9 mm of centre for the shank",
        "sensor, whose angular acceleration at heel strike the gyro's 7-sample derivative does",
        "not follow. On the real walk a moved sensor also carries its wobble, turned about a",
        "point centimetres away, so the lengths move by up to about a tenth of the offset (the",
        "right shank 9 mm for 8 cm): an upper bound of what a real re-strapping does. Fitted from",
        "zero alone, the left knee's centre fell into a basin above the thigh sensor with that",
        "sensor 8 cm higher (the thigh replaced by de Leva's, the shank 57 mm short); the knee",
        "centre's extra starts and its anatomical check prevent it.",
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    real_data_main(__doc__, "sensor_placement", run, markdown)


if __name__ == "__main__":
    main()
