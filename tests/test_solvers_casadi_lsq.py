"""CasADi least squares: Gauss–Newton and IPOPT agree, both residual forms, errors wrapped."""

from __future__ import annotations

import shutil

import casadi
import numpy as np
import pytest

from solvers import SolverError, casadi_lsq, gauss_newton
from solvers.casadi_lsq import _BufferedEvaluator, _build_rj, _layout
from solvers.problems import rosenbrock, shared_point_acceleration, sphere_fit

SOLVERS = ["gauss_newton", "ipopt"]
PROBLEMS = {
    "sphere_fit": lambda: sphere_fit(n_points=200, noise=1e-3, seed=0),
    "shared_point": lambda: shared_point_acceleration(n_samples=1000, noise=0.05, seed=1),
}


@pytest.mark.parametrize("name", PROBLEMS)
def test_gauss_newton_and_ipopt_agree_and_recover_the_truth(name):
    prob = PROBLEMS[name]()
    ref = gauss_newton(prob.residual, prob.jacobian, prob.x0)
    results = {}
    for solver in SOLVERS:
        res = casadi_lsq(
            prob.casadi_residual,
            prob.x0,
            params=prob.data,
            solver=solver,
            lower=prob.lower,
            upper=prob.upper,
        )
        assert res.converged, res.diagnostics["message"]
        assert res.method == f"casadi_lsq/{solver}"
        assert res.diagnostics["n_residuals"] == prob.data.shape[1]
        assert res.diagnostics["singular_values"].shape == (prob.x_true.size,)
        assert res.diagnostics["rank"] == prob.x_true.size
        assert res.cost == pytest.approx(0.5 * np.sum(prob.residual(res.x) ** 2), rel=1e-12)
        results[solver] = res
    np.testing.assert_allclose(results["gauss_newton"].x, ref.x, atol=1e-9)
    np.testing.assert_allclose(results["ipopt"].x, results["gauss_newton"].x, atol=1e-8)
    # within 5 standard errors of the truth (sub-millimetre for both problems)
    J = prob.jacobian(ref.x)
    sigma = ref.diagnostics["rms_residual"] * np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
    assert np.all(np.abs(results["gauss_newton"].x - prob.x_true) < 5 * sigma)


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("n", [2, 5])
def test_residual_of_x_only(solver, n):
    prob = rosenbrock(n)
    x0 = np.full(n, 0.5)  # in the basin of the global minimum
    res = casadi_lsq(prob.casadi_residual, x0, solver=solver, lower=prob.lower, upper=prob.upper)
    assert res.converged
    np.testing.assert_allclose(res.x, 1.0, atol=1e-7)


def test_user_mapped_residual_gives_the_same_answer():
    prob = sphere_fit(n_points=150, noise=1e-3, seed=5)
    mapped = prob.casadi_residual.map(prob.data.shape[1])  # whole form: p is (3, N)
    a = casadi_lsq(prob.casadi_residual, prob.x0, params=prob.data)
    for solver in SOLVERS:
        b = casadi_lsq(mapped, prob.x0, params=prob.data, solver=solver)
        np.testing.assert_allclose(b.x, a.x, atol=1e-9)
        assert b.diagnostics["n_residuals"] == 150


def two_residuals_per_sample():
    """Per-sample residual with m = 2 rows, and its numpy twin stacked sample by sample."""
    prob = sphere_fit(n_points=60, noise=1e-3, seed=6)
    x = casadi.SX.sym("x", 4)
    p = casadi.SX.sym("p", 3)
    d = casadi.norm_2(p - x[:3])
    fun = casadi.Function("two", [x, p], [casadi.vertcat(d - x[3], 0.5 * (d**2 - x[3] ** 2))])
    a = prob.data.T

    def residual(xv):
        dv = np.linalg.norm(a - xv[:3], axis=1)
        return np.column_stack([dv - xv[3], 0.5 * (dv**2 - xv[3] ** 2)]).ravel()

    return prob, fun, residual


