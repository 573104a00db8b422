"""Hostile input, tried as a new user would (issue 10, deliverable 4).

Every mistake exits 2 with one line naming the problem, before any progress line
(checks run before computing), and leaves no output behind.
"""

from __future__ import annotations

import copy
import gzip
import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import lowerlimb as ll
from lowerlimb.cli import main
from lowerlimb.errors import UnitError

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def files(tmp_path_factory, walk_clean):
    """A 20 s trial CSV, its header and data, and a calibration.json / s2j.json to corrupt."""
    d = tmp_path_factory.mktemp("hostile")
    trial = d / "walk.csv"
    walk_clean.trial.to_csv(trial)
    header = trial.read_text().splitlines()[0].split(",")
    data = np.loadtxt(trial, delimiter=",", skiprows=1)
    calibration = d / "calibration.json"
    calibration.write_text(json.dumps(walk_clean.truth))
    from lowerlimb.s2j import S2JModel, constant_s2j_from_calibration

    s2j = d / "s2j.json"
    model = S2JModel("M1", constant_s2j_from_calibration(walk_clean.truth))
    s2j.write_text(json.dumps(model.to_dict()))
    return {"dir": d, "trial": trial, "header": header, "data": data, "cal": calibration, "s2j": s2j}


def save(path: Path, header: list[str], data: np.ndarray) -> Path:
    np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.9g")
    return path


def refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run the CLI; assert exit 2, one line, no traceback and no progress line; return the line."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith("lowerlimb: error: ") and "Traceback" not in err
    return err


def calibrate_refused(files, tmp_path, capsys, trial: Path, *extra: str) -> str:
    out = tmp_path / "out"
    err = refused(["calibrate", str(trial), "--out", str(out), *extra], capsys)
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]
    return err


# ---------------------------------------------------------------- wrong results with exit 0


def test_duplicated_column_name_is_refused(files, tmp_path, capsys):
    header = list(files["header"])
    header[header.index("foot_mag_x")] = "pelvis_acc_x"  # the last copy used to win silently
    trial = save(tmp_path / "dup.csv", header, files["data"])
    err = calibrate_refused(files, tmp_path, capsys, trial)
    assert "'pelvis_acc_x' 2 times" in err


@pytest.mark.parametrize(
    ("column", "value"), [("thigh_acc_x", 1e300), ("shank_acc_z", 1e6), ("foot_gyr_y", 1e10)]
)
def test_one_corrupt_huge_sample_is_named(files, tmp_path, capsys, column, value):
    """A finite sample beyond any sensor's range: an internal solver error (1e300), or
    "thigh and shank swapped" (1e6), or "deg/s" (a 1e10 gyro) before."""
    data = files["data"].copy()
    data[1200, files["header"].index(column)] = value
    err = calibrate_refused(files, tmp_path, capsys, save(tmp_path / "huge.csv", files["header"], data))
    assert f"column '{column}' reads {value:.3g} at data row 1201, beyond any sensor's range" in err


def test_a_constant_accelerometer_is_named(files, tmp_path, capsys):
    """It was reported as two knee axes pointing apart (a two-leg trial) or a bad hinge."""
    data = files["data"].copy()
    k = files["header"].index("thigh_acc_x")
    data[:, k : k + 3] = data[0, k : k + 3]
    err = calibrate_refused(files, tmp_path, capsys, save(tmp_path / "c.csv", files["header"], data))
    assert "the thigh accelerometer reads one constant value in every row" in err


def test_an_accelerometer_in_mm_per_s2_is_a_unit_not_a_glitch(files, tmp_path, capsys):
    data = files["data"].copy()
    k = files["header"].index("shank_acc_x")
    data[:, k : k + 3] *= 1000.0
    err = calibrate_refused(files, tmp_path, capsys, save(tmp_path / "mm.csv", files["header"], data))
    assert "shank accelerometer median magnitude" in err and "expects m/s²" in err


