"""Gait events and spatio-temporal parameters of a calibrated two-leg trial.

The :mod:`lowerlimb.gait` stages, fed with what the calibration knows:

1. events per leg (:func:`~lowerlimb.gait.detect_gait_events`) from the shank and foot
   sensors, gyro bias removed;
2. each foot's ZUPT trajectory (:func:`~lowerlimb.gait.integrate_foot`) with the foot
   orientation of the calibrated chain (heading made consistent with the pelvis
   through hip, knee and ankle), so that both feet move in one earth frame, the
   pelvis's; the trajectory is carried to the calibrated ankle centre
   (``sensor_to_ankle_m`` = the ankle centre in that foot's sensor frame);
3. the :class:`~lowerlimb.gait.FootAnchor` from the calibrated chain: the right minus
   left ankle centre (pelvis sensor frame: the hip centre plus ``hip_to_ankle``; a leg
   standing before the first step and tilted beyond
   :attr:`GaitParams.max_standing_leg_tilt_deg` is taken as vertical),
   turned into the earth frame with the pelvis orientation, at the last double-support
   instant (both feet stationary) before the first initial contact, in the walking
   coordinates of the two feet's next strides (their mean direction);
4. the chain's ankle vector at every initial contact, that foot minus the other
   (:func:`~lowerlimb.bilateral.chain_steps.chain_steps`, both feet), which removes the slow
   drift of one foot's track against the other (:mod:`lowerlimb.gait.drift`);
5. :func:`~lowerlimb.gait.compute_gait_parameters`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from ..conventions import SIDES, FloatArray, quat_to_matrix
from ..gait import (
    FootAnchor,
    FootTrajectory,
    GaitEvents,
    GaitParameters,
    GaitParams,
    NoGaitCyclesError,
    SideEvents,
    compute_gait_parameters,
    detect_gait_events,
    foot_contacts,
    integrate_foot,
)
from ..gait.placement import mean_walking_direction
from ..gait.turns import Turns, detect_turns, vertical_rate
from ..pipeline import TrialResult
from .chain_steps import chain_steps

__all__ = [
    "BilateralGait",
    "CutFootGyroWarning",
    "NoGaitWarning",
    "UnanchoredFeetWarning",
    "analyse_gait",
    "chain_anchor",
    "gyro_restorations",
]


class NoGaitWarning(UserWarning):
    """The trial has no walking: ``events.csv`` is empty and ``gait.json`` holds nulls."""


class CutFootGyroWarning(UserWarning):
    """A foot gyro is cut at its range: step length and width are ``null``."""


class UnanchoredFeetWarning(UserWarning):
    """The feet never stand still together before the first step: step length and width are ``null``."""


@dataclass(frozen=True)
class BilateralGait:
    """Events, foot trajectories and parameters of a two-leg trial.

    Attributes:
        events: Events of both legs, times on the trial's clock (s), or ``None`` without walking.
        parameters: The per-stride parameters, or ``None``.
        anchor: The inter-foot anchor from the calibrated chain (times from sample 0), or ``None``.
        sensor_to_ankle_m: ``{side: (3,)}`` calibrated ankle centre in the foot sensor frame, m.
        trajectories: ``{side: ankle-centre trajectory}`` (earth frame of the pelvis heading).
        note: Why there are no parameters, or ``""``.
        turns: The walker's turns from the pelvis sensor (:mod:`lowerlimb.gait.turns`), or
            ``None`` without events.
        unplaced: why the feet were not placed against each other although they could be
            anchored (a cut foot gyro), or ``""``.
        gyro_restored: ``{side: {sensor: …}}`` what the cut gyros got back
            (:func:`gyro_restorations`); empty without a cut gyro.
    """

    events: GaitEvents | None
    parameters: GaitParameters | None
    anchor: FootAnchor | None
    sensor_to_ankle_m: dict[str, FloatArray]
    trajectories: dict[str, FootTrajectory] = field(default_factory=dict)
    note: str = ""
    turns: Turns | None = None
    unplaced: str = ""
    gyro_restored: dict[str, dict[str, dict[str, Any]]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The docs/formats.md ``gait.json`` content (NaN as ``None``), with the anchor and offsets."""
        if self.parameters is None:
            d: dict[str, Any] = {
                "cadence_steps_per_min": None,
                "gait_speed_m_s": None,
                "step_width_m": {"mean": None, "sd": None},
                "left": None,
                "right": None,
                "note": self.note,
            }
        else:
            d = self.parameters.to_dict()
            d["params"]["sensor_to_ankle_m"] = {
                s: np.asarray(v).tolist() for s, v in self.sensor_to_ankle_m.items()
            }
        d["anchor"] = None if self.anchor is None else asdict(self.anchor) | {"source": "calibrated chain"}
        d["turns"] = None if self.turns is None else self.turns.to_dict()
        d["cut_force_restored"] = {s: _restored(t) for s, t in self.trajectories.items()} or None
        d["steps_unplaced"] = self.unplaced or None
        d["cut_gyro_restored"] = self.gyro_restored or None
        return _json_safe(d)


