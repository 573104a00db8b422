"""The whole pipeline in memory: trial → calibration → orientations → segments → model → positions.

:func:`process_trial` reads no file and writes none; it runs four named
stages, each a function of its own (as pink's ``solve_ik`` reads
``objective → inequalities → build → solve``):

1. :func:`calibrate_joints` — the joint-constraint calibration, or a reused one
   with this trial's gyro bias;
2. :func:`estimate_orientations` — one orientation filter per sensor, with the
   magnetometer when its field looks undisturbed;
3. :func:`track_segments` — consistent headings, ISB segment frames and angles;
4. :func:`build_model` — the calibrated leg and its forward-kinematics positions.

Writing the result folder is :mod:`lowerlimb.outputs`; the command is
:mod:`lowerlimb.cli.calibrate`.
"""

from __future__ import annotations

import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .calibration import LegCalibration, calibrate_leg
from .calibration.axial_sign import axial_sign_correlation, gyro_sign_is_clear
from .calibration.clock_sync import ClockOffsets, synchronise
from .calibration.options import CalibrationOptions
from .calibration.plausibility import SIDE_MIN_MOTION_S, check_side, pelvis_turn_side_cue
from .calibration.rest_gravity import AccelerometerOffsetWarning, rest_gravity_notes, rest_gravity_offsets
from .calibration.thigh_twist import (
    ThighTwistWarning,
    estimate_thigh_twist,
    standing_mismatch_deg,
    unconfirmed_message,
    untwist_trial,
)
from .conventions import SENSORS, FloatArray, quat_from_matrix
from .errors import InputError
from .gait.cut_rate import RateRestore, restore_cut_gyro
from .gait.cut_segment import JointLink, SegmentRestore, restore_cut_segment_gyro
from .gait.one_leg import LegGait, analyse_leg_gait
from .gait.params import GaitParams
from .gait.stationary import detect_stationary
from .io.held_samples import warn_held_samples
from .io.saturation import Saturation, trial_saturation, warn_saturation
from .io.trial import ImuTrial
from .methods import ORIENTATION_FILTERS
from .model.calibrated import calibrated_geometry, chain_positions
from .model.fallback import segment_lengths, with_plausible_lengths
from .model.leg_model import LegModel
from .orientation.estimate import estimate_orientation_passes
from .orientation.magnetic import check_magnetic_field
from .orientation.sign_check import InvertedSignError, InvertedSignWarning, chain_sign_check
from .s2j import S2JModel, constant_s2j_from_calibration
from .segments.angle_range import ImplausibleAnglesWarning, implausible_angles
from .segments.tracking import SegmentMotion, track_segments
from .stillness import StillPeriod, gyro_bias

__all__ = [
    "MAG_FILTERS",
    "MagneticDisturbanceWarning",
    "Orientations",
    "TrialResult",
    "build_model",
    "calibrate_joints",
    "estimate_orientations",
    "process_trial",
]


#: Neighbouring sensors of one leg, proximal first (the sign check's chain).
_CHAIN_EDGES: tuple[tuple[str, str], ...] = tuple(zip(SENSORS[:-1], SENSORS[1:], strict=True))


class MagneticDisturbanceWarning(UserWarning):
    """The magnetometer was not fused because the field looks disturbed."""


#: Filters that use the magnetometer when the trial has one (all of the registry).
MAG_FILTERS: tuple[str, ...] = tuple(ORIENTATION_FILTERS)