@pytest.mark.parametrize(
    ("sensor", "message"),
    [
        ("shank", "the shank turns against the neighbouring segments"),
        # named by its turns since the sign check correlates turns, not strides (before, the
        # hip's mirror check found it: "a pelvis accelerometer that reads -9.81 … mirrors the hip")
        ("pelvis", "the pelvis turns against the neighbouring segments"),
    ],
)
def test_a_negated_accelerometer_is_named(files, tmp_path, capsys, sensor, message):
    """It was calibrated silently: hip or ankle rotation 40-80° off (an iOS-style sign)."""
    data = files["data"].copy()
    k = files["header"].index(f"{sensor}_acc_x")
    data[:, k : k + 3] *= -1.0
    out = tmp_path / "out"
    trial = save(tmp_path / "neg.csv", files["header"], data)
    assert main(["calibrate", str(trial), "--out", str(out)]) == 2
    err = capsys.readouterr().err  # found after the filters: the progress lines come first
    last = err.splitlines()[-1]
    assert last.startswith("lowerlimb: error: ") and message in last and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize("kind", ["constant", "still"])
def test_trial_with_no_motion_is_refused(files, tmp_path, capsys, kind):
    data = files["data"]
    n = 3000
    still = np.tile(data[0], (n, 1))
    still[:, 0] = np.arange(n) / 100.0
    if kind == "still":
        still[:, 1:] += np.random.default_rng(0).normal(0.0, 0.01, still[:, 1:].shape)
    trial = save(tmp_path / f"{kind}.csv", files["header"], still)
    err = calibrate_refused(files, tmp_path, capsys, trial)
    assert "no motion" in err


def test_identical_sensor_columns_are_refused(files, tmp_path, capsys):
    header, data = files["header"], files["data"].copy()
    for signal_ in ("acc", "gyr"):
        for axis in "xyz":
            data[:, header.index(f"shank_{signal_}_{axis}")] = data[
                :, header.index(f"thigh_{signal_}_{axis}")
            ]
    trial = save(tmp_path / "copied.csv", header, data)
    err = calibrate_refused(files, tmp_path, capsys, trial)
    assert "thigh and shank columns hold identical data" in err


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda d: d["joints"]["ankle"].__setitem__("center_in_parent_sensor", [1000, 0, 0]), "1000 m"),
        (lambda d: d["joints"]["hip"].__setitem__("center_in_child_sensor", [1e308, 0, 0]), "1e+308 m"),
        (lambda d: d["joints"]["knee"].__setitem__("axis_in_parent_sensor", [0, 0, 0]), "not a unit vector"),
        (lambda d: d["joints"].__setitem__("knee", None), "'knee' is missing or not an object"),
        (lambda d: d["joints"]["hip"].__setitem__("center_in_parent_sensor", "abc"), "not a list of numbers"),
        (lambda d: d["joints"]["hip"].__setitem__("center_in_parent_sensor", [1, 2]), "must hold 3 numbers"),
        (lambda d: d.__setitem__("side", "up"), "neither 'left' nor 'right'"),
        (lambda d: d["joints"]["hip"].__setitem__("rms_residual", "x"), "not a lowerlimb calibration"),
    ],
)
def test_implausible_calibration_is_refused_before_computing(files, tmp_path, capsys, edit, message):
    d = copy.deepcopy(json.loads(files["cal"].read_text()))
    edit(d)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    err = calibrate_refused(files, tmp_path, capsys, files["trial"], "--calibration", str(bad))
    assert message in err and "bad.json" in err


@pytest.mark.parametrize(
    "text, message",
    [
        ("[1, 2]", "JSON list, not a calibration object"),
        ('{"format": "lowerlimb-calibration/1", "joints": {"hip": NaN}}', "NaN"),
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ("not json", "not a valid calibration.json"),
    ],
)
def test_unreadable_calibration_json_is_exit_2(files, tmp_path, capsys, text, message):
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    err = calibrate_refused(files, tmp_path, capsys, files["trial"], "--calibration", str(bad))
    assert message in err


@pytest.mark.parametrize("value", [1e308, float("nan"), 5.0])
def test_implausible_s2j_is_refused(files, tmp_path, capsys, value):
    d = json.loads(files["s2j"].read_text())
    d["joints"]["ankle"]["center_in_child_sensor"] = [value, 0.0, 0.0]
    bad = tmp_path / "s2j_bad.json"
    bad.write_text(json.dumps(d))  # NaN is written as the JSON extension NaN
    err = calibrate_refused(files, tmp_path, capsys, files["trial"], "--s2j", str(bad))
    assert "s2j_bad.json" in err


