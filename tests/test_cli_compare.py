import csv
import json
import warnings

import numpy as np
import pytest

from lowerlimb.cli import main
from lowerlimb.conventions import ANGLE_COLUMNS, POSITION_COLUMNS
from lowerlimb.io.tables import write_angles_csv, write_positions_csv


def _calibrate_dir(tmp_path):
    """A calibrate-like output folder (angles.csv in deg, positions.csv in m) on a 100 Hz clock."""
    d = tmp_path / "cal"
    d.mkdir()
    t = np.arange(0, 12, 0.01)
    phase = 2 * np.pi * 0.9 * t
    angles_rad = np.deg2rad(
        np.column_stack([(k + 1) * 5 * np.sin(phase + k) + 3 * np.sin(0.37 * t) for k in range(9)])
    )
    positions_m = np.column_stack([0.1 * np.sin(phase + k) + 0.02 * np.cos(0.41 * t) for k in range(6)])
    write_angles_csv(d / "angles.csv", t, angles_rad)
    write_positions_csv(d / "positions.csv", t, positions_m)
    return d, t, np.rad2deg(angles_rad), positions_m


def _write_ref(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def test_compare_writes_agreement_plots_and_offset(tmp_path, capsys):
    d, t, deg, pos = _calibrate_dir(tmp_path)
    offset = 0.12
    t_ref = t[50:-50] - offset  # reference clock lags ours by 0.12 s
    knee = list(ANGLE_COLUMNS).index("knee_flexion") - 1
    ref_knee = deg[50:-50, knee] - 2.0  # lowerlimb reads 2 deg more
    ref_px = pos[50:-50, 0]
    ref_px_gap = ref_px.copy()
    ref_px_gap[100:200] = np.nan
    rows = [
        [f"{a:.6f}", f"{b:.6f}", "" if np.isnan(c) else f"{c:.7f}", "1"]
        for a, b, c in zip(t_ref, ref_knee, ref_px_gap, strict=True)
    ]
    ref = tmp_path / "vicon.csv"
    _write_ref(ref, ["time", "knee_flexion", "pelvis_to_foot_x", "marker_count"], rows)
    out = tmp_path / "agree"
    assert main(["compare", str(d), str(ref), "--out", str(out), "--align-time"]) == 0
    assert "shifted by +0.120 s" in capsys.readouterr().out
    assert {p.name for p in out.iterdir()} == {
        "agreement.csv",
        "agreement.json",
        "bland_altman_angles.png",
        "bland_altman_positions.png",
    }
    with open(out / "agreement.csv") as f:
        table = {r["quantity"]: r for r in csv.DictReader(f)}
    assert list(table) == ["knee_flexion", "pelvis_to_foot_x"]
    k = table["knee_flexion"]
    assert k["unit"] == "deg" and table["pelvis_to_foot_x"]["unit"] == "m"
    assert float(k["bias"]) == pytest.approx(2.0, abs=0.01)
    assert float(k["loa_lower"]) == pytest.approx(2.0, abs=0.02) and float(k["loa_upper"]) == pytest.approx(
        2.0, abs=0.02
    )
    assert float(k["pearson_r"]) == pytest.approx(1.0, abs=1e-4)
    assert float(k["cmc"]) < 1.0  # the 2 deg offset lowers the CMC, not r
    # the 100-sample gap is dropped, plus a neighbour at each edge and end for a sub-sample shift
    assert t_ref.size - 104 <= int(table["pelvis_to_foot_x"]["n"]) <= t_ref.size - 100
    assert float(table["pelvis_to_foot_x"]["rmse"]) < 1e-4
    summary = json.loads((out / "agreement.json").read_text())
    assert summary["time_offset_s"] == pytest.approx(offset, abs=0.002)
    assert summary["ignored_reference_columns"] == ["marker_count"]
    assert summary["plots"] == ["bland_altman_angles.png", "bland_altman_positions.png"]

    out2 = tmp_path / "agree2"
    assert main(["compare", str(d), str(ref), "--out", str(out2), "--remove-offset"]) == 0
    with open(out2 / "agreement.csv") as f:
        k2 = next(r for r in csv.DictReader(f) if r["quantity"] == "knee_flexion")
    assert float(k2["bias"]) == pytest.approx(0.0, abs=1e-9)
    assert float(k2["offset_removed"]) > 1.0  # the unaligned 0.12 s adds to the 2 deg differently
    assert json.loads((out2 / "agreement.json").read_text())["time_offset_s"] == 0.0
    assert POSITION_COLUMNS[1] == "pelvis_to_foot_x"


@pytest.mark.parametrize(
    "case, message",
    [
        ("missing_dir", "is not a directory"),
        ("missing_ref", "does not exist"),
        ("empty_dir", "neither angles.csv nor positions.csv"),
        ("no_common", "rename its columns"),
        ("no_overlap", "no overlap"),
        ("nan_only", "fewer than 3 finite values"),
        ("no_time", "no header with a 'time' column"),
        ("existing_out", "already exists"),
    ],
)
def test_compare_bad_input_is_one_line_exit_2_and_writes_nothing(case, message, tmp_path, capsys):
    d, t, deg, _ = _calibrate_dir(tmp_path)
    ref = tmp_path / "ref.csv"
    header, cols = ["time", "knee_flexion"], [t, deg[:, 3]]
    if case == "no_common":
        header = ["time", "KneeFlex"]
    elif case == "no_overlap":
        cols = [t + 1000.0, deg[:, 3]]
    elif case == "nan_only":
        cols = [t, np.full(t.size, np.nan)]
    elif case == "no_time":
        header = ["t", "knee_flexion"]
    _write_ref(
        ref, header, [["" if np.isnan(v) else f"{v:.6f}" for v in row] for row in zip(*cols, strict=True)]
    )
    if case == "missing_dir":
        d = tmp_path / "nope"
    elif case == "missing_ref":
        ref = tmp_path / "nope.csv"
    elif case == "empty_dir":
        (d / "angles.csv").unlink()
        (d / "positions.csv").unlink()
    out = tmp_path / "agree"
    if case == "existing_out":
        out.mkdir()
        (out / "keep.txt").write_text("mine")
    before = sorted(p.name for p in tmp_path.iterdir())
    assert main(["compare", str(d), str(ref), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert err.startswith("lowerlimb: error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing half-written, no staging left
    if case == "existing_out":
        assert [p.name for p in out.iterdir()] == ["keep.txt"]


def test_compare_requires_out(capsys):
    assert main(["compare", "a", "b.csv"]) == 2
    assert "--out" in capsys.readouterr().err


def _rows(*columns, digits=6):
    """CSV rows of equal-length columns, each value with ``digits`` decimals."""
    return [[f"{v:.{digits}f}" for v in row] for row in zip(*columns, strict=True)]


def _refused_in_one_line(capsys, out, words):
    """stderr is one error line holding every word, without a traceback, and ``out`` was not made."""
    err = capsys.readouterr().err
    assert err.startswith("lowerlimb: error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert all(w in err for w in words), err
    assert not out.exists()


def _hostile_reference(case, path, t, deg, pos):
    """Write the reference of one hostile case; returns the words its one-line error must hold."""
    knee = deg[:, 3]
    header = ["time", "knee_flexion"]
    if case == "latin1":
        text = "time,knee_flexion,subject\n" + "".join(f"{a},{b},Müller\n" for a, b in _rows(t, knee))
        path.write_bytes(text.encode("latin-1"))
        return ["is not UTF-8 text", "byte 0xfc", "line 2", "save it as UTF-8"]
    if case == "time_ms":
        _write_ref(path, header, _rows(1000 * t, knee))
        return ["time steps of 10", "milliseconds", "lowerlimb's are 0.01 s", "divide its time column"]
    if case == "tiny_overlap":
        _write_ref(path, header, _rows(t - t[-1] + 0.5, knee))
        return ["overlap for only 0.5 s", "at least 25 %", "put both on one clock"]
    if case == "duplicate_column":
        _write_ref(path, [*header, "knee_flexion"], _rows(t, knee, -knee))
        return ["'knee_flexion' 2 times", "must appear once"]
    if case == "unsorted":
        rows = _rows(t, knee)
        rows[10], rows[11] = rows[11], rows[10]
        _write_ref(path, header, rows)
        return ["not strictly increasing at data row 12", "sort the rows"]
    if case == "radians":
        _write_ref(path, header, _rows(t, np.deg2rad(knee)))
        return ["'knee_flexion'", "looks like radians", "multiply by 180/π"]
    if case == "millimetres":
        _write_ref(path, ["time", "pelvis_to_foot_y"], _rows(t, 1000 * pos[:, 1], digits=3))
        return ["'pelvis_to_foot_y'", "looks like millimetres", "divide by 1000"]
    raise AssertionError(case)


@pytest.mark.parametrize(
    "case",
    ["latin1", "time_ms", "tiny_overlap", "duplicate_column", "unsorted", "radians", "millimetres"],
)
def test_compare_refuses_a_hostile_reference_with_one_line(case, tmp_path, capsys):
    d, t, deg, pos = _calibrate_dir(tmp_path)
    ref = tmp_path / "ref.csv"
    words = _hostile_reference(case, ref, t, deg, pos)
    out = tmp_path / "agree"
    assert main(["compare", str(d), str(ref), "--out", str(out)]) == 2
    _refused_in_one_line(capsys, out, words)


@pytest.mark.parametrize(
    "case, words",
    [
        (
            "other_leg",
            [
                "is the left leg's result",
                "names the right leg",
                "right_knee_flexion",
                "give the result of a right-leg or two-leg trial",
            ],
        ),
        ("both_legs", ["names both legs", "two-leg result"]),
        ("own_leg_prefixed", ["names the left leg with a 'left_' prefix", "drop the 'left_' prefix"]),
        ("no_angles", ["has no angles.csv", "re-run calibrate with the angles output"]),
        ("two_legs_unprefixed", ["is a two-leg result", "names no leg", "'left_' or 'right_'"]),
    ],
)
def test_compare_names_why_no_reference_column_is_ours(case, words, tmp_path, capsys):
    d, t, deg, _ = _calibrate_dir(tmp_path)
    (d / "calibration.json").write_text(json.dumps({"side": "left"}))
    ref = tmp_path / "ref.csv"
    header = {
        "other_leg": ["time", "right_knee_flexion", "right_hip_flexion"],
        "both_legs": ["time", "left_knee_flexion", "right_knee_flexion"],
        "own_leg_prefixed": ["time", "left_knee_flexion", "left_hip_flexion"],
        "no_angles": ["time", "knee_flexion", "hip_flexion"],
        "two_legs_unprefixed": ["time", "knee_flexion", "hip_flexion"],
    }[case]
    _write_ref(ref, header, _rows(t, deg[:, 3], deg[:, 0]))
    if case == "no_angles":  # as 'calibrate --outputs positions' leaves it
        (d / "angles.csv").unlink()
    if case == "two_legs_unprefixed":
        two = ["time"] + [f"{s}_{c}" for s in ("left", "right") for c in ANGLE_COLUMNS[1:]]
        _write_ref(d / "angles.csv", two, _rows(t, *deg.T, *deg.T))
        (d / "positions.csv").unlink()
    out = tmp_path / "agree"
    assert main(["compare", str(d), str(ref), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("lowerlimb: error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert all(w in err for w in words), err
    assert "rename its columns to ours" not in err
    assert not out.exists()


def test_compare_reads_a_header_in_capitals_with_our_units(tmp_path):
    d, t, deg, pos = _calibrate_dir(tmp_path)
    ref = tmp_path / "ref.csv"
    _write_ref(
        ref, ["Time (s)", "KNEE_FLEXION [deg]", "Pelvis_To_Foot_Y (m)"], _rows(t, deg[:, 3], pos[:, 1])
    )
    out = tmp_path / "agree"
    assert main(["compare", str(d), str(ref), "--out", str(out)]) == 0
    with open(out / "agreement.csv") as f:
        table = {r["quantity"]: r for r in csv.DictReader(f)}
    assert list(table) == ["knee_flexion", "pelvis_to_foot_y"]
    assert float(table["knee_flexion"]["rmse"]) < 1e-4
    ref.write_text(ref.read_text().replace("Time (s)", "time_s", 1))
    assert main(["compare", str(d), str(ref), "--out", str(tmp_path / "agree2")]) == 0


@pytest.mark.parametrize(
    "case, words",
    [
        ("semicolons", ["is separated by ';', not commas", "save it comma-separated"]),
        ("time_ms_column", ["column 'time_ms' in milliseconds", "in seconds as 'time'", "divide by 1000"]),
        ("time_annotated_ms", ["column 'Time [ms]' in milliseconds", "divide by 1000"]),
        ("angle_in_rad", ["column 'knee_flexion (rad)' in radians", "in degrees", "multiply by 180/π"]),
        ("position_in_mm", ["column 'pelvis_to_foot_y [mm]' in millimetres", "in metres", "divide by 1000"]),
        ("directory", ["is a directory, not a CSV file", "give the path of a CSV file"]),
    ],
)
def test_compare_names_the_real_problem_of_a_header(case, words, tmp_path, capsys):
    d, t, deg, _ = _calibrate_dir(tmp_path)
    ref = tmp_path / "ref.csv"
    header = {
        "time_ms_column": ["time_ms", "knee_flexion"],
        "time_annotated_ms": ["Time [ms]", "knee_flexion"],
        "angle_in_rad": ["time", "knee_flexion (rad)"],
        "position_in_mm": ["time", "pelvis_to_foot_y [mm]"],
    }.get(case, ["time", "knee_flexion"])
    scale = 1000 if "ms" in case else 1
    _write_ref(ref, header, _rows(scale * t, deg[:, 3]))
    if case == "semicolons":
        ref.write_text(ref.read_text().replace(",", ";"))
    if case == "directory":
        ref = d  # a result folder given as the reference
    out = tmp_path / "agree"
    assert main(["compare", str(d), str(ref), "--out", str(out)]) == 2
    _refused_in_one_line(capsys, out, words)


def test_compare_align_time_warns_in_one_line_when_strides_make_the_offset_ambiguous(tmp_path):
    d = tmp_path / "cal"
    d.mkdir()
    t = np.arange(0, 30, 0.01)
    rng = np.random.default_rng(7)
    knots = np.arange(-10, 40, 1.1)

    def walk(tt):  # a walk repeating each 1.1 s stride, its amplitude varying by stride (deg)
        amp = np.interp(tt, knots, 1 + 0.1 * rng_amp)
        phase = 2 * np.pi * tt / 1.1
        return np.column_stack([(k + 1) * 5 * amp * np.sin(phase + k) for k in range(9)])

    rng_amp = rng.standard_normal(knots.size)
    write_angles_csv(d / "angles.csv", t, np.deg2rad(walk(t)))
    t_true = np.arange(-8, 38, 0.01)
    ref = tmp_path / "ref.csv"
    _write_ref(ref, list(ANGLE_COLUMNS), _rows(t_true + 5.0, *walk(t_true).T))  # 5 s late: beyond ±2 s
    with pytest.warns(UserWarning) as caught:  # the CLI prints each as one 'lowerlimb: warning:' line
        assert main(["compare", str(d), str(ref), "--out", str(tmp_path / "o"), "--align-time"]) == 0
    assert len(caught) == 1
    text = str(caught[0].message)
    assert "\n" not in text and "is ambiguous" in text and "align the reference by hand" in text
    summary = json.loads((tmp_path / "o" / "agreement.json").read_text())
    assert summary["time_alignment"]["ambiguous"] is True
    _write_ref(ref, list(ANGLE_COLUMNS), _rows(t_true + 1.5, *walk(t_true).T))  # within ±2 s: found, clear
    with warnings.catch_warnings(record=True) as caught:
        assert main(["compare", str(d), str(ref), "--out", str(tmp_path / "o2"), "--align-time"]) == 0
    assert not caught, [str(w.message) for w in caught]
    summary = json.loads((tmp_path / "o2" / "agreement.json").read_text())
    assert summary["time_offset_s"] == pytest.approx(-1.5, abs=0.002)
    assert summary["time_alignment"]["ambiguous"] is False


def test_compare_accepts_a_reference_that_covers_part_of_the_trial(tmp_path):
    d, t, deg, _ = _calibrate_dir(tmp_path)
    ref = tmp_path / "ref.csv"
    part = (t > 4) & (t < 8)  # a 4 s reference inside a 12 s trial: all of its span overlaps
    _write_ref(ref, ["time", "knee_flexion"], _rows(t[part], deg[part, 3]))
    assert main(["compare", str(d), str(ref), "--out", str(tmp_path / "agree")]) == 0


@pytest.fixture(scope="module")
def walk_trial_csv(walk_clean, tmp_path_factory):
    """A simulated one-leg walk as a trial CSV, its (N,) time, s, and (N, 9) angles, deg."""
    path = tmp_path_factory.mktemp("walk") / "walk.csv"
    walk_clean.trial.to_csv(path)
    return path, np.asarray(walk_clean.trial.time_s), np.rad2deg(walk_clean.angles_rad)


@pytest.mark.parametrize("case", ["time_ms", "duplicate_column", "no_overlap", "unsorted", "latin1"])
def test_calibrate_refuses_a_bad_reference_before_computing(case, walk_trial_csv, tmp_path, capsys):
    trial, t, deg = walk_trial_csv
    ref = tmp_path / "ref.csv"
    if case == "no_overlap":
        _write_ref(ref, ["time", "knee_flexion"], _rows(t + 1000, deg[:, 3]))
        words = ["no overlap", "put both on one clock"]
    else:
        words = _hostile_reference(case, ref, t, deg, np.zeros((t.size, 6)))
    out = tmp_path / "o"
    assert main(["calibrate", str(trial), "--out", str(out), "--reference", str(ref)]) == 2
    _refused_in_one_line(capsys, out, words)  # and no progress line: refused before calibrating


@pytest.mark.parametrize("flags", [["--no-report"], ["--outputs", "calibration,angles"]])
def test_calibrate_refuses_a_reference_without_the_report(flags, walk_trial_csv, tmp_path, capsys):
    trial, t, deg = walk_trial_csv
    ref = tmp_path / "ref.csv"
    _write_ref(ref, ["time", "knee_flexion"], _rows(t, deg[:, 3]))
    out = tmp_path / "o"
    assert main(["calibrate", str(trial), "--out", str(out), "--reference", str(ref), *flags]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "report.html, which is not written" in err and "drop --reference" in err
    assert not out.exists()
