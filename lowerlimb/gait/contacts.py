"""Foot contact positions and headings: the stationary period nearest each initial contact.

A contact is also told by how far the foot turns about the vertical between initial
contact and the end of the stationary period that gives its position: a foot that pivots
on the floor through a turn about has no still ankle, so that position is not where the
ankle was at initial contact, and a stride or step ending on it is a turning one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lowerlimb.conventions import FloatArray, quat_to_matrix
from lowerlimb.gait.trajectory import FootTrajectory

__all__ = ["Contacts", "foot_contacts", "heading_change_rad", "stance_turn_rad", "walking_direction"]


@dataclass(frozen=True)
class Contacts:
    """The foot's resting pose at each initial contact.

    Attributes:
        time_s: (K,) initial-contact times, s.
        position_m: (K, 3) ankle (or sensor) position during the stationary period nearest
            each contact, earth frame, m.
        R_earth_sensor: (K, 3, 3) sensor orientation in the middle of that period.
        period: (K,) index of the stationary run used (-1: none within reach, position NaN).
        stance_turn_rad: (K,) how far the foot's heading ranges from each contact until the
            end of its stationary period (:func:`stance_turn_rad`), rad ≥ 0; NaN where
            neither that period nor a toe-off ends it; ``None``: not measured (no toe-offs).
    """

    time_s: FloatArray
    position_m: FloatArray
    R_earth_sensor: FloatArray
    period: np.ndarray
    stance_turn_rad: FloatArray | None = None

    def pivots(self, max_stance_turn_rad: float) -> np.ndarray:
        """(K,) bool: the foot turned about the vertical by more than this during the contact's stance."""
        if self.stance_turn_rad is None:
            return np.zeros(len(self.time_s), dtype=bool)
        with np.errstate(invalid="ignore"):
            return np.asarray(self.stance_turn_rad > max_stance_turn_rad)

    def turning(self, k: int, max_heading_rad: float, max_stance_turn_rad: float) -> bool:
        """Whether stride ``k`` (contact k to k + 1) turns.

        It turns when the foot's resting heading changes by more than ``max_heading_rad``
        between its contacts, or when the foot pivots (:meth:`pivots`) during either
        contact's stance, rad.
        """
        h = heading_change_rad(self.R_earth_sensor[k], self.R_earth_sensor[k + 1])
        if np.isfinite(h) and abs(h) > max_heading_rad:
            return True
        return bool(np.any(self.pivots(max_stance_turn_rad)[k : k + 2]))


def foot_contacts(
    traj: FootTrajectory,
    ic_s: FloatArray,
    offset_in_sensor_m: FloatArray,
    max_gap_s: float,
    to_s: FloatArray | None = None,
) -> Contacts:
    """Positions of a point fixed in the foot at each initial contact.

    The stationary period nearest in time to each contact among those that have not ended
    before it (time to the interval's start, zero when inside) gives the position; a point at
    ``offset_in_sensor_m`` (e.g. the ankle centre, m) is added with the period's
    orientation. During flat-foot the foot does not move, so any such offset
    shifts all contact positions of a straight pass equally (for equal foot
    heading) and leaves stride length unchanged. Contacts farther than
    ``max_gap_s`` from every period get NaN positions and ``period = -1``, and so
    does a contact whose nearest period is nearer to another contact: a foot stands
    once per contact, and a contact whose stance has no stationary period (recorded
    only in part, or pivoting through a turn) would otherwise take a neighbour's period
    and make a stride of length zero.

    Args:
        traj: Foot trajectory with its stationary periods.
        ic_s: (K,) initial-contact times, s (sample 0 at t = 0).
        offset_in_sensor_m: (3,) point in the foot sensor frame, m.
        max_gap_s: Largest accepted time gap between a contact and its period, s.
        to_s: (M,) toe-off times, s, to measure each stance's turn (``None``: not measured).

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
    ic = np.asarray(ic_s, dtype=float)
    turn = None
    if to_s is not None:
        run_end = np.array([traj.stationary.runs[j][1] / traj.rate_hz if j >= 0 else np.nan for j in idx])
        turn = stance_turn_rad(R, traj.rate_hz, ic, np.asarray(to_s, dtype=float), run_end)
    return Contacts(time_s=ic, position_m=pos, R_earth_sensor=rot, period=idx, stance_turn_rad=turn)


def stance_turn_rad(
    R_earth_sensor: FloatArray, rate_hz: float, ic_s: FloatArray, to_s: FloatArray, run_end_s: FloatArray
) -> FloatArray:
    """(K,) range of the foot's heading from each contact until its position was taken, rad.

    The span runs from each initial contact to the end of the stationary period that gives
    its position (``run_end_s``), or without one to the first toe-off after it (NaN: no
    toe-off before the next contact). The heading is the rotation about the vertical from
    the orientation at the contact (:func:`heading_change_rad`), unwrapped, and its range
    (largest minus smallest) is kept. A foot that turns only after its stationary period
    (onto the next pass, pushing off its forefoot) keeps its contact position. On the real
    walk of ``gait/`` straight stances range over 4–8° (the foot rolls and its sensor moves
    on the skin); the simulator's feet pivoting through a turn about 17–180°.

    Args:
        R_earth_sensor: (N, 3, 3) sensor orientation at each sample (sample 0 at t = 0).
        rate_hz: Sampling rate, Hz.
        ic_s: (K,) initial-contact times, s, increasing.
        to_s: (M,) toe-off times, s, increasing.
        run_end_s: (K,) end of each contact's stationary period, s (NaN: none).
    """
    n = R_earth_sensor.shape[0]
    out = np.full(len(ic_s), np.nan)
    for k, t in enumerate(ic_s):
        stop = run_end_s[k]
        if not np.isfinite(stop):
            later = to_s[to_s > t]
            if later.size == 0 or (k + 1 < len(ic_s) and later[0] >= ic_s[k + 1]):
                continue
            stop = later[0]
        a, b = int(round(t * rate_hz)), int(round(stop * rate_hz))
        if a < 0 or b >= n or b <= a:
            continue
        D = R_earth_sensor[a : b + 1] @ R_earth_sensor[a].T
        yaw = np.unwrap(np.arctan2(D[:, 1, 0] - D[:, 0, 1], D[:, 0, 0] + D[:, 1, 1]))
        out[k] = float(np.ptp(yaw))
    return out


def _nearest_periods(intervals_s: FloatArray, ic_s: FloatArray, max_gap_s: float) -> np.ndarray:
    """(K,) index of each contact's stationary period (-1: none within ``max_gap_s``, or taken).

    ``intervals_s`` (P, 2) are the periods' start and end times, s. The gap is the time
    from the contact to the interval's start (zero inside). A period that ended before the
    contact belongs to an earlier stance (the foot stands after it touches down: a pivoting
    foot with no period of its own took the previous stance's and made a stride of 1 cm) and
    is not a candidate. A period that is the nearest of several contacts stays with the
    contact it is nearest to; the others get -1.
    """
    idx = np.full(len(ic_s), -1, dtype=int)
    if intervals_s.shape[0] == 0:
        return idx
    gap = np.maximum(intervals_s[None, :, 0] - ic_s[:, None], 0.0)
    gap[intervals_s[None, :, 1] < ic_s[:, None]] = np.inf  # ended before the contact: an earlier stance
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
