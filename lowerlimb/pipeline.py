"""``lowerlimb calibrate``: trial → calibration → angles, positions, URDF, report.

:func:`process_trial` is the library form (no files); :func:`run_calibrate`
is the command: it validates everything first, computes everything, then
writes every output of DESIGN.md into the new directory at once (a staging
directory renamed into place), so a failure never leaves a partial DIR.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .calibrated_leg import calibrated_geometry, chain_positions
from .calibration import LegCalibration, calibrate_leg
from .conventions import SENSORS, FloatArray, quat_from_matrix
from .errors import InputError
from .leg_model import LegModel
from .magnetic import check_magnetic_field
from .motion import SegmentMotion, track_segments
from .orientation import estimate_orientation
from .output import write_angles_csv, write_positions_csv
from .s2j import S2JModel, constant_s2j_from_calibration
from .stillness import gyro_bias, initial_still_samples
from .trial import ImuTrial

#: Name of the S2J sidecar written beside the URDF.
S2J_SIDECAR = "s2j.json"

#: CLI method names → calibration methods.
CLI_METHODS = {"casadi": "casadi", "gn": "gn", "dwpso": "dwpso", "gwo": "gwo"}


class MagneticDisturbanceWarning(UserWarning):
    """The magnetometer was not fused because the field looks disturbed."""


#: Filters that use the magnetometer when the trial has one.
MAG_FILTERS = ("mahony", "ftecf", "madgwick", "quest_kf")


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

    @property
    def angles_rad(self) -> FloatArray:
        """(N, 9) ISB joint angles, rad."""
        return self.motion.angles_rad

    def calibration_dict(self) -> dict[str, Any]:
        """calibration.json content: the DESIGN.md schema plus segment frames and diagnostics."""
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
        d["sensor_placements"] = self.model.calibration_dict()["sensors"]
        d["timings_s"] = dict(self.timings_s)
        return d


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
) -> TrialResult:
    """Calibrate a trial and compute its joint angles and positions.

    Args:
        trial: a validated four-IMU trial.
        method: joint-constraint solver (``casadi``, ``gn``, ``dwpso``, ``gwo``…).
        filter_name: orientation filter (``mahony``, ``ftecf``, ``madgwick``, ``quest_kf``).
        height_m: subject stature for the URDF inertias, m.
        mass_kg: subject mass for the URDF inertias, kg.
        use_mag: fuse the magnetometer when the trial has one.
        s2j: a fitted time-varying S2J model (Lee & Lee 2022, M2/M3) of these
            sensor placements; default: constant vectors from this calibration (M1).
        calibration: reuse a joint-constraint calibration of the same sensor
            placements (e.g. from a walk or the "mixed" motion) instead of
            calibrating this trial; its gyro bias is re-measured on this trial.
        progress: print one line per stage on stderr.
    """
    timings: dict[str, float] = {}

    def step(name: str, t0: float) -> None:
        timings[name] = time.perf_counter() - t0
        if progress:
            print(f"  {name:<22s} {timings[name]:6.2f} s", file=sys.stderr)

    reference = trial.reference_samples()
    t0 = time.perf_counter()
    if calibration is None:
        calib = calibrate_leg(trial, method=method)
    else:
        if calibration.side != trial.side:
            raise InputError(
                f"the calibration is of the {calibration.side} leg but the trial is the {trial.side} "
                f"leg; pass --side {calibration.side} or another calibration"
            )
        n_still = initial_still_samples(
            [trial.gyr[s] for s in SENSORS], [trial.acc[s] for s in SENSORS], trial.rate_hz
        )
        calib = replace(
            calibration,
            runtime_s=0.0,
            gyro_bias={s: gyro_bias(trial.gyr[s], n_still) for s in SENSORS},
            still_s=n_still / trial.rate_hz,
        )
    step("joint calibration", t0)
    calib_dict = calib.to_dict()

    t0 = time.perf_counter()
    mag = trial.mag if (use_mag and trial.mag is not None and filter_name in MAG_FILTERS) else None
    mag_check = check_magnetic_field(trial, reference) if mag is not None else None
    if mag_check is not None and not mag_check.usable:
        warnings.warn(
            f"the magnetometer looks disturbed ({mag_check.reason}); fusing gyro and accelerometer "
            f"only (the joints keep the headings consistent); pass --no-mag to silence this",
            MagneticDisturbanceWarning,
            stacklevel=2,
        )
        mag = None
    quats = {
        s: estimate_orientation(
            trial.gyr[s],
            trial.acc[s],
            None if mag is None else mag[s],
            rate_hz=trial.rate_hz,
            method=filter_name,
        )
        for s in SENSORS
    }
    step("orientation filters", t0)

    t0 = time.perf_counter()
    gyr = {s: trial.gyr[s] - calib.gyro_bias.get(s, np.zeros(3)) for s in SENSORS}
    motion = track_segments(
        quats,
        trial.acc,
        gyr,
        calib_dict,
        rate_hz=trial.rate_hz,
        reference=reference,
        side=trial.side,
        shared_heading=mag is not None,
    )
    step("segment frames, angles", t0)

    t0 = time.perf_counter()
    model = LegModel(calibrated_geometry(calib_dict, motion.frames, height_m=height_m, mass_kg=mass_kg))
    if s2j is None:
        s2j = S2JModel("M1", constant_s2j_from_calibration(calib_dict))
        positions = chain_positions(model, motion.angles_rad)
    else:
        positions = chain_positions(model, motion.angles_rad, s2j.predict(motion.angles_rad))
    step("forward kinematics", t0)
    result = TrialResult(
        trial,
        calib,
        quats,
        motion,
        model,
        positions,
        s2j,
        timings,
        mag is not None,
        filter_name,
        calibration is not None,
    )
    result.magnetometer_note = "" if mag_check is None else mag_check.reason
    return result


def write_outputs(
    result: TrialResult,
    directory: Path,
    *,
    truth_angles_rad: FloatArray | None = None,
    truth_positions_m: FloatArray | None = None,
) -> None:
    """Write every DESIGN.md output of a processed trial into ``directory``.

    Args:
        result: the processed trial.
        directory: an existing, empty folder.
        truth_angles_rad: (N, 9) known angles (simulations) to overlay in the report.
        truth_positions_m: (N, 6) known positions to overlay in the report.
    """
    d = result.calibration_dict()
    d["urdf"] = "calibrated.urdf"
    d["s2j"] = S2J_SIDECAR
    (directory / "calibration.json").write_text(json.dumps(d, indent=2), encoding="utf-8")
    write_angles_csv(directory / "angles.csv", result.trial.time_s, result.angles_rad)
    write_positions_csv(directory / "positions.csv", result.trial.time_s, result.positions_m)
    (directory / S2J_SIDECAR).write_text(json.dumps(result.s2j.to_dict(), indent=1), encoding="utf-8")
    (directory / "calibrated.urdf").write_text(
        urdf_with_sidecar(result.model.to_urdf_string()), encoding="utf-8"
    )
    _write_report(result, directory, d, truth_angles_rad, truth_positions_m)


def urdf_with_sidecar(urdf: str) -> str:
    """Name the S2J sidecar in the URDF, as an XML comment right after the ``<robot>`` tag."""
    start = urdf.find("<robot")
    end = urdf.find(">", start)
    note = (
        f"<!-- lowerlimb: time-varying segment-to-joint model in {S2J_SIDECAR} (same folder); "
        f"load both with lowerlimb.pipeline.load_calibrated -->"
    )
    return urdf[: end + 1] + note + urdf[end + 1 :]


def load_calibrated(directory: str | Path) -> tuple[LegModel, S2JModel]:
    """Re-load a calibrated leg and its S2J model from a ``lowerlimb calibrate`` directory.

    Raises:
        InputError: when the directory lacks ``calibrated.urdf`` or ``s2j.json``.
    """
    d = Path(directory)
    for name in ("calibrated.urdf", S2J_SIDECAR):
        if not (d / name).is_file():
            raise InputError(f"{d} has no {name}; give an output directory of 'lowerlimb calibrate'")
    model = LegModel.from_urdf(d / "calibrated.urdf")
    s2j = S2JModel.from_dict(json.loads((d / S2J_SIDECAR).read_text(encoding="utf-8")))
    return model, s2j


def _write_report(
    result: TrialResult,
    directory: Path,
    calibration: dict[str, Any],
    truth_angles_rad: FloatArray | None = None,
    truth_positions_m: FloatArray | None = None,
) -> None:
    from .report import write_report

    write_report(
        directory / "report.html",
        model=result.model,
        time_s=result.trial.time_s,
        angles_rad=result.angles_rad,
        positions_m=result.positions_m,
        calibration=calibration,
        truth_angles_rad=truth_angles_rad,
        truth_positions_m=truth_positions_m,
    )


def run_calibrate(args: argparse.Namespace) -> None:
    """``lowerlimb calibrate TRIAL.csv --out DIR``: see DESIGN.md for the outputs.

    Raises:
        InputError: bad trial, bad options, or an existing non-empty DIR.
    """
    from .cli import populate_directory

    out = Path(args.out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise InputError(f"{out} already exists and is not empty; choose a new --out directory")
    trial = ImuTrial.from_csv(args.trial, side=args.side)
    s2j = None
    if getattr(args, "s2j", None) is not None:
        s2j = _read_s2j(Path(args.s2j))
    previous = None
    if getattr(args, "calibration", None) is not None:
        previous = _read_calibration(Path(args.calibration))
    if args.method not in CLI_METHODS:
        raise InputError(f"unknown method '{args.method}'; choose one of {', '.join(CLI_METHODS)}")
    print(
        f"calibrating {args.trial} ({trial.n_samples} samples at {trial.rate_hz:.4g} Hz, "
        f"{trial.duration_s:.1f} s, {trial.side} leg, method {args.method}, filter {args.filter})",
        file=sys.stderr,
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = process_trial(
            trial,
            method=CLI_METHODS[args.method],
            filter_name=args.filter,
            height_m=args.height,
            mass_kg=args.mass,
            use_mag=not getattr(args, "no_mag", False),
            s2j=s2j,
            calibration=previous,
            progress=True,
        )
    seen: set[str] = set()
    for w in caught:
        if issubclass(w.category, DeprecationWarning | PendingDeprecationWarning | FutureWarning):
            continue
        text = str(w.message)
        if text not in seen:
            seen.add(text)
            print(f"lowerlimb: warning: {text}", file=sys.stderr)
    populate_directory(out, lambda d: write_outputs(result, d))
    cal = result.calibration
    print(f"joint calibration took {cal.runtime_s:.3f} s; wrote {out}/", file=sys.stderr)
    for name, joint in cal.joints.items():
        print(f"  {name:<6s} rms residual {joint.to_dict()['rms_residual']:.4g}", file=sys.stderr)


def _read_s2j(path: Path) -> S2JModel:
    if not path.is_file():
        raise FileNotFoundError(f"S2J model not found: {path}")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as e:
        raise InputError(
            f"{path} is not JSON ({_first_line(e)}); give an S2J model written by S2JModel.to_dict()"
        ) from None
    try:
        return S2JModel.from_dict(data)
    except InputError as e:
        raise InputError(f"{path}: {e}") from None
    except (KeyError, TypeError) as e:
        raise InputError(
            f"{path} is not a lowerlimb S2J model ({e}); write one with S2JModel.to_dict()"
        ) from None


def _read_calibration(path: Path) -> LegCalibration:
    if not path.is_file():
        raise FileNotFoundError(f"calibration not found: {path}")
    try:
        return LegCalibration.from_dict(json.loads(path.read_text(encoding="utf-8")))
    except (ValueError, TypeError) as e:
        raise InputError(
            f"{path} is not a lowerlimb calibration.json ({_first_line(e)}); give the calibration.json "
            f"written by 'lowerlimb calibrate'"
        ) from None


def _first_line(e: BaseException) -> str:
    return str(e).splitlines()[0] if str(e) else type(e).__name__
