"""Foot-stationary periods from a foot IMU: the SHOE zero-velocity detector (Skog et al. 2010).

Skog, Händel, Nilsson, Rantakokko, "Zero-velocity detection — an algorithm
evaluation", IEEE TBME 57(11), 2010, eq. 8 (stance hypothesis optimal detector):

    T_k = 1/W Σ_{l in window k} ( ‖a_l − g ā_k/‖ā_k‖‖² / σ_a²  +  ‖ω_l‖² / σ_ω² ),

with ā_k the mean specific force over the window; sample k is stationary when
``T_k < γ``. Choices the paper leaves open: the window is centred; σ_a and σ_ω
are not sensor noise but scales of the residual motion a foot keeps in
flat-foot (the paper's "model" interpretation), so γ = 1 means "on average
within one scale"; g is measured as the median specific-force norm over the
samples whose gyro norm is below σ_ω (or taken from the params);
stationary runs shorter than :attr:`GaitParams.min_stationary_s` are dropped
after moving gaps shorter than :attr:`GaitParams.merge_gap_s` are closed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.ndimage import uniform_filter1d

from lowerlimb.conventions import FloatArray
from lowerlimb.gait._signal import as_signal, runs
from lowerlimb.gait.params import GaitParams, samples

__all__ = ["StationaryPeriods", "detect_stationary"]


@dataclass(frozen=True)
class StationaryPeriods:
    """Foot-stationary samples of one foot IMU.

    Attributes:
        mask: (N,) True while the foot is stationary.
        runs: Half-open sample ranges ``(start, stop)`` of the stationary periods.
        statistic: (N,) SHOE test statistic T_k (dimensionless).
        gravity_mps2: Gravity magnitude used, m/s².
        rate_hz: Sampling rate, Hz.
    """

    mask: np.ndarray
    runs: list[tuple[int, int]]
    statistic: FloatArray
    gravity_mps2: float
    rate_hz: float

    def intervals_s(self) -> FloatArray:
        """(K, 2) start and end times of the periods, s (end = time of the last stationary sample)."""
        return np.array([(a / self.rate_hz, (b - 1) / self.rate_hz) for a, b in self.runs]).reshape(-1, 2)


def _clean(mask: np.ndarray, min_len: int, max_gap: int) -> np.ndarray:
    out = mask.copy()
    r = runs(out)
    for (_, b), (c, _) in zip(r[:-1], r[1:], strict=True):
        if c - b <= max_gap:
            out[b:c] = True
    for a, b in runs(out):
        if b - a < min_len:
            out[a:b] = False
    return out


def detect_stationary(
    gyr: ArrayLike, acc: ArrayLike, rate_hz: float, params: GaitParams | None = None
) -> StationaryPeriods:
    """Stationary (zero-velocity) periods of a foot IMU by the SHOE detector.

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s².
        rate_hz: Sampling rate, Hz.
        params: Thresholds (defaults: :class:`GaitParams`).

    Returns:
        The stationary mask, its runs and the SHOE statistic.

    Raises:
        GaitSignalError: ``gyr`` or ``acc`` is not a finite (N, 3) array, or their lengths differ.
    """
    p = params or GaitParams()
    w = as_signal(gyr, "gyr")
    a = as_signal(acc, "acc", w.shape[0])
    win = samples(p.shoe_window_s, rate_hz)
    gnorm = np.linalg.norm(w, axis=1)
    anorm = np.linalg.norm(a, axis=1)
    if p.gravity_mps2 is not None:
        g = float(p.gravity_mps2)
    else:
        quiet = gnorm < p.shoe_sigma_gyr_rps
        g = float(np.median(anorm[quiet])) if quiet.any() else 9.81
    a_mean = uniform_filter1d(a, win, axis=0, mode="nearest")
    # Σ_l ‖a_l − g u‖² over the window = Σ‖a_l‖² − 2 g u·Σa_l + W g², with u = ā/‖ā‖
    a2_mean = uniform_filter1d(anorm**2, win, mode="nearest")
    abar = np.linalg.norm(a_mean, axis=1)
    acc_term = a2_mean - 2.0 * g * abar + g**2
    gyr_term = uniform_filter1d(gnorm**2, win, mode="nearest")
    T = np.maximum(acc_term, 0.0) / p.shoe_sigma_acc_mps2**2 + gyr_term / p.shoe_sigma_gyr_rps**2
    mask = _clean(T < p.shoe_threshold, samples(p.min_stationary_s, rate_hz), samples(p.merge_gap_s, rate_hz))
    return StationaryPeriods(mask=mask, runs=runs(mask), statistic=T, gravity_mps2=g, rate_hz=rate_hz)
