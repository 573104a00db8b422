"""A simulated gait-lab walk with turns about (lowerlimb.simulation.turns) and the pipeline on it.

The walk must turn by 180° between straight passes, a foot in stance must pivot on the floor
(its sole's middle still while it turns), the hips, not the ankles, must take the turn, and
the walk without turns must stay what it was. The pipeline must find the events and the
angles through the turns as on a bending walk.
"""

from __future__ import annotations

import json
from functools import lru_cache

import numpy as np
import pytest

from lowerlimb.bilateral import process_bilateral_trial
from lowerlimb.errors import InputError
from lowerlimb.simulation import BilateralSimulation, ImuNoise, simulate_bilateral
from lowerlimb.simulation.pauses import PauseParams
from lowerlimb.simulation.treadmill import TreadmillParams
from lowerlimb.simulation.turns import TurnParams, turn_starts

SEED = 11
ANKLE_ROTATION = (8, 17)  # left and right ankle internal rotation in the 18 angle columns


@lru_cache(maxsize=2)
def _walk(noise: bool = False) -> BilateralSimulation:
    return simulate_bilateral(
        40.0, SEED, noise=None if noise else ImuNoise.none(), turns=TurnParams(pass_s=5.0)
    )


def _yaw(R: np.ndarray) -> np.ndarray:
    return np.unwrap(np.arctan2(R[:, 1, 0], R[:, 0, 0]))


def test_the_walk_turns_about_between_straight_passes() -> None:
    sim = _walk()
    t = sim.trial.time_s
    starts = sim.truth["turns"]["start_s"]
    assert len(starts) == turn_starts(TurnParams(pass_s=5.0), 1.5, float(t[-1])).size >= 2
    yaw = _yaw(sim.feet["left"].rotation)
    for t_k in starts:
        before = yaw[(t > t_k - 3.0) & (t < t_k - 0.5)]
        assert np.abs(before - before.mean()).max() < np.deg2rad(20.0)  # straight before the turn
    # each turn reverses the direction of travel of the pelvis
    pel = sim.sensor_pos_m["pelvis"][:, :2]
    for t_k in starts[:-1]:
        v0 = pel[np.searchsorted(t, t_k - 0.5)] - pel[np.searchsorted(t, t_k - 1.5)]
        v1 = pel[np.searchsorted(t, t_k + 3.4)] - pel[np.searchsorted(t, t_k + 2.4)]
        cos = float(v0 @ v1 / np.linalg.norm(v0) / np.linalg.norm(v1))
        assert cos < -0.9


def test_a_foot_pivots_on_the_floor_and_the_hip_takes_the_turn() -> None:
    sim = _walk()
    t = sim.trial.time_s
    turned = []
    for side in ("left", "right"):
        plan = sim.feet[side]
        yaw = _yaw(plan.rotation)
        for a, b in plan.events.foot_flat_s:
            inside = (t >= a) & (t <= b)
            if not inside.any():
                continue
            turned.append(abs(yaw[inside][-1] - yaw[inside][0]))
            # flat and on the floor: the ankle keeps its height while the foot turns
            z = plan.ankle_m[inside, 2]
            assert np.ptp(z) < 1e-6
    assert max(turned) > np.deg2rad(30.0)  # some stances pivot a lot
    assert np.median(turned) < np.deg2rad(1.0)  # on the straight passes the foot is still
    # the hips rotate through the turn; the ankles stay within their everyday range
    ankle_rot = np.rad2deg(sim.angles_rad[:, ANKLE_ROTATION])
    assert np.abs(ankle_rot).max() < 25.0


def test_a_walk_without_turns_is_unchanged_by_the_option() -> None:
    a = simulate_bilateral(6.0, 3, noise=ImuNoise.none())
    b = simulate_bilateral(6.0, 3, noise=ImuNoise.none(), turns=None)
    np.testing.assert_array_equal(a.trial.acc["left_foot"], b.trial.acc["left_foot"])
    assert "turns" not in a.truth


