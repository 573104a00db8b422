"""Initial contact and toe-off from the shank (and foot) gyro; foot-stationary periods from the foot IMU.

With a foot IMU, initial contact (IC) is the onset of the foot's heel rocker, the
swing-to-stance zero crossing of the foot's sagittal rate
(:mod:`lowerlimb.gait.foot_contact`), and toe-off (TO) is the forefoot's unloading
in the foot's specific force (:mod:`lowerlimb.gait.toe_off`), or, in a stride where
the foot shows no unloading, the middle of its push-off rate bracket; without a foot
IMU, or in a stride where the foot shows no push-off, they are the shank minima below.
Mid-swing always comes from the shank.

Shank method of Salarian et al. 2004 ("Gait assessment in Parkinson's disease:
toward an ambulatory system for long-term monitoring", IEEE TBME 51(8)),
after Aminian et al. 2002 (J. Biomech. 35): on the sagittal shank angular
velocity ω (mid-swing positive, :func:`~lowerlimb.gait.sagittal.sagittal_rate`)

1. mid-swing (MS) = peaks of the strongly low-passed ω above
   :attr:`GaitParams.midswing_min_rps`, at least :attr:`GaitParams.min_stride_time_s` apart;
2. initial contact (IC, shank fallback) = the first local minimum of ω (low-passed at
   :attr:`GaitParams.sagittal_lowpass_hz`) after MS, within
   :attr:`GaitParams.ic_search_s` and before the next MS;
3. toe-off (TO) = the deepest local minimum of ω before MS, within
   :attr:`GaitParams.to_search_s` and after the previous MS.

Both minima must lie below ``-event_min_rps``. Choices left open by the papers:
the filters (zero-phase Butterworth instead of Aminian's wavelet), and sub-sample
timing: each minimum is refined by a parabola through it and its two neighbours.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.signal import find_peaks

from lowerlimb.conventions import FloatArray
from lowerlimb.gait._signal import as_signal, lowpass, parabolic_vertex
from lowerlimb.gait.errors import NoGaitCyclesError
from lowerlimb.gait.foot_contact import foot_sagittal_rate, heel_rocker_onsets
from lowerlimb.gait.params import GaitParams, samples
from lowerlimb.gait.sagittal import SagittalRate, sagittal_rate
from lowerlimb.gait.stationary import StationaryPeriods, detect_stationary
from lowerlimb.gait.toe_off import forefoot_unloading, push_off_midpoint
from lowerlimb.upsample import upsample_factor, upsampled

__all__ = ["TOE_OFF_SOURCES", "GaitEvents", "SideEvents", "detect_gait_events", "detect_side_events"]

#: Where a toe-off can come from, in order of preference (``SideEvents.toe_off_source``).
TOE_OFF_SOURCES: tuple[str, ...] = ("foot_unloading", "foot_rate", "shank_minimum")


@dataclass(frozen=True)
class SideEvents:
    """Gait events of one leg.

    Attributes:
        side: ``"left"`` or ``"right"``.
        initial_contact_s: (K,) initial-contact times, s, increasing.
        toe_off_s: (M,) toe-off times, s, increasing.
        midswing_s: (J,) mid-swing peak times, s.
        sagittal: The shank's sagittal rate and axis.
        stationary: Foot-stationary periods (``None`` without a foot IMU).
        start_time_s: Time of sample 0, s.
        foot_sagittal: The foot's sagittal rate, signed like the shank's (``None``
            without a foot IMU).
        ic_method: ``"foot_heel_rocker"`` (foot gyro zero crossing) or
            ``"shank_minimum"`` (Aminian/Salarian fallback without a foot IMU).
        toe_off_source: (M,) where each toe-off came from: ``"foot_unloading"`` (the
            forefoot's unloading, :func:`~lowerlimb.gait.toe_off.forefoot_unloading`),
            ``"foot_rate"`` (no unloading in that stride: the middle of the foot's
            push-off rate bracket, :func:`~lowerlimb.gait.toe_off.push_off_midpoint`) or
            ``"shank_minimum"`` (no foot IMU, or no push-off in the foot's rate).
    """

    side: str
    initial_contact_s: FloatArray
    toe_off_s: FloatArray
    midswing_s: FloatArray
    sagittal: SagittalRate
    stationary: StationaryPeriods | None = None
    start_time_s: float = 0.0
    foot_sagittal: SagittalRate | None = None
    ic_method: str = "shank_minimum"
    toe_off_source: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype="<U14"))

    @property
    def toe_off_from_foot(self) -> np.ndarray:
        """(M,) ``True`` where the toe-off is the forefoot's unloading."""
        return np.asarray(self.toe_off_source == "foot_unloading", dtype=bool)

    def toe_off_counts(self) -> dict[str, int]:
        """How many toe-offs came from each source (``TOE_OFF_SOURCES``, all keys present)."""
        return {k: int(np.count_nonzero(self.toe_off_source == k)) for k in TOE_OFF_SOURCES}

    def on_clock(self, t0: float) -> SideEvents:
        """The events with their times on a trial's clock whose first sample is at ``t0``, s."""
        if t0 == 0.0:
            return self
        return replace(
            self,
            initial_contact_s=self.initial_contact_s + t0,
            toe_off_s=self.toe_off_s + t0,
            midswing_s=self.midswing_s + t0,
            start_time_s=t0,
        )


@dataclass(frozen=True)
class GaitEvents:
    """Gait events of both legs (either may be ``None`` for a single-leg trial)."""

    left: SideEvents | None = None
    right: SideEvents | None = None
    extras: dict[str, object] = field(default_factory=dict)

    def sides(self) -> list[SideEvents]:
        """The legs present, left first."""
        return [s for s in (self.left, self.right) if s is not None]

    def table(self) -> list[tuple[float, str, str]]:
        """All events as ``(time_s, side, event)`` rows sorted by time (docs/formats.md, "Two legs")."""
        rows = []
        for s in self.sides():
            rows += [(float(t), s.side, "initial_contact") for t in s.initial_contact_s]
            rows += [(float(t), s.side, "toe_off") for t in s.toe_off_s]
        return sorted(rows)


def _local_minima(x: FloatArray, lo: int, hi: int, below: float) -> np.ndarray:
    """Indices k in [lo, hi) with x[k-1] > x[k] <= x[k+1] and x[k] < below."""
    lo, hi = max(lo, 1), min(hi, x.shape[0] - 1)
    if hi <= lo:
        return np.zeros(0, dtype=int)
    k = np.arange(lo, hi)
    ok = (x[k - 1] > x[k]) & (x[k] <= x[k + 1]) & (x[k] < below)
    return k[ok]


def _shank_minima(
    om: FloatArray, ms: np.ndarray, rate_hz: float, p: GaitParams
) -> tuple[list[float], list[float | None], list[tuple[int, int]]]:
    """Shank IC and TO (fractional samples) around each mid-swing peak, and the TO search windows.

    Returns:
        ``(ic, to, windows)``: the initial contacts found; one toe-off per mid-swing peak
        (``None`` when none); the half-open ``[lo, hi)`` toe-off search window of each peak.
    """
    n_ic, n_to = samples(p.ic_search_s, rate_hz), samples(p.to_search_s, rate_hz)
    half = samples(0.5 * p.max_stride_time_s, rate_hz)
    ic: list[float] = []
    to: list[float | None] = []
    windows: list[tuple[int, int]] = []
    for j, m in enumerate(ms):
        nxt = ms[j + 1] if j + 1 < ms.size else om.shape[0]
        prv = ms[j - 1] if j > 0 else 0
        cand = _local_minima(om, m + 1, min(m + 1 + n_ic, nxt, m + half), -p.event_min_rps)
        if cand.size:
            ic.append(parabolic_vertex(om, int(cand[0])))
        lo = max(m - n_to, prv + 1, m - half)
        windows.append((int(lo), int(m)))
        cand = _local_minima(om, lo, m, -p.event_min_rps)
        to.append(parabolic_vertex(om, int(cand[np.argmin(om[cand])])) if cand.size else None)
    return ic, to, windows


def _merge_toe_offs(candidates: dict[str, list[float | None]]) -> tuple[list[float], list[str]]:
    """Per stride the first source, in ``TOE_OFF_SOURCES`` order, with a toe-off; strides with none drop.

    Args:
        candidates: ``{source: one entry per stride}``, the sources of ``TOE_OFF_SOURCES``
            (a missing source has no toe-off in any stride).

    Returns:
        ``(toe_offs, sources)``: fractional samples and, for each, the source that gave it.
    """
    n = max(len(v) for v in candidates.values())
    times, sources = [], []
    for j in range(n):
        for name in TOE_OFF_SOURCES:
            x = candidates.get(name, [None] * n)[j]
            if x is not None:
                times.append(x)
                sources.append(name)
                break
    return times, sources


def detect_side_events(
    shank_gyr: ArrayLike,
    rate_hz: float,
    side: str,
    *,
    foot_gyr: ArrayLike | None = None,
    foot_acc: ArrayLike | None = None,
    params: GaitParams | None = None,
    start_time_s: float = 0.0,
) -> SideEvents:
    """Initial contacts, toe-offs and foot-stationary periods of one leg.

    Args:
        shank_gyr: (N, 3) shank angular velocity, sensor frame, rad/s.
        rate_hz: Sampling rate, Hz.
        side: ``"left"`` or ``"right"`` (a label; the method is the same for both).
        foot_gyr: (N, 3) foot angular velocity, sensor frame, rad/s (optional).
        foot_acc: (N, 3) foot specific force, sensor frame, m/s² (with ``foot_gyr``).
        params: Thresholds (defaults: :class:`GaitParams`).
        start_time_s: Time of sample 0, s.

    Returns:
        The leg's events; times are ``start_time_s + index / rate_hz``. Initial
        contacts come from the foot gyro when ``foot_gyr`` is given
        (:func:`~lowerlimb.gait.foot_contact.heel_rocker_onsets`), else from the shank.

    Raises:
        GaitSignalError: A signal is not a finite (N, 3) array of the shank's length.
        NoGaitCyclesError: No mid-swing peak (no walking in the shank signal).
    """
    p = params or GaitParams()
    w = as_signal(shank_gyr, "shank_gyr")
    k = upsample_factor(rate_hz, p.min_event_rate_hz)
    if k > 1:
        return _timed_on_interpolated(w, rate_hz, side, k, foot_gyr, foot_acc, p, start_time_s)
    sag = sagittal_rate(w, rate_hz, p)
    om = lowpass(sag.omega_rps, p.sagittal_lowpass_hz, rate_hz)
    om_ms = lowpass(sag.omega_rps, p.midswing_lowpass_hz, rate_hz)
    ms, _ = find_peaks(om_ms, height=p.midswing_min_rps, distance=samples(p.min_stride_time_s, rate_hz))
    if ms.size == 0:
        raise NoGaitCyclesError(side, float(np.max(om_ms)), p.midswing_min_rps)
    ic, to, windows = _shank_minima(om, ms, rate_hz, p)
    stationary = foot_sag = None
    ic_method = "shank_minimum"
    candidates: dict[str, list[float | None]] = {"shank_minimum": to}
    if foot_gyr is not None:
        fg = as_signal(foot_gyr, "foot_gyr", w.shape[0])
        fa = as_signal(foot_acc if foot_acc is not None else np.zeros((0, 3)), "foot_acc", w.shape[0])
        stationary = detect_stationary(fg, fa, rate_hz, p)
        foot_sag = foot_sagittal_rate(fg, sag.omega_rps, rate_hz, p)
        ic = heel_rocker_onsets(foot_sag.omega_rps, ms, rate_hz, p)
        ic_method = "foot_heel_rocker"
        candidates["foot_unloading"] = forefoot_unloading(foot_sag.omega_rps, fa, windows, rate_hz, p)
        candidates["foot_rate"] = push_off_midpoint(foot_sag.omega_rps, windows, rate_hz, p)
    to_s, to_src = _merge_toe_offs(candidates)
    return SideEvents(
        side=side,
        initial_contact_s=start_time_s + np.asarray(ic, dtype=float) / rate_hz,
        toe_off_s=start_time_s + np.asarray(to_s, dtype=float) / rate_hz,
        midswing_s=start_time_s + ms.astype(float) / rate_hz,
        sagittal=sag,
        stationary=stationary,
        start_time_s=start_time_s,
        foot_sagittal=foot_sag,
        ic_method=ic_method,
        toe_off_source=np.asarray(to_src, dtype="<U14"),
    )


def _timed_on_interpolated(
    shank_gyr: FloatArray,
    rate_hz: float,
    side: str,
    k: int,
    foot_gyr: ArrayLike | None,
    foot_acc: ArrayLike | None,
    p: GaitParams,
    start_time_s: float,
) -> SideEvents:
    """The recorded samples' events with their times found on the signals interpolated ``k``-fold.

    The stationary periods and the sagittal rates stay on the recorded samples (the feet's
    strapdown and the output files use them); the initial contacts, toe-offs and mid-swings
    are found again at ``k · rate_hz`` (:mod:`lowerlimb.upsample`).
    """
    once = replace(p, min_event_rate_hz=None)
    kw: dict[str, Any] = {"params": once, "start_time_s": start_time_s}
    recorded = detect_side_events(shank_gyr, rate_hz, side, foot_gyr=foot_gyr, foot_acc=foot_acc, **kw)
    n = shank_gyr.shape[0]
    sig = {"shank": shank_gyr}
    if foot_gyr is not None:  # then foot_acc is an (N, 3) array too: the first call checked both
        sig["foot"] = as_signal(foot_gyr, "foot_gyr", n)
        sig["acc"] = as_signal(foot_acc if foot_acc is not None else np.zeros((n, 3)), "foot_acc", n)
    fine = upsampled(sig, k)
    timed = detect_side_events(
        fine["shank"], rate_hz * k, side, foot_gyr=fine.get("foot"), foot_acc=fine.get("acc"), **kw
    )
    return replace(
        recorded,
        initial_contact_s=timed.initial_contact_s,
        toe_off_s=timed.toe_off_s,
        midswing_s=timed.midswing_s,
        ic_method=timed.ic_method,
        toe_off_source=timed.toe_off_source,
    )


def detect_gait_events(
    rate_hz: float,
    *,
    left_shank_gyr: ArrayLike | None = None,
    right_shank_gyr: ArrayLike | None = None,
    left_foot_gyr: ArrayLike | None = None,
    left_foot_acc: ArrayLike | None = None,
    right_foot_gyr: ArrayLike | None = None,
    right_foot_acc: ArrayLike | None = None,
    params: GaitParams | None = None,
    start_time_s: float = 0.0,
) -> GaitEvents:
    """Gait events of both legs (:func:`detect_side_events` on each leg given).

    Args:
        rate_hz: Sampling rate, Hz.
        left_shank_gyr: (N, 3) left shank gyro, sensor frame, rad/s.
        right_shank_gyr: (N, 3) right shank gyro, sensor frame, rad/s.
        left_foot_gyr: (N, 3) left foot gyro, rad/s (optional).
        left_foot_acc: (N, 3) left foot specific force, m/s² (optional).
        right_foot_gyr: (N, 3) right foot gyro, rad/s (optional).
        right_foot_acc: (N, 3) right foot specific force, m/s² (optional).
        params: Thresholds (defaults: :class:`GaitParams`).
        start_time_s: Time of sample 0, s.

    Returns:
        Events of the legs whose shank gyro is given.

    Raises:
        GaitSignalError: A signal is malformed.
        NoGaitCyclesError: A given shank shows no walking.
    """
    kw = {"params": params, "start_time_s": start_time_s}
    left = right = None
    if left_shank_gyr is not None:
        left = detect_side_events(
            left_shank_gyr,
            rate_hz,
            "left",
            foot_gyr=left_foot_gyr,
            foot_acc=left_foot_acc,
            **kw,  # type: ignore[arg-type]
        )
    if right_shank_gyr is not None:
        right = detect_side_events(
            right_shank_gyr,
            rate_hz,
            "right",
            foot_gyr=right_foot_gyr,
            foot_acc=right_foot_acc,
            **kw,  # type: ignore[arg-type]
        )
    return GaitEvents(left=left, right=right)
