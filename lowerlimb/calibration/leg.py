"""Whole-leg joint-constraint calibration: hip, knee and ankle from four IMUs (Hu et al. 2021 §2–3).

:func:`calibrate_leg` runs, on one :class:`~lowerlimb.io.trial.ImuTrial`:

1. gyro-bias removal from the still start, motion-adaptive prefilter and α
   for the four sensors (:mod:`~lowerlimb.calibration._prepare`);
2. hip: spherical joint pelvis–thigh (eq. 1–3, 7);
3. knee: hinge axis thigh–shank (eq. 4–6, 12) with the signs resolved so that
   both axes point to the subject's right (knee flexion positive, see
   :mod:`~lowerlimb.calibration.hinge_axis`), then a centre on the axis: the
   spherical residual restricted (gauge of eq. 16) to the point of the axis
   nearest the two sensors (eq. 16); the relative axis sign is cross-checked
   with the joint-centre accelerations;
4. ankle: spherical joint shank–foot.

All four run first as the options give them and, where a rigid-band cap lowered a cut-off,
again with the caps widened by ``fit_band_factor``; that fit is kept unless it shows sensors
that are not rigid on the bone or an implausible segment
(:mod:`~lowerlimb.calibration.fit_band`).

``runtime_s`` is the wall time of these steps (signal preparation included,
trial loading excluded), the number calibration.json reports (docs/formats.md).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from lowerlimb.calibration._prepare import (
    PreparedSignals,
    check_duration,
    check_rate,
    check_signal,
    joint_signals,
    prepare_signals,
)
from lowerlimb.calibration._solve import subsample_step
from lowerlimb.calibration.cutoff_probe import cutoff_shift_message, with_cutoff_shifts
from lowerlimb.calibration.excitation import issue_warnings
from lowerlimb.calibration.fit_band import (
    NO_CAP_BINDS,
    NO_STANDING_START,
    FitBand,
    axis_mismatch_reason,
    implausible_segment,
    moving_mismatch_reason,
    widened_caps,
)
from lowerlimb.calibration.hinge_joint import below_parent_above_child, fit_hinge_joint
from lowerlimb.calibration.impact_window import dilate, impact_cutoff_limit_hz, impact_keep_mask
from lowerlimb.calibration.joint_center import fit_spherical
from lowerlimb.calibration.joint_cutoff import joint_cutoffs_hz
from lowerlimb.calibration.knee_line import axis_mismatch_message, standing_axis_mismatch, with_knee_line
from lowerlimb.calibration.options import CalibrationOptions, check_method
from lowerlimb.calibration.rest_gravity import rest_gravity_offsets, vertical_offsets_removed
from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration
from lowerlimb.calibration.segment_prior import CenterPrior, center_prior, segment_up
from lowerlimb.calibration.split_half import half_masks, split_half_message, split_half_shift
from lowerlimb.calibration.thigh_twist import ThighTwist
from lowerlimb.constraints.spherical import SphericalData
from lowerlimb.conventions import JOINT_SENSORS, SENSORS, FloatArray
from lowerlimb.errors import InputError
from lowerlimb.io.saturation import at_limit_samples
from lowerlimb.side_by_side import Beside
from lowerlimb.stillness import StillPeriod, detect_still_period
from lowerlimb.upsample import upsample_factor, upsampled, upsampled_still

__all__ = ["CALIBRATION_FORMAT", "LegCalibration", "calibrate_leg"]

#: Value of the ``format`` key of calibration.json.
CALIBRATION_FORMAT = "lowerlimb-calibration/1"


class _TrialLike(Protocol):
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]
    side: str

    @property
    def rate_hz(self) -> float: ...


@dataclass
class LegCalibration:
    """Calibrated joints of one leg, serialisable to calibration.json (docs/formats.md).

    Attributes:
        side: ``"left"`` or ``"right"``.
        method: calibration method used.
        hip: pelvis–thigh spherical joint.
        knee: thigh–shank hinge (axis pointing right, centre on the axis).
        ankle: shank–foot spherical joint.
        runtime_s: wall time of the three joints' calibration, s.
        gyro_bias: ``{sensor: (3,)}`` gyro bias removed, rad/s.
        still_s: length of the still start used for the bias, s (0: none found).
        cutoff_hz: ``{sensor: Hz or None}`` prefilter cut-offs.
        rigid_band_cap_hz: ``{"parent-child": Hz or None}`` the cap the rigid band
            of each joint's sensor pair put on its cut-offs (``None``: no cap).
        impact_cutoff_hz: ``{"parent-child": Hz}`` the limit on the cut-offs of a pair
            whose joint leaves impacts out, where the trial had impacts
            (``CalibrationOptions.impact_max_cutoff_hz``; empty: none).
        priors: ``{"hip"|"ankle": {"on", "mean", "std_m"}}`` the anthropometric
            priors used (:mod:`~lowerlimb.calibration.segment_prior`; empty: none).
        clock_offsets: the sensors' clock offsets found and the re-timing applied
            (:meth:`~lowerlimb.calibration.clock_sync.ClockOffsets.to_dict`; empty: not estimated).
        fit_rate_hz: the rate the joints were fitted at, Hz: the recorded one, or a multiple
            of it for a trial below ``min_fit_rate_hz`` (:mod:`~lowerlimb.upsample`;
            0: not recorded).
        rest_gravity_offsets: ``{sensor: m/s²}`` each accelerometer's norm at the standing
            start minus 9.81 (:mod:`~lowerlimb.calibration.rest_gravity`; empty: no standing
            start).
        rest_gravity_removed: whether those offsets were taken off along each sensor's
            standing vertical before the fits (``CalibrationOptions.rest_gravity_correction``).
        fit_band: the band the joints were fitted in (:mod:`~lowerlimb.calibration.fit_band`).
        thigh_twist: the thigh sensor's twist undone before the fits
            (:mod:`~lowerlimb.calibration.thigh_twist`; the calibration is of the untwisted
            thigh sensor, which coincides with the sensor at standing); ``None``: none.
        coherent_fit: the leg fitted in the coherent band, beside a kept widened fit (not
            written; the clock search compares coherent-band fits); ``None`` otherwise.
    """

    side: str
    method: str
    hip: SphericalJointCalibration
    knee: HingeJointCalibration
    ankle: SphericalJointCalibration
    runtime_s: float = 0.0
    gyro_bias: dict[str, FloatArray] = field(default_factory=dict)
    still_s: float = 0.0
    cutoff_hz: dict[str, float | None] = field(default_factory=dict)
    rigid_band_cap_hz: dict[str, float | None] = field(default_factory=dict)
    impact_cutoff_hz: dict[str, float] = field(default_factory=dict)
    priors: dict[str, dict[str, Any]] = field(default_factory=dict)
    clock_offsets: dict[str, Any] = field(default_factory=dict)
    fit_rate_hz: float = 0.0
    rest_gravity_offsets: dict[str, float] = field(default_factory=dict)
    rest_gravity_removed: bool = False
    fit_band: FitBand = field(default_factory=FitBand)
    thigh_twist: ThighTwist | None = None
    coherent_fit: LegCalibration | None = field(default=None, repr=False, compare=False)

    @property
    def joints(self) -> dict[str, SphericalJointCalibration | HingeJointCalibration]:
        """``{"hip": …, "knee": …, "ankle": …}``."""
        return {"hip": self.hip, "knee": self.knee, "ankle": self.ankle}

    @property
    def warnings(self) -> list[str]:
        """All excitation and sign warnings of the three joints."""
        return self.hip.warnings + self.knee.warnings + self.ankle.warnings

    def to_dict(self) -> dict[str, Any]:
        """The calibration.json document (docs/formats.md schema, metres; extras after)."""
        return {
            "format": CALIBRATION_FORMAT,
            "side": self.side,
            "method": self.method,
            "joints": {name: j.to_dict() for name, j in self.joints.items()},
            "runtime_s": float(self.runtime_s),
            "gyro_bias_rps": {k: [float(x) for x in v] for k, v in self.gyro_bias.items()},
            "still_period_s": float(self.still_s),
            "prefilter_cutoff_hz": {k: (None if v is None else float(v)) for k, v in self.cutoff_hz.items()},
            "rigid_band_cap_hz": {
                k: (None if v is None else float(v)) for k, v in self.rigid_band_cap_hz.items()
            },
            "impact_cutoff_hz": {k: float(v) for k, v in self.impact_cutoff_hz.items()},
            "anthropometric_prior": dict(self.priors),
            "clock_offsets": dict(self.clock_offsets),
            "fit_rate_hz": float(self.fit_rate_hz),
            "rest_gravity_offset_mps2": {k: float(v) for k, v in self.rest_gravity_offsets.items()},
            "rest_gravity_removed": bool(self.rest_gravity_removed),
            "fit_band": self.fit_band.to_dict(),
            "thigh_twist": None if self.thigh_twist is None else self.thigh_twist.to_dict(),
            "warnings": self.warnings,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> LegCalibration:
        """Inverse of :meth:`to_dict`; only the docs/formats.md keys are required.

        Raises:
            InputError: a missing key or another format.
        """
        fmt = d.get("format")
        if fmt != CALIBRATION_FORMAT:
            raise InputError(
                f"not a calibration document: format is {fmt!r}, expected {CALIBRATION_FORMAT!r}"
            )
        try:
            joints = d["joints"]
            return cls(
                side=d["side"],
                method=d.get("method", ""),
                hip=SphericalJointCalibration.from_dict(joints["hip"], "hip"),
                knee=HingeJointCalibration.from_dict(joints["knee"], "knee"),
                ankle=SphericalJointCalibration.from_dict(joints["ankle"], "ankle"),
                runtime_s=float(d.get("runtime_s", 0.0)),
                gyro_bias={k: np.asarray(v, dtype=float) for k, v in d.get("gyro_bias_rps", {}).items()},
                still_s=float(d.get("still_period_s", 0.0)),
                cutoff_hz=dict(d.get("prefilter_cutoff_hz", {})),
                rigid_band_cap_hz=dict(d.get("rigid_band_cap_hz", {})),
                impact_cutoff_hz={k: float(v) for k, v in d.get("impact_cutoff_hz", {}).items()},
                priors=dict(d.get("anthropometric_prior", {})),
                clock_offsets=dict(d.get("clock_offsets", {})),
                fit_rate_hz=float(d.get("fit_rate_hz", 0.0)),
                rest_gravity_offsets={k: float(v) for k, v in d.get("rest_gravity_offset_mps2", {}).items()},
                rest_gravity_removed=bool(d.get("rest_gravity_removed", False)),
                fit_band=FitBand.from_dict(d.get("fit_band")),
                thigh_twist=None if d.get("thigh_twist") is None else ThighTwist.from_dict(d["thigh_twist"]),
            )
        except KeyError as e:
            raise InputError(f"calibration document lacks the key {e.args[0]!r}") from None


def leg_priors(
    knee: HingeJointCalibration, acc: dict[str, FloatArray], n_still: int, options: CalibrationOptions
) -> tuple[CenterPrior | None, CenterPrior | None]:
    """The anthropometric priors of the hip in the thigh sensor and the ankle in the shank sensor.

    Args:
        knee: the calibrated knee (axis and centre in the thigh and shank sensors).
        acc: ``{sensor: (N, 3)}`` accelerometers, sensor frames, m/s².
        n_still: samples of the standing start (0: none, no prior).
        options: the prior's stature, length fractions and spreads.

    Returns:
        ``(hip prior on the child, ankle prior on the parent)``; ``None`` where the
        standing direction is unknown.
    """
    if n_still < 1:
        return None, None
    out: list[CenterPrior | None] = []
    for sensor, axis, center, length, on_child in (
        (
            "thigh",
            knee.axis.axis_in_parent_sensor,
            knee.center.center_in_parent_sensor,
            options.thigh_length_per_stature,
            True,
        ),
        (
            "shank",
            knee.axis.axis_in_child_sensor,
            knee.center.center_in_child_sensor,
            -options.shank_length_per_stature,
            False,
        ),
    ):
        up = segment_up(acc[sensor][:n_still].mean(axis=0), axis)
        if up is None:
            out.append(None)
            continue
        L = length * options.prior_stature_m
        out.append(
            center_prior(
                center,
                axis,
                up,
                L,
                std_along_m=options.prior_std_along * abs(L),
                std_across_m=options.prior_std_across_m,
                std_axis_m=options.prior_std_axis_m,
                on_child=on_child,
            )
        )
    return out[0], out[1]


def calibrate_leg(
    trial: _TrialLike,
    *,
    method: str = "casadi",
    options: CalibrationOptions | None = None,
    still: StillPeriod | None = None,
) -> LegCalibration:
    """Calibrate hip, knee and ankle of one leg from a four-IMU trial (Hu et al. 2021).

    Args:
        trial: an :class:`~lowerlimb.io.trial.ImuTrial` (``acc``/``gyr`` dicts of
            (N, 3) arrays for pelvis, thigh, shank, foot in m/s² and rad/s;
            ``rate_hz``; ``side``). It should start with ≥ 1 s standing still.
        method: ``"casadi"`` (default), ``"gn"``, ``"dwpso"``, ``"gwo"``,
            ``"dwpso+casadi"`` or ``"gwo+casadi"``.
        options: tuning parameters (defaults: :class:`CalibrationOptions`).
        still: the trial's still start when already detected
            (:meth:`ImuTrial.still_period <lowerlimb.io.trial.ImuTrial.still_period>`).

    Returns:
        The calibration; ``to_dict()`` is the calibration.json document.

    Raises:
        InputError: a sensor is missing, a signal is malformed (``ShapeError``,
            ``NonFiniteValueError``, ``UnitError``), the trial is too short, the
            side or the method is unknown, or two sensors' columns look swapped
            (``SensorOrderError``, :mod:`~lowerlimb.calibration.plausibility`).
        SolverError: a solver failed.

    Warns:
        ExcitationWarning: a joint is poorly excited (also in ``warnings``).
    """
    opts = options or CalibrationOptions()
    check_method(method)
    side = getattr(trial, "side", None)
    if side not in ("left", "right"):
        raise InputError(f"trial.side must be 'left' or 'right', got {side!r}")
    rate = check_rate(trial.rate_hz)
    acc: dict[str, FloatArray] = {}
    gyr: dict[str, FloatArray] = {}
    n: int | None = None
    for s in SENSORS:
        if s not in trial.acc or s not in trial.gyr:
            raise InputError(
                f"the trial has no {s} sensor; calibrate_leg needs acc and gyr of {', '.join(SENSORS)}"
            )
        acc[s] = check_signal(trial.acc[s], f"{s} accelerometer", "m/s²", n)
        n = acc[s].shape[0]
        gyr[s] = check_signal(trial.gyr[s], f"{s} gyroscope", "rad/s", n)
    assert n is not None
    check_duration(n, rate, opts)

    t0 = time.perf_counter()
    still = still or detect_still_period(list(gyr.values()), list(acc.values()), rate)
    at_limit = at_limit_samples(acc, gyr) if opts.saturation_exclusion else {}
    return _fit_in_band(_CheckedLeg(side, method, acc, gyr, rate, still, t0, at_limit), opts)


@dataclass(frozen=True)
class _CheckedLeg:
    """A leg's checked signals and what every fit of it shares.

    Attributes:
        side: ``"left"`` or ``"right"``.
        method: the calibration method.
        acc: ``{sensor: (N, 3)}`` checked accelerometers, sensor frames, m/s².
        gyr: ``{sensor: (N, 3)}`` checked gyros, sensor frames, rad/s.
        rate: sampling rate, Hz.
        still: the still start (``None``: none found).
        t0: the :func:`time.perf_counter` at which the calibration began (``runtime_s``).
        at_limit: ``{sensor: (N,) booleans}`` where a sensor sits at the end of its range
            (:func:`at_limit_samples`; empty without ``saturation_exclusion``), found once for
            every fit of the leg.
    """

    side: str
    method: str
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]
    rate: float
    still: StillPeriod | None
    t0: float
    at_limit: dict[str, NDArray[np.bool_]] = field(default_factory=dict)


def _fit_in_band(leg: _CheckedLeg, opts: CalibrationOptions) -> LegCalibration:
    """The leg fitted with widened rigid-band caps where a standing start shows rigid sensors, else as given.

    See :mod:`~lowerlimb.calibration.fit_band`. The coherent band's fit decides; the widened
    one counts only where a cap lowered a cut-off, and stops as soon as its knee shows an axis
    mismatch. Where the machine has two cores the widened fit runs beside the coherent one
    (:class:`~lowerlimb.side_by_side.Beside`: a forked child, dropped where no cap binds), else
    after it, only where needed; the fits are the same. Only the kept fit is probed and only
    its warnings are issued; a leg refitted for an implausible segment also gets the fit
    band's warning.
    """
    n = leg.still.samples(opts.still_min_s) if leg.still is not None else 0
    caps = opts.prefilter and opts.rigid_band and opts.cutoff_hz is None  # else nothing to widen
    if opts.fit_band_factor == 1.0 or not caps:
        fit = _fit_leg(leg, opts)
        return _kept(leg, fit, fit.cal.fit_band, [])
    factor = opts.fit_band_factor
    if n == 0 and not opts.fit_band_without_standing:
        fit = _fit_leg(leg, opts)
        return _kept(leg, fit, replace(fit.cal.fit_band, factor=factor, reason=NO_STANDING_START), [])
    rigid_knee = _rigid_knee(leg, n, opts)
    # the widened fit is started beside the coherent one (lowerlimb.side_by_side) and dropped
    # where no cap binds: the same fits as one after the other, in the time of one
    with Beside(lambda: _widened(leg, opts, rigid_knee)) as beside:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            coherent = _fit_leg(leg, opts)
        capped = coherent.cal.fit_band.capped
        if not capped:
            return _kept(leg, coherent, FitBand(factor, reason=NO_CAP_BINDS), caught)
        tried = beside.value()
    if tried.fit is None:  # the knee's own mismatch warning says so: no warning of the band's
        return _kept(leg, coherent, FitBand(factor, reason=tried.not_rigid, capped=capped), caught)
    wide, caught_wide = tried.fit, tried.caught
    reason = implausible_segment(wide.cal, opts)
    if reason is None:
        kept = _kept(leg, wide, FitBand(factor, widened=True, capped=capped), caught_wide)
        return replace(kept, coherent_fit=replace(coherent.cal, fit_band=kept.fit_band))
    band = FitBand(factor, reason=reason, capped=capped)
    coherent_reason = implausible_segment(coherent.cal, opts)
    if coherent_reason is not None:
        free = _uncapped_fit(leg, opts, rigid_knee)
        if free is not None:
            band = replace(band, uncapped=True)
            cal = _kept(leg, free[0], band, free[1])
            return replace(cal, knee=_with_warning(cal.knee, band.uncapped_message(coherent_reason)))
    cal = _kept(leg, coherent, band, caught)
    return replace(cal, knee=_with_warning(cal.knee, band.fallback_message()))


def _rigid_knee(
    leg: _CheckedLeg, n: int, opts: CalibrationOptions
) -> Callable[[HingeJointCalibration], None]:
    """The test that stops a fit whose knee shows sensors that are not rigid (raises :class:`_NotRigid`).

    With a standing start of ``n`` samples it reads the knee's axis mismatch there, else over
    the motion (:mod:`~lowerlimb.calibration.fit_band`).
    """

    def rigid_knee(knee: HingeJointCalibration) -> None:
        reason = (
            axis_mismatch_reason(
                knee, leg.acc["thigh"][:n].mean(axis=0), leg.acc["shank"][:n].mean(axis=0), opts
            )
            if n
            else moving_mismatch_reason(knee, leg.acc["thigh"], leg.acc["shank"], leg.rate, opts)
        )
        if reason is not None:
            raise _NotRigid(reason)

    return rigid_knee


@dataclass(frozen=True)
class _Widened:
    """The widened band's fit and its warnings, or why its knee stopped it (``fit`` ``None``)."""

    fit: _Fit | None
    not_rigid: str | None
    caught: list[warnings.WarningMessage]


