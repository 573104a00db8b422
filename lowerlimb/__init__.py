"""lowerlimb: wearable IMU motion capture of the human leg.

Public API (docs/architecture.md): :func:`estimate_orientation`, :func:`estimate_hinge_axis`,
:func:`estimate_joint_center`; the whole pipeline :func:`process_trial`; and
:class:`ImuTrial`, :class:`LegModel`, :func:`simulate`; vendor recordings
:func:`read_xsens`, :func:`read_mapped_csv`.

Attributes are imported on first use (PEP 562): ``import lowerlimb`` is
cheap, and each name pulls in only its own module.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.5.16"

_EXPORTS = {
    "calibrate_leg": "calibration",
    "estimate_hinge_axis": "calibration",
    "estimate_joint_center": "calibration",
    "InputError": "errors",
    "LowerLimbError": "errors",
    "LegModel": "model.leg_model",
    "estimate_orientation": "orientation",
    "load_calibrated": "outputs",
    "process_trial": "pipeline",
    "process_study": "batch",
    "ImuNoise": "simulation",
    "simulate": "simulation",
    "ImuTrial": "io.trial",
    "read_mapped_csv": "io",
    "read_xsens": "io",
}

__all__ = [
    "ImuNoise",
    "ImuTrial",
    "InputError",
    "LegModel",
    "LowerLimbError",
    "__version__",
    "calibrate_leg",
    "estimate_hinge_axis",
    "estimate_joint_center",
    "estimate_orientation",
    "load_calibrated",
    "process_study",
    "process_trial",
    "read_mapped_csv",
    "read_xsens",
    "simulate",
]

if TYPE_CHECKING:
    from .batch import process_study
    from .calibration import calibrate_leg, estimate_hinge_axis, estimate_joint_center
    from .errors import InputError, LowerLimbError
    from .io import read_mapped_csv, read_xsens
    from .io.trial import ImuTrial
    from .model.leg_model import LegModel
    from .orientation import estimate_orientation
    from .outputs import load_calibrated
    from .pipeline import process_trial
    from .simulation import ImuNoise, simulate


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'lowerlimb' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_EXPORTS))
