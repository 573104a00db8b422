"""The result folder of ``lowerlimb calibrate`` for a two-leg (seven-IMU) trial.

Files (docs/formats.md, "Two legs"): ``calibration.json`` (``legs.left`` / ``legs.right``,
each with the single-leg ``joints``), ``angles.csv`` (``left_*``/``right_*``),
``positions.csv`` (with ``left_foot_to_right_foot``), ``events.csv``, ``stationary.csv``, ``gait.json``, the
URDF (:func:`write_lower_body_urdf`) and ``report.html``. As for one leg, the folder is
staged and renamed into place (:func:`lowerlimb.io.atomic.populate_directory`), so a
failure leaves nothing. :func:`run_calibrate_bilateral` is the whole command in typed form.
"""

from __future__ import annotations

import html
import json
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .bilateral import BilateralResult, process_bilateral_trial
from .calibration.options import check_method
from .conventions import SIDES
from .errors import InputError
from .gait import GaitEvents, write_events_csv, write_stationary_csv
from .io.atomic import populate_directory
from .io.bilateral_tables import write_bilateral_tables
from .io.bilateral_trial import BilateralTrial
from .io.bounds import INPUT_BOUNDS
from .io.result_files import OUTPUT_FILES, check_outputs
from .model.fallback import segment_lengths
from .outputs import (
    CalibrateOptions,
    _print_warnings,
    announce,
    build_provenance,
    check_options,
    residual_lines,
)

__all__ = [
    "LEG_URDF_FILES",
    "gait_summary_lines",
    "run_calibrate_bilateral",
    "write_bilateral_outputs",
    "write_bilateral_result",
    "write_lower_body_urdf",
]

#: The single-leg URDFs written beside the lower-body model (:func:`write_lower_body_urdf`).
LEG_URDF_FILES: dict[str, str] = {side: f"calibrated_{side}.urdf" for side in SIDES}


def write_lower_body_urdf(result: BilateralResult, directory: Path) -> list[str]:
    """Write the lower-body model and each calibrated leg; return the file names, the model first.

    ``calibrated.urdf`` (docs/formats.md, "Two legs") is one model of the pelvis, the
    upper body and both calibrated legs on a REP 103 z-up base
    (:func:`lowerlimb.model.lower_body.lower_body_urdf`); ``calibrated_left.urdf`` and
    ``calibrated_right.urdf`` are the single-leg models, as a one-leg trial writes them.
    """
    from lowerlimb.model.lower_body import lower_body_urdf

    left, right = (result.legs[s].model.geometry for s in ("left", "right"))
    xml = lower_body_urdf(left, right, height_m=left.height_m, mass_kg=left.mass_kg)
    (directory / "calibrated.urdf").write_text(xml, encoding="utf-8")
    for side, name in LEG_URDF_FILES.items():
        (directory / name).write_text(result.legs[side].model.to_urdf_string(), encoding="utf-8")
    return ["calibrated.urdf", *LEG_URDF_FILES.values()]


def write_bilateral_outputs(
    result: BilateralResult,
    directory: Path,
    *,
    files: frozenset[str] = frozenset(OUTPUT_FILES),
    exports: tuple[str, ...] = (),
    provenance: dict[str, Any] | None = None,
) -> list[str]:
    """Write the outputs of a processed two-leg trial into the existing, empty ``directory``.

    Args:
        result: the processed trial.
        directory: an existing, empty folder.
        files: short names (:data:`~lowerlimb.io.result_files.OUTPUT_FILES`) of the files to
            write; ``s2j`` does not apply to two legs. ``events.csv``, ``stationary.csv`` and
            ``gait.json`` are always written.
        exports: extra formats (``opensim``, ``bids``; :mod:`lowerlimb.export.bilateral`).
        provenance: calibration.json's ``provenance``
            (:func:`~lowerlimb.outputs.build_provenance`), or ``None``.

    Returns:
        The names of the files written.
    """
    from .export.bilateral import write_bilateral_exports, write_bilateral_units_sidecars

    written: list[str] = []
    urdf = write_lower_body_urdf(result, directory) if "urdf" in files else []
    written += urdf
    d = result.calibration_dict()
    if provenance is not None:
        d["provenance"] = provenance
    d["urdf"] = urdf
    if "calibration" in files:
        (directory / "calibration.json").write_text(json.dumps(d, indent=2), encoding="utf-8")
        written.append("calibration.json")
    tables = [t for t in ("angles", "positions") if t in files]
    if tables:
        write_bilateral_tables(directory, result.trial.time_s, result.angles_rad, result.positions_m, tables)
        written += [f"{t}.csv" for t in tables] + write_bilateral_units_sidecars(directory, tables)
    events = result.gait.events or GaitEvents()
    write_events_csv(events, directory / "events.csv")
    write_stationary_csv(events, directory / "stationary.csv")
    (directory / "gait.json").write_text(json.dumps(result.gait.to_dict(), indent=2) + "\n", encoding="utf-8")
    written += ["events.csv", "stationary.csv", "gait.json"]
    if "report" in files:
        _write_report(result, directory, d)
        written.append("report.html")
    return written + write_bilateral_exports(result, directory, exports)


