"""Per-sensor orientation from gyro + accelerometer (+ magnetometer).

:func:`estimate_orientation` runs one of four filters — ``"mahony"`` (PI
complementary filter, Hu et al. 2021 §4.3), ``"ftecf"`` (fuzzy-tuned ESOQ-2
complementary filter, Zhu & Xu 2018), ``"madgwick"`` (gradient descent) and
``"quest_kf"`` (QUEST + Kalman filter, Yun & Bachmann 2006) — and returns
(N, 4) quaternions ``w, x, y, z``, sensor -> ENU.
"""

from lowerlimb.orientation.accuracy import OrientationErrors, orientation_errors
from lowerlimb.orientation.esoq2 import davenport_q_method, esoq2
from lowerlimb.orientation.estimate import METHODS, estimate_orientation
from lowerlimb.orientation.ftecf import FtecfParams
from lowerlimb.orientation.initialisation import InitialState, RestParams, initialise
from lowerlimb.orientation.madgwick import MadgwickParams
from lowerlimb.orientation.mahony import MahonyParams
from lowerlimb.orientation.quest import quest
from lowerlimb.orientation.quest_kf import QuestKfParams

__all__ = [
    "METHODS",
    "FtecfParams",
    "InitialState",
    "MadgwickParams",
    "MahonyParams",
    "OrientationErrors",
    "QuestKfParams",
    "RestParams",
    "davenport_q_method",
    "esoq2",
    "estimate_orientation",
    "initialise",
    "orientation_errors",
    "quest",
]
