"""The walker's turns from the pelvis's vertical rate (lowerlimb.gait.turns).

A turn about must be found with its angle, direction, duration and steps through the
pelvis's axial rotation of every stride; that rotation alone, a gently bending walk, a
small change of direction and walking round in circles must not make turns; hesitations
inside one turn must not split it; a turn cut by the recording must be listed, not summarised.
"""

from __future__ import annotations

import numpy as np
import pytest

from lowerlimb.conventions import quat_from_rotvec
from lowerlimb.errors import InputError
from lowerlimb.gait import GaitParams
from lowerlimb.gait.turns import detect_turns, vertical_rate

RATE = 100.0
STRIDE = 1.1  # s


def _walk(duration_s: float, turns: list[tuple[float, float, float]], sway_dps: float = 30.0) -> np.ndarray:
    """(N,) vertical rate, rad/s: the pelvis's axial sway once per stride plus turns.

    ``turns``: (start s, duration s, angle deg) each, a raised-cosine rate profile.
    """
    t = np.arange(int(duration_s * RATE)) / RATE
    w = np.deg2rad(sway_dps) * np.sin(2 * np.pi * t / STRIDE)
    for start, dur, angle in turns:
        inside = (t >= start) & (t < start + dur)
        profile = 1 - np.cos(2 * np.pi * (t[inside] - start) / dur)  # mean 1 over the turn
        w[inside] += np.deg2rad(angle) / dur * profile
    return w


def test_a_turn_about_is_found_through_the_pelvis_sway() -> None:
    w = _walk(20.0, [(8.0, 2.0, -180.0)])
    ic = 100.0 + np.arange(0.3, 20.0, STRIDE / 2)  # on the trial's clock, which starts at 100 s
    found = detect_turns(w, RATE, stride_time_s=STRIDE, initial_contacts_s=ic, start_time_s=100.0)
    assert len(found.turns) == 1
    turn = found.turns[0]
    assert turn.angle_deg == pytest.approx(-180.0, abs=5.0) and turn.direction == "right"
    assert 107.4 < turn.start_s < 108.3 and 109.7 < turn.end_s < 110.6  # on the trial's clock
    assert 120.0 < turn.peak_rate_deg_s < 180.0  # the profile peaks at 180 °/s; a stride's mean lowers it
    assert turn.steps == int(np.count_nonzero((ic >= turn.start_s) & (ic <= turn.end_s))) >= 3
    assert turn.complete and found.window_s == STRIDE
    d = found.to_dict()
    assert d["count"] == 1 and d["cut_by_recording"] == 0
    assert d["angle_deg"]["mean"] == pytest.approx(abs(turn.angle_deg)) and d["angle_deg"]["sd"] is None
    assert d["list"][0]["direction"] == "right"


@pytest.mark.parametrize(
    "turns, what",
    [
        ([], "the sway alone"),
        ([(5.0, 10.0, 50.0)], "a walk bending at 5 °/s"),
        ([(8.0, 1.5, 30.0)], "a 30° change of direction"),
        ([(2.0, 16.0, 720.0)], "walking round in circles for 16 s"),
    ],
)
def test_no_turn_is_made_of(turns: list, what: str) -> None:
    assert detect_turns(_walk(20.0, turns), RATE, stride_time_s=STRIDE).turns == [], what


def test_a_hesitation_does_not_split_a_turn_and_opposite_turns_stay_apart() -> None:
    # 90° and a stop of 0.9 s and 90° more; then a turn and a turn back
    w = _walk(30.0, [(8.0, 1.2, 90.0), (10.1, 1.2, 90.0), (20.0, 2.0, 180.0), (23.0, 2.0, -180.0)], 0.0)
    found = detect_turns(w, RATE, stride_time_s=STRIDE).turns
    assert [round(t.angle_deg / 10) * 10 for t in found] == [180, 180, -180]
    # without merging the hesitating turn is two
    apart = detect_turns(w, RATE, stride_time_s=STRIDE, params=GaitParams(pelvis_turn_merge_s=0.0))
    assert [round(t.angle_deg / 10) * 10 for t in apart.turns] == [90, 90, 180, -180]


def test_a_turn_cut_by_the_recording_is_listed_not_summarised() -> None:
    w = _walk(20.0, [(5.0, 2.0, 180.0), (18.5, 2.0, 180.0)])
    found = detect_turns(w, RATE, stride_time_s=STRIDE)
    assert [t.complete for t in found.turns] == [True, False]
    d = found.to_dict()
    assert d["count"] == 1 and d["cut_by_recording"] == 1 and len(d["list"]) == 2
    assert d["angle_deg"]["mean"] == pytest.approx(180.0, abs=5.0)


def test_without_events_the_window_is_about_a_stride() -> None:
    found = detect_turns(_walk(20.0, [(8.0, 2.0, 180.0)]), RATE)
    assert len(found.turns) == 1 and 0.8 < found.window_s < 1.4 and found.turns[0].steps == 0


def test_vertical_rate_uses_the_tilt_of_the_sensor() -> None:
    # a sensor pitched 90° about the earth's y: its x axis points down, so a rate about its
    # -x axis is a rate about the vertical
    q = np.tile(quat_from_rotvec(np.array([0.0, np.pi / 2, 0.0])), (3, 1))
    gyr = np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    assert vertical_rate(gyr, q) == pytest.approx([1.0, 0.0, 0.0], abs=1e-12)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"pelvis_turn_edge_dps": 0.0}, "pelvis_turn_edge_dps"),
        ({"pelvis_turn_edge_dps": 20.0, "pelvis_turn_peak_dps": 15.0}, "pelvis_turn_peak_dps"),
        ({"pelvis_turn_duration_s": (5.0, 1.0)}, "pelvis_turn_duration_s"),
        ({"pelvis_turn_min_deg": float("nan")}, "pelvis_turn_min_deg"),
        ({"pelvis_turn_merge_s": -1.0}, "pelvis_turn_merge_s"),
    ],
)
def test_bad_turn_thresholds_are_refused(kwargs: dict, name: str) -> None:
    with pytest.raises(InputError, match=name):
        GaitParams(**kwargs)
