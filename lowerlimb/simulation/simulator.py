"""The IMU simulator: exactly what four leg IMUs measure for a known motion.

The leg is the :class:`~lowerlimb.model.leg_model.LegModel` built from a template
with random sensor placements; its pelvis hangs from a composite root joint
(x, y, z translation in the ENU world, heading about the vertical, then the
pelvis tilt/obliquity/rotation), so every configuration coordinate is a plain
scalar trajectory. Trajectories are interpolated by quintic splines, whose
first and second derivatives give ``v`` and ``a``; Pinocchio then gives each
IMU frame's angular velocity (the gyro) and classical linear acceleration,
from which the specific force is ``f = R^T (a − g)`` in the sensor frame.
The magnetometer reads the ENU field (50 µT, 65° inclination) in the sensor
frame.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from scipy.interpolate import make_interp_spline

from ..conventions import (
    GRAVITY_ENU,
    SENSORS,
    FloatArray,
    check_side,
    quat_from_matrix,
    quat_make_continuous,
)
from ..errors import InputError
from ..io.trial import ImuTrial
from ..model.geometry import LegGeometry
from ..model.leg_model import DOF_NAMES, LegModel
from .artefacts import Artefacts, ArtefactTruth
from .motions import MOTION_FUNCTIONS, MOTIONS, smoothstep
from .noise import ImuNoise, SoftTissue
from .placements import random_placements
from .sensor_errors import SensorErrors, draw_sensor_errors, resample_at
from .tissue_motion import TissueMotion, compute_tissue_motion, contact_times, exp_so3, right_jacobian_so3

#: Earth magnetic field in ENU, µT (50 µT, inclination 65° downwards, pointing north).
MAG_FIELD_ENU_UT = 50.0 * np.array([0.0, np.cos(np.deg2rad(65.0)), -np.sin(np.deg2rad(65.0))])

#: Rotation of the pelvis frame (x anterior, y up, z right) at zero heading in ENU:
#: facing east, up is up, right is south.
R_ENU_PELVIS0 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])

#: Joint angles (by angles.csv index) that drive each sensor's soft-tissue artefact.
_STA_DRIVERS: dict[str, tuple[int, ...]] = {
    "pelvis": (0,),
    "thigh": (0, 3),
    "shank": (3, 6),
    "foot": (6,),
}


@dataclass
class Simulation:
    """Everything the simulator put in and what the IMUs measured.

    Attributes:
        trial: the measured trial (noise and bias added).
        clean: the ideal, noise-free measurements.
        quat_wxyz: ``{sensor: (N, 4)}`` true orientations, sensor → ENU.
        sensor_pos_m: ``{sensor: (N, 3)}`` true sensor positions in ENU, m.
        angles_rad: (N, 9) true ISB joint angles, angles.csv order, rad.
        positions_m: (N, 6) true pelvis→foot sensor and hip→ankle centre
            vectors in the pelvis sensor frame, positions.csv order, m.
        truth: true joint parameters in the calibration.json schema (+ extras).
        model: the true :class:`LegModel` (free-flyer root).
        gyr_bias_rps: ``{sensor: (3,)}`` the constant gyro bias added, rad/s.
        sta_offsets_m: ``{sensor: (N, 3)}`` soft-tissue displacement in the segment frame, m.
        artefacts: what the realism profile did (None without one); with it,
            ``clean`` holds the non-rigid sensors' exact signals and ``trial``
            adds the clock, scale and misalignment errors as well as noise.
    """

    trial: ImuTrial
    clean: ImuTrial
    quat_wxyz: dict[str, FloatArray]
    sensor_pos_m: dict[str, FloatArray]
    angles_rad: FloatArray
    positions_m: FloatArray
    truth: dict[str, Any]
    model: LegModel
    gyr_bias_rps: dict[str, FloatArray]
    sta_offsets_m: dict[str, FloatArray] = field(default_factory=dict)
    runtime_s: float = 0.0
    artefacts: ArtefactTruth | None = None


def _root_joint() -> pin.JointModelComposite:
    root = pin.JointModelComposite()
    root.addJoint(pin.JointModelPX())
    root.addJoint(pin.JointModelPY())
    root.addJoint(pin.JointModelPZ())
    root.addJoint(pin.JointModelRZ())  # heading about ENU up
    root.addJoint(pin.JointModelRZ(), pin.SE3(R_ENU_PELVIS0, np.zeros(3)))  # pelvis tilt
    root.addJoint(pin.JointModelRX())  # obliquity
    root.addJoint(pin.JointModelRY())  # pelvis rotation
    return root


def simulate(
    motion: str = "walk",
    duration_s: float = 60.0,
    seed: int = 0,
    *,
    side: str = "left",
    rate_hz: float = 100.0,
    noise: ImuNoise | None = None,
    soft_tissue: bool | SoftTissue = False,
    with_mag: bool = True,
    height_m: float = 1.75,
    mass_kg: float = 75.0,
    still_s: float = 1.5,
    geometry: LegGeometry | None = None,
    artefacts: Artefacts | None = None,
) -> Simulation:
    """Simulate a four-IMU leg trial with known truth.

    Args:
        motion: one of :data:`~lowerlimb.simulation.motions.MOTIONS`.
        duration_s: trial length including the initial standing period, s (≥ 2).
        seed: seeds placements, motion variation and noise.
        side: ``"left"`` or ``"right"``.
        rate_hz: sampling rate, Hz.
        noise: sensor errors; ``None`` means the realistic default :class:`ImuNoise`.
        soft_tissue: ``True`` (default amplitude) or a :class:`SoftTissue` to let
            sensors slide with joint angles.
        with_mag: include magnetometer columns.
        height_m: subject stature for the template (de Leva 1996), m.
        mass_kg: subject mass for the template, kg.
        still_s: standing still at the start, s.
        geometry: a leg to use instead of the random template placements.
        artefacts: realism profile (impacts, wobbling soft tissue, skin motion,
            clock and scale errors); ``None`` or :meth:`Artefacts.none` gives
            the rigid signals. Its random draws use their own stream, so the
            placements, motion and noise are those of the rigid simulation.

    Returns:
        A :class:`Simulation`.

    Raises:
        InputError: unknown motion, side, or non-positive duration/rate.
    """
    t_start = time.perf_counter()
    if motion not in MOTION_FUNCTIONS:
        raise InputError(f"unknown motion '{motion}'; choose one of {', '.join(MOTIONS)}")
    try:
        side = check_side(side)
    except ValueError as e:
        raise InputError(str(e)) from None
    if rate_hz <= 0 or duration_s < 2.0:
        raise InputError("duration must be at least 2 s and the rate positive; e.g. --duration 60")
    noise = ImuNoise() if noise is None else noise
    sta = SoftTissue() if soft_tissue is True else (soft_tissue or None)
    rng = np.random.default_rng(seed)
    art = artefacts if artefacts is not None and artefacts.active else None

    if geometry is None:
        geometry = LegGeometry.from_anthropometry(side, height_m, mass_kg)
        geometry.sensor_placements = random_placements(geometry, rng)
    sim_model = LegModel(geometry, root_joint=_root_joint())
    model, data = sim_model.model, sim_model.data

    n = int(round(duration_s * rate_hz))
    t = np.arange(n) / rate_hz
    s = smoothstep(t, still_s, 1.0)
    kin = MOTION_FUNCTIONS[motion](t - still_s, s, rng)

    n_root = 7
    Q = np.zeros((n, model.nq))
    Q[:, 3] = kin.yaw_rad
    Q[:, 4:7] = kin.pelvis_euler_rad
    Q[:, n_root:] = kin.angles_rad
    if kin.pelvis_pos_m is None:
        Q[:, :3] = _anchor_pelvis(sim_model, Q)
    else:
        Q[:, :3] = kin.pelvis_pos_m
    spline = make_interp_spline(t, Q, k=5)
    V = spline.derivative(1)(t)
    A = spline.derivative(2)(t)

    # soft-tissue displacement (segment frame) and its derivatives
    sta_dirs: dict[str, FloatArray] = {}
    if sta is not None:
        sta_rng = rng if sta.seed is None else np.random.default_rng(sta.seed)
        for sensor in SENSORS:
            d = sta_rng.normal(size=(len(_STA_DRIVERS[sensor]), 3))
            d *= sta.amplitude_m_per_rad / np.linalg.norm(d, axis=1, keepdims=True)
            sta_dirs[sensor] = d

    fids = {sensor: sim_model.frame_id(f"imu_{sensor}") for sensor in SENSORS}
    base_pl = {sensor: pin.SE3(model.frames[fids[sensor]].placement) for sensor in SENSORS}
    hip_j = model.getJointId(DOF_NAMES[0])
    ankle_j = model.getJointId(DOF_NAMES[6])
    gyr = {sensor: np.empty((n, 3)) for sensor in SENSORS}
    acc = {sensor: np.empty((n, 3)) for sensor in SENSORS}
    rot = {sensor: np.empty((n, 3, 3)) for sensor in SENSORS}
    pos = {sensor: np.empty((n, 3)) for sensor in SENSORS}
    sta_off = {sensor: np.zeros((n, 3)) for sensor in SENSORS}
    hip_c = np.empty((n, 3))
    ankle_c = np.empty((n, 3))
    LOCAL = pin.ReferenceFrame.LOCAL
    alpha = {sensor: np.empty((n, 3)) for sensor in SENSORS}
    for k in range(n):
        pin.forwardKinematics(model, data, Q[k], V[k], A[k])
        hip_c[k] = data.oMi[hip_j].translation
        ankle_c[k] = data.oMi[ankle_j].translation
        for sensor in SENSORS:
            fid = fids[sensor]
            oMf = pin.updateFramePlacement(model, data, fid)
            gyr[sensor][k] = pin.getFrameVelocity(model, data, fid, LOCAL).angular
            acc[sensor][k] = pin.getFrameClassicalAcceleration(model, data, fid, LOCAL).linear
            if sta is not None or art is not None:
                alpha[sensor][k] = pin.getFrameAcceleration(model, data, fid, LOCAL).angular
            rot[sensor][k] = oMf.rotation
            pos[sensor][k] = oMf.translation
    tissue: dict[str, TissueMotion] = {}
    contacts = (np.zeros(0), np.zeros(0))
    art_rng = np.random.default_rng([seed, 9] if art is None or art.seed is None else art.seed)
    if art is not None:
        contacts, tissue = _tissue_motion(
            art, rate_hz, t, s, kin.gait_phase, acc, base_pl, (Q, V, A), art_rng
        )
    for sensor in SENSORS:
        if sta is not None:
            # the sensor slides by Δ(t) on its segment (Δ in the segment frame, linear in the
            # joint angles): the point's classical acceleration in the sensor frame is
            # a0 + α×r + ω×(ω×r) + 2 ω×ṙ + r̈ with r = R_seg_sensorᵀ Δ
            d = sta_dirs[sensor]
            idx = [n_root + i for i in _STA_DRIVERS[sensor]]
            R_seg_s = base_pl[sensor].rotation
            off = Q[:, idx] @ d
            sta_off[sensor] = off
            r, r_v, r_a = (x @ d @ R_seg_s for x in (Q[:, idx], V[:, idx], A[:, idx]))
            w = gyr[sensor]
            acc[sensor] += (
                np.cross(alpha[sensor], r) + np.cross(w, np.cross(w, r)) + 2.0 * np.cross(w, r_v) + r_a
            )
            pos[sensor] += np.einsum("nij,nj->ni", rot[sensor], r)
        if art is not None:
            tm = tissue[sensor]
            R_seg_s = base_pl[sensor].rotation
            r, r_v, r_a = (x @ R_seg_s for x in (tm.d, tm.d_v, tm.d_a))
            w = gyr[sensor]
            acc[sensor] += (
                np.cross(alpha[sensor], r) + np.cross(w, np.cross(w, r)) + 2.0 * np.cross(w, r_v) + r_a
            )
            pos[sensor] += np.einsum("nij,nj->ni", rot[sensor], r)
        acc[sensor] -= np.einsum("nji,j->ni", rot[sensor], GRAVITY_ENU)
        if art is not None:
            # the sensor is rotated by φ (nominal sensor frame) relative to its nominal frame
            R_seg_s = base_pl[sensor].rotation
            phi, phi_v = tissue[sensor].th @ R_seg_s, tissue[sensor].th_v @ R_seg_s
            R_w = exp_so3(phi)
            acc[sensor] = np.einsum("nji,nj->ni", R_w, acc[sensor])
            gyr[sensor] = np.einsum("nji,nj->ni", R_w, gyr[sensor]) + np.einsum(
                "nij,nj->ni", right_jacobian_so3(phi), phi_v
            )
            rot[sensor] = rot[sensor] @ R_w

    quat = {sensor: quat_make_continuous(quat_from_matrix(rot[sensor])) for sensor in SENSORS}
    mag = {sensor: np.einsum("nji,j->ni", rot[sensor], MAG_FIELD_ENU_UT) for sensor in SENSORS}
    Rp = rot["pelvis"]
    p2f = np.einsum("nji,nj->ni", Rp, pos["foot"] - pos["pelvis"])
    h2a = np.einsum("nji,nj->ni", Rp, ankle_c - hip_c)

    clean = ImuTrial(t.copy(), acc, gyr, mag if with_mag else None, side)
    errors = draw_sensor_errors(art, n, art_rng) if art is not None else None
    m_acc, m_gyr, m_mag = (acc, gyr, mag) if errors is None else _apply_errors(t, acc, gyr, mag, errors)
    bias = {}
    n_acc, n_gyr, n_mag = {}, {}, {}
    for sensor in SENSORS:
        b = rng.normal(size=3)
        bias[sensor] = noise.gyr_bias_rps * b / np.linalg.norm(b)
        n_gyr[sensor] = m_gyr[sensor] + bias[sensor] + noise.gyr_std_rps * rng.normal(size=(n, 3))
        n_acc[sensor] = m_acc[sensor] + noise.acc_std_mps2 * rng.normal(size=(n, 3))
        n_mag[sensor] = m_mag[sensor] + noise.mag_std_ut * rng.normal(size=(n, 3))
    trial = ImuTrial(t.copy(), n_acc, n_gyr, n_mag if with_mag else None, side)

    true_model = LegModel(sim_model.geometry)
    truth = true_model.calibration_dict("truth")
    truth.update(
        {
            "motion": motion,
            "seed": seed,
            "rate_hz": rate_hz,
            "duration_s": duration_s,
            "height_m": height_m,
            "mass_kg": mass_kg,
            "noise": {
                "gyr_std_rps": noise.gyr_std_rps,
                "acc_std_mps2": noise.acc_std_mps2,
                "gyr_bias_rps": noise.gyr_bias_rps,
                "mag_std_ut": noise.mag_std_ut,
            },
            "soft_tissue_m_per_rad": sta.amplitude_m_per_rad if sta is not None else 0.0,
            "gyr_bias": {sensor: bias[sensor].tolist() for sensor in SENSORS},
            "urdf": true_model.to_urdf_string(),
        }
    )
    art_truth = None
    if art is not None and errors is not None:
        art_truth = ArtefactTruth(
            params=art,
            contact_times_s=contacts[0],
            contra_contact_times_s=contacts[1],
            displacement_m={sensor: tissue[sensor].d for sensor in SENSORS},
            rotation_rad={sensor: tissue[sensor].th @ base_pl[sensor].rotation for sensor in SENSORS},
            clock_offset_s=errors.clock_offset_s,
            acc_matrix=errors.acc_matrix,
            gyr_matrix=errors.gyr_matrix,
        )
        truth["artefacts"] = art_truth.to_dict()
    return Simulation(
        trial=trial,
        clean=clean,
        quat_wxyz=quat,
        sensor_pos_m=pos,
        angles_rad=kin.angles_rad.copy(),
        positions_m=np.hstack([p2f, h2a]),
        truth=truth,
        model=true_model,
        gyr_bias_rps=bias,
        sta_offsets_m=sta_off if sta is not None else {},
        runtime_s=time.perf_counter() - t_start,
        artefacts=art_truth,
    )


def _tissue_motion(
    art: Artefacts,
    rate_hz: float,
    t: FloatArray,
    s: FloatArray,
    gait_phase: FloatArray | None,
    acc_rigid: dict[str, FloatArray],
    base_pl: dict[str, pin.SE3],
    QVA: tuple[FloatArray, FloatArray, FloatArray],
    rng: np.random.Generator,
) -> tuple[tuple[FloatArray, FloatArray], dict[str, TissueMotion]]:
    """Initial contacts (instrumented, other foot) and each sensor's non-rigid motion.

    ``acc_rigid`` is the rigid classical acceleration of each sensor point
    (nominal sensor frame, without gravity); impacts are weighted by the walk's
    start-up ramp ``s`` at the contact.
    """
    if gait_phase is None:
        ipsi, contra = np.zeros(0), np.zeros(0)
    else:
        ipsi, contra = contact_times(t, gait_phase, 0.0), contact_times(t, gait_phase, 0.5)
        ipsi, contra = ipsi[np.interp(ipsi, t, s) > 0.0], contra[np.interp(contra, t, s) > 0.0]
    weights = (np.interp(ipsi, t, s), np.interp(contra, t, s))
    bone_acc = {sensor: acc_rigid[sensor] @ base_pl[sensor].rotation.T for sensor in SENSORS}
    normal = {sensor: base_pl[sensor].rotation[:, 2] for sensor in SENSORS}
    n_root = 7
    joints = (QVA[0][:, n_root:], QVA[1][:, n_root:], QVA[2][:, n_root:])
    tissue = compute_tissue_motion(art, rate_hz, t, ipsi, contra, weights, bone_acc, normal, joints, rng)
    return (ipsi, contra), tissue


def _apply_errors(
    t: FloatArray,
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    mag: dict[str, FloatArray],
    errors: SensorErrors,
) -> tuple[dict[str, FloatArray], dict[str, FloatArray], dict[str, FloatArray]]:
    """Clock-shifted, scaled and misaligned accelerometer, gyro and magnetometer signals."""
    out_acc, out_gyr, out_mag = {}, {}, {}
    for sensor in SENSORS:
        dt = errors.sample_time_error_s[sensor]
        out_acc[sensor] = resample_at(t, acc[sensor], dt) @ errors.acc_matrix[sensor].T
        out_gyr[sensor] = resample_at(t, gyr[sensor], dt) @ errors.gyr_matrix[sensor].T
        out_mag[sensor] = resample_at(t, mag[sensor], dt)
    return out_acc, out_gyr, out_mag


def _anchor_pelvis(sim_model: LegModel, Q: FloatArray) -> FloatArray:
    """Pelvis positions (N, 3) that keep the ankle centre fixed in the world at its start point."""
    model, data = sim_model.model, sim_model.data
    ankle_j = model.getJointId(DOF_NAMES[6])
    n = Q.shape[0]
    rel = np.empty((n, 3))
    q = Q.copy()
    q[:, :3] = 0.0
    for k in range(n):
        pin.forwardKinematics(model, data, q[k])
        rel[k] = data.oMi[ankle_j].translation
    anchor = rel[0] + np.array([0.0, 0.0, 0.95 - 0.0])
    anchor[2] = 0.07
    return anchor - rel
