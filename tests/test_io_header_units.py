"""Unit annotations in trial CSV headers (``lowerlimb.io.header_units``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.cli import main
from lowerlimb.io.header_units import without_own_unit
from lowerlimb.io.trial import ImuTrial


@pytest.mark.parametrize(
    "cell, name",
    [
        ("pelvis_acc_x [m/s^2]", "pelvis_acc_x"),
        ("pelvis_acc_x (m/s²)", "pelvis_acc_x"),
        ("thigh_gyr_z [rad/s]", "thigh_gyr_z"),
        ("left_foot_mag_y [µt]", "left_foot_mag_y"),
        ("time (s)", "time"),
        ("time [sec]", "time"),
        ("pelvis_acc_x [g]", "pelvis_acc_x [g]"),  # another unit stays: the column is then missing
        ("thigh_gyr_z (deg/s)", "thigh_gyr_z (deg/s)"),
        ("time [ms]", "time [ms]"),
        ("label (s)", "label (s)"),  # not a trial column
        ("pelvis_acc_x", "pelvis_acc_x"),
    ],
)
def test_only_the_columns_own_unit_is_dropped(cell, name):
    assert without_own_unit(cell) == name


def _annotated(tmp_path: Path, units: dict[str, str]) -> Path:
    src = tmp_path / "plain.csv"
    cached_simulation("walk", 20.0, 0).trial.to_csv(src)
    lines = src.read_text().splitlines()
    header = [
        f"{h} {units[h.split('_')[-2]]}" if h != "time" else f"Time {units['time']}"
        for h in lines[0].split(",")
    ]
    out = tmp_path / "annotated.csv"
    out.write_text("\n".join([",".join(header)] + lines[1:]) + "\n")
    return out


def test_a_header_with_its_own_units_reads_as_without(tmp_path):
    path = _annotated(tmp_path, {"time": "(s)", "acc": "[m/s^2]", "gyr": "[rad/s]", "mag": "[uT]"})
    t = ImuTrial.from_csv(path)
    plain = ImuTrial.from_csv(tmp_path / "plain.csv")
    np.testing.assert_array_equal(t.gyr["shank"], plain.gyr["shank"])
    assert t.mag is not None


def test_a_header_in_other_units_names_the_conversion(tmp_path, capsys):
    path = _annotated(tmp_path, {"time": "(s)", "acc": "[g]", "gyr": "[rad/s]", "mag": "[uT]"})
    assert main(["calibrate", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "the file has 'pelvis_acc_x [g]': give it in m/s² as 'pelvis_acc_x'" in err
