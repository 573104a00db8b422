"""Bland–Altman plots of a comparison, drawn as in seed paper 000, Fig. 13 (matplotlib, Agg)."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import BinaryIO

from .comparison import PairedSeries
from .statistics import QuantityAgreement


def plot_bland_altman(
    path: str | os.PathLike[str] | BinaryIO,
    stats: Sequence[QuantityAgreement],
    series: Sequence[PairedSeries],
    *,
    title: str = "",
    ncols: int = 3,
) -> None:
    """Write one PNG with a grid of Bland–Altman plots, one panel per quantity.

    Each panel, as in seed paper 000 Fig. 13: x = mean of lowerlimb and
    reference, y = difference ``lowerlimb − reference`` (docs/formats.md sign), a
    solid green line at the bias, red lines at the 95 % limits of agreement
    and a dotted purple line at zero difference. Drawn on an Agg canvas
    without pyplot, so no display and no global state are touched.

    Args:
        path: PNG file to write, or a binary file object.
        stats: statistics per quantity (the lines).
        series: the paired values per quantity (the points), same order.
        title: figure title.
        ncols: panels per row.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(stats)
    cols = max(1, min(ncols, n))
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(4.2 * cols, 3.3 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False)
    for k, (s, pair) in enumerate(zip(stats, series, strict=True)):
        ax = axes[k // cols][k % cols]
        mean = 0.5 * (pair.ours + pair.reference)
        diff = pair.ours - pair.reference
        ax.scatter(mean, diff, s=4, alpha=0.4, color="tab:blue", linewidths=0)
        ax.axhline(0.0, color="purple", linestyle=":", linewidth=1.2)
        ax.axhline(s.bias, color="green", linewidth=1.4, label=f"bias {s.bias:+.3g}")
        ax.axhline(
            s.loa_upper, color="red", linewidth=1.2, label=f"LoA {s.loa_lower:+.3g}…{s.loa_upper:+.3g}"
        )
        ax.axhline(s.loa_lower, color="red", linewidth=1.2)
        ax.set_title(f"{s.quantity} (n={s.n}, r={s.pearson_r:.2f})", fontsize=9)
        ax.set_xlabel(f"mean of lowerlimb and reference [{s.unit}]", fontsize=8)
        ax.set_ylabel(f"lowerlimb − reference [{s.unit}]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=7, loc="upper right")
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    if title:
        fig.suptitle(title)
    fig.savefig(path, dpi=110, format="png")
