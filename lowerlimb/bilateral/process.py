"""Both legs of a seven-IMU trial: :func:`process_bilateral_trial` → :class:`BilateralResult`.

Each leg is the pelvis sensor with that side's thigh, shank and foot, run through the
single-leg stages of :func:`lowerlimb.pipeline.process_trial` unchanged. What the two
legs share:

- **one pelvis heading.** The pelvis orientation is the reference of each leg's
  heading correction (kept, never turned), and both legs fuse the magnetometer or
  both do not (it is checked on both legs first), so the pelvis quaternion is the same
  in the two legs; every segment of both legs is therefore in one earth frame, and
  ``left_foot_to_right_foot`` (the difference of the two legs' forward kinematics in the
  pelvis sensor frame) is consistent;
- **one pelvis** (:mod:`lowerlimb.bilateral.pelvis`): after the single-leg runs, the two
  hip centres are estimated jointly (mirror symmetry about one pelvis frame, de Leva's
  spacing, each hip's covariance); both legs' headings, frames, angles and forward
  kinematics are recomputed with them (``one_pelvis=False`` keeps each leg's own). Each
  leg's angles keep its own pelvis segment frame, so they are zero at the standing
  reference as for one leg (a shared frame for the angles made the simulated hip angles
  worse: rotation 10–12° RMSE against 2–3°); the shared frame is reported;
- **the two hips** (:mod:`lowerlimb.bilateral.hips`): their distance against de Leva's
  hip spacing and their sides, reported in ``calibration.json`` and warned about;
- **gait** (:mod:`lowerlimb.bilateral.gait`): events per foot and spatio-temporal
  parameters, the feet anchored to each other by the calibrated chain.
"""

from __future__ import annotations

import sys
import time
import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..calibration.options import CalibrationOptions
from ..calibration.plausibility import (
    PlausibilityParams,
    SensorOrderError,
    SideEvidenceWarning,
    WrongSideError,
    pelvis_turn_side_cue,
)
from ..conventions import SIDES, FloatArray
from ..errors import InputError
from ..gait import GaitParams
from ..io.bilateral_trial import BilateralTrial, with_file_names
from ..io.trial import StandingStartWarning
from ..orientation.magnetic import check_magnetic_field
from ..pipeline import MAG_FILTERS, MagneticDisturbanceWarning, TrialResult, build_model, process_trial
from ..segments.angle_range import ImplausibleAnglesWarning, implausible_angles
from ..segments.tracking import track_segments
from .gait import BilateralGait, analyse_gait
from .hips import HipCheck, HipParams, HipSpacingWarning, check_hips
from .leg_pairing import check_leg_pairing
from .leg_runner import LegWarning, recorded, run_two_legs
from .pelvis import OppositeKneesError, OppositeKneesWarning, PelvisParams, SharedPelvis, shared_pelvis

__all__ = ["BilateralResult", "BilateralSideError", "process_bilateral_trial"]


class BilateralSideError(WrongSideError):
    """One side's sensors look like the other leg: the left_* and right_* columns are swapped."""

    def __init__(self, side: str, lateral_m: float) -> None:
        super().__init__(side, lateral_m)
        other = "right" if side == "left" else "left"
        where = "right" if lateral_m > 0 else "left"
        self.args = (
            f"the {side}_* sensors look like the {other} leg: the calibrated {side} hip centre lies "
            f"{abs(lateral_m) * 100:.1f} cm to the {where} of the pelvis sensor; "
            f"exchange the left_* and right_* columns (or pass --no-side-check if the pelvis sensor "
            f"is not on the sacrum)",
        )


