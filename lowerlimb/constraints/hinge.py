"""Hinge-joint constraint: equal angular-velocity components normal to the axis (Hu 2021, eq. 4–6, 12–14).

Two sensors P and C on segments joined by a hinge with unit axis ``j_P``
(parent sensor frame) and ``j_C`` (child sensor frame) satisfy
``R_PC ω_C = ω_P + q̇ j_P``, so the angular-velocity components normal to the
axis have equal norms (eq. 4):

    e(t) = ‖ω_P(t) × j_P‖ − ‖ω_C(t) × j_C‖.                                (6)

The axes are parametrised by spherical coordinates (eq. 5, corrected in
docs/methods.md: the last component is sin φ, not sin θ):

    j(φ, θ) = (cos φ cos θ, cos φ sin θ, sin φ),     x = (φ_P, θ_P, φ_C, θ_C).

The Jacobian (eq. 13–14, with the corrected denominator, docs/methods.md):

    ∂‖ω × j‖/∂j = ((ω × j) × ω)ᵀ / ‖ω × j‖,
    ∂j/∂(φ, θ)  = [[−sin φ cos θ, −cos φ sin θ],
                   [−sin φ sin θ,  cos φ cos θ],
                   [ cos φ,         0         ]].

The residual is invariant to flipping either axis; the calibration layer
resolves the signs (:mod:`lowerlimb.calibration.hinge_axis`). Near the poles
φ = ±π/2 the θ column of the Jacobian vanishes; the calibration layer
therefore solves in a rotated basis in which the current estimate sits on
the equator (``‖ω × Q j'‖ = ‖Qᵀω × j'‖``: rotate the data, not the model).

A second, sign-sensitive hinge relation is used by the calibration layer:
any point on the axis is fixed in both segments, so its accelerations
``g_P``, ``g_C`` (see :mod:`.spherical`) have equal components along the axis
(Olsson et al. 2020's accelerometer-based hinge constraint, written at the
joint centre): :func:`hinge_acc_residual` ``= g_P·j_P − g_C·j_C``.

Norms are smoothed as ``sqrt(‖u‖² + ε²)``, ε = 1e-9 rad/s.
"""

from __future__ import annotations

from functools import cache

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray
from lowerlimb.errors import ShapeError

__all__ = [
    "axis_from_angles",
    "axis_angles_jacobian",
    "angles_from_axis",
    "hinge_residual",
    "hinge_jacobian",
    "hinge_residual_population",
    "hinge_acc_residual",
    "hinge_sample_function",
    "hinge_casadi",
]

_EPS2 = 1e-18  # ε² of the smoothed norm, (rad/s)²


def axis_from_angles(phi: ArrayLike, theta: ArrayLike) -> FloatArray:
    """Unit vector(s) of eq. 5 (corrected): ``(cos φ cos θ, cos φ sin θ, sin φ)``.

    Args:
        phi: elevation(s) φ, rad, any shape S.
        theta: azimuth(s) θ, rad, shape S.

    Returns:
        (*S, 3) unit vectors.
    """
    p = np.asarray(phi, dtype=float)
    t = np.asarray(theta, dtype=float)
    return np.stack([np.cos(p) * np.cos(t), np.cos(p) * np.sin(t), np.sin(p)], axis=-1)


def axis_angles_jacobian(phi: float, theta: float) -> FloatArray:
    """(3, 2) derivative of :func:`axis_from_angles` with respect to (φ, θ)."""
    sp, cp, st, ct = np.sin(phi), np.cos(phi), np.sin(theta), np.cos(theta)
    return np.array([[-sp * ct, -cp * st], [-sp * st, cp * ct], [cp, 0.0]])


