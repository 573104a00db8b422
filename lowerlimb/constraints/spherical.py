"""Spherical-joint constraint: equal joint-centre acceleration norms (Hu et al. 2021, eq. 1–3, 7–9).

Two sensors P (parent) and C (child) sit on two segments joined by a
spherical joint. With the library convention (docs/methods.md, errata)
``c_S`` = the joint centre expressed in sensor S's frame (``c = −V`` of the
paper), the acceleration of the joint centre seen from sensor S is

    g_S(t) = a_S(t) + ω_S(t) × (ω_S(t) × c_S) + α_S(t) × c_S = a_S(t) + K_S(t) c_S,
    K_S = [ω_S]×[ω_S]× + [α_S]×,

and both sensors see the same point, so ``‖g_P(t)‖ = ‖g_C(t)‖`` (the
accelerometer reads specific force; gravity is common to both and norms are
rotation invariant). The residual per sample (eq. 3 with c = −V) is

    e(t) = ‖g_P(t)‖ − ‖g_C(t)‖,                 x = (c_P, c_C) ∈ R⁶ (m),

and its Jacobian (eq. 9, sign corrected for c = −V)

    ∂e/∂c_P = (g_P/‖g_P‖)ᵀ K_P,        ∂e/∂c_C = −(g_C/‖g_C‖)ᵀ K_C.

When the relative orientation ``R_PC`` (child to parent) is known, the
stronger 3-D form ``g_P − R_PC g_C = 0`` (three residuals per sample) is
available as :func:`spherical_residual_3d`.

Every residual exists twice: vectorised NumPy (for Gauss–Newton and the
swarms, which evaluate a whole population at once) and CasADi (a per-sample
SX function ``map``-ed over the samples, the data matrix being a parameter).
Norms are smoothed as ``sqrt(‖g‖² + ε²)`` with ε = 1e-9 m/s² so that the
derivative exists everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, cached_property

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray, skew
from lowerlimb.errors import ShapeError

__all__ = [
    "SphericalData",
    "kinematic_matrix",
    "joint_acceleration",
    "spherical_residual",
    "spherical_jacobian",
    "spherical_residual_population",
    "spherical_residual_3d",
    "spherical_jacobian_3d",
    "spherical_sample_function",
    "spherical_axis_gauge_sample_function",
    "AXIS_GAUGE_MAP",
    "spherical_casadi",
]

_EPS2 = 1e-18  # ε² of the smoothed norm, (m/s²)²
#: Rows of the CasADi data matrix, in order (each a 3-vector, sensor frame).
DATA_ROWS = ("acc_parent", "gyr_parent", "angacc_parent", "acc_child", "gyr_child", "angacc_child")


def _vec3(x: ArrayLike, name: str, n: int | None = None) -> FloatArray:
    arr = np.ascontiguousarray(np.asarray(x, dtype=float))
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ShapeError(f"{name} must have shape (N, 3), got {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ShapeError(f"{name} has {arr.shape[0]} samples but the other signals have {n}")
    return arr


def kinematic_matrix(gyr: ArrayLike, angacc: ArrayLike) -> FloatArray:
    """K = [ω]×[ω]× + [α]×, so that ω × (ω × c) + α × c = K c (Hu 2021 eq. 2, 10).

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        angacc: (N, 3) angular acceleration, sensor frame, rad/s².

    Returns:
        (N, 3, 3) matrices, 1/s².
    """
    W = skew(gyr)
    return np.asarray(W @ W + skew(angacc), dtype=float)


def joint_acceleration(acc: ArrayLike, gyr: ArrayLike, angacc: ArrayLike, center: ArrayLike) -> FloatArray:
    """Specific force at a point ``center`` fixed to the sensor (eq. 2 with c = −V).

    Args:
        acc: (N, 3) accelerometer (specific force), sensor frame, m/s².
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        angacc: (N, 3) angular acceleration, sensor frame, rad/s².
        center: (3,) the point in the sensor frame, m.

    Returns:
        (N, 3) ``a + ω × (ω × c) + α × c``, sensor frame, m/s².
    """
    w = np.asarray(gyr, dtype=float)
    c = np.broadcast_to(np.asarray(center, dtype=float), w.shape)
    al = np.asarray(angacc, dtype=float)
    return np.asarray(acc, dtype=float) + np.cross(w, np.cross(w, c)) + np.cross(al, c)


def _norm_terms(acc: FloatArray, K: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    n = acc.shape[0]
    return (
        np.einsum("ni,ni->n", acc, acc),
        np.einsum("ni,nij->nj", acc, K),
        np.einsum("nki,nkj->nij", K, K).reshape(n, 9),
    )


@dataclass(frozen=True)
class SphericalData:
    """The per-sample inputs of the spherical-joint residual of one sensor pair.

    Attributes:
        acc_parent: (N, 3) parent accelerometer, parent sensor frame, m/s².
        gyr_parent: (N, 3) parent gyroscope (bias removed), rad/s.
        angacc_parent: (N, 3) parent angular acceleration, rad/s².
        acc_child: (N, 3) child accelerometer, child sensor frame, m/s².
        gyr_child: (N, 3) child gyroscope (bias removed), rad/s.
        angacc_child: (N, 3) child angular acceleration, rad/s².
        gyr_noise_parent: white-noise standard deviation per axis of ``gyr_parent``
            (after its filter), rad/s (0: unknown;
            :mod:`~lowerlimb.constraints.regressor_noise`).
        angacc_noise_parent: the same for ``angacc_parent``, rad/s².
        gyr_noise_child: the same for ``gyr_child``, rad/s.
        angacc_noise_child: the same for ``angacc_child``, rad/s².
    """

    acc_parent: FloatArray
    gyr_parent: FloatArray
    angacc_parent: FloatArray
    acc_child: FloatArray
    gyr_child: FloatArray
    angacc_child: FloatArray
    gyr_noise_parent: float = 0.0
    angacc_noise_parent: float = 0.0
    gyr_noise_child: float = 0.0
    angacc_noise_child: float = 0.0

    def __post_init__(self) -> None:
        n = _vec3(self.acc_parent, "acc_parent").shape[0]
        for name in DATA_ROWS:
            object.__setattr__(self, name, _vec3(getattr(self, name), name, n))

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.acc_parent.shape[0])

    @cached_property
    def K_parent(self) -> FloatArray:
        """(N, 3, 3) kinematic matrices of the parent sensor, 1/s²."""
        return kinematic_matrix(self.gyr_parent, self.angacc_parent)

    @cached_property
    def K_child(self) -> FloatArray:
        """(N, 3, 3) kinematic matrices of the child sensor, 1/s²."""
        return kinematic_matrix(self.gyr_child, self.angacc_child)

    @cached_property
    def norm_terms_parent(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(‖a‖², aᵀK, vec(KᵀK))`` of the parent: (N,), (N, 3), (N, 9)."""
        return _norm_terms(self.acc_parent, self.K_parent)

    @cached_property
    def norm_terms_child(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(‖a‖², aᵀK, vec(KᵀK))`` of the child: (N,), (N, 3), (N, 9)."""
        return _norm_terms(self.acc_child, self.K_child)

    def data_matrix(self) -> FloatArray:
        """(18, N) CasADi parameter matrix; rows follow ``DATA_ROWS`` (3 rows each)."""
        return np.ascontiguousarray(np.hstack([getattr(self, k) for k in DATA_ROWS]).T)

    def rotated(self, Q_parent: FloatArray, Q_child: FloatArray) -> SphericalData:
        """The same signals in rotated sensor frames: each vector ``v`` becomes ``Qᵀ v``.

        Args:
            Q_parent: (3, 3) orthonormal; its columns are the new parent axes.
            Q_child: (3, 3) orthonormal; its columns are the new child axes.
        """
        return SphericalData(
            self.acc_parent @ Q_parent,
            self.gyr_parent @ Q_parent,
            self.angacc_parent @ Q_parent,
            self.acc_child @ Q_child,
            self.gyr_child @ Q_child,
            self.angacc_child @ Q_child,
            *self.noise_levels,
        )

    def subsample(self, step: int) -> SphericalData:
        """Every ``step``-th sample (for the swarms, whose cost is evaluated many times)."""
        return SphericalData(
            self.acc_parent[::step],
            self.gyr_parent[::step],
            self.angacc_parent[::step],
            self.acc_child[::step],
            self.gyr_child[::step],
            self.angacc_child[::step],
            *self.noise_levels,
        )

    def select(self, keep: ArrayLike) -> SphericalData:
        """The samples where ``keep`` is true ((N,) booleans), in order; noise levels kept."""
        k = np.asarray(keep, dtype=bool)
        if k.shape != (self.n_samples,):
            raise ShapeError(f"keep must have shape ({self.n_samples},), got {k.shape}")
        return SphericalData(
            self.acc_parent[k],
            self.gyr_parent[k],
            self.angacc_parent[k],
            self.acc_child[k],
            self.gyr_child[k],
            self.angacc_child[k],
            *self.noise_levels,
        )

    @property
    def noise_levels(self) -> tuple[float, float, float, float]:
        """The four regressor noise levels, in field order.

        ``(gyr_noise_parent, angacc_noise_parent, gyr_noise_child, angacc_noise_child)``;
        the noise is isotropic, so :meth:`rotated` keeps them.
        """
        return (
            self.gyr_noise_parent,
            self.angacc_noise_parent,
            self.gyr_noise_child,
            self.angacc_noise_child,
        )


def _split(x: ArrayLike) -> tuple[FloatArray, FloatArray]:
    v = np.asarray(x, dtype=float).reshape(-1)
    if v.shape != (6,):
        raise ShapeError(f"x must hold (c_parent, c_child): 6 numbers, got shape {v.shape}")
    return v[:3], v[3:]


def spherical_residual(x: ArrayLike, data: SphericalData) -> FloatArray:
    """Residual e(t) = ‖g_P(t)‖ − ‖g_C(t)‖ of Hu 2021 eq. 3 (c = −V), vectorised over samples.

    Args:
        x: (6,) ``(c_P, c_C)``: joint centre in the parent and child sensor frames, m.
        data: the sensor pair's signals.

    Returns:
        (N,) residuals, m/s².
    """
    cp, cc = _split(x)
    gp = data.acc_parent + data.K_parent @ cp
    gc = data.acc_child + data.K_child @ cc
    return np.asarray(
        np.sqrt(np.einsum("ni,ni->n", gp, gp) + _EPS2) - np.sqrt(np.einsum("ni,ni->n", gc, gc) + _EPS2),
        dtype=float,
    )


def spherical_jacobian(x: ArrayLike, data: SphericalData) -> FloatArray:
    """Jacobian ∂e/∂x of :func:`spherical_residual` (Hu 2021 eq. 8–9, sign for c = −V).

    Args:
        x: (6,) ``(c_P, c_C)``, m.
        data: the sensor pair's signals.

    Returns:
        (N, 6) Jacobian, 1/s².
    """
    cp, cc = _split(x)
    gp = data.acc_parent + data.K_parent @ cp
    gc = data.acc_child + data.K_child @ cc
    up = gp / np.sqrt(np.einsum("ni,ni->n", gp, gp) + _EPS2)[:, None]
    uc = gc / np.sqrt(np.einsum("ni,ni->n", gc, gc) + _EPS2)[:, None]
    J = np.empty((data.n_samples, 6))
    J[:, :3] = np.einsum("ni,nij->nj", up, data.K_parent)
    J[:, 3:] = -np.einsum("ni,nij->nj", uc, data.K_child)
    return J


def spherical_residual_population(X: ArrayLike, data: SphericalData) -> FloatArray:
    """Residuals of a whole population of candidates at once (for DWPSO/GWO).

    Args:
        X: (P, 6) candidates ``(c_P, c_C)``, m.
        data: the sensor pair's signals (usually subsampled).

    Returns:
        (P, N) residuals, m/s².
    """
    Xa = np.asarray(X, dtype=float)
    if Xa.ndim != 2 or Xa.shape[1] != 6:
        raise ShapeError(f"X must have shape (P, 6), got {Xa.shape}")
    # ‖a + K c‖² = ‖a‖² + 2 (aᵀK) c + cᵀ (KᵀK) c: two small BLAS products per sensor
    # (fine for ranking candidates; the Gauss–Newton paths use the direct form).
    out = np.zeros((Xa.shape[0], data.n_samples))
    for (aa, aK, KtK), C, sign in (
        (data.norm_terms_parent, Xa[:, :3], 1.0),
        (data.norm_terms_child, Xa[:, 3:], -1.0),
    ):
        CC = (C[:, :, None] * C[:, None, :]).reshape(-1, 9)
        sq = aa[None, :] + 2.0 * (C @ aK.T) + CC @ KtK.T
        out += sign * np.sqrt(np.maximum(sq, 0.0) + _EPS2)
    return out


def spherical_residual_3d(x: ArrayLike, data: SphericalData, R_parent_child: ArrayLike) -> FloatArray:
    """Stronger 3-D residual ``g_P − R_PC g_C`` when orientations are known.

    Args:
        x: (6,) ``(c_P, c_C)``, m.
        data: the sensor pair's signals.
        R_parent_child: (N, 3, 3) rotations mapping child-sensor coordinates to
            parent-sensor coordinates.

    Returns:
        (N, 3) residuals in the parent sensor frame, m/s².
    """
    cp, cc = _split(x)
    R = np.asarray(R_parent_child, dtype=float)
    if R.shape != (data.n_samples, 3, 3):
        raise ShapeError(f"R_parent_child must have shape ({data.n_samples}, 3, 3), got {R.shape}")
    gp = data.acc_parent + data.K_parent @ cp
    gc = data.acc_child + data.K_child @ cc
    return np.asarray(gp - np.einsum("nij,nj->ni", R, gc), dtype=float)


def spherical_jacobian_3d(x: ArrayLike, data: SphericalData, R_parent_child: ArrayLike) -> FloatArray:
    """Jacobian of :func:`spherical_residual_3d`: ``[K_P, −R_PC K_C]`` (it is linear in x).

    Args:
        x: (6,) ``(c_P, c_C)``, m (unused: the residual is affine).
        data: the sensor pair's signals.
        R_parent_child: (N, 3, 3) child-to-parent rotations.

    Returns:
        (N, 3, 6) Jacobian, 1/s².
    """
    _split(x)
    R = np.asarray(R_parent_child, dtype=float)
    J = np.empty((data.n_samples, 3, 6))
    J[:, :, :3] = data.K_parent
    J[:, :, 3:] = -R @ data.K_child
    return J


@cache
def spherical_sample_function() -> ca.Function:
    """Per-sample CasADi SX function ``(x[6], p[18]) -> e`` of eq. 3 (c = −V).

    ``p`` stacks ``a_P, ω_P, α_P, a_C, ω_C, α_C`` (sensor frames, SI units).
    The same object is returned on every call, so solvers can cache what they
    build from it.
    """
    x = ca.SX.sym("x", 6)
    p = ca.SX.sym("p", 18)

    def g(off: int, c: ca.SX) -> ca.SX:
        a, w, al = p[off : off + 3], p[off + 3 : off + 6], p[off + 6 : off + 9]
        return a + ca.cross(w, ca.cross(w, c)) + ca.cross(al, c)

    gp = g(0, x[0:3])
    gc = g(9, x[3:6])
    e = ca.sqrt(ca.sumsqr(gp) + _EPS2) - ca.sqrt(ca.sumsqr(gc) + _EPS2)
    return ca.Function("spherical_sample", [x, p], [e], ["x", "p"], ["e"])


#: (6, 5) map from the 5 parameters of a centre on a hinge axis to x = (c_P, c_C), in
#: sensor frames rotated so that their first axis is the hinge axis (see below).
AXIS_GAUGE_MAP = np.array(
    [
        [1.0, 0, 0, 0, 0],
        [0, 1.0, 0, 0, 0],
        [0, 0, 1.0, 0, 0],
        [-1.0, 0, 0, 0, 0],
        [0, 0, 0, 1.0, 0],
        [0, 0, 0, 0, 1.0],
    ]
)


@cache
def spherical_axis_gauge_sample_function() -> ca.Function:
    """Per-sample ``(y[5], p[18]) -> e``: eq. 3 for a centre on a hinge axis, gauge built in.

    At a hinge every point of the axis satisfies eq. 3, so x has an
    unobservable direction. With each sensor's data expressed in a frame whose
    first axis is the hinge axis (``Q_S = [j_S, u_S, v_S]``, data rotated by
    ``Q_Sᵀ``), that direction is ``c'_P[0] = c'_C[0]`` moving together. Fixing
    ``c'_P[0] + c'_C[0] = 0`` (the point of the axis nearest the two sensors,
    Hu 2021 eq. 16) leaves five parameters ``y``: ``x' = AXIS_GAUGE_MAP @ y``.
    """
    y = ca.SX.sym("y", 5)
    p = ca.SX.sym("p", 18)
    x = ca.vertcat(y[0], y[1], y[2], -y[0], y[3], y[4])
    e = spherical_sample_function()(x, p)
    return ca.Function("spherical_axis_gauge_sample", [y, p], [e], ["x", "p"], ["e"])


def spherical_casadi(n_samples: int) -> ca.Function:
    """CasADi residual ``(x[6], P[18×N]) -> r[N]`` of eq. 3: the per-sample function ``map``-ed.

    Args:
        n_samples: N, the number of columns of the data matrix
            (:meth:`SphericalData.data_matrix`).

    Returns:
        A ``casadi.Function`` named ``spherical_residual`` with inputs ``x``
        (6×1, m) and ``p`` (18×N) and output ``r`` (N×1, m/s²).
    """
    f = spherical_sample_function().map(int(n_samples), "serial")
    x = ca.MX.sym("x", 6)
    p = ca.MX.sym("p", 18, int(n_samples))
    r = f(x, p).T
    return ca.Function("spherical_residual", [x, p], [r], ["x", "p"], ["r"])