def _restored(track: FootTrajectory) -> dict[str, Any] | None:
    """What a cut foot accelerometer got back (:mod:`lowerlimb.gait.cut_force`), or ``None`` without a cut."""
    v = track.restored_mps[track.restored_mps > 0]
    if v.size == 0:
        return None
    return {
        "swings": int(v.size),
        "velocity_mps_median": float(np.median(v)),
        "velocity_mps_max": float(v.max()),
    }


def gyro_restorations(legs: dict[str, TrialResult]) -> dict[str, dict[str, dict[str, Any]]]:
    """``{side: {sensor: …}}`` what each leg's cut gyros got back, for ``gait.json``.

    A foot (:mod:`lowerlimb.gait.cut_rate`): ``swings`` restored and the tilt mismatch from one
    rest to the next before and after (``tilt_deg_before_median``, ``tilt_deg_after_median``).
    A thigh or shank (:mod:`lowerlimb.gait.cut_segment`): ``runs`` restored and the rotation they
    got back (``rotation_deg_median``, ``rotation_deg_max``).
    """
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for side, leg in legs.items():
        mine: dict[str, dict[str, Any]] = {}
        foot = leg.foot_gyro_restore
        if foot is not None and foot.swings:
            mine["foot"] = {
                "swings": foot.swings,
                "tilt_deg_before_median": float(np.median(foot.tilt_before_deg)),
                "tilt_deg_after_median": float(np.median(foot.tilt_after_deg)),
            }
        for sensor, r in leg.segment_gyro_restore.items():
            if r.lost_deg.size:
                mine[sensor] = {
                    "runs": int(r.lost_deg.size),
                    "rotation_deg_median": float(np.median(r.lost_deg)),
                    "rotation_deg_max": float(r.lost_deg.max()),
                }
        if mine:
            out[side] = mine
    return out


def _json_safe(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_json_safe(v) for v in x]
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _shift(ev: SideEvents | None, t0: float) -> SideEvents | None:
    return None if ev is None else ev.on_clock(t0)


