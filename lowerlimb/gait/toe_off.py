"""Toe-off from a foot IMU: the end of push-off, when the forefoot unloads.

A foot IMU sits on the rearfoot or midfoot. In pre-swing the rearfoot rotates
about the metatarsophalangeal joint while the toes stay on the floor, so the
foot's plantarflexion rate peaks *before* the toe leaves (44-64 ms before
Zeni et al. 2008's marker toe-off on the real walk of ``gait/``;
benchmarks/gait_events.py), and its return to zero (the foot's largest
plantarflexion) comes after it (57-66 ms). Neither rate feature is the event.
The accelerometer sees the event itself: it measures the contact forces on the
foot per unit mass, and in push-off the ground reaction under the forefoot
raises the foot's specific force; when the toe leaves, that reaction vanishes
and the specific force collapses within a few tens of ms before the swing
begins. Toe-off is taken as the half-way point of that collapse: the instant
the specific-force magnitude crosses the mean of its last peak and the
collapse's minimum, like the half-amplitude time of any step (the "foot
acceleration feature" idea of Joshi, Nakamura
& Hahn 2015, "A novel approach for toe off estimation during locomotion and
transitions on ramps and level ground", IEEE J. Biomed. Health Inform. 20(1),
which time toe-off from a foot accelerometer's wavelet features).

Choices the paper leaves open, stated here:

* the search is bracketed by the foot's sagittal-rate minimum before the shank's
  mid-swing peak (the rearfoot's fastest plantarflexion) and the rate's next
  negative-to-positive crossing (its largest plantarflexion), so the estimate
  can never leave the interval the rate alone allows;
* the collapse is the first trough of the specific-force magnitude in that bracket
  that comes within :attr:`GaitParams.unloading_min_mps2` of the bracket's smallest
  value, not the smallest value itself: the swing's first forward acceleration can
  raise the magnitude again and drop it into a second trough as deep as the first
  (on seed 201 of the seven-IMU simulator at 60 Hz the second was 0.4 m/s² deeper
  and 19 toe-offs came 53 ms late; one stride of the real walk had the same shape,
  32 ms late at 100 Hz and 72 ms at 50 Hz). The collapse counts only when it lies at
  least ``unloading_min_mps2`` below the peak before it; otherwise the stride's
  toe-off is the middle of the bracket (:func:`push_off_midpoint`), and only a
  stride with no bracket falls back to the shank;
* the unloading must lie within :attr:`GaitParams.unloading_max_offset` (a quarter) of
  the bracket's length from the bracket's middle, else the middle is taken. A foot that
  barely loads its forefoot before toe-off (a shuffling gait, the simulator's
  ``pace="shuffle"``, and a first draft of its slow walker) shows no collapse at toe-off,
  but the swing's first transient 30-40 ms later (a 2-3 g spike, in the real walk's foot
  IMU too: 25-33 m/s² some 40 ms after the marker toe-off) makes a deep trough of its own:
  taken for the unloading, three shuffling walks of six timed every toe-off 42-52 ms late;
* the magnitude is low-passed at :attr:`GaitParams.unloading_lowpass_hz`
  (unchanged at 100 Hz), and the half-way crossing is interpolated linearly
  between the two samples around it;
* why half-way, not the peak: the peak is where the forefoot's reaction starts to
  fall, not where it has gone. On the seven-IMU simulator, whose forefoot reaction
  ends exactly at its toe-off, the peak came 9-11 ms early on every seed and the
  half-way crossing 0.3 ms (median, 6 seeds; benchmarks/gait.py). On the real walk
  of ``gait/`` the two straddle Zeni et al. 2008's marker toe-off (peak 8 / 11 ms
  early, half-way 14 / 8 ms late, left / right), a kinematic reference with a bias
  of its own against force plates.

The fallback, the middle of the rate bracket, uses the two rate features the
docstring's first paragraph rejects as the event, and their mean because they
straddle it by similar amounts (44-64 ms before, 57-66 ms after on the real walk).
Taken as every stride's toe-off it is coarser than the unloading on the simulator
(six walks at 100 Hz: 5.8 / 11.1 ms median / worst against 1.5 / 3.9 ms) and closer to
Zeni et al.'s marker toe-offs on the real walk's straight strides (left / right
9.8 / 2.8 ms median, 15.3 / 6.5 ms worst, against 14.1 / 7.6 and 31.8 / 14.0 ms), a
reference with its own bias and one subject; the unloading, a force event, stays first.
As the fallback it is much closer than the shank's minimum where the forefoot's
unloading is too shallow to time: on six simulated walks at 50 Hz the worst toe-off
went from 114 ms (shank) to 9 ms, and the real walk's pivot turn from 73 to 17 ms.
"""

from __future__ import annotations

import numpy as np

from lowerlimb.conventions import FloatArray
from lowerlimb.gait._signal import lowpass, parabolic_vertex
from lowerlimb.gait.params import GaitParams

__all__ = ["forefoot_unloading", "push_off_midpoint"]


def _bracket(w: FloatArray, lo: int, hi: int, min_rps: float) -> tuple[int, int] | None:
    """(rate minimum, next negative-to-positive crossing) of ``w`` in [lo, hi), or ``None``."""
    if hi - lo < 3:
        return None
    k = lo + int(np.argmin(w[lo:hi]))
    if w[k] >= -min_rps:
        return None
    j = np.arange(k, hi - 1)
    up = j[(w[j] < 0.0) & (w[j + 1] >= 0.0)]
    return (k, int(up[0]) + 1) if up.size else None


