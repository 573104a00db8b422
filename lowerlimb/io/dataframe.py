"""The output tables as one pandas DataFrame: time index, angles (deg) and positions (m), units attached.

pandas is an optional dependency (``pip install 'lowerlimb[pandas]'``); it is
imported only when a DataFrame is asked for.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..conventions import ANGLE_COLUMNS, POSITION_COLUMNS, FloatArray
from ..errors import MissingDependencyError, ShapeError
from .tables import ANGLE_UNIT, POSITION_UNIT, TIME_UNIT


def column_units() -> dict[str, str]:
    """Unit of every column of :func:`motion_dataframe` (angles.csv then positions.csv names)."""
    return {c: ANGLE_UNIT for c in ANGLE_COLUMNS[1:]} | {c: POSITION_UNIT for c in POSITION_COLUMNS[1:]}


def motion_dataframe(time_s: FloatArray, angles_rad: FloatArray, positions_m: FloatArray) -> Any:
    """A ``pandas.DataFrame`` of a trial's angles and positions, as ``angles.csv`` + ``positions.csv``.

    The index is ``time`` (s, float). The columns are the angle columns of
    ``angles.csv`` in DEGREES, then the position columns of ``positions.csv`` in
    metres (pelvis sensor frame). Units travel with the frame in
    ``df.attrs["units"]`` (column -> unit; ``"time"`` -> ``"s"`` for the index),
    and ``df.attrs["description"]`` says what the values are.

    Args:
        time_s: (N,) sample times, s.
        angles_rad: (N, 9) ISB joint angles, rad, ``angles.csv`` order.
        positions_m: (N, 6) position vectors, m, ``positions.csv`` order.

    Returns:
        The DataFrame (N rows, 15 columns).

    Raises:
        MissingDependencyError: pandas is not installed.
        ShapeError: an array's shape does not match the above.
    """
    try:
        import pandas as pd
    except ImportError:
        raise MissingDependencyError("pandas", "TrialResult.to_dataframe()", "pandas") from None
    t = np.asarray(time_s, dtype=float)
    a = np.asarray(angles_rad, dtype=float)
    p = np.asarray(positions_m, dtype=float)
    n_a, n_p = len(ANGLE_COLUMNS) - 1, len(POSITION_COLUMNS) - 1
    if t.ndim != 1 or a.shape != (t.size, n_a) or p.shape != (t.size, n_p):
        raise ShapeError(
            f"expected time (N,), angles (N, {n_a}) and positions (N, {n_p}); "
            f"got {t.shape}, {a.shape}, {p.shape}"
        )
    data = np.column_stack([np.rad2deg(a), p])
    index = pd.Index(t, name="time")
    df = pd.DataFrame(data, index=index, columns=list(ANGLE_COLUMNS[1:] + POSITION_COLUMNS[1:]))
    df.attrs["units"] = {"time": TIME_UNIT} | column_units()
    df.attrs["description"] = (
        "ISB joint angles (Z-X-Y: flexion, adduction, internal rotation; clinical signs; zero = standing "
        "reference posture) in deg; pelvis sensor -> foot sensor and hip centre -> ankle centre vectors "
        "in the pelvis sensor frame, m"
    )
    return df
