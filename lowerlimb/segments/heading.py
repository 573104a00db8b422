"""Consistent headings of adjacent sensors from the kinematic constraints (issue 5, item 3).

A 6-axis filter knows the vertical but not the heading: every sensor's earth
frame is turned about the vertical by its own unknown, slowly drifting angle.
That ruins the out-of-plane joint angles (Hu et al. 2021 report 21–25° ankle
rotation RMSE). The joints tell us the relative heading of adjacent sensors:

* **Spherical joint** (hip, ankle): the joint centre's acceleration is one
  vector, whichever sensor it is computed from (Hu et al. eq. 1–3). In the
  earth frame: ``u = R_p (f_p + ω_p×(ω_p×c_p) + α_p×c_p)`` and the same ``v``
  from the child; gravity enters both equally and is vertical.
* **Hinge** (knee): the knee axis is one direction:
  ``u = R_p j_p``, ``v = R_c j_c``; while the leg is straight the axis is
  horizontal, which is exactly when it fixes the heading best. Being unit vectors,
  their products are scaled by :data:`HINGE_HEADING_WEIGHT` / (1 + (σ_axis / 2°)²) to
  the (m/s²)² of the other terms.

The correction ``δ(t)`` turns the child's earth frame about the vertical so
that the horizontal parts of ``R_z(δ) v`` and ``u`` agree. It is the
kernel-weighted circular mean of the per-sample angle,
``δ(t) = atan2(Σ_k w_k (v_h × u_h)_z, Σ_k w_k v_h·u_h)`` with a Gaussian kernel
of standard deviation ``window_s`` (default 4 s: long enough to average noise,
short enough to follow a heading drift of a few degrees per minute). The
joint accelerations are first low-passed at 4 Hz (zero-phase Butterworth). Each product is
implicitly weighted by ``‖u_h‖‖v_h‖``, so samples without horizontal signal
count for nothing; a small share of the whole-trial mean keeps ``δ`` defined
during long rests. Corrections cascade down the chain: pelvis (kept) →
thigh → shank → foot.

**Magnetometer.** With 9-axis filters each sensor's field, carried into the earth
frame by its (corrected) orientation, is one more pair of vectors: the horizontal
field seen from the parent and from the child should point the same way. Their unit
horizontal parts enter the same kernel sums with the weight ``common_heading_weight``,
sample by sample only as far as the two sensors see one field (:func:`field_agreement`:
the same magnitude within 4 %, the same dip within 2°); elsewhere the term trusts the
filters' headings. On the real walk a shank sensor read the field at another dip
(47° against 71°) and, used unweighted, put the left ankle 24° off; weighted, 4.3°.
This is a direct measurement of the relative heading at each sample, not the filters'
own headings: a filter's magnetic loop is slow (Mahony's ``kp_mag`` 0.05 /s), so its
heading sits ``b / kp_mag`` off for a residual gyro bias ``b`` left after a short still
start (0.2°/s → 4°), differently in every sensor; pulling the correction towards zero
(trusting the filters' headings, as before) put 3.2° into the demo walk's hip rotation,
the fields' own directions 0.8°.

**Range-of-motion prior.** When a spherical joint's centre does not accelerate
horizontally — the ankle of a planted foot in a squat, the hip in a knee lift —
its relative heading is unobservable from inertial data. A second pass
(given the segment frames) then adds a weak "soft hinge" term: the segment z
axes (flexion axes) of the two segments, seen in the earth frame, should agree
horizontally, i.e. ad/abduction and axial rotation stay small. Its weight
(``prior_weight``, (m/s²)²) is far below the acceleration information of
walking, so it decides only where the accelerations say nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy.ndimage import gaussian_filter1d
from scipy.signal import butter, fftconvolve, sosfiltfilt

from ..constraints.angular_acceleration import angular_acceleration
from ..conventions import JOINT_SENSORS, FloatArray, quat_multiply, quat_rotate

if TYPE_CHECKING:
    from ..calibration import ExcitationReport, LegCalibration

#: Joint-centre standard deviation at which a spherical joint's heading term counts half, m.
CENTRE_STD_REF_M = 0.015
#: Least weight of a spherical joint's heading term, even when its centre is undetermined.
#: A wrong centre biases the joint acceleration, but the two segments' common translation
#: (walking's fore-aft and sideways sway) still ties their headings; without a magnetometer
#: nothing else does before the range-of-motion prior, which needs segment frames built
#: with these headings (at weight 0 a two-leg walk with an undetermined hip, seed 205 of the
#: simulator's artefact profile in its lab field, kept a thigh's arbitrary filter heading and
#: its knee axis pointed 153° from the other's). Far below the magnetic heading's weight.
CENTRE_MIN_RELIABILITY = 0.05
#: Weight of the knee's hinge-axis heading term, (m/s²)² per unit axis product. The axes are
#: unit vectors while the spherical joints' terms and the shared magnetic heading weight
#: (:data:`lowerlimb.segments.tracking.MAG_HEADING_WEIGHT`, 10) are in (m/s²)²; at weight 1 the
#: magnetometer overruled the hinge and the filters' relative heading drift (a residual gyro
#: bias, ~4°/min) went into the knee's rotation. At 100 an axis known to ±2° counts five
#: times the magnetic heading and one known to ±6° (the real walk's) about as much. Chosen on
#: the seven-IMU simulator (seeds 201–206: knee rotation 3.0° → 1.2° worst RMSE), checked on
#: the real walk (right knee 4.8° → 4.5°, right ankle 3.3° → 3.7° RMSE; benchmarks/real_gait.py).
HINGE_HEADING_WEIGHT = 100.0
#: Knee-axis standard deviation at which the hinge heading term counts half, deg.
AXIS_STD_REF_DEG = 2.0
#: Share of the whole-trial mean blended into each local (kernel-mean) estimate.
GLOBAL_PRIOR_WEIGHT = 0.1
#: Low-pass cut-off of the joint accelerations before they are compared, Hz:
#: limb motion lives below it, most sensor noise above.
LOWPASS_HZ = 4.0


@dataclass(frozen=True)
class HeadingCorrection:
    """Relative heading corrections applied to the sensors.

    Attributes:
        delta_rad: ``{sensor: (N,)}`` total rotation about the vertical applied
            to each sensor's orientation (pelvis: zeros), rad.
        joint_delta_rad: ``{joint: (N,)}`` the correction found at each joint, rad.
        field_agreement: ``{joint: mean}`` of :func:`field_agreement` over the trial, the
            share of the samples at which the magnetic term read the field seen from both
            sensors (only the joints where the magnetometer was used).
    """

    delta_rad: dict[str, FloatArray]
    joint_delta_rad: dict[str, FloatArray]
    field_agreement: dict[str, float] = field(default_factory=dict)


#: Weight of the soft-hinge range-of-motion prior, (m/s²)² per unit axis product.
PRIOR_WEIGHT = 0.25


#: Spread of the field magnitude between two sensors, as a share of their mean, at which
#: their magnetic heading term counts e^-1/2 (a field that differs is not one field).
FIELD_NORM_SD = 0.04
#: Spread of the field's dip between two sensors at which the term counts e^-1/2, deg.
FIELD_DIP_SD_DEG = 2.0


def field_agreement(m_parent: FloatArray, m_child: FloatArray) -> FloatArray:
    """How far two sensors see one field (N,) in [0, 1], from its magnitude and dip.

    Args:
        m_parent: (N, 3) the field measured by the parent sensor, in the earth frame (its
            orientation applied), any unit.
        m_child: (N, 3) the same for the child sensor.

    Returns:
        ``exp(-½ (Δ|m| / (FIELD_NORM_SD · mean |m|))² - ½ (Δdip / FIELD_DIP_SD_DEG)²)``:
        a sensor near an iron object or the floor's reinforcement sees another magnitude
        and dip, and its horizontal direction is then not the other sensor's north.
    """
    n_p, n_c = np.linalg.norm(m_parent, axis=1), np.linalg.norm(m_child, axis=1)
    mean = np.maximum(0.5 * (n_p + n_c), 1e-12)
    dip_p = np.arctan2(m_parent[:, 2], np.linalg.norm(m_parent[:, :2], axis=1))
    dip_c = np.arctan2(m_child[:, 2], np.linalg.norm(m_child[:, :2], axis=1))
    z = ((n_p - n_c) / (FIELD_NORM_SD * mean)) ** 2 + (np.rad2deg(dip_p - dip_c) / FIELD_DIP_SD_DEG) ** 2
    return np.asarray(np.exp(-0.5 * z))


def _field_sums(
    m_parent: FloatArray, m_child: FloatArray, rate_hz: float, window_s: float
) -> tuple[FloatArray, FloatArray, float]:
    """Kernel sums of the magnetic heading term (module docstring).

    The fields' horizontal directions count where the two sensors see one field
    (:func:`field_agreement`), the filters' own headings elsewhere. The earth-frame
    fields are low-passed first (:data:`LOWPASS_HZ`), so that the agreement measures the
    field, not the magnetometer's white noise. Also returns the mean agreement.
    """
    m_parent, m_child = _lowpass(m_parent, rate_hz), _lowpass(m_child, rate_hz)
    w = field_agreement(m_parent, m_child)
    u, v = _horizontal_unit(m_parent), _horizontal_unit(m_child)
    cross = w * (v[:, 0] * u[:, 1] - v[:, 1] * u[:, 0])
    dot = w * (v[:, 0] * u[:, 0] + v[:, 1] * u[:, 1]) + (1.0 - w)
    S, C = _kernel_sums(cross, dot, rate_hz, window_s)
    return S, C, float(np.mean(w))


def _heading_sums(
    u: FloatArray, v: FloatArray, rate_hz: float, window_s: float
) -> tuple[FloatArray, FloatArray]:
    """Kernel means of the horizontal cross and dot products, blended with their trial means.

    The first and last ``ceil(rate / LOWPASS_HZ)`` samples count for nothing: the joint
    accelerations there are the zero-phase low-pass's edge transient (no data beyond the
    ends), and a trial that ends in a heel strike makes them tens of m/s²; their products,
    squared accelerations, then outweighed the last seconds of walking and turned a thigh's
    heading by 13° over the last 5 s (seven-IMU simulator, seed 206, 6-axis).
    """
    cross = v[:, 0] * u[:, 1] - v[:, 1] * u[:, 0]
    dot = v[:, 0] * u[:, 0] + v[:, 1] * u[:, 1]
    return _kernel_sums(cross, dot, rate_hz, window_s)


def _kernel_sums(
    cross: FloatArray, dot: FloatArray, rate_hz: float, window_s: float
) -> tuple[FloatArray, FloatArray]:
    """Kernel means of per-sample cross and dot products (N,), blended with their trial means.

    The edge samples count for nothing (:func:`_heading_sums`).
    """
    cross, dot = np.array(cross, dtype=float), np.array(dot, dtype=float)
    edge = min(int(np.ceil(rate_hz / LOWPASS_HZ)), cross.size // 4)
    if edge > 0:
        cross[:edge] = cross[-edge:] = 0.0
        dot[:edge] = dot[-edge:] = 0.0
    sigma = max(1.0, window_s * rate_hz)
    S = _gaussian_smooth(cross, sigma) + GLOBAL_PRIOR_WEIGHT * np.mean(cross)
    C = _gaussian_smooth(dot, sigma) + GLOBAL_PRIOR_WEIGHT * np.mean(dot)
    return S, C


def _gaussian_smooth(x: FloatArray, sigma: float) -> FloatArray:
    """``gaussian_filter1d(x, sigma, mode="reflect")`` (same kernel, same edges) through an FFT.

    A 2 s window at 100 Hz is a 1601-tap kernel: direct convolution costs ~1600
    multiply-adds per sample, the FFT a few dozen.
    """
    radius = int(4.0 * sigma + 0.5)  # scipy's truncate=4.0
    if x.size <= 2 * radius:
        return np.asarray(gaussian_filter1d(x, sigma, mode="reflect"))
    t = np.arange(-radius, radius + 1, dtype=float)
    kernel = np.exp(-0.5 * (t / sigma) ** 2)
    kernel /= kernel.sum()
    padded = np.pad(x, radius, mode="symmetric")  # ndimage "reflect" = numpy "symmetric"
    return np.asarray(fftconvolve(padded, kernel, mode="valid"))


def _lowpass(x: FloatArray, rate_hz: float, cutoff_hz: float = LOWPASS_HZ) -> FloatArray:
    """Zero-phase 2nd-order Butterworth low-pass along axis 0 (scipy)."""
    if cutoff_hz >= 0.45 * rate_hz:
        return x
    sos = butter(2, cutoff_hz, fs=rate_hz, output="sos")
    return np.asarray(sosfiltfilt(sos, x, axis=0))


def relative_heading(u: FloatArray, v: FloatArray, rate_hz: float, window_s: float = 2.0) -> FloatArray:
    """Heading angle δ(t) (N,) rad that turns earth vectors ``v`` (N, 3) onto ``u`` (N, 3) about z."""
    S, C = _heading_sums(u, v, rate_hz, window_s)
    return np.asarray(np.arctan2(S, C))


def rotate_about_vertical(quat_wxyz: FloatArray, delta_rad: FloatArray) -> FloatArray:
    """Left-multiply orientations (N, 4) by a rotation of ``delta_rad`` (N,) about the earth z."""
    half = 0.5 * np.asarray(delta_rad)
    qz = np.column_stack([np.cos(half), np.zeros_like(half), np.zeros_like(half), np.sin(half)])
    return quat_multiply(qz, quat_wxyz)


def joint_acceleration_earth(
    quat_wxyz: FloatArray, acc: FloatArray, gyr: FloatArray, center: FloatArray, rate_hz: float
) -> FloatArray:
    """Joint-centre specific force (N, 3) in the earth frame seen from one sensor (Hu eq. 1–3).

    Args:
        quat_wxyz: (N, 4) sensor orientation, sensor → earth.
        acc: (N, 3) specific force, sensor frame, m/s².
        gyr: (N, 3) angular velocity (bias removed), sensor frame, rad/s.
        center: (3,) joint centre in the sensor frame (sensor → centre), m.
        rate_hz: sampling rate, Hz.
    """
    alpha = angular_acceleration(gyr, rate_hz)
    c = np.asarray(center, dtype=float)
    a = acc + np.cross(gyr, np.cross(gyr, c)) + np.cross(alpha, c)
    return _lowpass(quat_rotate(quat_wxyz, a), rate_hz)


def _horizontal_unit(x: FloatArray) -> FloatArray:
    """The horizontal part of earth vectors (N, 3), scaled to unit length (zero where it vanishes)."""
    h = np.array(x, dtype=float)
    h[:, 2] = 0.0
    n = np.linalg.norm(h, axis=1, keepdims=True)
    return np.divide(h, n, out=np.zeros_like(h), where=n > 1e-12)


def _centre_reliability(excitation: ExcitationReport | None) -> float:
    """Weight in (0, 1] of a spherical joint's heading term: 1 / (1 + (σ / σ_ref)²) or more.

    The weight is at least :data:`CENTRE_MIN_RELIABILITY`. ``σ`` is the joint centre's
    standard deviation along its most poorly determined direction
    (:class:`~lowerlimb.calibration.ExcitationReport`); a centre known to
    ±:data:`CENTRE_STD_REF_M` counts half. A wrong centre adds a spurious
    ``α × Δc + ω × (ω × Δc)`` to the joint acceleration of one side only, which turns the
    child's heading; nearly planar walking leaves the hip centre in a sacral sensor
    ±6–8 cm uncertain, and its heading term would then overrule a good magnetometer or
    the range-of-motion prior.
    """
    if excitation is None:
        return 1.0
    if not np.isfinite(excitation.weakest_std):
        return CENTRE_MIN_RELIABILITY
    return max(CENTRE_MIN_RELIABILITY, float(1.0 / (1.0 + (excitation.weakest_std / CENTRE_STD_REF_M) ** 2)))


def _axis_reliability(knee: object) -> float:
    """Weight of the knee's heading term: ``HINGE_HEADING_WEIGHT / (1 + (σ / σ_ref)²)``.

    ``σ`` is the larger of the axis's two reported standard deviations (deg), ``σ_ref``
    :data:`AXIS_STD_REF_DEG`.
    """
    std = np.asarray(getattr(knee, "axis_std_deg", np.zeros(2)), dtype=float)
    sigma = float(np.max(std)) if std.size and np.all(np.isfinite(std)) else 0.0
    return float(HINGE_HEADING_WEIGHT / (1.0 + (sigma / AXIS_STD_REF_DEG) ** 2))


def correct_headings(
    quat_wxyz: dict[str, FloatArray],
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    calibration: LegCalibration,
    rate_hz: float,
    *,
    window_s: float = 4.0,
    R_sensor_segment: dict[str, FloatArray] | None = None,
    prior_weight: float = PRIOR_WEIGHT,
    common_heading_weight: float = 0.0,
    mag: dict[str, FloatArray] | None = None,
) -> tuple[dict[str, FloatArray], HeadingCorrection]:
    """Make the headings of thigh, shank and foot consistent with the pelvis.

    Args:
        quat_wxyz: ``{sensor: (N, 4)}`` filter orientations, sensor → (own) earth frame.
        acc: ``{sensor: (N, 3)}`` specific force, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity with the bias removed, rad/s.
        calibration: the joint calibration (joint centres, knee axes).
        rate_hz: sampling rate, Hz.
        window_s: Gaussian kernel standard deviation, s.
        R_sensor_segment: segment frames in the sensor frames (from a first
            pass); enables the range-of-motion prior at the hip and ankle.
        prior_weight: weight of that prior, (m/s²)².
        common_heading_weight: weight, (m/s²)², of the magnetic heading (9-axis
            filters referenced to the field): with ``mag``, the term of the horizontal
            fields seen from both sensors (module docstring); without, the belief that
            the input orientations already share one heading, which pulls every
            correction towards zero.
        mag: ``{sensor: (N, 3)}`` magnetic field in the sensor frames (any unit: only its
            horizontal direction counts), or ``None``.

    Returns:
        The corrected orientations and the corrections applied.
    """
    joints = calibration.joints
    out = {"pelvis": np.asarray(quat_wxyz["pelvis"], dtype=float)}
    total = {"pelvis": np.zeros(len(out["pelvis"]))}
    per_joint: dict[str, FloatArray] = {}
    agreement: dict[str, float] = {}
    for joint, parent, child in (
        ("hip", "pelvis", "thigh"),
        ("knee", "thigh", "shank"),
        ("ankle", "shank", "foot"),
    ):
        j = joints[joint]
        hinge = JOINT_SENSORS[joint][2] == "hinge"
        q_child = np.asarray(quat_wxyz[child], dtype=float)
        if hinge:
            knee = calibration.knee
            u = quat_rotate(out[parent], knee.axis_in_parent_sensor)
            v = quat_rotate(q_child, knee.axis_in_child_sensor)
        else:
            u = joint_acceleration_earth(
                out[parent], acc[parent], gyr[parent], j.center_in_parent_sensor, rate_hz
            )
            v = joint_acceleration_earth(q_child, acc[child], gyr[child], j.center_in_child_sensor, rate_hz)
        S, C = _heading_sums(u, v, rate_hz, window_s)
        r = (
            _axis_reliability(calibration.knee)
            if hinge
            else _centre_reliability(getattr(j, "excitation", None))
        )
        S, C = r * S, r * C
        if R_sensor_segment is not None and not hinge:
            e_z = np.array([0.0, 0.0, 1.0])
            up = quat_rotate(out[parent], R_sensor_segment[parent] @ e_z)
            vp = quat_rotate(q_child, R_sensor_segment[child] @ e_z)
            Sp, Cp = _heading_sums(up, vp, rate_hz, window_s)
            S, C = S + prior_weight * Sp, C + prior_weight * Cp
        if common_heading_weight and mag is not None:
            Sm, Cm, agreement[joint] = _field_sums(
                quat_rotate(out[parent], mag[parent]), quat_rotate(q_child, mag[child]), rate_hz, window_s
            )
            S, C = S + common_heading_weight * Sm, C + common_heading_weight * Cm
        elif common_heading_weight:
            C = C + common_heading_weight
        delta = np.arctan2(S, C)
        per_joint[joint] = delta
        out[child] = rotate_about_vertical(q_child, delta)
        total[child] = delta
    return out, HeadingCorrection(total, per_joint, agreement)
