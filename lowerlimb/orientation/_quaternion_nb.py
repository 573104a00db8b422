"""Scalar quaternion helpers compiled with numba for the filters' inner loops.

Same conventions as :mod:`lowerlimb.conventions`: ``w, x, y, z``, Hamilton
product, a sensor orientation ``q`` maps sensor-frame vectors into the earth
frame (ENU). Every function takes and returns plain floats (tuples), so the
compiled loops never allocate; :func:`put_quat` writes one row of a loop's
(N, 4) output.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from lowerlimb.conventions import GRAVITY_MPS2

Quat = tuple[float, float, float, float]
Vec = tuple[float, float, float]


@njit(cache=True, inline="always")
def qmul(aw: float, ax: float, ay: float, az: float, bw: float, bx: float, by: float, bz: float) -> Quat:
    """Hamilton product ``a ⊗ b``."""
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True, inline="always")
def qnormalize(w: float, x: float, y: float, z: float) -> Quat:
    """Unit quaternion; the identity for a zero input."""
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if n == 0.0:
        return 1.0, 0.0, 0.0, 0.0
    return w / n, x / n, y / n, z / n


@njit(cache=True, inline="always")
def qintegrate(w: float, x: float, y: float, z: float, gx: float, gy: float, gz: float, dt: float) -> Quat:
    """``q ⊗ exp(½ ω Δt)``: exact solution of ``q̇ = ½ q ⊗ (0, ω)`` for constant ω (sensor frame).

    The result is renormalised, so rounding never accumulates.
    """
    n = math.sqrt(gx * gx + gy * gy + gz * gz)
    half = 0.5 * n * dt
    if n > 1e-12:
        c = math.cos(half)
        s = math.sin(half) / n
    else:
        c = 1.0
        s = 0.5 * dt
    rw, rx, ry, rz = qmul(w, x, y, z, c, s * gx, s * gy, s * gz)
    return qnormalize(rw, rx, ry, rz)


@njit(cache=True, inline="always")
def rotate_to_earth(w: float, x: float, y: float, z: float, vx: float, vy: float, vz: float) -> Vec:
    """``R(q) v``: a sensor-frame vector expressed in the earth frame."""
    return (
        (1.0 - 2.0 * (y * y + z * z)) * vx + 2.0 * (x * y - w * z) * vy + 2.0 * (x * z + w * y) * vz,
        2.0 * (x * y + w * z) * vx + (1.0 - 2.0 * (x * x + z * z)) * vy + 2.0 * (y * z - w * x) * vz,
        2.0 * (x * z - w * y) * vx + 2.0 * (y * z + w * x) * vy + (1.0 - 2.0 * (x * x + y * y)) * vz,
    )


@njit(cache=True, inline="always")
def rotate_to_sensor(w: float, x: float, y: float, z: float, vx: float, vy: float, vz: float) -> Vec:
    """``R(q)ᵀ v``: an earth-frame vector expressed in the sensor frame."""
    return (
        (1.0 - 2.0 * (y * y + z * z)) * vx + 2.0 * (x * y + w * z) * vy + 2.0 * (x * z - w * y) * vz,
        2.0 * (x * y - w * z) * vx + (1.0 - 2.0 * (x * x + z * z)) * vy + 2.0 * (y * z + w * x) * vz,
        2.0 * (x * z + w * y) * vx + 2.0 * (y * z - w * x) * vy + (1.0 - 2.0 * (x * x + y * y)) * vz,
    )


@njit(cache=True, inline="always")
def earth_lowpass_start(
    dt: float, tau: float, w: float, x: float, y: float, z: float, acc: NDArray[np.float64], up: bool
) -> tuple[float, float, float, float]:
    """Gain ``k = dt / (tau + dt)`` and the initial state of :func:`earth_lowpass`.

    The state starts at the first accelerometer sample rotated into the earth
    frame by the initial attitude ``q``; (0, 0, 0) for an empty record. With ``up``
    it starts at gravity, (0, 0, g): the attitude is known but the first sample
    moves (a warm start, :class:`~lowerlimb.orientation.initialisation.InitialState`).
    """
    k = dt / (tau + dt)
    lx = 0.0
    ly = 0.0
    lz = 0.0
    if up:
        lz = GRAVITY_MPS2
    elif acc.shape[0] > 0:
        lx, ly, lz = rotate_to_earth(w, x, y, z, acc[0, 0], acc[0, 1], acc[0, 2])
    return k, lx, ly, lz


@njit(cache=True, inline="always")
def earth_lowpass(
    w: float,
    x: float,
    y: float,
    z: float,
    ax: float,
    ay: float,
    az: float,
    lx: float,
    ly: float,
    lz: float,
    k: float,
) -> tuple[float, float, float, float, float, float]:
    """One step of a first-order low-pass of the specific force in the earth frame.

    ``a`` (sensor frame) is rotated into the earth frame with ``q``, the state
    ``l`` (earth frame) moves the fraction ``k`` towards it, and the new state
    is rotated back into the sensor frame (VQF's accelerometer update, Laidig &
    Seel 2023). Returns the new state ``l`` and ``R(q)ᵀ l``.
    """
    fx, fy, fz = rotate_to_earth(w, x, y, z, ax, ay, az)
    lx += k * (fx - lx)
    ly += k * (fy - ly)
    lz += k * (fz - lz)
    sx, sy, sz = rotate_to_sensor(w, x, y, z, lx, ly, lz)
    return lx, ly, lz, sx, sy, sz


@njit(cache=True, inline="always")
def up_in_sensor(w: float, x: float, y: float, z: float) -> Vec:
    """Earth "up" ``e_z`` in the sensor frame, ``R(q)ᵀ e_z`` (Hu et al. 2021 eq. 45–46)."""
    return (
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        w * w - x * x - y * y + z * z,
    )


@njit(cache=True, inline="always")
def cross(ax: float, ay: float, az: float, bx: float, by: float, bz: float) -> Vec:
    """``a × b``."""
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(cache=True, inline="always")
def norm3(x: float, y: float, z: float) -> float:
    """Euclidean norm of a 3-vector."""
    return math.sqrt(x * x + y * y + z * z)


@njit(cache=True, inline="always")
def put_quat(out: NDArray[np.float64], i: int, w: float, x: float, y: float, z: float) -> None:
    """Store ``w, x, y, z`` in row ``i`` of the (N, 4) array ``out``."""
    out[i, 0] = w
    out[i, 1] = x
    out[i, 2] = y
    out[i, 3] = z
