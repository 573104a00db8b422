"""The two-pass (forward and backward) orientation estimate: inclination from both, heading from one."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from simcache import cached_simulation

from lowerlimb.conventions import quat_conjugate, quat_multiply, quat_rotate
from lowerlimb.orientation import METHODS, estimate_orientation, orientation_errors
from lowerlimb.orientation.estimate import two_pass_inclination
from lowerlimb.simulation import ImuNoise

DATA = Path(os.environ.get("LOWERLIMB_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))


def _unit(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _up(q: np.ndarray) -> np.ndarray:
    """The earth's vertical in the sensor frame."""
    return quat_rotate(quat_conjugate(q), np.tile([0.0, 0.0, 1.0], (len(q), 1)))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 0.5))
def test_the_mean_inclination_with_the_forward_heading(seed: int, spread: float) -> None:
    rng = np.random.default_rng(seed)
    f = _unit(rng, 50)
    small = np.c_[np.ones(50), spread * rng.normal(size=(50, 3))]
    b = quat_multiply(small / np.linalg.norm(small, axis=1, keepdims=True), f)
    b[::3] *= -1.0  # either sign of the backward pass
    out = two_pass_inclination(f, b)
    b_signed = np.where((np.sum(f * b, axis=1) < 0)[:, None], -b, b)
    mean = (f + b_signed) / np.linalg.norm(f + b_signed, axis=1, keepdims=True)
    assert np.allclose(np.linalg.norm(out, axis=1), 1.0)
    assert np.allclose(_up(out), _up(mean), atol=1e-9)  # the mean's inclination
    turn = quat_multiply(out, quat_conjugate(f))  # forward -> result, earth frame
    assert np.allclose(np.arctan2(turn[:, 3], turn[:, 0]), 0.0, atol=1e-9)  # no twist about the vertical
    assert np.all(np.sum(out * f, axis=1) >= 0.0)  # the forward pass's sign
    assert np.allclose(two_pass_inclination(f, f), f)


@pytest.fixture(scope="module")
def walk():
    sim = cached_simulation("walk", 30.0, 3, noise=ImuNoise())
    return sim.trial, sim.quat_wxyz


@pytest.mark.parametrize("method", METHODS)
def test_the_backward_pass_halves_the_inclination_error_of_a_simulated_walk(walk, method) -> None:
    """30 s simulated walk, all four sensors: the smoothed inclination error is below the
    forward one (Mahony 9-axis: 1.5° → 0.7° mean) and the heading error barely moves. The
    QUEST Kalman filter's inclination error is not its lag: smoothing moves it either way on
    the simulator (6-axis 2.4° → 2.9° here) and improves it on BROAD (2.12° → 1.40°)."""
    trial, truth = walk
    mask = trial.time_s - trial.time_s[0] >= 1.5
    for mag in (trial.mag, None):
        fwd, smooth = [], []
        for s in ("pelvis", "thigh", "shank", "foot"):
            m = None if mag is None else mag[s]
            for out, kw in ((fwd, {}), (smooth, {"smooth": True})):
                q = estimate_orientation(
                    trial.gyr[s], trial.acc[s], m, rate_hz=trial.rate_hz, method=method, **kw
                )
                assert np.all(np.isfinite(q)) and np.allclose(np.linalg.norm(q, axis=1), 1.0)
                assert np.all(np.sum(q[1:] * q[:-1], axis=1) > 0)  # sign continuous
                out.append(orientation_errors(q, truth[s], mask, remove_heading_offset=mag is None))
        incl = [np.mean([e.inclination_deg for e in x]) for x in (fwd, smooth)]
        head = [np.mean([e.heading_deg for e in x]) for x in (fwd, smooth)]
        assert incl[1] < (1.3 if method == "quest_kf" else 0.85) * incl[0], (method, mag is None, incl)
        assert abs(head[1] - head[0]) < 0.1 + 0.1 * head[0], (method, mag is None, head)


@pytest.mark.data
@pytest.mark.skipif(not sorted((DATA / "broad").glob("*.mat")), reason=f"BROAD trials not found in {DATA}")
def test_the_backward_pass_helps_on_the_real_broad_trials() -> None:
    """Optical truth, 8 trials, Mahony 9-axis: inclination 0.91 → 0.84°, total 2.02 → 1.99°."""
    import scipy.io as sio

    incl, total = {False: [], True: []}, {False: [], True: []}
    for path in sorted((DATA / "broad").glob("*.mat")):
        d = sio.loadmat(path)
        gyr, acc, mag = (np.ascontiguousarray(d[k], dtype=float) for k in ("imu_gyr", "imu_acc", "imu_mag"))
        rate = float(np.squeeze(d["sampling_rate"]))
        movement = np.asarray(d["movement"]).reshape(-1).astype(bool)
        for smooth in (False, True):
            q = estimate_orientation(gyr, acc, mag, rate_hz=rate, smooth=smooth)
            e = orientation_errors(q, np.asarray(d["opt_quat"], dtype=float), movement)
            incl[smooth].append(e.inclination_deg)
            total[smooth].append(e.total_deg)
    assert np.mean(incl[True]) < np.mean(incl[False]) - 0.03, incl
    assert np.mean(total[True]) <= np.mean(total[False]), total


def test_the_forward_pass_keeps_the_still_start() -> None:
    """Weight 1 over the still start (where every angle is zeroed), ½ from 1 s after it on;
    a recording that starts moving hands over from its first sample."""
    from lowerlimb.orientation.estimate import STILL_HANDOVER_S, forward_weight

    w = forward_weight(500, 150, 100.0)
    assert np.all(w[:151] == 1.0) and np.all(np.diff(w) <= 0.0)
    assert np.all(w[150 + int(100 * STILL_HANDOVER_S) :] == 0.5)
    moving = forward_weight(300, 0, 100.0)
    assert moving[0] == 1.0 and moving[50] == pytest.approx(0.75) and moving[-1] == 0.5
    rng = np.random.default_rng(1)
    for n in (1, 2, 3):  # too short to run backward: the forward estimate, unit and finite
        q = estimate_orientation(
            0.1 * rng.normal(size=(n, 3)), np.tile([0.0, 0.0, 9.81], (n, 1)), rate_hz=100.0, smooth=True
        )
        assert q.shape == (n, 4) and np.allclose(np.linalg.norm(q, axis=1), 1.0)


def test_both_passes_in_one_run_are_the_two_estimates(walk) -> None:
    from lowerlimb.orientation.estimate import estimate_orientation_passes

    trial, _ = walk
    args = (trial.gyr["thigh"], trial.acc["thigh"], trial.mag["thigh"])
    forward, two_pass = estimate_orientation_passes(*args, rate_hz=trial.rate_hz, method="madgwick")
    assert np.array_equal(forward, estimate_orientation(*args, rate_hz=trial.rate_hz, method="madgwick"))
    assert np.array_equal(
        two_pass, estimate_orientation(*args, rate_hz=trial.rate_hz, method="madgwick", smooth=True)
    )
