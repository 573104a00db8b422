"""The result folder of ``lowerlimb calibrate``: writing it all at once, and loading it back.

The folder's files are specified in ``docs/formats.md``: ``calibration.json``,
``angles.csv``, ``positions.csv``, ``s2j.json``, ``calibrated.urdf`` and
``report.html``. :func:`write_result` stages them in a hidden sibling folder
and renames it into place, so a failure never leaves a partial folder.
:func:`run_calibrate` is the whole command in typed form: the CLI only parses
its arguments into :class:`CalibrateOptions`.
"""

from __future__ import annotations

import json
import sys
import warnings
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .calibration import LegCalibration
from .calibration.options import CalibrationOptions, check_method
from .conventions import FloatArray
from .errors import InputError
from .io.atomic import check_new_directory, populate_directory
from .io.result_files import OUTPUT_FILES, check_outputs
from .io.tables import write_angles_csv, write_positions_csv
from .io.trial import ImuTrial
from .model.leg_model import LegModel
from .pipeline import TrialResult, process_trial
from .s2j import S2JModel

__all__ = [
    "OUTPUT_FILES",
    "S2J_SIDECAR",
    "CalibrateOptions",
    "check_outputs",
    "load_calibrated",
    "read_calibration",
    "read_s2j",
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
    files: Collection[str] = tuple(OUTPUT_FILES),
) -> None:
    """Write the outputs of a processed trial (docs/formats.md) into ``directory``.

    Args:
        result: the processed trial.
        directory: an existing, empty folder.
        truth_angles_rad: (N, 9) known angles (simulations) to overlay in the report.
        truth_positions_m: (N, 6) known positions to overlay in the report.
        files: short names (:data:`OUTPUT_FILES`) of the files to write; default all.
    """
    d = result.calibration_dict()
    d["urdf"] = OUTPUT_FILES["urdf"]
    d["s2j"] = S2J_SIDECAR
    if "calibration" in files:
        (directory / "calibration.json").write_text(json.dumps(d, indent=2), encoding="utf-8")
    if "angles" in files:
        write_angles_csv(directory / "angles.csv", result.trial.time_s, result.angles_rad)
    if "positions" in files:
        write_positions_csv(directory / "positions.csv", result.trial.time_s, result.positions_m)
    if "s2j" in files:
        (directory / S2J_SIDECAR).write_text(json.dumps(result.s2j.to_dict(), indent=1), encoding="utf-8")
    if "urdf" in files:
        (directory / "calibrated.urdf").write_text(
            urdf_with_sidecar(result.model.to_urdf_string()), encoding="utf-8"
        )
    if "report" in files:
        _write_report(result, directory, d, truth_angles_rad, truth_positions_m)


def write_result(result: TrialResult, out: Path, files: Collection[str] = tuple(OUTPUT_FILES)) -> None:
    """Create the folder ``out`` holding the outputs of ``result`` (default all), or nothing at all.

    Raises:
        InputError: ``out`` exists and is not empty, or its parent does not exist.
    """
    populate_directory(out, lambda d: write_outputs(result, d, files=files))


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
        outputs: short names (:data:`OUTPUT_FILES`) of the files to write.
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
    outputs: frozenset[str] = frozenset(OUTPUT_FILES)


def run_calibrate(options: CalibrateOptions) -> TrialResult:
    """Calibrate a trial file and write its result folder; progress and warnings go to stderr.

    Checks every input before computing, computes everything, then writes the
    folder at once.

    Raises:
        InputError: bad trial, bad options, or an existing non-empty output folder.
        FileNotFoundError: the trial, calibration or S2J file does not exist.
    """
    out = Path(options.out)
    check_new_directory(out)
    trial = ImuTrial.from_csv(options.trial, side=options.side)
    s2j = None if options.s2j is None else read_s2j(Path(options.s2j))
    previous = None if options.calibration is None else read_calibration(Path(options.calibration))
    check_method(options.method)
    files = check_outputs(options.outputs)
    print(
        f"calibrating {options.trial} ({trial.n_samples} samples at {trial.rate_hz:.4g} Hz, "
        f"{trial.duration_s:.1f} s, {trial.side} leg, method {options.method}, filter {options.filter_name})",
        file=sys.stderr,
    )
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
            calibration_options=CalibrationOptions(check_sensor_order=options.order_check),
            side_check=options.side_check,
        )
    _print_warnings(caught)
    write_result(result, out, files)
    cal = result.calibration
    print(f"joint calibration took {cal.runtime_s:.3f} s; wrote {out}/", file=sys.stderr)
    for name, joint in cal.joints.items():
        print(f"  {name:<6s} rms residual {joint.to_dict()['rms_residual']:.4g}", file=sys.stderr)
    return result


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


def read_s2j(path: Path) -> S2JModel:
    """Read an ``s2j.json`` written by :meth:`S2JModel.to_dict`.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        InputError: the file is not JSON or not an S2J model; the message names the file.
    """
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


def read_calibration(path: Path) -> LegCalibration:
    """Read a ``calibration.json`` written by ``lowerlimb calibrate``.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        InputError: the file is not a lowerlimb calibration; the message names the file.
    """
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