@pytest.mark.parametrize(
    "kwargs",
    [
        {"turns": TurnParams(pass_s=0.1)},
        {"turns": TurnParams(speed_factor=1.5)},
        {"turns": TurnParams(), "treadmill": TreadmillParams()},
        {"turns": TurnParams(), "stops": PauseParams(count=1)},
    ],
)
def test_bad_turns_are_refused_in_one_line(kwargs: dict) -> None:
    with pytest.raises(InputError) as e:
        simulate_bilateral(20.0, 0, **kwargs)
    assert "\n" not in str(e.value)


def test_the_pipeline_finds_events_and_angles_through_the_turns() -> None:
    sim = _walk(noise=True)
    res = process_bilateral_trial(sim.trial)
    assert res.gait.events is not None
    errs = []
    for side in ("left", "right"):
        est = np.asarray(getattr(res.gait.events, side).initial_contact_s)
        for t_true in sim.feet[side].events.initial_contact_s:
            if t_true > 3.0:
                errs.append(1000.0 * np.min(np.abs(est - t_true)))
    assert np.median(errs) < 10.0
    assert np.max(errs) < 40.0
    walking = sim.trial.time_s > 3.0
    err = np.rad2deg(res.angles_rad - sim.angles_rad)[walking]
    knee = np.sqrt(np.mean(err[:, [3, 12]] ** 2, axis=0))
    assert knee.max() < 2.0
    # the tracks went through the turns unaided: the drift breaks there, each pass is straight,
    # and gait.json says that step width rests on the calibrated chain
    params = res.gait.parameters
    assert params is not None and params.track_drift is not None
    assert params.track_drift.knot_time_s.size > 2 + len(sim.truth["turns"]["start_s"])
    assert params.track_drift.heading_spread < 0.1
    assert params.step_width_basis == "standing_chain_straight_walk"
    # a foot pivoting through a turn has no contact position; its strides and steps are turning
    # ones, so the strides the summary calls straight have their lengths and widths
    straight = params.select(turning=False)
    assert len(straight) > 20
    assert np.mean([np.isnan(s.stride_length_m) for s in straight]) < 0.2
    steps = [s for s in params.strides if not s.step_turning]
    assert np.mean([np.isnan(s.step_width_m) for s in steps]) < 0.2
    # the walker's turns from the pelvis sensor: each simulated turn about, its direction and 180°
    turns = res.gait.turns
    assert turns is not None
    done = [t for t in turns.turns if t.complete]
    truth = sim.truth["turns"]
    ends = [s + truth["turn_s"] for s in truth["start_s"] if s + truth["turn_s"] < sim.trial.time_s[-1]]
    assert len(done) == len(ends)
    for t, start, direction in zip(done, truth["start_s"], truth["direction"], strict=False):
        assert abs(abs(t.angle_deg) - 180.0) < 15.0 and t.direction == direction
        assert abs(t.start_s - start) < 0.5 and abs(t.end_s - (start + truth["turn_s"])) < 0.5
        assert t.steps >= 3


def test_the_command_line_simulates_turns_for_two_legs_only(tmp_path, capsys) -> None:
    from lowerlimb.cli import main

    out = tmp_path / "turns.csv"
    assert main(["simulate", "--side", "both", "--duration", "16", "--turns", "--out", str(out)]) == 0
    assert "straight passes and turns about" in capsys.readouterr().out and out.is_file()
    # calibrate reports the walker's turn in gait.json, on the terminal and in the report
    assert main(["calibrate", str(out), "--out", str(tmp_path / "cal")]) == 0
    said = "".join(capsys.readouterr())
    turns = json.loads((tmp_path / "cal" / "gait.json").read_text())["turns"]
    assert turns["count"] == 1 and abs(turns["angle_deg"]["mean"] - 180.0) < 15.0
    assert "turns  1:" in said
    report = (tmp_path / "cal" / "report.html").read_text()
    assert "id='turns-table'" in report and f"{turns['list'][0]['steps']}</td></tr>" in report
    for argv, says in (
        (["--turns"], "--turns is a seven-IMU walk option; add --side both"),
        (["--side", "both", "--turns", "--stops", "1"], "--turns walks have no --stops and no --treadmill"),
        (["--side", "both", "--turns", "--treadmill"], "--turns walks have no --stops and no --treadmill"),
    ):
        assert main(["simulate", "--duration", "20", *argv, "--out", str(tmp_path / "x.csv")]) == 2
        err = capsys.readouterr().err
        assert says in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.csv").exists()