@dataclass
class TrialResult:
    """Everything :func:`process_trial` computes.

    Attributes:
        trial: the input trial.
        calibration: the joint-constraint calibration.
        quat_wxyz: ``{sensor: (N, 4)}`` filter orientations (before heading correction).
        motion: segment frames, corrected orientations and ISB angles.
        model: the calibrated leg.
        positions_m: (N, 6) pelvis→foot and hip→ankle vectors, pelvis sensor frame, m.
        s2j: the segment-to-joint model used for the positions (M1 = the calibration).
        timings_s: wall time of each stage, s.
        used_mag: whether the magnetometer was fused.
        filter_name: the orientation filter used.
        calibration_reused: the joint calibration came from an earlier trial.
        magnetometer_note: why the magnetometer was not fused, or ``""``.
        quat_smoothed_wxyz: ``{sensor: (N, 4)}`` the same filters run forward and backward
            (inclination of both passes, heading of the forward one;
            :func:`~lowerlimb.orientation.estimate_orientation`'s ``smooth``), or ``None``
            (``smooth_orientation=False``: forward only).
        foot_gyro_cut: the foot gyro found cut at its range (:mod:`lowerlimb.io.saturation`), or
            ``None``.
        foot_acc_cut: the foot accelerometer found cut at its range, or ``None`` (the two-leg
            foot tracks restore its swings, :mod:`lowerlimb.gait.cut_force`).
        foot_gyro_restore: its swings restored between the foot's rests
            (:mod:`lowerlimb.gait.cut_rate`; ``trial`` holds the restored gyro), or ``None``
            (not cut, or ``GaitParams.cut_restore`` off).
        segment_gyro_restore: ``{"thigh"|"shank": …}`` the cut runs of those gyros restored
            (:mod:`lowerlimb.gait.cut_segment`; ``trial`` holds the restored gyros); empty when
            none is cut or ``GaitParams.cut_restore`` is off.
        gait: the leg's events, ankle track and gait parameters
            (:mod:`lowerlimb.gait.one_leg`), or ``None`` (no walking, or not asked for).
    """

    trial: ImuTrial
    calibration: LegCalibration
    quat_wxyz: dict[str, FloatArray]
    motion: SegmentMotion
    model: LegModel
    positions_m: FloatArray
    s2j: S2JModel
    timings_s: dict[str, float] = field(default_factory=dict)
    used_mag: bool = False
    filter_name: str = "mahony"
    calibration_reused: bool = False
    magnetometer_note: str = ""
    quat_smoothed_wxyz: dict[str, FloatArray] | None = None
    foot_gyro_cut: Saturation | None = None
    foot_gyro_restore: RateRestore | None = None
    foot_acc_cut: Saturation | None = None
    segment_gyro_restore: dict[str, SegmentRestore] = field(default_factory=dict)
    gait: LegGait | None = None

    @property
    def angles_rad(self) -> FloatArray:
        """(N, 9) ISB joint angles, rad."""
        return self.motion.angles_rad

    def to_dataframe(self) -> Any:
        """Angles (deg) and positions (m) as a ``pandas.DataFrame`` indexed by time (s).

        Columns as ``angles.csv`` then ``positions.csv``; ``df.attrs["units"]`` maps
        every column (and ``"time"``, the index) to its unit
        (:func:`lowerlimb.io.dataframe.motion_dataframe`).

        Raises:
            MissingDependencyError: pandas is not installed (``pip install 'lowerlimb[pandas]'``).
        """
        from .io.dataframe import motion_dataframe

        return motion_dataframe(self.trial.time_s, self.angles_rad, self.positions_m)

    def calibration_dict(self) -> dict[str, Any]:
        """calibration.json content: the docs/formats.md schema plus segment frames and diagnostics."""
        d = self.calibration.to_dict()
        d["filter"] = self.filter_name
        d["calibration_reused"] = self.calibration_reused
        d["magnetometer_used"] = self.used_mag
        if self.magnetometer_note:
            d["magnetometer_rejected"] = self.magnetometer_note
        d["segment_frames"] = {
            seg: {"quat_wxyz_segment_in_sensor": quat_from_matrix(R).tolist()}
            for seg, R in self.motion.frames.R_sensor_segment.items()
        }
        d["heading_correction_deg"] = {
            s: {
                "mean": float(np.rad2deg(np.mean(v))),
                "span": float(np.rad2deg(np.ptp(v))),
            }
            for s, v in self.motion.heading.delta_rad.items()
            if s != "pelvis"
        }
        if self.motion.heading.field_agreement:
            d["magnetic_field_agreement"] = dict(self.motion.heading.field_agreement)
        d["sensor_placements"] = self.model.calibration_dict()["sensors"]
        thigh, shank = segment_lengths(self.calibration)
        d["segment_lengths_m"] = {"thigh": float(thigh), "shank": float(shank)}
        d["timings_s"] = dict(self.timings_s)
        return d


