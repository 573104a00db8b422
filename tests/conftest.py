"""Shared fixtures: simulated trials (cached per session); required tests may not skip in CI."""

from __future__ import annotations

import signal

import blas_threads  # noqa: F401  (before numpy: one BLAS thread per worker)
import pytest
from required_skips import pytest_configure, pytest_runtest_makereport  # noqa: F401  (hooks)
from simcache import cached_simulation

from lowerlimb.simulation import ImuNoise, Simulation

# A suite started in the background of a non-interactive shell (`pytest &`, nohup) inherits
# an ignored SIGINT, and so would every command it starts: the Ctrl-C tests would find their
# signal ignored. A handled signal is reset to the default in a child at exec.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def walk_clean() -> Simulation:
    return cached_simulation("walk", 20.0, 0, noise=ImuNoise.none())


@pytest.fixture(scope="session")
def walk_noisy() -> Simulation:
    return cached_simulation("walk", 60.0, 1)
