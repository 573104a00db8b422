"""Empty magnetometer cells and extra columns in trial CSVs (``lowerlimb.io.mag_cells``).

A magnetometer sampled at half the rate (every other cell empty) is interpolated, empty or
long-broken magnetometer columns leave the trial 6-axis with one warning, an empty
accelerometer or gyro cell is still refused, and a two-leg trial ignores extra columns as a
one-leg trial does.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.cli import main
from lowerlimb.errors import InputError
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.mag_cells import MagnetometerCellsWarning, bridged_magnetometer
from lowerlimb.io.trial import ImuTrial
from lowerlimb.simulation import simulate_bilateral


def _rows(path: Path) -> tuple[list[str], list[list[str]]]:
    lines = path.read_text().splitlines()
    return lines[0].split(","), [line.split(",") for line in lines[1:]]


def _write(path: Path, header: list[str], rows: list[list[str]]) -> Path:
    path.write_text("\n".join([",".join(header)] + [",".join(r) for r in rows]) + "\n")
    return path


def _blank(path: Path, out: Path, columns: str, rows: slice) -> Path:
    """``path`` with the cells of the columns containing ``columns`` emptied on ``rows``."""
    header, data = _rows(path)
    cols = [i for i, h in enumerate(header) if columns in h]
    for r in data[rows]:
        for c in cols:
            r[c] = ""
    return _write(out, header, data)


@pytest.fixture(scope="module")
def one_leg(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("magcells")
    path = d / "walk.csv"
    cached_simulation("walk", 20.0, 0).trial.to_csv(path)
    return path


def test_half_rate_magnetometer_is_interpolated(one_leg, tmp_path):
    full = ImuTrial.from_csv(one_leg)
    assert full.mag is not None
    half = _blank(one_leg, tmp_path / "half.csv", "_mag_", slice(1, None, 2))
    with pytest.warns(MagnetometerCellsWarning, match="interpolated"):
        t = ImuTrial.from_csv(half)
    assert t.mag is not None
    for s, m in t.mag.items():
        assert np.all(np.isfinite(m))
        np.testing.assert_array_equal(m[::2], full.mag[s][::2])  # the recorded cells are kept
        assert np.median(np.abs(m - full.mag[s])) < 1.0  # µT: a 50 µT field moved by a 10 ms step


def test_empty_or_broken_magnetometer_leaves_the_trial_6_axis(one_leg, tmp_path):
    empty = _blank(one_leg, tmp_path / "empty.csv", "thigh_mag_", slice(None))
    with pytest.warns(MagnetometerCellsWarning, match="thigh magnetometer columns are empty"):
        assert ImuTrial.from_csv(empty).mag is None
    broken = _blank(one_leg, tmp_path / "broken.csv", "foot_mag_", slice(500, 530))  # 0.3 s
    with pytest.warns(MagnetometerCellsWarning, match="0.3 s long"):
        assert ImuTrial.from_csv(broken).mag is None


def test_an_empty_accelerometer_cell_is_still_refused(one_leg, tmp_path):
    bad = _blank(one_leg, tmp_path / "acc.csv", "shank_acc_y", slice(40, 41))
    with pytest.raises(InputError, match="'shank_acc_y' is empty at data row 41"):
        ImuTrial.from_csv(bad)


def test_bridging_leaves_a_complete_magnetometer_alone():
    t = np.arange(10) / 100.0
    mag = {"pelvis": np.ones((10, 3))}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert bridged_magnetometer(t, mag) is mag
        assert bridged_magnetometer(t, None) is None


@pytest.fixture(scope="module")
def two_legs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("magcells2")
    path = d / "both.csv"
    simulate_bilateral(duration_s=12.0, seed=3).trial.to_csv(path)
    return path


def test_two_leg_trial_ignores_extra_columns_and_bridges_its_magnetometer(two_legs, tmp_path):
    header, rows = _rows(two_legs)
    extra = _write(tmp_path / "extra.csv", header + ["label", "sync"], [r + ["walk", ""] for r in rows])
    plain = BilateralTrial.from_csv(two_legs)
    t = BilateralTrial.from_csv(extra)
    np.testing.assert_array_equal(t.acc["right_foot"], plain.acc["right_foot"])
    half = _blank(extra, tmp_path / "half.csv", "_mag_", slice(1, None, 2))
    with pytest.warns(MagnetometerCellsWarning, match="interpolated"):
        assert BilateralTrial.from_csv(half).mag is not None


def test_calibrate_runs_on_an_empty_magnetometer(one_leg, tmp_path, capsys):
    empty = _blank(one_leg, tmp_path / "empty.csv", "_mag_", slice(None))
    assert main(["calibrate", str(empty), "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "magnetometer columns are empty" in err and "6-axis" in err
    assert (tmp_path / "out" / "angles.csv").is_file()


def test_a_written_out_nan_in_the_magnetometer_is_still_refused(one_leg, tmp_path, capsys):
    """The trial contract refuses NaN; only an empty magnetometer cell means "no sample"."""
    header, rows = _rows(one_leg)
    c = header.index("pelvis_mag_y")
    rows[99][c] = "NaN"
    bad = _write(tmp_path / "nan.csv", header, rows)
    assert main(["calibrate", str(bad), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'pelvis_mag_y' has a NaN value ('NaN') at data row 100" in err
    assert not (tmp_path / "out").exists()
    rows[99][c] = ""
    rows[100][header.index("thigh_mag_x")] = "nan"  # beside an empty cell: the slow path names it
    with pytest.raises(InputError, match=r"'thigh_mag_x' has a NaN value \('nan'\) at data row 101"):
        ImuTrial.from_csv(_write(tmp_path / "nan2.csv", header, rows))
