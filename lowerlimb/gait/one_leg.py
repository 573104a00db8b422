"""Gait of one instrumented leg: its events, its foot's track and the parameters one leg gives.

A single-leg trial has the shank and foot sensors of one side, so the stages of the two-leg
gait run for that side alone (:func:`~lowerlimb.gait.detect_gait_events` on its shank and foot
gyros, :func:`~lowerlimb.gait.integrate_foot` with the calibrated foot orientation, carried to
the calibrated ankle centre, :func:`~lowerlimb.gait.compute_gait_parameters`). What needs the
other foot — step time and length, step width, double support — stays null; cadence is taken
from the stride time (two steps a stride, ``120 / stride time``), which assumes the two steps
of a stride alike (``cadence_basis: "stride_time"`` in ``gait.json``).

A trial in which the shank shows no walking (a squat, a sit-to-stand), or with fewer than
:attr:`GaitParams.min_leg_strides` strides of at least :attr:`GaitParams.min_leg_stride_m`
(its foot never rests between strides: not walking on the ground, as in the one-leg
simulator's walk; or it hardly moves between its rests, as a sit-to-stand's foot), has no
gait: ``None``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .errors import NoGaitCyclesError
from .events import GaitEvents, detect_gait_events
from .parameters import GaitParameters, compute_gait_parameters
from .params import GaitParams
from .trajectory import FootTrajectory, integrate_foot

__all__ = ["LegGait", "analyse_leg_gait"]


@dataclass(frozen=True)
class LegGait:
    """The gait of one leg of a trial.

    Attributes:
        side: ``"left"`` or ``"right"``.
        events: the leg's events, times on the trial's clock (s).
        parameters: its strides (times from the trial's first sample).
        trajectory: the ankle centre's ZUPT track, earth frame of the foot's filter, m.
    """

    side: str
    events: GaitEvents
    parameters: GaitParameters
    trajectory: FootTrajectory

    def to_dict(self) -> dict[str, Any]:
        """``gait.json`` of one leg: the two-leg keys, the other side's and the step keys null."""
        out = self.parameters.to_dict()
        cadence = self.means()["cadence_steps_per_min"]
        out["cadence_steps_per_min"] = cadence if np.isfinite(cadence) else None
        out["cadence_basis"] = "stride_time"
        out["legs"] = [self.side]
        return out

    def means(self) -> dict[str, float]:
        """Means over the leg's straight strides; NaN where there are none.

        Keys: ``stride_length_m``, ``stride_time_s``, ``gait_speed_m_s`` and
        ``cadence_steps_per_min`` (``120 / stride time``).
        """
        leg = self.parameters.summary(self.side)
        out = {k: float(leg[k]["mean"]) for k in ("stride_length_m", "stride_time_s", "gait_speed_m_s")}
        stride = out["stride_time_s"]
        out["cadence_steps_per_min"] = 120.0 / stride if np.isfinite(stride) and stride > 0 else float("nan")
        return out

    @property
    def n_strides(self) -> int:
        """Straight strides of the leg."""
        return len(self.parameters.select(self.side))


def analyse_leg_gait(
    side: str,
    rate_hz: float,
    *,
    shank_gyr: ArrayLike,
    foot_gyr: ArrayLike,
    foot_acc: ArrayLike,
    foot_quat_wxyz: ArrayLike,
    ankle_in_foot_m: ArrayLike,
    start_time_s: float = 0.0,
    params: GaitParams | None = None,
    cut_axes: ArrayLike | None = None,
) -> LegGait | None:
    """Events, the ankle's track and the gait parameters of one leg.

    Args:
        side: ``"left"`` or ``"right"``.
        rate_hz: sampling rate, Hz.
        shank_gyr: (N, 3) shank gyro, bias removed, sensor frame, rad/s.
        foot_gyr: (N, 3) foot gyro, bias removed, sensor frame, rad/s.
        foot_acc: (N, 3) foot specific force, sensor frame, m/s².
        foot_quat_wxyz: (N, 4) the foot sensor's orientation (scalar first).
        ankle_in_foot_m: (3,) the calibrated ankle centre in the foot sensor frame, m.
        start_time_s: the trial's first sample time, s.
        params: gait thresholds (defaults: :class:`GaitParams`).
        cut_axes: (N, 3) ``±1`` where the foot accelerometer sits at its range, else 0
            (:func:`~lowerlimb.gait.integrate_foot`), or None.

    Returns:
        The leg's gait, or ``None`` when its shank shows no walking.
    """
    p = params or GaitParams()
    try:
        if side == "left":
            events = detect_gait_events(
                rate_hz, left_shank_gyr=shank_gyr, left_foot_gyr=foot_gyr, left_foot_acc=foot_acc, params=p
            )
        else:
            events = detect_gait_events(
                rate_hz, right_shank_gyr=shank_gyr, right_foot_gyr=foot_gyr, right_foot_acc=foot_acc, params=p
            )
    except NoGaitCyclesError:
        return None
    ev = events.left if side == "left" else events.right
    if ev is None or ev.stationary is None:
        return None
    track = integrate_foot(
        foot_gyr, foot_acc, rate_hz, ev.stationary, quat_wxyz=foot_quat_wxyz, params=p, cut_axes=cut_axes
    )
    track = replace(track, position_m=track.point_m(np.asarray(ankle_in_foot_m, dtype=float)))
    at_ankle = replace(p, sensor_to_ankle_m=(0.0, 0.0, 0.0))  # the track is the ankle centre's
    left, right = (track, None) if side == "left" else (None, track)
    parameters = compute_gait_parameters(events, left, right, params=at_ankle)
    walked = [st for st in parameters.strides if st.stride_length_m >= p.min_leg_stride_m]  # NaN: no
    if len(walked) < p.min_leg_strides:
        return None  # the foot never rests between strides (not walking on the ground), or hardly moves
    shifted = ev.on_clock(start_time_s)
    on_clock = replace(events, left=shifted if left else None, right=shifted if right else None)
    return LegGait(side, on_clock, parameters, track)
