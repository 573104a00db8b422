"""Joint constraints: residuals and Jacobians of the spherical and hinge joints (Hu et al. 2021)."""

from lowerlimb.constraints.angular_acceleration import angular_acceleration, smooth
from lowerlimb.constraints.hinge import (
    angles_from_axis,
    axis_from_angles,
    hinge_acc_residual,
    hinge_casadi,
    hinge_jacobian,
    hinge_residual,
    hinge_residual_population,
)
from lowerlimb.constraints.spherical import (
    SphericalData,
    joint_acceleration,
    spherical_casadi,
    spherical_jacobian,
    spherical_jacobian_3d,
    spherical_residual,
    spherical_residual_3d,
    spherical_residual_population,
)

__all__ = [
    "SphericalData",
    "angles_from_axis",
    "angular_acceleration",
    "axis_from_angles",
    "hinge_acc_residual",
    "hinge_casadi",
    "hinge_jacobian",
    "hinge_residual",
    "hinge_residual_population",
    "joint_acceleration",
    "smooth",
    "spherical_casadi",
    "spherical_jacobian",
    "spherical_jacobian_3d",
    "spherical_residual",
    "spherical_residual_3d",
    "spherical_residual_population",
]
