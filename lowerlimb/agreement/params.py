"""Every threshold of the agreement analysis, in one dataclass."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class AgreementParams:
    """Parameters of :func:`~lowerlimb.agreement.compare_series`.

    Attributes:
        loa_z: multiplier of the SD of the difference in the 95 % limits of
            agreement (Bland & Altman 1986: 1.96, the 97.5 % normal quantile).
        sd_ddof: delta degrees of freedom of that SD; 1 = the sample SD, as
            Bland & Altman use.
        max_offset_s: the time-offset search covers ``[-max_offset_s,
            +max_offset_s]``, s. Larger offsets are not found: cut or shift the
            reference first.
        min_samples: fewer valid (lowerlimb, reference) pairs than this and a
            quantity is skipped (a SD with ``ddof=1`` needs at least 2; a
            correlation needs 3 to mean anything).
        min_overlap_fraction: at every candidate offset the correlation is
            only computed when at least this fraction of our samples fall
            inside the shifted reference, so that an offset cannot win on a
            few overlapping samples.
    """

    loa_z: float = 1.96
    sd_ddof: int = 1
    max_offset_s: float = 2.0
    min_samples: int = 3
    min_overlap_fraction: float = 0.5
