"""The one still-period detector: detected once per processed trial and handed on."""

import numpy as np
import pytest
from simcache import cached_simulation

import lowerlimb.stillness as stillness
from lowerlimb.conventions import SENSORS
from lowerlimb.simulation import ImuNoise


def test_samples_applies_the_minimum_duration_to_one_detection():
    sim = cached_simulation("walk", 8.0, 2, noise=ImuNoise())
    tr = sim.trial
    gyrs, accs = [tr.gyr[s] for s in SENSORS], [tr.acc[s] for s in SENSORS]
    found = stillness.detect_still_period(gyrs, accs, tr.rate_hz)
    assert found.n_samples > 0
    for min_s in (0.5, 1.0, 30.0):
        assert found.samples(min_s) == stillness.initial_still_samples(
            gyrs, accs, tr.rate_hz, min_duration_s=min_s
        )
    assert found.samples(30.0) == 0
    assert tr.standing_samples(1.0) == found.samples(1.0)


def test_process_trial_detects_the_still_period_once(monkeypatch):
    import lowerlimb.io.trial as trial_module
    from lowerlimb.pipeline import process_trial

    calls = []
    real = stillness.detect_still_period

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(trial_module, "detect_still_period", counting)
    monkeypatch.setattr(stillness, "detect_still_period", counting)
    import lowerlimb.calibration._prepare as prepare

    monkeypatch.setattr(prepare, "detect_still_period", counting)
    sim = cached_simulation("walk", 8.0, 2, noise=ImuNoise())
    result = process_trial(sim.trial, method="gn")
    assert len(calls) == 1
    assert np.isfinite(result.angles_rad).all()


def test_the_bias_window_spans_the_whole_quiet_stand():
    # 8 s stand, a 0.2 s weight shift at 2 s, a slow settling turn in the first 1.5 s, then walking
    rate, n = 100.0, 1200
    rng = np.random.default_rng(3)
    bias = np.array([0.01, -0.02, 0.015])
    gyrs = [bias + rng.normal(0.0, 0.002, (n, 3)) for _ in range(2)]
    accs = [np.array([0.0, 0.0, 9.81]) + rng.normal(0.0, 0.01, (n, 3)) for _ in range(2)]
    gyrs[0][:150, 2] += 0.03  # settling: below the still threshold, a real rotation
    gyrs[1][200:220, 0] += 0.4  # weight shift: ends the first still run
    t = np.arange(n) / rate
    for g in gyrs:
        g[800:, 0] += 2.0 * np.sin(2 * np.pi * t[800:])  # the walk: sustained motion
    found = stillness.detect_still_period(gyrs, accs, rate)
    assert 180 <= found.n_samples <= 200  # the first still run ends at the weight shift
    assert found.quiet is not None and 790 <= len(found.quiet) <= 800
    assert not found.quiet[195:225].any() and found.quiet[300:780].all()
    first_run = stillness.gyro_bias(gyrs[0], found.n_samples)
    whole = stillness.gyro_bias(gyrs[0], found.n_samples, found.quiet)
    assert abs(first_run[2] - bias[2]) > 0.02  # the settling turn, taken for bias
    assert np.max(np.abs(whole - bias)) < 0.007  # diluted over the stand


def test_a_recording_that_ends_still_has_its_bias_measured_there():
    """Moving at the start, still for the last 2 s: the end's run is found and, with no still
    start, the gyro bias is its mean; a still start keeps priority."""
    rate, n = 100.0, 1000
    rng = np.random.default_rng(0)
    bias = np.array([0.02, -0.01, 0.005])
    t = np.arange(n) / rate
    gyr = bias + 0.002 * rng.standard_normal((n, 3))
    acc = np.tile([0.0, 0.0, 9.81], (n, 1)) + 0.01 * rng.standard_normal((n, 3))
    moving = t < 8.0
    gyr[moving, 0] += 2.0 * np.sin(2 * np.pi * 1.0 * t[moving])
    acc[moving, 1] += 3.0 * np.sin(2 * np.pi * 1.0 * t[moving])
    still = stillness.detect_still_period([gyr], [acc], rate)
    assert still.samples() == 0
    assert 150 <= still.end() <= 200  # 2 s, less the window and the margin
    assert stillness.gyro_bias(gyr, 0, None, still.end()) == pytest.approx(bias, abs=1e-3)
    assert not np.any(stillness.gyro_bias(gyr, 0, None, 0))  # neither: no bias
    start = stillness.gyro_bias(gyr[::-1], still.end(), None, still.end())  # a still start wins
    assert start == pytest.approx(bias, abs=1e-3)
    assert stillness.StillPeriod(0, rate, end_samples=30).end(0.5) == 0  # under the minimum


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_a_bad_still_end_minimum_is_refused(bad):
    from lowerlimb.calibration.options import CalibrationOptions
    from lowerlimb.errors import InputError

    with pytest.raises(InputError, match="still_end_min_s"):
        CalibrationOptions(still_end_min_s=bad)


def test_the_bias_end_needs_no_still_start_and_a_long_enough_end():
    p = stillness.StillPeriod(0, 100.0, end_samples=150)
    assert p.bias_end(0.5, 1.0) == 150
    assert p.bias_end(0.5, 2.0) == 0  # too short an end
    assert p.bias_end(0.5, None) == 0  # switched off
    assert stillness.StillPeriod(80, 100.0, end_samples=150).bias_end(0.5, 1.0) == 0  # a still start wins