@dataclass
class BilateralResult:
    """Everything :func:`process_bilateral_trial` computes.

    Attributes:
        trial: the input trial.
        legs: ``{"left": …, "right": …}`` each leg's single-leg result (pelvis + that side).
        hips: the two hip centres checked together.
        gait: events, foot trajectories and gait parameters.
        timings_s: wall time of each stage, s.
        pelvis: the one pelvis of both legs (frame and joint hip centres), or ``None``
            when the legs kept their own (``shared_pelvis=False``).
    """

    trial: BilateralTrial
    legs: dict[str, TrialResult]
    hips: HipCheck
    gait: BilateralGait
    timings_s: dict[str, float] = field(default_factory=dict)
    pelvis: SharedPelvis | None = None

    @property
    def angles_rad(self) -> FloatArray:
        """(N, 18) ISB joint angles, left then right, rad (two-leg angles.csv order)."""
        return np.hstack([self.legs[s].angles_rad for s in SIDES])

    @property
    def left_foot_to_right_foot_m(self) -> FloatArray:
        """(N, 3) right foot sensor minus left foot sensor, pelvis sensor frame, m."""
        return self.legs["right"].positions_m[:, :3] - self.legs["left"].positions_m[:, :3]

    @property
    def positions_m(self) -> FloatArray:
        """(N, 15) two-leg positions.csv columns (pelvis sensor frame, m)."""
        L, R = self.legs["left"].positions_m, self.legs["right"].positions_m
        return np.hstack([L[:, :3], R[:, :3], L[:, 3:6], R[:, 3:6], self.left_foot_to_right_foot_m])

    @property
    def runtime_s(self) -> float:
        """In-process wall time of the joint-constraint calibration of both legs, s."""
        return float(sum(r.calibration.runtime_s for r in self.legs.values()))

    def calibration_dict(self) -> dict[str, Any]:
        """The two-leg calibration.json content (docs/formats.md, "Two legs")."""
        legs = {}
        for side, r in self.legs.items():
            d = r.calibration_dict()
            d.pop("format", None)
            legs[side] = d
        left = self.legs["left"]
        return {
            "format": "lowerlimb-calibration/1",
            "layout": "two_legs",
            "method": legs["left"].get("method"),
            "filter": left.filter_name,
            "legs": legs,
            "runtime_s": self.runtime_s,
            "hips": self.hips.to_dict(),
            "pelvis": None if self.pelvis is None else self.pelvis.to_dict(),
            "shared_pelvis_heading": bool(
                np.array_equal(
                    left.motion.sensor_quat_wxyz["pelvis"],
                    self.legs["right"].motion.sensor_quat_wxyz["pelvis"],
                )
            ),
            "magnetometer_used": left.used_mag,
            "timings_s": dict(self.timings_s),
        }


def _use_mag(trial: BilateralTrial, filter_name: str, use_mag: bool) -> bool:
    """Fuse the magnetometer in both legs or in neither: True only when both legs' fields look usable.

    Warns:
        MagneticDisturbanceWarning: a leg's field looks disturbed; both legs run 6-axis.
    """
    if not use_mag or trial.mag is None or filter_name not in MAG_FILTERS:
        return False
    for side in SIDES:
        leg = trial.leg(side)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            still = leg.still_period()
            standing = leg.reference_samples(still) if leg.standing_samples(1.0, still) else None
            check = check_magnetic_field(leg, standing)
        if not check.usable:
            warnings.warn(
                f"the magnetometer looks disturbed ({check.reason}, {side} leg); fusing gyro and "
                f"accelerometer only in both legs (the joints keep the headings consistent); pass "
                f"--no-mag to silence this",
                MagneticDisturbanceWarning,
                stacklevel=3,
            )
            return False
    return True


def _pelvis_turn(leg: TrialResult) -> float:
    """The leg's pelvis-turn side cue (:func:`~lowerlimb.calibration.plausibility.pelvis_turn_side_cue`)."""
    t, cal = leg.trial, leg.calibration
    gyr = {s: t.gyr[s] - cal.gyro_bias.get(s, np.zeros(3)) for s in ("pelvis", "thigh")}
    reference = t.reference_samples(t.still_period())
    return pelvis_turn_side_cue(
        gyr["pelvis"],
        gyr["thigh"],
        cal.knee.axis_in_parent_sensor,
        t.acc["pelvis"][reference].mean(axis=0),
        t.rate_hz,
    )


