"""A two-leg walk planned from footprints: what each foot and the pelvis do in the world.

A real walk is constrained by the ground: a foot in stance does not slide, the two
legs move in opposite phase and both feet are down during double support. The
one-leg motions of :mod:`lowerlimb.simulation.motions` prescribe joint angles and
cannot honour that for two legs at once. Here the walk is planned the other way
round, the way gait is described clinically (Perry & Burnfield 2010, *Gait
Analysis*, ch. 2–4):

1. **Timing.** Stride time ``T``; the left foot's initial contacts (IC) every ``T``,
   the right's half a stride later; toe-off (TO) at the stance fraction ``β`` of the
   stride, so each double support lasts ``(β − ½) T``.
2. **Footprints.** Each stance has a footprint: the ankle centre at foot-flat and the
   foot's heading. It lies beside the pelvis path (half the step width to its side)
   where the pelvis will be in mid-stance, turned out by the foot's toe-out angle.
3. **The foot in stance** rolls over the rockers: from IC it pivots about the
   heel point (pitch ``θ_ic`` toes up → 0, heel rocker), stays flat and still
   (ankle rocker, the foot-stationary period), then the heel rises about the
   metatarsophalangeal (MTP) joint while the toes lie flat (forefoot rocker), and
   in pre-swing the toe segment tilts about the toe tip, the last point in contact,
   until TO, when the tip leaves the ground (toe rocker; :mod:`.toe_rocker`). The
   rearfoot's plantarflexion rate peaks before TO; its pitch reaches ``−θ_to`` at TO
   and its largest plantarflexion shortly after. Each pivot is fixed in the world,
   so the contact point has zero velocity throughout stance and the whole foot is
   still while flat.
4. **The foot in swing** goes from its TO pose to the next IC pose along quintic
   Hermite curves that match position and velocity at both ends; at both ends the
   floor's push starts or stops, so the acceleration steps there (C¹ joins): the swing
   starts with the ankle released (:func:`_released`) and ends at rest on the heel.
   After TO the rearfoot keeps its plantarflexion rate, then is stopped
   (:func:`_post_toe_off_pitch`); a lift at mid-swing gives the toe its drawn minimum
   clearance (:func:`_mid_swing_lift`); the MTP joint returns to neutral by the next
   contact.
5. **The pelvis** follows the path at the walking speed (ramped up from standing),
   sways over the stance foot, tilts, drops and rotates a few degrees per stride;
   its height is lowered where a leg could not otherwise reach its foot with the
   knee flexed at least ``min_knee_deg`` (:func:`pelvis_height`).

The leg joint angles then follow by inverse kinematics
(:mod:`lowerlimb.simulation.leg_ik`). The trial starts with both feet flat under
the hips in the reference posture (all joint angles zero); the right foot steps
first.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..conventions import GRAVITY_MPS2, FloatArray, rot_z
from .motions import smoothstep
from .toe_rocker import PreSwingParams, push_off_shape, toe_roll_shape

__all__ = [
    "FootPlan",
    "StanceEvents",
    "PACES",
    "PACE_RANGES",
    "PaceRanges",
    "WalkDraw",
    "draw_walk",
    "first_contacts",
    "pelvis_path",
    "plan_feet",
]

#: The pelvis passes over the foot's ankle this fraction of the stride after IC (Perry 2010:
#: ankle about 0.26 m ahead of the hip at IC and 0.40 m behind at toe-off).
MID_STANCE_FRACTION = 0.20

#: 1 / max of s⁴(1 − s)⁴ on [0, 1] (at s = ½): the swing lift adds height where the toe passes
#: closest to the floor, at mid-swing (minimum toe clearance; Winter 1992). It joins toe-off
#: to third order (no step in acceleration or jerk), so it does not re-accelerate the foot
#: upwards in initial swing: there the ankle's rise decelerates at nearly −g (as measured on
#: the real walk of ``gait/``, Vicon ankle centre: −8 … −10 m/s² from 50 to 100 ms after
#: toe-off) and peaks early in swing, ~15 % into it.
_LIFT_NORM = 2.0**8

#: Rotation of a segment frame (x anterior, y up, z right) at zero heading in ENU.
R_ENU_SEGMENT0 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class WalkDraw:
    """The random choices of one simulated walk (drawn by :func:`draw_walk`).

    Attributes:
        stride_time_s: Stride time T, s.
        speed_m_s: Steady walking speed, m/s.
        stance_fraction: Stance share β of the stride (TO at β T after IC).
        foot_flat_fraction: Foot-flat onset after IC, fraction of T.
        heel_off_fraction: Heel-off after IC, fraction of T.
        ic_pitch_rad: Foot pitch at IC, toes up, rad.
        to_pitch_rad: Foot pitch at TO, toes down (positive number), rad.
        step_width_m: Lateral distance between the two feet's ankle centres, m.
        toe_out_rad: ``(left, right)`` foot progression angle, outwards positive, rad.
        min_toe_clearance_m: Height of the toe tip above the floor where it passes closest
            to it, about mid-swing, m (:func:`_mid_swing_lift`).
        pelvis_drop_m: Pelvis lowering in mid-stance while walking, m.
        heading0_rad: Initial heading (walking direction from ENU east), rad.
        turn_amplitude_rad: Amplitude of the slow heading oscillation, rad.
        turn_hz: Its frequency, Hz.
        sway_m: Lateral pelvis sway amplitude, m.
        pelvis_deg: Pelvis tilt, obliquity and rotation amplitudes, deg.
        hip_rotation_deg: Hip internal-rotation amplitude (both legs), deg.
        swing_peak_fraction: The swing foot's forward velocity peaks this fraction of the
            swing after toe-off (at minimum toe clearance, about mid-swing).
        plantarflexion_hold_s: After toe-off the rearfoot keeps its plantarflexion rate
            this long, s (:func:`_post_toe_off_pitch`).
        plantarflexion_stop_s: Then its rate falls to zero within this time, s: the largest
            plantarflexion comes ``hold + stop`` after toe-off.
        pace_change: Relative amplitude of a slow change of walking speed at constant
            cadence (the step length follows), 0 for a steady walk.
        pace_hz: Frequency of that change and of the step width's, Hz.
        width_change: Relative amplitude of the slow change of step width.
    """

    stride_time_s: float
    speed_m_s: float
    stance_fraction: float
    foot_flat_fraction: float
    heel_off_fraction: float
    ic_pitch_rad: float
    to_pitch_rad: float
    step_width_m: float
    toe_out_rad: tuple[float, float]
    min_toe_clearance_m: float
    pelvis_drop_m: float
    heading0_rad: float
    turn_amplitude_rad: float
    turn_hz: float
    sway_m: float
    pelvis_deg: tuple[float, float, float]
    hip_rotation_deg: float
    swing_peak_fraction: float
    plantarflexion_hold_s: float
    plantarflexion_stop_s: float
    pace_change: float = 0.0
    pace_hz: float = 0.0
    width_change: float = 0.0


#: Walking paces the simulator draws from (:func:`draw_walk`).
PACES = ("normal", "slow", "shuffle")


@dataclass(frozen=True)
class PaceRanges:
    """The ranges of the pace-dependent :class:`WalkDraw` fields (uniform draws).

    Attributes:
        stride_time_s: Stride time, s.
        speed_m_s: Walking speed, m/s.
        stance_fraction: Stance share of the stride.
        heel_off_fraction: Heel-off after IC, fraction of the stride.
        ic_pitch_deg: Foot pitch at IC, toes up, deg.
        to_pitch_deg: Foot pitch at TO, toes down, deg.
        step_width_m: Step width, m.
        pelvis_deg: Pelvis tilt, obliquity and rotation amplitude ranges, deg.
    """

    stride_time_s: tuple[float, float]
    speed_m_s: tuple[float, float]
    stance_fraction: tuple[float, float]
    heel_off_fraction: tuple[float, float]
    ic_pitch_deg: tuple[float, float]
    to_pitch_deg: tuple[float, float]
    step_width_m: tuple[float, float]
    pelvis_deg: tuple[tuple[float, float], tuple[float, float], tuple[float, float]]


#: ``normal``: a healthy adult's self-selected pace (Perry & Burnfield 2010; Winter 2009).
#: ``slow``: the pace of older adults and of many clinical gait studies, 0.55-0.85 m/s with
#: a stride of 1.3-1.55 s (77-92 steps/min): stance and double support lengthen, the step
#: widens and the pelvis moves less (Perry & Burnfield 2010, ch. 25; Murray et al. 1984;
#: Kirtley 2006, ch. 5). The foot still pushes off: the real walk of ``gait/`` (0.8 m/s,
#: 1.43 s strides, Vicon heel and toe markers) has a stance of 63-68 %, the heel 10 mm up
#: at 24-42 % of the stride, the foot pitched 50-60° down at toe-off and 20-35° up at
#: initial contact, a foot rate of 6.6-8.8 rad/s before toe-off and the forefoot's loading
#: peak in the specific force (20-24 m/s²) at toe-off, as at the normal pace. A first
#: draft with a later heel-off (38-45 %) and less pitch (8-15° at contact, 40-55° at
#: toe-off) had no such peak (the magnitude fell smoothly through toe-off) and timed every
#: toe-off 40-50 ms late.
#: ``shuffle``: a shuffling gait (Parkinson's disease; Morris et al. 1994, Brain 117;
#: Perry & Burnfield 2010, ch. 26): short strides at a near-normal cadence, 0.4-0.7 m/s,
#: a flat foot at contact (5-12°), a weak push-off (30-45° at toe-off, late heel-off) and a
#: long stance. Its forefoot barely loads before toe-off.
PACE_RANGES: dict[str, PaceRanges] = {
    "normal": PaceRanges(
        stride_time_s=(1.0, 1.15),
        speed_m_s=(1.0, 1.3),
        stance_fraction=(0.58, 0.62),
        heel_off_fraction=(0.30, 0.38),
        ic_pitch_deg=(14.0, 22.0),
        to_pitch_deg=(55.0, 65.0),
        step_width_m=(0.08, 0.14),
        pelvis_deg=((2.0, 4.0), (3.0, 5.0), (4.0, 7.0)),
    ),
    "slow": PaceRanges(
        stride_time_s=(1.3, 1.55),
        speed_m_s=(0.55, 0.85),
        stance_fraction=(0.63, 0.67),
        heel_off_fraction=(0.32, 0.40),
        ic_pitch_deg=(14.0, 22.0),
        to_pitch_deg=(48.0, 60.0),
        step_width_m=(0.10, 0.18),
        pelvis_deg=((1.4, 2.8), (2.1, 3.5), (2.8, 4.9)),
    ),
    "shuffle": PaceRanges(
        stride_time_s=(1.0, 1.3),
        speed_m_s=(0.4, 0.7),
        stance_fraction=(0.63, 0.68),
        heel_off_fraction=(0.38, 0.45),
        ic_pitch_deg=(5.0, 12.0),
        to_pitch_deg=(30.0, 45.0),
        step_width_m=(0.10, 0.16),
        pelvis_deg=((1.2, 2.4), (1.8, 3.0), (2.4, 4.2)),
    ),
}


def draw_walk(rng: np.random.Generator, pace: str = "normal") -> WalkDraw:
    """Draw an adult walk at ``pace`` (:data:`PACE_RANGES`; Perry & Burnfield 2010, Winter 2009).

    The draws come in one order whatever the pace, so a seed's other choices (heading,
    toe-out, sway, …) are the same at both paces.

    Raises:
        ValueError: ``pace`` not in :data:`PACES`.
    """
    if pace not in PACE_RANGES:
        raise ValueError(f"pace must be one of {', '.join(PACES)}, not {pace!r}")
    r = PACE_RANGES[pace]

    def u(lo_hi: tuple[float, float]) -> float:
        return float(rng.uniform(*lo_hi))

    uniform = rng.uniform
    return WalkDraw(
        stride_time_s=u(r.stride_time_s),
        speed_m_s=u(r.speed_m_s),
        stance_fraction=u(r.stance_fraction),
        foot_flat_fraction=uniform(0.07, 0.10),
        heel_off_fraction=u(r.heel_off_fraction),
        ic_pitch_rad=np.deg2rad(u(r.ic_pitch_deg)),
        to_pitch_rad=np.deg2rad(u(r.to_pitch_deg)),
        step_width_m=u(r.step_width_m),
        toe_out_rad=(np.deg2rad(uniform(2.0, 10.0)), np.deg2rad(uniform(2.0, 10.0))),
        # minimum toe clearance 1.29 ± 0.45 cm (Winter 1992, healthy young adults)
        min_toe_clearance_m=uniform(0.008, 0.02),
        pelvis_drop_m=uniform(0.003, 0.008),
        heading0_rad=uniform(-np.pi, np.pi),
        turn_amplitude_rad=uniform(0.3, 0.8),
        turn_hz=uniform(0.03, 0.06),
        sway_m=uniform(0.015, 0.03),
        pelvis_deg=(u(r.pelvis_deg[0]), u(r.pelvis_deg[1]), u(r.pelvis_deg[2])),
        hip_rotation_deg=uniform(2.0, 5.0),
        # the foot's forward velocity peaks at minimum toe clearance (Winter 1992; Perry &
        # Burnfield 2010, ch. 8: mid-swing)
        swing_peak_fraction=uniform(0.5, 0.6),
        **_draw_release(rng.spawn(1)[0]),
    )


def _draw_release(rng: np.random.Generator) -> dict[str, float]:
    """The post-toe-off rearfoot phase of :class:`WalkDraw`, from its own child stream.

    A child stream (:meth:`numpy.random.Generator.spawn` does not advance ``rng``) leaves
    every other draw of a seed, and the sensor placements drawn after the walk, as they were.
    """
    u = rng.uniform
    return {"plantarflexion_hold_s": u(0.015, 0.03), "plantarflexion_stop_s": u(0.025, 0.04)}


@dataclass(frozen=True)
class StanceEvents:
    """True gait events of one foot.

    Attributes:
        initial_contact_s: (K,) heel contacts, s.
        toe_off_s: (M,) toe-offs, s.
        foot_flat_s: (P, 2) start and end of each foot-flat (stationary) period, s.
    """

    initial_contact_s: FloatArray
    toe_off_s: FloatArray
    foot_flat_s: FloatArray


@dataclass(frozen=True)
class FootPlan:
    """One foot's planned motion on the sample times.

    Attributes:
        ankle_m: (N, 3) ankle centre in ENU, m.
        rotation: (N, 3, 3) foot segment frame → ENU.
        events: The foot's true events.
        toe_tip_m: (N, 3) tip of the (sensorless) toe segment in ENU, m: on the ground and
            still from foot-flat until toe-off, which is when it leaves the ground.
    """

    ankle_m: FloatArray
    rotation: FloatArray
    events: StanceEvents
    toe_tip_m: FloatArray


@dataclass(frozen=True)
class _FootGeometry:
    """Points of the foot in its segment frame (origin at the ankle centre), m.

    ``heel`` and ``toe`` lie on the sole; ``mtp`` is the metatarsophalangeal joint centre,
    the hinge of the (sensorless) toe segment that reaches from it to ``toe``.
    """

    heel: FloatArray
    mtp: FloatArray
    toe: FloatArray


@dataclass(frozen=True)
class _Stance:
    """One stance: footprint and event times (``ic`` is None for the standing start).

    ``pivot`` (rad) turns the flat foot about the vertical through the middle of its sole
    between foot-flat and heel-off (:mod:`lowerlimb.simulation.turns`); ``heading`` is the
    foot's before it.
    """

    ankle: FloatArray
    heading: float
    ic: float | None
    foot_flat: float
    heel_off: float
    toe_off: float
    pivot: float = 0.0


def _stance_pose(
    st: _Stance, d: WalkDraw, foot: _FootGeometry, T: float, pre: PreSwingParams
) -> Callable[[float], tuple]:
    """Pose ``t ↦ (ankle (3,), pitch, heading, MTP dorsiflexion)`` over the rockers of ``st``.

    Pitch and MTP dorsiflexion in rad; the push-off follows :mod:`.toe_rocker`.
    """
    R_flat = rot_z(st.heading) @ R_ENU_SEGMENT0
    heel_w = st.ankle + R_flat @ foot.heel
    # the pivot: about the vertical through the sole's middle, the foot's pose after it
    centre = 0.5 * (heel_w + st.ankle + R_flat @ foot.mtp)
    centre[2] = 0.0
    ankle_end = st.ankle if st.pivot == 0.0 else centre + rot_z(st.pivot) @ (st.ankle - centre)
    heading_end = st.heading + st.pivot
    R_end = rot_z(heading_end) @ R_ENU_SEGMENT0
    toe_w = ankle_end + R_end @ foot.toe
    standing = st.ic is None
    # largest plantarflexion after toe-off, and the pitch scale that puts the draw's
    # to_pitch at toe-off
    t_max = st.toe_off + pre.largest_plantarflexion_fraction * T
    u_to = (st.toe_off - st.heel_off) / (t_max - st.heel_off)
    pitch_max = d.to_pitch_rad / push_off_shape(u_to, standing)
    # pre-swing: from the other foot's contact to toe-off, at most max_toe_roll_s
    roll = min((d.stance_fraction - 0.5) * T, pre.max_toe_roll_s)
    # the toe segment's tilt at toe-off: the rearfoot's pitch less the MTP dorsiflexion
    toe_tilt = max(d.to_pitch_rad - np.deg2rad(pre.mtp_at_toe_off_deg), 0.0)

    def pose(t: float) -> tuple[FloatArray, float, float, float]:
        if st.ic is not None and t < st.foot_flat:
            v = (t - st.ic) / (st.foot_flat - st.ic)
            # the foot is most toes-up at contact (rate 0); the floor then slaps it down
            p = d.ic_pitch_rad * (1.0 - v) ** 3 * (1.0 + 3.0 * v)
            return heel_w - R_flat @ rot_z(p) @ foot.heel, p, st.heading, 0.0
        if t <= st.heel_off:
            if st.pivot == 0.0:
                return st.ankle.copy(), 0.0, st.heading, 0.0
            turned = st.pivot * float(smoothstep(np.array(t), st.foot_flat, st.heel_off - st.foot_flat))
            return centre + rot_z(turned) @ (st.ankle - centre), 0.0, st.heading + turned, 0.0
        p = -pitch_max * push_off_shape((t - st.heel_off) / (t_max - st.heel_off), standing)
        phi = -toe_tilt * toe_roll_shape((t - st.toe_off + roll) / roll, pre.toe_roll_power)  # toe pitch
        # the toe tip stays put; the MTP joint turns about it, the rearfoot about the MTP joint
        mtp_w = toe_w + R_end @ rot_z(phi) @ (foot.mtp - foot.toe)
        return mtp_w - R_end @ rot_z(p) @ foot.mtp, p, heading_end, phi - p

    return pose


def _state(f: Callable[[float], tuple], t: float, eps: float = 1e-4) -> tuple[FloatArray, ...]:
    """Value, first and second derivative of ``f``'s (ankle, pitch, heading, MTP) at ``t``."""
    vals = [np.concatenate([f(t + k * eps)[0], f(t + k * eps)[1:]]) for k in (-1, 0, 1)]
    return vals[1], (vals[2] - vals[0]) / (2 * eps), (vals[2] - 2 * vals[1] + vals[0]) / eps**2


