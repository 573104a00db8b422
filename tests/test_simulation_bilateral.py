"""The seven-IMU walk simulator: a consistent bilateral gait with the feet on the ground.

Each test checks what the simulator promises (lowerlimb/simulation/bilateral_walk.py):
opposite phase and double support, a still foot while flat, a fixed heel and forefoot
pivot on the rockers, the planned foot poses reproduced by the joint angles, one pelvis
sensor, the standing reference posture, and gait parameters that agree with the walk drawn.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from lowerlimb.conventions import GRAVITY_ENU, SIDES
from lowerlimb.errors import InputError
from lowerlimb.simulation import BilateralSimulation, ImuNoise, simulate_bilateral
from lowerlimb.simulation.bilateral_walk import _foot_points
from lowerlimb.simulation.footsteps import PACE_RANGES, PACES


@lru_cache(maxsize=4)
def _walk(seed: int = 4, pace: str = "normal") -> BilateralSimulation:
    return simulate_bilateral(16.0, seed, noise=ImuNoise.none(), pace=pace)


#: The physical promises hold at both paces the simulator draws.
both_paces = pytest.mark.parametrize("pace", PACES)


def _mask(t: np.ndarray, periods: np.ndarray, trim: float) -> np.ndarray:
    m = np.zeros(t.shape, bool)
    for a, b in periods:
        m |= (t > a + trim) & (t < b - trim)
    return m


@both_paces
def test_legs_move_in_opposite_phase_with_double_support(pace):
    sim = _walk(pace=pace)
    left, right = (sim.feet[s].events for s in SIDES)
    T = sim.draw.stride_time_s
    # right contacts fall half a stride after the left ones
    for ic in left.initial_contact_s[1:-1]:
        nearest = right.initial_contact_s[np.argmin(np.abs(right.initial_contact_s - ic - T / 2))]
        assert nearest - ic == pytest.approx(T / 2, abs=1e-9)
    # after each contact the other foot is still down for (β − ½) T: double support
    for ic in right.initial_contact_s[1:-1]:
        to_other = left.toe_off_s[left.toe_off_s > ic][0]
        assert to_other - ic == pytest.approx((sim.draw.stance_fraction - 0.5) * T, abs=1e-9)


@both_paces
def test_a_flat_foot_is_still_and_its_rockers_pivot_on_fixed_points(pace):
    sim = _walk(pace=pace)
    t = sim.clean.time_s
    for side in SIDES:
        ev = sim.feet[side].events
        flat = _mask(t, ev.foot_flat_s, 0.03)
        assert flat.sum() > 100
        gyr = sim.clean.gyr[f"{side}_foot"][flat]
        acc = sim.clean.acc[f"{side}_foot"][flat]
        assert np.abs(gyr).max() < 0.01  # rad/s
        assert np.abs(np.linalg.norm(acc, axis=1) - np.linalg.norm(GRAVITY_ENU)).max() < 0.2
        # heel rocker: the heel point does not move between contact and foot-flat
        heel = _foot_points(sim.models[side])[0]
        for ic, (ff, _) in zip(ev.initial_contact_s, ev.foot_flat_s, strict=False):
            k = (t >= ic) & (t <= ff)
            p = sim.feet[side].ankle_m[k] + np.einsum("nij,j->ni", sim.feet[side].rotation[k], heel)
            assert np.ptp(p, axis=0).max() < 1e-9


@both_paces
def test_joint_angles_reproduce_the_planned_foot_and_the_knee_is_a_hinge(pace):
    sim = _walk(pace=pace)
    for side in SIDES:
        np.testing.assert_allclose(sim.ankle_m[side], sim.feet[side].ankle_m, atol=1e-7)
    knee = sim.angles_rad[:, [3, 12]]
    assert np.all(knee >= -1e-9)
    np.testing.assert_array_equal(sim.angles_rad[:, [4, 5, 13, 14]], 0.0)


def test_the_walk_starts_in_the_reference_posture_with_one_pelvis_sensor():
    sim = _walk()
    still = sim.clean.time_s < 1.4
    np.testing.assert_allclose(sim.angles_rad[still], 0.0, atol=1e-5)
    np.testing.assert_allclose(sim.clean.gyr["left_foot"][still], 0.0, atol=1e-6)
    for s in SIDES:
        np.testing.assert_array_equal(
            sim.models[s].sensor_placement("pelvis").homogeneous,
            sim.models["left"].sensor_placement("pelvis").homogeneous,
        )
    assert set(sim.trial.acc) == {
        "pelvis",
        *(f"{side}_{seg}" for side in SIDES for seg in ("thigh", "shank", "foot")),
    }


@both_paces
def test_gait_truth_agrees_with_the_walk_drawn(pace):
    sim = _walk(pace=pace)
    d = sim.draw
    steady = [s for s in sim.gait.strides if s.start_s > 5.0]
    assert len(steady) >= 8
    for s in steady:
        assert s.stride_time_s == pytest.approx(d.stride_time_s, abs=1e-9)
        assert s.stance_pct == pytest.approx(100 * d.stance_fraction, abs=1e-6)
        assert s.double_support_pct == pytest.approx(200 * (d.stance_fraction - 0.5), abs=1e-6)
        # the pelvis path bends slowly: stride length = speed × stride time within a few %
        assert s.stride_length_m == pytest.approx(d.speed_m_s * d.stride_time_s, rel=0.05)
    # on the slowly bending path a step's width swings by a few cm with the curvature
    widths = [s.step_width_m for s in steady]
    assert np.mean(widths) == pytest.approx(d.step_width_m, abs=0.015)
    assert max(abs(w - d.step_width_m) for w in widths) < 0.05
    assert sim.gait.cadence_steps_per_min == pytest.approx(120.0 / d.stride_time_s, rel=0.02)


@both_paces
def test_signals_look_like_walking(pace):
    sim = _walk(pace=pace)
    c = sim.clean
    body = slice(0, -30)  # the spline's last samples are extrapolated
    for name in c.acc:
        peak = np.linalg.norm(c.acc[name][body], axis=1).max()
        # the sacrum only bobs (~2-3 cm at the step frequency: ~±1.5-2 m/s² about g)
        assert (11.0 if name == "pelvis" else 12.0) < peak < 90.0, name
    knee = np.rad2deg(sim.angles_rad[:, 3])
    assert 50.0 < knee.max() < 85.0


def test_too_short_a_two_leg_walk_is_refused():
    with pytest.raises(InputError, match="at least"):
        simulate_bilateral(3.0, 0)


def test_a_walker_who_changes_pace_changes_step_length_and_width_at_constant_cadence():
    steady = simulate_bilateral(100.0, 7, noise=ImuNoise.none())
    pace = simulate_bilateral(100.0, 7, noise=ImuNoise.none(), pace_changes=True)
    d = pace.draw
    assert 0.15 <= d.pace_change <= 0.25 and 0.2 <= d.width_change <= 0.4
    assert (steady.draw.pace_change, steady.draw.width_change) == (0.0, 0.0)
    strides = [s for s in pace.gait.strides if s.start_s > 5.0]
    assert all(s.stride_time_s == pytest.approx(d.stride_time_s, abs=1e-9) for s in strides)
    for s in strides:  # stride length = the path's speed at the time × stride time, within a few %
        mid = s.start_s + 0.5 * s.stride_time_s - 1.5
        speed = d.speed_m_s * (1.0 + d.pace_change * np.sin(2 * np.pi * d.pace_hz * mid))
        assert s.stride_length_m == pytest.approx(speed * d.stride_time_s, rel=0.06)
    lengths = np.array([s.stride_length_m for s in strides])
    widths = np.array([s.step_width_m for s in strides])
    assert lengths.max() / lengths.min() > 1.25 and widths.max() / widths.min() > 1.3
    # everything else is the steady walk's: the pace has its own random stream
    np.testing.assert_array_equal(pace.trial.time_s, steady.trial.time_s)
    assert pace.draw.stride_time_s == steady.draw.stride_time_s


def test_the_command_line_simulates_a_change_of_pace_for_two_legs_only(tmp_path, capsys):
    import json

    from lowerlimb.cli import main

    out, truth = tmp_path / "t.csv", tmp_path / "truth.json"
    argv = ["simulate", "--side", "both", "--duration", "8", "--seed", "3", "--out", str(out)]
    assert main([*argv, "--truth", str(truth), "--pace-changes"]) == 0
    assert json.loads(truth.read_text())["walk"]["pace_change"] > 0.1
    capsys.readouterr()
    one = ["simulate", "--duration", "8", "--out", str(tmp_path / "one.csv"), "--pace-changes"]
    assert main(one) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--pace-changes is a seven-IMU walk option" in err
    assert not (tmp_path / "one.csv").exists()


@pytest.mark.parametrize("pace", ["slow", "shuffle"])
def test_a_slow_walker_draws_its_ranges_and_keeps_the_seeds_other_choices(pace):
    normal, slow = _walk(), _walk(pace=pace)
    r = PACE_RANGES[pace]
    d = slow.draw
    for field in ("stride_time_s", "speed_m_s", "stance_fraction", "heel_off_fraction", "step_width_m"):
        lo, hi = getattr(r, field)
        assert lo <= getattr(d, field) <= hi, field
    assert r.ic_pitch_deg[0] <= np.rad2deg(d.ic_pitch_rad) <= r.ic_pitch_deg[1]
    assert r.to_pitch_deg[0] <= np.rad2deg(d.to_pitch_rad) <= r.to_pitch_deg[1]
    # slower than any normal walk, with a longer double support
    assert d.speed_m_s < PACE_RANGES["normal"].speed_m_s[0]
    assert d.stance_fraction > PACE_RANGES["normal"].stance_fraction[1]
    # the pace-independent choices (heading, toe-out, sway, ...) are the seed's
    for field in ("heading0_rad", "toe_out_rad", "sway_m", "hip_rotation_deg", "min_toe_clearance_m"):
        assert getattr(d, field) == getattr(normal.draw, field), field
    with pytest.raises(InputError, match="pace must be one of normal, slow, shuffle"):
        simulate_bilateral(8.0, 0, pace="jog")


def test_the_command_line_simulates_a_slow_walker_for_two_legs_only(tmp_path, capsys):
    import json

    from lowerlimb.cli import main

    out, truth = tmp_path / "t.csv", tmp_path / "truth.json"
    argv = ["simulate", "--side", "both", "--duration", "8", "--seed", "3", "--out", str(out)]
    assert main([*argv, "--truth", str(truth), "--pace", "slow"]) == 0
    lo, hi = PACE_RANGES["slow"].speed_m_s
    assert lo <= json.loads(truth.read_text())["walk"]["speed_m_s"] <= hi
    capsys.readouterr()
    one = ["simulate", "--duration", "8", "--out", str(tmp_path / "one.csv"), "--pace", "slow"]
    assert main(one) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--pace slow is a seven-IMU walk option" in err


@pytest.mark.parametrize("pace", ["normal", "slow"])
def test_the_forefoot_loads_before_toe_off_at_a_slow_pace_too(pace):
    """The real walk (0.8 m/s) peaks at 20-24 m/s² in the foot's specific force at toe-off.
    With the toe rocker stretched over a slow walker's longer double support the magnitude
    fell smoothly through toe-off (at most 11 m/s² in the last 60 ms)."""
    sim = _walk(pace=pace)
    t = sim.clean.time_s
    f = np.linalg.norm(sim.clean.acc["left_foot"], axis=1)
    for to in sim.feet["left"].events.toe_off_s[2:-1]:
        before = (t > to - 0.06) & (t <= to)
        assert f[before].max() > 13.0


def test_a_vibrating_limb_moves_the_joints_rigidly_while_walking_only():
    calm = simulate_bilateral(12.0, 7, noise=ImuNoise.none())
    shaky = simulate_bilateral(12.0, 7, noise=ImuNoise.none(), limb_vibration_deg=0.3)
    d = np.rad2deg(shaky.angles_rad - calm.angles_rad)
    standing = slice(0, int(1.4 * 100))
    walking = slice(400, None)
    assert np.abs(d[standing]).max() < 1e-9
    for side in range(2):
        leg = d[walking, 9 * side : 9 * side + 9]
        moving = [0, 1, 2, 3, 6, 7, 8]  # hip, knee flexion, ankle
        np.testing.assert_allclose(leg[:, moving].std(axis=0), 0.3, rtol=0.2)
        assert np.abs(leg[:, 4:6]).max() < 1e-12  # the knee stays a hinge
    # the sensors follow the vibration: faster signals, the same placements and joint centres
    assert np.abs(shaky.trial.gyr["left_shank"][walking] - calm.trial.gyr["left_shank"][walking]).max() > 0.05
    assert shaky.truth["legs"] == calm.truth["legs"]


def test_a_limb_vibration_can_be_given_per_joint():
    calm = simulate_bilateral(8.0, 7, noise=ImuNoise.none())
    hip_only = simulate_bilateral(8.0, 7, noise=ImuNoise.none(), limb_vibration_deg=(0.2, 0.0, 0.0))
    d = np.rad2deg(hip_only.angles_rad - calm.angles_rad)[400:]
    np.testing.assert_allclose(d[:, 0:3].std(axis=0), 0.2, rtol=0.25)
    assert np.abs(d[:, 3:9]).max() < 1e-9  # the knee and ankle angles are those of the calm walk


def test_a_knee_that_turns_as_it_flexes_keeps_the_planned_feet():
    hinge = simulate_bilateral(8.0, 7, noise=ImuNoise.none())
    turning = simulate_bilateral(8.0, 7, noise=ImuNoise.none(), knee_rotation_per_flexion=0.2)
    for side in range(2):
        a = turning.angles_rad[:, 9 * side : 9 * side + 9]
        np.testing.assert_allclose(a[:, 5], 0.2 * a[:, 3], atol=1e-12)  # rotation follows flexion
        assert np.abs(a[:, 4]).max() < 1e-12  # no adduction
        assert np.rad2deg(np.ptp(a[200:, 5])) > 6.0
    # the rotation is about the shank's long axis: the ankle centres and the feet are where planned
    for s in SIDES:
        np.testing.assert_allclose(turning.ankle_m[s], hinge.ankle_m[s], atol=1e-8)
    np.testing.assert_allclose(turning.angles_rad[:, 3], hinge.angles_rad[:, 3], atol=1e-8)


@pytest.mark.parametrize(
    "kw",
    [
        {"limb_vibration_deg": -0.1},
        {"limb_vibration_deg": float("nan")},
        {"limb_vibration_deg": (0.1, 0.2)},
        {"knee_rotation_per_flexion": float("nan")},
        {"knee_rotation_per_flexion": 3.0},
    ],
)
def test_a_bad_vibration_or_knee_rotation_is_refused_with_its_name(kw):
    with pytest.raises(InputError, match=next(iter(kw))):
        simulate_bilateral(8.0, 7, **kw)
