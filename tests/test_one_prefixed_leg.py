"""One leg exported with the two-leg names: ``pelvis``, ``right_thigh``, ``right_shank``, ``right_foot``.

A lab that instruments one leg often keeps its system's side-prefixed sensor names. Such a header
is that leg: ``calibrate`` takes the side from the names (no ``--side`` needed), gives the same
results as the same signals under the single-leg names, refuses a ``--side`` of the other leg in
one line, names the columns as they are in the file in its messages, and a study reads the side
from the names when its manifest gives none.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lowerlimb.batch import BatchParams, run_study
from lowerlimb.cli import main
from lowerlimb.errors import InputError
from lowerlimb.io.bilateral_trial import trial_layout
from lowerlimb.io.trial import ImuTrial, one_side_prefix
from lowerlimb.simulation import simulate


@pytest.fixture(scope="module")
def right_leg(tmp_path_factory) -> tuple[Path, Path]:
    """The same right-leg walk as a single-leg CSV and with ``right_`` prefixed sensor names."""
    root = tmp_path_factory.mktemp("prefixed")
    plain = root / "plain.csv"
    simulate("walk", 12.0, seed=2, side="right").trial.to_csv(plain)
    lines = plain.read_text().splitlines()
    header = [h if h.startswith(("time", "pelvis")) else f"right_{h}" for h in lines[0].split(",")]
    prefixed = root / "prefixed.csv"
    prefixed.write_text("\n".join([",".join(header), *lines[1:]]) + "\n")
    return plain, prefixed


def test_the_header_names_one_side_only() -> None:
    one = ["time", "pelvis_acc_x", "left_thigh_acc_x", "left_shank_acc_x", "left_foot_acc_x"]
    assert one_side_prefix(one) == "left" and trial_layout(one) == "one_leg"
    both = [*one, "right_thigh_acc_x"]
    assert one_side_prefix(both) is None and trial_layout(both) == "two_legs"
    assert one_side_prefix(["time", "pelvis_acc_x", "thigh_acc_x"]) is None


def test_calibrate_takes_the_side_from_the_names(right_leg, tmp_path, capsys) -> None:
    plain, prefixed = right_leg
    assert main(["calibrate", str(plain), "--side", "right", "--out", str(tmp_path / "a")]) == 0
    capsys.readouterr()
    assert main(["calibrate", str(prefixed), "--out", str(tmp_path / "b")]) == 0
    assert "right leg" in capsys.readouterr().err.splitlines()[0]
    a, b = (json.loads((tmp_path / d / "calibration.json").read_text()) for d in ("a", "b"))
    assert a["side"] == b["side"] == "right"
    for joint, fit in a["joints"].items():
        for key in ("center_in_parent_sensor", "center_in_child_sensor", "axis_in_parent_sensor"):
            assert fit.get(key) == b["joints"][joint].get(key), (joint, key)
    angles = [np.loadtxt(tmp_path / d / "angles.csv", delimiter=",", skiprows=1) for d in ("a", "b")]
    np.testing.assert_array_equal(angles[0], angles[1])


def test_the_other_side_is_refused_in_one_line(right_leg, tmp_path, capsys) -> None:
    _, prefixed = right_leg
    out = tmp_path / "o"
    assert main(["calibrate", str(prefixed), "--side", "left", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "right_thigh" in err[0] and "drop --side" in err[0]
    assert not out.exists()
    with pytest.raises(InputError, match="the side is left"):
        ImuTrial.from_csv(prefixed, side="left")


def test_messages_name_the_columns_as_in_the_file(right_leg, tmp_path) -> None:
    _, prefixed = right_leg
    lines = prefixed.read_text().splitlines()
    header = lines[0].split(",")
    row = lines[300].split(",")
    row[header.index("right_shank_gyr_y")] = "nan"
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join([lines[0], *lines[1:300], ",".join(row), *lines[301:]]) + "\n")
    with pytest.raises(InputError, match="'right_shank_gyr_y'"):
        ImuTrial.from_csv(bad)


def test_a_study_reads_the_side_from_the_names(right_leg, tmp_path) -> None:
    _, prefixed = right_leg
    root = tmp_path / "in"
    root.mkdir()
    (root / "walk.csv").write_bytes(prefixed.read_bytes())
    params = BatchParams(workers=1, outputs=frozenset({"calibration"}))
    result = run_study(root, tmp_path / "out", params)
    assert result.processed == 1
    cal = json.loads((tmp_path / "out" / "walk" / "calibration.json").read_text())
    assert cal["side"] == "right"


def test_an_import_mapping_of_one_prefixed_leg_says_how_to_name_it() -> None:
    from lowerlimb.io.errors import MappingError
    from lowerlimb.io.recording import sensor_layout

    with pytest.raises(MappingError, match="one leg: name its sensors pelvis, thigh, shank, foot"):
        sensor_layout(["pelvis", "left_thigh", "left_shank", "left_foot"])
    with pytest.raises(MappingError) as e:
        sensor_layout(["pelvis", "left_thigh", "left_shank", "left_foot", "right_thigh"])
    assert "one leg" not in str(e.value)
