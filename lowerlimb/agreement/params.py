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
        min_reference_rate_hz: a reference whose median time step is longer
            than ``1 / min_reference_rate_hz`` is refused: its time is taken
            to be in ms (the trial reader's threshold, ``io.trial.MIN_RATE_HZ``).
        min_span_overlap_fraction: the time spans of lowerlimb and the
            reference must overlap over at least this fraction of the shorter
            span (with ``align_time``, at the best shift within the search
            window); less is refused as a clock or unit mistake.
        unit_factor_tolerance: a reference column is taken to be in another
            unit only when its size differs from ours by that unit's factor
            (180/π for radians, 1000 for mm, 100 for cm) within this factor
            either way; a constant or wildly different column is not a unit
            mistake.
        max_radians_range: a reference angle column whose range over the
            overlap is below this (about π, in its own unit) may be radians…
        min_radians_check_range_deg: …when our angle moves at least this
            much, deg, over the same samples (a still joint proves nothing).
        max_position_m: a reference position column whose RMS exceeds this,
            m, may be in mm or cm (a leg's positions stay within ~1.2 m).
        ambiguous_peak_ratio: with ``align_time``, the offset is called
            ambiguous (and a warning says so) when another peak of the mean
            correlation, at least ``min_peak_separation_s`` away, reaches this
            fraction of the best peak's correlation: a walk repeats every
            stride, so a reference shifted by more than the search window still
            correlates almost as well one stride off the true offset…
        clear_misfit_ratio: …unless the best peak's misfit ``1 - r`` is below
            this fraction of the other peak's: a near-perfect fit is the true
            offset even when a very regular walk correlates almost as well one
            stride away.
        min_peak_separation_s: a correlation peak this close to the best one,
            s, is the same peak (its shoulder), not another stride.
    """

    loa_z: float = 1.96
    sd_ddof: int = 1
    max_offset_s: float = 2.0
    min_samples: int = 3
    min_overlap_fraction: float = 0.5
    min_reference_rate_hz: float = 5.0
    min_span_overlap_fraction: float = 0.25
    unit_factor_tolerance: float = 3.0
    max_radians_range: float = 3.2
    min_radians_check_range_deg: float = 20.0
    max_position_m: float = 3.0
    ambiguous_peak_ratio: float = 0.95
    clear_misfit_ratio: float = 0.25
    min_peak_separation_s: float = 0.3