def _widened(
    leg: _CheckedLeg, opts: CalibrationOptions, rigid_knee: Callable[[HingeJointCalibration], None]
) -> _Widened:
    """The leg fitted with the caps widened, its warnings recorded, unless its knee is not rigid."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            # the sensor order is checked by the coherent fit
            wide = _fit_leg(leg, replace(widened_caps(opts), check_sensor_order=False), rigid_knee)
    except _NotRigid as e:
        return _Widened(None, str(e), [])
    return _Widened(wide, None, list(caught))


def _uncapped_fit(
    leg: _CheckedLeg, opts: CalibrationOptions, rigid_knee: Callable[[HingeJointCalibration], None]
) -> tuple[_Fit, list[warnings.WarningMessage]] | None:
    """The leg fitted without rigid-band caps, when that gives a plausible leg on a rigid knee, else ``None``.

    The caps end a joint's band where the two sensors' acceleration norms stop being coherent,
    which soft tissue does, but so does rigid rotation about the hip: a pelvis and a thigh
    sensor see different centripetal and tangential accelerations (their lever arms differ).
    A shuffling walk with turns about (seed 203) had both hips capped at the 2 Hz floor, both
    legs' thighs 144–157 mm long and fell back on de Leva; uncapped, the hips and ankles came
    out 1–3 mm from the truth. Tried only where both capped fits are implausible.
    """
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            free = _fit_leg(leg, replace(opts, rigid_band=False, check_sensor_order=False), rigid_knee)
    except _NotRigid:
        return None
    if implausible_segment(free.cal, opts) is not None:
        return None
    return free, caught


def _without_limits(
    keep: NDArray[np.bool_] | None,
    at_limit: Mapping[str, NDArray[np.bool_]],
    sensors: tuple[str, str],
    factor: int,
    half: int,
) -> NDArray[np.bool_] | None:
    """A joint's keep mask without the samples near where its sensors sit at their range.

    Args:
        keep: the fit's (k·N,) mask so far (``None``: every sample).
        at_limit: ``{sensor: (N,) booleans}`` of the recorded samples (:func:`at_limit_samples`).
        sensors: the joint's two sensors.
        factor: the fit's upsampling factor ``k``.
        half: samples either side of one at the limit also left out (fit rate).
    """
    cut = [at_limit[s] for s in sensors if s in at_limit]
    if not cut:
        return keep
    near = dilate(np.repeat(np.logical_or.reduce(cut), factor), half)
    return ~near if keep is None else keep & ~near


def _kept(
    leg: _CheckedLeg, fit: _Fit, band: FitBand, caught: list[warnings.WarningMessage]
) -> LegCalibration:
    """The kept fit: its recorded warnings issued, then probed, with its band and the whole runtime."""
    for w in caught:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    cal = fit.probes.recorded(fit.cal)
    return replace(cal, fit_band=band, runtime_s=time.perf_counter() - leg.t0)


class _NotRigid(Exception):
    """The widened fit's knee shows sensors that are not rigid on the bone (the reason)."""


