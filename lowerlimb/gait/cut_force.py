"""What a cut foot accelerometer lost in a swing, restored from the zero-velocity updates at its ends.

A foot accelerometer cut at its range (an MPU-6050 or a Shimmer's low-noise channel at
±2 g; :mod:`lowerlimb.io.saturation` finds the cut) loses the specific force beyond the
limit exactly where the foot accelerates hardest: push-off, the swing's reversal, heel
strike. Integrated (:func:`~lowerlimb.gait.trajectory.integrate_foot`), the swing then ends
with a velocity far from zero, and the linear de-drift spreads that error evenly over the
swing as if a constant acceleration error had made it: the track's shape is wrong (at ±2 g
the simulated seven-IMU walks' stride lengths came out 13 % short, median; the step width
131 mm off).

Here the error is put back where it arose. Each run of samples at one axis-sign's limit
(axis ``e``, sign ``s``) missed a hump of force beyond the limit along that axis,

    δf_j = s α_r φ_j e,        φ_j = sin(π (j + ½) / L),   j = 0 … L − 1,

a half-sine over the run's ``L`` samples (peak 1) with an unknown height ``α_r ≥ 0``, m/s².
In the earth frame the swing's runs change its end velocity by ``D α``, where column ``r``
of the (3, R) matrix ``D`` is ``Σ_j w_j q_j ⊗ (s φ_j e) ⊗ q_j*`` (``w_j`` the trapezoidal
weights of the velocity integral, s). The zero-velocity update at the swing's end asks for
``v_end + D α = 0``. Three equations cannot share the velocity among a swing's runs (a
push-off's and a heel strike's lost force add to the same end velocity but move the foot
very differently), so each run's height has a prior ``α⁰_r``: the half-sine whose ends
leave at the slopes of the recorded signal just before and just after the run
(``α⁰ = T ṡ / π`` for a run of ``T`` seconds and a mean edge slope ``ṡ``). The heights solve

    min_{α ≥ 0}  ‖v_end + D α‖² + λ ‖α − α⁰‖²,        λ = GaitParams.cut_restore_ridge_s2,

by ``scipy.optimize.nnls`` on the stacked system. Whatever of ``v_end`` the cut cannot
explain (a bias, an orientation error) is left to the linear de-drift, as before. The
force is restored along the cut axes only and only beyond the limit, so a swing without a
cut is untouched.

Measured on the simulated seven-IMU walks cut at ±2 g (seeds 201–203,
``benchmarks/results/saturation.md``): stride length 13.3 → 1.0 % median error (4.1 %
worst; uncut 0.7 %), step width 131 → 38 mm median (uncut 10). λ = 10⁻⁴ s² (the
columns are 0.02–0.2 s long, so the end velocity dominates and the priors share out what
it leaves open): 10⁻⁵ and 3·10⁻⁵ gave 0.96 / 0.92 % and 51 / 49 mm, 10⁻³ 1.17 % and 44 mm,
10⁻² 4.1 % and 66 mm; without the priors (``α⁰ = 0``) 1.2 % and 58 mm, and λ = 0 (no prior
at all) put one swing's stride 52 % off. The edge heights are rough (on seed 201's feet the
runs longer than 5 samples have 1.3–1.6 times their true area, the 1–2-sample heel-strike
spikes a third of it); the end velocity corrects their sum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import nnls

from lowerlimb.conventions import FloatArray, quat_rotate
from lowerlimb.gait._signal import runs

__all__ = ["SwingRestore", "cut_runs", "edge_height", "hump", "parabola_height", "restore_swing"]


@dataclass(frozen=True)
class SwingRestore:
    """The force one swing's cut runs get back.

    Attributes:
        force_earth_mps2: (M, 3) earth-frame specific force to add over the swing's samples
            ``lo … hi`` (inclusive), m/s².
        heights_mps2: (R,) the runs' hump heights beyond the limit, m/s².
        velocity_mps: how much of the swing's end velocity the restored force accounts for
            (norm of ``D α``), m/s.
    """

    force_earth_mps2: FloatArray
    heights_mps2: FloatArray
    velocity_mps: float


def _trapezoid_weights(m: int, dt: float) -> FloatArray:
    """Weights of the trapezoidal integral over ``m`` samples, s."""
    w = np.full(m, dt)
    w[0] = w[-1] = 0.5 * dt
    return w


def hump(n: int) -> FloatArray:
    """``sin(π (j + ½) / n)``, ``j = 0 … n − 1``: a half-sine of height 1 over ``n`` samples."""
    return np.asarray(np.sin(np.pi * (np.arange(n) + 0.5) / n), dtype=float)


def parabola_height(x: FloatArray, a: int, b: int, sign: int) -> float:
    """The peak above the limit of the parabola through two samples either side of ``[a, b)``.

    A least-squares fit to the (up to four) samples; 0 when it does not peak. Units of ``x``.
    """
    idx = [i for i in (a - 2, a - 1, b, b + 1) if 0 <= i < x.size]
    if len(idx) < 3:
        return 0.0
    c2, c1, c0 = np.polyfit(np.asarray(idx, dtype=float), sign * x[idx], 2)
    if c2 >= 0:
        return 0.0
    tp = float(np.clip(-c1 / (2 * c2), a, b - 1))
    return max(0.0, float(c0 + c1 * tp + c2 * tp * tp) - sign * float(x[a]))


def edge_height(x: FloatArray, a: int, b: int, sign: int) -> float:
    """The hump height the signal's slopes into and out of the run ``[a, b)`` suggest, units of ``x``.

    A half-sine of height ``h`` over ``L`` samples leaves its ends at a slope of ``π h / L``
    per sample.
    """
    slopes = []
    if a >= 2:
        slopes.append(sign * (x[a - 1] - x[a - 2]))
    if b + 1 < x.size:
        slopes.append(sign * (x[b] - x[b + 1]))
    if not slopes:
        return 0.0
    return max(0.0, float(np.mean(slopes))) * (b - a) / np.pi


def cut_runs(cut: NDArray[np.int8]) -> list[tuple[int, int, int, int]]:
    """``(start, stop, axis, sign)`` of every run of samples at one axis-sign's limit (``cut`` (M, 3))."""
    return [
        (a, b, axis, sign) for axis in range(3) for sign in (1, -1) for a, b in runs(cut[:, axis] == sign)
    ]


