"""Parsing of our output column names into (side, base name), for one-leg and two-leg tables."""

from __future__ import annotations

from ..conventions import Side, check_side


def split_side(name: str, side: str) -> tuple[Side, str]:
    """``"left_hip_flexion"`` -> ``("left", "hip_flexion")``; unprefixed names take ``side``.

    Two-leg tables (docs/formats.md, "Two legs") prefix every per-leg column with
    ``left_`` / ``right_``; one-leg tables do not and the trial's side applies.

    Raises:
        ValueError: when ``side`` is neither ``"left"`` nor ``"right"``.
    """
    for s in ("left", "right"):
        if name.startswith(s + "_"):
            return check_side(s), name[len(s) + 1 :]
    return check_side(side), name
