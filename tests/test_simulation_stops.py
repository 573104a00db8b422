"""A simulated walker who stops, stands and walks on (lowerlimb.simulation.pauses).

The stop must be physical (every sensor still, both feet down, nothing slides), the events must
be those of the walk at their real times (none inside a stop), the walk around the stops must
be the steady walk's, and the two-leg pipeline must find the strides on both sides of a stop.
"""

from __future__ import annotations

import warnings
from functools import lru_cache

import numpy as np
import pytest

from lowerlimb.bilateral import process_bilateral_trial
from lowerlimb.conventions import GRAVITY_ENU, SIDES
from lowerlimb.errors import InputError
from lowerlimb.simulation import BilateralSimulation, ImuNoise, simulate_bilateral
from lowerlimb.simulation.bilateral_walk import _foot_points
from lowerlimb.simulation.pauses import PauseParams, paused_time

STOPS = PauseParams(count=2, pause_s=3.0)


@lru_cache(maxsize=2)
def _walk(stops: bool) -> BilateralSimulation:
    return simulate_bilateral(30.0, 7, noise=ImuNoise.none(), stops=STOPS if stops else None)


def _stopped(sim: BilateralSimulation) -> list[tuple[float, float]]:
    """Runs of ≥ 1 s in which every sensor's clean gyro is below 1e-6 rad/s, s."""
    still = np.all([np.linalg.norm(g, axis=1) < 1e-6 for g in sim.clean.gyr.values()], axis=0)
    t = sim.clean.time_s
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(int), [0]])))
    return [(t[a], t[b - 1]) for a, b in zip(edges[::2], edges[1::2], strict=True) if t[b - 1] - t[a] >= 1.0]


def test_the_warp_stops_plan_time_for_the_pause_and_keeps_its_pace_elsewhere() -> None:
    t = np.arange(0.0, 20.0, 0.01)
    p = PauseParams(pause_s=3.0, ramp_s=0.6)
    tau = paused_time(t, np.array([5.0]), p)
    assert np.all(np.diff(tau) >= -1e-12)
    np.testing.assert_allclose(tau[t < 4.69], t[t < 4.69], atol=1e-9)  # untouched before the ramp
    frozen = np.abs(tau - 5.0) < 1e-9
    assert t[frozen].max() - t[frozen].min() == pytest.approx(3.0, abs=0.02)  # the hold
    # after the stop the plan runs at the walk's pace again, ramp + pause behind
    np.testing.assert_allclose(tau[t > 9.0], t[t > 9.0] - 3.6, atol=1e-6)


def test_a_stop_is_still_with_both_feet_down() -> None:
    sim = _walk(True)
    stops = _stopped(sim)
    assert len(stops) == 3  # the standing start and two stops
    for a, b in stops[1:]:
        assert b - a >= STOPS.pause_s - 0.15
        k = (sim.clean.time_s > a) & (sim.clean.time_s < b)
        for acc in sim.clean.acc.values():
            np.testing.assert_allclose(np.linalg.norm(acc[k], axis=1), np.linalg.norm(GRAVITY_ENU), atol=1e-4)
        for side in SIDES:  # both feet touch the ground: the heel or the toe tip at floor level
            heel, _, toe = _foot_points(sim.models[side])
            R, p = sim.feet[side].rotation[k], sim.feet[side].ankle_m[k]
            low = np.minimum((p + R @ heel)[:, 2], sim.feet[side].toe_tip_m[k][:, 2])
            assert np.ptp(low) < 1e-9 and abs(low[0] - sim.feet[side].toe_tip_m[0, 2]) < 0.01


