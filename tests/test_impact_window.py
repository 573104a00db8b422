"""Samples near impacts left out of the spherical joint-centre fits."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lowerlimb.calibration.impact_window import impact_cutoff_limit_hz, impact_keep_mask, jerk_norm
from lowerlimb.calibration.joint_center import calibrate_spherical_joint
from lowerlimb.calibration.leg import LegCalibration, calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.constraints.spherical import SphericalData
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.simulation import ImuNoise, simulate_bilateral

RATE = 100.0


def _smooth(n: int = 1000) -> np.ndarray:
    """Walking-like specific force: 2 m/s² at 1 Hz on top of gravity (jerk ≈ 13 m/s³)."""
    t = np.arange(n) / RATE
    a = np.zeros((n, 3))
    a[:, 0] = 2.0 * np.sin(2 * np.pi * t)
    a[:, 2] = 9.81
    return a


def test_jerk_of_a_ramp_is_its_slope():
    a = np.zeros((50, 3))
    a[:, 1] = 3.0 * np.arange(50) / RATE  # 3 m/s³
    assert np.allclose(jerk_norm(a, RATE), 3.0)


def test_a_step_is_left_out_with_its_window_and_smooth_motion_is_kept():
    a = _smooth()
    assert impact_keep_mask([a], RATE, CalibrationOptions()).all()
    a[500:, 0] += 30.0  # a 30 m/s² jump between samples 499 and 500
    opts = CalibrationOptions(impact_window_s=0.05)
    keep = impact_keep_mask([_smooth(), a], RATE, opts)
    dropped = np.flatnonzero(~keep)
    assert dropped.min() == 499 - 5 and dropped.max() == 500 + 5
    assert keep.sum() == 1000 - 12


def test_no_more_than_the_allowed_fraction_is_left_out():
    rng = np.random.default_rng(1)
    a = _smooth() + rng.normal(scale=20.0, size=(1000, 3))  # high jerk everywhere
    opts = CalibrationOptions(impact_max_excluded=0.3)
    keep = impact_keep_mask([a], RATE, opts)
    assert 0.6 < keep.mean()
    assert (~keep).mean() <= 0.3


@pytest.mark.parametrize(
    "kw",
    [
        {"impact_jerk_mps3": 0.0},
        {"impact_window_s": -0.01},
        {"impact_max_excluded": 1.0},
        {"impact_joints": ("knee",)},
        {"impact_max_cutoff_hz": 0.0},
    ],
)
def test_options_refuse_bad_impact_settings(kw):
    with pytest.raises(InputError):
        CalibrationOptions(**kw)


def test_select_checks_the_mask_length():
    z = np.zeros((10, 3))
    d = SphericalData(z, z, z, z, z, z)
    assert d.select(np.arange(10) < 4).n_samples == 4
    with pytest.raises(ShapeError):
        d.select(np.ones(9, dtype=bool))


@pytest.fixture(scope="module")
def kinked_walk():
    # noise-free seven-IMU walk: the feet roll over heel, ankle and forefoot rockers, and
    # the kinematics kink at each contact, where the rigid constraint fails
    return simulate_bilateral(15.0, 201, noise=ImuNoise.none())


def _ankle_in_shank_error_m(sim, cal) -> float:
    truth = np.asarray(sim.truth["legs"]["left"]["joints"]["ankle"]["center_in_parent_sensor"])
    return float(np.linalg.norm(cal.ankle.center_in_parent_sensor - truth))


def test_leaving_out_the_contacts_recovers_the_simulated_ankle(kinked_walk):
    trial = kinked_walk.trial.leg("left")
    off = calibrate_leg(trial, options=CalibrationOptions(impact_exclusion=False, center_std_tol_m=np.inf))
    on = calibrate_leg(trial, options=CalibrationOptions(center_std_tol_m=np.inf))
    assert _ankle_in_shank_error_m(kinked_walk, off) > 0.015
    assert _ankle_in_shank_error_m(kinked_walk, on) < 0.006
    assert off.ankle.impact_excluded_fraction == 0.0
    assert 0.1 < on.ankle.impact_excluded_fraction < 0.5
    assert on.hip.impact_excluded_fraction == 0.0  # the hip fit keeps every sample by default
    d = json.loads(json.dumps(on.to_dict()))
    back = LegCalibration.from_dict(d)
    assert back.ankle.impact_excluded_fraction == pytest.approx(on.ankle.impact_excluded_fraction)


def test_the_pair_api_leaves_out_the_contacts_too(kinked_walk):
    trial = kinked_walk.trial.leg("left")
    truth = np.asarray(kinked_walk.truth["legs"]["left"]["joints"]["ankle"]["center_in_parent_sensor"])
    errs = {}
    for on in (False, True):
        res = calibrate_spherical_joint(
            trial.acc["shank"],
            trial.gyr["shank"],
            trial.acc["foot"],
            trial.gyr["foot"],
            rate_hz=trial.rate_hz,
            options=CalibrationOptions(impact_exclusion=on, center_std_tol_m=np.inf),
        )
        errs[on] = float(np.linalg.norm(res.center_in_parent_sensor - truth))
        assert (res.impact_excluded_fraction > 0) == on
    assert errs[True] < 0.5 * errs[False]


def test_the_cutoff_limit_needs_impacts_and_the_option():
    o = CalibrationOptions()
    some = np.ones(100, dtype=bool)
    assert impact_cutoff_limit_hz(None, o) is None
    assert impact_cutoff_limit_hz(some, o) is None  # smooth motion: nothing left out
    some[40:45] = False
    assert impact_cutoff_limit_hz(some, o) == o.impact_max_cutoff_hz == 12.0
    assert impact_cutoff_limit_hz(some, CalibrationOptions(impact_max_cutoff_hz=None)) is None


def test_the_limit_filters_an_unfiltered_pair_and_keeps_a_lower_cutoff():
    from lowerlimb.calibration._prepare import joint_signals, prepare_signals

    rng = np.random.default_rng(3)
    n = 1500
    gyr = {k: rng.normal(size=(n, 3)) for k in ("shank", "foot")}
    acc = {k: np.array([0.0, 0.0, 9.81]) + rng.normal(size=(n, 3)) for k in ("shank", "foot")}
    o = CalibrationOptions(rigid_band=False)
    for set_hz, limit, want in (
        ({"shank": None, "foot": None}, 12.0, 12.0),
        ({"shank": 6.0, "foot": 6.0}, 12.0, 6.0),
        ({"shank": None, "foot": None}, 60.0, None),  # past 0.45 x 100 Hz: no limit
    ):
        sig = prepare_signals(acc, gyr, 100.0, o, n_still=100, set_hz=set_hz)
        data = joint_signals(acc, gyr, sig, "shank", "foot", o, max_hz=limit)
        ref = prepare_signals(acc, gyr, 100.0, o, n_still=100, set_hz={"shank": want, "foot": want})
        np.testing.assert_allclose(data.gyr_parent, ref.gyr["shank"])
        np.testing.assert_allclose(data.acc_child, ref.acc["foot"])


def test_the_limit_places_a_slow_walkers_ankle_along_its_axis():
    """On a slow walk the unfiltered contacts put the ankle 4 cm lateral in the shank sensor."""
    sim = simulate_bilateral(30.0, 201, pace="slow")
    trial = sim.trial.leg("left")
    truth = np.asarray(sim.truth["legs"]["left"]["joints"]["ankle"]["center_in_parent_sensor"])
    err = {}
    for limit in (None, 12.0):
        cal = calibrate_leg(trial, options=CalibrationOptions(impact_max_cutoff_hz=limit))
        err[limit] = float(np.linalg.norm(cal.ankle.center_in_parent_sensor - truth))
        assert cal.impact_cutoff_hz == ({} if limit is None else {"shank-foot": 12.0})
    assert err[None] > 0.025 and err[12.0] < 0.4 * err[None], err
    back = LegCalibration.from_dict(json.loads(json.dumps(cal.to_dict())))
    assert back.impact_cutoff_hz == {"shank-foot": 12.0}
