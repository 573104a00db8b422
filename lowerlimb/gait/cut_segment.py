"""What a cut thigh or shank gyro lost in a swing, restored from its joints' accelerations.

A shank gyro at ±250 °/s (an MPU-6050's default) is cut in every swing: the simulated shanks
reach 350 °/s, the real walk's 460, and each cut run loses 1–9° of the shank's rotation about
the knee axis (simulated walks) or up to 34° (the real walk's turn). Unlike the foot, the thigh
and the shank never rest during a walk, so the foot's restoration between rests
(:mod:`lowerlimb.gait.cut_rate`) does not apply. Their joints do: the calibrated hip, knee and
ankle centres (Hu et al. 2021, eq. 2) tie each segment's acceleration at a joint centre to its
neighbour's,

    ‖a_S + ω_S × (ω_S × r_S) + α_S × r_S‖ = ‖a_N + ω_N × (ω_N × r_N) + α_N × r_N‖,

(both sides the acceleration of one point, seen from either sensor; the norm needs no relative
orientation), and the centripetal and tangential terms of a cut sensor read the rate it lost.

Each run of samples at one axis-sign's limit (axis ``e``, sign ``s``) missed a hump beyond the
limit, ``δω_j = s h φ_j e`` with the half-sine ``φ`` of :mod:`lowerlimb.gait.cut_force`. Its
prior height ``h⁰`` is the peak above the limit of the parabola through the two recorded samples
on either side of the run (:func:`~lowerlimb.gait.cut_force.parabola_height`): a thigh's or a
shank's swing rate is one smooth peak, and on the simulated walks cut at ±250 °/s the parabola
alone leaves 0.3–0.5° of a run's 8–9° (median; 1.2° worst). On the real walk it is as good on
most runs, but a long run (0.2 s, a shank's spin in the turn) can overshoot by more than it
lost. So each run's height solves

    min_{h ≥ 0}  Σ_t Σ_joints ((‖a_S,j‖ − ‖a_N,j‖) / σ_a)² + ((h − h⁰) / σ_h)²,
    σ_h = max(k h⁰, σ_min),

over the run and ``margin`` samples on either side (``α`` is the Savitzky–Golay derivative
of :mod:`lowerlimb.constraints.angular_acceleration`, which spreads a hump's edges), with
``scipy.optimize.least_squares`` (bounds ``h ≥ 0``), the signals smoothed by the same filter.
Runs are restored one after another in time, every other run at its prior or its solved height.
Samples where either sensor's accelerometer is cut at its range (and the smoothing window around
them) say nothing of the run; a run left with fewer joint equations inside it than it has samples
(one joint's worth) keeps its prior.

What it does downstream is in ``benchmarks/results/saturation.md`` (±250 °/s: the simulated knees'
worst angle 5.9 → 1.5° RMSE, the real walk's knee flexion against Vicon 12.1 / 6.9 → 11.8 / 5.8°,
uncut 10.5 / 4.7; the parabola alone, ``GaitParams.cut_segment_fit=False``: 1.4° and 11.5 / 5.5°,
but 6.0° for 4.8 on the real walk's right knee at ±350 °/s).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares

from lowerlimb.constraints.angular_acceleration import (
    DEFAULT_POLYORDER,
    DEFAULT_WINDOW_S,
    angular_acceleration,
    smooth,
    window_length,
)
from lowerlimb.conventions import FloatArray
from lowerlimb.gait.cut_force import cut_runs, hump, parabola_height
from lowerlimb.gait.params import GaitParams

__all__ = ["JointLink", "SegmentRestore", "restore_cut_segment_gyro"]


@dataclass(frozen=True)
class JointLink:
    """One joint of the cut sensor's segment and the neighbour across it.

    Attributes:
        centre_here_m: (3,) the joint centre in the cut sensor's frame, m.
        centre_there_m: (3,) the joint centre in the neighbour sensor's frame, m.
        acc: (N, 3) the neighbour's specific force, its frame, m/s².
        gyr: (N, 3) the neighbour's angular velocity, its frame, rad/s.
        unusable: (N,) ``True`` where either sensor's accelerometer is cut at its range (those
            samples do not constrain the run); empty: none.
    """

    centre_here_m: FloatArray
    centre_there_m: FloatArray
    acc: FloatArray
    gyr: FloatArray
    unusable: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))


@dataclass(frozen=True)
class SegmentRestore:
    """A cut thigh or shank gyro with its runs restored.

    Attributes:
        gyr_rps: (N, 3) the gyro with the restored humps, sensor frame, rad/s.
        prior_rps: (runs,) each run's parabola height, rad/s.
        height_rps: (runs,) each run's restored height, rad/s.
        lost_deg: (runs,) the rotation each run got back, deg.
    """

    gyr_rps: FloatArray
    prior_rps: FloatArray
    height_rps: FloatArray
    lost_deg: FloatArray


def _centre_acc(acc: FloatArray, gyr: FloatArray, alpha: FloatArray, r: FloatArray) -> FloatArray:
    """(M,) norm of the acceleration of point ``r`` seen from a sensor (eq. 2), m/s²."""
    a = acc + np.cross(gyr, np.cross(gyr, r)) + np.cross(alpha, r)
    return np.asarray(np.linalg.norm(a, axis=1), dtype=float)


class _Window:
    """The samples around one run that its height changes, with what stays fixed precomputed."""

    def __init__(
        self,
        gyr: FloatArray,
        acc: FloatArray,
        links: list[JointLink],
        keep: list[NDArray[np.bool_] | None],
        span: tuple[int, int],
        rate_hz: float,
    ) -> None:
        self.rate_hz = rate_hz
        self.lo, self.hi = span
        self.gyr = gyr[self.lo : self.hi].copy()
        self.acc = smooth(acc[self.lo : self.hi], rate_hz)
        self.keep = [None if k is None else k[self.lo : self.hi] for k in keep]
        self.links = links
        self.there = [
            _centre_acc(
                smooth(k.acc[self.lo : self.hi], rate_hz),
                smooth(k.gyr[self.lo : self.hi], rate_hz),
                angular_acceleration(k.gyr[self.lo : self.hi], rate_hz),
                k.centre_there_m,
            )
            for k in links
        ]

    def usable(self, a: int, b: int) -> int:
        """Joint equations left over the window's samples ``[a, b)``."""
        return sum(b - a if k is None else int(k[a:b].sum()) for k in self.keep)

    def residual(self, w: FloatArray) -> FloatArray:
        """(links · M,) ‖a_here‖ − ‖a_there‖ at each joint with the window's gyro ``w``, m/s²."""
        ws = smooth(w, self.rate_hz)
        alpha = angular_acceleration(w, self.rate_hz)
        out = []
        for k, there, keep in zip(self.links, self.there, self.keep, strict=True):
            r = _centre_acc(self.acc, ws, alpha, k.centre_here_m) - there
            out.append(r if keep is None else r[keep])
        return np.concatenate(out)