def chain_anchor(
    legs: dict[str, TrialResult],
    events: GaitEvents,
    trajectories: dict[str, FootTrajectory],
    params: GaitParams,
) -> FootAnchor | None:
    """Right minus left ankle centre at a double-support instant, from the calibrated chain.

    Args:
        legs: the two processed legs (same pelvis sensor, one pelvis heading).
        events: events of both legs (times from sample 0).
        trajectories: the two ankle-centre trajectories (earth frame of the pelvis heading).
        params: gait thresholds (``max_stride_time_s``).

    Returns:
        The anchor, or ``None`` when the feet never rest together before the first step
        or neither foot has a stride. Only a standing start anchors: anchored where a
        walk ends (two passes and a turn later), the real walk of ``gait/`` cut mid-stride
        had its step width 94-145 mm off Vicon's (65 mm uncut), against 17 mm from its
        standing start (``benchmarks/results/cut_start.md``); during walking the chain's
        right-minus-left vector is decimetres off (``lowerlimb.gait.drift``).
    """
    if events.left is None or events.right is None:
        return None
    both = trajectories["left"].stationary.mask & trajectories["right"].stationary.mask
    first_ic = min(float(events.left.initial_contact_s[0]), float(events.right.initial_contact_s[0]))
    rate = trajectories["left"].rate_hz
    cand = np.flatnonzero(both[: max(int(first_ic * rate), 0)])
    if cand.size == 0:
        return None
    k = int(cand[-1])
    R_pelvis = quat_to_matrix(legs["left"].motion.sensor_quat_wxyz["pelvis"][k])
    down = R_pelvis.T @ np.array([0.0, 0.0, -1.0])  # the vertical in the pelvis sensor frame
    ankle = {}
    for s, r in legs.items():
        leg = r.positions_m[k, 3:6]
        tilt = np.degrees(np.arccos(np.clip(leg @ down / max(float(np.linalg.norm(leg)), 1e-9), -1.0, 1.0)))
        if tilt > params.max_standing_leg_tilt_deg:
            # a standing leg this far from vertical is a calibration error (a poorly determined
            # hip or knee centre turns the thigh or shank in its sensor), not a posture: take
            # the leg as vertical, so the ankles are offset like the hips
            leg = (leg @ down) * down
        ankle[s] = np.asarray(r.calibration.hip.center_in_parent_sensor, dtype=float) + leg
    d = R_pelvis @ (ankle["right"] - ankle["left"])
    cl, cr = (
        foot_contacts(trajectories[s], ev.initial_contact_s, np.zeros(3), 0.5 * params.max_stride_time_s)
        for s, ev in (("left", events.left), ("right", events.right))
    )
    u = mean_walking_direction(cl, cr, k / rate)
    if u is None:
        return None
    return FootAnchor(time_s=k / rate, forward_m=float(d[:2] @ u), left_m=float(-u[1] * d[0] + u[0] * d[1]))


