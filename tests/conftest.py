"""Shared fixtures: simulated trials (cached per session); required tests may not skip in CI."""

from __future__ import annotations

import pytest
from required_skips import pytest_configure, pytest_runtest_makereport  # noqa: F401  (hooks)
from simcache import cached_simulation

from lowerlimb.simulation import ImuNoise, Simulation


@pytest.fixture(scope="session")
def walk_clean() -> Simulation:
    return cached_simulation("walk", 20.0, 0, noise=ImuNoise.none())


@pytest.fixture(scope="session")
def walk_noisy() -> Simulation:
    return cached_simulation("walk", 60.0, 1)
