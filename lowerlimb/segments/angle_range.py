"""Joint angles that no leg holds: a warning naming the joint, the angle and the likely causes.

Every angle is zero in the standing reference posture, so while the leg moves each one's
*median* stays within a few tens of degrees of zero: a walk's rotations and ab/adductions
within ±10° (the real walk of ``gait/``: at most 17°), its flexions within 0–40°; a squat
or a sitting period moves the flexions' median further, never the rotations'. A median
far beyond that says the segment frames disagree: a sensor mapped to the wrong segment,
an axis or sign inverted that no other check caught, a sensor that slipped, or a standing
start that was not the reference posture. Only samples in which the shank turns faster
than :attr:`AngleRangeParams.moving_rate_rps` count (a recording's standing periods, at
zero by construction, would otherwise hide a walk's error). The limits are drawn from the
normal ranges of motion (American Academy of Orthopaedic Surgeons 1965, as tabulated by
Norkin & White, *Measurement of Joint Motion*, 5th ed., 2016: hip rotation 45° each way,
hip abduction 45° / adduction 30°, ankle inversion 35° / eversion 20°): a median is held
to about two thirds of them, the flexions to what sitting and deep squats reach, and a
moving knee or hip does not sit hyperextended.

Measured (moving medians, ``benchmarks/results/sign_check.md`` for the cases): with one
sensor's accelerometer negated along straight simulated walks, where the sign check
(:mod:`lowerlimb.orientation.sign_check`) sees too little turning to decide, hip rotation
reached ±59 … ±125° (pelvis or thigh negated) and ankle rotation ±32 … ±61° (shank or
foot negated); the unmodified walks stay within ±12°, except one artefact walk's right hip
at +34°, which this warning then flags (its hip rotation is that far from the truth).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lowerlimb.conventions import JOINT_DOF_NAMES, JOINTS, FloatArray

__all__ = ["AngleRangeParams", "ImplausibleAnglesWarning", "implausible_angles"]


def _default_limits() -> dict[str, tuple[float, float]]:
    return {
        "hip_flexion": (-20.0, 110.0),
        "hip_adduction": (-30.0, 25.0),
        "hip_internal_rotation": (-30.0, 30.0),
        "knee_flexion": (-10.0, 130.0),
        "knee_adduction": (-25.0, 25.0),
        "knee_internal_rotation": (-30.0, 30.0),
        "ankle_dorsiflexion": (-45.0, 30.0),
        "ankle_inversion": (-25.0, 30.0),
        "ankle_internal_rotation": (-30.0, 30.0),
    }


@dataclass(frozen=True)
class AngleRangeParams:
    """Limits of each angle's median while the leg moves, deg (lower, upper; clinical signs).

    Attributes:
        median_limits_deg: ``{angle name: (lower, upper)}`` (module docstring for the source).
        moving_rate_rps: a sample counts when the shank's angular rate exceeds this, rad/s
            (walking: 1–6 rad/s through most of the stride).
        min_samples: fewer moving samples than this are not judged.
    """

    median_limits_deg: dict[str, tuple[float, float]] = field(default_factory=_default_limits)
    moving_rate_rps: float = 1.0
    min_samples: int = 50


class ImplausibleAnglesWarning(UserWarning):
    """A joint angle's median over the trial lies beyond what a leg holds."""


def implausible_angles(
    angles_rad: FloatArray, shank_gyr: FloatArray, params: AngleRangeParams | None = None
) -> list[str]:
    """Messages for the angles whose median while moving is out of range (empty: all plausible).

    Args:
        angles_rad: (N, 9) ISB joint angles of one leg, angles.csv order, rad.
        shank_gyr: (N, 3) the shank's angular rate, sensor frame, rad/s (what "moving" means).
        params: the limits (defaults when ``None``).

    Returns:
        One message per implausible angle, naming it, its median and the limits.
    """
    p = params or AngleRangeParams()
    moving = np.linalg.norm(shank_gyr, axis=1) > p.moving_rate_rps
    if np.count_nonzero(moving) < p.min_samples:
        return []
    median = np.rad2deg(np.nanmedian(angles_rad[moving], axis=0))
    names = [n for j in JOINTS for n in JOINT_DOF_NAMES[j]]
    out = []
    for name, m in zip(names, median, strict=True):
        lo, hi = p.median_limits_deg[name]
        if np.isfinite(m) and not lo <= m <= hi:
            out.append(
                f"the {name.replace('_', ' ')} is {m:+.0f}° while the leg moves (median), beyond the "
                f"{lo:+.0f}…{hi:+.0f}° a leg holds: the segment frames disagree; check that each sensor's "
                f"columns are mapped to its segment with the right signs, that the sensors did not slip, "
                f"and that the trial starts standing in the reference posture"
            )
    return out
