"""Checks of a reference against lowerlimb's outputs: its clock, its time overlap, its units.

Each check refuses what would otherwise give plausible-looking but meaningless
statistics: time in ms (a few reference samples stretched over the whole
trial), time spans that barely overlap, angles in radians, positions in mm.
The thresholds are those of :class:`~lowerlimb.agreement.params.AgreementParams`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..conventions import FloatArray
from ..errors import TimeAxisError
from ..io.time_axis import require_increasing
from .errors import NoTimeOverlapError, ReferenceTimeUnitError, ReferenceUnitError, TooLittleTimeOverlapError
from .params import AgreementParams

#: Per our unit, the units a reference column is often in by mistake: name, factor, fix.
WRONG_UNITS: dict[str, tuple[tuple[str, float, str], ...]] = {
    "deg": (("radians", 180.0 / np.pi, "multiply by 180/π"),),
    "m": (("millimetres", 1000.0, "divide by 1000"), ("centimetres", 100.0, "divide by 100")),
}


def check_reference_time(
    time_ref_s: ArrayLike,
    *,
    time_s: ArrayLike | None = None,
    path: str = "",
    params: AgreementParams | None = None,
) -> FloatArray:
    """The reference's time column, checked: finite, strictly increasing, in seconds.

    Args:
        time_ref_s: (M,) reference sample times, meant to be s.
        time_s: (N,) our sample times, s, to name our step in the message (optional).
        path: the reference file, for the messages.
        params: thresholds; defaults to :class:`AgreementParams`.

    Returns:
        (M,) the times as floats, s.

    Raises:
        TimeAxisError: fewer than 2 samples, a non-finite time, or time not
            strictly increasing (naming the data row).
        ReferenceTimeUnitError: the median step is longer than
            ``1 / min_reference_rate_hz`` (time in ms).
    """
    p = params or AgreementParams()
    t = np.asarray(time_ref_s, dtype=float)
    whose = f"the time of reference {path}" if path else "the reference time"
    if t.ndim != 1 or t.size < 2:
        raise TimeAxisError(
            f"the reference time axis needs at least 2 samples, got shape {t.shape}; export more rows"
        )
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise TimeAxisError(
            f"{whose} is not a number at data row {bad[0] + 1} (the time column must be finite and "
            f"strictly increasing); fill or drop that row"
        )
    require_increasing(t, whose, "sort the rows and drop repeated times")
    step = float(np.median(np.diff(t)))
    if step > 1.0 / p.min_reference_rate_hz:
        ours = None
        if time_s is not None and np.size(time_s) > 1:
            ours = float(np.median(np.diff(np.asarray(time_s, dtype=float))))
        raise ReferenceTimeUnitError(step, ours, path)
    return t


def span_overlap_s(time_s: FloatArray, time_ref_s: FloatArray, margin_s: float = 0.0) -> float:
    """The longest overlap of the two time spans, s, over shifts of the reference within ±``margin_s``.

    Args:
        time_s: (N,) our sample times, s, increasing.
        time_ref_s: (M,) reference sample times, s, increasing.
        margin_s: largest shift of the reference considered, s (0: as given).

    Returns:
        The overlap, s; negative when the spans are apart (by that much).
    """
    t0, t1 = float(time_s[0]), float(time_s[-1])
    r0, r1 = float(time_ref_s[0]), float(time_ref_s[-1])
    shifts = np.clip([-margin_s, margin_s, t0 - r0, t1 - r1], -margin_s, margin_s)
    return max(min(t1, r1 + s) - max(t0, r0 + s) for s in shifts)


def check_time_overlap(
    time_s: ArrayLike,
    time_ref_s: ArrayLike,
    *,
    margin_s: float = 0.0,
    params: AgreementParams | None = None,
) -> None:
    """Refuse time spans that do not overlap, or overlap over too little of the shorter one.

    Args:
        time_s: (N,) our sample times, s, increasing.
        time_ref_s: (M,) reference sample times, s, increasing.
        margin_s: largest clock shift that alignment may still apply, s.
        params: thresholds; defaults to :class:`AgreementParams`.

    Raises:
        NoTimeOverlapError: the spans do not overlap even shifted by ``margin_s``.
        TooLittleTimeOverlapError: they overlap over less than
            ``min_span_overlap_fraction`` of the shorter span.
    """
    p = params or AgreementParams()
    t = np.asarray(time_s, dtype=float)
    t_ref = np.asarray(time_ref_s, dtype=float)
    ours = (float(t[0]), float(t[-1]))
    ref = (float(t_ref[0]), float(t_ref[-1]))
    overlap = span_overlap_s(t, t_ref, margin_s)
    if overlap <= 0:
        raise NoTimeOverlapError(ours, ref)
    shorter = min(ours[1] - ours[0], ref[1] - ref[0])
    if overlap < p.min_span_overlap_fraction * shorter:
        raise TooLittleTimeOverlapError(ours, ref, overlap, p.min_span_overlap_fraction)


def check_reference_unit(
    quantity: str,
    unit: str,
    ours: ArrayLike,
    reference: ArrayLike,
    params: AgreementParams | None = None,
) -> None:
    """Refuse a reference column whose size says radians (for deg) or mm/cm (for m).

    Only the pairs where both are finite count. Angles: the reference is
    taken to be in radians when it spans less than ``max_radians_range`` while
    ours spans at least ``min_radians_check_range_deg`` deg, about 180/π times
    more. Positions: in mm (or cm) when its RMS exceeds ``max_position_m``
    and is about 1000 (or 100) times ours. "About" is within
    ``unit_factor_tolerance`` either way.

    Args:
        quantity: the column name.
        unit: our unit of it, ``"deg"`` or ``"m"`` (others are not checked).
        ours: (n,) our values, ``unit``.
        reference: (n,) reference values on our time stamps, meant to be ``unit``.
        params: thresholds; defaults to :class:`AgreementParams`.

    Raises:
        ReferenceUnitError: naming the column, the unit it looks like and the factor.
    """
    p = params or AgreementParams()
    x = np.asarray(ours, dtype=float)
    y = np.asarray(reference, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < p.min_samples:
        return
    x, y = x[ok], y[ok]
    if unit == "deg":
        ours_size, ref_size = float(np.ptp(x)), float(np.ptp(y))
        if ours_size < p.min_radians_check_range_deg or ref_size >= p.max_radians_range:
            return
    elif unit == "m":
        ours_size, ref_size = float(np.sqrt(np.mean(x * x))), float(np.sqrt(np.mean(y * y)))
        if ref_size <= p.max_position_m:
            return
    else:
        return
    if ref_size <= 0 or ours_size <= 0:
        return
    ratio = ours_size / ref_size if unit == "deg" else ref_size / ours_size
    for name, factor, fix in WRONG_UNITS[unit]:
        if abs(np.log(ratio / factor)) <= np.log(p.unit_factor_tolerance):
            raise ReferenceUnitError(quantity, unit, ref_size, ours_size, name, fix)
