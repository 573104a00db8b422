"""The agreement section of ``report.html`` (``calibrate --reference``): table and Bland–Altman plots.

The section is self-contained HTML (plots inline as PNG data URLs), handed to
:func:`lowerlimb.viz.report.write_report` as an extra section. The statistics are
those of ``lowerlimb compare`` without time alignment or offset removal.
"""

from __future__ import annotations

import base64
import html
import io
import math
import os
from pathlib import Path

import numpy as np

from ..conventions import ANGLE_COLUMNS, POSITION_COLUMNS, FloatArray
from ..io.tables import ANGLE_UNIT, POSITION_UNIT
from .bland_altman import plot_bland_altman
from .comparison import Comparison, compare_series
from .files import Table, read_reference_table

#: Our columns of a one-leg result folder and their units.
RESULT_COLUMN_UNITS: dict[str, str] = {c: ANGLE_UNIT for c in ANGLE_COLUMNS[1:]} | {
    c: POSITION_UNIT for c in POSITION_COLUMNS[1:]
}
_GROUPS = {ANGLE_UNIT: "Joint angles", POSITION_UNIT: "Positions"}


def read_reference(
    path: str | os.PathLike[str], time_s: FloatArray | None = None, side: str | None = None
) -> Table:
    """Read a reference CSV and check that it shares a column with ``angles.csv``/``positions.csv``.

    ``time_s``, (N,) our sample times, s, when known, is quoted in a time-unit error; ``side``, the
    leg calibrated, names a reference of the other leg as such.

    Raises:
        FileNotFoundError: the file does not exist.
        InputError: not a UTF-8 table with a ``time`` column, a column named twice, time not
            strictly increasing or in ms (:func:`~lowerlimb.agreement.files.read_reference_table`).
        NoCommonColumnsError: none of its columns is one of ours (checked before the time).
    """
    return read_reference_table(path, our_columns=list(RESULT_COLUMN_UNITS), time_s=time_s, side=side)


def compare_result(
    time_s: FloatArray, angles_rad: FloatArray, positions_m: FloatArray, reference: Table
) -> Comparison:
    """Compare a processed trial's angles (deg) and positions (m) with a reference table.

    Args:
        time_s: (N,) our sample times, s.
        angles_rad: (N, 9) ISB joint angles, rad, ``angles.csv`` order.
        positions_m: (N, 6) positions, m, ``positions.csv`` order.
        reference: the table of :func:`read_reference` (deg and m, columns named as ours).

    Raises:
        InputError: as :func:`~lowerlimb.agreement.compare_series` (no overlap, no valid pairs…).
    """
    deg = np.rad2deg(angles_rad)
    ours = {c: deg[:, k] for k, c in enumerate(ANGLE_COLUMNS[1:])}
    ours |= {c: positions_m[:, k] for k, c in enumerate(POSITION_COLUMNS[1:])}
    return compare_series(time_s, ours, RESULT_COLUMN_UNITS, reference.time_s, reference.columns)


def agreement_section_html(comparison: Comparison, reference_name: str = "") -> str:
    """The ``<section id="agreement">`` of the report: statistics table and Bland–Altman plots."""
    e = html.escape
    source = f" ({e(Path(reference_name).name)})" if reference_name else ""
    head = "".join(
        f"<th>{h}</th>"
        for h in ("quantity", "unit", "n", "RMSE", "bias", "95 % limits of agreement", "Pearson r", "CMC")
    )
    rows = "".join(
        f"<tr><th>{e(s.quantity)}</th><td>{e(s.unit)}</td><td>{s.n}</td><td>{_g(s.rmse)}</td>"
        f"<td>{_g(s.bias, signed=True)}</td><td>{_g(s.loa_lower, signed=True)} … "
        f"{_g(s.loa_upper, signed=True)}</td><td>{_g(s.pearson_r)}</td><td>{_g(s.cmc)}</td></tr>"
        for s in comparison.quantities
    )
    plots = []
    for unit, title in _GROUPS.items():
        idx = [i for i, s in enumerate(comparison.quantities) if s.unit == unit]
        if idx:
            buf = io.BytesIO()
            plot_bland_altman(
                buf,
                [comparison.quantities[i] for i in idx],
                [comparison.series[i] for i in idx],
                title=f"{title}: lowerlimb vs reference",
            )
            data = base64.b64encode(buf.getvalue()).decode("ascii")
            plots.append(
                f"<img class='plot' id='bland-altman-{unit}' alt='Bland–Altman plots, {e(title.lower())}' "
                f"src='data:image/png;base64,{data}'>"
            )
    notes = []
    if comparison.skipped:
        notes.append(f"Too few valid pairs, not compared: {e(', '.join(comparison.skipped))}.")
    if comparison.ignored_reference_columns:
        notes.append(f"Reference columns not ours: {e(', '.join(comparison.ignored_reference_columns))}.")
    return (
        "<section id='agreement'><h2>Agreement with the reference</h2>"
        f"<p class='note'>lowerlimb − reference{source}, reference linearly interpolated onto our time "
        "stamps over the overlap; no time alignment and no offset removal (use <code>lowerlimb compare "
        "--align-time --remove-offset</code> for those). Limits of agreement = bias ± 1.96 SD "
        "(Bland &amp; Altman 1986); CMC: Ferrari et al. 2010.</p>"
        f"<table class='errors' id='agreement-table'><thead><tr>{head}</tr></thead><tbody>{rows}</tbody>"
        "</table>" + "".join(f"<p class='note'>{n}</p>" for n in notes) + "".join(plots) + "</section>"
    )


def _g(v: float, signed: bool = False) -> str:
    if not math.isfinite(v):
        return "—"
    return f"{v:+.3g}" if signed else f"{v:.3g}"
