"""What a cut foot gyro lost in a swing, restored from the foot's tilt at the rests on either side.

A foot gyro cut at its range (an MPU-6050 at ±250 °/s; the simulated feet reach 590 °/s, the
real walk's 460) loses the rotation beyond the limit in every swing: on the simulated walks
cut at ±250 °/s a cut run's missing rotation is 24° (median, one foot), and the foot's
orientation, its track and the ankle's angles carry that from one swing to the next.

The foot rests between its swings (:func:`~lowerlimb.gait.stationary.detect_stationary`) and
at rest its accelerometer reads gravity alone, so the rotation from the last sample of one
rest (``A``) to the first of the next (``B``) must carry gravity's direction in the sensor
frame from ``f_A`` to ``f_B``:

    M(α)ᵀ f̂_A = f̂_B,        M(α) = Π_{j=A}^{B−1} exp([ω_j + δω_j(α)]_× Δt),

with orientation ``q_{j+1} = q_j ⊗ exp(ω_j Δt)`` (sensor rates), as in every filter here.
Each run of samples at one axis-sign's limit (axis ``e``, sign ``s``) missed a hump beyond the
limit, ``δω_j = s α_r φ_j e`` with the half-sine ``φ`` of :mod:`lowerlimb.gait.cut_force`
and a prior height ``α⁰_r``: the peak above the limit of the parabola through the two
recorded samples on either side of the run (a foot's swing rate is a smooth peak there; the
edge-slope prior of the accelerometer, whose runs include heel-strike spikes, put the
simulated strides 1.7 % off median against 0.6 % with the parabola, the real walk's 0.66
against 0.62 %). The heights of one swing solve

    min_{α ≥ 0}  ‖(M(α)ᵀ f̂_A − f̂_B) / σ_t‖² + Σ_r ((α_r − α⁰_r) / σ_r)²,
    σ_r = max(k α⁰_r, σ_min),

by ``scipy.optimize.least_squares`` (trust-region reflective, bounds ``α ≥ 0``). The tilt
gives two equations per swing (a turn about the vertical leaves no trace in it), so a
swing's runs that turn the foot about gravity keep their priors. Only the swings of a foot
gyro found cut (:mod:`lowerlimb.io.saturation`) are touched, and only along the cut axes.

Per cut run, the rotation still missing (median / 90th percentile / worst; what it does
downstream is in ``benchmarks/results/saturation.md``): the real walk cut at ±250 °/s, left
foot 0.8 / 6.0 / 21.6° (cut: 1.0 / 11.8 / 21.6), right foot 0.2 / 1.8 / 4.6° (0.4 / 11.2 /
31.2); seed 201's simulated walk, left foot 1.5 / 5.1 / 23.6° (23.7 / 27.3 / 37.0), right
foot 3.0 / 4.6 / 5.4° (10.8 / 12.3 / 23.2). The real left foot's worst is its spin in the
turn, about the vertical, which the tilt cannot see.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from lowerlimb.conventions import FloatArray
from lowerlimb.gait._signal import runs
from lowerlimb.gait.cut_force import cut_runs, hump, parabola_height
from lowerlimb.gait.params import GaitParams
from lowerlimb.gait.stationary import StationaryPeriods

__all__ = ["RateRestore", "restore_cut_gyro"]


@dataclass(frozen=True)
class RateRestore:
    """A cut foot gyro with its swings restored.

    Attributes:
        gyr_rps: (N, 3) the gyro with the restored humps, sensor frame, rad/s.
        swings: swings between two rests that held a cut sample and were restored.
        tilt_before_deg: (swings,) angle between ``M ᵀ f̂_A`` and ``f̂_B`` as recorded, deg.
        tilt_after_deg: (swings,) ... with the restored humps, deg.
    """

    gyr_rps: FloatArray
    swings: int
    tilt_before_deg: FloatArray
    tilt_after_deg: FloatArray


@dataclass(frozen=True)
class _Run:
    start: int  # swing index of the run's first sample
    stop: int
    axis: int
    sign: int
    prior_rps: float


def _product(mats: FloatArray) -> FloatArray:
    """The ordered product of (K, 3, 3) rotation matrices (identity for none)."""
    m = np.eye(3)
    for r in mats:
        m = m @ r
    return m


class _Swing:
    """One swing's rotation as a function of its runs' hump heights.

    The samples outside the runs never change: their products are computed once, and each
    evaluation multiplies only the runs' own samples.
    """

    def __init__(self, gyr: FloatArray, cut: NDArray[np.int8], rate_hz: float) -> None:
        self.gyr, self.dt = gyr, 1.0 / rate_hz
        self.runs = [
            _Run(a, b, axis, sign, parabola_height(gyr[:, axis], a, b, sign))
            for a, b, axis, sign in cut_runs(cut)
        ]
        self.runs.sort(key=lambda r: r.start)
        self.humps = [hump(r.stop - r.start) for r in self.runs]
        # the runs may overlap (two axes cut at once): the samples between their union's pieces are fixed
        cover = np.zeros(gyr.shape[0], dtype=bool)
        for r in self.runs:
            cover[r.start : r.stop] = True
        self.pieces = runs(cover)
        edges = [0] + [i for p in self.pieces for i in p] + [gyr.shape[0]]
        self.fixed = [self._rotations(gyr[a:b]) for a, b in zip(edges[::2], edges[1::2], strict=True)]

    def _rotations(self, w: FloatArray) -> FloatArray:
        return _product(Rotation.from_rotvec(w * self.dt).as_matrix()) if w.size else np.eye(3)

    def signal(self, heights: FloatArray) -> FloatArray:
        w = self.gyr.copy()
        for r, h, alpha in zip(self.runs, self.humps, heights, strict=True):
            w[r.start : r.stop, r.axis] += r.sign * alpha * h
        return w

    def rotation(self, heights: FloatArray) -> FloatArray:
        w = self.signal(heights)
        m = self.fixed[0]
        for (a, b), after in zip(self.pieces, self.fixed[1:], strict=True):
            m = m @ self._rotations(w[a:b]) @ after
        return m


def _tilt_deg(m: FloatArray, f_a: FloatArray, f_b: FloatArray) -> float:
    return float(np.degrees(np.arccos(np.clip(f_b @ (m.T @ f_a), -1.0, 1.0))))


def _restore_swing(swing: _Swing, f_a: FloatArray, f_b: FloatArray, p: GaitParams) -> FloatArray:
    """The hump heights of one swing (module docstring), rad/s."""
    prior = np.array([r.prior_rps for r in swing.runs])
    sd = np.maximum(p.cut_rate_prior_fraction * prior, p.cut_rate_prior_min_rps)

    def residual(alpha: FloatArray) -> FloatArray:
        tilt = swing.rotation(alpha).T @ f_a - f_b
        return np.concatenate([tilt / p.cut_rate_tilt_sd_rad, (alpha - prior) / sd])

    return np.asarray(least_squares(residual, prior, bounds=(0.0, np.inf)).x, dtype=float)


def _unit(f: FloatArray) -> FloatArray:
    m = f.mean(axis=0)
    return np.asarray(m / np.linalg.norm(m), dtype=float)


def restore_cut_gyro(
    gyr: ArrayLike,
    acc: ArrayLike,
    rate_hz: float,
    cut_axes: ArrayLike,
    stationary: StationaryPeriods,
    params: GaitParams | None = None,
) -> RateRestore:
    """A cut foot gyro with each swing between two rests restored (module docstring).

    Args:
        gyr: (N, 3) the foot's angular velocity as recorded (cut), sensor frame, rad/s.
        acc: (N, 3) the foot's specific force, sensor frame, m/s².
        rate_hz: sampling rate, Hz.
        cut_axes: (N, 3) ``+1`` / ``-1`` where a gyro axis sits at its positive / negative
            limit, ``0`` elsewhere (:attr:`lowerlimb.io.saturation.Saturation.axes`).
        stationary: the foot's rests (:func:`~lowerlimb.gait.stationary.detect_stationary`).
        params: ``cut_rate_*`` (defaults: :class:`GaitParams`).

    Returns:
        The restored gyro; swings with a cut sample but no rest on either side (the
        recording's start and end) are left as recorded.
    """
    p = params or GaitParams()
    w = np.array(gyr, dtype=float)
    f = np.asarray(acc, dtype=float)
    cut = np.asarray(cut_axes, dtype=np.int8)
    n_edge = max(1, int(round(p.cut_rate_rest_s * rate_hz)))
    rests = [(a, b) for a, b in stationary.runs if b > a]
    before, after = [], []
    for (a0, a1), (b0, b1) in zip(rests[:-1], rests[1:], strict=True):
        lo, hi = a1 - 1, b0  # the last sample of rest A, the first of rest B
        if not cut[lo:hi].any():
            continue
        swing = _Swing(w[lo:hi], cut[lo:hi], rate_hz)
        f_a, f_b = _unit(f[max(a0, a1 - n_edge) : a1]), _unit(f[b0 : min(b1, b0 + n_edge)])
        heights = _restore_swing(swing, f_a, f_b, p)
        before.append(_tilt_deg(swing.rotation(np.zeros(len(swing.runs))), f_a, f_b))
        after.append(_tilt_deg(swing.rotation(heights), f_a, f_b))
        w[lo:hi] = swing.signal(heights)
    return RateRestore(w, len(before), np.asarray(before), np.asarray(after))