def _hermite5(
    y0: FloatArray,
    v0: FloatArray,
    a0: FloatArray,
    y1: FloatArray,
    v1: FloatArray,
    a1: FloatArray,
    D: float,
    s: FloatArray,
) -> FloatArray:
    """Quintic Hermite (len(s), dim) on s ∈ [0, 1] over a duration ``D`` (s)."""
    s = s[:, None]
    h0 = 1 - 10 * s**3 + 15 * s**4 - 6 * s**5
    h1 = s - 6 * s**3 + 8 * s**4 - 3 * s**5
    h2 = 0.5 * s**2 - 1.5 * s**3 + 1.5 * s**4 - 0.5 * s**5
    h3 = 0.5 * s**3 - s**4 + 0.5 * s**5
    h4 = -4 * s**3 + 7 * s**4 - 3 * s**5
    h5 = 10 * s**3 - 15 * s**4 + 6 * s**5
    return np.asarray(y0 * h0 + v0 * D * h1 + a0 * D**2 * h2 + a1 * D**2 * h3 + v1 * D * h4 + y1 * h5)


def pelvis_path(t: FloatArray, d: WalkDraw, t0: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Heading (N,), rad; path point (N, 2), m; and the start-up ramp (N,) of the pelvis."""
    ramp = smoothstep(t, t0, d.stride_time_s)
    heading = d.heading0_rad + d.turn_amplitude_rad * np.sin(2 * np.pi * d.turn_hz * (t - t0)) * ramp
    speed = d.speed_m_s * ramp * (1.0 + d.pace_change * np.sin(2 * np.pi * d.pace_hz * (t - t0)))
    dt = np.diff(t, prepend=t[0])
    xy = np.cumsum((speed * dt)[:, None] * np.column_stack([np.cos(heading), np.sin(heading)]), axis=0)
    return heading, xy, ramp


def first_contacts(d: WalkDraw, t0: float) -> dict[str, float]:
    """Time of each foot's first initial contact (s) when the right heel rises at ``t0`` (s)."""
    T, beta = d.stride_time_s, d.stance_fraction
    right = t0 + (beta - d.heel_off_fraction) * T + (1.0 - beta) * T
    return {"right": right, "left": right + 0.5 * T}


def _stances(
    side: str,
    d: WalkDraw,
    t: FloatArray,
    t0: float,
    path: tuple[FloatArray, FloatArray],
    stand: FloatArray,
    pivot: bool = False,
) -> list[_Stance]:
    """The stances of one foot: the standing start, then one per IC until the trial ends.

    With ``pivot`` each foot turns while flat by what the path turns from foot-flat to
    heel-off, starting from the path's heading at foot-flat.
    """
    T, beta = d.stride_time_s, d.stance_fraction
    heading, xy = path
    lat = 1.0 if side == "left" else -1.0
    first_ic = first_contacts(d, t0)[side]
    first_to = first_ic - (1.0 - beta) * T
    out = [
        _Stance(
            stand, float(heading[0]), None, -np.inf, first_to - (beta - d.heel_off_fraction) * T, first_to
        )
    ]
    toe_out = d.toe_out_rad[0 if side == "left" else 1]
    ic = first_ic
    while ic < t[-1] + T:
        t_mid = ic + MID_STANCE_FRACTION * T
        psi = float(np.interp(t_mid, t, heading))
        c = np.array([np.interp(t_mid, t, xy[:, 0]), np.interp(t_mid, t, xy[:, 1])])
        if t_mid > t[-1]:  # extrapolate the path past the end
            c = xy[-1] + (t_mid - t[-1]) * d.speed_m_s * np.array([np.cos(psi), np.sin(psi)])
        left_dir = np.array([-np.sin(psi), np.cos(psi)])
        width = d.step_width_m * (1.0 + d.width_change * np.sin(2 * np.pi * d.pace_hz * (t_mid - t0) + 1.0))
        ankle = np.array([*(c + lat * 0.5 * width * left_dir), stand[2]])
        flat, heel_off = ic + d.foot_flat_fraction * T, ic + d.heel_off_fraction * T
        turn = 0.0
        if pivot:
            psi = float(np.interp(flat, t, heading))
            turn = float(np.interp(heel_off, t, heading)) - psi
        out.append(_Stance(ankle, psi + lat * toe_out, ic, flat, heel_off, ic + beta * T, turn))
        ic += T
    return out


def _bump(s: FloatArray | float, order: int = 0, k: int = 3) -> FloatArray:
    """``s³(1 − s)ᵏ`` (order 0) or its first or second derivative in ``s``, on s ∈ [0, 1], k ≥ 3.

    Zero to second order at both ends: added to a quintic Hermite curve it keeps the end
    conditions (position, velocity, acceleration) and spends one more degree of freedom.
    """
    s = np.asarray(s, dtype=float)
    r = 1.0 - s
    if order == 0:
        return np.asarray(s**3 * r**k)
    if order == 1:
        return np.asarray(3.0 * s**2 * r**k - k * s**3 * r ** (k - 1))
    return np.asarray(6.0 * s * r**k - 6.0 * k * s**2 * r ** (k - 1) + k * (k - 1) * s**3 * r ** (k - 2))


def _hermite_derivative(
    ends: tuple[FloatArray, ...], D: float, s: float, order: int, eps: float = 1e-4
) -> FloatArray:
    """First or second derivative in ``s`` of :func:`_hermite5` (``ends``: its six ends) at ``s``."""
    y0, v0, a0, y1, v1, a1 = ends
    y = _hermite5(y0, v0, a0, y1, v1, a1, D, np.array([s - eps, s, s + eps]))
    if order == 1:
        return np.asarray((y[2] - y[0]) / (2 * eps))
    return np.asarray((y[2] - 2 * y[1] + y[0]) / eps**2)


def _post_toe_off_pitch(
    p0: float, w0: float, hold_s: float, stop_s: float, tau: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Rearfoot pitch (rad) and rate (rad/s) ``tau`` s after toe-off, over hold and stop.

    The rate stays at its toe-off value ``w0`` (rad/s) for ``hold_s``, then falls to zero
    within ``stop_s`` along ``1 − smoothstep``: the pitch is ``p0`` (rad) at toe-off and
    ``p0 + w0 (hold + stop / 2)`` at the largest plantarflexion.
    """
    x = np.clip((tau - hold_s) / stop_s, 0.0, 1.0)
    pitch = p0 + w0 * (np.minimum(tau, hold_s) + stop_s * (x - x**3 + 0.5 * x**4))
    rate = w0 * (1.0 - 3.0 * x**2 + 2.0 * x**3)
    return np.asarray(pitch), np.asarray(rate)


def _swing(ends: tuple, D: float, s: FloatArray, d: WalkDraw, lift_m: float = 0.0) -> FloatArray:
    """(len(s), 6) swing from toe-off (s = 0) to the next contact (s = 1), as in :func:`_foot_samples`.

    Each coordinate is the quintic Hermite curve between the two stance states ``ends`` (value,
    rate and acceleration at toe-off and contact, six arrays of (6,)), except the rearfoot
    pitch. The ankle's progression (along the horizontal line from toe-off to contact)
    spends a sextic's freedom (:func:`_bump`) on being fastest at ``d.swing_peak_fraction``
    of the swing, mid-swing, where the toe passes closest to the floor (peak forward foot
    velocity at minimum toe clearance: Winter 1992, "Foot trajectory in human gait: a
    precise and multifactorial motor control task", Phys. Ther. 72(1); Perry & Burnfield
    2010, ch. 8). Then the lift ``lift_m`` (:data:`_LIFT_NORM`, :func:`_mid_swing_lift`)
    raises the ankle at mid-swing.

    The rearfoot pitch keeps its toe-off rate for ``d.plantarflexion_hold_s`` and is then
    stopped within ``d.plantarflexion_stop_s`` (:func:`_post_toe_off_pitch`): the foot's
    plantarflexion is not braked until the toe has left, and then abruptly, by the
    dorsiflexors' burst at toe-off (tibialis anterior: onset in pre-swing, first peak in
    initial swing; Perry & Burnfield 2010, ch. 7, and Winter 2009, *Biomechanics and Motor
    Control of Human Movement*, app. A: largest plantarflexion a few per cent of the cycle
    after toe-off). From that largest plantarflexion (rate and angular acceleration zero)
    a quintic Hermite curve dorsiflexes the foot to its contact pitch.
    """
    y0, v0, a0, y1, v1, a1 = ends
    y = _hermite5(y0, v0, a0, y1, v1, a1, D, s)
    sp = d.swing_peak_fraction
    u = np.asarray(y1[:2] - y0[:2], dtype=float)
    u = u / max(float(np.linalg.norm(u)), 1e-9)
    curv = float(u @ _hermite_derivative(ends, D, sp, 2)[:2])
    y[:, :2] += (-curv / float(_bump(sp, 2))) * _bump(s)[:, None] * u
    y[:, 2] += lift_m * _LIFT_NORM * s**4 * (1.0 - s) ** 4
    hold, stop = d.plantarflexion_hold_s, d.plantarflexion_stop_s
    tau = s * D
    p, _ = _post_toe_off_pitch(float(y0[3]), float(v0[3]), hold, stop, tau)
    t_max = hold + stop
    late = tau > t_max
    p_max = float(_post_toe_off_pitch(float(y0[3]), float(v0[3]), hold, stop, np.array([t_max]))[0][0])
    zero = np.zeros(1)
    p[late] = _hermite5(
        np.array([p_max]), zero, zero, y1[3:4], v1[3:4], a1[3:4], D - t_max, (tau[late] - t_max) / (D - t_max)
    )[:, 0]
    y[:, 3] = p
    return y


def _released(ends: tuple, D: float, d: WalkDraw, foot: _FootGeometry) -> tuple:
    """``ends`` of :func:`_swing` with the ankle's acceleration at toe-off that of a released foot.

    Toe-off is a C¹ join, as contact is: the floor's push on the toe ends there, a step in
    the foot's acceleration (on the real walk of ``gait/`` the foot IMU's specific force
    falls from ~20 to ~10 m/s² within 20 ms of toe-off). The ankle starts its swing with
    gravity's acceleration alone, no forward one, unless that would take the toe tip, which
    leaves the floor at rest, back into it: then the ankle falls only as fast as leaves the
    tip's vertical acceleration zero.
    """
    y0, v0, a0, y1, v1, a1 = ends
    a0 = a0.copy()
    a0[:3] = (0.0, 0.0, -GRAVITY_MPS2)
    e = 1e-4
    tip = _toe_tip(_swing((y0, v0, a0, y1, v1, a1), D, np.array([0.0, e, 2 * e]), d), foot)[:, 2]
    tip_acc = (tip[2] - 2 * tip[1] + tip[0]) / (e * D) ** 2
    a0[2] -= min(tip_acc, 0.0)
    return y0, v0, a0, y1, v1, a1


def _mid_swing_lift(ends: tuple, D: float, d: WalkDraw, foot: _FootGeometry) -> float:
    """The lift (m) of :func:`_swing` that puts the toe tip ``d.min_toe_clearance_m`` above the floor.

    The minimum is taken over the middle of the swing (s ∈ [0.2, 0.8]), where the toe passes
    closest to the floor (Winter 1992); the floor is the toe tip's height at toe-off. The
    clearance grows with the lift, so one root search finds it.
    """
    s = np.linspace(0.0, 1.0, 401)
    mid = (s >= 0.2) & (s <= 0.8)
    y = _swing(ends, D, s, d)
    floor = float(_toe_tip(ends[0][None, :], foot)[0, 2])
    tip = _toe_tip(y, foot)[:, 2] - floor
    bump = _LIFT_NORM * s**4 * (1.0 - s) ** 4

    def excess(lift: float) -> float:
        return float(np.min(tip[mid] + lift * bump[mid])) - d.min_toe_clearance_m

    return float(brentq(excess, -0.2, 0.4))


def _foot_samples(
    stances: list[_Stance], d: WalkDraw, foot: _FootGeometry, t: FloatArray, pre: PreSwingParams
) -> FloatArray:
    """(N, 6) ankle (3), pitch, heading and MTP dorsiflexion of one foot over its stances and swings.

    In swing the MTP joint relaxes to neutral by the next contact (one more Hermite curve).
    """
    T = d.stride_time_s
    out = np.full((t.size, 6), np.nan)
    for j, st in enumerate(stances):
        pose = _stance_pose(st, d, foot, T, pre)
        start = -np.inf if st.ic is None else st.ic
        inside = (t >= start) & (t <= st.toe_off)
        for k in np.flatnonzero(inside):
            a, p, h, m = pose(float(t[k]))
            out[k] = [*a, p, h, m]
        if j + 1 == len(stances):
            break
        nxt = stances[j + 1]
        assert nxt.ic is not None
        y0, v0, a0 = _state(pose, st.toe_off)
        y1, v1, _ = _state(_stance_pose(nxt, d, foot, T, pre), nxt.ic)
        a1 = np.zeros_like(v1)  # contact is a C¹ join: the floor's push is a step in acceleration
        swing = (t > st.toe_off) & (t < nxt.ic)
        D = nxt.ic - st.toe_off
        s = (t[swing] - st.toe_off) / D
        ends = _released((y0, v0, a0, y1, v1, a1), D, d, foot)
        y = _swing(ends, D, s, d, _mid_swing_lift(ends, D, d, foot))
        out[swing] = y
    return out


def _toe_tip(samples: FloatArray, foot: _FootGeometry) -> FloatArray:
    """(N, 3) toe tip in ENU, m, from the (N, 6) samples of :func:`_foot_samples`."""
    R_rear = rot_z(samples[:, 4]) @ R_ENU_SEGMENT0 @ rot_z(samples[:, 3])
    R_toe = rot_z(samples[:, 4]) @ R_ENU_SEGMENT0 @ rot_z(samples[:, 3] + samples[:, 5])
    return np.asarray(samples[:, :3] + R_rear @ foot.mtp + R_toe @ (foot.toe - foot.mtp))


def plan_feet(
    side: str,
    d: WalkDraw,
    t: FloatArray,
    t0: float,
    path: tuple[FloatArray, FloatArray],
    stand_ankle: FloatArray,
    foot: tuple[FloatArray, FloatArray, FloatArray],
    pre: PreSwingParams | None = None,
    pivot: bool = False,
) -> FootPlan:
    """One foot's planned poses and events (see the module docstring, steps 2–4).

    Args:
        side: ``"left"`` or ``"right"``.
        d: The walk's random choices.
        t: (N,) sample times, s.
        t0: Time the walk starts (the right heel rises), s.
        path: Pelvis heading (N,), rad, and path point (N, 2), m.
        stand_ankle: (3,) the ankle centre while standing, ENU, m.
        foot: Heel, MTP joint centre and toe tip (3,) in the foot segment frame, m.
        pre: Push-off geometry and timing (defaults: :class:`PreSwingParams`).
        pivot: Each foot in stance pivots while flat with the path (:mod:`.turns`).
    """
    pre = PreSwingParams() if pre is None else pre
    geom = _FootGeometry(*(np.asarray(p, float) for p in foot))
    stances = _stances(side, d, t, t0, path, stand_ankle, pivot)
    y = _foot_samples(stances, d, geom, t, pre)
    R = rot_z(y[:, 4]) @ R_ENU_SEGMENT0 @ rot_z(y[:, 3])
    walking = [st for st in stances if st.ic is not None]
    end = t[-1]
    events = StanceEvents(
        initial_contact_s=np.array([st.ic for st in walking if st.ic is not None and st.ic <= end]),
        toe_off_s=np.array([st.toe_off for st in stances if st.toe_off <= end]),
        foot_flat_s=np.array([[st.foot_flat, st.heel_off] for st in walking if st.heel_off <= end]).reshape(
            -1, 2
        ),
    )
    return FootPlan(y[:, :3].copy(), R, events, _toe_tip(y, geom))
