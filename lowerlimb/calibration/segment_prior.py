"""A weak anthropometric prior on a spherical joint's centre in a thigh or shank sensor.

Why: on nearly straight walking the hip and ankle residuals (eq. 7) leave a
direction of ``(c_P, c_C)`` almost free; the least-squares optimum then wanders
along it (simulated seven-IMU walks: hip in the thigh sensor 75 mm off median,
ankle in the shank sensor 69 mm). In the thigh and shank sensors the centre is
known roughly at calibration time:

- the knee axis ``j`` (well determined) and the sensor's mean specific force
  over the standing start (pointing up) give the segment's long axis in the
  sensor, ``u = (g − (g·j) j) / ‖…‖``;
- the knee centre ``k`` is a point of the axis (its place along the axis is a
  gauge); the hip lies near ``k⊥ + L_thigh u``, the ankle near ``k⊥ − L_shank u``
  (de Leva 1996 lengths for the stature), ``k⊥`` the knee centre's part off
  the axis through the sensor: along the axis the prior only says that the
  joint lies within a segment radius of the sensor.

The prior is Gaussian with a spread ``σ_along`` along ``u``, ``σ_axis`` along
the knee axis and ``σ_across`` along the third direction; :meth:`CenterPrior.rows`
turns it into residual rows of a MAP problem whose weight against the data is
the data's own noise (residual RMS times the square root of its correlation
time; :func:`~lowerlimb.calibration.joint_center.fit_spherical`): where the data
determine the centre, the prior moves it by a fraction of a millimetre.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray

__all__ = ["CenterPrior", "segment_up", "center_prior"]


@dataclass(frozen=True)
class CenterPrior:
    """Gaussian prior on one of the two centres of a spherical joint.

    Attributes:
        on_child: ``True``: on ``c_C`` (x[3:]), else on ``c_P`` (x[:3]).
        mean: (3,) prior mean in that sensor's frame, m.
        sqrt_info: (3, 3) ``W`` with ``WᵀW = Σ⁻¹``, 1/m.
    """

    on_child: bool
    mean: FloatArray
    sqrt_info: FloatArray

    def selector(self) -> FloatArray:
        """(3, 6) map from ``x = (c_P, c_C)`` to the centre the prior is on."""
        S = np.zeros((3, 6))
        if self.on_child:
            S[:, 3:] = np.eye(3)
        else:
            S[:, :3] = np.eye(3)
        return S

    def rows(self, x: ArrayLike, scale: float) -> tuple[FloatArray, FloatArray]:
        """Residual rows ``scale · W (S x − mean)`` (3,) and their Jacobian (3, 6)."""
        S = self.selector()
        xv = np.asarray(x, dtype=float)
        return scale * self.sqrt_info @ (S @ xv - self.mean), scale * self.sqrt_info @ S

    def to_dict(self) -> dict[str, object]:
        """The prior as recorded in calibration.json (metres)."""
        cov = np.linalg.inv(self.sqrt_info.T @ self.sqrt_info)
        return {
            "on": "child" if self.on_child else "parent",
            "mean": [float(v) for v in self.mean],
            "std_m": [float(v) for v in np.sqrt(np.linalg.eigvalsh(cov))],
        }


def segment_up(gravity: ArrayLike, axis: ArrayLike) -> FloatArray | None:
    """The segment's long axis (pointing up when standing) in its sensor frame.

    Args:
        gravity: (3,) mean specific force over the standing start, sensor frame, m/s²
            (points up).
        axis: (3,) hinge axis in the same frame (any length).

    Returns:
        (3,) unit vector: ``gravity`` made orthogonal to the axis; ``None`` when
        the two are nearly parallel (no standing start, or a lying segment).
    """
    g = np.asarray(gravity, dtype=float)
    j = np.asarray(axis, dtype=float)
    j = j / np.linalg.norm(j)
    v = g - (g @ j) * j
    n = float(np.linalg.norm(v))
    if n < 0.5 * float(np.linalg.norm(g)) or n == 0.0:
        return None
    return v / n


def center_prior(
    knee_center: ArrayLike,
    knee_axis: ArrayLike,
    up: ArrayLike,
    offset_m: float,
    *,
    std_along_m: float,
    std_across_m: float,
    std_axis_m: float,
    on_child: bool,
) -> CenterPrior:
    """The prior on a hip or ankle centre from the knee in one sensor frame.

    With ``j`` the knee axis and ``k⊥`` the knee centre's part off the axis
    through the sensor (the centre's position along ``j`` is only a gauge),
    the mean is ``k⊥ + offset · u``: nothing along ``j`` (the joint lies within a
    segment radius of the sensor across the leg). The covariance is
    ``σ_along² uuᵀ + σ_axis² jjᵀ + σ_across² nnᵀ`` with ``n = j × u``.

    Args:
        knee_center: (3,) knee centre in the sensor frame (any point of the axis), m.
        knee_axis: (3,) unit knee axis in that frame.
        up: (3,) unit long axis of the segment in that frame, orthogonal to ``knee_axis``.
        offset_m: signed distance along ``up`` (hip: +L_thigh; ankle: −L_shank), m.
        std_along_m: standard deviation along ``up``, m.
        std_across_m: standard deviation along ``j × u`` (antero-posterior), m.
        std_axis_m: standard deviation along the knee axis (medio-lateral), m.
        on_child: the sensor is the joint's child (hip: thigh) rather than its parent
            (ankle: shank).

    Returns:
        The prior (mean in m, square-root information in 1/m).
    """
    u = np.asarray(up, dtype=float)
    j = np.asarray(knee_axis, dtype=float)
    j = j / np.linalg.norm(j)
    n = np.cross(j, u)
    k = np.asarray(knee_center, dtype=float)
    mean = k - (k @ j) * j + offset_m * u
    W = np.outer(u, u) / std_along_m + np.outer(j, j) / std_axis_m + np.outer(n, n) / std_across_m
    return CenterPrior(on_child, mean, W)
