"""The IMU simulator: the referee every estimator is tested against."""

from .motions import MOTIONS
from .noise import ImuNoise, SoftTissue
from .simulator import Simulation, simulate

__all__ = ["MOTIONS", "ImuNoise", "Simulation", "SoftTissue", "simulate"]
