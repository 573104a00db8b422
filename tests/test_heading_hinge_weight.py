"""The knee's hinge-axis heading term against the shared magnetic heading (segments.heading)."""

import numpy as np

from lowerlimb.calibration import LegCalibration
from lowerlimb.segments.heading import correct_headings, rotate_about_vertical
from lowerlimb.segments.tracking import MAG_HEADING_WEIGHT
from lowerlimb.simulation import simulate


def test_a_drifting_shank_heading_is_pulled_back_by_the_knee_axis_despite_the_magnetometer():
    sim = simulate("walk", 30.0, seed=5)
    t = sim.trial.time_s
    cal = LegCalibration.from_dict(sim.truth)
    quats = {s: q.copy() for s, q in sim.quat_wxyz.items()}
    drift = np.deg2rad(4.0) * t / t[-1]  # a residual gyro bias: 4 deg over the trial
    quats["shank"] = rotate_about_vertical(quats["shank"], drift)
    quats["foot"] = rotate_about_vertical(quats["foot"], drift)
    _, corr = correct_headings(
        quats, sim.trial.acc, sim.trial.gyr, cal, sim.trial.rate_hz, common_heading_weight=MAG_HEADING_WEIGHT
    )
    knee = corr.joint_delta_rad["knee"]
    late = t > 0.75 * t[-1]
    # the knee correction undoes most of the drift (a magnetometer-weighted unit-vector term
    # at weight 1 undid about a tenth of it)
    residual = np.rad2deg(np.abs(knee[late] + drift[late]))
    assert np.median(residual) < 1.0


def test_edge_transients_do_not_turn_the_heading() -> None:
    """The first and last 1/LOWPASS_HZ s of the joint accelerations are the low-pass's edge
    transient: a spike there must not turn the estimated relative heading."""
    import numpy as np

    from lowerlimb.segments.heading import relative_heading

    rate = 100.0
    t = np.arange(3000) / rate
    v = np.column_stack([np.cos(2.0 * t), np.sin(1.3 * t), np.zeros_like(t)])
    turn = np.deg2rad(10.0)
    R = np.array([[np.cos(turn), -np.sin(turn), 0.0], [np.sin(turn), np.cos(turn), 0.0], [0.0, 0.0, 1.0]])
    u = v @ R.T  # u = R_z(10°) v: the heading that turns v onto u is 10°
    spiked_u = u.copy()
    spiked_u[-3:] = [[-30.0, 40.0, 0.0]] * 3  # a heel strike at the very end, tens of m/s²
    spiked_u[:2] = [[25.0, -20.0, 0.0]] * 2
    clean = np.rad2deg(relative_heading(u, v, rate))
    spiked = np.rad2deg(relative_heading(spiked_u, v, rate))
    assert np.allclose(clean, 10.0, atol=0.5)
    assert np.max(np.abs(spiked - clean)) < 0.01


def test_the_field_seen_from_both_sensors_sets_their_relative_heading():
    """A filter's slow magnetic loop leaves a sensor's heading off (residual gyro bias / gain);
    the field measured by both sensors says by how much, the filters' headings do not."""
    sim = simulate("walk", 30.0, seed=5)
    assert sim.trial.mag is not None
    cal = LegCalibration.from_dict(sim.truth)
    offset = np.deg2rad(5.0)
    quats = {s: q.copy() for s, q in sim.quat_wxyz.items()}
    for s in ("thigh", "shank", "foot"):  # the thigh filter's heading sits 5° off; the chain below follows
        quats[s] = rotate_about_vertical(quats[s], np.full(len(sim.trial.time_s), offset))
    args = (quats, sim.trial.acc, sim.trial.gyr, cal, sim.trial.rate_hz)
    _, with_field = correct_headings(*args, common_heading_weight=MAG_HEADING_WEIGHT, mag=sim.trial.mag)
    _, trusting = correct_headings(*args, common_heading_weight=MAG_HEADING_WEIGHT)
    # every child is 5° off its corrected parent, so every joint's correction should be −5°
    for joint in ("hip", "knee", "ankle"):
        err_field = np.rad2deg(np.abs(with_field.joint_delta_rad[joint] + offset))
        err_trust = np.rad2deg(np.abs(trusting.joint_delta_rad[joint] + offset))
        assert np.median(err_field) < 0.5, joint
        assert np.median(err_trust) > 2.0, joint


def test_a_field_the_two_sensors_do_not_share_is_not_used():
    """Near iron the child's field has another dip and magnitude: its direction is not the
    parent's north, and the term falls back to the filters' own headings."""
    from lowerlimb.segments.heading import FIELD_DIP_SD_DEG, field_agreement

    n = 500
    field = np.tile([0.0, 20.0, -45.0], (n, 1))  # µT, earth frame: north and down
    assert np.allclose(field_agreement(field, field), 1.0)
    tilt = np.deg2rad(3 * FIELD_DIP_SD_DEG)  # the child's field dips 3 SD further
    R = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(tilt), np.sin(tilt)], [0.0, -np.sin(tilt), np.cos(tilt)]])
    assert np.all(field_agreement(field, field @ R.T) < 0.02)
    assert np.all(field_agreement(field, 1.2 * field) < 0.02)
    assert np.all(field_agreement(field, 1.02 * field) > 0.8)

    sim = simulate("walk", 20.0, seed=5)
    assert sim.trial.mag is not None
    cal = LegCalibration.from_dict(sim.truth)
    args = (sim.quat_wxyz, sim.trial.acc, sim.trial.gyr, cal, sim.trial.rate_hz)
    disturbed = dict(sim.trial.mag)
    disturbed["thigh"] = 1.5 * disturbed["thigh"] + np.array([0.0, 0.0, 30.0])
    _, with_field = correct_headings(*args, common_heading_weight=MAG_HEADING_WEIGHT, mag=disturbed)
    _, trusting = correct_headings(*args, common_heading_weight=MAG_HEADING_WEIGHT)
    np.testing.assert_allclose(with_field.joint_delta_rad["hip"], trusting.joint_delta_rad["hip"], atol=1e-3)


def test_calibration_json_says_how_far_the_field_set_the_headings():
    import warnings

    import lowerlimb as ll

    sim = simulate("walk", 12.0, seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nine = ll.process_trial(sim.trial)
        six = ll.process_trial(sim.trial, use_mag=False)
    assert nine.used_mag
    agreement = nine.calibration_dict()["magnetic_field_agreement"]
    assert set(agreement) == {"hip", "knee", "ankle"}
    assert all(0.8 < a <= 1.0 for a in agreement.values())  # the simulator's field is one field
    assert "magnetic_field_agreement" not in six.calibration_dict()
    from lowerlimb.outputs import residual_lines

    line = [x for x in residual_lines(nine.calibration_dict()) if x.startswith("magnetometer fused")]
    assert len(line) == 1 and f"hip {100 * agreement['hip']:.0f} %" in line[0]
    assert not any(x.startswith("magnetometer") for x in residual_lines(six.calibration_dict()))
    from lowerlimb.viz.report import _magnetometer_note

    assert f"hip {100 * agreement['hip']:.0f} %" in _magnetometer_note(nine.calibration_dict())
    assert _magnetometer_note(six.calibration_dict()) == ""
