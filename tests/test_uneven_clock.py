"""Uneven sample times: resampled onto a constant clock as the trial CSV is read."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from simcache import cached_simulation

from lowerlimb.cli import main
from lowerlimb.io import PacketGapError
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.trial import ImuTrial
from lowerlimb.io.uneven_clock import (
    ClockParams,
    UnevenClockWarning,
    nominal_step,
    sample_index,
    to_uniform_clock,
)
from lowerlimb.simulation.bilateral_walk import simulate_bilateral

RATE = 100.0


def _signal(t: np.ndarray) -> np.ndarray:
    """(N, 2) smooth test signal: 1.3 Hz and 3.1 Hz sines."""
    return np.column_stack([np.sin(2 * np.pi * 1.3 * t), 0.5 * np.cos(2 * np.pi * 3.1 * t)])


def _uniform(n: int = 1001) -> np.ndarray:
    return np.arange(n) / RATE


def test_even_time_is_returned_unchanged_without_a_warning():
    t = _uniform()
    x = _signal(t)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        t2, (x2,), repair = to_uniform_clock(t, [x])
    assert repair is None
    np.testing.assert_array_equal(t2, t)
    np.testing.assert_array_equal(x2, x)


def test_dropped_rows_are_filled_on_the_original_clock():
    t = _uniform()
    keep = np.ones(t.size, dtype=bool)
    keep[[100, 101, 102, 400, 750]] = False
    with pytest.warns(
        UnevenClockWarning, match=r"3 gaps of missing samples bridged.*100 Hz.*996 → 1001 rows"
    ):
        t2, (x2,), repair = to_uniform_clock(t[keep], [_signal(t[keep])])
    assert repair is not None and repair.n_gaps == 3 and repair.n_uniform == t.size
    np.testing.assert_allclose(t2, t, atol=1e-12)
    np.testing.assert_array_equal(x2[keep], _signal(t[keep]))  # the recorded samples as they were
    np.testing.assert_allclose(x2, _signal(t), atol=1e-3)  # a cubic spline across three missing samples


def test_jittered_stamps_keep_the_recorder_period_and_beat_linear_interpolation():
    rng = np.random.default_rng(1)
    t = _uniform()
    stamps = t + rng.uniform(-0.2, 0.2, t.size) / RATE
    stamps[[0, -1]] = t[[0, -1]]
    x = _signal(stamps)
    with pytest.warns(UnevenClockWarning, match="steps more than 25 % off the median"):
        t2, (x2,), repair = to_uniform_clock(stamps, [x])
    assert repair is not None and repair.n_gaps == 0
    assert nominal_step(stamps) == pytest.approx(1 / RATE, rel=1e-5)
    np.testing.assert_allclose(t2, t, atol=1e-5)
    linear = np.column_stack([np.interp(t, stamps, c) for c in x.T])
    err, err_linear = np.abs(x2 - _signal(t)).max(), np.abs(linear - _signal(t)).max()
    assert err < 1e-4 and err < 0.1 * err_linear


def test_a_cut_signal_stays_at_its_range():
    """The spline overshoots a flat top; clipped, the held samples stay exactly at the range."""
    t = _uniform()
    x = np.clip(3.0 * _signal(t), -2.0, 2.0)
    keep = np.ones(t.size, dtype=bool)
    keep[1::7] = False
    _, (x2,), _ = to_uniform_clock(t[keep], [x[keep]])
    assert x2.max(axis=0) == pytest.approx([2.0, 1.5]) and x2.min() == pytest.approx(-2.0)
    assert np.count_nonzero(x2[keep, 0] == 2.0) == np.count_nonzero(x[keep][:, 0] == 2.0)


def test_a_gap_longer_than_the_limit_is_refused_naming_it():
    t = np.r_[_uniform(300), 3.5 + _uniform(300)]
    with pytest.raises(PacketGapError, match=r"the trial has a gap of 0.51 s at 2.990 s.*cut the recording"):
        to_uniform_clock(t, [_signal(t)])
    _, _, repair = to_uniform_clock(t, [_signal(t)], ClockParams(max_gap_s=1.0))
    assert repair is not None and repair.n_gaps == 1


@pytest.mark.parametrize(
    "edit",
    [
        lambda t, x: (t, np.where(np.arange(t.size)[:, None] == 5, np.nan, x)),  # NaN: the trial names it
        lambda t, x: (t[::-1].copy(), x),  # not increasing
        lambda t, x: (1000.0 * t, x),  # milliseconds
    ],
)
def test_problems_the_trial_names_are_left_to_it(edit):
    t = _uniform()
    keep = np.ones(t.size, dtype=bool)
    keep[50] = False
    t2, x2 = edit(t[keep], _signal(t[keep]))
    out_t, (out_x,), repair = to_uniform_clock(t2, [x2])
    assert repair is None
    np.testing.assert_array_equal(out_t, t2)


def _write(path: Path, trial: ImuTrial, keep: np.ndarray) -> Path:
    """The rows ``keep`` of a single-leg trial as a trial CSV."""
    header = ",".join(trial.header())
    np.savetxt(path, trial.to_array()[keep], delimiter=",", header=header, comments="", fmt="%.9g")
    return path


def test_a_trial_csv_with_dropped_rows_is_read_on_its_clock(tmp_path):
    trial = cached_simulation("walk", 4.0, 3).trial
    keep = np.ones(trial.n_samples, dtype=bool)
    keep[[120, 121, 250]] = False
    with pytest.warns(UnevenClockWarning, match=r"\b2 gaps"):
        back = ImuTrial.from_csv(_write(tmp_path / "t.csv", trial, keep), side="left")
    assert back.n_samples == trial.n_samples and back.rate_hz == pytest.approx(RATE)
    np.testing.assert_allclose(back.time_s, trial.time_s, atol=1e-9)
    np.testing.assert_allclose(back.gyr["shank"][keep], trial.gyr["shank"][keep], atol=1e-7)
    filled = np.abs(back.gyr["shank"][~keep] - trial.gyr["shank"][~keep]).max()
    assert filled < 0.1 * np.abs(trial.gyr["shank"]).max()


def test_a_two_leg_trial_csv_with_jittered_stamps_is_resampled(tmp_path):
    trial = simulate_bilateral(6.0, seed=3).trial
    rng = np.random.default_rng(2)
    stamps = trial.time_s + rng.uniform(-0.2, 0.2, trial.n_samples) / RATE
    stamps[[0, -1]] = trial.time_s[[0, -1]]
    jittered = BilateralTrial(stamps, trial.acc, trial.gyr, trial.mag)
    jittered.to_csv(tmp_path / "t.csv")
    with pytest.warns(UnevenClockWarning):
        back = BilateralTrial.from_csv(tmp_path / "t.csv")
    np.testing.assert_allclose(back.time_s, trial.time_s, atol=1e-9)
    assert set(back.gyr) == set(trial.gyr) and (back.mag is None) == (trial.mag is None)


def test_calibrate_says_the_resampling_in_one_line_and_refuses_a_long_gap(tmp_path, capsys):
    trial = cached_simulation("walk", 20.0, 3).trial
    keep = np.ones(trial.n_samples, dtype=bool)
    keep[700:703] = False
    assert (
        main(["calibrate", str(_write(tmp_path / "drop.csv", trial, keep)), "--out", str(tmp_path / "a")])
        == 0
    )
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "time steps vary" in ln]
    assert len(lines) == 1 and "resampled to a constant 100 Hz" in lines[0]
    assert (tmp_path / "a" / "angles.csv").is_file()
    keep[900:950] = False  # 0.51 s
    assert (
        main(["calibrate", str(_write(tmp_path / "gap.csv", trial, keep)), "--out", str(tmp_path / "b")]) == 2
    )
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "gap of 0.51 s" in err and "Traceback" not in err
    assert not (tmp_path / "b").exists()


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(40, 20000),
    jitter=st.floats(0.0, 0.2),
    drop=st.floats(0.0, 0.05),
    rate=st.sampled_from([50.0, 60.0, 100.0, 128.0, 200.0]),
    seed=st.integers(0, 2**31),
)
@example(n=40, jitter=0.1875, drop=0.0, rate=50.0, seed=51559306)  # numbered from the first stamp: 30 off
def test_sample_numbers_are_recovered_through_drops_and_jitter(n, jitter, drop, rate, seed):
    """Any share of dropped stamps up to 5 %, jitter within a fifth of a period: every number right."""
    rng = np.random.default_rng(seed)
    stamps = (np.arange(n) + rng.uniform(-jitter, jitter, n)) / rate + 12.5
    keep = rng.random(n) >= drop
    keep[[0, -1]] = True
    index, step = sample_index(stamps[keep])
    np.testing.assert_array_equal(index, np.flatnonzero(keep))
    assert step == pytest.approx(1 / rate, rel=0.4 / (n - 1) + 1e-9)
