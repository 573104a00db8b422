"""Random but realistic IMU placements on the leg segments (3–30 cm from the joints)."""

from __future__ import annotations

import numpy as np

from ..conventions import FloatArray, quat_normalize, quat_to_matrix
from ..model.geometry import LegGeometry, transform


def _frame_with_normal(normal: FloatArray, rng: np.random.Generator, tilt_rad: float) -> FloatArray:
    """A sensor rotation whose z axis is ``normal`` tilted by up to ``tilt_rad``, any spin about it."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, n)
    x /= np.linalg.norm(x)
    y = np.cross(n, x)
    R = np.column_stack([x, y, n])
    spin = rng.uniform(-np.pi, np.pi)
    c, s = np.cos(spin), np.sin(spin)
    R = R @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    axis = rng.normal(size=3)
    axis -= axis.dot(n) * n
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(0.0, tilt_rad)
    q = quat_normalize(np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis]))
    return quat_to_matrix(q) @ R


def random_placements(geometry: LegGeometry, rng: np.random.Generator) -> dict[str, FloatArray]:
    """Draw IMU placements (4x4 sensor pose in segment frame) for the four segments.

    Pelvis: on the sacrum; thigh: lateral or anterior mid-thigh; shank: lateral
    or anteromedial mid-shank; foot: dorsum. The sensor's z axis is the skin
    normal (± 20° tilt) and the spin about it is uniform, so any orientation
    of the sensor axes relative to the segment occurs.
    """
    lat = 1.0 if geometry.side == "right" else -1.0
    Lt = geometry.inertias["thigh"].length_m
    Ls = geometry.inertias["shank"].length_m
    Lf = geometry.inertias["foot"].length_m
    tilt = np.deg2rad(20.0)
    out: dict[str, FloatArray] = {}
    p = np.array([rng.uniform(-0.14, -0.10), rng.uniform(0.04, 0.10), lat * rng.uniform(0.0, 0.04)])
    out["pelvis"] = transform(_frame_with_normal(np.array([-1.0, 0.0, 0.0]), rng, tilt), p)
    if rng.uniform() < 0.5:  # lateral thigh
        p = np.array([rng.uniform(-0.01, 0.03), -rng.uniform(0.35, 0.6) * Lt, lat * rng.uniform(0.07, 0.09)])
        normal = np.array([0.0, 0.0, lat])
    else:  # anterior thigh
        p = np.array([rng.uniform(0.06, 0.08), -rng.uniform(0.35, 0.6) * Lt, lat * rng.uniform(-0.01, 0.03)])
        normal = np.array([1.0, 0.0, 0.0])
    out["thigh"] = transform(_frame_with_normal(normal, rng, tilt), p)
    if rng.uniform() < 0.5:  # lateral shank
        p = np.array([rng.uniform(-0.01, 0.02), -rng.uniform(0.3, 0.5) * Ls, lat * rng.uniform(0.045, 0.06)])
        normal = np.array([0.0, 0.0, lat])
    else:  # anteromedial shank (on the tibia)
        p = np.array([rng.uniform(0.035, 0.05), -rng.uniform(0.3, 0.5) * Ls, -lat * rng.uniform(0.0, 0.02)])
        normal = np.array([1.0, 0.0, -0.4 * lat])
    out["shank"] = transform(_frame_with_normal(normal, rng, tilt), p)
    p = np.array([rng.uniform(0.25, 0.4) * Lf, rng.uniform(-0.01, 0.015), lat * rng.uniform(-0.01, 0.02)])
    out["foot"] = transform(_frame_with_normal(np.array([0.3, 1.0, 0.0]), rng, tilt), p)
    return out
