"""A foot accelerometer cut at its range gets the force it lost in each swing back (gait.cut_force)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from lowerlimb.bilateral.process import process_bilateral_trial
from lowerlimb.conventions import GRAVITY_MPS2
from lowerlimb.errors import InputError
from lowerlimb.gait import GaitParams, detect_stationary, integrate_foot
from lowerlimb.gait.cut_force import restore_swing
from lowerlimb.io.saturation import find_saturation
from lowerlimb.simulation.bilateral_walk import simulate_bilateral

RATE = 100.0
G2 = 2.0 * GRAVITY_MPS2


def _swings(n_strides: int = 4) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A foot resting 0.7 s between swings along x: a short 4 g push (0.16 s) and a long
    1.4 g braking (0.46 s), so only the push goes beyond ±2 g. Returns (specific force, the
    contact positions' x, the swing's ends as sample indices)."""
    t1, a1, a2 = 0.16, 4.0 * GRAVITY_MPS2, 1.4 * GRAVITY_MPS2
    t2 = a1 * t1 / a2  # the braking takes away the push's velocity
    rest = int(0.7 * RATE)
    pieces, ends = [np.zeros(rest)], []
    for _ in range(n_strides):
        tau1 = (np.arange(int(round(t1 * RATE))) + 0.5) / RATE
        tau2 = (np.arange(int(round(t2 * RATE))) + 0.5) / RATE
        push, brake = a1 * np.sin(np.pi * tau1 / t1), a2 * np.sin(np.pi * tau2 / t2)
        pieces += [push, -brake * push.sum() / brake.sum(), np.zeros(rest)]  # ends at rest exactly
        ends.append(sum(p.size for p in pieces) - rest)
    ax = np.concatenate(pieces)
    f = np.zeros((ax.size, 3))
    f[:, 0] = ax
    f[:, 2] = GRAVITY_MPS2
    v = np.cumsum(ax) / RATE
    x = np.cumsum(v) / RATE
    return f, x[np.asarray(ends) + rest // 2], np.asarray(ends)


def _track(f: np.ndarray, cut_axes: np.ndarray | None, params: GaitParams | None = None) -> np.ndarray:
    n = f.shape[0]
    gyr, quat = np.zeros((n, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    p = params or GaitParams(gravity_mps2=GRAVITY_MPS2)
    st = detect_stationary(gyr, f, RATE, p)
    return integrate_foot(gyr, f, RATE, st, quat_wxyz=quat, params=p, cut_axes=cut_axes).position_m


def test_a_cut_push_is_restored() -> None:
    """One cut run per swing: the end velocity fixes its height; the stride comes back within
    1 %, where the cut signal integrated as recorded puts it more than 5 % off."""
    f, true_x, ends = _swings()
    cut = np.clip(f, -G2, G2)
    sat = find_saturation(cut, "acc")
    assert sat is not None and sat.level == pytest.approx(G2)
    assert set(np.unique(sat.axes[:, 0])) == {0, 1} and not sat.axes[:, 1:].any()
    mid = ends + int(0.35 * RATE)
    truth = np.diff(true_x)
    restored = np.diff(_track(cut, sat.axes)[mid, 0])
    raw = np.diff(_track(cut, None)[mid, 0])
    assert np.all(np.abs(restored / truth - 1) < 0.01), (restored, truth)
    assert np.all(np.abs(raw / truth - 1) > 0.05), (raw, truth)


def test_nothing_cut_changes_nothing() -> None:
    f, *_ = _swings(2)
    zeros = np.zeros(f.shape, dtype=np.int8)
    assert np.array_equal(_track(f, zeros), _track(f, None))


def test_the_force_goes_beyond_the_limit_only_along_the_cut_axis() -> None:
    f, *_ = _swings(1)
    cut = np.clip(f, -G2, G2)
    axes = np.zeros(f.shape, dtype=np.int8)
    axes[cut[:, 0] >= G2, 0] = 1
    seg = slice(int(0.7 * RATE) - 1, None)
    v_end = np.array([np.sum(cut[seg, 0]) / RATE, 0.0, 0.0])  # as if integrated (rectangles)
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (f.shape[0], 1))
    fix = restore_swing(v_end, quat[seg], cut[seg], axes[seg], RATE, 1e-4)
    assert fix.heights_mps2.size == 1 and fix.heights_mps2[0] > 0
    assert not fix.force_earth_mps2[:, 1:].any()
    assert np.all(fix.force_earth_mps2[axes[seg, 0] == 0] == 0)
    assert fix.velocity_mps == pytest.approx(abs(v_end[0]), rel=1e-2)


def test_bad_ridge_is_refused() -> None:
    with pytest.raises(InputError, match="cut_restore_ridge_s2"):
        GaitParams(cut_restore_ridge_s2=-1.0)


@pytest.fixture(scope="module")
def cut_walk():
    """A seven-IMU walk (30 s) with every accelerometer cut at ±2 g, processed with and without
    restoring the feet."""
    sim = simulate_bilateral(30.0, 201)
    trial = replace(sim.trial, acc={k: np.clip(v, -G2, G2) for k, v in sim.trial.acc.items()})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        restored = process_bilateral_trial(trial)
        raw = process_bilateral_trial(trial, gait_params=GaitParams(cut_restore=False))
    return sim, restored, raw


def _stride_errors(sim, res) -> np.ndarray:
    true = {(s.side, round(s.start_s, 1)): s.stride_length_m for s in sim.gait.strides}
    params = res.gait.parameters
    return np.array(
        [
            c.stride_length_m / true[(c.side, round(c.start_s, 1))] - 1.0
            for c in params.strides
            if (c.side, round(c.start_s, 1)) in true and np.isfinite(c.stride_length_m)
        ]
    )


def test_a_walk_cut_at_2g_keeps_its_stride_lengths(cut_walk) -> None:
    sim, restored, raw = cut_walk
    fixed, cut = _stride_errors(sim, restored), _stride_errors(sim, raw)
    assert fixed.size > 20 and cut.size == fixed.size
    assert np.median(np.abs(fixed)) < 0.025, np.median(np.abs(fixed))
    assert np.median(np.abs(cut)) > 0.08, np.median(np.abs(cut))


def test_gait_json_says_what_was_restored(cut_walk) -> None:
    _, restored, raw = cut_walk
    said = restored.gait.to_dict()["cut_force_restored"]
    for side in ("left", "right"):
        assert said[side]["swings"] > 10
        assert 0 < said[side]["velocity_mps_median"] <= said[side]["velocity_mps_max"]
    assert raw.gait.to_dict()["cut_force_restored"] == {"left": None, "right": None}
