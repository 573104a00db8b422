"""Agreement statistics of two synchronous waveforms: Bland–Altman, RMSE, Pearson r, CMC.

The difference is always ``lowerlimb − reference`` (docs/formats.md, "Agreement with a reference").
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ShapeError
from .params import AgreementParams


@dataclass(frozen=True)
class QuantityAgreement:
    """Agreement of one quantity (one angle or one position component).

    Attributes:
        quantity: column name as in ``angles.csv`` / ``positions.csv``.
        unit: ``"deg"`` or ``"m"`` (the unit of every value below except r, CMC, n).
        n: number of valid (lowerlimb, reference) pairs used.
        rmse: root mean square of the difference.
        bias: mean of ``lowerlimb − reference``.
        sd_diff: SD of the difference (``ddof`` = :attr:`AgreementParams.sd_ddof`, 1 by default).
        loa_lower: ``bias − loa_z · sd_diff`` (95 % limit of agreement).
        loa_upper: ``bias + loa_z · sd_diff``.
        pearson_r: Pearson correlation; NaN when either series is constant.
        cmc: coefficient of multiple correlation (:func:`cmc_two_waveforms`); NaN when undefined.
        offset_removed: constant subtracted from the lowerlimb values before the
            statistics (the bias before removal); 0 unless offsets are removed.
    """

    quantity: str
    unit: str
    n: int
    rmse: float
    bias: float
    sd_diff: float
    loa_lower: float
    loa_upper: float
    pearson_r: float
    cmc: float
    offset_removed: float = 0.0

    def to_dict(self) -> dict[str, object]:
        """Plain-JSON dictionary (NaN becomes ``None``)."""
        return {
            k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in asdict(self).items()
        }


def cmc_two_waveforms(a: ArrayLike, b: ArrayLike) -> float:
    """Coefficient of multiple correlation of two synchronous waveforms.

    Ferrari, Cutti, Cappello 2010, "A new formulation of the coefficient of
    multiple correlation to assess the similarity of waveforms measured
    synchronously by different motion analysis protocols", Gait & Posture
    31(4):540–542, eq. 2, with G = 2 protocols and N = 1 cycle (the whole
    compared record is one "cycle"; the paper averages over gait cycles)::

        CMC = sqrt(1 − [Σ_g Σ_f (Y_gf − Ȳ_f)² / (F (G − 1))]
                     / [Σ_g Σ_f (Y_gf − Ȳ)²  / (G F − 1)])

    where ``Y_gf`` is waveform g at frame f, ``Ȳ_f`` the mean of the G
    waveforms at frame f and ``Ȳ`` the grand mean over all G·F values.

    Undefined cases return NaN: when the between-frame variance (denominator)
    is zero (both waveforms the same constant), and when the ratio exceeds 1,
    where the square root is imaginary — Ferrari et al. note that the CMC is
    then a complex number and the waveforms are to be judged dissimilar.
    Unlike Pearson r, the CMC falls with an offset or a gain between the two.

    Args:
        a: (F,) first waveform (lowerlimb), any unit.
        b: (F,) second waveform (reference), same unit and frames.

    Returns:
        CMC in [0, 1], or NaN when undefined.

    Raises:
        ShapeError: when ``a`` and ``b`` are not 1-D of the same length.
    """
    Y = np.stack(_pair(a, b))  # (G=2, F)
    G, F = Y.shape
    within = np.sum((Y - Y.mean(axis=0)) ** 2) / (F * (G - 1))
    total = np.sum((Y - Y.mean()) ** 2) / (G * F - 1)
    if not total > 0:
        return float("nan")
    ratio = within / total
    return float(np.sqrt(1.0 - ratio)) if ratio <= 1.0 else float("nan")


def pearson_r(a: ArrayLike, b: ArrayLike) -> float:
    """Pearson correlation of two (F,) series; NaN when either is constant.

    Raises:
        ShapeError: when ``a`` and ``b`` are not 1-D of the same length.
    """
    x, y = _pair(a, b)
    x = x - x.mean()
    y = y - y.mean()
    denom = np.sqrt(np.sum(x * x) * np.sum(y * y))
    return float(np.sum(x * y) / denom) if denom > 0 else float("nan")


def agreement_statistics(
    ours: ArrayLike,
    reference: ArrayLike,
    *,
    quantity: str,
    unit: str,
    remove_offset: bool = False,
    params: AgreementParams | None = None,
) -> QuantityAgreement:
    """Bland–Altman statistics, RMSE, Pearson r and CMC of one quantity.

    Pairs where either value is NaN are dropped. Bland & Altman 1986
    (Lancet 327:307–310): bias = mean of ``d = ours − reference``, limits of
    agreement = bias ± 1.96 SD(d), the SD with ``ddof = 1``.

    Args:
        ours: (F,) lowerlimb values on the common time axis, ``unit``.
        reference: (F,) reference values on the same time axis, ``unit``.
        quantity: name of the quantity (a column of angles.csv / positions.csv).
        unit: its unit, ``"deg"`` or ``"m"``.
        remove_offset: subtract the mean difference from ``ours`` first (a
            constant-offset correction: bias becomes 0, the LoA centre on 0,
            RMSE becomes the SD of the difference with ``ddof = 0``); the
            removed constant is reported in ``offset_removed``.
        params: thresholds; defaults to :class:`AgreementParams`.

    Returns:
        The statistics; all NaN with ``n`` = the number of valid pairs when
        fewer than ``params.min_samples`` pairs are valid.

    Raises:
        ShapeError: when the two series are not 1-D of the same length.
    """
    p = params or AgreementParams()
    x, y = _pair(ours, reference)
    valid = np.isfinite(x) & np.isfinite(y)
    x, y = x[valid], y[valid]
    n = int(x.size)
    nan = float("nan")
    if n < max(p.min_samples, p.sd_ddof + 1):
        return QuantityAgreement(quantity, unit, n, nan, nan, nan, nan, nan, nan, nan)
    offset = float(np.mean(x - y)) if remove_offset else 0.0
    x = x - offset
    d = x - y
    bias = float(np.mean(d))
    sd = float(np.std(d, ddof=p.sd_ddof))
    return QuantityAgreement(
        quantity=quantity,
        unit=unit,
        n=n,
        rmse=float(np.sqrt(np.mean(d * d))),
        bias=bias,
        sd_diff=sd,
        loa_lower=bias - p.loa_z * sd,
        loa_upper=bias + p.loa_z * sd,
        pearson_r=pearson_r(x, y),
        cmc=cmc_two_waveforms(x, y),
        offset_removed=offset,
    )


def _pair(a: ArrayLike, b: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(a, dtype=float)
    y = np.asarray(b, dtype=float)
    if x.ndim != 1 or x.shape != y.shape:
        raise ShapeError(f"expected two 1-D series of equal length, got shapes {x.shape} and {y.shape}")
    return x, y
