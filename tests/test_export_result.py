"""calibrate --export opensim/bids, units sidecars, --reference and TrialResult.to_dataframe()."""

import csv
import json
import sys

import numpy as np
import pytest

from lowerlimb.cli import main
from lowerlimb.conventions import ANGLE_COLUMNS, POSITION_COLUMNS, joint_angles_from_matrix, quat_to_matrix
from lowerlimb.errors import InputError, MissingDependencyError
from lowerlimb.export.opensim import Q_OPENSIM_FROM_ENU
from lowerlimb.export.result import check_export_formats
from lowerlimb.outputs import CalibrateOptions, run_calibrate

BIDS_STEM = "sub-01_task-walk_tracksys-imu"


def _storage(path):
    lines = path.read_text().splitlines()
    end = lines.index("endheader")
    meta = dict(line.split("=", 1) for line in lines[:end] if "=" in line)
    return meta, lines[end + 1].split("\t"), [r.split("\t") for r in lines[end + 2 :]]


@pytest.fixture(scope="module")
def exported(walk_clean, tmp_path_factory):
    d = tmp_path_factory.mktemp("exports")
    trial = d / "walk.csv"
    walk_clean.trial.to_csv(trial)
    truth_deg = np.rad2deg(walk_clean.angles_rad)
    reference = d / "vicon.csv"
    with open(reference, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time", "knee_flexion", "hip_flexion", "marker_x"])
        for t, row in zip(walk_clean.trial.time_s, truth_deg, strict=True):
            w.writerow([t, row[3], row[0], 0.0])
    out = d / "out"
    result = run_calibrate(
        CalibrateOptions(trial=trial, out=out, exports=("bids", "opensim"), reference=reference)
    )
    return result, out


def test_exports_and_sidecars_are_written(exported):
    _, out = exported
    names = {p.name for p in out.iterdir()}
    expected = {"angles.mot", "orientations.sto", "angles.units.json", "positions.units.json"}
    expected |= {f"{BIDS_STEM}_{s}" for s in ("motion.tsv", "channels.tsv", "motion.json", "channels.json")}
    assert expected <= names
    for table, columns, unit in (("angles", ANGLE_COLUMNS, "deg"), ("positions", POSITION_COLUMNS, "m")):
        doc = json.loads((out / f"{table}.units.json").read_text())
        header = (out / f"{table}.csv").read_text().splitlines()[0].split(",")
        assert list(doc["units"]) == header == list(columns)
        assert doc["units"]["time"] == "s" and set(list(doc["units"].values())[1:]) == {unit}


def test_mot_holds_the_angles_csv_values(exported):
    _, out = exported
    meta, labels, rows = _storage(out / "angles.mot")
    assert meta["inDegrees"] == "yes" and int(meta["nRows"]) == len(rows)
    mot = np.array(rows, dtype=float)
    angles = np.loadtxt(out / "angles.csv", delimiter=",", skiprows=1)
    knee = ANGLE_COLUMNS.index("knee_flexion")
    np.testing.assert_allclose(mot[:, labels.index("knee_angle_l")], angles[:, knee], atol=2e-6)
    np.testing.assert_allclose(mot[:, 0], angles[:, 0], atol=1e-6)


def test_sto_orientations_are_the_ones_the_angles_come_from(exported):
    """Knee angles rebuilt from orientations.sto and calibration.json's segment frames = angles.csv."""
    result, out = exported
    meta, labels, rows = _storage(out / "orientations.sto")
    assert meta["DataType"] == "Quaternion"
    assert labels == ["time", "pelvis_imu", "femur_l_imu", "tibia_l_imu", "calcn_l_imu"]
    q = {lab: np.array([r[k].split(",") for r in rows], dtype=float) for k, lab in enumerate(labels) if k}
    # heading-corrected sensor orientations, rotated into OpenSim's y-up world
    expected = quat_to_matrix(Q_OPENSIM_FROM_ENU) @ quat_to_matrix(result.motion.sensor_quat_wxyz["shank"])
    np.testing.assert_allclose(quat_to_matrix(q["tibia_l_imu"]), expected, atol=1e-7)
    frames = json.loads((out / "calibration.json").read_text())["segment_frames"]
    R = {
        seg: quat_to_matrix(q[lab]) @ quat_to_matrix(frames[seg]["quat_wxyz_segment_in_sensor"])
        for seg, lab in (("thigh", "femur_l_imu"), ("shank", "tibia_l_imu"))
    }
    knee = joint_angles_from_matrix(np.einsum("nji,njk->nik", R["thigh"], R["shank"]), "knee", "left")
    angles = np.loadtxt(out / "angles.csv", delimiter=",", skiprows=1)
    diff = np.angle(np.exp(1j * (np.rad2deg(knee[:, 0]) - angles[:, 4]) * np.pi / 180)) * 180 / np.pi
    assert np.max(np.abs(diff)) < 1e-3


def test_bids_files_are_consistent(exported):
    result, out = exported
    with open(out / f"{BIDS_STEM}_channels.tsv") as f:
        channels = list(csv.DictReader(f, delimiter="\t"))
    data = np.loadtxt(out / f"{BIDS_STEM}_motion.tsv", delimiter="\t")
    assert data.shape == (result.trial.n_samples, len(channels))
    kinds = [c["type"] for c in channels]
    assert kinds.count("JNTANG") == 9 and kinds.count("POS") == 6 and kinds.count("ORNT") == 16
    knee = next(i for i, c in enumerate(channels) if c["name"] == "knee_flexion")
    assert channels[knee]["units"] == "deg" and channels[knee]["tracked_point"] == "left_knee"
    np.testing.assert_allclose(data[:, knee], np.rad2deg(result.angles_rad[:, 3]), atol=1e-4)
    sidecar = json.loads((out / f"{BIDS_STEM}_motion.json").read_text())
    assert sidecar["TaskName"] == "walk" and sidecar["SamplingFrequency"] == pytest.approx(100.0)


def test_report_has_the_agreement_section(exported, walk_clean):
    result, out = exported
    page = (out / "report.html").read_text()
    assert "<section id='agreement'>" in page and "id='bland-altman-deg'" in page
    section = page[page.index("<section id='agreement'>") :]
    assert "<th>knee_flexion</th>" in section and "<th>hip_flexion</th>" in section
    assert "marker_x" in section  # listed as not ours
    assert "(vicon.csv)" in section
    # the reference is the simulator's truth: the knee row shows our RMSE against it
    truth = np.rad2deg(walk_clean.angles_rad[:, 3])
    rmse = np.sqrt(np.mean((np.rad2deg(result.angles_rad[:, 3]) - truth) ** 2))
    assert f"<th>knee_flexion</th><td>deg</td><td>{truth.size}</td><td>{rmse:.3g}</td>" in section


def test_to_dataframe_has_time_index_and_units(exported):
    pytest.importorskip("pandas")
    result, _ = exported
    df = result.to_dataframe()
    assert df.index.name == "time" and list(df.columns) == list(ANGLE_COLUMNS[1:] + POSITION_COLUMNS[1:])
    np.testing.assert_allclose(df.index.to_numpy(), result.trial.time_s)
    np.testing.assert_allclose(df["knee_flexion"].to_numpy(), np.rad2deg(result.angles_rad[:, 3]))
    np.testing.assert_allclose(df["hip_to_ankle_z"].to_numpy(), result.positions_m[:, 5])
    units = df.attrs["units"]
    assert units["time"] == "s" and units["knee_flexion"] == "deg" and units["pelvis_to_foot_x"] == "m"


def test_to_dataframe_without_pandas_names_the_fix(exported, monkeypatch):
    result, _ = exported
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'pandas'.*lowerlimb\[pandas\]") as e:
        result.to_dataframe()
    assert isinstance(e.value, ImportError) and e.value.package == "pandas"


def test_export_formats_are_checked():
    assert check_export_formats(["bids", "opensim", "bids"]) == ("opensim", "bids")
    with pytest.raises(InputError, match="unknown export format fbx; use one of opensim, bids"):
        check_export_formats(["fbx"])


def test_cli_passes_exports_and_reference(monkeypatch, tmp_path):
    seen = {}
    monkeypatch.setattr("lowerlimb.outputs.run_calibrate", lambda options: seen.setdefault("o", options))
    argv = ["calibrate", "t.csv", "--out", "o", "--export", "opensim", "--export", "bids"]
    assert main([*argv, "--reference", "ref.csv"]) == 0
    assert seen["o"].exports == ("opensim", "bids") and str(seen["o"].reference) == "ref.csv"


@pytest.mark.parametrize(
    "content, message",
    [
        (None, "does not exist"),
        ("time,foo\n0,1\n1,2\n", "has no column named as in angles.csv/positions.csv"),
        ("knee_flexion\n1\n", "no header with a 'time' column"),
    ],
)
def test_bad_reference_exits_2_before_computing(walk_clean, tmp_path, capsys, content, message):
    trial = tmp_path / "walk.csv"
    walk_clean.trial.to_csv(trial)
    ref = tmp_path / "ref.csv"
    if content is not None:
        ref.write_text(content)
    assert main(["calibrate", str(trial), "--out", str(tmp_path / "o"), "--reference", str(ref)]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()
