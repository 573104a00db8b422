"""The leg model: anthropometry, geometry, the Pinocchio leg, the calibrated leg and the URDF templates."""

from lowerlimb.model.calibrated import calibrated_geometry, chain_positions
from lowerlimb.model.geometry import LegGeometry
from lowerlimb.model.leg_model import LegModel

__all__ = ["LegGeometry", "LegModel", "calibrated_geometry", "chain_positions"]
