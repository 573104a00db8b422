"""Huber weights of the spherical residual (the optional robust spherical fit)."""

from __future__ import annotations

import numpy as np
import pytest

from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.robust_weights import huber_weights
from lowerlimb.errors import InputError
from lowerlimb.simulation import simulate_bilateral


def test_outliers_are_weighted_down_and_inliers_kept():
    rng = np.random.default_rng(0)
    r = rng.normal(size=1000)
    r[:10] = 50.0
    w = huber_weights(r, 1.345)
    assert np.all(w[:10] < 0.05)
    assert np.mean(w[10:] == 1.0) > 0.8
    assert np.all((w > 0) & (w <= 1))


def test_the_floor_keeps_noise_free_residuals_unweighted():
    assert np.all(huber_weights(np.full(100, 1e-9), 1.345, floor=0.1) == 1.0)


def test_options_refuse_a_non_positive_threshold():
    with pytest.raises(InputError):
        CalibrationOptions(huber_k=0.0)


def test_robust_fit_ignores_the_simulated_contacts_at_the_ankle():
    # the seven-IMU simulator's kinematics kink at heel strike and toe-off, where the
    # rigid constraint fails by several m/s²; least squares lets those samples decide
    sim = simulate_bilateral(20.0, 201)
    truth = np.asarray(sim.truth["legs"]["left"]["joints"]["ankle"]["center_in_parent_sensor"])
    errs = {}
    for robust in (False, True):
        opts = CalibrationOptions(robust=robust, impact_exclusion=False, center_std_tol_m=np.inf)
        cal = calibrate_leg(sim.trial.leg("left"), options=opts)
        errs[robust] = float(np.linalg.norm(cal.ankle.center_in_parent_sensor - truth))
    assert errs[True] < 0.015
    assert errs[True] < 0.5 * errs[False]
