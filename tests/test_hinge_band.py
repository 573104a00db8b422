"""The band-limited witness of the hinge fit (calibration.hinge_band) and the two-leg side cue."""

import warnings

import numpy as np
import pytest

from lowerlimb.calibration.hinge_band import axes_disagreement_deg, band_limited_gyros
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.errors import InputError


def test_disagreement_is_sign_blind_and_takes_the_worse_sensor():
    x, y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    tilt = np.array([np.cos(0.1), np.sin(0.1), 0.0])
    assert axes_disagreement_deg((x, y), (-x, -y)) == pytest.approx(0.0, abs=1e-6)
    assert axes_disagreement_deg((x, y), (tilt, y)) == pytest.approx(np.degrees(0.1))


def test_no_band_without_a_cutoff_below_the_signal_band():
    w = np.random.default_rng(0).normal(size=(500, 3))
    assert band_limited_gyros(w, w, 100.0, None) is None
    assert band_limited_gyros(w, w, 100.0, 45.0) is None
    wp, wc = band_limited_gyros(w, w, 100.0, 4.0)
    assert wp.shape == w.shape and np.std(wp) < 0.5 * np.std(w)


def test_band_options_are_checked():
    with pytest.raises(InputError, match="hinge_band_hz"):
        CalibrationOptions(hinge_band_hz=0.0)
    with pytest.raises(InputError, match="hinge_band_max_disagreement_deg"):
        CalibrationOptions(hinge_band_max_disagreement_deg=-1.0)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [201, 202])
def test_wobbling_sensors_neither_mirror_a_knee_nor_swap_the_hips(seed):
    """Simulated walks with the real-walk artefact profile: the wobble once drew the knee
    axes 20-40 deg off (three of twelve mirrored) and both hips onto the wrong side; the
    trial runs (no side refusal) and both knee axes stay within 12 deg."""
    from lowerlimb.bilateral import process_bilateral_trial
    from lowerlimb.simulation.artefacts import Artefacts
    from lowerlimb.simulation.bilateral_walk import simulate_bilateral

    sim = simulate_bilateral(60.0, seed, artefacts=Artefacts.real_walk())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = process_bilateral_trial(sim.trial)
    for side in ("left", "right"):
        est = np.asarray(res.calibration_dict()["legs"][side]["joints"]["knee"]["axis_in_parent_sensor"])
        tru = np.asarray(sim.truth["legs"][side]["joints"]["knee"]["axis_in_parent_sensor"])
        assert est @ tru > np.cos(np.radians(12.0)), side
