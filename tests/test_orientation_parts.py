"""Building blocks: fuzzy gain, Madgwick gradient, initialisation, accuracy metrics."""

import numpy as np
import pytest

from lowerlimb.conventions import (
    GRAVITY_MPS2,
    quat_conjugate,
    quat_from_rotvec,
    quat_multiply,
    quat_normalize,
    quat_rotate,
)
from lowerlimb.errors import ShapeError
from lowerlimb.orientation import initialise, orientation_errors
from lowerlimb.orientation.fuzzy_fusion import fuzzy_gain, zmf
from lowerlimb.orientation.initialisation import attitude_from_gravity, detect_initial_rest
from lowerlimb.orientation.madgwick import objective_gradient

MAG_ENU = np.array([0.0, 20.0, -45.0])


def test_zmf_matches_matlab_shape():
    assert zmf(0.0, 1.0, 3.0) == 1.0
    assert zmf(2.0, 1.0, 3.0) == pytest.approx(0.5)
    assert zmf(1.5, 1.0, 3.0) == pytest.approx(1 - 2 * 0.25**2)
    assert zmf(2.5, 1.0, 3.0) == pytest.approx(2 * 0.25**2)
    assert zmf(3.0, 1.0, 3.0) == 0.0


def test_fuzzy_gain_is_monotone_between_its_bounds():
    e = np.linspace(0.0, 1.0, 2001)
    k = np.array([fuzzy_gain(x, 0.01, 0.1, 0.2, 2.0) for x in e])
    assert np.all(np.diff(k) >= -1e-12)
    assert k[0] == pytest.approx(0.1)  # fast motion: k_a / 2
    assert k[-1] == pytest.approx(2.0)  # still: k_max
    # mean of maximum jumps at the crossover e1 = 0.055 (K = 1.1 there)
    assert fuzzy_gain(0.0549, 0.01, 0.1, 0.2, 2.0) == pytest.approx(1.1 / 2, rel=1e-2)
    assert fuzzy_gain(0.0551, 0.01, 0.1, 0.2, 2.0) == pytest.approx((1.1 + 2.0) / 2, rel=1e-2)


def test_madgwick_gradient_matches_finite_differences():
    rng = np.random.default_rng(0)

    def f(q, d, s):
        w, x, y, z = q
        R = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        r = R.T @ d - s
        return 0.5 * r @ r

    for _ in range(20):
        q, d, s = rng.normal(size=4), rng.normal(size=3), rng.normal(size=3)
        g = np.array(objective_gradient(*q, *d, *s))
        fd = np.array([(f(q + h, d, s) - f(q - h, d, s)) / 2e-6 for h in 1e-6 * np.eye(4)])
        np.testing.assert_allclose(g, fd, atol=1e-6)


def test_attitude_from_gravity_and_magnetometer():
    rng = np.random.default_rng(1)
    for _ in range(50):
        q = quat_normalize(rng.normal(size=4))
        acc = quat_rotate(quat_conjugate(q), [0, 0, 9.81])
        mag = quat_rotate(quat_conjugate(q), MAG_ENU)
        q9 = attitude_from_gravity(acc, mag)
        assert min(np.abs(q9 - q).max(), np.abs(q9 + q).max()) < 1e-9
        q6 = attitude_from_gravity(acc)
        np.testing.assert_allclose(quat_rotate(q6, acc), [0, 0, 9.81], atol=1e-9)
        x_e = quat_rotate(q6, [1.0, 0, 0])
        assert x_e[1] == pytest.approx(0.0, abs=1e-9) and x_e[0] > 0  # heading 0: x east


def _still_then_move(rate=100.0, still_s=2.0, bias=(0.01, -0.02, 0.005), seed=0):
    rng = np.random.default_rng(seed)
    n_still, n_move = int(still_s * rate), int(3 * rate)
    t = np.arange(n_still + n_move) / rate
    gyr = np.zeros((len(t), 3))
    gyr[n_still:, 0] = 2.0 * np.sin(2 * np.pi * (t[n_still:] - still_s))
    gyr += np.asarray(bias) + 0.01 * rng.normal(size=gyr.shape)
    acc = np.tile([0.0, 0.0, GRAVITY_MPS2], (len(t), 1)) + 0.05 * rng.normal(size=gyr.shape)
    acc[n_still:, 1] += 3.0 * np.sin(4 * np.pi * t[n_still:])
    return gyr, acc, n_still


def test_rest_detection_and_bias():
    gyr, acc, n_still = _still_then_move()
    rest = detect_initial_rest(gyr, acc, 100.0)
    assert n_still - 30 <= rest <= n_still + 5
    init = initialise(gyr, acc, None, 100.0)
    assert init.bias_estimated
    np.testing.assert_allclose(init.gyr_bias_rad_s, [0.01, -0.02, 0.005], atol=0.003)


def test_moving_start_estimates_no_bias():
    gyr, acc, n_still = _still_then_move()
    init = initialise(gyr[n_still:], acc[n_still:], None, 100.0)
    assert init.rest_samples == 0
    assert not init.bias_estimated
    np.testing.assert_array_equal(init.gyr_bias_rad_s, 0.0)
    assert np.all(np.isfinite(init.quat_wxyz))


def test_orientation_errors_decomposition():
    rng = np.random.default_rng(2)
    q_ref = quat_normalize(rng.normal(size=(500, 4)))
    heading = quat_from_rotvec([0.0, 0.0, np.radians(5.0)])
    e = orientation_errors(quat_multiply(heading, q_ref), q_ref)
    assert e.total_deg == pytest.approx(5.0)
    assert e.heading_deg == pytest.approx(5.0)
    assert e.inclination_deg == pytest.approx(0.0, abs=1e-5)
    assert e.yaw_deg == pytest.approx(5.0)
    e6 = orientation_errors(quat_multiply(heading, q_ref), q_ref, remove_heading_offset=True)
    assert e6.total_deg == pytest.approx(0.0, abs=1e-3)
    assert e6.heading_offset_deg == pytest.approx(5.0, abs=1e-3)
    tilt = quat_from_rotvec([np.radians(3.0), 0.0, 0.0])  # about east: pitch
    e = orientation_errors(quat_multiply(tilt, q_ref), q_ref)
    assert e.inclination_deg == pytest.approx(3.0)
    assert e.pitch_deg == pytest.approx(3.0)
    assert e.roll_deg == pytest.approx(0.0, abs=1e-5)
    q_nan = q_ref.copy()
    q_nan[:10] = np.nan
    assert orientation_errors(q_ref, q_nan).samples == 490
    with pytest.raises(ShapeError, match="no sample"):
        orientation_errors(q_ref, q_ref, np.zeros(500, bool))
