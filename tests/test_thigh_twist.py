"""The thigh sensor's twist with hip flexion: undone exactly on the simulator, found from the knee axes."""

from __future__ import annotations

import json
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from simcache import data_dir, real_walk_leg_mapping, true_leg

import lowerlimb as ll
from lowerlimb.calibration.leg import LegCalibration
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.thigh_twist import (
    ThighTwist,
    ThighTwistWarning,
    unconfirmed_message,
    untwist_signals,
    untwist_trial,
)
from lowerlimb.cli import main
from lowerlimb.conventions import quat_to_matrix
from lowerlimb.errors import InputError
from lowerlimb.model.fallback import segment_lengths
from lowerlimb.simulation import Artefacts, ImuNoise, simulate, simulate_bilateral

C = 0.3
HIP_DRIVEN = {"pelvis": "hip", "thigh": "hip", "shank": "knee", "foot": "ankle"}


def _hip_twist(seed: int, c: float = C) -> Artefacts:
    return Artefacts(
        seed=seed,
        skin_twist_rad_per_rad={"pelvis": 0.0, "thigh": c, "shank": 0.0, "foot": 0.0},
        skin_twist_driver=HIP_DRIVEN,
    )


def _quiet(f, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*a, **k)


@pytest.mark.parametrize("side", ["left", "right"])
def test_untwisting_with_the_true_turn_returns_the_rigid_sensor(side):
    kw = {"side": side, "rate_hz": 1000.0, "noise": ImuNoise.none()}
    twisted = simulate("walk", 6.0, 5, artefacts=_hip_twist(5), **kw)
    rigid = simulate("walk", 6.0, 5, **kw)
    hip = twisted.angles_rad[:, 0]
    rate = np.gradient(hip, 1e-3)
    sign = 1.0 if side == "right" else -1.0
    R = quat_to_matrix(np.asarray(twisted.truth["sensors"]["thigh"]["quat_wxyz_in_segment"])[None])[0]
    p = np.asarray(twisted.truth["sensors"]["thigh"]["position_in_segment"])
    e, r0 = R.T @ np.array([0.0, 1.0, 0.0]), R.T @ (p * np.array([1.0, 0.0, 1.0]))
    phi = sign * C * (hip - hip.mean())
    g, a = twisted.clean.gyr["thigh"], twisted.clean.acc["thigh"]
    w, f = untwist_signals(g, a, phi, sign * C * rate, e, r0, 1000.0)
    inner = slice(20, -20)  # the finite-difference derivatives' ends
    g_rigid, a_rigid = rigid.clean.gyr["thigh"][inner], rigid.clean.acc["thigh"][inner]
    assert np.max(np.abs(g[inner] - g_rigid)) > 0.1  # the twist is there ...
    assert np.max(np.abs(w[inner] - g_rigid)) < 0.01  # ... and undone (rad/s)
    assert np.max(np.abs(a[inner] - a_rigid)) > 0.3
    # specific force: the sensor's place differs from the rigid one by the mean of its circle (< 1 mm)
    assert np.sqrt(np.mean((f[inner] - a_rigid) ** 2)) < 0.03
    # without the sensor's motion round the femur the force stays off
    _, f_turn_only = untwist_signals(g, a, phi, sign * C * rate, e, np.zeros(3), 1000.0)
    assert np.sqrt(np.mean((f_turn_only[inner] - a_rigid) ** 2)) > 3 * np.sqrt(
        np.mean((f[inner] - a_rigid) ** 2)
    )


@pytest.fixture(scope="module")
def twisted_walk():
    return simulate_bilateral(40.0, 202, artefacts=_hip_twist(202), pace="slow")


