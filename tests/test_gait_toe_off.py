"""Toe-off from the forefoot's unloading in the foot's specific force (lowerlimb.gait.toe_off)."""

import numpy as np
from test_gait_foot_contact import _trial

from lowerlimb.gait import GaitParams, detect_side_events
from lowerlimb.gait.toe_off import forefoot_unloading, push_off_midpoint

RATE = 100.0


def _push_off(
    n: int, t_min: float, t_off: float, t_zero: float, drop: float
) -> tuple[np.ndarray, np.ndarray]:
    """Foot rate with its push-off minimum at ``t_min`` and zero at ``t_zero``; |f| unloading at ``t_off``.

    The specific force rises through push-off and then falls by ``drop`` m/s² in a
    smooth step, half-way at ``t_off`` (the toe leaving); its peak comes 10-20 ms before.
    """
    t = np.arange(n) / RATE
    om = np.where(t < t_min, -6.0 * np.exp(-0.5 * ((t - t_min) / 0.08) ** 2), 0.0)
    om += np.where(t >= t_min, -6.0 + 6.0 * np.clip((t - t_min) / (t_zero - t_min), 0.0, 2.0), 0.0)
    step = 0.5 * (1.0 - np.tanh((t - t_off) / 0.01))
    f = 10.0 + drop * step * np.exp(-0.5 * ((t - t_off) / 0.06) ** 2)
    acc = np.zeros((n, 3))
    acc[:, 2] = f
    return om, acc


def test_toe_off_is_half_way_down_the_unloading_not_at_its_peak():
    om, acc = _push_off(300, t_min=1.00, t_off=1.063, t_zero=1.12, drop=12.0)
    (k,) = forefoot_unloading(om, acc, [(60, 200)], RATE, GaitParams())
    peak = np.argmax(acc[100:112, 2]) + 100
    assert k is not None
    assert abs(k / RATE - 1.063) < 0.003
    assert k - peak > 0.8  # the peak, the earlier definition, is more than 8 ms early


def test_a_second_trough_after_the_swing_starts_is_not_the_unloading():
    # the swing's first forward acceleration lifts |f| again and drops it 0.5 m/s² deeper
    om, acc = _push_off(300, t_min=1.00, t_off=1.063, t_zero=1.12, drop=12.0)
    t = np.arange(300) / RATE
    acc[:, 2] += 20.0 * np.exp(-0.5 * ((t - 1.09) / 0.006) ** 2)
    acc[:, 2] -= 0.5 * np.exp(-0.5 * ((t - 1.105) / 0.005) ** 2)
    (k,) = forefoot_unloading(om, acc, [(60, 200)], RATE, GaitParams())
    assert k is not None
    assert abs(k / RATE - 1.063) < 0.004


def test_no_unloading_no_push_off_gives_none():
    om, acc = _push_off(300, t_min=1.00, t_off=1.053, t_zero=1.12, drop=12.0)
    flat = np.tile([0.0, 0.0, 9.81], (300, 1))
    assert forefoot_unloading(om, flat, [(60, 200)], RATE, GaitParams()) == [None]
    slow = 0.02 * om  # the foot never plantarflexes faster than event_min_rps
    assert forefoot_unloading(slow, acc, [(60, 200)], RATE, GaitParams()) == [None]
    shallow = GaitParams(unloading_min_mps2=40.0)
    assert forefoot_unloading(om, acc, [(60, 200)], RATE, shallow) == [None]


def test_estimate_stays_between_rate_minimum_and_zero_crossing():
    # a force peak long after the foot's plantarflexion has ended is not searched
    om, acc = _push_off(300, t_min=1.00, t_off=1.30, t_zero=1.12, drop=12.0)
    (k,) = forefoot_unloading(om, acc, [(60, 200)], RATE, GaitParams())
    assert k is None or 1.0 <= k / RATE <= 1.13


def test_push_off_midpoint_is_the_middle_of_the_rate_bracket():
    om, _ = _push_off(300, t_min=1.00, t_off=1.063, t_zero=1.12, drop=12.0)
    (k,) = push_off_midpoint(om, [(60, 200)], RATE, GaitParams())
    assert k is not None
    # within 7 ms of the analytic middle: the 15 Hz low-pass rounds the kink at the minimum
    assert abs(k / RATE - 0.5 * (1.00 + 1.12)) < 0.007
    assert push_off_midpoint(0.02 * om, [(60, 200)], RATE, GaitParams()) == [None]


