"""The seven-IMU walk's push-off: a toe segment, the toe tip as the last contact, a human rate profile.

Each test checks what lowerlimb/simulation/toe_rocker.py and footsteps.py promise: the toe
tip stays put on the floor until toe-off and toe-off is the instant it leaves; the MTP joint
is dorsiflexed as set at toe-off; the rearfoot plantarflexes fastest before toe-off and most
after it, keeping its toe-off rate for the drawn hold and stopping within the drawn stop; the
rearfoot's pose has no step in acceleration where a pivot changes, and one at toe-off, where the
floor lets the foot go; the toe passes the floor at the drawn minimum clearance.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from lowerlimb.conventions import GRAVITY_MPS2, SIDES
from lowerlimb.simulation import BilateralSimulation, ImuNoise, simulate_bilateral
from lowerlimb.simulation.footsteps import FootPlan, WalkDraw, draw_walk, pelvis_path, plan_feet
from lowerlimb.simulation.toe_rocker import PreSwingParams

#: Steady walking: after the first strides, before the spline's extrapolated end.
STEADY_S = (4.0, 14.0)


#: Heel, MTP joint centre and toe tip of a foot ~26 cm long, foot frame, m (as _foot_points).
FOOT = (np.array([-0.057, -0.075, 0.0]), np.array([0.16, -0.05, 0.0]), np.array([0.2, -0.075, 0.0]))


@lru_cache(maxsize=1)
def _fine_plan() -> tuple[FootPlan, WalkDraw, float]:
    """One foot's plan sampled at 1 kHz (6 s, walking from 1 s), its walk and the step, s."""
    d = draw_walk(np.random.default_rng(11))
    h = 1e-3
    t = np.arange(0.0, 6.0, h)
    heading, xy, _ = pelvis_path(t, d, 1.0)
    return plan_feet("right", d, t, 1.0, (heading, xy), np.array([0.0, -0.09, 0.08]), FOOT), d, h


@lru_cache(maxsize=1)
def _walk() -> BilateralSimulation:
    return simulate_bilateral(16.0, 4, noise=ImuNoise.none())


def _steady(times: np.ndarray) -> np.ndarray:
    return times[(times > STEADY_S[0]) & (times < STEADY_S[1])]


def _pitch(plan: FootPlan) -> np.ndarray:
    """(N,) rearfoot pitch, toes up positive, rad (its x axis above the horizontal)."""
    return np.arcsin(np.clip(plan.rotation[:, 2, 0], -1.0, 1.0))


def test_the_toe_tip_stays_on_the_floor_until_toe_off_and_then_leaves_it():
    sim = _walk()
    t = sim.clean.time_s
    for side in SIDES:
        plan = sim.feet[side]
        ev = plan.events
        tip = plan.toe_tip_m
        floor = tip[t < 1.0, 2].mean()  # standing: the whole sole on the floor
        for to in _steady(ev.toe_off_s):
            flat_start = ev.foot_flat_s[ev.foot_flat_s[:, 0] < to][-1, 0]
            on = (t >= flat_start) & (t <= to)
            # from foot-flat until toe-off the tip does not move and touches the floor
            assert np.ptp(tip[on], axis=0).max() < 1e-9
            np.testing.assert_allclose(tip[on, 2], floor, atol=1e-9)
            # it leaves the floor at toe-off: higher at every sample of the next 0.15 s
            after = (t > to) & (t < to + 0.15)
            assert np.all(tip[after, 2] > floor - 1e-9)
            assert np.all(tip[after & (t > to + 0.02), 2] > floor + 1e-4)
            assert np.all(np.diff(tip[after, 2][:8]) > 0.0)
            assert tip[after, 2][-1] > floor + 0.01


def test_the_mtp_joint_is_dorsiflexed_as_set_at_toe_off():
    plan, d, h = _fine_plan()
    heel, mtp, toe = FOOT
    for to in plan.events.toe_off_s[plan.events.toe_off_s > 2.5]:
        k = int(round(to / h))
        R = plan.rotation[k]
        toe_dir = plan.toe_tip_m[k] - (plan.ankle_m[k] + R @ mtp)
        rear_dir = R @ (toe - mtp)  # where the toe would point with the MTP joint neutral
        cos = toe_dir @ rear_dir / (np.linalg.norm(toe_dir) * np.linalg.norm(rear_dir))
        assert np.rad2deg(np.arccos(np.clip(cos, -1, 1))) == pytest.approx(
            PreSwingParams().mtp_at_toe_off_deg, abs=0.5
        )


