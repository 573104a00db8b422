"""Initial contact from a foot gyro: the end of the foot's swing rotation (heel-rocker onset).

In terminal swing the foot rotates toes-up (the same sense as the shank's forward
swing). The heel is the first point to touch the floor, and the ground reaction
at the heel then rotates the foot toes-down about it (the heel rocker, Perry &
Burnfield, *Gait Analysis*, 2nd ed., 2010, ch. 4) until foot flat. Heel contact
is therefore the instant the foot's sagittal angular velocity ω_f changes sign
from swing (positive) to heel rocker (negative): the foot's largest toes-up
pitch. Foot-gyro detectors place heel strike at this sign change or at the
heel-rocker peak just after it (Jasiewicz et al. 2006, "Gait event detection
using linear accelerometers or angular velocity transducers in able-bodied and
spinal-cord injured individuals", Gait Posture 24(4); Mansour et al. 2015
take the peak); the sign change is the one tied to contact
itself, the peak is later by the heel rocker's rise time. The shank's local
minimum after mid-swing (Aminian et al. 2002, Salarian et al. 2004) falls at
the end of the heel rocker too: on the real walk of ``gait/`` it coincided with
the heel marker coming to rest, ~60 ms after Zeni et al. 2008's marker contact,
while this zero crossing was 14-15 ms (median; bias +15/+19 ms) after it
(benchmarks/gait_events.py).

Choices the papers leave open, stated here:

* the foot's sagittal axis is its principal gyro axis (:func:`sagittal_rate`),
  signed so that ω_f correlates positively with the shank's sagittal rate (both
  segments rotate forward in swing about parallel medio-lateral axes), so no
  mounting convention is needed;
* the crossing searched is the first one after the shank's mid-swing peak,
  within :attr:`GaitParams.ic_search_s` and before the next mid-swing peak;
* a crossing counts only when ω_f then falls below ``-event_min_rps`` within
  :attr:`GaitParams.heel_rocker_s` (a real heel rocker, not noise about zero in
  a slow swing), all of which must be recorded: a contact in the recording's last
  ``heel_rocker_s`` is not reported (at 50 Hz the two contacts 50 ms before the end of
  six 60 s simulated walks came out 17 and 22 ms early, every other one within 12 ms;
  the zero-phase filters meet the edge there);
* the crossing is found on the rate low-passed at :attr:`GaitParams.sagittal_lowpass_hz`
  (robust against noise about zero) and then re-timed to the nearest crossing of the
  rate low-passed at :attr:`GaitParams.ic_refine_lowpass_hz` within
  :attr:`GaitParams.ic_refine_s`: the heel rocker begins with a kink that a low
  cut-off spreads backwards in time;
* sub-sample timing: linear interpolation between the two samples that straddle zero.
"""

from __future__ import annotations

import numpy as np

from lowerlimb.conventions import FloatArray
from lowerlimb.gait._signal import lowpass
from lowerlimb.gait.params import GaitParams, samples
from lowerlimb.gait.sagittal import SagittalRate, sagittal_rate

__all__ = ["foot_sagittal_rate", "heel_rocker_onsets"]


def foot_sagittal_rate(
    foot_gyr: FloatArray, shank_omega_rps: FloatArray, rate_hz: float, params: GaitParams
) -> SagittalRate:
    """The foot's sagittal rate, signed like the shank's (swing positive).

    Args:
        foot_gyr: (N, 3) foot angular velocity, sensor frame, rad/s.
        shank_omega_rps: (N,) shank sagittal rate, rad/s, mid-swing positive.
        rate_hz: Sampling rate, Hz.
        params: Thresholds.

    Returns:
        The foot's sagittal rate (rad/s) and axis (foot sensor frame), with the sign
        that makes its correlation with ``shank_omega_rps`` positive.
    """
    sr = sagittal_rate(foot_gyr, rate_hz, params)
    if float(np.dot(sr.omega_rps, shank_omega_rps)) >= 0.0:
        return sr
    return SagittalRate(
        omega_rps=-sr.omega_rps,
        axis_in_sensor=-sr.axis_in_sensor,
        walking_fraction=sr.walking_fraction,
        axis_share=sr.axis_share,
    )


def heel_rocker_onsets(
    foot_omega_rps: FloatArray, midswing: np.ndarray, rate_hz: float, params: GaitParams
) -> list[float]:
    """Initial contacts as fractional sample indices, one per mid-swing peak at most.

    Args:
        foot_omega_rps: (N,) foot sagittal rate, rad/s, swing positive
            (:func:`foot_sagittal_rate`).
        midswing: (J,) increasing sample indices of the shank's mid-swing peaks.
        rate_hz: Sampling rate, Hz.
        params: Thresholds (:attr:`~GaitParams.sagittal_lowpass_hz`,
            :attr:`~GaitParams.ic_search_s`, :attr:`~GaitParams.heel_rocker_s`,
            :attr:`~GaitParams.event_min_rps`, :attr:`~GaitParams.max_stride_time_s`,
            :attr:`~GaitParams.ic_refine_lowpass_hz`, :attr:`~GaitParams.ic_refine_s`).

    Returns:
        Increasing fractional sample indices of the positive-to-negative zero
        crossings of the low-passed ``foot_omega_rps`` that start a heel rocker.
    """
    raw = np.asarray(foot_omega_rps, dtype=float)
    w = lowpass(raw, params.sagittal_lowpass_hz, rate_hz)
    fine = lowpass(raw, params.ic_refine_lowpass_hz, rate_hz)
    n_ref = samples(params.ic_refine_s, rate_hz)
    n = w.shape[0]
    n_ic = samples(params.ic_search_s, rate_hz)
    n_rock = samples(params.heel_rocker_s, rate_hz)
    half = samples(0.5 * params.max_stride_time_s, rate_hz)
    out: list[float] = []
    for j, m in enumerate(midswing):
        nxt = int(midswing[j + 1]) if j + 1 < len(midswing) else n - 1
        hi = min(int(m) + n_ic, nxt, int(m) + half, n - 1)
        k = np.arange(int(m), hi)
        cross = k[(w[k] > 0.0) & (w[k + 1] <= 0.0)]
        for c in cross:
            if c + 1 + n_rock > n:
                break  # the heel rocker runs past the recording's end: not confirmed, not timed
            if np.min(w[c + 1 : c + 1 + n_rock]) < -params.event_min_rps:
                out.append(_retime(fine, float(c) + float(w[c] / (w[c] - w[c + 1])), n_ref))
                break
    return out


def _crossings(w: FloatArray, lo: int, hi: int) -> FloatArray:
    """Fractional indices of the positive-to-non-positive crossings of ``w`` in [lo, hi)."""
    lo, hi = max(lo, 0), min(hi, w.shape[0] - 1)
    k = np.arange(lo, hi)
    k = k[(w[k] > 0.0) & (w[k + 1] <= 0.0)]
    return k + w[k] / (w[k] - w[k + 1])


def _retime(fine: FloatArray, coarse: float, half: int) -> float:
    """The crossing of ``fine`` nearest ``coarse`` within ``half`` samples, else ``coarse``."""
    c = _crossings(fine, int(coarse) - half, int(coarse) + half + 1)
    c = c[np.abs(c - coarse) <= half]
    return float(c[np.argmin(np.abs(c - coarse))]) if c.size else coarse
