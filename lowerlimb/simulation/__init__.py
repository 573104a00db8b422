"""The IMU simulator: the referee every estimator is tested against.

Names are imported on first use (PEP 562), so the command line can list the
motions without loading Pinocchio.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .motions import MOTIONS

__all__ = [
    "MOTIONS",
    "ArtefactTruth",
    "Artefacts",
    "BilateralSimulation",
    "ImuNoise",
    "Simulation",
    "SoftTissue",
    "simulate",
    "simulate_bilateral",
]

_EXPORTS = {
    "Artefacts": "artefacts",
    "ArtefactTruth": "artefacts",
    "ImuNoise": "noise",
    "SoftTissue": "noise",
    "BilateralSimulation": "bilateral_walk",
    "Simulation": "simulator",
    "simulate": "simulator",
    "simulate_bilateral": "bilateral_walk",
}

if TYPE_CHECKING:
    from .artefacts import Artefacts, ArtefactTruth
    from .bilateral_walk import BilateralSimulation, simulate_bilateral
    from .noise import ImuNoise, SoftTissue
    from .simulator import Simulation, simulate


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'lowerlimb.simulation' has no attribute {name!r}")