def test_vector_residual_per_sample_jacobian_layout():
    prob, fun, residual = two_residuals_per_sample()
    layout = _layout(fun, 4, prob.data)
    assert layout.per_sample and layout.m == 2 and layout.M == 120
    evaluator = _BufferedEvaluator(
        _build_rj(fun, layout, False), layout, layout.flat_params(prob.data), "test"
    )
    r, J = evaluator(prob.x0)
    np.testing.assert_allclose(r, residual(prob.x0), rtol=1e-13)
    h = 1e-6
    J_fd = np.column_stack(
        [(residual(prob.x0 + h * e) - residual(prob.x0 - h * e)) / (2 * h) for e in np.eye(4)]
    )
    np.testing.assert_allclose(J, J_fd, rtol=1e-6, atol=1e-8)
    res = casadi_lsq(fun, prob.x0, params=prob.data)

    def jac_fd(xv):
        return np.column_stack([(residual(xv + h * e) - residual(xv - h * e)) / (2 * h) for e in np.eye(4)])

    ref = gauss_newton(residual, jac_fd, prob.x0)
    np.testing.assert_allclose(res.x, ref.x, atol=1e-7)


@pytest.mark.parametrize("step", ["line_search", "pinv", "levenberg_marquardt"])
def test_every_step_rule_matches_numpy_gauss_newton(step):
    prob = sphere_fit(n_points=80, noise=1e-3, seed=9)
    res = casadi_lsq(prob.casadi_residual, prob.x0, params=prob.data, step=step, tol=1e-10)
    ref = gauss_newton(prob.residual, prob.jacobian, prob.x0, step=step, tol=1e-10)
    np.testing.assert_allclose(res.x, ref.x, atol=1e-10)
    # same path; the last step may differ when a stopping test sits at rounding level
    assert abs(res.iterations - ref.iterations) <= 1
    k = min(res.iterations, ref.iterations)
    np.testing.assert_allclose(
        res.diagnostics["cost_history"][:k], ref.diagnostics["cost_history"][:k], rtol=1e-9
    )


def test_evaluations_do_not_alias_earlier_results():
    prob = sphere_fit(n_points=30, seed=0)
    layout = _layout(prob.casadi_residual, 4, prob.data)
    fun = _build_rj(prob.casadi_residual, layout, False)
    evaluator = _BufferedEvaluator(fun, layout, layout.flat_params(prob.data), "test")
    r1, J1 = evaluator(prob.x0)
    kept = (r1.copy(), J1.copy())
    evaluator(prob.x_true)
    np.testing.assert_array_equal(r1, kept[0])
    np.testing.assert_array_equal(J1, kept[1])


@pytest.mark.parametrize("solver", SOLVERS)
def test_active_bound(solver):
    prob = sphere_fit(n_points=100, noise=0.0, seed=2)
    upper = np.array([1.0, 1.0, 1.0, 0.45])  # the true radius is 0.5
    x0 = np.array([0.0, 0.0, 0.0, 0.3])
    res = casadi_lsq(prob.casadi_residual, x0, params=prob.data, solver=solver, upper=upper)
    ref = gauss_newton(prob.residual, prob.jacobian, x0, upper=upper)
    assert res.x[3] == pytest.approx(0.45, abs=1e-8)
    np.testing.assert_allclose(res.x, ref.x, atol=1e-6)


def test_new_data_with_the_same_function_is_not_mixed_up():
    prob = sphere_fit(n_points=100, noise=0.0, seed=7)
    shifted = prob.data + np.array([[0.05], [0.0], [-0.02]])
    for solver in SOLVERS:
        a = casadi_lsq(prob.casadi_residual, prob.x0, params=prob.data, solver=solver)
        b = casadi_lsq(prob.casadi_residual, prob.x0, params=shifted, solver=solver)
        np.testing.assert_allclose(a.x, prob.x_true, atol=1e-8)
        np.testing.assert_allclose(b.x, prob.x_true + [0.05, 0.0, -0.02, 0.0], atol=1e-8)


def decay_residual():
    """Per sample: A exp(-(k1 + k2) t) - y; only k1 + k2 is identifiable."""
    x = casadi.SX.sym("x", 3)
    p = casadi.SX.sym("p", 2)  # (t, y)
    fun = casadi.Function("decay", [x, p], [x[0] * casadi.exp(-(x[1] + x[2]) * p[0]) - p[1]])
    t = np.linspace(0.0, 2.0, 40)
    return fun, np.vstack([t, 2.0 * np.exp(-1.5 * t)])


