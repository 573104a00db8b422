"""The cut-off probe: a systematic spread of the hip and ankle centres, recorded beside the noise one."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from lowerlimb.calibration import calibrate_leg
from lowerlimb.calibration.cutoff_probe import cutoff_shift_message, probe_options
from lowerlimb.calibration.leg import LegCalibration
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.errors import InputError
from lowerlimb.simulation import simulate_bilateral
from lowerlimb.viz.report import _joint_table


def test_probe_options_widen_every_cutoff_and_stay_quiet() -> None:
    o = CalibrationOptions(cutoff_probe_factor=2.0)
    w = probe_options(o)
    assert w.cutoff_factor == 2 * o.cutoff_factor and w.rigid_band_factor == 2 * o.rigid_band_factor
    assert w.center_std_tol_m == np.inf
    assert probe_options(CalibrationOptions(cutoff_hz=4.0)).cutoff_hz == pytest.approx(6.0)
    with pytest.raises(InputError, match="cutoff_probe_factor"):
        CalibrationOptions(cutoff_probe_factor=1.0)


@pytest.fixture(scope="module")
def walk():
    sim = simulate_bilateral(20.0, 201)
    return sim.trial.leg("left"), sim.truth["legs"]["left"]["joints"]


def test_shift_sees_the_systematic_error_the_spread_does_not(walk) -> None:
    """Simulated walk, norm form: the hip in the pelvis sensor is centimetres off with a
    spread of millimetres; the cut-off shift is of the error's size. (The default takes that
    centre from the aligned form, which the shift does not describe; and it fits this rigid
    walk in a widened band, where the error is smaller: the coherent band shows it.)"""
    trial, truth = walk
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(trial, options=CalibrationOptions(hip_in_pelvis_form="norm", fit_band_factor=1.0))
    hip = cal.hip
    err = np.linalg.norm(hip.center_in_parent_sensor - np.asarray(truth["hip"]["center_in_parent_sensor"]))
    std = np.linalg.norm(hip.center_std_in_parent_sensor)
    shift = np.linalg.norm(hip.cutoff_shift[:3])
    assert err > 3 * std  # the noise spread misses the error
    assert shift > 3 * std and err < 4 * shift  # the shift is of its size
    assert np.all(np.isfinite(cal.ankle.cutoff_shift))
    # recorded, read back, shown in the report
    d = cal.to_dict()
    assert len(d["joints"]["hip"]["center_cutoff_shift_in_parent_sensor"]) == 3
    back = LegCalibration.from_dict(d)
    assert np.allclose(back.hip.cutoff_shift, hip.cutoff_shift)
    assert "(cut-off:" in _joint_table(d)


def test_probe_can_be_switched_off_and_changes_no_estimate(walk) -> None:
    trial, _ = walk
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        on = calibrate_leg(trial)
        off = calibrate_leg(trial, options=CalibrationOptions(cutoff_probe=False))
    assert np.all(np.isnan(off.hip.cutoff_shift))
    assert "center_cutoff_shift_in_parent_sensor" not in off.to_dict()["joints"]["hip"]
    assert np.allclose(on.hip.center_in_parent_sensor, off.hip.center_in_parent_sensor)
    assert np.allclose(on.ankle.center_in_child_sensor, off.ankle.center_in_child_sensor)


def test_a_long_trial_is_probed_on_every_kth_sample(walk) -> None:
    """The shift barely depends on thinning (20 s walk: 55.7 mm on all 2000 samples, 55.6 on 700)."""
    from lowerlimb.constraints.spherical import SphericalData

    trial, _ = walk
    shifts = []
    for most in (6000, 700):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            opts = CalibrationOptions(hip_in_pelvis_form="norm", cutoff_probe_max_samples=most)
            shifts.append(np.linalg.norm(calibrate_leg(trial, options=opts).hip.cutoff_shift[:3]))
    assert shifts[0] > 0.02 and abs(shifts[1] - shifts[0]) < 0.2 * shifts[0], shifts
    z = np.zeros((10, 3))
    d = SphericalData(z, z, z, z, z, z, gyr_noise_parent=0.5).subsample(3)
    assert d.acc_parent.shape == (4, 3) and d.gyr_noise_parent == 0.5
    with pytest.raises(InputError, match="cutoff_probe_max_samples"):
        CalibrationOptions(cutoff_probe_max_samples=10)


def test_the_aligned_sides_of_the_hip_are_not_recorded(walk) -> None:
    """The probe refits the norm form: the hip in the pelvis sensor that the aligned form
    places by default gets no shift (it was the norm form's, 47–110 mm on simulated walks
    whose aligned centre is 4–10 mm off); with the whole hip aligned, neither side does."""
    trial, _ = walk
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        default = calibrate_leg(trial)
        whole = calibrate_leg(trial, options=CalibrationOptions(centre_form="aligned"))
    hip = default.hip
    assert np.all(np.isnan(hip.cutoff_shift[:3])) and np.all(np.isfinite(hip.cutoff_shift[3:]))
    assert np.all(np.isnan(hip.split_half_shift[:3])) and np.all(np.isfinite(hip.split_half_shift[3:]))
    d = default.to_dict()["joints"]["hip"]
    assert (
        "center_cutoff_shift_in_parent_sensor" not in d and len(d["center_cutoff_shift_in_child_sensor"]) == 3
    )
    back = LegCalibration.from_dict(default.to_dict()).hip
    assert np.allclose(back.cutoff_shift, hip.cutoff_shift, equal_nan=True)
    assert np.all(np.isnan(whole.hip.cutoff_shift)) and np.all(np.isnan(whole.hip.split_half_shift))
    assert np.all(np.isfinite(whole.ankle.cutoff_shift))


def test_a_centre_the_filter_decides_is_warned_about(walk) -> None:
    trial, _ = walk
    quiet = cutoff_shift_message(_hip(walk), 1.0)
    assert quiet is None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = calibrate_leg(trial, options=CalibrationOptions(cutoff_shift_warn_m=1e-4))
    said = [str(w.message) for w in caught]
    for joint in ("hip: the centre in the thigh", "ankle: the centre in the"):
        assert any(m.startswith(joint) and "mm when the low-pass cut-offs" in m for m in said), said
    assert any("widened by half" in w for w in cal.ankle.warnings)
    largest = cal.ankle.largest_shift(cal.ankle.cutoff_shift)
    assert largest is not None and largest[1] == pytest.approx(
        max(np.linalg.norm(cal.ankle.cutoff_shift[:3]), np.linalg.norm(cal.ankle.cutoff_shift[3:]))
    )
    assert cal.hip.largest_shift(np.full(6, np.nan)) is None
    with pytest.raises(InputError, match="cutoff_shift_warn_m"):
        CalibrationOptions(cutoff_shift_warn_m=0.0)


def _hip(walk):
    trial, _ = walk
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate_leg(trial).hip
