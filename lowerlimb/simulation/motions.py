"""Joint-angle and pelvis trajectories of the simulated motions.

Every motion is a smooth function of time, multiplied by a quintic
smoothstep ``s(t)`` that is 0 during the initial standing period and rises to
1 over one second, so each trial starts still in the reference posture (all
joint angles zero). The shapes follow typical adult curves (Winter 2009 for
gait: hip flexion −10…+30°, knee 5…60° with a stance bump, ankle −15…+10°)
with per-seed variation of cadence and amplitudes, plus small incommensurate
sinusoids on the out-of-plane degrees of freedom (people are never perfectly
planar), which the spherical-joint calibration needs.

Motions whose feet stay on the ground (squat, half squat, sit-to-stand)
return ``pelvis_pos_m = None``: the simulator then moves the pelvis so that
the ankle centre stays fixed in the world.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..conventions import FloatArray

MOTIONS: tuple[str, ...] = ("walk", "squat", "half-squat", "knee-lift", "sit-to-stand", "mixed")


@dataclass
class MotionKinematics:
    """Trajectories on the sample times (N samples).

    Attributes:
        angles_rad: (N, 9) ISB joint angles, angles.csv order, rad.
        pelvis_euler_rad: (N, 3) pelvis tilt (about pelvis z), obliquity (x),
            rotation (y), applied after the heading, rad.
        yaw_rad: (N,) heading about the earth's vertical, rad.
        pelvis_pos_m: (N, 3) pelvis origin in the ENU world, m; None to keep
            the ankle centre fixed.
        gait_phase: (N,) unit gait phase of the instrumented leg for walks,
            0 at its initial contact (heel strike), 0.5 at the other foot's; None
            for motions without foot contacts.
    """

    angles_rad: FloatArray
    pelvis_euler_rad: FloatArray
    yaw_rad: FloatArray
    pelvis_pos_m: FloatArray | None
    gait_phase: FloatArray | None = None


def smoothstep(t: FloatArray, t0: float, duration: float) -> FloatArray:
    """Quintic 0→1 ramp on [t0, t0 + duration], C² continuous."""
    u = np.clip((np.asarray(t) - t0) / duration, 0.0, 1.0)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u**2)


def _bump(phase: FloatArray, centre: float, width: float) -> FloatArray:
    """Periodic Gaussian bump on a unit phase circle."""
    d = (phase - centre + 0.5) % 1.0 - 0.5
    return np.exp(-((d / width) ** 2))


def _wobble(t: FloatArray, rng: np.random.Generator, amp_deg: float) -> FloatArray:
    """Sum of two sinusoids with random incommensurate frequencies (0.15–0.7 Hz), rad."""
    out = np.zeros_like(t)
    for _ in range(2):
        f = rng.uniform(0.15, 0.7)
        out += (
            0.5
            * np.deg2rad(amp_deg)
            * rng.uniform(0.6, 1.0)
            * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
        )
    return out


def _out_of_plane(t: FloatArray, rng: np.random.Generator, scale: float = 1.0) -> dict[int, FloatArray]:
    """Small hip ad/rotation and ankle inversion/rotation wobble, by angle column index."""
    return {
        1: _wobble(t, rng, 8.0 * scale),  # hip adduction
        2: _wobble(t, rng, 10.0 * scale),  # hip internal rotation
        7: _wobble(t, rng, 8.0 * scale),  # ankle inversion
        8: _wobble(t, rng, 6.0 * scale),  # ankle internal rotation
    }


def walk(t: FloatArray, s: FloatArray, rng: np.random.Generator) -> MotionKinematics:
    """Level walking at 1.0–1.4 m/s with slow changes of heading.

    The gait phase is 0 at the instrumented foot's initial contact: hip flexion
    is at its maximum, the knee nearly straight before the loading-response
    bump (phase 0.15), push-off at 0.62, peak swing knee flexion at 0.72.
    """
    n = t.shape[0]
    stride_hz = rng.uniform(0.85, 1.0)
    phase = (stride_hz * t + rng.uniform()) % 1.0
    amp = rng.uniform(0.85, 1.15, size=3)
    deg = np.zeros((n, 9))
    deg[:, 0] = amp[0] * (10.0 + 20.0 * np.cos(2 * np.pi * phase) + 3.0 * np.cos(4 * np.pi * phase + 0.5))
    deg[:, 3] = amp[1] * (5.0 + 15.0 * _bump(phase, 0.15, 0.08) + 55.0 * _bump(phase, 0.72, 0.12))
    deg[:, 6] = amp[2] * (2.0 + 8.0 * _bump(phase, 0.42, 0.12) - 22.0 * _bump(phase, 0.62, 0.06))
    deg[:, 1] = 5.0 * np.sin(2 * np.pi * phase + 0.3)
    deg[:, 2] = 4.0 * np.sin(2 * np.pi * phase - 0.8)
    deg[:, 7] = 4.0 * np.sin(2 * np.pi * phase + 1.2)
    deg[:, 8] = 3.0 * np.sin(2 * np.pi * phase)
    angles = np.deg2rad(deg)
    for k, w in _out_of_plane(t, rng, 0.6).items():
        angles[:, k] += w
    angles *= s[:, None]
    pelvis = (
        np.deg2rad(
            np.column_stack(
                [
                    3.0 * np.sin(4 * np.pi * phase),
                    4.0 * np.sin(2 * np.pi * phase + 0.4),
                    5.0 * np.sin(2 * np.pi * phase - 0.3),
                ]
            )
        )
        * s[:, None]
    )
    turn_hz = rng.uniform(0.03, 0.06)
    yaw = rng.uniform(-np.pi, np.pi) + 0.8 * np.sin(2 * np.pi * turn_hz * t) * s
    # forward speed fluctuates twice per stride (±0.08–0.14 m/s) and the pelvis
    # sways laterally once per stride (±2–3 cm), as in normal gait
    speed = (rng.uniform(1.0, 1.4) + rng.uniform(0.08, 0.14) * np.cos(4 * np.pi * phase + 0.6)) * s
    dt = np.diff(t, prepend=t[0])
    heading = np.column_stack([np.cos(yaw), np.sin(yaw)])
    left = np.column_stack([-np.sin(yaw), np.cos(yaw)])
    xy = np.cumsum(speed[:, None] * heading * dt[:, None], axis=0)
    xy += (rng.uniform(0.02, 0.03) * np.sin(2 * np.pi * phase) * s)[:, None] * left
    z = 0.95 + 0.02 * np.cos(4 * np.pi * phase) * s
    return MotionKinematics(angles, pelvis, yaw, np.column_stack([xy, z]), gait_phase=phase)


def _cycle(t: FloatArray, period: float, hold: float) -> FloatArray:
    """0→1→0 cycle: smooth descent, hold at 1, smooth return, rest at 0."""
    move = 0.5 * (period - 2 * hold)
    u = t % period
    down = smoothstep(u, hold, move)
    up = smoothstep(u, 2 * hold + move, move)
    return np.asarray(down - up)


def squat(t: FloatArray, s: FloatArray, rng: np.random.Generator, depth: float = 1.0) -> MotionKinematics:
    """Repeated squats; ``depth`` 1 = full (hip ≈ 95°, knee ≈ 110°), 0.5 = half squat."""
    n = t.shape[0]
    period = rng.uniform(3.0, 4.0)
    c = _cycle(t + rng.uniform(0, period), period, rng.uniform(0.2, 0.4))
    deg = np.zeros((n, 9))
    deg[:, 0] = depth * rng.uniform(85, 100) * c
    deg[:, 3] = depth * rng.uniform(100, 120) * c
    deg[:, 6] = depth * rng.uniform(20, 30) * c
    angles = np.deg2rad(deg)
    for k, w in _out_of_plane(t, rng).items():
        angles[:, k] += w
    angles *= s[:, None]
    pelvis = (
        np.column_stack([np.deg2rad(-25.0) * depth * c, _wobble(t, rng, 5.0), _wobble(t, rng, 8.0)])
        * s[:, None]
    )
    yaw = rng.uniform(-np.pi, np.pi) + _wobble(t, rng, 30.0) * s
    return MotionKinematics(angles, pelvis, yaw, None)


def half_squat(t: FloatArray, s: FloatArray, rng: np.random.Generator) -> MotionKinematics:
    """Half squats (hip ≈ 45°, knee ≈ 55°)."""
    return squat(t, s, rng, depth=0.5)


def knee_lift(t: FloatArray, s: FloatArray, rng: np.random.Generator) -> MotionKinematics:
    """Alternating knee lifts: hip and knee to ≈ 90° while standing on the other leg."""
    n = t.shape[0]
    period = rng.uniform(2.2, 3.0)
    c = _cycle(t + rng.uniform(0, period), period, rng.uniform(0.1, 0.3))
    deg = np.zeros((n, 9))
    deg[:, 0] = rng.uniform(75, 95) * c
    deg[:, 3] = rng.uniform(80, 100) * c
    deg[:, 6] = -rng.uniform(10, 25) * c
    angles = np.deg2rad(deg)
    for k, w in _out_of_plane(t, rng, 1.3).items():
        angles[:, k] += w
    angles *= s[:, None]
    pelvis = np.column_stack([np.deg2rad(-8.0) * c, _wobble(t, rng, 8.0), _wobble(t, rng, 10.0)]) * s[:, None]
    yaw = rng.uniform(-np.pi, np.pi) + _wobble(t, rng, 40.0) * s
    pos = np.column_stack([0.01 * np.sin(0.7 * t), 0.01 * np.cos(0.5 * t), np.full(n, 0.95)]) * 1.0
    pos[:, :2] *= s[:, None]
    return MotionKinematics(angles, pelvis, yaw, pos)


def sit_to_stand(t: FloatArray, s: FloatArray, rng: np.random.Generator) -> MotionKinematics:
    """Repeated sit-to-stand: hip ≈ 95°, knee ≈ 95°, pelvis tilting forward on the way."""
    n = t.shape[0]
    period = rng.uniform(5.0, 6.5)
    c = _cycle(t + rng.uniform(0, period), period, rng.uniform(0.8, 1.2))
    deg = np.zeros((n, 9))
    deg[:, 0] = rng.uniform(85, 100) * c
    deg[:, 3] = rng.uniform(85, 100) * c
    deg[:, 6] = rng.uniform(8, 18) * c
    angles = np.deg2rad(deg)
    for k, w in _out_of_plane(t, rng, 0.8).items():
        angles[:, k] += w
    angles *= s[:, None]
    lean = np.sin(np.pi * c) ** 2  # forward lean in the transitions
    pelvis = (
        np.column_stack([np.deg2rad(-20.0) * lean, _wobble(t, rng, 4.0), _wobble(t, rng, 6.0)]) * s[:, None]
    )
    yaw = rng.uniform(-np.pi, np.pi) + _wobble(t, rng, 10.0) * s
    return MotionKinematics(angles, pelvis, yaw, None)


def mixed(t: FloatArray, s: FloatArray, rng: np.random.Generator) -> MotionKinematics:
    """A calibration motion rich in every degree of freedom: knee lifts with hip circles.

    Standing on the other leg: hip flexion 0–80° in knee lifts with hip
    ab/adduction (±20°) and rotation (±15°) circles, knee bending with the
    hip, ankle circles (dorsiflexion ±20°, inversion ±15°, rotation ±10°) and a
    pelvis that tilts, lists and turns briskly (±6–16°, up to 1 Hz). It excites the hip and ankle
    centres along every direction, which walking and squats do not.
    """
    n = t.shape[0]

    def sine(amp_deg: float, f_lo: float, f_hi: float) -> FloatArray:
        f = rng.uniform(f_lo, f_hi)
        return np.asarray(np.deg2rad(amp_deg) * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)))

    period = rng.uniform(2.5, 3.2)
    c = _cycle(t + rng.uniform(0, period), period, rng.uniform(0.1, 0.3))
    angles = np.zeros((n, 9))
    angles[:, 0] = np.deg2rad(rng.uniform(60, 80)) * c + sine(10, 0.2, 0.3)
    angles[:, 1] = sine(20, 0.25, 0.45)
    angles[:, 2] = sine(15, 0.3, 0.55)
    angles[:, 3] = np.deg2rad(rng.uniform(70, 90)) * c + np.deg2rad(10) * (1 + np.sin(2 * np.pi * 0.37 * t))
    angles[:, 6] = sine(20, 0.5, 0.8)
    angles[:, 7] = sine(15, 0.45, 0.7)
    angles[:, 8] = sine(10, 0.35, 0.6)
    angles *= s[:, None]
    # the pelvis must turn briskly, not only far: its angular acceleration is what
    # makes the hip centre visible from the pelvis sensor
    pelvis = (
        np.column_stack(
            [
                sine(6, 0.6, 1.0) + sine(6, 0.15, 0.3),
                sine(6, 0.7, 1.1),
                sine(8, 0.5, 0.9) + sine(8, 0.1, 0.25),
            ]
        )
        * s[:, None]
    )
    yaw = rng.uniform(-np.pi, np.pi) + sine(25, 0.05, 0.1) * s
    pos = np.column_stack(
        [0.03 * np.sin(0.9 * t), 0.03 * np.cos(0.7 * t), np.full(n, 0.95) + 0.02 * np.sin(1.3 * t)]
    )
    pos[:, :2] *= s[:, None]
    pos[:, 2] = 0.95 + (pos[:, 2] - 0.95) * s
    return MotionKinematics(angles, pelvis, yaw, pos)


MOTION_FUNCTIONS: dict[str, Callable[[FloatArray, FloatArray, np.random.Generator], MotionKinematics]] = {
    "walk": walk,
    "squat": squat,
    "half-squat": half_squat,
    "knee-lift": knee_lift,
    "sit-to-stand": sit_to_stand,
    "mixed": mixed,
}