def forefoot_unloading(
    foot_omega_rps: FloatArray,
    foot_acc: FloatArray,
    windows: list[tuple[int, int]],
    rate_hz: float,
    params: GaitParams,
) -> list[float | None]:
    """Toe-off of each search window as a fractional sample index (``None``: not found).

    Args:
        foot_omega_rps: (N,) foot sagittal rate, rad/s, swing positive (push-off negative;
            :func:`~lowerlimb.gait.foot_contact.foot_sagittal_rate`).
        foot_acc: (N, 3) foot specific force, sensor frame, m/s².
        windows: Half-open sample ranges ``[lo, hi)`` ending at a mid-swing peak, one per
            stride, in which toe-off is searched.
        rate_hz: Sampling rate, Hz.
        params: Thresholds (:attr:`~GaitParams.sagittal_lowpass_hz`,
            :attr:`~GaitParams.event_min_rps`, :attr:`~GaitParams.unloading_lowpass_hz`,
            :attr:`~GaitParams.unloading_min_mps2`).

    Returns:
        One entry per window: the half-way crossing of the specific-force magnitude
        from its last peak down to the forefoot's unloading, or ``None`` when the
        window shows no push-off, no unloading deeper than ``unloading_min_mps2``, or
        one further than ``unloading_max_offset`` from the rate bracket's middle.
    """
    w = lowpass(np.asarray(foot_omega_rps, dtype=float), params.sagittal_lowpass_hz, rate_hz)
    f = lowpass(
        np.linalg.norm(np.asarray(foot_acc, dtype=float), axis=1), params.unloading_lowpass_hz, rate_hz
    )
    out: list[float | None] = []
    for lo, hi in windows:
        br = _bracket(w, max(lo, 0), min(hi, w.shape[0]), params.event_min_rps)
        if br is None:
            out.append(None)
            continue
        k, z = br
        d = _first_trough(f, k, z, params.unloading_min_mps2)
        t = None if d is None else _half_way(f, k + int(np.argmax(f[k:d])), d)
        far = t is not None and abs(t - _bracket_middle(w, k, z)) > params.unloading_max_offset * (z - k)
        out.append(None if far else t)
    return out


def _first_trough(f: FloatArray, k: int, z: int, depth: float) -> int | None:
    """First trough of ``f[k : z + 1]`` within ``depth`` of its minimum and ``depth`` under an earlier peak.

    Returns:
        Its index in ``f``, or ``None`` when no trough qualifies.
    """
    seg = f[k : z + 1]
    j = np.arange(1, seg.shape[0])
    nxt = np.append(seg[2:], np.inf)
    trough = j[(seg[j] < seg[j - 1]) & (seg[j] <= nxt) & (seg[j] <= seg.min() + depth)]
    peak_before = np.maximum.accumulate(seg)
    deep = trough[peak_before[trough - 1] - seg[trough] >= depth]
    return k + int(deep[0]) if deep.size else None


def _half_way(f: FloatArray, p: int, d: int) -> float:
    """Fractional sample index where ``f`` first falls below the mean of ``f[p]`` and ``f[d]`` (p < d)."""
    half = 0.5 * (f[p] + f[d])
    j = p + 1 + int(np.argmax(f[p + 1 : d + 1] < half))
    return float(j - 1 + (f[j - 1] - half) / (f[j - 1] - f[j]))


def _zero_crossing(w: FloatArray, z: int) -> float:
    """Fractional sample index of the negative-to-positive crossing between ``z - 1`` and ``z``."""
    a, b = w[z - 1], w[z]
    return float(z - 1 + (-a) / (b - a)) if b > a else float(z)


def _bracket_middle(w: FloatArray, k: int, z: int) -> float:
    """Fractional sample index half-way between the rate's minimum ``k`` (parabola) and its crossing ``z``."""
    return 0.5 * (parabolic_vertex(w, k) + _zero_crossing(w, z))


def push_off_midpoint(
    foot_omega_rps: FloatArray, windows: list[tuple[int, int]], rate_hz: float, params: GaitParams
) -> list[float | None]:
    """The fallback toe-off of each window: the middle of the foot's push-off rate bracket.

    Args:
        foot_omega_rps: (N,) foot sagittal rate, rad/s, swing positive.
        windows: Half-open sample ranges ``[lo, hi)``, as for :func:`forefoot_unloading`.
        rate_hz: Sampling rate, Hz.
        params: Thresholds (:attr:`~GaitParams.sagittal_lowpass_hz`,
            :attr:`~GaitParams.event_min_rps`).

    Returns:
        One entry per window, a fractional sample index: the mean of the rate's minimum
        (refined by a parabola) and its next negative-to-positive crossing (interpolated
        linearly), or ``None`` when the window shows no push-off.
    """
    w = lowpass(np.asarray(foot_omega_rps, dtype=float), params.sagittal_lowpass_hz, rate_hz)
    out: list[float | None] = []
    for lo, hi in windows:
        br = _bracket(w, max(lo, 0), min(hi, w.shape[0]), params.event_min_rps)
        out.append(None if br is None else _bracket_middle(w, *br))
    return out
