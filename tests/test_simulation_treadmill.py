"""A simulated treadmill walk (lowerlimb.simulation.treadmill) and what the pipeline makes of it.

The belt carries the walker back, so the sensors stay over one spot of the lab: their
lab-frame accelerations must integrate to no net velocity, the lab's field they read must
be nearly constant, and the walk must be straight. The pipeline must find the strides with
their belt-frame lengths, and say that a straight walk cannot separate the chain's bias
from the standing anchor (the drift fit's heading spread).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from lowerlimb.bilateral import process_bilateral_trial
from lowerlimb.conventions import GRAVITY_ENU, quat_to_matrix
from lowerlimb.errors import InputError
from lowerlimb.gait.drift import heading_spread
from lowerlimb.outputs_bilateral import gait_summary_lines
from lowerlimb.simulation import BilateralSimulation, ImuNoise, simulate_bilateral
from lowerlimb.simulation.treadmill import TreadmillParams, lab_specific_force

SEED = 7


@lru_cache(maxsize=2)
def _walk(treadmill: bool, noise: bool = False) -> BilateralSimulation:
    return simulate_bilateral(
        30.0,
        SEED,
        noise=None if noise else ImuNoise.none(),
        treadmill=TreadmillParams() if treadmill else None,
    )


def _lab_velocity(sim: BilateralSimulation, sensor: str) -> np.ndarray:
    """(N, 3) the sensor's velocity integrated from its clean specific force, ENU m/s."""
    R = quat_to_matrix(sim.quat_wxyz[sensor])
    a = np.einsum("nij,nj->ni", R, sim.clean.acc[sensor]) + GRAVITY_ENU
    return np.asarray(cumulative_trapezoid(a, sim.clean.time_s, axis=0, initial=0.0))


def test_lab_specific_force_takes_off_the_belts_acceleration() -> None:
    t = np.linspace(0.0, 2.0, 201)
    travel = np.column_stack([0.25 * t**2, np.zeros_like(t), np.zeros_like(t)])  # 0.5 m/s²
    f_belt = {"s": np.tile([0.0, 0.0, 9.81], (t.size, 1))}
    rot = {"s": np.tile(np.eye(3), (t.size, 1, 1))}
    f_lab = lab_specific_force(f_belt, rot, t, travel)["s"]
    np.testing.assert_allclose(f_lab[5:-5], np.tile([-0.5, 0.0, 9.81], (t.size - 10, 1)), atol=1e-9)


def test_the_sensors_stay_over_one_spot_of_the_lab() -> None:
    tread, over = _walk(True), _walk(False)
    walking = tread.clean.time_s > 5.0
    speed = over.truth["gait"]["gait_speed_m_s"]
    for sensor in ("pelvis", "left_foot", "right_shank"):
        v_tread = _lab_velocity(tread, sensor)[walking, :2].mean(axis=0)
        v_over = _lab_velocity(over, sensor)[walking, :2].mean(axis=0)
        assert np.linalg.norm(v_tread) < 0.05 * speed
        assert np.linalg.norm(v_over) == pytest.approx(speed, rel=0.1)


def test_the_treadmill_walk_is_straight_and_its_truth_in_the_belt_frame() -> None:
    sim = _walk(True)
    assert sim.truth["walk"]["turn_amplitude_rad"] == 0.0
    assert sim.truth["treadmill"]["deck_m"] == TreadmillParams().deck_m
    for side in ("left", "right"):
        strides = [s for s in sim.gait.strides if s.side == side]
        lengths = np.array([s.stride_length_m for s in strides[1:]])
        assert np.ptp(lengths) < 0.02 and lengths.mean() > 0.8  # steady, belt-frame strides
    pelvis = sim.sensor_pos_m["pelvis"][sim.clean.time_s > 5.0, :2]
    direction = pelvis[-1] - pelvis[0]
    lateral = (pelvis - pelvis[0]) @ np.array([-direction[1], direction[0]]) / np.linalg.norm(direction)
    assert np.ptp(lateral) < 0.1  # sway only, no bend of the path


def test_the_field_read_on_a_treadmill_hardly_changes() -> None:
    tread, over = _walk(True), _walk(False)
    k = tread.clean.time_s > 5.0
    assert tread.clean.mag is not None and over.clean.mag is not None

    def cv(mag: np.ndarray) -> float:
        n = np.linalg.norm(mag[k], axis=1)
        return float(np.std(n) / np.mean(n))

    for foot in ("left_foot", "right_foot"):
        assert cv(tread.clean.mag[foot]) < 0.05 < cv(over.clean.mag[foot])


def test_the_pipeline_finds_belt_strides_and_reports_a_straight_walk() -> None:
    sim = _walk(True, noise=True)
    res = process_bilateral_trial(sim.trial)
    params = res.gait.parameters
    assert params is not None and params.track_drift is not None
    assert params.track_drift.heading_spread < 0.05
    assert params.step_width_basis == "standing_chain_straight_walk"
    lines = gait_summary_lines(res)
    assert lines[0].startswith("gait ") and "the walk is straight" in lines[1]
    true = {(s.side, round(s.start_s, 1)): s.stride_length_m for s in sim.gait.strides}
    errs = [
        c.stride_length_m / true[(c.side, round(c.start_s, 1))] - 1.0
        for c in params.strides
        if (c.side, round(c.start_s, 1)) in true and np.isfinite(c.stride_length_m)
    ]
    assert len(errs) > 30 and np.median(np.abs(errs)) < 0.02


def test_heading_spread_is_zero_one_way_and_one_both_ways() -> None:
    east = np.tile([1.0, 0.0], (10, 1))
    assert heading_spread(east) == pytest.approx(0.0, abs=1e-12)
    assert heading_spread(np.vstack([east, -east])) == pytest.approx(1.0)
    assert heading_spread(np.zeros((0, 2))) == 0.0


def test_bad_treadmills_and_stops_on_one_are_refused() -> None:
    with pytest.raises(InputError, match="deck_m"):
        simulate_bilateral(10.0, 1, treadmill=TreadmillParams(deck_m=-0.1))
    from lowerlimb.simulation.pauses import PauseParams

    with pytest.raises(InputError, match="no stops"):
        simulate_bilateral(30.0, 1, treadmill=TreadmillParams(), stops=PauseParams(count=1))


def test_the_command_line_simulates_a_treadmill_for_two_legs_only(tmp_path, capsys) -> None:
    from lowerlimb.cli import main

    out = tmp_path / "treadmill.csv"
    assert main(["simulate", "--side", "both", "--duration", "10", "--treadmill", "--out", str(out)]) == 0
    assert "on a treadmill" in capsys.readouterr().out and out.is_file()
    for argv, says in (
        (["--treadmill"], "--treadmill is a seven-IMU walk option; add --side both"),
        (["--side", "both", "--treadmill", "--stops", "1"], "--treadmill walks have no --stops"),
    ):
        assert main(["simulate", "--duration", "20", *argv, "--out", str(tmp_path / "x.csv")]) == 2
        err = capsys.readouterr().err
        assert says in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.csv").exists()
