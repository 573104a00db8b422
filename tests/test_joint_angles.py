"""Segment frames, heading correction, ISB angles and FK positions against the simulator's truth."""

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.calibration import LegCalibration
from lowerlimb.conventions import SENSORS, quat_rotate
from lowerlimb.model.calibrated import calibrated_geometry, chain_positions, knee_center_pair
from lowerlimb.model.leg_model import LegModel
from lowerlimb.s2j.relative_position import segment_relative_positions
from lowerlimb.segments.heading import relative_heading, rotate_about_vertical
from lowerlimb.segments.tracking import track_segments
from lowerlimb.simulation import ImuNoise


def _pipeline(sim, quats, **kw):
    tr = sim.trial
    motion = track_segments(
        quats,
        tr.acc,
        tr.gyr,
        LegCalibration.from_dict(sim.truth),
        rate_hz=tr.rate_hz,
        reference=tr.reference_samples(),
        side=tr.side,
        **kw,
    )
    model = LegModel(calibrated_geometry(LegCalibration.from_dict(sim.truth), motion.frames))
    return (
        motion.angles_rad,
        chain_positions(model, motion.angles_rad),
        motion.sensor_quat_wxyz,
        motion.frames,
    )


@pytest.mark.parametrize("side", ["left", "right"])
def test_true_inputs_give_true_angles_and_positions(side):
    sim = cached_simulation("walk", 15.0, 4, side=side, noise=ImuNoise.none())
    angles, pos, _, _ = _pipeline(sim, sim.quat_wxyz, range_of_motion_prior=False)
    assert np.max(np.abs(angles - sim.angles_rad)) < np.deg2rad(0.01)
    assert np.max(np.abs(pos - sim.positions_m)) < 1e-4


@pytest.mark.parametrize(
    "motion, offset_rad, mag",
    [("walk", np.pi, False), ("knee-lift", 0.03, True), ("squat", 0.03, True), ("sit-to-stand", 0.03, True)],
)
def test_heading_offsets_and_drift_are_removed(motion, offset_rad, mag):
    """Each sensor's heading is off by a random angle (6-axis: plus a drift of 3°/min): the joints fix it.

    6-axis (any offset, drifting) on walking; on the motions with a planted foot
    or a still pelvis the heading is observable only with a magnetometer, whose
    filters share one heading up to small, constant disagreements.
    """
    sim = cached_simulation(motion, 30.0, 5, noise=ImuNoise.none())
    rng = np.random.default_rng(2)
    t = sim.trial.time_s
    quats = {
        s: sim.quat_wxyz[s]
        if s == "pelvis"
        else rotate_about_vertical(
            sim.quat_wxyz[s], rng.uniform(-offset_rad, offset_rad) + (not mag) * np.deg2rad(3.0 / 60) * t
        )
        for s in SENSORS
    }
    angles, pos, _, _ = _pipeline(sim, quats, shared_heading=mag)
    rmse = np.rad2deg(np.sqrt(np.mean((angles - sim.angles_rad) ** 2, axis=0)))
    assert np.all(rmse < 1.5), rmse
    assert np.sqrt(np.mean(np.sum((pos[:, :3] - sim.positions_m[:, :3]) ** 2, axis=1))) < 0.005


def test_relative_heading_recovers_a_known_rotation():
    rng = np.random.default_rng(0)
    u = rng.normal(size=(2000, 3))
    delta = 0.7 + 0.2 * np.sin(np.linspace(0, 3, 2000))
    v = quat_rotate(rotate_about_vertical(np.tile([1.0, 0, 0, 0], (2000, 1)), -delta), u)
    est = relative_heading(u, v + 0.05 * rng.normal(size=v.shape), rate_hz=100.0, window_s=0.5)
    assert np.max(np.abs(est - delta)[100:-100]) < 0.02


def test_fk_positions_equal_lee_eq_2_3():
    """Pinocchio FK of the calibrated chain equals the NumPy eq. 2–3 with constant S2J vectors."""
    sim = cached_simulation("knee-lift", 10.0, 6, noise=ImuNoise.none())
    _, pos, qc, _ = _pipeline(sim, sim.quat_wxyz)
    j = sim.truth["joints"]
    c_knee_t, c_knee_s = knee_center_pair(LegCalibration.from_dict(sim.truth))
    s2j = {
        "hip": (np.array(j["hip"]["center_in_parent_sensor"]), np.array(j["hip"]["center_in_child_sensor"])),
        "knee": (c_knee_t, c_knee_s),
        "ankle": (
            np.array(j["ankle"]["center_in_parent_sensor"]),
            np.array(j["ankle"]["center_in_child_sensor"]),
        ),
    }
    ref = segment_relative_positions(s2j, qc)["pelvis_foot"]
    assert np.max(np.abs(ref - pos[:, :3])) < 1e-9


def test_time_varying_s2j_through_pinocchio_equals_eq_2_3():
    """Per-sample placement updates in Pinocchio reproduce eq. 2–3 with time-varying S2J vectors."""
    sim = cached_simulation("squat", 8.0, 8, noise=ImuNoise.none())
    angles, _, qc, frames = _pipeline(sim, sim.quat_wxyz)
    model = LegModel(calibrated_geometry(LegCalibration.from_dict(sim.truth), frames))
    n = len(angles)
    rng = np.random.default_rng(0)
    j = sim.truth["joints"]
    s2j = {}
    for joint in ("hip", "knee", "ankle"):
        wobble = 0.01 * np.sin(np.linspace(0, 6, n))[:, None] * rng.normal(size=(2, 3))[:, None, :]
        s2j[joint] = (
            np.array(j[joint]["center_in_parent_sensor"]) + wobble[0],
            np.array(j[joint]["center_in_child_sensor"]) + wobble[1],
        )
    pos = chain_positions(model, angles, s2j)
    ref = segment_relative_positions(s2j, qc)["pelvis_foot"]
    assert np.max(np.abs(ref - pos[:, :3])) < 1e-6
    # the model is left as it was
    assert np.allclose(chain_positions(model, angles[:5]), chain_positions(model, angles[:5], None))