@dataclass
class Orientations:
    """Stage 2's result: the filter orientations and how the magnetometer was used.

    Attributes:
        quat_wxyz: ``{sensor: (N, 4)}`` sensor → earth (ENU), before heading correction;
            the filters run forward in time.
        used_mag: whether the magnetometer was fused.
        magnetometer_note: why it was not fused (disturbed field), or ``""``.
        smoothed_wxyz: ``{sensor: (N, 4)}`` the forward estimate with the inclination of a
            forward and a backward pass, or ``None`` (not asked for).
    """

    quat_wxyz: dict[str, FloatArray]
    used_mag: bool
    magnetometer_note: str = ""
    smoothed_wxyz: dict[str, FloatArray] | None = None


def _warn_rest_gravity(trial: ImuTrial, still: StillPeriod, options: CalibrationOptions) -> None:
    """Warn of each accelerometer whose norm at the standing start is far from gravity."""
    n = still.samples(1.0)
    if options.rest_gravity_warn_mps2 is None or not n:
        return
    offsets = rest_gravity_offsets(trial.acc, slice(0, n))
    for note in rest_gravity_notes(offsets, options.rest_gravity_warn_mps2):
        warnings.warn(note, AccelerometerOffsetWarning, stacklevel=3)


def _calibrate_synchronised(
    trial: ImuTrial,
    method: str,
    still: StillPeriod,
    previous: LegCalibration | None,
    options: CalibrationOptions,
) -> tuple[ImuTrial, LegCalibration]:
    """Stage 1 with the clock search: the (re-timed) trial and its calibration.

    The clock search (:func:`~lowerlimb.calibration.clock_sync.synchronise`) calibrates
    again on each re-timed trial, and every calibration warns of its own fit: the
    warnings of the calibrations it replaced are dropped and those of the one kept are
    issued once (before, a re-timed trial repeated each excitation warning two or three
    times, with slightly different numbers).
    """

    def calibrate(t: ImuTrial, o: CalibrationOptions) -> tuple[LegCalibration, list[warnings.WarningMessage]]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            cal = calibrate_joints(t, method, still, previous, o)
        return cal, list(caught)

    calib, kept = calibrate(trial, options)
    if previous is None and options.clock_sync:
        # the clock search compares fits in the coherent band: widened caps let a thigh–shank
        # offset bend the knee centre until its lag explains too little (seven-IMU simulator,
        # σ 10 ms clocks: knee pairs left 11–28 ms off); the leg's band is chosen again after
        calib, kept, trial, offsets = _search_clocks(trial, calib, kept, calibrate, options)
        calib = replace(calib, clock_offsets=offsets.to_dict())
    clock_record = calib.clock_offsets
    trial, calib, kept = _untwisted(trial, calib, kept, calibrate, still, previous, options)
    # the untwisted trial's fit is a new calibration: it keeps the clock search's record (the
    # trial it fits is the re-timed one), which calibration.json's clock_offsets reports
    calib = replace(calib, clock_offsets=clock_record)
    for w in kept:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return trial, calib


_Calibrate = Callable[[ImuTrial, CalibrationOptions], tuple[LegCalibration, list[warnings.WarningMessage]]]


def _untwisted(
    trial: ImuTrial,
    calib: LegCalibration,
    kept: list[warnings.WarningMessage],
    calibrate: _Calibrate,
    still: StillPeriod,
    previous: LegCalibration | None,
    options: CalibrationOptions,
) -> tuple[ImuTrial, LegCalibration, list[warnings.WarningMessage]]:
    """Stage 1b: the thigh sensor's twist with the thigh's flexion undone (``options.thigh_twist``).

    A reused calibration's twist is applied as recorded; otherwise the twist is estimated
    (:func:`~lowerlimb.calibration.thigh_twist.estimate_thigh_twist`, its trial fits without
    the probes) and the untwisted trial calibrated again, whose warnings replace ``kept``.
    """
    n = still.samples(options.still_min_s)
    if previous is not None:
        if previous.thigh_twist is None:
            if options.thigh_twist:
                raise InputError(
                    "the thigh twist is found while calibrating and the reused calibration records none: "
                    "calibrate once with --thigh-twist (its calibration.json keeps the twist, and a reuse "
                    "re-applies it), or drop --thigh-twist"
                )
            return trial, calib, kept
        return (
            untwist_trial(trial, previous.thigh_twist, n),
            replace(calib, thigh_twist=previous.thigh_twist),
            kept,
        )
    if not options.thigh_twist:
        return trial, calib, kept
    quick = replace(options, cutoff_probe=False, split_half_probe=False)
    twist = estimate_thigh_twist(trial, calib, lambda t: calibrate(t, quick)[0], n, options)
    if twist is None:
        return trial, calib, kept
    trial = untwist_trial(trial, twist, n)
    calib, kept = calibrate(trial, options)
    twist = replace(twist, mismatch_after_deg=standing_mismatch_deg(calib, trial, n))
    if not twist.confirmed(options.thigh_twist_min_evidence):
        warnings.warn(unconfirmed_message(twist), ThighTwistWarning, stacklevel=3)
    return trial, replace(calib, thigh_twist=twist), kept


