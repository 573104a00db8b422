"""Gauss–Newton least squares with a pseudo-inverse step (Hu et al. 2021, eq. 7–15).

Minimises ``0.5 * ||r(x)||²`` subject to optional box bounds. Three step rules share one loop:

- ``"pinv"``: the paper's plain update ``x ← x − pinv(J) r`` (Hu et al. 2021, eq. 11 and 15),
  projected onto the bounds.
- ``"line_search"`` (default): the same direction with a backtracking Armijo line search on
  the projected path, falling back to projected steepest descent when the Gauss–Newton
  direction does not decrease the cost.
- ``"levenberg_marquardt"``: the damped step ``(JᵀJ + λI) d = −Jᵀr`` with Nielsen's update of λ.

Bounds are handled as in projected Newton methods: variables at a bound whose gradient points
out of the box are frozen for the step, the step is computed in the free variables and the
trial point is projected onto the box.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from solvers._checks import as_bounds, as_vector, check_inside
from solvers.errors import SolverError
from solvers.result import SolverResult

Step = Literal["line_search", "pinv", "levenberg_marquardt"]
STEPS: tuple[str, ...] = ("line_search", "pinv", "levenberg_marquardt")

#: ``evaluate(x, need_jacobian) -> (r, J or None)``; may return J even when not asked.
Evaluate = Callable[[np.ndarray, bool], tuple[np.ndarray, np.ndarray | None]]

_ARMIJO_C1 = 1e-4
_MAX_BACKTRACKS = 40
_LM_TAU = 1e-3


def gauss_newton(
    residual: Callable[[np.ndarray], ArrayLike],
    jacobian: Callable[[np.ndarray], ArrayLike],
    x0: ArrayLike,
    *,
    max_iter: int = 100,
    tol: float = 1e-10,
    step: Step = "line_search",
    lower: ArrayLike | None = None,
    upper: ArrayLike | None = None,
    rcond: float | None = None,
) -> SolverResult:
    """Minimise ``0.5 * ||r(x)||²`` by Gauss–Newton (Hu et al. 2021, eq. 7–15).

    The Gauss–Newton direction is the minimum-norm solution of ``J d = −r`` through the SVD of
    ``J`` (``pinv(J)``, eq. 11): singular values below ``rcond * s_max`` are treated as zero,
    so an unidentifiable direction leaves that component of ``x`` unchanged instead of
    producing NaN. It is reported in ``diagnostics`` (the paper's §3.1 rank deficiency).

    Stopping (``converged=True``) when any of these holds after an accepted step:
    ``||Δx|| <= tol * (tol + ||x||)``; a full step reduced the cost by at most ``tol * cost``
    (an increase, possible with ``"pinv"``, does not count);
    the largest cosine between ``r`` and a free column of ``J`` (MINPACK's gradient test)
    is at most ``tol``; or the residual is exactly zero.

    Args:
        residual: ``r(x)``, maps unknowns of shape (n,) to residuals of shape (M,).
        jacobian: ``J(x) = dr/dx``, shape (M, n).
        x0: Initial estimate, shape (n,); must lie inside the bounds.
        max_iter: Maximum number of iterations (each computes one step; a rejected
            Levenberg–Marquardt step counts as an iteration).
        tol: Tolerance of the stopping tests above (relative, dimensionless).
        step: ``"line_search"``, ``"pinv"`` (eq. 11 as printed) or ``"levenberg_marquardt"``.
        lower: Lower bounds, scalar or shape (n,); ``None`` for unbounded.
        upper: Upper bounds, scalar or shape (n,); ``None`` for unbounded.
        rcond: Relative cut-off for small singular values in the pseudo-inverse and in the
            reported rank; default ``max(M, n) * eps`` (the numpy/MATLAB rank convention).

    Returns:
        The estimate with ``cost = 0.5 * sum(r**2)``. ``diagnostics`` holds
        ``singular_values`` (of ``J`` at the solution, descending, shape (n,)),
        ``condition_number``, ``rank``, ``unidentifiable_directions`` (shape (n − rank, n),
        unit rows spanning the numerical null space of ``J``), ``cost_history``,
        ``gradient_cosine``, ``rms_residual``, ``active_bounds``, ``n_residual_evaluations``,
        ``n_jacobian_evaluations`` and ``message``.

    Raises:
        ValueError: Bad ``x0``, bounds, ``step``, ``max_iter``, ``tol``, or a residual or
            Jacobian of the wrong shape.
        SolverError: The residual is NaN/inf at ``x0`` or after a ``"pinv"`` step, or the
            Jacobian is NaN/inf.
    """
    n_jac = 0

    def evaluate(x: np.ndarray, need_jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
        nonlocal n_jac
        r = np.asarray(residual(x), dtype=float)
        if not need_jacobian:
            return r, None
        n_jac += 1
        return r, np.asarray(jacobian(x), dtype=float)

    return least_squares_core(
        evaluate,
        x0,
        max_iter=max_iter,
        tol=tol,
        step=step,
        lower=lower,
        upper=upper,
        rcond=rcond,
        method=f"gauss_newton/{step}",
    )


def least_squares_core(
    evaluate: Evaluate,
    x0: ArrayLike,
    *,
    max_iter: int,
    tol: float,
    step: str,
    lower: ArrayLike | None,
    upper: ArrayLike | None,
    rcond: float | None,
    method: str,
) -> SolverResult:
    """The Gauss–Newton loop shared by :func:`gauss_newton` and ``casadi_lsq``.

    Stages: check the inputs → evaluate at ``x0`` → iterate → diagnose ``J`` at the solution.

    Args:
        evaluate: ``evaluate(x, need_jacobian) -> (r, J)``; ``r`` shape (M,), ``J`` shape
            (M, n) or ``None`` when not asked for. Returning ``J`` although not asked for is
            allowed (and used when the Jacobian comes for free with the residual).
        x0: Initial estimate, shape (n,).
        max_iter: See :func:`gauss_newton`.
        tol: See :func:`gauss_newton`.
        step: See :func:`gauss_newton`.
        lower: See :func:`gauss_newton`.
        upper: See :func:`gauss_newton`.
        rcond: See :func:`gauss_newton`.
        method: Name recorded in the result and in error messages.

    Returns:
        See :func:`gauss_newton`.

    Raises:
        ValueError: See :func:`gauss_newton`.
        SolverError: See :func:`gauss_newton`.
    """
    t_start = time.perf_counter()
    x, lo, hi = _check_inputs(x0, lower, upper, step, max_iter, tol)
    call = _CheckedEvaluate(evaluate, x.size, method)
    state = _initial_state(call, x, method)
    rtol = float(max(state.M, x.size) * np.finfo(float).eps) if rcond is None else float(rcond)
    _iterate(call, state, lo, hi, step, max_iter, tol, rtol, method)
    return SolverResult(
        x=state.x,
        cost=state.f,
        iterations=state.iterations,
        wall_time_s=time.perf_counter() - t_start,
        converged=state.converged,
        method=method,
        diagnostics=_final_diagnostics(call, state, lo, hi, rtol),
    )


@dataclass
class _LoopState:
    """The Gauss–Newton loop's current point and bookkeeping (updated in place).

    Attributes:
        x: Current estimate, shape (n,).
        r: Residual at ``x``, shape (M,).
        J: Jacobian at ``x``, shape (M, n), or ``None`` when not evaluated yet.
        f: Cost ``0.5 * ||r||²`` at ``x``.
        M: Number of residuals at ``x0``.
        history: Costs: the initial one, then one per iteration (also rejected steps).
        message: Why the loop stopped (so far: the iteration limit).
        converged: A stopping test held.
        done: The loop must stop (set by a step rule that found no step).
        iterations: Iterations (steps computed) so far.
        gcos: MINPACK gradient cosine at ``x`` (dimensionless).
        lam: Levenberg–Marquardt damping (``-1`` until the first iteration sets it).
        nu: Levenberg–Marquardt growth factor of ``lam`` after a rejected step.
    """

    x: np.ndarray
    r: np.ndarray
    J: np.ndarray | None
    f: float
    M: int
    history: list[float]
    message: str
    converged: bool = False
    done: bool = False
    iterations: int = 0
    gcos: float = np.inf
    lam: float = -1.0
    nu: float = 2.0


#: An accepted trial point: ``(x (n,), r (M,), f, J (M, n) or None, full_step)``.
_Trial = tuple[np.ndarray, np.ndarray, float, np.ndarray | None, bool]


def _check_inputs(
    x0: ArrayLike, lower: ArrayLike | None, upper: ArrayLike | None, step: str, max_iter: int, tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate the start, bounds and options.

    Returns:
        ``x0`` as a float vector, shape (n,), and the lower and upper bounds, shape (n,).

    Raises:
        ValueError: Bad ``x0``, bounds (or ``x0`` outside them), ``step``, ``max_iter`` or ``tol``.
    """
    x = as_vector(x0, "x0")
    lo, hi = as_bounds(lower, upper, x.size)
    check_inside(x, lo, hi)
    if step not in STEPS:
        raise ValueError(f"unknown step {step!r}; choose one of {STEPS}")
    if int(max_iter) != max_iter or max_iter < 0:
        raise ValueError(f"max_iter must be a non-negative integer, got {max_iter}")
    if not tol >= 0:
        raise ValueError(f"tol must be >= 0, got {tol}")
    return x, lo, hi


class _CheckedEvaluate:
    """``evaluate`` with shape and finiteness checks and evaluation counts.

    ``self(x, need_jacobian) -> (r, J)``: ``x`` shape (n,), ``r`` shape (M,), ``J`` shape
    (M, n) or ``None``. ``n_r`` counts calls, ``n_J`` the Jacobians returned.
    """

    def __init__(self, evaluate: Evaluate, n: int, method: str) -> None:
        self._evaluate = evaluate
        self._n = n
        self._method = method
        self.n_r = 0
        self.n_J = 0

    def __call__(self, xq: np.ndarray, need_jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
        self.n_r += 1
        r, J = self._evaluate(xq, need_jacobian)
        if r.ndim != 1:
            raise ValueError(f"{self._method}: the residual must have shape (M,), got {r.shape}")
        if J is not None:
            self.n_J += 1
            if J.shape != (r.size, self._n):
                raise ValueError(
                    f"{self._method}: the Jacobian must have shape (M, n) = {(r.size, self._n)}, "
                    f"got {J.shape}"
                )
            if not np.all(np.isfinite(J)) and np.all(np.isfinite(r)):
                raise SolverError(
                    f"the Jacobian contains NaN/inf ({np.count_nonzero(~np.isfinite(J))} "
                    f"entries) at x = {xq}; check the Jacobian for divisions by zero "
                    "(e.g. the derivative of a norm at 0)",
                    method=self._method,
                    x=xq,
                )
        return r, J

    def jacobian_at(self, xq: np.ndarray) -> np.ndarray:
        """The Jacobian at ``xq`` (shape (n,)), shape (M, n); ``ValueError`` when none comes back."""
        J = self(xq, True)[1]
        if J is None:
            raise ValueError(f"{self._method}: evaluate(x, True) returned no Jacobian")
        return J


def _initial_state(call: _CheckedEvaluate, x: np.ndarray, method: str) -> _LoopState:
    """Residual and Jacobian at the start ``x`` (shape (n,)); the loop state before iteration 1.

    Raises:
        SolverError: The residual is NaN/inf at ``x``.
    """
    r, J = call(x, True)
    if not np.all(np.isfinite(r)):
        raise SolverError(
            f"the residual is NaN/inf at the initial point ({np.count_nonzero(~np.isfinite(r))} "
            f"of {r.size} entries); check the data for NaN and the residual for divisions by "
            "zero, or start from another x0",
            method=method,
            x=x,
        )
    f = 0.5 * float(r @ r)
    return _LoopState(x, r, J, f, r.size, [f], "")


def _iterate(
    call: _CheckedEvaluate,
    state: _LoopState,
    lo: np.ndarray,
    hi: np.ndarray,
    step: str,
    max_iter: int,
    tol: float,
    rtol: float,
    method: str,
) -> None:
    """Run the loop on ``state`` until a stopping test, a failed step or ``max_iter``.

    Each iteration: gradient ``g = Jᵀr`` and the free variables (shape (n,)) → tests before the
    step → Gauss–Newton/Levenberg–Marquardt direction → the step rule's trial → tests after it.
    """
    state.message = f"maximum number of iterations ({max_iter}) reached"
    while True:
        J = state.J if state.J is not None else call.jacobian_at(state.x)
        state.J = J
        g = J.T @ state.r
        free = ~(((state.x <= lo) & (g > 0)) | ((state.x >= hi) & (g < 0)))
        state.gcos = _gradient_cosine(J, state.r, g, free)
        if _stops_before_step(state, tol, max_iter):
            break
        state.iterations += 1
        d = _direction(J, state, free, step, rtol)
        trial = _trial_step(call, state, J, g, free, d, lo, hi, step, method)
        if trial is None:
            if state.done:
                break
            continue
        if _accept(state, trial, tol):
            break


def _stops_before_step(state: _LoopState, tol: float, max_iter: int) -> bool:
    """The tests at the current point: zero residual, gradient cosine, iteration limit."""
    if state.f == 0.0:
        state.converged, state.message = True, "zero residual"
        return True
    if state.gcos <= tol:
        state.converged, state.message = True, f"gradient cosine {state.gcos:.3g} <= tol"
        return True
    return state.iterations >= max_iter


def _direction(J: np.ndarray, state: _LoopState, free: np.ndarray, step: str, rtol: float) -> np.ndarray:
    """The step direction, shape (n,), zero in the frozen variables (``free`` is (n,) bool).

    ``J`` is the Jacobian at ``state.x``, shape (M, n).

    Levenberg–Marquardt: ``(JᵀJ + λI) d = −Jᵀr`` (sets the initial ``λ`` in ``state`` at the
    first iteration); otherwise the minimum-norm ``d = −pinv(J) r`` with singular values
    ``<= rtol * s_max`` treated as zero (eq. 11).
    """
    U, s, Vt = np.linalg.svd(J if free.all() else J[:, free], full_matrices=False)
    Utr = U.T @ state.r
    d = np.zeros(state.x.size)
    if step == "levenberg_marquardt":
        if state.lam < 0:
            state.lam = _LM_TAU * float(np.max(np.sum(J * J, axis=0)))
        d[free] = -Vt.T @ (s / (s * s + state.lam) * Utr)
    else:
        inv = np.zeros_like(s)
        keep = s > rtol * (s[0] if s.size else 0.0)
        inv[keep] = 1.0 / s[keep]
        d[free] = -Vt.T @ (inv * Utr)
    return d


def _trial_step(
    call: _CheckedEvaluate,
    state: _LoopState,
    J: np.ndarray,
    g: np.ndarray,
    free: np.ndarray,
    d: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    step: str,
    method: str,
) -> _Trial | None:
    """The trial point of the step rule along ``d`` (shape (n,)), or ``None`` when none was accepted.

    ``J`` (M, n) and ``g = Jᵀr`` (n,) are taken at ``state.x``; ``free`` (n,) marks the free variables.
    """
    if step == "pinv":
        return _pinv_step(call, state, d, lo, hi, method)
    if step == "line_search":
        return _line_search_step(call, state, g, free, d, lo, hi)
    return _levenberg_marquardt_step(call, state, J, d, lo, hi)


def _pinv_step(
    call: _CheckedEvaluate, state: _LoopState, d: np.ndarray, lo: np.ndarray, hi: np.ndarray, method: str
) -> _Trial:
    """The full step ``clip(x + d)`` (eq. 11 and 15), always taken.

    Raises:
        SolverError: The residual is NaN/inf at the new point.
    """
    x_new = np.clip(state.x + d, lo, hi)
    r_new, J_new = call(x_new, False)
    if not np.all(np.isfinite(r_new)):
        raise SolverError(
            f"the residual became NaN/inf after the pseudo-inverse step of iteration "
            f"{state.iterations}; use step='line_search' or 'levenberg_marquardt'",
            method=method,
            x=x_new,
        )
    f_new = 0.5 * float(r_new @ r_new)
    return x_new, r_new, f_new, J_new, True


def _line_search_step(
    call: _CheckedEvaluate,
    state: _LoopState,
    g: np.ndarray,
    free: np.ndarray,
    d: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
) -> _Trial | None:
    """Armijo search along ``d``, then along projected steepest descent; ``None`` stops the loop."""
    found = _line_search(call, state.x, state.f, g, d, lo, hi)
    if found is None and np.any(d != -g):
        found = _line_search(call, state.x, state.f, g, _steepest(g, free, d), lo, hi)
    if found is None:
        state.converged = bool(np.linalg.norm(d) <= 1e-8 * (1.0 + np.linalg.norm(state.x)))
        state.message = "line search found no decrease (cost at its rounding floor)"
        state.history.append(state.f)
        state.done = True
    return found


def _levenberg_marquardt_step(
    call: _CheckedEvaluate, state: _LoopState, J: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> _Trial | None:
    """Damped step with Nielsen's update of ``λ``; ``None`` for a rejected step.

    A rejected step raises ``λ`` and records the unchanged cost; the loop stops (``done``)
    when ``λ`` overflows.
    """
    x, f = state.x, state.f
    x_new = np.clip(x + d, lo, hi)
    r_new, J_new = call(x_new, False)
    f_new = 0.5 * float(r_new @ r_new) if np.all(np.isfinite(r_new)) else np.inf
    lin = state.r + J @ (x_new - x)
    predicted = f - 0.5 * float(lin @ lin)
    rho = (f - f_new) / predicted if predicted > 0 and np.isfinite(f_new) else -1.0
    if rho <= 0:
        state.lam *= state.nu
        state.nu *= 2.0
        state.history.append(f)
        if not np.isfinite(state.lam) or state.lam > 1e300:
            state.message = "Levenberg–Marquardt damping overflowed without a decrease"
            state.done = True
        return None
    state.lam = max(state.lam * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 1e-300)
    state.nu = 2.0
    return x_new, r_new, f_new, J_new, rho > 0.25


def _accept(state: _LoopState, trial: _Trial, tol: float) -> bool:
    """Move ``state`` to the trial point; True when the step or cost-reduction test stops the loop."""
    x_new, r_new, f_new, J_new, full_step = trial
    dx = x_new - state.x
    f_old = state.f
    state.x, state.r, state.f, state.J = x_new, r_new, f_new, J_new
    state.history.append(state.f)
    if np.linalg.norm(dx) <= tol * (tol + np.linalg.norm(state.x)):
        state.converged, state.message = True, "step size <= tol"
        return True
    if full_step and 0.0 <= f_old - state.f <= tol * f_old:
        state.converged, state.message = True, "relative cost reduction <= tol"
        return True
    return False


def _final_diagnostics(
    call: _CheckedEvaluate, state: _LoopState, lo: np.ndarray, hi: np.ndarray, rtol: float
) -> dict[str, Any]:
    """:func:`jacobian_diagnostics` at the solution plus the loop's history and counts.

    ``message`` gains a note on the unidentifiable directions when ``J`` is rank-deficient.
    """
    J = state.J if state.J is not None else call.jacobian_at(state.x)
    n = state.x.size
    diagnostics = jacobian_diagnostics(J, rtol)
    message = state.message
    if diagnostics["rank"] < n:
        message += (
            f"; Jacobian rank {diagnostics['rank']} < {n} unknowns "
            f"(condition number {diagnostics['condition_number']:.3g}): the directions in "
            "diagnostics['unidentifiable_directions'] are not determined by the data"
        )
    diagnostics.update(
        cost_history=np.asarray(state.history),
        gradient_cosine=float(state.gcos),
        rms_residual=float(np.sqrt(2.0 * state.f / state.M)) if state.M else 0.0,
        active_bounds=(state.x <= lo) | (state.x >= hi),
        n_residual_evaluations=call.n_r,
        n_jacobian_evaluations=call.n_J,
        message=message,
    )
    return diagnostics


def jacobian_diagnostics(J: np.ndarray, rtol: float) -> dict[str, Any]:
    """Singular values, condition number, rank and null space of a Jacobian.

    Args:
        J: Jacobian, shape (M, n).
        rtol: Singular values ``<= rtol * s_max`` count as zero for the rank.

    Returns:
        ``singular_values`` (descending, shape (n,); zeros padded when M < n),
        ``condition_number`` (``inf`` when the smallest is zero), ``rank`` and
        ``unidentifiable_directions`` (shape (n − rank, n)).
    """
    n = J.shape[1]
    if J.shape[0] < n:  # pad with zero rows so that Vt spans the whole of R^n
        J = np.vstack([J, np.zeros((n - J.shape[0], n))])
    _, s, Vt = np.linalg.svd(J, full_matrices=False)
    s_full = np.zeros(n)
    s_full[: s.size] = s
    s_max = s_full[0] if n else 0.0
    rank = int(np.count_nonzero(s_full > rtol * s_max)) if s_max > 0 else 0
    cond = float(s_max / s_full[-1]) if n and s_full[-1] > 0 else float(np.inf)
    return {
        "singular_values": s_full,
        "condition_number": cond,
        "rank": rank,
        "unidentifiable_directions": Vt[rank:].copy(),
    }


def _gradient_cosine(J: np.ndarray, r: np.ndarray, g: np.ndarray, free: np.ndarray) -> float:
    """MINPACK's gradient test: max over free columns of |J_jᵀ r| / (||J_j|| ||r||)."""
    r_norm = float(np.linalg.norm(r))
    if r_norm == 0.0 or not np.any(free):
        return 0.0
    col = np.linalg.norm(J[:, free], axis=0)
    ok = col > 0
    if not np.any(ok):
        return 0.0
    return float(np.max(np.abs(g[free][ok]) / (col[ok] * r_norm)))


def _steepest(g: np.ndarray, free: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Projected steepest-descent direction with the length of ``d``."""
    sd = np.where(free, -g, 0.0)
    norm = np.linalg.norm(sd)
    return sd if norm == 0 else sd * (np.linalg.norm(d) / norm if np.any(d) else 1.0 / norm)


def _line_search(
    call: Callable[[np.ndarray, bool], tuple[np.ndarray, np.ndarray | None]],
    x: np.ndarray,
    f: float,
    g: np.ndarray,
    d: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, float, np.ndarray | None, bool] | None:
    """Backtracking Armijo search on the projected path ``clip(x + t d)``.

    Returns:
        ``(x_t, r_t, f_t, J_t or None, t == 1)`` for the first accepted ``t`` in
        1, 1/2, 1/4, …, or ``None`` when no trial decreased the cost. Trials with a
        non-finite residual are rejected.
    """
    t = 1.0
    for _ in range(_MAX_BACKTRACKS):
        x_t = np.clip(x + t * d, lo, hi)
        r_t, J_t = call(x_t, False)
        if np.all(np.isfinite(r_t)):
            f_t = 0.5 * float(r_t @ r_t)
            decrease = float(g @ (x_t - x))
            if decrease < 0 and f_t <= f + _ARMIJO_C1 * decrease:
                return x_t, r_t, f_t, J_t, t == 1.0
        t *= 0.5
    return None
