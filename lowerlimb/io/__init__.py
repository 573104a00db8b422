"""Reading what users record: vendor files → the trial of DESIGN.md.

:func:`read_xsens` reads Xsens MT Manager text exports (one file per sensor);
:func:`read_mapped_csv` reads any per-column CSV through a small JSON mapping
of column names and units. Both return a validated single-leg
:class:`~lowerlimb.trial.ImuTrial`; :func:`load_xsens` and
:func:`load_mapped_csv` also take the seven-sensor two-leg names and return an
:class:`ImportedRecording` (write it with :meth:`ImportedRecording.to_csv`).
"""

from .csv_mapping import CsvMapping
from .errors import ColumnNotFoundError, MappingError, PacketGapError, SensorFileError
from .mapped_csv import load_mapped_csv, read_mapped_csv
from .params import XSENS_MAG_FIELD_UT, ImportParams
from .recording import TWO_LEG_SENSORS, ImportedRecording
from .xsens import FilledPacketsWarning, load_xsens, read_xsens

__all__ = [
    "TWO_LEG_SENSORS",
    "XSENS_MAG_FIELD_UT",
    "ColumnNotFoundError",
    "CsvMapping",
    "FilledPacketsWarning",
    "ImportParams",
    "ImportedRecording",
    "MappingError",
    "PacketGapError",
    "SensorFileError",
    "load_mapped_csv",
    "load_xsens",
    "read_mapped_csv",
    "read_xsens",
]
