"""Reading and writing files: the trial CSV, the output tables and atomic writes.

The bottom of the data flow (``io → calibration → segments → model → outputs/viz``);
nothing here computes.
"""

from lowerlimb.io.atomic import populate_directory, write_atomically
from lowerlimb.io.tables import read_table, write_angles_csv, write_positions_csv
from lowerlimb.io.trial import ImuTrial

__all__ = [
    "ImuTrial",
    "populate_directory",
    "read_table",
    "write_angles_csv",
    "write_atomically",
    "write_positions_csv",
]
