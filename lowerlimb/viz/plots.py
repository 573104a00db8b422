"""Static plots of joint angles (matplotlib, no display needed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lowerlimb.conventions import ANGLE_COLUMNS, FloatArray

__all__ = ["plot_angles"]


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
