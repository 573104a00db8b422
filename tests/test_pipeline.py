"""``lowerlimb calibrate`` end to end on simulated trials, against the simulator's truth."""

import json

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.cli import main
from lowerlimb.conventions import ANGLE_COLUMNS, POSITION_COLUMNS
from lowerlimb.demo import compare_with_truth
from lowerlimb.model.leg_model import LegModel
from lowerlimb.outputs import load_calibrated
from lowerlimb.simulation import ImuNoise


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    sim = cached_simulation("walk", 40.0, 21, noise=ImuNoise(), side="right")
    d = tmp_path_factory.mktemp("cal")
    trial = d / "trial.csv"
    sim.trial.to_csv(trial)
    out = d / "out"
    assert main(["calibrate", str(trial), "--out", str(out), "--side", "right", "--no-mag"]) == 0
    return sim, out


def test_every_output_is_written(calibrated):
    _, out = calibrated
    assert sorted(p.name for p in out.iterdir()) == sorted(
        ["calibration.json", "angles.csv", "positions.csv", "calibrated.urdf", "report.html", "s2j.json"]
        + ["angles.units.json", "positions.units.json"]
    )
    cal = json.loads((out / "calibration.json").read_text())
    assert cal["format"] == "lowerlimb-calibration/1" and cal["side"] == "right" and cal["method"] == "casadi"
    assert cal["runtime_s"] > 0
    for joint, kind in (("hip", "spherical"), ("knee", "hinge"), ("ankle", "spherical")):
        j = cal["joints"][joint]
        assert j["type"] == kind
        assert len(j["center_in_parent_sensor"]) == 3 and len(j["center_in_child_sensor"]) == 3
        assert np.isfinite(j["rms_residual"])
    assert np.isclose(np.linalg.norm(cal["joints"]["knee"]["axis_in_parent_sensor"]), 1.0)
    assert (out / "angles.csv").read_text().splitlines()[0] == ",".join(ANGLE_COLUMNS)
    assert (out / "positions.csv").read_text().splitlines()[0] == ",".join(POSITION_COLUMNS)
    LegModel.from_urdf(out / "calibrated.urdf")
    model, s2j = load_calibrated(out)
    assert s2j.method == "M1" and "s2j.json" in (out / "calibrated.urdf").read_text()
    hip = model.joint_center_in_sensor("hip", "pelvis")
    assert np.allclose(hip, cal["joints"]["hip"]["center_in_parent_sensor"], atol=1e-9)


def test_calibration_angles_and_positions_match_the_truth(calibrated):
    sim, out = calibrated
    cal = json.loads((out / "calibration.json").read_text())
    err = compare_with_truth(cal, sim.truth)
    assert err["knee"]["axis_deg"] < 1.0
    assert err["hip"]["child_mm"] < 10 and err["ankle"]["child_mm"] < 10
    assert err["hip"]["parent_mm"] < 20 and err["ankle"]["parent_mm"] < 20
    angles = np.loadtxt(out / "angles.csv", delimiter=",", skiprows=1)
    rmse = np.sqrt(np.mean((np.deg2rad(angles[:, 1:]) - sim.angles_rad) ** 2, axis=0))
    rmse_deg = np.rad2deg(rmse)
    assert rmse_deg[[0, 3, 6]].max() < 2.0, rmse_deg
    assert rmse_deg.max() < 3.0, rmse_deg
    pos = np.loadtxt(out / "positions.csv", delimiter=",", skiprows=1)[:, 1:]
    assert 1e3 * np.sqrt(np.mean(np.sum((pos[:, :3] - sim.positions_m[:, :3]) ** 2, axis=1))) < 20.0


