"""Errors-in-variables correction of the spherical-joint cost (corrected score).

The spherical fit (Hu et al. 2021, eq. 7) minimises ``Σ e(t)²`` with
``e = ‖g_P‖ − ‖g_C‖`` and ``g_S = a_S + K_S c_S``, ``K_S = [ω_S]×[ω_S]× + [α_S]×``.
The regressors ω and α are measured: gyro white noise ``n_ω`` (filtered) and
its derivative ``n_α`` enter ``g_S`` as ``δ_S = L_S n_ω + [c_S]×ᵀ n_α`` with
``L_S = −([ω_S × c_S]× + [ω_S]×[c_S]×)``. To first order
``e = e₀ + ĝ_Pᵀ δ_P − ĝ_Cᵀ δ_C``, so the expected cost is

    E Σ e² = Σ e₀² + Σ_t [v_P(t) + v_C(t)],
    v_S = σ_α,S² |c_S × ĝ_S|² + σ_ω,S² |M_S c_S|²,   M_S = [ĝ_S]×[ω_S]× + [ĝ_S × ω_S]×

(``ĝ = g/‖g‖``; ω and α noise are uncorrelated at lag 0 because the filters
are symmetric and the derivative antisymmetric). Every ``v`` is a quadratic
form ``cᵀ Q c`` that grows with the distance from the sensor, so the plain fit
is pulled towards the sensor whose regressors are noisiest — the classical
attenuation of errors in variables (Fuller 1987, *Measurement Error Models*,
§1.1). The corrected score (Nakamura 1990, *Biometrika* 77:127–137) removes
the expectation: minimise

    F(x) = Σ e(x)² − xᵀ Q(x) x,       Q = blockdiag(Q_P, Q_C),

with ``Q_S = Σ_t [σ_α,S² (I − ĝĝᵀ) + σ_ω,S² M_Sᵀ M_S]`` evaluated at the current
centres (ĝ changes slowly with x). The noise also shifts the mean of each norm
by ``tr((I − ĝĝᵀ) Σ_δ) / (2‖g‖)``; that shift is left out (in a Monte-Carlo
check on a simulated walk's ankle, correcting it too moved the mean centre by
less than the Monte-Carlo standard error, about 2 mm). The noise levels come
from the still start (:mod:`lowerlimb.constraints.regressor_noise`).

Where the noise's share of the information ``Q`` approaches the data's ``JᵀJ``
the corrected cost loses its minimum (the moment matrix is no longer positive
definite); as in Fuller's modified estimators (§2.5) the correction is limited
there: each generalised eigenvalue λ of ``(Q, JᵀJ)`` is capped at
``noise_correction_max_fraction``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lowerlimb.constraints.spherical import SphericalData, joint_acceleration
from lowerlimb.conventions import FloatArray, skew

__all__ = ["NoiseCorrection", "noise_information", "capped_noise_information", "corrected_gauss_newton"]


#: Passes of the corrected Gauss–Newton, each with ``Q`` re-evaluated at the last solution.
_OUTER_PASSES = 2


@dataclass(frozen=True)
class NoiseCorrection:
    """The result of the corrected fit.

    Attributes:
        x: (6,) corrected ``(c_P, c_C)``, sensor frames, m.
        Q: (6, 6) the (capped) noise information subtracted at ``x``, (1/s²)²·samples.
        max_fraction: largest generalised eigenvalue of ``(Q, JᵀJ)`` before the cap.
        iterations: Gauss–Newton iterations.
    """

    x: FloatArray
    Q: FloatArray
    max_fraction: float
    iterations: int


def _sensor_block(
    acc: FloatArray,
    gyr: FloatArray,
    angacc: FloatArray,
    c: FloatArray,
    s_gyr: float,
    s_alpha: float,
    w: FloatArray,
) -> FloatArray:
    if s_gyr == 0.0 and s_alpha == 0.0:
        return np.zeros((3, 3))
    g = joint_acceleration(acc, gyr, angacc, c)
    gh = g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-9)
    Q = s_alpha**2 * (float(np.sum(w)) * np.eye(3) - (gh * w[:, None]).T @ gh)
    if s_gyr > 0.0:
        M = skew(gh) @ skew(gyr) + skew(np.cross(gh, gyr))
        Q = Q + s_gyr**2 * np.einsum("n,nki,nkj->ij", w, M, M)
    return np.asarray(Q, dtype=float)


def noise_information(x: FloatArray, data: SphericalData, weights: FloatArray | None = None) -> FloatArray:
    """The quadratic form ``Q`` of the expected noise part of ``Σ w e²`` at ``x``.

    Args:
        x: (6,) ``(c_P, c_C)``, m.
        data: the pair's signals and their regressor noise levels.
        weights: (N,) sample weights ``w`` (``None``: all 1).

    Returns:
        (6, 6) block-diagonal ``Q`` such that ``E Σ w e² ≈ Σ w e₀² + xᵀ Q x``, 1/s⁴.
    """
    w = np.ones(data.n_samples) if weights is None else np.asarray(weights, dtype=float)
    Q = np.zeros((6, 6))
    Q[:3, :3] = _sensor_block(
        data.acc_parent,
        data.gyr_parent,
        data.angacc_parent,
        x[:3],
        data.gyr_noise_parent,
        data.angacc_noise_parent,
        w,
    )
    Q[3:, 3:] = _sensor_block(
        data.acc_child,
        data.gyr_child,
        data.angacc_child,
        x[3:],
        data.gyr_noise_child,
        data.angacc_noise_child,
        w,
    )
    return Q


def capped_noise_information(Q: FloatArray, H: FloatArray, max_fraction: float) -> tuple[FloatArray, float]:
    """``Q`` with its generalised eigenvalues against ``H`` capped at ``max_fraction``.

    Args:
        Q: (n, n) symmetric positive semi-definite noise information.
        H: (n, n) symmetric positive definite data information ``JᵀJ``.
        max_fraction: the cap, in (0, 1).

    Returns:
        The capped ``Q`` and the largest eigenvalue before capping.
    """
    w, V = np.linalg.eigh(H)
    if w[0] <= 0:
        return np.zeros_like(Q), float("inf")
    S = V @ np.diag(1.0 / np.sqrt(w)) @ V.T  # H^(-1/2)
    lam, U = np.linalg.eigh(S @ Q @ S)
    top = float(lam[-1]) if lam.size else 0.0
    if top <= max_fraction:
        return Q, top
    R = V @ np.diag(np.sqrt(w)) @ V.T  # H^(1/2)
    return R @ U @ np.diag(np.minimum(lam, max_fraction)) @ U.T @ R, top


def corrected_gauss_newton(
    residual: Callable[[FloatArray], FloatArray],
    jacobian: Callable[[FloatArray], FloatArray],
    data: SphericalData,
    x0: FloatArray,
    *,
    n_data: int,
    weights: FloatArray | None = None,
    max_fraction: float,
    bound: float,
    max_iter: int,
    tol: float,
) -> NoiseCorrection:
    """Minimise ``‖r(x)‖² − xᵀ Q(x) x`` by Gauss–Newton with step halving.

    ``Q`` depends on x only through the directions ĝ of the joint acceleration,
    which the centres hardly turn, so it is held fixed during a pass and
    re-evaluated at the pass's solution (:data:`_OUTER_PASSES` passes).

    Args:
        residual: x ↦ (M,) residual; its first ``n_data`` rows are eq. 7, the rest
            (a prior's rows) carry no regressor noise.
        jacobian: x ↦ (M, 6) Jacobian.
        data: the pair's signals with their noise levels.
        x0: (6,) start (the plain fit), m.
        n_data: number of eq. 7 rows.
        weights: (n_data,) sample weights already applied to the rows (``None``: 1).
        max_fraction: cap of the correction (:func:`capped_noise_information`).
        bound: search box ``|x_i| ≤ bound``, m.
        max_iter: iteration limit.
        tol: stop when the step is below ``tol · (1 + ‖x‖)``.

    Returns:
        The corrected fit.
    """
    x = np.asarray(x0, dtype=float).copy()

    def capped_q(x: FloatArray) -> tuple[FloatArray, float]:
        Jd = jacobian(x)[:n_data]
        return capped_noise_information(noise_information(x, data, weights), Jd.T @ Jd, max_fraction)

    def cost(x: FloatArray, Q: FloatArray) -> float:
        r = residual(x)
        return float(r @ r - x @ Q @ x)

    Q, first_top = capped_q(x)
    iterations = 0
    for _ in range(_OUTER_PASSES):
        c = cost(x, Q)
        for _ in range(max_iter):
            iterations += 1
            r, J = residual(x), jacobian(x)
            try:
                step = np.linalg.solve(J.T @ J - Q, -(J.T @ r) + Q @ x)
            except np.linalg.LinAlgError:
                break
            t, xn, cn = 1.0, x, c
            while t > 1e-4:
                xn = np.clip(x + t * step, -bound, bound)
                cn = cost(xn, Q)
                if cn <= c:
                    break
                t *= 0.5
            if cn > c:
                break
            moved = float(np.linalg.norm(xn - x))
            x, c = xn, cn
            if moved < tol * (1.0 + float(np.linalg.norm(x))):
                break
        Q, _ = capped_q(x)
    return NoiseCorrection(x=x, Q=Q, max_fraction=first_top, iterations=iterations)