def _fit_leg(
    leg: _CheckedLeg,
    opts: CalibrationOptions,
    knee_check: Callable[[HingeJointCalibration], None] | None = None,
) -> _Fit:
    """The joints of one leg fitted with ``opts`` (stages 1–4 of the module docstring), unprobed.

    ``knee_check`` sees the knee as soon as it is fitted and may raise to stop the fit.
    """
    side, method, acc, gyr, rate, still = leg.side, leg.method, leg.acc, leg.gyr, leg.rate, leg.still
    at_limit = leg.at_limit if opts.saturation_exclusion else {}
    offsets: dict[str, float] = {}
    n_rest = still.samples(opts.still_min_s) if still is not None else 0
    if n_rest and opts.rest_gravity_correction:
        acc, offsets = vertical_offsets_removed(acc, slice(0, n_rest))
    elif n_rest:
        offsets = rest_gravity_offsets(acc, slice(0, n_rest))  # recorded, signals untouched
    k = upsample_factor(rate, opts.min_fit_rate_hz)
    if k > 1:
        acc, gyr, rate, still = upsampled(acc, k), upsampled(gyr, k), rate * k, upsampled_still(still, k)
    sig = prepare_signals(acc, gyr, rate, opts, still=still)
    if opts.check_sensor_order:
        from lowerlimb.calibration.plausibility import check_sensor_order

        check_sensor_order(acc, gyr, sig, opts)

    caps: dict[str, float | None] = {}
    capped: set[str] = set()
    p, c, _ = JOINT_SENSORS["hip"]
    pa, ca, _ = JOINT_SENSORS["ankle"]
    hip_keep, ankle_keep = (
        impact_keep_mask((acc[s], acc[t], acc["foot"]), rate, opts)
        if opts.impact_exclusion and joint in opts.impact_joints
        else None
        for joint, s, t in (("hip", p, c), ("ankle", pa, ca))
    )
    limits = {j: impact_cutoff_limit_hz(kp, opts) for j, kp in (("hip", hip_keep), ("ankle", ankle_keep))}
    hip_keep, ankle_keep = (
        _without_limits(kp, at_limit, (s, t), k, int(round(opts.impact_window_s * rate)))
        for kp, s, t in ((hip_keep, p, c), (ankle_keep, pa, ca))
    )
    pair_keys = {"hip": f"{p}-{c}", "ankle": f"{pa}-{ca}"}
    hip_data = joint_signals(acc, gyr, sig, p, c, opts, caps, max_hz=limits["hip"], capped=capped)
    ankle_data = joint_signals(acc, gyr, sig, pa, ca, opts, caps, max_hz=limits["ankle"], capped=capped)
    near = [v for v in caps.values() if v is not None]
    pk, ck, _ = JOINT_SENSORS["knee"]
    knee = fit_hinge_joint(
        joint_signals(
            acc, gyr, sig, pk, ck, opts, caps, min(near) if near else None, own_band=False, capped=capped
        ),
        rate_hz=rate,
        method=method,
        options=opts,
        n_still=sig.n_still,
        joint="knee",
        parent_sensor=pk,
        child_sensor=ck,
        proximal_parent=True,
    )
    if knee_check is not None:
        knee_check(knee)
    hip_prior, ankle_prior = (
        leg_priors(knee, acc, sig.n_still, opts) if opts.anthropometric_prior else (None, None)
    )
    hip, ankle = (
        fit_spherical(
            data, method=method, options=opts, joint=joint, parent_sensor=s, child_sensor=t, prior=pr, keep=kp
        )
        for joint, data, s, t, pr, kp in (
            ("hip", hip_data, p, c, hip_prior, hip_keep),
            ("ankle", ankle_data, pa, ca, ankle_prior, ankle_keep),
        )
    )
    setup = {"hip": (p, c, hip_prior, hip_keep), "ankle": (pa, ca, ankle_prior, ankle_keep)}
    probes = _Probes(setup, {"hip": hip_data, "ankle": ankle_data}, limits, acc, gyr, sig, method, opts)
    if opts.centre_form == "aligned" or opts.hip_in_pelvis_form == "aligned":
        keeps = {"hip": hip_keep, "ankle": ankle_keep}
        hip, knee, ankle = _aligned(hip, knee, ankle, acc, gyr, sig, caps, keeps, opts)
    priors = {n: pr.to_dict() for n, pr in (("hip", hip_prior), ("ankle", ankle_prior)) if pr is not None}
    if opts.anthropometric_prior and opts.knee_line_prior:
        knee, priors["knee_line"] = _knee_line(knee, hip, ankle, acc, gyr, sig, caps, method, opts)
    cal = LegCalibration(
        side=side,
        method=method,
        hip=hip,
        knee=knee,
        ankle=ankle,
        runtime_s=time.perf_counter() - leg.t0,
        gyro_bias=sig.gyro_bias,
        still_s=sig.n_still / rate,
        cutoff_hz=sig.cutoff_hz,
        rigid_band_cap_hz=caps,
        impact_cutoff_hz={pair_keys[j]: v for j, v in limits.items() if v is not None},
        fit_rate_hz=rate,
        priors=priors,
        rest_gravity_offsets=offsets,
        rest_gravity_removed=bool(offsets) and opts.rest_gravity_correction,
        fit_band=FitBand(capped=tuple(sorted(capped))),
    )
    return _Fit(cal, probes)


