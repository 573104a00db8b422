"""Nonlinear least squares on a CasADi residual: Gauss–Newton in numpy, or IPOPT.

Two forms of residual are accepted:

- **per sample** (fast path): ``residual(x, p_k) -> r_k`` with ``p_k`` one column of the data
  matrix ``params`` of shape (k, N). The residual and its Jacobian are differentiated per
  sample (in SX when the function can be expanded) and mapped over the N columns with
  ``Function.map(..., reduce_in=[x])``, so a Jacobian costs about one residual evaluation;
- **whole**: ``residual(x[, p]) -> r`` with ``p`` exactly the shape of the function's second
  input (e.g. a user's own ``Function.map``). Correct, but CasADi's AD through a mapped
  residual with a broadcast ``x`` is 10–40× slower than the per-sample form.

Built functions are cached per residual ``Function`` object (and data shape), so repeated
solves with new data reuse them. Evaluations go through ``Function.buffer()`` on numpy
memory: no DM conversion per iteration.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import casadi
import numpy as np
from numpy.typing import ArrayLike

from solvers._checks import as_bounds, as_vector, check_inside
from solvers.errors import SolverError
from solvers.gauss_newton import STEPS, Step, jacobian_diagnostics, least_squares_core
from solvers.result import SolverResult

Backend = Literal["gauss_newton", "ipopt"]

_CACHE_SIZE = 16
_CACHE: OrderedDict[tuple[object, ...], tuple[casadi.Function, casadi.Function]] = OrderedDict()
_JIT_OPTIONS: dict[str, Any] = {
    "jit": True,
    "compiler": "shell",
    "jit_options": {"flags": ["-O2"], "verbose": False},
}
_IPOPT_ERRORS = {
    "Invalid_Number_Detected",
    "Invalid_Problem_Definition",
    "Invalid_Option",
    "Internal_Error",
    "Unrecoverable_Exception",
    "NonIpopt_Exception_Thrown",
    "Insufficient_Memory",
}


def casadi_lsq(
    residual: casadi.Function,
    x0: ArrayLike,
    *,
    params: ArrayLike | None = None,
    solver: Backend = "gauss_newton",
    lower: ArrayLike | None = None,
    upper: ArrayLike | None = None,
    max_iter: int = 50,
    tol: float = 1e-12,
    step: Step = "line_search",
    jit: bool = False,
) -> SolverResult:
    """Minimise ``0.5 * ||r(x)||²`` for a CasADi residual (Hu et al. 2021, eq. 7 and 12).

    ``solver="gauss_newton"`` runs :func:`~solvers.gauss_newton.least_squares_core` (the
    pseudo-inverse step of eq. 11 with a line search by default) on numpy arrays filled by
    one compiled CasADi function that returns ``r`` and ``J = dr/dx`` together.
    ``solver="ipopt"`` calls ``nlpsol("ipopt")`` on ``f = 0.5 rᵀr`` with the Gauss–Newton
    Hessian ``JᵀJ`` (option ``hess_lag``), silent (``print_level 0``, no timings).

    Args:
        residual: CasADi function ``(x) -> r`` or ``(x, p) -> r``; ``x`` a dense vector of n
            unknowns; only the first output is used, flattened column-major. With ``params``
            of shape (k, N) and a second input of shape (k, 1), the function is taken per
            sample (``r`` stacked sample by sample, M = N·m); see the module docstring.
        x0: Initial estimate, shape (n,); must lie inside the bounds.
        params: Data: shape (k, N) with one sample per column (per-sample form), or exactly
            the shape of the second input (whole form); ``None`` when ``residual`` takes x only.
        solver: ``"gauss_newton"`` or ``"ipopt"``.
        lower: Lower bounds, scalar or shape (n,); ``None`` for unbounded.
        upper: Upper bounds, scalar or shape (n,); ``None`` for unbounded.
        max_iter: Maximum iterations (Gauss–Newton steps or IPOPT iterations).
        tol: Gauss–Newton: tolerance of the stopping tests of
            :func:`~solvers.gauss_newton.gauss_newton`. IPOPT: its ``tol`` (scaled NLP error),
            with ``acceptable_tol = max(1e3 * tol, 1e-8)``.
        step: Gauss–Newton step rule (``"line_search"``, ``"pinv"``,
            ``"levenberg_marquardt"``); ignored by IPOPT.
        jit: Compile the residual and Jacobian to C with the system compiler (about 0.2–1 s
            once per residual function and data size, then 3–5× faster evaluations).

    Returns:
        ``x`` shape (n,), ``cost = 0.5 * sum(r**2)``. ``diagnostics`` has
        ``singular_values``, ``condition_number``, ``rank``, ``unidentifiable_directions``
        of ``J`` at the solution, ``n_residuals`` (M), ``build_time_s`` (time spent building
        or fetching CasADi functions, included in ``wall_time_s``) and ``message``; Gauss–Newton
        adds its own (``cost_history`` …), IPOPT adds ``return_status``.

    Raises:
        ValueError: Bad ``x0``, bounds, options, or shapes of ``residual``/``params``.
        SolverError: The residual or Jacobian is NaN/inf at ``x0`` (e.g. NaN in ``params``),
            CasADi fails to build or evaluate the functions (also JIT compilation), or IPOPT
            stops with an error status (``Invalid_Number_Detected`` …). CasADi's exception is
            chained as ``__cause__``.
    """
    t_start = time.perf_counter()
    method = f"casadi_lsq/{solver}"
    if not isinstance(residual, casadi.Function):
        raise ValueError(f"residual must be a casadi.Function, got {type(residual).__name__}")
    if solver not in ("gauss_newton", "ipopt"):
        raise ValueError(f"unknown solver {solver!r}; choose 'gauss_newton' or 'ipopt'")
    if step not in STEPS:
        raise ValueError(f"unknown step {step!r}; choose one of {STEPS}")
    x_init = as_vector(x0, "x0")
    layout = _layout(residual, x_init.size, params)
    lo, hi = as_bounds(lower, upper, layout.n)
    check_inside(x_init, lo, hi)

    p_flat = layout.flat_params(params)
    model = _cached(("rj", layout.key, jit), residual, lambda: _build_rj(residual, layout, jit))
    evaluator = _BufferedEvaluator(model, layout, p_flat, method)
    if solver == "ipopt":
        return _solve_ipopt(
            residual, layout, evaluator, p_flat, x_init, lo, hi, max_iter, tol, t_start, method
        )
    build_time = time.perf_counter() - t_start
    result = least_squares_core(
        evaluator,
        x_init,
        max_iter=max_iter,
        tol=tol,
        step=step,
        lower=lo,
        upper=hi,
        rcond=None,
        method=method,
    )
    result.diagnostics.update(n_residuals=layout.M, build_time_s=build_time)
    return SolverResult(
        x=result.x,
        cost=result.cost,
        iterations=result.iterations,
        wall_time_s=time.perf_counter() - t_start,
        converged=result.converged,
        method=method,
        diagnostics=result.diagnostics,
    )


@dataclass(frozen=True)
class _Layout:
    """How a residual is evaluated: sizes and the form (per-sample or whole)."""

    n: int
    per_sample: bool
    k: int  # rows of p (0 when no p)
    n_samples: int  # N for per-sample, 1 otherwise
    p_shape: tuple[int, int] | None
    m: int  # residuals per sample (per-sample) or M (whole)

    @property
    def M(self) -> int:
        return self.m * self.n_samples

    @property
    def P_shape(self) -> tuple[int, int] | None:
        """Shape of the whole data matrix passed per call, or None without data."""
        if self.p_shape is None:
            return None
        return (self.k, self.n_samples) if self.per_sample else self.p_shape

    @property
    def key(self) -> tuple[object, ...]:
        return (self.per_sample, self.n_samples, self.p_shape)

    def flat_params(self, params: ArrayLike | None) -> np.ndarray | None:
        if params is None:
            return None
        p = np.asarray(params, dtype=float)
        p = p.reshape(-1, 1) if p.ndim == 1 else p
        return np.asfortranarray(p).ravel(order="F")


def _layout(residual: casadi.Function, n_x0: int, params: ArrayLike | None) -> _Layout:
    """Check the residual's signature against ``x0`` and ``params``; pick the form."""
    if residual.n_in() not in (1, 2) or residual.n_out() < 1:
        raise ValueError(
            f"residual must map (x) or (x, p) to r; {residual.name()!r} has "
            f"{residual.n_in()} inputs and {residual.n_out()} outputs"
        )
    sp_x = residual.sparsity_in(0)
    vector = sp_x.is_vector() and sp_x.numel() == n_x0
    broadcast = sp_x.size1() == n_x0  # (n, K), e.g. from Function.map(K): x is repeated
    if not (sp_x.is_dense() and (vector or broadcast)):
        raise ValueError(
            f"residual's first input must be a dense vector of the {n_x0} unknowns of x0 "
            f"(or ({n_x0}, K) from Function.map); it has shape {residual.size_in(0)}"
        )
    m_out = int(residual.numel_out(0))
    if residual.n_in() == 1:
        if params is not None:
            raise ValueError("residual takes x only, but params were given; drop params")
        return _Layout(n_x0, False, 0, 1, None, m_out)
    if params is None:
        raise ValueError(
            f"residual takes (x, p) with p of shape {residual.size_in(1)}; pass params "
            "(one sample per column for a per-sample residual)"
        )
    p = np.asarray(params, dtype=float)
    shape = (p.shape[0], 1) if p.ndim == 1 else p.shape
    p_in = tuple(int(v) for v in residual.size_in(1))
    if len(shape) != 2:
        raise ValueError(f"params must be a matrix (k, N), got shape {p.shape}")
    if shape == p_in:
        return _Layout(n_x0, False, p_in[0], 1, (p_in[0], p_in[1]), m_out)
    if p_in[1] == 1 and shape[0] == p_in[0]:
        return _Layout(n_x0, True, p_in[0], int(shape[1]), (p_in[0], 1), m_out)
    raise ValueError(
        f"params has shape {shape}, but the residual's p input has shape {p_in}: pass "
        f"params of shape {p_in}, or ({p_in[0]}, N) with one sample per column for a "
        f"per-sample residual (p input of shape ({p_in[0]}, 1))"
    )


