"""Non-rigid sensor motion on its segment: heel-strike impact mode, wobbling mass, skin sliding.

Computes, for each sensor, the displacement ``δ(t)`` from its nominal place
and the rotation ``θ(t)`` of the sensor relative to the bone, both in the
segment frame, with their first and second time derivatives, so that the
simulator can compute the accelerometer and gyro exactly from the non-rigid
motion (:mod:`~lowerlimb.simulation.artefacts` describes the model).

The mass–spring–damper modes are integrated exactly for an input that is
linear between samples (first-order hold, :func:`scipy.signal.cont2discrete`
with ``method="foh"``); their acceleration then follows from the equation of
motion ``ẍ = u − ω² x − 2 ζ ω ẋ`` at each sample, so position, velocity and
acceleration are mutually consistent at any rate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import cont2discrete, lfilter, ss2tf

from ..conventions import SENSORS, FloatArray
from ..errors import InputError
from .artefacts import Artefacts

#: Joint angles (angles.csv index) that deform the tissue under each sensor.
SKIN_DRIVERS: dict[str, tuple[int, ...]] = {
    "pelvis": (0,),
    "thigh": (0, 3),
    "shank": (3, 6),
    "foot": (6,),
}
#: Each joint's flexion angle (angles.csv index): the drivers of the skin twist
#: (:attr:`~lowerlimb.simulation.artefacts.Artefacts.skin_twist_driver`).
FLEXION_INDEX: dict[str, int] = {"hip": 0, "knee": 3, "ankle": 6}


def internal_twist_sign(side: str) -> float:
    """+1 on the right leg, −1 on the left: an internal rotation about the segment's +y axis.

    The segment frames of both legs are ISB right-leg frames (x anterior, y up, z right), so
    an internal rotation (the front turning medially) is a positive rotation about y on the
    right leg and a negative one on the left.
    """
    return 1.0 if side == "right" else -1.0


def _twist_index(params: Artefacts, sensor: str) -> int:
    driver = params.skin_twist_driver[sensor]
    if driver not in FLEXION_INDEX:
        raise InputError(
            f"Artefacts.skin_twist_driver[{sensor!r}] is {driver!r}: use one of {', '.join(FLEXION_INDEX)}"
        )
    return FLEXION_INDEX[driver]


@dataclass
class TissueMotion:
    """Non-rigid motion of one sensor relative to its bone, segment frame (N samples).

    Attributes:
        d, d_v, d_a: (N, 3) displacement (m), velocity (m/s), acceleration (m/s²).
        th, th_v, th_a: (N, 3) rotation vector (rad) and its derivatives (rad/s, rad/s²).
    """

    d: FloatArray
    d_v: FloatArray
    d_a: FloatArray
    th: FloatArray
    th_v: FloatArray
    th_a: FloatArray


def contact_times(t: FloatArray, gait_phase: FloatArray, phase_at_contact: float = 0.0) -> FloatArray:
    """Times (K,) at which the unit gait phase passes ``phase_at_contact`` (linear interpolation), s."""
    u = np.unwrap(2 * np.pi * (gait_phase - phase_at_contact)) / (2 * np.pi)
    k = np.nonzero(np.floor(u[1:]) > np.floor(u[:-1]))[0]
    target = np.floor(u[k + 1])
    frac = (target - u[k]) / (u[k + 1] - u[k])
    return np.asarray(t[k] + frac * (t[k + 1] - t[k]))


def impact_force(t: FloatArray, times_s: FloatArray, peaks: FloatArray, pulse_s: float) -> FloatArray:
    """Sum of Hann pulses (N,) of length ``pulse_s`` starting at ``times_s`` with heights ``peaks``, m/s²."""
    out = np.zeros_like(t)
    for t0, peak in zip(times_s, peaks, strict=True):
        u = (t - t0) / pulse_s
        inside = (u >= 0.0) & (u <= 1.0)
        out[inside] += peak * np.sin(np.pi * u[inside]) ** 2
    return out


def msd_response(
    u: FloatArray, rate_hz: float, freq_hz: float, damping: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Response of ``ẍ + 2ζω ẋ + ω² x = u`` from rest, exact for u linear between samples.

    Args:
        u: (N, m) input acceleration, m/s², one column per independent channel.
        rate_hz: sampling rate, Hz.
        freq_hz: natural frequency ω/2π, Hz.
        damping: damping ratio ζ.

    Returns:
        x, ẋ, ẍ, each (N, m), m, m/s, m/s².
    """
    w = 2 * np.pi * freq_hz
    A = np.array([[0.0, 1.0], [-(w**2), -2.0 * damping * w]])
    B = np.array([[0.0], [1.0]])
    Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), 1.0 / rate_hz, method="foh")
    num, den = ss2tf(Ad, Bd, Cd, Dd)
    x = lfilter(num[0], den, u, axis=0)
    v = lfilter(num[1], den, u, axis=0)
    a = u - w**2 * x - 2.0 * damping * w * v
    return x, v, a


