"""QUEST + Kalman filter after Yun & Bachmann (IEEE T-RO 2006), 6- and 9-axis.

State ``x = [ω; q]`` (7): the angular rate (sensor frame, rad/s) and the
orientation quaternion (``w, x, y, z``, sensor -> ENU). Process model:

* ``ω`` is a first-order Gauss–Markov process with time constant ``τ``:
  ``ω_{k+1} = e^{−Δt/τ} ω_k + w``, ``Var w = D (1 − e^{−2Δt/τ})``;
* ``q_{k+1} = q_k ⊗ exp(½ ω_{k+1} Δt)``, linearised for the covariance as
  ``∂q_{k+1}/∂q = I + ½Δt Ω(ω)``, ``∂q_{k+1}/∂ω_k = ½Δt φ Ξ(q_k)``
  (``q ⊗ (0, ω) = Ω(ω) q = Ξ(q) ω``, ``φ = e^{−Δt/τ}``), plus a small
  quaternion process noise. Choice: the quaternion advances with the *new*
  rate ω_{k+1} (its process noise therefore enters ``q`` too, ``Q = G Q_ω Gᵀ``
  with ``G = [I; ½Δt Ξ(q)]``), so the gyro measurement of sample k+1 moves
  ``q_{k+1}`` through the cross-covariance. Driving ``q`` with ω_k instead
  would lag the gyro by one sample (2° at 8 rad/s and 200 Hz). Gyro sample
  k is taken as the mean rate over (t_{k−1}, t_k], as in the other filters.

Measurement ``z = [ω_gyro; q_QUEST]`` is linear in the state (``H = I₇``,
Yun & Bachmann's key simplification): QUEST (:mod:`~lowerlimb.orientation.quest`)
turns the accelerometer and magnetometer into a quaternion before the filter.
The 7 measurements are processed one by one (exact for the diagonal noise
covariance), ``q_QUEST`` is first put on the hemisphere of the prediction,
and the quaternion is renormalised after each update.

QUEST inputs (choices, as for the FTECF): the accelerometer compensation of
Zhu & Xu 2018 eq. 18 (the FTECF paper applied it to Yun's method too), the
magnetometer with the dip measured at the start and disturbance rejection,
and, 6-axis, the predicted north made orthogonal to gravity, so that the
measurement carries the inclination only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from lowerlimb.conventions import FloatArray
from lowerlimb.orientation._filter_inputs import loop_inputs, magnetic_reference
from lowerlimb.orientation._quaternion_nb import norm3, put_quat, qintegrate, qnormalize
from lowerlimb.orientation._wahba_pairs_nb import hemisphere_sign, measure_pairs, reference_pairs
from lowerlimb.orientation.initialisation import InitialState
from lowerlimb.orientation.quest import quest_kernel


@dataclass(frozen=True)
class QuestKfParams:
    """Noise model of the QUEST Kalman filter; defaults chosen by ``benchmarks/tune_orientation.py``.

    Attributes:
        tau_s: Time constant τ of the angular-rate Gauss–Markov model, s.
        rate_var: Stationary variance D of the angular rate, (rad/s)².
        quat_process_std: Standard deviation of the quaternion process noise
            per sample and per √s, 1/√s (scaled by √Δt).
        gyr_std_rad_s: Gyro measurement noise, rad/s.
        quest_std: Standard deviation of each component of the QUEST
            quaternion measurement.
        acc_tol_mps2: δa of the accelerometer compensation, m/s².
        gyr_tol_rad_s: δw of the accelerometer compensation, rad/s.
        mag_weight: QUEST weight of the magnetic pair (gravity: ``1 − α``).
        mag_norm_tol: Magnetometer samples whose norm differs from the start
            by more than this fraction are replaced by the prediction.
        mag_dip_tol_rad: Same for the dip angle, rad.
    """

    tau_s: float = 0.5
    rate_var: float = 100.0
    quat_process_std: float = 0.0003
    gyr_std_rad_s: float = 0.01
    quest_std: float = 0.1
    acc_tol_mps2: float = 1.0
    gyr_tol_rad_s: float = 2.0
    mag_weight: float = 0.5
    mag_norm_tol: float = 0.1
    mag_dip_tol_rad: float = math.radians(10.0)


@njit(cache=True)
def _quest_kf_loop(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray,
    use_mag: bool,
    dt: float,
    q0: FloatArray,
    lowpass_up: bool,
    g_ref: float,
    mag_norm_ref: float,
    mag_dip_ref: float,
    tau: float,
    rate_var: float,
    q_proc_std: float,
    gyr_std: float,
    quest_std: float,
    acc_tol: float,
    gyr_tol: float,
    mag_weight: float,
    mag_norm_tol: float,
    mag_dip_tol: float,
) -> FloatArray:
    n = gyr.shape[0]
    out = np.empty((n, 4))
    xs = np.zeros(7)
    xs[3] = q0[0]
    xs[4] = q0[1]
    xs[5] = q0[2]
    xs[6] = q0[3]
    if n > 0:
        xs[0] = gyr[0, 0]
        xs[1] = gyr[0, 1]
        xs[2] = gyr[0, 2]
    P = np.zeros((7, 7))
    for j in range(3):
        P[j, j] = gyr_std * gyr_std
    for j in range(3, 7):
        P[j, j] = 1e-4
    F = np.zeros((7, 7))
    FP = np.empty((7, 7))
    z = np.empty(7)
    kg = np.empty(7)
    prow = np.empty(7)
    Rm = np.empty(7)
    for j in range(3):
        Rm[j] = gyr_std * gyr_std
    for j in range(3, 7):
        Rm[j] = quest_std * quest_std
    phi = math.exp(-dt / tau)
    q_rate = rate_var * (1.0 - phi * phi)
    q_quat = q_proc_std * q_proc_std * dt
    b, r, wts = reference_pairs(use_mag, mag_dip_ref, mag_weight)
    for i in range(n):
        # ---- prediction
        wx, wy, wz = xs[0], xs[1], xs[2]
        qw, qx, qy, qz = xs[3], xs[4], xs[5], xs[6]
        h = 0.5 * dt
        for a in range(7):
            for c in range(7):
                F[a, c] = 0.0
        F[0, 0] = phi
        F[1, 1] = phi
        F[2, 2] = phi
        # q_k = q_{k-1} ⊗ exp(½ ω_k Δt) with ω_k = φ ω_{k-1} + noise
        wx *= phi
        wy *= phi
        wz *= phi
        # dq/dq = I + h Omega(w), q ⊗ (0, w) = Omega(w) q
        F[3, 3] = 1.0
        F[3, 4] = -h * wx
        F[3, 5] = -h * wy
        F[3, 6] = -h * wz
        F[4, 3] = h * wx
        F[4, 4] = 1.0
        F[4, 5] = h * wz
        F[4, 6] = -h * wy
        F[5, 3] = h * wy
        F[5, 4] = -h * wz
        F[5, 5] = 1.0
        F[5, 6] = h * wx
        F[6, 3] = h * wz
        F[6, 4] = h * wy
        F[6, 5] = -h * wx
        F[6, 6] = 1.0
        # dq_k/dω_{k-1} = φ h Xi(q), q ⊗ (0, w) = Xi(q) w
        hp = h * phi
        F[3, 0] = -hp * qx
        F[3, 1] = -hp * qy
        F[3, 2] = -hp * qz
        F[4, 0] = hp * qw
        F[4, 1] = -hp * qz
        F[4, 2] = hp * qy
        F[5, 0] = hp * qz
        F[5, 1] = hp * qw
        F[5, 2] = -hp * qx
        F[6, 0] = -hp * qy
        F[6, 1] = hp * qx
        F[6, 2] = hp * qw
        pw, px, py, pz = qintegrate(qw, qx, qy, qz, wx, wy, wz, dt)
        xs[0] = wx
        xs[1] = wy
        xs[2] = wz
        xs[3] = pw
        xs[4] = px
        xs[5] = py
        xs[6] = pz
        for a in range(7):
            for c in range(7):
                s = 0.0
                for k in range(7):
                    s += F[a, k] * P[k, c]
                FP[a, c] = s
        for a in range(7):
            for c in range(a, 7):
                s = 0.0
                for k in range(7):
                    s += FP[a, k] * F[c, k]
                P[a, c] = s
                P[c, a] = s
        # Q = G q_rate G^T + q_quat I_q with G = [I3; h Xi(q)] (the rate noise enters q too)
        for a in range(3):
            P[a, a] += q_rate
            for c in range(3, 7):
                v = q_rate * F[c, a] / phi
                P[c, a] += v
                P[a, c] += v
        for a in range(3, 7):
            for c in range(3, 7):
                s = 0.0
                for k in range(3):
                    s += F[a, k] * F[c, k]
                P[a, c] += q_rate * s / (phi * phi)
            P[a, a] += q_quat
        # ---- QUEST measurement
        gx, gy, gz = gyr[i, 0], gyr[i, 1], gyr[i, 2]
        measure_pairs(
            b, r, pw, px, py, pz, acc, mag, i, use_mag, norm3(gx, gy, gz),
            g_ref, acc_tol, gyr_tol, mag_norm_ref, mag_dip_ref, mag_norm_tol, mag_dip_tol,
        )  # fmt: skip
        qm = quest_kernel(b, r, wts)
        sgn = hemisphere_sign(qm, pw, px, py, pz)
        z[0] = gx
        z[1] = gy
        z[2] = gz
        z[3] = sgn * qm[0]
        z[4] = sgn * qm[1]
        z[5] = sgn * qm[2]
        z[6] = sgn * qm[3]
        # ---- sequential scalar updates, H = I
        for j in range(7):
            s_inv = 1.0 / (P[j, j] + Rm[j])
            innov = z[j] - xs[j]
            for a in range(7):
                prow[a] = P[j, a]
                kg[a] = P[a, j] * s_inv  # Kalman gain
            for a in range(7):
                xs[a] += kg[a] * innov
                for c in range(7):
                    P[a, c] -= kg[a] * prow[c]
        qw, qx, qy, qz = qnormalize(xs[3], xs[4], xs[5], xs[6])
        xs[3] = qw
        xs[4] = qx
        xs[5] = qy
        xs[6] = qz
        put_quat(out, i, qw, qx, qy, qz)
    return out


def quest_kf_filter(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray | None,
    *,
    rate_hz: float,
    initial: InitialState,
    params: QuestKfParams | None = None,
) -> FloatArray:
    """Run the QUEST Kalman filter over a recording (inputs are not validated).

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s².
        mag: (N, 3) magnetic field, sensor frame, any unit, or ``None`` (6-axis).
        rate_hz: Sampling rate, Hz.
        initial: Orientation before the first sample (sensor -> ENU), gyro
            bias, gravity norm and magnetic reference
            (:func:`~lowerlimb.orientation.initialisation.initialise`).
        params: :class:`QuestKfParams` (defaults when ``None``).

    Returns:
        (N, 4) unit quaternions ``w, x, y, z``, sensor -> ENU.
    """
    p = params or QuestKfParams()
    return _quest_kf_loop(
        *loop_inputs(gyr, acc, mag, rate_hz, initial),
        initial.acc_norm_mps2,
        *magnetic_reference(initial),
        p.tau_s,
        p.rate_var,
        p.quat_process_std,
        p.gyr_std_rad_s,
        p.quest_std,
        p.acc_tol_mps2,
        p.gyr_tol_rad_s,
        p.mag_weight,
        p.mag_norm_tol,
        p.mag_dip_tol_rad,
    )