@dataclass(frozen=True)
class _Probes:
    """What the cut-off and split-half probes of one fit refit (records: no estimate changes).

    They run only on the fit that is kept (:meth:`recorded`), after the aligned form and the
    knee line, which leave the probed sides of the centres as they are.

    Attributes:
        setup: ``{joint: (parent sensor, child sensor, prior, keep mask)}`` of the hip and ankle fits.
        data: ``{joint: pair data}`` the hip and ankle were fitted on.
        limits: ``{joint: Hz or None}`` their impact cut-off limits.
        acc: ``{sensor: (N, 3)}`` the fit's accelerometers, m/s².
        gyr: ``{sensor: (N, 3)}`` its gyros, rad/s.
        sig: its prepared signals.
        method: the calibration method.
        opts: the fit's options.
    """

    setup: Mapping[str, tuple[str, str, CenterPrior | None, ArrayLike | None]]
    data: Mapping[str, SphericalData]
    limits: Mapping[str, float | None]
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]
    sig: PreparedSignals
    method: str
    opts: CalibrationOptions

    def recorded(self, cal: LegCalibration) -> LegCalibration:
        """``cal`` with its hip and ankle probes recorded and warned about (as the options ask)."""
        hip, ankle, o = cal.hip, cal.ankle, self.opts
        if o.cutoff_probe:
            hip, ankle = _probe_cutoffs(
                hip, ankle, self.setup, self.limits, self.acc, self.gyr, self.sig, self.method, o
            )
        if o.split_half_probe:
            hip, ankle = (
                _probe_halves(j, self.data[j.joint], self.setup[j.joint], self.sig.n_still, self.method, o)
                for j in (hip, ankle)
            )
        return replace(cal, hip=hip, ankle=ankle)


