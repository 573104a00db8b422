"""The one exception of the ``solvers`` package: the base of every error a solver raises on purpose.

``solvers`` is domain-free and never imports ``lowerlimb``; a caller that owns a
domain wraps this error in its own (``lowerlimb.errors.SolverError`` does, chained
with ``from``, keeping :attr:`SolverError.method` and :attr:`SolverError.x`).
"""

from __future__ import annotations

import numpy as np


class SolverError(RuntimeError):
    """A solver could not run to the end: a non-finite evaluation or a backend failure.

    CasADi and IPOPT exceptions are wrapped in this class and chained (``raise ... from e``),
    so callers never catch backend exception types.

    Attributes:
        method: Name of the solver that failed, e.g. ``"casadi_lsq/gauss_newton"``.
        x: The point at which the failure happened (copy), shape (n,), or ``None`` when
            unknown.
    """

    def __init__(self, message: str, *, method: str, x: np.ndarray | None = None) -> None:
        self.method = method
        self.x = None if x is None else np.array(x, dtype=float, copy=True)
        super().__init__(f"{method}: {message}")