def test_s2j_that_is_a_list_is_exit_2(files, tmp_path, capsys):
    bad = tmp_path / "s2j_list.json"
    bad.write_text("[[1, 2, 3]]")
    err = calibrate_refused(files, tmp_path, capsys, files["trial"], "--s2j", str(bad))
    assert "not an S2J model record" in err


def test_estimate_joint_center_refuses_acceleration_in_g(walk_clean):
    t = walk_clean.trial
    with pytest.raises(UnitError, match="look like g"):
        ll.estimate_joint_center(
            t.acc["pelvis"] / 9.81, t.gyr["pelvis"], t.acc["thigh"] / 9.81, t.gyr["thigh"], rate_hz=t.rate_hz
        )


# ---------------------------------------------------------------- exit 1 "internal error" → exit 2


@pytest.mark.parametrize(
    "content, message",
    [
        ("time,pelvis_acc_x µ\n0,1\n".encode("latin-1"), "not UTF-8 text"),
        (gzip.compress(b"time,pelvis_acc_x\n0,1\n", mtime=0), "gzip-compressed"),
        (bytes(range(256)) * 4, "binary file"),
        (b"time;pelvis_acc_x;pelvis_acc_y\n0;9,81;0,1\n", "separates its columns with semicolons"),
    ],
    ids=["latin-1", "gzip", "binary", "semicolons"],
)
def test_unreadable_trial_files_name_the_problem(files, tmp_path, capsys, content, message):
    trial = tmp_path / "bad.csv"
    trial.write_bytes(content)
    assert message in calibrate_refused(files, tmp_path, capsys, trial)


def test_comma_decimal_cell_is_named(files, tmp_path, capsys):
    lines = files["trial"].read_text().splitlines()
    cells = lines[5].split(",")
    cells[1] = '"' + cells[1].replace(".", ",") + '"'
    lines[5] = ",".join(cells)
    trial = tmp_path / "comma.csv"
    trial.write_text("\n".join(lines) + "\n")
    err = calibrate_refused(files, tmp_path, capsys, trial)
    assert "comma as decimal mark" in err and "data row 5" in err


def test_text_cell_is_not_called_nan(files, tmp_path, capsys):
    lines = files["trial"].read_text().splitlines()
    cells = lines[3].split(",")
    cells[2] = "abc"
    lines[3] = ",".join(cells)
    trial = tmp_path / "text.csv"
    trial.write_text("\n".join(lines) + "\n")
    err = calibrate_refused(files, tmp_path, capsys, trial)
    assert "the text 'abc' at data row 3" in err and "NaN" not in err


def test_directory_as_trial_is_not_not_found(files, tmp_path, capsys):
    err = calibrate_refused(files, tmp_path, capsys, files["dir"])
    assert "is a directory" in err and "not found" not in err


def test_all_zero_data_does_not_suggest_9_81(files, tmp_path, capsys):
    data = files["data"].copy()
    data[:, 1:] = 0.0
    trial = save(tmp_path / "zero.csv", files["header"], data)
    err = calibrate_refused(files, tmp_path, capsys, trial)
    assert "all zero" in err and "9.81" not in err


def test_no_mag_accepts_nan_in_magnetometer_columns(files, tmp_path):
    from lowerlimb.io.trial import ImuTrial

    header, data = files["header"], files["data"].copy()
    data[100:110, header.index("foot_mag_x")] = np.nan
    trial = save(tmp_path / "magnan.csv", header, data)
    with pytest.raises(ll.InputError, match="foot_mag_x"):
        ImuTrial.from_csv(trial)
    loaded = ImuTrial.from_csv(trial, use_mag=False)
    assert loaded.mag is None and loaded.n_samples == data.shape[0]


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--height", "inf"], "--height inf m is out of range"),
        (["--height", "0.01"], "--height 0.01 m is out of range"),
        (["--mass", "1e300"], "--mass 1e+300 kg is out of range"),
    ],
)
def test_calibrate_subject_values_checked_before_computing(files, tmp_path, capsys, extra, message):
    assert message in calibrate_refused(files, tmp_path, capsys, files["trial"], *extra)


def test_missing_out_parent_is_checked_before_computing(files, tmp_path, capsys):
    out = tmp_path / "no" / "such" / "out"
    err = refused(["calibrate", str(files["trial"]), "--out", str(out)], capsys)
    assert "does not exist" in err


