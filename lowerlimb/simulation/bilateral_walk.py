"""Seven IMUs on a walking lower body: pelvis and both legs, with known truth.

Stages of :func:`simulate_bilateral`: the two legs (template geometry, random sensor
placements, one pelvis sensor shared by both) → the walk planned from footprints
(:mod:`lowerlimb.simulation.footsteps`) → the pelvis pose, its height lowered where a
leg could not reach its foot (:func:`_pelvis_root`) → joint angles by inverse
kinematics (:mod:`lowerlimb.simulation.leg_ik`) → the rigid sensor signals of each leg
by the single-leg simulator's forward kinematics → with a realism profile, each leg's
non-rigid sensor motion (:mod:`lowerlimb.simulation.bilateral_artefacts`) → gravity →
sensor errors (with a profile), noise and bias → truth: joints, angles, positions, gait
events and spatio-temporal parameters (:mod:`lowerlimb.simulation.gait_truth`).

Both legs move in opposite phase with double support, and each foot is still on the
ground while flat; the heel (heel rocker), the MTP joint (forefoot rocker) and the toe
tip (toe rocker, until toe-off) are pivots with zero velocity.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
import pinocchio as pin
from scipy.interpolate import make_interp_spline
from scipy.signal import butter, sosfiltfilt

from ..conventions import (
    SENSORS,
    SIDES,
    FloatArray,
    matrix_from_euler_zxy,
    quat_from_matrix,
    quat_make_continuous,
    rot_z,
)
from ..errors import InputError
from ..io.bilateral_trial import BilateralTrial
from ..model.anthropometry import ankle_height_m
from ..model.geometry import LegGeometry
from ..model.leg_model import DOF_NAMES, LegModel
from .artefacts import Artefacts
from .bilateral_artefacts import BilateralArtefactTruth, bilateral_artefact_truth, bilateral_tissue_motion
from .footsteps import (
    MID_STANCE_FRACTION,
    PACES,
    R_ENU_SEGMENT0,
    FootPlan,
    WalkDraw,
    draw_walk,
    first_contacts,
    pelvis_path,
    plan_feet,
)
from .gait_truth import GaitTruth, gait_truth
from .leg_ik import solve_leg
from .magnetic_field import LAB_FIELD, LabField, dipole_grid, field_enu_ut
from .motions import MotionKinematics, smoothstep
from .noise import ImuNoise
from .pauses import PauseParams, pause_plan_times, paused_time, warped_events
from .placements import random_placements
from .sensor_errors import SensorErrors, draw_sensor_errors
from .simulator import (
    MAG_FIELD_ENU_UT,
    _apply_errors,
    _move_sensors,
    _rigid_signals,
    _root_joint,
    _SensorSignals,
    _Trajectories,
)
from .tissue_motion import TissueMotion
from .toe_rocker import PreSwingParams
from .treadmill import TreadmillParams, belt_travel, lab_positions, lab_specific_force, motor_dipole, straight
from .turns import TurnParams, hip_turn_rotation, turn_starts, turnaround_path

__all__ = ["BilateralSimulation", "simulate_bilateral"]

#: Smallest knee flexion kept while walking (the pelvis is lowered to keep it), rad; the
#: smoothed height aims at 1.5 times as much. Near a straight knee its angle changes like the
#: square root of the hip–ankle distance, so a leg that touched full extension would see a
#: kink in knee angle; adults keep 3–8° at initial contact and heel-off (Perry 2010).
MIN_WALKING_KNEE_RAD = np.deg2rad(7.0)
#: The minimum knee flexion is reached this long after the walk starts, s.
KNEE_RAMP_S = 0.3
#: The pelvis reaches its walking height this long after the walk starts (the first heel
#: rises at the start; the first contact comes about 0.6 s later), s.
HEIGHT_RAMP_S = 0.5
#: Harmonics of the step frequency in the pelvis height (:func:`_step_harmonics`).
PELVIS_HARMONICS = 3


@dataclass
class BilateralSimulation:
    """Everything :func:`simulate_bilateral` put in and what the seven IMUs measured.

    Attributes:
        trial: The measured seven-sensor trial (noise and gyro bias added).
        clean: The ideal measurements.
        angles_rad: (N, 18) true joint angles, left then right, two-leg angles.csv order, rad.
        positions_m: (N, 15) true two-leg positions.csv columns, pelvis sensor frame, m.
        ankle_m: ``{side: (N, 3)}`` true ankle centres in ENU, m.
        sensor_pos_m: ``{sensor: (N, 3)}`` true sensor positions in ENU, m (two-leg names).
        quat_wxyz: ``{sensor: (N, 4)}`` true orientations, sensor → ENU.
        feet: ``{side: FootPlan}`` the planned foot poses and true events.
        gait: True spatio-temporal parameters.
        truth: The calibration.json schema for both legs plus the settings, events and gait.
        models: ``{side: LegModel}`` the true legs (free-flyer root).
        draw: The walk's random choices.
        runtime_s: Wall time of the simulation, s.
        artefacts: What the realism profile did (None without one); with it, ``clean`` holds
            the non-rigid sensors' exact signals and ``trial`` adds the clock, scale and
            misalignment errors as well as noise.
    """

    trial: BilateralTrial
    clean: BilateralTrial
    angles_rad: FloatArray
    positions_m: FloatArray
    ankle_m: dict[str, FloatArray]
    sensor_pos_m: dict[str, FloatArray]
    quat_wxyz: dict[str, FloatArray]
    feet: dict[str, FootPlan]
    gait: GaitTruth
    truth: dict[str, Any]
    models: dict[str, LegModel]
    draw: WalkDraw
    runtime_s: float = 0.0
    artefacts: BilateralArtefactTruth | None = None


def _legs(height_m: float, mass_kg: float, rng: np.random.Generator) -> dict[str, LegModel]:
    """Both template legs with random placements; the right leg gets the left leg's pelvis sensor."""
    geoms = {}
    for side in SIDES:
        g = LegGeometry.from_anthropometry(side, height_m, mass_kg)
        g.sensor_placements = random_placements(g, rng)
        geoms[side] = g
    geoms["right"].sensor_placements["pelvis"] = geoms["left"].sensor_placements["pelvis"].copy()
    return {side: LegModel(g, root_joint=_root_joint()) for side, g in geoms.items()}


