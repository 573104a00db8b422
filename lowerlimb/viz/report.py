"""``report.html``: one self-contained, offline page summarising a calibrated trial.

The page holds, with nothing fetched from the network:

- the calibrated leg in 3-D (meshcat, animated over the trial with its play
  controls and time slider), in an ``<iframe srcdoc>`` carrying meshcat's
  JavaScript inline (:mod:`lowerlimb.viz.scene`);
- the calibration table: joint centres in each sensor frame (mm, with their
  standard deviations when the calibration gives them), the knee axis in the
  thigh and shank sensor frames, RMS residuals and condition numbers;
- the excitation warnings of the calibration;
- plots of the 9 ISB joint angles (deg) and the two relative-position vectors
  (mm) as inline PNG images, with the truth overlaid and RMS errors tabled
  when the truth is given (simulated trials);
- extra sections given by the caller (``calibrate --reference``: the agreement
  with a reference, built by :mod:`lowerlimb.agreement.report`).

A 60 s walk at 100 Hz gives a file of about 2.4 MB (meshcat's JavaScript is
0.85 MB; the animation is capped at :data:`MAX_ANIMATION_FRAMES` frames).
"""

from __future__ import annotations

import base64
import html
import io
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .. import __version__
from ..conventions import ANGLE_COLUMNS, JOINTS, POSITION_COLUMNS, FloatArray
from ..errors import InputError, ShapeError
from ..model.leg_model import LegModel
from ..side_by_side import side_by_side
from .scene import CommandRecorder, draw_leg, standalone_html

#: Largest number of animation frames embedded in the report (keeps the file small).
MAX_ANIMATION_FRAMES = 1500
#: Animation frame rate of the report, Hz (lowered for long trials).
REPORT_FPS = 25.0

_MAX_PLOT_POINTS = 1600
_ANGLE_NAMES: tuple[str, ...] = ANGLE_COLUMNS[1:]
_POSITION_NAMES: tuple[str, ...] = POSITION_COLUMNS[1:]


def write_report(
    path: str | os.PathLike[str],
    *,
    model: LegModel,
    time_s: FloatArray,
    angles_rad: FloatArray,
    positions_m: FloatArray,
    calibration: Mapping[str, Any],
    truth_angles_rad: FloatArray | None = None,
    truth_positions_m: FloatArray | None = None,
    title: str = "lowerlimb calibration report",
    extra_sections: Sequence[str] = (),
    gait_html: str = "",
) -> None:
    """Write ``report.html``: 3-D leg, calibration table, warnings, angle and position plots.

    Args:
        path: HTML file to write.
        model: the calibrated leg (drawn and animated).
        time_s: (N,) sample times, s.
        angles_rad: (N, 9) ISB joint angles, rad, angles.csv order.
        positions_m: (N, 6) pelvis→foot sensor and hip→ankle centre vectors in
            the pelvis sensor frame, m, positions.csv order.
        calibration: the calibration.json document (docs/formats.md schema; the
            optional extras ``rms_residual_unit``, ``condition_number``,
            ``center_std_in_*_sensor``, ``axis_std_deg_in_*_sensor``,
            ``rms_residual_axis`` and ``warnings`` are shown when present).
        truth_angles_rad: optional (N, 9) true angles, rad, overlaid and compared.
        truth_positions_m: optional (N, 6) true positions, m, overlaid and compared.
        title: page title and heading.
        extra_sections: HTML fragments appended after the plots, as given (trusted
            markup from the library, e.g. the agreement section of
            :mod:`lowerlimb.agreement.report`).
        gait_html: optional HTML section shown after the joint-angle time plots, e.g.
            the gait-cycle curves and parameter table of
            :func:`lowerlimb.viz.gait_curves.gait_report_section` (readable where a long
            trial's time plots are a solid block).

    Raises:
        ShapeError: when an array does not have the shape given above.
        InputError: when ``calibration`` lacks its ``joints`` entries.
    """
    t, angles, positions, truth_a, truth_p = _check_arrays(
        time_s, angles_rad, positions_m, truth_angles_rad, truth_positions_m
    )
    joints = calibration.get("joints")
    if not isinstance(joints, Mapping) or any(j not in joints for j in JOINTS):
        raise InputError(
            "the calibration has no 'joints' entry with hip, knee and ankle; "
            "pass the calibration.json document (docs/formats.md schema)"
        )
    page = render_report(
        model=model,
        time_s=t,
        angles_rad=angles,
        positions_m=positions,
        calibration=calibration,
        truth_angles_rad=truth_a,
        truth_positions_m=truth_p,
        title=title,
        extra_sections=extra_sections,
        gait_html=gait_html,
    )
    with open(path, "w", encoding="utf-8") as f:
        f.write(page)


