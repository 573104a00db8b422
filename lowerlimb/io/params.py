"""``ImportParams``: every threshold of the vendor importers, in one place."""

from __future__ import annotations

from dataclasses import dataclass

#: Xsens normalised magnetometer unit in µT: 1 = the local field magnitude at the
#: time of the MT magnetic calibration; about 50 µT in most of Europe and North America.
XSENS_MAG_FIELD_UT = 50.0


@dataclass(frozen=True)
class ImportParams:
    """Thresholds of :func:`~lowerlimb.io.read_xsens`, :func:`~lowerlimb.io.read_mapped_csv`, trial CSVs.

    Attributes:
        max_gap_s: longest run of missing packets (Xsens) or longest interval
            between two source samples (mapped CSV with ``resample_hz``) that
            is bridged by linear interpolation, s. A longer gap is refused. Also the
            longest run of empty magnetometer cells a trial CSV bridges; beyond it the
            magnetometer is not used (:mod:`~lowerlimb.io.mag_cells`).
        warn_fill_fraction: warn when more than this fraction of the samples of
            the trial were filled by interpolation.
        rate_tolerance: largest relative difference between the update rates of
            the sensor files of one recording.
    """

    max_gap_s: float = 0.1
    warn_fill_fraction: float = 0.01
    rate_tolerance: float = 1e-3
