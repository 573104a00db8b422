"""The registry of ``calibrate --export`` formats: name -> what it adds to the result folder.

Kept free of heavy imports: the command line builds its ``choices`` from it.
"""

from __future__ import annotations

#: Export format -> the files it adds (docs/exports.md).
EXPORT_FORMATS: dict[str, str] = {
    "opensim": "angles.mot (OpenSim coordinates) and orientations.sto (OpenSense quaternion table)",
    "bids": "BIDS-motion sub-01_task-<t>_tracksys-imu_{motion,channels}.{tsv,json}",
}