def render_report(
    *,
    model: LegModel,
    time_s: FloatArray,
    angles_rad: FloatArray,
    positions_m: FloatArray,
    calibration: Mapping[str, Any],
    truth_angles_rad: FloatArray | None = None,
    truth_positions_m: FloatArray | None = None,
    title: str = "lowerlimb calibration report",
    extra_sections: Sequence[str] = (),
    gait_html: str = "",
) -> str:
    """The HTML text of :func:`write_report` (arguments as there, already checked)."""
    recorder = CommandRecorder()
    scene = draw_leg(
        recorder.visualizer(),
        model,
        time_s,
        angles_rad,
        fps=REPORT_FPS,
        max_frames=MAX_ANIMATION_FRAMES,
        light_background=True,
    )
    scene_html = standalone_html(recorder.messages, title=title)
    duration = float(time_s[-1] - time_s[0]) if len(time_s) > 1 else 0.0
    rate = (len(time_s) - 1) / duration if duration > 0 else float("nan")
    summary = [
        ("side", str(calibration.get("side", model.side))),
        ("method", str(calibration.get("method", "—"))),
        ("samples", f"{len(time_s)} ({duration:.1f} s at {rate:.0f} Hz)" if duration > 0 else "1"),
    ]
    fit_rate = float(calibration.get("fit_rate_hz", 0.0) or 0.0)
    if duration > 0 and fit_rate > 1.5 * rate:
        summary.append(("calibration fitted at", f"{fit_rate:.0f} Hz (interpolated from {rate:.0f} Hz)"))
    if "runtime_s" in calibration:
        summary.append(("calibration time", f"{float(calibration['runtime_s']):.2f} s"))

    angle_curves: dict[str, FloatArray] = {"estimate": np.rad2deg(angles_rad)}
    position_curves: dict[str, FloatArray] = {"estimate": 1000.0 * positions_m}
    if truth_angles_rad is not None:
        angle_curves["truth"] = np.rad2deg(truth_angles_rad)
    if truth_positions_m is not None:
        position_curves["truth"] = 1000.0 * truth_positions_m
    # the two figures on two cores (lowerlimb.side_by_side): most of the report's time is drawing
    angle_png, position_png = side_by_side(
        lambda: _plot_grid(time_s, angle_curves, _ANGLE_NAMES, (3, 3), "deg", column_major=True),
        lambda: _plot_grid(time_s, position_curves, _POSITION_NAMES, (2, 3), "mm", column_major=False),
    )

    parts = [
        f"<h1>{_e(title)}</h1>",
        "<table class='summary'>"
        + "".join(f"<tr><th>{_e(k)}</th><td>{_e(v)}</td></tr>" for k, v in summary)
        + "</table>",
        _warnings_section(calibration),
        "<h2>Calibrated leg</h2>",
        "<p class='note'>Grey: segments; orange: IMUs with their x/y/z axes (red/green/blue); "
        "blue: joint centres; red rod: knee axis. Drag to orbit; "
        "<em>Open Controls → Animations</em> to pause, scrub or change the speed. "
        f"{len(scene.frame_time_s)} frames at {scene.fps:.1f} fps.</p>",
        f"<iframe class='scene' id='scene' title='3-D leg' srcdoc=\"{_srcdoc(scene_html)}\"></iframe>",
        "<h2>Calibration</h2>",
        _joint_table(calibration),
        _lengths_note(calibration),
        _magnetometer_note(calibration),
        _knee_axis_table(calibration),
        _clock_note(calibration),
        _twist_note(calibration),
        "<h2>Joint angles</h2>",
        "<p class='note'>ISB angles, Z-X-Y decomposition; flexion, adduction/inversion and "
        "internal rotation positive; zero = standing reference posture.</p>",
        f"<img class='plot' id='angles-plot' alt='joint angles (deg)' src='{angle_png}'>",
    ]
    if truth_angles_rad is not None:
        err = _rms(np.rad2deg(angles_rad - truth_angles_rad))
        parts.append(_error_table("RMS error against the truth (deg)", _ANGLE_NAMES, err, 2))
    parts.append(gait_html)
    parts += [
        "<h2>Relative positions</h2>",
        "<p class='note'>Pelvis sensor → foot sensor and hip centre → ankle centre, in the "
        "pelvis sensor frame, mm.</p>",
        f"<img class='plot' id='positions-plot' alt='relative positions (mm)' src='{position_png}'>",
    ]
    if truth_positions_m is not None:
        err = _rms(1000.0 * (positions_m - truth_positions_m))
        parts.append(_error_table("RMS error against the truth (mm)", _POSITION_NAMES, err, 1))
    parts += list(extra_sections)
    parts.append(f"<footer>lowerlimb {_e(__version__)}</footer>")
    body = "\n".join(p for p in parts if p)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{_e(title)}</title>
