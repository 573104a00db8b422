"""Stops in a simulated walk: the walker slows to a halt in double support, stands, and walks on.

Clinical protocols stop between passes (walk 10 m, stand, turn, walk back), and a walker stops
at a door or to listen. The two-leg walk (:mod:`lowerlimb.simulation.bilateral_walk`) is planned
on a *plan time* ``τ``; a stop is a time warp ``τ(t)`` of the sample times ``t`` whose rate
``dτ/dt`` falls from 1 to 0 over ``ramp_s`` (a quintic smoothstep, so the accelerations stay
continuous), stays 0 for ``pause_s`` and rises back over ``ramp_s``. Every pose of the walk is
its planned pose at ``τ(t)``: the feet stay on their footprints (a foot in stance does not
slide, whatever the rate), the pelvis decelerates from the walking speed to rest within about
half a second, and during the stop every sensor is still, both feet down (one on its heel
rocker, the other on its toe rocker: the stop falls halfway between the leading foot's
initial contact and the trailing foot's toe-off, in double support). The planned events are
mapped back to sample times (:func:`real_times`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import FloatArray
from ..errors import InputError
from .footsteps import StanceEvents

__all__ = ["PauseParams", "pause_plan_times", "paused_time", "real_times", "warped_events"]

#: Sub-samples per sample for the warp's integral.
_FINE = 20


@dataclass(frozen=True)
class PauseParams:
    """How a simulated walk stops.

    Attributes:
        count: number of stops, spread evenly over the walk.
        pause_s: standing still at each stop, s.
        ramp_s: slowing to a halt, and starting again, each takes this long, s.
    """

    count: int = 0
    pause_s: float = 3.0
    ramp_s: float = 0.6

    def validate(self) -> None:
        """Raise :class:`InputError` for a negative count or a non-positive duration."""
        if self.count < 0 or not (np.isfinite(self.pause_s) and self.pause_s > 0.0):
            raise InputError(f"stops need count ≥ 0 and pause_s > 0, got {self.count} and {self.pause_s}")
        if not (np.isfinite(self.ramp_s) and self.ramp_s > 0.0):
            raise InputError(f"stops need ramp_s > 0, got {self.ramp_s}")


def _rate(t: FloatArray, starts: FloatArray, params: PauseParams) -> FloatArray:
    """``dτ/dt`` (N,): 1 walking, 0 stopped, quintic smoothsteps between."""

    def step(u: FloatArray) -> FloatArray:
        u = np.clip(u, 0.0, 1.0)
        return np.asarray(u**3 * (10.0 - 15.0 * u + 6.0 * u**2))

    rate = np.ones_like(t)
    r, p = params.ramp_s, params.pause_s
    for a in starts:
        rate -= step((t - a) / r) - step((t - a - r - p) / r)
    return rate


def paused_time(t: FloatArray, freeze_plan_s: FloatArray, params: PauseParams) -> FloatArray:
    """The plan time ``τ`` (N,) of each sample time ``t`` (N,), s, with a stop at each plan time.

    Args:
        t: (N,) evenly spaced sample times, s.
        freeze_plan_s: (K,) increasing plan times at which the walk stands still, s.
        params: the stops' durations.

    Returns:
        (N,) non-decreasing plan times, s; ``τ = t`` before the first stop's ramp.
    """
    freeze = np.asarray(freeze_plan_s, dtype=float)
    # a stop's rate ramp covers ramp_s / 2 of plan time on either side of its hold; each stop
    # before it has shifted plan time by ramp_s + pause_s
    cost = params.ramp_s + params.pause_s
    starts = freeze - 0.5 * params.ramp_s + cost * np.arange(freeze.size)
    dt = float(t[1] - t[0]) / _FINE
    fine = t[0] + dt * np.arange((t.size - 1) * _FINE + 1)
    rate = _rate(fine, starts, params)
    tau = t[0] + np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * dt)])
    return np.asarray(tau[::_FINE])


def real_times(plan_s: FloatArray, t: FloatArray, tau: FloatArray) -> FloatArray:
    """Sample times (s) at which the walk reaches the plan times ``plan_s`` (never a frozen one)."""
    moving = np.concatenate([[True], np.diff(tau) > 0.0])
    return np.asarray(np.interp(plan_s, tau[moving], t[moving]))


def warped_events(events: StanceEvents, t: FloatArray, tau: FloatArray) -> StanceEvents:
    """A foot's planned events (plan time) at their sample times."""
    return StanceEvents(
        real_times(events.initial_contact_s, t, tau),
        real_times(events.toe_off_s, t, tau),
        real_times(events.foot_flat_s.reshape(-1), t, tau).reshape(-1, 2),
    )


def pause_plan_times(
    events: dict[str, StanceEvents], walk_start_s: float, walk_end_s: float, count: int
) -> FloatArray:
    """Plan times of ``count`` stops spread over the walk, each in a double support (module docstring).

    Args:
        events: ``{side: StanceEvents}`` in plan time, s.
        walk_start_s: plan time the walk starts, s.
        walk_end_s: last plan time, s.
        count: number of stops.

    Returns:
        (count,) increasing plan times, s (fewer when the walk has too few double supports).
    """
    contacts = sorted((float(ic), side) for side, ev in events.items() for ic in ev.initial_contact_s)
    out: list[float] = []
    for k in range(1, count + 1):
        target = walk_start_s + k * (walk_end_s - walk_start_s) / (count + 1)
        lead = [(ic, s) for ic, s in contacts if ic <= target]
        if not lead:
            continue
        ic, side = lead[-1]
        trail = events["left" if side == "right" else "right"].toe_off_s
        after = trail[trail > ic]
        if after.size and (not out or ic > out[-1]):
            out.append(0.5 * (ic + float(after[0])))
    return np.asarray(out)
