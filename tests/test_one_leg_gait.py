"""One leg's gait: a four-IMU trial that walks gets its events, stride lengths and cadence."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.cli import main
from lowerlimb.pipeline import TrialResult, process_trial
from lowerlimb.simulation.bilateral_walk import BilateralSimulation, simulate_bilateral


@pytest.fixture(scope="module")
def walk() -> BilateralSimulation:
    return simulate_bilateral(30.0, 201)


def _leg(walk: BilateralSimulation, side: str) -> TrialResult:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return process_trial(walk.trial.leg(side))


@pytest.mark.parametrize("side", ["left", "right"])
def test_one_leg_finds_its_events_strides_and_cadence(walk, side):
    gait = _leg(walk, side).gait
    assert gait is not None and gait.side == side
    ev = getattr(gait.events, side)
    assert getattr(gait.events, "right" if side == "left" else "left") is None
    true_ic = np.asarray(walk.feet[side].events.initial_contact_s)
    true_ic = true_ic[true_ic > 3.0]
    err = np.array([np.min(np.abs(ev.initial_contact_s - walk.trial.time_s[0] - t)) for t in true_ic])
    found = err[err < 0.1]  # the last contact may fall in an unfinished stride
    assert found.size >= true_ic.size - 1 and np.median(found) < 0.015 and np.max(found) < 0.04
    d = gait.to_dict()
    true = walk.truth["gait"]
    assert d[side]["stride_length_m"]["mean"] == pytest.approx(
        true[side]["stride_length_m"]["mean"], rel=0.02
    )
    assert d["cadence_steps_per_min"] == pytest.approx(true["cadence_steps_per_min"], abs=1.0)
    assert d["cadence_basis"] == "stride_time" and d["legs"] == [side]
    assert np.isnan(d[side]["step_width_m"]["mean"]) and ("left" if side == "right" else "right") not in d


@pytest.mark.parametrize(("motion", "seed"), [("walk", 3), ("squat", 3), ("sit-to-stand", 3002)])
def test_no_gait_where_the_foot_never_rests_or_the_leg_does_not_walk(motion, seed):
    """The one-leg simulator's walk never rests its foot; a squat has no strides; seed 3002's
    sit-to-stand shows two "strides" of 2 cm between its foot's rests, which is no walk."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert process_trial(cached_simulation(motion, 20.0, seed).trial).gait is None


def test_the_two_leg_pipeline_finds_the_legs_gait_together(walk):
    assert _leg(walk, "left").gait is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert process_trial(walk.trial.leg("left"), leg_gait=False).gait is None


def test_calibrate_writes_the_legs_gait_files_and_says_so(walk, tmp_path, capsys):
    walk.trial.leg("right").to_csv(tmp_path / "right.csv")
    assert (
        main(["calibrate", str(tmp_path / "right.csv"), "--side", "right", "--out", str(tmp_path / "o")]) == 0
    )
    err = capsys.readouterr().err
    assert "gait (right leg, events.csv, gait.json):" in err and "steps/min" in err
    events = (tmp_path / "o" / "events.csv").read_text().splitlines()
    assert events[0] == "time,side,event" and all(",right," in row for row in events[1:]) and len(events) > 20
    gait = json.loads((tmp_path / "o" / "gait.json").read_text())
    assert gait["right"]["n_strides"] > 10 and gait["step_width_m"]["mean"] is None
    assert (tmp_path / "o" / "stationary.csv").read_text().startswith("side,start,end")


def test_a_study_row_of_one_walking_leg_has_its_gait(walk):
    from lowerlimb.batch.worker import leg_gait_results

    row = leg_gait_results(_leg(walk, "left"))
    assert row["cadence_steps_per_min"] == pytest.approx(walk.truth["gait"]["cadence_steps_per_min"], abs=1.0)
    assert 0.5 < row["stride_length_m"] < 2.0 and 0.5 < row["gait_speed_m_s"] < 2.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        squat = process_trial(cached_simulation("squat", 20.0, 3).trial)
    assert all(np.isnan(v) for v in leg_gait_results(squat).values())
