"""BIDS-motion files checked against the specification's rules, and the units sidecars."""

import csv
import json

import numpy as np
import pytest

from lowerlimb.conventions import ANGLE_COLUMNS, POSITION_COLUMNS
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.export.bids import write_bids_motion
from lowerlimb.export.units import write_units_sidecar

# BIDS motion: REQUIRED channels.tsv columns and the restricted keyword lists
REQUIRED_COLUMNS = ["name", "component", "type", "tracked_point", "units"]
COMPONENTS = {"x", "y", "z", "quat_x", "quat_y", "quat_z", "quat_w", "n/a"}
TYPES = {"ACCEL", "ANGACCEL", "GYRO", "JNTANG", "LATENCY", "MAGN", "MISC", "ORNT", "POS", "VEL"}


def _two_leg_inputs(t):
    angles = {f"{s}_{n}": np.sin(t + k) for s in ("left", "right") for k, n in enumerate(ANGLE_COLUMNS[1:])}
    positions = {f"left_{n}": np.cos(t + k) for k, n in enumerate(POSITION_COLUMNS[1:])}
    positions.update({f"left_foot_to_right_foot_{a}": t * 0 + 0.2 for a in "xyz"})
    rng = np.random.default_rng(0)
    quats = {s: rng.normal(size=(t.size, 4)) for s in ("pelvis", "left_thigh")}
    return angles, positions, quats


def test_bids_motion_files_follow_the_spec(tmp_path):
    t = np.arange(0, 2, 0.01) + 3.0
    angles, positions, quats = _two_leg_inputs(t)
    angles["left_knee_flexion"] = angles["left_knee_flexion"].copy()
    angles["left_knee_flexion"][5] = np.nan
    files = write_bids_motion(
        tmp_path, t, subject="01", task="walk", angles_deg=angles, positions_m=positions, quats_wxyz=quats
    )
    assert files.motion_tsv.name == "sub-01_task-walk_tracksys-imu_motion.tsv"
    assert files.channels_tsv.name == "sub-01_task-walk_tracksys-imu_channels.tsv"
    assert files.motion_json.name == "sub-01_task-walk_tracksys-imu_motion.json"

    with open(files.channels_tsv) as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    assert list(rows[0])[:5] == REQUIRED_COLUMNS
    assert all(r[c] not in ("", None) for r in rows for c in REQUIRED_COLUMNS)
    assert {r["component"] for r in rows} <= COMPONENTS and {r["type"] for r in rows} <= TYPES
    n_channels = 1 + 18 + 9 + 8
    assert len(rows) == n_channels

    # motion.tsv: no header row, one column per channels.tsv row, n/a for missing
    lines = files.motion_tsv.read_text().splitlines()
    assert len(lines) == t.size
    cells = [line.split("\t") for line in lines]
    assert all(len(c) == n_channels for c in cells)
    float(cells[0][0])  # first line is data, not a header
    by_name = {r["name"]: i for i, r in enumerate(rows)}
    assert cells[5][by_name["left_knee_flexion"]] == "n/a"
    col = np.array([float(c[by_name["right_hip_adduction"]]) for c in cells])
    np.testing.assert_allclose(col, angles["right_hip_adduction"], atol=1e-7)
    latency = np.array([float(c[0]) for c in cells])
    np.testing.assert_allclose(latency, t - t[0], atol=1e-9)

    ch = {r["name"]: r for r in rows}
    assert ch["latency"]["type"] == "LATENCY" and ch["latency"]["units"] == "s"
    knee = ch["right_knee_flexion"]
    assert (knee["type"], knee["component"], knee["tracked_point"], knee["units"]) == (
        "JNTANG",
        "z",
        "right_knee",
        "deg",
    )
    assert (
        ch["left_ankle_inversion"]["component"] == "x"
        and ch["left_hip_internal_rotation"]["component"] == "y"
    )
    pos = ch["left_hip_to_ankle_y"]
    assert (pos["type"], pos["component"], pos["units"], pos["tracked_point"]) == (
        "POS",
        "y",
        "m",
        "left_ankle_centre",
    )
    assert pos["reference_frame"] == "left_hip_centre"
    assert ch["left_foot_to_right_foot_z"]["tracked_point"] == "right_foot_sensor"
    assert [ch[f"left_thigh_quat_{c}"]["component"] for c in "wxyz"] == [
        "quat_w",
        "quat_x",
        "quat_y",
        "quat_z",
    ]
    assert ch["pelvis_quat_w"]["type"] == "ORNT" and ch["pelvis_quat_w"]["reference_frame"] == "global"

    meta = json.loads(files.motion_json.read_text())
    for key in ("SamplingFrequency", "TaskName", "TrackingSystemName"):  # REQUIRED
        assert key in meta
    assert meta["SamplingFrequency"] == pytest.approx(100.0) and meta["TaskName"] == "walk"
    assert meta["MotionChannelCount"] == n_channels
    assert (meta["JNTANGChannelCount"], meta["POSChannelCount"], meta["ORNTChannelCount"]) == (18, 9, 8)
    assert meta["RecordingDuration"] == pytest.approx(1.99)
    levels = json.loads(files.channels_json.read_text())["reference_frame"]["Levels"]
    assert {r["reference_frame"] for r in rows} - {"n/a"} == set(levels)


