"""A trial recorded at a low rate, interpolated before the joint calibration and the gait events.

Why: the calibration differentiates the gyros (α by a Savitzky–Golay window,
:mod:`~lowerlimb.constraints.angular_acceleration`), finds impacts by the
accelerometer's jerk (:mod:`~lowerlimb.calibration.impact_window`) and leaves out
windows around them; each of these works on samples, and at 60 Hz (the default
of Movella DOT sensors, and Xsens Awinda with many sensors) a foot contact's kink
falls between two samples. On seven-IMU simulated walks at 60 Hz (seeds 201–206)
the ankle in the shank sensor came out 30 mm from the truth median (100 Hz: 8.5 mm)
and the ankle in the foot sensor 10.5 mm (2.6 mm), mostly along the knee axis, and
the step width error doubled (29 against 16 mm median).

A band-limited interpolation (``scipy.signal.resample_poly``, a polyphase FIR
low-pass at the original Nyquist frequency) to an integer multiple of the rate adds
no information (nothing above the recorded band), but gives the derivative and the
impact windows the sample density they were designed at: ×2 (120 Hz) brought the
60 Hz ankle to 10 mm median. The joint centres and axes do not depend on the rate.

The gait events are times found on sample features as well (a heel-rocker onset, the
half-way point of the forefoot's unloading within a bracket of the foot's rate): at
60 Hz one walk's toe-offs jumped by +42 or −115 ms between neighbouring features, and
interpolated to 120 Hz its worst toe-off came to 4 ms and the initial contacts' median
from 10 to 7 ms (:func:`lowerlimb.gait.events.detect_side_events`). Every other stage
(orientation filters, angles, the feet's strapdown, the stationary periods, output
files) keeps the recorded samples.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from scipy.signal import resample_poly

from lowerlimb.conventions import FloatArray
from lowerlimb.stillness import StillPeriod

__all__ = ["upsample_factor", "upsampled", "upsampled_still"]


#: A rate this close below the minimum counts as reaching it: a 100 Hz recording whose
#: timestamps say 99.8 Hz is not worth twice the samples.
RATE_TOLERANCE = 0.05


def upsample_factor(rate_hz: float, min_rate_hz: float | None) -> int:
    """The smallest integer ``k ≥ 1`` with ``k · rate_hz ≥ min_rate_hz`` (1 when it is ``None``).

    A rate within :data:`RATE_TOLERANCE` (5 %) below ``min_rate_hz`` gives 1.
    """
    if min_rate_hz is None or rate_hz >= (1.0 - RATE_TOLERANCE) * min_rate_hz:
        return 1
    return math.ceil(min_rate_hz / rate_hz - 1e-9)


def upsampled(signals: Mapping[str, FloatArray], factor: int) -> dict[str, FloatArray]:
    """Each (N, 3) signal interpolated to (factor · N, 3) samples, band-limited (unit unchanged).

    The ends are extended along a fitted line before filtering (``padtype="line"``), so a
    recording that starts standing still keeps its still samples.
    """
    if factor == 1:
        return dict(signals)
    out: dict[str, FloatArray] = {}
    gain: FloatArray | None = None
    for name, x in signals.items():
        xv = np.asarray(x, dtype=float)
        if gain is None or gain.shape[0] != factor * xv.shape[0]:
            # each polyphase branch passes DC with a gain off 1 by ~0.05 %: divided out,
            # so a constant (gravity, a still start) stays exactly constant
            gain = np.asarray(resample_poly(np.ones(xv.shape[0]), factor, 1, padtype="line"), dtype=float)
        y = resample_poly(xv, factor, 1, axis=0, padtype="line")
        out[name] = np.asarray(y / gain[:, None], dtype=float)
    return out


def upsampled_still(still: StillPeriod | None, factor: int) -> StillPeriod | None:
    """The still start of the recorded samples, on the interpolated samples."""
    if still is None or factor == 1:
        return still
    quiet = None if still.quiet is None else np.repeat(still.quiet, factor)
    return StillPeriod(still.n_samples * factor, still.rate_hz * factor, quiet, still.end_samples * factor)
