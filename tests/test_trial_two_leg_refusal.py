"""``ImuTrial.from_csv`` on a two-leg (seven-sensor) trial names the two-leg reader."""

from __future__ import annotations

import pytest

from lowerlimb.errors import InputError
from lowerlimb.io.recording import TWO_LEG_SENSORS
from lowerlimb.io.trial import ImuTrial


def test_a_two_leg_trial_is_named_with_the_reader_to_use(tmp_path):
    header = ["time"] + [f"{s}_{k}_{a}" for s in TWO_LEG_SENSORS for k in ("acc", "gyr") for a in "xyz"]
    row = ["0"] + ["0.0"] * (len(header) - 1)
    path = tmp_path / "walk.csv"
    path.write_text(",".join(header) + "\n" + ",".join(row) + "\n")
    with pytest.raises(InputError, match=r"is a two-leg trial .*BilateralTrial\.from_csv") as info:
        ImuTrial.from_csv(path)
    assert "\n" not in str(info.value)