def _search_clocks(
    trial: ImuTrial,
    calib: LegCalibration,
    kept: list[warnings.WarningMessage],
    calibrate: _Calibrate,
    options: CalibrationOptions,
) -> tuple[LegCalibration, list[warnings.WarningMessage], ImuTrial, ClockOffsets]:
    """The clock search on coherent-band fits; the kept calibration and its warnings, the trial, the record.

    It starts from the leg's coherent-band fit (``LegCalibration.coherent_fit`` beside a
    widened one) and fits each re-timed trial in that band (without the cut-off and
    split-half probes and the sensor-order check, which change no estimate); when the search
    re-times the trial, the re-timed trial is fitted with ``options`` (its band chosen
    again), else the first fit stays.
    """
    # the search reads only the centres and axes: the probes (records) and the sensor-order
    # check (done on the first fit) are left out
    coherent = replace(
        options, fit_band_factor=1.0, cutoff_probe=False, split_half_probe=False, check_sensor_order=False
    )
    start = calib.coherent_fit if calib.coherent_fit is not None else calib
    retimed, _, offsets = synchronise(trial, start, lambda t: calibrate(t, coherent)[0], options)
    if not offsets.applied:
        return calib, kept, trial, offsets
    calib, kept = calibrate(retimed, options)
    return calib, kept, retimed, offsets


def calibrate_joints(
    trial: ImuTrial,
    method: str,
    still: StillPeriod,
    previous: LegCalibration | None = None,
    options: CalibrationOptions | None = None,
) -> LegCalibration:
    """Stage 1: calibrate the joints on this trial, or reuse ``previous`` with this trial's gyro bias.

    Args:
        trial: the trial.
        method: joint-constraint solver.
        still: the trial's still start (:meth:`ImuTrial.still_period`).
        previous: a calibration of the same sensor placements to reuse.
        options: calibration options (defaults: :class:`CalibrationOptions`).

    Raises:
        InputError: ``previous`` is of the other leg; swapped sensor columns.
    """
    if previous is None:
        return calibrate_leg(trial, method=method, options=options, still=still)
    if previous.side != trial.side:
        raise InputError(
            f"the calibration is of the {previous.side} leg but the trial is the {trial.side} "
            f"leg; pass --side {previous.side} or another calibration"
        )
    n_still = still.samples()
    opts = options or CalibrationOptions()
    n_end = still.bias_end(opts.still_min_s, opts.still_end_min_s)
    return replace(
        previous,
        runtime_s=0.0,
        gyro_bias={s: gyro_bias(trial.gyr[s], n_still, still.quiet, n_end) for s in SENSORS},
        still_s=n_still / trial.rate_hz,
        clock_offsets={},  # the earlier trial's clocks say nothing of this one's; not searched
    )


