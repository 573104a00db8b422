"""Reference problems: Jacobians against finite differences, all forms agree, package hygiene."""

from __future__ import annotations

import ast
from pathlib import Path

import casadi
import numpy as np
import pytest

import solvers
from solvers import problems

PROBLEMS = [
    problems.sphere_fit(n_points=50, seed=3),
    problems.shared_point_acceleration(n_samples=200, seed=3),
    problems.rosenbrock(2),
    problems.rosenbrock(5),
]


def central_differences(fun, x, h=1e-6):
    cols = [(fun(x + h * e) - fun(x - h * e)) / (2 * h) for e in np.eye(x.size)]
    return np.column_stack(cols)


@pytest.mark.parametrize("prob", PROBLEMS, ids=lambda p: f"{p.name}-{p.x_true.size}")
def test_jacobian_matches_finite_differences(prob):
    for x in (prob.x0, prob.x_true, 0.5 * (prob.x0 + prob.lower)):
        J = prob.jacobian(x)
        J_fd = central_differences(prob.residual, x)
        assert J.shape == J_fd.shape
        np.testing.assert_allclose(J, J_fd, rtol=1e-6, atol=1e-6 * np.abs(J).max())


@pytest.mark.parametrize("prob", PROBLEMS, ids=lambda p: f"{p.name}-{p.x_true.size}")
def test_all_forms_agree(prob):
    rng = np.random.default_rng(0)
    X = prob.lower + rng.random((7, prob.x_true.size)) * (prob.upper - prob.lower)
    expected = np.array([0.5 * np.sum(prob.residual(x) ** 2) for x in X])
    np.testing.assert_allclose(prob.cost_batch(X), expected, rtol=1e-12)
    for x in X[:3]:
        if prob.data is None:
            r_ca = np.asarray(prob.casadi_residual(x)).ravel()
        else:
            mapped = prob.casadi_residual.map(prob.data.shape[1])
            r_ca = np.asarray(mapped(x, prob.data)).ravel()
        np.testing.assert_allclose(r_ca, prob.residual(x), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("prob", PROBLEMS, ids=lambda p: f"{p.name}-{p.x_true.size}")
def test_truth_inside_box_and_start_differs(prob):
    assert np.all(prob.lower < prob.x_true) and np.all(prob.x_true < prob.upper)
    assert np.all(prob.lower <= prob.x0) and np.all(prob.x0 <= prob.upper)
    assert not np.allclose(prob.x0, prob.x_true)


def test_noise_free_problems_have_zero_residual_at_truth():
    assert np.abs(problems.sphere_fit(noise=0.0).residual(np.array([0.1, -0.2, 0.3, 0.5]))).max() < 1e-14
    prob = problems.shared_point_acceleration(n_samples=100, noise=0.0)
    assert np.abs(prob.residual(prob.x_true)).max() < 1e-12


def test_rosenbrock_rejects_one_unknown():
    with pytest.raises(ValueError, match="n >= 2"):
        problems.rosenbrock(1)


def test_public_api_is_explicit():
    assert sorted(solvers.__all__) == [
        "DWPSOParams",
        "GWOParams",
        "LeastSquaresProblem",
        "SolverError",
        "SolverResult",
        "casadi_lsq",
        "dwpso",
        "gauss_newton",
        "gwo",
        "swarm_then_refine",
    ]
    assert issubclass(solvers.SolverError, RuntimeError)
    assert isinstance(problems.rosenbrock().casadi_residual, casadi.Function)
    assert isinstance(problems.rosenbrock(), solvers.LeastSquaresProblem)


def test_solvers_never_imports_lowerlimb():
    package = Path(solvers.__file__).parent
    for path in sorted(package.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            assert not any(n.split(".")[0] == "lowerlimb" for n in names), path.name


def test_result_is_a_frozen_dataclass():
    res = solvers.SolverResult(np.zeros(2), 0.0, 0, 0.0, True, "none", {})
    with pytest.raises(AttributeError):
        res.cost = 1.0  # type: ignore[misc]


def test_lowerlimb_wraps_the_solver_error_with_its_data():
    """One SolverError per package: lowerlimb's wraps solvers', keeping method and x, chained."""
    import numpy as np

    from lowerlimb.calibration._solve import _wrap
    from lowerlimb.errors import LowerLimbError

    cause = solvers.SolverError("non-finite residual", method="gauss_newton", x=np.ones(3))
    wrapped = _wrap(cause, "the gn Gauss–Newton solve")
    assert isinstance(wrapped, LowerLimbError) and isinstance(wrapped, RuntimeError)
    assert not isinstance(wrapped, solvers.SolverError)
    assert wrapped.method == "gauss_newton" and np.array_equal(wrapped.x, np.ones(3))
