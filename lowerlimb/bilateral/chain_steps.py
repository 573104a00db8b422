"""The calibrated chain's ankle vector at every initial contact of one foot: that foot minus the other.

At a right initial contact the left foot is in stance (and the other way round). The
chain gives both ankle centres in the pelvis sensor frame (each hip centre plus its ``hip_to_ankle``), and
the pelvis orientation turns their difference into an earth frame whose heading is the
pelvis filter's. That heading drifts independently of the feet's, so the vector is
expressed in the walking frame of the moment: forward is the direction in which the
stance ankle moves backwards under the pelvis during its flat-foot part
(:attr:`GaitParams.chain_stance_margin_s` after its initial contact to as long before
its toe-off), left is up × forward. These vectors carry no drift, only a bias
(:mod:`lowerlimb.gait.drift` uses what changes of them over time).
"""

from __future__ import annotations

import numpy as np

from ..conventions import FloatArray, quat_to_matrix
from ..gait import GaitEvents, GaitParams
from ..gait.drift import ChainSteps
from ..pipeline import TrialResult

__all__ = ["ankle_centres_in_pelvis_earth", "chain_steps"]


def ankle_centres_in_pelvis_earth(legs: dict[str, TrialResult]) -> dict[str, FloatArray]:
    """``{side: (N, 3)}`` ankle centre minus the pelvis sensor, earth frame of the pelvis filter, m."""
    R = quat_to_matrix(legs["left"].motion.sensor_quat_wxyz["pelvis"])
    out = {}
    for side, r in legs.items():
        ankle = np.asarray(r.calibration.hip.center_in_parent_sensor, dtype=float) + r.positions_m[:, 3:6]
        out[side] = np.einsum("nij,nj->ni", R, ankle)
    return out


def chain_steps(
    legs: dict[str, TrialResult], events: GaitEvents, params: GaitParams, side: str = "right"
) -> ChainSteps | None:
    """The chain's ``side``-minus-other ankle vector at each ``side`` initial contact (module docstring).

    Args:
        legs: the two processed legs (one pelvis sensor), with per-sample positions.
        events: events of both legs, times from sample 0.
        params: ``chain_stance_margin_s``, ``max_stride_time_s``.
        side: the foot making contact, ``"right"`` or ``"left"``; the other is in stance.

    Returns:
        The steps, or ``None`` without events of both legs.
    """
    if events.left is None or events.right is None:
        return None
    other = "left" if side == "right" else "right"
    mine, theirs = (events.right, events.left) if side == "right" else (events.left, events.right)
    ankle = ankle_centres_in_pelvis_earth(legs)
    rate = legs[side].trial.rate_hz
    n = ankle[other].shape[0]
    ic_o, to_o = theirs.initial_contact_s, theirs.toe_off_s
    margin = params.chain_stance_margin_s
    rows = []
    for t in mine.initial_contact_s:
        start, end = ic_o[ic_o < t], to_o[to_o > t]
        if not start.size or not end.size or end[0] - start[-1] > params.max_stride_time_s:
            continue
        k0, k1, k = (int(round(x * rate)) for x in (start[-1] + margin, end[0] - margin, t))
        if not 0 <= k0 < k1 < n or k >= n:
            continue
        back = ankle[other][k0, :2] - ankle[other][k1, :2]
        length = float(np.linalg.norm(back))
        if not np.isfinite(length) or length == 0.0:
            continue
        u = back / length
        d = (ankle[side][k] - ankle[other][k])[:2]
        rows.append((float(t), float(d @ u), float(u[0] * d[1] - u[1] * d[0])))
    r = np.asarray(rows, dtype=float).reshape(-1, 3)
    return ChainSteps(time_s=r[:, 0], forward_m=r[:, 1], left_m=r[:, 2], side=side)
