"""Processing one trial of a study, in whatever process runs it: never raises, always an outcome.

:func:`run_trial` is what the local pool and the Dask workers call. It reads the
trial, runs :func:`lowerlimb.process_trial` (or, for a seven-sensor trial,
:func:`lowerlimb.bilateral.process_bilateral_trial`), writes the chosen outputs and the record
into a staging folder and renames it into place (:mod:`lowerlimb.io.atomic`), so a
trial's folder is complete or absent. Any error becomes a ``failed`` outcome.
"""

from __future__ import annotations

import math
import os
import shutil
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from lowerlimb.bilateral import BilateralResult, BilateralSideError, process_bilateral_trial
from lowerlimb.calibration.plausibility import WrongSideError
from lowerlimb.conventions import ANGLE_COLUMNS
from lowerlimb.errors import InputError
from lowerlimb.io.atomic import default_dir_mode
from lowerlimb.io.bilateral_trial import BilateralTrial, read_header, trial_layout
from lowerlimb.io.bounds import INPUT_BOUNDS
from lowerlimb.io.trial import ImuTrial
from lowerlimb.model.fallback import segment_lengths
from lowerlimb.outputs import CalibrateOptions, build_provenance, read_calibration, write_outputs
from lowerlimb.outputs_bilateral import write_bilateral_outputs
from lowerlimb.pipeline import TrialResult, process_trial
from lowerlimb.side_by_side import set_enabled

from .record import MARKER, TrialJob, TrialOutcome

__all__ = ["bilateral_key_results", "key_results", "leg_gait_results", "run_trial"]

#: Errors that mean the trial or its options are bad (a re-run gives the same).
_INPUT_ERRORS = (InputError, FileNotFoundError, IsADirectoryError, PermissionError, UnicodeDecodeError)


def run_trial(job: TrialJob) -> TrialOutcome:
    """Process one trial and write its folder ``job.out / job.trial.name``; never raises.

    The trial's header decides the layout: four sensors (one leg, :func:`lowerlimb.process_trial`)
    or seven (both legs, :func:`lowerlimb.bilateral.process_bilateral_trial`; the manifest's
    ``side`` does not apply and ``calibration`` reuse is refused).
    """
    set_enabled(False)  # the study's trials already fill the cores
    t0, cpu0 = time.perf_counter(), time.process_time()
    trial = job.trial
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            results, write = _process(job)
        reason = _warning_line(caught)
        outcome = TrialOutcome(
            trial.name,
            trial.label,
            "warning" if reason else "ok",
            reason,
            0.0,
            math.nan,
            math.nan,
            trial.subject,
            trial.task,
            "both" if "left_thigh_length_mm" in results else trial.side,
            results,
            job.digest,
            "",
            job.attempt,
        )

        def fill(d: Path) -> None:
            write(d)
            outcome.wall_s = time.perf_counter() - t0
            outcome.cpu_s = time.process_time() - cpu0
            outcome.peak_rss_mb = peak_rss_mb()
            from .record import file_digests, write_record

            outcome.files = file_digests(d)
            write_record(d / MARKER, outcome)

        replace_directory(job.out / trial.name, fill)
        return outcome
    except WrongSideError as e:  # said as a manifest's fix: batch has no --side
        if not isinstance(e, BilateralSideError):  # (that one says to exchange the columns)
            e = WrongSideError(
                e.side,
                e.lateral_m,
                fix=f"set the trial's side column to {'right' if e.side == 'left' else 'left'} in a manifest",
                no_check=f"run 'lowerlimb calibrate {trial.label} --no-side-check' on it alone",
            )
        return _failed(job, _one_line(e), "input", t0)
    except _INPUT_ERRORS as e:
        return _failed(job, _one_line(e), "input", t0)
    except Exception as e:  # a bug or a solver failure: recorded, the study goes on
        return _failed(job, f"internal error ({type(e).__name__}): {_one_line(e)}", "internal", t0)


