"""Units accepted by the importers and their factors to the trial units (s, m/s², rad/s, µT).

``g`` is converted with :data:`lowerlimb.conventions.GRAVITY_MPS2`, the value the
whole library uses for gravity.
"""

from __future__ import annotations

import math

from lowerlimb.conventions import GRAVITY_MPS2

#: Time units → factor to seconds.
TIME_UNITS: dict[str, float] = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "ns": 1e-9}
#: Accelerometer units → factor to m/s².
ACC_UNITS: dict[str, float] = {"m/s^2": 1.0, "m/s2": 1.0, "m/s²": 1.0, "g": GRAVITY_MPS2}
#: Gyroscope units → factor to rad/s.
GYR_UNITS: dict[str, float] = {"rad/s": 1.0, "deg/s": math.pi / 180.0, "°/s": math.pi / 180.0}
#: Magnetometer units → factor to µT.
MAG_UNITS: dict[str, float] = {"uT": 1.0, "µT": 1.0, "nT": 1e-3, "mT": 1e3, "gauss": 100.0}
#: Units of each quantity of a sensor.
QUANTITY_UNITS: dict[str, dict[str, float]] = {"acc": ACC_UNITS, "gyr": GYR_UNITS, "mag": MAG_UNITS}