def write_bilateral_result(
    result: BilateralResult,
    out: Path,
    *,
    files: frozenset[str] = frozenset(OUTPUT_FILES),
    exports: tuple[str, ...] = (),
    provenance: dict[str, Any] | None = None,
) -> None:
    """Create the folder ``out`` holding the chosen outputs of ``result``, or nothing at all.

    ``files``, ``exports`` and ``provenance`` as in :func:`write_bilateral_outputs`.

    Raises:
        InputError: ``out`` exists and is not empty, or its parent does not exist.
    """

    def fill(d: Path) -> None:
        write_bilateral_outputs(result, d, files=files, exports=exports, provenance=provenance)

    populate_directory(out, fill)


def _summary_rows(result: BilateralResult) -> str:
    h = result.hips
    rows = [
        ("hip spacing", f"{h.spacing_m * 1000:.0f} mm (de Leva {h.expected_spacing_m * 1000:.0f} mm)"),
        ("right hip to the right of the left", f"{h.lateral_m * 1000:.0f} mm"),
        ("hips plausible", "yes" if h.plausible else f"no: {h.reason}"),
    ]
    for side in SIDES:
        thigh, shank = segment_lengths(result.legs[side].calibration)
        rows.append(
            (
                f"{side} thigh, shank",
                f"{thigh * 1000:.0f} mm, {shank * 1000:.0f} mm (hip / ankle centre to knee axis)",
            )
        )
    g = result.gait.to_dict()
    if result.gait.parameters is not None:
        if g.get("cadence_steps_per_min") is not None:
            rows.append(("cadence", f"{g['cadence_steps_per_min']:.1f} steps/min"))
        if g.get("gait_speed_m_s") is not None:
            rows.append(("gait speed", f"{g['gait_speed_m_s']:.2f} m/s"))
        for side in SIDES:
            s = g.get(side) or {}
            sl = (s.get("stride_length_m") or {}).get("mean")
            st = (s.get("stride_time_s") or {}).get("mean")
            if sl is not None and st is not None:
                rows.append((f"{side} stride", f"{sl:.2f} m, {st:.2f} s"))
    else:
        rows.append(("gait", result.gait.note))
    return "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>" for k, v in rows)


#: What the terminal says of step width, by ``gait.json``'s ``step_width_basis``.
_WIDTH_BASIS = {
    "standing_chain": "step width rests on the calibrated chain at the standing start (too few steps "
    "to check it over the walk)",
    "standing_chain_straight_walk": "step width rests on the calibrated chain at the standing start: "
    "the walk is straight (or straight passes whose turns the feet's tracks went through unaided), so "
    "nothing checks its sideways error (up to 7 cm on simulated treadmill walks; walks that bend: "
    "about 1 cm; docs/limits.md)",
}


def gait_summary_lines(result: BilateralResult) -> list[str]:
    """The terminal's gait lines: strides, cadence, speed, step width and what sets it."""
    params = result.gait.parameters
    if params is None or not params.strides:
        return []
    g = params.to_dict()
    n = {side: g[side]["n_strides"] if isinstance(g.get(side), dict) else 0 for side in SIDES}
    width = g["step_width_m"]
    width_text = (
        f", step width {1000 * width['mean']:.0f} +- {1000 * width['sd']:.0f} mm"
        if np.isfinite(width["mean"]) and np.isfinite(width["sd"])
        else ""
    )
    lines = [
        f"gait   {n['left']} / {n['right']} strides (left / right), cadence "
        f"{g['cadence_steps_per_min']:.0f} steps/min, speed {g['gait_speed_m_s']:.2f} m/s{width_text}"
    ]
    basis = _WIDTH_BASIS.get(str(g.get("step_width_basis")))
    lines += [f"       {basis}"] if basis and width_text else []
    return lines + _turn_lines(result)


def _turn_lines(result: BilateralResult) -> list[str]:
    """The terminal's line on the walker's turns (none when the walker did not turn)."""
    turns = result.gait.turns
    if turns is None or not turns.turns:
        return []
    t = turns.to_dict()
    cut = f" (and {t['cut_by_recording']} cut by the recording)" if t["cut_by_recording"] else ""
    if not t["count"]:
        return [f"turns  none complete{cut}"]
    return [
        f"turns  {t['count']}{cut}: {t['angle_deg']['mean']:.0f} deg in {t['duration_s']['mean']:.1f} s, "
        f"{t['steps']['mean']:.1f} steps, peak {t['peak_rate_deg_s']['mean']:.0f} deg/s (means); turning "
        "strides and steps are summarised apart in gait.json"
    ]


