from __future__ import annotations

import os
import signal
import subprocess
import sys
import urllib.error
import urllib.request

import numpy as np
import pytest
import umsgpack
from chromium import orange_mask, screenshot

from lowerlimb.cli import main
from lowerlimb.conventions import ANGLE_COLUMNS
from lowerlimb.errors import InputError
from lowerlimb.io.tables import write_angles_csv
from lowerlimb.viz.scene import R_WORLD_PELVIS
from lowerlimb.viz.view import build_animation, load_view_data, serve

SEGMENTS = ("pelvis", "thigh", "shank", "foot")


@pytest.fixture
def cal_dir(tmp_path, walk_clean):
    """A directory as 'lowerlimb calibrate' leaves it (the parts the view reads), 5 s of walking."""
    n = 500
    walk_clean.model.write_urdf(tmp_path / "calibrated.urdf")
    write_angles_csv(tmp_path / "angles.csv", walk_clean.trial.time_s[:n], walk_clean.angles_rad[:n])
    return tmp_path


def test_load_view_data_reads_degrees_as_radians(cal_dir, walk_clean):
    data = load_view_data(cal_dir)
    assert data.time_s.shape == (500,) and data.angles_rad.shape == (500, 9)
    assert np.allclose(data.angles_rad, walk_clean.angles_rad[:500], atol=1e-7)
    want = walk_clean.model.geometry
    assert np.allclose(data.model.geometry.sensor_placements["shank"], want.sensor_placements["shank"])
    assert np.allclose(data.model.knee_axis_in_thigh, want.knee_axis_in_thigh)


def test_build_animation_records_the_trial_without_a_server(cal_dir):
    anim = build_animation(cal_dir, fps=20.0)
    scene, data = anim.scene, anim.data
    duration = data.time_s[-1] - data.time_s[0]
    n_frames = int(np.floor(duration * 20.0)) + 1
    assert scene.frame_time_s.shape == (n_frames,)
    assert anim.recorder is not None and anim.scene.animation is not None
    # the segment poses are the calibrated model's forward kinematics, pelvis fixed
    for k in (0, n_frames - 1):
        angles = np.array(
            [np.interp(scene.frame_time_s[k] + data.time_s[0], data.time_s, a) for a in data.angles_rad.T]
        )
        want = data.model.frame_poses(data.model.configuration(angles), SEGMENTS)
        T_pelvis = scene.segment_poses["pelvis"][k]
        assert np.allclose(T_pelvis[:3, :3], R_WORLD_PELVIS)
        for seg in SEGMENTS:
            rel = np.linalg.inv(T_pelvis) @ scene.segment_poses[seg][k]
            assert np.allclose(rel, want[seg].homogeneous, atol=1e-9)
    # the recorded set_animation command carries one clip per segment with every frame
    commands = [umsgpack.unpackb(m) for m in anim.recorder.messages]
    (cmd,) = [c for c in commands if c["type"] == "set_animation"]
    assert sorted(a["path"] for a in cmd["animations"]) == sorted(f"/meshcat/leg/{s}" for s in SEGMENTS)
    for a in cmd["animations"]:
        assert {t["name"] for t in a["clip"]["tracks"]} == {".position", ".quaternion"}
        assert all(len(t["keys"]) == n_frames for t in a["clip"]["tracks"])
    # the foot stands on the grid at zero angles: the grid was moved to the floor
    (grid,) = [c for c in commands if c["type"] == "set_transform" and c["path"] == "/Grid"]
    assert grid["matrix"][14] < -0.3


@pytest.mark.parametrize(
    ("remove", "message"),
    [
        (
            "calibrated.urdf",
            r"calibrated\.urdf is missing; give the output directory of 'lowerlimb calibrate",
        ),
        ("angles.csv", r"angles\.csv is missing; give the output directory"),
    ],
)
def test_missing_files_name_the_fix(cal_dir, remove, message):
    (cal_dir / remove).unlink()
    with pytest.raises(InputError, match=message):
        build_animation(cal_dir)


def test_not_a_directory(tmp_path):
    with pytest.raises(InputError, match="is not a directory; give the output directory"):
        load_view_data(tmp_path / "nowhere")


