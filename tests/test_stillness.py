"""The one still-period detector: detected once per processed trial and handed on."""

import numpy as np
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
