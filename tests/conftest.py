"""Shared fixtures: simulated trials (cached per session)."""

from __future__ import annotations

import pytest
from simcache import cached_simulation

from lowerlimb.simulation import ImuNoise, Simulation


@pytest.fixture(scope="session")
def walk_clean() -> Simulation:
    return cached_simulation("walk", 20.0, 0, noise=ImuNoise.none())


@pytest.fixture(scope="session")
def walk_noisy() -> Simulation:
    return cached_simulation("walk", 60.0, 1)