@pytest.mark.parametrize("side", ["left", "right"])
def test_the_twist_is_found_and_undone_on_a_simulated_walk(twisted_walk, side):
    sim = twisted_walk
    trial = sim.trial.leg(side)
    joints = sim.truth["legs"][side]["joints"]
    truth = np.array(segment_lengths(true_leg(joints)))
    i = ("left", "right").index(side)
    keep = sim.trial.time_s > 3.0

    def score(options):
        res = _quiet(ll.process_trial, trial, calibration_options=options)
        err = 1000.0 * (np.array(segment_lengths(res.calibration)) - truth)
        rot = np.rad2deg(res.angles_rad[keep, 5] - sim.angles_rad[keep, 9 * i + 5])
        return res, err, float(np.sqrt(np.mean(rot**2)))

    off, err_off, rot_off = score(None)
    on, err_on, rot_on = score(CalibrationOptions(thigh_twist=True))
    assert off.calibration.thigh_twist is None
    tw = on.calibration.thigh_twist
    assert tw is not None
    # found: ~0.33 internal per rad of hip flexion (0.3 simulated), the knee axes made to agree
    assert 0.25 < tw.internal_per_flexion(side) < 0.42
    # the untwisted trial's fit keeps the clock search's record (it was dropped: clock_offsets {})
    assert set(on.calibration.clock_offsets) >= {"shift_s", "joints", "passes"}
    assert abs(tw.mismatch_before_deg) > 12 and abs(tw.mismatch_after_deg) < 1.5
    assert 0.03 < np.linalg.norm(tw.offset_from_axis_m) < 0.15  # the sensor sits on the thigh's side
    # undone: lengths and knee rotation as on rigid sensors (measured: 30-60 mm and 8 deg before)
    assert np.max(np.abs(err_off)) > 20 and rot_off > 5
    assert np.max(np.abs(err_on)) < 10 and rot_on < 3


def test_a_rigid_walk_is_left_as_it_is():
    trial = simulate_bilateral(30.0, 203, pace="slow").trial.leg("right")
    off = _quiet(ll.process_trial, trial)
    on = _quiet(ll.process_trial, trial, calibration_options=CalibrationOptions(thigh_twist=True))
    assert on.calibration.thigh_twist is None
    np.testing.assert_array_equal(on.angles_rad, off.angles_rad)


def test_the_twist_is_recorded_and_reapplied_with_a_reused_calibration(twisted_walk):
    trial = twisted_walk.trial.leg("left")
    first = _quiet(ll.process_trial, trial, calibration_options=CalibrationOptions(thigh_twist=True))
    doc = json.loads(json.dumps(first.calibration.to_dict()))
    assert doc["thigh_twist"]["per_flexion_rad_per_rad"] == pytest.approx(
        first.calibration.thigh_twist.per_flexion
    )
    back = LegCalibration.from_dict(doc)
    assert back.thigh_twist is not None
    np.testing.assert_allclose(
        back.thigh_twist.offset_from_axis_m, first.calibration.thigh_twist.offset_from_axis_m
    )
    again = _quiet(ll.process_trial, trial, calibration=back)
    assert again.calibration.thigh_twist is back.thigh_twist
    np.testing.assert_allclose(again.trial.gyr["thigh"], first.trial.gyr["thigh"], atol=1e-12)
    knee = 3  # knee_flexion
    assert np.max(np.abs(np.rad2deg(again.angles_rad[:, knee] - first.angles_rad[:, knee]))) < 1.0
    # without the record, the reused calibration meets the twisted thigh as recorded
    plain = _quiet(ll.process_trial, trial, calibration=replace(back, thigh_twist=None))
    np.testing.assert_array_equal(plain.trial.gyr["thigh"], trial.gyr["thigh"])


def test_no_twist_is_the_identity():
    trial = simulate("walk", 3.0, 1, noise=ImuNoise.none()).trial
    tw = ThighTwist(0.0, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.zeros(3), 0.0, 0.0, 0.1)
    assert untwist_trial(trial, tw, 100) is trial


def test_bad_twist_options_are_refused_by_name():
    with pytest.raises(InputError, match="thigh_twist_max"):
        CalibrationOptions(thigh_twist_max=0.0)
    with pytest.raises(InputError, match="thigh_twist_steps"):
        CalibrationOptions(thigh_twist_steps=0)


def test_calibrate_thigh_twist_writes_the_twist(tmp_path, capsys):
    trial = simulate("walk", 30.0, 4, artefacts=_hip_twist(4)).trial
    csv = tmp_path / "walk.csv"
    trial.to_csv(csv)
    out = tmp_path / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert (
            main(
                ["calibrate", str(csv), "--thigh-twist", "--out", str(out), "--outputs", "calibration,report"]
            )
            == 0
        )
    doc = json.loads((out / "calibration.json").read_text())
    assert doc["thigh_twist"] is not None and abs(doc["thigh_twist"]["mismatch_after_deg"]) < 2.0
    assert "thigh sensor twist undone" in capsys.readouterr().err
    assert "id='twist-note'" in (out / "report.html").read_text()


