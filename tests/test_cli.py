import json

import numpy as np
import pytest

from lowerlimb.cli import main
from lowerlimb.io.trial import ImuTrial


def test_simulate_writes_trial_truth_and_tables(tmp_path, capsys):
    out = tmp_path / "t.csv"
    truth = tmp_path / "truth.json"
    rc = main(
        [
            "simulate",
            "--motion",
            "squat",
            "--duration",
            "5",
            "--seed",
            "3",
            "--out",
            str(out),
            "--truth",
            str(truth),
            "--side",
            "right",
        ]
    )
    assert rc == 0
    trial = ImuTrial.from_csv(out, side="right")
    assert trial.n_samples == 500 and trial.has_mag
    t = json.loads(truth.read_text())
    assert t["format"] == "lowerlimb-calibration/1" and t["side"] == "right"
    assert set(t["joints"]) == {"hip", "knee", "ankle"}
    angles = np.loadtxt(tmp_path / "truth_angles.csv", delimiter=",", skiprows=1)
    assert angles.shape == (500, 10)
    assert (tmp_path / "truth_positions.csv").read_text().startswith("time,pelvis_to_foot_x")


def test_simulate_both_legs_writes_a_seven_imu_walk_and_its_truth(tmp_path, capsys):
    from lowerlimb.io.bilateral_trial import BilateralTrial

    out, truth = tmp_path / "t7.csv", tmp_path / "truth.json"
    argv = ["simulate", "--side", "both", "--duration", "8", "--seed", "5", "--out", str(out)]
    assert main([*argv, "--truth", str(truth)]) == 0
    trial = BilateralTrial.from_csv(out)
    assert trial.n_samples == 800 and "right_foot" in trial.acc and trial.mag is not None
    t = json.loads(truth.read_text())
    assert set(t["legs"]) == {"left", "right"} and set(t["legs"]["left"]["joints"]) == {
        "hip",
        "knee",
        "ankle",
    }
    events = (tmp_path / "truth_events.csv").read_text().splitlines()
    assert events[0] == "time,side,event" and {"left,initial_contact", "right,toe_off"} <= {
        line.split(",", 1)[1] for line in events[1:]
    }
    gait = json.loads((tmp_path / "truth_gait.json").read_text())
    assert gait["left"]["stride_time_s"]["mean"] > 0.9 and gait["step_width_m"]["mean"] > 0.0
    assert np.loadtxt(tmp_path / "truth_angles.csv", delimiter=",", skiprows=1).shape == (800, 19)
    assert (tmp_path / "truth_positions.csv").read_text().startswith("time,left_pelvis_to_foot_x")


def test_simulate_both_legs_with_real_walk_artefacts(tmp_path, capsys):
    from lowerlimb.io.bilateral_trial import BilateralTrial

    out, truth = tmp_path / "t7.csv", tmp_path / "truth.json"
    argv = ["simulate", "--side", "both", "--duration", "8", "--seed", "5", "--artefacts", "real"]
    assert main([*argv, "--out", str(out), "--truth", str(truth)]) == 0
    assert "real-walk artefacts" in capsys.readouterr().out
    trial = BilateralTrial.from_csv(out)
    assert trial.n_samples == 800 and len(trial.acc) == 7
    rec = json.loads(truth.read_text())["artefacts"]
    assert set(rec["clock_offset_s"]) == set(trial.acc) and rec["params"]["impact_mps2"]["shank"] > 0
    assert (tmp_path / "truth_events.csv").exists() and (tmp_path / "truth_gait.json").exists()
    # the same seed without artefacts: same walk, different signals
    rigid = tmp_path / "rigid.csv"
    assert main([*argv[:-2], "--out", str(rigid)]) == 0
    r = BilateralTrial.from_csv(rigid)
    assert not np.allclose(r.acc["left_shank"], trial.acc["left_shank"], atol=0.5)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["simulate", "--side", "both", "--motion", "squat", "--out", "x.csv"], "walking only"),
        (
            ["simulate", "--side", "both", "--soft-tissue", "--out", "x.csv"],
            "does not simulate --soft-tissue",
        ),
        (["simulate", "--side", "both", "--duration", "4", "--out", "x.csv"], "at least 6 s"),
        (["simulate", "--motion", "jog", "--out", "x.csv"], "invalid choice: 'jog'"),
        (["simulate", "--duration", "-3", "--out", "x.csv"], "must be positive"),
        (["simulate", "--out", "missing_dir/x.csv"], "does not exist"),
        (["simulate"], "required: --out"),
        (["frobnicate"], "invalid choice"),
        ([], "no command given"),
        (["calibrate", "nope.csv", "--out", "o"], "not found"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(argv, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "x.csv").exists() and not (tmp_path / "o").exists()


def test_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert "lowerlimb" in capsys.readouterr().out


def test_internal_error_is_one_line_and_exit_1(monkeypatch, capsys):
    import lowerlimb.cli as cli

    def broken(args):
        raise RuntimeError("boom")

    monkeypatch.setitem(cli.COMMANDS, "simulate", broken)
    monkeypatch.delenv("LOWERLIMB_DEBUG", raising=False)
    assert main(["simulate", "--out", "x.csv"]) == 1
    err = capsys.readouterr().err
    assert "internal error (RuntimeError): boom" in err and err.count("\n") == 1
    monkeypatch.setenv("LOWERLIMB_DEBUG", "1")
    with pytest.raises(RuntimeError):
        main(["simulate", "--out", "x.csv"])


def test_demo_runs_the_whole_pipeline(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--duration", "12"]) == 0
    for name in (
        "trial.csv",
        "truth.json",
        "calibration.json",
        "angles.csv",
        "positions.csv",
        "calibrated.urdf",
        "s2j.json",
        "report.html",
        "summary.md",
        "angles.png",
    ):
        assert (out / name).is_file(), name
    summary = (out / "summary.md").read_text()
    assert "pelvis-to-foot position RMSE" in summary
    angles = np.loadtxt(out / "angles.csv", delimiter=",", skiprows=1)
    truth = np.loadtxt(out / "truth_angles.csv", delimiter=",", skiprows=1)
    assert np.sqrt(np.mean((angles[:, 1:] - truth[:, 1:]) ** 2, axis=0)).max() < 3.0
    # a second run into the same folder is refused, leaving it intact
    assert main(["demo", "--out", str(out), "--duration", "12"]) == 2
    assert (out / "report.html").is_file()