def _widened(flags: NDArray[np.bool_], half: int) -> NDArray[np.bool_]:
    """``flags`` spread by ``half`` samples either way."""
    kernel = np.ones(2 * half + 1)
    return np.asarray(np.convolve(flags.astype(float), kernel, mode="same") > 0, dtype=bool)


def restore_cut_segment_gyro(
    gyr: ArrayLike,
    acc: ArrayLike,
    rate_hz: float,
    cut_axes: ArrayLike,
    links: list[JointLink],
    params: GaitParams | None = None,
) -> SegmentRestore:
    """A cut thigh or shank gyro with each run at its limit restored (module docstring).

    Args:
        gyr: (N, 3) the sensor's angular velocity as recorded (cut), sensor frame, rad/s.
        acc: (N, 3) the sensor's specific force, sensor frame, m/s².
        rate_hz: sampling rate, Hz.
        cut_axes: (N, 3) ``+1`` / ``-1`` where a gyro axis sits at its positive / negative
            limit, ``0`` elsewhere (:attr:`lowerlimb.io.saturation.Saturation.axes`).
        links: the segment's joints with their calibrated centres and neighbours' signals
            (the neighbours' own cut runs as restored, or as recorded).
        params: ``cut_rate_prior_*``, ``cut_segment_*`` (defaults: :class:`GaitParams`).

    Returns:
        The restored gyro and each run's heights.
    """
    p = params or GaitParams()
    w = np.array(gyr, dtype=float)
    f = np.asarray(acc, dtype=float)
    cut = np.asarray(cut_axes, dtype=np.int8)
    n = w.shape[0]
    n_window = window_length(rate_hz, DEFAULT_WINDOW_S, DEFAULT_POLYORDER)
    margin = max(int(round(p.cut_segment_margin_s * rate_hz)), n_window)
    # a cut accelerometer's samples, widened by the smoothing window, say nothing
    keep = [~_widened(k.unusable, n_window // 2) if k.unusable.size else None for k in links]
    found = sorted(cut_runs(cut))
    priors = np.array([parabola_height(w[:, axis], a, b, sign) for a, b, axis, sign in found])
    shapes = []
    for a, b, axis, sign in found:
        shape = np.zeros((b - a, 3))
        shape[:, axis] = sign * hump(b - a)
        shapes.append(shape)
    heights = priors.copy()
    restored = w.copy()
    for (a, b, _, _), h, shape in zip(found, heights, shapes, strict=True):
        restored[a:b] += h * shape
    fitted = found if links and n >= 2 * margin else []  # else every run keeps its prior
    for i, (a, b, _, _) in enumerate(fitted):
        lo, hi = max(0, a - margin), min(n, b + margin)
        restored[a:b] -= heights[i] * shapes[i]  # this run's hump is the unknown
        window = _Window(restored, f, links, keep, (lo, hi), rate_hz)
        if window.usable(a - lo, b - lo) >= b - a:  # else the prior stands
            heights[i] = _height(window, shapes[i], a - lo, priors[i], p)
        restored[a:b] += heights[i] * shapes[i]
    lost = [np.degrees(h * np.abs(s).sum() / rate_hz) for h, s in zip(heights, shapes, strict=True)]
    return SegmentRestore(restored, priors, heights, np.asarray(lost, dtype=float))


def _height(window: _Window, shape: FloatArray, offset: int, prior: float, p: GaitParams) -> float:
    """One run's hump height (module docstring), rad/s; ``shape`` starts at ``offset`` in the window."""
    full = np.zeros_like(window.gyr)
    full[offset : offset + shape.shape[0]] = shape
    sd = max(p.cut_rate_prior_fraction * prior, p.cut_rate_prior_min_rps)

    def residual(h: FloatArray) -> FloatArray:
        fit = window.residual(window.gyr + h[0] * full) / p.cut_segment_acc_sd_mps2
        return np.append(fit, (h[0] - prior) / sd)

    return float(least_squares(residual, [prior], bounds=(0.0, np.inf)).x[0])