def _check_pair_sides(
    legs: dict[str, TrialResult],
    height_m: float,
    hip_params: HipParams | None,
    pelvis_params: PelvisParams | None = None,
) -> None:
    """Refuse swapped ``left_*``/``right_*`` columns: the right hip must lie right of the left one.

    Each leg's pelvis frame points right whatever its label (the knee axis is signed by
    flexion), so with the columns swapped the "right" hip comes out on the left. The pair
    is more robust than one hip against the sacral sensor: a straight walk leaves
    each hip centre uncertain by centimetres (mostly along the same directions in both
    legs), and a pelvis sensor off the midline shifts both hips alike. The verdict needs
    a standing start and a separation of at least ``side_min_sigmas`` combined standard
    deviations of the two hip centres (reported spread plus
    :attr:`PelvisParams.model_std_m` each), and each hip on the other side of the sacral
    sensor as well.

    The hip centres are the least determined quantities of a walk (soft tissue and impacts
    move them by decimetres), so, as for one leg
    (:func:`~lowerlimb.calibration.plausibility.check_side`), the verdict hears a witness
    that no joint centre enters: the pelvis turns with each swinging leg
    (:func:`~lowerlimb.calibration.plausibility.pelvis_turn_side_cue`, < 0 for a left thigh,
    > 0 for a right one). When both legs' cues confirm their labels by at least
    ``side_cue_min_corr``, swapped-looking hips give a :class:`SideEvidenceWarning`;
    swapped columns turn both cues the other way, and the hips still refuse them.

    Raises:
        BilateralSideError: the hips are swapped and the pelvis's turning does not confirm the sides.

    Warns:
        SideEvidenceWarning: the hips look swapped, the pelvis's turning confirms the sides given.
    """
    trial = legs["left"].trial
    if trial.standing_samples(1.0, trial.still_period()) == 0:
        return
    pair = check_hips(
        legs["left"].calibration,
        legs["right"].calibration,
        {s: r.motion.frames.R_sensor_segment["pelvis"] for s, r in legs.items()},
        height_m=height_m,
        params=hip_params,
    )
    p = PlausibilityParams()
    stds = [legs[s].calibration.hip.excitation for s in SIDES]
    # the reported spread understates a hip centre's error several-fold on walking (the
    # pelvis barely rotates about horizontal axes): add the model error of each hip
    model = (pelvis_params or PelvisParams()).model_std_m
    sigma = float(np.sqrt(sum((e.weakest_std if e is not None else 0.0) ** 2 + model**2 for e in stds)))
    # a swap puts each hip on the other side of the sacral sensor too; one hip alone on the
    # wrong side is a failed hip calibration (e.g. stuck at a bound), not a swap
    lateral = {
        s: float(
            legs[s].model.geometry.joint_origins["hip"][2, 3]
            - legs[s].model.geometry.sensor_placements["pelvis"][2, 3]
        )
        for s in SIDES
    }
    both_flipped = lateral["left"] > 0.0 and lateral["right"] < 0.0
    if (
        both_flipped
        and pair.lateral_m < -p.side_min_offset_m
        and abs(pair.lateral_m) >= p.side_min_sigmas * sigma
    ):
        cue = {s: _pelvis_turn(legs[s]) for s in SIDES}
        if cue["left"] <= -p.side_cue_min_corr and cue["right"] >= p.side_cue_min_corr:
            warnings.warn(
                SideEvidenceWarning(
                    f"the calibrated right hip centre lies {abs(pair.lateral_m) * 100:.1f} cm to the left "
                    f"of the left one, as with the left_* and right_* columns swapped, but the pelvis turns "
                    f"with each leg's swing as with the sides given (correlation {cue['left']:+.2f} left, "
                    f"{cue['right']:+.2f} right); kept the sides: the hip centres are unreliable here"
                ),
                stacklevel=3,
            )
            return
        err = BilateralSideError("left", -pair.lateral_m)
        err.args = (
            f"the left_* and right_* sensors look swapped: the calibrated right hip centre lies "
            f"{abs(pair.lateral_m) * 100:.1f} cm to the left of the left one; exchange the left_* and "
            f"right_* columns (an accelerometer sign that reads -9.81 along up at rest mirrors the centres "
            f"too: negate the acc columns; or pass --no-side-check if the pelvis sensor moved during the "
            f"standing start)",
        )
        raise err


def _process_leg(
    trial: BilateralTrial, side: str, note: str = "", **kwargs: Any
) -> tuple[TrialResult, list[LegWarning]]:
    """One leg through the single-leg pipeline, with the warnings it raised (to re-issue per side).

    With ``progress``, its stage lines follow a line naming the leg (and ``note``).
    """
    if kwargs.get("progress"):
        print(f"  {side} leg{note}:", file=sys.stderr)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = process_trial(trial.leg(side), leg_gait=False, **kwargs)
        return result, recorded(caught)
    except WrongSideError as e:
        raise BilateralSideError(side, e.lateral_m) from None
    except SensorOrderError as e:
        raise with_file_names(e, side) from None
    except InputError as e:
        raise InputError(f"{side} leg (pelvis and {side}_*): {e}") from None


