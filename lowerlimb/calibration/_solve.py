"""Dispatch of one least-squares calibration problem to the solvers of :mod:`solvers` (internal).

Every joint problem is given in all the forms the solvers take: a NumPy
residual and analytic Jacobian (``gn``), a population cost on a subsample
(``dwpso``, ``gwo``) and a per-sample CasADi residual with its data matrix
(``casadi``). Solver failures are re-raised as :class:`lowerlimb.errors.SolverError`.
"""

from __future__ import annotations

import numpy as np

import solvers
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import FloatArray
from lowerlimb.errors import SolverError
from solvers.problem import LeastSquaresProblem as LsqProblem


def _wrap(e: Exception, what: str) -> SolverError:
    return SolverError(f"{what} failed: {e}", method=getattr(e, "method", ""), x=getattr(e, "x", None))


def solve_local(
    problem: LsqProblem, x0: FloatArray, local: str, options: CalibrationOptions
) -> solvers.SolverResult:
    """Gauss–Newton from ``x0``: CasADi (``local="casadi"``) or NumPy (``local="gn"``).

    Raises:
        SolverError: the solver failed (chained).
    """
    lo, hi = (problem.lower, problem.upper) if problem.bounded else (None, None)
    x_start = np.clip(x0, problem.lower, problem.upper) if problem.bounded else x0
    try:
        if local == "casadi":
            return solvers.casadi_lsq(
                problem.casadi_residual,
                x_start,
                params=problem.data,
                solver="gauss_newton",
                lower=lo,
                upper=hi,
                max_iter=options.max_iter,
                tol=options.tol,
            )
        return solvers.gauss_newton(
            problem.residual,
            problem.jacobian,
            x_start,
            max_iter=options.max_iter,
            tol=options.tol,
            step="line_search",
            lower=lo,
            upper=hi,
        )
    except (solvers.SolverError, RuntimeError, ValueError) as e:
        raise _wrap(e, f"the {local} Gauss–Newton solve") from e


def solve_global(problem: LsqProblem, method: str, options: CalibrationOptions) -> solvers.SolverResult:
    """A swarm (``dwpso``/``gwo``), optionally refined by CasADi Gauss–Newton (``…+casadi``).

    Raises:
        SolverError: the solver failed (chained).
    """
    swarm, _, refine = method.partition("+")
    try:
        if refine:
            return solvers.swarm_then_refine(
                problem.cost_batch,
                problem.lower,
                problem.upper,
                lambda x0: solve_local(problem, np.asarray(x0, dtype=float), "casadi", options),
                swarm="gwo" if swarm == "gwo" else "dwpso",
                seed=options.seed,
                population=options.n_particles if swarm == "dwpso" else options.n_wolves,
                max_iter=options.hybrid_swarm_iter,
            )
        if swarm == "dwpso":
            return solvers.dwpso(
                problem.cost_batch,
                problem.lower,
                problem.upper,
                n_particles=options.n_particles,
                max_iter=options.swarm_iter,
                seed=options.seed,
            )
        return solvers.gwo(
            problem.cost_batch,
            problem.lower,
            problem.upper,
            n_wolves=options.n_wolves,
            max_iter=options.swarm_iter,
            seed=options.seed,
        )
    except SolverError:
        raise
    except (solvers.SolverError, RuntimeError, ValueError) as e:
        raise _wrap(e, f"the {method} search") from e


def subsample_step(n_samples: int, max_samples: int) -> int:
    """Stride that keeps at most ``max_samples`` of ``n_samples``."""
    return max(1, int(np.ceil(n_samples / max_samples)))