def estimate_orientations(
    trial: ImuTrial,
    filter_name: str,
    *,
    use_mag: bool,
    reference: slice | None,
    gyro_bias: dict[str, FloatArray] | None = None,
    smooth: bool = True,
) -> Orientations:
    """Stage 2: one orientation filter per sensor; the magnetometer only when its field is usable.

    ``reference`` are the standing samples on which the sensors' magnetic dips are compared
    (``None``: the trial does not start standing, and no dip is compared: from samples in
    motion the accelerometer's "up" is off, and a walk cut mid-stride was said to have a
    disturbed field). ``gyro_bias`` (``{sensor: (3,)}`` rad/s), when given, is subtracted
    and the filters estimate none of their own: a trial that ends still but does not start
    still (the filters find a bias only in a still start). ``smooth`` also gives each
    sensor's estimate with the inclination of a forward and a backward pass
    (``Orientations.smoothed_wxyz``).

    Warns:
        MagneticDisturbanceWarning: the field looks disturbed; the filters run 6-axis.
    """
    mag = trial.mag if (use_mag and trial.mag is not None and filter_name in MAG_FILTERS) else None
    mag_check = check_magnetic_field(trial, reference) if mag is not None else None
    if mag_check is not None and not mag_check.usable:
        warnings.warn(
            f"the magnetometer looks disturbed ({mag_check.reason}); fusing gyro and accelerometer "
            f"only (the joints keep the headings consistent); pass --no-mag to silence this",
            MagneticDisturbanceWarning,
            stacklevel=3,
        )
        mag = None

    def run(s: str) -> tuple[FloatArray, FloatArray]:
        gyr_s = trial.gyr[s] if gyro_bias is None else trial.gyr[s] - gyro_bias[s]
        mag_s = None if mag is None else mag[s]
        return estimate_orientation_passes(
            gyr_s,
            trial.acc[s],
            mag_s,
            rate_hz=trial.rate_hz,
            method=filter_name,
            remove_bias=gyro_bias is None,
            smooth=smooth,
        )

    passes = {s: run(s) for s in SENSORS}
    quats = {s: p[0] for s, p in passes.items()}
    smoothed = {s: p[1] for s, p in passes.items()} if smooth else None
    return Orientations(quats, mag is not None, "" if mag_check is None else mag_check.reason, smoothed)


def build_model(
    calibration: LegCalibration,
    motion: SegmentMotion,
    *,
    height_m: float,
    mass_kg: float,
    s2j: S2JModel | None = None,
    positions: bool = True,
) -> tuple[LegModel, FloatArray, S2JModel]:
    """Stage 4: the calibrated leg, its (N, 6) positions (m) and the S2J model they used (M1 by default).

    ``positions=False`` skips the forward kinematics of every sample: the positions are
    then an empty (0, 6) array.
    """
    model = LegModel(calibrated_geometry(calibration, motion.frames, height_m=height_m, mass_kg=mass_kg))
    own = s2j is None
    if s2j is None:
        s2j = S2JModel("M1", constant_s2j_from_calibration(calibration))
    if not positions:
        return model, np.zeros((0, 6)), s2j
    if own:  # this calibration's constant vectors are the model's own placements
        return model, chain_positions(model, motion.angles_rad), s2j
    return model, chain_positions(model, motion.angles_rad, s2j.predict(motion.angles_rad)), s2j


def _axial_witnesses(
    trial: ImuTrial, still: StillPeriod, calib: LegCalibration, reused: bool
) -> dict[tuple[str, str], float]:
    """The knee's and ankle's axial-acceleration correlations (:mod:`~lowerlimb.calibration.axial_sign`).

    The knee's comes from this trial's calibration (its accelerometer sign test), when its
    gyros fixed the axes' direction; the ankle's is measured here. NaN: no verdict.
    """
    knee = calib.knee.axis
    clear = not reused and gyro_sign_is_clear(knee.sign_coherence)
    ankle = axial_sign_correlation(trial.acc, trial.gyr, trial.rate_hz, "shank", "foot", still=still)
    knee_r = knee.acc_sign_correlation if clear else float("nan")
    return {("thigh", "shank"): knee_r, ("shank", "foot"): ankle}


class _Stopwatch:
    """Wall time of each stage, optionally printed as one line per stage on stderr."""

    def __init__(self, progress: bool) -> None:
        self.progress = progress
        self.timings_s: dict[str, float] = {}
        self._t0 = time.perf_counter()

    def start(self) -> None:
        self._t0 = time.perf_counter()

    def stop(self, name: str, note: str = "") -> None:
        """End a stage; print its time, or ``note`` instead (a stage that was skipped)."""
        self.timings_s[name] = time.perf_counter() - self._t0
        if self.progress:
            shown = note or f"{self.timings_s[name]:6.2f} s"
            print(f"  {name:<22s} {shown}", file=sys.stderr)


