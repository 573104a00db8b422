"""A trial's rate is its samples over its time span, not one over its median step (io.time_axis).

Stamps rounded to a coarser tick than the period (148 Hz stamped in ms: steps of 7 and 6 ms,
within the jitter tolerance, so the clock is kept as it is) had a median step of 7 ms: the trial
ran at 142.9 Hz, and its cadence and stride lengths came out 3 % and 9 % off.
"""

import numpy as np
import pytest

from lowerlimb.io import ImuTrial
from lowerlimb.simulation import simulate


@pytest.mark.parametrize(("rate", "tick"), [(148.0, 1e-3), (148.148, 1e-4), (51.2, 1e-3), (100.0, 1e-2)])
def test_stamps_rounded_to_a_tick_keep_the_rate(rate, tick):
    n = 2000
    t = np.round(np.arange(n) / rate / tick) * tick
    z = np.zeros((n, 3))
    trial = ImuTrial(time_s=t, acc={"thigh": z}, gyr={"thigh": z})
    assert trial.rate_hz == pytest.approx(rate, rel=2e-4)


def test_an_even_clock_has_its_rate_and_an_unchecked_gap_leaves_the_median():
    z = np.zeros((1000, 3))
    t = np.arange(1000) / 120.0
    assert ImuTrial(time_s=t, acc={"thigh": z}, gyr={"thigh": z}).rate_hz == pytest.approx(120.0, rel=1e-12)
    gap = t + np.where(np.arange(1000) >= 500, 3.0, 0.0)  # a 3 s gap (refused by the trial's checks)
    assert ImuTrial(time_s=gap, acc={"thigh": z}, gyr={"thigh": z}).rate_hz == pytest.approx(120.0)


def test_a_walk_stamped_in_ms_at_148_hz_reads_at_148_hz(tmp_path):
    sim = simulate("walk", 6.0, seed=1, rate_hz=148.0)
    path = tmp_path / "trial.csv"
    sim.trial.to_csv(path)
    text = path.read_text().splitlines()
    rows = [text[0]] + [f"{float(r.split(',', 1)[0]):.3f},{r.split(',', 1)[1]}" for r in text[1:]]
    path.write_text("\n".join(rows) + "\n")
    back = ImuTrial.from_csv(path)
    assert np.unique(np.round(np.diff(back.time_s), 6)).size == 2  # 6 and 7 ms, kept as stamped
    assert back.rate_hz == pytest.approx(148.0, rel=1e-3)


def test_the_bids_sidecar_names_the_rate_of_stamps_rounded_to_ms():
    from lowerlimb.export.bids import _motion_sidecar

    t = np.round(np.arange(1000) / 148.0, 3)
    assert _motion_sidecar(t, [], "walk", "x", None)["SamplingFrequency"] == pytest.approx(148.0, rel=1e-3)
