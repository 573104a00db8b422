"""Gradient-descent orientation filter (Madgwick et al. 2011), 6- and 9-axis.

Each sample, the gyro rate is integrated and the estimate takes one
normalised gradient-descent step of length ``β Δt`` on the objective
``½‖R(q)ᵀ d − s‖²`` summed over gravity (``d = e_z``, ``s`` = normalised
accelerometer) and, for 9-axis, the magnetic field (``d = (0, b_y, b_z)`` in
ENU, the measured field rotated into the earth frame with its horizontal part
turned north, ``s`` = normalised magnetometer)::

    q̇ = ½ q ⊗ (0, ω) − β ∇f / ‖∇f‖,   ∇f = Jᵀ f   (Madgwick 2011, eq. 25–34, 43–44)

Addition to the paper (parameter ``acc_lowpass_s``, on by default):

* **Accelerometer low-pass in the earth frame**, as in
  :mod:`~lowerlimb.orientation.mahony` and VQF (Laidig & Seel 2023). Before
  the gradient is evaluated, the specific force is rotated into the earth
  frame with the gyro prediction, low-pass filtered there (first order, time
  constant ``acc_lowpass_s``) and rotated back; this vector, normalised, is
  the ``s`` of the gravity term. The linear accelerations of a limb average
  out in the earth frame (their integral is a velocity change) while gravity
  does not, so the gradient no longer follows the shank's and foot's
  accelerations of several g during walking. The step remains the paper's
  normalised gradient step of length ``β Δt``. ``acc_lowpass_s = 0`` gives
  the original filter. The effect is measured in
  ``benchmarks/results/orientation.md`` and ``benchmarks/results/pipeline_accuracy.md``
  (``pipeline_accuracy.py --filters madgwick``).

Other choices: the reference field points north along ENU +y (Madgwick's
report uses north = x); the gyro part is integrated exactly,
``q ⊗ exp(½ ω Δt)`` (the original's first-order Euler step loses θ³/12 per
sample, 1° per 20 s at 8 rad/s and 200 Hz), the gradient is evaluated at that
gyro prediction (the orientation of the accelerometer's own sample time,
rather than the previous estimate), then the step is added and the result
renormalised; no gyro-bias drift term (the bias from the still start is
removed by :func:`lowerlimb.orientation.estimate_orientation`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from lowerlimb.conventions import FloatArray
from lowerlimb.orientation._filter_inputs import loop_inputs
from lowerlimb.orientation._quaternion_nb import (
    earth_lowpass,
    earth_lowpass_start,
    norm3,
    put_quat,
    qintegrate,
    qnormalize,
    rotate_to_earth,
)
from lowerlimb.orientation.initialisation import InitialState


@dataclass(frozen=True)
class MadgwickParams:
    """Parameters of the gradient-descent filter.

    Defaults: a grid search on the cost of ``benchmarks/tune_orientation.py``
    (BROAD and simulated trials, 9- and 6-axis), checked on the leg pipeline
    (``benchmarks/pipeline_accuracy.py``).

    Attributes:
        beta: Gradient step rate β, rad/s (Madgwick's "gyroscope measurement
            error"); the correction rate of a wrong attitude is at most β.
        acc_lowpass_s: Time constant of the earth-frame accelerometer low-pass
            (an addition to the paper, see the module docstring), s; 0 uses
            each accelerometer sample as it is (the original filter).
    """

    beta: float = 0.007
    acc_lowpass_s: float = 3.0


@njit(cache=True, inline="always")
def objective_gradient(
    w: float,
    x: float,
    y: float,
    z: float,
    dx: float,
    dy: float,
    dz: float,
    sx: float,
    sy: float,
    sz: float,
) -> tuple[float, float, float, float]:
    """``Jᵀ f`` for ``f(q) = R(q)ᵀ d − s`` (Madgwick 2011 eq. 25–26), general reference ``d``.

    ``R(q)ᵀ d`` is written in Madgwick's polynomial form, e.g. its first row
    ``d_x(1 − 2y² − 2z²) + 2d_y(wz + xy) + 2d_z(xz − wy)``; J is its exact
    derivative with respect to ``(w, x, y, z)``.
    """
    f1 = dx * (1.0 - 2.0 * (y * y + z * z)) + 2.0 * dy * (w * z + x * y)
    f1 += 2.0 * dz * (x * z - w * y) - sx
    f2 = 2.0 * dx * (x * y - w * z) + dy * (1.0 - 2.0 * (x * x + z * z))
    f2 += 2.0 * dz * (w * x + y * z) - sy
    f3 = 2.0 * dx * (w * y + x * z) + 2.0 * dy * (y * z - w * x)
    f3 += dz * (1.0 - 2.0 * (x * x + y * y)) - sz
    gw = f1 * (2.0 * dy * z - 2.0 * dz * y)
    gw += f2 * (-2.0 * dx * z + 2.0 * dz * x)
    gw += f3 * (2.0 * dx * y - 2.0 * dy * x)
    gx = f1 * (2.0 * dy * y + 2.0 * dz * z)
    gx += f2 * (2.0 * dx * y - 4.0 * dy * x + 2.0 * dz * w)
    gx += f3 * (2.0 * dx * z - 2.0 * dy * w - 4.0 * dz * x)
    gy = f1 * (-4.0 * dx * y + 2.0 * dy * x - 2.0 * dz * w)
    gy += f2 * (2.0 * dx * x + 2.0 * dz * z)
    gy += f3 * (2.0 * dx * w + 2.0 * dy * z - 4.0 * dz * y)
    gz = f1 * (-4.0 * dx * z + 2.0 * dy * w + 2.0 * dz * x)
    gz += f2 * (-2.0 * dx * w - 4.0 * dy * z + 2.0 * dz * y)
    gz += f3 * (2.0 * dx * x + 2.0 * dy * y)
    return gw, gx, gy, gz


@njit(cache=True)
def _madgwick_loop(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray,
    use_mag: bool,
    dt: float,
    q0: FloatArray,
    lowpass_up: bool,
    beta: float,
    acc_tau: float,
) -> FloatArray:
    n = gyr.shape[0]
    out = np.empty((n, 4))
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    k_lp, lx, ly, lz = earth_lowpass_start(dt, acc_tau, w, x, y, z, acc, lowpass_up)
    for i in range(n):
        # eq. 43, integrated exactly over the sample
        pw, px, py, pz = qintegrate(w, x, y, z, gyr[i, 0], gyr[i, 1], gyr[i, 2], dt)
        dw = 0.0
        dx_ = 0.0
        dy_ = 0.0
        dz_ = 0.0
        ax, ay, az = acc[i, 0], acc[i, 1], acc[i, 2]
        if acc_tau > 0.0:
            lx, ly, lz, ax, ay, az = earth_lowpass(pw, px, py, pz, ax, ay, az, lx, ly, lz, k_lp)
        an = norm3(ax, ay, az)
        sw = 0.0
        sx = 0.0
        sy = 0.0
        sz = 0.0
        if an > 0.0:
            sw, sx, sy, sz = objective_gradient(pw, px, py, pz, 0.0, 0.0, 1.0, ax / an, ay / an, az / an)
            if use_mag:
                mx, my, mz = mag[i, 0], mag[i, 1], mag[i, 2]
                mn = norm3(mx, my, mz)
                if mn > 0.0:
                    mx /= mn
                    my /= mn
                    mz /= mn
                    hx, hy, hz = rotate_to_earth(pw, px, py, pz, mx, my, mz)
                    by = math.sqrt(hx * hx + hy * hy)
                    mw, mxx, myy, mzz = objective_gradient(pw, px, py, pz, 0.0, by, hz, mx, my, mz)
                    sw += mw
                    sx += mxx
                    sy += myy
                    sz += mzz
            sn = math.sqrt(sw * sw + sx * sx + sy * sy + sz * sz)
            if sn > 0.0:
                # eq. 44: normalised gradient step
                dw -= beta * sw / sn
                dx_ -= beta * sx / sn
                dy_ -= beta * sy / sn
                dz_ -= beta * sz / sn
        w, x, y, z = qnormalize(pw + dw * dt, px + dx_ * dt, py + dy_ * dt, pz + dz_ * dt)
        put_quat(out, i, w, x, y, z)
    return out


def madgwick_filter(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray | None,
    *,
    rate_hz: float,
    initial: InitialState,
    params: MadgwickParams | None = None,
) -> FloatArray:
    """Run the gradient-descent filter over a recording (inputs are not validated).

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s².
        mag: (N, 3) magnetic field, sensor frame, any unit, or ``None`` (6-axis).
        rate_hz: Sampling rate, Hz.
        initial: Orientation before the first sample (sensor -> ENU), the gyro
            bias to subtract and the magnetic reference
            (:func:`~lowerlimb.orientation.initialisation.initialise`).
        params: Gain; :class:`MadgwickParams` defaults when ``None``.

    Returns:
        (N, 4) unit quaternions ``w, x, y, z``, sensor -> ENU.
    """
    p = params or MadgwickParams()
    return _madgwick_loop(
        *loop_inputs(gyr, acc, mag, rate_hz, initial),
        p.beta,
        p.acc_lowpass_s,
    )
