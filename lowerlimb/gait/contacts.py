"""Foot contact positions and headings: the stationary period nearest each initial contact."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lowerlimb.conventions import FloatArray, quat_to_matrix
from lowerlimb.gait.trajectory import FootTrajectory

__all__ = ["Contacts", "foot_contacts", "heading_change_rad", "walking_direction"]


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
    ``max_gap_s`` from every period get NaN positions and ``period = -1``, and so
    does a contact whose nearest period is nearer to another contact: a foot stands
    once per contact, and a contact just before the recording ends, whose stance was
    not recorded, would otherwise take the previous contact's period and make a
    stride of length zero.

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
    idx = _nearest_periods(iv, np.asarray(ic_s, dtype=float), max_gap_s)
    for i, j in enumerate(idx):
        if j < 0:
            continue
        a, b = traj.stationary.runs[j]
        pos[i] = pts[a:b].mean(axis=0)
        rot[i] = R[(a + b - 1) // 2]
    return Contacts(time_s=np.asarray(ic_s, dtype=float), position_m=pos, R_earth_sensor=rot, period=idx)


def _nearest_periods(intervals_s: FloatArray, ic_s: FloatArray, max_gap_s: float) -> np.ndarray:
    """(K,) index of each contact's stationary period (-1: none within ``max_gap_s``, or taken).

    ``intervals_s`` (P, 2) are the periods' start and end times, s. The gap is the time
    distance from the contact to the interval (zero inside). A period that is the nearest
    of several contacts stays with the contact it is nearest to; the others get -1.
    """
    idx = np.full(len(ic_s), -1, dtype=int)
    if intervals_s.shape[0] == 0:
        return idx
    gap = np.maximum(intervals_s[None, :, 0] - ic_s[:, None], 0.0)
    gap += np.maximum(ic_s[:, None] - intervals_s[None, :, 1], 0.0)
    nearest = np.argmin(gap, axis=1)
    best = gap[np.arange(len(ic_s)), nearest]
    lowest = np.full(intervals_s.shape[0], np.inf)  # each period's smallest gap to a contact
    np.minimum.at(lowest, nearest, best)
    keep = (best <= max_gap_s) & (best == lowest[nearest])
    idx[keep] = nearest[keep]
    return idx


def walking_direction(contacts: Contacts, time_s: float) -> FloatArray | None:
    """(2,) unit horizontal direction of the foot's stride nearest in time to ``time_s`` (s).

    Among the strides (two consecutive contacts with positions, apart), the one whose time
    interval contains ``time_s`` or lies nearest to it (the earlier on a tie): the first
    stride for a standing start, the last for an anchor where the walk ends (the first
    stride's direction, used before, points the other way after a turn). ``None`` without
    any such stride.
    """
    p = contacts.position_m[:, :2]
    d = p[1:] - p[:-1]
    length = np.linalg.norm(d, axis=1)
    ok = np.flatnonzero(np.isfinite(length) & (length > 0.0))
    if ok.size == 0:
        return None
    t = contacts.time_s
    gap = np.maximum(t[ok] - time_s, 0.0) + np.maximum(time_s - t[ok + 1], 0.0)
    j = int(ok[np.argmin(gap)])
    return np.asarray(d[j] / length[j], dtype=float)


def heading_change_rad(R_a: FloatArray, R_b: FloatArray) -> float:
    """Rotation about the vertical (earth z) from orientation ``R_a`` to ``R_b``, rad in (-π, π].

    The yaw of the relative rotation ``R_b R_aᵀ`` by the swing–twist split
    (``atan2(R10 − R01, R00 + R11)``), which ignores small tilts.
    """
    D = R_b @ R_a.T
    return float(np.arctan2(D[1, 0] - D[0, 1], D[0, 0] + D[1, 1]))
