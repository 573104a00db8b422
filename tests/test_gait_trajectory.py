import json

import numpy as np
import pytest

from lowerlimb.gait import (
    EVENTS_COLUMNS,
    FootAnchor,
    GaitEvents,
    GaitParams,
    SagittalRate,
    SideEvents,
    compute_gait_parameters,
    detect_stationary,
    integrate_foot,
    write_events_csv,
    write_gait_json,
)

RATE = 100.0
G = 9.81
T, SWING = 1.2, 0.48  # stride time and swing time, s: stance 60 %, double support 20 %
L, W = 1.3, 0.2  # stride length and step width, m


def _foot(first_to_s: float, first_disp: float, y: float, n_strides: int, bias=(0.0, 0.0, 0.0)):
    """Foot at rest except swings along x, acceleration A sin(2 pi tau / SWING): D = A SWING^2 / (2 pi)."""
    n = int((first_to_s + n_strides * T + 1.5) * RATE)
    t = np.arange(n) / RATE
    acc = np.zeros((n, 3))
    ic, to, contacts = [], [], [0.0]
    for k in range(n_strides):
        t0 = first_to_s + k * T
        d = first_disp if k == 0 else L
        amp = 2.0 * np.pi * d / SWING**2
        sw = (t >= t0) & (t <= t0 + SWING)
        acc[sw, 0] = amp * np.sin(2.0 * np.pi * (t[sw] - t0) / SWING)
        to.append(t0)
        ic.append(t0 + SWING)
        contacts.append(contacts[-1] + d)
    f = acc + np.array([0.0, 0.0, G]) + np.asarray(bias)
    gyr = np.zeros((n, 3))
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return gyr, f, quat, np.array(ic), np.array(to), np.array(contacts[1:]), y


def _side(name, ic, to):
    sag = SagittalRate(
        omega_rps=np.zeros(3), axis_in_sensor=np.array([0.0, 0.0, 1.0]), walking_fraction=1.0, axis_share=1.0
    )
    return SideEvents(side=name, initial_contact_s=ic, toe_off_s=to, midswing_s=ic - SWING / 2, sagittal=sag)


def _traj(foot, params=None):
    gyr, f, quat, *_ = foot
    st = detect_stationary(gyr, f, RATE, params)
    return integrate_foot(gyr, f, RATE, st, quat_wxyz=quat, params=params)


@pytest.mark.parametrize("bias", [(0.0, 0.0, 0.0), (0.05, -0.03, 0.02)])
def test_zupt_recovers_stride_lengths(bias):
    foot = _foot(1.0, L, 0.0, 5, bias)
    # gravity from params: with a biased accelerometer the measured norm is not g. The
    # orientation here is exact, not a filter's: levelling it on the biased accelerometer would
    # tilt it by the bias (a filter's tilt follows the accelerometer anyway), so it is off
    tr = _traj(foot, GaitParams(gravity_mps2=G, level_at_stance=not any(bias)))
    ic, contacts = foot[3], foot[5]
    rest = tr.position_m[np.round(ic * RATE).astype(int) + 5]
    # trapezoidal integration of a 48-sample swing costs ~0.15 % of each stride
    assert np.diff(rest[:, 0]) == pytest.approx(np.diff(contacts), rel=3e-3)
    assert np.all(np.abs(rest[:, 1:]) < 2e-3)
    assert np.all(np.linalg.norm(tr.velocity_mps[tr.stationary.mask], axis=1) == 0.0)


def _both():
    left = _foot(1.0, L / 2, W / 2, 6)
    right = _foot(1.0 + T / 2, L, -W / 2, 6)
    trl, trr = _traj(left), _traj(right)
    # each foot is integrated in its own frame from its own start: put the right one's start where it stands
    ev = GaitEvents(left=_side("left", left[3], left[4]), right=_side("right", right[3], right[4]))
    return ev, trl, trr


def test_parameters_from_known_bilateral_gait():
    ev, trl, trr = _both()
    gp = compute_gait_parameters(ev, trl, trr, anchor=FootAnchor(time_s=0.5, forward_m=0.0, left_m=-W))
    assert gp.anchored
    assert abs(gp.relative_heading_deg) < 0.1
    st = gp.select()
    assert len(st) == 10 and not gp.select(turning=True)
    for s in st:
        assert s.stride_time_s == pytest.approx(T, abs=1e-9)
        assert s.stride_length_m == pytest.approx(L, rel=3e-3)
        assert s.stance_pct == pytest.approx(60.0, abs=1e-6)
        assert s.swing_pct == pytest.approx(40.0, abs=1e-6)
    steps = [s for s in st if np.isfinite(s.step_length_m)]
    assert len(steps) >= 8
    for s in steps:
        assert s.step_length_m == pytest.approx(L / 2, abs=5e-3)
        assert s.step_width_m == pytest.approx(W, abs=5e-3)
        assert s.step_time_s == pytest.approx(T / 2, abs=1e-9)
    ds = [s.double_support_pct for s in st if np.isfinite(s.double_support_pct)]
    assert len(ds) >= 8 and np.allclose(ds, 20.0)
    d = gp.to_dict()
    assert d["cadence_steps_per_min"] == pytest.approx(100.0)
    assert d["gait_speed_m_s"] == pytest.approx(L / T, rel=5e-3)


