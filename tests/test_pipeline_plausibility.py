"""A wrong --side, swapped columns and an implausible segment: caught or replaced, never silent."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from simcache import cached_simulation, data_dir, real_walk_leg_mapping

import lowerlimb as ll
from lowerlimb.calibration.plausibility import WrongSideError
from lowerlimb.cli import main
from lowerlimb.model.fallback import CalibrationFallbackWarning, segment_lengths, with_plausible_lengths


@pytest.fixture(scope="module")
def left_walk():
    return cached_simulation("walk", 30.0, 5)


def test_wrong_side_is_refused_with_the_fix(left_walk, tmp_path, capsys):
    left_walk.trial.to_csv(tmp_path / "t.csv")
    code = main(["calibrate", str(tmp_path / "t.csv"), "--out", str(tmp_path / "o"), "--side", "right"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and not (tmp_path / "o").exists()
    assert "this looks like a left leg" in err[-1] and "--side left" in err[-1]
    assert main(["calibrate", str(tmp_path / "t.csv"), "--out", str(tmp_path / "ok")]) == 0


def test_side_check_can_be_switched_off(left_walk, tmp_path):
    left_walk.trial.to_csv(tmp_path / "t.csv")
    argv = ["calibrate", str(tmp_path / "t.csv"), "--out", str(tmp_path / "o"), "--side", "right"]
    assert main([*argv, "--no-side-check"]) == 0


def test_swapped_columns_exit_2(left_walk, tmp_path, capsys):
    t = left_walk.trial
    acc, gyr = dict(t.acc), dict(t.gyr)
    acc["thigh"], acc["shank"] = acc["shank"], acc["thigh"]
    gyr["thigh"], gyr["shank"] = gyr["shank"], gyr["thigh"]
    type(t)(time_s=t.time_s, acc=acc, gyr=gyr, mag=t.mag, side=t.side).to_csv(tmp_path / "s.csv")
    code = main(["calibrate", str(tmp_path / "s.csv"), "--out", str(tmp_path / "o")])
    assert code == 2 and not (tmp_path / "o").exists()
    assert "thigh and shank columns look swapped" in capsys.readouterr().err


def test_degenerate_thigh_falls_back_on_the_template(left_walk):
    cal = ll.calibrate_leg(left_walk.trial)
    k = cal.knee
    on_axis = k.center_in_parent_sensor + 0.01 * k.axis_in_parent_sensor  # a 0 mm thigh
    broken = replace(cal, hip=replace(cal.hip, center_in_child_sensor=on_axis))
    up = {s: left_walk.trial.acc[s][:50].mean(axis=0) for s in ("thigh", "shank")}
    with pytest.warns(CalibrationFallbackWarning, match="hip: the calibrated thigh is 0 mm long"):
        fixed = with_plausible_lengths(broken, up, height_m=1.75)
    thigh, shank = segment_lengths(fixed)
    true_thigh, _ = segment_lengths(ll.calibrate_leg(left_walk.trial))
    assert thigh == pytest.approx(0.245 * 1.75, rel=0.03)  # de Leva 422 mm at 1.741 m
    assert abs(thigh - true_thigh) < 0.06  # the template is near the subject's thigh
    assert np.allclose(fixed.hip.center_in_parent_sensor, cal.hip.center_in_parent_sensor)
    assert any("fell back on the de Leva thigh" in w for w in fixed.warnings)
    # the hip lies above the knee: the fallback points up the thigh, not down
    assert np.dot(fixed.hip.center_in_child_sensor - k.center_in_parent_sensor, up["thigh"]) > 0


def test_plausible_lengths_are_untouched(left_walk):
    cal = ll.calibrate_leg(left_walk.trial)
    up = {s: left_walk.trial.acc[s][:50].mean(axis=0) for s in ("thigh", "shank")}
    with warnings.catch_warnings():
        warnings.simplefilter("error", CalibrationFallbackWarning)
        assert with_plausible_lengths(cal, up, height_m=1.75) is cal


@pytest.mark.data
@pytest.mark.skipif(data_dir() is None or not (data_dir() / "gait").is_dir(), reason="no gait/ data")
@pytest.mark.parametrize("side", ["left", "right"])
def test_real_walk_catches_the_wrong_side(side):
    mapping = real_walk_leg_mapping(side)
    other = "right" if side == "left" else "left"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ll.process_trial(ll.read_xsens(data_dir() / "gait" / "rawimu", mapping, side=side))  # as worn: passes
        trial = ll.read_xsens(data_dir() / "gait" / "rawimu", mapping, side=other)
        if side == "right":
            # in the one-leg pelvis frame (the thigh frame at standing, turned with this knee
            # axis's toe-out) the right hip lies 0.7 cm left of the sacral sensor: no verdict
            ll.process_trial(trial)
            return
        with pytest.raises(WrongSideError) as e:
            ll.process_trial(trial)
    # 3.3 cm left at 1.8 sigma: the pelvis turn (-0.26, a left leg's) is the second witness
    assert abs(e.value.lateral_m) > 0.03 and f"--side {side}" in str(e.value)
