"""Orientation accuracy against a reference: the BROAD metrics and Euler-angle RMSE.

BROAD (Laidig et al. 2021): the error quaternion in the earth frame,
``q_err = q_est ⊗ q_ref*``, splits into a heading error (rotation about the
vertical, ``2 atan(|z/w|)``) and an inclination error
(``2 acos √(w² + z²)``); the total error is its rotation angle. RMSEs are taken
over the scored samples where the reference is finite. 6-axis estimates have
an arbitrary heading: the best constant heading offset is removed first.

FTECF paper (Zhu & Xu 2018 eq. 22): RMSE of pitch, roll, yaw. Choice: the
angles are those of the earth-frame error rotation, decomposed
``R_err = R_z(yaw) R_x(pitch) R_y(roll)`` (pitch about east, roll about
north, yaw about up, Fig. 3). For small errors this equals the difference of
the Euler angles of estimate and reference, without their gimbal-lock jumps.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize_scalar

from lowerlimb.conventions import (
    FloatArray,
    euler_zxy_from_matrix,
    quat_conjugate,
    quat_multiply,
    quat_normalize,
    quat_to_matrix,
)
from lowerlimb.errors import ShapeError


@dataclass(frozen=True)
class OrientationErrors:
    """RMS errors of an orientation estimate, degrees.

    Attributes:
        total_deg: RMSE of the total rotation error.
        heading_deg: RMSE of the heading (about the vertical) error.
        inclination_deg: RMSE of the inclination error.
        pitch_deg: RMSE of the error about earth x (east).
        roll_deg: RMSE of the error about earth y (north).
        yaw_deg: RMSE of the error about earth z (up).
        max_deg: Largest total error.
        heading_offset_deg: Constant heading offset removed before scoring
            (0 unless ``remove_heading_offset``).
        samples: Number of samples scored.
    """

    total_deg: float
    heading_deg: float
    inclination_deg: float
    pitch_deg: float
    roll_deg: float
    yaw_deg: float
    max_deg: float
    heading_offset_deg: float
    samples: int

    def as_dict(self) -> dict[str, float]:
        """The fields as a plain dict."""
        return asdict(self)


def _rz(angle: float) -> FloatArray:
    return np.array([np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)])


def _rms(x: FloatArray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def orientation_errors(
    quat_est_wxyz: ArrayLike,
    quat_ref_wxyz: ArrayLike,
    mask: ArrayLike | None = None,
    *,
    remove_heading_offset: bool = False,
) -> OrientationErrors:
    """Total/heading/inclination and pitch/roll/yaw RMSE of an estimate.

    Args:
        quat_est_wxyz: (N, 4) estimated orientations, sensor -> earth.
        quat_ref_wxyz: (N, 4) reference orientations, same convention; rows
            with NaN are skipped.
        mask: (N,) boolean, the samples to score (all when ``None``).
        remove_heading_offset: Remove the constant heading (rotation about
            earth z) offset that minimises the total RMSE (6-axis estimates).

    Returns:
        The :class:`OrientationErrors`, degrees.

    Raises:
        ShapeError: shapes differ or are not (N, 4), or no sample is scored.
    """
    qe = np.asarray(quat_est_wxyz, dtype=float)
    qr = np.asarray(quat_ref_wxyz, dtype=float)
    if qe.shape != qr.shape or qe.ndim != 2 or qe.shape[1] != 4:
        raise ShapeError(f"estimate and reference must both be (N, 4), got {qe.shape}, {qr.shape}")
    keep = np.all(np.isfinite(qr), axis=1) & np.all(np.isfinite(qe), axis=1)
    if mask is not None:
        keep &= np.asarray(mask, dtype=bool).reshape(-1)
    if not keep.any():
        raise ShapeError("no sample to score: the mask is empty or the reference is all NaN")
    d = quat_normalize(quat_multiply(quat_normalize(qe[keep]), quat_conjugate(quat_normalize(qr[keep]))))
    offset = 0.0
    if remove_heading_offset:
        h = 2.0 * np.arctan2(d[:, 3], d[:, 0])
        c = float(np.arctan2(np.mean(np.sin(h)), np.mean(np.cos(h))))

        def total_rmse(delta: float) -> float:
            dd = quat_multiply(_rz(-delta), d)
            return _rms(2.0 * np.arccos(np.clip(np.abs(dd[:, 0]), 0.0, 1.0)))

        res = minimize_scalar(total_rmse, bounds=(c - 0.5, c + 0.5), method="bounded")
        offset = float(res.x)
        d = quat_multiply(_rz(-offset), d)
    w = np.abs(d[:, 0])
    total = 2.0 * np.arccos(np.clip(w, 0.0, 1.0))
    with np.errstate(divide="ignore"):
        heading = 2.0 * np.arctan(np.abs(d[:, 3] / d[:, 0]))
    incl = 2.0 * np.arccos(np.clip(np.sqrt(d[:, 0] ** 2 + d[:, 3] ** 2), 0.0, 1.0))
    yaw, pitch, roll = euler_zxy_from_matrix(quat_to_matrix(d)).T
    deg = np.degrees
    return OrientationErrors(
        total_deg=float(deg(_rms(total))),
        heading_deg=float(deg(_rms(heading))),
        inclination_deg=float(deg(_rms(incl))),
        pitch_deg=float(deg(_rms(pitch))),
        roll_deg=float(deg(_rms(roll))),
        yaw_deg=float(deg(_rms(yaw))),
        max_deg=float(deg(total.max())),
        heading_offset_deg=float(deg(offset)),
        samples=int(keep.sum()),
    )
