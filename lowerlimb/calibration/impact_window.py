"""Samples near impacts, left out of the spherical joint-centre fits.

The rigid-body constraint of Hu et al. 2021 (eq. 7) needs the angular acceleration
α of both sensors, by differentiation of the low-passed gyros
(:mod:`lowerlimb.constraints.angular_acceleration`), and their low-passed
accelerometers. Where a segment's motion is not smooth — at foot contacts, where
the heel strikes, the foot slaps flat and the forefoot pushes off — the derivative
and the prefilter smear a kink of the kinematics over neighbouring samples, and the
accelerometer and α no longer describe the same rigid motion there; on real legs the
heel-strike impact also rings in the strap and the soft tissue. On the seven-IMU
simulator the residual at the true ankle reaches −25 m/s² in the sample after a
heel contact and stays below 0.01 m/s² between contacts (noise-free, 100 Hz).

An impact is a jump of the specific force: its *jerk* (time derivative, m/s³) is
large. Each sample whose jerk (central difference of the raw accelerometer, norm)
exceeds ``impact_jerk_mps3`` in any of the given sensors is flagged, and every
sample within ``impact_window_s`` of a flagged one is left out (the smearing of
the filters reaches that far). The rule needs no gait events, so it also applies
to one-leg trials and to joints whose sensors see the other leg's contacts (a
pelvis). When the flagged windows would leave out more than
``impact_max_excluded`` of the samples (vigorous motion in which high jerk is
not an impact), the threshold is raised until they do not.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import FloatArray

__all__ = ["dilate", "jerk_norm", "impact_keep_mask", "impact_cutoff_limit_hz"]


def jerk_norm(acc: ArrayLike, rate_hz: float) -> FloatArray:
    """Norm of the specific force's time derivative by central differences.

    Args:
        acc: (N, 3) accelerometer (specific force), sensor frame, m/s².
        rate_hz: sampling rate, Hz.

    Returns:
        (N,) jerk norm, m/s³ (one-sided differences at the two ends).
    """
    a = np.asarray(acc, dtype=float)
    if a.shape[0] < 2:
        return np.zeros(a.shape[0])
    return np.asarray(np.linalg.norm(np.gradient(a, axis=0), axis=1) * rate_hz, dtype=float)


def dilate(flags: NDArray[np.bool_], half: int) -> NDArray[np.bool_]:
    """Flags spread to ``half`` samples either side (a running maximum)."""
    if half <= 0 or not flags.any():
        return flags
    c = np.concatenate([[0], np.cumsum(flags, dtype=np.int64)])
    n = flags.size
    idx = np.arange(n)
    hi = np.minimum(idx + half + 1, n)
    lo = np.maximum(idx - half, 0)
    return np.asarray((c[hi] - c[lo]) > 0)


def impact_keep_mask(
    acc: Sequence[ArrayLike], rate_hz: float, options: CalibrationOptions
) -> NDArray[np.bool_]:
    """The samples away from impacts, to keep in a joint-centre fit.

    Args:
        acc: one or more (N, 3) raw accelerometers (specific force, own sensor
            frames, m/s²) whose impacts matter: the joint's two sensors and,
            on a leg, the foot's.
        rate_hz: sampling rate, Hz.
        options: ``impact_jerk_mps3``, ``impact_window_s`` and ``impact_max_excluded``.

    Returns:
        (N,) boolean mask, ``True`` where the sample is kept.
    """
    jerk = np.max(np.vstack([jerk_norm(a, rate_hz) for a in acc]), axis=0)
    half = int(round(options.impact_window_s * rate_hz))
    threshold = options.impact_jerk_mps3
    flags = dilate(jerk > threshold, half)
    if flags.mean() > options.impact_max_excluded:
        # the lowest threshold among the jerk values that leaves enough samples
        candidates = np.unique(jerk[jerk > threshold])
        lo, hi = 0, candidates.size - 1
        while lo < hi:
            mid = (lo + hi) // 2
            if dilate(jerk > candidates[mid], half).mean() > options.impact_max_excluded:
                lo = mid + 1
            else:
                hi = mid
        flags = dilate(jerk > candidates[lo], half)
    return np.asarray(~flags)


def impact_cutoff_limit_hz(keep: ArrayLike | None, options: CalibrationOptions) -> float | None:
    """The cut-off limit of an impact joint's pair: ``impact_max_cutoff_hz`` when impacts were found.

    Why: leaving the impact samples out is not enough. A foot's gyro is broadband with its
    contacts, so its adaptive cut-off leaves the shank–foot pair unfiltered, and between the
    flagged windows the unfiltered strikes, slaps and push-offs still make the accelerometers
    and the smoothed α disagree; walking pins the ankle least along its flexion axis, and
    there the fit moved 30–60 mm on slow simulated walks (noise-free as well). Filtered at
    12 Hz, below the contacts' transients and above walking's kinematics, it came within
    6 mm (``CalibrationOptions.impact_max_cutoff_hz``).

    Args:
        keep: the joint's impact mask (:func:`impact_keep_mask`; ``None``: not computed).
        options: ``impact_max_cutoff_hz``.

    Returns:
        The limit, Hz, or ``None`` (no impacts found, or no limit set).
    """
    if keep is None or options.impact_max_cutoff_hz is None or bool(np.all(keep)):
        return None
    return float(options.impact_max_cutoff_hz)
