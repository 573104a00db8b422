"""A two-leg trial from two simulated legs that share one pelvis (import as ``bilateral_sim``).

The simulator models one leg. Two runs with the same seed and motion draw the same
pelvis motion (the walk's pelvis path does not depend on the leg, and the right leg's
run is asked not to mirror it: ``mirror_pelvis=False``); given the same
pelvis sensor placement (``geometry=``) the two pelvis IMUs are then identical, noise
included, and the thigh/shank/foot IMUs of the two runs are the two legs of one body.
Both legs move in phase (the simulator has one leg's motion), which the calibration
does not mind; gait parameters of such a "hopping" trial are not meaningful.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from lowerlimb.conventions import SIDES, FloatArray, quat_to_matrix
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.model.geometry import LegGeometry
from lowerlimb.simulation import Simulation, simulate
from lowerlimb.simulation.placements import random_placements


@dataclass(frozen=True)
class TwoLegSimulation:
    """The joined trial, each leg's simulation, and the true left foot → right foot vector."""

    trial: BilateralTrial
    sims: dict[str, Simulation]
    left_foot_to_right_foot_m: FloatArray  # (N, 3) pelvis sensor frame


@lru_cache(maxsize=4)
def simulate_two_legs(seed: int = 3, duration_s: float = 30.0, motion: str = "walk") -> TwoLegSimulation:
    """Simulate a left and a right leg sharing the pelvis (module docstring)."""
    rng = np.random.default_rng(seed + 1000)
    geo = {}
    for side in SIDES:
        g = LegGeometry.from_anthropometry(side)
        g.sensor_placements = random_placements(g, rng)
        geo[side] = g
    geo["right"].sensor_placements["pelvis"] = geo["left"].sensor_placements["pelvis"].copy()
    sims = {
        s: simulate(motion, duration_s, seed, side=s, geometry=geo[s], mirror_pelvis=False) for s in SIDES
    }
    trial = BilateralTrial.from_legs(sims["left"].trial, sims["right"].trial)
    Rp = quat_to_matrix(sims["left"].quat_wxyz["pelvis"])
    d = sims["right"].sensor_pos_m["foot"] - sims["left"].sensor_pos_m["foot"]
    return TwoLegSimulation(trial, sims, np.einsum("nji,nj->ni", Rp, d))
