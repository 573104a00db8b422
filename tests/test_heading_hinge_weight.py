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
