"""The rigid band is sought where the sensors rotate as usual: a fast turn is rotation, not soft tissue."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from simcache import true_leg

from lowerlimb.bilateral.process import process_bilateral_trial
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.constraints.prefilter import rigid_band_hz
from lowerlimb.conventions import SIDES
from lowerlimb.errors import InputError
from lowerlimb.model.fallback import segment_lengths
from lowerlimb.simulation.bilateral_walk import simulate_bilateral
from lowerlimb.simulation.turns import TurnParams

RATE = 100.0


def _norms_with_a_burst(seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two accelerometers that move together (1–8 Hz) but for a 2 s burst of unlike 5–10 Hz
    content, and gyros that spin fast during the burst only."""
    rng = np.random.default_rng(seed)
    n = int(60 * RATE)
    t = np.arange(n) / RATE
    common = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 6)) for f in np.arange(1.0, 8.0, 0.5))
    acc_p = np.column_stack([common, 0.1 * rng.normal(size=n), 9.81 + 0.0 * t])
    acc_c = acc_p + np.column_stack([0.1 * rng.normal(size=n), 0.1 * rng.normal(size=n), 0.0 * t])
    burst = (t > 30.0) & (t < 32.0)
    for acc in (acc_p, acc_c):
        acc[burst, 0] += 20 * sum(np.sin(2 * np.pi * f * t[burst] + rng.uniform(0, 6)) for f in range(5, 11))
    gyr = np.column_stack([np.sin(2 * np.pi * t), 0.0 * t, 0.0 * t, np.sin(2 * np.pi * t), 0.0 * t, 0.0 * t])
    gyr[burst, 2] = gyr[burst, 5] = 8.0  # a spin about the vertical
    return acc_p, acc_c, gyr


def test_a_burst_of_rotation_is_left_out_of_the_coherence():
    acc_p, acc_c, gyr = _norms_with_a_burst()
    with_burst = rigid_band_hz(acc_p, acc_c, RATE)
    assert with_burst is not None and with_burst < 8.0  # the burst's unlike content ends the band
    assert rigid_band_hz(acc_p, acc_c, RATE, gyr=gyr, max_rotation=4.0) is None  # coherent without it
    assert rigid_band_hz(acc_p, acc_c, RATE, gyr=gyr, max_rotation=None) == with_burst


def test_the_rule_needs_a_factor_above_one():
    with pytest.raises(InputError, match="rigid_band_max_rotation must be > 1 or None"):
        CalibrationOptions(rigid_band_max_rotation=0.5)


def test_fast_turns_leave_rigid_legs_their_lengths():
    sim = simulate_bilateral(40.0, 201, turns=TurnParams(turn_s=0.6))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = process_bilateral_trial(sim.trial)
    for side in SIDES:
        true = segment_lengths(true_leg(sim.truth["legs"][side]["joints"]))
        est = segment_lengths(res.legs[side].calibration)
        assert np.max(np.abs(np.subtract(est, true))) < 0.01  # were 57 / 41 mm short (thigh / shank)