def _pelvis_rotation(root_q: FloatArray) -> FloatArray:
    """(N, 3, 3) pelvis → ENU of the composite root joint (heading, then tilt, obliquity, rotation)."""
    return (
        rot_z(root_q[:, 3]) @ R_ENU_SEGMENT0 @ matrix_from_euler_zxy(root_q[:, 4], root_q[:, 5], root_q[:, 6])
    )


def _hip_offsets(legs: dict[str, LegModel]) -> dict[str, FloatArray]:
    """Hip centre in the pelvis frame, per side, m."""
    return {side: leg.geometry.joint_origins["hip"][:3, 3].copy() for side, leg in legs.items()}


def _reach(leg: LegModel, knee_rad: FloatArray) -> FloatArray:
    """Hip–ankle distance (m) at knee flexion ``knee_rad`` (rad), collinear template offsets."""
    g = leg.geometry
    L1 = np.linalg.norm(g.joint_origins["knee"][:3, 3])
    L2 = np.linalg.norm(g.joint_origins["ankle"][:3, 3])
    return np.asarray(np.sqrt(L1**2 + L2**2 + 2 * L1 * L2 * np.cos(knee_rad)))


def _pelvis_root(
    t: FloatArray,
    d: WalkDraw,
    t0: float,
    legs: dict[str, LegModel],
    feet: dict[str, FootPlan],
    path: tuple[FloatArray, FloatArray, FloatArray],
    z_stand: float,
) -> FloatArray:
    """(N, 7) pelvis root coordinates: path + sway, height, heading, tilt, obliquity, rotation.

    The height is periodic at the step frequency (Perry 2010, ch. 17: lowest in double
    support, highest in mid-stance): the highest sum of :data:`PELVIS_HARMONICS` harmonics
    that lets both legs reach their ankles with 1.5 :data:`MIN_WALKING_KNEE_RAD` of knee
    flexion at every sample, with a mean at least a few millimetres below standing (a
    straight leg vaults over the foot: 5 mm of drop already bends the knee by about 10°);
    :data:`MIN_WALKING_KNEE_RAD` is then enforced sample by sample.
    """
    heading, xy, ramp = path
    T = d.stride_time_s
    u = (t - first_contacts(d, t0)["left"]) / T  # left gait phase, 0 at its IC
    left_dir = np.column_stack([-np.sin(heading), np.cos(heading)])
    q = np.zeros((t.size, 7))
    q[:, :2] = xy + (d.sway_m * np.cos(2 * np.pi * (u - MID_STANCE_FRACTION)) * ramp)[:, None] * left_dir
    q[:, 3] = heading
    tilt, obl, rot = np.deg2rad(d.pelvis_deg)
    q[:, 4] = tilt * np.sin(4 * np.pi * u) * ramp
    q[:, 5] = obl * np.sin(2 * np.pi * u + 0.4) * ramp
    q[:, 6] = rot * np.sin(2 * np.pi * u - 0.3) * ramp
    knee_ramp = smoothstep(t, t0, KNEE_RAMP_S)
    z_soft = _highest_pelvis(q, legs, feet, 1.5 * MIN_WALKING_KNEE_RAD * knee_ramp)
    z_hard = _highest_pelvis(q, legs, feet, MIN_WALKING_KNEE_RAD * knee_ramp)
    # leave standing with a high-order contact (the knee angle goes like the square root of the
    # drop), fully lowered before the first step lands
    lower = smoothstep(t, t0, HEIGHT_RAMP_S) ** 2
    walking = lower > 0.999
    basis = _step_harmonics(u)
    coef = _height_wave(z_stand - d.pelvis_drop_m, z_soft[walking], basis[walking])
    z = z_stand - (z_stand - basis @ coef) * lower
    q[:, 2] = np.minimum(z, z_hard)
    return q