def _cached(
    key: tuple[object, ...], residual: casadi.Function, build: Callable[[], casadi.Function]
) -> casadi.Function:
    """Small LRU cache keyed on the residual object's identity (held, so ids stay unique)."""
    full_key = (id(residual), *key)
    hit = _CACHE.get(full_key)
    if hit is not None and hit[0] is residual:
        _CACHE.move_to_end(full_key)
        return hit[1]
    value = build()
    _CACHE[full_key] = (residual, value)
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return value


def _per_sample_rj(residual: casadi.Function, layout: _Layout) -> casadi.Function:
    """``(x[, p]) -> (r, J)`` for one sample (expanded to SX when possible) or the whole residual."""
    fun = residual
    if layout.per_sample and fun.is_a("MXFunction"):  # small: expand to SX, faster
        try:
            fun = fun.expand()
        except RuntimeError:
            pass  # not expandable (e.g. calls an external function): stay in MX
    sym: Any = casadi.SX.sym if fun.is_a("SXFunction") else casadi.MX.sym
    args: list[Any] = [sym("x", layout.n)]
    if layout.p_shape is not None:
        args.append(sym("p", *layout.p_shape))
    r = casadi.densify(casadi.vec(fun.call(args)[0]))
    J = casadi.densify(casadi.jacobian(r, args[0]))
    return casadi.Function("lsq_rj", args, [r, J])


