"""How far a joint centre moves with the prefilter: a systematic spread beside the noise one.

Why: each joint's reported standard deviation is the Gauss–Newton covariance
scaled by the residual's correlation time (:mod:`~lowerlimb.calibration.excitation`):
honest about noise, blind to systematic error. On walking the larger error is
systematic: the low-pass filter that keeps the constraint's noise down also
changes the constraint (squaring a low-passed gyro is not low-passing the
squared gyro, and the two frames turn against each other inside the filter's
window), so the centre depends on the cut-off. Measured on simulated seven-IMU
walks (seeds 201–203, six legs): the hip in the pelvis sensor is 61–131 mm from
the truth with a reported spread of 7–10 mm, and moves 47–72 mm when every
cut-off is widened by half; the hip in the thigh sensor 5–12 mm off, spread
1–2 mm, shift 4–10 mm. On the real walk the thigh length moves by tens of
millimetres between cut-offs of 3 and 5 Hz.

So the leg calibration repeats the hip and ankle fits once with the adaptive
cut-offs and the rigid-band caps multiplied by
:attr:`~lowerlimb.calibration.options.CalibrationOptions.cutoff_probe_factor`
(same samples, priors and solver) and records the shift of each centre
(:attr:`~lowerlimb.calibration.results.SphericalJointCalibration.cutoff_shift`,
``center_cutoff_shift_in_*_sensor`` in calibration.json). No estimate changes, but a
shift above :attr:`~lowerlimb.calibration.options.CalibrationOptions.cutoff_shift_warn_m`
(30 mm) in either sensor frame is warned about. On the rigid seven-IMU walks (seeds
201–206, 24 hip and ankle centres) the shift tracked the error: the three centres it moved
by more than 30 mm were 35, 41 and 134 mm off (the ankle in a shank sensor whose pair the
rigid band capped at 3.9 Hz), and every other centre it moved by 23 mm or less was 30 mm
or less off; on the real walk of ``gait/`` no centre moves by more than 25 mm. A side the
aligned form places (the hip in the pelvis sensor, by default) is not the norm form's
that the probe refits, and its shift is not recorded.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import replace

import numpy as np

from lowerlimb.calibration._prepare import PreparedSignals, joint_signals, prepare_signals
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.results import SphericalJointCalibration
from lowerlimb.constraints.spherical import SphericalData
from lowerlimb.conventions import FloatArray

__all__ = ["cutoff_shift_message", "probe_options", "with_cutoff_shifts"]

#: ``fit(joint, data, options) -> centre`` of one spherical joint, as the calibration fits it.
Refit = Callable[[str, SphericalData, CalibrationOptions], SphericalJointCalibration]


def probe_options(options: CalibrationOptions) -> CalibrationOptions:
    """The options with every cut-off (and cut-off limit) widened by ``cutoff_probe_factor``, no warnings."""
    f = options.cutoff_probe_factor

    def wider(hz: float | None) -> float | None:
        return None if hz is None else hz * f

    return replace(
        options,
        cutoff_factor=options.cutoff_factor * f,
        cutoff_hz=wider(options.cutoff_hz),
        impact_max_cutoff_hz=wider(options.impact_max_cutoff_hz),
        rigid_band_factor=options.rigid_band_factor * f,
        center_std_tol_m=np.inf,
        min_rms_rate_rps=0.0,
    )


def with_cutoff_shifts(
    joints: Mapping[str, SphericalJointCalibration],
    pairs: Mapping[str, tuple[str, str]],
    acc: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    sig: PreparedSignals,
    options: CalibrationOptions,
    refit: Refit,
    limits: Mapping[str, float | None] | None = None,
) -> dict[str, SphericalJointCalibration]:
    """Each joint with its :attr:`~SphericalJointCalibration.cutoff_shift` recorded (module docstring).

    Args:
        joints: ``{name: fitted joint}``.
        pairs: ``{name: (parent sensor, child sensor)}``.
        acc: ``{sensor: (N, 3)}`` raw accelerometers, m/s².
        gyr: ``{sensor: (N, 3)}`` raw gyros, rad/s.
        sig: the prepared signals of the main fit (still period and gyro biases reused).
        options: the main fit's options.
        refit: fits one joint on the widened data, quietly.
        limits: ``{name: Hz or None}`` each joint's impact cut-off limit in the main fit
            (:func:`~lowerlimb.calibration.impact_window.impact_cutoff_limit_hz`), widened too.

    Returns:
        The joints, each a copy with ``cutoff_shift`` set (m).
    """
    wide = probe_options(options)
    wsig = prepare_signals(acc, gyr, sig.rate_hz, wide, n_still=sig.n_still, bias=sig.gyro_bias)
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, joint in joints.items():
            p, c = pairs[name]
            limited = (limits or {}).get(name) is not None
            wide_lim = wide.impact_max_cutoff_hz if limited else None
            probe = refit(name, joint_signals(acc, gyr, wsig, p, c, wide, max_hz=wide_lim), wide)
            x = np.r_[joint.center_in_parent_sensor, joint.center_in_child_sensor]
            xp = np.r_[probe.center_in_parent_sensor, probe.center_in_child_sensor]
            out[name] = replace(joint, cutoff_shift=xp - x)
    return out


def cutoff_shift_message(joint: SphericalJointCalibration, limit_m: float) -> str | None:
    """The warning for a centre that moves more than ``limit_m`` with the cut-offs, else ``None``.

    A frame whose shift is NaN (not probed) is left out.
    """
    hit = joint.largest_shift(joint.cutoff_shift, above_m=limit_m)
    if hit is None:
        return None
    worst, moved = hit
    return (
        f"{joint.joint}: the centre in the {worst} sensor frame moves by {1000 * moved:.0f} mm when the "
        f"low-pass cut-offs are widened by half; the filter decides it more than the data do, so "
        f"treat it as uncertain by that much (a longer trial with more varied motion pins it better)"
    )
