"""Input checks shared by the solvers (private)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from solvers.errors import SolverError


def as_vector(x: ArrayLike, name: str) -> np.ndarray:
    """Return ``x`` as a finite float vector of shape (n,), n >= 1, or raise ValueError."""
    v = np.array(x, dtype=float, copy=True)
    if v.ndim != 1 or v.size == 0:
        raise ValueError(f"{name} must be a non-empty vector of shape (n,), got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name} contains NaN or inf at indices {np.flatnonzero(~np.isfinite(v))}")
    return v


def as_bounds(lower: ArrayLike | None, upper: ArrayLike | None, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Broadcast optional bounds to shape (n,); ``None`` means unbounded (±inf).

    Raises:
        ValueError: A bound has the wrong shape, contains NaN, or ``lower > upper``.
    """
    lo = np.full(n, -np.inf) if lower is None else np.array(lower, dtype=float)
    hi = np.full(n, np.inf) if upper is None else np.array(upper, dtype=float)
    try:
        lo = np.broadcast_to(lo, (n,)).copy()
        hi = np.broadcast_to(hi, (n,)).copy()
    except ValueError:
        raise ValueError(
            f"bounds must be scalars or have shape ({n},); got lower {lo.shape}, upper {hi.shape}"
        ) from None
    if np.any(np.isnan(lo)) or np.any(np.isnan(hi)):
        raise ValueError("bounds contain NaN; use -inf/inf (or None) for an unbounded variable")
    bad = np.flatnonzero(lo > hi)
    if bad.size:
        raise ValueError(f"lower > upper at indices {bad}; swap or fix the bounds")
    return lo, hi


def as_box(lower: ArrayLike, upper: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Finite search box for the swarms: two vectors of shape (n,) with lower <= upper.

    Raises:
        ValueError: Shapes differ or are not 1-D, a bound is not finite, or lower > upper.
    """
    lo = np.atleast_1d(np.array(lower, dtype=float))
    hi = np.atleast_1d(np.array(upper, dtype=float))
    if lo.ndim != 1 or lo.shape != hi.shape:
        raise ValueError(
            f"lower and upper must be vectors of the same shape (n,); got {lo.shape} and {hi.shape}"
        )
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ValueError("a swarm needs a finite search box: lower and upper must be finite")
    bad = np.flatnonzero(lo > hi)
    if bad.size:
        raise ValueError(f"lower > upper at indices {bad}; swap or fix the bounds")
    return lo, hi


def check_inside(x: np.ndarray, lower: np.ndarray, upper: np.ndarray, name: str = "x0") -> None:
    """Raise ValueError when ``x`` lies outside ``[lower, upper]``."""
    if x.shape != lower.shape:
        raise ValueError(f"{name} has shape {x.shape}, the bounds have shape {lower.shape}")
    out = np.flatnonzero((x < lower) | (x > upper))
    if out.size:
        raise ValueError(
            f"{name} lies outside the bounds at indices {out} "
            f"({name}={x[out]}, lower={lower[out]}, upper={upper[out]}); "
            f"clip it with np.clip({name}, lower, upper) or widen the bounds"
        )


def evaluate_population(cost: Callable[[np.ndarray], ArrayLike], X: np.ndarray, method: str) -> np.ndarray:
    """Evaluate a vectorised cost on a population; non-finite values become +inf.

    Args:
        cost: Maps positions, shape (P, n), to costs, shape (P,).
        X: Positions, shape (P, n).
        method: Solver name, for error messages.

    Returns:
        Costs, shape (P,), float, with NaN replaced by +inf (an infeasible point).

    Raises:
        ValueError: The cost returned an array of the wrong shape.
    """
    f = np.asarray(cost(X.copy()), dtype=float)
    if f.shape != (X.shape[0],):
        raise ValueError(
            f"{method}: cost(X) must take the whole population X of shape {X.shape} and "
            f"return one value per row, shape ({X.shape[0]},); got shape {f.shape}"
        )
    return np.where(np.isfinite(f), f, np.inf)


def require_finite_best(best_cost: float, n_evaluations: int, method: str) -> None:
    """Raise SolverError when no evaluated point had a finite cost."""
    if not np.isfinite(best_cost):
        raise SolverError(
            f"the cost was NaN or inf at all {n_evaluations} evaluated points; "
            "check the cost function and the search box",
            method=method,
        )
