"""Whole comparison of lowerlimb outputs with a reference: alignment, resampling, statistics."""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from ..conventions import FloatArray
from ..errors import ShapeError, TimeAxisError
from .alignment import TimeAlignment, estimate_time_offset
from .errors import EmptyReferenceError, NoCommonColumnsError
from .params import AgreementParams
from .reference_checks import check_reference_time, check_reference_unit, check_time_overlap
from .resample import resample_linear
from .statistics import QuantityAgreement, agreement_statistics


@dataclass(frozen=True)
class PairedSeries:
    """The valid (lowerlimb, reference) pairs of one quantity, as the statistics used them.

    Attributes:
        quantity: column name.
        unit: ``"deg"`` or ``"m"``.
        time_s: (n,) our sample times of the pairs, s.
        ours: (n,) lowerlimb values, ``unit``, after any offset removal.
        reference: (n,) reference values resampled onto ``time_s``, ``unit``.
    """

    quantity: str
    unit: str
    time_s: FloatArray
    ours: FloatArray
    reference: FloatArray


@dataclass(frozen=True)
class Comparison:
    """Result of :func:`compare_series`.

    Attributes:
        quantities: statistics per compared quantity, in our column order.
        series: the pairs behind each entry of ``quantities`` (for plots).
        time_offset_s: offset applied to the reference clock, s (0 without alignment).
        alignment: the cross-correlation result, or None when not aligned.
        remove_offset: whether constant offsets were removed per quantity.
        skipped: common quantities without enough valid pairs (not in ``quantities``).
        ignored_reference_columns: reference columns that are not ours.
        params: the thresholds used.
    """

    quantities: tuple[QuantityAgreement, ...]
    series: tuple[PairedSeries, ...]
    time_offset_s: float
    alignment: TimeAlignment | None
    remove_offset: bool
    skipped: tuple[str, ...] = ()
    ignored_reference_columns: tuple[str, ...] = ()
    params: AgreementParams = field(default_factory=AgreementParams)


def compare_series(
    time_s: ArrayLike,
    ours: Mapping[str, ArrayLike],
    units: Mapping[str, str],
    time_ref_s: ArrayLike,
    reference: Mapping[str, ArrayLike],
    *,
    align_time: bool = False,
    remove_offset: bool = False,
    params: AgreementParams | None = None,
) -> Comparison:
    """Compare every quantity the reference shares with our outputs.

    Stages: check the reference's clock (s, not ms) and its time overlap
    with ours → pick the common columns → (optionally) estimate the clock
    offset by cross-correlation (:func:`estimate_time_offset`) → resample the
    reference onto our clock by linear interpolation over the overlap
    (:func:`resample_linear`) → refuse a column whose size says radians or
    mm (:func:`~lowerlimb.agreement.reference_checks.check_reference_unit`)
    → statistics per quantity (:func:`agreement_statistics`, optionally
    after removing each constant offset).

    Args:
        time_s: (N,) our sample times, s, strictly increasing.
        ours: quantity name -> (N,) values (angles in deg, positions in m).
        units: quantity name -> unit string for every key of ``ours``.
        time_ref_s: (M,) reference sample times, s, strictly increasing.
        reference: column name -> (M,) values in the same units; NaN = missing.
        align_time: estimate and apply the clock offset.
        remove_offset: remove the constant offset of each quantity.
        params: thresholds; defaults to :class:`AgreementParams`.

    Returns:
        The comparison.

    Raises:
        NoCommonColumnsError: no reference column is one of ours.
        NoTimeOverlapError: the time axes do not overlap (within the search window when aligning).
        TooLittleTimeOverlapError: they overlap over less than ``min_span_overlap_fraction``
            of the shorter span.
        ReferenceTimeUnitError: the reference's time steps look like ms.
        ReferenceUnitError: a reference column looks like radians (deg expected) or mm (m expected).
        AlignmentError: the offset cannot be estimated.
        EmptyReferenceError: no common quantity has ``min_samples`` valid pairs.
        TimeAxisError: a time axis is not strictly increasing and finite.
        ShapeError: a column's length differs from its time axis.
    """
    p = params or AgreementParams()
    t = _time_axis(time_s, "lowerlimb")
    t_ref = check_reference_time(time_ref_s, time_s=t, params=p)
    common = [q for q in ours if q in reference]
    ignored = tuple(c for c in reference if c not in ours)
    if not common:
        raise NoCommonColumnsError(list(reference), list(ours))
    X = _columns(ours, common, t.size, "lowerlimb")
    Y = _columns(reference, common, t_ref.size, "reference")
    margin = p.max_offset_s if align_time else 0.0
    check_time_overlap(t, t_ref, margin_s=margin, params=p)
    alignment = None
    offset = 0.0
    if align_time:
        alignment = estimate_time_offset(t, X, t_ref, Y, params=p)
        offset = alignment.offset_s
        if alignment.ambiguous:
            warnings.warn(
                f"the time offset {offset:+.3f} s is ambiguous: the correlation (r = "
                f"{alignment.peak_correlation:.3f}) is almost as high at "
                f"{alignment.second_peak_offset_s:+.3f} s (r = {alignment.second_peak_correlation:.3f}), "
                f"as a repeating walk gives one stride apart, and the true offset may lie outside "
                f"±{p.max_offset_s:g} s; align the reference by hand (shift its time so that one event "
                f"has the same time in both) and compare without --align-time",
                stacklevel=2,
            )
        elif alignment.at_window_edge:
            warnings.warn(
                f"the best time offset {offset:+.3f} s is at the edge of the ±{p.max_offset_s:g} s "
                f"search window; the true offset may be larger (pre-shift the reference)",
                stacklevel=2,
            )
    Y_on_ours = resample_linear(t_ref + offset, Y, t)
    for j, q in enumerate(common):
        check_reference_unit(q, units[q], X[:, j], Y_on_ours[:, j], params=p)
    stats: list[QuantityAgreement] = []
    series: list[PairedSeries] = []
    skipped: list[str] = []
    for j, q in enumerate(common):
        s = agreement_statistics(
            X[:, j], Y_on_ours[:, j], quantity=q, unit=units[q], remove_offset=remove_offset, params=p
        )
        if s.n < p.min_samples or not np.isfinite(s.rmse):
            skipped.append(q)
            continue
        ok = np.isfinite(X[:, j]) & np.isfinite(Y_on_ours[:, j])
        stats.append(s)
        series.append(PairedSeries(q, units[q], t[ok], X[ok, j] - s.offset_removed, Y_on_ours[ok, j]))
    if not stats:
        raise EmptyReferenceError(skipped, p.min_samples)
    return Comparison(
        quantities=tuple(stats),
        series=tuple(series),
        time_offset_s=offset,
        alignment=alignment,
        remove_offset=remove_offset,
        skipped=tuple(skipped),
        ignored_reference_columns=ignored,
        params=p,
    )


def _time_axis(time_s: ArrayLike, who: str) -> FloatArray:
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise TimeAxisError(f"the {who} time axis needs at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise TimeAxisError(
            f"the {who} time column is not finite and strictly increasing; sort it and drop repeats"
        )
    return t


def _columns(table: Mapping[str, ArrayLike], names: list[str], n: int, who: str) -> FloatArray:
    out = np.empty((n, len(names)))
    for j, q in enumerate(names):
        v = np.asarray(table[q], dtype=float)
        if v.shape != (n,):
            raise ShapeError(f"{who} column '{q}' has shape {v.shape}, expected ({n},) like its time axis")
        out[:, j] = v
    return out