def _process(job: TrialJob) -> tuple[dict[str, float], Callable[[Path], None]]:
    """Process the trial of ``job``: its key results and the writer of its outputs.

    Raises:
        InputError: a bad trial or manifest row (e.g. ``calibration`` reuse for two legs).
    """
    trial, p = job.trial, job.params
    if trial_layout(read_header(trial.path)) == "two_legs":
        if trial.calibration is not None:
            raise InputError(
                "calibration reuse is a single-leg option; a two-leg trial is calibrated on itself "
                "(clear the manifest's calibration cell for it)"
            )
        seven = BilateralTrial.from_csv(trial.path)
        seven.check_motion(INPUT_BOUNDS.min_motion_gyro_std_rps)
        both = process_bilateral_trial(
            seven,
            method=p.method,
            filter_name=p.filter_name,
            height_m=trial.height_m,
            mass_kg=trial.mass_kg,
            use_mag=p.use_mag,
            calibration_options=_calibrate_options(job).calibration_options(),
            smooth_orientation=p.smooth_orientation,
            side_check=p.side_check,
            parallel_legs=False,  # the study's trials already fill the cores
        )
        provenance = _provenance(job, None, two_legs=True)
        return bilateral_key_results(both), lambda d: _write_two_legs(both, d, p.outputs, provenance)
    if trial.side == "both":
        raise InputError(
            f"side 'both', but {trial.label} has one leg's sensors; write left or right in the manifest's "
            "side column"
        )
    imu = ImuTrial.from_csv(trial.path, side=trial.side)
    previous = None if trial.calibration is None else read_calibration(trial.calibration)
    if previous is not None and previous.side != trial.side:
        raise InputError(
            f"{trial.calibration} is of the {previous.side} leg but the trial is the {trial.side} leg; "
            f"set the trial's side column to {previous.side} in the manifest, or give another calibration"
        )
    if previous is None:
        imu.check_motion(INPUT_BOUNDS.min_motion_gyro_std_rps)
    result = process_trial(
        imu,
        method=p.method,
        filter_name=p.filter_name,
        height_m=trial.height_m,
        mass_kg=trial.mass_kg,
        use_mag=p.use_mag,
        calibration=previous,
        calibration_options=_calibrate_options(job).calibration_options(),
        smooth_orientation=p.smooth_orientation,
        side_check=p.side_check,
    )
    provenance = _provenance(job, imu.side, two_legs=False)
    return key_results(result) | leg_gait_results(result), lambda d: write_outputs(
        result, d, files=p.outputs, provenance=provenance
    )


def _provenance(job: TrialJob, side: str | None, *, two_legs: bool) -> dict[str, Any]:
    """calibration.json's ``provenance`` for a study's trial, as ``calibrate`` writes it (docs/formats.md)."""
    return build_provenance(_calibrate_options(job, side), two_legs=two_legs)


def _calibrate_options(job: TrialJob, side: str | None = None) -> CalibrateOptions:
    """What ``lowerlimb calibrate`` would be asked for this trial with the study's settings."""
    trial, p = job.trial, job.params
    return CalibrateOptions(
        trial=Path(trial.path),
        out=Path(trial.name),
        side=side or "left",
        method=p.method,
        filter_name=p.filter_name,
        height_m=trial.height_m,
        mass_kg=trial.mass_kg,
        use_mag=p.use_mag,
        calibration=None if trial.calibration is None else Path(trial.calibration),
        side_check=p.side_check,
        order_check=p.order_check,
        sign_check=p.sign_check,
        centre_form=p.centre_form,
        hip_in_pelvis_form=p.hip_in_pelvis_form,
        thigh_twist=p.thigh_twist,
        smooth_orientation=p.smooth_orientation,
    )


def _write_two_legs(
    result: BilateralResult, directory: Path, files: frozenset[str], provenance: dict[str, Any]
) -> None:
    write_bilateral_outputs(result, directory, files=files, provenance=provenance)


def bilateral_key_results(result: BilateralResult) -> dict[str, float]:
    """``batch.csv``'s key results of a processed two-leg trial.

    Returns:
        ``duration_s``; each leg's :func:`key_results` with a ``left_``/``right_`` prefix;
        ``thigh_length_mm`` and ``shank_length_mm`` as the mean of the two legs (so that
        the per-subject summaries include two-leg trials); and from ``gait.json``
        ``cadence_steps_per_min``, ``gait_speed_m_s``, ``stride_length_m`` (mean of the
        two legs' straight strides) and ``step_width_m`` (mean of both legs' straight steps);
        NaN without walking.
    """
    legs = {side: key_results(result.legs[side]) for side in ("left", "right")}
    out: dict[str, float] = {"duration_s": legs["left"]["duration_s"]}
    for name in ("thigh_length_mm", "shank_length_mm"):
        out[name] = round(0.5 * (legs["left"][name] + legs["right"][name]), 2)
    for side, values in legs.items():
        out |= {f"{side}_{k}": v for k, v in values.items() if k != "duration_s"}
    gait = result.gait.to_dict()
    strides = [gait.get(side, {}).get("stride_length_m", {}).get("mean") for side in ("left", "right")]
    finite = [float(v) for v in strides if isinstance(v, int | float) and math.isfinite(v)]
    out["cadence_steps_per_min"] = _rounded(gait.get("cadence_steps_per_min"))
    out["gait_speed_m_s"] = _rounded(gait.get("gait_speed_m_s"))
    out["stride_length_m"] = round(float(np.mean(finite)), 4) if finite else math.nan
    width = gait.get("step_width_m")
    out["step_width_m"] = _rounded(width.get("mean") if isinstance(width, dict) else None)
    return out


