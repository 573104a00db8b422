"""FTECF: fuzzy-tuned ESOQ-2 complementary filter (Zhu & Xu, Sensors 2018), 6- and 9-axis.

Per sample:

1. Gyro quaternion (eq. 1–4): ``q_gyr = q̂_{t−Δt} ⊗ exp(½ ω Δt)`` (the exact
   solution of eq. 1 for a rate constant over the sample; eq. 4 is its first
   order), normalised so that eq. 20 holds.
2. Accelerometer compensation (eq. 18–20): the specific force ``f`` (with
   the addition below: its earth-frame low-pass) is used as the gravity
   direction only when ``|‖f‖ − ‖g‖| ≤ δa`` and ``‖ω‖ ≤ δw``; otherwise the
   gravity direction predicted by ``q_gyr``, ``C_E^B e_z``. Choice: ``‖g‖``
   is the accelerometer norm measured during the still start (an
   accelerometer's own scale), not a fixed 9.78 m/s².
3. Reference quaternion by ESOQ-2 (eq. 13–17) from two vector pairs:
   gravity ``(f_B, e_z)`` and, 9-axis, the magnetic field ``(m/‖m‖, r_m)``
   with ``r_m = (0, cos δ, −sin δ)`` in ENU (eq. 17's ``m`` with declination
   ε replaced by the dip δ measured at the start, pointing down in the
   northern hemisphere), weights ``1 − mag_weight`` and ``mag_weight``.
   Magnetometer samples whose norm or dip departs from the start values are
   replaced, like eq. 18 does for the accelerometer, by the field predicted
   by ``q_gyr``. 6-axis (choice): the second pair is the gyro's predicted
   north, ``C_E^B e_y`` made orthogonal to ``f_B``, against ``e_y`` — the
   reference then corrects the inclination only and keeps the gyro heading.
4. Fusion factor (eq. 21, §2.6): ``e1 = ξ / (ξ + ‖q̇_gyr‖)``,
   ``‖q̇_gyr‖ = ½‖ω‖``, and the fuzzy gain ``K`` of
   :func:`~lowerlimb.orientation.fuzzy_fusion.fuzzy_gain`;
   ``μ = KΔt / (1 + KΔt)`` (eq. 10–11).
5. Blend (eq. 9–12): ``q_m`` is put on the hemisphere of ``q_gyr``,
   ``q̂ = (1 − μ) q_gyr + μ q_m``, then normalised.

No gyro-bias estimation (the paper has none); the bias measured during the
still start is subtracted.

Addition to the paper (parameter ``acc_lowpass_s``, on by default):

* **Accelerometer low-pass in the earth frame**, as in
  :mod:`~lowerlimb.orientation.mahony` and VQF (Laidig & Seel 2023). Before
  step 2 the specific force is rotated into the earth frame with ``q_gyr``,
  low-pass filtered there (first order, time constant ``acc_lowpass_s``) and
  rotated back; this vector replaces the raw sample in eq. 18 and in the
  gravity pair of ESOQ-2. A limb's linear accelerations average out in the
  earth frame (their integral is a velocity change) while gravity does not;
  eq. 18's norm test alone cannot reject them, since the shank and foot of a
  walking leg accelerate by several g while their rotation rate and the
  accelerometer norm often look plausible. ESOQ-2, the fuzzy gain and the
  blend are unchanged. ``acc_lowpass_s = 0`` gives the paper's filter.
  With the low-pass the defaults were re-tuned (larger δw, since the
  low-passed vector is usable during fast turns; ``k_a`` 0.3 1/s; magnetic
  weight 0.1). The effect is measured in ``benchmarks/results/orientation.md``
  and ``benchmarks/results/pipeline_accuracy.md`` (``pipeline_accuracy.py --filters ftecf``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from lowerlimb.conventions import FloatArray
from lowerlimb.orientation._filter_inputs import loop_inputs, magnetic_reference
from lowerlimb.orientation._quaternion_nb import (
    earth_lowpass,
    earth_lowpass_start,
    norm3,
    put_quat,
    qintegrate,
    qnormalize,
)
from lowerlimb.orientation._wahba_pairs_nb import hemisphere_sign, measure_pairs, reference_pairs
from lowerlimb.orientation.esoq2 import esoq2_kernel
from lowerlimb.orientation.fuzzy_fusion import fuzzy_gain
from lowerlimb.orientation.initialisation import InitialState


@dataclass(frozen=True)
class FtecfParams:
    """Parameters of the FTECF.

    Defaults: a coordinate and grid search on the cost of
    ``benchmarks/tune_orientation.py`` (BROAD and simulated trials, 9- and
    6-axis), checked on the leg pipeline (``benchmarks/pipeline_accuracy.py``).

    Attributes:
        xi: ξ of eq. 21, 1/s (paper: 0.0006325).
        e1_a: Fuzzy input breakpoint: "e1 small" starts to fall here.
        e1_b: Fuzzy input breakpoint: "e1 large" is 1 from here.
        gain_a_per_s: Output breakpoint ``k_a`` (1/s); the gain in fast motion
            is ``k_a / 2``.
        gain_max_per_s: Output universe end ``k_max`` (1/s), the gain at rest.
        acc_tol_mps2: δa of eq. 18, m/s² (paper: 0.1), applied to the
            low-passed specific force when ``acc_lowpass_s > 0``.
        gyr_tol_rad_s: δw of eq. 18, rad/s (paper: 10 °/s).
        mag_weight: Weight α of the magnetic pair in eq. 13 (the gravity pair
            has ``1 − α``).
        mag_norm_tol: Magnetometer samples whose norm differs from the start
            by more than this fraction are replaced by the prediction.
        mag_dip_tol_rad: Same for the dip angle, rad.
        acc_lowpass_s: Time constant of the earth-frame accelerometer low-pass
            (an addition to the paper, see the module docstring), s; 0 uses
            each accelerometer sample as it is (the paper's filter).
    """

    xi: float = 0.0006325
    e1_a: float = 0.002
    e1_b: float = 0.2
    gain_a_per_s: float = 0.3
    gain_max_per_s: float = 0.5
    acc_tol_mps2: float = 0.5
    gyr_tol_rad_s: float = 5.0
    mag_weight: float = 0.1
    mag_norm_tol: float = 0.1
    mag_dip_tol_rad: float = math.radians(10.0)
    acc_lowpass_s: float = 3.0


@njit(cache=True)
def _ftecf_loop(
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
    xi: float,
    e_a: float,
    e_b: float,
    k_a: float,
    k_max: float,
    acc_tol: float,
    gyr_tol: float,
    mag_weight: float,
    mag_norm_tol: float,
    mag_dip_tol: float,
    acc_tau: float,
) -> FloatArray:
    n = gyr.shape[0]
    out = np.empty((n, 4))
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    b, r, wts = reference_pairs(use_mag, mag_dip_ref, mag_weight)
    k_lp, lx, ly, lz = earth_lowpass_start(dt, acc_tau, w, x, y, z, acc, lowpass_up)
    # the accelerometer samples ESOQ-2 sees: low-passed in the earth frame, or as measured
    acc_in = acc.copy() if acc_tau > 0.0 else acc
    for i in range(n):
        gx, gy, gz = gyr[i, 0], gyr[i, 1], gyr[i, 2]
        wn = norm3(gx, gy, gz)
        # 1. gyro quaternion (eq. 1-4)
        gw_, gx_, gy_, gz_ = qintegrate(w, x, y, z, gx, gy, gz, dt)
        if acc_tau > 0.0:
            # addition: earth-frame low-pass of the specific force (module docstring)
            lx, ly, lz, fx, fy, fz = earth_lowpass(
                gw_, gx_, gy_, gz_, acc[i, 0], acc[i, 1], acc[i, 2], lx, ly, lz, k_lp
            )  # fmt: skip
            acc_in[i, 0] = fx
            acc_in[i, 1] = fy
            acc_in[i, 2] = fz
        # 2.-3. accelerometer compensation (eq. 18-20), second vector pair and
        # ESOQ-2 reference quaternion (eq. 13-17)
        measure_pairs(
            b, r, gw_, gx_, gy_, gz_, acc_in, mag, i, use_mag, wn,
            g_ref, acc_tol, gyr_tol, mag_norm_ref, mag_dip_ref, mag_norm_tol, mag_dip_tol,
        )  # fmt: skip
        qm = esoq2_kernel(b, r, wts)
        # 4. fusion factor (eq. 21, fuzzy rules; eq. 11)
        e1 = xi / (xi + 0.5 * wn)
        k = fuzzy_gain(e1, e_a, e_b, k_a, k_max)
        mu = k * dt / (1.0 + k * dt)
        # 5. blend on the same hemisphere (eq. 9-11) and normalise (eq. 12)
        s = hemisphere_sign(qm, gw_, gx_, gy_, gz_)
        w, x, y, z = qnormalize(
            (1.0 - mu) * gw_ + mu * s * qm[0],
            (1.0 - mu) * gx_ + mu * s * qm[1],
            (1.0 - mu) * gy_ + mu * s * qm[2],
            (1.0 - mu) * gz_ + mu * s * qm[3],
        )
        put_quat(out, i, w, x, y, z)
    return out


def ftecf_filter(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray | None,
    *,
    rate_hz: float,
    initial: InitialState,
    params: FtecfParams | None = None,
) -> FloatArray:
    """Run the FTECF over a recording (inputs are not validated).

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s².
        mag: (N, 3) magnetic field, sensor frame, any unit, or ``None`` (6-axis).
        rate_hz: Sampling rate, Hz.
        initial: Orientation before the first sample (sensor -> ENU), gyro
            bias, gravity norm and magnetic reference
            (:func:`~lowerlimb.orientation.initialisation.initialise`).
        params: :class:`FtecfParams` (defaults when ``None``).

    Returns:
        (N, 4) unit quaternions ``w, x, y, z``, sensor -> ENU.
    """
    p = params or FtecfParams()
    return _ftecf_loop(
        *loop_inputs(gyr, acc, mag, rate_hz, initial),
        initial.acc_norm_mps2,
        *magnetic_reference(initial),
        p.xi,
        p.e1_a,
        p.e1_b,
        p.gain_a_per_s,
        p.gain_max_per_s,
        p.acc_tol_mps2,
        p.gyr_tol_rad_s,
        p.mag_weight,
        p.mag_norm_tol,
        p.mag_dip_tol_rad,
        p.acc_lowpass_s,
    )
