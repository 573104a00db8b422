"""One segment's sensors exchanged between the legs (``lowerlimb.bilateral.leg_pairing``)."""

from __future__ import annotations

import warnings

import pytest
from simcache import data_dir

from lowerlimb.bilateral.leg_pairing import CrossedLegsError, check_leg_pairing, leg_pairing
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.simulation import simulate_bilateral


@pytest.fixture(scope="module")
def walk() -> BilateralTrial:
    return simulate_bilateral(20.0, 201).trial


def _exchanged(trial: BilateralTrial, segment: str) -> BilateralTrial:
    acc, gyr = dict(trial.acc), dict(trial.gyr)
    for d in (acc, gyr):
        d[f"left_{segment}"], d[f"right_{segment}"] = d[f"right_{segment}"], d[f"left_{segment}"]
    return BilateralTrial(trial.time_s, acc, gyr, None)


def test_a_valid_walk_passes(walk: BilateralTrial) -> None:
    check_leg_pairing(walk)
    p = leg_pairing(walk)
    assert p.knees_crossed > 5 * p.knees


@pytest.mark.parametrize("segment", ["thigh", "shank"])
def test_exchanged_thighs_or_shanks_are_named(walk: BilateralTrial, segment: str) -> None:
    with pytest.raises(
        CrossedLegsError, match=f"the left_{segment} and right_{segment} columns look swapped"
    ):
        check_leg_pairing(_exchanged(walk, segment))


def test_exchanged_feet_in_a_walk_with_turns_are_named() -> None:
    from lowerlimb.simulation.bilateral_walk import TurnParams

    trial = simulate_bilateral(40.0, 203, turns=TurnParams()).trial
    check_leg_pairing(trial)
    with pytest.raises(CrossedLegsError, match="left_foot and right_foot columns look swapped"):
        check_leg_pairing(_exchanged(trial, "foot"))


DATA = data_dir()


@pytest.mark.data
@pytest.mark.skipif(DATA is None or not (DATA / "gait").is_dir(), reason="real-walk data absent")
@pytest.mark.parametrize("segment", [None, "thigh", "shank", "foot"])
def test_the_real_walk_as_recorded_and_exchanged(segment: str | None) -> None:
    import importlib.util
    from pathlib import Path

    from lowerlimb.io import load_xsens

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "_realwalk.py"
    spec = importlib.util.spec_from_file_location("realwalk_ids", path)
    assert spec is not None and spec.loader is not None and DATA is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = load_xsens(mod.raw_dir(DATA), mod.IDS)
    trial = BilateralTrial(rec.time_s, rec.acc, rec.gyr, None)
    if segment is None:
        check_leg_pairing(trial)
        return
    with pytest.raises(CrossedLegsError, match=f"left_{segment} and right_{segment}"):
        check_leg_pairing(_exchanged(trial, segment))


def test_ankles_that_cannot_tell_name_both_candidates() -> None:
    from lowerlimb.bilateral.leg_pairing import LegPairing, LegPairingParams

    p = LegPairingParams()
    assert LegPairing(1.0, 0.1, 1.0, 1.03).exchanged(p) == "thigh or shank"
    assert LegPairing(1.0, 0.1, 1.0, 1.3).exchanged(p) == "thigh"
    assert LegPairing(1.0, 0.1, 1.0, 0.7).exchanged(p) == "shank"
    assert "whichever were mixed up" in str(CrossedLegsError("thigh or shank", 0.2, 0.05))