@dataclass(frozen=True)
class _Fit:
    """One fit of a leg: its calibration without the probes, and the probes to record on it if kept."""

    cal: LegCalibration
    probes: _Probes


def _aligned(
    hip: SphericalJointCalibration,
    knee: HingeJointCalibration,
    ankle: SphericalJointCalibration,
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    sig: PreparedSignals,
    caps: dict[str, float | None],
    keeps: Mapping[str, ArrayLike | None],
    options: CalibrationOptions,
) -> tuple[SphericalJointCalibration, HingeJointCalibration, SphericalJointCalibration]:
    """Hip and knee centres refined by the aligned 3-D form at their joints' cut-offs.

    With ``centre_form="norm"`` only the hip centre in the pelvis sensor is taken from
    it, given the norm form's centre in the thigh sensor (``hip_in_pelvis_form``,
    :func:`_pelvis_side`). See :mod:`~lowerlimb.calibration.aligned_form`; each fit starts
    from the norm form's centres. The ankle keeps the norm form: its pair is rarely filtered (the form's
    reason) and carries the heel-strike impacts, and there the aligned fit was worse
    on the simulator (ankle in the shank sensor 2.6 → 15 mm). The knee takes the aligned
    fit across its axis only (the lever arms, the segment lengths); along the axis the
    centre is weakly determined by either form (:mod:`~lowerlimb.calibration.knee_line`) and
    the norm form's coordinates are kept: the aligned ones moved the real walk's standing
    stance width from 29.5 to 22 cm (Vicon: 30.9) and its step-width error from 18 to 72 mm.
    Across the axis the aligned form undoes the norm form's shortening of both segments on
    the simulator (docs/limits.md, "The aligned 3-D form"); the default keeps the norm form
    there because the real walk's shanks disagree.
    """
    # imported here: the strapdown kernel loads numba and scipy's rotations (~0.2 s), which
    # the single-joint entry points (calibrate_spherical_joint, …) do not need
    from lowerlimb.calibration.aligned_form import AlignedSettings, aligned_centres

    o = options
    settings = AlignedSettings(
        o.aligned_window_s, o.aligned_iterations, o.angacc_window_s, o.angacc_polyorder, o.fit_max_samples
    )

    def refit(
        joint: str,
        res: SphericalJointCalibration,
        gauge: tuple[FloatArray, FloatArray] | None,
        fixed_child: bool = False,
    ) -> SphericalJointCalibration:
        p, c, _ = JOINT_SENSORS[joint]
        cutoff = _one_cutoff(joint_cutoffs_hz(sig.cutoff_hz[p], sig.cutoff_hz[c], caps.get(f"{p}-{c}"), o))
        fit = aligned_centres(
            acc[p],
            gyr[p] - sig.gyro_bias[p],
            acc[c],
            gyr[c] - sig.gyro_bias[c],
            rate_hz=sig.rate_hz,
            cutoff_hz=cutoff,
            start=np.concatenate([res.center_in_parent_sensor, res.center_in_child_sensor]),
            settings=settings,
            keep=keeps.get(joint),
            gauge_axes=gauge,
            fixed_child=fixed_child,
        )
        x = np.concatenate([fit.center_in_parent, fit.center_in_child])
        if not np.all(np.abs(x) < o.center_bound_m):
            message = (
                f"{joint}: the aligned form's centre left the search box (±{o.center_bound_m:g} m from a "
                f"sensor); the norm form's centre is kept"
            )
            issue_warnings([message], stacklevel=4)
            return replace(res, warnings=[*res.warnings, message])
        return replace(
            res,
            center_in_parent_sensor=fit.center_in_parent,
            center_in_child_sensor=fit.center_in_child,
            solver=f"{res.solver}+aligned",
        )

    whole = o.centre_form == "aligned"
    if whole and "knee" in o.aligned_joints:
        gauge = (knee.axis_in_parent_sensor, knee.axis_in_child_sensor)
        knee = replace(knee, center=_across_axis(refit("knee", knee.center, gauge), knee.center, gauge))
    if whole and "hip" in o.aligned_joints:
        hip = refit("hip", hip, None)
    elif o.hip_in_pelvis_form == "aligned":
        hip = _pelvis_side(refit("hip", hip, None, fixed_child=True), hip)
    return hip, knee, ankle