<style>{_CSS}</style>
</head>
<body>
{body}
</body>
</html>
"""


# ---------------------------------------------------------------- sections


def _warnings_section(calibration: Mapping[str, Any]) -> str:
    messages: list[str] = []
    for w in _as_list(calibration.get("warnings")):
        if str(w) not in messages:
            messages.append(str(w))
    joints = calibration.get("joints", {})
    for joint in JOINTS:
        for w in _as_list(joints.get(joint, {}).get("warnings")):
            if str(w) not in messages:
                messages.append(str(w))
    if not messages:
        return "<p class='ok' id='warnings'>No excitation warnings.</p>"
    items = "".join(f"<li>{_e(m)}</li>" for m in messages)
    return f"<div class='warnings' id='warnings'><h2>Warnings</h2><ul>{items}</ul></div>"


#: A centre, its noise spread and its cut-off shift: calibration.json keys before ``_in_*_sensor``.
_CENTRE_KEYS = ("center", "center_std", "center_cutoff_shift", "center_split_half_shift")


def _joint_table(calibration: Mapping[str, Any]) -> str:
    rows = []
    for joint in JOINTS:
        d = calibration["joints"][joint]
        unit = d.get("rms_residual_unit", "")
        rows.append(
            "<tr>"
            f"<th>{_e(joint)}</th><td>{_e(d.get('type', ''))}</td>"
            f"<td>{_e(d.get('parent_sensor', ''))} → {_e(d.get('child_sensor', ''))}</td>"
            f"<td>{_mm(*(d.get(k + '_in_parent_sensor') for k in _CENTRE_KEYS))}</td>"
            f"<td>{_mm(*(d.get(k + '_in_child_sensor') for k in _CENTRE_KEYS))}</td>"
            f"<td>{_num(d.get('rms_residual'))} {_e(unit)}</td>"
            f"<td>{_num(d.get('condition_number'))}</td>"
            "</tr>"
        )
    return (
        "<table class='calibration' id='calibration-table'><thead><tr>"
        "<th>joint</th><th>type</th><th>sensors</th>"
        "<th>centre in parent sensor (mm)</th><th>centre in child sensor (mm)</th>"
        "<th>RMS residual</th><th>condition number</th></tr></thead><tbody>"
        + "".join(rows)
        + "</tbody></table>"
    )


def _lengths_note(calibration: Mapping[str, Any]) -> str:
    """Thigh and shank length (calibration.json ``segment_lengths_m``; empty when absent)."""
    lengths = calibration.get("segment_lengths_m")
    if not isinstance(lengths, Mapping) or not {"thigh", "shank"} <= set(lengths):
        return ""
    return (
        f"<p class='note' id='segment-lengths'>Thigh {_num(1000 * float(lengths['thigh']))} mm "
        f"(hip centre to the knee axis), shank {_num(1000 * float(lengths['shank']))} mm "
        "(ankle centre to the knee axis).</p>"
    )


def _magnetometer_note(calibration: Mapping[str, Any]) -> str:
    """How often the field set each joint's relative heading (``magnetic_field_agreement``; 9-axis)."""
    agreement = calibration.get("magnetic_field_agreement")
    if not isinstance(agreement, Mapping) or not agreement:
        return ""
    shares = ", ".join(f"{_e(str(joint))} {100 * float(a):.0f} %" for joint, a in agreement.items())
    return (
        "<p class='note' id='magnetometer'>Magnetometer fused: its field set each joint's relative "
        f"heading where the joint's two sensors saw one field ({shares} of the samples; elsewhere the "
        "joint and the filters' own headings did).</p>"
    )


