"""A short or a tall subject calibrated without their height: the data, not the prior, decide.

``calibrate`` defaults to a 1.75 m subject (``--height``), which scales the anthropometric
prior on the hip and ankle centres and the plausible length range. A 1.55 m and a 1.95 m
walker simulated and calibrated at the default height must come out as with their own height
and near the truth. Measured (30 s walks, seeds 3 and 4): lengths within 0.2 mm of the
own-height calibration and within 3 mm of the truth.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from simcache import cached_simulation, true_leg

from lowerlimb import process_trial
from lowerlimb.model.fallback import segment_lengths


@pytest.mark.parametrize(("height_m", "seed"), [(1.55, 3), (1.95, 4)])
def test_a_subject_of_another_height_calibrated_at_the_default(height_m, seed):
    sim = cached_simulation("walk", 30.0, seed, height_m=height_m)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        default = process_trial(sim.trial)
        own = process_trial(sim.trial, height_m=height_m)
    truth = np.array(segment_lengths(true_leg(sim.truth["joints"])))  # type: ignore[arg-type]
    at_default = np.array(segment_lengths(default.calibration))
    np.testing.assert_allclose(at_default, segment_lengths(own.calibration), atol=0.002)
    np.testing.assert_allclose(at_default, truth, atol=0.012)
    # the simulated legs really are short or long (de Leva: thigh 24 % of stature)
    assert abs(truth[0] - 0.2425 * height_m) < 0.03
