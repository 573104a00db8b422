"""Warnings for a sensor of a pair that hardly rotates (internal)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from lowerlimb.conventions import FloatArray


def low_rotation_messages(
    joint: str, gyros: Iterable[tuple[str, FloatArray]], min_rms_rps: float, consequence: str
) -> list[str]:
    """One message per sensor whose RMS angular rate is below ``min_rms_rps``.

    Args:
        joint: joint name used in messages.
        gyros: ``(sensor name, (N, 3) gyro in rad/s)`` pairs, in message order.
        min_rms_rps: smallest acceptable RMS rate, rad/s.
        consequence: what cannot be determined and how to fix it (end of the message).

    Returns:
        The messages (empty when every sensor rotates enough).
    """
    messages: list[str] = []
    for name, w in gyros:
        rms = float(np.sqrt(np.mean(np.sum(w**2, axis=1))))
        if rms < min_rms_rps:
            messages.append(f"{joint}: the {name} sensor hardly rotates (RMS {rms:.3f} rad/s); {consequence}")
    return messages
