"""Optimal quaternion from weighted vector pairs (Wahba's problem): ESOQ-2 and Davenport's q-method.

Wahba's problem (Zhu & Xu 2018 eq. 13): find the rotation ``A`` minimising
``½ Σ αᵢ ‖bᵢ − A rᵢ‖²`` for unit vectors ``bᵢ`` measured in the sensor frame and
their references ``rᵢ`` in the earth frame. With ``B = Σ αᵢ bᵢ rᵢᵀ``,
``σ = tr B``, ``S = B + Bᵀ``, ``z = Σ αᵢ bᵢ × rᵢ`` and (eq. 15)::

    K = [[S − σ I, z], [zᵀ, σ]]

the optimal quaternion ``[q_v; q_4]`` is the eigenvector of ``K`` of its largest
eigenvalue ``λ_max`` (Davenport's q-method, eq. 14). In this library's
convention (``w, x, y, z``, sensor -> earth) it is ``(q_4, q_v)``:
``A = R(q)ᵀ`` maps earth vectors into the sensor frame.

ESOQ-2 (Mortari 1997; 2000, J. Guid. Control Dyn. 23:885) avoids the
eigen-decomposition. Writing ``q = [e sin(Φ/2); cos(Φ/2)]``, the two block rows
of ``K q = λ q`` give ``zᵀe sin(Φ/2) = (λ − σ) cos(Φ/2)`` and::

    M e = 0,   M = (λ − σ) [(λ + σ) I − S] − z zᵀ

so the rotation axis ``e`` spans the null space of the symmetric rank-2 matrix
``M`` — taken as the largest of the three cross products of its rows — and
(eq. 17) ``q ∝ [(λ − σ) e; zᵀe]``.

``λ_max`` (eq. 16, garbled in the print): ``K`` is traceless, its
characteristic polynomial is ``λ⁴ + b λ² + c λ + d`` with
``b = −2σ² + tr adj(S) − zᵀz`` (= −½ tr K²), ``c = −8 det B`` and
``d = det K``. For two pairs ``det B = 0``, the polynomial is biquadratic and
``λ_max = ½(√(2√d − b) + √(−2√d − b))``; for more pairs Newton's method
from ``Σ αᵢ`` converges in a few steps.

The formula degenerates when the rotation angle is near 0 (``λ − σ`` and ``z``
vanish). Mortari's remedy, Shuster's method of sequential rotations, is used
every time: the reference vectors are first turned by 180° about the earth
axis ``k ∈ {none, x, y, z}`` that makes ``σ`` smallest (the four candidate
traces sum to 0, so ``σ ≤ 0`` and ``λ − σ ≥ λ``), and
the result is composed back, ``q = (0, −e_k) ⊗ q'``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError, ShapeError


@njit(cache=True, inline="always")
def turn_reference(B: FloatArray, rot: int) -> None:
    """``B ← B R_k`` in place: negate the columns other than ``k`` (180° about earth axis ``rot``).

    The turn is its own inverse; ``rot = 0`` leaves ``B`` unchanged.
    """
    if rot > 0:
        for c in range(3):
            if c != rot - 1:
                for j in range(3):
                    B[j, c] = -B[j, c]


@njit(cache=True)
def attitude_profile(
    b: FloatArray, r: FloatArray, weights: FloatArray, largest_trace: bool
) -> tuple[FloatArray, int]:
    """Attitude profile matrix ``B = Σ αᵢ bᵢ (R_k rᵢ)ᵀ`` after the sequential rotation.

    Returns ``(B, k)``: the (3, 3) matrix, and the reference rotation ``k``
    (0: none, 1/2/3: 180° about earth x/y/z) that minimises ``tr B`` (ESOQ-2,
    singular near 0°) or, with ``largest_trace``, maximises it (QUEST,
    singular near 180°).
    """
    B = np.zeros((3, 3))
    for i in range(b.shape[0]):
        for j in range(3):
            for k in range(3):
                B[j, k] += weights[i] * b[i, j] * r[i, k]
    d0, d1, d2 = B[0, 0], B[1, 1], B[2, 2]
    traces = (d0 + d1 + d2, d0 - d1 - d2, -d0 + d1 - d2, -d0 - d1 + d2)
    rot = 0
    sign = -1.0 if largest_trace else 1.0
    for k in range(1, 4):
        if sign * traces[k] < sign * traces[rot]:
            rot = k
    turn_reference(B, rot)
    return B, rot


@njit(cache=True, inline="always")
def _k_terms(B: FloatArray) -> tuple[float, float, float, float, float, float, float, float, float, float]:
    """Entries of ``K(B)``: ``σ = tr B``, ``z`` (3) and the upper triangle of ``S = B + Bᵀ``.

    Returned as ``σ, z0, z1, z2, S00, S11, S22, S01, S02, S12``.
    """
    return (
        B[0, 0] + B[1, 1] + B[2, 2],
        B[1, 2] - B[2, 1],
        B[2, 0] - B[0, 2],
        B[0, 1] - B[1, 0],
        2.0 * B[0, 0],
        2.0 * B[1, 1],
        2.0 * B[2, 2],
        B[0, 1] + B[1, 0],
        B[0, 2] + B[2, 0],
        B[1, 2] + B[2, 1],
    )


@njit(cache=True, inline="always")
def _det4(
    a00: float, a01: float, a02: float, a03: float,
    a10: float, a11: float, a12: float, a13: float,
    a20: float, a21: float, a22: float, a23: float,
    a30: float, a31: float, a32: float, a33: float,
) -> float:  # fmt: skip
    """Determinant of a 4x4 matrix given row by row (Laplace expansion by 2x2 minors)."""
    s0 = a00 * a11 - a10 * a01
    s1 = a00 * a12 - a10 * a02
    s2 = a00 * a13 - a10 * a03
    s3 = a01 * a12 - a11 * a02
    s4 = a01 * a13 - a11 * a03
    s5 = a02 * a13 - a12 * a03
    c5 = a22 * a33 - a32 * a23
    c4 = a21 * a33 - a31 * a23
    c3 = a21 * a32 - a31 * a22
    c2 = a20 * a33 - a30 * a23
    c1 = a20 * a32 - a30 * a22
    c0 = a20 * a31 - a30 * a21
    return s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0


@njit(cache=True)
def lambda_max(B: FloatArray, n_pairs: int, weight_sum: float) -> float:
    """Largest eigenvalue of ``K(B)`` (eq. 16 corrected): closed form for 2 pairs, else Newton."""
    sigma, z0, z1, z2, S00, S11, S22, S01, S02, S12 = _k_terms(B)
    adj_tr = (S11 * S22 - S12 * S12) + (S00 * S22 - S02 * S02) + (S00 * S11 - S01 * S01)
    pb = -2.0 * sigma * sigma + adj_tr - (z0 * z0 + z1 * z1 + z2 * z2)
    detB = (
        B[0, 0] * (B[1, 1] * B[2, 2] - B[1, 2] * B[2, 1])
        - B[0, 1] * (B[1, 0] * B[2, 2] - B[1, 2] * B[2, 0])
        + B[0, 2] * (B[1, 0] * B[2, 1] - B[1, 1] * B[2, 0])
    )
    pc = -8.0 * detB
    # d = det K, K = [[S - sigma I, z], [z^T, sigma]], by the Schur-free cofactor expansion
    k00 = S00 - sigma
    k11 = S11 - sigma
    k22 = S22 - sigma
    pd = _det4(
        k00, S01, S02, z0,
        S01, k11, S12, z1,
        S02, S12, k22, z2,
        z0, z1, z2, sigma,
    )  # fmt: skip
    if n_pairs == 2:
        sd = math.sqrt(max(pd, 0.0))
        return 0.5 * (math.sqrt(max(2.0 * sd - pb, 0.0)) + math.sqrt(max(-2.0 * sd - pb, 0.0)))
    lam = weight_sum
    for _ in range(50):
        f = ((lam * lam + pb) * lam + pc) * lam + pd
        df = (4.0 * lam * lam + 2.0 * pb) * lam + pc
        if df == 0.0:
            break
        step = f / df
        lam -= step
        if abs(step) < 1e-15 * max(1.0, abs(lam)):
            break
    return lam


@njit(cache=True, inline="always")
def undo_rotation(qw: float, qx: float, qy: float, qz: float, rot: int) -> tuple[float, float, float, float]:
    """``(0, −e_k) ⊗ q'`` for the sequential rotation ``k``, returned with ``w >= 0``."""
    if rot == 1:
        qw, qx, qy, qz = qx, -qw, qz, -qy
    elif rot == 2:
        qw, qx, qy, qz = qy, -qz, -qw, qx
    elif rot == 3:
        qw, qx, qy, qz = qz, qy, -qx, -qw
    if qw < 0.0:
        return -qw, -qx, -qy, -qz
    return qw, qx, qy, qz


