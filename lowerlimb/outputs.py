"""The result folder of ``lowerlimb calibrate``: writing it all at once, and loading it back.

The folder's files are specified in ``docs/formats.md``: ``calibration.json``,
``angles.csv``, ``positions.csv`` (with their units sidecars), ``s2j.json``,
``calibrated.urdf`` and ``report.html``, plus the exports asked for
(``docs/exports.md``). :func:`write_result` stages them in a hidden sibling folder
and renames it into place, so a failure never leaves a partial folder.
:func:`run_calibrate` is the whole command in typed form: the CLI only parses
its arguments into :class:`CalibrateOptions`.
"""

from __future__ import annotations

import json
import sys
import warnings
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .agreement.comparison import Comparison
from .agreement.files import Table
from .agreement.reference_checks import check_time_overlap
from .agreement.report import agreement_section_html, compare_result, read_reference
from .calibration import LegCalibration
from .calibration.fit_band import NO_CAP_BINDS
from .calibration.options import CalibrationOptions, check_method
from .conventions import FloatArray, check_side
from .errors import InputError
from .export.result import check_export_formats, write_exports, write_units_sidecars
from .gait.one_leg import LegGait
from .gait.writers import write_leg_gait
from .io.atomic import check_new_directory, populate_directory
from .io.bounds import INPUT_BOUNDS, InputBounds, check_range, check_vectors
from .io.file_hash import file_sha256
from .io.interrupts import check_interrupted
from .io.result_files import OUTPUT_FILES, check_outputs
from .io.tables import write_angles_csv, write_positions_csv
from .io.trial import ImuTrial
from .methods import ORIENTATION_FILTERS
from .model.leg_model import LegModel
from .pipeline import TrialResult, process_trial
from .s2j import S2JModel

__all__ = [
    "OUTPUT_FILES",
    "S2J_SIDECAR",
    "CalibrateOptions",
    "build_provenance",
    "check_options",
    "check_outputs",
    "load_calibrated",
    "read_calibration",
    "read_s2j",
    "residual_lines",
    "run_calibrate",
    "urdf_with_sidecar",
    "write_outputs",
    "write_result",
]

#: Name of the S2J sidecar written beside the URDF.
S2J_SIDECAR = OUTPUT_FILES["s2j"]


def write_outputs(
    result: TrialResult,
    directory: Path,
    *,
    truth_angles_rad: FloatArray | None = None,
    truth_positions_m: FloatArray | None = None,
    provenance: dict[str, Any] | None = None,
    exports: Sequence[str] = (),
    agreement: Comparison | None = None,
    reference_name: str = "",
    files: Collection[str] = tuple(OUTPUT_FILES),
) -> None:
    """Write the outputs of a processed trial (docs/formats.md) into ``directory``.

    Args:
        result: the processed trial.
        directory: an existing, empty folder.
        truth_angles_rad: (N, 9) known angles (simulations) to overlay in the report.
        truth_positions_m: (N, 6) known positions to overlay in the report.
        provenance: calibration.json's ``provenance`` (:func:`build_provenance`).
        exports: export formats (:data:`lowerlimb.export.formats.EXPORT_FORMATS`) to add.
        agreement: a comparison with a reference, shown in the report.
        reference_name: the reference file's name, for the report.
        files: short names (:data:`OUTPUT_FILES`) of the files to write; default all.
    """
    d = result.calibration_dict()
    if provenance is not None:
        d["provenance"] = provenance
    d["urdf"] = OUTPUT_FILES["urdf"]
    d["s2j"] = S2J_SIDECAR
    if "calibration" in files:
        (directory / "calibration.json").write_text(json.dumps(d, indent=2), encoding="utf-8")
    if "angles" in files:
        write_angles_csv(directory / "angles.csv", result.trial.time_s, result.angles_rad)
    if "positions" in files:
        write_positions_csv(directory / "positions.csv", result.trial.time_s, result.positions_m)
    write_units_sidecars(directory, [t for t in ("angles", "positions") if t in files])
    write_exports(result, directory, exports)
    if "s2j" in files:
        (directory / S2J_SIDECAR).write_text(json.dumps(result.s2j.to_dict(), indent=1), encoding="utf-8")
    if "urdf" in files:
        (directory / "calibrated.urdf").write_text(
            urdf_with_sidecar(result.model.to_urdf_string()), encoding="utf-8"
        )
    if result.gait is not None:  # a leg that walks: its events and gait, as two legs always have
        write_leg_gait(result.gait, directory)
    if "report" in files:
        sections = [] if agreement is None else [agreement_section_html(agreement, reference_name)]
        _write_report(result, directory, d, truth_angles_rad, truth_positions_m, sections)


