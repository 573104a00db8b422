"""Gauss–Newton (Hu et al. 2021, eq. 7–15): known answers, rank deficiency, bounds, errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import SolverError, SolverResult, gauss_newton
from solvers.problems import rosenbrock, shared_point_acceleration, sphere_fit

STEPS = ["line_search", "pinv", "levenberg_marquardt"]


def standard_errors(J: np.ndarray, sigma: float) -> np.ndarray:
    """1-σ uncertainty of a least-squares estimate with residual noise sigma."""
    return sigma * np.sqrt(np.diag(np.linalg.inv(J.T @ J)))


@pytest.mark.parametrize("step", STEPS)
def test_sphere_fit_recovers_centre_and_radius(step):
    prob = sphere_fit(n_points=200, noise=1e-3, seed=0)
    res = gauss_newton(prob.residual, prob.jacobian, prob.x0, step=step)
    assert isinstance(res, SolverResult)
    assert res.converged and res.method == f"gauss_newton/{step}"
    sigma = standard_errors(prob.jacobian(res.x), 1e-3)  # about 0.1 mm here
    assert np.all(np.abs(res.x - prob.x_true) < 5 * sigma)
    assert res.cost == pytest.approx(0.5 * np.sum(prob.residual(res.x) ** 2))
    assert res.diagnostics["rank"] == 4 and res.diagnostics["condition_number"] < 10
    assert res.diagnostics["rms_residual"] == pytest.approx(1e-3, rel=0.3)


@pytest.mark.parametrize("step", STEPS)
def test_shared_point_recovers_both_offsets(step):
    prob = shared_point_acceleration(n_samples=1000, noise=0.05, seed=1)
    res = gauss_newton(prob.residual, prob.jacobian, prob.x0, step=step)
    assert res.converged
    sigma = standard_errors(prob.jacobian(res.x), res.diagnostics["rms_residual"])
    assert np.all(np.abs(res.x - prob.x_true) < 5 * sigma)
    assert np.abs(res.x - prob.x_true).max() < 2e-3  # metres


@pytest.mark.parametrize("step", STEPS)
def test_rosenbrock_reaches_the_minimum_exactly(step):
    prob = rosenbrock(2)
    res = gauss_newton(prob.residual, prob.jacobian, prob.x0, step=step)
    assert res.converged
    np.testing.assert_allclose(res.x, 1.0, atol=1e-9)
    assert res.cost < 1e-20


def decay_problem():
    """y = A exp(-(k1 + k2) t): only k1 + k2 is identifiable."""
    t = np.linspace(0.0, 2.0, 40)
    y = 2.0 * np.exp(-1.5 * t)

    def residual(x):
        return x[0] * np.exp(-(x[1] + x[2]) * t) - y

    def jacobian(x):
        e = np.exp(-(x[1] + x[2]) * t)
        d = -x[0] * t * e
        return np.column_stack([e, d, d])

    return residual, jacobian


@pytest.mark.parametrize("step", STEPS)
def test_rank_deficiency_is_reported_not_nan(step):
    residual, jacobian = decay_problem()
    x0 = np.array([1.0, 0.2, 0.4])
    res = gauss_newton(residual, jacobian, x0, step=step)
    d = res.diagnostics
    assert np.all(np.isfinite(res.x))
    assert d["rank"] == 2
    assert d["condition_number"] > 1e12
    assert d["singular_values"].shape == (3,) and d["singular_values"][-1] < 1e-10
    null = d["unidentifiable_directions"]
    assert null.shape == (1, 3)
    np.testing.assert_allclose(np.abs(null[0]), [0.0, np.sqrt(0.5), np.sqrt(0.5)], atol=1e-8)
    assert "rank 2 < 3" in d["message"]
    assert res.x[0] == pytest.approx(2.0, abs=1e-8)
    assert res.x[1] + res.x[2] == pytest.approx(1.5, abs=1e-8)
    if step != "levenberg_marquardt":  # the pseudo-inverse never moves along the null space
        assert res.x[1] - res.x[2] == pytest.approx(x0[1] - x0[2], abs=1e-8)


@pytest.mark.parametrize("step", STEPS)
def test_solution_on_an_active_bound(step):
    prob = sphere_fit(n_points=100, noise=0.0, seed=2)
    upper = np.array([1.0, 1.0, 1.0, 0.45])  # the true radius is 0.5
    x0 = np.array([0.0, 0.0, 0.0, 0.3])
    res = gauss_newton(prob.residual, prob.jacobian, x0, step=step, upper=upper)
    assert res.converged
    assert res.x[3] == 0.45 and res.diagnostics["active_bounds"].tolist() == [0, 0, 0, 1]
    # the centre is the fit with the radius fixed at the bound; this large-residual problem
    # converges linearly, so the relative cost test stops both within about 1e-7 m
    fixed = gauss_newton(
        lambda c: prob.residual(np.append(c, 0.45)),
        lambda c: prob.jacobian(np.append(c, 0.45))[:, :3],
        x0[:3],
    )
    np.testing.assert_allclose(res.x[:3], fixed.x, atol=1e-6)


def test_line_search_avoids_a_step_into_nan_where_pinv_fails():
    def residual(x):
        with np.errstate(invalid="ignore"):
            return np.sqrt(x) - 1.0  # NaN for x < 0

    def jacobian(x):
        return (0.5 / np.sqrt(x))[:, None]

    x0 = np.array([9.0])  # the full step lands on x = -3
    res = gauss_newton(residual, jacobian, x0, step="line_search")
    assert res.converged and res.x[0] == pytest.approx(1.0, abs=1e-10)
    with pytest.raises(SolverError, match="NaN/inf after the pseudo-inverse step") as info:
        gauss_newton(residual, jacobian, x0, step="pinv")
    assert info.value.method == "gauss_newton/pinv" and info.value.x is not None


def test_nan_residual_at_start_raises_solver_error():
    with pytest.raises(SolverError, match=r"residual is NaN/inf at the initial point \(1 of 2"):
        gauss_newton(lambda x: np.array([x[0], np.nan]), lambda x: np.ones((2, 1)), np.array([1.0]))


def test_nan_jacobian_raises_solver_error():
    with pytest.raises(SolverError, match="Jacobian contains NaN/inf"):
        gauss_newton(lambda x: x - 1.0, lambda x: np.full((1, 1), np.nan), np.array([3.0]))


def test_bad_inputs_raise_value_error():
    prob = rosenbrock(2)
    with pytest.raises(ValueError, match="outside the bounds.*np.clip"):
        gauss_newton(prob.residual, prob.jacobian, prob.x0, lower=0.0)
    with pytest.raises(ValueError, match="unknown step"):
        gauss_newton(prob.residual, prob.jacobian, prob.x0, step="newton")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"shape \(M,\)"):
        gauss_newton(lambda x: prob.residual(x)[:, None], prob.jacobian, prob.x0)
    with pytest.raises(ValueError, match=r"Jacobian must have shape"):
        gauss_newton(prob.residual, lambda x: prob.jacobian(x)[:, :1], prob.x0)
    with pytest.raises(ValueError, match="lower > upper"):
        gauss_newton(prob.residual, prob.jacobian, prob.x0, lower=1.0, upper=-1.0)
    with pytest.raises(ValueError, match="NaN or inf"):
        gauss_newton(prob.residual, prob.jacobian, [np.nan, 1.0])


def test_iteration_limit_is_not_convergence():
    prob = rosenbrock(2)
    res = gauss_newton(prob.residual, prob.jacobian, prob.x0, max_iter=1, step="levenberg_marquardt")
    assert not res.converged and res.iterations == 1
    assert "maximum number of iterations" in res.diagnostics["message"]
    assert res.diagnostics["cost_history"].shape == (2,)
    assert res.wall_time_s > 0


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    m=st.integers(3, 30),
    n=st.integers(1, 3),
    step=st.sampled_from(STEPS),
)
def test_linear_least_squares_matches_lstsq(seed, m, n, step):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(m, n)) + np.eye(m, n) * 3.0  # well conditioned
    b = rng.normal(size=m)
    res = gauss_newton(lambda x: A @ x - b, lambda x: A, np.zeros(n), step=step)
    expected = np.linalg.lstsq(A, b, rcond=None)[0]
    np.testing.assert_allclose(res.x, expected, atol=1e-8 * (1 + np.abs(expected).max()))
    if step != "levenberg_marquardt":
        assert res.iterations <= 2  # one Gauss–Newton step solves a linear problem


def numerically_singular_start():
    """r = (x0, 1 + 1e-17 x1 + x1³), minimum r = 0 at (0, -1), started at (0, 0).

    At the start J = diag(1, 1e-17): the second singular value is below the pseudo-inverse
    cut-off, so the Gauss–Newton direction is zero although the cost is 0.5 and the
    gradient (0, 1e-17) is not. Only the steepest-descent fallback can move (downhill is
    x1 < 0; uphill, x1 > 0, only increases the cost).
    """

    def residual(x):
        return np.array([x[0], 1.0 + 1e-17 * x[1] + x[1] ** 3])

    def jacobian(x):
        return np.array([[1.0, 0.0], [0.0, 1e-17 + 3.0 * x[1] ** 2]])

    return residual, jacobian


def test_steepest_descent_fallback_moves_where_the_gauss_newton_step_is_zero():
    residual, jacobian = numerically_singular_start()
    res = gauss_newton(residual, jacobian, np.zeros(2), step="line_search")
    assert res.converged
    np.testing.assert_allclose(res.x, [0.0, -1.0], atol=1e-9)
    assert res.cost < 1e-20
    history = res.diagnostics["cost_history"]
    assert history[0] == 0.5 and np.all(np.diff(history) <= 0)  # every accepted step went downhill
    # the pure pseudo-inverse step cannot leave the start: the problem needs the fallback
    stuck = gauss_newton(residual, jacobian, np.zeros(2), step="pinv", max_iter=5)
    assert stuck.cost == 0.5 and np.all(stuck.x == 0.0)
