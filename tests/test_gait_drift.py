"""The drift of one foot's track against the other, removed with the chain (lowerlimb.gait.drift)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_gait_trajectory import RATE, W, _both

from lowerlimb.errors import InputError
from lowerlimb.gait import FootAnchor, GaitParams, compute_gait_parameters
from lowerlimb.gait.drift import ChainSteps, fit_track_drift, unaided_gaps

STEP_S = 0.55  # one right contact per stride, s


def _walk(duration_s: float, turn: str, rng: np.random.Generator):
    """Times (s) and unit walking directions of right contacts on a walk.

    ``turn``: "straight"; "bend" (a steady turn of 1.2°/step); "laps" (30 s passes,
    turning back between them).
    """
    t = np.arange(1.0, duration_s, STEP_S)
    if turn == "straight":
        psi = np.full_like(t, 0.3)
    elif turn == "bend":
        psi = np.deg2rad(1.2) * np.arange(t.size)
    else:
        psi = np.pi * (np.floor(t / 30.0) % 2)
    psi = psi + np.deg2rad(2.0) * rng.standard_normal(t.size)  # stride-to-stride wobble
    return t, np.column_stack([np.cos(psi), np.sin(psi)])


def _offsets(t, u, drift, bias, noise_m, rng):
    """Chain minus track: the chain's bias turned with the walk, plus the track's drift, plus noise."""
    lateral = np.column_stack([-u[:, 1], u[:, 0]])
    return bias[0] * u + bias[1] * lateral + drift(t) + noise_m * rng.standard_normal((t.size, 2))


def _drift(t):
    """A drift that speeds up and turns: 1 m in 10 minutes, as on the simulated walk seed 11."""
    return np.column_stack([-1.0e-6 * (t - 0.5) ** 2 * 2.8, 2.0e-4 * (t - 0.5) + 0.03 * np.sin(t / 90.0)])


@pytest.mark.parametrize("turn", ["bend", "laps"])
@pytest.mark.parametrize("bias", [(-0.06, 0.02), (0.05, 0.2)])
def test_the_drift_is_found_and_the_chains_bias_left_out(turn, bias):
    rng = np.random.default_rng(1)
    t, u = _walk(600.0, turn, rng)
    o = _offsets(t, u, _drift, np.asarray(bias), 0.03, rng)
    fit = fit_track_drift(t, o, u, 0.5, GaitParams())
    assert fit is not None and fit.steps_used == t.size
    err = fit.at(t) - _drift(t)
    assert np.median(np.linalg.norm(err, axis=1)) < 0.015  # a drift of up to 1 m
    assert np.max(np.linalg.norm(err, axis=1)) < 0.05
    assert fit.chain_bias_m == pytest.approx(bias, abs=0.01)
    assert fit.residual_sd_m == pytest.approx(0.03 * np.sqrt(1.0), rel=0.25)
    # an exact anchor: the fit may correct it, by under a centimetre here
    assert np.max(np.linalg.norm(fit.at(np.array([0.0, 0.5])), axis=1)) < 0.01
    pinned = fit_track_drift(t, o, u, 0.5, GaitParams(chain_anchor_sd_m=None))
    assert pinned is not None
    assert pinned.at(np.array([0.0, 0.5])) == pytest.approx(np.zeros((2, 2)))  # pinned at the anchor


@pytest.mark.parametrize("turn", ["bend", "laps"])
def test_an_anchor_error_is_corrected_on_a_walk_that_turns(turn):
    """The standing anchor put the right track 4 cm off; a turning walk tells that from the chain's bias."""
    rng = np.random.default_rng(5)
    t, u = _walk(300.0, turn, rng)
    anchor_error = np.array([0.03, -0.03])
    o = _offsets(t, u, lambda x: _drift(x) + anchor_error, np.array([0.05, 0.2]), 0.03, rng)
    fit = fit_track_drift(t, o, u, 0.5, GaitParams())
    pinned = fit_track_drift(t, o, u, 0.5, GaitParams(chain_anchor_sd_m=None))
    assert fit is not None and pinned is not None
    truth = _drift(t) + anchor_error
    err, err_pinned = (np.linalg.norm(f.at(t) - truth, axis=1) for f in (fit, pinned))
    assert np.max(err[t < 30.0]) < 0.025 < np.max(err_pinned[t < 30.0])  # pinned: 4 cm at the start
    assert np.median(err) < np.median(err_pinned)


def test_a_biased_chain_on_a_straight_walk_moves_nothing():
    """Walking straight, the chain's bias and a constant offset look alike: the anchor is kept."""
    rng = np.random.default_rng(2)
    t, u = _walk(300.0, "straight", rng)
    o = _offsets(t, u, lambda x: np.zeros((x.size, 2)), np.array([0.1, 0.2]), 0.03, rng)
    fit = fit_track_drift(t, o, u, 0.5, GaitParams())
    assert fit is not None
    assert fit.max_m < 0.03  # a 2° stride-to-stride wobble lets the noise move the anchor a little
    pinned = fit_track_drift(t, o, u, 0.5, GaitParams(chain_anchor_sd_m=None))
    assert pinned is not None and pinned.max_m < 0.02


