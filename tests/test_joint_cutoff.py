"""One prefilter cut-off per joint: both sensors see the joint through the same filter."""

from __future__ import annotations

import numpy as np
import pytest

from lowerlimb.calibration.joint_cutoff import joint_cutoffs_hz
from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.simulation import simulate_bilateral

OPTS = CalibrationOptions()


def test_the_joint_takes_the_higher_cut_off():
    assert joint_cutoffs_hz(4.4, 7.0, None, OPTS) == (7.0, 7.0)
    assert joint_cutoffs_hz(7.0, 4.4, None, OPTS) == (7.0, 7.0)


def test_an_unfiltered_sensor_leaves_the_joint_unfiltered():
    assert joint_cutoffs_hz(4.4, None, None, OPTS) == (None, None)


def test_the_rigid_band_cap_applies_before_sharing():
    # the child reaches far above the cap (> rigid_band_trigger × cap): capped to 5 Hz, then shared
    assert joint_cutoffs_hz(4.0, 30.0, 5.0, OPTS) == (5.0, 5.0)
    # within the trigger: kept, and shared
    assert joint_cutoffs_hz(4.0, 12.0, 5.0, OPTS) == (12.0, 12.0)


def test_each_sensor_keeps_its_own_cut_off_when_asked():
    own = CalibrationOptions(shared_joint_cutoff=False)
    assert joint_cutoffs_hz(4.4, 7.0, None, own) == (4.4, 7.0)


@pytest.fixture(scope="module")
def walk():
    return simulate_bilateral(20.0, 201)


@pytest.mark.parametrize("side", ["left", "right"])
def test_noisy_two_leg_walk_finds_the_hip_in_the_thigh(walk, side):
    # Realistic gyro noise makes the pelvis's noise-limited cut-off (4.4 Hz) lower than
    # the thigh's (7 Hz); filtered apart, the hip in the thigh sensor was 87 mm (left)
    # and 220 mm (right) off the truth while reporting about ±12 mm.
    cal = calibrate_leg(walk.trial.leg(side), options=CalibrationOptions(center_std_tol_m=np.inf))
    true = np.asarray(walk.truth["legs"][side]["joints"]["hip"]["center_in_child_sensor"])
    err = float(np.linalg.norm(cal.hip.center_in_child_sensor - true))
    spread = float(np.linalg.norm(cal.hip.center_std_in_child_sensor))
    assert err < 0.02
    # the remaining error is the simulator's non-rigid contact instants, which no spread
    # from the residual sees; it stays within a few reported standard deviations
    assert err < 4.0 * spread