def write_result(
    result: TrialResult,
    out: Path,
    *,
    provenance: dict[str, Any] | None = None,
    exports: Sequence[str] = (),
    agreement: Comparison | None = None,
    reference_name: str = "",
    files: Collection[str] = tuple(OUTPUT_FILES),
) -> None:
    """Create the folder ``out`` holding the outputs of ``result`` (default all), or nothing at all.

    Args:
        result: the processed trial.
        out: the folder to create.
        provenance: calibration.json's ``provenance`` (:func:`build_provenance`).
        exports: export formats to add (:func:`write_outputs`).
        agreement: a comparison with a reference, shown in the report.
        reference_name: the reference file's name, for the report.
        files: short names (:data:`OUTPUT_FILES`) of the files to write; default all.

    Raises:
        InputError: ``out`` exists and is not empty, or its parent does not exist.
    """
    populate_directory(
        out,
        lambda d: write_outputs(
            result,
            d,
            provenance=provenance,
            exports=exports,
            agreement=agreement,
            reference_name=reference_name,
            files=files,
        ),
    )


def urdf_with_sidecar(urdf: str) -> str:
    """Name the S2J sidecar in the URDF, as an XML comment right after the ``<robot>`` tag."""
    start = urdf.find("<robot")
    end = urdf.find(">", start)
    note = (
        f"<!-- lowerlimb: time-varying segment-to-joint model in {S2J_SIDECAR} (same folder); "
        f"load both with lowerlimb.load_calibrated -->"
    )
    return urdf[: end + 1] + note + urdf[end + 1 :]


def load_calibrated(directory: str | Path) -> tuple[LegModel, S2JModel]:
    """Re-load a calibrated leg and its S2J model from a ``lowerlimb calibrate`` directory.

    Raises:
        InputError: when the directory lacks ``calibrated.urdf`` or ``s2j.json``.
    """
    d = Path(directory)
    if (d / "calibrated.urdf").is_file() and not (d / S2J_SIDECAR).is_file():
        # the URDF names its S2J sidecar, but `calibrate --outputs` may have left it out
        raise InputError(
            f"{d} has calibrated.urdf but no {S2J_SIDECAR}; re-run lowerlimb calibrate with s2j in --outputs"
        )
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
    extra_sections: Sequence[str] = (),
) -> None:
    from .viz.report import write_report

    write_report(
        directory / "report.html",
        model=result.model,
        time_s=result.trial.time_s,
        angles_rad=result.angles_rad,
        positions_m=result.positions_m,
        calibration=calibration,
        truth_angles_rad=truth_angles_rad,
        truth_positions_m=truth_positions_m,
        extra_sections=extra_sections,
        gait_html=gait_cycles_html(result),
    )


#: Fewest strides for which the report shows gait-cycle curves.
MIN_REPORT_STRIDES = 3


def gait_cycles_html(result: TrialResult) -> str:
    """The report's gait-cycle section of a walking trial, or ``""`` when the trial shows no gait.

    Initial contacts are the leg's gait events (``result.gait``), else found here from the shank
    and foot gyros (:func:`lowerlimb.gait.detect_side_events`);
    each stride's angles are time-normalised (:func:`lowerlimb.viz.gait_curves.gait_report_section`),
    so a long walk reads as mean ± SD curves rather than a solid block of time plots.
    """
    from .conventions import ANGLE_COLUMNS
    from .gait import detect_side_events
    from .viz.gait_curves import gait_report_section

    t = result.trial
    found = None if result.gait is None else getattr(result.gait.events, t.side)
    if found is None:  # a foot that never rests (no gait.json) may still show strides
        bias = result.calibration.gyro_bias
        zero = np.zeros(3)
        try:
            found = detect_side_events(
                t.gyr["shank"] - bias.get("shank", zero),
                t.rate_hz,
                t.side,
                foot_gyr=t.gyr["foot"] - bias.get("foot", zero),
                foot_acc=t.acc["foot"],
                start_time_s=float(t.time_s[0]),
            )
        except InputError:  # no walking in this trial (squats, sit-to-stand…)
            return ""
    if len(found.initial_contact_s) < MIN_REPORT_STRIDES + 1:
        return ""
    return gait_report_section(
        t.time_s,
        {t.side: np.degrees(result.angles_rad)},
        {t.side: list(found.initial_contact_s)},
        list(ANGLE_COLUMNS[1:]),
    )