def test_read_only_out_parent_is_exit_2(files, tmp_path, capsys, monkeypatch):
    import lowerlimb.io.atomic as atomic

    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    # root ignores permission bits, so make the folder read-only in the check itself
    monkeypatch.setattr(atomic.os, "access", lambda p, m: False if Path(p) == locked else real_access(p, m))
    err = refused(["calibrate", str(files["trial"]), "--out", str(locked / "out")], capsys)
    assert "is not writable" in err
    err = refused(["simulate", "--duration", "3", "--out", str(locked / "t.csv")], capsys)
    assert "is not writable" in err


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--duration", "inf"], "--duration inf s is out of range"),
        (["--duration", "1e9"], "--duration 1e+09 s is out of range"),
        (["--rate", "inf"], "--rate inf Hz is out of range"),
        (["--rate", "1e-3"], "--rate 0.001 Hz is out of range"),
        (["--rate", "1"], "--rate 1 Hz is out of range"),
        (["--seed", "-1"], "--seed -1 is out of range"),
    ],
)
def test_simulate_option_ranges(tmp_path, capsys, extra, message):
    out = tmp_path / "t.csv"
    err = refused(["simulate", "--duration", "3", "--out", str(out), *extra], capsys)
    assert message in err and not out.exists()


# ---------------------------------------------------------------- simulate never overwrites


def test_simulate_refuses_to_overwrite_unless_forced(tmp_path, capsys):
    out, truth = tmp_path / "t.csv", tmp_path / "truth.json"
    angles = tmp_path / "truth_angles.csv"
    angles.write_text("mine")  # never named by the user, used to be replaced silently
    err = refused(["simulate", "--duration", "3", "--out", str(out), "--truth", str(truth)], capsys)
    assert "truth_angles.csv already exists" in err
    assert angles.read_text() == "mine" and not out.exists() and not truth.exists()

    angles.unlink()
    assert main(["simulate", "--duration", "3", "--out", str(out)]) == 0
    first = out.read_text()
    err = refused(["simulate", "--duration", "3", "--seed", "5", "--out", str(out)], capsys)
    assert "t.csv already exists" in err and "--force" in err and out.read_text() == first
    assert main(["simulate", "--duration", "3", "--seed", "5", "--out", str(out), "--force"]) == 0
    assert out.read_text() != first


def test_simulate_out_and_truth_the_same_file(tmp_path, capsys):
    same = tmp_path / "same.csv"
    err = refused(["simulate", "--duration", "3", "--out", str(same), "--truth", str(same)], capsys)
    assert "both name" in err and not same.exists()


