"""Excitation diagnostics: is the motion rich enough to determine the joint parameters?

Hu et al. 2021 (§3.1) point out that the Gauss–Newton Jacobian loses rank
when a degree of freedom is not excited (a knee that only flexes, a pelvis
that hardly rotates). Rather than return a poor estimate silently, every
joint result carries an :class:`ExcitationReport` computed from the
Jacobian ``J`` (N×n) of the residual at the solution:

- the singular values of ``J`` and its condition number;
- the Gauss–Newton covariance ``τ σ² (JᵀJ)⁻¹`` (pseudo-inverse), with
  ``σ² = max(RSS/(N − n), noise_floor²)``: the floor keeps noise-free data
  from reporting zero uncertainty in an unobservable direction; ``τ`` is the
  residual's integrated autocorrelation time in samples (Sokal's
  self-consistent window), because the residuals of low-passed signals and of
  soft-tissue motion are far from white: N samples carry only about N/τ
  independent ones, and the white-noise covariance would be τ times too small;
- its standard deviations per parameter and along the weakest direction
  (the right singular vector of the smallest singular value).

When the weakest-direction standard deviation exceeds a tolerance, or a
sensor hardly rotates, an :class:`ExcitationWarning` is issued naming the
joint and the poorly determined direction in sensor coordinates, and the
message is kept in the result.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray

__all__ = ["ExcitationWarning", "ExcitationReport", "correlation_time", "jacobian_report", "issue_warnings"]


class ExcitationWarning(UserWarning):
    """The motion does not excite a joint enough to determine all its parameters."""


@dataclass
class ExcitationReport:
    """Identifiability of one joint's parameters from its residual Jacobian.

    Attributes:
        singular_values: (n,) singular values of the Jacobian, descending
            (units: residual unit per parameter unit).
        condition_number: largest over smallest singular value (inf if rank deficient).
        std: (n,) standard deviation of each parameter (parameter units).
        weakest_direction: (n,) unit vector in parameter space along which the
            estimate is least certain.
        weakest_std: standard deviation along ``weakest_direction`` (parameter units).
        noise_std: residual noise level used for the covariance (residual units).
        correlation_samples: integrated autocorrelation time ``τ`` of the residual,
            samples (1 for white residuals); the covariance is scaled by it.
        warnings: human-readable messages; non-empty means insufficient excitation.
    """

    singular_values: FloatArray
    condition_number: float
    std: FloatArray
    weakest_direction: FloatArray
    weakest_std: float
    noise_std: float
    correlation_samples: float = 1.0
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (lists of floats)."""
        return {
            "singular_values": [float(v) for v in self.singular_values],
            "condition_number": _finite_or_none(self.condition_number),
            "std": [_finite_or_none(float(v)) for v in self.std],
            "weakest_direction": [float(v) for v in self.weakest_direction],
            "weakest_std": _finite_or_none(self.weakest_std),
            "noise_std": float(self.noise_std),
            "correlation_samples": float(self.correlation_samples),
            "warnings": list(self.warnings),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ExcitationReport:
        """Inverse of :meth:`to_dict`."""
        cn = d.get("condition_number")
        return cls(
            singular_values=np.asarray(d["singular_values"], dtype=float),
            condition_number=float("inf") if cn is None else float(cn),
            std=np.array([np.inf if v is None else float(v) for v in d["std"]]),
            weakest_direction=np.asarray(d["weakest_direction"], dtype=float),
            weakest_std=float("inf") if d["weakest_std"] is None else float(d["weakest_std"]),
            noise_std=float(d["noise_std"]),
            correlation_samples=float(d.get("correlation_samples", 1.0)),
            warnings=list(d.get("warnings", [])),
        )


def _finite_or_none(v: float) -> float | None:
    return float(v) if np.isfinite(v) else None


def correlation_time(residual: ArrayLike, *, window_factor: float = 5.0) -> float:
    """Integrated autocorrelation time of a time-ordered residual, samples.

    ``τ = 1 + 2 Σ_{k=1}^{M} ρ_k`` with the window ``M`` chosen self-consistently as
    the smallest ``M ≥ window_factor · τ(M)`` (Sokal 1997), the autocorrelation
    ``ρ`` by FFT. White residuals give about 1.

    Args:
        residual: (N,) residual in time order (any unit).
        window_factor: Sokal's ``c`` (5 is customary).

    Returns:
        τ ≥ 1, samples.
    """
    x = np.asarray(residual, dtype=float)
    x = x - x.mean()
    n = x.shape[0]
    if n < 4 or not np.any(x):
        return 1.0
    f = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n]
    rho = acf / acf[0]
    tau = 1.0 + 2.0 * np.cumsum(rho[1:])
    m = np.arange(1, n)
    ok = np.flatnonzero(m >= window_factor * tau)
    value = float(tau[ok[0]]) if ok.size else float(tau[-1])
    return max(value, 1.0)


def jacobian_report(
    J: ArrayLike,
    residual: ArrayLike,
    *,
    noise_floor: float,
    param_map: ArrayLike | None = None,
) -> ExcitationReport:
    """Singular values, condition number and Gauss–Newton covariance of a least-squares fit.

    Args:
        J: (N, n) Jacobian of the residual at the solution.
        residual: (N,) residual at the solution.
        noise_floor: smallest residual noise standard deviation assumed (residual units).
        param_map: optional (m, n) linear map from the solved parameters to the
            reported ones (``x = M y``): the covariance becomes ``M C Mᵀ`` and the
            weakest direction ``M v`` (normalised; its standard deviation scaled).

    Returns:
        The report (without warnings; the caller adds them).
    """
    Ja = np.asarray(J, dtype=float)
    r = np.asarray(residual, dtype=float)
    n_obs, n_par = Ja.shape
    dof = max(n_obs - n_par, 1)
    tau = correlation_time(r)
    sigma = max(float(np.sqrt(np.sum(r**2) / dof)), noise_floor)
    spread = sigma * float(np.sqrt(tau))  # standard deviation scale of the estimate
    _, s, Vt = np.linalg.svd(Ja, full_matrices=False)
    tiny = s[0] * 1e-12 if s.size and s[0] > 0 else 1e-300
    inv_s = np.where(s > tiny, 1.0 / np.where(s > tiny, s, 1.0), np.inf)
    cond = float(s[0] / s[-1]) if s[-1] > tiny else float("inf")
    A = Vt.T * inv_s  # covariance = sigma² A Aᵀ
    weakest = Vt[-1].copy()
    weakest_std = float(spread * inv_s[-1])
    if param_map is not None:
        M = np.asarray(param_map, dtype=float)
        A = M @ np.where(np.isfinite(A), A, 0.0)
        if not np.all(np.isfinite(inv_s)):
            A = np.full_like(A, np.inf)
        weakest = M @ weakest
        scale = float(np.linalg.norm(weakest))
        weakest /= scale
        weakest_std *= scale
    with np.errstate(invalid="ignore"):
        std = spread * np.sqrt(np.sum(A**2, axis=1))
    weakest *= np.sign(weakest[np.argmax(np.abs(weakest))]) or 1.0
    return ExcitationReport(
        singular_values=s,
        condition_number=cond,
        std=std,
        weakest_direction=weakest,
        weakest_std=weakest_std,
        noise_std=sigma,
        correlation_samples=tau,
    )


def issue_warnings(messages: list[str], stacklevel: int = 3) -> None:
    """Issue each message as an :class:`ExcitationWarning`."""
    for m in messages:
        warnings.warn(m, ExcitationWarning, stacklevel=stacklevel)
