"""A treadmill walk: a straight walk on a belt that carries the walker back to one spot.

Gait labs record on treadmills as often as overground: long steady walks in a small room,
at a set speed. The belt runs at the walker's speed, so the walker stays over one patch of
the lab floor. Once the belt runs at a constant speed its frame is inertial, and a walk on
it is, to the sensors' accelerometers and gyros, a straight overground walk at the belt's
speed: the feet rest on the belt in stance (zero velocity in the belt's frame, which is what
zero-velocity updates assume), and stride length and gait speed are the belt-frame ones a
treadmill study reports. Three things differ, and the simulator makes them:

* the walk is straight: no bend of the path, no turn (:func:`straight`);
* while the belt speeds up at the start, its frame accelerates: the sensors measure in the
  lab (inertial) frame, whose points move by ``p_lab = p_belt − s(t)`` with ``s`` the belt's
  travel, so every sensor's specific force loses ``Rᵀ s̈`` (:func:`lab_specific_force`;
  here the belt follows the walker's start-up, one stride time from rest to speed);
* the magnetometers read the lab's field where the sensors are *in the lab*: the floor's
  disturbance stays nearly constant in time (each sensor over its own patch, the deck's
  height above the floor), and the drive motor under the front roller adds a dipole the
  feet swing towards and away from (:func:`lab_positions`, :func:`motor_dipole`). A
  disturbance that is constant in time is the one a variation check cannot see.

The walk's truth (events, stride lengths, step widths, positions) stays in the belt's frame.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..conventions import FloatArray
from ..errors import InputError
from .footsteps import WalkDraw

__all__ = [
    "TreadmillParams",
    "belt_travel",
    "lab_positions",
    "lab_specific_force",
    "motor_dipole",
    "straight",
]


@dataclass(frozen=True)
class TreadmillParams:
    """A treadmill's geometry and drive motor.

    Attributes:
        deck_m: Height of the belt above the lab floor, m: the floor's dipoles lie this
            much farther below the feet than in an overground walk.
        motor_moment_am2: Magnitude of the drive motor's magnetic moment, A·m² (0: no
            motor); its direction is drawn from the walk's seed. 2 A·m² adds about 3 µT
            (6 % of the earth's field) half a metre away and 15 µT at 0.3 m.
        motor_ahead_m: The motor's horizontal distance ahead of the pelvis's mean lab
            position, along the walking direction, m (under the front roller).
        motor_height_m: Its height above the lab floor, m.
    """

    deck_m: float = 0.2
    motor_moment_am2: float = 2.0
    motor_ahead_m: float = 0.8
    motor_height_m: float = 0.1

    def validate(self) -> None:
        """Raise :class:`InputError` for a negative or non-finite value."""
        values = (self.deck_m, self.motor_moment_am2, self.motor_ahead_m, self.motor_height_m)
        if not all(np.isfinite(v) and v >= 0.0 for v in values):
            raise InputError(
                "a treadmill needs finite deck_m, motor_moment_am2, motor_ahead_m and motor_height_m ≥ 0, "
                f"got {values}"
            )


def straight(d: WalkDraw) -> WalkDraw:
    """The walk ``d`` without its slow bend: a treadmill's constant heading."""
    return replace(d, turn_amplitude_rad=0.0)


def belt_travel(xy_m: FloatArray) -> FloatArray:
    """The belt's travel ``s(t)`` (N, 3), ENU m: the pelvis path's progress (N, 2), z = 0.

    The belt follows the walker, so in the lab the pelvis path stays at its start.
    """
    xy = np.asarray(xy_m, dtype=float)
    return np.column_stack([xy - xy[0], np.zeros(xy.shape[0])])


def lab_specific_force(
    acc: dict[str, FloatArray], rot: dict[str, FloatArray], t_s: FloatArray, travel_m: FloatArray
) -> dict[str, FloatArray]:
    """``{sensor: (N, 3)}`` specific force in the lab, m/s², from the belt frame's ``acc``.

    ``f_lab = f_belt − Rᵀ s̈`` with ``R`` (N, 3, 3) sensor → ENU in ``rot`` and ``s`` the
    belt's travel (N, 3), m, on the sample times ``t_s`` (N,), s; ``s̈`` is zero once the
    belt runs at a constant speed along a straight line.
    """
    s_dd = np.gradient(np.gradient(travel_m, t_s, axis=0), t_s, axis=0)
    return {k: a - np.einsum("nji,nj->ni", rot[k], s_dd) for k, a in acc.items()}


def lab_positions(
    pos: dict[str, FloatArray], travel_m: FloatArray, params: TreadmillParams
) -> dict[str, FloatArray]:
    """``{sensor: (N, 3)}`` positions in the lab, ENU m: belt frame minus travel, on the deck."""
    lift = np.array([0.0, 0.0, params.deck_m])
    return {k: p - travel_m + lift for k, p in pos.items()}


def motor_dipole(
    pelvis_lab_m: FloatArray, heading_rad: float, params: TreadmillParams, rng: np.random.Generator
) -> tuple[FloatArray, FloatArray]:
    """The drive motor as one dipole: position (1, 3) m and moment (1, 3) A·m², ENU.

    Placed ``motor_ahead_m`` ahead of the pelvis's mean lab position (``pelvis_lab_m``,
    (N, 3)) along ``heading_rad`` (from east), ``motor_height_m`` above the floor; its
    moment points in a direction drawn from ``rng``.
    """
    centre = np.asarray(pelvis_lab_m, dtype=float)[:, :2].mean(axis=0)
    ahead = centre + params.motor_ahead_m * np.array([np.cos(heading_rad), np.sin(heading_rad)])
    direction = rng.normal(size=3)
    moment = params.motor_moment_am2 * direction / np.linalg.norm(direction)
    return np.array([[*ahead, params.motor_height_m]]), moment[None, :]
