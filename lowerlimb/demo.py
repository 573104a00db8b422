"""``lowerlimb demo``: the whole pipeline on a built-in simulated walk, checked against its truth."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from .conventions import ANGLE_COLUMNS
from .output import write_angles_csv, write_positions_csv
from .simulation import ImuNoise, simulate


def plot_angles(path: Path, time_s: np.ndarray, curves: dict[str, np.ndarray], title: str) -> None:
    """Save a 3x3 grid of joint-angle curves (degrees) to a PNG; ``curves`` maps a label to (N, 9) rad."""
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


def run_demo(args: argparse.Namespace) -> None:
    """Simulate a walk; write the trial, its truth and a plot into ``args.out``."""
    from .cli import populate_directory

    out = Path(args.out)
    sim = simulate("walk", args.duration, args.seed, noise=ImuNoise())

    def fill(d: Path) -> None:
        sim.trial.to_csv(d / "trial.csv")
        (d / "truth.json").write_text(json.dumps(sim.truth, indent=2), encoding="utf-8")
        write_angles_csv(d / "truth_angles.csv", sim.trial.time_s, sim.angles_rad)
        write_positions_csv(d / "truth_positions.csv", sim.trial.time_s, sim.positions_m)
        plot_angles(
            d / "angles.png",
            sim.trial.time_s,
            {"truth": sim.angles_rad},
            "Simulated walk: true ISB angles",
        )

    populate_directory(out, fill)
    print(f"simulated a {args.duration:g} s walk (seed {args.seed}) in {sim.runtime_s:.2f} s")
    print(f"wrote {out}/trial.csv, truth.json, truth_angles.csv, truth_positions.csv, angles.png")
