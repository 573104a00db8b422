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
        min_walk_after_s: the walker must walk at least this long after the last stop, s
            (a stop longer than that leaves the walker standing at the end of the trial).
    """

    count: int = 0
    pause_s: float = 3.0
    ramp_s: float = 0.6
    min_walk_after_s: float = 2.0

    def longest_pause_s(self, duration_s: float, walk_start_s: float) -> float:
        """The longest ``pause_s`` (s) with which ``count`` stops fit in the walk (≤ 0: none fits).

        The stops are planned evenly over the walk's plan time (:func:`pause_plan_times`), and
        each delays the rest of the walk by ``ramp_s + pause_s``: the last one ends at about
        ``walk_start_s + count (duration_s - walk_start_s) / (count + 1) + count (ramp_s +
        pause_s)``, which must leave ``min_walk_after_s`` before ``duration_s`` (all in s).
        """
        n = max(self.count, 1)
        return ((duration_s - walk_start_s) / (n + 1) - self.min_walk_after_s) / n - self.ramp_s

    def needed_duration_s(self, walk_start_s: float) -> float:
        """The shortest trial (s) in which these stops fit (:meth:`longest_pause_s`)."""
        n = max(self.count, 1)
        return walk_start_s + (n + 1) * (n * (self.ramp_s + self.pause_s) + self.min_walk_after_s)

    def check_fits(self, duration_s: float, walk_start_s: float) -> None:
        """Refuse stops that do not fit in a ``duration_s`` (s) trial walking from ``walk_start_s`` (s).

        Raises:
            InputError: naming the longest stop that fits and the trial length needed.
        """
        if self.count and self.pause_s > self.longest_pause_s(duration_s, walk_start_s):
            longest = self.longest_pause_s(duration_s, walk_start_s)
            fits = f"stops of at most {longest:.3g} s fit" if longest > 0 else "no such stop fits"
            raise InputError(
                f"{self.count} stops of {self.pause_s:g} s do not fit in a {duration_s:g} s walk (at least "
                f"{self.min_walk_after_s:g} s of walking after the last): {fits}; shorten the stops or "
                f"make the trial at least {self.needed_duration_s(walk_start_s):.3g} s"
            )

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
