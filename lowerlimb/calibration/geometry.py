"""Small geometric helpers of the calibration: orthonormal bases, distances to lines."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray

__all__ = ["basis_with_first_axis", "distance_to_line", "angle_between_deg"]


def basis_with_first_axis(d: ArrayLike) -> FloatArray:
    """Right-handed orthonormal (3, 3) matrix whose first column is ``d/‖d‖``."""
    a = np.asarray(d, dtype=float).reshape(3)
    a = a / np.linalg.norm(a)
    helper = np.eye(3)[int(np.argmin(np.abs(a)))]
    u = np.cross(a, helper)
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    return np.column_stack([a, u, v])


def distance_to_line(point: ArrayLike, line_point: ArrayLike, line_direction: ArrayLike) -> float:
    """Distance from ``point`` (3,) to the line through ``line_point`` along ``line_direction``."""
    d = np.asarray(line_direction, dtype=float)
    d = d / np.linalg.norm(d)
    v = np.asarray(point, dtype=float) - np.asarray(line_point, dtype=float)
    return float(np.linalg.norm(v - (v @ d) * d))


def angle_between_deg(a: ArrayLike, b: ArrayLike, *, unsigned: bool = False) -> float:
    """Angle between two vectors, deg; ``unsigned`` treats ``b`` and ``−b`` alike (axes)."""
    u = np.asarray(a, dtype=float)
    w = np.asarray(b, dtype=float)
    c = float(u @ w / (np.linalg.norm(u) * np.linalg.norm(w)))
    if unsigned:
        c = abs(c)
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))
