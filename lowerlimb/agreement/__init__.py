"""Agreement of lowerlimb outputs with a reference system (docs/formats.md, "Agreement with a reference").

Per quantity: n, RMSE, bias, 95 % limits of agreement (Bland & Altman 1986),
Pearson r and the coefficient of multiple correlation (Ferrari et al. 2010);
time alignment by cross-correlation; Bland–Altman plots (seed paper 000, Fig. 13).
"""

from lowerlimb.agreement.alignment import TimeAlignment, estimate_time_offset
from lowerlimb.agreement.bland_altman import plot_bland_altman
from lowerlimb.agreement.comparison import Comparison, PairedSeries, compare_series
from lowerlimb.agreement.errors import (
    AlignmentError,
    EmptyReferenceError,
    NoCommonColumnsError,
    NoTimeOverlapError,
    ReferenceTimeUnitError,
    ReferenceUnitError,
    TooLittleTimeOverlapError,
)
from lowerlimb.agreement.params import AgreementParams
from lowerlimb.agreement.resample import resample_linear
from lowerlimb.agreement.statistics import (
    QuantityAgreement,
    agreement_statistics,
    cmc_two_waveforms,
    pearson_r,
)

__all__ = [
    "AgreementParams",
    "AlignmentError",
    "Comparison",
    "EmptyReferenceError",
    "NoCommonColumnsError",
    "NoTimeOverlapError",
    "PairedSeries",
    "QuantityAgreement",
    "ReferenceTimeUnitError",
    "ReferenceUnitError",
    "TimeAlignment",
    "TooLittleTimeOverlapError",
    "agreement_statistics",
    "cmc_two_waveforms",
    "compare_series",
    "estimate_time_offset",
    "pearson_r",
    "plot_bland_altman",
    "resample_linear",
]
