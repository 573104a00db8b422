"""The gait band of a hinge fit: the axis seen by the joint's own motion, without the tissue's wobble.

Eq. 12 (Hu et al. 2021) weighs every gyro sample alike. A sensor on soft tissue adds its
own rotation, a damped wobble at 7–20 Hz after each heel strike (the simulator's
real-walk artefacts: several rad/s at the thigh and shank), which no hinge explains.
On such a walk the full-band least squares can prefer a minimum 20–40° off the knee
axis that absorbs part of the wobble (lower cost than the true axes: 0.84 against
1.09 rad/s RMS on one simulated walk), and the sign rules then read a joint angle that
mixes the two segments' rotations: the relative sign came out mirrored on two of twelve
simulated legs and the overall sign on one (its knee axes 140° from the other leg's).

A walking knee moves below a few hertz (stride ~1 Hz, its harmonics), so the same fit
on gyros low-passed at ``hinge_band_hz`` sees the joint and not the wobble. The filter is
not free: the segments' relative rotation does not commute with it, which costs a
rigid walk 0.5–1° of axis. So the band-limited fit is only a witness: where the two
fits agree (within ``hinge_band_max_disagreement_deg``), the full-band axes are kept;
where they do not, the full band holds rotation that the joint's motion does not
explain, and the band-limited axes (with the sign rules on the band-limited gyros) are
taken, with a warning.
"""

from __future__ import annotations

import numpy as np

from lowerlimb.constraints.prefilter import lowpass
from lowerlimb.conventions import FloatArray

__all__ = ["axes_disagreement_deg", "band_limited_gyros"]


def band_limited_gyros(
    gyr_parent: FloatArray, gyr_child: FloatArray, rate_hz: float, cutoff_hz: float | None
) -> tuple[FloatArray, FloatArray] | None:
    """The two gyros low-passed at ``cutoff_hz`` (zero phase), or ``None`` when it does not apply.

    Args:
        gyr_parent: (N, 3) parent gyro, parent sensor frame, rad/s.
        gyr_child: (N, 3) child gyro, child sensor frame, rad/s.
        rate_hz: sampling rate, Hz.
        cutoff_hz: the band's upper edge, Hz (``None`` or ≥ 0.4·rate: no band-limited fit).

    Returns:
        ``(gyr_parent, gyr_child)`` filtered, (N, 3) each, rad/s; or ``None``.
    """
    if cutoff_hz is None or not 0 < cutoff_hz < 0.4 * rate_hz or gyr_parent.shape[0] < 30:
        return None
    return (
        lowpass(gyr_parent, rate_hz, cutoff_hz, order=2),
        lowpass(gyr_child, rate_hz, cutoff_hz, order=2),
    )


def axes_disagreement_deg(
    first: tuple[FloatArray, FloatArray], second: tuple[FloatArray, FloatArray]
) -> float:
    """Largest angle between two hinge fits' axes, each sensor compared sign-blind, deg.

    Args:
        first: ``(j_P, j_C)`` (3,) unit axes in the parent and child sensor frames.
        second: the other fit's ``(j_P, j_C)``.
    """
    return float(
        max(
            np.degrees(np.arccos(np.clip(abs(float(np.asarray(a) @ np.asarray(b))), 0.0, 1.0)))
            for a, b in zip(first, second, strict=True)
        )
    )