@dataclass(frozen=True)
class CalibrateOptions:
    """Everything ``lowerlimb calibrate`` is asked to do (docs/formats.md, command line).

    Attributes:
        trial: the trial CSV.
        out: the output folder to create (absent or empty).
        side: instrumented leg, ``"left"`` or ``"right"``.
        method: joint-constraint solver (:data:`lowerlimb.methods.CALIBRATION_METHODS`).
        filter_name: orientation filter (:data:`lowerlimb.methods.ORIENTATION_FILTERS`).
        height_m: subject stature, m.
        mass_kg: subject mass, kg.
        use_mag: fuse the magnetometer when the trial has one.
        calibration: an earlier ``calibration.json`` to reuse instead of calibrating.
        s2j: a fitted S2J model (``s2j.json``) instead of the constant vectors.
        side_check: refuse a trial whose calibrated hip is on the other side.
        order_check: refuse a trial whose sensor columns look swapped.
        sign_check: refuse a trial in which a sensor turns about the vertical against its
            neighbours (an inverted accelerometer or gyro sign).
        clock_sync: estimate the sensors' clock offsets from the joints and re-time the
            signals when they are offset (:mod:`lowerlimb.calibration.clock_sync`).
        centre_form: the form of the joint constraint that decides the hip and knee centres
            (:attr:`~lowerlimb.calibration.options.CalibrationOptions.centre_form`).
        hip_in_pelvis_form: the form that decides the hip centre in the pelvis sensor
            (:attr:`~lowerlimb.calibration.options.CalibrationOptions.hip_in_pelvis_form`).
        thigh_twist: undo each thigh sensor's turn about the femur with hip flexion
            (:attr:`~lowerlimb.calibration.options.CalibrationOptions.thigh_twist`).
        exports: extra formats to write (``"opensim"``, ``"bids"``; docs/exports.md).
        reference: a reference CSV (``time`` and columns named as ours, deg / m) whose
            agreement with the result goes into ``report.html``.
        outputs: short names (:data:`OUTPUT_FILES`) of the files to write.
        smooth_orientation: filter each sensor forward and backward in time (offline);
            ``False`` (``--causal``): forward only, as in real time.
        parallel_legs: with two legs, the right leg in a second process beside the left
            (:mod:`lowerlimb.bilateral.leg_runner`); ``False`` (``--one-core``): one after the other.
    """

    trial: Path
    out: Path
    side: str = "left"
    method: str = "casadi"
    filter_name: str = "mahony"
    height_m: float = 1.75
    mass_kg: float = 75.0
    use_mag: bool = True
    calibration: Path | None = None
    s2j: Path | None = None
    side_check: bool = True
    order_check: bool = True
    sign_check: bool = True
    clock_sync: bool = True
    centre_form: str = "norm"
    hip_in_pelvis_form: str = "aligned"
    thigh_twist: bool = False
    exports: tuple[str, ...] = ()
    reference: Path | None = None
    outputs: frozenset[str] = frozenset(OUTPUT_FILES)
    smooth_orientation: bool = True
    parallel_legs: bool = True

    def calibration_options(self) -> CalibrationOptions:
        """The joint-calibration options these command-line options choose (one and two legs)."""
        return CalibrationOptions(
            check_sensor_order=self.order_check,
            check_signs=self.sign_check,
            clock_sync=self.clock_sync,
            centre_form=self.centre_form,
            hip_in_pelvis_form=self.hip_in_pelvis_form,
            thigh_twist=self.thigh_twist,
        )


