"""Turns of the walker: where the pelvis turns about the vertical, by how much, how fast, in how many steps.

A clinician asks how a patient turns (turn duration, angle, peak rate, steps: the turning
measures of El-Gohary et al. 2014, "Continuous monitoring of turning in patients with
movement disability", Sensors 14(1):356–369, and Shah et al. 2021, IEEE TBME 68(9):2615),
and a gait lab's walk is straight passes joined by turns. From the pelvis sensor:

1. the vertical angular rate ω_z = (R ω)_z, with R the sensor's tilt from the orientation
   filter (no magnetometer needed: only the vertical's direction is used), rad/s;
2. smoothed by a moving average over one stride (the events' median stride time), which
   removes the pelvis's axial rotation, once per stride and ±10–40°/s, and its harmonics;
3. a turn is a run where the smoothed rate keeps one sign above
   :attr:`GaitParams.pelvis_turn_edge_dps` and peaks above
   :attr:`GaitParams.pelvis_turn_peak_dps`; runs of one direction less than
   :attr:`GaitParams.pelvis_turn_merge_s` apart are one turn (a hesitation);
4. its angle is the smoothed rate integrated over the run (the raw rate would add up to
   ±10° of the sway's phase at its ends), and it is kept when the angle is at
   least :attr:`GaitParams.pelvis_turn_min_deg` and the duration within
   :attr:`GaitParams.pelvis_turn_duration_s`.

The steps of a turn are the initial contacts of both feet inside it. A turn that the
recording starts or ends in is listed but not summarised (its angle is only a part).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.ndimage import uniform_filter1d

from lowerlimb.conventions import FloatArray, quat_rotate
from lowerlimb.gait._signal import runs
from lowerlimb.gait.params import GaitParams

__all__ = ["Turn", "Turns", "detect_turns", "vertical_rate"]

#: Smoothing window without gait events (about one stride of an adult), s.
_DEFAULT_WINDOW_S = 1.1


@dataclass(frozen=True)
class Turn:
    """One turn of the walker.

    Attributes:
        start_s: Start, s (the trial's clock).
        end_s: End, s.
        angle_deg: Turn angle, deg, positive counter-clockwise seen from above (to the left).
        peak_rate_deg_s: Largest smoothed vertical rate within the turn, deg/s (≥ 0).
        steps: Initial contacts of both feet within the turn (0 without events).
        complete: ``False`` when the recording starts or ends inside the turn (its angle and
            duration are then only the recorded part's).
    """

    start_s: float
    end_s: float
    angle_deg: float
    peak_rate_deg_s: float
    steps: int
    complete: bool = True

    @property
    def duration_s(self) -> float:
        """End minus start, s."""
        return self.end_s - self.start_s

    @property
    def direction(self) -> str:
        """``"left"`` (counter-clockwise seen from above) or ``"right"``."""
        return "left" if self.angle_deg > 0 else "right"

    def to_dict(self) -> dict[str, Any]:
        """The ``gait.json`` row of this turn."""
        return {
            "start_s": self.start_s,
            "end_s": self.end_s,
            "duration_s": self.duration_s,
            "angle_deg": self.angle_deg,
            "direction": self.direction,
            "peak_rate_deg_s": self.peak_rate_deg_s,
            "steps": self.steps,
            "complete": self.complete,
        }


@dataclass(frozen=True)
class Turns:
    """The turns of a trial and how they were found.

    Attributes:
        turns: The turns, in time order.
        window_s: The moving-average window applied to the vertical rate, s.
    """

    turns: list[Turn]
    window_s: float

    def to_dict(self) -> dict[str, Any]:
        """``gait.json``'s ``turns``: summaries over the complete turns, the count cut, the list.

        Count, mean and SD of each measure (absolute angle) over the complete turns, how many
        the recording cut, and the list of all.
        """

        def stat(values: list[float]) -> dict[str, float | None]:
            if not values:
                return {"mean": None, "sd": None}
            a = np.asarray(values, dtype=float)
            return {"mean": float(a.mean()), "sd": float(a.std(ddof=1)) if a.size > 1 else None}

        t = [x for x in self.turns if x.complete]
        return {
            "count": len(t),
            "cut_by_recording": len(self.turns) - len(t),
            "duration_s": stat([x.duration_s for x in t]),
            "angle_deg": stat([abs(x.angle_deg) for x in t]),
            "peak_rate_deg_s": stat([x.peak_rate_deg_s for x in t]),
            "steps": stat([float(x.steps) for x in t]),
            "smoothing_window_s": self.window_s,
            "list": [x.to_dict() for x in self.turns],
        }


def vertical_rate(gyr: ArrayLike, quat_wxyz: ArrayLike) -> FloatArray:
    """(N,) angular rate about the earth's vertical, rad/s (positive counter-clockwise from above).

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s (bias removed).
        quat_wxyz: (N, 4) sensor → earth orientation (z up); only its tilt matters.
    """
    return np.asarray(quat_rotate(np.asarray(quat_wxyz, dtype=float), np.asarray(gyr, dtype=float))[:, 2])


def _candidates(smooth: FloatArray, rate_hz: float, p: GaitParams) -> list[tuple[int, int, int]]:
    """``(a, b, sign)`` runs of one sign above the edge rate, peaking above the peak rate, merged."""
    edge, peak = np.deg2rad(p.pelvis_turn_edge_dps), np.deg2rad(p.pelvis_turn_peak_dps)
    out: list[tuple[int, int, int]] = []
    for sign in (1, -1):
        strong = [(a, b) for a, b in runs(sign * smooth > edge) if np.max(sign * smooth[a:b]) > peak]
        merged: list[tuple[int, int]] = []
        for a, b in strong:
            if merged and (a - merged[-1][1]) / rate_hz < p.pelvis_turn_merge_s:
                merged[-1] = (merged[-1][0], b)
            else:
                merged.append((a, b))
        out += [(a, b, sign) for a, b in merged]
    return sorted(out)


def detect_turns(
    rate_z_rps: ArrayLike,
    rate_hz: float,
    *,
    stride_time_s: float | None = None,
    initial_contacts_s: ArrayLike | None = None,
    start_time_s: float = 0.0,
    params: GaitParams | None = None,
) -> Turns:
    """The walker's turns from the pelvis's vertical angular rate (module docstring).

    Args:
        rate_z_rps: (N,) vertical angular rate of the pelvis sensor (:func:`vertical_rate`), rad/s.
        rate_hz: Sampling rate, Hz.
        stride_time_s: Median stride time, s: the smoothing window (``None``: 1.1 s).
        initial_contacts_s: Initial contacts of both feet, s on the trial's clock, to count
            each turn's steps (``None``: 0 steps).
        start_time_s: Time of sample 0, s.
        params: Thresholds (``pelvis_turn_*``; defaults: :class:`GaitParams`).

    Returns:
        The turns, with the smoothing window used.
    """
    p = params or GaitParams()
    w = np.asarray(rate_z_rps, dtype=float)
    window_s = float(stride_time_s) if stride_time_s and np.isfinite(stride_time_s) else _DEFAULT_WINDOW_S
    size = max(1, int(round(window_s * rate_hz)))
    smooth = uniform_filter1d(w, size=size, mode="nearest") if w.size else w
    ic = np.sort(np.asarray(initial_contacts_s if initial_contacts_s is not None else [], dtype=float))
    lo, hi = p.pelvis_turn_duration_s
    turns = []
    for a, b, sign in _candidates(smooth, rate_hz, p):
        angle = float(np.rad2deg(np.sum(smooth[a:b]) / rate_hz))
        start, end = start_time_s + a / rate_hz, start_time_s + (b - 1) / rate_hz
        if abs(angle) < p.pelvis_turn_min_deg or not lo <= end - start <= hi:
            continue
        steps = int(np.count_nonzero((ic >= start) & (ic <= end)))
        peak = float(np.rad2deg(np.max(sign * smooth[a:b])))
        turns.append(Turn(start, end, angle, peak, steps, complete=0 < a and b < w.size))
    return Turns(turns=turns, window_s=window_s)
