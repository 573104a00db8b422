"""Command-line mistakes outside the trial file: each one line on stderr, exit 2, nothing written."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.cli import main
from lowerlimb.io.trial import ImuTrial


@pytest.fixture(scope="module")
def one_leg(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli_messages") / "plain.csv"
    cached_simulation("walk", 20.0, 0).trial.to_csv(path)
    return path


def test_out_under_a_file_and_contradictory_outputs_are_one_line(
    one_leg: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    afile = tmp_path / "afile"
    afile.write_text("")
    assert main(["calibrate", str(one_leg), "--out", str(afile / "sub")]) == 2
    assert f"{afile} is a file, not a directory" in capsys.readouterr().err
    out = tmp_path / "o"
    assert main(["calibrate", str(one_leg), "--out", str(out), "--outputs", "report", "--no-report"]) == 2
    assert "leave nothing to write" in capsys.readouterr().err and not out.exists()


def test_calibrate_reference_of_the_other_leg_is_named(one_leg: Path, tmp_path: Path, capsys) -> None:
    from lowerlimb.io.tables import write_angles_csv

    trial = ImuTrial.from_csv(one_leg)
    ref = tmp_path / "ref.csv"
    write_angles_csv(ref, trial.time_s, np.zeros((trial.time_s.size, 9)))
    lines = ref.read_text().splitlines()
    lines[0] = ",".join(c if c == "time" else f"right_{c}" for c in lines[0].split(","))
    ref.write_text("\n".join(lines) + "\n")
    out = tmp_path / "o"
    assert main(["calibrate", str(one_leg), "--out", str(out), "--reference", str(ref)]) == 2
    err = capsys.readouterr().err
    assert "the left leg's result" in err and "names the right leg" in err and not out.exists()
