"""Two legs from seven IMUs (docs/formats.md, "Two legs"): both legs calibrated on one pelvis sensor.

:func:`process_bilateral_trial` runs the single-leg pipeline on each leg
(:mod:`lowerlimb.bilateral.process`), checks the two hip centres together
(:mod:`lowerlimb.bilateral.hips`) and computes gait events and parameters
(:mod:`lowerlimb.bilateral.gait`). Writing the result folder is
:mod:`lowerlimb.outputs_bilateral`.
"""

from lowerlimb.bilateral.gait import (
    BilateralGait,
    CutFootGyroWarning,
    NoGaitWarning,
    UnanchoredFeetWarning,
    analyse_gait,
    chain_anchor,
)
from lowerlimb.bilateral.hips import HipCheck, HipParams, HipSpacingWarning, check_hips
from lowerlimb.bilateral.process import BilateralResult, BilateralSideError, process_bilateral_trial

__all__ = [
    "BilateralGait",
    "BilateralResult",
    "BilateralSideError",
    "CutFootGyroWarning",
    "HipCheck",
    "HipParams",
    "HipSpacingWarning",
    "UnanchoredFeetWarning",
    "NoGaitWarning",
    "analyse_gait",
    "chain_anchor",
    "check_hips",
    "process_bilateral_trial",
]
