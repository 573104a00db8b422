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
from .motions import MOTION_FUNCTIONS, MOTIONS, MotionKinematics, smoothstep
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

#: Configuration coordinates of the composite root joint (pelvis x, y, z, heading, tilt,
#: obliquity, rotation); the 9 leg DOFs follow.
_N_ROOT = 7


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
    mirror_pelvis: bool | None = None,
) -> Simulation:
    """Simulate a four-IMU leg trial with known truth.

    Stages: check the request → leg model → joint trajectories → rigid sensor signals →
    non-rigid sensor motion and gravity → measured signals (errors, noise) → truth.

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
        mirror_pelvis: mirror the pelvis's obliquity and rotation (:data:`_MIRRORED_PELVIS`);
            ``None``: for a right leg, as a real pelvis turns with the leg that swings.
            ``False`` gives a right leg the left leg's pelvis motion (two runs then share
            one pelvis, as a test fixture joining two legs needs).

    Returns:
        A :class:`Simulation`.

    Raises:
        InputError: unknown motion, side, or non-positive duration/rate.
    """
    t_start = time.perf_counter()
    side = _check_request(motion, side, rate_hz, duration_s)
    noise = ImuNoise() if noise is None else noise
    sta = SoftTissue() if soft_tissue is True else (soft_tissue or None)
    rng = np.random.default_rng(seed)
    art = artefacts if artefacts is not None and artefacts.active else None
    sim_model = _sim_model(geometry, side, height_m, mass_kg, rng)
    mirror = side == "right" if mirror_pelvis is None else mirror_pelvis
    traj = _trajectories(sim_model, motion, duration_s, rate_hz, still_s, rng, mirror)
    sta_dirs = _sta_directions(sta, rng) if sta is not None else None
    sig = _rigid_signals(sim_model, traj, with_alpha=sta is not None or art is not None)
    art_rng = np.random.default_rng([seed, 9] if art is None or art.seed is None else art.seed)
    contacts, tissue = _artefact_motion(art, rate_hz, traj, sig, art_rng, side)
    sta_off = _move_sensors(sig, traj, sta_dirs, tissue)
    mag = {sensor: np.einsum("nji,j->ni", sig.rot[sensor], MAG_FIELD_ENU_UT) for sensor in SENSORS}
    clean = ImuTrial(traj.t.copy(), sig.acc, sig.gyr, mag if with_mag else None, side)
    errors = draw_sensor_errors(art, traj.t.size, art_rng) if art is not None else None
    trial, bias = _measure(traj.t, sig, mag, errors, noise, rng, with_mag, side)
    true_model, truth = _truth(
        sim_model, motion, seed, rate_hz, duration_s, height_m, mass_kg, noise, sta, bias
    )
    art_truth = _artefact_truth(art, errors, contacts, tissue, sig.base_pl)
    if art_truth is not None:
        truth["artefacts"] = art_truth.to_dict()
    return Simulation(
        trial=trial,
        clean=clean,
        quat_wxyz={sensor: quat_make_continuous(quat_from_matrix(sig.rot[sensor])) for sensor in SENSORS},
        sensor_pos_m=sig.pos,
        angles_rad=traj.kin.angles_rad.copy(),
        positions_m=_positions(sig),
        truth=truth,
        model=true_model,
        gyr_bias_rps=bias,
        sta_offsets_m=sta_off,
        runtime_s=time.perf_counter() - t_start,
        artefacts=art_truth,
    )


@dataclass
class _Trajectories:
    """The sampled motion.

    Attributes:
        t: (N,) sample times from 0, s.
        s: (N,) start-up ramp (0 while standing still, 1 after), dimensionless.
        kin: the motion's joint-angle, pelvis and gait-phase trajectories.
        Q: (N, nq) configuration of the simulation model (root joint, then the 9 leg DOFs).
        V: (N, nq) its first derivative from the quintic spline, per s.
        A: (N, nq) its second derivative, per s².
    """

    t: FloatArray
    s: FloatArray
    kin: MotionKinematics
    Q: FloatArray
    V: FloatArray
    A: FloatArray