def check_options(options: CalibrateOptions, bounds: InputBounds = INPUT_BOUNDS) -> None:
    """Check the options that need no file: side, method, filter, height, mass, the output folder.

    Raises:
        InputError: naming the option and the accepted values.
    """
    try:
        check_side(options.side)
    except ValueError as e:
        raise InputError(f"{e}; pass --side left or --side right") from None
    check_method(options.method)
    if options.filter_name not in ORIENTATION_FILTERS:
        raise InputError(
            f"unknown filter {options.filter_name!r}; choose one of {', '.join(ORIENTATION_FILTERS)}"
        )
    check_range("--height", options.height_m, bounds.height_m, "m", "the subject's stature")
    check_range("--mass", options.mass_kg, bounds.mass_kg, "kg", "the subject's mass")
    check_new_directory(Path(options.out))


def announce(options: CalibrateOptions, n_samples: int, rate_hz: float, duration_s: float, legs: str) -> None:
    """The first progress line of ``calibrate`` on stderr: the trial and the methods."""
    print(
        f"calibrating {options.trial} ({n_samples} samples at {rate_hz:.4g} Hz, {duration_s:.1f} s, "
        f"{legs}, method {options.method}, filter {options.filter_name})",
        file=sys.stderr,
    )


def run_calibrate(options: CalibrateOptions) -> TrialResult:
    """Calibrate a trial file and write its result folder; progress and warnings go to stderr.

    Checks every input before computing (options, output folder, trial, the
    calibration, S2J and reference files and their values), computes everything, then
    writes the folder at once.

    Raises:
        InputError: bad trial, bad options, a reference that shares no column or time with
            the result, or an existing non-empty output folder.
        FileNotFoundError: the trial, calibration, S2J or reference file does not exist.
    """
    out = Path(options.out)
    check_options(options)
    s2j = None if options.s2j is None else read_s2j(Path(options.s2j))
    previous = None if options.calibration is None else read_calibration(Path(options.calibration))
    if previous is not None and previous.side != options.side:
        raise InputError(
            f"{options.calibration} is of the {previous.side} leg but the trial is the {options.side} "
            f"leg; pass --side {previous.side} or another calibration"
        )
    with warnings.catch_warnings(record=True) as read_warnings:  # said with the run's, once it runs
        warnings.simplefilter("always")
        trial = ImuTrial.from_csv(options.trial, side=options.side, use_mag=options.use_mag)
    if previous is None:
        trial.check_motion(INPUT_BOUNDS.min_motion_gyro_std_rps)
    provenance = build_provenance(options)
    check_interrupted()
    exports = check_export_formats(options.exports)
    files = check_outputs(options.outputs)
    reference = _checked_reference(options, files, trial.time_s)
    announce(options, trial.n_samples, trial.rate_hz, trial.duration_s, f"{trial.side} leg")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = process_trial(
            trial,
            method=options.method,
            filter_name=options.filter_name,
            height_m=options.height_m,
            mass_kg=options.mass_kg,
            use_mag=options.use_mag,
            s2j=s2j,
            calibration=previous,
            progress=True,
            calibration_options=options.calibration_options(),
            side_check=options.side_check,
            smooth_orientation=options.smooth_orientation,
        )
    _print_warnings(read_warnings + caught)
    agreement = None
    if reference is not None:
        agreement = compare_result(result.trial.time_s, result.angles_rad, result.positions_m, reference)
    write_result(
        result,
        out,
        provenance=provenance,
        exports=exports,
        agreement=agreement,
        reference_name=str(options.reference or ""),
        files=files,
    )
    cal = result.calibration
    if options.calibration is not None:
        print(
            f"joint calibration reused from {options.calibration} (not estimated on this trial); "
            f"wrote {out}/",
            file=sys.stderr,
        )
        return result
    print(f"joint calibration took {cal.runtime_s:.3f} s; wrote {out}/", file=sys.stderr)
    for line in residual_lines(result.calibration_dict()):
        print(f"  {line}", file=sys.stderr)
    if result.gait is not None:
        print(f"  {gait_line(result.gait)}", file=sys.stderr)
    return result


