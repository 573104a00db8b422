"""Start, stall test and result shared by the population solvers (private)."""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from solvers._checks import as_vector, check_inside, require_finite_best
from solvers.result import SolverResult


def initial_positions(
    rng: np.random.Generator, lo: np.ndarray, hi: np.ndarray, size: int, x0: ArrayLike | None
) -> np.ndarray:
    """``size`` positions uniform in the box, member 0 replaced by ``x0`` when given.

    Raises:
        ValueError: ``x0`` is not a finite vector inside the box.
    """
    X = lo + rng.random((size, lo.size)) * (hi - lo)
    if x0 is not None:
        x_start = as_vector(x0, "x0")
        check_inside(x_start, lo, hi)
        X[0] = x_start
    return X


def stall_message(history: list[float], start: int, stall: int, tol: float) -> str | None:
    """The stop message when the best cost improved by at most ``tol`` (relative), else ``None``.

    Args:
        history: best cost after each iteration (index 0: the initial population).
        start: first index of ``history`` the test may look back to (< 0: not yet).
        stall: number of iterations looked back over.
        tol: relative tolerance on the improvement.
    """
    if 0 <= start <= len(history) - 1 - stall and np.isfinite(history[-1]):
        if history[-1 - stall] - history[-1] <= tol * abs(history[-1]):
            return f"best cost improved by <= tol (relative) over {stall} iterations"
    return None


def swarm_result(
    method: str,
    x_best: np.ndarray,
    f_best: float,
    X: np.ndarray,
    span: np.ndarray,
    history: list[float],
    *,
    population: int,
    iterations: int,
    converged: bool,
    message: str,
    t_start: float,
    extra: dict[str, Any],
) -> SolverResult:
    """The :class:`SolverResult` of a population solver, with the common diagnostics.

    ``diagnostics``: ``cost_history``, ``n_evaluations``, then ``extra``, then
    ``final_spread`` (RMS distance of ``X`` from ``x_best`` relative to the box diagonal)
    and ``message``.

    Raises:
        SolverError: ``f_best`` is not finite.
    """
    n_evaluations = population * (iterations + 1)
    require_finite_best(f_best, n_evaluations, method)
    diag = float(np.linalg.norm(span)) or 1.0
    spread = float(np.sqrt(np.mean(np.sum((X - x_best) ** 2, axis=1)))) / diag
    return SolverResult(
        x=x_best.copy(),
        cost=float(f_best),
        iterations=iterations,
        wall_time_s=time.perf_counter() - t_start,
        converged=converged,
        method=method,
        diagnostics={
            "cost_history": np.asarray(history),
            "n_evaluations": n_evaluations,
            **extra,
            "final_spread": spread,
            "message": message,
        },
    )