def own_force(bone_acc: FloatArray, rate_hz: float, rms_mps2: float, rng: np.random.Generator) -> FloatArray:
    """A wobbling mass's own random force (N, 3), m/s²: white per axis, silent at rest.

    Its RMS per axis is ``rms_mps2`` where the segment's acceleration, smoothed over half
    a second, is at its RMS, and follows that envelope elsewhere (zero while standing).

    Args:
        bone_acc: (N, 3) rigid acceleration of the sensor point without gravity, m/s².
        rate_hz: sampling rate, Hz.
        rms_mps2: RMS per axis at the segment's typical acceleration, m/s².
        rng: the profile's random stream.
    """
    norm = np.linalg.norm(bone_acc, axis=1)
    width = max(1, int(round(0.5 * rate_hz)))
    env = np.convolve(norm, np.ones(width) / width, mode="same")
    scale = float(np.sqrt(np.mean(env**2)))
    env = env / scale if scale > 0.0 else env
    return np.asarray(rms_mps2 * env[:, None] * rng.standard_normal(bone_acc.shape))


def _saturating(theta: FloatArray, sat: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """f(θ) = sat·tanh(θ/sat) and its first and second derivatives with respect to θ."""
    th = np.tanh(theta / sat)
    sech2 = 1.0 - th**2
    return sat * th, sech2, -2.0 / sat * th * sech2


def skin_motion(
    angles: FloatArray,
    angles_v: FloatArray,
    angles_a: FloatArray,
    quad: FloatArray,
    sat_dirs: FloatArray,
    sat_rad: float,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Skin displacement ``Σ_j c_j θ_j² + e_j f(θ_j)`` and its time derivatives.

    Args:
        angles: (N, J) driving joint angles, rad.
        angles_v: (N, J) their rates, rad/s.
        angles_a: (N, J) their accelerations, rad/s².
        quad: (J, 3) quadratic coefficients ``c_j`` in the segment frame, m/rad².
        sat_dirs: (J, 3) saturating amplitudes ``e_j`` in the segment frame, m.
        sat_rad: saturation angle of ``f(θ) = θ_s tanh(θ/θ_s)``, rad.

    Returns:
        Displacement (m), velocity (m/s), acceleration (m/s²), each (N, 3), segment frame.
    """
    f, f1, f2 = _saturating(angles, sat_rad)
    d = angles**2 @ quad + f @ sat_dirs
    d_v = (2.0 * angles * angles_v) @ quad + (f1 * angles_v) @ sat_dirs
    d_a = (2.0 * angles_v**2 + 2.0 * angles * angles_a) @ quad + (f2 * angles_v**2 + f1 * angles_a) @ sat_dirs
    return d, d_v, d_a


def _random_dirs(rng: np.random.Generator, n: int, norm: float) -> FloatArray:
    d = rng.normal(size=(n, 3))
    return np.asarray(norm * d / np.linalg.norm(d, axis=1, keepdims=True))


def skin_twist(
    params: Artefacts,
    sensor: str,
    joints: tuple[FloatArray, FloatArray, FloatArray],
    side: str,
    pos: FloatArray,
) -> TissueMotion:
    """The sensor's turn about its bone's long axis with the flexion of the driving joint.

    The skin turns about the bone, the segment's y axis through its origin (the joint
    centre), so the sensor turns by ``φ = c (θ − mean θ)`` about y and moves with it on a
    circle about that axis: ``Δp = (cos φ − 1) p⊥ + sin φ (y × p⊥)``, ``p⊥`` the sensor's
    nominal position across the axis.

    Args:
        params: the artefact parameters (``skin_twist_rad_per_rad``, ``skin_twist_driver``).
        sensor: the sensor (segment) name.
        joints: (N, 9) joint angles (rad), their rates and accelerations.
        side: the leg: a positive twist is internal on either leg (:func:`internal_twist_sign`).
        pos: (3,) the sensor's nominal position in the segment frame, m.

    Returns:
        The twist's rotation (segment frame) and displacement of the sensor, zero when off.
    """
    n = joints[0].shape[0]
    c = internal_twist_sign(side) * params.skin_twist_rad_per_rad[sensor]
    if c == 0.0:
        z = np.zeros((n, 3))
        return TissueMotion(z, z, z, z, z, z)
    j = _twist_index(params, sensor)
    phi = c * (joints[0][:, j] - joints[0][:, j].mean())
    phi_v, phi_a = c * joints[1][:, j], c * joints[2][:, j]
    along = np.array([0.0, 1.0, 0.0])
    p = np.asarray(pos, dtype=float) * np.array([1.0, 0.0, 1.0])
    q = np.cross(along, p)
    cos, sin = np.cos(phi)[:, None], np.sin(phi)[:, None]
    turn = -sin * p + cos * q  # d/dφ of Δp
    return TissueMotion(
        d=(cos - 1.0) * p + sin * q,
        d_v=phi_v[:, None] * turn,
        d_a=phi_a[:, None] * turn + (phi_v**2)[:, None] * (-cos * p - sin * q),
        th=np.outer(phi, along),
        th_v=np.outer(phi_v, along),
        th_a=np.outer(phi_a, along),
    )


def compute_tissue_motion(
    params: Artefacts,
    rate_hz: float,
    t: FloatArray,
    contacts_s: FloatArray,
    contra_contacts_s: FloatArray,
    contact_weight: tuple[FloatArray, FloatArray],
    bone_acc_seg: dict[str, FloatArray],
    skin_normal_seg: dict[str, FloatArray],
    sensor_pos_seg: dict[str, FloatArray],
    joints: tuple[FloatArray, FloatArray, FloatArray],
    rng: np.random.Generator,
    *,
    side: str,
) -> dict[str, TissueMotion]:
    """Non-rigid motion of every sensor (zero-mean displacement and rotation).

    Args:
        params: the artefact parameters.
        rate_hz: sampling rate, Hz.
        t: (N,) sample times, s.
        contacts_s: (K,) initial contacts of the instrumented foot, s.
        contra_contacts_s: (K',) initial contacts of the other foot, s.
        contact_weight: (K,) and (K',) scale of each impact (0 while the walk starts up).
        bone_acc_seg: ``{sensor: (N, 3)}`` rigid classical acceleration of the
            sensor point, without gravity, segment frame, m/s².
        skin_normal_seg: ``{sensor: (3,)}`` the sensor's z axis in the segment frame.
        sensor_pos_seg: ``{sensor: (3,)}`` the sensor's nominal position in the segment
            frame (from the joint centre at its origin), m.
        joints: (N, 9) joint angles (rad), their rates and accelerations.
        rng: draws the skin-motion directions (in :data:`SENSORS` order).
        side: the leg (``"left"`` or ``"right"``): the sign of an internal skin twist.

    Returns:
        ``{sensor: TissueMotion}``.
    """
    direction = np.asarray(params.impact_direction, dtype=float)
    direction /= np.linalg.norm(direction)
    out: dict[str, TissueMotion] = {}
    for sensor in SENSORS:
        idx = list(SKIN_DRIVERS[sensor])
        quad = _random_dirs(rng, len(idx), params.skin_quadratic_m_per_rad2[sensor])
        sat = _random_dirs(rng, len(idx), params.skin_saturating_m[sensor])
        d_s, v_s, a_s = skin_motion(
            joints[0][:, idx], joints[1][:, idx], joints[2][:, idx], quad, sat, params.skin_saturation_rad
        )
        pulse = params.impact_pulse_s
        force = impact_force(t, contacts_s, params.impact_mps2[sensor] * contact_weight[0], pulse)
        force += impact_force(
            t, contra_contacts_s, params.impact_contra_mps2[sensor] * contact_weight[1], pulse
        )
        b, b_v, b_a = msd_response(force[:, None], rate_hz, params.bone_freq_hz[sensor], params.bone_damping)
        d_b, v_b, a_b = b * direction, b_v * direction, b_a * direction
        u = -params.tissue_gain[sensor] * (bone_acc_seg[sensor] + a_b)
        if params.tissue_random_mps2[sensor] > 0.0:
            u = u + own_force(bone_acc_seg[sensor], rate_hz, params.tissue_random_mps2[sensor], rng)
        d_t, v_t, a_t = msd_response(u, rate_hz, params.tissue_freq_hz[sensor], params.tissue_damping[sensor])
        # the sensor rocks on the tissue: rotation about n × (shear displacement)
        n = skin_normal_seg[sensor]
        k = params.rock_rad_per_m[sensor]
        dt_s, vt_s, at_s = d_t + d_s, v_t + v_s, a_t + a_s
        th, th_v, th_a = (k * np.cross(n, x) for x in (dt_s, vt_s, at_s))
        # ... and twists about the bone with the flexion of the joint whose muscles slide under it
        tw = skin_twist(params, sensor, joints, side, sensor_pos_seg[sensor])
        th, th_v, th_a = th + tw.th, th_v + tw.th_v, th_a + tw.th_a
        dt_s, vt_s, at_s = dt_s + tw.d, vt_s + tw.d_v, at_s + tw.d_a
        d = d_b + dt_s
        out[sensor] = TissueMotion(
            d=d - d.mean(axis=0),
            d_v=v_b + vt_s,
            d_a=a_b + at_s,
            th=th - th.mean(axis=0),
            th_v=th_v,
            th_a=th_a,
        )
    return out


def exp_so3(phi: FloatArray) -> FloatArray:
    """Rotation matrices (N, 3, 3) of rotation vectors ``phi`` (N, 3), rad (Rodrigues)."""
    theta = np.linalg.norm(phi, axis=1)
    small = theta < 1e-8
    ts = np.where(small, 1.0, theta)
    a = np.where(small, 1.0 - theta**2 / 6.0, np.sin(ts) / ts)
    b = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(ts)) / ts**2)
    K = _skew_n(phi)
    return np.eye(3) + a[:, None, None] * K + b[:, None, None] * (K @ K)


def right_jacobian_so3(phi: FloatArray) -> FloatArray:
    """Right Jacobians (N, 3, 3) of SO(3) at ``phi`` (N, 3): ω_body = J_r(φ) φ̇."""
    theta = np.linalg.norm(phi, axis=1)
    small = theta < 1e-6
    ts = np.where(small, 1.0, theta)
    b = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(ts)) / ts**2)
    c = np.where(small, 1.0 / 6.0 - theta**2 / 120.0, (ts - np.sin(ts)) / ts**3)
    K = _skew_n(phi)
    return np.eye(3) - b[:, None, None] * K + c[:, None, None] * (K @ K)


def _skew_n(v: FloatArray) -> FloatArray:
    K = np.zeros((v.shape[0], 3, 3))
    K[:, 0, 1], K[:, 0, 2] = -v[:, 2], v[:, 1]
    K[:, 1, 0], K[:, 1, 2] = v[:, 2], -v[:, 0]
    K[:, 2, 0], K[:, 2, 1] = -v[:, 1], v[:, 0]
    return K