def _restored_foot_gyro(
    trial: ImuTrial, found: list[Saturation], params: GaitParams
) -> tuple[ImuTrial, RateRestore | None]:
    """The trial with a cut foot gyro's swings restored between its rests (:mod:`.gait.cut_rate`)."""
    cut = next((s for s in found if s.sensor == "foot" and s.signal == "gyr"), None)
    if cut is None or not params.cut_restore:
        return trial, None
    gyr, acc = trial.gyr["foot"], trial.acc["foot"]
    rests = detect_stationary(gyr, acc, trial.rate_hz, params)
    restored = restore_cut_gyro(gyr, acc, trial.rate_hz, cut.axes, rests, params)
    return replace(trial, gyr=trial.gyr | {"foot": restored.gyr_rps}), restored


#: A segment's joints: (joint, the segment's end of it, the neighbour sensor).
_SEGMENT_JOINTS = {
    "thigh": (("hip", "child", "pelvis"), ("knee", "parent", "shank")),
    "shank": (("knee", "child", "thigh"), ("ankle", "parent", "foot")),
}


def _restored_segment_gyros(
    trial: ImuTrial, calib: LegCalibration, found: list[Saturation], params: GaitParams
) -> tuple[ImuTrial, dict[str, SegmentRestore]]:
    """The trial with cut thigh and shank gyros restored run by run (:mod:`.gait.cut_segment`)."""
    cut = {s.sensor: s for s in found if s.signal == "gyr" and s.sensor in _SEGMENT_JOINTS}
    if not cut or not params.cut_restore:
        return trial, {}
    n = trial.time_s.shape[0]
    acc_cut = {s.sensor: s.at_limit for s in found if s.signal == "acc"}
    no_cut = np.zeros(n, dtype=bool)
    gyr = dict(trial.gyr)
    out: dict[str, SegmentRestore] = {}
    for sensor in ("shank", "thigh"):
        if sensor not in cut:
            continue
        links = []
        for joint, end, other in _SEGMENT_JOINTS[sensor] if params.cut_segment_fit else ():
            fit = getattr(calib, joint)
            there = "child" if end == "parent" else "parent"
            here_c, there_c = (np.asarray(getattr(fit, f"center_in_{e}_sensor"), float) for e in (end, there))
            # a cut accelerometer says nothing (a neighbour's cut gyro is taken as restored)
            unusable = acc_cut.get(sensor, no_cut) | acc_cut.get(other, no_cut)
            links.append(JointLink(here_c, there_c, trial.acc[other], gyr[other], unusable))
        restored = restore_cut_segment_gyro(
            gyr[sensor], trial.acc[sensor], trial.rate_hz, cut[sensor].axes, links, params
        )
        gyr[sensor], out[sensor] = restored.gyr_rps, restored
    return replace(trial, gyr=gyr), out


