"""One BLAS/OpenMP thread per test process; conftest imports this before numpy.

The suite runs one pytest-xdist worker per core, and threaded BLAS on the small matrices
of these tests only oversubscribes the cores (the suite took 7.9 instead of 6.4 minutes
on 2 cores). A variable the caller has set is kept.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