def _step_harmonics(u: FloatArray) -> FloatArray:
    """(N, 1 + 2 H) basis: 1, then cos and sin of the first H harmonics of the step frequency.

    ``u`` is the gait phase (strides); a step is half a stride, so the k-th harmonic is
    ``cos(4π k u)``, ``sin(4π k u)``: the same pelvis height under both legs.
    """
    cols = [np.ones_like(u)]
    for k in range(1, PELVIS_HARMONICS + 1):
        cols += [np.cos(4 * np.pi * k * u), np.sin(4 * np.pi * k * u)]
    return np.column_stack(cols)


def _height_wave(highest: float, z_max: FloatArray, basis: FloatArray) -> FloatArray:
    """Coefficients of the highest periodic pelvis height that stays below ``z_max`` (m).

    The linear programme: maximise the mean of ``basis @ c`` subject to
    ``basis @ c ≤ z_max`` at every sample and a mean no higher than ``highest`` (m).
    """
    from scipy.optimize import linprog

    mean_row = basis.mean(axis=0)
    A = np.vstack([basis, mean_row])
    b = np.concatenate([z_max, [highest]])
    res = linprog(-mean_row, A_ub=A, b_ub=b, bounds=[(None, None)] * basis.shape[1], method="highs")
    if not res.success:  # pragma: no cover - the constant min(z_max) is always feasible
        return np.concatenate([[float(z_max.min())], np.zeros(basis.shape[1] - 1)])
    return np.asarray(res.x)


def _highest_pelvis(
    q: FloatArray, legs: dict[str, LegModel], feet: dict[str, FootPlan], knee_rad: FloatArray
) -> FloatArray:
    """(N,) highest pelvis height (m) at which both legs reach their ankles with ≥ ``knee_rad`` flexion."""
    R = _pelvis_rotation(q)
    z_max = np.full(q.shape[0], np.inf)
    for side, hip in _hip_offsets(legs).items():
        h = q[:, :3] + R @ hip  # hip centre with the pelvis at height 0 (q[:, 2] is not used)
        h[:, 2] -= q[:, 2]
        reach = _reach(legs[side], knee_rad)
        r2 = np.sum((feet[side].ankle_m[:, :2] - h[:, :2]) ** 2, axis=1)
        z_max = np.minimum(
            z_max, feet[side].ankle_m[:, 2] + np.sqrt(np.maximum(reach**2 - r2, 0.0)) - h[:, 2]
        )
    return z_max


def _standing(legs: dict[str, LegModel], heading0: float) -> tuple[float, dict[str, FloatArray]]:
    """Pelvis height (m) and ankle centres (ENU, m) of the standing reference posture at the origin."""
    leg = legs["left"]
    h_a = ankle_height_m(leg.geometry.height_m)
    ankles = {}
    for side, lg in legs.items():
        q = np.zeros(lg.model.nq)
        q[3] = heading0
        pin.forwardKinematics(lg.model, lg.data, q)
        ankles[side] = lg.data.oMi[lg.model.getJointId(DOF_NAMES[6])].translation.copy()
    z_stand = h_a - ankles["left"][2]
    for a in ankles.values():
        a[2] += z_stand
    return z_stand, ankles


