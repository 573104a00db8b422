"""Initial contact from the foot gyro's heel-rocker onset (lowerlimb.gait.foot_contact)."""

import numpy as np
import pytest
from test_gait_events import _shank_gyro

from lowerlimb.gait import GaitParams, detect_gait_events, detect_side_events
from lowerlimb.gait.foot_contact import heel_rocker_onsets

LAG_S = 0.06  # the shank minimum lags true contact by about this much (the heel rocker)


def _foot_gyro(rate_hz: float, contact_s: np.ndarray, to_s: np.ndarray, seed: int = 1) -> np.ndarray:
    """Foot gyro whose sagittal rate crosses zero (swing -> heel rocker) exactly at ``contact_s``.

    Near each contact the rate is ``g(t) (t_c - t)`` with a positive Gaussian window g, so
    it is positive (toes-up swing) before and negative (heel rocker) after; push-off is a
    negative pulse at toe-off and swing a positive pulse between; embedded along a random
    axis with a small off-axis component and noise.
    """
    rng = np.random.default_rng(seed)
    n = int(round((contact_s[-1] + 2.0) * rate_hz))
    t = np.arange(n) / rate_hz
    om = np.zeros_like(t)
    for tc, tt in zip(contact_s, to_s, strict=True):
        om += 30.0 * np.exp(-0.5 * ((t - tc) / 0.08) ** 2) * (tc - t)
        om += -6.0 * np.exp(-0.5 * ((t - tt) / 0.05) ** 2)
        om += 3.0 * np.exp(-0.5 * ((t - 0.5 * (tt + tc)) / 0.06) ** 2)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    other = np.cross(axis, rng.normal(size=3))
    other /= np.linalg.norm(other)
    gyr = om[:, None] * axis + 0.2 * np.sin(2 * np.pi * t / 1.1)[:, None] * other
    return gyr + 0.01 * rng.normal(size=gyr.shape)


def _trial(rate_hz: float):
    shank, ic_shank, to, _ = _shank_gyro(rate_hz)
    contact = ic_shank - LAG_S
    foot = _foot_gyro(rate_hz, contact, to)[: shank.shape[0]]
    acc = np.tile([0.0, 0.0, 9.81], (shank.shape[0], 1))
    return shank, foot, acc, contact, ic_shank, to


@pytest.mark.parametrize("rate_hz", [100.0, 200.0])
def test_foot_heel_rocker_onset_recovers_contact(rate_hz):
    shank, foot, acc, contact, ic_shank, _ = _trial(rate_hz)
    ev = detect_side_events(shank, rate_hz, "left", foot_gyr=foot, foot_acc=acc)
    assert ev.ic_method == "foot_heel_rocker"
    assert ev.foot_sagittal is not None
    assert len(ev.initial_contact_s) == len(contact)
    assert np.max(np.abs(ev.initial_contact_s - contact)) <= 1.0 / rate_hz
    # without the foot, the shank minimum (one heel rocker later) is the fallback
    ev_shank = detect_side_events(shank, rate_hz, "left")
    assert ev_shank.ic_method == "shank_minimum"
    assert np.max(np.abs(ev_shank.initial_contact_s - ic_shank)) <= 1.0 / rate_hz


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_foot_mounting_sign_does_not_matter(sign):
    shank, foot, acc, contact, _, _ = _trial(100.0)
    ev = detect_side_events(shank, 100.0, "right", foot_gyr=sign * foot, foot_acc=acc)
    assert ev.foot_sagittal is not None
    assert np.corrcoef(ev.foot_sagittal.omega_rps, ev.sagittal.omega_rps)[0, 1] > 0
    assert np.max(np.abs(ev.initial_contact_s - contact)) <= 0.01


def test_toe_off_without_foot_from_shank_and_both_legs():
    shank, foot, acc, _, _, to = _trial(100.0)
    ev = detect_gait_events(
        100.0, left_shank_gyr=shank, left_foot_gyr=foot, left_foot_acc=acc, right_shank_gyr=shank
    )
    assert ev.left is not None and ev.right is not None
    assert ev.left.ic_method == "foot_heel_rocker" and ev.right.ic_method == "shank_minimum"
    assert set(ev.right.toe_off_source) == {"shank_minimum"}
    assert np.max(np.abs(ev.right.toe_off_s - to)) <= 0.01


def test_crossing_without_heel_rocker_is_not_a_contact():
    # a slow drift through zero that never reaches -event_min_rps is no heel rocker
    rate = 100.0
    p = GaitParams()
    t = np.arange(400) / rate
    ms = np.array([60])  # a mid-swing peak 0.4 s before the crossing at t = 1 s
    slow = 0.5 * np.cos(2 * np.pi * t / 4.0)  # reaches only -0.12 rad/s within heel_rocker_s
    assert heel_rocker_onsets(slow, ms, rate, p) == []
    floored = np.maximum(slow, -0.5 * p.event_min_rps)
    assert heel_rocker_onsets(floored, ms, rate, p) == []
    fast = np.where(t < 1.0, 2.0 * (1.0 - t), 4.0 * (1.0 - t))  # a heel rocker from t = 1 s
    (k,) = heel_rocker_onsets(fast, ms, rate, p)
    assert abs(k / rate - 1.0) < 0.5 / rate  # the 15 Hz low-pass rounds the kink


def test_kinked_heel_rocker_is_retimed_on_the_finer_low_pass():
    # slow toes-up swing that ends at the contact, then a steep heel rocker: a 15 Hz
    # low-pass alone spreads the kink backwards and moves the crossing early
    rate = 100.0
    t = np.arange(300) / rate
    tc = 1.503
    kinked = np.where(t < tc, 0.8 * (tc - t), -12.0 * (t - tc))
    ms = np.array([110])  # mid-swing 0.4 s before the contact
    coarse = heel_rocker_onsets(kinked, ms, rate, GaitParams(ic_refine_lowpass_hz=15.0))
    (k,) = heel_rocker_onsets(kinked, ms, rate, GaitParams())
    assert abs(k / rate - tc) < 0.004
    assert abs(coarse[0] / rate - tc) > 2.0 * abs(k / rate - tc)  # what the re-timing corrects


def test_a_contact_whose_heel_rocker_is_not_recorded_is_not_reported():
    """The recording ends within heel_rocker_s of a contact: it is dropped, not timed on the
    filters' edge (at 50 Hz such contacts came out 17-22 ms early); the others stay."""
    rate = 100.0
    shank, foot, acc, contact, _, _ = _trial(rate)
    p = GaitParams()
    for after_s, kept in ((p.heel_rocker_s + 0.1, len(contact)), (0.05, len(contact) - 1)):
        n = int(round((contact[-1] + after_s) * rate))
        ev = detect_side_events(shank[:n], rate, "left", foot_gyr=foot[:n], foot_acc=acc[:n])
        assert len(ev.initial_contact_s) == kept, after_s
        assert np.max(np.abs(ev.initial_contact_s - contact[:kept])) <= 1.0 / rate