def _leg_warnings(caught: dict[str, list[LegWarning]]) -> list[tuple[str, type[Warning]]]:
    """Each leg's warnings once, naming the leg; one both legs raised alike, once without a side."""
    both = {(str(w.message), w.category) for w in caught["left"]}
    both &= {(str(w.message), w.category) for w in caught["right"]}
    out: list[tuple[str, type[Warning]]] = []
    for side in SIDES:
        for w in caught[side]:
            key = (str(w.message), w.category)
            if key not in both:
                out.append((f"{side} leg: {w.message}", w.category))
            elif side == SIDES[0]:
                out.append(key)
    return out


def _one_pelvis(
    legs: dict[str, TrialResult], *, height_m: float, mass_kg: float, params: PelvisParams | None
) -> tuple[dict[str, TrialResult], SharedPelvis]:
    """Both legs re-tracked with the jointly estimated hip centres (one pelvis).

    The joint calibrations are kept except the hip centre in the pelvis sensor; the
    orientation filters are not re-run. Each leg's headings, segment frames, angles and
    forward kinematics are recomputed (:func:`~lowerlimb.segments.tracking.track_segments`,
    :func:`~lowerlimb.pipeline.build_model`).
    """
    trial = legs["left"].trial
    reference = trial.reference_samples(trial.still_period())
    pelvis = shared_pelvis(
        {s: r.calibration.hip.center_in_parent_sensor for s, r in legs.items()},
        {s: r.calibration.hip.center_std_in_parent_sensor for s, r in legs.items()},
        {s: r.motion.frames.R_sensor_segment["pelvis"][:, 2] for s, r in legs.items()},
        trial.acc["pelvis"][reference].mean(axis=0),
        height_m=height_m,
        params=params,
    )
    out = {}
    for side, r in legs.items():
        cal = r.calibration
        cal = replace(
            cal, hip=replace(cal.hip, center_in_parent_sensor=pelvis.hips.center_in_pelvis_sensor_m[side])
        )
        t = r.trial
        gyr = {s: t.gyr[s] - cal.gyro_bias.get(s, np.zeros(3)) for s in t.gyr}
        motion = track_segments(
            r.quat_wxyz,
            t.acc,
            gyr,
            cal,
            rate_hz=t.rate_hz,
            reference=t.reference_samples(t.still_period()),
            side=t.side,
            shared_heading=r.used_mag,
            quat_smoothed=r.quat_smoothed_wxyz,
            mag=t.mag if r.used_mag else None,
        )
        model, positions, s2j = build_model(cal, motion, height_m=height_m, mass_kg=mass_kg)
        out[side] = replace(r, calibration=cal, motion=motion, model=model, positions_m=positions, s2j=s2j)
    return out, pelvis


def _own_pelvises(legs: dict[str, TrialResult], *, height_m: float, mass_kg: float) -> dict[str, TrialResult]:
    """Each leg with its own pelvis: the forward kinematics the one-pelvis stage would have redone."""
    out = {}
    for side, r in legs.items():
        model, positions, s2j = build_model(r.calibration, r.motion, height_m=height_m, mass_kg=mass_kg)
        out[side] = replace(r, model=model, positions_m=positions, s2j=s2j)
    return out


