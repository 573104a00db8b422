"""The one result type every solver returns."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class SolverResult:
    """Outcome of one solve.

    Attributes:
        x: The estimate, shape (n,), in the units of the unknowns.
        cost: Objective at ``x``: ``0.5 * sum(r**2)`` for the least-squares solvers, the
            value of the user's cost for the swarms.
        iterations: Number of iterations (Gauss–Newton steps, swarm generations).
        wall_time_s: Wall-clock time of the solve, in seconds.
        converged: Whether the solver's stopping test was met (see each solver's docstring)
            rather than an iteration limit or a failed line search.
        method: Solver name, e.g. ``"gauss_newton/line_search"``, ``"dwpso"``,
            ``"dwpso+casadi_lsq/gauss_newton"``.
        diagnostics: Solver-specific extras. The least-squares solvers report
            ``singular_values`` (descending, shape (n,)), ``condition_number``
            (``inf`` when singular), ``rank``, ``cost_history`` and ``message``; the swarms
            ``cost_history`` (best cost per iteration), ``n_evaluations`` and ``message``.
    """

    x: np.ndarray
    cost: float
    iterations: int
    wall_time_s: float
    converged: bool
    method: str
    diagnostics: dict[str, Any] = field(default_factory=dict)
