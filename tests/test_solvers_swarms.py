"""Behaviour shared by the swarms (DWPSO and GWO): bounds, seeds, x0, vectorised calls, NaN."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import SolverError, dwpso, gwo

SWARMS = {"dwpso": dwpso, "gwo": gwo}


class Recorder:
    """Vectorised cost that records every population it is given."""

    def __init__(self, cost):
        self.cost = cost
        self.calls: list[np.ndarray] = []

    def __call__(self, X):
        self.calls.append(X.copy())
        return self.cost(X)


@pytest.mark.parametrize("name", SWARMS)
@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 4))
def test_positions_stay_in_the_box(name, seed, n):
    rng = np.random.default_rng(seed)
    lower = rng.uniform(-2, 0, n)
    upper = lower + rng.uniform(0.1, 3, n)
    direction = rng.normal(size=n)
    cost = Recorder(lambda X: X @ direction)  # unbounded below: pushes against the walls
    res = SWARMS[name](cost, lower, upper, max_iter=30, seed=seed)
    every = np.vstack(cost.calls)
    assert np.all(every >= lower) and np.all(every <= upper)
    assert np.all(res.x >= lower) and np.all(res.x <= upper)
    # the optimum is the corner picked by the sign of the direction
    corner = np.where(direction > 0, lower, upper)
    assert res.cost <= corner @ direction + 0.05 * np.abs(direction).sum() * (upper - lower).max()


@pytest.mark.parametrize("name", SWARMS)
def test_same_seed_same_result_other_seed_other_path(name):
    def cost(X):
        return np.sum((X - 0.3) ** 2, axis=1) + np.sum(np.sin(5 * X) ** 2, axis=1)

    a = SWARMS[name](cost, -np.ones(3), np.ones(3), seed=7, max_iter=40)
    b = SWARMS[name](cost, -np.ones(3), np.ones(3), seed=7, max_iter=40)
    c = SWARMS[name](cost, -np.ones(3), np.ones(3), seed=8, max_iter=40)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.diagnostics["cost_history"], b.diagnostics["cost_history"])
    assert not np.array_equal(a.diagnostics["cost_history"], c.diagnostics["cost_history"])


@pytest.mark.parametrize("name", SWARMS)
def test_one_vectorised_call_per_iteration(name):
    cost = Recorder(lambda X: np.sum(X**2, axis=1))
    size = {"dwpso": "n_particles", "gwo": "n_wolves"}[name]
    res = SWARMS[name](cost, -np.ones(2), np.ones(2), max_iter=12, tol=0.0, **{size: 9})
    assert len(cost.calls) == res.iterations + 1 == 13
    assert all(X.shape == (9, 2) for X in cost.calls)
    assert res.diagnostics["n_evaluations"] == 9 * 13
    history = res.diagnostics["cost_history"]
    assert history.shape == (13,) and np.all(np.diff(history) <= 0)  # best never gets worse


@pytest.mark.parametrize("name", SWARMS)
def test_x0_seeds_one_member(name):
    x0 = np.array([0.123, -0.456])

    def cost(X):
        return np.sum((X - x0) ** 2, axis=1)

    res = SWARMS[name](cost, -np.ones(2), np.ones(2), max_iter=0, x0=x0)
    np.testing.assert_array_equal(res.x, x0)
    assert res.cost == 0.0 and res.iterations == 0
    with pytest.raises(ValueError, match="outside the bounds"):
        SWARMS[name](cost, -np.ones(2), np.ones(2), x0=[2.0, 0.0])


@pytest.mark.parametrize("name", SWARMS)
def test_nan_costs_are_infeasible_points(name):
    def cost(X):  # NaN on the left half of the box, minimum at (0.5, 0.5)
        f = np.sum((X - 0.5) ** 2, axis=1)
        return np.where(X[:, 0] < 0, np.nan, f)

    res = SWARMS[name](cost, -np.ones(2), np.ones(2), seed=1)
    np.testing.assert_allclose(res.x, 0.5, atol=1e-2)
    with pytest.raises(SolverError, match="NaN or inf at all"):
        SWARMS[name](lambda X: np.full(len(X), np.nan), -np.ones(2), np.ones(2), max_iter=3)


@pytest.mark.parametrize("name", SWARMS)
def test_bad_inputs(name):
    fn = SWARMS[name]
    with pytest.raises(ValueError, match=r"return one value per row"):
        fn(lambda X: np.sum(X, axis=1, keepdims=True), -np.ones(2), np.ones(2), max_iter=2)
    with pytest.raises(ValueError, match="finite search box"):
        fn(lambda X: X[:, 0], [-np.inf, 0], [1, 1])
    with pytest.raises(ValueError, match="lower > upper"):
        fn(lambda X: X[:, 0], [1, 0], [0, 1])
    with pytest.raises(ValueError, match="same shape"):
        fn(lambda X: X[:, 0], [0, 0], [1, 1, 1])


def test_stall_test_stops_early_and_counts_as_converged():
    res = dwpso(lambda X: np.zeros(len(X)), -np.ones(2), np.ones(2), max_iter=150)
    assert res.converged and res.iterations == 30  # default stall_iterations
    res = gwo(lambda X: np.zeros(len(X)), -np.ones(2), np.ones(2), max_iter=150)
    assert res.converged and res.iterations == 113 + 30 + 1  # counted in the last quarter
