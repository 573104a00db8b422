"""Segment-to-joint (S2J) vectors and relative positions (Lee & Lee 2022).

Constant (M1) or joint-angle-dependent (M2, M3) vectors from each sensor to
the hip, knee and ankle centres; the reference Kalman filter that produces
their learning data (eq. 4–6); the relative positions of eq. 2–3.
"""

from __future__ import annotations

from lowerlimb.s2j.model import (
    REGRESSION_INPUTS,
    S2JModel,
    constant_s2j_from_calibration,
    reference_s2j_from_poses,
)
from lowerlimb.s2j.reference_kf import ReferenceKFParams, ReferenceS2J, estimate_reference_s2j
from lowerlimb.s2j.regression import KernelRegression, KernelRegressionParams, fit_kernel_regression
from lowerlimb.s2j.relative_position import (
    RELATIVE_POSITIONS,
    chain_position,
    reference_relative_position,
    reference_segment_relative_positions,
    relative_position,
    relative_rotation,
    segment_relative_positions,
)

__all__ = [
    "REGRESSION_INPUTS",
    "RELATIVE_POSITIONS",
    "KernelRegression",
    "KernelRegressionParams",
    "ReferenceKFParams",
    "ReferenceS2J",
    "S2JModel",
    "chain_position",
    "constant_s2j_from_calibration",
    "estimate_reference_s2j",
    "fit_kernel_regression",
    "reference_relative_position",
    "reference_s2j_from_poses",
    "reference_segment_relative_positions",
    "relative_position",
    "relative_rotation",
    "segment_relative_positions",
]