@dataclass
class _SensorSignals:
    """Per-sensor signals ``{sensor: array}`` on the N samples, updated in place by the stages.

    Attributes:
        gyr: (N, 3) angular velocity in the sensor frame, rad/s.
        acc: (N, 3) classical linear acceleration in the sensor frame, m/s² (specific force
            once :func:`_move_sensors` has subtracted gravity).
        alpha: (N, 3) angular acceleration in the sensor frame, rad/s² (only filled when
            soft tissue or artefacts need it).
        rot: (N, 3, 3) sensor → ENU rotation.
        pos: (N, 3) sensor position in ENU, m.
        base_pl: nominal placement of each sensor frame in its segment frame.
        hip_c: (N, 3) hip centre in ENU, m.
        ankle_c: (N, 3) ankle centre in ENU, m.
    """

    gyr: dict[str, FloatArray]
    acc: dict[str, FloatArray]
    alpha: dict[str, FloatArray]
    rot: dict[str, FloatArray]
    pos: dict[str, FloatArray]
    base_pl: dict[str, pin.SE3]
    hip_c: FloatArray
    ankle_c: FloatArray


def _check_request(motion: str, side: str, rate_hz: float, duration_s: float) -> str:
    """The checked side (``"left"``/``"right"``); raises :class:`InputError` for a bad request."""
    if motion not in MOTION_FUNCTIONS:
        raise InputError(f"unknown motion '{motion}'; choose one of {', '.join(MOTIONS)}")
    try:
        side = check_side(side)
    except ValueError as e:
        raise InputError(str(e)) from None
    if rate_hz <= 0 or duration_s < 2.0:
        raise InputError("duration must be at least 2 s and the rate positive; e.g. --duration 60")
    return side


def _sim_model(
    geometry: LegGeometry | None, side: str, height_m: float, mass_kg: float, rng: np.random.Generator
) -> LegModel:
    """The leg to simulate, on the composite root joint (:func:`_root_joint`).

    Without ``geometry``: the template for ``height_m`` (m) and ``mass_kg`` (kg) with random
    sensor placements drawn from ``rng``.
    """
    if geometry is None:
        geometry = LegGeometry.from_anthropometry(side, height_m, mass_kg)
        geometry.sensor_placements = random_placements(geometry, rng)
    return LegModel(geometry, root_joint=_root_joint())


#: Signs of the pelvis's (tilt, obliquity, rotation) for a right leg: a mirror image in the
#: sagittal plane keeps rotations about the medio-lateral axis and reverses those about the
#: anterior and vertical axes. (In a left-leg walk the pelvis turns clockwise seen from above
#: while that leg swings forward; the right leg's swing turns it the other way, so a pelvis
#: that was not mirrored told a right leg apart from a left one by nothing but its sensors.)
_MIRRORED_PELVIS = np.array([1.0, -1.0, -1.0])


def _trajectories(
    sim_model: LegModel,
    motion: str,
    duration_s: float,
    rate_hz: float,
    still_s: float,
    rng: np.random.Generator,
    mirror_pelvis: bool,
) -> _Trajectories:
    """The motion sampled at ``rate_hz`` (Hz) over ``duration_s`` (s), after ``still_s`` (s) still.

    Derivatives come from a quintic spline; the pelvis is anchored at the ankle when the motion
    gives no pelvis position. The motions are written for a left leg; ``mirror_pelvis``
    mirrors the pelvis's obliquity and rotation (:data:`_MIRRORED_PELVIS`) for a right leg,
    so that the pelvis drops and turns with the instrumented leg's swing as a real pelvis does.
    """
    model = sim_model.model
    n = int(round(duration_s * rate_hz))
    t = np.arange(n) / rate_hz
    s = smoothstep(t, still_s, 1.0)
    kin = MOTION_FUNCTIONS[motion](t - still_s, s, rng)
    Q = np.zeros((n, model.nq))
    Q[:, 3] = kin.yaw_rad
    Q[:, 4:7] = kin.pelvis_euler_rad
    if mirror_pelvis:
        Q[:, 4:7] *= _MIRRORED_PELVIS
    Q[:, _N_ROOT:] = kin.angles_rad
    if kin.pelvis_pos_m is None:
        Q[:, :3] = _anchor_pelvis(sim_model, Q)
    else:
        Q[:, :3] = kin.pelvis_pos_m
    spline = make_interp_spline(t, Q, k=5)
    return _Trajectories(t, s, kin, Q, spline.derivative(1)(t), spline.derivative(2)(t))


