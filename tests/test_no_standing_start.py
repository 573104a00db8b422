"""A two-leg walk cut from a longer recording: no standing start, the first sample mid-stride.

Such a trial must calibrate with one warning (docs/formats.md); it used to be refused as
mirrored knees (the right knee axis flipped by a sign rule referenced to the first sample),
warned three times, and its right foot's first strides came out 0.47-0.99 m for 1.25 m
while that foot's orientation filter converged from a mid-swing start.
"""

import warnings

import numpy as np
import pytest

from lowerlimb.bilateral import UnanchoredFeetWarning, process_bilateral_trial
from lowerlimb.conventions import quat_to_matrix
from lowerlimb.io.trial import StandingStartWarning
from lowerlimb.orientation import estimate_orientation
from lowerlimb.simulation import simulate_bilateral


@pytest.fixture(scope="module")
def cut():
    sim = simulate_bilateral(30.0, 7)
    ev = sim.feet["right"].events
    rate = sim.trial.rate_hz
    to = float(ev.toe_off_s[ev.toe_off_s > 5.0][0])
    ic = float(ev.initial_contact_s[ev.initial_contact_s > to][0])
    k0 = int(round(0.5 * (to + ic) * rate))  # the right foot mid-swing
    return sim, k0, sim.trial.from_sample(k0)


def _tilt_deg(q_est, q_true):
    up_e, up_t = quat_to_matrix(q_est)[:, 2, :], quat_to_matrix(q_true)[:, 2, :]
    return np.degrees(np.arccos(np.clip(np.sum(up_e * up_t, axis=1), -1.0, 1.0)))


def test_orientation_from_a_mid_swing_start_is_right_from_the_first_sample(cut):
    sim, k0, trial = cut
    rate = trial.rate_hz
    q = estimate_orientation(trial.gyr["right_foot"], trial.acc["right_foot"], rate_hz=rate)
    tilt = _tilt_deg(q, sim.quat_wxyz["right_foot"][k0:])
    # without the warm start: 60-70° over the first 2 s (the first sample's swing acceleration)
    assert tilt[: int(5 * rate)].max() < 6.0


def test_two_legs_calibrate_with_one_warning(cut):
    sim, k0, trial = cut
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = process_bilateral_trial(trial)
    standing = [w for w in caught if issubclass(w.category, StandingStartWarning)]
    assert len(standing) == 1 and "first second" in str(standing[0].message)
    # the feet never stand together before the first step: no step length or width, said once
    assert sum(issubclass(w.category, UnanchoredFeetWarning) for w in caught) == 1
    assert all(np.isnan(s.step_width_m) for s in res.gait.parameters.strides)
    for side in ("left", "right"):
        est = np.asarray(res.calibration_dict()["legs"][side]["joints"]["knee"]["axis_in_parent_sensor"])
        tru = np.asarray(sim.truth["legs"][side]["joints"]["knee"]["axis_in_parent_sensor"])
        assert est @ tru > 0.95, side
    true_length = float(np.median([s.stride_length_m for s in sim.gait.side("right")]))
    first = [s.stride_length_m for s in res.gait.parameters.select("right")[:3]]
    assert first == pytest.approx([true_length] * 3, rel=0.03)
