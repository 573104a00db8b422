"""Huber weights of the spherical residual: samples that break the rigid constraint count less.

The rigid-body constraint of Hu et al. 2021 (eq. 7) fails for short spells: at heel strike
and toe-off a sensor rings on its strap and the skin slides, and on the seven-IMU
simulator the kinematics kink at the contacts. There the residual is many times its
typical size (on simulated walks its RMS is 2.3 m/s² at the ankle against a robust
scale of 0.6 m/s²), and least squares lets those few samples decide the centre. Huber's
M-estimator (Huber 1964, *Ann. Math. Stat.* 35:73–101; iteratively reweighted least
squares, Holland & Welsch 1977, *Commun. Stat.* 6:813–827) keeps the squared cost for
residuals below ``k s`` and a linear one above, i.e. weights

    w(t) = min(1, k s / |e(t)|),     s = 1.4826 · median |e − median e|

(``s``: the residual's scale from its median absolute deviation, consistent for Gaussian
noise; ``k = 1.345`` gives 95 % efficiency at the Gaussian, Holland & Welsch 1977).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import FloatArray

__all__ = ["MAD_TO_STD", "huber_weights"]

#: Standard deviation over median absolute deviation of a Gaussian, 1/Φ⁻¹(3/4).
MAD_TO_STD = 1.4826


def huber_weights(residual: ArrayLike, k: float, floor: float = 0.0) -> FloatArray:
    """Huber IRLS weights of a residual.

    Args:
        residual: (N,) residual, any unit.
        k: Huber's threshold in robust standard deviations.
        floor: lowest scale, residual units (noise-free data would otherwise
            weight every sample by its own tiny residual).

    Returns:
        (N,) weights in (0, 1].
    """
    r = np.asarray(residual, dtype=float)
    s = max(MAD_TO_STD * float(np.median(np.abs(r - np.median(r)))), floor)
    if s <= 0.0:
        return np.ones_like(r)
    a = np.abs(r)
    return np.asarray(np.where(a > k * s, k * s / np.maximum(a, 1e-300), 1.0), dtype=float)