def process_trial(
    trial: ImuTrial,
    *,
    method: str = "casadi",
    filter_name: str = "mahony",
    height_m: float = 1.75,
    mass_kg: float = 75.0,
    use_mag: bool = True,
    s2j: S2JModel | None = None,
    calibration: LegCalibration | None = None,
    progress: bool = False,
    calibration_options: CalibrationOptions | None = None,
    side_check: bool = True,
    positions: bool = True,
    smooth_orientation: bool = True,
    gait_params: GaitParams | None = None,
    leg_gait: bool = True,
) -> TrialResult:
    """Calibrate a trial and compute its joint angles and positions.

    Args:
        trial: a validated four-IMU trial.
        method: joint-constraint solver, one of :data:`lowerlimb.methods.CALIBRATION_METHODS`.
        filter_name: orientation filter, one of :data:`lowerlimb.methods.ORIENTATION_FILTERS`.
        height_m: subject stature for the URDF inertias, m.
        mass_kg: subject mass for the URDF inertias, kg.
        use_mag: fuse the magnetometer when the trial has one.
        s2j: a fitted time-varying S2J model (Lee & Lee 2022, M2/M3) of these
            sensor placements; default: constant vectors from this calibration (M1).
        calibration: reuse a joint-constraint calibration of the same sensor
            placements (e.g. from a walk or the "mixed" motion) instead of
            calibrating this trial; its gyro bias is re-measured on this trial.
        progress: print one line per stage on stderr.
        calibration_options: joint-calibration options (e.g. ``check_sensor_order``);
            their ``prior_stature_m`` is set to ``height_m``.
        side_check: refuse a trial whose calibrated hip lies on the other side of the
            pelvis sensor (:func:`~lowerlimb.calibration.plausibility.check_side`); made
            only when the trial starts standing (the pelvis frame's "right" comes from it).
        positions: compute the forward kinematics of every sample; ``False`` leaves
            ``positions_m`` an empty (0, 6) array, for a caller that recomputes the chain
            (the two-leg pipeline's one-pelvis stage).
        smooth_orientation: take each sensor's inclination from a forward and a backward
            pass of its filter (offline; the headings and their joint corrections stay the
            forward pass's; docs/methods.md); ``False``: forward only, as in real time.
        gait_params: the foot's rests and what a foot gyro cut at its range gets back between
            them (``cut_restore``, ``cut_rate_*``; :mod:`lowerlimb.gait.cut_rate`); defaults:
            :class:`~lowerlimb.gait.GaitParams`.
        leg_gait: find the leg's gait events and parameters when it walks
            (:mod:`lowerlimb.gait.one_leg`, ``TrialResult.gait``); the two-leg pipeline finds
            both legs' together instead.

    Raises:
        InputError: a calibration of the other leg, swapped sensor columns
            (``SensorOrderError``), the wrong side (``WrongSideError``), or bad options.

    Warns:
        ImplausibleAnglesWarning: a joint angle's median while the leg moves lies beyond
            what a leg holds (:mod:`lowerlimb.segments.angle_range`).
        CalibrationFallbackWarning: an implausible thigh or shank length was replaced
            by the anthropometric template (:mod:`lowerlimb.model.fallback`).
        SaturationWarning: a sensor's accelerometer or gyro is cut at its range
            (:mod:`lowerlimb.io.saturation`).
        HeldSamplesWarning: a sensor's readings repeat the row before while it moves: a
            lower rate held to the table's (:mod:`lowerlimb.io.held_samples`).
    """
    clock = _Stopwatch(progress)
    found = trial_saturation(trial.acc, trial.gyr)
    warn_saturation(found)
    warn_held_samples(trial.acc, trial.gyr, trial.rate_hz)
    still = trial.still_period()  # detected once, handed on
    reference = trial.reference_samples(still)

    clock.start()
    # the subject's stature scales the anthropometric prior of the calibration
    cal_options = replace(calibration_options or CalibrationOptions(), prior_stature_m=height_m)
    _warn_rest_gravity(trial, still, cal_options)
    trial, calib = _calibrate_synchronised(trial, method, still, calibration, cal_options)
    # after the calibration, which leaves the cut samples out of its centre fits instead; found
    # again, as the clock search may have re-timed the sensors
    found = trial_saturation(trial.acc, trial.gyr) if found else []
    gp = gait_params or GaitParams()
    trial, restore = _restored_foot_gyro(trial, found, gp)
    trial, segment_restore = _restored_segment_gyros(trial, calib, found, gp)
    foot_cut = next((s for s in found if s.sensor == "foot" and s.signal == "gyr"), None)
    foot_acc_cut = next((s for s in found if s.sensor == "foot" and s.signal == "acc"), None)
    up = {s: trial.acc[s][reference].mean(axis=0) for s in ("thigh", "shank")}
    calib = with_plausible_lengths(calib, up, height_m=height_m)
    clock.stop("joint calibration", "" if calibration is None else "reused, not estimated")

    clock.start()
    standing = reference if trial.standing_samples(1.0, still) else None
    # a trial that ends still but does not start still: the filters take the end's bias
    from_end = still.bias_end(cal_options.still_min_s, cal_options.still_end_min_s)
    end_bias = calib.gyro_bias if from_end else None
    orientations = estimate_orientations(
        trial, filter_name, use_mag=use_mag, reference=standing, gyro_bias=end_bias, smooth=smooth_orientation
    )
    clock.stop("orientation filters")

    gyr = {s: trial.gyr[s] - calib.gyro_bias.get(s, np.zeros(3)) for s in SENSORS}
    if cal_options.check_signs:
        signs = chain_sign_check(orientations.quat_wxyz, gyr, _CHAIN_EDGES, trial.rate_hz)
        if "" in signs.decided_by[1:]:  # the knee or ankle left open: hear the axial witness (0.4 s)
            axial = _axial_witnesses(trial, still, calib, calibration is not None)
            signs = chain_sign_check(orientations.quat_wxyz, gyr, _CHAIN_EDGES, trial.rate_hz, axial=axial)
        if signs.inverted and signs.firm:
            raise InvertedSignError(signs)
        if signs.inverted:
            warnings.warn(InvertedSignWarning(signs), stacklevel=2)

    clock.start()
    motion = track_segments(
        orientations.quat_wxyz,
        trial.acc,
        gyr,
        calib,
        rate_hz=trial.rate_hz,
        reference=reference,
        side=trial.side,
        shared_heading=orientations.used_mag,
        quat_smoothed=orientations.smoothed_wxyz,
        mag=trial.mag if orientations.used_mag else None,
    )
    clock.stop("segment frames, angles")
    for message in implausible_angles(motion.angles_rad, gyr["shank"]):
        warnings.warn(message, ImplausibleAnglesWarning, stacklevel=2)

    clock.start()
    model, positions_m, s2j_used = build_model(
        calib, motion, height_m=height_m, mass_kg=mass_kg, s2j=s2j, positions=positions
    )
    clock.stop("forward kinematics")
    clock.start()
    gait = _leg_gait(trial, calib, motion, gyr, gp, foot_acc_cut) if leg_gait else None
    clock.stop("gait")
    moving_s = trial.duration_s - trial.standing_samples(1.0, still) / trial.rate_hz
    if side_check and trial.standing_samples(1.0, still) > 0 and moving_s >= SIDE_MIN_MOTION_S:
        # the pelvis frame's "right" comes from the standing reference: without one, no verdict;
        # a second of motion leaves the hip anywhere (a 2 s trial was called the other leg)
        g = model.geometry
        hip_ex = calib.hip.excitation
        check_side(
            trial.side,
            g.joint_origins["hip"][:3, 3] - g.sensor_placements["pelvis"][:3, 3],
            hip_std_m=hip_ex.weakest_std if hip_ex is not None else 0.0,
            pelvis_turn=pelvis_turn_side_cue(
                gyr["pelvis"],
                gyr["thigh"],
                calib.knee.axis_in_parent_sensor,
                trial.acc["pelvis"][reference].mean(axis=0),
                trial.rate_hz,
            ),
        )
    return TrialResult(
        trial,
        calib,
        orientations.quat_wxyz,
        motion,
        model,
        positions_m,
        s2j_used,
        clock.timings_s,
        orientations.used_mag,
        filter_name,
        calibration is not None,
        orientations.magnetometer_note,
        orientations.smoothed_wxyz,
        foot_cut,
        restore,
        foot_acc_cut,
        segment_restore,
        gait,
    )


def _leg_gait(
    trial: ImuTrial,
    calib: LegCalibration,
    motion: SegmentMotion,
    gyr: dict[str, FloatArray],
    params: GaitParams,
    foot_acc_cut: Saturation | None,
) -> LegGait | None:
    """The leg's gait from its bias-free shank and foot gyros and the calibrated foot orientation."""
    cut = foot_acc_cut if params.cut_restore else None
    return analyse_leg_gait(
        trial.side,
        trial.rate_hz,
        shank_gyr=gyr["shank"],
        foot_gyr=gyr["foot"],
        foot_acc=trial.acc["foot"],
        foot_quat_wxyz=motion.sensor_quat_wxyz["foot"],
        ankle_in_foot_m=calib.ankle.center_in_child_sensor,
        start_time_s=float(trial.time_s[0]),
        params=params,
        cut_axes=None if cut is None else cut.axes,
    )