def test_contact_at_the_recording_end_is_no_zero_length_stride():
    # the recording stops 50 ms after the last contact: that stance was not recorded, and
    # the contact must not take the previous stance (a stride of length zero)
    gyr, f, quat, ic, to, contacts, y = _foot(1.0, L, 0.0, 5)
    n = int((ic[-1] + 0.05) * RATE)
    foot = (gyr[:n], f[:n], quat[:n], ic, to, contacts, y)
    tr = _traj(foot)
    gp = compute_gait_parameters(GaitEvents(left=_side("left", ic, to), right=None), tr, None)
    lengths = [s.stride_length_m for s in gp.select("left")]
    assert len(lengths) == len(ic) - 1
    assert np.isnan(lengths[-1])
    assert lengths[:-1] == pytest.approx([L] * (len(ic) - 2), rel=3e-3)
    assert gp.summary("left")["stride_length_m"]["sd"] < 0.01


def test_without_anchor_step_geometry_is_unknown():
    ev, trl, trr = _both()
    gp = compute_gait_parameters(ev, trl, trr)
    assert not gp.anchored
    assert all(np.isnan(s.step_width_m) and np.isnan(s.step_length_m) for s in gp.strides)
    assert all(s.stride_length_m == pytest.approx(L, rel=3e-3) for s in gp.strides)


def test_sensor_to_ankle_offset_leaves_stride_length():
    ev, trl, trr = _both()
    p = GaitParams(sensor_to_ankle_m=(-0.08, 0.02, -0.05))
    gp = compute_gait_parameters(ev, trl, trr, anchor=FootAnchor(0.5, 0.0, -W), params=p)
    assert all(s.stride_length_m == pytest.approx(L, rel=3e-3) for s in gp.strides)


def test_turning_stride_is_reported_apart():
    ev, trl, trr = _both()
    # rotate the left foot's resting orientation by 90 deg about z from its 3rd contact on
    q = trl.quat_wxyz.copy()
    k = int(round(ev.left.initial_contact_s[2] * RATE)) - 5
    q[k:] = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]
    from dataclasses import replace

    gp = compute_gait_parameters(ev, replace(trl, quat_wxyz=q), trr)
    turning = gp.select("left", turning=True)
    assert len(turning) == 1 and turning[0].heading_change_deg == pytest.approx(90.0, abs=1e-6)
    assert gp.to_dict()["turning"]["left"]["n_strides"] == 1


def test_writers_produce_design_columns_and_keys(tmp_path):
    ev, trl, trr = _both()
    gp = compute_gait_parameters(ev, trl, trr, anchor=FootAnchor(0.5, 0.0, -W))
    p = write_events_csv(ev, tmp_path / "events.csv")
    lines = p.read_text().splitlines()
    assert tuple(lines[0].split(",")) == EVENTS_COLUMNS == ("time", "side", "event")
    rows = [ln.split(",") for ln in lines[1:]]
    assert {r[1] for r in rows} == {"left", "right"}
    assert {r[2] for r in rows} == {"initial_contact", "toe_off"}
    times = [float(r[0]) for r in rows]
    assert times == sorted(times) and len(rows) == 24
    d = json.loads(write_gait_json(gp, tmp_path / "gait.json").read_text())
    for key in ("cadence_steps_per_min", "gait_speed_m_s"):
        assert isinstance(d[key], float)
    assert set(d["step_width_m"]) >= {"mean", "sd"}
    for side in ("left", "right"):
        for key in ("stride_time_s", "stride_length_m", "step_length_m", "stance_pct", "double_support_pct"):
            assert set(d[side][key]) >= {"mean", "sd"}
            assert d[side][key]["mean"] is not None
    # NaN is written as null, not as an invalid JSON token
    d2 = json.loads(write_gait_json(compute_gait_parameters(ev, trl, trr), tmp_path / "g2.json").read_text())
    assert d2["left"]["step_width_m"]["mean"] is None


