"""Two-leg (seven-IMU) trials: layout, validation messages, the calibrate command and its outputs.

The trial is two simulated legs sharing one pelvis (``bilateral_sim``); numeric
bounds are set from what the single-leg pipeline achieves on the simulator.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from bilateral_sim import simulate_two_legs

from lowerlimb.conventions import SIDES
from lowerlimb.errors import InputError, MissingColumnError, NonFiniteValueError, SampleGlitchError, UnitError
from lowerlimb.gait import EVENTS_COLUMNS, STATIONARY_COLUMNS
from lowerlimb.io.bilateral_tables import BILATERAL_ANGLE_COLUMNS, BILATERAL_POSITION_COLUMNS
from lowerlimb.io.bilateral_trial import BilateralTrial, trial_layout
from lowerlimb.io.recording import TWO_LEG_SENSORS

ROOT = Path(__file__).resolve().parents[1]


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "lowerlimb.cli", *args], capture_output=True, text=True, cwd=ROOT, check=False
    )


@pytest.fixture(scope="module")
def two_legs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(trial CSV, calibrate output folder) of the shared-pelvis simulation."""
    folder = tmp_path_factory.mktemp("bilateral")
    csv = folder / "walk7.csv"
    simulate_two_legs().trial.to_csv(csv)
    out = folder / "out"
    r = _cli("calibrate", str(csv), "--out", str(out))
    assert r.returncode == 0, r.stderr
    (folder / "stderr.txt").write_text(r.stderr)
    return csv, out


def test_the_console_names_each_leg_and_its_segments(two_legs: tuple[Path, Path]) -> None:
    _, out = two_legs
    err = (out.parent / "stderr.txt").read_text().splitlines()
    cal = json.loads((out / "calibration.json").read_text())
    start = {side: err.index(f"  {side} leg:") for side in ("left", "right")}
    assert start["left"] < start["right"] and err[start["left"] + 1].lstrip().startswith("joint calibration")
    for side in ("left", "right"):
        thigh = 1000 * cal["legs"][side]["segment_lengths_m"]["thigh"]
        assert any(line.startswith(f"  {side:<5s} thigh {thigh:.0f} mm, shank") for line in err), err
        assert f"<th>{side} thigh, shank</th><td>{thigh:.0f} mm," in (out / "report.html").read_text()


def test_layout_is_recognised_from_the_header():
    two = ["time"] + [f"{s}_{q}_{a}" for s in TWO_LEG_SENSORS for q in ("acc", "gyr") for a in "xyz"]
    one = ["time"] + [
        f"{s}_{q}_{a}" for s in ("pelvis", "thigh", "shank", "foot") for q in ("acc", "gyr") for a in "xyz"
    ]
    assert trial_layout(two) == "two_legs"
    assert trial_layout(one) == "one_leg"
    with pytest.raises(InputError, match="mixes single-leg columns"):
        trial_layout(one + ["left_thigh_acc_x"])


def test_joined_legs_share_the_pelvis_and_round_trip(tmp_path: Path):
    sim = simulate_two_legs()
    t = sim.trial
    assert t.leg("left").gyr["pelvis"] is t.leg("right").gyr["pelvis"]
    t.to_csv(tmp_path / "t.csv")
    back = BilateralTrial.from_csv(tmp_path / "t.csv")
    assert back.header() == t.header() and back.header()[1:4] == [
        "pelvis_acc_x",
        "pelvis_acc_y",
        "pelvis_acc_z",
    ]
    np.testing.assert_allclose(back.gyr["right_foot"], t.gyr["right_foot"], rtol=1e-8)


def _write_variant(tmp_path: Path, change) -> Path:
    t = simulate_two_legs().trial
    acc = {k: v.copy() for k, v in t.acc.items()}
    gyr = {k: v.copy() for k, v in t.gyr.items()}
    change(acc, gyr)
    path = tmp_path / "bad.csv"
    BilateralTrial(t.time_s.copy(), acc, gyr, None).to_csv(path)
    return path


def test_validation_names_the_column_as_in_the_file(tmp_path: Path):
    def nan(acc, gyr):
        gyr["left_thigh"][10, 1] = np.nan

    with pytest.raises(NonFiniteValueError, match="'left_thigh_gyr_y' has a NaN") as e:
        BilateralTrial.from_csv(_write_variant(tmp_path, nan))
    assert e.value.column == "left_thigh_gyr_y" and e.value.row == 11

    def degrees(acc, gyr):
        gyr["right_shank"] *= 180.0 / np.pi

    with pytest.raises(
        UnitError, match=r"right_shank gyro values up to \d+ look like deg/s.*multiply by π/180"
    ):
        BilateralTrial.from_csv(_write_variant(tmp_path, degrees))