def gait_line(gait: LegGait) -> str:
    """One console line of a leg's gait: strides, stride length and time, cadence, speed."""
    m = gait.means()

    def text(key: str, fmt: str) -> str:
        return "–" if not np.isfinite(m[key]) else format(m[key], fmt)

    return (
        f"gait ({gait.side} leg, events.csv, gait.json): {gait.n_strides} straight strides of "
        f"{text('stride_length_m', '.2f')} m in {text('stride_time_s', '.2f')} s, "
        f"{text('cadence_steps_per_min', '.0f')} steps/min, {text('gait_speed_m_s', '.2f')} m/s"
    )


def _checked_reference(options: CalibrateOptions, files: frozenset[str], time_s: FloatArray) -> Table | None:
    """The ``--reference`` table, checked against the options and the trial's (N,) time, s, before computing.

    Raises:
        InputError: the report is not written (nowhere to put the agreement), or the reference is
            unreadable, has no column of ours, or its time is unsorted, in ms or off the trial's.
        FileNotFoundError: the reference does not exist.
    """
    if options.reference is None:
        return None
    if "report" not in files:
        raise InputError(
            f"--reference {options.reference} goes into report.html, which is not written "
            f"(--no-report, or --outputs without report); drop --reference, or write the report"
        )
    reference = read_reference(options.reference, time_s, options.side)
    check_time_overlap(time_s, reference.time_s)
    return reference


def residual_lines(calibration: dict[str, Any]) -> list[str]:
    """Console lines: each joint's RMS residuals, the segment lengths, the magnetometer's share.

    The lengths when recorded; the share of the samples at which the field set each joint's
    relative heading when the magnetometer was fused. Units: m/s² for a spherical joint's
    residual, rad/s for the hinge axis's.
    """
    lines = []
    for name, joint in calibration["joints"].items():
        unit = joint.get("rms_residual_unit", "m/s^2").replace("^2", "²")
        text = f"{name:<6s} rms residual {_fmt(joint.get('rms_residual'))} {unit}"
        if "rms_residual_axis" in joint:
            text += f" (centre), axis {_fmt(joint['rms_residual_axis'])} rad/s"
        lines.append(text)
    lengths = calibration.get("segment_lengths_m")
    if isinstance(lengths, dict) and {"thigh", "shank"} <= lengths.keys():
        lines.append(
            f"thigh {1000 * float(lengths['thigh']):.0f} mm, shank {1000 * float(lengths['shank']):.0f} mm "
            f"(hip and ankle centre to the knee axis{_band_text(calibration)})"
        )
    twist = calibration.get("thigh_twist")
    if isinstance(twist, dict):
        lines.append(
            f"thigh sensor twist undone: {float(twist['per_flexion_rad_per_rad']):+.2f} rad per rad of the "
            f"thigh's flexion about the femur (knee axes {abs(float(twist['mismatch_before_deg'])):.0f}° → "
            f"{abs(float(twist['mismatch_after_deg'])):.1f}° apart at standing)"
        )
    agreement = calibration.get("magnetic_field_agreement")
    if isinstance(agreement, dict) and agreement:
        shares = ", ".join(f"{joint} {100 * float(a):.0f} %" for joint, a in agreement.items())
        lines.append(
            f"magnetometer fused: its field set each joint's relative heading where the two sensors "
            f"saw one field ({shares} of the time)"
        )
    return lines


def _band_text(calibration: dict[str, Any]) -> str:
    """How the joints' band reads on the lengths line (calibration.json ``fit_band``; empty: none).

    Nothing when no widening was tried, or when no cap lowered a cut-off (both bands give
    one fit; an older calibration: a widened fit without caps).
    """
    band = calibration.get("fit_band")
    if not isinstance(band, dict) or float(band.get("factor", 1.0)) == 1.0:
        return ""
    if band.get("reason") == NO_CAP_BINDS:
        return ""
    if band.get("widened"):
        caps = calibration.get("rigid_band_cap_hz") or {}
        if not any(v is not None for v in caps.values()):
            return ""
        return f"; fitted with the rigid-band caps widened {float(band['factor']):g}x"
    return f"; fitted within the coherent band: {band.get('reason')}"


def _fmt(value: Any) -> str:
    return "n/a" if value is None else f"{float(value):.4g}"


