"""The one least-squares problem type every solver entry point reads.

A problem ``min 0.5 * ||r(x)||²`` in every form the solvers take: a NumPy
residual and Jacobian (:func:`~solvers.gauss_newton`), a vectorised population
cost (the swarms), and a CasADi residual with its data matrix
(:func:`~solvers.casadi_lsq`). A reference problem (:mod:`solvers.problems`)
also carries the parameters that generated it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi
import numpy as np


@dataclass(frozen=True)
class LeastSquaresProblem:
    """A nonlinear least-squares problem ``min 0.5 * ||r(x)||²``.

    Attributes:
        residual: ``r(x)``, shape (n,) → (M,).
        jacobian: ``dr/dx``, shape (n,) → (M, n).
        cost_batch: the cost of a population, shape (P, n) → (P,).
        casadi_residual: CasADi residual: per sample ``(x, p_k) -> r_k`` when ``data`` is
            given (one column of ``data`` per sample), else ``x -> r``.
        data: The data matrix, shape (k, N), one sample per column; ``None`` when the
            residual has no data.
        lower: Lower corner of the search box, shape (n,).
        upper: Upper corner of the search box, shape (n,).
        bounded: Whether the local (Gauss–Newton) solvers also get the box; ``False``
            when the box only seeds the swarms (e.g. angles).
        name: Short identifier (reference problems).
        x_true: The parameters that generated the data, shape (n,), when known.
        x0: A starting point near (but not at) ``x_true``, shape (n,), when known.
    """

    residual: Callable[[np.ndarray], np.ndarray]
    jacobian: Callable[[np.ndarray], np.ndarray]
    cost_batch: Callable[[np.ndarray], np.ndarray]
    casadi_residual: casadi.Function
    data: np.ndarray | None
    lower: np.ndarray
    upper: np.ndarray
    bounded: bool = True
    name: str = ""
    x_true: np.ndarray | None = None
    x0: np.ndarray | None = None
