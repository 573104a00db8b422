"""An accelerometer that reads a norm far from gravity at rest is named (its bias moves the centres)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.rest_gravity import (
    AccelerometerOffsetWarning,
    rest_gravity_notes,
    rest_gravity_offsets,
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
