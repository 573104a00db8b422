"""The files of a result folder (of `calibrate`, and of each trial of `batch`), by short name."""

from __future__ import annotations

from collections.abc import Collection

from lowerlimb.errors import InputError

__all__ = ["OUTPUT_FILES", "check_outputs"]

#: The files of a result folder, by the short name ``--outputs`` takes (docs/formats.md).
OUTPUT_FILES: dict[str, str] = {
    "calibration": "calibration.json",
    "angles": "angles.csv",
    "positions": "positions.csv",
    "s2j": "s2j.json",
    "urdf": "calibrated.urdf",
    "report": "report.html",
}


def check_outputs(names: Collection[str]) -> frozenset[str]:
    """The set of output short names, checked against :data:`OUTPUT_FILES`.

    ``names`` may also be one string, a name or a comma-separated list as ``--outputs`` takes
    it (``"angles"``, ``"calibration,angles"``), not split into its letters.

    Raises:
        InputError: an unknown name, or none at all; the message lists the accepted ones.
    """
    if isinstance(names, str):
        names = [n.strip() for n in names.split(",") if n.strip()]
    unknown = sorted(set(names) - set(OUTPUT_FILES))
    if unknown or not names:
        what = f"unknown output {', '.join(map(repr, unknown))}" if unknown else "no output chosen"
        raise InputError(f"{what}; choose among {', '.join(OUTPUT_FILES)}")
    return frozenset(names)
