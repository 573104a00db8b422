"""Time alignment of a reference to our clock by cross-correlation."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..conventions import FloatArray
from .errors import AlignmentError
from .params import AgreementParams
from .resample import resample_linear


@dataclass(frozen=True)
class TimeAlignment:
    """Result of :func:`estimate_time_offset`.

    Attributes:
        offset_s: time added to the reference's time stamps to put them on our
            clock, s: reference sample at ``t_ref`` belongs with our sample at
            ``t_ref + offset_s``.
        peak_correlation: mean Pearson r over the quantities at ``offset_s``.
        search_window_s: half-width of the searched offset interval, s.
        at_window_edge: the best offset lies at the edge of the window (the
            true offset may be larger: widen the window or pre-shift).
        n_quantities: number of quantities that entered the correlation.
        second_peak_offset_s: offset of the highest other peak of the correlation (a local
            maximum, or a window edge the score rises toward, at least
            ``min_peak_separation_s`` from ``offset_s``), s; None when there is none.
        second_peak_correlation: mean Pearson r at ``second_peak_offset_s``; None when none.
        ambiguous: the second peak is almost as high as the best (``ambiguous_peak_ratio``,
            ``clear_misfit_ratio``): which one is the true offset (or whether it lies outside
            the window) cannot be told.
    """

    offset_s: float
    peak_correlation: float
    search_window_s: float
    at_window_edge: bool
    n_quantities: int
    second_peak_offset_s: float | None = None
    second_peak_correlation: float | None = None
    ambiguous: bool = False


def estimate_time_offset(
    time_s: ArrayLike,
    ours: ArrayLike,
    time_ref_s: ArrayLike,
    reference: ArrayLike,
    *,
    params: AgreementParams | None = None,
) -> TimeAlignment:
    """Find the clock offset between our values and a reference by cross-correlation.

    For each candidate offset τ on a grid of our median sample interval over
    ``[-max_offset_s, +max_offset_s]``, the reference is resampled onto our
    times as ``ref(t − τ)`` (linear interpolation, NaN outside and across
    gaps) and the Pearson r of every quantity over its valid pairs is
    averaged (so that quantities in different units weigh the same, and
    constant offsets between the systems do not matter). Offsets at which
    fewer than ``min_overlap_fraction`` of our samples overlap are not
    considered. The best grid offset is refined to sub-sample precision by a
    parabola through the scores at it and its two neighbours (not by
    evaluating the score between grid points: interpolating a noisy reference
    at fractional offsets smooths its noise and would bias the estimate toward
    half-sample offsets).

    Args:
        time_s: (N,) our sample times, s, increasing.
        ours: (N, Q) our values, one column per quantity.
        time_ref_s: (M,) reference times, s, strictly increasing.
        reference: (M, Q) reference values, same columns and units; NaN = missing.
        params: thresholds; defaults to :class:`AgreementParams`.

    Returns:
        The offset and the correlation at it.

    Raises:
        AlignmentError: when no offset in the window overlaps enough samples
            or no quantity varies (nothing to correlate).
    """
    p = params or AgreementParams()
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(ours, dtype=float).reshape(t.size, -1)
    t_ref = np.asarray(time_ref_s, dtype=float)
    y = np.asarray(reference, dtype=float).reshape(t_ref.size, -1)
    dt = float(np.median(np.diff(t)))
    k = int(np.floor(p.max_offset_s / dt + 1e-9))
    grid = np.arange(-k, k + 1) * dt
    scores = np.array([_score(tau, t, x, t_ref, y, p)[0] for tau in grid])
    if not np.any(np.isfinite(scores)):
        raise AlignmentError(
            f"no time offset within ±{p.max_offset_s:g} s gives enough overlapping, varying samples "
            "to correlate; check that both files cover the same recording"
        )
    i = int(np.nanargmax(scores))
    best = float(grid[i])
    if 0 < i < grid.size - 1 and np.all(np.isfinite(scores[i - 1 : i + 2])):
        s_m, s_0, s_p = scores[i - 1 : i + 2]
        curvature = s_m - 2.0 * s_0 + s_p
        if curvature < 0:
            best += float(np.clip(0.5 * (s_m - s_p) / curvature, -0.5, 0.5)) * dt
    score, n_q = _score(best, t, x, t_ref, y, p)
    j = _second_peak(scores, grid, i, p.min_peak_separation_s)
    second = None if j is None else float(scores[j])
    return TimeAlignment(
        offset_s=best,
        peak_correlation=float(score),
        search_window_s=float(k * dt),
        at_window_edge=i in (0, grid.size - 1),
        n_quantities=n_q,
        second_peak_offset_s=None if j is None else float(grid[j]),
        second_peak_correlation=second,
        ambiguous=second is not None and _ambiguous(float(scores[i]), second, p),
    )


def _ambiguous(best: float, second: float, p: AgreementParams) -> bool:
    """Whether a second correlation peak ``second`` (mean r) is too close to the best one ``best``.

    Too close: it reaches ``ambiguous_peak_ratio`` of the best, and the best's misfit ``1 - r`` is
    not below ``clear_misfit_ratio`` of its own.
    """
    return second >= p.ambiguous_peak_ratio * best and (1.0 - best) >= p.clear_misfit_ratio * (1.0 - second)


def _second_peak(scores: FloatArray, grid: ArrayLike, best: int, min_separation_s: float) -> int | None:
    """Index of the highest local maximum of ``scores`` (NaN = none) apart from the best one.

    Local maxima are grid points at least as high as their finite neighbours; a window edge
    counts when the score rises toward it (a peak may lie beyond). Points closer than
    ``min_separation_s`` (s) to ``grid[best]`` are the best peak's shoulder and do not count.
    """
    g = np.asarray(grid, dtype=float)
    s = np.where(np.isfinite(scores), scores, -np.inf)
    left = np.r_[-np.inf, s[:-1]]
    right = np.r_[s[1:], -np.inf]
    peak = np.isfinite(s) & (s >= left) & (s >= right)
    peak &= np.abs(g - g[best]) >= min_separation_s
    if not np.any(peak):
        return None
    candidates = np.flatnonzero(peak)
    return int(candidates[np.argmax(s[candidates])])


def _score(
    tau: float, t: FloatArray, x: FloatArray, t_ref: FloatArray, y: FloatArray, p: AgreementParams
) -> tuple[float, int]:
    """Mean Pearson r over the quantities with the reference shifted by ``tau``."""
    shifted = resample_linear(t_ref + tau, y, t)
    rs = []
    for j in range(x.shape[1]):
        ok = np.isfinite(x[:, j]) & np.isfinite(shifted[:, j])
        if ok.sum() < max(p.min_samples, p.min_overlap_fraction * t.size):
            continue
        a = x[ok, j] - x[ok, j].mean()
        b = shifted[ok, j] - shifted[ok, j].mean()
        denom = np.sqrt(np.sum(a * a) * np.sum(b * b))
        if denom > 0:
            rs.append(np.sum(a * b) / denom)
    return (float(np.mean(rs)) if rs else float("nan")), len(rs)
