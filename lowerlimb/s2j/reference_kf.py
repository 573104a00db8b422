"""Reference S2J vectors per sample by a Kalman filter (Lee & Lee 2022, §2.3, eq. 4–6).

The filter finds, at every sample t, segment-to-joint vectors that reproduce
the reference (optical or simulated) relative position exactly while staying
close to the constant (calibrated) vectors:

- state (eq. 4): ``x_t = [s_prox,t; s_dist,t]`` (6,), m, ``s_prox`` in the
  proximal sensor frame, ``s_dist`` in the distal sensor frame;
- process model (eq. 4): ``x_t = x_{t-1} + w_{t-1}``, identity transition.
  The paper gives no process noise; here ``w`` is white with covariance
  ``Q = σ_w² Δt I₆`` — a random walk with spectral density σ_w (m/√s), so that
  the filter behaves the same at every sampling rate;
- measurements (eq. 5–6): ``z_t = [s̄_prox; s̄_dist; p_pd,ref,t]`` with
  ``H_t = [[I, 0], [0, I], [I, −R_pd,t]]`` and noise covariance
  ``diag(δ² I₃, δ² I₃, ε² I₃)``. δ is the paper's deformation δ_pJ, δ_dJ (one
  isotropic value for both sides); ε is the "near-zero" noise of the
  reference relative position (the paper writes 0; a small positive value
  keeps the innovation covariance invertible).

Choices the paper leaves open, written down:

- initial state ``x_0 = [s̄_prox; s̄_dist]`` with covariance ``δ² I₆``;
- the nine rows of eq. 6 have independent noise, so they are applied as
  sequential scalar updates (algebraically the same as the joint update),
  each with the Joseph form of the covariance update;
- ``smooth=True`` (default) adds a Rauch–Tung–Striebel backward pass. The
  reference vectors are learning data computed offline, so using future
  samples is allowed; the smoother removes the lag of the forward filter in
  the directions the constraint does not fix. ``smooth=False`` returns the
  paper's forward filter.

The constant vectors are "measured" again at every sample, so δ and σ_w
together set how long the filter remembers: with σ_w ≪ δ the state
integrates the constraint over many samples (and many relative
orientations) and can correct a biased calibration; with σ_w ≳ δ each
sample is nearly a separate least-squares problem, the minimum-change
(δ-weighted) correction of the constants that satisfies eq. 5. The defaults
(δ = 3 cm, σ_w = 2 cm/√s) lean towards the second, which follows
deformation as fast as the motion.

Only ``s_prox − R_pd s_dist`` is observed at one sample: three of the six
state directions (moving the joint centre by the same physical vector in
both frames) are fixed only by the constant-vector prior and by how
``R_pd`` varies over time. Relative positions computed from the output
equal the reference to ~ε regardless.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError, ShapeError


@dataclass(frozen=True)
class ReferenceKFParams:
    """Noise parameters of the reference-S2J Kalman filter (eq. 4–6).

    Attributes:
        constant_noise_m: δ, standard deviation of the constant S2J vectors
            as measurements of the time-varying ones (eq. 6), m. Larger values
            let the vectors deform further from the constants.
        position_noise_m: ε, standard deviation of the reference relative
            position (eq. 5–6, "near zero"), m.
        process_noise_m_per_sqrt_s: σ_w, random-walk spectral density of the
            S2J vectors (eq. 4), m/√s; per-sample variance ``σ_w² / rate_hz``.
        smooth: run the RTS backward pass after the forward filter.
    """

    constant_noise_m: float = 0.03
    position_noise_m: float = 1e-4
    process_noise_m_per_sqrt_s: float = 0.02
    smooth: bool = True

    def __post_init__(self) -> None:
        for name in ("constant_noise_m", "position_noise_m", "process_noise_m_per_sqrt_s"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"ReferenceKFParams.{name} must be a positive number, got {value}")


@dataclass(frozen=True)
class ReferenceS2J:
    """Per-sample reference S2J vectors of one joint (result of :func:`estimate_reference_s2j`).

    Attributes:
        s_prox_m: (N, 3) proximal sensor -> joint centre, proximal sensor frame, m.
        s_dist_m: (N, 3) distal sensor -> joint centre, distal sensor frame, m.
        std_m: (N, 6) posterior standard deviation of the six state
            components, m.
        constraint_rms_m: RMS over samples of ``‖s_prox − R_pd s_dist − p_pd,ref‖``, m.
    """

    s_prox_m: FloatArray
    s_dist_m: FloatArray
    std_m: FloatArray
    constraint_rms_m: float


# The two kernels are written as plain scalar loops in one function each: numba
# compiles them in a few seconds (array expressions, helper calls and
# np.linalg cost several times more).


@numba.njit(cache=True)
def _kalman_forward(
    R_pd: FloatArray,
    p_ref: FloatArray,
    s_bar: FloatArray,
    q_var: float,
    r_const: float,
    r_pos: float,
    xs: FloatArray,
    Ps: FloatArray,
) -> None:
    """Forward pass (eq. 4–6); writes filtered states xs (N, 6) and covariances Ps (N, 6, 6).

    The nine measurement rows have independent noise and are applied one at a
    time (exactly the joint update), each with the Joseph-form covariance update.
    """
    n = p_ref.shape[0]
    x = np.empty(6)
    P = np.zeros((6, 6))
    h = np.zeros(6)
    ph = np.zeros(6)
    k = np.zeros(6)
    A = np.zeros((6, 6))
    AP = np.zeros((6, 6))
    for i in range(6):
        x[i] = s_bar[i]
        P[i, i] = r_const
    for t in range(n):
        if t > 0:
            for i in range(6):
                P[i, i] += q_var
        for row in range(9):
            for i in range(6):
                h[i] = 0.0
            if row < 6:  # the constant vectors
                h[row] = 1.0
                z = s_bar[row]
                r = r_const
            else:  # the reference relative position, [I, -R_pd] x
                i3 = row - 6
                h[i3] = 1.0
                for j in range(3):
                    h[3 + j] = -R_pd[t, i3, j]
                z = p_ref[t, i3]
                r = r_pos
            s = r
            innov = z
            for i in range(6):
                acc = 0.0
                for j in range(6):
                    acc += P[i, j] * h[j]
                ph[i] = acc
            for i in range(6):
                s += h[i] * ph[i]
                innov -= h[i] * x[i]
            for i in range(6):
                k[i] = ph[i] / s
                x[i] += k[i] * innov
            # Joseph form: P <- (I - k h) P (I - k h)^T + r k k^T
            for i in range(6):
                for j in range(6):
                    A[i, j] = (1.0 if i == j else 0.0) - k[i] * h[j]
            for i in range(6):
                for j in range(6):
                    acc = 0.0
                    for m in range(6):
                        acc += A[i, m] * P[m, j]
                    AP[i, j] = acc
            for i in range(6):
                for j in range(i, 6):
                    acc = r * k[i] * k[j]
                    for m in range(6):
                        acc += AP[i, m] * A[j, m]
                    P[i, j] = acc
                    P[j, i] = acc
        for i in range(6):
            xs[t, i] = x[i]
            for j in range(6):
                Ps[t, i, j] = P[i, j]


@numba.njit(cache=True)
def _rts_backward(xs: FloatArray, Ps: FloatArray, q_var: float) -> None:
    """Rauch–Tung–Striebel pass for the identity process model, in place on xs (N, 6), Ps (N, 6, 6).

    ``C = P_f (P_f + Q)^-1``, ``x_s = x_f + C (x_s,next − x_f)``,
    ``P_s = P_f + C (P_s,next − P_f − Q) C^T``.
    """
    n = xs.shape[0]
    L = np.zeros((6, 6))
    C = np.zeros((6, 6))
    CdP = np.zeros((6, 6))
    dP = np.zeros((6, 6))
    dx = np.zeros(6)
    Pf = np.zeros((6, 6))
    for t in range(n - 2, -1, -1):
        for i in range(6):
            dx[i] = xs[t + 1, i] - xs[t, i]  # xs[t + 1] is already smoothed
            for j in range(6):
                Pf[i, j] = Ps[t, i, j]
        # P_pred = P_f + Q; Cholesky L L^T = P_pred
        for i in range(6):
            for j in range(i + 1):
                acc = Pf[i, j] + (q_var if i == j else 0.0)
                for m in range(j):
                    acc -= L[i, m] * L[j, m]
                if i == j:
                    L[i, i] = np.sqrt(max(acc, 1e-300))
                else:
                    L[i, j] = acc / L[j, j]
        # C^T = P_pred^-1 P_f, column by column
        for c in range(6):
            for i in range(6):
                acc = Pf[i, c]
                for m in range(i):
                    acc -= L[i, m] * C[c, m]
                C[c, i] = acc / L[i, i]
            for i in range(5, -1, -1):
                acc = C[c, i]
                for m in range(i + 1, 6):
                    acc -= L[m, i] * C[c, m]
                C[c, i] = acc / L[i, i]
        for i in range(6):
            for j in range(6):
                dP[i, j] = Ps[t + 1, i, j] - Pf[i, j] - (q_var if i == j else 0.0)
        for i in range(6):
            acc = 0.0
            for j in range(6):
                acc += C[i, j] * dx[j]
            xs[t, i] += acc
        for i in range(6):
            for j in range(6):
                acc = 0.0
                for m in range(6):
                    acc += C[i, m] * dP[m, j]
                CdP[i, j] = acc
        for i in range(6):
            for j in range(i, 6):
                acc = Pf[i, j]
                for m in range(6):
                    acc += CdP[i, m] * C[j, m]
                Ps[t, i, j] = acc
                Ps[t, j, i] = acc


def estimate_reference_s2j(
    R_pd: ArrayLike,
    p_pd_ref_m: ArrayLike,
    s_prox_const_m: ArrayLike,
    s_dist_const_m: ArrayLike,
    *,
    rate_hz: float,
    params: ReferenceKFParams | None = None,
) -> ReferenceS2J:
    """Reference S2J vectors of one joint at every sample (Lee & Lee 2022, eq. 4–6).

    Args:
        R_pd: (N, 3, 3) reference relative orientation, maps distal-sensor
            coordinates to proximal-sensor coordinates
            (:func:`lowerlimb.s2j.relative_position.relative_rotation`).
        p_pd_ref_m: (N, 3) reference position of the distal sensor relative to
            the proximal one, proximal sensor frame, m
            (:func:`lowerlimb.s2j.relative_position.reference_relative_position`).
        s_prox_const_m: (3,) constant S2J vector of the proximal sensor
            (``center_in_parent_sensor``), m.
        s_dist_const_m: (3,) constant S2J vector of the distal sensor
            (``center_in_child_sensor``), m.
        rate_hz: sampling rate, Hz (sets the per-sample process noise).
        params: noise parameters; defaults to :class:`ReferenceKFParams`.

    Returns:
        The per-sample vectors, their posterior standard deviations and the
        RMS residual of eq. 5.

    Raises:
        ShapeError: on wrong shapes or mismatched numbers of samples.
        InputError: on NaN values, a non-positive rate or fewer than 2 samples.
    """
    p = params if params is not None else ReferenceKFParams()
    R = np.ascontiguousarray(R_pd, dtype=float)
    pr = np.ascontiguousarray(p_pd_ref_m, dtype=float)
    sp = np.asarray(s_prox_const_m, dtype=float)
    sd = np.asarray(s_dist_const_m, dtype=float)
    if R.ndim != 3 or R.shape[1:] != (3, 3):
        raise ShapeError(f"R_pd must have shape (N, 3, 3), got {R.shape}")
    if pr.shape != (R.shape[0], 3):
        raise ShapeError(
            f"p_pd_ref_m must have shape (N, 3) = {(R.shape[0], 3)} to match R_pd, got {pr.shape}"
        )
    if sp.shape != (3,) or sd.shape != (3,):
        raise ShapeError(f"the constant S2J vectors must have shape (3,), got {sp.shape} and {sd.shape}")
    if R.shape[0] < 2:
        raise InputError(f"need at least 2 samples for the reference KF, got {R.shape[0]}")
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"rate_hz must be a positive number of samples per second, got {rate_hz}")
    named = (("R_pd", R), ("p_pd_ref_m", pr), ("s_prox_const_m", sp), ("s_dist_const_m", sd))
    for name, a in named:
        if not np.all(np.isfinite(a)):
            raise InputError(f"{name} contains NaN or infinite values; fill or cut the gaps first")
    q_var = p.process_noise_m_per_sqrt_s**2 / float(rate_hz)
    n = R.shape[0]
    xs = np.empty((n, 6))
    Ps = np.empty((n, 6, 6))
    _kalman_forward(
        R, pr, np.concatenate([sp, sd]), q_var, p.constant_noise_m**2, p.position_noise_m**2, xs, Ps
    )
    if p.smooth:
        _rts_backward(xs, Ps, q_var)
    s_prox = xs[:, :3].copy()
    s_dist = xs[:, 3:].copy()
    resid = s_prox - np.einsum("nij,nj->ni", R, s_dist) - pr
    std = np.sqrt(np.maximum(np.diagonal(Ps, axis1=1, axis2=2), 0.0))
    return ReferenceS2J(
        s_prox_m=s_prox,
        s_dist_m=s_dist,
        std_m=std,
        constraint_rms_m=float(np.sqrt(np.mean(np.sum(resid**2, axis=1)))),
    )
