"""Gait-cycle-normalised curves (mean ± SD per side) and a spatio-temporal table with a symmetry index.

Plain inputs, so any pipeline can call it: per side, joint angles (N, k) in
degrees on a common time base, the initial-contact times of that side, and a
dict of spatio-temporal parameters. :func:`gait_report_section` returns one
HTML section (inline PNG and table) to embed in ``report.html``
(:func:`lowerlimb.viz.report.write_report`'s ``gait_html``).

Choices:

- a stride runs from one initial contact to the next of the same side and is
  resampled by linear interpolation at :data:`CYCLE_POINTS` = 101 points
  (0, 1, …, 100 % of the cycle); a stride with a missing (NaN) sample, outside
  the recording, or longer than :data:`MAX_STRIDE_S` (a stop or a lost event)
  is left out;
- the symmetry index is SI = 2 |L − R| / |L + R| · 100 % (Robinson, Herzog &
  Nigg 1987, J. Manipulative Physiol. Ther. 10:172–176, taken unsigned); 0 %
  is perfect symmetry.
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..conventions import FloatArray
from ..errors import ShapeError

__all__ = [
    "CYCLE_POINTS",
    "gait_report_section",
    "normalise_strides",
    "parameter_table_html",
    "plot_gait_cycles",
    "symmetry_index_pct",
]

#: Samples per normalised gait cycle (0–100 % in steps of 1 %).
CYCLE_POINTS = 101
#: Longest stride kept, s (a longer gap between contacts is a stop or a missed event).
MAX_STRIDE_S = 3.0
#: Line colours: the usual gait-lab convention, left red, right blue.
SIDE_COLORS = {"left": "#d62728", "right": "#1f77b4"}


def normalise_strides(
    time_s: FloatArray, values: FloatArray, initial_contacts_s: Sequence[float]
) -> FloatArray:
    """Time-normalise each stride between consecutive initial contacts to 101 points.

    Args:
        time_s: (N,) increasing sample times, s.
        values: (N, k) signals (e.g. joint angles, deg).
        initial_contacts_s: the side's initial-contact times, s (any order).

    Returns:
        (n_strides, 101, k); ``n_strides`` may be 0.

    Raises:
        ShapeError: when ``values`` does not have N rows.
    """
    t = np.asarray(time_s, dtype=float)
    y = np.asarray(values, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    if t.ndim != 1 or y.shape[0] != t.shape[0]:
        raise ShapeError(f"values must have shape (N, k) with N = len(time_s) = {t.shape[0]}, got {y.shape}")
    ic = np.sort(np.asarray(initial_contacts_s, dtype=float))
    phase = np.linspace(0.0, 1.0, CYCLE_POINTS)
    strides = []
    for t0, t1 in zip(ic[:-1], ic[1:], strict=True):
        if t0 < t[0] or t1 > t[-1] or not 0.0 < t1 - t0 <= MAX_STRIDE_S:
            continue
        # the stride's own samples (and one either side for the interpolation), not all N
        lo = max(int(np.searchsorted(t, t0, side="left")) - 1, 0)
        hi = int(np.searchsorted(t, t1, side="right")) + 1
        ts, ys = t[lo:hi], y[lo:hi]
        if np.isnan(ys[(ts >= t0) & (ts <= t1)]).any():
            continue
        tc = t0 + phase * (t1 - t0)
        strides.append(np.column_stack([np.interp(tc, ts, ys[:, j]) for j in range(y.shape[1])]))
    return np.array(strides).reshape(len(strides), CYCLE_POINTS, y.shape[1])


def symmetry_index_pct(left: float, right: float) -> float:
    """SI = 2 |L − R| / |L + R| · 100 % (Robinson et al. 1987); NaN when undefined."""
    total = abs(left + right)
    if not np.isfinite(left) or not np.isfinite(right) or total == 0.0:
        return float("nan")
    return 200.0 * abs(left - right) / total


def plot_gait_cycles(
    time_s: FloatArray,
    angles_deg: Mapping[str, FloatArray],
    initial_contacts_s: Mapping[str, Sequence[float]],
    names: Sequence[str],
    *,
    toe_off_pct: Mapping[str, float] | None = None,
    columns: int = 3,
) -> str:
    """Mean ± SD gait-cycle curves, left and right overlaid, as a ``data:image/png;base64`` URL.

    Args:
        time_s: (N,) sample times, s.
        angles_deg: ``{side: (N, k) angles, deg}`` (one or both sides).
        initial_contacts_s: ``{side: initial-contact times, s}``.
        names: the k column names (panel titles).
        toe_off_pct: optional ``{side: mean stance %}``, drawn as a dashed line (toe-off).
        columns: panels per row; with 9 angles, one joint per column.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator, MultipleLocator

    k = len(names)
    rows = -(-k // columns)
    fig = Figure(figsize=(12.0, 2.4 * rows + 0.6))
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, columns, sharex=True, squeeze=False)
    panels = axes.T.ravel() if rows * columns == k and rows == 3 else axes.ravel()
    pct = np.linspace(0.0, 100.0, CYCLE_POINTS)
    for side, angles in angles_deg.items():
        strides = normalise_strides(time_s, angles, initial_contacts_s.get(side, ()))
        if strides.shape[0] == 0:
            continue
        mean, sd = strides.mean(axis=0), strides.std(axis=0, ddof=1 if strides.shape[0] > 1 else 0)
        color = SIDE_COLORS.get(side, "#444")
        for j, ax in enumerate(panels[:k]):
            ax.fill_between(pct, mean[:, j] - sd[:, j], mean[:, j] + sd[:, j], color=color, alpha=0.2, lw=0)
            ax.plot(pct, mean[:, j], color=color, lw=1.4, label=f"{side} (n = {strides.shape[0]})")
            if toe_off_pct is not None and np.isfinite(toe_off_pct.get(side, np.nan)):
                ax.axvline(toe_off_pct[side], color=color, ls="--", lw=0.8)
    for j, ax in enumerate(panels):
        if j >= k:
            ax.set_visible(False)
            continue
        ax.set_title(names[j].replace("_", " "), fontsize=9, y=1.0, pad=4)
        ax.xaxis.set_major_locator(MultipleLocator(20.0))
        ax.yaxis.set_major_locator(MaxNLocator(4))  # few ticks: most of the drawing time is ticks
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=8)
        ax.set_xlim(0.0, 100.0)
    for ax in axes[-1]:
        ax.set_xlabel("gait cycle (%)", fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel("deg", fontsize=8)
    if panels[0].get_legend_handles_labels()[0]:
        panels[0].legend(fontsize=8)
    fig.subplots_adjust(left=0.06, right=0.99, top=0.95, hspace=0.4, wspace=0.18)
    fig.subplots_adjust(bottom=0.5 / fig.get_figheight() + 0.02)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


#: Per-side entries that are counts, not gait parameters: no symmetry index.
_COUNTS = frozenset({"n_strides"})


def parameter_table_html(
    parameters: Mapping[str, Mapping[str, Any]], overall: Mapping[str, Any] | None = None
) -> str:
    """An HTML table: one row per parameter, left and right mean ± SD, and the symmetry index.

    Args:
        parameters: ``{"left": {name: value}, "right": {name: value}}``; a value is a
            number or ``{"mean": m, "sd": s}`` (the ``gait.json`` per-side entries).
            Names ending in ``_s``, ``_m``, ``_pct``, ``_m_s`` show their unit.
        overall: optional ``{name: value}`` of both sides together (cadence, speed,
            step width), shown in the table without a symmetry index.

    Counts (``n_strides``) are shown without a symmetry index too.
    """
    left, right = parameters.get("left", {}), parameters.get("right", {})
    names = [n for n in left if n in right] + [n for n in (*left, *right) if not (n in left and n in right)]
    rows = []
    for name in dict.fromkeys(names):
        lm, ls = _mean_sd(left.get(name))
        rm, rs = _mean_sd(right.get(name))
        if lm is None and rm is None:
            continue
        paired = lm is not None and rm is not None and name not in _COUNTS
        si = symmetry_index_pct(lm, rm) if paired else float("nan")  # type: ignore[arg-type]
        rows.append(
            f"<tr><th>{_e(_label(name))}</th><td>{_fmt(lm, ls)}</td><td>{_fmt(rm, rs)}</td>"
            f"<td>{'—' if not np.isfinite(si) else f'{si:.1f}'}</td></tr>"
        )
    for name, value in (overall or {}).items():
        m, s = _mean_sd(value)
        if m is not None:
            rows.append(f"<tr><th>{_e(_label(name))}</th><td colspan='2'>{_fmt(m, s)}</td><td></td></tr>")
    return (
        "<table class='gait-parameters' id='gait-parameters'><thead><tr><th>parameter</th>"
        "<th>left (mean ± SD)</th><th>right (mean ± SD)</th><th>SI (%)</th></tr></thead><tbody>"
        + "".join(rows)
        + "</tbody></table>"
    )


def gait_report_section(
    time_s: FloatArray,
    angles_deg: Mapping[str, FloatArray],
    initial_contacts_s: Mapping[str, Sequence[float]],
    names: Sequence[str],
    parameters: Mapping[str, Mapping[str, Any]] | None = None,
    overall: Mapping[str, Any] | None = None,
) -> str:
    """The HTML section for ``report.html``: gait-cycle curves and, when given, the parameter table.

    Args are as in :func:`plot_gait_cycles` and :func:`parameter_table_html`; the
    dashed toe-off lines come from each side's ``stance_pct`` when present.
    """
    toe_off: dict[str, float] = {}
    for side, params in (parameters or {}).items():
        mean, _ = _mean_sd(params.get("stance_pct"))
        if mean is not None:
            toe_off[side] = mean
    png = plot_gait_cycles(time_s, angles_deg, initial_contacts_s, names, toe_off_pct=toe_off)
    counts = {
        side: normalise_strides(time_s, a, initial_contacts_s.get(side, ())).shape[0]
        for side, a in angles_deg.items()
    }
    parts = [
        "<section id='gait-cycles'>",
        "<h2>Gait cycles</h2>",
        "<p class='note'>Each stride from initial contact to the next of the same side, "
        f"time-normalised to {CYCLE_POINTS} points; line: mean, band: ± 1 SD; dashed: mean toe-off. "
        "Strides: " + ", ".join(f"{_e(s)} {n}" for s, n in counts.items()) + ".</p>",
        f"<img class='plot' id='gait-cycles-plot' alt='gait-cycle joint angles (deg)' src='{png}'>",
    ]
    if parameters:
        parts += [
            "<h3>Spatio-temporal parameters</h3>",
            parameter_table_html(parameters, overall),
            "<p class='note'>SI = 2 |L − R| / (L + R) · 100 % (Robinson, Herzog &amp; Nigg 1987); "
            "0 % is perfect symmetry.</p>",
        ]
    parts.append("</section>")
    return "\n".join(parts)


def _mean_sd(value: Any) -> tuple[float | None, float | None]:
    if value is None:
        return None, None
    if isinstance(value, Mapping):
        mean, sd = value.get("mean"), value.get("sd")
        if mean is None or not np.isfinite(float(mean)):
            return None, None
        return float(mean), None if sd is None else float(sd)
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None, None
    return (x, None) if np.isfinite(x) else (None, None)


def _fmt(mean: float | None, sd: float | None) -> str:
    if mean is None:
        return "—"
    text = f"{mean:.3g}"
    if sd is not None and np.isfinite(sd):
        text += f" ± {sd:.2g}"
    return text


_UNITS = (("_steps_per_min", "steps/min"), ("_m_s", "m/s"), ("_pct", "%"), ("_s", "s"), ("_m", "m"))


def _label(name: str) -> str:
    for suffix, unit in _UNITS:
        if name.endswith(suffix):
            return f"{name[: -len(suffix)].replace('_', ' ')} ({unit})"
    return name.replace("_", " ")


def _e(text: object) -> str:
    return html.escape(str(text), quote=True)
