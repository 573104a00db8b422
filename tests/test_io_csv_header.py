"""Trial CSVs as other software writes them: lines before the header, rows of the wrong length,
UTF-16 text, magnetometer columns in another unit (``lowerlimb.io.csv_header``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.cli import main
from lowerlimb.errors import InputError
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.trial import ImuTrial
from lowerlimb.simulation import simulate_bilateral


@pytest.fixture(scope="module")
def one_leg(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("csv_header") / "plain.csv"
    cached_simulation("walk", 20.0, 0).trial.to_csv(path)
    return path


def _write(tmp_path: Path, name: str, lines: list[str]) -> Path:
    out = tmp_path / name
    out.write_text("\n".join(lines) + "\n")
    return out


def test_comment_and_sep_lines_before_the_header_are_skipped(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    plain = ImuTrial.from_csv(one_leg)
    for preamble in (["# exported by some software", "# subject 7"], ["sep=,"], ["", "# a note", ""]):
        trial = ImuTrial.from_csv(_write(tmp_path, "pre.csv", preamble + lines))
        np.testing.assert_array_equal(trial.gyr["thigh"], plain.gyr["thigh"])
        np.testing.assert_array_equal(trial.time_s, plain.time_s)


def test_a_two_leg_trial_with_a_preamble_reads(tmp_path: Path) -> None:
    path = tmp_path / "two.csv"
    simulate_bilateral(12.0, 201).trial.to_csv(path)
    plain = BilateralTrial.from_csv(path)
    pre = _write(tmp_path, "pre.csv", ["sep=,", "# two legs"] + path.read_text().splitlines())
    np.testing.assert_array_equal(BilateralTrial.from_csv(pre).acc["right_foot"], plain.acc["right_foot"])


def test_a_row_with_an_extra_value_is_named_not_shifted(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    cells = lines[500].split(",")
    lines[500] = ",".join(cells[:10] + ["0.0"] + cells[10:])  # data row 500: one value too many
    with pytest.raises(InputError, match=r"data row 500 has 38 values but the header names 37 columns"):
        ImuTrial.from_csv(_write(tmp_path, "shifted.csv", lines))


def test_a_trailing_comma_on_every_row_still_reads(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    trial = ImuTrial.from_csv(_write(tmp_path, "trailing.csv", [lines[0]] + [ln + "," for ln in lines[1:]]))
    np.testing.assert_array_equal(trial.acc["foot"], ImuTrial.from_csv(one_leg).acc["foot"])


def test_an_interrupted_last_row_is_named(
    one_leg: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    lines = one_leg.read_text().splitlines()
    lines[-1] = ",".join(lines[-1].split(",")[:20])
    path = _write(tmp_path, "cut.csv", lines)
    assert main(["calibrate", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"the last data row ({len(lines) - 1}) has 20 of 37 values" in err[0]
    assert "delete that row" in err[0] and not (tmp_path / "out").exists()


def test_utf16_text_is_named(one_leg: Path, tmp_path: Path) -> None:
    path = tmp_path / "utf16.csv"
    path.write_bytes(one_leg.read_text().encode("utf-16"))
    with pytest.raises(InputError, match="is UTF-16 text.*save the trial CSV as UTF-8"):
        ImuTrial.from_csv(path)


def test_a_magnetometer_in_another_unit_is_refused_not_dropped(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    header = [f"{h} [mG]" if "_mag_" in h else h for h in lines[0].split(",")]
    path = _write(tmp_path, "mg.csv", [",".join(header)] + lines[1:])
    with pytest.raises(
        InputError, match=r"'pelvis_mag_x \[mg\]': give the magnetometer in µT as 'pelvis_mag_x'"
    ):
        ImuTrial.from_csv(path)
    assert not ImuTrial.from_csv(path, use_mag=False).has_mag


def test_a_trial_the_user_may_not_read_is_one_line(
    one_leg: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    import builtins

    import lowerlimb.io.csv_header as csv_header

    real_open = builtins.open

    def denied(file, *args, **kwargs):  # type: ignore[no-untyped-def]
        if str(file) == str(one_leg):
            raise PermissionError(13, "Permission denied", str(file))
        return real_open(file, *args, **kwargs)

    monkeypatch.setattr(csv_header, "open", denied, raising=False)
    assert main(["calibrate", str(one_leg), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "permission denied" in err[0] and "chmod u+r" in err[0]
    assert not (tmp_path / "out").exists()


def test_a_device_is_not_called_missing(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="is not a regular file"):
        ImuTrial.from_csv("/dev/null")


@pytest.mark.parametrize(
    "mark, named", [("l_{s}", "left_{s}"), ("{s}_left", "left_{s}"), ("r_{s}", "right_{s}")]
)
def test_legs_marked_otherwise_are_told_the_left_right_names(
    one_leg: Path, tmp_path: Path, mark: str, named: str
) -> None:
    lines = one_leg.read_text().splitlines()
    header = lines[0]
    for s in ("thigh", "shank", "foot"):
        header = header.replace(f"{s}_", mark.format(s=s) + "_")
    path = _write(tmp_path, "marked.csv", [header] + lines[1:])
    with pytest.raises(InputError, match=f"name them '{named.format(s='thigh')}_acc_x'"):
        ImuTrial.from_csv(path)


def test_a_header_ending_with_a_comma_over_rows_without_reads(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    plain = ImuTrial.from_csv(one_leg)
    unnamed_last = [lines[0] + ","] + lines[1:]  # rows without the unnamed column's empty value
    excel_empty = [lines[0] + ",,"] + [ln + ",," for ln in lines[1:]]  # two empty columns
    for rows in (unnamed_last, excel_empty):
        trial = ImuTrial.from_csv(_write(tmp_path, "h.csv", rows))
        np.testing.assert_array_equal(trial.gyr["shank"], plain.gyr["shank"])


def test_an_extra_value_is_named_in_a_file_with_quotes_too(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    lines[0] = ",".join(f'"{h}"' for h in lines[0].split(","))  # R's write.csv, pandas QUOTE_ALL
    cells = lines[500].split(",")
    lines[500] = ",".join(cells[:10] + ["0.0"] + cells[10:])
    with pytest.raises(InputError, match=r"data row 500 has 38 values but the header names 37 columns"):
        ImuTrial.from_csv(_write(tmp_path, "quoted.csv", lines))


def test_a_quoted_comma_in_an_unused_column_does_not_shift_the_others(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    rows = [f"label,{lines[0]}"] + [f'"walk, trial 1",{ln}' for ln in lines[1:]]
    trial = ImuTrial.from_csv(_write(tmp_path, "label.csv", rows))
    np.testing.assert_array_equal(trial.acc["pelvis"], ImuTrial.from_csv(one_leg).acc["pelvis"])


def test_a_header_written_as_a_comment_is_named(one_leg: Path, tmp_path: Path) -> None:
    lines = one_leg.read_text().splitlines()
    with pytest.raises(InputError, match="is a comment line.*numpy.savetxt"):
        ImuTrial.from_csv(_write(tmp_path, "savetxt.csv", ["# " + lines[0]] + lines[1:]))