def process_bilateral_trial(
    trial: BilateralTrial,
    *,
    method: str = "casadi",
    filter_name: str = "mahony",
    height_m: float = 1.75,
    mass_kg: float = 75.0,
    use_mag: bool = True,
    progress: bool = False,
    smooth_orientation: bool = True,
    calibration_options: CalibrationOptions | None = None,
    side_check: bool = True,
    hip_params: HipParams | None = None,
    gait_params: GaitParams | None = None,
    one_pelvis: bool = True,
    pelvis_params: PelvisParams | None = None,
    parallel_legs: bool = True,
) -> BilateralResult:
    """Calibrate both legs of a seven-IMU trial; angles, positions, hips and gait.

    Args:
        trial: a validated two-leg trial.
        method: joint-constraint solver (:data:`lowerlimb.methods.CALIBRATION_METHODS`).
        filter_name: orientation filter (:data:`lowerlimb.methods.ORIENTATION_FILTERS`).
        height_m: subject stature (URDF inertias, de Leva hip spacing), m.
        mass_kg: subject mass (URDF inertias), kg.
        use_mag: fuse the magnetometer when both legs' fields look usable.
        progress: print one line per stage and leg on stderr.
        smooth_orientation: forward and backward orientation filters (``process_trial``).
        calibration_options: joint-calibration options, both legs.
        side_check: refuse a leg whose calibrated hip lies on the other side of the pelvis sensor.
        hip_params: thresholds of the two-hip check.
        gait_params: thresholds of the gait stages.
        one_pelvis: give both legs the jointly estimated hip centres of one pelvis
            (:mod:`lowerlimb.bilateral.pelvis`); False keeps each leg's own (the single-leg
            results side by side).
        pelvis_params: uncertainties of the shared pelvis.
        parallel_legs: run the right leg in a forked child process while this one runs the
            left (:mod:`lowerlimb.bilateral.leg_runner`; where that is not possible, or
            False, one after the other; the results are the same).

    Raises:
        InputError: swapped columns (``BilateralSideError``, ``SensorOrderError`` with the
            file's column names, :class:`~lowerlimb.bilateral.leg_pairing.CrossedLegsError` for one
            segment's sensors exchanged between the legs), or a leg's problem (prefixed with the leg).

    Warns:
        OppositeKneesWarning: the two knee axes point apart seen from the pelvis
            (:class:`~lowerlimb.bilateral.pelvis.OppositeKneesError`); each leg keeps its own
            pelvis, as with ``one_pelvis=False``.
        HipSpacingWarning: the two hip centres do not look like one pelvis.
        NoGaitWarning: the trial has no walking.
    """
    if (calibration_options or CalibrationOptions()).check_sensor_order:
        check_leg_pairing(trial)
    mag = _use_mag(trial, filter_name, use_mag)
    kwargs: dict[str, Any] = {
        "method": method,
        "filter_name": filter_name,
        "height_m": height_m,
        "mass_kg": mass_kg,
        "progress": progress,
        "smooth_orientation": smooth_orientation,
        "calibration_options": calibration_options,
        "side_check": False,  # two legs: the pair of hips decides (_check_pair_sides)
        "positions": not one_pelvis,  # the one-pelvis stage recomputes them
        "gait_params": gait_params,
    }
    t0 = time.perf_counter()
    both = run_two_legs(lambda side: _process_leg(trial, side, use_mag=mag, **kwargs), parallel_legs)
    legs = {side: both[side][0] for side in SIDES}
    caught = {side: both[side][1] for side in SIDES}
    if mag and not legs["left"].used_mag and legs["right"].used_mag:  # the left field was rejected
        again = " again, without the magnetometer (the left leg's field was disturbed)"
        legs["right"], caught["right"] = _process_leg(trial, "right", again, use_mag=False, **kwargs)
    if legs["left"].used_mag and not legs["right"].used_mag:  # the right field was rejected
        again = " again, without the magnetometer (the right leg's field was disturbed)"
        legs["left"], caught["left"] = _process_leg(trial, "left", again, use_mag=False, **kwargs)
    legs_wall_s = time.perf_counter() - t0
    # the angles are judged once the legs share their pelvis (below)
    caught = {s: [w for w in c if w.category is not ImplausibleAnglesWarning] for s, c in caught.items()}
    for message, category in _leg_warnings(caught):
        warnings.warn(message, category, stacklevel=2)
    timings: dict[str, float] = {}
    for side, r in legs.items():
        for k, v in r.timings_s.items():
            timings[f"{side}: {k}"] = v
    timings["both legs"] = legs_wall_s  # side by side: less than the sum of the two
    if side_check:
        _check_pair_sides(legs, height_m, hip_params, pelvis_params)
    pelvis = None
    if one_pelvis:
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", StandingStartWarning)  # said once above
                legs, pelvis = _one_pelvis(legs, height_m=height_m, mass_kg=mass_kg, params=pelvis_params)
        except OppositeKneesError as e:  # never worse than the two legs as one-leg trials
            warnings.warn(OppositeKneesWarning(e.angle_deg), stacklevel=2)
            legs = _own_pelvises(legs, height_m=height_m, mass_kg=mass_kg)
        timings["one pelvis"] = time.perf_counter() - t0
    for side, r in legs.items():
        for message in implausible_angles(r.angles_rad, r.trial.gyr["shank"]):
            warnings.warn(f"{side} leg: {message}", ImplausibleAnglesWarning, stacklevel=2)
    hips = check_hips(
        legs["left"].calibration,
        legs["right"].calibration,
        {s: r.motion.frames.R_sensor_segment["pelvis"] for s, r in legs.items()},
        height_m=height_m,
        params=hip_params,
    )
    if not hips.plausible:
        warnings.warn(
            f"the two hip centres do not look like one pelvis: {hips.reason}; check the sensor "
            f"placements and the --height",
            HipSpacingWarning,
            stacklevel=2,
        )
    gait = analyse_gait(legs, gait_params)
    return BilateralResult(trial, legs, hips, gait, timings, pelvis)
