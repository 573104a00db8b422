"""End-to-end accuracy of ``lowerlimb calibrate`` on simulated trials (issue 5).

For each seed: simulate a trial with realistic noise and gyro bias, run the
whole pipeline (joint-constraint calibration, orientation filter, heading
consistency, segment frames, ISB angles, Pinocchio FK positions) exactly as
the command line does, and compare with the simulator's truth: joint-angle
RMSE per degree of freedom over the whole trial, and pelvis-to-foot /
hip-to-ankle position RMSE. 6-axis (magnetometer ignored) and 9-axis.

Usage: ``python benchmarks/pipeline_accuracy.py [--seeds 5] [--duration 60] [--quick]``
Writes ``benchmarks/results/pipeline_accuracy.{md,json}``.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path

import numpy as np

from lowerlimb.conventions import ANGLE_COLUMNS
from lowerlimb.pipeline import process_trial
from lowerlimb.simulation import Artefacts, ImuNoise, simulate

GOALS_DEG = {"hip_flexion": 2.0, "knee_flexion": 2.0, "ankle_dorsiflexion": 2.0}
OTHER_GOAL_DEG = 3.0
POSITION_GOAL_MM = 20.0


def run(
    motions: list[str], seeds: int, duration: float, filters: list[str], artefacts: bool = False
) -> dict[str, object]:
    rows: list[dict[str, object]] = []
    for motion in motions:
        for filter_name in filters:
            for use_mag in (False, True):
                for seed in range(seeds):
                    sim = simulate(
                        motion,
                        duration,
                        100 + seed,
                        side="left" if seed % 2 == 0 else "right",
                        noise=ImuNoise(),
                        artefacts=Artefacts.real_walk() if artefacts else None,
                    )
                    t0 = time.perf_counter()
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        res = process_trial(sim.trial, filter_name=filter_name, use_mag=use_mag)
                    wall = time.perf_counter() - t0
                    err = res.angles_rad - sim.angles_rad
                    rmse = np.rad2deg(np.sqrt(np.mean(err**2, axis=0)))
                    pos = res.positions_m - sim.positions_m
                    p2f = 1e3 * np.sqrt(np.mean(np.sum(pos[:, :3] ** 2, axis=1)))
                    h2a = 1e3 * np.sqrt(np.mean(np.sum(pos[:, 3:] ** 2, axis=1)))
                    rows.append(
                        {
                            "motion": motion,
                            "filter": filter_name,
                            "axes": 9 if use_mag else 6,
                            "seed": 100 + seed,
                            "angle_rmse_deg": dict(zip(ANGLE_COLUMNS[1:], rmse.tolist(), strict=True)),
                            "pelvis_to_foot_rmse_mm": p2f,
                            "hip_to_ankle_rmse_mm": h2a,
                            "calibration_runtime_s": res.calibration.runtime_s,
                            "pipeline_wall_s": wall,
                        }
                    )
                    print(
                        f"{motion} {filter_name} {9 if use_mag else 6}-axis seed {100 + seed}: "
                        f"max angle RMSE {rmse.max():.2f} deg, pelvis-foot {p2f:.1f} mm, {wall:.2f} s"
                    )
    return {"duration_s": duration, "seeds": seeds, "rows": rows}


def to_markdown(result: dict[str, object]) -> str:
    rows = result["rows"]
    assert isinstance(rows, list)
    groups: dict[tuple[str, str, int], list[dict[str, object]]] = {}
    for r in rows:
        groups.setdefault((r["motion"], r["filter"], r["axes"]), []).append(r)
    names = list(ANGLE_COLUMNS[1:])
    short = [
        n.replace("internal_rotation", "rot").replace("dorsiflexion", "dflex").replace("_", " ")
        for n in names
    ]
    lines = [
        f"# End-to-end accuracy on simulated trials ({result['duration_s']} s, 100 Hz, noise + bias)",
        "",
        "Median over seeds of the whole-trial RMSE (deg; positions mm); worst seed in brackets.",
        f"Goals: flexion/dorsiflexion <= 2 deg, others <= {OTHER_GOAL_DEG} deg, "
        f"pelvis-foot <= {POSITION_GOAL_MM} mm.",
        "",
        "| motion | filter | axes | " + " | ".join(short) + " | pelvis-foot mm | hip-ankle mm | wall s |",
        "|---|---|---|" + "---|" * (len(names) + 3),
    ]
    for (motion, filt, axes), rs in groups.items():
        cells = []
        for n in names:
            v = np.array([r["angle_rmse_deg"][n] for r in rs])  # type: ignore[index]
            cells.append(f"{np.median(v):.2f} ({v.max():.2f})")
        p = np.array([r["pelvis_to_foot_rmse_mm"] for r in rs], dtype=float)
        h = np.array([r["hip_to_ankle_rmse_mm"] for r in rs], dtype=float)
        w = np.array([r["pipeline_wall_s"] for r in rs], dtype=float)
        lines.append(
            f"| {motion} | {filt} | {axes} | "
            + " | ".join(cells)
            + f" | {np.median(p):.1f} ({p.max():.1f}) | {np.median(h):.1f} ({h.max():.1f})"
            + f" | {np.median(w):.2f} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--motions", default="walk")
    ap.add_argument("--filters", default="mahony")
    ap.add_argument("--quick", action="store_true", help="2 seeds, 30 s")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    ap.add_argument(
        "--artefacts", action="store_true", help="add the real-walk artefacts (simulate --artefacts real)"
    )
    ap.add_argument("--name", default="pipeline_accuracy")
    args = ap.parse_args()
    seeds, duration = (2, 30.0) if args.quick else (args.seeds, args.duration)
    result = run(args.motions.split(","), seeds, duration, args.filters.split(","), args.artefacts)
    md = to_markdown(result)
    if args.artefacts:
        md = "**With the simulator's real-walk artefacts** (`simulate --artefacts real`).\n\n" + md
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / f"{args.name}.json").write_text(json.dumps(result, indent=1))
    (args.out / f"{args.name}.md").write_text(md)
    print(md)


if __name__ == "__main__":
    main()