@pytest.mark.data
@pytest.mark.skipif(
    data_dir() is None or not (data_dir() / "gait").is_dir(),  # type: ignore[operator]
    reason="real-walk data absent",
)
@pytest.mark.parametrize("side", ["left", "right"])
def test_the_real_thighs_turn_internally_with_the_hip(side):
    data = data_dir()
    assert data is not None
    trial = ll.read_xsens(data / "gait" / "rawimu", real_walk_leg_mapping(side), side=side)
    res = _quiet(ll.process_trial, trial, calibration_options=CalibrationOptions(thigh_twist=True))
    tw = res.calibration.thigh_twist
    assert tw is not None
    # measured: 0.33 / 0.59 internal, from -17.4 / +18.4 deg of mismatch to within 0.5 deg
    assert 0.2 < tw.internal_per_flexion(side) < 0.8
    assert "shift_s" in res.calibration.clock_offsets  # the clock search's record survives the untwist
    assert abs(tw.mismatch_before_deg) > 12 and abs(tw.mismatch_after_deg) < 1.5


def test_a_study_can_undo_the_twist_and_its_hash_says_so():
    from lowerlimb.batch import BatchParams
    from lowerlimb.batch.manifest import StudyTrial
    from lowerlimb.batch.record import TrialJob
    from lowerlimb.batch.worker import _calibrate_options

    assert "thigh_twist" not in BatchParams().processing_key()  # studies run before stay up to date
    assert BatchParams(thigh_twist=True).processing_key()["thigh_twist"] is True
    trial = StudyTrial("t", Path("t.csv"), "t.csv", "left", "", "", 1.75, 75.0, None)
    job = TrialJob(trial, BatchParams(thigh_twist=True), Path("out"), "")
    assert _calibrate_options(job).calibration_options().thigh_twist


def test_thigh_twist_with_a_calibration_that_records_none_is_refused(tmp_path, capsys):
    csv = tmp_path / "walk.csv"
    simulate("walk", 20.0, 6).trial.to_csv(csv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["calibrate", str(csv), "--out", str(tmp_path / "a"), "--outputs", "calibration"]) == 0
        capsys.readouterr()
        cal = str(tmp_path / "a" / "calibration.json")
        args = ["calibrate", str(csv), "--calibration", cal, "--thigh-twist", "--out", str(tmp_path / "b")]
        code = main(args)
    assert code == 2
    err = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert len(err) == 1 and "--thigh-twist" in err[0] and "records none" in err[0]
    assert not (tmp_path / "b").exists()


def test_both_legs_untwisted_share_one_pelvis_frame(twisted_walk):
    from lowerlimb.bilateral import process_bilateral_trial

    def legs_apart(options):
        res = _quiet(process_bilateral_trial, twisted_walk.trial, calibration_options=options)
        return res, res.hips.pelvis_axes_angle_deg

    _, off = legs_apart(None)
    res, on = legs_apart(CalibrationOptions(thigh_twist=True))
    # measured: the two legs' pelvis frames 37 deg apart with the twist (1 deg rigid), 1 deg undone
    assert off > 20 and on < 5
    for side in ("left", "right"):
        twist = res.legs[side].calibration.thigh_twist
        assert twist is not None and 0.25 < twist.internal_per_flexion(side) < 0.42


def test_a_twist_the_gyros_do_not_see_is_named():
    tw = ThighTwist(
        0.3, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.zeros(3), 18.0, 0.0, 0.1, 0.26
    )
    assert tw.confirmed(1.0 / 3.0) and not tw.confirmed(1.0)
    assert not replace(tw, gyro_evidence=-0.26).confirmed(1.0 / 3.0)  # the other sign
    assert not replace(tw, gyro_evidence=float("nan")).confirmed(0.0)
    assert "too little knee motion" in unconfirmed_message(replace(tw, gyro_evidence=float("nan")))
    assert "+0.30" in unconfirmed_message(replace(tw, gyro_evidence=0.02))


def test_the_pipeline_warns_when_the_gyros_do_not_confirm_the_twist(twisted_walk):
    trial = twisted_walk.trial.leg("right")
    strict = CalibrationOptions(thigh_twist=True, thigh_twist_min_evidence=5.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = ll.process_trial(trial, calibration_options=strict)
    twist = res.calibration.thigh_twist
    assert twist is not None and 0.2 < twist.gyro_evidence < 0.4  # measured 0.28 (0.34 found)
    assert [w for w in caught if issubclass(w.category, ThighTwistWarning)]


@pytest.mark.parametrize("bad", [[0.0, 1.0], [0.0, 0.0, 0.0], [0.0, float("inf"), 1.0]])
def test_a_malformed_twist_record_is_refused_by_name(bad):
    doc = ThighTwist(
        0.3, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.zeros(3), 18.0, 0.0, 0.1
    ).to_dict()
    with pytest.raises(InputError, match="thigh_twist.axis_in_sensor must be three finite numbers"):
        ThighTwist.from_dict(doc | {"axis_in_sensor": bad})