def angles_from_axis(axis: ArrayLike) -> tuple[float, float]:
    """(φ, θ) in rad of a (3,) vector (normalised first); inverse of :func:`axis_from_angles`."""
    v = np.asarray(axis, dtype=float).reshape(3)
    v = v / np.linalg.norm(v)
    # atan2 rather than arcsin: arcsin loses half the digits next to the poles
    return float(np.arctan2(v[2], np.hypot(v[0], v[1]))), float(np.arctan2(v[1], v[0]))


def _check(x: ArrayLike, gyr_parent: ArrayLike, gyr_child: ArrayLike) -> tuple[FloatArray, ...]:
    v = np.asarray(x, dtype=float).reshape(-1)
    if v.shape != (4,):
        raise ShapeError(f"x must hold (phi_P, theta_P, phi_C, theta_C), got shape {v.shape}")
    wp = np.asarray(gyr_parent, dtype=float)
    wc = np.asarray(gyr_child, dtype=float)
    if wp.ndim != 2 or wp.shape[1] != 3 or wc.shape != wp.shape:
        raise ShapeError(f"gyr_parent and gyr_child must both have shape (N, 3), got {wp.shape}, {wc.shape}")
    return v, wp, wc


def hinge_residual(x: ArrayLike, gyr_parent: ArrayLike, gyr_child: ArrayLike) -> FloatArray:
    """Residual e(t) = ‖ω_P × j_P‖ − ‖ω_C × j_C‖ of Hu 2021 eq. 6, vectorised over samples.

    Args:
        x: (4,) ``(φ_P, θ_P, φ_C, θ_C)`` of eq. 5, rad.
        gyr_parent: (N, 3) parent angular velocity, parent sensor frame, rad/s.
        gyr_child: (N, 3) child angular velocity, child sensor frame, rad/s.

    Returns:
        (N,) residuals, rad/s.
    """
    v, wp, wc = _check(x, gyr_parent, gyr_child)
    up = np.cross(wp, axis_from_angles(v[0], v[1]))
    uc = np.cross(wc, axis_from_angles(v[2], v[3]))
    return np.asarray(
        np.sqrt(np.einsum("ni,ni->n", up, up) + _EPS2) - np.sqrt(np.einsum("ni,ni->n", uc, uc) + _EPS2),
        dtype=float,
    )


def hinge_jacobian(x: ArrayLike, gyr_parent: ArrayLike, gyr_child: ArrayLike) -> FloatArray:
    """Jacobian of :func:`hinge_residual` w.r.t. ``(φ_P, θ_P, φ_C, θ_C)`` (eq. 13–14 corrected).

    Args:
        x: (4,) angles, rad.
        gyr_parent: (N, 3) parent angular velocity, rad/s.
        gyr_child: (N, 3) child angular velocity, rad/s.

    Returns:
        (N, 4) Jacobian, rad/s per rad.
    """
    v, wp, wc = _check(x, gyr_parent, gyr_child)
    J = np.empty((wp.shape[0], 4))
    for k, (w, sign) in enumerate(((wp, 1.0), (wc, -1.0))):
        phi, theta = v[2 * k], v[2 * k + 1]
        r = axis_from_angles(phi, theta)
        u = np.cross(w, r)
        n = np.sqrt(np.einsum("ni,ni->n", u, u) + _EPS2)
        d_dr = np.cross(u, w) / n[:, None]  # ((ω × j) × ω)/‖ω × j‖, eq. 14 corrected
        J[:, 2 * k : 2 * k + 2] = sign * d_dr @ axis_angles_jacobian(phi, theta)
    return J


