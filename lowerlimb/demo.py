"""``lowerlimb demo``: the whole pipeline on a built-in simulated walk, checked against its truth."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from .conventions import ANGLE_COLUMNS, JOINT_SENSORS, FloatArray
from .output import write_angles_csv, write_positions_csv
from .simulation import ImuNoise, Simulation, simulate


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table from a header and rows of cell strings."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def demo_parser(description: str | None, quick_help: str, default_out: Path) -> argparse.ArgumentParser:
    """The arguments every script in ``demos/`` takes: ``--out DIR`` and ``--quick``."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", type=Path, default=default_out, help="output folder (default: %(default)s)")
    parser.add_argument("--quick", action="store_true", help=quick_help)
    return parser


def demo_output(args: argparse.Namespace, name: str) -> Path:
    """``args.out / name``, created."""
    out = Path(args.out) / name
    out.mkdir(parents=True, exist_ok=True)
    return out


def plot_angles(path: Path, time_s: FloatArray, curves: dict[str, FloatArray], title: str) -> None:
    """Save a 3x3 grid of joint-angle curves to a PNG; ``curves`` maps a label to (N, 9) rad."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 3, figsize=(12, 8), sharex=True)
    for k, ax in enumerate(axes.T.ravel()):
        for label, angles in curves.items():
            ax.plot(time_s, np.rad2deg(angles[:, k]), label=label, lw=1.0)
        ax.set_title(ANGLE_COLUMNS[1 + k].replace("_", " "), fontsize=9)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    for ax in axes[:, 0]:
        ax.set_ylabel("deg")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


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


def run_demo(args: argparse.Namespace) -> None:
    """Simulate a walk, calibrate it, write all outputs plus the truth comparison into ``args.out``."""
    from .cli import populate_directory
    from .pipeline import process_trial, write_outputs

    out = Path(args.out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        from .errors import InputError

        raise InputError(f"{out} already exists and is not empty; choose a new --out directory")
    print(
        f"simulating a {args.duration:g} s walk (seed {args.seed}, realistic noise and bias)…",
        file=sys.stderr,
    )
    sim = simulate("walk", args.duration, args.seed, noise=ImuNoise())
    print("calibrating…", file=sys.stderr)
    result = process_trial(sim.trial, progress=True)
    calibration = result.calibration_dict()
    summary = summary_markdown(sim, calibration, result.angles_rad, result.positions_m)

    def fill(d: Path) -> None:
        sim.trial.to_csv(d / "trial.csv")
        (d / "truth.json").write_text(json.dumps(sim.truth, indent=2), encoding="utf-8")
        write_angles_csv(d / "truth_angles.csv", sim.trial.time_s, sim.angles_rad)
        write_positions_csv(d / "truth_positions.csv", sim.trial.time_s, sim.positions_m)
        write_outputs(result, d, truth_angles_rad=sim.angles_rad, truth_positions_m=sim.positions_m)
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