def _foot_points(leg: LegModel) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Heel, MTP joint centre and toe tip in the foot segment frame (origin: ankle centre), m.

    The sole is ``ankle_height_m`` below the ankle; the heel 22 % of de Leva's foot length
    behind it; the MTP joint and the toe tip as :class:`PreSwingParams` places them.
    """
    pre = PreSwingParams()
    h_a = ankle_height_m(leg.geometry.height_m)
    Lf = leg.geometry.inertias["foot"].length_m
    return (
        np.array([-0.22 * Lf, -h_a, 0.0]),
        np.array([pre.mtp_ahead_fraction * Lf, pre.mtp_height_m - h_a, 0.0]),
        np.array([pre.toe_tip_fraction * Lf, -h_a, 0.0]),
    )


def limb_vibration(
    n: int,
    rate_hz: float,
    walking: FloatArray,
    rms_deg: float | tuple[float, float, float],
    rng: np.random.Generator,
) -> FloatArray:
    """A rigid vibration of one leg's joint angles (N, 9), rad, in the two-leg angle order.

    Band-limited white noise (4–12 Hz, zero-phase Butterworth; below the Nyquist frequency
    when the rate is low), scaled to ``rms_deg`` per angle (one value, or hip, knee, ankle)
    and by ``walking`` (0 standing, 1 walking). The knee moves about its hinge only: its
    adduction and rotation stay zero.

    Args:
        n: number of samples.
        rate_hz: sampling rate, Hz.
        walking: (N,) weight of the vibration, 0–1.
        rms_deg: RMS per angle while walking, degrees (one value, or per joint: hip, knee, ankle).
        rng: the vibration's random stream.
    """
    high = min(12.0, 0.45 * rate_hz)
    sos = butter(4, [4.0, high], btype="band", fs=rate_hz, output="sos")
    x = sosfiltfilt(sos, rng.standard_normal((n, 9)), axis=0)
    per_joint = np.broadcast_to(np.asarray(rms_deg, dtype=float), (3,))
    x *= np.deg2rad(np.repeat(per_joint, 3)) / np.maximum(x.std(axis=0, keepdims=True), 1e-12)
    x[:, 4:6] = 0.0  # knee adduction and rotation: the knee is a hinge
    return np.asarray(x * np.asarray(walking, dtype=float)[:, None])


def _trajectory(t: FloatArray, Q: FloatArray) -> _Trajectories:
    """One leg's configurations ``Q`` (N, 7 + 9) on ``t`` (N,), s, with quintic-spline derivatives."""
    spline = make_interp_spline(t, Q, k=5)
    kin = MotionKinematics(Q[:, 7:], Q[:, 4:7], Q[:, 3], Q[:, :3])
    return _Trajectories(t, np.ones_like(t), kin, Q, spline.derivative(1)(t), spline.derivative(2)(t))


def _leg_signals(
    legs: dict[str, LegModel],
    t: FloatArray,
    rate_hz: float,
    Q: dict[str, FloatArray],
    feet: dict[str, FootPlan],
    ramp: FloatArray,
    art: Artefacts | None,
    rng: np.random.Generator,
) -> tuple[dict[str, _SensorSignals], dict[str, dict[str, TissueMotion]] | None, dict[str, FloatArray]]:
    """Each leg's sensor signals (specific force, gyro, poses), non-rigid with a profile.

    Rigid signals by forward kinematics of the configurations ``Q`` (``{side: (N, 16)}``) on
    ``t`` (N,), s, sampled at ``rate_hz``, Hz;
    with ``art``, each leg's tissue motion (:func:`bilateral_tissue_motion`, draws from
    ``rng``) moves its sensors as in the single-leg simulator (slide, gravity, tilt).

    Returns:
        ``{side: signals}`` (specific force m/s², gyro rad/s, sensor frames), the tissue
        motion (``None`` without a profile) and ``{side: (K,)}`` the impact weights.
    """
    traj = {s: _trajectory(t, Q[s]) for s in SIDES}
    sig = {s: _rigid_signals(legs[s], traj[s], with_alpha=art is not None) for s in SIDES}
    tissue: dict[str, dict[str, TissueMotion]] | None = None
    weights: dict[str, FloatArray] = {}
    if art is not None:
        tissue, weights = bilateral_tissue_motion(art, rate_hz, feet, ramp, traj, sig, rng)
    for s in SIDES:
        _move_sensors(sig[s], traj[s], None, tissue[s] if tissue is not None else None)
    return sig, tissue, weights