def test_events_keep_their_order_and_none_falls_in_a_stop() -> None:
    sim, steady = _walk(True), _walk(False)
    stops = _stopped(sim)[1:]
    for side in SIDES:
        ev, ev0 = sim.feet[side].events, steady.feet[side].events
        assert np.all(np.diff(ev.initial_contact_s) > 0)
        for a, b in stops:
            assert not np.any((ev.initial_contact_s > a) & (ev.initial_contact_s < b))
            assert not np.any((ev.toe_off_s > a) & (ev.toe_off_s < b))
        # before the first stop's ramp the walk is the steady one's
        first = stops[0][0] - STOPS.ramp_s - 0.1
        np.testing.assert_allclose(
            ev.initial_contact_s[ev.initial_contact_s < first],
            ev0.initial_contact_s[ev0.initial_contact_s < first],
        )
    # a stride that spans a stop lasts a stride, the ramps and the pause
    spans = [
        s for s in sim.gait.strides if any(s.start_s < a < b < s.start_s + s.stride_time_s for a, b in stops)
    ]
    assert len(spans) == 2 * len(stops)
    T = sim.draw.stride_time_s
    for s in spans:
        assert s.stride_time_s > T + STOPS.pause_s


def test_the_pipeline_finds_the_strides_around_the_stops() -> None:
    sim = simulate_bilateral(30.0, 7, stops=STOPS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = process_bilateral_trial(sim.trial)
    assert res.gait.events is not None
    for side in SIDES:
        true_ic = sim.feet[side].events.initial_contact_s
        est = getattr(res.gait.events, side).initial_contact_s
        err = np.array([np.min(np.abs(est - ic)) for ic in true_ic[true_ic > 3.0]])
        assert np.all(err < 0.03), err


@pytest.mark.parametrize(
    "params", [PauseParams(count=-1), PauseParams(count=1, pause_s=0.0), PauseParams(count=1, ramp_s=np.nan)]
)
def test_bad_stops_are_refused(params: PauseParams) -> None:
    with pytest.raises(InputError, match="stops need"):
        simulate_bilateral(10.0, 1, stops=params)


def test_stops_that_leave_the_walker_standing_at_the_end_are_refused() -> None:
    with pytest.raises(InputError, match=r"1 stops of 100 s do not fit in a 30 s walk .*at most 11.7 s fit"):
        simulate_bilateral(30.0, 1, stops=PauseParams(count=1, pause_s=100.0))
    fits = PauseParams(count=1, pause_s=11.6)
    assert fits.longest_pause_s(30.0, 1.5) >= 11.6 and fits.needed_duration_s(1.5) <= 30.0
    sim = simulate_bilateral(30.0, 1, noise=ImuNoise.none(), stops=fits)
    moving = np.linalg.norm(sim.trial.gyr["left_shank"], axis=1) > 0.05
    # the longest stop that fits still leaves the walk the walking time it promises after it
    assert sim.trial.time_s[-1] - sim.trial.time_s[~moving][-1] >= fits.min_walk_after_s


def test_the_command_line_simulates_stops_for_two_legs_only(tmp_path, capsys) -> None:
    from lowerlimb.cli import main

    out = tmp_path / "stops.csv"
    assert main(["simulate", "--side", "both", "--duration", "20", "--stops", "1", "--out", str(out)]) == 0
    assert "1 stops of 3 s" in capsys.readouterr().out and out.is_file()
    for argv, says in (
        (["--stops", "1"], "--stops 1 is a seven-IMU walk option"),
        (["--side", "both", "--stops", "5"], "--stops 5 is out of range for a 20 s walk"),
        (
            ["--side", "both", "--stops", "1", "--stop-s", "100"],
            "--stops 1 of --stop-s 100 do not fit in --duration 20 (the walker must walk 2 s after the last "
            "stop); give --stop-s at most 6.65, or --duration 207 or more",
        ),
        (["--side", "both", "--stops", "2"], "give --stop-s at most 1.48, or --duration 30 or more"),
        (["--side", "both", "--stops", "1", "--stop-s", "inf"], "--stop-s inf is not a finite time"),
        (["--side", "both", "--stop-s", "5"], "--stop-s 5 is the length of each --stops stop; add --stops N"),
        (["--stop-s", "5"], "--stop-s 5 is the length of each --stops stop"),
    ):
        assert main(["simulate", "--duration", "20", *argv, "--out", str(tmp_path / "x.csv")]) == 2
        err = capsys.readouterr().err
        assert says in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.csv").exists()
