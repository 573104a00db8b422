"""lowerlimb: wearable IMU motion capture of the human leg.

Public API (DESIGN.md): :func:`estimate_orientation`, :func:`estimate_hinge_axis`,
:func:`estimate_joint_center`, plus :class:`ImuTrial`, :class:`LegModel` and
:func:`simulate`.
"""

from __future__ import annotations

__version__ = "0.1.0"

from .errors import InputError, LowerLimbError
from .leg_model import LegModel
from .simulation import ImuNoise, simulate
from .trial import ImuTrial

__all__ = [
    "ImuNoise",
    "ImuTrial",
    "InputError",
    "LegModel",
    "LowerLimbError",
    "__version__",
    "simulate",
]
