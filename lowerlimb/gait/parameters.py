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
changes by more than :attr:`GaitParams.turn_heading_deg` between its two contacts, or
when the foot pivots on the floor at either contact (turns about the vertical by more
than :attr:`GaitParams.stance_turn_deg` between touching down and the end of the stationary
period that gives its position); turning strides are summarised apart from the
straight ones. A step is straight when the other leg's stride P → N is and the foot did
not pivot at IC_k.

Step length and width need both feet in one horizontal frame. Each foot is
integrated on its own, so one foot's track is placed on the other's
(:mod:`lowerlimb.gait.placement`): turned about the vertical stride by stride by the
heading differences of simultaneous straight strides, shifted to where a
:class:`FootAnchor` puts it (the translation is unobservable from foot IMUs alone;
without an anchor, step length and step width are NaN, ``null`` in JSON), and, given the
chain's ankle vectors at that foot's contacts, freed of the slow drift that remains
(:mod:`lowerlimb.gait.drift`). This is done both ways, the right track onto the left and the
left onto the right, and the step length and width are the mean of the two placements (a
placement the chain de-drifted is preferred to one it could not): which leg is called right
changes nothing, and a mirror-image walk gives the same steps. Each foot's stride length
and turning stay its own track's.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from lowerlimb.conventions import FloatArray
from lowerlimb.gait.contacts import Contacts, foot_contacts, heading_change_rad
from lowerlimb.gait.drift import ChainSteps, TrackDrift
from lowerlimb.gait.events import GaitEvents, SideEvents
from lowerlimb.gait.params import GaitParams
from lowerlimb.gait.placement import FootAnchor, Placement, place_track, relative_heading_rad
from lowerlimb.gait.trajectory import FootTrajectory

__all__ = ["FootAnchor", "GaitParameters", "Stride", "compute_gait_parameters"]

_SIDES = ("left", "right")


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
        track_drift: the drift of one foot's track against the other's removed with the
            calibrated chain (:mod:`lowerlimb.gait.drift`): the right one's against the left
            when both placements had one (:mod:`lowerlimb.gait.placement`), or ``None``.
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

    @property
    def step_width_basis(self) -> str | None:
        """What sets the feet's sideways offset, hence step width's constant part.

        ``None``: not anchored (no step width); ``"standing_chain"``: the calibrated chain at
        the standing start alone (fewer than ``chain_drift_min_steps`` steps, or no drift
        fit); ``"standing_chain_straight_walk"``: the chain over the walk could not check it,
        the walk being straight, or its passes straight between breaks of the drift
        (:attr:`GaitParams.straight_heading_spread`); ``"chain_over_turns"``:
        the walk's turns told the chain's bias from the anchor's error (:mod:`lowerlimb.gait.drift`).
        """
        if not self.anchored:
            return None
        if self.track_drift is None:
            return "standing_chain"
        if self.track_drift.heading_spread < self.params.straight_heading_spread:
            return "standing_chain_straight_walk"
        return "chain_over_turns"

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
        out["step_width_basis"] = self.step_width_basis
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