def analyse_gait(legs: dict[str, TrialResult], params: GaitParams | None = None) -> BilateralGait:
    """Events, ankle trajectories, the chain anchor and the gait parameters of two processed legs.

    Args:
        legs: ``{"left": …, "right": …}`` single-leg results of one two-leg trial.
        params: gait thresholds (defaults: :class:`~lowerlimb.gait.GaitParams`).

    Warns:
        NoGaitWarning: a shank shows no walking; no events nor parameters.
    """
    p = params or GaitParams()
    trial = legs["left"].trial
    rate = trial.rate_hz
    offsets = {
        s: np.asarray(r.calibration.ankle.center_in_child_sensor, dtype=float) for s, r in legs.items()
    }
    gyr = {
        (s, seg): r.trial.gyr[seg] - r.calibration.gyro_bias.get(seg, np.zeros(3))
        for s, r in legs.items()
        for seg in ("shank", "foot")
    }
    try:
        events = detect_gait_events(
            rate,
            left_shank_gyr=gyr["left", "shank"],
            right_shank_gyr=gyr["right", "shank"],
            left_foot_gyr=gyr["left", "foot"],
            left_foot_acc=legs["left"].trial.acc["foot"],
            right_foot_gyr=gyr["right", "foot"],
            right_foot_acc=legs["right"].trial.acc["foot"],
            params=p,
        )
    except NoGaitCyclesError as e:
        note = f"no gait events: {e}"
        warnings.warn(
            f"{note}; events.csv is empty and gait.json has no parameters", NoGaitWarning, stacklevel=2
        )
        return BilateralGait(None, None, None, offsets, note=note, gyro_restored=gyro_restorations(legs))
    trajs: dict[str, FootTrajectory] = {}
    for s, ev in (("left", events.left), ("right", events.right)):
        assert ev is not None and ev.stationary is not None
        cut = legs[s].foot_acc_cut if p.cut_restore else None
        tr = integrate_foot(
            gyr[s, "foot"],
            legs[s].trial.acc["foot"],
            rate,
            ev.stationary,
            quat_wxyz=legs[s].motion.sensor_quat_wxyz["foot"],
            params=p,
            cut_axes=None if cut is None else cut.axes,
        )
        trajs[s] = replace(tr, position_m=tr.point_m(offsets[s]))
    p_ankle = replace(p, sensor_to_ankle_m=(0.0, 0.0, 0.0))  # the trajectories are the ankle centres
    unplaced = _cut_foot_gyros(legs)
    anchor = None if unplaced else chain_anchor(legs, events, trajs, p_ankle)
    if unplaced:
        warnings.warn(unplaced, CutFootGyroWarning, stacklevel=2)
    elif anchor is None:
        warnings.warn(
            "step length and step width are null: the two feet never stand still together before "
            "the first step, so the calibrated chain cannot place one against the other; start the "
            "recording standing still",
            UnanchoredFeetWarning,
            stacklevel=2,
        )
    sides = () if unplaced else SIDES  # unplaced feet need no chain steps
    chain = [c for c in (chain_steps(legs, events, p_ankle, side) for side in sides) if c is not None]
    parameters = compute_gait_parameters(
        events, trajs["left"], trajs["right"], anchor=anchor, chain=chain, params=p_ankle
    )
    t0 = float(trial.time_s[0])
    shifted = GaitEvents(left=_shift(events.left, t0), right=_shift(events.right, t0), extras=events.extras)
    turns = walker_turns(legs["left"], shifted, p)
    return BilateralGait(
        shifted,
        parameters,
        anchor,
        offsets,
        trajs,
        turns=turns,
        unplaced=unplaced,
        gyro_restored=gyro_restorations(legs),
    )


def _cut_foot_gyros(legs: dict[str, TrialResult]) -> str:
    """Why the feet cannot be placed against each other when a foot gyro is cut, or ``""``.

    A foot gyro cut at its range loses rotation in the swings; what it loses about gravity
    leaves no trace in the foot's tilt at its rests, so even restored
    (:mod:`lowerlimb.gait.cut_rate`) the foot's heading drifts by what it lost at each turn
    and the two tracks turn against each other (the real walk cut at ±250 °/s: step width
    130 mm off as cut, 607 restored, 13 uncut).
    """
    cut = {s: r.foot_gyro_cut for s, r in legs.items() if r.foot_gyro_cut is not None}
    if not cut:
        return ""
    said = ", ".join(f"{s} (±{math.degrees(c.level):.0f} °/s)" for s, c in cut.items())
    return (
        f"step length and step width are null: the foot gyro of the {said} leg is cut at its range, "
        "so its heading is lost in the swings and the feet cannot be placed against each other "
        "(stride lengths keep the restored swings); record the feet at ±1000 °/s or more"
    )


def walker_turns(leg: TrialResult, events: GaitEvents, params: GaitParams) -> Turns:
    """The walker's turns from the pelvis sensor of ``leg`` (events on the trial's clock, s)."""
    gyr = leg.trial.gyr["pelvis"] - leg.calibration.gyro_bias.get("pelvis", np.zeros(3))
    rate_z = vertical_rate(gyr, leg.motion.sensor_quat_wxyz["pelvis"])
    sides = events.sides()
    strides = [np.diff(e.initial_contact_s) for e in sides]
    stride = np.concatenate(strides) if strides else np.zeros(0)
    stride = stride[stride <= params.max_stride_time_s]
    return detect_turns(
        rate_z,
        leg.trial.rate_hz,
        stride_time_s=float(np.median(stride)) if stride.size else None,
        initial_contacts_s=np.concatenate([e.initial_contact_s for e in sides]) if sides else None,
        start_time_s=float(leg.trial.time_s[0]),
        params=params,
    )