def _knee_axis_table(calibration: Mapping[str, Any]) -> str:
    knee = calibration["joints"]["knee"]
    fit = knee.get("axis_fit", {}) if isinstance(knee.get("axis_fit"), Mapping) else {}
    parent, child = knee.get("parent_sensor", "thigh"), knee.get("child_sensor", "shank")
    rows = []
    for sensor, key in ((parent, "parent"), (child, "child")):
        std = knee.get(f"axis_std_deg_in_{key}_sensor")
        rows.append(
            f"<tr><th>in {_e(sensor)} sensor</th><td>{_vec(knee.get(f'axis_in_{key}_sensor'))}</td>"
            f"<td>{_num(std)}</td></tr>"
        )
    residual = knee.get("rms_residual_axis", fit.get("rms_residual"))
    extra = ""
    if residual is not None:
        extra = (
            f"<p class='note'>Axis fit: RMS residual {_num(residual)} "
            f"{_e(fit.get('rms_residual_unit', 'rad/s'))}, condition number "
            f"{_num(fit.get('condition_number'))}.</p>"
        )
    return (
        "<h3>Knee axis (unit vector pointing to the subject's right)</h3>"
        "<table class='calibration' id='knee-axis-table'><thead><tr><th></th><th>axis</th>"
        "<th>std (deg)</th></tr></thead><tbody>" + "".join(rows) + "</tbody></table>" + extra
    )


def _clock_note(calibration: Mapping[str, Any]) -> str:
    """One line on the sensors' clocks (calibration.json ``clock_offsets``; empty when not searched)."""
    rec = calibration.get("clock_offsets")
    if not isinstance(rec, Mapping) or not isinstance(rec.get("shift_s"), Mapping):
        return ""
    moved = [(s, float(v)) for s, v in rec["shift_s"].items() if float(v) != 0.0]
    if not moved:
        return (
            "<p class='note' id='clock-note'>Sensor clocks: no offset found between the sensors "
            "(lags searched at each joint).</p>"
        )
    text = ", ".join(f"{_e(s)} {1000.0 * v:+.1f} ms" for s, v in moved)
    return (
        "<p class='warnings' id='clock-note'>Sensor clocks: the signals were re-timed before "
        f"calibrating, as found from the joints ({text} against the pelvis sensor); "
        "synchronise the sensors when recording.</p>"
    )


