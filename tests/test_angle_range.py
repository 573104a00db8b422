"""Joint angles whose median while moving no leg holds are flagged, naming the angle."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from simcache import cached_simulation

import lowerlimb as ll
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.segments.angle_range import AngleRangeParams, ImplausibleAnglesWarning, implausible_angles
from lowerlimb.simulation import ImuNoise


def _walk_like(hip_rotation_deg: float, standing: int = 0, moving: int = 500):
    """Angles (N, 9) and shank rates (N, 3): ``standing`` still zero samples, then moving ones."""
    n = standing + moving
    angles = np.zeros((n, 9))
    t = np.arange(moving) / 100.0
    angles[standing:, 0] = np.deg2rad(20.0 + 20.0 * np.sin(2 * np.pi * t))  # hip flexion
    angles[standing:, 3] = np.deg2rad(30.0 + 30.0 * np.sin(2 * np.pi * t))  # knee flexion
    angles[standing:, 2] = np.deg2rad(hip_rotation_deg)
    gyr = np.zeros((n, 3))
    gyr[standing:, 2] = 3.0
    return angles, gyr


def test_a_walk_in_range_is_not_flagged():
    assert implausible_angles(*_walk_like(5.0)) == []


def test_a_rotated_hip_is_named_with_its_median_and_limits():
    (msg,) = implausible_angles(*_walk_like(-80.0))
    assert msg.startswith("the hip internal rotation is -80° while the leg moves (median)")
    assert "beyond the -30…+30° a leg holds" in msg
    assert "\n" not in msg


def test_standing_periods_do_not_hide_the_walk():
    """Zero at standing by construction: two thirds of the trial standing still."""
    angles, gyr = _walk_like(-80.0, standing=1000, moving=500)
    assert len(implausible_angles(angles, gyr)) == 1
    assert np.median(np.rad2deg(angles[:, 2])) == 0.0


def test_too_little_motion_is_not_judged():
    angles, gyr = _walk_like(-80.0, moving=20)
    assert implausible_angles(angles, gyr) == []
    assert implausible_angles(angles, gyr, AngleRangeParams(min_samples=10)) != []


def test_a_moving_knee_does_not_sit_hyperextended():
    angles, gyr = _walk_like(0.0)
    angles[:, 3] = np.deg2rad(-15.0)
    (msg,) = implausible_angles(angles, gyr)
    assert "knee flexion is -15°" in msg


@pytest.fixture(scope="module")
def walk():
    return cached_simulation("walk", 20.0, 0, noise=ImuNoise.none()).trial


def test_the_pipeline_warns_when_the_sign_check_is_off(walk):
    """The foot's accelerometer negated: its frame turns the wrong way about the vertical."""
    acc = dict(walk.acc)
    acc["foot"] = -acc["foot"]
    options = CalibrationOptions(check_signs=False)
    with pytest.warns(ImplausibleAnglesWarning, match="ankle internal rotation"):
        ll.process_trial(dataclasses.replace(walk, acc=acc), calibration_options=options)


def test_a_clean_walk_gives_no_angle_warning(walk):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ll.process_trial(walk)
    assert not [w for w in caught if w.category is ImplausibleAnglesWarning]
