"""A whole hinge joint from two IMUs: the axis (eq. 4–6), then a centre on it (eq. 1–3, 16).

:func:`calibrate_hinge_joint` is what the leg calibration does at the knee,
for any two IMUs: the hinge axis with its signs resolved
(:mod:`~lowerlimb.calibration.hinge_axis`; the accelerometers settle an
ambiguous relative sign), then the spherical residual restricted to the point
of the axis nearest the two sensors (Hu 2021 eq. 16,
:func:`~lowerlimb.constraints.spherical.spherical_axis_gauge_sample_function`).
Any point of the axis is an equally valid hinge centre: compare centres by
their distance to the axis line.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.calibration._prepare import prepare_pair_bands
from lowerlimb.calibration.excitation import issue_warnings
from lowerlimb.calibration.hinge_axis import acc_sign_correlation, fit_hinge_axis
from lowerlimb.calibration.joint_center import fit_spherical
from lowerlimb.calibration.knee_line import moving_axis_mismatch, standing_axis_mismatch
from lowerlimb.calibration.options import CalibrationOptions, check_method
from lowerlimb.calibration.results import HingeJointCalibration
from lowerlimb.constraints.spherical import SphericalData
from lowerlimb.conventions import FloatArray

__all__ = ["below_parent_above_child", "calibrate_hinge_joint", "fit_hinge_joint"]


def _still_gravity(data: SphericalData, n_still: int) -> tuple[FloatArray, FloatArray] | None:
    """Mean accelerometer of the still period in each frame (``None`` without one)."""
    if n_still < 1:
        return None
    return data.acc_parent[:n_still].mean(axis=0), data.acc_child[:n_still].mean(axis=0)


def fit_hinge_joint(
    data: SphericalData,
    *,
    rate_hz: float,
    method: str,
    options: CalibrationOptions,
    n_still: int = 0,
    joint: str = "joint",
    parent_sensor: str = "parent",
    child_sensor: str = "child",
    proximal_parent: bool = False,
) -> HingeJointCalibration:
    """Axis and centre of a hinge on prepared signals (see the module docstring).

    Args:
        data: the pair's bias-corrected, filtered signals with α.
        rate_hz: sampling rate, Hz.
        method: one of :data:`~lowerlimb.calibration.options.METHODS`.
        options: calibration options.
        n_still: still samples at the start (angle reference of the sign rule).
        joint: joint name used in messages.
        parent_sensor: parent sensor name used in messages.
        child_sensor: child sensor name used in messages.
        proximal_parent: the parent sensor sits above the joint and the child below it, along
            their up at standing (a knee): the centre's fit tries more starts and prefers such
            a centre (:func:`below_parent_above_child`, ``options.hinge_centre_start_m``).

    Returns:
        The hinge result; warnings are issued and recorded.

    Raises:
        SolverError: a solver failed.
    """

    def acc_check(jp: FloatArray, jc: FloatArray) -> float:
        return acc_sign_correlation(data, jp, jc, options)[0]

    axis = fit_hinge_axis(
        data.gyr_parent,
        data.gyr_child,
        rate_hz=rate_hz,
        method=method,
        options=options,
        n_still=n_still,
        joint=joint,
        parent_sensor=parent_sensor,
        child_sensor=child_sensor,
        acc_check=acc_check,
        gravity=_still_gravity(data, n_still),
    )
    center = fit_spherical(
        data,
        method=method,
        options=options,
        joint=joint,
        parent_sensor=parent_sensor,
        child_sensor=child_sensor,
        gauge_axes=(axis.axis_in_parent_sensor, axis.axis_in_child_sensor),
        accept=below_parent_above_child(data, n_still) if proximal_parent else None,
    )
    return HingeJointCalibration(axis=axis, center=center)


def below_parent_above_child(data: SphericalData, n_still: int) -> Callable[[FloatArray, FloatArray], bool]:
    """Whether a centre ``(c_P, c_C)`` (m) lies below the parent sensor and above the child sensor.

    Up is each sensor's mean specific force over the still start, or over the whole trial
    without one (a thigh and a shank are upright on average while walking).
    """
    still = _still_gravity(data, n_still)
    up_p, up_c = still if still is not None else (data.acc_parent.mean(axis=0), data.acc_child.mean(axis=0))

    def accept(c_p: FloatArray, c_c: FloatArray) -> bool:
        return bool(c_p @ up_p < 0.0 < c_c @ up_c)

    return accept


def _axis_mismatch_deg(
    hinge: HingeJointCalibration,
    data: SphericalData,
    n_still: int,
    rate_hz: float,
    options: CalibrationOptions,
) -> tuple[float, str]:
    """The axis's elevation mismatch between the two sensors, deg, and where it was read.

    At rest over the still start (:func:`~lowerlimb.calibration.knee_line.standing_axis_mismatch`);
    without one, its median over the motion
    (:func:`~lowerlimb.calibration.knee_line.moving_axis_mismatch`).
    """
    up = _still_gravity(data, n_still)
    if up is not None:
        return float(np.degrees(standing_axis_mismatch(hinge, *up))), "at rest"
    rad = moving_axis_mismatch(
        hinge, data.acc_parent, data.acc_child, rate_hz, options.moving_mismatch_lowpass_hz
    )
    return float(np.degrees(rad)), "over the motion (median; no still start)"


def calibrate_hinge_joint(
    acc_parent: ArrayLike,
    gyr_parent: ArrayLike,
    acc_child: ArrayLike,
    gyr_child: ArrayLike,
    *,
    rate_hz: float,
    method: str = "casadi",
    options: CalibrationOptions | None = None,
    joint: str = "joint",
    parent_sensor: str = "parent",
    child_sensor: str = "child",
) -> HingeJointCalibration:
    """Hinge axis and a centre on it between two IMUs, with diagnostics.

    A pair recorded below ``options.min_fit_rate_hz`` (100 Hz) is fitted on its signals
    interpolated to a multiple of the rate (:mod:`~lowerlimb.upsample`).

    With ``options.pair_band_test``, a pair whose rigid band caps its cut-offs and whose
    axis, seen from the two sensors, differs in elevation at rest by more than
    ``options.fit_band_max_mismatch_deg`` (6°; a rigid hinge keeps them equal, as the leg
    calibration's fit band reads it) is fitted again below the cap, with a warning: the
    sensors move on their segments (the real walk's knees: 17 / 22°, their centres 286 / 155 mm
    from the leg calibration's axis line in the thigh sensor → 7 / 0 mm;
    ``benchmarks/results/pair_api.md``). Without a still start the mismatch is read as its
    median over the motion (:func:`~lowerlimb.calibration.knee_line.moving_axis_mismatch`).

    Args:
        acc_parent: (N, 3) parent accelerometer (specific force), parent sensor frame, m/s².
        gyr_parent: (N, 3) parent gyroscope, parent sensor frame, rad/s.
        acc_child: (N, 3) child accelerometer, child sensor frame, m/s².
        gyr_child: (N, 3) child gyroscope, child sensor frame, rad/s.
        rate_hz: common sampling rate, Hz.
        method: ``"casadi"`` (default), ``"gn"``, ``"dwpso"``, ``"gwo"``,
            ``"dwpso+casadi"`` or ``"gwo+casadi"``.
        options: tuning parameters (defaults: :class:`CalibrationOptions`).
        joint: joint name used in messages.
        parent_sensor: parent sensor name used in messages.
        child_sensor: child sensor name used in messages.

    Returns:
        Axes (unit, same physical direction; for a knee pointing right) and the
        centre on the axis nearest the sensors (m), in both sensor frames.

    Raises:
        ShapeError: an array is not (N, 3) or lengths differ.
        NonFiniteValueError: NaN or inf in a signal.
        UnitError: a gyro that looks like deg/s.
        InputError: non-positive rate, too few samples, or unknown method.
        SolverError: a solver failed.
    """
    opts = options or CalibrationOptions()
    check_method(method)
    bands = prepare_pair_bands(
        acc_parent, gyr_parent, acc_child, gyr_child, rate_hz, opts, band=opts.pair_band_test
    )
    n = bands.sig.n_still

    def fit(data: SphericalData) -> HingeJointCalibration:
        return fit_hinge_joint(
            data, rate_hz=bands.sig.rate_hz, method=method, options=opts, n_still=n, joint=joint,
            parent_sensor=parent_sensor, child_sensor=child_sensor,
        )  # fmt: skip

    if bands.capped is None:
        return fit(bands.full)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        hinge = fit(bands.full)
    mismatch, where = _axis_mismatch_deg(hinge, bands.full, n, bands.sig.rate_hz, opts)
    if abs(mismatch) <= opts.fit_band_max_mismatch_deg:
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return hinge
    capped = fit(bands.capped)
    message = (
        f"{joint}: the hinge axis seen from the {parent_sensor} and from the {child_sensor} sensor differs "
        f"by {abs(mismatch):.0f}° in elevation {where} (a rigid hinge keeps them equal): the sensors move "
        f"on their segments, so the pair was fitted below {bands.cap_hz:.1f} Hz, where their "
        f"accelerometers stay coherent"
    )
    issue_warnings([message], stacklevel=2)
    return replace(capped, center=replace(capped.center, warnings=[*capped.center.warnings, message]))
