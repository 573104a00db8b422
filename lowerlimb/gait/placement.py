"""One foot's contact track placed on the other's: heading, anchor and drift (for step length and width).

Each foot is integrated on its own, so its track has its own heading and position error.
To measure one foot's contact against the other's stride line, the *moving* foot's track is
put in the frame of the *reference* foot's track:

1. turned about the vertical, stride by stride, by the kernel-weighted circular mean
   (:attr:`GaitParams.pair_yaw_window_s`) of the heading differences of simultaneous straight
   strides, each moving stride against the reference heading interpolated at its own
   mid-time (:attr:`GaitParams.pair_yaw_at_mid_time`);
2. shifted so that, at the :class:`FootAnchor`'s instant, it stands where the anchor says
   (the anchor's forward / left components are taken along the mean walking direction of the
   two feet's strides nearest that instant);
3. given the calibrated chain's moving-minus-reference ankle vectors at the moving foot's
   contacts, moved by the slow drift that remains (:mod:`lowerlimb.gait.drift`).

:func:`~lowerlimb.gait.parameters.compute_gait_parameters` places the right track on the left
and the left track on the right, and averages what the two placements give, so that which
leg is called right changes nothing (a mirror-image walk gives the same steps).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from lowerlimb.conventions import FloatArray, rot_z
from lowerlimb.gait.contacts import Contacts, walking_direction
from lowerlimb.gait.drift import ChainSteps, TrackDrift, track_drift, unaided_gaps
from lowerlimb.gait.params import GaitParams
from lowerlimb.gait.trajectory import FootTrajectory

__all__ = ["FootAnchor", "Placement", "mean_walking_direction", "place_track", "relative_heading_rad"]


@dataclass(frozen=True)
class FootAnchor:
    """Right-foot point minus left-foot point at one instant with both feet resting.

    Attributes:
        time_s: The instant, s.
        forward_m: Component along the walking direction (the mean direction of the two
            feet's strides nearest the instant, :func:`mean_walking_direction`), m.
        left_m: Component along up × forward (to the walker's left), m; negative for a right
            foot standing to the right of the left one.
    """

    time_s: float
    forward_m: float
    left_m: float


@dataclass(frozen=True)
class Placement:
    """The two feet's contacts with the moving foot's track in the reference foot's frame.

    Attributes:
        reference: the side whose track is kept.
        contacts: ``{side: Contacts}``, the moving side's turned, anchored and (with a
            chain) drift-corrected.
        yaw_rad: whole-walk rotation about the vertical of the moving track onto the
            reference one, rad.
        drift: the drift removed with the chain, or ``None``.
    """

    reference: str
    contacts: dict[str, Contacts]
    yaw_rad: float
    drift: TrackDrift | None


def mean_walking_direction(a: Contacts, b: Contacts, time_s: float) -> FloatArray | None:
    """(2,) unit mean of the two feet's walking directions nearest ``time_s`` (s), or ``None``.

    Either foot's alone when the other has no stride; ``None`` when neither has one.
    """
    dirs = [u for u in (walking_direction(a, time_s), walking_direction(b, time_s)) if u is not None]
    if not dirs:
        return None
    s = np.sum(dirs, axis=0)
    n = float(np.linalg.norm(s))
    return np.asarray(s / n, dtype=float) if n > 0.0 else dirs[0]


def _pair_yaw_samples(c_ref: Contacts, c_mov: Contacts, p: GaitParams) -> FloatArray:
    """(M, 3) rows ``(time s, reference − moving stride direction rad, weight m²)`` of overlapping strides."""
    thr, stance_thr = np.deg2rad(p.turn_heading_deg), np.deg2rad(p.stance_turn_deg)

    def straight(c: Contacts) -> list[tuple[float, float, FloatArray]]:
        out = []
        for k in range(len(c.time_s) - 1):
            d = c.position_m[k + 1, :2] - c.position_m[k, :2]
            dt = c.time_s[k + 1] - c.time_s[k]
            if not np.all(np.isfinite(d)) or dt > p.max_stride_time_s:
                continue
            if c.turning(k, thr, stance_thr):
                continue
            out.append((float(c.time_s[k]), float(c.time_s[k + 1]), d))
        return out

    sref, smov = straight(c_ref), straight(c_mov)
    mid = np.array([0.5 * (b0 + b1) for b0, b1, _ in sref])
    head = np.array([np.arctan2(d[1], d[0]) for *_, d in sref])
    rows = []
    for a0, a1, dm in smov:
        ov = [min(a1, b1) - max(a0, b0) for b0, b1, _ in sref]
        if not ov or max(ov) <= 0:
            continue
        i = int(np.argmax(ov))
        tm = 0.5 * (a0 + a1)
        ref = _heading_at(tm, i, mid, head, p) if p.pair_yaw_at_mid_time else head[i]
        ang = ref - np.arctan2(dm[1], dm[0])
        rows.append((tm, float(ang), float(np.linalg.norm(sref[i][2]) * np.linalg.norm(dm))))
    return np.asarray(rows, dtype=float).reshape(-1, 3)


def relative_heading_rad(c_ref: Contacts, c_mov: Contacts, p: GaitParams) -> float:
    """Whole-walk rotation about the vertical of the moving track onto the reference one, rad (NaN: none)."""
    samples = _pair_yaw_samples(c_ref, c_mov, p)
    return float(_yaw_at(samples, np.zeros(1), np.inf)[0]) if samples.shape[0] else float("nan")


def _heading_at(tm: float, i: int, mid: FloatArray, heading: FloatArray, p: GaitParams) -> float:
    """The reference foot's stride heading at time ``tm`` (s), rad.

    From its stride ``i`` (the most overlapping) and a neighbour: interpolated between
    them, extrapolated at the walk's ends. ``mid`` (s) and ``heading`` (rad) are the
    reference foot's straight strides' mid-times and directions.
    """
    order = (i + 1, i - 1) if mid[i] < tm else (i - 1, i + 1)
    near = [j for j in order if 0 <= j < len(mid) and 0 < abs(mid[j] - mid[i]) <= p.max_stride_time_s]
    if not near:
        return float(heading[i])
    j = near[0]
    dh = float(np.angle(np.exp(1j * (heading[j] - heading[i]))))
    return float(heading[i] + dh * (tm - mid[i]) / (mid[j] - mid[i]))


def _yaw_at(samples: FloatArray, t: FloatArray, window_s: float) -> FloatArray:
    """Moving-onto-reference heading (rad) at times ``t`` (s): kernel-weighted circular mean of ``samples``.

    A Gaussian kernel of ``window_s`` (s) follows the slow heading drift between the two
    feet; a tenth of the whole-walk mean keeps it defined far from straight strides.
    ``window_s = inf`` gives the whole-walk mean everywhere.
    """
    ts, ang, w = samples[:, 0], samples[:, 1], samples[:, 2]
    S0, C0 = float(np.sum(w * np.sin(ang))), float(np.sum(w * np.cos(ang)))
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if not np.isfinite(window_s):
        return np.full(t.shape, np.arctan2(S0, C0))
    K = w[None, :] * np.exp(-0.5 * ((t[:, None] - ts[None, :]) / window_s) ** 2)
    S = K @ np.sin(ang) + 0.1 * S0 / max(len(ang), 1)
    C = K @ np.cos(ang) + 0.1 * C0 / max(len(ang), 1)
    return np.asarray(np.arctan2(S, C))


def _rotate_track(
    time_s: FloatArray,
    pos: FloatArray,
    anchor_t: float,
    anchor_p: FloatArray,
    yaw: FloatArray,
    yaw_anchor: float,
) -> tuple[FloatArray, FloatArray]:
    """Contact positions (K, 3) and the anchor point (3,) with each step turned by its own yaw.

    The points, the anchor included, are chained in time order; each increment between
    consecutive finite points is turned about the vertical by the yaw at its later end,
    so a slowly varying heading error between the feet is undone stride by stride.
    """
    times = np.concatenate([[anchor_t], time_s])
    pts = np.vstack([anchor_p[None, :], pos])
    yaws = np.concatenate([[yaw_anchor], yaw])
    order = np.argsort(times, kind="stable")
    out = np.full_like(pts, np.nan)
    last_raw = last_out = None
    for i in order:
        if not np.all(np.isfinite(pts[i])):
            continue
        R = rot_z(yaws[i])
        out[i] = R @ pts[i] if last_raw is None else last_out + R @ (pts[i] - last_raw)
        last_raw, last_out = pts[i], out[i]
    return out[1:], out[0]


def _anchor_shift(
    ref_point: FloatArray,
    c_ref: Contacts,
    c_mov: Contacts,
    mov_point: FloatArray,
    anchor: FootAnchor,
    sign: float,
) -> FloatArray:
    """(3,) horizontal translation putting the moving foot's ``mov_point`` where the anchor says.

    ``ref_point`` and ``mov_point`` are the two feet's points at the anchor's instant; ``sign``
    is +1 when the moving foot is the right one (the anchor is right minus left), −1 otherwise.
    """
    u = mean_walking_direction(c_ref, c_mov, anchor.time_s)
    if u is None:
        return np.full(3, np.nan)
    left = np.array([-u[1], u[0]])
    target = ref_point[:2] + sign * (anchor.forward_m * u + anchor.left_m * left)
    shift = np.zeros(3)
    shift[:2] = target - mov_point[:2]
    return shift


def place_track(
    reference: str,
    contacts: dict[str, Contacts],
    trajectories: dict[str, FootTrajectory],
    anchor: FootAnchor,
    chain: ChainSteps | None,
    offset: FloatArray,
    p: GaitParams,
) -> Placement | None:
    """The other foot's contacts turned, anchored and de-drifted onto ``reference``'s (module docstring).

    Args:
        reference: ``"left"`` or ``"right"``, the track kept.
        contacts: both feet's contacts, each in its own track's frame.
        trajectories: both feet's trajectories (the points at the anchor's instant).
        anchor: right minus left at one instant.
        chain: the chain's steps at the moving foot's contacts (``chain.side`` the moving
            side), or ``None`` (no drift removal).
        offset: (3,) the tracked point in the foot sensor frame, m.
        p: ``pair_yaw_*``, ``turn_heading_deg``, ``max_stride_time_s``, ``chain_drift_*``.

    Returns:
        The placement, or ``None`` when the feet have no simultaneous straight strides.
    """
    moving = "right" if reference == "left" else "left"
    c_ref, c_mov, t_mov = contacts[reference], contacts[moving], trajectories[moving]
    samples = _pair_yaw_samples(c_ref, c_mov, p)
    if not samples.shape[0]:
        return None
    k = int(np.clip(round(anchor.time_s * t_mov.rate_hz), 0, t_mov.position_m.shape[0] - 1))
    yaw_c = _yaw_at(samples, c_mov.time_s, p.pair_yaw_window_s)
    yaw_a = float(_yaw_at(samples, np.array([anchor.time_s]), p.pair_yaw_window_s)[0])
    pos, pa = _rotate_track(
        c_mov.time_s, c_mov.position_m, anchor.time_s, t_mov.point_m(offset)[k], yaw_c, yaw_a
    )
    turned = replace(c_mov, position_m=pos, R_earth_sensor=rot_z(yaw_c) @ c_mov.R_earth_sensor)
    t_ref = trajectories[reference]
    kr = int(np.clip(round(anchor.time_s * t_ref.rate_hz), 0, t_ref.position_m.shape[0] - 1))
    shift = _anchor_shift(
        t_ref.point_m(offset)[kr], c_ref, turned, pa, anchor, 1.0 if moving == "right" else -1.0
    )
    moved = replace(turned, position_m=pos + shift)
    drift = None
    if chain is not None and chain.side == moving:
        gaps = unaided_gaps([t_ref.stationary.intervals_s(), t_mov.stationary.intervals_s()], p)
        drift = track_drift(c_ref, moved, chain, anchor.time_s, p, gaps)
        if drift is not None:
            drift = replace(drift, moving_side=moving)
            shifted = moved.position_m.copy()
            shifted[:, :2] += drift.at(moved.time_s)
            moved = replace(moved, position_m=shifted)
    yaw = float(_yaw_at(samples, np.zeros(1), np.inf)[0])
    return Placement(reference, {reference: c_ref, moving: moved}, yaw, drift)