def _gait_section(result: BilateralResult) -> str:
    """Left and right gait-cycle curves overlaid and the parameter table with symmetry indices."""
    from .conventions import ANGLE_COLUMNS
    from .viz.gait_curves import gait_report_section
    from .viz.turns_table import turns_table_html

    events = result.gait.events
    contacts = {e.side: list(e.initial_contact_s) for e in (events.sides() if events else [])}
    if sum(len(c) for c in contacts.values()) < 4:
        return ""
    gait = result.gait.to_dict()
    section = gait_report_section(
        result.trial.time_s,
        {side: np.degrees(result.legs[side].angles_rad) for side in contacts},
        contacts,
        list(ANGLE_COLUMNS[1:]),
        parameters={side: gait[side] for side in SIDES if isinstance(gait.get(side), dict)},
        # numbers only: not the flags (``anchored``), texts or per-side and per-stride lists
        overall={k: v for k, v in gait.items() if k not in SIDES and not isinstance(v, (list, str, bool))},
    )
    return section + turns_table_html((gait.get("turns") or {}).get("list", []))


def _write_report(result: BilateralResult, directory: Path, calibration: dict[str, object]) -> None:
    """``report.html``: a two-leg summary and each leg's single-leg report in an ``<iframe srcdoc>``."""
    from .viz.report import write_report

    frames = []
    for side in SIDES:
        leg = result.legs[side]
        tmp = directory / f".report_{side}.html"
        leg_calibration = dict(calibration["legs"][side])  # type: ignore[index]
        leg_calibration["side"] = side
        write_report(
            tmp,
            model=leg.model,
            time_s=result.trial.time_s,
            angles_rad=leg.angles_rad,
            positions_m=leg.positions_m,
            calibration=leg_calibration,
            title=f"lowerlimb calibration report: {side} leg",
        )
        doc = tmp.read_text(encoding="utf-8")
        tmp.unlink()
        frames.append(
            f'<h2>{side} leg</h2><iframe style="width:100%;height:90vh;border:0" '
            f'srcdoc="{html.escape(doc, quote=True)}"></iframe>'
        )
    page = (
        "<!DOCTYPE html><html><head><meta charset='utf-8'><title>lowerlimb: two legs</title></head>"
        "<body style='font-family:sans-serif'><h1>lowerlimb calibration report: two legs</h1>"
        f"<table>{_summary_rows(result)}</table>{_gait_section(result)}{''.join(frames)}</body></html>"
    )
    (directory / "report.html").write_text(page, encoding="utf-8")


def run_calibrate_bilateral(options: CalibrateOptions) -> BilateralResult:
    """Calibrate a two-leg trial file and write its result folder; progress and warnings go to stderr.

    ``options.side`` is not used (a two-leg trial has both); ``--calibration`` and ``--s2j``
    are single-leg options and are refused, and so is ``--reference`` (naming ``lowerlimb
    compare``, which compares a two-leg result); ``--outputs``/``--no-report`` and
    ``--export`` apply as for one leg.

    Raises:
        InputError: bad trial, bad or single-leg-only options, or an existing non-empty folder.
        FileNotFoundError: the trial does not exist.
    """
    out = Path(options.out)
    check_options(options)  # method, filter, height, mass and the output folder, before computing
    if options.reference is not None:  # the report of two legs has no agreement section
        raise InputError(
            f"--reference adds the agreement to a one-leg report; for a two-leg trial drop it and run "
            f"'lowerlimb compare {out} {options.reference} --out DIR' after calibrating"
        )
    single_leg_only = (
        (options.calibration, "--calibration"),
        (options.s2j, "--s2j"),
    )
    for given, flag in single_leg_only:
        if given is not None:
            raise InputError(
                f"{flag} is a single-leg option; a two-leg trial is calibrated on itself (drop {flag}, "
                f"or import one leg as a four-sensor trial)"
            )
    files = check_outputs(options.outputs)
    with warnings.catch_warnings(record=True) as read_warnings:  # said with the run's, once it runs
        warnings.simplefilter("always")
        trial = BilateralTrial.from_csv(options.trial)
    trial.check_motion(INPUT_BOUNDS.min_motion_gyro_std_rps)
    check_method(options.method)
    announce(options, trial.n_samples, trial.rate_hz, trial.duration_s, "two legs")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = process_bilateral_trial(
            trial,
            method=options.method,
            filter_name=options.filter_name,
            height_m=options.height_m,
            mass_kg=options.mass_kg,
            use_mag=options.use_mag,
            progress=True,
            calibration_options=options.calibration_options(),
            side_check=options.side_check,
            smooth_orientation=options.smooth_orientation,
            parallel_legs=options.parallel_legs,
        )
    _print_warnings(read_warnings + caught)
    write_bilateral_result(
        result,
        out,
        files=files,
        exports=tuple(options.exports),
        provenance=build_provenance(options, two_legs=True),
    )
    print(f"joint calibration of both legs took {result.runtime_s:.3f} s; wrote {out}/", file=sys.stderr)
    for side in SIDES:
        for line in residual_lines(result.legs[side].calibration_dict()):
            print(f"  {side:<5s} {line}", file=sys.stderr)
    h = result.hips
    print(
        f"  hips {h.spacing_m * 1000:.0f} mm apart (de Leva {h.expected_spacing_m * 1000:.0f} mm)",
        file=sys.stderr,
    )
    for line in gait_summary_lines(result):
        print(f"  {line}", file=sys.stderr)
    return result