def _mx_args(layout: _Layout) -> list[Any]:
    args: list[Any] = [casadi.MX.sym("x", layout.n)]
    if layout.P_shape is not None:
        args.append(casadi.MX.sym("P", *layout.P_shape))
    return args


def _build_rj(residual: casadi.Function, layout: _Layout, jit: bool) -> casadi.Function:
    """One function ``(x[, P]) -> (r, J)`` over all samples; J layout: see _BufferedEvaluator."""
    try:
        rj = _per_sample_rj(residual, layout)
        if layout.per_sample:
            rj = rj.map("lsq_rj_map", "serial", layout.n_samples, [0], [])
        if jit:
            args = _mx_args(layout)
            rj = casadi.Function("lsq_rj_jit", args, rj.call(args), _JIT_OPTIONS)
        return rj
    except RuntimeError as e:
        hint = " (JIT needs a working C compiler; retry with jit=False)" if jit else ""
        raise SolverError(f"building the residual/Jacobian failed{hint}: {e}", method="casadi_lsq") from e


class _BufferedEvaluator:
    """``evaluate(x, need_jacobian) -> (r, J)`` on numpy memory via ``Function.buffer()``.

    The Jacobian comes with every residual evaluation (one compiled function), so trial
    points of the line search return it too.
    """

    def __init__(self, fun: casadi.Function, layout: _Layout, p_flat: np.ndarray | None, method: str) -> None:
        self._layout = layout
        self._method = method
        self._x = np.zeros(layout.n)
        self._p = p_flat  # held: the buffer points into it
        self._r = np.empty(layout.M)
        self._J = np.empty(layout.M * layout.n)
        buf: Any  # the stubs list a size argument that the binding does not take
        buf, self._eval = fun.buffer()
        buf.set_arg(0, self._x.data)
        if p_flat is not None:
            buf.set_arg(1, p_flat.data)
        buf.set_res(0, self._r.data)
        buf.set_res(1, self._J.data)
        self._buf = buf

    def __call__(self, x: np.ndarray, need_jacobian: bool = True) -> tuple[np.ndarray, np.ndarray]:
        self._x[:] = x
        try:
            self._eval()
        except RuntimeError as e:
            raise SolverError(f"CasADi evaluation failed: {e}", method=self._method, x=x) from e
        lay = self._layout
        J: np.ndarray
        if lay.per_sample:  # map output m × (n N): memory [sample][unknown][row of r_k]
            J = self._J.reshape(lay.n_samples, lay.n, lay.m).transpose(0, 2, 1)
        else:  # column-major (M, n)
            J = self._J.reshape(lay.n, lay.M).T
        # copies: the buffers are overwritten by the next evaluation
        return self._r.copy(), np.array(J.reshape(lay.M, lay.n), copy=True)