def _artefact_motion(
    art: Artefacts | None,
    rate_hz: float,
    traj: _Trajectories,
    sig: _SensorSignals,
    rng: np.random.Generator,
    side: str,
) -> tuple[tuple[FloatArray, FloatArray], dict[str, TissueMotion] | None]:
    """Initial contacts (s) and each sensor's non-rigid motion (:func:`_tissue_motion`).

    Without a profile: no contacts and ``None``.
    """
    if art is None:
        return (np.zeros(0), np.zeros(0)), None
    QVA = (traj.Q, traj.V, traj.A)
    phase = traj.kin.gait_phase
    return _tissue_motion(art, rate_hz, traj.t, traj.s, phase, sig.acc, sig.base_pl, QVA, rng, side)


def _sta_directions(sta: SoftTissue, rng: np.random.Generator) -> dict[str, FloatArray]:
    """Per sensor, (n_drivers, 3) displacement per driving joint angle in the segment frame, m/rad."""
    sta_dirs: dict[str, FloatArray] = {}
    sta_rng = rng if sta.seed is None else np.random.default_rng(sta.seed)
    for sensor in SENSORS:
        d = sta_rng.normal(size=(len(_STA_DRIVERS[sensor]), 3))
        d *= sta.amplitude_m_per_rad / np.linalg.norm(d, axis=1, keepdims=True)
        sta_dirs[sensor] = d
    return sta_dirs


def _rigid_signals(sim_model: LegModel, traj: _Trajectories, with_alpha: bool) -> _SensorSignals:
    """Signals of rigidly mounted sensors, by Pinocchio forward kinematics at every sample.

    Frame velocity, classical acceleration (without gravity) and placement of each sensor,
    and the hip and ankle centres; see :class:`_SensorSignals` for shapes, frames and units.
    """
    model, data = sim_model.model, sim_model.data
    n = traj.t.size
    Q, V, A = traj.Q, traj.V, traj.A
    fids = {sensor: sim_model.frame_id(f"imu_{sensor}") for sensor in SENSORS}
    base_pl = {sensor: pin.SE3(model.frames[fids[sensor]].placement) for sensor in SENSORS}
    hip_j = model.getJointId(DOF_NAMES[0])
    ankle_j = model.getJointId(DOF_NAMES[6])
    sig = _SensorSignals(
        gyr={sensor: np.empty((n, 3)) for sensor in SENSORS},
        acc={sensor: np.empty((n, 3)) for sensor in SENSORS},
        alpha={sensor: np.empty((n, 3)) for sensor in SENSORS},
        rot={sensor: np.empty((n, 3, 3)) for sensor in SENSORS},
        pos={sensor: np.empty((n, 3)) for sensor in SENSORS},
        base_pl=base_pl,
        hip_c=np.empty((n, 3)),
        ankle_c=np.empty((n, 3)),
    )
    LOCAL = pin.ReferenceFrame.LOCAL
    for k in range(n):
        pin.forwardKinematics(model, data, Q[k], V[k], A[k])
        sig.hip_c[k] = data.oMi[hip_j].translation
        sig.ankle_c[k] = data.oMi[ankle_j].translation
        for sensor in SENSORS:
            fid = fids[sensor]
            oMf = pin.updateFramePlacement(model, data, fid)
            sig.gyr[sensor][k] = pin.getFrameVelocity(model, data, fid, LOCAL).angular
            sig.acc[sensor][k] = pin.getFrameClassicalAcceleration(model, data, fid, LOCAL).linear
            if with_alpha:
                sig.alpha[sensor][k] = pin.getFrameAcceleration(model, data, fid, LOCAL).angular
            sig.rot[sensor][k] = oMf.rotation
            sig.pos[sensor][k] = oMf.translation
    return sig


def _move_sensors(
    sig: _SensorSignals,
    traj: _Trajectories,
    sta_dirs: dict[str, FloatArray] | None,
    tissue: dict[str, TissueMotion] | None,
) -> dict[str, FloatArray]:
    """Soft-tissue sliding, artefact displacement, gravity and artefact rotation, in place.

    Returns:
        ``{sensor: (N, 3)}`` soft-tissue displacement in the segment frame, m (empty without
        soft tissue).
    """
    sta_off: dict[str, FloatArray] = {}
    for sensor in SENSORS:
        R_seg_s = sig.base_pl[sensor].rotation
        if sta_dirs is not None:
            # the sensor slides by Δ(t) on its segment (Δ in the segment frame, linear in the
            # joint angles)
            d = sta_dirs[sensor]
            idx = [_N_ROOT + i for i in _STA_DRIVERS[sensor]]
            sta_off[sensor] = traj.Q[:, idx] @ d
            _slide(sig, sensor, *(x @ d @ R_seg_s for x in (traj.Q[:, idx], traj.V[:, idx], traj.A[:, idx])))
        if tissue is not None:
            tm = tissue[sensor]
            _slide(sig, sensor, *(x @ R_seg_s for x in (tm.d, tm.d_v, tm.d_a)))
        sig.acc[sensor] -= np.einsum("nji,j->ni", sig.rot[sensor], GRAVITY_ENU)
        if tissue is not None:
            _tilt(sig, sensor, tissue[sensor].th @ R_seg_s, tissue[sensor].th_v @ R_seg_s)
    return sta_off


