"""The split-half probe: how far the hip and ankle centres move between the recording's halves."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.calibration import calibrate_leg
from lowerlimb.calibration.leg import LegCalibration
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.results import SphericalJointCalibration
from lowerlimb.calibration.split_half import half_masks, split_half_message
from lowerlimb.errors import InputError
from lowerlimb.io.trial import ImuTrial
from lowerlimb.viz.report import _joint_table


def test_halves_split_the_kept_moving_samples_and_share_the_still_start() -> None:
    keep = np.ones(100, dtype=bool)
    keep[60:70] = False
    first, second = half_masks(100, keep, 10)
    assert np.all(first[:10] & second[:10])  # the still start in both
    moving = [np.count_nonzero(m[10:]) for m in (first, second)]
    assert moving == [40, 40] and not np.any(first[10:] & second[10:])
    assert not np.any((first | second)[60:70])  # the main fit's left-out samples stay out
    a, b = half_masks(7, None, 0)
    assert np.count_nonzero(a) + np.count_nonzero(b) == 7


def _joint(shift_mm: list[float]) -> SphericalJointCalibration:
    return SphericalJointCalibration(
        "hip", "pelvis", "thigh", np.zeros(3), np.zeros(3), 0.0, split_half_shift=np.array(shift_mm) / 1000
    )


def test_the_warning_names_the_frame_that_moved_and_skips_unprobed_ones() -> None:
    assert split_half_message(_joint([0, 0, 0, 0, 20, 0]), 0.03) is None
    msg = split_half_message(_joint([np.nan] * 3 + [0, 40, 0]), 0.03)
    assert msg is not None and "in the thigh sensor frame moves by ±40 mm" in msg
    assert "record a longer trial" in msg
    assert split_half_message(_joint([np.nan] * 6), 0.03) is None
    with pytest.raises(InputError, match="split_half_warn_m"):
        CalibrationOptions(split_half_warn_m=0.0)


def test_a_restrapped_sensor_is_seen_and_a_steady_walk_is_not() -> None:
    """Two walks, the sensors re-strapped between them (other placements): each half pins its
    own centres, and half their difference is what the probe reports."""
    a, b = cached_simulation("walk", 20.0, 1), cached_simulation("walk", 20.0, 2)
    n = a.trial.n_samples
    both = ImuTrial(
        np.arange(2 * n) / a.trial.rate_hz,
        {s: np.vstack([a.trial.acc[s], b.trial.acc[s]]) for s in a.trial.acc},
        {s: np.vstack([a.trial.gyr[s], b.trial.gyr[s]]) for s in a.trial.gyr},
    )
    with warnings.catch_warnings(record=True) as steady_w:
        warnings.simplefilter("always")
        steady = calibrate_leg(a.trial)
    with warnings.catch_warnings(record=True) as moved_w:
        warnings.simplefilter("always")
        moved = calibrate_leg(both)
    assert np.all(np.isnan(steady.hip.split_half_shift[:3]))  # the aligned form places that centre
    assert np.linalg.norm(steady.hip.split_half_shift[3:]) < 0.005
    assert np.linalg.norm(steady.ankle.split_half_shift) < 0.01
    assert not [w for w in steady_w if "second half" in str(w.message)]
    true_half = 0.5 * np.subtract(
        b.truth["joints"]["hip"]["center_in_child_sensor"], a.truth["joints"]["hip"]["center_in_child_sensor"]
    )
    assert np.linalg.norm(moved.hip.split_half_shift[3:] - true_half) < 0.03
    said = [str(w.message) for w in moved_w if "second half" in str(w.message)]
    assert any(m.startswith("hip: the centre in the thigh sensor frame") for m in said)
    # recorded, read back, shown in the report
    d = moved.to_dict()
    assert "center_split_half_shift_in_parent_sensor" not in d["joints"]["hip"]
    back = LegCalibration.from_dict(d)
    assert np.allclose(back.hip.split_half_shift[3:], moved.hip.split_half_shift[3:])
    assert np.all(np.isnan(back.hip.split_half_shift[:3]))
    assert "(halves:" in _joint_table(d)
    quiet = calibrate_leg(a.trial, options=CalibrationOptions(split_half_probe=False))
    assert np.all(np.isnan(quiet.hip.split_half_shift))
    assert np.allclose(quiet.hip.center_in_child_sensor, steady.hip.center_in_child_sensor)
