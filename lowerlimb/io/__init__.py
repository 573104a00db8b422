"""Reading and writing files: vendor imports, the trial CSV, the output tables and atomic writes.

The bottom of the data flow (``io → calibration → segments → model → outputs/viz``);
nothing here computes. :func:`read_xsens` reads Xsens MT Manager text exports
(one file per sensor); :func:`read_mapped_csv` reads any per-column CSV through
a small JSON mapping of column names and units. Both return a validated
single-leg :class:`~lowerlimb.io.trial.ImuTrial`; :func:`load_xsens` and
:func:`load_mapped_csv` also take the seven-sensor two-leg names and return an
:class:`ImportedRecording` (write it with :meth:`ImportedRecording.to_csv`).
"""

from lowerlimb.io.atomic import populate_directory, write_atomically
from lowerlimb.io.csv_mapping import CsvMapping
from lowerlimb.io.errors import ColumnNotFoundError, MappingError, PacketGapError, SensorFileError
from lowerlimb.io.mapped_csv import load_mapped_csv, read_mapped_csv
from lowerlimb.io.params import XSENS_MAG_FIELD_UT, ImportParams
from lowerlimb.io.recording import TWO_LEG_SENSORS, ImportedRecording
from lowerlimb.io.tables import read_table, write_angles_csv, write_positions_csv
from lowerlimb.io.trial import ImuTrial
from lowerlimb.io.xsens import FilledPacketsWarning, load_xsens, read_xsens

__all__ = [
    "TWO_LEG_SENSORS",
    "XSENS_MAG_FIELD_UT",
    "ColumnNotFoundError",
    "CsvMapping",
    "FilledPacketsWarning",
    "ImportParams",
    "ImportedRecording",
    "ImuTrial",
    "MappingError",
    "PacketGapError",
    "SensorFileError",
    "load_mapped_csv",
    "load_xsens",
    "populate_directory",
    "read_mapped_csv",
    "read_table",
    "read_xsens",
    "write_angles_csv",
    "write_atomically",
    "write_positions_csv",
]