def _two_leg(per_leg: dict[str, dict[str, FloatArray]]) -> dict[str, FloatArray]:
    """``{two-leg sensor name: array}`` from ``{side: {sensor: array}}`` (pelvis from the left)."""
    out = {"pelvis": per_leg["left"]["pelvis"]}
    for side in SIDES:
        out |= {f"{side}_{s}": per_leg[side][s] for s in SENSORS[1:]}
    return out


def _measure(
    t: FloatArray,
    clean: BilateralTrial,
    errors: SensorErrors | None,
    noise: ImuNoise,
    rng: np.random.Generator,
    with_mag: bool,
) -> tuple[BilateralTrial, dict[str, FloatArray]]:
    """Measured trial and ``{sensor: (3,)}`` the constant gyro bias added, rad/s.

    The clean signals (sensor frames: m/s², rad/s, µT) read with the clock, scale and
    misalignment ``errors`` (if any), then gyro bias and white noise from ``rng``.
    """
    acc, gyr, mag, bias = {}, {}, {}, {}
    assert clean.mag is not None
    m_acc, m_gyr, m_mag = (
        (clean.acc, clean.gyr, clean.mag)
        if errors is None
        else _apply_errors(t, clean.acc, clean.gyr, clean.mag, errors)
    )
    for s in clean.acc:
        b = rng.normal(size=3)
        bias[s] = noise.gyr_bias_rps * b / np.linalg.norm(b)
        gyr[s] = m_gyr[s] + bias[s] + noise.gyr_std_rps * rng.normal(size=(t.size, 3))
        acc[s] = m_acc[s] + noise.acc_std_mps2 * rng.normal(size=(t.size, 3))
        mag[s] = m_mag[s] + noise.mag_std_ut * rng.normal(size=(t.size, 3))
        acc[s] = acc[s] + noise.acc_bias(rng)
    return BilateralTrial(t.copy(), acc, gyr, mag if with_mag else None), bias


def _magnetometers(
    rot: dict[str, FloatArray],
    pos: dict[str, FloatArray],
    lab_field: LabField | None,
    seed: int,
    extra: tuple[FloatArray, FloatArray] | None = None,
) -> dict[str, FloatArray]:
    """``{sensor: (N, 3)}`` clean field in the sensor frames, µT: uniform, or the lab's.

    The lab's (:mod:`~lowerlimb.simulation.magnetic_field`) dipoles are drawn from their own
    generator, so that the noise of a seed stays the same; ``extra`` adds dipoles
    (positions (K, 3) m, moments (K, 3) A·m²: a treadmill's motor) to either field.
    """
    if lab_field is None and extra is None:
        return {k: np.einsum("nji,j->ni", R, MAG_FIELD_ENU_UT) for k, R in rot.items()}
    grid = (
        dipole_grid(np.vstack(list(pos.values())), lab_field, np.random.default_rng([seed, 17]))
        if lab_field is not None
        else (np.zeros((0, 3)), np.zeros((0, 3)))
    )
    if extra is not None:
        grid = (np.vstack([grid[0], extra[0]]), np.vstack([grid[1], extra[1]]))
    return {
        k: np.einsum("nji,nj->ni", R, field_enu_ut(pos[k], MAG_FIELD_ENU_UT, grid)) for k, R in rot.items()
    }


def _positions(sig: dict[str, _SensorSignals]) -> FloatArray:
    """(N, 15) two-leg positions.csv columns in the pelvis sensor frame, m."""
    Rp = sig["left"].rot["pelvis"]

    def in_pelvis(v: FloatArray) -> FloatArray:
        return np.einsum("nji,nj->ni", Rp, v)

    p2f = {s: in_pelvis(sig[s].pos["foot"] - sig[s].pos["pelvis"]) for s in SIDES}
    h2a = {s: in_pelvis(sig[s].ankle_c - sig[s].hip_c) for s in SIDES}
    return np.hstack([p2f["left"], p2f["right"], h2a["left"], h2a["right"], p2f["right"] - p2f["left"]])


def _pace_changes(d: WalkDraw, rng: np.random.Generator) -> WalkDraw:
    """The walk with a slow change of speed (step length) and step width drawn."""
    return replace(
        d,
        pace_change=rng.uniform(0.15, 0.25),
        pace_hz=1.0 / rng.uniform(90.0, 180.0),
        width_change=rng.uniform(0.2, 0.4),
    )


#: Standing still in the reference posture at the start of a simulated two-leg walk, s (default).
STILL_S = 1.5


