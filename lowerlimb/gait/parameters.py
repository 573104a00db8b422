"""Spatio-temporal gait parameters per stride and their summary (docs/formats.md, "Two legs").

Definitions (events from :mod:`lowerlimb.gait.events`, positions from
:func:`~lowerlimb.gait.contacts.foot_contacts`; "other" = the opposite leg):

- stride k of a leg: from its initial contact IC_k to IC_{k+1} (at most
  :attr:`GaitParams.max_stride_time_s`); stride time T = IC_{k+1} − IC_k;
- stance % = 100 (TO − IC_k)/T with TO the leg's first toe-off in the stride; swing % = 100 − stance %;
- step time = IC_k − the other leg's last IC before it;
- double support % = 100 (initial + terminal double support)/T: initial = the other leg's
  first TO after IC_k minus IC_k; terminal = the leg's TO minus the other leg's last IC before it;
- stride length = horizontal distance between the contact positions at IC_k and IC_{k+1};
- step length and width at IC_k: with P, N the other leg's contact positions
  before and after IC_k and u = (N − P)/‖N − P‖ (horizontal), step length = (p_k − P)·u
  and step width = |u × (p_k − P)| (distance of p_k from the line through P and N);
- cadence = 60 / mean step time (steps/min); gait speed = stride length / stride time.

A stride is *turning* when the foot's heading (yaw of its resting orientation)
changes by more than :attr:`GaitParams.turn_heading_deg` between its two contacts;
turning strides are summarised apart from the straight ones. A step is straight
when the other leg's stride P → N is.

Step length and width need both feet in one horizontal frame. Each foot is
integrated on its own, so (i) the right trajectory is rotated about the
vertical onto the left one, stride by stride, by the kernel-weighted circular
mean (:attr:`GaitParams.pair_yaw_window_s`) of the heading differences of
simultaneous straight strides (both feet walk the same way; the two feet's
headings drift apart by degrees over minutes, which a single rotation would
turn into decimetres of step width). Each right stride is compared with the left
heading interpolated at its own mid-time (:attr:`GaitParams.pair_yaw_at_mid_time`):
on a bending walk the overlapping left stride is half a stride's turn away, always
on one side, and that bias drifted a 5-minute walk's step width by 2 m. (ii) The
remaining translation is unobservable from foot IMUs alone: it comes from a
:class:`FootAnchor` (e.g. from the calibrated chain, or a standing posture).
Without an anchor, step length and step width are NaN (``null`` in JSON). (iii) Given
the chain's right-minus-left ankle vectors at the right contacts, the slow drift that
remains between the tracks is removed (:mod:`lowerlimb.gait.drift`); each foot's stride
length stays its own track's.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from lowerlimb.conventions import FloatArray, rot_z
from lowerlimb.gait.contacts import Contacts, foot_contacts, heading_change_rad, walking_direction
from lowerlimb.gait.drift import ChainSteps, TrackDrift, right_track_drift
from lowerlimb.gait.events import GaitEvents, SideEvents
from lowerlimb.gait.params import GaitParams
from lowerlimb.gait.trajectory import FootTrajectory

__all__ = ["FootAnchor", "GaitParameters", "Stride", "compute_gait_parameters"]

_SIDES = ("left", "right")


@dataclass(frozen=True)
class FootAnchor:
    """Right-foot point minus left-foot point at one instant with both feet resting.

    Attributes:
        time_s: The instant, s.
        forward_m: Component along the walking direction of the left foot's next straight stride, m.
        left_m: Component along up × forward (to the walker's left), m; negative for a right
            foot standing to the right of the left one.
    """

    time_s: float
    forward_m: float
    left_m: float


@dataclass(frozen=True)
class Stride:
    """One stride of one leg (NaN where a quantity could not be formed); times s, lengths m."""

    side: str
    start_s: float
    end_s: float
    stride_time_s: float
    step_time_s: float
    stance_pct: float
    swing_pct: float
    double_support_pct: float
    stride_length_m: float
    step_length_m: float
    step_width_m: float
    heading_change_deg: float
    turning: bool
    step_turning: bool = False

    @property
    def speed_m_s(self) -> float:
        """Stride length / stride time, m/s."""
        return self.stride_length_m / self.stride_time_s


@dataclass(frozen=True)
class GaitParameters:
    """Per-stride parameters of both legs and how the feet were put in one frame.

    Attributes:
        strides: Every stride found, both legs, in time order.
        relative_heading_deg: Rotation about the vertical applied to the right foot's
            trajectory to align it with the left one, deg (NaN when not formed).
        anchored: Whether step length and width could be formed (a :class:`FootAnchor` was given).
        params: The thresholds used.
        event_sources: ``{side: {"initial_contact": method, "toe_off_from_foot": n,
            "toe_off_from_foot_rate": n, "toe_off_from_shank": n}}``: where each leg's events came from
            (:class:`~lowerlimb.gait.events.SideEvents`).
        track_drift: the drift of the right track against the left one removed with the
            calibrated chain (:mod:`lowerlimb.gait.drift`), or ``None``.
    """

    strides: list[Stride]
    relative_heading_deg: float
    anchored: bool
    params: GaitParams = field(default_factory=GaitParams)
    event_sources: dict[str, dict[str, Any]] = field(default_factory=dict)
    track_drift: TrackDrift | None = None

    def select(self, side: str | None = None, *, turning: bool = False) -> list[Stride]:
        """Strides of one leg (or both) that are (not) turning."""
        return [s for s in self.strides if (side is None or s.side == side) and s.turning == turning]

    def summary(self, side: str | None, *, turning: bool = False) -> dict[str, Any]:
        """Mean and SD (ddof 1) of every parameter over the selected strides."""
        st = self.select(side, turning=turning)
        steps = [s for s in self.strides if (side is None or s.side == side) and s.step_turning == turning]

        def ms(vals: list[float]) -> dict[str, float]:
            x = np.asarray([v for v in vals if np.isfinite(v)], dtype=float)
            return {
                "mean": float(x.mean()) if x.size else float("nan"),
                "sd": float(x.std(ddof=1)) if x.size > 1 else float("nan"),
                "n": int(x.size),
            }

        step_t = ms([s.step_time_s for s in steps])
        return {
            "n_strides": len(st),
            "stride_time_s": ms([s.stride_time_s for s in st]),
            "step_time_s": step_t,
            "stance_pct": ms([s.stance_pct for s in st]),
            "swing_pct": ms([s.swing_pct for s in st]),
            "double_support_pct": ms([s.double_support_pct for s in st]),
            "stride_length_m": ms([s.stride_length_m for s in st]),
            "step_length_m": ms([s.step_length_m for s in steps]),
            "step_width_m": ms([s.step_width_m for s in steps]),
            "gait_speed_m_s": ms([s.speed_m_s for s in st]),
            "cadence_steps_per_min": ms([60.0 / s.step_time_s for s in steps]),
        }

    def to_dict(self) -> dict[str, Any]:
        """The docs/formats.md ``gait.json`` content (straight strides), with extra keys."""
        both = self.summary(None)
        out: dict[str, Any] = {
            "cadence_steps_per_min": 60.0 / both["step_time_s"]["mean"],
            "gait_speed_m_s": both["gait_speed_m_s"]["mean"],
            "step_width_m": both["step_width_m"],
        }
        for side in _SIDES:
            if any(s.side == side for s in self.strides):
                out[side] = self.summary(side)
        out["turning"] = {side: self.summary(side, turning=True) for side in _SIDES}
        out["relative_heading_deg"] = self.relative_heading_deg
        out["anchored"] = self.anchored
        out["track_drift_max_m"] = None if self.track_drift is None else self.track_drift.max_m
        out["track_drift"] = None if self.track_drift is None else self.track_drift.to_dict()
        out["event_sources"] = self.event_sources
        out["params"] = asdict(self.params)
        return out


_TOE_OFF_KEYS = {
    "foot_unloading": "toe_off_from_foot",
    "foot_rate": "toe_off_from_foot_rate",
    "shank_minimum": "toe_off_from_shank",
}


def _toe_off_counts(se: SideEvents) -> dict[str, int]:
    """``event_sources``' toe-off counts of one leg (docs/formats.md, "Two legs")."""
    return {_TOE_OFF_KEYS[k]: n for k, n in se.toe_off_counts().items()}


def _between(t: FloatArray, lo: float, hi: float) -> FloatArray:
    return t[(t > lo) & (t < hi)]


def _temporal(ev: SideEvents, other: SideEvents | None, k: int, p: GaitParams) -> dict[str, float]:
    ic = ev.initial_contact_s
    t0, t1 = float(ic[k]), float(ic[k + 1])
    T = t1 - t0
    nan = float("nan")
    out = {"stance_pct": nan, "swing_pct": nan, "step_time_s": nan, "double_support_pct": nan}
    to = _between(ev.toe_off_s, t0, t1)
    if to.size:
        out["stance_pct"] = 100.0 * (to[0] - t0) / T
        out["swing_pct"] = 100.0 - out["stance_pct"]
    if other is None:
        return out
    prev_o = other.initial_contact_s[other.initial_contact_s < t0]
    if prev_o.size and t0 - prev_o[-1] < T:
        out["step_time_s"] = float(t0 - prev_o[-1])
    to_o = _between(other.toe_off_s, t0, t1)
    if to.size and to_o.size:
        ic_o = _between(other.initial_contact_s, t0, float(to[0]))
        if ic_o.size:
            initial, terminal = to_o[0] - t0, to[0] - ic_o[-1]
            if 0 < initial < p.max_ds_fraction * T and 0 < terminal < p.max_ds_fraction * T:
                out["double_support_pct"] = 100.0 * (initial + terminal) / T
    return out


def _pair_yaw_samples(
    cl: Contacts, evl: SideEvents, cr: Contacts, evr: SideEvents, p: GaitParams
) -> FloatArray:
    """(M, 3) rows ``(time s, left − right stride direction rad, weight m²)`` of overlapping strides."""
    thr = np.deg2rad(p.turn_heading_deg)

    def straight(c: Contacts) -> list[tuple[float, float, FloatArray]]:
        out = []
        for k in range(len(c.time_s) - 1):
            d = c.position_m[k + 1, :2] - c.position_m[k, :2]
            dt = c.time_s[k + 1] - c.time_s[k]
            if not np.all(np.isfinite(d)) or dt > p.max_stride_time_s:
                continue
            if abs(heading_change_rad(c.R_earth_sensor[k], c.R_earth_sensor[k + 1])) > thr:
                continue
            out.append((float(c.time_s[k]), float(c.time_s[k + 1]), d))
        return out

    sl, sr = straight(cl), straight(cr)
    mid_l = np.array([0.5 * (b0 + b1) for b0, b1, _ in sl])
    head_l = np.array([np.arctan2(d[1], d[0]) for *_, d in sl])
    rows = []
    for a0, a1, dr in sr:
        ov = [min(a1, b1) - max(a0, b0) for b0, b1, _ in sl]
        if not ov or max(ov) <= 0:
            continue
        i = int(np.argmax(ov))
        tm = 0.5 * (a0 + a1)
        left = _left_heading_at(tm, i, mid_l, head_l, p) if p.pair_yaw_at_mid_time else head_l[i]
        ang = left - np.arctan2(dr[1], dr[0])
        rows.append((tm, float(ang), float(np.linalg.norm(sl[i][2]) * np.linalg.norm(dr))))
    return np.asarray(rows, dtype=float).reshape(-1, 3)


def _left_heading_at(tm: float, i: int, mid: FloatArray, heading: FloatArray, p: GaitParams) -> float:
    """The left foot's stride heading at time ``tm`` (s), rad.

    From its stride ``i`` (the most overlapping) and a neighbour: interpolated between
    them, extrapolated at the walk's ends. ``mid`` (s) and ``heading`` (rad) are the left
    straight strides' mid-times and directions.
    """
    order = (i + 1, i - 1) if mid[i] < tm else (i - 1, i + 1)
    near = [j for j in order if 0 <= j < len(mid) and 0 < abs(mid[j] - mid[i]) <= p.max_stride_time_s]
    if not near:
        return float(heading[i])
    j = near[0]
    dh = float(np.angle(np.exp(1j * (heading[j] - heading[i]))))
    return float(heading[i] + dh * (tm - mid[i]) / (mid[j] - mid[i]))


def _yaw_at(samples: FloatArray, t: FloatArray, window_s: float) -> FloatArray:
    """Right-onto-left heading (rad) at times ``t`` (s): kernel-weighted circular mean of ``samples``.

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
    trl: FootTrajectory, cl: Contacts, pr_k: FloatArray, anchor: FootAnchor, offset: FloatArray
) -> FloatArray:
    """Horizontal translation putting the right foot (``pr_k`` at the anchor time) where the anchor says."""
    k = int(np.clip(round(anchor.time_s * trl.rate_hz), 0, trl.position_m.shape[0] - 1))
    pl = trl.point_m(offset)[k]
    u = walking_direction(cl, anchor.time_s)
    if u is None:
        return np.full(3, np.nan)
    left = np.array([-u[1], u[0]])
    target = pl[:2] + anchor.forward_m * u + anchor.left_m * left
    shift = np.zeros(3)
    shift[:2] = target - pr_k[:2]
    return shift


def compute_gait_parameters(
    events: GaitEvents,
    left: FootTrajectory | None = None,
    right: FootTrajectory | None = None,
    *,
    anchor: FootAnchor | None = None,
    chain: ChainSteps | None = None,
    params: GaitParams | None = None,
) -> GaitParameters:
    """Spatio-temporal parameters of every stride.

    Args:
        events: Gait events of one or both legs (event times with sample 0 at t = 0).
        left: Left foot trajectory (for lengths and turn detection), or ``None``.
        right: Right foot trajectory, or ``None``.
        anchor: Right-minus-left foot offset at one instant, needed for step length/width.
        chain: The calibrated chain's right-minus-left ankle vectors at right contacts; with
            an anchor, the slow drift between the two tracks is removed with them
            (:mod:`lowerlimb.gait.drift`).
        params: Thresholds (``turn_heading_deg``, ``sensor_to_ankle_m``, ``max_stride_time_s``,
            ``max_ds_fraction``; defaults: :class:`GaitParams`).

    Returns:
        The strides of both legs with temporal and, given trajectories, spatial parameters.
    """
    p = params or GaitParams()
    offset = np.asarray(p.sensor_to_ankle_m, dtype=float)
    evs = {"left": events.left, "right": events.right}
    trajs = {"left": left, "right": right}
    contacts: dict[str, Contacts] = {}
    for side in _SIDES:
        ev, tr = evs[side], trajs[side]
        if ev is not None and tr is not None:
            contacts[side] = foot_contacts(tr, ev.initial_contact_s, offset, 0.5 * p.max_stride_time_s)
    own = dict(contacts)  # each foot's own track: its stride lengths owe nothing to the other foot
    yaw = float("nan")
    anchored = False
    drift: TrackDrift | None = None
    if "left" in contacts and "right" in contacts and events.left and events.right and left and right:
        samples = _pair_yaw_samples(contacts["left"], events.left, contacts["right"], events.right, p)
        if samples.shape[0]:
            yaw = float(_yaw_at(samples, np.zeros(1), np.inf)[0])
        if np.isfinite(yaw) and anchor is not None:
            cr = contacts["right"]
            k = int(np.clip(round(anchor.time_s * right.rate_hz), 0, right.position_m.shape[0] - 1))
            yaw_c = _yaw_at(samples, cr.time_s, p.pair_yaw_window_s)
            yaw_a = float(_yaw_at(samples, np.array([anchor.time_s]), p.pair_yaw_window_s)[0])
            pos, pa = _rotate_track(
                cr.time_s, cr.position_m, anchor.time_s, right.point_m(offset)[k], yaw_c, yaw_a
            )
            shift = _anchor_shift(left, contacts["left"], pa, anchor, offset)
            contacts["right"] = Contacts(
                time_s=cr.time_s,
                position_m=pos + shift,
                R_earth_sensor=rot_z(yaw_c) @ cr.R_earth_sensor,
                period=cr.period,
            )
            anchored = True
            if chain is not None:
                drift = right_track_drift(contacts["left"], contacts["right"], chain, anchor.time_s, p)
                if drift is not None:
                    moved = contacts["right"].position_m.copy()
                    moved[:, :2] += drift.at(cr.time_s)
                    contacts["right"] = replace(contacts["right"], position_m=moved)
    thr = np.deg2rad(p.turn_heading_deg)
    turning: dict[str, list[bool]] = {}
    heading: dict[str, list[float]] = {}
    for side, cc in contacts.items():
        R = cc.R_earth_sensor
        h = [heading_change_rad(R[k], R[k + 1]) for k in range(len(cc.time_s) - 1)]
        heading[side] = h
        turning[side] = [bool(abs(x) > thr) if np.isfinite(x) else False for x in h]
    strides: list[Stride] = []
    nan = float("nan")
    for side in _SIDES:
        ev = evs[side]
        if ev is None:
            continue
        oside = "right" if side == "left" else "left"
        other = evs[oside]
        c, co = contacts.get(side), contacts.get(oside)
        ic = ev.initial_contact_s
        for k in range(len(ic) - 1):
            T = float(ic[k + 1] - ic[k])
            if T > p.max_stride_time_s:
                continue
            tmp = _temporal(ev, other, k, p)
            length = step_len = width = hdg = nan
            turn = step_turn = False
            if c is not None:
                mine = own[side].position_m
                length = float(np.linalg.norm(mine[k + 1, :2] - mine[k, :2]))
                hdg, turn = float(np.rad2deg(heading[side][k])), turning[side][k]
            if anchored and c is not None and co is not None:
                before = np.flatnonzero(co.time_s < ic[k])
                if before.size and before[-1] + 1 < len(co.time_s):
                    j = int(before[-1])
                    P, N = co.position_m[j, :2], co.position_m[j + 1, :2]
                    u = (N - P) / np.linalg.norm(N - P)
                    d = c.position_m[k, :2] - P
                    step_len = float(d @ u)
                    width = float(abs(u[0] * d[1] - u[1] * d[0]))
                    step_turn = turning[oside][j]
            elif co is not None:
                before = np.flatnonzero(co.time_s < ic[k])
                if before.size and before[-1] < len(turning[oside]):
                    step_turn = turning[oside][int(before[-1])]
            strides.append(
                Stride(
                    side=side,
                    start_s=float(ic[k]),
                    end_s=float(ic[k + 1]),
                    stride_time_s=T,
                    stride_length_m=length,
                    step_length_m=step_len,
                    step_width_m=width,
                    heading_change_deg=hdg,
                    turning=turn,
                    step_turning=step_turn or turn,
                    **tmp,
                )
            )
    strides.sort(key=lambda s: s.start_s)
    sources = {se.side: {"initial_contact": se.ic_method} | _toe_off_counts(se) for se in events.sides()}
    return GaitParameters(
        strides=strides,
        relative_heading_deg=float(np.rad2deg(yaw)),
        anchored=anchored,
        params=p,
        event_sources=sources,
        track_drift=drift,
    )
