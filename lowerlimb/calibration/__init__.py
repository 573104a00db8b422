"""Joint-constraint sensor-to-segment calibration (Hu et al. 2021): centres, hinge axes, the leg."""

from lowerlimb.calibration.excitation import ExcitationReport, ExcitationWarning
from lowerlimb.calibration.hinge_axis import calibrate_hinge_axis, estimate_hinge_axis
from lowerlimb.calibration.hinge_joint import calibrate_hinge_joint
from lowerlimb.calibration.joint_center import calibrate_spherical_joint, estimate_joint_center
from lowerlimb.calibration.leg import LegCalibration, calibrate_leg
from lowerlimb.calibration.options import METHODS, CalibrationOptions
from lowerlimb.calibration.results import (
    HingeAxisCalibration,
    HingeJointCalibration,
    SphericalJointCalibration,
)

__all__ = [
    "METHODS",
    "CalibrationOptions",
    "ExcitationReport",
    "ExcitationWarning",
    "HingeAxisCalibration",
    "HingeJointCalibration",
    "LegCalibration",
    "SphericalJointCalibration",
    "calibrate_hinge_axis",
    "calibrate_hinge_joint",
    "calibrate_leg",
    "calibrate_spherical_joint",
    "estimate_hinge_axis",
    "estimate_joint_center",
]