def test_calibration_angles_and_positions_stay_near_what_the_code_achieves(calibrated):
    """Regression bounds (issue 10) beside the goals above, about 2-3x the measured values.

    The measured value is in the comment on each line; without gyro-bias removal the knee
    axis error is 0.30 deg.
    """
    sim, out = calibrated
    err = compare_with_truth(json.loads((out / "calibration.json").read_text()), sim.truth)
    assert err["knee"]["axis_deg"] < 0.12, err  # measured 0.050
    assert err["knee"]["parent_line_mm"] < 2.0 and err["knee"]["child_line_mm"] < 0.4, err  # 0.69, 0.14
    assert err["hip"]["parent_mm"] < 15.0 and err["hip"]["child_mm"] < 6.0, err  # 9.2, 2.8
    # ankle in the shank: 1.7 mm before the right leg's pelvis was mirrored (a different walk)
    assert err["ankle"]["parent_mm"] < 10.0 and err["ankle"]["child_mm"] < 1.2, err  # 4.8, 0.59
    angles = np.loadtxt(out / "angles.csv", delimiter=",", skiprows=1)
    rmse_deg = np.rad2deg(np.sqrt(np.mean((np.deg2rad(angles[:, 1:]) - sim.angles_rad) ** 2, axis=0)))
    assert rmse_deg.max() < 1.3, rmse_deg  # 0.65
    pos = np.loadtxt(out / "positions.csv", delimiter=",", skiprows=1)[:, 1:]
    hip_mm = 1e3 * np.sqrt(np.mean(np.sum((pos[:, :3] - sim.positions_m[:, :3]) ** 2, axis=1)))
    assert hip_mm < 15.0, hip_mm  # 10.4


def test_no_standing_start_warns_once_and_calibrates(tmp_path, capsys):
    sim = cached_simulation("walk", 40.0, 21, noise=ImuNoise(), side="right")
    t = sim.trial
    cut = 300
    from lowerlimb.io.trial import ImuTrial

    moving = ImuTrial(
        t.time_s[cut:] - t.time_s[cut],
        {k: v[cut:] for k, v in t.acc.items()},
        {k: v[cut:] for k, v in t.gyr.items()},
        None,
        "right",
    )
    moving.to_csv(tmp_path / "m.csv")
    assert main(["calibrate", str(tmp_path / "m.csv"), "--out", str(tmp_path / "o"), "--side", "right"]) == 0
    err = capsys.readouterr().err
    assert err.count("first second is taken as the angle reference") == 1
    assert (tmp_path / "o" / "angles.csv").exists()