def hinge_residual_population(X: ArrayLike, gyr_parent: ArrayLike, gyr_child: ArrayLike) -> FloatArray:
    """Residuals of a population of candidates (for DWPSO/GWO).

    Args:
        X: (P, 4) candidate angles ``(φ_P, θ_P, φ_C, θ_C)``, rad.
        gyr_parent: (N, 3) parent angular velocity, rad/s.
        gyr_child: (N, 3) child angular velocity, rad/s.

    Returns:
        (P, N) residuals, rad/s.
    """
    Xa = np.asarray(X, dtype=float)
    if Xa.ndim != 2 or Xa.shape[1] != 4:
        raise ShapeError(f"X must have shape (P, 4), got {Xa.shape}")
    wp = np.asarray(gyr_parent, dtype=float)
    wc = np.asarray(gyr_child, dtype=float)
    out = np.zeros((Xa.shape[0], wp.shape[0]))
    for k, (w, sign) in enumerate(((wp, 1.0), (wc, -1.0))):
        r = axis_from_angles(Xa[:, 2 * k], Xa[:, 2 * k + 1])  # (P, 3)
        # ‖ω × r‖² = ‖ω‖² ‖r‖² − (ω·r)², with ‖r‖ = 1
        wr = w @ r.T  # (N, P)
        nn = np.einsum("ni,ni->n", w, w)[:, None] - wr**2
        out += sign * np.sqrt(np.maximum(nn, 0.0) + _EPS2).T
    return out


def hinge_acc_residual(
    axis_parent: ArrayLike,
    axis_child: ArrayLike,
    joint_acc_parent: ArrayLike,
    joint_acc_child: ArrayLike,
) -> FloatArray:
    """Sign-sensitive hinge residual ``g_P·j_P − g_C·j_C`` (Olsson et al. 2020, at the joint centre).

    Args:
        axis_parent: (3,) axis in the parent sensor frame (unit).
        axis_child: (3,) axis in the child sensor frame (unit).
        joint_acc_parent: (N, 3) acceleration of a point on the axis seen from the
            parent (:func:`lowerlimb.constraints.spherical.joint_acceleration`), m/s².
        joint_acc_child: (N, 3) the same point's acceleration seen from the child, m/s².

    Returns:
        (N,) residuals, m/s²; near zero when the axes point the same physical way.
    """
    gp = np.asarray(joint_acc_parent, dtype=float)
    gc = np.asarray(joint_acc_child, dtype=float)
    return np.asarray(
        gp @ np.asarray(axis_parent, dtype=float) - gc @ np.asarray(axis_child, dtype=float),
        dtype=float,
    )


@cache
def hinge_sample_function() -> ca.Function:
    """Per-sample CasADi SX function ``(x[4], p[6]) -> e`` of eq. 6, ``p = (ω_P, ω_C)``.

    The same object is returned on every call (solvers cache what they build from it).
    """
    x = ca.SX.sym("x", 4)
    p = ca.SX.sym("p", 6)

    def axis(phi: ca.SX, theta: ca.SX) -> ca.SX:
        return ca.vertcat(ca.cos(phi) * ca.cos(theta), ca.cos(phi) * ca.sin(theta), ca.sin(phi))

    up = ca.cross(p[0:3], axis(x[0], x[1]))
    uc = ca.cross(p[3:6], axis(x[2], x[3]))
    e = ca.sqrt(ca.sumsqr(up) + _EPS2) - ca.sqrt(ca.sumsqr(uc) + _EPS2)
    return ca.Function("hinge_sample", [x, p], [e], ["x", "p"], ["e"])


def hinge_casadi(n_samples: int) -> ca.Function:
    """CasADi residual ``(x[4], P[6×N]) -> r[N]`` of eq. 6: the per-sample function ``map``-ed.

    Args:
        n_samples: N, the number of columns of the data matrix, whose rows are
            ``ω_P`` (3, parent frame) then ``ω_C`` (3, child frame), rad/s.

    Returns:
        A ``casadi.Function`` named ``hinge_residual`` with inputs ``x`` (4×1, rad)
        and ``p`` (6×N) and output ``r`` (N×1, rad/s).
    """
    f = hinge_sample_function().map(int(n_samples), "serial")
    x = ca.MX.sym("x", 4)
    p = ca.MX.sym("p", 6, int(n_samples))
    r = f(x, p).T
    return ca.Function("hinge_residual", [x, p], [r], ["x", "p"], ["r"])
