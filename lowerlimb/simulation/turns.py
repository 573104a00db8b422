"""A gait-lab walk: straight passes joined by turns about on the spot.

A gait lab's walkway is 6–10 m long, so a walk is a series of straight passes, the walker
turning about at each end (the real walk of ``gait/``: two passes, the pelvis turning 180°
in about 0.3 s on the left foot, which stood where it was put down and ended 80° from the
first pass). The bending walks of :mod:`lowerlimb.simulation.footsteps` never turn on the
spot, so nothing tested what a turn does to the gait events, the feet's still periods and
the strides around it. Here:

* the pelvis path is straight, then turns by 180° (left or right, drawn per turn) within
  :attr:`TurnParams.turn_s`, slowing to :attr:`TurnParams.speed_factor` of the walking
  speed at the turn's middle (:func:`turnaround_path`);
* a foot in stance **pivots** while flat (:attr:`TurnParams.pivot`): between foot-flat and
  heel-off it turns about the vertical through the middle of its sole by as much as the
  pelvis turns meanwhile (:func:`lowerlimb.simulation.footsteps.plan_feet`'s ``pivot``).
  The sole's middle stays put, the sensor does not: a pivoting foot is on the ground but
  not still, which is what a zero-velocity detector meets in a real turn;
* what the pelvis turns against a foot in stance outside the pivot, and against a foot in
  swing, the hip takes as rotation (:func:`hip_turn_rotation`), as in a step turn, so the
  ankle stays within its range.

A turn is no stop: the walker keeps stepping at the same cadence through it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import FloatArray
from ..errors import InputError
from .footsteps import WalkDraw
from .motions import smoothstep

__all__ = ["TurnParams", "hip_turn_rotation", "turn_starts", "turnaround_path"]


@dataclass(frozen=True)
class TurnParams:
    """Straight passes and the turns between them.

    Attributes:
        pass_s: Duration of each straight pass (the first from the start of walking), s.
            At 1.0–1.3 m/s, 6 s is a 6–8 m walkway.
        turn_s: Duration of the pelvis's 180° turn, s (about two steps).
        speed_factor: The walking speed at the turn's middle, as a fraction of the pass's.
        pivot: Whether a foot in stance pivots with the pelvis while flat.
    """

    pass_s: float = 6.0
    turn_s: float = 2.4
    speed_factor: float = 0.3
    pivot: bool = True

    def validate(self) -> None:
        """Raise :class:`InputError` for a pass or turn shorter than 0.5 s or a bad speed factor."""
        durations = np.array([self.pass_s, self.turn_s], dtype=float)
        if not np.all(np.isfinite(durations) & (durations >= 0.5)):
            raise InputError(
                f"turns need pass_s and turn_s of at least 0.5 s, got {self.pass_s} and {self.turn_s}"
            )
        if not (np.isfinite(self.speed_factor) and 0.0 <= self.speed_factor <= 1.0):
            raise InputError(f"a turn's speed_factor must lie in [0, 1], got {self.speed_factor}")


def turn_starts(p: TurnParams, t0: float, end_s: float) -> FloatArray:
    """(K,) start times of the turns that end before ``end_s``, s; walking starts at ``t0``."""
    k = np.arange(int(max(end_s - t0, 0.0) // (p.pass_s + p.turn_s)) + 1)
    starts = t0 + p.pass_s * (k + 1) + p.turn_s * k
    return np.asarray(starts[starts + p.turn_s <= end_s], dtype=float)


def turnaround_path(
    t: FloatArray, d: WalkDraw, t0: float, p: TurnParams, signs: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Heading (N,), rad; path point (N, 2), m; and start-up ramp (N,) of straight passes and turns.

    Args:
        t: (N,) plan times, s.
        d: The walk's draw (speed, initial heading, stride time for the start-up ramp).
        t0: Time walking starts, s.
        p: The passes and turns.
        signs: (K,) +1 (left, counter-clockwise) or −1 per turn, at least as many as
            :func:`turn_starts` gives for ``t``.
    """
    t = np.asarray(t, dtype=float)
    ramp = smoothstep(t, t0, d.stride_time_s)
    heading = np.full(t.size, d.heading0_rad)
    slow = np.zeros(t.size)
    for k, tk in enumerate(turn_starts(p, t0, float(t[-1]) + p.pass_s + p.turn_s)):
        heading += signs[k] * np.pi * smoothstep(t, float(tk), p.turn_s)
        s = np.clip((t - tk) / p.turn_s, 0.0, 1.0)
        slow += np.sin(np.pi * s) ** 2
    speed = d.speed_m_s * ramp * (1.0 - (1.0 - p.speed_factor) * slow)
    dt = np.diff(t, prepend=t[0])
    xy = np.cumsum((speed * dt)[:, None] * np.column_stack([np.cos(heading), np.sin(heading)]), axis=0)
    return heading, xy, ramp


def hip_turn_rotation(
    foot_rotation: FloatArray, pelvis_heading: FloatArray, side: str, toe_out_rad: float, ramp: FloatArray
) -> FloatArray:
    """(N,) hip internal rotation, rad, that takes the foot's heading against the pelvis's.

    Args:
        foot_rotation: (N, 3, 3) foot segment frame → ENU (x anterior).
        pelvis_heading: (N,) the pelvis path's heading, rad.
        side: ``"left"`` or ``"right"``.
        toe_out_rad: The foot's progression angle while walking (outwards positive), rad:
            a straight walk's foot, turned out by it, needs no rotation.
        ramp: (N,) 0 while standing (feet parallel), 1 once walking.

    Internal rotation turns the toes medially: to the right (clockwise, negative yaw) on the
    left leg, to the left on the right leg.
    """
    lat = 1.0 if side == "left" else -1.0
    yaw = np.arctan2(foot_rotation[:, 1, 0], foot_rotation[:, 0, 0])
    delta = (yaw - pelvis_heading - lat * toe_out_rad * ramp + np.pi) % (2.0 * np.pi) - np.pi
    return np.asarray(-lat * delta, dtype=float)
