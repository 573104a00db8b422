"""The report's table of the walker's turns (gait.json ``turns``, :mod:`lowerlimb.gait.turns`)."""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["turns_table_html"]


def turns_table_html(turns: Sequence[Mapping[str, Any]]) -> str:
    """An HTML section listing each turn (``""`` without turns).

    Args:
        turns: gait.json's ``turns["list"]`` rows: ``start_s``, ``end_s``, ``duration_s`` (s),
            ``angle_deg`` (positive to the left), ``direction``, ``peak_rate_deg_s``, ``steps``,
            ``complete``.
    """
    if not turns:
        return ""
    rows = []
    for t in turns:
        cut = "" if t.get("complete", True) else " (cut by the recording)"
        rows.append(
            f"<tr><td>{t['start_s']:.2f}–{t['end_s']:.2f}</td><td>{t['duration_s']:.2f}</td>"
            f"<td>{abs(t['angle_deg']):.0f} {html.escape(str(t['direction']))}{cut}</td>"
            f"<td>{t['peak_rate_deg_s']:.0f}</td><td>{t['steps']}</td></tr>"
        )
    return (
        "<section id='turns'><h2>Turns</h2><p class='note'>Where the walker turned, from the pelvis "
        "sensor's rate about the vertical averaged over a stride; turning strides and steps are "
        "summarised apart from the straight ones.</p>"
        "<table class='gait-parameters' id='turns-table'><thead><tr><th>time (s)</th><th>duration (s)</th>"
        "<th>angle (°)</th><th>peak rate (°/s)</th><th>steps</th></tr></thead><tbody>"
        + "".join(rows)
        + "</tbody></table></section>"
    )