def _twist_note(calibration: Mapping[str, Any]) -> str:
    """One line on the thigh sensor's twist undone (calibration.json ``thigh_twist``; empty: none)."""
    rec = calibration.get("thigh_twist")
    if not isinstance(rec, Mapping):
        return ""
    return (
        "<p class='note' id='twist-note'>Thigh sensor twist (<code>--thigh-twist</code>): the thigh "
        f"sensor turned {float(rec['per_flexion_rad_per_rad']):+.2f} rad about the femur per rad of the "
        f"thigh's flexion, and that turn was undone before calibrating (knee axes from the two sensors "
        f"{abs(float(rec['mismatch_before_deg'])):.0f}° → {abs(float(rec['mismatch_after_deg'])):.1f}° "
        "apart at standing). Thigh lengths are less certain with it (docs/limits.md).</p>"
    )


def _error_table(caption: str, names: Sequence[str], values: FloatArray, digits: int) -> str:
    head = "".join(f"<th>{_e(n.replace('_', ' '))}</th>" for n in names)
    cells = "".join(f"<td>{v:.{digits}f}</td>" for v in values)
    return f"<table class='errors'><caption>{_e(caption)}</caption><tr>{head}</tr><tr>{cells}</tr></table>"


# ---------------------------------------------------------------- plots