def test_the_rearfoot_plantarflexes_fastest_before_toe_off_and_most_after_it():
    sim = _walk()
    t = sim.clean.time_s
    T = sim.draw.stride_time_s
    for side in SIDES:
        plan = sim.feet[side]
        rate = np.gradient(_pitch(plan), t)
        for to in _steady(plan.events.toe_off_s):
            near = (t > to - 0.25 * T) & (t < to + 0.15 * T)
            k = np.flatnonzero(near)
            fastest = t[k[np.argmin(rate[k])]]
            most = t[k[np.argmin(_pitch(plan)[k])]]
            # the push-off slows down before the tip leaves (Perry & Burnfield 2010; on real
            # feet the peak comes 40-60 ms early) and the ankle plantarflexes on into swing
            assert 0.02 * T < to - fastest < 0.10 * T
            assert 0.02 * T < most - to < 0.10 * T
            assert np.deg2rad(50.0) < -_pitch(plan)[k].min() < np.deg2rad(85.0)


def _acc_jumps(plan: FootPlan, h: float, times: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Ankle (3) and pitch accelerations just before and just after each time, extrapolated to it."""
    y = np.column_stack([plan.ankle_m, _pitch(plan)])
    acc = np.gradient(np.gradient(y, h, axis=0), h, axis=0)
    t = np.arange(y.shape[0]) * h
    out = []
    for tj in times:
        k = int(round(tj / h))
        # each side's acceleration extrapolated to the join by a quadratic through 10 samples
        left = np.arange(k - 12, k - 2)
        right = np.arange(k + 3, k + 13)
        before = np.array([np.polyval(np.polyfit(t[left], acc[left, i], 2), tj) for i in range(4)])
        after = np.array([np.polyval(np.polyfit(t[right], acc[right, i], 2), tj) for i in range(4)])
        out.append((before, after))
    return out


def test_the_rearfoot_pose_has_no_step_in_acceleration_where_the_pivot_changes():
    """Heel-off and toe-roll onset are C² joins (initial contact, foot-flat and toe-off are not)."""
    plan, d, h = _fine_plan()
    ev = plan.events
    walking_to = ev.toe_off_s[ev.toe_off_s > 2.5]
    roll_onsets = walking_to - (d.stance_fraction - 0.5) * d.stride_time_s
    joins = np.concatenate([ev.foot_flat_s[ev.foot_flat_s[:, 1] > 2.5, 1], roll_onsets])
    assert joins.size >= 4
    for tj, (before, after) in zip(joins, _acc_jumps(plan, h, joins), strict=True):
        jump = after - before
        # a C¹ join (a rocker starting with a finite angular acceleration, as heel-off was)
        # steps by several m/s² and tens of rad/s²
        assert np.abs(jump[:3]).max() < 0.2, tj
        assert abs(jump[3]) < 1.0, tj


def test_at_toe_off_the_floor_lets_the_ankle_go():
    """Right after toe-off the ankle has no forward acceleration and falls at most at g."""
    plan, d, h = _fine_plan()
    tos = plan.events.toe_off_s[plan.events.toe_off_s > 2.5]
    assert tos.size >= 2
    for to, (before, after) in zip(tos, _acc_jumps(plan, h, tos), strict=True):
        assert np.abs(after[:2]).max() < 0.3, to
        assert -GRAVITY_MPS2 - 0.3 < after[2] < 0.0, to
        # a step: the push-off was still accelerating the ankle forwards
        assert np.linalg.norm(before[:2]) > 2.0, to


def test_after_toe_off_the_rearfoot_keeps_its_rate_then_stops():
    plan, d, h = _fine_plan()
    rate = np.gradient(_pitch(plan), h)
    hold, stop = d.plantarflexion_hold_s, d.plantarflexion_stop_s
    assert 0.01 < hold < 0.04 and 0.02 < stop < 0.05
    for to in plan.events.toe_off_s[plan.events.toe_off_s > 2.5]:
        k = int(round(to / h))
        w0 = rate[k + 2]
        assert w0 < -3.0  # still plantarflexing fast (rad/s)
        held = rate[k + 2 : k + int(hold / h) - 1]
        np.testing.assert_allclose(held, w0, rtol=0.02)
        k_max = k + int(round((hold + stop) / h))
        assert abs(rate[k_max]) < 0.05 * abs(w0)
        # the largest plantarflexion is there
        near = np.arange(k, k + int(0.15 / h))
        assert abs(near[np.argmin(_pitch(plan)[near])] - k_max) <= 3


def test_the_toe_passes_the_floor_at_the_drawn_clearance():
    plan, d, h = _fine_plan()
    ev = plan.events
    floor = plan.toe_tip_m[0, 2]  # standing: the whole sole on the floor
    for to in ev.toe_off_s[ev.toe_off_s > 2.5]:
        ic = ev.initial_contact_s[ev.initial_contact_s > to][0]
        s = (np.arange(plan.toe_tip_m.shape[0]) * h - to) / (ic - to)
        mid = (s >= 0.2) & (s <= 0.8)
        assert plan.toe_tip_m[mid, 2].min() - floor == pytest.approx(d.min_toe_clearance_m, abs=2e-4)
