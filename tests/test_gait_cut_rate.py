"""A foot gyro cut at its range gets the rotation it lost in each swing back (gait.cut_rate)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lowerlimb.bilateral import CutFootGyroWarning
from lowerlimb.bilateral.process import process_bilateral_trial
from lowerlimb.conventions import GRAVITY_MPS2
from lowerlimb.errors import InputError
from lowerlimb.gait import GaitParams, detect_stationary
from lowerlimb.gait.cut_rate import restore_cut_gyro
from lowerlimb.io.saturation import find_saturation
from lowerlimb.simulation.bilateral_walk import simulate_bilateral

RATE = 100.0
LIMIT = np.deg2rad(250.0)


def _foot(n_swings: int = 4, rest_s: float = 0.8) -> tuple[np.ndarray, np.ndarray]:
    """A foot resting between swings that pitch it about its y axis: a fast 0.2 s lobe peaking
    at 500 °/s, then a slow 0.6 s return at the rate that brings it back only halfway, so
    the foot rests tilted differently after each swing and only the fast lobe goes beyond
    ±250 °/s. Returns the true gyro and the specific force (gravity at rest, (N, 3) each)."""
    fast = np.deg2rad(500.0) * np.sin(np.pi * (np.arange(20) + 0.5) / 20)
    slow = -np.sin(np.pi * (np.arange(60) + 0.5) / 60)
    slow *= 0.5 * fast.sum() / -slow.sum()  # returns half the fast lobe's pitch
    rest = np.zeros(int(rest_s * RATE))
    wy = np.concatenate([rest] + [np.concatenate([fast, slow, rest]) for _ in range(n_swings)])
    gyr = np.zeros((wy.size, 3))
    gyr[:, 1] = wy
    pitch = np.concatenate([[0.0], np.cumsum(wy[:-1]) / RATE])  # orientation before each sample
    rot = Rotation.from_rotvec(np.column_stack([np.zeros_like(pitch), pitch, np.zeros_like(pitch)]))
    acc = rot.inv().apply([0.0, 0.0, GRAVITY_MPS2])  # gravity alone: only the rests matter here
    return gyr, acc


def _swing_pitch(gyr: np.ndarray) -> np.ndarray:
    """Each swing's pitch change, deg (the signal's positive area between rests)."""
    moving = np.abs(gyr[:, 1]) > 1e-9
    edges = np.flatnonzero(np.diff(moving.astype(int)))
    starts, stops = edges[::2] + 1, edges[1::2] + 1
    return np.degrees([gyr[a:b, 1].sum() / RATE for a, b in zip(starts, stops, strict=True)])


def _restore(gyr: np.ndarray, acc: np.ndarray, params: GaitParams | None = None):
    cut = np.clip(gyr, -LIMIT, LIMIT)
    sat = find_saturation(cut, "gyr")
    assert sat is not None and sat.level == pytest.approx(LIMIT)
    rests = detect_stationary(cut, acc, RATE, params or GaitParams())
    return cut, restore_cut_gyro(cut, acc, RATE, sat.axes, rests, params)


def test_a_cut_swing_gets_its_rotation_back() -> None:
    gyr, acc = _foot()
    cut, fix = _restore(gyr, acc)
    truth, lost, restored = _swing_pitch(gyr), _swing_pitch(cut), _swing_pitch(fix.gyr_rps)
    assert np.all(np.abs(lost - truth) > 10.0), (lost, truth)
    assert np.all(np.abs(restored - truth) < 1.0), (restored, truth)
    assert fix.swings == 4
    assert np.all(fix.tilt_before_deg > 10.0) and np.all(fix.tilt_after_deg < 0.5)
    # only the cut axis, only beyond the limit
    changed = fix.gyr_rps != cut
    assert not changed[:, [0, 2]].any()
    assert np.all(np.abs(fix.gyr_rps[changed[:, 1], 1]) >= LIMIT)


def test_swings_without_a_cut_or_a_rest_after_them_stay_as_recorded() -> None:
    gyr, acc = _foot(3)  # swings over 0.8–1.6, 2.4–3.2 and 4.0–4.8 s
    end = int(4.5 * RATE)  # the third swing runs into the recording's end
    gyr, acc = gyr[:end], acc[:end]
    cut = gyr.copy()
    for a, b in ((0.8, 1.6), (4.0, 4.5)):  # the second swing is not cut
        cut[int(a * RATE) : int(b * RATE)] = np.clip(cut[int(a * RATE) : int(b * RATE)], -LIMIT, LIMIT)
    axes = (np.sign(cut) * (np.abs(cut) == LIMIT)).astype(np.int8)  # at the limit: the cut samples
    rests = detect_stationary(cut, acc, RATE, GaitParams())
    fix = restore_cut_gyro(cut, acc, RATE, axes, rests)
    assert not np.array_equal(fix.gyr_rps[80:160], cut[80:160])
    assert np.array_equal(fix.gyr_rps[160:400], cut[160:400])  # through the uncut swing
    last_rest_end = max(b for _, b in rests.runs)
    assert last_rest_end < end and np.array_equal(fix.gyr_rps[last_rest_end:], cut[last_rest_end:])


def test_bad_settings_are_refused() -> None:
    for name in (
        "cut_rate_tilt_sd_rad",
        "cut_rate_prior_fraction",
        "cut_rate_prior_min_rps",
        "cut_rate_rest_s",
    ):
        with pytest.raises(InputError, match=name):
            GaitParams(**{name: 0.0})


@pytest.fixture(scope="module")
def cut_walk():
    """A seven-IMU walk (30 s) with every gyro cut at ±250 °/s, with and without the restoration."""
    sim = simulate_bilateral(30.0, 201)
    trial = replace(sim.trial, gyr={k: np.clip(v, -LIMIT, LIMIT) for k, v in sim.trial.gyr.items()})
    out = {}
    for restore in (True, False):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            out[restore] = process_bilateral_trial(trial, gait_params=GaitParams(cut_restore=restore))
        out[restore, "warned"] = [w for w in caught if w.category is CutFootGyroWarning]
    return sim, out


def _stride_errors(sim, res) -> np.ndarray:
    true = {(s.side, round(s.start_s, 1)): s.stride_length_m for s in sim.gait.strides}
    return np.array(
        [
            c.stride_length_m / true[(c.side, round(c.start_s, 1))] - 1.0
            for c in res.gait.parameters.strides
            if (c.side, round(c.start_s, 1)) in true and np.isfinite(c.stride_length_m)
        ]
    )


def test_a_walk_cut_at_250_dps_keeps_its_stride_lengths(cut_walk) -> None:
    sim, out = cut_walk
    fixed, cut = _stride_errors(sim, out[True]), _stride_errors(sim, out[False])
    assert fixed.size > 20
    assert np.median(np.abs(fixed)) < 0.6 * np.median(np.abs(cut)), (fixed, cut)
    for side in ("left", "right"):
        restore = out[True].legs[side].foot_gyro_restore
        assert restore is not None and restore.swings > 10
        assert np.median(restore.tilt_after_deg) < 0.5 * np.median(restore.tilt_before_deg)
        assert out[False].legs[side].foot_gyro_restore is None


def test_a_cut_foot_gyro_leaves_the_steps_unplaced(cut_walk) -> None:
    _, out = cut_walk
    for restore in (True, False):
        gait = out[restore].gait.to_dict()
        assert "foot gyro" in gait["steps_unplaced"] and "±250 °/s" in gait["steps_unplaced"]
        assert gait["anchor"] is None and gait["step_width_basis"] is None
        assert all(s.step_width_m != s.step_width_m for s in out[restore].gait.parameters.strides)  # NaN
        assert len(out[restore, "warned"]) == 1
        assert gait["left"]["stride_length_m"]["n"] > 5  # the strides stay


def test_the_cli_says_why_the_steps_are_null(tmp_path, capsys) -> None:
    """``calibrate`` on a seven-IMU walk recorded at ±250 °/s: exit 0, the cut sensors and the
    unplaced steps each said in one warning line, gait.json with strides and no step width."""
    import json

    from lowerlimb.cli import main

    sim = simulate_bilateral(16.0, 202)
    trial = replace(sim.trial, gyr={k: np.clip(v, -LIMIT, LIMIT) for k, v in sim.trial.gyr.items()})
    csv = tmp_path / "walk.csv"
    trial.to_csv(csv)
    capsys.readouterr()
    assert main(["calibrate", str(csv), "--out", str(tmp_path / "res")]) == 0
    err = capsys.readouterr().err.splitlines()
    said = [line for line in err if "step length and step width are null" in line]
    assert len(said) == 1 and said[0].startswith("lowerlimb: warning: ") and "±1000 °/s" in said[0]
    assert any("gyro is cut at its range" in line for line in err)
    gait = json.loads((tmp_path / "res" / "gait.json").read_text())
    assert gait["steps_unplaced"] == said[0].removeprefix("lowerlimb: warning: ")
    assert gait["step_width_m"]["mean"] is None and gait["left"]["stride_length_m"]["mean"] > 0.5