def test_simulate_failing_truth_write_leaves_nothing(tmp_path, capsys, monkeypatch):
    import lowerlimb.io.tables as tables

    def broken(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(tables, "write_positions_csv", broken)
    out, truth = tmp_path / "t.csv", tmp_path / "truth.json"
    assert main(["simulate", "--duration", "3", "--out", str(out), "--truth", str(truth)]) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == []


# ---------------------------------------------------------------- warnings and signals


def _run_script(script: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script)],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_numpy_runtime_warnings_do_not_reach_the_user(tmp_path):
    script = """
        import sys, warnings
        import numpy as np
        import lowerlimb.cli as cli

        def noisy(args):
            with np.errstate(invalid="warn"):
                np.log(np.array([-1.0]))
            warnings.warn("a real notice", UserWarning, stacklevel=1)
            return 0

        cli.COMMANDS["simulate"] = noisy
        sys.exit(cli.main(["simulate", "--out", "x.csv"]))
    """
    proc = _run_script(script, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "invalid value" not in proc.stderr and "lowerlimb: warning: a real notice" in proc.stderr


def test_ctrl_c_swallowed_by_an_import_still_stops_the_run(tmp_path):
    # an optional import that catches BaseException swallows the KeyboardInterrupt of Ctrl-C
    script = """
        import signal, sys
        import lowerlimb.cli as cli

        def run(args):
            try:  # what a third-party optional import does
                # raise_signal, not os.kill: delivered to this thread before it returns (os.kill may
                # land in a BLAS thread, and the handler then runs after the write, a flaky test)
                signal.raise_signal(signal.SIGINT)
            except BaseException:
                pass
            from lowerlimb.io.atomic import populate_directory
            populate_directory(args.out, lambda d: (d / "angles.csv").write_text("x"))
            return 0

        cli.COMMANDS["simulate"] = run
        sys.exit(cli.main(["simulate", "--out", "out"]))
    """
    proc = _run_script(script, tmp_path)
    assert proc.returncode == 130, proc.stderr
    assert "interrupted" in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_sigterm_during_the_write_removes_the_staging_folder(tmp_path):
    script = """
        import os, signal, sys, time
        import lowerlimb.cli as cli

        def run(args):
            from lowerlimb.io.atomic import populate_directory

            def fill(d):
                (d / "angles.csv").write_text("half")
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(5)
                (d / "positions.csv").write_text("never")

            populate_directory(args.out, fill)
            return 0

        cli.COMMANDS["simulate"] = run
        sys.exit(cli.main(["simulate", "--out", "out"]))
    """
    proc = _run_script(script, tmp_path)
    assert proc.returncode == 128 + signal.SIGTERM, proc.stderr
    assert "interrupted (SIGTERM)" in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_ctrl_c_during_calibrate_writes_nothing(tmp_path, walk_clean):
    trial = tmp_path / "walk.csv"
    walk_clean.trial.to_csv(trial)
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.Popen(
        [sys.executable, "-m", "lowerlimb.cli", "calibrate", str(trial), "--out", str(tmp_path / "out")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert proc.stderr is not None
        line = proc.stderr.readline()  # the first progress line: the run is computing
        assert line.startswith("calibrating"), line
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk.csv"]


# ---------------------------------------------------------------- demo, view


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--seed", "-5"], "--seed -5 is out of range"),
        (["--duration", "1e6"], "--duration 1e+06 s is out of range"),
    ],
)
def test_demo_checks_its_options_as_simulate_does(tmp_path, capsys, extra, message):
    """They were an internal error (a negative seed) and a run that never ended (1e6 s)."""
    err = refused(["demo", "--out", str(tmp_path / "d"), *extra], capsys)
    assert message in err and not (tmp_path / "d").exists()


@pytest.mark.parametrize(
    ("host", "message"),
    [("999.1.1.1", "is not an address"), ("nonexistent.invalid", "is not an address")],
)
def test_view_refuses_a_host_it_cannot_listen_on(host, message):
    """An internal error (the server's exit status) and a silent hang before."""
    from lowerlimb.errors import InputError
    from lowerlimb.viz.view import check_host

    with pytest.raises(InputError, match=message):
        check_host(host)
    check_host("127.0.0.1")


def test_view_refuses_an_unknown_side_of_a_two_leg_folder(tmp_path):
    """A two-leg folder was blamed on its URDF ("not a lowerlimb leg")."""
    from lowerlimb.errors import InputError
    from lowerlimb.viz.view import load_view_data

    for name in ("calibrated.urdf", "calibrated_left.urdf", "calibrated_right.urdf", "angles.csv"):
        (tmp_path / name).write_text("x")
    with pytest.raises(InputError, match="a two-leg result has the legs 'left' and 'right'"):
        load_view_data(tmp_path, "both")


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ({"format": "lowerlimb-calibration/1", "layout": "two_legs", "legs": {}}, "is a two-leg calibration"),
        ({"format": "lowerlimb-s2j/1", "joints": {}}, "is a segment-to-joint model (give it to --s2j)"),
    ],
)
def test_the_wrong_kind_of_calibration_file_is_named(files, tmp_path, capsys, content, message):
    """Both said "side None is neither 'left' nor 'right'"."""
    cal = tmp_path / "calibration.json"
    cal.write_text(json.dumps(content))
    err = calibrate_refused(files, tmp_path, capsys, files["trial"], "--calibration", str(cal))
    assert message in err


def test_a_two_second_trial_is_not_called_the_other_leg():
    """One second of walking after the standing start left the hip anywhere: a left leg was
    refused as a right one ("rerun with --side right")."""
    from lowerlimb.io.trial import ImuTrial

    t = ll.simulate("walk", 30.0, 3).trial
    n = 201  # the first 2 s: 1 s standing, 1 s of walking
    acc, gyr = ({k: v[:n] for k, v in d.items()} for d in (t.acc, t.gyr))
    cut = ImuTrial(time_s=t.time_s[:n], acc=acc, gyr=gyr)
    with pytest.warns(UserWarning, match="record a longer trial"):
        ll.process_trial(cut)
