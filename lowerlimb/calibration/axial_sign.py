"""Do two sensors' accelerometers agree in sign? Their acceleration along a shared hinge axis.

A hinge's axis is one line seen from both segments, so the specific force of a point on
it, projected on the axis, is one scalar whichever sensor measures it (the knee's
accelerometer sign test, :func:`~lowerlimb.calibration.hinge_axis.check_sign_with_acc`).
The gyros fix the axes' relative direction (their coherence, Seel et al. 2012); an
accelerometer read with the opposite sign then turns the correlation of the two
projections from about +1 to about −1. Unlike the sign check's rates about the vertical
(:mod:`lowerlimb.orientation.sign_check`), this needs no turning: a straight walk flexes
its knee and ankle. The ankle is not a hinge, but walking flexes it mostly about one axis:
on the real walk of ``gait/`` the correlation is +0.95 (−0.95 with the foot's
accelerometer negated).

The test is only as good as the gyros' axes. The acceleration along a joint's
medio-lateral axis is small in a straight walk; where the two frames' axes are not one
line (an ankle that is not a hinge, a knee under soft-tissue motion) the forward and
vertical accelerations that the mismatch projects onto it swamp it. On unmodified
straight simulated walks, rigid and with the real-walk artefacts, the correlation came
out as low as −0.73 (knee, coherence 0.59) and −0.64 (ankle, 0.66); on slow walks with
a weak push-off the ankle's was below −0.4 on three rigid walks of six, even at the true
ankle centre, and a shuffling walk's (``pace="shuffle"``, seed 206) −0.70. The real walk's
knees reach 0.84 / 0.83, its ankles 0.89 / 0.91. So a verdict needs
:attr:`AxialSignParams.min_coherence`. Even then soft tissue can turn it: a thigh sensor
that turns on the thigh with the knee angle tilts its axis, and gravity leaks into the
small axial acceleration. Unmodified one-leg squats and sit-to-stands simulated with the
real-walk artefacts (seeds 3001–3022, 20 s) gave knee correlations down to −0.83 at a
gyro coherence of 0.99 (rigid knees: +0.89 … +1.0). A verdict of this witness alone
nearer zero than :attr:`~lowerlimb.orientation.sign_check.SignCheckParams.min_refuse_axial`
is therefore only warned about.

The hip is no help: the pelvis barely turns about the flexion axis, so the gyros leave
the axes' relative direction open (its correlation came out −0.9 on unmodified walks),
and then no verdict is given.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from lowerlimb.calibration._prepare import joint_signals, prepare_signals
from lowerlimb.calibration.hinge_axis import acc_sign_correlation, fit_hinge_axis
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import FloatArray
from lowerlimb.stillness import StillPeriod

__all__ = ["AxialSignParams", "axial_sign_correlation", "gyro_sign_is_clear"]


@dataclass(frozen=True)
class AxialSignParams:
    """When the gyros fix the axes' relative direction well enough for the test.

    Attributes:
        min_coherence: least sign coherence of the kept direction (0–1; see the
            module docstring: below 0.85, unmodified simulated walks gave correlations
            down to −0.73).
        min_margin: least lead of the kept direction's coherence over the flipped one's.
        max_duration_s: only the recording's first this many seconds are used (the test's
            cost stays bounded; on a simulated 10-minute walk the whole record's gyro
            coherence was too low for a verdict; its first 120 s gave +0.41).
    """

    min_coherence: float = 0.85
    min_margin: float = 0.2
    max_duration_s: float = 120.0


def gyro_sign_is_clear(coherence: FloatArray, params: AxialSignParams | None = None) -> bool:
    """Whether ``[kept, flipped]`` sign coherences fix the axes' relative direction."""
    p = params or AxialSignParams()
    keep, flip = (float(c) for c in coherence)
    return keep >= p.min_coherence and keep - flip >= p.min_margin


def axial_sign_correlation(
    acc: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    rate_hz: float,
    parent: str,
    child: str,
    *,
    still: StillPeriod | None = None,
    options: CalibrationOptions | None = None,
    params: AxialSignParams | None = None,
) -> float:
    """Correlation in [−1, 1] of two sensors' accelerations along their joint's main axis.

    Args:
        acc: ``{sensor: (N, 3)}`` specific force, sensor frames, m/s².
        gyr: ``{sensor: (N, 3)}`` angular rate, sensor frames, rad/s.
        rate_hz: sampling rate, Hz.
        parent: the proximal sensor.
        child: the distal sensor.
        still: the still start (for the gyro bias), or ``None``.
        options: calibration options (prefilter, solver); defaults when ``None``.
        params: when the gyros' direction counts (defaults when ``None``).

    Returns:
        The correlation (≈ +1: the accelerometers agree; ≈ −1: one is inverted), or NaN
        when the gyros leave the axes' relative direction open.
    """
    quiet = replace(options or CalibrationOptions(), center_std_tol_m=np.inf, min_rms_rate_rps=0.0)
    n = int((params or AxialSignParams()).max_duration_s * rate_hz)
    pair_acc = {s: acc[s][:n] for s in (parent, child)}
    pair_gyr = {s: gyr[s][:n] for s in (parent, child)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sig = prepare_signals(pair_acc, pair_gyr, rate_hz, quiet, still=still)
        data = joint_signals(pair_acc, pair_gyr, sig, parent, child, quiet)
        axis = fit_hinge_axis(data.gyr_parent, data.gyr_child, rate_hz=rate_hz, method="gn", options=quiet)
        if not gyro_sign_is_clear(axis.sign_coherence, params):
            return float("nan")
        return acc_sign_correlation(data, axis.axis_in_parent_sensor, axis.axis_in_child_sensor, quiet)[0]
