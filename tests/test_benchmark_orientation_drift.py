"""The drift study's scoring (benchmarks/orientation_drift.py) on errors put in by hand."""

import sys
from pathlib import Path

import numpy as np
import pytest

from lowerlimb.conventions import quat_multiply, quat_normalize

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from orientation_drift import axis_errors  # noqa: E402


def _about(axis: int, deg: float) -> np.ndarray:
    q = np.zeros(4)
    q[0] = np.cos(np.radians(deg) / 2)
    q[1 + axis] = np.sin(np.radians(deg) / 2)
    return q


@pytest.fixture
def truth() -> np.ndarray:
    return quat_normalize(np.random.default_rng(0).normal(size=(200, 4)))


def test_axis_errors_recovers_known_earth_frame_errors(truth: np.ndarray) -> None:
    # first half: 2° about east (pitch); second half: 3° about up (yaw)
    err = np.array([_about(0, 2.0)] * 100 + [_about(2, -3.0)] * 100)
    est = quat_multiply(err, truth)
    e = axis_errors(est, truth)
    assert e["rmse_pitch_deg"] == pytest.approx(np.sqrt(2.0), abs=1e-9)
    assert e["rmse_yaw_deg"] == pytest.approx(np.sqrt(4.5), abs=1e-9)
    assert e["rmse_roll_deg"] == pytest.approx(0.0, abs=1e-9)
    assert e["max_pitch_deg"] == pytest.approx(2.0, abs=1e-9)
    assert e["max_yaw_deg"] == pytest.approx(3.0, abs=1e-9)
    assert e["max_euler_deg"] == pytest.approx(3.0, abs=1e-9)
    assert e["rmse_total_deg"] == pytest.approx(np.sqrt(6.5), abs=1e-9)


def test_axis_errors_mask_and_heading_offset(truth: np.ndarray) -> None:
    # a constant 30° heading offset plus 1° about north on the scored samples
    err = quat_multiply(_about(2, 30.0), _about(1, 1.0))
    est = quat_multiply(np.broadcast_to(err, truth.shape), truth)
    est[:50] = truth[:50] * np.array([1.0, 1.0, -1.0, 1.0])  # garbage outside the mask
    mask = np.arange(len(truth)) >= 50
    e = axis_errors(est, truth, mask, remove_heading_offset=True)
    assert e["heading_offset_deg"] == pytest.approx(30.0, abs=1e-3)
    assert e["max_yaw_deg"] < 1e-3
    assert e["max_roll_deg"] == pytest.approx(1.0, abs=1e-3)
    assert e["samples"] == 150
