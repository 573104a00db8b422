"""QUEST: QUaternion ESTimator (Shuster & Oh 1981), the measurement step of Yun & Bachmann 2006.

Same problem and ``K`` matrix as :mod:`lowerlimb.orientation.esoq2`. QUEST
finds ``λ_max`` from the characteristic polynomial, then the optimal
quaternion in closed form from the Cayley–Hamilton theorem::

    α = λ² − σ² + κ,  β = λ − σ,  γ = (λ + σ) α − Δ,
    x = (α I + β S + S²) z,     q ∝ [x; γ]

with ``κ = tr adj S`` and ``Δ = det S``. Like ESOQ-2 it is singular for a
rotation near 180°, handled by the same sequential rotation of the
reference (Shuster & Oh 1981, method of sequential rotations), here choosing
the 180° turn that makes ``σ`` largest.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray
from lowerlimb.orientation.esoq2 import (
    _check_pairs,
    attitude_profile,
    lambda_max,
    turn_reference,
    undo_rotation,
)


@njit(cache=True)
def _quest_rotated(B0: FloatArray, rot: int, lam: float) -> tuple[float, float, float, float]:
    """Unnormalised QUEST quaternion ``(γ, x)`` for the reference turned by 180° about axis ``rot``."""
    sg = (1.0, 1.0, 1.0)
    if rot == 1:
        sg = (1.0, -1.0, -1.0)
    elif rot == 2:
        sg = (-1.0, 1.0, -1.0)
    elif rot == 3:
        sg = (-1.0, -1.0, 1.0)
    # B R_k: column c scaled by sg[c]
    b00, b01, b02 = B0[0, 0] * sg[0], B0[0, 1] * sg[1], B0[0, 2] * sg[2]
    b10, b11, b12 = B0[1, 0] * sg[0], B0[1, 1] * sg[1], B0[1, 2] * sg[2]
    b20, b21, b22 = B0[2, 0] * sg[0], B0[2, 1] * sg[1], B0[2, 2] * sg[2]
    sigma = b00 + b11 + b22
    s00, s11, s22 = 2.0 * b00, 2.0 * b11, 2.0 * b22
    s01, s02, s12 = b01 + b10, b02 + b20, b12 + b21
    z0, z1, z2 = b12 - b21, b20 - b02, b01 - b10
    kappa = (s11 * s22 - s12 * s12) + (s00 * s22 - s02 * s02) + (s00 * s11 - s01 * s01)
    delta = s00 * (s11 * s22 - s12 * s12) - s01 * (s01 * s22 - s12 * s02) + s02 * (s01 * s12 - s11 * s02)
    alpha = lam * lam - sigma * sigma + kappa
    beta = lam - sigma
    gamma = (lam + sigma) * alpha - delta
    t0 = s00 * z0 + s01 * z1 + s02 * z2  # S z
    t1 = s01 * z0 + s11 * z1 + s12 * z2
    t2 = s02 * z0 + s12 * z1 + s22 * z2
    u0 = s00 * t0 + s01 * t1 + s02 * t2  # S² z
    u1 = s01 * t0 + s11 * t1 + s12 * t2
    u2 = s02 * t0 + s12 * t1 + s22 * t2
    return (
        gamma,
        alpha * z0 + beta * t0 + u0,
        alpha * z1 + beta * t1 + u1,
        alpha * z2 + beta * t2 + u2,
    )


@njit(cache=True)
def quest_kernel(b: FloatArray, r: FloatArray, weights: FloatArray) -> FloatArray:
    """QUEST on (n, 3) unit vectors ``b`` (sensor) and ``r`` (earth), weights (n,).

    Returns the (4,) unit quaternion ``w, x, y, z`` (sensor -> earth), ``w >= 0``.
    The sequential rotation starts with the one of largest ``σ``; when the
    rotated attitude is still within ~145° of singular (``|γ| < 0.3 ‖q‖``) the
    other three are tried and the best conditioned is kept.
    """
    B0, rot = attitude_profile(b, r, weights, True)
    lam = lambda_max(B0, b.shape[0], weights.sum())
    # undo the rotation applied by attitude_profile so B0 is the plain profile matrix
    turn_reference(B0, rot)
    qw, qx, qy, qz = _quest_rotated(B0, rot, lam)
    n = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    if abs(qw) < 0.3 * n:
        for k in range(4):
            if k != rot:
                cw, cx, cy, cz = _quest_rotated(B0, k, lam)
                cn = math.sqrt(cw * cw + cx * cx + cy * cy + cz * cz)
                if cn > 0.0 and abs(cw) / cn > abs(qw) / max(n, 1e-300):
                    qw, qx, qy, qz, n, rot = cw, cx, cy, cz, cn, k
    out = np.zeros(4)
    if n == 0.0:
        out[0] = 1.0
        return out
    qw, qx, qy, qz = undo_rotation(qw / n, qx / n, qy / n, qz / n, rot)
    out[0] = qw
    out[1] = qx
    out[2] = qy
    out[3] = qz
    return out


def quest(b_sensor: ArrayLike, r_earth: ArrayLike, weights: ArrayLike | None = None) -> FloatArray:
    """Optimal attitude from vector pairs by QUEST.

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
    return quest_kernel(b, r, w)
