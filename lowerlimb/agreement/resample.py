"""Linear resampling of a reference table onto our clock, with NaN outside and across gaps."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..conventions import FloatArray


def resample_linear(time_src_s: ArrayLike, values_src: ArrayLike, time_dst_s: ArrayLike) -> FloatArray:
    """Linear interpolation of columns onto new times; NaN where it cannot be done.

    A destination time gets NaN when it lies outside ``[time_src_s[0],
    time_src_s[-1]]`` (no extrapolation) or when one of its two bracketing
    source samples is NaN with a non-zero interpolation weight (a gap in the
    reference is not bridged).

    Args:
        time_src_s: (M,) strictly increasing source times, s.
        values_src: (M,) or (M, Q) source values, any unit, NaN for missing.
        time_dst_s: (N,) destination times, s (same clock as the source).

    Returns:
        (N,) or (N, Q) values, same unit as ``values_src``.
    """
    t_src = np.asarray(time_src_s, dtype=float)
    t_dst = np.asarray(time_dst_s, dtype=float)
    v = np.asarray(values_src, dtype=float)
    cols = v.reshape(v.shape[0], -1)
    out = np.empty((t_dst.size, cols.shape[1]))
    outside = (t_dst < t_src[0]) | (t_dst > t_src[-1])
    for j in range(cols.shape[1]):
        missing = ~np.isfinite(cols[:, j])
        filled = np.where(missing, 0.0, cols[:, j])
        out[:, j] = np.interp(t_dst, t_src, filled)
        touched = np.interp(t_dst, t_src, missing.astype(float)) > 0.0
        out[touched | outside, j] = np.nan
    return out.reshape((t_dst.size,) + v.shape[1:])
