"""PI complementary filter (Mahony) — Hu et al. 2021 §4.3, eq. 43–50, plus a magnetometer term.

The estimated "up" direction in the sensor frame (eq. 45–46) is compared with
the measured one by a cross product (eq. 47, corrected per docs/methods.md:
``ζ = a × g_est``); a proportional–integral correction of the gyro rate
(eq. 48–49) pulls the estimate towards the accelerometer and learns the gyro
bias; the corrected rate is integrated, ``q̇ = ½ q ⊗ (0, ω)``, and the
quaternion is renormalised (eq. 50).

Choices the paper leaves open (documented, chosen by
``benchmarks/tune_orientation.py``):

* **Accelerometer low-pass in the earth frame.** Before eq. 47 the specific
  force is rotated into the earth frame with the current estimate, low-pass
  filtered there (first order, time constant ``acc_lowpass_s``) and rotated
  back. Motion accelerations average out in a near-inertial frame (their
  integral is a velocity change), gravity does not; this is the
  accelerometer update of VQF (Laidig & Seel 2023), which filters in an
  almost-inertial frame. ``acc_lowpass_s = 0`` gives the plain filter of
  eq. 47.
* **Magnetometer (9-axis).** Mahony's magnetometer error, but only its
  component about the estimated vertical: the sine of the heading error of
  the measured horizontal field (north = ENU +y), with its own gain
  ``kp_mag``. A disturbed field therefore never tilts the estimate and the
  dip need not be known. Samples whose norm or dip departs from the values at
  the start (``mag_norm_tol``, ``mag_dip_tol_rad``; from the
  :class:`~lowerlimb.orientation.initialisation.InitialState`) are ignored.
* The integral term (bias) integrates the accelerometer error only; the
  heading error is not integrated, so magnetic disturbances cannot corrupt
  the bias estimate.
* Eq. 50 is integrated exactly for a rate constant over the sample,
  ``q ⊗ exp(½ ω Δt)``; the first-order form of the paper differs by
  O(‖ω‖³Δt³) after renormalisation. Gyro sample k is the mean rate over
  (t_{k−1}, t_k] (as in VQF). Each sample first integrates the gyro (with the
  integral term), then computes the errors with that prediction and applies
  the proportional correction ``exp(½ λp ζ Δt)``: the accelerometer sample
  of time t_k is compared with the orientation of time t_k, not t_{k−1}
  (2° apart at 8 rad/s and 200 Hz). The integral term enters with the next
  gyro sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from lowerlimb.conventions import FloatArray
from lowerlimb.orientation._filter_inputs import loop_inputs, magnetic_reference
from lowerlimb.orientation._magnetic_nb import mag_heading_error
from lowerlimb.orientation._quaternion_nb import (
    cross,
    earth_lowpass,
    earth_lowpass_start,
    norm3,
    put_quat,
    qintegrate,
    up_in_sensor,
)
from lowerlimb.orientation.initialisation import InitialState


@dataclass(frozen=True)
class MahonyParams:
    """Gains of the PI filter; defaults chosen by ``benchmarks/tune_orientation.py``.

    The paper writes ``λp = 2Δt`` and ``λi = 0.1Δt`` and calls Δt the sampling
    *frequency*; here both are rate-independent gains (docs/methods.md).

    Attributes:
        kp: Proportional gain λp of the accelerometer error, rad/s per unit
            error (eq. 49); the tilt correction time constant is ``1/kp`` s.
        ki: Integral gain λi, rad/s² per unit error (eq. 48), how fast the
            gyro bias estimate follows the error. The paper's factor ½ in
            eq. 48 is folded into ``ki``.
        kp_mag: Proportional gain of the heading error from the magnetometer,
            rad/s per unit error (9-axis only).
        acc_lowpass_s: Time constant of the earth-frame accelerometer low-pass,
            s (0 disables it).
        mag_norm_tol: Magnetometer samples whose norm differs from the norm at
            the start by more than this fraction are ignored.
        mag_dip_tol_rad: Magnetometer samples whose dip differs from the dip
            at the start by more than this (rad) are ignored.
        bias_clip_rad_s: Each component of the integral (bias) term is clipped
            to ± this, rad/s.
    """

    kp: float = 0.4
    ki: float = 0.003
    kp_mag: float = 0.05
    acc_lowpass_s: float = 2.0
    mag_norm_tol: float = 0.1
    mag_dip_tol_rad: float = math.radians(10.0)
    bias_clip_rad_s: float = 0.05


@njit(cache=True)
def _mahony_loop(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray,
    use_mag: bool,
    dt: float,
    q0: FloatArray,
    lowpass_up: bool,
    mag_norm_ref: float,
    mag_dip_ref: float,
    kp: float,
    ki: float,
    kp_mag: float,
    acc_tau: float,
    mag_norm_tol: float,
    mag_dip_tol: float,
    bias_clip: float,
) -> FloatArray:
    n = gyr.shape[0]
    out = np.empty((n, 4))
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    ix = 0.0
    iy = 0.0
    iz = 0.0
    k_lp, lx, ly, lz = earth_lowpass_start(dt, acc_tau, w, x, y, z, acc, lowpass_up)
    for i in range(n):
        # eq. 49-50, gyro part: integrate the rate corrected by the integral (bias) term
        w, x, y, z = qintegrate(
            w, x, y, z, gyr[i, 0] + ix, gyr[i, 1] + iy, gyr[i, 2] + iz, dt
        )  # fmt: skip
        ex = 0.0
        ey = 0.0
        ez = 0.0
        vx, vy, vz = up_in_sensor(w, x, y, z)  # eq. 45-46
        ax, ay, az = acc[i, 0], acc[i, 1], acc[i, 2]
        if acc_tau > 0.0:
            lx, ly, lz, ax, ay, az = earth_lowpass(w, x, y, z, ax, ay, az, lx, ly, lz, k_lp)
        an = norm3(ax, ay, az)
        if an > 0.0:
            ex, ey, ez = cross(ax / an, ay / an, az / an, vx, vy, vz)  # eq. 47 (corrected)
        # eq. 48: the integral of the error is the negative gyro bias estimate
        ix = min(max(ix + ki * ex * dt, -bias_clip), bias_clip)
        iy = min(max(iy + ki * ey * dt, -bias_clip), bias_clip)
        iz = min(max(iz + ki * ez * dt, -bias_clip), bias_clip)
        # eq. 49, proportional part
        cx = kp * ex
        cy = kp * ey
        cz = kp * ez
        if use_mag:
            ok, s_h = mag_heading_error(
                w, x, y, z, mag[i, 0], mag[i, 1], mag[i, 2],
                mag_norm_ref, mag_dip_ref, mag_norm_tol, mag_dip_tol,
            )  # fmt: skip
            if ok:
                cx += kp_mag * s_h * vx
                cy += kp_mag * s_h * vy
                cz += kp_mag * s_h * vz
        # eq. 50, correction part; renormalised
        w, x, y, z = qintegrate(w, x, y, z, cx, cy, cz, dt)
        put_quat(out, i, w, x, y, z)
    return out


def mahony_filter(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray | None,
    *,
    rate_hz: float,
    initial: InitialState,
    params: MahonyParams | None = None,
) -> FloatArray:
    """Run the PI complementary filter over a recording (inputs are not validated).

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s².
        mag: (N, 3) magnetic field, sensor frame, any unit, or ``None`` (6-axis).
        rate_hz: Sampling rate, Hz.
        initial: Orientation before the first sample (sensor -> ENU), the gyro
            bias to subtract and the magnetic reference
            (:func:`~lowerlimb.orientation.initialisation.initialise`).
        params: Gains; :class:`MahonyParams` defaults when ``None``.

    Returns:
        (N, 4) unit quaternions ``w, x, y, z``, sensor -> ENU, one per sample
        (after that sample's update).
    """
    p = params or MahonyParams()
    return _mahony_loop(
        *loop_inputs(gyr, acc, mag, rate_hz, initial),
        *magnetic_reference(initial),
        p.kp,
        p.ki,
        p.kp_mag,
        p.acc_lowpass_s,
        p.mag_norm_tol,
        p.mag_dip_tol_rad,
        p.bias_clip_rad_s,
    )
