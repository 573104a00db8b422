"""Domain-free optimisers: Gauss–Newton, DWPSO, GWO, CasADi least squares, swarm + refine.

Never imports ``lowerlimb``. Every solver returns one :class:`SolverResult` and raises one
:class:`SolverError`; a problem is one :class:`LeastSquaresProblem`; reference
problems with known answers are in :mod:`solvers.problems`.
"""

from solvers.casadi_lsq import casadi_lsq
from solvers.dwpso import DWPSOParams, dwpso
from solvers.errors import SolverError
from solvers.gauss_newton import gauss_newton
from solvers.gwo import GWOParams, gwo
from solvers.problem import LeastSquaresProblem
from solvers.refine import swarm_then_refine
from solvers.result import SolverResult

__all__ = [
    "DWPSOParams",
    "GWOParams",
    "LeastSquaresProblem",
    "SolverError",
    "SolverResult",
    "casadi_lsq",
    "dwpso",
    "gauss_newton",
    "gwo",
    "swarm_then_refine",
]