#: Distributions whose versions calibration.json records (import name -> distribution names).
KEY_DEPENDENCIES: dict[str, tuple[str, ...]] = {
    "numpy": ("numpy",),
    "scipy": ("scipy",),
    "casadi": ("casadi",),
    "pinocchio": ("pin", "pinocchio"),
    "numba": ("numba",),
    "meshcat": ("meshcat",),
}


def dependency_versions() -> dict[str, str | None]:
    """``{name: version}`` of the key dependencies (None when not installed)."""
    from importlib.metadata import PackageNotFoundError, version

    out: dict[str, str | None] = {}
    for name, dists in KEY_DEPENDENCIES.items():
        out[name] = None
        for dist in dists:
            try:
                out[name] = version(dist)
                break
            except PackageNotFoundError:
                continue
    return out


def build_provenance(options: CalibrateOptions, *, two_legs: bool = False) -> dict[str, Any]:
    """calibration.json's ``provenance`` (docs/formats.md, Provenance): versions, input, options, reuse.

    ``two_legs``: a seven-sensor trial, whose ``options.side`` is ``"both"`` (the batch
    manifest's word for it), not the one-leg default ``CalibrateOptions.side``.
    """
    from . import __version__

    return {
        "lowerlimb_version": __version__,
        "dependencies": dependency_versions(),
        "input_file": str(options.trial),
        "input_sha256": file_sha256(Path(options.trial)),
        "options": {
            "side": "both" if two_legs else options.side,
            "filter": options.filter_name,
            "method": options.method,
            "height": options.height_m,
            "mass": options.mass_kg,
            "use_mag": options.use_mag,
            "s2j": None if options.s2j is None else str(options.s2j),
            "clock_sync": options.clock_sync,
            "centre_form": options.centre_form,
            "hip_in_pelvis_form": options.hip_in_pelvis_form,
            "thigh_twist": options.thigh_twist,
            "smooth_orientation": options.smooth_orientation,
        },
        "calibration_reused_from": None if options.calibration is None else str(options.calibration),
    }


def _print_warnings(caught: list[warnings.WarningMessage]) -> None:
    """Print each distinct user-facing warning once (deprecation notices are not the user's business)."""
    seen: set[str] = set()
    for w in caught:
        if issubclass(w.category, DeprecationWarning | PendingDeprecationWarning | FutureWarning):
            continue
        text = str(w.message)
        if text not in seen:
            seen.add(text)
            print(f"lowerlimb: warning: {text}", file=sys.stderr)


def _load_json(path: Path, what: str, fix: str) -> Any:
    """Parse a JSON file; any unreadable content is one InputError naming the file.

    NaN, Infinity and numbers that overflow to infinity are refused here; a
    too-deep nesting is refused instead of exhausting the interpreter's stack.
    """
    if path.is_dir():
        raise InputError(f"{path} is a directory, not a {what}; {fix}")
    if not path.is_file():
        raise FileNotFoundError(f"{what} not found: {path}")
    if path.stat().st_size > INPUT_BOUNDS.max_json_bytes:
        raise InputError(f"{path} is larger than any {what} ({path.stat().st_size} bytes); {fix}")

    def refuse_constant(name: str) -> float:
        raise ValueError(f"it holds {name}, which is not a number")

    def finite_float(text: str) -> float:
        x = float(text)
        if not np.isfinite(x):
            raise ValueError(f"the number {text[:30]} overflows")
        return x

    try:
        text = path.read_text(encoding="utf-8")
        return json.loads(text, parse_constant=refuse_constant, parse_float=finite_float)
    except UnicodeDecodeError:
        raise InputError(f"{path} is not UTF-8 text; {fix}") from None
    except RecursionError:
        raise InputError(f"{path} is nested too deeply to be a {what}; {fix}") from None
    except ValueError as e:
        raise InputError(f"{path} is not a valid {what} ({_first_line(e)}); {fix}") from None


