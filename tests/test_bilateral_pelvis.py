"""One pelvis for two legs (lowerlimb.bilateral.pelvis): the shared frame and the joint hip centres.

Synthetic cases with known answers (the errors seen on the real walk: single-leg hip
centres off vertically and laterally, knee axes turned and tilted mirror-wise), then
two simulated legs sharing one pelvis (``bilateral_sim``).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from bilateral_sim import simulate_two_legs

from lowerlimb.bilateral.pelvis import OppositeKneesError, joint_hip_centers, pelvis_frame, shared_pelvis
from lowerlimb.bilateral.process import process_bilateral_trial
from lowerlimb.calibration import LegCalibration
from lowerlimb.conventions import SIDES


def _rot(axis: str, deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def _deg(u: np.ndarray, v: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1, 1))))


#: A sacral sensor tilted 60° about the lateral axis and turned 10° (pelvis frame in the sensor).
R_TRUE = _rot("z", 60.0) @ _rot("y", 10.0)
#: True hip centres in pelvis-frame coordinates from the sensor (sensor 1 cm right of the mid-line).
HIPS = {"left": np.array([0.12, -0.09, -0.10]), "right": np.array([0.12, -0.09, 0.08])}


def test_pelvis_frame_is_right_handed_with_up_and_a_horizontal_right_axis():
    R = pelvis_frame(np.array([0.1, 2.0, 0.3]), np.array([0.2, 0.5, 1.0]))
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) > 0
    assert abs(R[:, 2] @ np.array([0.1, 2.0, 0.3])) < 1e-12


def test_joint_hips_remove_the_asymmetric_error_and_the_widening():
    # single-leg errors like the real walk: 8 and 22 cm too high, 3 cm too lateral each,
    # reported standard deviations of a few millimetres
    err = {"left": np.array([0.0, 0.08, -0.03]), "right": np.array([0.01, 0.22, 0.03])}
    obs = {s: R_TRUE @ (HIPS[s] + err[s]) for s in SIDES}
    std = {s: np.array([0.01, 0.004, 0.003]) for s in SIDES}
    single = float(np.linalg.norm(obs["right"] - obs["left"]))
    j = joint_hip_centers(obs, std, R_TRUE, expected_spacing_m=0.17)
    p = {s: R_TRUE.T @ j.center_in_pelvis_sensor_m[s] for s in SIDES}
    d = p["right"] - p["left"]
    assert abs(d[0]) < 0.01 and abs(d[1]) < 0.01  # mirror-symmetric
    assert abs(j.spacing_m - 0.18) < 0.02 < abs(single - 0.18)
    assert p["right"][2] > 0 > p["left"][2]
    assert all(np.all(j.std_in_pelvis_m[s] > 0) for s in SIDES)


def test_joint_hips_keep_good_data():
    obs = {s: R_TRUE @ HIPS[s] for s in SIDES}
    std = {s: np.full(3, np.nan) for s in SIDES}  # unknown: the model error alone
    j = joint_hip_centers(obs, std, R_TRUE, expected_spacing_m=0.18)
    for s in SIDES:
        np.testing.assert_allclose(j.center_in_pelvis_sensor_m[s], obs[s], atol=1e-9)


def test_shared_frame_cancels_mirrored_knee_axis_errors():
    # each leg's own pelvis z (its knee axis at standing): toe-out 25° and a 20° tilt, mirrored
    knee = {
        "left": R_TRUE @ _rot("y", 25.0) @ _rot("x", 20.0) @ np.array([0.0, 0.0, 1.0]),
        "right": R_TRUE @ _rot("y", -25.0) @ _rot("x", -20.0) @ np.array([0.0, 0.0, 1.0]),
    }
    # hip centres: good anterior/lateral, bad and asymmetric vertical
    obs = {s: R_TRUE @ (HIPS[s] + np.array([0.0, 0.1 if s == "right" else 0.0, 0.0])) for s in SIDES}
    std = {s: np.array([0.01, 0.004, 0.003]) for s in SIDES}
    up = R_TRUE @ np.array([0.0, 9.81, 0.0])
    sp = shared_pelvis(obs, std, knee, up, height_m=1.75)
    assert sp.legs_axes_angle_deg > 50
    assert _deg(sp.R_sensor_pelvis[:, 2], R_TRUE[:, 2]) < 1.0
    assert _deg(sp.R_sensor_pelvis[:, 1], R_TRUE[:, 1]) < 1e-6
    assert 0.0 < sp.hip_line_weight < 1.0
    assert sp.to_dict()["hip_spacing_m"] == sp.hips.spacing_m


def test_opposite_knee_axes_are_refused_with_their_angle():
    # a mirrored leg: its "right" knee axis points left; the mean of the two axes vanishes
    z = R_TRUE @ np.array([0.0, 0.0, 1.0])
    obs = {s: R_TRUE @ HIPS[s] for s in SIDES}
    std = {s: np.full(3, 0.01) for s in SIDES}
    up = R_TRUE @ np.array([0.0, 9.81, 0.0])
    with pytest.raises(OppositeKneesError, match="point 180° apart") as e:
        shared_pelvis(obs, std, {"left": z, "right": -z}, up, height_m=1.75)
    assert e.value.angle_deg == pytest.approx(180.0)
    tilted = R_TRUE @ _rot("y", 100.0) @ np.array([0.0, 0.0, 1.0])  # 100° apart: still a pelvis
    sp = shared_pelvis(obs, std, {"left": z, "right": tilted}, up, height_m=1.75)
    assert np.all(np.isfinite(sp.R_sensor_pelvis))


def test_two_simulated_legs_share_the_hips_and_keep_zero_at_standing():
    sim = simulate_two_legs()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = process_bilateral_trial(sim.trial)
        own = process_bilateral_trial(sim.trial, one_pelvis=False)
    assert res.pelvis is not None and own.pelvis is None
    n = sim.trial.time_s.size  # the first pass skips the positions only when the pelvis stage redoes them
    assert all(r.legs[s].positions_m.shape == (n, 6) for r in (res, own) for s in SIDES)
    # the joint hip centres feed the positions; each leg's angles stay zero at the standing
    # reference (docs/conventions.md), so each keeps its own pelvis segment frame
    still = sim.trial.time_s < 1.0
    for s in SIDES:
        assert np.abs(np.rad2deg(res.legs[s].angles_rad[still, :3])).max() < 1.0
    truth = {s: LegCalibration.from_dict(sim.sims[s].truth) for s in SIDES}
    c_true = {s: np.asarray(truth[s].hip.center_in_parent_sensor) for s in SIDES}
    spacing_true = float(np.linalg.norm(c_true["right"] - c_true["left"]))
    assert abs(res.pelvis.hips.spacing_m - spacing_true) < 0.03
    # the shared right axis is along the true hip line (the simulated pelvis is symmetric)
    line_true = c_true["right"] - c_true["left"]
    assert _deg(res.pelvis.R_sensor_pelvis[:, 2], line_true) < 8.0
    for s in SIDES:  # the legs otherwise as before: the other joints untouched
        np.testing.assert_allclose(
            res.legs[s].calibration.knee.axis_in_parent_sensor,
            own.legs[s].calibration.knee.axis_in_parent_sensor,
        )
        np.testing.assert_allclose(
            res.legs[s].calibration.hip.center_in_parent_sensor, res.pelvis.hips.center_in_pelvis_sensor_m[s]
        )
    d = res.calibration_dict()
    assert d["pelvis"]["hip_spacing_m"] == res.pelvis.hips.spacing_m
    assert d["legs"]["left"]["joints"]["hip"]["center_in_parent_sensor"] == list(
        res.pelvis.hips.center_in_pelvis_sensor_m["left"]
    )
