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
    trial runs (no side refusal) and no knee is mirrored (> 20 deg), on the recorded clocks
    and re-timed. Seed 201's right knee lands in a hinge minimum 17.5 deg off that costs less
    than the one 3.8 deg off: re-timed (the profile offsets the clocks by σ 10 ms; the knee's
    starts fall into other basins once the thigh and shank move 20 ms against the pelvis), and
    on the recorded clocks since its 4.5-4.9 deg knee axis mismatch at standing no longer
    keeps it in the coherent band (the rigidity threshold went from 2 to 6 deg: a real knee
    that turns as it flexes shows 3-4 deg on rigid sensors, gait_knee_rotation.md). Seed 202
    keeps both knee axes within 12 deg on the recorded clocks."""
    from lowerlimb.bilateral import process_bilateral_trial
    from lowerlimb.calibration.options import CalibrationOptions
    from lowerlimb.simulation.artefacts import Artefacts
    from lowerlimb.simulation.bilateral_walk import simulate_bilateral

    sim = simulate_bilateral(60.0, seed, artefacts=Artefacts.real_walk())
    for sync, limit in ((False, 12.0 if seed == 202 else 20.0), (True, 20.0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = process_bilateral_trial(sim.trial, calibration_options=CalibrationOptions(clock_sync=sync))
        for side in ("left", "right"):
            est = np.asarray(res.calibration_dict()["legs"][side]["joints"]["knee"]["axis_in_parent_sensor"])
            tru = np.asarray(sim.truth["legs"][side]["joints"]["knee"]["axis_in_parent_sensor"])
            assert est @ tru > np.cos(np.radians(limit)), (side, sync)