@njit(cache=True)
def esoq2_kernel(b: FloatArray, r: FloatArray, weights: FloatArray) -> FloatArray:
    """ESOQ-2 on (n, 3) unit vectors ``b`` (sensor) and ``r`` (earth), weights (n,).

    Returns the (4,) unit quaternion ``w, x, y, z`` (sensor -> earth) with
    ``w >= 0``. No input checks (see :func:`esoq2`).
    """
    B, rot = attitude_profile(b, r, weights, False)
    lam = lambda_max(B, b.shape[0], weights.sum())
    sigma, z0, z1, z2, S00, S11, S22, S01, S02, S12 = _k_terms(B)
    # M = (lam - sigma) [(lam + sigma) I - S] - z z^T ; its null vector is the axis e
    a = lam - sigma
    c = lam + sigma
    m00 = a * (c - S00) - z0 * z0
    m11 = a * (c - S11) - z1 * z1
    m22 = a * (c - S22) - z2 * z2
    m01 = -a * S01 - z0 * z1
    m02 = -a * S02 - z0 * z2
    m12 = -a * S12 - z1 * z2
    # cross products of the rows (0,1), (1,2), (2,0); keep the largest
    e0a = m01 * m12 - m02 * m11
    e1a = m02 * m01 - m00 * m12
    e2a = m00 * m11 - m01 * m01
    e0b = m11 * m22 - m12 * m12
    e1b = m12 * m02 - m01 * m22
    e2b = m01 * m12 - m11 * m02
    e0c = m12 * m02 - m22 * m01
    e1c = m22 * m00 - m02 * m02
    e2c = m02 * m01 - m12 * m00
    na = e0a * e0a + e1a * e1a + e2a * e2a
    nb = e0b * e0b + e1b * e1b + e2b * e2b
    nc = e0c * e0c + e1c * e1c + e2c * e2c
    if na >= nb and na >= nc:
        e0, e1, e2 = e0a, e1a, e2a
    elif nb >= nc:
        e0, e1, e2 = e0b, e1b, e2b
    else:
        e0, e1, e2 = e0c, e1c, e2c
    # eq. 17: q' = [(lam - sigma) e; z^T e], scalar first
    qw = z0 * e0 + z1 * e1 + z2 * e2
    qx = a * e0
    qy = a * e1
    qz = a * e2
    n = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    out = np.zeros(4)
    if n == 0.0:  # degenerate input (parallel vectors): no unique attitude
        out[0] = 1.0
        return out
    qw, qx, qy, qz = undo_rotation(qw / n, qx / n, qy / n, qz / n, rot)
    out[0] = qw
    out[1] = qx
    out[2] = qy
    out[3] = qz
    return out