def test_side_events_fall_back_foot_rate_then_shank_and_flag_it():
    shank, foot, acc, _, _, to = _trial(RATE)
    ev = detect_side_events(shank, RATE, "left", foot_gyr=foot, foot_acc=acc)
    # constant specific force: no unloading, every toe-off is the foot's push-off bracket middle,
    # after the synthetic foot's rate minimum (placed at the toe-off) and before its zero crossing
    assert ev.toe_off_source.shape == ev.toe_off_s.shape
    assert set(ev.toe_off_source) == {"foot_rate"}
    assert not ev.toe_off_from_foot.any()
    assert np.all((ev.toe_off_s - to > 0.01) & (ev.toe_off_s - to < 0.1))
    # a foot that never plantarflexes faster than event_min_rps: the shank's minimum
    still = detect_side_events(shank, RATE, "left", foot_gyr=0.01 * foot, foot_acc=acc)
    assert set(still.toe_off_source) == {"shank_minimum"}
    assert np.max(np.abs(still.toe_off_s - to)) <= 0.01
    # with an unloading in every stride, the foot's unloading comes first
    loaded = acc.copy()
    for t in to:
        loaded[:, 2] += 12.0 * np.exp(-0.5 * ((np.arange(acc.shape[0]) / RATE - (t + 0.02)) / 0.02) ** 2)
    ev2 = detect_side_events(shank, RATE, "left", foot_gyr=foot, foot_acc=loaded)
    assert set(ev2.toe_off_source) == {"foot_unloading"} and ev2.toe_off_from_foot.all()
    assert ev2.toe_off_counts() == {"foot_unloading": to.size, "foot_rate": 0, "shank_minimum": 0}


def test_gait_json_says_where_the_events_came_from():
    from lowerlimb.gait import compute_gait_parameters, detect_gait_events

    shank, foot, acc, _, _, _ = _trial(RATE)
    ev = detect_gait_events(
        RATE, left_shank_gyr=shank, left_foot_gyr=foot, left_foot_acc=acc, right_shank_gyr=shank
    )
    src = compute_gait_parameters(ev).to_dict()["event_sources"]
    assert src["left"]["initial_contact"] == "foot_heel_rocker"
    assert src["right"]["initial_contact"] == "shank_minimum"
    assert src["left"]["toe_off_from_foot"] == src["left"]["toe_off_from_shank"] == 0
    assert src["left"]["toe_off_from_foot_rate"] == ev.left.toe_off_s.size > 0
    assert src["right"]["toe_off_from_shank"] == ev.right.toe_off_s.size > 0
    assert src["right"]["toe_off_from_foot"] == src["right"]["toe_off_from_foot_rate"] == 0


def test_a_shuffling_foot_falls_back_to_the_middle_of_the_rate_bracket():
    """A weak push-off: no collapse of the specific force at toe-off, but the swing's first
    transient 30-40 ms later makes a deep trough of its own, which timed every toe-off of a
    shuffling simulated walk 52 ms late; it lies too far from the rate bracket's middle."""
    import dataclasses

    from lowerlimb.gait import detect_gait_events
    from lowerlimb.simulation import simulate_bilateral

    sim = simulate_bilateral(30.0, 201, pace="shuffle")
    t = sim.trial

    def late_ms(params: GaitParams) -> np.ndarray:
        ev = detect_gait_events(
            t.rate_hz,
            left_shank_gyr=t.gyr["left_shank"],
            right_shank_gyr=t.gyr["right_shank"],
            left_foot_gyr=t.gyr["left_foot"],
            left_foot_acc=t.acc["left_foot"],
            right_foot_gyr=t.gyr["right_foot"],
            right_foot_acc=t.acc["right_foot"],
            params=params,
        )
        assert ev.left is not None
        est = ev.left.toe_off_s
        true = sim.feet["left"].events.toe_off_s
        return np.array([1000.0 * (est[np.argmin(abs(est - x))] - x) for x in true if 3.0 < x < 29.0])

    assert np.median(late_ms(dataclasses.replace(GaitParams(), unloading_max_offset=np.inf))) > 40.0
    assert np.abs(late_ms(GaitParams())).max() < 20.0