def _slide(sig: _SensorSignals, sensor: str, r: FloatArray, r_v: FloatArray, r_a: FloatArray) -> None:
    """Move ``sensor`` by ``r`` (N, 3) in its nominal frame, m (``r_v`` m/s, ``r_a`` m/s²).

    The point's classical acceleration in the sensor frame is
    a0 + α×r + ω×(ω×r) + 2 ω×ṙ + r̈; its ENU position moves by ``R r``.
    """
    w = sig.gyr[sensor]
    sig.acc[sensor] += (
        np.cross(sig.alpha[sensor], r) + np.cross(w, np.cross(w, r)) + 2.0 * np.cross(w, r_v) + r_a
    )
    sig.pos[sensor] += np.einsum("nij,nj->ni", sig.rot[sensor], r)


def _tilt(sig: _SensorSignals, sensor: str, phi: FloatArray, phi_v: FloatArray) -> None:
    """Rotate ``sensor`` by φ (N, 3), rad, in its nominal frame (φ̇ ``phi_v``, rad/s).

    Specific force and gyro are re-expressed in the rotated frame (the gyro gains
    ``J_r(φ) φ̇``) and the orientation becomes ``R exp(φ)``.
    """
    R_w = exp_so3(phi)
    sig.acc[sensor] = np.einsum("nji,nj->ni", R_w, sig.acc[sensor])
    sig.gyr[sensor] = np.einsum("nji,nj->ni", R_w, sig.gyr[sensor]) + np.einsum(
        "nij,nj->ni", right_jacobian_so3(phi), phi_v
    )
    sig.rot[sensor] = sig.rot[sensor] @ R_w


def _positions(sig: _SensorSignals) -> FloatArray:
    """(N, 6) pelvis→foot sensor and hip→ankle centre vectors in the pelvis sensor frame, m."""
    Rp = sig.rot["pelvis"]
    p2f = np.einsum("nji,nj->ni", Rp, sig.pos["foot"] - sig.pos["pelvis"])
    h2a = np.einsum("nji,nj->ni", Rp, sig.ankle_c - sig.hip_c)
    return np.hstack([p2f, h2a])


def _measure(
    t: FloatArray,
    sig: _SensorSignals,
    mag: dict[str, FloatArray],
    errors: SensorErrors | None,
    noise: ImuNoise,
    rng: np.random.Generator,
    with_mag: bool,
    side: str,
) -> tuple[ImuTrial, dict[str, FloatArray]]:
    """The measured trial: clock/scale/misalignment ``errors`` (if any), gyro bias and white noise.

    Returns:
        The trial (acc m/s², gyr rad/s, mag µT in the sensor frames) and ``{sensor: (3,)}`` the
        gyro bias added, rad/s.
    """
    n = t.size
    acc, gyr = sig.acc, sig.gyr
    m_acc, m_gyr, m_mag = (acc, gyr, mag) if errors is None else _apply_errors(t, acc, gyr, mag, errors)
    bias = {}
    n_acc, n_gyr, n_mag = {}, {}, {}
    for sensor in SENSORS:
        b = rng.normal(size=3)
        bias[sensor] = noise.gyr_bias_rps * b / np.linalg.norm(b)
        n_gyr[sensor] = m_gyr[sensor] + bias[sensor] + noise.gyr_std_rps * rng.normal(size=(n, 3))
        n_acc[sensor] = m_acc[sensor] + noise.acc_std_mps2 * rng.normal(size=(n, 3))
        n_mag[sensor] = m_mag[sensor] + noise.mag_std_ut * rng.normal(size=(n, 3))
        n_acc[sensor] = n_acc[sensor] + noise.acc_bias(rng)
    return ImuTrial(t.copy(), n_acc, n_gyr, n_mag if with_mag else None, side), bias


