"""Swapped sensor columns and the wrong side are refused with one line naming the fix."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.plausibility import (
    SensorOrderError,
    SideEvidenceWarning,
    WrongSideError,
    check_side,
    pelvis_turn_side_cue,
)
from lowerlimb.errors import InputError


def _swapped(a: str, b: str):
    t = cached_simulation("walk", 30.0, 5).trial
    acc, gyr = dict(t.acc), dict(t.gyr)
    acc[a], acc[b] = acc[b], acc[a]
    gyr[a], gyr[b] = gyr[b], gyr[a]
    return type(t)(time_s=t.time_s, acc=acc, gyr=gyr, mag=t.mag, side=t.side)


@pytest.mark.parametrize("pair", [("thigh", "shank"), ("shank", "foot")])
def test_swapped_columns_are_refused(pair):
    trial = _swapped(*pair)
    with pytest.raises(SensorOrderError) as e:
        calibrate_leg(trial)
    assert isinstance(e.value, InputError)
    assert e.value.swapped_rms < 0.7 * e.value.assumed_rms
    msg = str(e.value)
    assert f"{pair[0]} and {pair[1]} columns look swapped" in msg and "\n" not in msg


def test_swapped_columns_pass_when_the_check_is_off():
    trial = _swapped("thigh", "shank")
    calibrate_leg(trial, options=CalibrationOptions(check_sensor_order=False))


def test_the_right_order_passes():
    cal = calibrate_leg(cached_simulation("walk", 30.0, 5).trial)
    assert cal.side == "left"


@pytest.mark.parametrize(
    ("side", "lateral", "refused"),
    [
        ("left", -0.07, False),
        ("left", 0.07, True),
        ("right", 0.07, False),
        ("right", -0.07, True),
        ("left", 0.01, False),
    ],
)
def test_side_from_the_hip_offset(side, lateral, refused):
    v = np.array([0.15, -0.05, lateral])
    if refused:
        with pytest.raises(WrongSideError) as e:
            check_side(side, v)
        other = "right" if side == "left" else "left"
        assert f"--side {other}" in str(e.value) and e.value.lateral_m == pytest.approx(lateral)
    else:
        check_side(side, v)


@pytest.mark.parametrize(("cue", "outcome"), [(-0.3, "warned"), (0.3, "refused"), (-0.05, "refused")])
def test_a_confirming_pelvis_turn_outweighs_a_contrary_hip(cue, outcome):
    hip_on_the_right = np.array([0.15, -0.05, 0.07])  # given: left
    if outcome == "warned":
        with pytest.warns(SideEvidenceWarning, match="kept left"):
            check_side("left", hip_on_the_right, pelvis_turn=cue)
    else:  # contradicting or too weak a cue leaves the hip's verdict
        with pytest.raises(WrongSideError):
            check_side("left", hip_on_the_right, pelvis_turn=cue)


@pytest.mark.parametrize("side", ["left", "right"])
def test_the_pelvis_turns_with_the_simulated_leg_that_swings(side):
    sim = cached_simulation("walk", 30.0, 7, side=side)
    t, knee = sim.trial, np.asarray(sim.truth["joints"]["knee"]["axis_in_parent_sensor"])
    up = t.acc["pelvis"][:100].mean(axis=0)
    cue = pelvis_turn_side_cue(t.gyr["pelvis"], t.gyr["thigh"], knee, up, t.rate_hz)
    assert cue < -0.15 if side == "left" else cue > 0.15, cue
    if side == "right":  # the same leg with the left leg's (unmirrored) pelvis reads as a left leg
        t2 = cached_simulation("walk", 30.0, 7, side=side, mirror_pelvis=False).trial
        assert pelvis_turn_side_cue(t2.gyr["pelvis"], t2.gyr["thigh"], knee, up, t.rate_hz) < -0.15


@pytest.mark.parametrize(("cue", "refused"), [(0.3, True), (-0.3, False), (0.05, False), (None, False)])
def test_an_agreeing_pelvis_turn_lets_an_uncertain_hip_decide(cue, refused):
    """A contrary hip within two of its standard deviations decides only with the turn cue behind it."""
    hip_on_the_right = np.array([0.15, -0.05, 0.035])  # given: left; 1.75 sigma
    if refused:
        with pytest.raises(WrongSideError):
            check_side("left", hip_on_the_right, hip_std_m=0.02, pelvis_turn=cue)
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SideEvidenceWarning)
            check_side("left", hip_on_the_right, hip_std_m=0.02, pelvis_turn=cue)


def _swap(trial, a: str, b: str):
    acc, gyr = dict(trial.acc), dict(trial.gyr)
    acc[a], acc[b] = acc[b], acc[a]
    gyr[a], gyr[b] = gyr[b], gyr[a]
    return type(trial)(time_s=trial.time_s, acc=acc, gyr=gyr, mag=None, side=trial.side)


def test_a_knee_lift_whose_foot_fits_the_knee_is_not_called_swapped():
    """The ankle barely moves and the shank's tissue wobbles: the knee's centre fits the foot
    better (0.11 against 0.19 m/s²), its hinge does not. It was refused as shank/foot swapped."""
    from lowerlimb.calibration.plausibility import SwapVetoWarning
    from lowerlimb.simulation import Artefacts

    trial = cached_simulation("knee-lift", 40.0, 2, artefacts=Artefacts.real_walk()).trial
    with pytest.warns(SwapVetoWarning, match="the knee is the better hinge"):
        calibrate_leg(trial)


def test_a_squat_with_thigh_and_shank_exchanged_names_them():
    """The summed hip + ankle test missed it (the pelvis's noise) and the knee's named shank/foot."""
    from lowerlimb.simulation import Artefacts

    trial = cached_simulation("squat", 40.0, 2, artefacts=Artefacts.real_walk()).trial
    with pytest.raises(SensorOrderError, match="the thigh and shank columns look swapped"):
        calibrate_leg(_swap(trial, "thigh", "shank"))


@pytest.mark.parametrize(("motion", "seed"), [("knee-lift", 3021), ("sit-to-stand", 3006)])
def test_valid_soft_tissue_trials_are_not_called_swapped(motion, seed):
    """A knee lift whose summed hip + ankle test favours the columns as given 3.9× was refused
    as thigh/shank swapped on the ankle's term alone; a sit-to-stand whose knee is the better
    hinge by 1.49× (the veto was 1.5) as shank/foot swapped. Both valid, 20 s, artefacts."""
    from lowerlimb.calibration.plausibility import SwapVetoWarning, check_sensor_order
    from lowerlimb.simulation import Artefacts

    trial = cached_simulation(motion, 20.0, seed, artefacts=Artefacts.real_walk()).trial
    opts = CalibrationOptions()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SwapVetoWarning)
        check_sensor_order(trial.acc, trial.gyr, _prepared(trial, opts), opts)  # no SensorOrderError
    if motion == "knee-lift":  # its true thigh/shank swap is still named
        swapped = _swap(trial, "thigh", "shank")
        with pytest.raises(SensorOrderError, match="thigh and shank"):
            check_sensor_order(swapped.acc, swapped.gyr, _prepared(swapped, opts), opts)


def _prepared(trial, opts):
    from lowerlimb.calibration._prepare import prepare_signals

    return prepare_signals(trial.acc, trial.gyr, trial.rate_hz, opts, still=trial.still_period())


def test_the_two_pairings_are_compared_through_one_filter(monkeypatch):
    """A residual's RMS grows with its band. A pair that shares no joint (thigh–foot) gets a
    low rigid-band cap, and on a slow walk with the real-walk artefacts (a first draft of
    the slow walker) it fitted 0.71 m/s² at 2 Hz against the knee's 2.31 unfiltered: the
    trial was refused as shank/foot swapped. Each pairing is now seen through the lower
    cap of the two."""
    import lowerlimb.calibration.plausibility as plausibility
    from lowerlimb.calibration._prepare import rigid_band_cap_hz
    from lowerlimb.simulation import Artefacts

    seen: dict[tuple[str, str], float | None] = {}
    residual = plausibility._residual

    def recording(acc, gyr, sig, parent, child, options, max_samples, cap_hz=None):
        seen[parent, child] = cap_hz
        return residual(acc, gyr, sig, parent, child, options, max_samples, cap_hz)

    monkeypatch.setattr(plausibility, "_residual", recording)
    trial = cached_simulation("squat", 40.0, 1, artefacts=Artefacts.real_walk()).trial
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        calibrate_leg(trial)
    opts = CalibrationOptions()
    own = {
        pair: rigid_band_cap_hz(trial.acc[pair[0]], trial.acc[pair[1]], trial.rate_hz, opts)
        for pair in (("thigh", "shank"), ("thigh", "foot"))
    }
    # alone, the knee would be seen unfiltered and thigh–foot through a low cap
    assert own["thigh", "shank"] is None and own["thigh", "foot"] is not None
    # the knee's two candidates, through one filter: the lower of their own caps
    assert seen["thigh", "shank"] == seen["thigh", "foot"] == own["thigh", "foot"]
