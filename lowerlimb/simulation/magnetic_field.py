"""The magnetic field of a gait lab: the earth's field bent by magnetised material under the floor.

The simulators used to read one uniform field everywhere. Real labs are not uniform
near the floor: reinforcing steel, force plates and treadmill motors. On the real walk
of ``gait/`` (Xsens MTw; docs/limits.md, "Magnetic disturbances") the field strength seen
by each sensor over the walking window varied by (sd of the norm, % of its mean) 1.1 %
at the pelvis, 2.1 % at the thighs, 9.8-15.7 % at the shanks and 14.4-15.0 % at the
feet, and lowerlimb's check (:mod:`lowerlimb.orientation.magnetic`) rejects the
magnetometer there; on the BROAD trials (optical truth) trusting the heading from a real
indoor field more made every filter worse. A simulator with a uniform field says the
opposite, so it was too kind.

The model: the uniform earth field plus point dipoles on a square grid
(:attr:`LabField.spacing_m`) at :attr:`LabField.depth_m` below the floor (z = 0), with
independent Gaussian moments (:attr:`LabField.moment_am2` per axis). A dipole ``m`` at
``p`` adds ``μ0/4π (3 r̂ (m·r̂) − m) / |r|³`` at ``x`` (``r = x − p``), i.e. ``0.1 (…)``
µT for A·m² and m. The defaults give a norm sd of about 7.5 µT (15 % of 50 µT) at 7 cm
above the floor, 2.9 µT at 35 cm, 1.4 µT at 60 cm and 0.55 µT at 1 m at 6 A·m²; the
moment is set to 7.5 A·m² so that the feet's field strength varies as on the real walk
(coefficient of variation 14.6-15.3 % on the seven-IMU walk of seed 203, real 14.4-15.0 %;
shanks 7.0-7.6 %, real 9.8-15.7 %; thighs 3.0-3.4 %, real 2.1 %; pelvis 2.3 %, real
1.1 %).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import FloatArray

__all__ = ["LAB_FIELD", "LabField", "dipole_grid", "field_enu_ut"]

#: Points evaluated together against their near dipoles.
_BLOCK = 256


@dataclass(frozen=True)
class LabField:
    """Parameters of the disturbed lab field.

    Attributes:
        spacing_m: Grid spacing of the dipoles under the floor, m.
        depth_m: Depth of the grid below the floor, m.
        moment_am2: Standard deviation of each moment component, A·m².
        margin_m: The grid extends this far beyond the sensors' horizontal path, m.
    """

    spacing_m: float = 0.5
    depth_m: float = 0.5
    moment_am2: float = 7.5
    margin_m: float = 2.0


#: The default lab (the seven-IMU simulator's).
LAB_FIELD = LabField()


def dipole_grid(
    points_m: FloatArray, field: LabField, rng: np.random.Generator
) -> tuple[FloatArray, FloatArray]:
    """Dipole positions (K, 3) m and moments (K, 3) A·m² under the horizontal extent of ``points_m``."""
    p = np.asarray(points_m, dtype=float).reshape(-1, 3)
    lo = p[:, :2].min(axis=0) - field.margin_m
    hi = p[:, :2].max(axis=0) + field.margin_m
    xs = np.arange(lo[0], hi[0] + 0.5 * field.spacing_m, field.spacing_m)
    ys = np.arange(lo[1], hi[1] + 0.5 * field.spacing_m, field.spacing_m)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    pos = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, -field.depth_m)])
    return pos, field.moment_am2 * rng.normal(size=pos.shape)


def field_enu_ut(
    points_m: FloatArray,
    uniform_ut: FloatArray,
    dipoles: tuple[FloatArray, FloatArray],
    reach_m: float = 3.0,
) -> FloatArray:
    """The field (N, 3) µT, ENU, at ``points_m`` (N, 3) m: ``uniform_ut`` (3,) plus the dipoles.

    A dipole acts only on the points within ``reach_m`` of it along x and along y (one
    farther away adds below 1 % of a near one). The points are taken in blocks of
    consecutive rows, a short stretch of a sensor's path, so that each block meets only
    the dipoles under that stretch: the cost grows with the path's length, not with the
    area of the lab it spans (a bending 5-minute walk's grid holds ~10⁵ dipoles).
    """
    x = np.asarray(points_m, dtype=float).reshape(-1, 3)
    B = np.tile(np.asarray(uniform_ut, dtype=float), (x.shape[0], 1))
    pos, mom = dipoles
    by_x = np.argsort(pos[:, 0], kind="stable")
    px, py = pos[by_x, 0], pos[by_x, 1]
    for block in np.array_split(np.arange(x.shape[0]), max(1, x.shape[0] // _BLOCK)):
        if block.size == 0:
            continue
        xb = x[block]
        lo, hi = np.searchsorted(px, [xb[:, 0].min() - reach_m, xb[:, 0].max() + reach_m])
        in_y = (py[lo:hi] >= xb[:, 1].min() - reach_m) & (py[lo:hi] <= xb[:, 1].max() + reach_m)
        near = by_x[lo:hi][in_y]
        r = xb[:, None, :] - pos[None, near, :]  # (B, K, 3)
        d = np.linalg.norm(r, axis=2)
        u = r / d[..., None]
        m = mom[None, near, :]
        B[block] += np.sum(0.1 * (3.0 * u * np.sum(u * m, axis=2)[..., None] - m) / (d**3)[..., None], axis=1)
    return B
