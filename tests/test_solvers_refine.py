"""Swarm-initialised refinement: the swarm finds the basin, the local solver polishes."""

from __future__ import annotations

import casadi
import numpy as np
import pytest

from solvers import DWPSOParams, GWOParams, SolverResult, casadi_lsq, gauss_newton, swarm_then_refine
from solvers.problems import shared_point_acceleration


def frequency_problem():
    """y = 1.3 sin(3.3 t): least squares in the frequency has many local minima."""
    t = np.linspace(0.0, 10.0, 200)
    y = 1.3 * np.sin(3.3 * t)
    x = casadi.SX.sym("x", 2)
    p = casadi.SX.sym("p", 2)  # (t, y)
    fun = casadi.Function("sine", [x, p], [x[0] * casadi.sin(x[1] * p[0]) - p[1]])

    def cost_batch(X):
        r = X[:, :1] * np.sin(X[:, 1:] * t) - y
        return 0.5 * np.sum(r * r, axis=1)

    return fun, np.vstack([t, y]), cost_batch, np.array([1.3, 3.3])


@pytest.mark.parametrize("swarm", ["dwpso", "gwo"])
def test_swarm_escapes_the_local_minimum_that_traps_gauss_newton(swarm):
    fun, data, cost_batch, x_true = frequency_problem()
    lower, upper = np.array([0.0, 0.5]), np.array([3.0, 6.0])

    def refine(x):
        return casadi_lsq(fun, x, params=data, lower=lower, upper=upper)

    local = refine(np.array([1.0, 1.0]))
    assert np.abs(local.x - x_true).max() > 0.1  # trapped
    res = swarm_then_refine(cost_batch, lower, upper, refine, swarm=swarm, seed=0)
    np.testing.assert_allclose(res.x, x_true, atol=1e-9)
    assert res.converged and res.method == f"{swarm}+casadi_lsq/gauss_newton"
    stage = res.diagnostics["swarm"]
    assert stage["method"] == swarm and stage["iterations"] > 0
    assert stage["cost"] >= res.cost and stage["wall_time_s"] > 0
    assert res.wall_time_s >= stage["wall_time_s"] + res.diagnostics["refine_wall_time_s"]
    assert "singular_values" in res.diagnostics  # the refiner's own diagnostics are kept


def test_joint_centre_like_problem_end_to_end():
    prob = shared_point_acceleration(n_samples=800, noise=0.05, seed=2)

    def refine(x):
        return gauss_newton(prob.residual, prob.jacobian, x, lower=prob.lower, upper=prob.upper)

    res = swarm_then_refine(prob.cost_batch, prob.lower, prob.upper, refine, max_iter=60)
    assert np.abs(res.x - prob.x_true).max() < 3e-3  # metres
    assert res.method == "dwpso+gauss_newton/line_search"


def test_options_are_passed_to_the_swarm():
    _, _, cost_batch, _ = frequency_problem()
    lower, upper = np.array([0.0, 0.5]), np.array([3.0, 6.0])

    def refine(x):
        return SolverResult(x, 0.0, 0, 0.0, True, "identity", {})

    res = swarm_then_refine(
        cost_batch,
        lower,
        upper,
        refine,
        swarm="gwo",
        population=5,
        max_iter=4,
        params=GWOParams(),
        seed=3,
    )
    assert res.diagnostics["swarm"]["iterations"] == 4
    x0 = np.array([1.3, 3.3])
    res = swarm_then_refine(cost_batch, lower, upper, refine, max_iter=0, x0=x0)
    np.testing.assert_array_equal(res.x, x0)


def test_bad_arguments():
    _, _, cost_batch, _ = frequency_problem()
    lower, upper = np.array([0.0, 0.5]), np.array([3.0, 6.0])
    ok = lambda x: SolverResult(x, 0.0, 0, 0.0, True, "identity", {})  # noqa: E731
    with pytest.raises(ValueError, match="unknown swarm"):
        swarm_then_refine(cost_batch, lower, upper, ok, swarm="pso")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="takes DWPSOParams"):
        swarm_then_refine(cost_batch, lower, upper, ok, params=GWOParams(), max_iter=1)
    with pytest.raises(ValueError, match="takes GWOParams"):
        swarm_then_refine(cost_batch, lower, upper, ok, swarm="gwo", params=DWPSOParams())
    with pytest.raises(TypeError, match="must return a SolverResult"):
        swarm_then_refine(cost_batch, lower, upper, lambda x: x, max_iter=1)  # type: ignore