def _pelvis_side(new: SphericalJointCalibration, old: SphericalJointCalibration) -> SphericalJointCalibration:
    """``new`` (its pelvis side fitted with ``old``'s thigh side held) labelled as such.

    Why: the norm form cannot place the centre in a sensor that barely turns (the
    pelvis in walking) once the pair is low-passed, while the thigh's large rotation
    decides its side in either form; there the two forms disagree on the real walk by
    more than either's agreement with Vicon (``benchmarks/results/aligned_form.md``), and
    the norm form's side is kept.
    """
    if np.array_equal(new.center_in_parent_sensor, old.center_in_parent_sensor):
        return new  # the aligned fit was not used (search box)
    return replace(
        new,
        solver=f"{old.solver}+aligned(pelvis side)",
        norm_center_in_parent_sensor=np.asarray(old.center_in_parent_sensor, dtype=float),
    )


def _across_axis(
    new: SphericalJointCalibration, old: SphericalJointCalibration, axes: tuple[FloatArray, FloatArray]
) -> SphericalJointCalibration:
    """``new``'s knee centres across the axis with ``old``'s coordinates along it (both frames)."""
    out = []
    for c_new, c_old, j in (
        (new.center_in_parent_sensor, old.center_in_parent_sensor, axes[0]),
        (new.center_in_child_sensor, old.center_in_child_sensor, axes[1]),
    ):
        u = np.asarray(j, dtype=float) / np.linalg.norm(j)
        out.append(c_new - (c_new @ u) * u + (c_old @ u) * u)
    return replace(new, center_in_parent_sensor=out[0], center_in_child_sensor=out[1])


