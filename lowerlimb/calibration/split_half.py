"""How far a joint centre moves between the recording's two halves: a third spread.

Why: the reported standard deviation sees the noise
(:mod:`~lowerlimb.calibration.excitation`) and the cut-off shift sees the
prefilter (:mod:`~lowerlimb.calibration.cutoff_probe`); neither sees a walk too
short to pin a centre, or a centre that is not the same throughout (a sensor that
slid, a turn unlike the straight passes). Measured on the real walk of ``gait/``
calibrated on its first 5 s of walking only: the left shank came out 50 mm short
of Vicon with a reported spread of 3 mm and a cut-off shift of 1 mm, the right
thigh 48 mm long with 12 and 8 mm; fitted on each half of those samples, the
ankle in the left shank moved by 2 × 52 mm and the hip in the right thigh by
2 × 52 mm. On the whole walk (9.5 s of walking) the halves differ by 2 × 3 … 2 × 25
mm; on 15 s simulated walks, where a centre was 118 or 148 mm off, by 2 × 18 and
2 × 91 mm, and on 60 s ones by 2 × 1 … 2 × 3 mm.

So the leg calibration repeats the hip and ankle fits on each half of the moving
samples (the still start, when there is one, in both halves; same signals,
cut-offs, impact mask, priors and solver) and records half the difference of the
two centres (:attr:`~lowerlimb.calibration.results.SphericalJointCalibration.split_half_shift`,
``center_split_half_shift_in_*_sensor`` in calibration.json). A shift above
:attr:`~lowerlimb.calibration.options.CalibrationOptions.split_half_warn_m` in
either sensor frame is warned about; no estimate changes. It is a lower bound of
the error, not an estimate of it: it reads half the difference, and an offset
both halves share (a soft-tissue bias of the whole walk) does not show.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np

from lowerlimb.calibration.results import SphericalJointCalibration
from lowerlimb.conventions import FloatArray

__all__ = ["half_masks", "split_half_message", "split_half_shift"]

#: ``fit(keep) -> joint`` refits one spherical joint on the samples ``keep`` marks.
RefitOn = Callable[[np.ndarray], SphericalJointCalibration]


def half_masks(n_samples: int, keep: np.ndarray | None, n_still: int) -> tuple[np.ndarray, np.ndarray]:
    """(first, second) sample masks: the kept moving samples split at their middle, each with the still start.

    Args:
        n_samples: samples of the joint's signals.
        keep: (N,) the main fit's kept samples (``None``: all).
        n_still: still samples at the start (in both halves).
    """
    base = np.ones(n_samples, dtype=bool) if keep is None else np.asarray(keep, dtype=bool).copy()
    moving = np.flatnonzero(base[n_still:]) + n_still
    middle = moving[moving.size // 2] if moving.size else n_samples
    idx = np.arange(n_samples)
    still = idx < n_still
    return base & ((idx < middle) | still), base & ((idx >= middle) | still)


def split_half_shift(refit: RefitOn, masks: tuple[np.ndarray, np.ndarray]) -> FloatArray:
    """(6,) half the difference ``(c_parent, c_child)`` of the second half's fit minus the first's, m.

    NaN when either half is too short to fit (fewer than 10 samples).
    """
    if min(int(np.count_nonzero(m)) for m in masks) < 10:
        return np.full(6, np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a, b = (refit(m) for m in masks)
    xa = np.r_[a.center_in_parent_sensor, a.center_in_child_sensor]
    xb = np.r_[b.center_in_parent_sensor, b.center_in_child_sensor]
    return np.asarray(0.5 * (xb - xa), dtype=float)


def split_half_message(joint: SphericalJointCalibration, limit_m: float) -> str | None:
    """The warning for a centre that moves more than ``limit_m`` between the halves, else ``None``.

    A frame whose shift is NaN (not probed) is left out.
    """
    hit = joint.largest_shift(joint.split_half_shift, above_m=limit_m)
    if hit is None:
        return None
    worst, moved = hit
    return (
        f"{joint.joint}: the centre in the {worst} sensor frame moves by ±{1000 * moved:.0f} mm "
        f"between the recording's first and second half; the walk is too short to pin it, or the "
        f"sensor moved on the segment: record a longer trial (or check the strap)"
    )
