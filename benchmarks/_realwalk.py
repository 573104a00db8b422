"""The real overground walk of ``gait/`` (data/README.md): sensor IDs, frames, loaders.

Shared by the real-walk benchmarks (``real_gait``, ``bilateral_gait``, ``gait_events``,
``opensense``) so that each names the sensors and the scored frames once.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import scipy.io as sio

#: Xsens MTw IDs of the walk's sensors (data/README.md, gait/).
IDS: dict[str, str] = {
    "pelvis": "00B40B91",
    "left_thigh": "00B40C45",
    "right_thigh": "00B40C3C",
    "left_shank": "00B40C44",
    "right_shank": "00B40C47",
    "left_foot": "00B40C55",
    "right_foot": "00B40C48",
}
#: Standing period used to zero every angle (frames, 100 Hz).
STAND = slice(200, 1000)
#: The authors' walking window (frames).
WALK = slice(1120, 2074)


def leg_mapping(side: str) -> dict[str, str]:
    """``{pelvis, thigh, shank, foot: ID}`` of one leg, for :func:`lowerlimb.read_xsens`."""
    return {"pelvis": IDS["pelvis"]} | {s: IDS[f"{side}_{s}"] for s in ("thigh", "shank", "foot")}


def raw_dir(data: Path) -> Path:
    """The folder of the Xsens MT Manager exports."""
    return data / "gait" / "rawimu"


def load_vicon(data: Path) -> dict[str, Any]:
    """The Vicon file of the walk (joint centres in mm, lab frame z up; angles in deg)."""
    return dict(sio.loadmat(data / "gait" / "vicon" / "S02-Trial-Walk-1.mat"))
