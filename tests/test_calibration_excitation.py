import numpy as np
import pytest

from lowerlimb.calibration.excitation import ExcitationReport, jacobian_report
from lowerlimb.stillness import gyro_bias, initial_still_samples


def test_report_of_a_well_posed_fit():
    rng = np.random.default_rng(0)
    J = rng.normal(size=(500, 3))
    r = 0.1 * rng.normal(size=500)
    rep = jacobian_report(J, r, noise_floor=0.0)
    assert rep.condition_number < 2
    assert np.allclose(rep.std, 0.1 / np.sqrt(500), rtol=0.2)
    assert np.isclose(np.linalg.norm(rep.weakest_direction), 1.0)
    back = ExcitationReport.from_dict(rep.to_dict())
    assert np.allclose(back.std, rep.std)


def test_rank_deficiency_is_reported_with_its_direction():
    rng = np.random.default_rng(1)
    J = rng.normal(size=(200, 3))
    J[:, 2] = J[:, 0] + J[:, 1]  # direction (1, 1, -1) unobservable
    rep = jacobian_report(J, np.zeros(200), noise_floor=0.1)
    assert rep.condition_number > 1e10 or not np.isfinite(rep.condition_number)
    v = rep.weakest_direction
    assert abs(v @ np.array([1, 1, -1]) / np.sqrt(3)) > 0.999
    assert rep.weakest_std > 1e3
    d = rep.to_dict()
    assert d["weakest_std"] is None or d["weakest_std"] > 1e3


def test_noise_floor_keeps_noise_free_fits_honest():
    J = np.diag([10.0, 0.01]).repeat(50, axis=0)
    rep = jacobian_report(J, np.zeros(100), noise_floor=0.1)
    assert rep.std[1] > 100 * rep.std[0]


def test_param_map_transforms_the_covariance():
    rng = np.random.default_rng(2)
    J = rng.normal(size=(300, 2))
    M = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    rep = jacobian_report(J, 0.1 * rng.normal(size=300), noise_floor=0.0, param_map=M)
    assert rep.std.shape == (3,) and rep.weakest_direction.shape == (3,)
    C = np.linalg.inv(J.T @ J) * rep.noise_std**2
    assert np.allclose(rep.std, np.sqrt(np.diag(M @ C @ M.T)))


def test_still_start_detection_and_bias():
    rng = np.random.default_rng(3)
    n = 1000
    bias = np.array([0.01, -0.005, 0.008])
    gyr = bias + 0.015 * rng.normal(size=(n, 3))
    t = np.arange(n) / 100.0
    moving = t >= 2.0
    gyr[moving] += np.stack([np.sin(3 * t[moving])] * 3, axis=1) * 2
    acc = np.array([0, 0, 9.81]) + 0.08 * rng.normal(size=(n, 3))
    acc[moving] += rng.normal(size=(int(moving.sum()), 3))
    n_still = initial_still_samples([gyr], [acc], 100.0)
    assert 150 <= n_still <= 200
    assert np.linalg.norm(gyro_bias(gyr, n_still) - bias) < 0.005
    assert initial_still_samples([gyr[200:]], [acc[200:]], 100.0) == 0
    assert np.array_equal(gyro_bias(gyr, 0), np.zeros(3))


@pytest.mark.parametrize("field,value", [("center_bound_m", 0.0), ("max_iter", 0)])
def test_options_are_checked(field, value):
    from lowerlimb.calibration import CalibrationOptions
    from lowerlimb.errors import InputError

    with pytest.raises(InputError, match=field):
        CalibrationOptions(**{field: value})


def test_correlation_time_of_white_and_ar1_residuals():
    from lowerlimb.calibration.excitation import correlation_time

    rng = np.random.default_rng(0)
    assert correlation_time(rng.normal(size=20000)) == pytest.approx(1.0, abs=0.1)
    phi = 0.8
    e = rng.normal(size=40000)
    x = np.empty_like(e)
    x[0] = e[0]
    for i in range(1, e.size):
        x[i] = phi * x[i - 1] + e[i]
    assert correlation_time(x) == pytest.approx((1 + phi) / (1 - phi), rel=0.15)  # 9 samples


def test_correlated_residuals_widen_the_covariance():
    from lowerlimb.calibration.excitation import jacobian_report

    rng = np.random.default_rng(1)
    J = rng.normal(size=(5000, 2))
    white = rng.normal(size=5000)
    smooth = np.convolve(white, np.ones(9) / 3.0, mode="same")  # same variance, τ ≈ 9
    a = jacobian_report(J, white, noise_floor=0.0)
    b = jacobian_report(J, smooth * white.std() / smooth.std(), noise_floor=0.0)
    assert b.correlation_samples > 5 and a.correlation_samples < 1.5
    assert b.std[0] / a.std[0] == pytest.approx(
        np.sqrt(b.correlation_samples / a.correlation_samples), rel=0.05
    )
