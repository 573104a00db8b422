"""DWPSO (Hu et al. 2021, eq. 17–24): known answers, the inertia-weight schedule, parameters."""

from __future__ import annotations

import numpy as np
import pytest

from solvers import DWPSOParams, dwpso, gauss_newton
from solvers.dwpso import inertia_weight
from solvers.problems import rosenbrock, sphere_fit


def test_shifted_sphere_function():
    centre = np.array([0.3, -0.7, 0.1, 0.45])
    res = dwpso(lambda X: np.sum((X - centre) ** 2, axis=1), -np.ones(4), np.ones(4), seed=0)
    np.testing.assert_allclose(res.x, centre, atol=1e-4)
    assert res.method == "dwpso"


def test_rosenbrock_valley():
    prob = rosenbrock(2)
    res = dwpso(prob.cost_batch, prob.lower, prob.upper, seed=0, max_iter=200)
    np.testing.assert_allclose(res.x, prob.x_true, atol=1e-2)
    assert res.cost < 1e-5


def test_noisy_sphere_fit_matches_least_squares():
    prob = sphere_fit(n_points=100, noise=1e-3, seed=4)
    res = dwpso(prob.cost_batch, prob.lower, prob.upper, seed=0)
    ls = gauss_newton(prob.residual, prob.jacobian, prob.x0)
    np.testing.assert_allclose(res.x, prob.x_true, atol=1e-3)  # metres
    np.testing.assert_allclose(res.x, ls.x, atol=1e-4)
    assert res.cost <= ls.cost * (1 + 1e-3)


def test_inertia_weight_decays_exponentially_from_max_to_min():
    p = DWPSOParams()
    w = np.array([inertia_weight(k, 150, p) for k in range(150)])
    assert w[0] == pytest.approx(0.8) and w[-1] == pytest.approx(0.2)
    assert np.all(np.diff(w) < 0)
    np.testing.assert_allclose(np.diff(np.log(w)), np.log(0.25) / 149)  # constant ratio
    res = dwpso(lambda X: np.sum(X**2, axis=1), -np.ones(2), np.ones(2), max_iter=20, tol=0)
    expected = [inertia_weight(k, 20, p) for k in range(20)]
    np.testing.assert_allclose(res.diagnostics["inertia_weights"], expected)


@pytest.mark.parametrize(
    "kwargs",
    [{"mu_min": 0.9}, {"mu_min": 0.0}, {"jump": -0.1}, {"max_velocity": 0.0}, {"stall_iterations": 0}],
)
def test_params_are_validated(kwargs):
    with pytest.raises(ValueError):
        DWPSOParams(**kwargs)


def test_params_change_the_search():
    def cost(X):
        return np.sum(X**2, axis=1)

    a = dwpso(cost, -np.ones(2), np.ones(2), max_iter=10, tol=0)
    b = dwpso(cost, -np.ones(2), np.ones(2), max_iter=10, tol=0, params=DWPSOParams(jump=0.0))
    assert not np.array_equal(a.diagnostics["cost_history"], b.diagnostics["cost_history"])