def test_bad_files(cal_dir, caplog):
    urdf = cal_dir / "calibrated.urdf"
    text = urdf.read_text(encoding="utf-8")
    for damaged in ("<robot name='x'><link", text[: len(text) // 2]):  # the second: a truncated copy
        urdf.write_text(damaged, encoding="utf-8")
        with pytest.raises(
            InputError, match=r"calibrated\.urdf is damaged \(not well-formed XML: .*line"
        ) as e:
            load_view_data(cal_dir)
        assert str(e.value).endswith("; re-run lowerlimb calibrate") and "\n" not in str(e.value)
    assert not caplog.records  # yourdfpy's "Using different parsing approach." log is not reached
    urdf.write_text("<robot name='x'><link name='a'/></robot>", encoding="utf-8")
    with pytest.raises(InputError, match=r"is damaged \(URDF is not a lowerlimb leg: joint .*\); re-run"):
        load_view_data(cal_dir)


HEADER = ",".join(ANGLE_COLUMNS)
ROW = ",".join(["0.1"] * 10)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("time,a,b\n0,1,2\n", r"its header is 'time,a,b', not time,hip_flexion,hip_adduction,…"),
        (HEADER + "\n", "no data rows"),
        (HEADER + "\n0,1,2\n", "its rows have 3 values, not 10"),
        (HEADER + "\n" + ROW + "\n0,1,2\n", "data row 2 has 3 values, not 10"),
        (HEADER + "\n" + ROW + "\n0.2,0.1,0.1,0", "data row 2 has 4 values, not 10"),  # cut short
        (
            HEADER + "\n" + ROW + "\n0.2,0.1,0.1,0.1,,0.1,0.1,0.1,0.1,0.1\n",
            "data row 2, column 'knee_flexion' is empty",
        ),
        (
            HEADER + "\n" + ROW + "\n0.2,0.1,0.1,x,0.1,0.1,0.1,0.1,0.1,0.1\n",
            "column 'hip_internal_rotation' holds 'x'",
        ),
        (
            HEADER + "\n0.0," + ",".join(["nan"] * 9) + "\n",
            "NaN or infinite value at data row 1, column 'hip_flexion'",
        ),
        (HEADER + "\n" + ROW + "\n" + ROW + "\n", "time column is not strictly increasing at data row 2"),
    ],
)
def test_bad_angles_csv(cal_dir, text, message):
    (cal_dir / "angles.csv").write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as e:
        load_view_data(cal_dir)
    assert str(e.value).startswith(f"{cal_dir / 'angles.csv'} is damaged (") and message in str(e.value)
    assert str(e.value).endswith("); re-run lowerlimb calibrate")


def test_view_refuses_the_other_side_of_a_one_leg_result(cal_dir, capsys):
    assert load_view_data(cal_dir, "left").model.side == "left"
    with pytest.raises(InputError, match="is a one-leg result of the left leg, so it has no right leg"):
        load_view_data(cal_dir, "right")
    assert main(["view", str(cal_dir), "--side", "right"]) == 2  # refused before any server starts
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "drop --side right" in err


def test_cli_bad_dir_is_one_line_exit_2(tmp_path, capsys):
    assert main(["view", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith("lowerlimb: error: ") and "calibrated.urdf is missing" in err


def test_serve_starts_and_stops_a_meshcat_server(cal_dir):
    session = serve(cal_dir)
    try:
        assert session.url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(session.url, timeout=20) as page:
            assert b"MeshCat" in page.read()
        assert session.animation.scene.animation is not None
    finally:
        session.close()
    assert session.server is None
    with pytest.raises(urllib.error.URLError):
        urllib.request.urlopen(session.url, timeout=5)


def test_cli_view_serves_until_ctrl_c(cal_dir):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(
        [sys.executable, "-m", "lowerlimb.cli", "view", str(cal_dir)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        url = None
        assert proc.stdout is not None
        for line in proc.stdout:
            if line.startswith("lowerlimb: showing"):
                url = line.rsplit(" at ", 1)[1].strip()
                break
        assert url and url.startswith("http://")
        with urllib.request.urlopen(url, timeout=20) as page:
            assert b"MeshCat" in page.read()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert "stopped" in out
    with pytest.raises(urllib.error.URLError):
        urllib.request.urlopen(url, timeout=5)


@pytest.mark.browser
def test_live_view_renders_in_headless_chromium(cal_dir, tmp_path):
    session = serve(cal_dir)
    try:
        rgb = screenshot(session.url, tmp_path / "view.png", width=900, height=700, budget_ms=3000)
    finally:
        session.close()
    orange = orange_mask(rgb)
    rows, _ = np.nonzero(orange)
    assert orange.sum() > 40, "no IMU box drawn in the live view"
    assert rows.max() - rows.min() > 150


def test_a_two_leg_folder_shows_the_chosen_leg(tmp_path):
    """It was refused as "not a lowerlimb leg" (the lower-body URDF)."""
    from lowerlimb.io.bilateral_tables import BILATERAL_ANGLE_COLUMNS
    from lowerlimb.model.leg_model import LegModel

    for side in ("left", "right"):
        LegModel.from_template(side).write_urdf(tmp_path / f"calibrated_{side}.urdf")
    (tmp_path / "calibrated.urdf").write_text("<robot name='lower_body'/>")
    t = np.arange(50) / 100.0
    deg = np.column_stack([t, np.full((50, 9), 10.0), np.full((50, 9), -20.0)])
    header = ",".join(BILATERAL_ANGLE_COLUMNS)
    np.savetxt(tmp_path / "angles.csv", deg, delimiter=",", header=header, comments="")
    for side, value in (("left", 10.0), ("right", -20.0), (None, 10.0)):
        data = load_view_data(tmp_path, side)
        assert data.model.side == (side or "left") and data.angles_rad.shape == (50, 9)
        assert np.allclose(data.angles_rad, np.deg2rad(value))
