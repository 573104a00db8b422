"""Which sensor noise biases the joint centres on simulated seven-IMU walks, and what the fixes do.

Each simulated walk (``simulate_bilateral``, 60 s) is re-measured with one noise term of
:class:`~lowerlimb.simulation.noise.ImuNoise` at a time (the walk itself is the same: the
noise is drawn after it) and each leg is calibrated (``calibrate_leg``) with

- ``before``: each sensor filtered at its own adaptive cut-off, plain eq. 7 cost
  (``shared_joint_cutoff=False, noise_correction=False``), every sample fitted;
- ``shared``: one cut-off per joint (:mod:`lowerlimb.calibration.joint_cutoff`);
- ``corrected``: shared cut-off and the errors-in-variables correction
  (:mod:`lowerlimb.calibration.noise_correction`);
- ``default``: also the samples near impacts left out of the ankle fit
  (:mod:`lowerlimb.calibration.impact_window`);
- ``impacts hip too``: the same for the hip fit (``impact_joints=("hip", "ankle")``).

Errors against the simulator's truth, mm; ``spread`` is the norm of the reported standard
deviations of the centre; ``fc`` the pelvis and thigh cut-offs the hip used, Hz.

Usage: ``python benchmarks/noise_bias.py [--seeds 201 … 206] [--duration 60] [--out DIR]``;
writes ``noise_bias.{md,json}``.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from lowerlimb.calibration._prepare import prepare_signals, rigid_band_cap_hz
from lowerlimb.calibration.joint_cutoff import joint_cutoffs_hz
from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import SIDES
from lowerlimb.simulation import ImuNoise, simulate_bilateral

ROOT = Path(__file__).resolve().parents[1]
_DEFAULT = ImuNoise()
NOISES = {
    "none": ImuNoise.none(),
    "all (realistic)": _DEFAULT,
    "gyro white only": ImuNoise(_DEFAULT.gyr_std_rps, 0.0, 0.0, 0.0),
    "acc white only": ImuNoise(0.0, _DEFAULT.acc_std_mps2, 0.0, 0.0),
    "gyro bias only": ImuNoise(0.0, 0.0, _DEFAULT.gyr_bias_rps, 0.0),
}
OPTIONS = {
    "before": CalibrationOptions(shared_joint_cutoff=False, noise_correction=False, impact_exclusion=False),
    "shared": CalibrationOptions(noise_correction=False, impact_exclusion=False),
    "corrected": CalibrationOptions(impact_exclusion=False),
    "default": CalibrationOptions(),
    "impacts hip too": CalibrationOptions(impact_joints=("hip", "ankle")),
}
#: (label, joint, key) of the scored centres.
CENTRES = (
    ("hip in thigh", "hip", "center_in_child_sensor"),
    ("hip in pelvis", "hip", "center_in_parent_sensor"),
    ("ankle in shank", "ankle", "center_in_parent_sensor"),
    ("ankle in foot", "ankle", "center_in_child_sensor"),
)


def _hip_cutoffs(trial: Any, options: CalibrationOptions) -> list[float | None]:
    """The pelvis and thigh cut-offs the hip is filtered at, Hz."""
    acc = {k: np.asarray(v) for k, v in trial.acc.items()}
    gyr = {k: np.asarray(v) for k, v in trial.gyr.items()}
    sig = prepare_signals(acc, gyr, trial.rate_hz, options)
    cap = rigid_band_cap_hz(acc["pelvis"], acc["thigh"], trial.rate_hz, options)
    return list(joint_cutoffs_hz(sig.cutoff_hz["pelvis"], sig.cutoff_hz["thigh"], cap, options))


def run(seeds: list[int], duration_s: float) -> list[dict[str, Any]]:
    """One row per seed, noise, option set and leg."""
    rows = []
    for seed in seeds:
        for noise_name, noise in NOISES.items():
            sim = simulate_bilateral(duration_s, seed, noise=noise)
            for opt_name, opts in OPTIONS.items():
                if opt_name != "before" and noise_name not in ("none", "all (realistic)"):
                    continue
                for side in SIDES:
                    trial = sim.trial.leg(side)
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        cal = calibrate_leg(trial, options=opts)
                    truth = sim.truth["legs"][side]["joints"]
                    row: dict[str, Any] = {"seed": seed, "noise": noise_name, "options": opt_name}
                    row["side"] = side
                    for label, joint, key in CENTRES:
                        j = getattr(cal, joint)
                        est = np.asarray(getattr(j, key))
                        std = np.asarray(getattr(j, key.replace("center_", "center_std_")))
                        row[label] = 1000.0 * float(np.linalg.norm(est - np.asarray(truth[joint][key])))
                        row[label + " spread"] = 1000.0 * float(np.linalg.norm(std))
                    row["fc"] = _hip_cutoffs(trial, opts)
                    rows.append(row)
            print(f"seed {seed} {noise_name}: done", flush=True)
    return rows


def markdown(rows: list[dict[str, Any]], seeds: list[int], duration_s: float, wall_s: float) -> str:
    """The summary table: median / worst over legs of each (noise, options) pair."""
    out = [
        "# Noise and the joint centres of simulated seven-IMU walks",
        "",
        f"`simulate_bilateral` seeds {', '.join(map(str, seeds))}, {duration_s:g} s each, both legs "
        f"({2 * len(seeds)} legs per row); `calibrate_leg` per leg. Errors against the truth, mm, "
        "median / worst; `covered`: legs whose error is within twice the reported spread; "
        f"`hip fc`: median pelvis / thigh cut-off of the hip, Hz. {wall_s:.0f} s.",
        "",
        "| noise | options | hip in thigh | spread | covered | hip in pelvis | ankle in shank "
        "| ankle in foot | hip fc |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault((r["noise"], r["options"]), []).append(r)
    for (noise, opt), rs in groups.items():

        def mw(key: str, rs: list[dict[str, Any]] = rs) -> str:
            v = np.array([r[key] for r in rs])
            return f"{np.median(v):.0f} / {v.max():.0f}"

        err = np.array([r["hip in thigh"] for r in rs])
        spread = np.array([r["hip in thigh spread"] for r in rs])
        fc = np.array([[np.nan if f is None else f for f in r["fc"]] for r in rs])
        out.append(
            f"| {noise} | {opt} | {mw('hip in thigh')} | {np.median(spread):.1f} | "
            f"{int(np.sum(err <= 2 * spread))}/{len(rs)} | {mw('hip in pelvis')} | {mw('ankle in shank')} | "
            f"{mw('ankle in foot')} | {np.nanmedian(fc[:, 0]):.1f} / {np.nanmedian(fc[:, 1]):.1f} |"
        )
    return "\n".join(out) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[201, 202, 203, 204, 205, 206])
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args()
    t0 = time.perf_counter()
    rows = run(args.seeds, args.duration)
    md = markdown(rows, args.seeds, args.duration, time.perf_counter() - t0)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "noise_bias.md").write_text(md)
    (args.out / "noise_bias.json").write_text(json.dumps(rows, indent=1))
    print(md)


if __name__ == "__main__":
    main()
