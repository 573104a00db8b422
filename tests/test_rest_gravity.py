"""An accelerometer that reads a norm far from gravity at rest is named (its bias moves the centres)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.calibration import LegCalibration, calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.rest_gravity import (
    AccelerometerOffsetWarning,
    rest_gravity_notes,
    rest_gravity_offsets,
    vertical_offsets_removed,
)
from lowerlimb.errors import InputError
from lowerlimb.pipeline import process_trial
from lowerlimb.simulation import ImuNoise


def test_offsets_are_the_rest_norm_minus_gravity_and_only_large_ones_are_named() -> None:
    still = slice(0, 100)
    up = np.array([0.6, 0.0, 0.8])
    acc = {"pelvis": np.tile(9.81 * up, (200, 1)), "thigh": np.tile(10.11 * up, (200, 1))}
    acc["thigh"][100:] = 0.0  # moving samples do not count
    off = rest_gravity_offsets(acc, still)
    assert off["pelvis"] == pytest.approx(0.0, abs=1e-12) and off["thigh"] == pytest.approx(0.30)
    notes = rest_gravity_notes(off, 0.2)
    assert len(notes) == 1 and "thigh accelerometer reads 10.11 m/s² at rest, +0.30" in notes[0]
    assert not rest_gravity_notes(off, 0.5)


def test_a_biased_accelerometer_is_warned_and_a_clean_one_is_not() -> None:
    sim = cached_simulation("walk", 20.0, 0, noise=ImuNoise.none())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        process_trial(sim.trial)
    assert not [w for w in caught if w.category is AccelerometerOffsetWarning]
    # 0.3 m/s² along the shank sensor's standing vertical: a 3 % scale error
    a = sim.trial.acc["shank"]
    up = a[:50].mean(axis=0) / np.linalg.norm(a[:50].mean(axis=0))
    biased = replace(sim.trial, acc=sim.trial.acc | {"shank": a + 0.3 * up})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        process_trial(biased)
    named = [str(w.message) for w in caught if w.category is AccelerometerOffsetWarning]
    assert len(named) == 1 and "the shank accelerometer reads 10.11 m/s² at rest, +0.30" in named[0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        process_trial(biased, calibration_options=CalibrationOptions(rest_gravity_warn_mps2=None))
    assert not [w for w in caught if w.category is AccelerometerOffsetWarning]


def test_the_option_is_checked() -> None:
    with pytest.raises(InputError, match="rest_gravity_warn_mps2"):
        CalibrationOptions(rest_gravity_warn_mps2=0.0)


def test_the_removal_takes_off_the_rest_offset_along_the_vertical_only() -> None:
    rng = np.random.default_rng(0)
    up = np.array([0.6, 0.0, 0.8])
    a = np.tile(10.11 * up, (300, 1))
    a[100:] += rng.normal(size=(200, 3))  # the motion after the standing start
    out, off = vertical_offsets_removed({"thigh": a}, slice(0, 100))
    assert off["thigh"] == pytest.approx(0.30)
    assert np.linalg.norm(out["thigh"][:100].mean(axis=0)) == pytest.approx(9.81)
    np.testing.assert_allclose(out["thigh"] - a, np.tile(-0.30 * up, (300, 1)), atol=1e-12)


def test_the_calibration_records_the_offsets_it_removed() -> None:
    sim = cached_simulation("walk", 20.0, 0, noise=ImuNoise.none())
    a = sim.trial.acc["shank"]
    up = a[:50].mean(axis=0) / np.linalg.norm(a[:50].mean(axis=0))
    biased = replace(sim.trial, acc=sim.trial.acc | {"shank": a + 0.3 * up})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        off = calibrate_leg(biased)
        on = calibrate_leg(biased, options=CalibrationOptions(rest_gravity_correction=True))
    # both record the offsets; only the option takes them off the signals
    assert off.rest_gravity_offsets["shank"] == pytest.approx(0.30, abs=0.005)
    assert not off.rest_gravity_removed and on.rest_gravity_removed
    assert on.rest_gravity_offsets["shank"] == pytest.approx(0.30, abs=0.005)
    assert not np.allclose(on.hip.center_in_child_sensor, off.hip.center_in_child_sensor, atol=1e-9)
    assert abs(on.rest_gravity_offsets["thigh"]) < 0.005  # noise-free: the others read 9.81
    again = LegCalibration.from_dict(on.to_dict())
    assert again.rest_gravity_offsets == pytest.approx(on.rest_gravity_offsets)
    assert again.rest_gravity_removed