def compute_gait_parameters(
    events: GaitEvents,
    left: FootTrajectory | None = None,
    right: FootTrajectory | None = None,
    *,
    anchor: FootAnchor | None = None,
    chain: ChainSteps | Sequence[ChainSteps] | None = None,
    params: GaitParams | None = None,
) -> GaitParameters:
    """Spatio-temporal parameters of every stride.

    Args:
        events: Gait events of one or both legs (event times with sample 0 at t = 0).
        left: Left foot trajectory (for lengths and turn detection), or ``None``.
        right: Right foot trajectory, or ``None``.
        anchor: Right-minus-left foot offset at one instant, needed for step length/width.
        chain: The calibrated chain's ankle vectors at one foot's contacts (that foot minus
            the other; :class:`~lowerlimb.gait.drift.ChainSteps`), for either foot or both;
            with an anchor, the slow drift between the two tracks is removed with them
            (:mod:`lowerlimb.gait.drift`) in the placement whose moving foot they belong to.
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
            half = 0.5 * p.max_stride_time_s
            contacts[side] = foot_contacts(tr, ev.initial_contact_s, offset, half, ev.toe_off_s)
    placements = _placements(contacts, trajs, anchor, chain, offset, p)
    yaw = next((pl.yaw_rad for pl in placements if pl.reference == "left"), float("nan"))
    if np.isnan(yaw) and "left" in contacts and "right" in contacts:
        yaw = relative_heading_rad(contacts["left"], contacts["right"], p)
    thr, stance_thr = np.deg2rad(p.turn_heading_deg), np.deg2rad(p.stance_turn_deg)
    turning: dict[str, list[bool]] = {}
    heading: dict[str, list[float]] = {}
    pivots: dict[str, np.ndarray] = {}
    for side, cc in contacts.items():
        R = cc.R_earth_sensor
        heading[side] = [heading_change_rad(R[k], R[k + 1]) for k in range(len(cc.time_s) - 1)]
        turning[side] = [cc.turning(k, thr, stance_thr) for k in range(len(cc.time_s) - 1)]
        pivots[side] = cc.pivots(stance_thr)
    strides: list[Stride] = []
    nan = float("nan")
    for side in _SIDES:
        ev = evs[side]
        if ev is None:
            continue
        oside = "right" if side == "left" else "left"
        other = evs[oside]
        c = contacts.get(side)
        ic = ev.initial_contact_s
        for k in range(len(ic) - 1):
            T = float(ic[k + 1] - ic[k])
            if T > p.max_stride_time_s:
                continue
            tmp = _temporal(ev, other, k, p)
            length = hdg = nan
            turn = step_turn = False
            if c is not None:
                length = float(np.linalg.norm(c.position_m[k + 1, :2] - c.position_m[k, :2]))
                hdg, turn = float(np.rad2deg(heading[side][k])), turning[side][k]
                step_turn = bool(pivots[side][k])
            step_len, width = _step(placements, side, k)
            co = contacts.get(oside)
            if co is not None:
                before = np.flatnonzero(co.time_s < ic[k])
                if before.size and before[-1] < len(turning[oside]):
                    step_turn = step_turn or turning[oside][int(before[-1])]
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
        anchored=bool(placements),
        params=p,
        event_sources=sources,
        track_drift=next((pl.drift for pl in placements if pl.drift is not None), None),
    )


def _placements(
    contacts: dict[str, Contacts],
    trajs: dict[str, FootTrajectory | None],
    anchor: FootAnchor | None,
    chain: ChainSteps | Sequence[ChainSteps] | None,
    offset: FloatArray,
    p: GaitParams,
) -> list[Placement]:
    """Both placements (right onto left, left onto right), or those whose drift was removed.

    With an anchor and both feet's contacts; a placement whose tracks the chain de-drifted
    is kept over one it could not (its moving foot had too few chain steps).
    """
    if anchor is None or "left" not in contacts or "right" not in contacts:
        return []
    tl, tr = trajs["left"], trajs["right"]
    assert tl is not None and tr is not None
    given = [] if chain is None else [chain] if isinstance(chain, ChainSteps) else list(chain)
    chains = {c.side: c for c in given}
    out = []
    for ref, mov in (("left", "right"), ("right", "left")):
        pl = place_track(ref, contacts, {"left": tl, "right": tr}, anchor, chains.get(mov), offset, p)
        if pl is not None:
            out.append(pl)
    if any(pl.drift is not None for pl in out):
        out = [pl for pl in out if pl.drift is not None]
    return out


def _step(placements: list[Placement], side: str, k: int) -> tuple[float, float]:
    """Step length and width (m) at ``side``'s contact ``k``: the mean over the placements (NaN: none).

    In each placement, with P, N the other foot's contacts before and after it and
    u = (N − P)/‖N − P‖: step length = (p_k − P)·u, width = |u × (p_k − P)|.
    """
    oside = "right" if side == "left" else "left"
    lengths, widths = [], []
    for pl in placements:
        c, co = pl.contacts[side], pl.contacts[oside]
        before = np.flatnonzero(co.time_s < c.time_s[k])
        if not before.size or before[-1] + 1 >= len(co.time_s):
            continue
        j = int(before[-1])
        P, N = co.position_m[j, :2], co.position_m[j + 1, :2]
        u = (N - P) / np.linalg.norm(N - P)
        d = c.position_m[k, :2] - P
        lengths.append(float(d @ u))
        widths.append(float(abs(u[0] * d[1] - u[1] * d[0])))
    return _finite_mean(lengths), _finite_mean(widths)


def _finite_mean(x: list[float]) -> float:
    v = np.asarray(x, dtype=float)
    v = v[np.isfinite(v)]
    return float(v.mean()) if v.size else float("nan")
