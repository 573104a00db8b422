"""The sagittal angular velocity of a shank (or foot) gyro, with the axis found from the data.

During walking the shank rotates mostly about the medio-lateral axis, so the
principal axis of the gyro samples (eigenvector of the largest eigenvalue of
their second-moment matrix) is the sagittal rotation axis whatever the sensor
mounting. Only walking samples enter the fit: those whose low-passed gyro norm
exceeds :attr:`GaitParams.walking_gyro_rps`. The eigenvector's sign is free;
it is fixed so that mid-swing is a *positive* peak: in the strongly low-passed
projection (:attr:`GaitParams.midswing_lowpass_hz`) the largest excursion of a
gait cycle is the mid-swing forward swing of the shank (several rad/s), larger
than any backward rotation in stance, so the sign makes the 99th percentile of
the projection exceed the 99th percentile of its negative.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray
from lowerlimb.gait._signal import as_signal, lowpass
from lowerlimb.gait.params import GaitParams

__all__ = ["SagittalRate", "sagittal_rate"]


@dataclass(frozen=True)
class SagittalRate:
    """Sagittal angular velocity of one segment.

    Attributes:
        omega_rps: (N,) angular velocity about ``axis_in_sensor``, rad/s, mid-swing positive.
        axis_in_sensor: (3,) unit rotation axis in the sensor frame.
        walking_fraction: Fraction of the samples used in the axis fit.
        axis_share: Share of the fitted samples' squared rate along the axis (1 = planar).
    """

    omega_rps: FloatArray
    axis_in_sensor: FloatArray
    walking_fraction: float
    axis_share: float


def sagittal_rate(gyr: ArrayLike, rate_hz: float, params: GaitParams | None = None) -> SagittalRate:
    """Project a gyro onto its principal (sagittal) axis, signed so that mid-swing is positive.

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        rate_hz: Sampling rate, Hz.
        params: Thresholds (defaults: :class:`GaitParams`).

    Returns:
        The signed sagittal rate and the axis.

    Raises:
        GaitSignalError: ``gyr`` is not a finite (N, 3) array.
    """
    p = params or GaitParams()
    w = as_signal(gyr, "gyr")
    smooth = lowpass(w, p.midswing_lowpass_hz, rate_hz)
    walking = np.linalg.norm(smooth, axis=1) > p.walking_gyro_rps
    fit = w[walking] if walking.sum() >= 3 else w
    M = fit.T @ fit
    evals, evecs = np.linalg.eigh(M)
    axis = evecs[:, -1]
    proj = smooth[walking] @ axis if walking.any() else smooth @ axis
    if np.percentile(proj, 99) < np.percentile(-proj, 99):
        axis = -axis
    share = float(evals[-1] / max(evals.sum(), 1e-300))
    return SagittalRate(
        omega_rps=w @ axis,
        axis_in_sensor=axis,
        walking_fraction=float(walking.mean()),
        axis_share=share,
    )