def _humps(
    cut: NDArray[np.int8], quat: FloatArray, acc: FloatArray
) -> tuple[list[tuple[int, int]], list[FloatArray], FloatArray]:
    """Each cut run's samples ``[a, b)``, unit hump (L, 3, earth frame) and edge height (m/s²)."""
    spans, humps, prior = [], [], []
    for a, b, axis, sign in cut_runs(cut):
        local = np.zeros((b - a, 3))
        local[:, axis] = sign * hump(b - a)
        spans.append((a, b))
        humps.append(np.asarray(quat_rotate(quat[a:b], local), dtype=float))
        prior.append(edge_height(acc[:, axis], a, b, sign))
    return spans, humps, np.asarray(prior)


def restore_swing(
    end_velocity_mps: ArrayLike,
    quat_wxyz: ArrayLike,
    acc: ArrayLike,
    cut_axes: ArrayLike,
    rate_hz: float,
    ridge_s2: float,
) -> SwingRestore:
    """The force a swing's cut runs lost, sized by its end velocity (module docstring).

    Args:
        end_velocity_mps: (3,) the swing's integrated velocity at its end, earth frame, m/s
            (zero if nothing were lost).
        quat_wxyz: (M, 4) sensor → earth orientation over the swing's samples.
        acc: (M, 3) the swing's specific force as recorded (cut), sensor frame, m/s².
        cut_axes: (M, 3) ``+1`` / ``-1`` where an axis sits at its positive / negative limit,
            ``0`` elsewhere (:attr:`lowerlimb.io.saturation.Saturation.axes`).
        rate_hz: sampling rate, Hz.
        ridge_s2: ``λ``, s² (≥ 0).

    Returns:
        The restored force (zeros and no heights when the swing has no cut sample).
    """
    q = np.asarray(quat_wxyz, dtype=float)
    cut = np.asarray(cut_axes, dtype=np.int8)
    v_end = np.asarray(end_velocity_mps, dtype=float)
    m = q.shape[0]
    spans, humps, prior = _humps(cut, q, np.asarray(acc, dtype=float))
    force = np.zeros((m, 3))
    if not spans or m < 2:
        return SwingRestore(force, np.zeros(0), 0.0)
    w = _trapezoid_weights(m, 1.0 / rate_hz)
    D = np.column_stack([(w[a:b, None] * h).sum(axis=0) for (a, b), h in zip(spans, humps, strict=True)])
    r = D.shape[1]
    A = np.vstack([D, np.sqrt(ridge_s2) * np.eye(r)])
    heights, _ = nnls(A, np.concatenate([-v_end, np.sqrt(ridge_s2) * prior]))
    for (a, b), h, alpha in zip(spans, humps, heights, strict=True):
        force[a:b] += alpha * h
    return SwingRestore(force, heights, float(np.linalg.norm(D @ heights)))
