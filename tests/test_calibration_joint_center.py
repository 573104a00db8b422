import warnings

import numpy as np
import pytest
from rigid_pair import rigid_pair

from lowerlimb.calibration import (
    CalibrationOptions,
    ExcitationWarning,
    calibrate_spherical_joint,
    estimate_joint_center,
)
from lowerlimb.errors import InputError, NonFiniteValueError, ShapeError, UnitError


@pytest.fixture(scope="module")
def clean():
    return rigid_pair("spherical", seed=5, duration_s=20.0, still_s=1.5)


@pytest.fixture(scope="module")
def noisy():
    return rigid_pair(
        "spherical",
        seed=6,
        duration_s=30.0,
        still_s=1.5,
        gyro_noise=0.015,
        acc_noise=0.08,
        gyro_bias=0.01,
    )


def _args(p):
    return (p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child)


def _err_mm(est, p):
    return 1000 * np.linalg.norm(est[0] - p.center_parent), 1000 * np.linalg.norm(est[1] - p.center_child)


@pytest.mark.parametrize("method", ["casadi", "gn"])
def test_recovers_centres_noise_free(clean, method):
    est = estimate_joint_center(*_args(clean), rate_hz=clean.rate_hz, method=method)
    assert max(_err_mm(est, clean)) < 1.0


def test_recovers_centres_with_realistic_noise_and_bias(noisy):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ExcitationWarning)  # well excited: no warning
        res = calibrate_spherical_joint(*_args(noisy), rate_hz=noisy.rate_hz)
    ep, ec = _err_mm((res.center_in_parent_sensor, res.center_in_child_sensor), noisy)
    assert ep < 5.0 and ec < 5.0
    assert res.warnings == []
    assert 0 < res.rms_residual < 1.0
    assert np.all(res.center_std_in_parent_sensor < 0.005)
    assert res.excitation is not None
    assert np.isfinite(res.excitation.condition_number)


@pytest.mark.parametrize("method", ["dwpso+casadi", "gwo+casadi"])
def test_swarm_refined_equals_casadi(clean, method):
    opts = CalibrationOptions(swarm_iter=40)
    ref = estimate_joint_center(*_args(clean), rate_hz=clean.rate_hz)
    est = estimate_joint_center(*_args(clean), rate_hz=clean.rate_hz, method=method, options=opts)
    assert np.allclose(np.r_[est], np.r_[ref], atol=1e-4)


def test_pure_swarm_gets_close(clean):
    est = estimate_joint_center(*_args(clean), rate_hz=clean.rate_hz, method="dwpso")
    assert max(_err_mm(est, clean)) < 15.0


def test_still_segments_warn_and_stay_finite():
    rng = np.random.default_rng(0)
    n = 1500
    g = np.array([0.3, -9.6, 1.8])
    acc = [g + 0.08 * rng.normal(size=(n, 3)) for _ in range(2)]
    gyr = [0.01 + 0.015 * rng.normal(size=(n, 3)) for _ in range(2)]
    with pytest.warns(ExcitationWarning) as rec:
        res = calibrate_spherical_joint(acc[0], gyr[0], acc[1], gyr[1], rate_hz=100.0)
    assert sum("hardly rotates" in str(r.message) for r in rec) == 2
    assert np.all(np.isfinite(res.center_in_parent_sensor))
    assert np.all(np.isfinite(res.center_in_child_sensor))
    assert len(res.warnings) == len(rec) >= 2


def test_pure_hinge_at_a_spherical_joint_names_the_axis():
    p = rigid_pair("hinge", seed=3, duration_s=30.0, gyro_noise=0.015, acc_noise=0.08)
    with pytest.warns(ExcitationWarning, match="poorly determined"):
        res = calibrate_spherical_joint(*_args(p), rate_hz=p.rate_hz, joint="hip")
    assert res.excitation is not None
    v = res.excitation.weakest_direction
    # the unobservable direction is "along the axis" in both frames
    assert abs(v[:3] @ p.axis_parent) / np.linalg.norm(v[:3]) > 0.99
    assert abs(v[3:] @ p.axis_child) / np.linalg.norm(v[3:]) > 0.99
    assert res.warnings[0].startswith("hip:")
    assert np.all(np.isfinite(res.center_in_parent_sensor))


def test_input_errors_name_the_fix(clean):
    a = _args(clean)
    with pytest.raises(ShapeError, match="transpose"):
        estimate_joint_center(a[0].T, a[1], a[2], a[3], rate_hz=100.0)
    with pytest.raises(ShapeError, match="equal length"):
        estimate_joint_center(a[0], a[1][:-5], a[2], a[3], rate_hz=100.0)
    bad = a[2].copy()
    bad[17, 1] = np.nan
    with pytest.raises(NonFiniteValueError, match="row 17"):
        estimate_joint_center(a[0], a[1], bad, a[3], rate_hz=100.0)
    with pytest.raises(InputError, match="positive"):
        estimate_joint_center(*a, rate_hz=0.0)
    with pytest.raises(InputError, match="casadi, gn, dwpso, gwo"):
        estimate_joint_center(*a, rate_hz=100.0, method="lm")
    with pytest.raises(UnitError, match="deg/s"):
        estimate_joint_center(a[0], np.degrees(a[1]) * 3, a[2], a[3], rate_hz=100.0)
    with pytest.raises(InputError, match="at least"):
        estimate_joint_center(*(x[:20] for x in a), rate_hz=100.0)
