"""Is the magnetometer worth fusing? A check of the field seen by all sensors of a trial.

Indoors the magnetic field near the floor is bent by steel, force plates and
treadmills; a 9-axis filter then turns each sensor's heading by a different,
changing amount (the RING recordings show field strengths varying 2× and dip
angles disagreeing by > 100° between sensors). The leg pipeline's kinematic
heading consistency (:mod:`lowerlimb.segments.heading`) works without a magnetometer,
so a disturbed field is better ignored.

The field is accepted when, for every sensor,

* its strength varies little over the trial: coefficient of variation of
  ‖m‖ ≤ :data:`MAX_STRENGTH_CV`;
* the sensors agree on the strength: largest / smallest median ‖m‖ ≤
  :data:`MAX_STRENGTH_RATIO`;
* they agree on the dip (inclination) measured while standing still at the
  start: spread ≤ :data:`MAX_DIP_SPREAD_DEG` (dip = angle of the field below
  the horizontal, from the accelerometer's "up").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import SENSORS
from ..io.trial import ImuTrial

#: Largest accepted coefficient of variation of one sensor's field strength.
MAX_STRENGTH_CV = 0.15
#: Largest accepted ratio between the sensors' median field strengths.
MAX_STRENGTH_RATIO = 1.3
#: Largest accepted spread of the dip angle between sensors at rest, deg.
MAX_DIP_SPREAD_DEG = 10.0


@dataclass(frozen=True)
class MagneticCheck:
    """Outcome of :func:`check_magnetic_field`.

    Attributes:
        usable: True when the magnetometer can be fused.
        reason: the first failed criterion, or ``""``.
        strength_cv: ``{sensor: coefficient of variation of ‖m‖}``.
        dip_deg: ``{sensor: dip at rest, deg}`` (NaN without a still start).
    """

    usable: bool
    reason: str
    strength_cv: dict[str, float]
    dip_deg: dict[str, float]


def check_magnetic_field(trial: ImuTrial, reference: slice | None = None) -> MagneticCheck:
    """Check the magnetometer of every sensor of a trial (see the module docstring).

    Args:
        trial: a trial with magnetometer data.
        reference: still samples used for the dip; default: the trial's detected
            still start (no dip check when there is none).

    Returns:
        The check; ``usable`` is False when the trial has no magnetometer.
    """
    if trial.mag is None:
        return MagneticCheck(False, "the trial has no magnetometer columns", {}, {})
    if reference is None:
        n = trial.standing_samples(0.5)
        reference = slice(0, n) if n else None
    cv: dict[str, float] = {}
    median: dict[str, float] = {}
    dip: dict[str, float] = {}
    for s in SENSORS:
        norm = np.linalg.norm(trial.mag[s], axis=1)
        median[s] = float(np.median(norm))
        cv[s] = float(np.std(norm) / max(np.mean(norm), 1e-12))
        if reference is not None:
            m = np.mean(trial.mag[s][reference], axis=0)
            up = np.mean(trial.acc[s][reference], axis=0)
            sin_dip = -float(m @ up) / max(float(np.linalg.norm(m) * np.linalg.norm(up)), 1e-12)
            dip[s] = float(np.degrees(np.arcsin(np.clip(sin_dip, -1.0, 1.0))))
        else:
            dip[s] = float("nan")
    reason = ""
    worst = max(cv, key=lambda k: cv[k])
    if median[min(median, key=lambda k: median[k])] <= 0:
        reason = "a magnetometer reads zero"
    elif cv[worst] > MAX_STRENGTH_CV:
        reason = f"the {worst} field strength varies by {100 * cv[worst]:.0f} % over the trial"
    elif max(median.values()) / min(median.values()) > MAX_STRENGTH_RATIO:
        reason = (
            f"the sensors disagree on the field strength ({min(median.values()):.3g} to "
            f"{max(median.values()):.3g})"
        )
    elif reference is not None:
        spread = max(dip.values()) - min(dip.values())
        if spread > MAX_DIP_SPREAD_DEG:
            reason = f"the sensors disagree on the dip angle by {spread:.0f}°"
    return MagneticCheck(reason == "", reason, cv, dip)