def _one_cutoff(pair: tuple[float | None, float | None]) -> float | None:
    """One cut-off for both sensors of a joint: the higher (``None``, unfiltered, wins)."""
    a, b = pair
    if a is None or b is None:
        return None
    return max(a, b)


def _knee_line(
    knee: HingeJointCalibration,
    hip: SphericalJointCalibration,
    ankle: SphericalJointCalibration,
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    sig: PreparedSignals,
    caps: dict[str, float | None],
    method: str,
    options: CalibrationOptions,
) -> tuple[HingeJointCalibration, dict[str, Any]]:
    """The knee moved along its axis by the mechanical-axis prior, and the record.

    See :mod:`~lowerlimb.calibration.knee_line`; the cut-off probes run only where the prior applies.
    """
    pk, ck, _ = JOINT_SENSORS["knee"]
    n = sig.n_still
    mismatch = (
        standing_axis_mismatch(knee, acc[pk][:n].mean(axis=0), acc[ck][:n].mean(axis=0)) if n > 0 else 0.0
    )
    max_mismatch = float(np.radians(options.knee_line_max_mismatch_deg))
    probes = []
    if abs(mismatch) <= max_mismatch:
        cap = caps.get(f"{pk}-{ck}")
        # without a cap the main fit already is the uncapped one: nothing to probe
        cuts = [] if cap is None else [None, *(f * cap for f in options.knee_line_probe_factors)]
        for hz in cuts:
            data = joint_signals(acc, gyr, sig, pk, ck, options, None, hz, own_band=False)
            probes.append(_knee_probe(knee, data, n, method, options))
    knee, line = with_knee_line(
        knee,
        hip.center_in_child_sensor,
        ankle.center_in_parent_sensor,
        probes,
        mean_m=options.knee_line_mean_m,
        std_m=options.knee_line_std_m,
        min_data_std_m=options.knee_line_min_data_std_m,
        axis_mismatch_rad=mismatch,
        max_mismatch_rad=max_mismatch,
    )
    if not line.applied:
        knee = _with_warning(knee, axis_mismatch_message(line.axis_mismatch_deg))
    return knee, line.to_dict()