def _check_pairs(
    b_sensor: ArrayLike, r_earth: ArrayLike, weights: ArrayLike | None
) -> tuple[FloatArray, FloatArray, FloatArray]:
    b = np.asarray(b_sensor, dtype=float)
    r = np.asarray(r_earth, dtype=float)
    if b.ndim != 2 or b.shape[1] != 3 or b.shape != r.shape:
        raise ShapeError(f"b_sensor and r_earth must both have shape (n, 3), got {b.shape} and {r.shape}")
    if b.shape[0] < 2:
        raise ShapeError(f"need at least 2 vector pairs, got {b.shape[0]}")
    w = np.full(b.shape[0], 1.0 / b.shape[0]) if weights is None else np.asarray(weights, float)
    if w.shape != (b.shape[0],) or np.any(w < 0) or not np.any(w > 0):
        raise InputError(f"weights must be {b.shape[0]} non-negative numbers, not all zero")
    nb = np.linalg.norm(b, axis=1, keepdims=True)
    nr = np.linalg.norm(r, axis=1, keepdims=True)
    if np.any(nb == 0) or np.any(nr == 0) or not (np.all(np.isfinite(b)) and np.all(np.isfinite(r))):
        raise InputError("vectors must be finite and non-zero")
    return b / nb, r / nr, w


def esoq2(b_sensor: ArrayLike, r_earth: ArrayLike, weights: ArrayLike | None = None) -> FloatArray:
    """Optimal attitude from vector pairs by ESOQ-2 (Mortari 1997; Zhu & Xu 2018 eq. 13–17).

    Args:
        b_sensor: (n, 3) directions measured in the sensor frame (any norm,
            normalised here), n >= 2, not all parallel.
        r_earth: (n, 3) the same directions in the earth frame.
        weights: (n,) non-negative weights αᵢ (equal when ``None``).

    Returns:
        (4,) unit quaternion ``w, x, y, z`` with ``w >= 0``: the orientation
        sensor -> earth that best maps ``b_sensor`` onto ``r_earth``.

    Raises:
        ShapeError: shapes are not (n, 3) with n >= 2.
        InputError: zero or non-finite vectors, or bad weights.
    """
    b, r, w = _check_pairs(b_sensor, r_earth, weights)
    return esoq2_kernel(b, r, w)


def davenport_q_method(
    b_sensor: ArrayLike, r_earth: ArrayLike, weights: ArrayLike | None = None
) -> FloatArray:
    """Exact Wahba solution: eigenvector of ``K`` with the largest eigenvalue (Davenport's q-method).

    Args:
        b_sensor: (n, 3) directions measured in the sensor frame, n >= 2.
        r_earth: (n, 3) the same directions in the earth frame.
        weights: (n,) non-negative weights (equal when ``None``).

    Returns:
        (4,) unit quaternion ``w, x, y, z`` with ``w >= 0``, sensor -> earth.

    Raises:
        ShapeError: shapes are not (n, 3) with n >= 2.
        InputError: zero or non-finite vectors, or bad weights.
    """
    b, r, w = _check_pairs(b_sensor, r_earth, weights)
    B = (w[:, None, None] * b[:, :, None] * r[:, None, :]).sum(axis=0)
    sigma = np.trace(B)
    S = B + B.T
    z = np.array([B[1, 2] - B[2, 1], B[2, 0] - B[0, 2], B[0, 1] - B[1, 0]])
    K = np.zeros((4, 4))
    K[:3, :3] = S - sigma * np.eye(3)
    K[:3, 3] = z
    K[3, :3] = z
    K[3, 3] = sigma
    _, vecs = np.linalg.eigh(K)
    v = vecs[:, -1]
    q = np.array([v[3], v[0], v[1], v[2]])
    return q if q[0] >= 0 else -q
