"""A long trial's centre and axis fits on every k-th sample (CalibrationOptions.fit_max_samples).

Thinning must leave the estimates and their spreads where the fit on every sample puts
them (the signals are low-passed, so neighbouring samples repeat each other), and it must
actually happen: the Jacobian's singular values fall by √k.
"""

from __future__ import annotations

import numpy as np
import pytest
from rigid_pair import rigid_pair

import lowerlimb.calibration.hinge_axis as hinge_axis
from lowerlimb.calibration import CalibrationOptions, calibrate_hinge_joint, calibrate_spherical_joint
from lowerlimb.errors import InputError

ALL = CalibrationOptions(fit_max_samples=None)
HALF = CalibrationOptions(fit_max_samples=3000)  # 6000 samples → every 2nd


def _args(p):
    return (p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child)


@pytest.fixture(scope="module")
def noisy_ball():
    return rigid_pair(
        "spherical", seed=11, duration_s=60.0, still_s=1.5, gyro_noise=0.015, acc_noise=0.08, gyro_bias=0.01
    )


def test_a_thinned_centre_fit_keeps_the_centre_and_its_spread(noisy_ball):
    p = noisy_ball
    full = calibrate_spherical_joint(*_args(p), rate_hz=p.rate_hz, options=ALL)
    thin = calibrate_spherical_joint(*_args(p), rate_hz=p.rate_hz, options=HALF)
    for res in (full, thin):
        assert 1000 * np.linalg.norm(res.center_in_parent_sensor - p.center_parent) < 5.0
        assert 1000 * np.linalg.norm(res.center_in_child_sensor - p.center_child) < 5.0
    assert 1000 * np.linalg.norm(thin.center_in_parent_sensor - full.center_in_parent_sensor) < 1.0
    # half the samples: the singular values fall by √2 ...
    ratio = thin.excitation.singular_values[0] / full.excitation.singular_values[0]
    assert ratio == pytest.approx(np.sqrt(0.5), rel=0.05)
    # ... but the spread, scaled by the residual's correlation time, stays
    spread = thin.center_std_in_parent_sensor / full.center_std_in_parent_sensor
    assert np.all((spread > 0.75) & (spread < 1.35)), spread


def test_a_thinned_hinge_solve_keeps_the_axis(monkeypatch):
    p = rigid_pair(
        "hinge", seed=12, duration_s=60.0, still_s=1.5, gyro_noise=0.015, acc_noise=0.08, one_sided=True
    )
    solved_on: list[int] = []
    solve = hinge_axis._solve_axes

    def spy(wp, wc, *a, **k):
        solved_on.append(wp.shape[0])
        return solve(wp, wc, *a, **k)

    monkeypatch.setattr(hinge_axis, "_solve_axes", spy)
    full = calibrate_hinge_joint(*_args(p), rate_hz=p.rate_hz, joint="knee", options=ALL)
    n_full = solved_on[0]
    solved_on.clear()
    thin = calibrate_hinge_joint(*_args(p), rate_hz=p.rate_hz, joint="knee", options=HALF)
    assert solved_on and all(n <= 3000 < n_full for n in solved_on)
    for a, b in (
        (thin.axis_in_parent_sensor, full.axis_in_parent_sensor),
        (thin.axis_in_child_sensor, full.axis_in_child_sensor),
    ):
        assert np.degrees(np.arccos(min(1.0, float(a @ b)))) < 0.3
    assert np.degrees(np.arccos(min(1.0, float(thin.axis_in_parent_sensor @ p.axis_parent)))) < 1.0


def test_a_short_trial_is_fitted_on_every_sample(noisy_ball):
    p = noisy_ball
    full = calibrate_spherical_joint(*_args(p), rate_hz=p.rate_hz, options=ALL)
    default = calibrate_spherical_joint(*_args(p), rate_hz=p.rate_hz)  # 6000 ≤ 12000 samples
    assert np.array_equal(default.center_in_parent_sensor, full.center_in_parent_sensor)


def test_too_few_samples_are_refused():
    with pytest.raises(InputError, match="fit_max_samples"):
        CalibrationOptions(fit_max_samples=10)
