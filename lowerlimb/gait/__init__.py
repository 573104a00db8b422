"""Gait events, foot trajectories and spatio-temporal parameters from leg IMUs (docs/formats.md, "Two legs").

Stages: :func:`detect_gait_events` (foot gyro → initial contact, shank gyro without one;
shank gyro → toe-off; foot IMU → stationary periods) → :func:`integrate_foot` (strapdown +
zero-velocity updates) → :func:`compute_gait_parameters` → :func:`write_events_csv`, :func:`write_gait_json`.
Every threshold is in :class:`GaitParams`.
"""

from lowerlimb.gait.contacts import Contacts, foot_contacts, heading_change_rad, walking_direction
from lowerlimb.gait.errors import GaitSignalError, NoGaitCyclesError
from lowerlimb.gait.events import GaitEvents, SideEvents, detect_gait_events, detect_side_events
from lowerlimb.gait.parameters import FootAnchor, GaitParameters, Stride, compute_gait_parameters
from lowerlimb.gait.params import GaitParams
from lowerlimb.gait.sagittal import SagittalRate, sagittal_rate
from lowerlimb.gait.stationary import StationaryPeriods, detect_stationary
from lowerlimb.gait.trajectory import FootTrajectory, integrate_foot
from lowerlimb.gait.writers import (
    EVENTS_COLUMNS,
    STATIONARY_COLUMNS,
    write_events_csv,
    write_gait_json,
    write_stationary_csv,
)

__all__ = [
    "EVENTS_COLUMNS",
    "Contacts",
    "FootAnchor",
    "FootTrajectory",
    "GaitEvents",
    "GaitParameters",
    "GaitParams",
    "GaitSignalError",
    "NoGaitCyclesError",
    "SagittalRate",
    "SideEvents",
    "Stride",
    "StationaryPeriods",
    "compute_gait_parameters",
    "detect_gait_events",
    "detect_side_events",
    "detect_stationary",
    "foot_contacts",
    "heading_change_rad",
    "integrate_foot",
    "sagittal_rate",
    "walking_direction",
    "write_events_csv",
    "write_stationary_csv",
    "STATIONARY_COLUMNS",
    "write_gait_json",
]