def _rounded(v: object, digits: int = 4) -> float:
    return round(float(v), digits) if isinstance(v, int | float) and math.isfinite(v) else math.nan


def key_results(result: TrialResult) -> dict[str, float]:
    """``batch.csv``'s key results of a processed trial.

    Returns:
        ``duration_s``; ``thigh_length_mm`` and ``shank_length_mm`` of the calibrated leg
        (hip and ankle centre to the knee axis line, calibration.json's ``segment_lengths_m``);
        ``<angle>_range_deg``, the range (max − min) of each of the 9 ISB angles over the
        trial, deg; and
        ``split_half_max_mm``, the largest split-half shift of the hip and ankle centres
        (:mod:`lowerlimb.calibration.split_half`; NaN when not probed), mm.
    """
    thigh, shank = segment_lengths(result.calibration)
    out = {
        "duration_s": round(float(result.trial.duration_s), 3),
        "thigh_length_mm": round(1000.0 * float(thigh), 2),
        "shank_length_mm": round(1000.0 * float(shank), 2),
        "split_half_max_mm": _split_half_max_mm(result),
    }
    deg = np.rad2deg(result.angles_rad)
    for k, name in enumerate(ANGLE_COLUMNS[1:]):
        column = deg[:, k][np.isfinite(deg[:, k])]
        out[f"{name}_range_deg"] = round(float(np.ptp(column)), 2) if column.size else float("nan")
    return out


def leg_gait_results(result: TrialResult) -> dict[str, float]:
    """``batch.csv``'s gait results of a single-leg trial (the two-leg trial's names).

    Returns:
        ``cadence_steps_per_min`` (``120 / stride time``), ``gait_speed_m_s`` and
        ``stride_length_m`` of the leg's straight strides (:mod:`lowerlimb.gait.one_leg`);
        NaN without walking.
    """
    m = result.gait.means() if result.gait is not None else {}
    return {k: _rounded(m.get(k)) for k in ("cadence_steps_per_min", "gait_speed_m_s", "stride_length_m")}


def _split_half_max_mm(result: TrialResult) -> float:
    """Largest split-half shift (norm per sensor frame) of the hip and ankle, mm; NaN when none."""
    shifts = [
        float(np.linalg.norm(part))
        for joint in (result.calibration.hip, result.calibration.ankle)
        for part in (joint.split_half_shift[:3], joint.split_half_shift[3:])
        if np.all(np.isfinite(part))
    ]
    return round(1000.0 * max(shifts), 1) if shifts else math.nan


def replace_directory(out: Path, fill: Callable[[Path], None]) -> None:
    """Create ``out`` with what ``fill(staging)`` writes, replacing an older ``out`` only on success."""
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    old: Path | None = None
    try:
        fill(staging)
        os.chmod(staging, default_dir_mode())  # as calibrate's folders, not mkdtemp's 0700
        if out.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old.", dir=out.parent))
            os.replace(out, old / "previous")
        os.replace(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        if old is not None and not out.exists():
            os.replace(old / "previous", out)
        raise
    finally:
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


def peak_rss_mb() -> float:
    """Peak resident memory of this process, MB (NaN where ``resource`` is missing)."""
    try:
        import resource
    except ImportError:  # Windows
        return math.nan
    kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return kb / 1024.0 if sys.platform != "darwin" else kb / 1024.0**2


def _failed(job: TrialJob, reason: str, failure: str, t0: float) -> TrialOutcome:
    out = TrialOutcome.failed(job.trial, reason, failure, job.digest, time.perf_counter() - t0)
    out.attempts = job.attempt
    out.peak_rss_mb = peak_rss_mb()
    return out


def _warning_line(caught: list[warnings.WarningMessage]) -> str:
    seen: list[str] = []
    for w in caught:
        if issubclass(w.category, DeprecationWarning | PendingDeprecationWarning | FutureWarning):
            continue
        text = " ".join(str(w.message).split())
        if text not in seen:
            seen.append(text)
    return "; ".join(seen)


def _one_line(e: BaseException) -> str:
    return " ".join((str(e) or type(e).__name__).split())
