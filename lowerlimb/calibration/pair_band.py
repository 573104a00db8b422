"""Which band a two-IMU spherical fit keeps: the sensors' own, or the pair's rigid band.

A leg's calibration always caps a joint's cut-offs at the band in which its two
accelerometer norms stay coherent (``CalibrationOptions.rigid_band``): above it, soft
tissue, strap resonance and impacts move the sensors on their segments and break the
rigid-body constraint (Hu 2021 eq. 3). An arbitrary pair's motion can make the norms
incoherent although the chain is rigid (the two lever arms see different centripetal
accelerations), so :func:`~lowerlimb.calibration.joint_center.calibrate_spherical_joint`
fits both bands and keeps the cap only where the two fits say the sensors are not rigid:

- ``low_band_gain`` = RMS(eq. 3 of the uncapped centres on the capped band) /
  RMS(the capped centres on it) − 1: what the uncapped fit fails to explain below the cap;
- ``full_band_cost`` = RMS(the capped centres on the full band) / RMS(the uncapped
  centres on it) − 1: what the capped fit fails to explain above it.

Rigid sensors leave both small and alike (the mechanical rig of ``rig.md``, 2D and 3D
trials: gains 0.05 / 0.15 against costs 0.04 / 0.08; its hinge trial 0.09 / 0.41); a
sensor that moves on its segment makes the uncapped centres fail below the cap far more
than the capped ones fail above it (the real walk's hips and ankles: gains 0.74–2.1
against costs 0.09–1.0). The cap is kept when the gain exceeds the cost by
``CalibrationOptions.pair_band_margin``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.constraints.spherical import SphericalData, spherical_residual
from lowerlimb.conventions import FloatArray

__all__ = ["PairBand", "choose_band"]


@dataclass(frozen=True)
class PairBand:
    """The band test of one two-IMU spherical fit (see the module docstring).

    Attributes:
        cap_hz: the pair's rigid-band cap, Hz.
        low_band_gain: how much worse the uncapped centres explain the capped band (ratio − 1).
        full_band_cost: how much worse the capped centres explain the full band (ratio − 1).
        capped: whether the capped fit was kept.
    """

    cap_hz: float
    low_band_gain: float
    full_band_cost: float
    capped: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (calibration.json ``pair_band``)."""
        return {
            "cap_hz": float(self.cap_hz),
            "low_band_gain": float(self.low_band_gain),
            "full_band_cost": float(self.full_band_cost),
            "capped": bool(self.capped),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> PairBand:
        """Inverse of :meth:`to_dict`."""
        gain, cost = float(d["low_band_gain"]), float(d["full_band_cost"])
        return cls(float(d["cap_hz"]), gain, cost, bool(d["capped"]))


def _rms(centres: FloatArray, data: SphericalData) -> float:
    return float(np.sqrt(np.mean(spherical_residual(centres, data) ** 2)))


def choose_band(
    uncapped: FloatArray,
    capped: FloatArray,
    full: SphericalData,
    band: SphericalData,
    *,
    cap_hz: float,
    margin: float,
    keep: ArrayLike | None = None,
) -> PairBand:
    """Whether the capped fit of a pair is kept (see the module docstring).

    Args:
        uncapped: (6,) ``(c_parent, c_child)`` fitted on ``full``, sensor frames, m.
        capped: (6,) ``(c_parent, c_child)`` fitted on ``band``, m.
        full: the pair's data at its sensors' own cut-offs.
        band: the pair's data at the rigid band's cap.
        cap_hz: the cap, Hz (recorded).
        margin: the gain must exceed the cost by this much
            (``CalibrationOptions.pair_band_margin``).
        keep: (N,) booleans, the samples both fits used (``None``: all).

    Returns:
        The test's numbers and verdict.
    """
    if keep is not None:
        full, band = full.select(keep), band.select(keep)
    gain = _rms(uncapped, band) / max(_rms(capped, band), 1e-12) - 1.0
    cost = _rms(capped, full) / max(_rms(uncapped, full), 1e-12) - 1.0
    return PairBand(cap_hz, gain, cost, gain > cost + margin)