@pytest.mark.parametrize("radius_m", [15.0, -40.0])
def test_feet_on_a_bending_walk_are_not_turned_against_each_other(radius_m):
    """Both feet walk one circle (same frame, relative heading 0). A right stride overlaps
    left strides half a stride apart, whose directions differ by half a stride's turn; taken
    as it is, that difference turned the right track by 0.4° on a 5-minute simulated walk and
    drifted its step width by 2 m. The left heading interpolated at the right stride's
    mid-time leaves none."""
    from lowerlimb.conventions import rot_z
    from lowerlimb.gait.contacts import Contacts
    from lowerlimb.gait.placement import _pair_yaw_samples

    R, step = abs(radius_m), np.sign(radius_m) * (L / 2) / abs(radius_m)  # angle per step, rad

    def contacts(first: int, lateral: float) -> Contacts:
        th = step * np.arange(first, first + 40, 2)
        r = R + np.sign(radius_m) * lateral
        pos = np.column_stack(
            [r * np.sin(np.abs(th)), np.sign(radius_m) * (R - r * np.cos(th)), np.zeros_like(th)]
        )
        return Contacts(
            time_s=T / 2 * np.arange(first, first + 40, 2),
            position_m=pos,
            R_earth_sensor=np.stack([rot_z(a) for a in th]),
            period=np.arange(th.size),
        )

    left, right = contacts(0, -W / 2), contacts(1, W / 2)
    rows = _pair_yaw_samples(left, right, GaitParams())
    assert rows.shape[0] >= 15
    # half a stride's turn: 2.5° at 15 m, 0.9° at 40 m; now below a hundredth of that
    assert np.max(np.abs(np.rad2deg(rows[:, 1]))) < 0.01 * np.rad2deg(abs(step))
    overlap = _pair_yaw_samples(left, right, GaitParams(pair_yaw_at_mid_time=False))
    assert np.median(np.abs(overlap[:, 1])) == pytest.approx(abs(step), rel=0.05)  # half a stride


def test_walking_direction_near_an_anchor_after_a_turn():
    """An anchor where the walk ends takes the last stride's direction: the first one's, as
    before, points the other way after a turn and mirrored the feet's offset (the real walk
    cut mid-stride: step width 250-324 mm off)."""
    from lowerlimb.conventions import rot_z
    from lowerlimb.gait import walking_direction
    from lowerlimb.gait.contacts import Contacts

    x = np.array([0.0, 1.3, 2.6, 3.9, np.nan, 3.9, 2.6, 1.3])  # out, a turn (no position), back
    pos = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    c = Contacts(
        time_s=np.arange(x.size) * 1.1,
        position_m=pos,
        R_earth_sensor=np.stack([rot_z(0.0)] * x.size),
        period=np.arange(x.size),
    )
    assert walking_direction(c, -0.5) == pytest.approx([1.0, 0.0])  # a standing start: the first stride
    assert walking_direction(c, 3.0) == pytest.approx([1.0, 0.0])  # the stride around it
    assert walking_direction(c, 5.2) == pytest.approx([-1.0, 0.0])  # nearer the first stride back
    assert walking_direction(c, 20.0) == pytest.approx([-1.0, 0.0])  # after the walk: the last stride
    none = Contacts(
        time_s=np.zeros(1), position_m=np.zeros((1, 3)), R_earth_sensor=np.eye(3)[None], period=np.zeros(1)
    )
    assert walking_direction(none, 0.0) is None


def test_tilt_is_levelled_at_each_stance_and_heading_kept():
    """A tilt error growing with time (a filter lagging a gyro bias) is removed where the foot
    stands and, linear in time, in between; a heading error is not the accelerometer's to fix."""
    from lowerlimb.conventions import quat_from_rotvec, quat_multiply, quat_rotate
    from lowerlimb.gait.trajectory import levelled_at_stance

    n = 1000
    t = np.arange(n) / RATE
    f = np.tile([0.0, 0.0, G], (n, 1))  # the true orientation is the identity
    mask = (t % 1.0) < 0.4  # stance 0.4 s of every second
    st = detect_stationary(np.zeros((n, 3)), f, RATE)
    st = type(st)(mask, [(a, b) for a, b in _runs(mask)], st.statistic, st.gravity_mps2, RATE)
    tilt = np.column_stack([0.02 * t, -0.01 * t, np.zeros(n)])  # rad, up to 11° and 6°
    yaw = quat_from_rotvec(np.column_stack([np.zeros(n), np.zeros(n), np.full(n, 0.3)]))
    q = quat_multiply(quat_from_rotvec(tilt), yaw)
    fixed = levelled_at_stance(q, f, st)
    up = quat_rotate(fixed, f) / G
    inside = (t >= 0.2) & (t <= 9.2)  # between the first and the last stance's middle (held outside)
    assert np.degrees(np.arccos(np.clip(up[inside, 2], -1, 1))).max() < 0.05
    x = quat_rotate(fixed, np.tile([1.0, 0.0, 0.0], (n, 1)))
    assert np.allclose(np.arctan2(x[:, 1], x[:, 0]), 0.3, atol=2e-3)
    assert np.array_equal(levelled_at_stance(q, f, type(st)(np.zeros(n, bool), [], st.statistic, G, RATE)), q)


def _runs(mask):
    d = np.diff(np.r_[0, mask.astype(int), 0])
    return zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True)
