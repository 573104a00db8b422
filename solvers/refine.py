"""A swarm finds the basin, a local least-squares solver polishes (swarm-initialised refinement)."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from typing import Literal, TypeVar

import numpy as np
from numpy.typing import ArrayLike

from solvers.dwpso import DWPSOParams, dwpso
from solvers.gwo import GWOParams, gwo
from solvers.result import SolverResult

Swarm = Literal["dwpso", "gwo"]

_P = TypeVar("_P", DWPSOParams, GWOParams)


def _swarm_params(swarm: str, params: DWPSOParams | GWOParams | None, kind: type[_P]) -> _P:
    """``params``, or the defaults when ``None``; ValueError when they belong to the other swarm."""
    if params is None:
        return kind()
    if not isinstance(params, kind):
        raise ValueError(f"swarm={swarm!r} takes {kind.__name__}")
    return params


def swarm_then_refine(
    cost_batch: Callable[[np.ndarray], ArrayLike],
    lower: ArrayLike,
    upper: ArrayLike,
    refine: Callable[[np.ndarray], SolverResult],
    *,
    swarm: Swarm = "dwpso",
    seed: int = 0,
    population: int | None = None,
    max_iter: int = 150,
    tol: float = 1e-10,
    x0: ArrayLike | None = None,
    params: DWPSOParams | GWOParams | None = None,
) -> SolverResult:
    """Run a swarm over the box, then refine its best point with a local solver.

    The swarm (:func:`~solvers.dwpso.dwpso` or :func:`~solvers.gwo.gwo`, Hu et al. 2021
    §3.2–3.3) is robust to a poor start and to weakly identified directions; the local solver
    (e.g. ``lambda x: casadi_lsq(r, x, params=data, lower=lo, upper=hi)``, §3.1) then reaches
    the minimum to machine precision in a few iterations.

    Args:
        cost_batch: Vectorised cost for the swarm, shape (P, n) → (P,).
        lower: Lower corner of the search box, shape (n,), finite.
        upper: Upper corner, shape (n,), finite.
        refine: Local solver started from the swarm's best point, shape (n,); it should
            respect the same box.
        swarm: ``"dwpso"`` or ``"gwo"``.
        seed: Seed of the swarm.
        population: Number of particles/wolves; default 40 (DWPSO) or 30 (GWO).
        max_iter: Swarm iterations.
        tol: Swarm stall tolerance.
        x0: Optional starting position given to the swarm (one member), shape (n,).
        params: :class:`~solvers.dwpso.DWPSOParams` or :class:`~solvers.gwo.GWOParams`
            matching ``swarm``; defaults when ``None``.

    Returns:
        The refined result with ``method = "<swarm>+<refine method>"``, ``wall_time_s`` of
        both stages, and ``diagnostics["swarm"]`` recording the swarm stage (``x``, ``cost``,
        ``iterations``, ``wall_time_s``, ``converged``, ``message``) next to the refiner's
        own diagnostics; ``diagnostics["refine_wall_time_s"]`` is the refinement alone.

    Raises:
        ValueError: Unknown ``swarm`` or ``params`` of the other swarm; the swarm's own
            ValueErrors.
        TypeError: ``refine`` did not return a :class:`SolverResult`.
        SolverError: From the swarm (cost never finite) or from the refiner.
    """
    t_start = time.perf_counter()
    if swarm == "dwpso":
        first = dwpso(
            cost_batch,
            lower,
            upper,
            n_particles=population or 40,
            max_iter=max_iter,
            seed=seed,
            tol=tol,
            x0=x0,
            params=_swarm_params(swarm, params, DWPSOParams),
        )
    elif swarm == "gwo":
        first = gwo(
            cost_batch,
            lower,
            upper,
            n_wolves=population or 30,
            max_iter=max_iter,
            seed=seed,
            tol=tol,
            x0=x0,
            params=_swarm_params(swarm, params, GWOParams),
        )
    else:
        raise ValueError(f"unknown swarm {swarm!r}; choose 'dwpso' or 'gwo'")

    refined = refine(first.x.copy())
    if not isinstance(refined, SolverResult):
        raise TypeError(f"refine must return a SolverResult, got {type(refined).__name__}")
    diagnostics = dict(refined.diagnostics)
    diagnostics["swarm"] = {
        "method": first.method,
        "x": first.x,
        "cost": first.cost,
        "iterations": first.iterations,
        "wall_time_s": first.wall_time_s,
        "converged": first.converged,
        "message": first.diagnostics.get("message", ""),
    }
    diagnostics["refine_wall_time_s"] = refined.wall_time_s
    return dataclasses.replace(
        refined,
        method=f"{first.method}+{refined.method}",
        wall_time_s=time.perf_counter() - t_start,
        diagnostics=diagnostics,
    )