def test_bids_one_leg_names_and_bad_input(tmp_path):
    t = np.arange(0, 1, 0.01)
    files = write_bids_motion(
        tmp_path, t, subject="p3", task="squat", session="2", side="right", angles_deg={"knee_flexion": t}
    )
    assert files.motion_tsv.name == "sub-p3_ses-2_task-squat_tracksys-imu_motion.tsv"
    assert files.channels[1].tracked_point == "right_knee"
    with pytest.raises(InputError, match="letters and digits"):
        write_bids_motion(tmp_path, t, subject="p_3", task="walk", angles_deg={"knee_flexion": t})
    with pytest.raises(InputError, match="not a lowerlimb angle"):
        write_bids_motion(tmp_path, t, subject="1", task="walk", angles_deg={"knee_valgus": t})
    with pytest.raises(InputError, match="not a lowerlimb position"):
        write_bids_motion(tmp_path, t, subject="1", task="walk", positions_m={"knee_to_toe_x": t})
    with pytest.raises(InputError, match="no angles"):
        write_bids_motion(tmp_path, t, subject="1", task="walk")
    with pytest.raises(ShapeError):
        write_bids_motion(tmp_path, t, subject="1", task="walk", quats_wxyz={"pelvis": np.ones((t.size, 3))})
    with pytest.raises(InputError, match="does not exist"):
        write_bids_motion(tmp_path / "nope", t, subject="1", task="walk", angles_deg={"knee_flexion": t})


def test_units_sidecars(tmp_path):
    units = write_units_sidecar(tmp_path / "angles.units.json", ANGLE_COLUMNS, "angles")
    doc = json.loads((tmp_path / "angles.units.json").read_text())
    assert doc["table"] == "angles.csv" and doc["units"] == units
    assert list(units) == list(ANGLE_COLUMNS)
    assert units["time"] == "s" and {units[c] for c in ANGLE_COLUMNS[1:]} == {"deg"}
    pos = write_units_sidecar(tmp_path / "positions.units.json", POSITION_COLUMNS, "positions")
    assert {pos[c] for c in POSITION_COLUMNS[1:]} == {"m"}
    assert write_units_sidecar(tmp_path / "x.json", {"time": "s", "a": "deg"}) == {"time": "s", "a": "deg"}
    with pytest.raises(InputError, match="kind"):
        write_units_sidecar(tmp_path / "y.json", ANGLE_COLUMNS)
    with pytest.raises(InputError, match="angles, positions"):
        write_units_sidecar(tmp_path / "y.json", ANGLE_COLUMNS, "forces")
