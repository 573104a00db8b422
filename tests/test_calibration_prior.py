"""The weak anthropometric prior on the hip (thigh sensor) and ankle (shank sensor) centres."""

import warnings

import numpy as np
import pytest

from lowerlimb.calibration import calibrate_leg
from lowerlimb.calibration.leg import leg_priors
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.segment_prior import center_prior, segment_up
from lowerlimb.errors import InputError
from lowerlimb.simulation import simulate_bilateral


def test_segment_up_is_gravity_made_orthogonal_to_the_axis() -> None:
    up = segment_up([0.5, 9.8, 0.3], [0.0, 0.0, 1.0])
    assert up is not None
    assert np.allclose(up, np.array([0.5, 9.8, 0.0]) / np.hypot(0.5, 9.8))
    assert segment_up([0.0, 0.1, 9.8], [0.0, 0.0, 1.0]) is None  # axis along gravity


def test_center_prior_mean_and_spreads() -> None:
    j, u = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])
    p = center_prior(
        [0.02, 0.05, 0.3], j, u, -0.4, std_along_m=0.05, std_across_m=0.03, std_axis_m=0.06, on_child=False
    )
    # the knee centre's place along the axis is a gauge: dropped from the mean
    assert np.allclose(p.mean, [0.02, 0.05 - 0.4, 0.0])
    cov = np.linalg.inv(p.sqrt_info.T @ p.sqrt_info)
    assert np.allclose(np.sqrt(np.diag(cov)), [0.03, 0.05, 0.06])
    r, J = p.rows(np.r_[p.mean, np.zeros(3)], 2.0)
    assert np.allclose(r, 0.0) and np.allclose(J[:, 3:], 0.0) and np.allclose(J[:, :3], 2.0 * p.sqrt_info)
    assert set(p.to_dict()) == {"on", "mean", "std_m"}


def test_prior_options_are_checked() -> None:
    with pytest.raises(InputError, match="prior_std_along"):
        CalibrationOptions(prior_std_along=0.0)


@pytest.fixture(scope="module")
def walk_leg():
    sim = simulate_bilateral(20.0, 3)
    return sim.trial.leg("right"), sim.truth["legs"]["right"]["joints"]


def test_priors_on_a_simulated_walk_lie_near_the_truth(walk_leg) -> None:
    trial, truth = walk_leg
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(trial, options=CalibrationOptions(anthropometric_prior=False))
    n = int(round(cal.still_s * trial.rate_hz))
    hip, ankle = leg_priors(cal.knee, trial.acc, n, CalibrationOptions())
    assert hip is not None and ankle is not None and hip.on_child and not ankle.on_child
    for prior, true in (
        (hip, truth["hip"]["center_in_child_sensor"]),
        (ankle, truth["ankle"]["center_in_parent_sensor"]),
    ):
        # within three standard deviations of the prior, in its own metric
        assert np.linalg.norm(prior.sqrt_info @ (prior.mean - np.asarray(true))) < 3.0 * np.sqrt(3.0)
    assert leg_priors(cal.knee, trial.acc, 0, CalibrationOptions()) == (None, None)


def test_prior_is_recorded_and_can_be_switched_off(walk_leg) -> None:
    trial, _ = walk_leg
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        on = calibrate_leg(trial)
        off = calibrate_leg(trial, options=CalibrationOptions(anthropometric_prior=False))
    assert set(on.to_dict()["anthropometric_prior"]) == {"hip", "ankle", "knee_line"}
    assert off.to_dict()["anthropometric_prior"] == {}
    # the knee is not touched by the prior
    assert np.allclose(on.knee.axis_in_parent_sensor, off.knee.axis_in_parent_sensor)
