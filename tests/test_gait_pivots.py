"""A foot that pivots on the floor makes its strides and steps turning ones (lowerlimb.gait.contacts).

The contact position is the foot's still ankle during its stationary period; a foot turning
about the vertical between initial contact and the end of that period (a turn about) had no
still ankle, so the strides and steps ending on it must be summarised apart, while a foot
that only pitches (heel strike to foot flat) or turns after its period (onto the next pass)
must not be.
"""

from __future__ import annotations

import numpy as np
import pytest

from lowerlimb.conventions import rot_z
from lowerlimb.errors import InputError
from lowerlimb.gait import GaitParams
from lowerlimb.gait.contacts import Contacts, stance_turn_rad

RATE = 100.0


def _rot_y(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _stance(yaw_deg: np.ndarray, pitch_deg: np.ndarray) -> np.ndarray:
    """(N, 3, 3) orientations turning by ``yaw_deg`` about the vertical after pitching by ``pitch_deg``."""
    return np.stack(
        [rot_z(np.deg2rad(y)) @ _rot_y(np.deg2rad(p)) for y, p in zip(yaw_deg, pitch_deg, strict=True)]
    )


def test_a_pivot_before_the_period_ends_is_measured() -> None:
    n = 100  # one stance of 1 s: contact at 0.1 s, period 0.3-0.6 s, toe-off 0.8 s
    t = np.arange(n) / RATE
    turn = np.clip((t - 0.2) / 0.3, 0.0, 1.0) * 45.0  # turns 45° by 0.5 s
    R = _stance(turn, np.zeros(n))
    got = stance_turn_rad(R, RATE, np.array([0.1]), np.array([0.8]), np.array([0.6]))
    assert np.rad2deg(got[0]) == pytest.approx(45.0, abs=0.5)


def test_a_foot_that_only_pitches_or_turns_after_its_period_did_not_pivot() -> None:
    n = 100
    t = np.arange(n) / RATE
    pitch = 20.0 * np.cos(np.pi * t)  # heel strike to push-off, 20° either way
    late_turn = np.clip((t - 0.65) / 0.15, 0.0, 1.0) * 60.0  # onto the next pass on the forefoot
    R = _stance(late_turn, pitch)
    got = stance_turn_rad(R, RATE, np.array([0.1]), np.array([0.8]), np.array([0.6]))
    assert np.rad2deg(got[0]) < 1.0
    # without a stationary period the whole stance counts, and the late turn is seen
    whole = stance_turn_rad(R, RATE, np.array([0.1]), np.array([0.8]), np.array([np.nan]))
    assert np.rad2deg(whole[0]) == pytest.approx(60.0, abs=0.5)


def test_a_turn_through_half_a_circle_is_unwrapped_and_missing_toe_offs_are_nan() -> None:
    n = 200
    t = np.arange(n) / RATE
    R = _stance(170.0 + 40.0 * np.clip(t - 0.2, 0.0, 1.0), np.zeros(n))  # 170° → 210° (−150°)
    ic = np.array([0.1, 1.5])
    got = stance_turn_rad(R, RATE, ic, np.array([1.3]), np.array([np.nan, np.nan]))
    assert np.rad2deg(got[0]) == pytest.approx(40.0, abs=0.5)
    assert np.isnan(got[1])  # no toe-off after the last contact and no period: unknown


def _contacts(stance_turn_deg: list[float], heading_deg: list[float]) -> Contacts:
    k = len(heading_deg)
    return Contacts(
        time_s=np.arange(k) * 1.1,
        position_m=np.column_stack([np.arange(k) * 1.3, np.zeros(k), np.zeros(k)]),
        R_earth_sensor=np.stack([rot_z(np.deg2rad(h)) for h in heading_deg]),
        period=np.arange(k),
        stance_turn_rad=np.deg2rad(np.asarray(stance_turn_deg, dtype=float)),
    )


def test_strides_ending_on_a_pivot_are_turning() -> None:
    c = _contacts([2.0, 3.0, 45.0, 4.0, np.nan], [0.0, 1.0, 2.0, 3.0, 4.0])
    thr = np.deg2rad(20.0)
    assert list(c.pivots(thr)) == [False, False, True, False, False]
    # the strides into and out of the pivoting contact turn; NaN (unknown) is not a pivot
    assert [c.turning(k, thr, thr) for k in range(4)] == [False, True, True, False]
    # a heading change between the contacts alone still makes a turning stride
    turned = _contacts([2.0, 3.0, 4.0], [0.0, 30.0, 31.0])
    assert [turned.turning(k, thr, thr) for k in range(2)] == [True, False]
    # contacts measured without toe-offs never pivot
    plain = Contacts(turned.time_s, turned.position_m, turned.R_earth_sensor, turned.period)
    assert not plain.pivots(thr).any()


@pytest.mark.parametrize("value", [0.0, -5.0, float("nan")])
def test_bad_stance_turn_threshold_is_refused(value: float) -> None:
    with pytest.raises(InputError, match="stance_turn_deg"):
        GaitParams(stance_turn_deg=value)


def test_a_contact_without_a_stationary_period_takes_no_earlier_stances() -> None:
    """A foot pivoting through its whole stance has no still period; the previous stance's,
    which ended before it touched down, made a stride of 1 cm on a slow walk with turns."""
    from lowerlimb.gait.contacts import _nearest_periods

    periods = np.array([[0.2, 0.6], [0.7, 0.8], [3.2, 3.6]])  # a stance split in two, then one later
    ic = np.array([0.1, 1.5, 3.0])  # the middle contact pivoted: no period of its own
    assert list(_nearest_periods(periods, ic, max_gap_s=1.0)) == [0, -1, 2]
