"""True spatio-temporal gait parameters of a simulated two-leg walk.

Computed from the simulator's own events and ankle centres, independently of the
estimators in :mod:`lowerlimb.gait`, with the definitions of issue 11 and
docs/formats.md ("Two legs"):

- stride k of a leg: IC_k → IC_{k+1}; stride time = IC_{k+1} − IC_k;
- stance % = 100 (TO − IC_k) / stride time, TO the leg's toe-off inside the stride (the
  instant the toe tip, the foot's last point in contact, leaves the floor; :mod:`.toe_rocker`);
- step time = IC_k − the other leg's last IC before it;
- double support % = 100 (initial + terminal double support) / stride time:
  initial = the other leg's first TO after IC_k − IC_k; terminal = the leg's TO −
  the other leg's last IC before that TO;
- stride length = horizontal distance between the ankle centres at IC_k and IC_{k+1};
- step length and step width at IC_k: with P and N the other ankle's centres at its
  ICs just before and after IC_k and u the horizontal unit vector from P to N,
  step length = (a_k − P)·u and step width = |u × (a_k − P)|;
- cadence = 60 / mean step time; gait speed = mean stride length / mean stride time.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..conventions import SIDES, FloatArray
from .footsteps import StanceEvents

__all__ = ["GaitTruth", "TrueStride", "gait_truth"]


@dataclass(frozen=True)
class TrueStride:
    """One stride of one leg (times s, lengths m, percentages of the stride time)."""

    side: str
    start_s: float
    stride_time_s: float
    step_time_s: float
    stance_pct: float
    double_support_pct: float
    stride_length_m: float
    step_length_m: float
    step_width_m: float


@dataclass(frozen=True)
class GaitTruth:
    """The true strides of both legs and their summary.

    Attributes:
        strides: Every complete stride, in time order per side.
        cadence_steps_per_min: 60 / mean step time.
        gait_speed_m_s: Mean stride length / mean stride time.
    """

    strides: list[TrueStride] = field(default_factory=list)
    cadence_steps_per_min: float = float("nan")
    gait_speed_m_s: float = float("nan")

    def side(self, side: str) -> list[TrueStride]:
        """The strides of one leg."""
        return [s for s in self.strides if s.side == side]

    def to_dict(self) -> dict[str, Any]:
        """The gait.json layout (mean and SD per side), plus the strides."""

        def stat(values: list[float]) -> dict[str, float | None]:
            v = np.asarray([x for x in values if np.isfinite(x)])
            if v.size == 0:
                return {"mean": None, "sd": None}
            return {"mean": float(v.mean()), "sd": float(v.std(ddof=1)) if v.size > 1 else 0.0}

        out: dict[str, Any] = {
            "cadence_steps_per_min": self.cadence_steps_per_min,
            "gait_speed_m_s": self.gait_speed_m_s,
            "step_width_m": stat([s.step_width_m for s in self.strides]),
        }
        keys = (
            "stride_time_s",
            "step_time_s",
            "stance_pct",
            "double_support_pct",
            "stride_length_m",
            "step_length_m",
        )
        for side in SIDES:
            out[side] = {k: stat([getattr(s, k) for s in self.side(side)]) for k in keys}
        out["strides"] = [s.__dict__ for s in self.strides]
        return out


def _at(t: FloatArray, x: FloatArray, times: FloatArray) -> FloatArray:
    """(K, 3) positions ``x`` (N, 3) at ``times`` (K,), linear interpolation."""
    return np.column_stack([np.interp(times, t, x[:, i]) for i in range(3)])


def _last_before(times: FloatArray, t: float) -> float:
    earlier = times[times < t]
    return float(earlier[-1]) if earlier.size else float("nan")


def _first_after(times: FloatArray, t: float) -> float:
    later = times[times > t]
    return float(later[0]) if later.size else float("nan")


def _stride(
    side: str, k: int, ev: StanceEvents, other: StanceEvents, pos: FloatArray, other_pos: FloatArray
) -> TrueStride | None:
    """Stride k of ``side`` (None when a needed event is missing)."""
    ic, nxt = float(ev.initial_contact_s[k]), float(ev.initial_contact_s[k + 1])
    T = nxt - ic
    to = ev.toe_off_s[(ev.toe_off_s > ic) & (ev.toe_off_s < nxt)]
    o_ic = other.initial_contact_s
    p_prev, p_next = _last_before(o_ic, ic), _first_after(o_ic, ic)
    if to.size == 0 or not (np.isfinite(p_prev) and np.isfinite(p_next)):
        return None
    init_ds = _first_after(other.toe_off_s, ic) - ic
    term_ds = float(to[0]) - _last_before(o_ic, float(to[0]))
    a = pos[k]
    P = other_pos[int(np.flatnonzero(o_ic == p_prev)[0])]
    N = other_pos[int(np.flatnonzero(o_ic == p_next)[0])]
    u = (N - P)[:2] / np.linalg.norm((N - P)[:2])
    rel = (a - P)[:2]
    return TrueStride(
        side=side,
        start_s=ic,
        stride_time_s=T,
        step_time_s=ic - p_prev,
        stance_pct=100.0 * (float(to[0]) - ic) / T,
        double_support_pct=100.0 * (init_ds + term_ds) / T,
        stride_length_m=float(np.linalg.norm((pos[k + 1] - a)[:2])),
        step_length_m=float(rel @ u),
        step_width_m=float(abs(u[0] * rel[1] - u[1] * rel[0])),
    )


def gait_truth(events: dict[str, StanceEvents], ankle_m: dict[str, FloatArray], t: FloatArray) -> GaitTruth:
    """True strides and summary from the events and ankle centres (ENU, m) on times ``t`` (s)."""
    pos = {s: _at(t, ankle_m[s], events[s].initial_contact_s) for s in SIDES}
    strides: list[TrueStride] = []
    for side, other in (("left", "right"), ("right", "left")):
        ev = events[side]
        for k in range(ev.initial_contact_s.size - 1):
            st = _stride(side, k, ev, events[other], pos[side], pos[other])
            if st is not None:
                strides.append(st)
    if not strides:
        return GaitTruth()
    step = np.mean([s.step_time_s for s in strides])
    speed = np.mean([s.stride_length_m for s in strides]) / np.mean([s.stride_time_s for s in strides])
    return GaitTruth(sorted(strides, key=lambda s: (s.side, s.start_s)), float(60.0 / step), float(speed))
