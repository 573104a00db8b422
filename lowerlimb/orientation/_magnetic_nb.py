"""Compiled magnetometer helpers: heading error and magnetic disturbance rejection.

Shared by the filters' inner loops. Earth frame ENU: magnetic north is +y, the
field dips below the horizon (positive dip) in the northern hemisphere.
"""

from __future__ import annotations

import math

from numba import njit

from lowerlimb.orientation._quaternion_nb import norm3, rotate_to_earth


@njit(cache=True, inline="always")
def mag_heading_error(
    w: float,
    x: float,
    y: float,
    z: float,
    mx: float,
    my: float,
    mz: float,
    norm_ref: float,
    dip_ref: float,
    norm_tol: float,
    dip_tol: float,
) -> tuple[bool, float]:
    """Sine of the heading error of one magnetometer sample, with disturbance rejection.

    The sample ``m`` (sensor frame) is rotated into the earth frame with the
    current estimate ``q``; its horizontal part should point north (+y).

    Args:
        w: Estimate, scalar part (x, y, z: vector part), sensor -> ENU.
        x: See ``w``.
        y: See ``w``.
        z: See ``w``.
        mx: Magnetometer sample, sensor frame, any unit (my, mz likewise).
        my: See ``mx``.
        mz: See ``mx``.
        norm_ref: Undisturbed field norm (same unit as ``m``); ``<= 0`` disables
            the norm test.
        dip_ref: Undisturbed dip angle, rad.
        norm_tol: Largest relative deviation of ``‖m‖`` from ``norm_ref``.
        dip_tol: Largest deviation of the dip from ``dip_ref``, rad.

    Returns:
        ``(valid, s)``: ``valid`` is False for a zero, vertical or disturbed
        sample; ``s = h_x / ‖h_xy‖`` is the sine of the heading error (positive:
        the estimate must turn counter-clockwise about +z).
    """
    hx, hy, hz = rotate_to_earth(w, x, y, z, mx, my, mz)
    hn = norm3(hx, hy, hz)
    hxy = math.sqrt(hx * hx + hy * hy)
    if hn <= 0.0 or hxy <= 1e-6 * hn:
        return False, 0.0
    if norm_ref > 0.0:
        if abs(hn - norm_ref) > norm_tol * norm_ref:
            return False, 0.0
        if abs(math.asin(max(-1.0, min(1.0, -hz / hn))) - dip_ref) > dip_tol:
            return False, 0.0
    return True, hx / hxy
