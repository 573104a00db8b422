import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.conventions import (
    JOINT_SENSORS,
    quat_conjugate,
    quat_multiply,
    quat_to_matrix,
    quat_to_rotvec,
)
from lowerlimb.errors import InputError
from lowerlimb.simulation import MOTIONS, ImuNoise, simulate

SENSORS = ("pelvis", "thigh", "shank", "foot")


@pytest.fixture(scope="module", params=[False, True], ids=["rigid", "soft-tissue"])
def fast_sim(request):
    # a high rate so that finite differences are an exact enough referee
    return simulate("walk", 6.0, 5, rate_hz=500.0, noise=ImuNoise.none(), soft_tissue=request.param)


def test_accelerometer_matches_double_difference_of_positions(fast_sim):
    dt = 1.0 / 500.0
    for s in SENSORS:
        p = fast_sim.sensor_pos_m[s]
        a_world = (p[2:] - 2 * p[1:-1] + p[:-2]) / dt**2
        R = quat_to_matrix(fast_sim.quat_wxyz[s])[1:-1]
        f = np.einsum("nji,nj->ni", R, a_world - np.array([0.0, 0.0, -9.81]))
        rms = np.sqrt(np.mean((f - fast_sim.clean.acc[s][1:-1]) ** 2))
        assert rms < 0.05, (s, rms)


def test_gyro_matches_differentiated_orientation(fast_sim):
    dt = 1.0 / 500.0
    for s in SENSORS:
        q = fast_sim.quat_wxyz[s]
        w = quat_to_rotvec(quat_multiply(quat_conjugate(q[:-2]), q[2:])) / (2 * dt)
        rms = np.sqrt(np.mean((w - fast_sim.clean.gyr[s][1:-1]) ** 2))
        assert rms < 0.01, (s, rms)


def test_sensor_at_rest_reads_plus_g_along_up(walk_clean):
    for s in SENSORS:
        f = walk_clean.clean.acc[s][:50]
        up = np.einsum("nij,nj->ni", quat_to_matrix(walk_clean.quat_wxyz[s][:50]), f)
        assert np.allclose(up, [0.0, 0.0, 9.81], atol=1e-9)
        assert np.allclose(walk_clean.clean.gyr[s][:50], 0.0, atol=1e-9)


def test_joint_centre_acceleration_agrees_between_sensors():
    """Truth is self-consistent: a_S + ω×(ω×c_S) + α×c_S, rotated to the earth, is one vector."""
    sim = simulate("knee-lift", 6.0, 2, rate_hz=500.0, noise=ImuNoise.none(), side="right")
    dt = 1.0 / 500.0
    for joint, (parent, child, _) in JOINT_SENSORS.items():
        acc_world = []
        for s, key in ((parent, "center_in_parent_sensor"), (child, "center_in_child_sensor")):
            c = np.array(sim.truth["joints"][joint][key])
            w = sim.clean.gyr[s]
            alpha = np.gradient(w, dt, axis=0)
            a = sim.clean.acc[s] + np.cross(w, np.cross(w, c)) + np.cross(alpha, c)
            acc_world.append(np.einsum("nij,nj->ni", quat_to_matrix(sim.quat_wxyz[s]), a))
        err = np.linalg.norm(acc_world[0] - acc_world[1], axis=1)[5:-5]
        assert np.sqrt(np.mean(err**2)) < 0.02, joint
    # the knee axis is the same physical direction from both sensors
    knee = sim.truth["joints"]["knee"]
    a_t = np.einsum("nij,j->ni", quat_to_matrix(sim.quat_wxyz["thigh"]), knee["axis_in_parent_sensor"])
    a_s = np.einsum("nij,j->ni", quat_to_matrix(sim.quat_wxyz["shank"]), knee["axis_in_child_sensor"])
    assert np.max(np.linalg.norm(a_t - a_s, axis=1)) < 1e-9


@pytest.mark.parametrize("motion", MOTIONS)
def test_every_motion_is_plausible(motion):
    sim = cached_simulation(motion, 12.0, 7, noise=ImuNoise.none())
    deg = np.rad2deg(sim.angles_rad)
    assert np.allclose(deg[:100], 0.0)  # standing reference posture first
    assert deg[:, 3].max() > 40.0  # the knee bends
    assert deg[:, 3].min() > -1.0  # and never hyper-extends
    assert np.allclose(deg[:, 4:6], 0.0)  # the simulated knee is a pure hinge
    for s in SENSORS:
        assert np.max(np.linalg.norm(sim.clean.gyr[s], axis=1)) < 15.0
    # sensors sit 3–35 cm from their joints
    for joint in ("hip", "knee", "ankle"):
        for key in ("center_in_parent_sensor", "center_in_child_sensor"):
            d = np.linalg.norm(sim.truth["joints"][joint][key])
            assert 0.03 < d < 0.35, (joint, key, d)


def test_noise_statistics_and_bias():
    sim = cached_simulation("walk", 20.0, 0)
    clean = cached_simulation("walk", 20.0, 0, noise=ImuNoise.none())
    for s in SENSORS:
        d = sim.trial.gyr[s] - clean.clean.gyr[s]
        # same seed, same motion: the difference is bias + white noise
        assert np.allclose(d.mean(axis=0), sim.gyr_bias_rps[s], atol=0.002)
        assert np.linalg.norm(sim.gyr_bias_rps[s]) == pytest.approx(0.01)
        assert np.std(d - d.mean(axis=0)) == pytest.approx(0.015, rel=0.05)


def test_seed_reproducible_and_bad_motion():
    a = simulate("squat", 3.0, 11)
    b = simulate("squat", 3.0, 11)
    assert np.array_equal(a.trial.acc["foot"], b.trial.acc["foot"])
    with pytest.raises(InputError, match="unknown motion 'jog'"):
        simulate("jog", 3.0)