def read_s2j(path: Path, bounds: InputBounds = INPUT_BOUNDS) -> S2JModel:
    """Read an ``s2j.json`` written by :meth:`S2JModel.to_dict`, and check its vectors are plausible.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        InputError: the file is not JSON, not an S2J model, or holds a vector
            that is not finite or longer than ``bounds.max_center_m``; the message
            names the file.
    """
    fix = "give an S2J model written by S2JModel.to_dict()"
    data = _load_json(path, "S2J model (s2j.json)", fix)
    try:
        model = S2JModel.from_dict(data)
    except InputError as e:
        raise InputError(f"{path}: {e}") from None
    except (
        KeyError,
        TypeError,
        ValueError,
        AttributeError,
        IndexError,
        RecursionError,
        np.linalg.LinAlgError,
    ) as e:
        raise InputError(f"{path} is not a lowerlimb S2J model ({_first_line(e)}); {fix}") from None
    vectors: list[tuple[str, Any]] = []
    for joint, (s_prox, s_dist) in model.constant.items():
        vectors += [(f"{joint} s_prox", s_prox), (f"{joint} s_dist", s_dist)]
    for joint, reg in model.regressions.items():
        try:
            values = np.asarray(reg.grid_values, dtype=float)
        except (TypeError, ValueError, IndexError, np.linalg.LinAlgError) as e:
            raise InputError(
                f"{path}: the {joint} regression cannot be evaluated ({_first_line(e)}); {fix}"
            ) from None
        if values.ndim != 2 or values.shape[1] != 6:
            raise InputError(
                f"{path}: the {joint} regression does not predict 6 values (s_prox, s_dist); {fix}"
            )
        vectors += [
            (f"{joint} regression s_prox", values[:, :3]),
            (f"{joint} regression s_dist", values[:, 3:]),
        ]
    check_vectors(str(path), vectors, bounds.max_center_m)
    return model


def read_calibration(path: Path, bounds: InputBounds = INPUT_BOUNDS) -> LegCalibration:
    """Read a ``calibration.json`` written by ``lowerlimb calibrate``, and check its values are plausible.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        InputError: the file is not a lowerlimb calibration, or a centre is not
            finite or lies beyond ``bounds.max_center_m`` from its sensor, or an
            axis is not a finite non-zero vector; the message names the file.
    """
    fix = "give the calibration.json written by 'lowerlimb calibrate'"
    data = _load_json(path, "calibration.json", fix)
    if not isinstance(data, dict):
        raise InputError(f"{path} holds a JSON {type(data).__name__}, not a calibration object; {fix}")
    if data.get("layout") == "two_legs":
        raise InputError(
            f"{path} is a two-leg calibration; reuse needs one leg's calibration.json (a four-sensor "
            f"trial's), and a two-leg trial is calibrated on itself"
        )
    if str(data.get("format", "")).startswith("lowerlimb-s2j"):
        raise InputError(f"{path} is a segment-to-joint model (give it to --s2j); {fix}")
    try:
        check_side(str(data.get("side")))
    except ValueError:
        raise InputError(f"{path}: side {data.get('side')!r} is neither 'left' nor 'right'; {fix}") from None
    joints = data.get("joints")
    if not isinstance(joints, dict):
        raise InputError(f"{path} has no 'joints' object; {fix}")
    for joint in ("hip", "knee", "ankle"):
        if not isinstance(joints.get(joint), dict):
            raise InputError(f"{path}: joint {joint!r} is missing or not an object; {fix}")
    vectors = [
        (f"{joint} {key}", joints[joint].get(key))
        for joint in ("hip", "knee", "ankle")
        for key in ("center_in_parent_sensor", "center_in_child_sensor")
    ]
    check_vectors(str(path), vectors, bounds.max_center_m)
    for key in ("axis_in_parent_sensor", "axis_in_child_sensor"):
        axis = joints["knee"].get(key)
        check_vectors(str(path), [(f"knee {key}", axis)], np.inf)
        if not 0.5 < float(np.linalg.norm(np.asarray(axis, dtype=float))) < 2.0:
            raise InputError(f"{path}: knee {key} {axis} is not a unit vector; {fix}")
    try:
        return LegCalibration.from_dict(data)
    except InputError as e:
        raise InputError(f"{path}: {e}; {fix}") from None
    except (ValueError, TypeError, KeyError, AttributeError, IndexError, np.linalg.LinAlgError) as e:
        raise InputError(f"{path} is not a lowerlimb calibration.json ({_first_line(e)}); {fix}") from None


def _first_line(e: BaseException) -> str:
    return str(e).splitlines()[0] if str(e) else type(e).__name__