def _solve_ipopt(
    residual: casadi.Function,
    layout: _Layout,
    evaluator: _BufferedEvaluator,
    params: np.ndarray | None,
    x_init: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    max_iter: int,
    tol: float,
    t_start: float,
    method: str,
) -> SolverResult:
    """IPOPT on f = 0.5 rᵀr with a Gauss–Newton Hessian; see :func:`casadi_lsq`."""
    if int(max_iter) != max_iter or max_iter < 0:
        raise ValueError(f"max_iter must be a non-negative integer, got {max_iter}")
    if not tol > 0:
        raise ValueError(f"IPOPT needs tol > 0, got {tol}")
    r0, J0 = evaluator(x_init)
    if not np.all(np.isfinite(r0)):
        raise SolverError(
            f"the residual is NaN/inf at the initial point ({np.count_nonzero(~np.isfinite(r0))}"
            f" of {r0.size} entries); check the data for NaN and the residual for divisions by "
            "zero, or start from another x0",
            method=method,
            x=x_init,
        )
    if not np.all(np.isfinite(J0)):
        raise SolverError(
            f"the Jacobian contains NaN/inf ({np.count_nonzero(~np.isfinite(J0))} entries) at "
            f"x0 = {x_init}; check the Jacobian for divisions by zero (e.g. the derivative of a "
            "norm at 0) or start from another x0",
            method=method,
            x=x_init,
        )
    key = ("ipopt", layout.key, int(max_iter), float(tol))
    nlp = _cached(key, residual, lambda: _build_ipopt(residual, layout, int(max_iter), tol))
    args: dict[str, Any] = {"x0": x_init, "lbx": lo, "ubx": hi}
    if params is not None and layout.P_shape is not None:
        args["p"] = casadi.DM(params.reshape(layout.P_shape, order="F"))
    build_time = time.perf_counter() - t_start
    try:
        sol = nlp(**args)
    except RuntimeError as e:
        raise SolverError(f"IPOPT failed: {e}", method=method, x=x_init) from e
    stats = nlp.stats()
    status = str(stats.get("return_status", "unknown"))
    x = np.clip(np.asarray(sol["x"].full(), dtype=float).ravel(), lo, hi)
    if status in _IPOPT_ERRORS:
        raise SolverError(
            f"IPOPT stopped with status {status}; for Invalid_Number_Detected check the "
            "residual for NaN/inf (divisions by zero, norms at 0) inside the bounds",
            method=method,
            x=x,
        )
    r, J = evaluator(x)
    diagnostics = jacobian_diagnostics(J, max(J.shape) * float(np.finfo(float).eps))
    diagnostics.update(
        return_status=status,
        rms_residual=float(np.sqrt(np.mean(r * r))) if r.size else 0.0,
        n_residuals=layout.M,
        build_time_s=build_time,
        message=status,
    )
    return SolverResult(
        x=x,
        cost=0.5 * float(r @ r),
        iterations=int(stats.get("iter_count", 0)),
        wall_time_s=time.perf_counter() - t_start,
        converged=bool(stats.get("success", False)),
        method=method,
        diagnostics=diagnostics,
    )


