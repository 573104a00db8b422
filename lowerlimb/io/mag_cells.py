"""Empty magnetometer cells of a trial CSV: bridged, or the magnetometer left out (6-axis).

Exports often carry a magnetometer sampled slower than the accelerometer and gyro (every
other row empty), or magnetometer columns that a 6-axis recording left empty. The
magnetometer only steers the headings (it is optional), so neither refuses a trial the way an
empty accelerometer or gyro cell does:

- a sensor whose magnetometer column is empty throughout, or whose longest run of empty
  cells is longer than :attr:`~lowerlimb.io.params.ImportParams.max_gap_s`: no magnetometer is
  used (every sensor's field is needed), with one :class:`MagnetometerCellsWarning`;
- shorter runs: each column is interpolated linearly in time (the ends take the nearest
  value), with one warning saying how many cells were filled.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..conventions import FloatArray
from .params import ImportParams
from .saturation import longest_run

__all__ = ["MagnetometerCellsWarning", "bridged_magnetometer"]


class MagnetometerCellsWarning(UserWarning):
    """The trial's magnetometer columns have empty cells: interpolated, or not used."""


def _interpolated(time_s: FloatArray, x: FloatArray) -> FloatArray:
    """(N, 3) ``x`` with every NaN replaced by linear interpolation in time, per column."""
    out = x.copy()
    for j in range(x.shape[1]):
        bad = np.isnan(x[:, j])
        if bad.any():
            out[bad, j] = np.interp(time_s[bad], time_s[~bad], x[~bad, j])
    return out


def bridged_magnetometer(
    time_s: FloatArray,
    mag: dict[str, FloatArray] | None,
    params: ImportParams | None = None,
) -> dict[str, FloatArray] | None:
    """The magnetometer with its empty (NaN) cells bridged, or ``None`` where they cannot be.

    Args:
        time_s: (N,) sample times, s.
        mag: ``{sensor: (N, 3)}`` magnetic field, sensor frames, µT, NaN where a cell was empty;
            or ``None`` (no magnetometer).
        params: thresholds (``max_gap_s``).

    Returns:
        ``mag`` unchanged without empty cells; bridged copies; or ``None`` (6-axis).

    Warns:
        MagnetometerCellsWarning: some cells were filled, or the magnetometer is not used.
    """
    if mag is None or not any(np.isnan(m).any() for m in mag.values()):
        return mag
    p = params or ImportParams()
    step = float(np.median(np.diff(time_s))) if len(time_s) > 1 else 1.0
    for sensor, m in mag.items():
        missing = np.asarray(np.isnan(m).any(axis=1))
        reason = None
        if missing.all():
            reason = f"the {sensor} magnetometer columns are empty"
        elif (gap_s := longest_run(missing) * step) > p.max_gap_s:
            reason = (
                f"the {sensor} magnetometer has a run of empty cells {gap_s:.3g} s long (bridged up to "
                f"{p.max_gap_s:g} s)"
            )
        if reason is not None:
            _warn_unused(reason)
            return None
    filled = sum(int(np.isnan(m).any(axis=1).sum()) for m in mag.values())
    warnings.warn(
        f"{filled} of {len(time_s) * len(mag)} magnetometer samples were empty (a magnetometer sampled "
        f"slower than the other signals?); interpolated in time",
        MagnetometerCellsWarning,
        stacklevel=3,
    )
    return {s: _interpolated(time_s, m) for s, m in mag.items()}


def _warn_unused(reason: str) -> None:
    warnings.warn(
        f"{reason}; the orientation filters need every sensor's field, so none is used (6-axis); "
        f"fill the magnetometer columns, or drop them to silence this",
        MagnetometerCellsWarning,
        stacklevel=4,
    )