def simulate_bilateral(
    duration_s: float = 60.0,
    seed: int = 0,
    *,
    rate_hz: float = 100.0,
    noise: ImuNoise | None = None,
    with_mag: bool = True,
    height_m: float = 1.75,
    mass_kg: float = 75.0,
    still_s: float = STILL_S,
    artefacts: Artefacts | None = None,
    lab_field: LabField | None = LAB_FIELD,
    pace_changes: bool = False,
    pace: str = "normal",
    limb_vibration_deg: float | tuple[float, float, float] = 0.0,
    knee_rotation_per_flexion: float = 0.0,
    stops: PauseParams | None = None,
    treadmill: TreadmillParams | None = None,
    turns: TurnParams | None = None,
) -> BilateralSimulation:
    """Simulate a seven-IMU walk (pelvis, both thighs, shanks and feet) with known truth.

    Args:
        duration_s: Trial length including the initial standing period, s (≥ still_s + 4).
        seed: Seeds placements, the walk and noise.
        rate_hz: Sampling rate, Hz.
        noise: Sensor errors; ``None`` is the realistic default :class:`ImuNoise`.
        with_mag: Include magnetometer columns.
        height_m: Stature for the template (de Leva 1996), m.
        mass_kg: Body mass, kg.
        still_s: Standing still in the reference posture at the start, s.
        artefacts: Realism profile (impacts at each foot's contacts, wobbling soft tissue,
            skin motion, clock and scale errors of all seven sensors,
            :mod:`lowerlimb.simulation.bilateral_artefacts`); ``None`` or
            :meth:`Artefacts.none` gives the rigid signals. Its random draws use their own
            stream, so the placements, walk and noise are those of the rigid simulation.
        lab_field: The magnetometers read the earth's field bent by dipoles under the floor
            (:mod:`lowerlimb.simulation.magnetic_field`: varying by ~15 % at the feet, ~1 %
            at the pelvis, like the real walk's lab); ``None``: one uniform field.
        pace_changes: The walker speeds up and slows down by 15–25 % over 1.5–3 minutes at
            constant cadence (step length follows), and the step width changes by 20–40 %
            (their own random stream: the rest of the walk is the steady one's).
        pace: ``"normal"`` (a healthy adult's self-selected pace, 1.0–1.3 m/s), ``"slow"``
            (0.55–0.85 m/s, longer stance; older adults, clinical studies, the real walk of
            ``gait/``) or ``"shuffle"`` (0.4–0.7 m/s, short strides, a flat contact and a
            weak push-off, as in Parkinson's disease);
            :data:`~lowerlimb.simulation.footsteps.PACE_RANGES`. A seed's other draws are the
            same at every pace.
        limb_vibration_deg: RMS of a rigid 4–12 Hz vibration of every joint angle (hip and
            ankle about all three axes, the knee about its hinge) while walking, degrees, one
            value or one per joint (hip, knee, ankle): the
            limb's own fast motion, which the sensors follow rigidly and the truth's angles
            include (:func:`limb_vibration`; its own random stream). An experiment, not part of
            any profile: it also moves the feet in stance. ``benchmarks/sim_signatures.py``
            shows that it lowers a joint's accelerometer-norm coherence as the real walk's is
            low, while the calibration stays exact.
        knee_rotation_per_flexion: The tibia turns inwards as the knee flexes (rad per rad
            of flexion; 0: an ideal hinge). A real knee's internal rotation spans about 10°
            over a walking stride (Lafortune et al. 1992, J Biomech 25:347–357, bone pins);
            0.2 gives about 11°. The knee is then no hinge: a hinge fit finds an
            axis between the flexion axis and the rotation's, and the knee axis seen from the
            thigh and from the shank sensor differs at standing (3–4° at 0.2; the true knee
            axis in ``truth.json`` stays the flexion axis).
        stops: The walker stops ``stops.count`` times, spread over the walk, and stands still
            in double support for ``stops.pause_s`` (:mod:`lowerlimb.simulation.pauses`; the
            walk is the steady one's, slowed to a halt and started again; ``None``: no stop).
        treadmill: The walker walks straight on a treadmill whose belt carries them back to one
            spot of the lab (:mod:`lowerlimb.simulation.treadmill`: the lab-frame specific
            force while the belt speeds up, the lab's field where the sensors are in the lab
            and the drive motor's); the truth stays in the belt's frame. ``None``: overground.
        turns: The walker walks straight passes and turns about 180° between them, each
            foot pivoting while flat and the hips rotating through the turn
            (:mod:`lowerlimb.simulation.turns`; each turn's direction from its own random
            stream). ``None``: the gently bending path.

    Returns:
        A :class:`BilateralSimulation`.

    Raises:
        InputError: too short a trial, a non-positive rate, an unknown pace, a negative or
            non-finite limb vibration, a non-finite or implausible knee rotation, bad stops or
            stops that do not fit in the walk (:meth:`PauseParams.check_fits`), a bad treadmill,
            stops on a treadmill, bad turns, or turns with stops or a treadmill.
    """
    t_start = time.perf_counter()
    if rate_hz <= 0 or duration_s < still_s + 4.0:
        raise InputError(
            f"a two-leg walk needs at least {still_s + 4.0:g} s and a positive rate; e.g. --duration 60"
        )
    if pace not in PACES:
        raise InputError(f"pace must be one of {', '.join(PACES)}, not {pace!r}")
    vibration = np.atleast_1d(np.asarray(limb_vibration_deg, dtype=float))
    if vibration.size not in (1, 3) or not np.all(np.isfinite(vibration) & (vibration >= 0.0)):
        raise InputError(
            "limb_vibration_deg must be one finite value ≥ 0 or three (hip, knee, ankle), "
            f"not {limb_vibration_deg!r}"
        )
    if not np.isfinite(knee_rotation_per_flexion) or abs(knee_rotation_per_flexion) > 1.0:
        raise InputError(
            f"knee_rotation_per_flexion must be finite and within ±1 rad/rad (0.2: about 11° over a stride), "
            f"not {knee_rotation_per_flexion!r}"
        )
    if stops is not None:
        stops.validate()
        stops.check_fits(duration_s, still_s)
    if treadmill is not None:
        treadmill.validate()
        if stops is not None and stops.count:
            raise InputError("a simulated treadmill walk has no stops; drop stops or treadmill")
    if turns is not None:
        turns.validate()
        if treadmill is not None or (stops is not None and stops.count):
            raise InputError("a simulated walk with turns has no stops and no treadmill; drop one of them")
    noise = ImuNoise() if noise is None else noise
    rng = np.random.default_rng(seed)
    art = artefacts if artefacts is not None and artefacts.active else None
    art_rng = np.random.default_rng([seed, 9] if art is None or art.seed is None else art.seed)
    legs = _legs(height_m, mass_kg, rng)
    d = draw_walk(rng, pace)
    if pace_changes:
        d = _pace_changes(d, np.random.default_rng([seed, 11]))
    if treadmill is not None or turns is not None:
        d = straight(d)
    t = np.arange(int(round(duration_s * rate_hz))) / rate_hz
    t0 = still_s
    z_stand, stand = _standing(legs, d.heading0_rad)
    pivot = turns is not None and turns.pivot
    turn_signs = np.random.default_rng([seed, 23]).choice([-1.0, 1.0], size=int(duration_s) + 3)

    def plan(tau: FloatArray) -> tuple[tuple[FloatArray, FloatArray, FloatArray], dict[str, FootPlan]]:
        path = pelvis_path(tau, d, t0) if turns is None else turnaround_path(tau, d, t0, turns, turn_signs)
        return path, {
            s: plan_feet(s, d, tau, t0, (path[0], path[1]), stand[s], _foot_points(legs[s]), pivot=pivot)
            for s in SIDES
        }

    path, feet = plan(t)
    tau = t  # the plan time of each sample (stops: lowerlimb.simulation.pauses)
    if stops is not None and stops.count:
        freeze = pause_plan_times({s: f.events for s, f in feet.items()}, t0, float(t[-1]), stops.count)
        tau = paused_time(t, freeze, stops)
        path, feet = plan(tau)
    root = _pelvis_root(tau, d, t0, legs, feet, path, z_stand)
    if tau is not t:
        feet = {s: replace(f, events=warped_events(f.events, t, tau)) for s, f in feet.items()}
    ramp = smoothstep(tau, t0, d.stride_time_s)
    Q = {}
    for s in SIDES:
        u = (tau - first_contacts(d, t0)[s]) / d.stride_time_s
        hip_rot = np.deg2rad(d.hip_rotation_deg) * np.sin(2 * np.pi * u - 0.8) * ramp
        if turns is not None:
            toe_out = d.toe_out_rad[SIDES.index(s)]
            hip_rot = hip_rot + hip_turn_rotation(feet[s].rotation, path[0], s, toe_out, ramp)
        angles = solve_leg(
            legs[s],
            root,
            hip_rot,
            feet[s].ankle_m,
            feet[s].rotation,
            knee_rotation_per_flexion=knee_rotation_per_flexion,
        )
        Q[s] = np.hstack([root, angles])
    if np.any(np.asarray(limb_vibration_deg) > 0.0):
        vib_rng = np.random.default_rng([seed, 13])
        for s in SIDES:
            Q[s][:, 7:] += limb_vibration(t.size, rate_hz, ramp, limb_vibration_deg, vib_rng)
    sig, tissue, weights = _leg_signals(legs, t, rate_hz, Q, feet, ramp, art, art_rng)
    acc = _two_leg({s: sig[s].acc for s in SIDES})
    gyr = _two_leg({s: sig[s].gyr for s in SIDES})
    rot = _two_leg({s: sig[s].rot for s in SIDES})
    pos = _two_leg({s: sig[s].pos for s in SIDES})
    motor = None
    if treadmill is not None:
        travel = belt_travel(path[1])
        acc = lab_specific_force(acc, rot, t, travel)
        pos = lab_positions(pos, travel, treadmill)
        motor = motor_dipole(pos["pelvis"], d.heading0_rad, treadmill, np.random.default_rng([seed, 19]))
    mag = _magnetometers(rot, pos, lab_field, seed, motor)
    clean = BilateralTrial(t.copy(), acc, gyr, mag)
    errors = draw_sensor_errors(art, t.size, art_rng, tuple(acc)) if art is not None else None
    trial, bias = _measure(t, clean, errors, noise, rng, with_mag)
    ankle = {s: sig[s].ankle_c for s in SIDES}
    gt = gait_truth({s: feet[s].events for s in SIDES}, ankle, t)
    models = {s: LegModel(legs[s].geometry) for s in SIDES}
    truth = _truth(models, d, gt, bias, seed, rate_hz, duration_s, height_m, mass_kg, noise, feet)
    if treadmill is not None:
        truth["treadmill"] = asdict(treadmill)
    if turns is not None:
        starts = turn_starts(turns, t0, float(tau[-1]))
        truth["turns"] = {
            **asdict(turns),
            "start_s": [float(np.interp(x, tau, t)) for x in starts],
            "direction": ["left" if g > 0 else "right" for g in turn_signs[: starts.size]],
        }
    art_truth = None
    if art is not None and errors is not None and tissue is not None:
        base_pl = {s: sig[s].base_pl for s in SIDES}
        art_truth = bilateral_artefact_truth(art, errors, feet, weights, tissue, base_pl)
        truth["artefacts"] = art_truth.to_dict()
    return BilateralSimulation(
        trial=trial,
        clean=clean,
        angles_rad=np.hstack([Q["left"][:, 7:], Q["right"][:, 7:]]),
        positions_m=_positions(sig),
        ankle_m=ankle,
        sensor_pos_m=_two_leg({s: sig[s].pos for s in SIDES}),
        quat_wxyz={k: quat_make_continuous(quat_from_matrix(R)) for k, R in rot.items()},
        feet=feet,
        gait=gt,
        truth=truth,
        models=models,
        draw=d,
        runtime_s=time.perf_counter() - t_start,
        artefacts=art_truth,
    )


