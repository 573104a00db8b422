"""Dynamic-weight particle swarm optimisation (Hu et al. 2021, eq. 17–24; Shi & Eberhart 1998)."""

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
class DWPSOParams:
    """Parameters of :func:`dwpso` (defaults from Hu et al. 2021 and the errata in docs/methods.md).

    Attributes:
        mu_max: Inertia weight at the first iteration (μ_max = 0.8).
        mu_min: Inertia weight at the last iteration (μ_min = 0.2).
        jump: Half-width of the uniform random jump added to the inertia weight of each
            particle at each iteration (dimensionless).
        omega1: Cognitive acceleration constant Ω1 (pull towards the particle's best), 2.
        omega2: Social acceleration constant Ω2 (pull towards the swarm's best), 2.
        max_velocity: Velocity limit per coordinate, as a fraction of ``upper − lower``.
        stall_iterations: Stop when the best cost improved by at most ``tol`` (relative)
            over this many iterations.
    """

    mu_max: float = 0.8
    mu_min: float = 0.2
    jump: float = 0.05
    omega1: float = 2.0
    omega2: float = 2.0
    max_velocity: float = 0.2
    stall_iterations: int = 30

    def __post_init__(self) -> None:
        if not 0.0 < self.mu_min <= self.mu_max:
            raise ValueError(f"need 0 < mu_min <= mu_max, got mu_min={self.mu_min}, mu_max={self.mu_max}")
        if self.jump < 0 or self.omega1 < 0 or self.omega2 < 0:
            raise ValueError("jump, omega1 and omega2 must be >= 0")
        if not self.max_velocity > 0:
            raise ValueError(f"max_velocity must be > 0, got {self.max_velocity}")
        if self.stall_iterations < 1:
            raise ValueError(f"stall_iterations must be >= 1, got {self.stall_iterations}")


def inertia_weight(iteration: int, max_iter: int, params: DWPSOParams) -> float:
    """Deterministic part of the dynamic inertia weight (replaces the garbled eq. 24).

    ``μ(γ) = μ_max · (μ_min / μ_max) ** (γ / (γ_max − 1))``, γ = 0 … γ_max − 1: an
    exponential decay from μ_max at the first iteration to μ_min at the last.

    Args:
        iteration: γ, 0-based.
        max_iter: γ_max.
        params: Supplies μ_max and μ_min.

    Returns:
        μ(γ), dimensionless.
    """
    frac = iteration / max(max_iter - 1, 1)
    return float(params.mu_max * (params.mu_min / params.mu_max) ** frac)


def dwpso(
    cost: Callable[[np.ndarray], ArrayLike],
    lower: ArrayLike,
    upper: ArrayLike,
    *,
    n_particles: int = 40,
    max_iter: int = 150,
    seed: int = 0,
    tol: float = 1e-10,
    x0: ArrayLike | None = None,
    params: DWPSOParams = DWPSOParams(),
) -> SolverResult:
    """Minimise a cost over a box with dynamic-weight PSO (Hu et al. 2021, eq. 17–24).

    Each iteration γ updates every particle ε (eq. 22–23)::

        F ← μ̃ F + Ω1 ∂1 (η_ε − x_ε) + Ω2 ∂2 (p − x_ε),    x_ε ← x_ε + F,

    with ∂1, ∂2 ~ U[0, 1] per coordinate, η_ε the particle's best position (eq. 19), p the
    swarm's best (eq. 20), and the dynamic weight (eq. 24 is garbled in print; docs/methods.md)::

        μ̃_{γ,ε} = μ_max (μ_min/μ_max)^(γ/(γ_max−1)) + jump · (2u − 1),   u ~ U[0, 1],

    one jump per particle and iteration. Velocities are clamped to
    ``±max_velocity · (upper − lower)``; positions are clipped to the box and the velocity
    components that hit a wall are set to zero. Initial positions are uniform in the box,
    initial velocities uniform within the clamp. Non-finite costs count as +inf.

    Args:
        cost: Vectorised cost: positions of the whole swarm, shape (P, n), to costs, shape
            (P,); called once per iteration.
        lower: Lower corner of the search box, shape (n,), finite.
        upper: Upper corner, shape (n,), finite, ``>= lower``.
        n_particles: Swarm size P (>= 1).
        max_iter: γ_max, the number of velocity/position updates.
        seed: Seed of ``numpy.random.default_rng``; equal seeds give equal results.
        tol: Relative stall tolerance: stop when the best cost improved by at most
            ``tol * |best|`` over ``params.stall_iterations`` iterations.
        x0: Optional position, shape (n,), inside the box, that replaces particle 0.
        params: Inertia, acceleration and velocity parameters.

    Returns:
        The swarm's best position and cost. ``converged`` is True when the stall test
        stopped the run, False when ``max_iter`` did. ``diagnostics``: ``cost_history``
        (best cost after each iteration, shape (iterations + 1,)), ``n_evaluations``,
        ``inertia_weights`` (μ(γ) without the jump), ``final_spread`` (RMS distance of the
        particles from the best, relative to the box diagonal) and ``message``.

    Raises:
        ValueError: Bad box, ``x0``, sizes or a cost returning the wrong shape.
        SolverError: The cost was NaN/inf at every evaluated point.
    """
    t_start = time.perf_counter()
    lo, hi = as_box(lower, upper)
    n = lo.size
    if n_particles < 1 or max_iter < 0:
        raise ValueError(f"need n_particles >= 1 and max_iter >= 0, got {n_particles}, {max_iter}")
    span = hi - lo
    v_max = params.max_velocity * span
    rng = np.random.default_rng(seed)

    X = initial_positions(rng, lo, hi, n_particles, x0)
    V = rng.uniform(-1.0, 1.0, (n_particles, n)) * v_max
    f = evaluate_population(cost, X, "dwpso")
    best_pos, best_f = X.copy(), f.copy()
    g = int(np.argmin(best_f))
    history = [float(best_f[g])]
    weights = []
    converged = False
    message = f"maximum number of iterations ({max_iter}) reached"
    iterations = 0

    for k in range(max_iter):
        mu = inertia_weight(k, max_iter, params)
        weights.append(mu)
        mu_tilde = mu + params.jump * (2.0 * rng.random((n_particles, 1)) - 1.0)
        r1 = rng.random((n_particles, n))
        r2 = rng.random((n_particles, n))
        V = mu_tilde * V + params.omega1 * r1 * (best_pos - X) + params.omega2 * r2 * (best_pos[g] - X)
        np.clip(V, -v_max, v_max, out=V)
        X = X + V
        hit = (X < lo) | (X > hi)
        np.clip(X, lo, hi, out=X)
        V[hit] = 0.0
        f = evaluate_population(cost, X, "dwpso")
        better = f < best_f
        best_pos[better] = X[better]
        best_f[better] = f[better]
        g = int(np.argmin(best_f))
        history.append(float(best_f[g]))
        iterations = k + 1
        stalled = stall_message(history, 0, params.stall_iterations, tol)
        if stalled is not None:
            converged, message = True, stalled
            break

    return swarm_result(
        "dwpso",
        best_pos[g],
        best_f[g],
        X,
        span,
        history,
        population=n_particles,
        iterations=iterations,
        converged=converged,
        message=message,
        t_start=t_start,
        extra={"inertia_weights": np.asarray(weights)},
    )
