"""A sensor recorded at a lower rate and held to the table's rate (sample-and-hold) is said.

The held rows are steps to every derivative and integral of the pipeline; the check must find
them whether one sensor or all are held, and never flag an honest recording: the simulator's
walks, the real walk, or a still sensor exported with few digits.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.io.held_samples import HeldSamplesWarning, held_fractions, warn_held_samples
from lowerlimb.pipeline import process_trial


def _held(x: np.ndarray, k: int) -> np.ndarray:
    return x[np.arange(len(x)) // k * k]


@pytest.fixture(scope="module")
def walk():
    return cached_simulation("walk", 20.0, 0)


def test_honest_signals_are_not_flagged(walk) -> None:
    assert max(held_fractions(walk.trial.acc, walk.trial.gyr).values()) == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error", HeldSamplesWarning)
        warn_held_samples(walk.trial.acc, walk.trial.gyr, walk.trial.rate_hz)
    # a still sensor written with two decimals repeats its rows honestly: not counted
    still_acc = {
        "s": np.round(
            np.tile([0.0, 0.0, 9.81], (500, 1)) + 0.001 * np.random.default_rng(0).normal(size=(500, 3)), 2
        )
    }
    still_gyr = {"s": np.round(0.001 * np.random.default_rng(1).normal(size=(500, 3)), 2)}
    assert held_fractions(still_acc, still_gyr) == {}


@pytest.mark.parametrize("k", [2, 3])
def test_held_sensors_are_found_with_their_rate(walk, k: int) -> None:
    acc = dict(walk.trial.acc, shank=_held(walk.trial.acc["shank"], k))
    gyr = dict(walk.trial.gyr, shank=_held(walk.trial.gyr["shank"], k))
    fractions = held_fractions(acc, gyr)
    assert fractions["shank"] == pytest.approx(1.0 - 1.0 / k, abs=0.02)
    assert all(v == 0.0 for s, v in fractions.items() if s != "shank")
    with pytest.warns(HeldSamplesWarning, match=rf"the shank readings repeat .* about {100 / k:.3g} Hz") as w:
        warn_held_samples(acc, gyr, 100.0)
    assert len(w) == 1


def test_the_pipeline_says_it(walk) -> None:
    trial = walk.trial
    held = type(trial)(
        trial.time_s,
        {s: _held(v, 2) for s, v in trial.acc.items()},
        {s: _held(v, 2) for s, v in trial.gyr.items()},
        trial.mag,
        trial.side,
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        process_trial(held)
    said = [str(c.message) for c in caught if c.category is HeldSamplesWarning]
    # the pelvis turns too slowly to be judged; the three leg sensors are named
    assert {m.split()[1] for m in said} == {"thigh", "shank", "foot"}
    assert all("about 50 Hz" in m for m in said)