def test_bad_input_leaves_no_directory(tmp_path, capsys):
    sim = cached_simulation("walk", 4.0, 3)
    header = sim.trial.header()
    data = sim.trial.to_array()
    data[5, 7] = np.nan
    np.savetxt(tmp_path / "bad.csv", data, delimiter=",", header=",".join(header), comments="")
    assert main(["calibrate", str(tmp_path / "bad.csv"), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "NaN" in err and err.count("\n") == 1
    assert not (tmp_path / "o").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["bad.csv"]


def test_existing_output_directory_is_refused(tmp_path, capsys):
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "keep.txt").write_text("x")
    sim = cached_simulation("walk", 4.0, 3)
    sim.trial.to_csv(tmp_path / "t.csv")
    assert main(["calibrate", str(tmp_path / "t.csv"), "--out", str(tmp_path / "o")]) == 2
    assert "not empty" in capsys.readouterr().err
    assert main(["calibrate", str(tmp_path / "t.csv"), "--out", str(tmp_path / "o" / "keep.txt")]) == 2
    assert "is an existing file, not a folder" in capsys.readouterr().err
    assert (tmp_path / "o" / "keep.txt").read_text() == "x"


def test_reusing_a_rich_calibration_fixes_a_poorly_excited_trial(tmp_path, capsys):
    """Calibrate the 'mixed' motion once, then apply it to squats of the same sensor placements."""
    rich = cached_simulation("mixed", 40.0, 31)
    squats = cached_simulation("squat", 40.0, 32, geometry=rich.model.geometry)
    rich.trial.to_csv(tmp_path / "rich.csv")
    squats.trial.to_csv(tmp_path / "squat.csv")
    assert main(["calibrate", str(tmp_path / "rich.csv"), "--out", str(tmp_path / "rich")]) == 0
    assert main(["calibrate", str(tmp_path / "squat.csv"), "--out", str(tmp_path / "self")]) == 0
    assert (
        main(
            [
                "calibrate",
                str(tmp_path / "squat.csv"),
                "--out",
                str(tmp_path / "reuse"),
                "--calibration",
                str(tmp_path / "rich" / "calibration.json"),
            ]
        )
        == 0
    )

    def p2f_mm(d):
        pos = np.loadtxt(d / "positions.csv", delimiter=",", skiprows=1)[:, 1:4]
        return 1e3 * np.sqrt(np.mean(np.sum((pos - squats.positions_m[:, :3]) ** 2, axis=1)))

    reused = json.loads((tmp_path / "reuse" / "calibration.json").read_text())
    assert reused["calibration_reused"] is True and reused["runtime_s"] == 0.0
    assert p2f_mm(tmp_path / "reuse") < 20.0
    # measured 5.4 against 8.6 mm (the squats' own hip in the pelvis sensor is off)
    assert p2f_mm(tmp_path / "reuse") < 0.8 * p2f_mm(tmp_path / "self")
    # a calibration of the other leg is refused with one line
    capsys.readouterr()
    assert (
        main(
            [
                "calibrate",
                str(tmp_path / "squat.csv"),
                "--out",
                str(tmp_path / "x"),
                "--side",
                "right",
                "--calibration",
                str(tmp_path / "rich" / "calibration.json"),
            ]
        )
        == 2
    )
    assert "left leg" in capsys.readouterr().err and not (tmp_path / "x").exists()


def test_disturbed_magnetometer_is_ignored_with_a_warning():
    """A magnet near the shank bends its field: the pipeline falls back to 6-axis fusion and says so."""
    import warnings as w

    from lowerlimb.io.trial import ImuTrial
    from lowerlimb.orientation.magnetic import check_magnetic_field
    from lowerlimb.pipeline import MagneticDisturbanceWarning, process_trial

    sim = cached_simulation("walk", 20.0, 33)
    assert check_magnetic_field(sim.trial).usable
    t = sim.trial
    mag = {k: v.copy() for k, v in t.mag.items()}
    n = len(t.time_s)
    mag["shank"] += np.outer(40.0 * np.clip(np.sin(np.linspace(0, 9, n)), 0, None), [1.0, 0.3, 0.0])
    disturbed = ImuTrial(t.time_s, t.acc, t.gyr, mag, t.side)
    check = check_magnetic_field(disturbed)
    assert not check.usable and "shank" in check.reason
    with w.catch_warnings(record=True) as caught:
        w.simplefilter("always")
        res = process_trial(disturbed)
    assert any(issubclass(c.category, MagneticDisturbanceWarning) for c in caught)
    assert res.used_mag is False and "shank" in res.calibration_dict()["magnetometer_rejected"]
    rmse = np.rad2deg(np.sqrt(np.mean((res.angles_rad - sim.angles_rad) ** 2, axis=0)))
    assert rmse.max() < 3.0


def test_positions_can_be_left_to_the_caller():
    """``positions=False`` skips the per-sample forward kinematics and changes nothing else."""
    from lowerlimb.pipeline import process_trial

    sim = cached_simulation("walk", 20.0, 33)
    full = process_trial(sim.trial, use_mag=False)
    bare = process_trial(sim.trial, use_mag=False, positions=False)
    assert full.positions_m.shape == (sim.trial.time_s.size, 6) and bare.positions_m.shape == (0, 6)
    np.testing.assert_array_equal(bare.angles_rad, full.angles_rad)
    np.testing.assert_array_equal(
        bare.model.geometry.joint_origins["knee"], full.model.geometry.joint_origins["knee"]
    )


def test_a_walk_cut_mid_stride_keeps_a_usable_magnetometer():
    """Without a standing start the sensors' magnetic dips are not compared: on samples in
    motion the accelerometer's "up" is off and a clean field was called disturbed (the
    sensors' dips 19° apart on this walk cut at sample 800)."""
    import warnings as w

    from lowerlimb.pipeline import process_trial

    cut = cached_simulation("walk", 20.0, 33).trial.from_sample(800)
    assert not cut.has_standing_start() and cut.mag is not None
    with w.catch_warnings():
        w.simplefilter("ignore")
        assert process_trial(cut).used_mag


def test_segment_lengths_are_recorded_shown_and_near_the_truth(calibrated):
    """calibration.json's thigh and shank (hip / ankle centre to the knee axis) are those of its
    joints, within 15 mm of the simulator's, and the report shows them."""
    from types import SimpleNamespace

    from lowerlimb.calibration import LegCalibration
    from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration
    from lowerlimb.model.fallback import segment_lengths
    from lowerlimb.outputs import residual_lines

    sim, out = calibrated
    cal = json.loads((out / "calibration.json").read_text())
    lengths = cal["segment_lengths_m"]
    assert np.allclose([lengths["thigh"], lengths["shank"]], segment_lengths(LegCalibration.from_dict(cal)))
    joints = sim.truth["joints"]
    truth = SimpleNamespace(
        hip=SphericalJointCalibration.from_dict(joints["hip"], "hip"),
        knee=HingeJointCalibration.from_dict(joints["knee"]),
        ankle=SphericalJointCalibration.from_dict(joints["ankle"], "ankle"),
    )
    true_lengths = segment_lengths(truth)  # type: ignore[arg-type]
    assert abs(lengths["thigh"] - true_lengths[0]) < 0.015 and abs(lengths["shank"] - true_lengths[1]) < 0.015
    thigh_mm = f"{1000 * lengths['thigh']:.0f} mm"
    assert any(line.startswith(f"thigh {thigh_mm}, shank") for line in residual_lines(cal))
    band = {"factor": 1.5, "widened": False, "reason": "the knee axis differs"}
    (line,) = [x for x in residual_lines(cal | {"fit_band": band}) if x.startswith("thigh")]
    assert line.endswith("fitted within the coherent band: the knee axis differs)")
    wide = {"fit_band": band | {"widened": True}, "rigid_band_cap_hz": {"pelvis-thigh": 3.9}}
    (line,) = [x for x in residual_lines(cal | wide) if x.startswith("thigh")]
    assert line.endswith("fitted with the rigid-band caps widened 1.5x)")
    assert f"Thigh {1000 * lengths['thigh']:.3g} mm" in (out / "report.html").read_text()


def test_causal_filters_are_an_option_and_recorded(calibrated, tmp_path):
    """Default: each filter runs forward and backward (the inclination of both passes);
    ``--causal``: forward only. Both are recorded in the provenance, and on this simulated
    walk the smoothed angles are the closer ones to the truth."""
    sim, out = calibrated
    trial = out.parent / "trial.csv"
    causal = tmp_path / "causal"
    assert (
        main(["calibrate", str(trial), "--out", str(causal), "--side", "right", "--no-mag", "--causal"]) == 0
    )
    options = {
        d.name: json.loads((d / "calibration.json").read_text())["provenance"]["options"]
        for d in (out, causal)
    }
    assert options["out"]["smooth_orientation"] is True and options["causal"]["smooth_orientation"] is False
    rmse = {}
    for d in (out, causal):
        angles = np.loadtxt(d / "angles.csv", delimiter=",", skiprows=1)[:, 1:]
        rmse[d.name] = float(np.sqrt(np.mean((np.deg2rad(angles) - sim.angles_rad) ** 2)))
    assert rmse["out"] < rmse["causal"], rmse
