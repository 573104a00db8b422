"""Grey wolf optimiser (Hu et al. 2021, eq. 25–29, after Mirjalili et al. 2014)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from solvers._checks import as_box, evaluate_population
from solvers._swarm import initial_positions, stall_message, swarm_result
from solvers.result import SolverResult


@dataclass(frozen=True)
class GWOParams:
    """Parameters of :func:`gwo`.

    Attributes:
        a_start: Convergence factor a (the paper's ψ) at the first iteration, 2.
        a_end: Convergence factor at the last iteration, 0.
        stall_iterations: Stop when the best cost improved by at most ``tol`` (relative)
            over this many iterations, counted within the last quarter of the schedule only:
            earlier, the step ``A·|C·X_p − X|`` scales with ``|X_p|`` rather than with the
            distance to the optimum, and the pack often goes many iterations without a new
            best before ``a`` has shrunk.
    """

    a_start: float = 2.0
    a_end: float = 0.0
    stall_iterations: int = 30

    def __post_init__(self) -> None:
        if self.a_start < 0 or self.a_end < 0:
            raise ValueError(f"a_start and a_end must be >= 0, got {self.a_start}, {self.a_end}")
        if self.stall_iterations < 1:
            raise ValueError(f"stall_iterations must be >= 1, got {self.stall_iterations}")


def gwo(
    cost: Callable[[np.ndarray], ArrayLike],
    lower: ArrayLike,
    upper: ArrayLike,
    *,
    n_wolves: int = 30,
    max_iter: int = 150,
    seed: int = 0,
    tol: float = 1e-10,
    x0: ArrayLike | None = None,
    params: GWOParams = GWOParams(),
) -> SolverResult:
    """Minimise a cost over a box with the grey wolf optimiser (Hu et al. 2021, eq. 25–29).

    The leaders α, β, δ are the three best positions found so far (an archive: a leader is
    replaced only by a better wolf). At iteration γ every wolf X moves, for each leader
    X_p ∈ {α, β, δ} (eq. 27–28, Mirjalili et al. 2014)::

        A = 2a·r1 − a,  C = 2·r2,  D = |C·X_p − X|,  X_p' = X_p − A·D,

    with r1, r2 ~ U[0, 1] drawn per wolf, leader and coordinate, and
    ``a = a_start + (a_end − a_start) · γ/(γ_max − 1)`` falling linearly from 2 to 0. The new
    position is the mean ``(X_α' + X_β' + X_δ')/3`` (eq. 29), clipped to the box. Initial
    positions are uniform in the box. Non-finite costs count as +inf.

    Args:
        cost: Vectorised cost: positions of the whole pack, shape (P, n), to costs, shape
            (P,); called once per iteration.
        lower: Lower corner of the search box, shape (n,), finite.
        upper: Upper corner, shape (n,), finite, ``>= lower``.
        n_wolves: Pack size P (>= 3).
        max_iter: γ_max, the number of position updates.
        seed: Seed of ``numpy.random.default_rng``; equal seeds give equal results.
        tol: Relative stall tolerance: stop when the best cost improved by at most
            ``tol * |best|`` over ``params.stall_iterations`` iterations of the last quarter
            of the schedule (see :class:`GWOParams`).
        x0: Optional position, shape (n,), inside the box, that replaces wolf 0.
        params: Convergence-factor schedule and stall length.

    Returns:
        The α wolf's position and cost. ``converged`` is True when the stall test stopped
        the run, False when ``max_iter`` did. ``diagnostics``: ``cost_history`` (best cost
        after each iteration, shape (iterations + 1,)), ``n_evaluations``, ``leaders``
        (shape (3, n)), ``leader_costs`` (3,), ``final_spread`` (RMS distance of the wolves
        from α, relative to the box diagonal) and ``message``.

    Raises:
        ValueError: Bad box, ``x0``, sizes or a cost returning the wrong shape.
        SolverError: The cost was NaN/inf at every evaluated point.
    """
    t_start = time.perf_counter()
    lo, hi = as_box(lower, upper)
    n = lo.size
    if n_wolves < 3 or max_iter < 0:
        raise ValueError(f"need n_wolves >= 3 and max_iter >= 0, got {n_wolves}, {max_iter}")
    span = hi - lo
    rng = np.random.default_rng(seed)

    X = initial_positions(rng, lo, hi, n_wolves, x0)
    f = evaluate_population(cost, X, "gwo")
    order = np.argsort(f, kind="stable")[:3]
    leaders, leader_f = X[order].copy(), f[order].copy()
    history = [float(leader_f[0])]
    converged = False
    message = f"maximum number of iterations ({max_iter}) reached"
    iterations = 0
    final_start = -1  # index in history where the last quarter of the schedule began

    for k in range(max_iter):
        a = params.a_start + (params.a_end - params.a_start) * k / max(max_iter - 1, 1)
        r1 = rng.random((3, n_wolves, n))
        r2 = rng.random((3, n_wolves, n))
        A = 2.0 * a * r1 - a
        C = 2.0 * r2
        D = np.abs(C * leaders[:, None, :] - X[None, :, :])
        X = np.clip(np.mean(leaders[:, None, :] - A * D, axis=0), lo, hi)
        f = evaluate_population(cost, X, "gwo")
        pool = np.vstack([leaders, X])
        pool_f = np.concatenate([leader_f, f])
        order = np.argsort(pool_f, kind="stable")[:3]
        leaders, leader_f = pool[order].copy(), pool_f[order].copy()
        history.append(float(leader_f[0]))
        iterations = k + 1
        if k >= 0.75 * max_iter and final_start < 0:
            final_start = len(history) - 1
        stalled = stall_message(history, final_start, params.stall_iterations, tol)
        if stalled is not None:
            converged, message = True, stalled
            break

    return swarm_result(
        "gwo",
        leaders[0],
        leader_f[0],
        X,
        span,
        history,
        population=n_wolves,
        iterations=iterations,
        converged=converged,
        message=message,
        t_start=t_start,
        extra={"leaders": leaders, "leader_costs": leader_f},
    )
