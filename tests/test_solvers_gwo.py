"""GWO (Hu et al. 2021, eq. 25–29; Mirjalili et al. 2014): known answers, leaders, parameters."""

from __future__ import annotations

import numpy as np
import pytest

from solvers import GWOParams, gwo
from solvers.problems import rosenbrock, sphere_fit


def test_shifted_sphere_function():
    centre = np.array([0.3, -0.7, 0.1, 0.45])
    res = gwo(lambda X: np.sum((X - centre) ** 2, axis=1), -np.ones(4), np.ones(4), seed=0)
    np.testing.assert_allclose(res.x, centre, atol=5e-3)
    assert res.method == "gwo"


def test_rosenbrock_valley():
    prob = rosenbrock(2)
    res = gwo(prob.cost_batch, prob.lower, prob.upper, seed=0, max_iter=300)
    np.testing.assert_allclose(res.x, prob.x_true, atol=0.1)


def test_noisy_sphere_fit():
    prob = sphere_fit(n_points=100, noise=1e-3, seed=4)
    res = gwo(prob.cost_batch, prob.lower, prob.upper, seed=0)
    np.testing.assert_allclose(res.x, prob.x_true, atol=2e-3)  # metres: GWO polishes slowly


def test_leaders_are_the_three_best_in_order():
    res = gwo(lambda X: np.sum(X**2, axis=1), -np.ones(3), np.ones(3), max_iter=25, tol=0)
    leaders, costs = res.diagnostics["leaders"], res.diagnostics["leader_costs"]
    assert leaders.shape == (3, 3) and np.all(np.diff(costs) >= 0)
    np.testing.assert_allclose(costs, np.sum(leaders**2, axis=1))
    np.testing.assert_array_equal(res.x, leaders[0])
    assert res.cost == costs[0]


def test_params_are_validated_and_used():
    with pytest.raises(ValueError):
        GWOParams(a_start=-1.0)
    with pytest.raises(ValueError):
        GWOParams(stall_iterations=0)
    with pytest.raises(ValueError, match="n_wolves >= 3"):
        gwo(lambda X: X[:, 0], [0.0], [1.0], n_wolves=2)

    def cost(X):
        return np.sum((X - 0.2) ** 2, axis=1)

    # a = 2 throughout: the pack never switches from exploring to attacking
    frozen = gwo(cost, -np.ones(2), np.ones(2), max_iter=30, tol=0, params=GWOParams(2.0, 2.0))
    default = gwo(cost, -np.ones(2), np.ones(2), max_iter=30, tol=0)
    assert not np.array_equal(frozen.diagnostics["cost_history"], default.diagnostics["cost_history"])