def test_outlying_steps_do_not_pull_the_drift():
    rng = np.random.default_rng(3)
    t, u = _walk(300.0, "laps", rng)
    o = _offsets(t, u, _drift, np.array([0.0, 0.2]), 0.03, rng)
    bad = rng.choice(t.size, t.size // 20, replace=False)
    o[bad] += 0.5  # a stumble, a missed contact
    fit = fit_track_drift(t, o, u, 0.5, GaitParams())
    assert fit is not None
    assert np.median(np.linalg.norm(fit.at(t) - _drift(t), axis=1)) < 0.015


def test_laps_spread_the_walking_directions():
    rng = np.random.default_rng(4)
    t, u = _walk(300.0, "laps", rng)
    fit = fit_track_drift(t, _offsets(t, u, _drift, np.zeros(2), 0.03, rng), u, 0.5, GaitParams())
    assert fit is not None and fit.heading_spread > 0.9  # as many steps one way as back


def test_too_few_steps_or_switched_off_leave_the_tracks():
    rng = np.random.default_rng(4)
    t, u = _walk(300.0, "laps", rng)
    o = _offsets(t, u, _drift, np.zeros(2), 0.03, rng)
    assert fit_track_drift(t, o, u, 0.5, GaitParams(chain_drift_knot_s=None)) is None
    n = GaitParams().chain_drift_min_steps
    assert fit_track_drift(t[: n - 1], o[: n - 1], u[: n - 1], 0.5, GaitParams()) is None
    nan = o.copy()
    nan[n - 1 :] = np.nan  # only finite steps count
    assert fit_track_drift(t, nan, u, 0.5, GaitParams()) is None


def _passes(duration_s: float, pass_s: float, rng: np.random.Generator):
    """Right contacts on straight passes of ``pass_s`` with a turn about between them (no contact in it)."""
    t, _ = _walk(duration_s, "straight", rng)
    lap = np.floor(t / pass_s)
    t = t[(t - lap * pass_s) > 1.5]  # the turn: 1.5 s without a contact at the start of each pass
    psi = np.pi * (np.floor(t / pass_s) % 2) + np.deg2rad(2.0) * rng.standard_normal(t.size)
    turns = pass_s * np.arange(1, duration_s // pass_s + 1)
    gaps = np.column_stack([turns - 0.2, turns + 1.5])  # the feet's last and first stance around it
    return t, np.column_stack([np.cos(psi), np.sin(psi)]), gaps


def _jumps(pass_s: float, rng: np.random.Generator):
    """A track that jumps by a few centimetres at every turn (integrated through it unaided)."""
    steps = 0.06 * rng.standard_normal((200, 2))
    steps[0] = 0.0  # the first pass stands where the anchor put it
    return lambda x: np.cumsum(steps, axis=0)[np.floor(np.asarray(x) / pass_s).astype(int)]


def test_a_track_that_jumps_at_each_turn_is_followed_across_the_breaks():
    rng = np.random.default_rng(8)
    t, u, gaps = _passes(90.0, 8.0, rng)
    jumps = _jumps(8.0, rng)
    o = _offsets(t, u, jumps, np.array([0.02, 0.1]), 0.02, rng)
    broken = fit_track_drift(t, o, u, 0.5, GaitParams(), breaks_s=gaps)
    smooth = fit_track_drift(t, o, u, 0.5, GaitParams())
    assert broken is not None and smooth is not None
    # each pass has one walking direction, so a free jump also takes that pass's share of the
    # chain's bias: what must hold is the error in the walking frame, the same on every pass
    # (the step width's error does not change at the turns)
    lateral = np.column_stack([-u[:, 1], u[:, 0]])

    def walking_frame_spread(f):
        e = f.at(t) - jumps(t)
        return max(np.std(np.sum(e * u, axis=1)), np.std(np.sum(e * lateral, axis=1)))

    assert walking_frame_spread(broken) < 0.015
    assert walking_frame_spread(smooth) > 2.0 * walking_frame_spread(broken)
    # each pass is straight: the turns' directions no longer tell the bias from the drift
    assert smooth.heading_spread > 0.9 and broken.heading_spread < 0.1
    # knots at both ends of every gap inside the fitted steps
    inside = gaps[(gaps[:, 0] > 0.5) & (gaps[:, 1] < t[-1])]
    assert set(np.round(inside.ravel(), 6)) <= set(np.round(broken.knot_time_s, 6))


def test_without_gaps_the_fit_is_the_regular_grids():
    rng = np.random.default_rng(9)
    t, u = _walk(120.0, "bend", rng)
    o = _offsets(t, u, _drift, np.array([0.05, 0.2]), 0.03, rng)
    plain = fit_track_drift(t, o, u, 0.5, GaitParams())
    none = fit_track_drift(t, o, u, 0.5, GaitParams(), breaks_s=np.zeros((0, 2)))
    assert plain is not None and none is not None
    np.testing.assert_allclose(plain.knot_offset_m, none.knot_offset_m, atol=1e-12)
    np.testing.assert_allclose(plain.knot_time_s, 0.5 + 30.0 * np.arange(plain.knot_time_s.size))


def test_unaided_gaps_are_the_long_ones_of_either_foot():
    left = np.array([[0.0, 1.0], [1.6, 1.9], [4.0, 4.3]])  # 0.6 s swing, then 2.1 s unaided
    right = np.array([[0.0, 1.3], [2.0, 2.2], [2.8, 3.0]])
    gaps = unaided_gaps([left, right], GaitParams())
    np.testing.assert_allclose(gaps, [[1.9, 4.0]])
    assert unaided_gaps([left, right], GaitParams(chain_drift_gap_s=None)).shape == (0, 2)
    assert unaided_gaps([np.zeros((0, 2))], GaitParams()).shape == (0, 2)


@pytest.mark.parametrize("side", ["right", "left"])
def test_step_geometry_survives_a_drifting_track(side):
    """One foot's track drifts 2 cm/s forward and 1 cm/s sideways; an exact chain at that
    foot's contacts undoes it, whichever foot it is."""
    ev, trl, trr = _both()
    anchor = FootAnchor(time_s=0.5, forward_m=0.0, left_m=-W)
    exact = compute_gait_parameters(ev, trl, trr, anchor=anchor)
    mine, other = (trr, trl) if side == "right" else (trl, trr)
    t = np.arange(mine.position_m.shape[0]) / RATE
    drifted = replace(mine, position_m=mine.position_m + np.column_stack([0.02 * t, 0.01 * t, 0 * t]))
    contacts = getattr(ev, side)
    assert contacts is not None
    k = np.round((contacts.initial_contact_s + 0.05) * RATE).astype(int)
    d = mine.position_m[k] - other.position_m[k]
    chain = ChainSteps(contacts.initial_contact_s, d[:, 0] + 0.05, d[:, 1] - 0.2, side=side)  # biased
    # knots 3 s apart: the left foot's first usable chain step (2.7 s; at 1.5 s the right foot
    # has no contact yet) must come before the second knot, or on this straight five-step walk
    # the chain's bias and the drift's first slope cannot be told apart (2 s: 47 mm off)
    p = GaitParams(chain_drift_knot_s=3.0, chain_drift_min_steps=3)
    tracks = (trl, drifted) if side == "right" else (drifted, trr)
    lost = compute_gait_parameters(ev, *tracks, anchor=anchor, params=p)
    found = compute_gait_parameters(ev, *tracks, anchor=anchor, chain=[chain], params=p)
    assert found.track_drift is not None and lost.track_drift is None
    assert found.track_drift.moving_side == side
    # a straight walk: the chain checked the drift but not the anchor's sideways error
    assert found.track_drift.heading_spread < p.straight_heading_spread
    assert found.step_width_basis == "standing_chain_straight_walk"
    assert lost.step_width_basis == "standing_chain"
    assert compute_gait_parameters(ev, *tracks, params=p).step_width_basis is None  # not anchored
    turned = replace(found, track_drift=replace(found.track_drift, heading_spread=0.4))
    assert turned.step_width_basis == "chain_over_turns"
    assert found.to_dict()["step_width_basis"] == "standing_chain_straight_walk"

    def steps(gp):
        rows = [(s.step_length_m, s.step_width_m) for s in gp.strides]
        return np.array([r for r in rows if np.isfinite(r[1])])

    truth, bad, good = steps(exact), steps(lost), steps(found)
    assert np.max(np.abs(bad - truth)) > 0.05
    assert np.max(np.abs(good - truth)) < 0.01
    assert found.to_dict()["track_drift_max_m"] == pytest.approx(found.track_drift.max_m)
    record = found.to_dict()["track_drift"]
    assert record["knot_time_s"][0] == pytest.approx(0.5)
    assert np.linalg.norm(record["knot_offset_m"][0]) < 0.01  # the exact anchor barely moves
    assert record["steps_used"] == found.track_drift.steps_used and lost.to_dict()["track_drift"] is None
    assert set(record) == {
        "moving_side",
        "max_m",
        "knot_time_s",
        "knot_offset_m",
        "chain_bias_forward_m",
        "chain_bias_left_m",
        "residual_sd_m",
        "steps_used",
        "heading_spread",
    }
    # each foot's stride length is its own track's: the drift between the feet leaves it alone
    assert [s.stride_length_m for s in found.strides] == [s.stride_length_m for s in lost.strides]


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("chain_drift_knot_s", 0.0),
        ("chain_drift_knot_s", float("nan")),
        ("chain_drift_sd_m", -0.05),
        ("chain_anchor_sd_m", 0.0),
        ("chain_drift_huber", 0.0),
        ("chain_drift_min_steps", 0),
        ("chain_drift_iterations", 0),
        ("chain_stance_margin_s", -0.1),
        ("chain_drift_gap_s", 0.0),
        ("chain_drift_break_sd_m", 0.0),
    ],
)
def test_impossible_drift_settings_are_refused_with_their_name(field, value):
    with pytest.raises(InputError, match=field):
        GaitParams(**{field: value})