def _truth(
    sim_model: LegModel,
    motion: str,
    seed: int,
    rate_hz: float,
    duration_s: float,
    height_m: float,
    mass_kg: float,
    noise: ImuNoise,
    sta: SoftTissue | None,
    bias: dict[str, FloatArray],
) -> tuple[LegModel, dict[str, Any]]:
    """The true model (fixed root) and its parameters in the calibration.json schema.

    Adds the simulation's settings, the gyro biases (rad/s) and the URDF.
    """
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
            "noise": noise.to_dict(),
            "soft_tissue_m_per_rad": sta.amplitude_m_per_rad if sta is not None else 0.0,
            "gyr_bias": {sensor: bias[sensor].tolist() for sensor in SENSORS},
            "urdf": true_model.to_urdf_string(),
        }
    )
    return true_model, truth


def _artefact_truth(
    art: Artefacts | None,
    errors: SensorErrors | None,
    contacts: tuple[FloatArray, FloatArray],
    tissue: dict[str, TissueMotion] | None,
    base_pl: dict[str, pin.SE3],
) -> ArtefactTruth | None:
    """What the realism profile did; ``None`` without a profile.

    Contact times (s), displacement (m) and rotation (rad) in the nominal sensor frame, and
    the clock and scale errors.
    """
    if art is None or errors is None or tissue is None:
        return None
    return ArtefactTruth(
        params=art,
        contact_times_s=contacts[0],
        contra_contact_times_s=contacts[1],
        displacement_m={sensor: tissue[sensor].d for sensor in SENSORS},
        rotation_rad={sensor: tissue[sensor].th @ base_pl[sensor].rotation for sensor in SENSORS},
        clock_offset_s=errors.clock_offset_s,
        acc_matrix=errors.acc_matrix,
        gyr_matrix=errors.gyr_matrix,
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
    side: str,
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
    tissue = tissue_at_contacts(art, rate_hz, t, (ipsi, contra), weights, acc_rigid, base_pl, QVA, rng, side)
    return (ipsi, contra), tissue


def tissue_at_contacts(
    art: Artefacts,
    rate_hz: float,
    t: FloatArray,
    contacts: tuple[FloatArray, FloatArray],
    weights: tuple[FloatArray, FloatArray],
    acc_rigid: dict[str, FloatArray],
    base_pl: dict[str, pin.SE3],
    QVA: tuple[FloatArray, FloatArray, FloatArray],
    rng: np.random.Generator,
    side: str,
) -> dict[str, TissueMotion]:
    """Each sensor's non-rigid motion (:func:`compute_tissue_motion`) for known initial contacts.

    Args:
        art: the realism profile.
        rate_hz: sampling rate, Hz.
        t: (N,) sample times, s.
        contacts: (K,) initial contacts of the instrumented foot and (K',) of the other foot, s.
        weights: (K,) and (K',) scale of each impact (dimensionless, 0–1).
        acc_rigid: ``{sensor: (N, 3)}`` rigid classical acceleration of each sensor point,
            nominal sensor frame, without gravity, m/s².
        base_pl: nominal placement of each sensor frame in its segment frame.
        QVA: (N, 7 + 9) configuration of the simulation model (root joint, then the leg
            DOFs, rad) and its first and second time derivatives.
        rng: draws the skin-motion directions.
        side: the leg, ``"left"`` or ``"right"`` (the sign of an internal skin twist).
    """
    bone_acc = {sensor: acc_rigid[sensor] @ base_pl[sensor].rotation.T for sensor in SENSORS}
    normal = {sensor: base_pl[sensor].rotation[:, 2] for sensor in SENSORS}
    pos = {sensor: np.asarray(base_pl[sensor].translation, dtype=float) for sensor in SENSORS}
    joints = (QVA[0][:, _N_ROOT:], QVA[1][:, _N_ROOT:], QVA[2][:, _N_ROOT:])
    return compute_tissue_motion(
        art, rate_hz, t, *contacts, weights, bone_acc, normal, pos, joints, rng, side=side
    )


def _apply_errors(
    t: FloatArray,
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    mag: dict[str, FloatArray],
    errors: SensorErrors,
) -> tuple[dict[str, FloatArray], dict[str, FloatArray], dict[str, FloatArray]]:
    """Clock-shifted, scaled and misaligned accelerometer, gyro and magnetometer signals.

    ``{sensor: (N, 3)}`` in the sensor frames (m/s², rad/s, µT), for every sensor of ``acc``.
    """
    out_acc, out_gyr, out_mag = {}, {}, {}
    for sensor in acc:
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
