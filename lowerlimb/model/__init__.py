"""The leg model: anthropometry, geometry, the Pinocchio leg, the calibrated leg and the URDF templates."""

from lowerlimb.model.calibrated import calibrated_geometry, chain_positions
from lowerlimb.model.geometry import LegGeometry
from lowerlimb.model.leg_model import LegModel
from lowerlimb.model.lower_body import LowerBodyGeometry, lower_body_urdf

__all__ = [
    "LegGeometry",
    "LegModel",
    "LowerBodyGeometry",
    "calibrated_geometry",
    "chain_positions",
    "lower_body_urdf",
]
