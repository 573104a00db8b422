"""Compiled vector pairs for the filters whose measurement solves Wahba's problem (FTECF, QUEST-KF).

Two pairs per sample, sensor-frame ``b`` against earth-frame ``r`` (ENU):

* gravity: the normalised specific force when it can be trusted
  (``|‖f‖ − g_ref| ≤ δa`` and ``‖ω‖ ≤ δw``, Zhu & Xu 2018 eq. 18), else the
  "up" direction predicted by the gyro, against ``e_z``;
* 9-axis: the normalised magnetometer against ``r_m = (0, cos δ, −sin δ)``
  (δ: the dip measured at the start), replaced by the field predicted by the
  gyro when its norm or dip departs from the start; 6-axis: the predicted
  north made orthogonal to gravity against ``e_y``, so that the pair
  constrains the inclination only.

The reasons for these choices are given by :mod:`~lowerlimb.orientation.ftecf`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from lowerlimb.conventions import FloatArray
from lowerlimb.orientation._quaternion_nb import norm3, rotate_to_sensor


@njit(cache=True)
def reference_pairs(
    use_mag: bool, mag_dip_ref: float, mag_weight: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(b, r, weights)`` for a run: ``r`` and ``weights`` filled in, ``b`` left for :func:`measure_pairs`.

    The second pair weighs ``mag_weight`` (the gravity pair ``1 − mag_weight``)
    with the magnetometer, and the same as the gravity pair without it.
    """
    b = np.empty((2, 3))
    r = np.zeros((2, 3))
    r[0, 2] = 1.0
    wts = np.empty(2)
    if use_mag:
        r[1, 1] = math.cos(mag_dip_ref)
        r[1, 2] = -math.sin(mag_dip_ref)
        wts[0] = 1.0 - mag_weight
        wts[1] = mag_weight
    else:
        r[1, 1] = 1.0
        wts[0] = 0.5
        wts[1] = 0.5
    return b, r, wts


@njit(cache=True)
def measure_pairs(
    b: FloatArray,
    r: FloatArray,
    w: float,
    x: float,
    y: float,
    z: float,
    acc: FloatArray,
    mag: FloatArray,
    i: int,
    use_mag: bool,
    gyr_norm: float,
    g_ref: float,
    acc_tol: float,
    gyr_tol: float,
    mag_norm_ref: float,
    mag_dip_ref: float,
    mag_norm_tol: float,
    mag_dip_tol: float,
) -> None:
    """Fill ``b`` (2, 3) with the sensor-frame vectors of sample ``i``.

    Args:
        b: Output, gravity and second vector, sensor frame.
        r: Earth references from :func:`reference_pairs` (``r[1]`` is ``r_m``
            with the magnetometer).
        w: Gyro prediction of the orientation at sample ``i``, scalar part
            (x, y, z: vector part), sensor -> ENU.
        x: See ``w``.
        y: See ``w``.
        z: See ``w``.
        acc: (N, 3) specific force, sensor frame, m/s².
        mag: (N, 3) magnetometer, any unit (read only when ``use_mag``).
        i: Sample index.
        use_mag: 9-axis.
        gyr_norm: ``‖ω‖`` of sample ``i``, rad/s.
        g_ref: Accelerometer norm at rest, m/s².
        acc_tol: δa, m/s².
        gyr_tol: δw, rad/s.
        mag_norm_ref: Undisturbed field norm; ``<= 0`` accepts every non-zero sample.
        mag_dip_ref: Undisturbed dip, rad.
        mag_norm_tol: Largest relative deviation of the field norm.
        mag_dip_tol: Largest deviation of the dip, rad.
    """
    ax, ay, az = acc[i, 0], acc[i, 1], acc[i, 2]
    an = norm3(ax, ay, az)
    if an > 0.0 and abs(an - g_ref) <= acc_tol and gyr_norm <= gyr_tol:
        fx, fy, fz = ax / an, ay / an, az / an
    else:
        fx, fy, fz = rotate_to_sensor(w, x, y, z, 0.0, 0.0, 1.0)
    b[0, 0] = fx
    b[0, 1] = fy
    b[0, 2] = fz
    if use_mag:
        mx, my, mz = mag[i, 0], mag[i, 1], mag[i, 2]
        mn = norm3(mx, my, mz)
        ok = False
        if mn > 0.0:
            mx /= mn
            my /= mn
            mz /= mn
            dip = math.asin(max(-1.0, min(1.0, -(mx * fx + my * fy + mz * fz))))
            ok = (
                mag_norm_ref <= 0.0
                or abs(mn - mag_norm_ref) <= mag_norm_tol * mag_norm_ref
                and abs(dip - mag_dip_ref) <= mag_dip_tol
            )
        if not ok:
            mx, my, mz = rotate_to_sensor(w, x, y, z, r[1, 0], r[1, 1], r[1, 2])
        b[1, 0] = mx
        b[1, 1] = my
        b[1, 2] = mz
    else:
        nx, ny, nz = rotate_to_sensor(w, x, y, z, 0.0, 1.0, 0.0)
        d = nx * fx + ny * fy + nz * fz
        nx -= d * fx
        ny -= d * fy
        nz -= d * fz
        nn = norm3(nx, ny, nz)
        b[1, 0] = nx / nn
        b[1, 1] = ny / nn
        b[1, 2] = nz / nn


@njit(cache=True, inline="always")
def hemisphere_sign(qm: FloatArray, w: float, x: float, y: float, z: float) -> float:
    """``±1``: the sign that puts the quaternion ``qm`` on the hemisphere of ``(w, x, y, z)``."""
    if qm[0] * w + qm[1] * x + qm[2] * y + qm[3] * z < 0.0:
        return -1.0
    return 1.0