@pytest.mark.parametrize("solver", SOLVERS)
def test_rank_deficiency_is_reported(solver):
    fun, data = decay_residual()
    res = casadi_lsq(fun, [1.0, 0.2, 0.4], params=data, solver=solver)
    assert np.all(np.isfinite(res.x))
    assert res.diagnostics["rank"] == 2 and res.diagnostics["condition_number"] > 1e12
    assert res.x[1] + res.x[2] == pytest.approx(1.5, abs=1e-6)


@pytest.mark.parametrize("solver", SOLVERS)
def test_nan_in_the_data_raises_solver_error(solver):
    prob = sphere_fit(n_points=50, seed=0)
    data = prob.data.copy()
    data[1, 7] = np.nan
    with pytest.raises(SolverError, match=r"NaN/inf at the initial point \(1 of 50.*data"):
        casadi_lsq(prob.casadi_residual, prob.x0, params=data, solver=solver)


@pytest.mark.parametrize("solver", SOLVERS)
def test_infinite_jacobian_raises_solver_error(solver):
    x = casadi.MX.sym("x", 2)
    fun = casadi.Function("f", [x], [casadi.vertcat(casadi.sqrt(x[0]) - 1, x[1] - 2)])
    with pytest.raises(SolverError, match="Jacobian contains NaN/inf"):
        casadi_lsq(fun, [0.0, 0.0], solver=solver)


class Exploding(casadi.Callback):
    """A CasADi function whose evaluation fails."""

    def __init__(self):
        casadi.Callback.__init__(self)
        self.construct("exploding", {"enable_fd": True})

    def get_n_in(self):
        return 1

    def get_n_out(self):
        return 1

    def get_sparsity_in(self, i):
        return casadi.Sparsity.dense(2, 1)

    def get_sparsity_out(self, i):
        return casadi.Sparsity.dense(3, 1)

    def eval(self, args):
        raise RuntimeError("model exploded")


@pytest.mark.parametrize("solver", SOLVERS)
def test_casadi_failure_is_wrapped_and_chained(solver):
    fun = Exploding()
    with pytest.raises(SolverError, match="CasADi evaluation failed") as info:
        casadi_lsq(fun, [0.1, 0.2], solver=solver)
    assert isinstance(info.value.__cause__, RuntimeError)
    assert info.value.method == f"casadi_lsq/{solver}"


def test_bad_arguments_raise_value_error():
    prob = sphere_fit(n_points=20)
    r = prob.casadi_residual
    with pytest.raises(ValueError, match=r"params has shape \(20, 3\).*one sample per column"):
        casadi_lsq(r, prob.x0, params=prob.data.T)
    with pytest.raises(ValueError, match="pass params"):
        casadi_lsq(r, prob.x0)
    with pytest.raises(ValueError, match="drop params"):
        casadi_lsq(rosenbrock(2).casadi_residual, [0.0, 0.0], params=prob.data)
    with pytest.raises(ValueError, match="dense vector of the 3 unknowns"):
        casadi_lsq(r, prob.x0[:3], params=prob.data)
    with pytest.raises(ValueError, match="casadi.Function"):
        casadi_lsq(prob.residual, prob.x0, params=prob.data)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="unknown solver"):
        casadi_lsq(r, prob.x0, params=prob.data, solver="sqp")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="outside the bounds"):
        casadi_lsq(r, prob.x0, params=prob.data, upper=0.0)


def test_ipopt_iteration_limit_is_not_an_error():
    prob = sphere_fit(n_points=50)
    res = casadi_lsq(prob.casadi_residual, prob.x0, params=prob.data, solver="ipopt", max_iter=1)
    assert not res.converged and res.iterations == 1
    assert res.diagnostics["return_status"] == "Maximum_Iterations_Exceeded"


@pytest.mark.skipif(shutil.which("gcc") is None, reason="JIT needs a C compiler")
def test_jit_gives_the_same_answer():
    prob = sphere_fit(n_points=64, noise=1e-3, seed=8)
    a = casadi_lsq(prob.casadi_residual, prob.x0, params=prob.data)
    b = casadi_lsq(prob.casadi_residual, prob.x0, params=prob.data, jit=True)
    np.testing.assert_allclose(b.x, a.x, atol=1e-12)
