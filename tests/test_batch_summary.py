"""The study tables' per-task and per-subject summaries over one- and two-leg trials."""

from __future__ import annotations

import math

import pytest

from lowerlimb.batch.summary import LENGTH_COLUMNS, RANGE_COLUMNS, group_summary


def _one_leg(knee: float) -> dict[str, object]:
    return {
        "status": "ok",
        "task": "walk",
        "subject": "s01",
        "knee_flexion_range_deg": knee,
        "thigh_length_mm": 400.0,
    }


def _two_legs(left: float, right: float) -> dict[str, object]:
    # batch.csv's two-leg row: each leg's ranges under a prefix, the lengths also as the legs' mean
    return {
        "status": "warning",
        "task": "walk",
        "subject": "s01",
        "knee_flexion_range_deg": "",
        "left_knee_flexion_range_deg": left,
        "right_knee_flexion_range_deg": right,
        "thigh_length_mm": 410.0,
        "left_thigh_length_mm": 400.0,
        "right_thigh_length_mm": 420.0,
    }


def test_a_two_leg_trial_counts_in_its_task_with_the_mean_of_its_legs():
    (row,) = group_summary([_one_leg(60.0), _two_legs(70.0, 74.0)], "task", RANGE_COLUMNS)
    assert row["trials"] == 2
    assert row["knee_flexion_range_deg_mean"] == pytest.approx(66.0)
    assert row["knee_flexion_range_deg_sd"] == pytest.approx(math.sqrt(72.0), abs=1e-3)  # 60 and 72


def test_a_task_of_two_leg_trials_only_has_its_angle_ranges():
    (row,) = group_summary([_two_legs(70.0, 74.0), _two_legs(60.0, 64.0)], "task", RANGE_COLUMNS)
    assert row["knee_flexion_range_deg_mean"] == pytest.approx(67.0)
    assert math.isnan(row["hip_flexion_range_deg_mean"])  # no trial has it


def test_the_unprefixed_value_wins_over_the_legs():
    (row,) = group_summary([_two_legs(70.0, 74.0)], "subject", LENGTH_COLUMNS)
    assert row["thigh_length_mm_mean"] == pytest.approx(410.0)
    assert math.isnan(row["thigh_length_mm_sd"])


def test_failed_trials_are_left_out():
    failed = _two_legs(10.0, 10.0) | {"status": "failed"}
    (row,) = group_summary([failed, _one_leg(60.0)], "task", RANGE_COLUMNS)
    assert row["trials"] == 1
    assert row["knee_flexion_range_deg_mean"] == pytest.approx(60.0)