def _truth(
    models: dict[str, LegModel],
    d: WalkDraw,
    gt: GaitTruth,
    bias: dict[str, FloatArray],
    seed: int,
    rate_hz: float,
    duration_s: float,
    height_m: float,
    mass_kg: float,
    noise: ImuNoise,
    feet: dict[str, FootPlan],
) -> dict[str, Any]:
    """The two-leg calibration.json schema of the true legs, plus settings, events and gait."""
    legs = {}
    for s, m in models.items():
        cal = m.calibration_dict("truth")
        legs[s] = {"joints": cal["joints"], "urdf": m.to_urdf_string()}
    return {
        "format": "lowerlimb-calibration/1",
        "layout": "two_legs",
        "method": "truth",
        "legs": legs,
        "motion": "walk",
        "seed": seed,
        "rate_hz": rate_hz,
        "duration_s": duration_s,
        "height_m": height_m,
        "mass_kg": mass_kg,
        "noise": noise.to_dict(),
        "gyr_bias": {k: v.tolist() for k, v in bias.items()},
        "events": {
            s: {
                "initial_contact_s": f.events.initial_contact_s.tolist(),
                "toe_off_s": f.events.toe_off_s.tolist(),
                "foot_flat_s": f.events.foot_flat_s.tolist(),
            }
            for s, f in feet.items()
        },
        "gait": gt.to_dict(),
        "walk": {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.__dict__.items()},
    }
