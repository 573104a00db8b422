"""``lowerlimb demo``: the whole pipeline on a built-in simulated walk, checked against its truth.

:func:`run_demo` simulates a walk, calibrates it and writes every output plus
the comparison with the truth; :func:`compare_with_truth` and
:func:`angle_rmse_deg` score any calibration against a simulation.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .conventions import ANGLE_COLUMNS, JOINT_SENSORS, FloatArray
from .errors import InputError
from .io.atomic import check_new_directory, populate_directory
from .io.tables import write_angles_csv, write_positions_csv
from .simulation import ImuNoise, Simulation, simulate

__all__ = [
    "DemoOptions",
    "angle_rmse_deg",
    "compare_with_truth",
    "run_demo",
    "fresh_directory",
    "summary_markdown",
]


@dataclass(frozen=True)
class DemoOptions:
    """What ``lowerlimb demo`` runs.

    Attributes:
        out: output folder to create (absent or empty); by default a fresh
            ``lowerlimb_demo``, ``lowerlimb_demo_2``, … in the current folder.
        duration_s: length of the simulated walk, s.
        seed: random seed of the simulation.
    """

    out: Path | None = None
    duration_s: float = 30.0
    seed: int = 1


def compare_with_truth(calibration: dict[str, Any], truth: dict[str, Any]) -> dict[str, dict[str, float]]:
    """Errors of a calibration against the simulator's truth.

    Returns:
        ``{joint: {"parent_mm", "child_mm", ["axis_deg", "axis_line_mm"]}}``:
        centre errors in each sensor frame (mm); for the hinge, the axis angle
        error (deg) and the distance of the estimated centre to the true axis line (mm).
    """
    out: dict[str, dict[str, float]] = {}
    for joint, (_, _, kind) in JOINT_SENSORS.items():
        e, t = calibration["joints"][joint], truth["joints"][joint]
        row: dict[str, float] = {}
        if kind == "hinge":
            a = np.asarray(e["axis_in_parent_sensor"])
            b = np.asarray(t["axis_in_parent_sensor"])
            row["axis_deg"] = float(
                np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1)))
            )
            for side in ("parent", "child"):
                c = np.asarray(e[f"center_in_{side}_sensor"]) - np.asarray(t[f"center_in_{side}_sensor"])
                axis = np.asarray(t[f"axis_in_{side}_sensor"])
                row[f"{side}_line_mm"] = 1e3 * float(np.linalg.norm(c - (c @ axis) * axis))
        else:
            for side in ("parent", "child"):
                c = np.asarray(e[f"center_in_{side}_sensor"]) - np.asarray(t[f"center_in_{side}_sensor"])
                row[f"{side}_mm"] = 1e3 * float(np.linalg.norm(c))
        out[joint] = row
    return out


def angle_rmse_deg(estimate: FloatArray, truth: FloatArray) -> dict[str, float]:
    """RMSE (deg) per angle column."""
    rmse = np.rad2deg(np.sqrt(np.mean((estimate - truth) ** 2, axis=0)))
    return {ANGLE_COLUMNS[1 + k]: float(v) for k, v in enumerate(rmse)}


def summary_markdown(
    sim: Simulation, calibration: dict[str, Any], angles: FloatArray, positions: FloatArray
) -> str:
    """Markdown report of a demo run against its truth."""
    lines = ["# lowerlimb demo: simulated walk, calibrated, against the truth", ""]
    lines += ["| joint | error |", "|---|---|"]
    for joint, row in compare_with_truth(calibration, sim.truth).items():
        text = ", ".join(f"{k.replace('_', ' ')} {v:.1f}" for k, v in row.items())
        lines.append(f"| {joint} | {text} |")
    lines += ["", "| angle | RMSE (deg) |", "|---|---|"]
    for name, v in angle_rmse_deg(angles, sim.angles_rad).items():
        lines.append(f"| {name} | {v:.2f} |")
    p2f = 1e3 * np.sqrt(np.mean(np.sum((positions[:, :3] - sim.positions_m[:, :3]) ** 2, axis=1)))
    h2a = 1e3 * np.sqrt(np.mean(np.sum((positions[:, 3:] - sim.positions_m[:, 3:]) ** 2, axis=1)))
    lines += ["", f"pelvis-to-foot position RMSE: {p2f:.1f} mm; hip-to-ankle: {h2a:.1f} mm", ""]
    return "\n".join(lines)


#: Stem of the demo's default output folder (in .gitignore).
DEFAULT_DEMO_DIR = "lowerlimb_demo"


def fresh_directory(base: Path) -> Path:
    """Return ``base`` if it is absent or empty, else the first absent ``base_2``, ``base_3``, …."""
    if not base.exists() or (base.is_dir() and not any(base.iterdir())):
        return base
    k = 2
    while base.with_name(f"{base.name}_{k}").exists():
        k += 1
    return base.with_name(f"{base.name}_{k}")


def run_demo(options: DemoOptions) -> None:
    """Simulate a walk, calibrate it, write all outputs plus the truth comparison into ``options.out``.

    Raises:
        InputError: ``options.out`` (when given) exists and is not empty, or the duration
            or seed is out of the range ``lowerlimb simulate`` accepts.
    """
    from .io.bounds import INPUT_BOUNDS, check_range
    from .outputs import CalibrateOptions, build_provenance, write_outputs
    from .pipeline import process_trial
    from .viz.plots import plot_angles

    check_range("--duration", options.duration_s, INPUT_BOUNDS.duration_s, "s", "the walk length")
    if not 0 <= options.seed <= INPUT_BOUNDS.max_seed:
        raise InputError(
            f"--seed {options.seed} is out of range; give an integer from 0 to {INPUT_BOUNDS.max_seed}"
        )
    out = fresh_directory(Path(DEFAULT_DEMO_DIR)) if options.out is None else Path(options.out)
    check_new_directory(out)
    print(
        f"simulating a {options.duration_s:g} s walk (seed {options.seed}, realistic noise and bias)…",
        file=sys.stderr,
    )
    sim = simulate("walk", options.duration_s, options.seed, noise=ImuNoise())
    print("calibrating…", file=sys.stderr)
    result = process_trial(sim.trial, progress=True)
    calibration = result.calibration_dict()
    summary = summary_markdown(sim, calibration, result.angles_rad, result.positions_m)

    def fill(d: Path) -> None:
        sim.trial.to_csv(d / "trial.csv")
        (d / "truth.json").write_text(json.dumps(sim.truth, indent=2), encoding="utf-8")
        write_angles_csv(d / "truth_angles.csv", sim.trial.time_s, sim.angles_rad)
        write_positions_csv(d / "truth_positions.csv", sim.trial.time_s, sim.positions_m)
        provenance = build_provenance(CalibrateOptions(trial=d / "trial.csv", out=out))
        provenance["input_file"] = str(out / "trial.csv")
        write_outputs(
            result,
            d,
            truth_angles_rad=sim.angles_rad,
            truth_positions_m=sim.positions_m,
            provenance=provenance,
        )
        (d / "summary.md").write_text(summary, encoding="utf-8")
        plot_angles(
            d / "angles.png",
            sim.trial.time_s,
            {"truth": sim.angles_rad, "lowerlimb": result.angles_rad},
            "Simulated walk: ISB joint angles, estimated vs true",
        )

    populate_directory(out, fill)
    print(summary)
    print(
        f"wrote {out}/ (trial.csv, truth.json, calibration.json, angles.csv, positions.csv, "
        f"calibrated.urdf, report.html, summary.md, angles.png)"
    )