def _plot_grid(
    time_s: FloatArray,
    curves: Mapping[str, FloatArray],
    names: Sequence[str],
    shape: tuple[int, int],
    unit: str,
    *,
    column_major: bool,
) -> str:
    """A grid of time plots as a ``data:image/png;base64`` URL; one column of each curve per panel.

    Panel ``k`` shows column ``k`` of every curve; panels are filled down the
    columns of the grid when ``column_major`` (one joint per column), else
    along its rows (one vector per row).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    rows, cols = shape
    fig = Figure(figsize=(12.0, 2.4 * rows + 0.4))
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, sharex=True, squeeze=False)
    styles = {"estimate": {"color": "#1f77b4", "lw": 1.0}, "truth": {"color": "#999", "lw": 1.6}}
    for k, ax in enumerate(axes.T.ravel() if column_major else axes.ravel()):
        for label, data in sorted(curves.items(), key=lambda c: c[0] != "truth"):
            t, y = _decimate(time_s, data[:, k], _MAX_PLOT_POINTS)
            ax.plot(t, y, label=label, **styles.get(label, {}))
        # a fixed title height spares matplotlib a layout pass per panel per draw
        ax.set_title(names[k].replace("_", " "), fontsize=9, y=1.0, pad=4)
        ax.xaxis.set_major_locator(MaxNLocator(6))  # few ticks: most of the drawing time is ticks
        ax.yaxis.set_major_locator(MaxNLocator(4))
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)", fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel(unit, fontsize=8)
    if len(curves) > 1:
        axes[0, 0].legend(fontsize=8)
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.5 / fig.get_figheight() + 0.02, top=0.95)
    fig.subplots_adjust(hspace=0.35, wspace=0.18)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _decimate(t: FloatArray, y: FloatArray, max_points: int) -> tuple[FloatArray, FloatArray]:
    """Keep each bin's minimum and maximum (in time order): the drawn envelope is unchanged.

    Args:
        t: (N,) times.
        y: (N,) values.
        max_points: largest number of points returned.

    Returns:
        ``(t_kept, y_kept)``, at most ``max_points`` samples (all of them when N is small).
    """
    n = len(y)
    if n <= max_points:
        return t, y
    k = -(-n // (max_points // 2))  # samples per bin
    padded = np.concatenate([y, np.full(-n % k, y[-1])]).reshape(-1, k)
    lo = np.argmin(np.where(np.isnan(padded), np.inf, padded), axis=1)
    hi = np.argmax(np.where(np.isnan(padded), -np.inf, padded), axis=1)
    base = k * np.arange(padded.shape[0])
    idx = np.unique(np.minimum(np.concatenate([base + lo, base + hi]), n - 1))
    return t[idx], y[idx]


# ---------------------------------------------------------------- helpers


def _check_arrays(
    time_s: FloatArray,
    angles_rad: FloatArray,
    positions_m: FloatArray,
    truth_angles_rad: FloatArray | None,
    truth_positions_m: FloatArray | None,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray | None, FloatArray | None]:
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size == 0:
        raise ShapeError(f"time_s must have shape (N,) with N ≥ 1, got {t.shape}")
    n = t.size

    def check(name: str, a: FloatArray, cols: int) -> FloatArray:
        arr = np.asarray(a, dtype=float)
        if arr.shape != (n, cols):
            raise ShapeError(f"{name} must have shape ({n}, {cols}) like time_s, got {arr.shape}")
        return arr

    n_a, n_p = len(_ANGLE_NAMES), len(_POSITION_NAMES)
    return (
        t,
        check("angles_rad", angles_rad, n_a),
        check("positions_m", positions_m, n_p),
        None if truth_angles_rad is None else check("truth_angles_rad", truth_angles_rad, n_a),
        None if truth_positions_m is None else check("truth_positions_m", truth_positions_m, n_p),
    )


def _rms(err: FloatArray) -> FloatArray:
    return np.asarray(np.sqrt(np.nanmean(err**2, axis=0)))


def _as_list(v: Any) -> list[Any]:
    if v is None:
        return []
    if isinstance(v, str):
        return [v]
    return list(v)


def _num(v: Any) -> str:
    if v is None:
        return "—"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return _e(str(v))
    if not np.isfinite(x):
        return "—"
    return f"{x:.3g}" if abs(x) < 1e4 else f"{x:.2e}"


def _vec(v: Any, scale: float = 1.0, digits: int = 3) -> str:
    if v is None:
        return "—"
    a = scale * np.asarray(v, dtype=float).ravel()
    return "(" + ", ".join(f"{x:.{digits}f}" for x in a) + ")"


def _mm(v: Any, std: Any = None, shift: Any = None, halves: Any = None) -> str:
    text = _vec(v, 1000.0, 1)
    if std is not None and np.all(np.isfinite(np.asarray(std, dtype=float))):
        text += f" <span class='std'>± {_vec(std, 1000.0, 1)}</span>"
    for value, label, tip in (
        (shift, "cut-off", "moves this far with the prefilter cut-offs widened by half"),
        (halves, "halves", "half the distance between the centres fitted on the first and second half"),
    ):
        if value is not None and np.all(np.isfinite(np.asarray(value, dtype=float))):
            moved = 1000.0 * float(np.linalg.norm(np.asarray(value, dtype=float)))
            text += f" <span class='shift' title='{tip}'>({label}: {moved:.0f} mm)</span>"
    return text


def _e(text: str) -> str:
    return html.escape(str(text), quote=True)


def _srcdoc(page: str) -> str:
    """Escape a page for an ``srcdoc="..."`` attribute."""
    return page.replace("&", "&amp;").replace('"', "&quot;")


_CSS = """
body {font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 1.5em auto;
      max-width: 1200px; padding: 0 1em; color: #222;}
h1 {font-size: 1.6em; margin-bottom: 0.3em;}
h2 {font-size: 1.25em; margin-top: 1.6em; border-bottom: 1px solid #ddd;}
h3 {font-size: 1.05em;}
table {border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em;}
th, td {border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left;}
thead th, table.errors th {background: #f3f4f6;}
td {font-variant-numeric: tabular-nums;}
caption {text-align: left; font-weight: 600; padding: 0.3em 0;}
.summary th {background: #f3f4f6;}
.std {color: #777;}
.note {color: #555; font-size: 0.9em;}
.warnings {background: #fdf6d8; border: 1px solid #c9a227; padding: 0.2em 1em; margin: 1em 0;}
.warnings h2 {border: none; margin-top: 0.4em;}
.ok {color: #2a7a2a;}
iframe.scene {width: 100%; height: 600px; border: 1px solid #ccc;}
img.plot {width: 100%; max-width: 1200px;}
footer {margin-top: 2em; color: #888; font-size: 0.8em;}
"""