def _probe_cutoffs(
    hip: SphericalJointCalibration,
    ankle: SphericalJointCalibration,
    setup: Mapping[str, tuple[str, str, CenterPrior | None, ArrayLike | None]],
    limits: Mapping[str, float | None],
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    sig: PreparedSignals,
    method: str,
    options: CalibrationOptions,
) -> tuple[SphericalJointCalibration, SphericalJointCalibration]:
    """Hip and ankle with their cut-off shifts recorded (:mod:`~lowerlimb.calibration.cutoff_probe`).

    ``setup`` is ``{joint: (parent sensor, child sensor, prior, keep mask)}`` of the main fits,
    ``limits`` their impact cut-off limits (widened with every other cut-off).
    """

    def refit(name: str, data: SphericalData, o: CalibrationOptions) -> SphericalJointCalibration:
        s, t, pr, kp = setup[name]
        step = subsample_step(data.acc_parent.shape[0], options.cutoff_probe_max_samples)
        if step > 1:
            data = data.subsample(step)
            kp = None if kp is None else np.asarray(kp)[::step]
        return fit_spherical(
            data,
            method=_local(method),
            options=o,
            joint=name,
            parent_sensor=s,
            child_sensor=t,
            prior=pr,
            keep=kp,
        )

    pairs = {k: (v[0], v[1]) for k, v in setup.items()}
    out = with_cutoff_shifts({"hip": hip, "ankle": ankle}, pairs, acc, gyr, sig, options, refit, limits)
    probed = []
    for joint in (out["hip"], out["ankle"]):
        joint = replace(joint, cutoff_shift=_norm_sides_only(joint.cutoff_shift, joint.joint, options))
        message = cutoff_shift_message(joint, options.cutoff_shift_warn_m)
        if message is not None:
            issue_warnings([message], stacklevel=4)
            joint = replace(joint, warnings=[*joint.warnings, message])
        probed.append(joint)
    return probed[0], probed[1]


def _norm_sides_only(shift: FloatArray, joint: str, options: CalibrationOptions) -> FloatArray:
    """A probe's (6,) shift of the norm form, NaN on a side of the hip that the aligned form places.

    The probes refit the norm form; the aligned form places the hip in the pelvis sensor
    (``hip_in_pelvis_form``) and, with ``centre_form="aligned"``, both sides (:func:`_aligned`).
    """
    out = np.array(shift, dtype=float)
    if joint != "hip":
        return out
    whole = options.centre_form == "aligned" and "hip" in options.aligned_joints
    if whole or options.hip_in_pelvis_form == "aligned":
        out[:3] = np.nan
    if whole:
        out[3:] = np.nan
    return out


def _probe_halves(
    joint: SphericalJointCalibration,
    data: SphericalData,
    setup: tuple[str, str, CenterPrior | None, ArrayLike | None],
    n_still: int,
    method: str,
    options: CalibrationOptions,
) -> SphericalJointCalibration:
    """The joint with its split-half shift recorded, and warned about (:mod:`.split_half`)."""
    s, t, pr, kp = setup
    keep = None if kp is None else np.asarray(kp, dtype=bool)
    # each half as many samples as the cut-off probe's half: the signals are low-passed well below
    # the sampling rate, so thinning costs the refit little precision
    step = subsample_step(data.acc_parent.shape[0], options.cutoff_probe_max_samples // 2)
    if step > 1:
        data, keep, n_still = (
            data.subsample(step),
            None if keep is None else keep[::step],
            -(-n_still // step),
        )
    quiet = replace(options, center_std_tol_m=np.inf, min_rms_rate_rps=0.0)

    def refit(mask: np.ndarray) -> SphericalJointCalibration:
        return fit_spherical(
            data,
            method=_local(method),
            options=quiet,
            joint=joint.joint,
            parent_sensor=s,
            child_sensor=t,
            prior=pr,
            keep=mask,
        )

    shift = split_half_shift(refit, half_masks(data.acc_parent.shape[0], keep, n_still))
    out = replace(joint, split_half_shift=_norm_sides_only(shift, joint.joint, options))
    message = split_half_message(out, options.split_half_warn_m)
    if message is None:
        return out
    issue_warnings([message], stacklevel=4)
    return replace(out, warnings=[*out.warnings, message])


def _with_warning(knee: HingeJointCalibration, message: str) -> HingeJointCalibration:
    """The knee with ``message`` issued and recorded among its centre's warnings."""
    issue_warnings([message], stacklevel=4)
    return replace(knee, center=replace(knee.center, warnings=[*knee.center.warnings, message]))


def _local(method: str) -> str:
    """The local solver a probe refit uses: the method itself, or CasADi after a swarm."""
    return method if method in ("casadi", "gn") else "casadi"


def _knee_probe(
    knee: HingeJointCalibration, data: SphericalData, n_still: int, method: str, options: CalibrationOptions
) -> HingeJointCalibration:
    """The knee centre refitted on the sensors' own cut-offs (no rigid-band cap), same axis, quietly.

    Like the knee's own fit, it prefers a centre below the thigh sensor and above the shank
    sensor (:func:`~lowerlimb.calibration.hinge_joint.below_parent_above_child`).

    How far this moves the knee along its axis is the systematic part of the
    data's spread there (:mod:`~lowerlimb.calibration.knee_line`).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        center = fit_spherical(
            data,
            method=_local(method),
            options=options,
            joint="knee",
            gauge_axes=(knee.axis_in_parent_sensor, knee.axis_in_child_sensor),
            accept=below_parent_above_child(data, n_still),
        )
    return replace(knee, center=center)
