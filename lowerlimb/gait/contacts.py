"""Foot contact positions and headings: the stationary period nearest each initial contact."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lowerlimb.conventions import FloatArray, quat_to_matrix
from lowerlimb.gait.trajectory import FootTrajectory

__all__ = ["Contacts", "foot_contacts", "heading_change_rad"]


@dataclass(frozen=True)
class Contacts:
    """The foot's resting pose at each initial contact.

    Attributes:
        time_s: (K,) initial-contact times, s.
        position_m: (K, 3) ankle (or sensor) position during the stationary period nearest
            each contact, earth frame, m.
        R_earth_sensor: (K, 3, 3) sensor orientation in the middle of that period.
        period: (K,) index of the stationary run used (-1: none within reach, position NaN).
    """

    time_s: FloatArray
    position_m: FloatArray
    R_earth_sensor: FloatArray
    period: np.ndarray


def foot_contacts(
    traj: FootTrajectory, ic_s: FloatArray, offset_in_sensor_m: FloatArray, max_gap_s: float
) -> Contacts:
    """Positions of a point fixed in the foot at each initial contact.

    The stationary period nearest in time to each contact (time distance to the
    interval, zero when inside) gives the position; a point at
    ``offset_in_sensor_m`` (e.g. the ankle centre, m) is added with the period's
    orientation. During flat-foot the foot does not move, so any such offset
    shifts all contact positions of a straight pass equally (for equal foot
    heading) and leaves stride length unchanged. Contacts farther than
    ``max_gap_s`` from every period get NaN positions and ``period = -1``.

    Args:
        traj: Foot trajectory with its stationary periods.
        ic_s: (K,) initial-contact times, s (sample 0 at t = 0).
        offset_in_sensor_m: (3,) point in the foot sensor frame, m.
        max_gap_s: Largest accepted time gap between a contact and its period, s.

    Returns:
        One resting pose per contact.
    """
    iv = traj.stationary.intervals_s()
    pts = traj.point_m(offset_in_sensor_m)
    R = quat_to_matrix(traj.quat_wxyz)
    pos = np.full((len(ic_s), 3), np.nan)
    rot = np.full((len(ic_s), 3, 3), np.nan)
    idx = np.full(len(ic_s), -1, dtype=int)
    for i, t in enumerate(ic_s):
        if iv.shape[0] == 0:
            break
        gap = np.maximum(iv[:, 0] - t, 0.0) + np.maximum(t - iv[:, 1], 0.0)
        j = int(np.argmin(gap))
        if gap[j] > max_gap_s:
            continue
        a, b = traj.stationary.runs[j]
        pos[i] = pts[a:b].mean(axis=0)
        rot[i] = R[(a + b - 1) // 2]
        idx[i] = j
    return Contacts(time_s=np.asarray(ic_s, dtype=float), position_m=pos, R_earth_sensor=rot, period=idx)


def heading_change_rad(R_a: FloatArray, R_b: FloatArray) -> float:
    """Rotation about the vertical (earth z) from orientation ``R_a`` to ``R_b``, rad in (-π, π].

    The yaw of the relative rotation ``R_b R_aᵀ`` by the swing–twist split
    (``atan2(R10 − R01, R00 + R11)``), which ignores small tilts.
    """
    D = R_b @ R_a.T
    return float(np.arctan2(D[1, 0] - D[0, 1], D[0, 0] + D[1, 1]))
