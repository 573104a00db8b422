"""A thigh or shank gyro cut at its range gets its runs back from the parabola and its joints.

The simulator knows what each cut run lost: the shanks of a seven-IMU walk cut at ±250 °/s lose
8–9° of rotation per swing (seed 201), which as recorded puts the knee flexion 3–4° RMSE off.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from lowerlimb.bilateral.process import process_bilateral_trial
from lowerlimb.errors import InputError
from lowerlimb.gait import GaitParams
from lowerlimb.gait.cut_force import cut_runs
from lowerlimb.gait.cut_segment import JointLink, restore_cut_segment_gyro
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.saturation import find_saturation
from lowerlimb.simulation.bilateral_walk import simulate_bilateral

LIMIT = np.deg2rad(250.0)


@pytest.fixture(scope="module")
def walk():
    return simulate_bilateral(30.0, 201)


def _lost_deg(true: np.ndarray, cut: np.ndarray, axes: np.ndarray, rate: float) -> np.ndarray:
    return np.array(
        [np.degrees(np.sum(true[a:b, k] - cut[a:b, k]) / rate) * s for a, b, k, s in sorted(cut_runs(axes))]
    )


def test_a_cut_shank_gets_its_swings_back(walk) -> None:
    """Each run's missing rotation: 8–9° as cut, within 1.5° restored, from the joints and from
    the parabola alone; nothing moves outside the runs or off the cut axis."""
    trial, truth = walk.trial, walk.truth["legs"]["left"]["joints"]
    rate = trial.rate_hz
    cut = np.clip(trial.gyr["left_shank"], -LIMIT, LIMIT)
    sat = find_saturation(cut, "gyr")
    assert sat is not None
    links = [
        JointLink(
            np.asarray(truth["knee"]["center_in_child_sensor"]),
            np.asarray(truth["knee"]["center_in_parent_sensor"]),
            trial.acc["left_thigh"],
            trial.gyr["left_thigh"],
        ),
        JointLink(
            np.asarray(truth["ankle"]["center_in_parent_sensor"]),
            np.asarray(truth["ankle"]["center_in_child_sensor"]),
            trial.acc["left_foot"],
            trial.gyr["left_foot"],
        ),
    ]
    lost = _lost_deg(trial.gyr["left_shank"], cut, sat.axes, rate)
    assert np.median(lost) > 5.0
    for chosen in (links, []):
        r = restore_cut_segment_gyro(cut, trial.acc["left_shank"], rate, sat.axes, chosen)
        assert np.all(np.abs(lost - r.lost_deg) < 1.5), np.abs(lost - r.lost_deg).max()
        assert np.all(r.height_rps >= 0.0)
        untouched = ~sat.at_limit
        np.testing.assert_array_equal(r.gyr_rps[untouched], cut[untouched])
        moved = np.flatnonzero(np.any(sat.axes != 0, axis=0))
        still = [k for k in range(3) if k not in moved]
        np.testing.assert_array_equal(r.gyr_rps[:, still], cut[:, still])


def test_nothing_cut_changes_nothing(walk) -> None:
    trial = walk.trial
    w = trial.gyr["left_shank"]
    r = restore_cut_segment_gyro(w, trial.acc["left_shank"], trial.rate_hz, np.zeros(w.shape, np.int8), [])
    np.testing.assert_array_equal(r.gyr_rps, w)
    assert r.height_rps.size == 0


def test_the_two_leg_pipeline_restores_cut_shanks(walk) -> None:
    """All gyros cut at ±250 °/s: the knees' flexion was 3–4° RMSE off with the shanks as cut,
    within 1.5° restored."""
    trial = walk.trial
    cut = BilateralTrial(
        trial.time_s, trial.acc, {k: np.clip(v, -LIMIT, LIMIT) for k, v in trial.gyr.items()}, trial.mag
    )
    errors = {}
    for label, params in (("restored", GaitParams()), ("as cut", GaitParams(cut_restore=False))):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = process_bilateral_trial(cut, gait_params=params)
        knees = [3, 12]
        err = np.rad2deg(res.angles_rad[:, knees] - walk.angles_rad[:, knees])[300:]
        errors[label] = np.sqrt(np.mean(err**2, axis=0))
        said = res.gait.to_dict()["cut_gyro_restored"]
        if label == "restored":
            assert set(res.legs["left"].segment_gyro_restore) >= {"shank"}
            shank = said["left"]["shank"]
            assert shank["runs"] > 10 and 5.0 < shank["rotation_deg_median"] < 12.0, shank
            foot = said["left"]["foot"]
            assert foot["tilt_deg_after_median"] < foot["tilt_deg_before_median"], foot
        else:
            assert said is None
    assert np.all(errors["as cut"] > 2.5), errors
    assert np.all(errors["restored"] < 1.5), errors


def test_params_are_checked() -> None:
    with pytest.raises(InputError, match="cut_segment_acc_sd_mps2"):
        GaitParams(cut_segment_acc_sd_mps2=0.0)
    with pytest.raises(InputError, match="cut_segment_margin_s"):
        GaitParams(cut_segment_margin_s=-1.0)
