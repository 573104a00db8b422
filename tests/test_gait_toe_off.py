"""Toe-off from the forefoot's unloading in the foot's specific force (lowerlimb.gait.toe_off)."""

import numpy as np
from test_gait_foot_contact import _trial

from lowerlimb.gait import GaitParams, detect_side_events
from lowerlimb.gait.toe_off import forefoot_unloading

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


def test_side_events_take_the_foot_toe_off_and_flag_it():
    shank, foot, acc, _, _, to = _trial(RATE)
    ev = detect_side_events(shank, RATE, "left", foot_gyr=foot, foot_acc=acc)
    # constant specific force: every toe-off falls back to the shank minimum
    assert ev.toe_off_from_foot.shape == ev.toe_off_s.shape
    assert not ev.toe_off_from_foot.any()
    assert np.max(np.abs(ev.toe_off_s - to)) <= 0.01


def test_gait_json_says_where_the_events_came_from():
    from lowerlimb.gait import compute_gait_parameters, detect_gait_events

    shank, foot, acc, _, _, _ = _trial(RATE)
    ev = detect_gait_events(
        RATE, left_shank_gyr=shank, left_foot_gyr=foot, left_foot_acc=acc, right_shank_gyr=shank
    )
    src = compute_gait_parameters(ev).to_dict()["event_sources"]
    assert src["left"]["initial_contact"] == "foot_heel_rocker"
    assert src["right"]["initial_contact"] == "shank_minimum"
    assert src["left"]["toe_off_from_foot"] == 0
    assert src["left"]["toe_off_from_shank"] == ev.left.toe_off_s.size > 0