def test_a_repeated_or_corrupt_two_leg_column_is_refused(tmp_path: Path):
    """A second ``left_thigh_gyr_x`` column used to win silently (a garbage left knee)."""
    path = _write_variant(tmp_path, lambda acc, gyr: None)
    lines = path.read_text().splitlines()
    path.write_text("\n".join([lines[0] + ",left_thigh_gyr_x"] + [r + ",0.0" for r in lines[1:]]) + "\n")
    with pytest.raises(InputError, match="has the column 'left_thigh_gyr_x' 2 times"):
        BilateralTrial.from_csv(path)

    def glitch(acc, gyr):
        acc["right_foot"][40, 2] = 1e300

    with pytest.raises(SampleGlitchError, match="'right_foot_acc_z' reads 1e\\+300 at data row 41") as e:
        BilateralTrial.from_csv(_write_variant(tmp_path, glitch))
    assert e.value.column == "right_foot_acc_z" and e.value.row == 41


def test_an_empty_cell_is_named_by_its_column(tmp_path: Path):
    """The fast reader refuses an empty cell; the careful one (the single-leg reader's) names it."""
    path = _write_variant(tmp_path, lambda acc, gyr: None)
    lines = path.read_text().splitlines()
    k = lines[0].split(",").index("right_shank_acc_x")
    cells = lines[5].split(",")
    cells[k] = ""
    lines[5] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="column 'right_shank_acc_x' is empty at data row 5"):
        BilateralTrial.from_csv(path)  # the file's fifth data row
    cells[k] = "abc"
    lines[5] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="'right_shank_acc_x' holds the text 'abc' at data row 5"):
        BilateralTrial.from_csv(path)  # a NaN before


def test_magnetometer_of_the_pelvis_only_is_said(tmp_path: Path):
    from lowerlimb.io.trial import PartialMagnetometerWarning

    path = _write_variant(tmp_path, lambda acc, gyr: None)
    lines = path.read_text().splitlines()
    mag = ",pelvis_mag_x,pelvis_mag_y,pelvis_mag_z"
    lines = [lines[0] + mag] + [r + ",20.0,0.0,-40.0" for r in lines[1:]]
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(PartialMagnetometerWarning, match="for pelvis but not for left_thigh"):
        assert BilateralTrial.from_csv(path).mag is None


def test_quoted_numbers_are_numbers(tmp_path: Path):
    path = _write_variant(tmp_path, lambda acc, gyr: None)
    lines = path.read_text().splitlines()
    quoted = [lines[0]] + [",".join(f'"{c}"' for c in r.split(",")) for r in lines[1:]]
    (tmp_path / "q.csv").write_text("\n".join(quoted) + "\n")
    a, b = BilateralTrial.from_csv(path), BilateralTrial.from_csv(tmp_path / "q.csv")
    assert np.array_equal(a.time_s, b.time_s) and np.array_equal(a.gyr["right_foot"], b.gyr["right_foot"])


