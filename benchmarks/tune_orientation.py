"""Choose the default parameters of the orientation filters (issue 4), scored on held-out data.

Coordinate search over a small grid per parameter: starting from the current
defaults, each parameter in turn takes the grid value that minimises the
cost with the others held, for ``--passes`` rounds. The cost is the mean of
four means (degrees): BROAD 9-axis and 6-axis total RMSE, and simulated trials
9-axis and 6-axis total RMSE — one global parameter set per filter, general
rather than per trial.

Tuning and scoring use disjoint data (issue 10): the search sees only the
tuning split (:data:`BROAD_TUNE` and :data:`SIM_TUNE`, the simulated trials of
``benchmarks/orientation.py``); the library defaults and the tuned parameters
are then both scored on the held-out split (:data:`BROAD_HELD_OUT`, fresh
simulated seeds :data:`SIM_HELD_OUT`). Only a clearly better held-out score
justifies changing a default.

Usage: ``python benchmarks/tune_orientation.py --data DIR [--methods mahony ftecf] [--passes 2]``
Writes ``orientation_tuning.json`` into ``--out`` (default ``benchmarks/results``)
and prints the chosen parameters with both scores.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np
from orientation import SIM_TRIALS, Trial, evaluate, load_broad, mean_metrics, simulated_trials

from lowerlimb.orientation.estimate import FILTERS

#: BROAD development trials the search sees (one of each kind: slow/fast rotation,
#: translation, disturbance) ...
BROAD_TUNE = (
    "01_undisturbed_slow_rotation_A",
    "06_undisturbed_fast_rotation_A",
    "10_undisturbed_slow_translation_A",
    "24_disturbed_tapping_A",
)
#: ... and the ones only used to score the result.
BROAD_HELD_OUT = (
    "02_undisturbed_slow_rotation_B",
    "07_undisturbed_fast_rotation_B",
    "15_undisturbed_fast_translation_A",
    "30_disturbed_stationary_magnet_C",
)
#: Simulated trials of the search (the benchmark's seeds 1-4) and fresh held-out seeds 5-8.
SIM_TUNE = SIM_TRIALS
SIM_HELD_OUT = (("walk", 60.0, 5), ("walk", 60.0, 6), ("squat", 30.0, 7), ("knee-lift", 30.0, 8))

GRIDS: dict[str, dict[str, list[float]]] = {
    "mahony": {
        "kp": [0.1, 0.2, 0.3, 0.4, 0.5, 0.8],
        "acc_lowpass_s": [0.0, 0.5, 1.0, 2.0, 4.0],
        "kp_mag": [0.01, 0.02, 0.05, 0.1],
        "ki": [0.0, 0.001, 0.003, 0.01],
    },
    "madgwick": {
        "beta": [0.003, 0.005, 0.007, 0.01, 0.015, 0.02, 0.03, 0.05, 0.1],
        "acc_lowpass_s": [0.0, 0.5, 1.0, 2.0, 3.0, 4.0],
    },
    "ftecf": {
        "gain_a_per_s": [0.02, 0.05, 0.1, 0.2, 0.3, 0.4],
        "gain_max_per_s": [0.5, 1.0, 2.0, 5.0],
        "e1_a": [0.002, 0.005, 0.01, 0.02],
        "e1_b": [0.02, 0.05, 0.1, 0.2],
        "acc_tol_mps2": [0.1, 0.3, 0.5, 1.0, 2.0],
        "gyr_tol_rad_s": [math.radians(10.0), 0.5, 1.0, 2.0, 5.0],
        "mag_weight": [0.02, 0.1, 0.3, 0.5],
        "acc_lowpass_s": [0.0, 0.5, 1.0, 2.0, 3.0, 4.0],
    },
    "quest_kf": {
        "quest_std": [0.03, 0.1, 0.3, 1.0, 3.0],
        "quat_process_std": [0.0003, 0.001, 0.003, 0.01],
        "rate_var": [1.0, 10.0, 100.0],
        "acc_tol_mps2": [0.1, 0.3, 1.0, 2.0],
        "gyr_tol_rad_s": [math.radians(10.0), 1.0, 2.0, 5.0],
        "mag_weight": [0.02, 0.1, 0.3, 0.5],
    },
}


def cost(method: str, params: Any, broad: list[Trial], sims: list[Trial]) -> tuple[float, dict]:
    """Tuning cost (deg) and its four parts."""
    parts = {}
    for group, trials in (("broad", broad), ("sim", sims)):
        for use_mag in (True, False):
            if trials:
                rows = evaluate(trials, method, use_mag, params)
                parts[f"{group}/{'9D' if use_mag else '6D'}"] = mean_metrics(rows)["total_deg"]
    return float(np.mean(list(parts.values()))), parts


def tune(method: str, broad: list[Trial], sims: list[Trial], passes: int) -> dict[str, Any]:
    """Coordinate search for one method on the tuning split."""
    params = FILTERS[method][1]()
    best, parts = cost(method, params, broad, sims)
    history = [{"params": asdict(params), "cost": best, "parts": parts}]
    print(f"{method}: defaults {best:.3f} {parts}", flush=True)
    for _ in range(passes):
        changed = False
        for name, grid in GRIDS[method].items():
            for value in grid:
                if value == getattr(params, name):
                    continue
                trial_params = replace(params, **{name: value})
                c, p = cost(method, trial_params, broad, sims)
                history.append({"params": asdict(trial_params), "cost": c, "parts": p})
                if c < best - 1e-4:
                    best, parts, params, changed = c, p, trial_params, True
                    print(f"  {name}={value}: {best:.3f} {parts}", flush=True)
        if not changed:
            break
    print(f"{method}: best {best:.3f} with {asdict(params)}", flush=True)
    return {
        "defaults": history[0],
        "best_params": asdict(params),
        "best_cost": best,
        "parts": parts,
        "history": history,
    }


def split(broad: list[Trial], names: tuple[str, ...]) -> list[Trial]:
    """The BROAD trials of one split (all of them must be present)."""
    by_name = {t.name: t for t in broad}
    missing = [n for n in names if n not in by_name]
    if missing:
        raise SystemExit(f"BROAD trials missing from the data folder: {missing}")
    return [by_name[n] for n in names]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--out", type=Path, default=Path("benchmarks/results"))
    ap.add_argument("--methods", nargs="+", default=list(GRIDS))
    ap.add_argument("--passes", type=int, default=2)
    args = ap.parse_args()
    broad = load_broad(args.data)
    broad_tune, broad_held = split(broad, BROAD_TUNE), split(broad, BROAD_HELD_OUT)
    sims_tune, sims_held = simulated_trials(SIM_TUNE), simulated_trials(SIM_HELD_OUT)
    t0 = time.perf_counter()
    out: dict[str, Any] = {
        "splits": {
            "tune": {"broad": list(BROAD_TUNE), "sim": [list(s) for s in SIM_TUNE]},
            "held_out": {"broad": list(BROAD_HELD_OUT), "sim": [list(s) for s in SIM_HELD_OUT]},
        }
    }
    for m in args.methods:
        result = tune(m, broad_tune, sims_tune, args.passes)
        defaults = FILTERS[m][1]()
        tuned = replace(defaults, **result["best_params"])
        for label, params in (("defaults", defaults), ("tuned", tuned)):
            c, p = cost(m, params, broad_held, sims_held)
            result[f"held_out_{label}"] = {"cost": c, "parts": p}
        print(
            f"{m}: held-out cost defaults {result['held_out_defaults']['cost']:.3f}, "
            f"tuned {result['held_out_tuned']['cost']:.3f}",
            flush=True,
        )
        out[m] = result
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "orientation_tuning.json"
    old = json.loads(path.read_text()) if path.exists() else {}
    old = {k: v for k, v in old.items() if k in out or "held_out_defaults" in v}
    old.update(out)
    path.write_text(json.dumps(old, indent=2))
    print(f"done in {time.perf_counter() - t0:.0f} s; wrote {path}")


if __name__ == "__main__":
    main()