def _build_ipopt(residual: casadi.Function, layout: _Layout, max_iter: int, tol: float) -> casadi.Function:
    """``nlpsol`` for f = 0.5 rᵀr with gradient Jᵀr and Gauss–Newton Hessian σ JᵀJ.

    ``f``, ``Jᵀr`` and ``JᵀJ`` are computed per sample and summed by
    ``map(..., reduce_out)``; the gradient and Hessian are given to IPOPT as the options
    ``grad_f`` and ``hess_lag`` so that no AD runs through the map.
    """
    try:
        rj = _per_sample_rj(residual, layout)
        sym: Any = casadi.SX.sym if rj.is_a("SXFunction") else casadi.MX.sym
        xs = sym("x", layout.n)
        ins: list[Any] = [xs] if layout.p_shape is None else [xs, sym("p", *layout.p_shape)]
        r, J = rj.call(ins)
        f_k = 0.5 * casadi.dot(r, r)
        parts = {
            "f": casadi.Function("lsq_f", ins, [f_k]),
            "fg": casadi.Function("lsq_fg", ins, [f_k, casadi.mtimes(J.T, r)]),
            "h": casadi.Function("lsq_gnh", ins, [casadi.mtimes(J.T, J)]),
        }
        if layout.per_sample:
            for name, fun in parts.items():
                n_out = fun.n_out()
                parts[name] = fun.map(
                    f"{fun.name()}_map", "serial", layout.n_samples, [0], list(range(n_out))
                )
        args = _mx_args(layout)
        x = args[0]
        p_sym = args[1] if len(args) > 1 else casadi.MX.sym("p", 0, 1)
        lam_f = casadi.MX.sym("lam_f")
        lam_g = casadi.MX.sym("lam_g", 0, 1)
        (JtJ,) = parts["h"].call(args)
        hess = casadi.Function("lsq_gn_hess", [x, p_sym, lam_f, lam_g], [casadi.triu(lam_f * JtJ)])
        grad = casadi.Function("lsq_grad_f", [x, p_sym], parts["fg"].call(args))
        nlp: dict[str, Any] = {"x": x, "f": parts["f"].call(args)[0]}
        if len(args) > 1:
            nlp["p"] = p_sym
        opts: dict[str, Any] = {
            "print_time": False,
            "error_on_fail": False,
            "grad_f": grad,
            "hess_lag": hess,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.max_iter": max_iter,
            "ipopt.tol": tol,
            "ipopt.acceptable_tol": max(1e3 * tol, 1e-8),
        }
        return casadi.nlpsol("lsq_ipopt", "ipopt", nlp, opts)
    except RuntimeError as e:
        raise SolverError(f"building the IPOPT problem failed: {e}", method="casadi_lsq/ipopt") from e