def test_a_missing_two_leg_column_is_named(tmp_path: Path):
    t = simulate_two_legs().trial
    t.to_csv(tmp_path / "t.csv")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    header = lines[0].split(",")
    k = header.index("right_foot_acc_z")
    cut = [",".join(c for i, c in enumerate(line.split(",")) if i != k) for line in lines]
    (tmp_path / "cut.csv").write_text("\n".join(cut) + "\n")
    with pytest.raises(MissingColumnError, match="missing column 'right_foot_acc_z'.*left_/right_ thigh"):
        BilateralTrial.from_csv(tmp_path / "cut.csv")
    r = _cli("calibrate", str(tmp_path / "cut.csv"), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "right_foot_acc_z" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists()


def test_a_leg_copied_onto_the_other_is_refused(tmp_path: Path):
    def copy_left(acc, gyr):
        for s in ("thigh", "shank", "foot"):
            acc[f"right_{s}"], gyr[f"right_{s}"] = acc[f"left_{s}"].copy(), gyr[f"left_{s}"].copy()

    path = _write_variant(tmp_path, copy_left)
    with pytest.raises(InputError, match="left_thigh and right_thigh columns hold identical data"):
        BilateralTrial.from_csv(path)
    r = _cli("calibrate", str(path), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "identical data" in r.stderr and not (tmp_path / "o").exists()


def test_a_leg_without_motion_is_named(tmp_path: Path):
    def still_right(acc, gyr):
        for s in ("thigh", "shank", "foot"):
            acc[f"right_{s}"][:] = acc[f"right_{s}"][0]
            gyr[f"right_{s}"][:] = gyr[f"right_{s}"][0]

    r = _cli("calibrate", str(_write_variant(tmp_path, still_right)), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "no motion" in r.stderr and "right_thigh" in r.stderr and "--calibration" not in r.stderr
    assert not (tmp_path / "o").exists()


def test_side_and_single_leg_options_are_refused_for_two_legs(two_legs, tmp_path: Path):
    csv, _ = two_legs
    for extra, words in (
        (["--side", "right"], "is a two-leg trial"),
        (["--calibration", str(csv)], "--calibration is a single-leg option"),
        (["--reference", str(csv)], "for a two-leg trial drop it and run 'lowerlimb compare "),
        (["--export", "fbx"], "invalid choice"),
        (["--outputs", "foo"], "unknown output 'foo'"),
        (["--height", "inf"], "--height"),
    ):
        r = _cli("calibrate", str(csv), "--out", str(tmp_path / "o"), *extra)
        assert r.returncode == 2, r.stderr
        assert words in r.stderr and len(r.stderr.strip().splitlines()) == 1
        assert not (tmp_path / "o").exists()


def test_exports_and_chosen_outputs_of_two_legs(two_legs, tmp_path: Path):
    csv, _ = two_legs
    out = tmp_path / "ex"
    r = _cli(
        "calibrate", str(csv), "--out", str(out), "--export", "opensim", "--export", "bids", "--no-report"
    )
    assert r.returncode == 0, r.stderr
    names = {p.name for p in out.iterdir()}
    assert "report.html" not in names and {"angles.mot", "orientations.sto", "events.csv"} <= names
    assert {"angles.units.json", "positions.units.json"} <= names
    mot = (out / "angles.mot").read_text().splitlines()
    header = mot[mot.index("endheader") + 1].split("\t")
    assert {"knee_angle_l", "knee_angle_r", "hip_flexion_l", "hip_flexion_r"} <= set(header)
    sto = (out / "orientations.sto").read_text().splitlines()
    labels = sto[sto.index("endheader") + 1].split("\t")
    assert labels == ["time", "pelvis_imu", "femur_l_imu", "tibia_l_imu", "calcn_l_imu"] + [
        "femur_r_imu",
        "tibia_r_imu",
        "calcn_r_imu",
    ]
    channels = next(out.glob("*_channels.tsv")).read_text()
    assert "left_foot_to_right_foot_x" in channels and "right_knee_flexion" in channels
    only = tmp_path / "only"
    r = _cli("calibrate", str(csv), "--out", str(only), "--outputs", "angles")
    assert r.returncode == 0, r.stderr
    assert {p.name for p in only.iterdir()} == {
        "angles.csv",
        "angles.units.json",
        "events.csv",
        "stationary.csv",
        "gait.json",
    }


def test_outputs_have_the_two_leg_columns_and_keys(two_legs):
    csv, out = two_legs
    names = sorted(p.name for p in out.iterdir())
    for f in ("angles.csv", "positions.csv", "events.csv", "gait.json", "calibration.json", "report.html"):
        assert f in names
    assert "calibrated_left.urdf" in names and "calibrated_right.urdf" in names
    assert "calibrated.urdf" in names
    assert tuple(open(out / "angles.csv").readline().strip().split(",")) == BILATERAL_ANGLE_COLUMNS
    assert tuple(open(out / "positions.csv").readline().strip().split(",")) == BILATERAL_POSITION_COLUMNS
    assert tuple(open(out / "events.csv").readline().strip().split(",")) == EVENTS_COLUMNS
    assert (
        BILATERAL_ANGLE_COLUMNS[1] == "left_hip_flexion"
        and BILATERAL_ANGLE_COLUMNS[10] == "right_hip_flexion"
    )
    assert BILATERAL_POSITION_COLUMNS[-3:] == tuple(f"left_foot_to_right_foot_{a}" for a in "xyz")
    cal = json.loads((out / "calibration.json").read_text())
    assert cal["format"] == "lowerlimb-calibration/1" and cal["runtime_s"] > 0
    assert cal["shared_pelvis_heading"] is True
    prov = cal["provenance"]  # as a one-leg calibration.json: versions, input, options
    assert prov["input_file"] == str(csv) and len(prov["input_sha256"]) == 64
    assert prov["options"]["centre_form"] == "norm" and prov["options"]["clock_sync"] is True
    assert prov["options"]["side"] == "both"  # not the one-leg default, "left"
    for side in SIDES:
        joints = cal["legs"][side]["joints"]
        assert joints["hip"]["parent_sensor"] == "pelvis" and joints["hip"]["child_sensor"] == "thigh"
        assert len(joints["knee"]["axis_in_parent_sensor"]) == 3 and "rms_residual" in joints["ankle"]
    gait = json.loads((out / "gait.json").read_text())
    keys = ("cadence_steps_per_min", "gait_speed_m_s", "step_width_m", "left", "right", "track_drift_max_m")
    assert set(keys) <= set(gait)
    drift = gait["track_drift_max_m"]  # null when nothing was removed
    assert drift is None or 0.0 <= drift < 0.5
    for side in SIDES:
        for key in ("stride_time_s", "stride_length_m", "step_length_m", "stance_pct", "double_support_pct"):
            assert {"mean", "sd"} <= set(gait[side][key])
    rows = (out / "events.csv").read_text().splitlines()[1:]
    assert rows and {r.split(",")[2] for r in rows} == {"initial_contact", "toe_off"}
    assert {r.split(",")[1] for r in rows} == {"left", "right"}
    _check_stationary(out, rows)


def _check_stationary(out, event_rows):
    """stationary.csv: both feet, ordered non-overlapping periods, no heel strike inside one."""
    lines = (out / "stationary.csv").read_text().splitlines()
    assert tuple(lines[0].split(",")) == STATIONARY_COLUMNS
    periods = [(r.split(",")[0], float(r.split(",")[1]), float(r.split(",")[2])) for r in lines[1:]]
    assert {side for side, _, _ in periods} == {"left", "right"}
    for side in SIDES:
        mine = sorted((a, b) for s_, a, b in periods if s_ == side)
        assert all(a <= b for a, b in mine) and all(
            b0 < a1 for (_, b0), (a1, _) in zip(mine[:-1], mine[1:], strict=True)
        )
        ics = [float(r.split(",")[0]) for r in event_rows if r.split(",")[1:] == [side, "initial_contact"]]
        assert not any(a + 0.02 < t < b - 0.02 for t in ics for a, b in mine)


def test_both_legs_calibrate_against_the_truth(two_legs):
    _, out = two_legs
    sim = simulate_two_legs()
    cal = json.loads((out / "calibration.json").read_text())
    for side in SIDES:
        truth = sim.sims[side].truth["joints"]
        for joint, key in (("hip", "center_in_parent_sensor"), ("ankle", "center_in_child_sensor")):
            err = np.linalg.norm(np.subtract(cal["legs"][side]["joints"][joint][key], truth[joint][key]))
            assert err < 0.03, (side, joint, err)
    hips = cal["hips"]
    assert hips["plausible"] and abs(hips["spacing_m"] - hips["expected_spacing_m"]) < 0.03
    pos = np.loadtxt(out / "positions.csv", delimiter=",", skiprows=1)
    f2f = pos[:, -3:]
    rmse = float(np.sqrt(np.mean(np.sum((f2f - sim.left_foot_to_right_foot_m) ** 2, axis=1))))
    assert rmse < 0.05, rmse
    np.testing.assert_allclose(f2f, pos[:, 4:7] - pos[:, 1:4], atol=2e-7)


def test_two_leg_report_overlays_the_gait_cycles_of_both_sides(two_legs):
    _, out = two_legs
    page = (out / "report.html").read_text()
    assert "id='gait-cycles'" in page  # both simulated legs walk (in phase)
    assert "gait-parameters" in page and "SI (%)" in page
    table = page.split("id='gait-parameters'", 1)[1].split("</table>", 1)[0]
    assert "anchored" not in table  # a flag, not a parameter


def test_a_walk_too_short_for_a_cadence_still_writes_its_report(tmp_path: Path):
    """3 s of a seven-IMU walk (one step per side): gait.json's cadence is null and the
    report says so instead of failing on it (it was an internal error)."""
    from lowerlimb.simulation import simulate_bilateral

    full = simulate_bilateral(30.0, 3).trial
    k = int(round(3.0 * full.rate_hz))
    short = BilateralTrial(
        full.time_s[:k], {s: a[:k] for s, a in full.acc.items()}, {s: g[:k] for s, g in full.gyr.items()}
    )
    short.to_csv(tmp_path / "short.csv")
    r = _cli("calibrate", str(tmp_path / "short.csv"), "--out", str(tmp_path / "o"))
    assert r.returncode == 0, r.stderr
    assert "internal error" not in r.stderr
    gait = json.loads((tmp_path / "o" / "gait.json").read_text())
    assert gait["cadence_steps_per_min"] is None
    assert "cadence" not in (tmp_path / "o" / "report.html").read_text().split("<h2>")[0]


def test_an_inverted_accelerometer_sign_is_named_among_the_causes():
    """Every accelerometer negated (−9.81 along up at rest) mirrors the joint centres: the
    hips come out on the wrong sides, and the message names that cause too."""
    import warnings

    from lowerlimb.bilateral import process_bilateral_trial
    from lowerlimb.bilateral.process import BilateralSideError

    t = simulate_two_legs().trial
    flipped = BilateralTrial(t.time_s, {k: -v for k, v in t.acc.items()}, t.gyr, t.mag)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(BilateralSideError, match="-9.81 along up at rest.*negate the acc columns"):
            process_bilateral_trial(flipped)
