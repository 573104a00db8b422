"""Both legs: the goals of issue 11 on simulated seven-IMU walks and on the real walk, in one table.

Simulated (``lowerlimb.simulation.simulate_bilateral``, fresh seeds, realistic noise, 60 s):
each trial goes through ``process_bilateral_trial`` (what ``lowerlimb calibrate`` runs on a
seven-sensor CSV) and is scored against the simulator's truth:

- events: each true initial contact (heel touches) and toe-off (toe leaves) is matched to the
  nearest detected event of its side and kind within 0.2 s (IMU − truth, ms);
- strides: each true stride is matched to the detected stride of its side starting within
  0.2 s; stride length error in % of the truth, step width and step length in mm;
- angles: RMSE per angle and side after the standing period, degrees;
- the hip spacing against the truth.

Real (``gait/``, Xsens + Vicon): the numbers of ``bilateral_gait.py`` (calibrate on seven
IMUs, segment lengths, stride length and step width against the Vicon ankle centres) and
``gait_events.py`` (events against the marker events of Zeni et al. 2008, straight walking).

Goals (issue 11): real walk: both legs calibrate, segment lengths within 20 mm, events within
20 ms median (40 ms worst), stride length within 3 %, step width within 20 mm; simulated:
events within 10 ms median, stride length within 2 %, flexion RMSE ≤ 2°, other angles ≤ 3°.

With ``--artefacts real`` the simulated walks carry the realism profile
(``Artefacts.real_walk()``: heel-strike impacts, wobbling soft tissue, skin motion, clock, scale
and misalignment errors of all seven sensors); the same seeds are also scored rigid and both
are tabulated side by side; the real walk is not re-run.

Usage: ``python benchmarks/gait.py [--data ../shared/data] [--seeds 201 202 …] [--duration 60]
[--artefacts none|real] [--uniform-field] [--stops N] [--out DIR]``; writes ``gait.{md,json}``
(``gait_artefacts.{md,json}`` with ``--artefacts real``, ``gait_uniform_field.{md,json}`` with
``--uniform-field``: the simulator's uniform magnetic field, 9-axis fusion; ``gait_stops`` with
``--stops N``: a walker who stops N times and walks on) in ``--out`` (default
``benchmarks/results``).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from types import ModuleType, SimpleNamespace
from typing import Any

import numpy as np

from lowerlimb.bilateral import BilateralSideError, process_bilateral_trial
from lowerlimb.bilateral.pelvis import OppositeKneesWarning
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration
from lowerlimb.conventions import ANGLE_COLUMNS, SIDES
from lowerlimb.gait import GaitParams
from lowerlimb.gait.turns import detect_turns, vertical_rate
from lowerlimb.model.fallback import segment_lengths
from lowerlimb.simulation import Artefacts, simulate_bilateral
from lowerlimb.simulation.footsteps import PACE_RANGES, PACES
from lowerlimb.simulation.pauses import PauseParams
from lowerlimb.simulation.treadmill import TreadmillParams
from lowerlimb.simulation.turns import TurnParams

ROOT = Path(__file__).resolve().parents[1]
MATCH_S = 0.2
SKIP_S = 3.0  # standing and the first step
GOALS = {
    "sim_event_median_ms": 10.0,
    "sim_stride_length_pct": 2.0,
    "sim_flexion_rmse_deg": 2.0,
    "sim_other_rmse_deg": 3.0,
    "real_event_median_ms": 20.0,
    "real_event_worst_ms": 40.0,
    "real_length_mm": 20.0,
    "real_stride_length_pct": 3.0,
    "real_step_width_mm": 20.0,
}
ANGLES = ANGLE_COLUMNS[1:]


def _module(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"{name}_benchmark", ROOT / "benchmarks" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _stats(x: list[float]) -> dict[str, float]:
    a = np.asarray([v for v in x if np.isfinite(v)], dtype=float)
    if a.size == 0:
        return {"n": 0, "median_abs": float("nan"), "worst_abs": float("nan"), "bias": float("nan")}
    return {
        "n": int(a.size),
        "median_abs": float(np.median(np.abs(a))),
        "worst_abs": float(np.max(np.abs(a))),
        "bias": float(np.mean(a)),
    }


def _event_errors(true_s: np.ndarray, est_s: np.ndarray) -> tuple[list[float], int]:
    """IMU − truth (ms) for each true event after :data:`SKIP_S`, and the number missed."""
    errs, missed = [], 0
    for x in true_s[true_s > SKIP_S]:
        if est_s.size == 0 or np.min(np.abs(est_s - x)) > MATCH_S:
            missed += 1
            continue
        errs.append(1000.0 * float(est_s[np.argmin(np.abs(est_s - x))] - x))
    return errs, missed


#: Calibrated joint quantities scored against the truth: (joint, key, label).
JOINT_QUANTITIES = (
    ("hip", "center_in_parent_sensor", "hip in pelvis sensor, mm"),
    ("hip", "center_in_child_sensor", "hip in thigh sensor, mm"),
    ("ankle", "center_in_parent_sensor", "ankle in shank sensor, mm"),
    ("ankle", "center_in_child_sensor", "ankle in foot sensor, mm"),
    ("knee", "axis_in_parent_sensor", "knee axis, deg"),
)


def _joint_errors(res: Any, truth: dict[str, Any]) -> dict[str, list[float]]:
    """Per quantity of :data:`JOINT_QUANTITIES`, the error of each leg (mm, or deg for the axis)."""
    out: dict[str, list[float]] = {}
    for joint, key, label in JOINT_QUANTITIES:
        errs = []
        for side in SIDES:
            est = np.asarray(res.calibration_dict()["legs"][side]["joints"][joint][key], dtype=float)
            tru = np.asarray(truth["legs"][side]["joints"][joint][key], dtype=float)
            if "axis" in key:
                errs.append(float(np.degrees(np.arccos(np.clip(abs(est @ tru), -1.0, 1.0)))))
            else:
                errs.append(1000.0 * float(np.linalg.norm(est - tru)))
        out[label] = errs
    return out


#: Labels of the segment-length rows (signed errors: hip or ankle centre to the knee axis line).
LENGTH_LABELS = ("thigh length (hip to knee axis), mm", "shank length (ankle to knee axis), mm")


def true_leg(joints: dict[str, Any]) -> SimpleNamespace:
    """A leg's true joints (calibration.json schema) as the calibration's objects (hip, knee, ankle)."""
    return SimpleNamespace(
        hip=SphericalJointCalibration.from_dict(joints["hip"], "hip"),
        knee=HingeJointCalibration.from_dict(joints["knee"]),
        ankle=SphericalJointCalibration.from_dict(joints["ankle"], "ankle"),
    )


def _length_errors(res: Any, truth: dict[str, Any]) -> dict[str, list[float]]:
    """Signed thigh and shank length errors of each leg, mm (``model.fallback.segment_lengths``)."""
    out: dict[str, list[float]] = {label: [] for label in LENGTH_LABELS}
    for side in SIDES:
        est = segment_lengths(res.legs[side].calibration)
        tru = segment_lengths(true_leg(truth["legs"][side]["joints"]))  # type: ignore[arg-type]
        for label, e, t in zip(LENGTH_LABELS, est, tru, strict=True):
            out[label].append(1000.0 * (e - t))
    return out


def matched_strides(sim: Any, res: Any) -> list[tuple[Any, Any]]:
    """Pairs (true stride, estimated stride) of one side starting within MATCH_S, after SKIP_S."""
    est = res.gait.parameters.strides if res.gait.parameters is not None else []
    pairs = []
    for st in sim.gait.strides:
        if st.start_s < SKIP_S:
            continue
        cand = [s for s in est if s.side == st.side and abs(s.start_s - st.start_s) < MATCH_S]
        if cand:
            pairs.append((st, cand[0]))
    return pairs


def score_simulation(
    seed: int,
    duration_s: float,
    artefacts: Artefacts | None = None,
    uniform_field: bool = False,
    calibration_options: CalibrationOptions | None = None,
    rate_hz: float = 100.0,
    gait_params: GaitParams | None = None,
    pace: str = "normal",
    knee_rotation: float = 0.0,
    transform: Callable[[Any], Any] | None = None,
    stops: PauseParams | None = None,
    treadmill: TreadmillParams | None = None,
    turns: TurnParams | None = None,
) -> dict[str, Any]:
    """One simulated walk through the two-leg pipeline, scored against its truth.

    ``artefacts`` is the simulator's realism profile (``None``: rigid sensors);
    ``uniform_field`` replaces the lab's magnetic field by one uniform field (9-axis fusion);
    ``calibration_options`` and ``gait_params`` are passed to the pipeline (``None``: the
    defaults); ``rate_hz`` is the simulated sampling rate; ``pace`` the walker's
    (``normal`` or ``slow``, :data:`lowerlimb.simulation.footsteps.PACE_RANGES`);
    ``knee_rotation`` the knees' internal rotation per rad of flexion (0: hinges);
    ``transform`` maps the simulated trial to the one processed (``None``: as simulated);
    ``stops`` makes the walker stop and stand (``None``: walks on); ``treadmill`` puts the
    walk on a treadmill (``None``: overground); ``turns`` makes it straight passes with turns
    about between them (``None``: a gently bending path).
    """
    kw: dict[str, Any] = {"lab_field": None} if uniform_field else {}
    kw["knee_rotation_per_flexion"] = knee_rotation
    kw["stops"] = stops
    kw["treadmill"] = treadmill
    kw["turns"] = turns
    sim = simulate_bilateral(duration_s, seed, artefacts=artefacts, rate_hz=rate_hz, pace=pace, **kw)
    trial = sim.trial if transform is None else transform(sim.trial)
    t0 = time.perf_counter()
    refused = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        kw = {"calibration_options": calibration_options, "gait_params": gait_params}
        try:
            res = process_bilateral_trial(trial, **kw)
        except BilateralSideError:
            # the pair of calibrated hips looks swapped: counted, then scored without the check
            refused = True
            res = process_bilateral_trial(trial, side_check=False, **kw)
    # the legs' pelvis frames point apart (undetermined hips turn the thigh headings): each leg
    # kept its own pelvis, with a warning; counted
    one_pelvis_refused = any(w.category is OppositeKneesWarning for w in caught)
    out: dict[str, Any] = {
        "seed": seed,
        "wall_s": time.perf_counter() - t0,
        "warnings": len(caught),
        "side_check_refused": refused,
        "one_pelvis_refused": one_pelvis_refused,
    }
    ev = res.gait.events
    for side in SIDES:
        se = getattr(ev, side) if ev is not None else None
        truth = sim.feet[side].events
        for kind, true_s, est in (
            ("initial_contact", truth.initial_contact_s, se.initial_contact_s if se else np.zeros(0)),
            ("toe_off", truth.toe_off_s, se.toe_off_s if se else np.zeros(0)),
        ):
            errs, missed = _event_errors(np.asarray(true_s), np.asarray(est))
            out[f"{side}_{kind}_ms"] = errs
            out[f"{side}_{kind}_missed"] = missed
    length, width, step, turning, own, start = [], [], [], [], [], []
    for st, c in matched_strides(sim, res):
        start.append(float(st.start_s))
        length.append(100.0 * (c.stride_length_m - st.stride_length_m) / st.stride_length_m)
        width.append(1000.0 * (c.step_width_m - st.step_width_m))
        step.append(1000.0 * (c.step_length_m - st.step_length_m))
        turning.append(bool(c.turning or c.step_turning))
        own.append(bool(c.turning))
    out |= {"stride_length_pct": length, "step_width_mm": width, "step_length_mm": step}
    out["stride_turning"] = turning  # the step (or the stride) turns: its step width is summarised apart
    out["stride_own_turning"] = own  # the stride turns: its stride length is summarised apart
    out["stride_start_s"] = start
    out["stride_time_s"] = float(sim.draw.stride_time_s)
    out["turn_starts_s"] = list(sim.truth.get("turns", {}).get("start_s", []))
    found = res.gait.turns
    if found is not None:
        # the same detector on the true pelvis, with the pipeline's window: the walker's turns
        true_rate = vertical_rate(sim.clean.gyr["pelvis"], sim.quat_wxyz["pelvis"])
        ref = detect_turns(
            true_rate, rate_hz, stride_time_s=found.window_s, start_time_s=float(sim.trial.time_s[0])
        )
        out["walker_turns"] = [t.to_dict() for t in found.turns]
        out["walker_turns_truth"] = [t.to_dict() for t in ref.turns]
    keep = sim.trial.time_s > SKIP_S
    err = np.rad2deg(res.angles_rad - sim.angles_rad)[keep]
    rmse = np.sqrt(np.mean(err**2, axis=0))
    out["angle_rmse_deg"] = {
        side: {name: float(rmse[9 * i + k]) for k, name in enumerate(ANGLES)} for i, side in enumerate(SIDES)
    }
    out["joint_err"] = _joint_errors(res, sim.truth) | _length_errors(res, sim.truth)
    drift = res.gait.parameters.track_drift if res.gait.parameters is not None else None
    out["heading_spread"] = None if drift is None else drift.heading_spread
    out["used_mag"] = {s: bool(res.legs[s].used_mag) for s in SIDES}
    c_true = {s: np.asarray(sim.truth["legs"][s]["joints"]["hip"]["center_in_parent_sensor"]) for s in SIDES}
    out["hip_spacing_err_mm"] = 1000.0 * (
        res.hips.spacing_m - float(np.linalg.norm(c_true["right"] - c_true["left"]))
    )
    return out


def summarise_simulation(trials: list[dict[str, Any]]) -> dict[str, Any]:
    """Pooled event, stride and angle statistics over the simulated trials."""
    pooled: dict[str, Any] = {}
    for kind in ("initial_contact", "toe_off"):
        errs = [e for tr in trials for side in SIDES for e in tr[f"{side}_{kind}_ms"]]
        pooled[kind] = _stats(errs) | {
            "missed": sum(tr[f"{s}_{kind}_missed"] for tr in trials for s in SIDES)
        }
    for key in ("stride_length_pct", "step_width_mm", "step_length_mm"):
        pooled[key] = _stats([e for tr in trials for e in tr[key]])
    worst = {
        side: {name: max(tr["angle_rmse_deg"][side][name] for tr in trials) for name in ANGLES}
        for side in SIDES
    }
    median = {
        side: {name: float(np.median([tr["angle_rmse_deg"][side][name] for tr in trials])) for name in ANGLES}
        for side in SIDES
    }
    pooled["angle_rmse_deg"] = {"median": median, "worst": worst}
    pooled["hip_spacing_err_mm"] = _stats([tr["hip_spacing_err_mm"] for tr in trials])
    pooled["joints"] = {
        label: _stats([e for tr in trials for e in tr["joint_err"][label]])
        for label in [q[2] for q in JOINT_QUANTITIES] + list(LENGTH_LABELS)
    }
    return pooled


def real(data: Path) -> dict[str, Any]:
    """The real-walk numbers of ``bilateral_gait.py`` and ``gait_events.py``."""
    bg = _module("bilateral_gait").run(data)
    ge = _module("gait_events").run(data)
    return {"bilateral_gait": bg, "gait_events": ge}


def _fmt(x: float, unit: str = "") -> str:
    return "–" if x is None or not np.isfinite(x) else f"{x:.1f}{unit}"


def _pace_text(sim: dict[str, Any]) -> str:
    """``"slow pace (…), "`` for a slow walker, ``"knees that turn … "`` for non-hinge knees, else ``""``."""
    knee = sim.get("knee_rotation_per_flexion", 0.0)
    out = (
        f"**knees that turn inwards as they flex** (`knee_rotation_per_flexion={knee:g}`: no hinge; "
        "the truth's knee axis is the flexion axis), "
        if knee
        else ""
    )
    stops = sim.get("stops", 0)
    if stops:
        out += (
            f"**{stops} stops** of {sim['stop_s']:g} s each (`stops=PauseParams(count={stops})`: slowed to a "
            "halt in double support, standing, walking on; the stride that spans a stop is not scored), "
        )
    if sim.get("pace", "normal") == "normal":
        return out
    r = PACE_RANGES[sim["pace"]]
    return out + (
        f'**{sim["pace"]} pace** (`pace="{sim["pace"]}"`: {r.speed_m_s[0]:g}–{r.speed_m_s[1]:g} m/s, '
        f"stride {r.stride_time_s[0]:g}–{r.stride_time_s[1]:g} s, stance "
        f"{100 * r.stance_fraction[0]:.0f}–{100 * r.stance_fraction[1]:.0f} %), "
    )


def markdown(res: dict[str, Any]) -> str:
    seeds = res["simulated"]["seeds"]
    L = [
        "# Both legs: issue 11's goals on simulated seven-IMU walks and on the real walk",
        "",
        f"Simulated: `simulate_bilateral` seeds {', '.join(map(str, seeds))}, "
        f"{res['simulated']['duration_s']:g} s each, {_pace_text(res['simulated'])}realistic noise, "
        + (
            "in one uniform magnetic field (`lab_field=None`: the magnetometer is fused, 9-axis; "
            "no real lab was this kind, `docs/limits.md`), "
            if res.get("uniform_field")
            else "in a lab whose magnetic field varies near the floor as the real walk's did "
            "(`simulation/magnetic_field.py`; the check rejects the magnetometer, so every walk "
            "runs 6-axis, as the real one), "
        )
        + f"scored after {SKIP_S:g} s (standing and the first step). "
        + (
            "The real walk: `gait.md`."
            if res.get("uniform_field")
            else "Real: `gait/` (Xsens + Vicon), straight walking."
        ),
        "",
        "## Simulated (truth: the simulator's heel contacts, toe-offs, ankle centres and angles)",
        "",
    ]
    L += _simulated_lines(res["simulated"])
    r = res.get("real")
    if r:
        L += _real_lines(r)
    return "\n".join(L) + "\n"


def _simulated_lines(sim: dict[str, Any]) -> list[str]:
    """The simulated walks' tables: pooled events and strides, joints, angles, per trial."""
    g = GOALS
    s = sim["pooled"]
    L = [
        "| quantity | n | median abs | worst abs | bias | goal | met |",
        "|---|---|---|---|---|---|---|",
    ]
    for key, unit, goal in (
        ("initial_contact", " ms", g["sim_event_median_ms"]),
        ("toe_off", " ms", g["sim_event_median_ms"]),
        ("stride_length_pct", " %", g["sim_stride_length_pct"]),
        ("step_width_mm", " mm", None),
        ("step_length_mm", " mm", None),
        ("hip_spacing_err_mm", " mm", None),
    ):
        st = s[key]
        met = "" if goal is None else ("yes" if st["median_abs"] <= goal else "**no**")
        L.append(
            f"| {key} | {st['n']} | {_fmt(st['median_abs'], unit)} | {_fmt(st['worst_abs'], unit)} | "
            f"{_fmt(st['bias'], unit)} | {'' if goal is None else f'≤ {goal:g}{unit} median'} | {met} |"
        )
    L += ["", "Calibrated joints of both legs against the truth (all legs of all trials):", ""]
    L += ["| quantity | n | median abs | worst abs | bias |", "|---|---|---|---|---|"]
    for label, st in s["joints"].items():
        bias = _fmt(st["bias"]) if label in LENGTH_LABELS else ""
        L.append(f"| {label} | {st['n']} | {_fmt(st['median_abs'])} | {_fmt(st['worst_abs'])} | {bias} |")
    L += ["", "Angle RMSE, degrees (median over trials / worst trial):", ""]
    L += ["| side | " + " | ".join(ANGLES) + " |", "|---|" + "---|" * len(ANGLES)]
    for side in SIDES:
        cells = []
        for name in ANGLES:
            med, worst = s["angle_rmse_deg"]["median"][side][name], s["angle_rmse_deg"]["worst"][side][name]
            goal = (
                g["sim_flexion_rmse_deg"]
                if name.endswith(("flexion", "dorsiflexion"))
                else g["sim_other_rmse_deg"]
            )
            mark = "" if worst <= goal else "*"
            cells.append(f"{med:.2f} / {worst:.2f}{mark}")
        L.append(f"| {side} | " + " | ".join(cells) + " |")
    L += ["", "`*` the worst trial misses the goal (flexion ≤ 2°, others ≤ 3°).", ""]
    L += [
        "Per trial:",
        "",
        "| seed | IC median ms | TO median ms | stride % median | wall s |",
        "|---|---|---|---|---|",
    ]
    for tr in sim["trials"]:
        ic = _stats(tr["left_initial_contact_ms"] + tr["right_initial_contact_ms"])["median_abs"]
        to = _stats(tr["left_toe_off_ms"] + tr["right_toe_off_ms"])["median_abs"]
        sl = _stats(tr["stride_length_pct"])["median_abs"]
        L.append(f"| {tr['seed']} | {_fmt(ic)} | {_fmt(to)} | {_fmt(sl)} | {tr['wall_s']:.1f} |")
    return L


def _real_lines(r: dict[str, Any]) -> list[str]:
    """The real walk's table (``bilateral_gait.py`` and ``gait_events.py``)."""
    g = GOALS
    bg, ge = r["bilateral_gait"], r["gait_events"]
    L: list[str] = []
    L += [
        "",
        "## Real walk (gait/, S02 Walk-1)",
        "",
        "| quantity | value | goal | met |",
        "|---|---|---|---|",
    ]
    L.append(
        f"| both legs calibrate | {bg.get('both_legs_calibrate')} | yes | "
        f"{'yes' if bg.get('both_legs_calibrate') else '**no**'} |"
    )
    for side, leg in bg.get("legs", {}).items():
        for seg in ("thigh", "shank"):
            e = leg.get(f"{seg}_err_mm", float("nan"))
            met = "yes" if abs(e) <= g["real_length_mm"] else "**no**"
            L.append(f"| {side} {seg} length error | {e:+.0f} mm | ≤ {g['real_length_mm']:g} mm | {met} |")
    for name, st in ge["events"].items():
        if "vs" in name:
            continue
        stt = st["straight"]
        met = (
            "yes"
            if stt["median_abs_ms"] <= g["real_event_median_ms"]
            and stt["worst_abs_ms"] <= g["real_event_worst_ms"]
            else "**no**"
        )
        L.append(
            f"| {name} (straight, n={stt['n']}) | median {_fmt(stt['median_abs_ms'])} / worst "
            f"{_fmt(stt['worst_abs_ms'])} / bias {_fmt(stt['bias_ms'])} ms | ≤ 20 / 40 ms | {met} |"
        )
    for key, goal, unit in (
        ("stride_length_err_pct", g["real_stride_length_pct"], "%"),
        ("step_width_err_mm", g["real_step_width_mm"], "mm"),
    ):
        st = bg.get(key, {})
        med, worst = st.get("median_abs", float("nan")), st.get("worst_abs", float("nan"))
        met = "yes" if med <= goal else "**no**"
        L.append(
            f"| {key} (n={st.get('n', 0)}) | median {_fmt(med)} / worst {_fmt(worst)} "
            f"{unit} | ≤ {goal:g} {unit} | {met} |"
        )
    return L


def _compare_row(label: str, rigid: dict[str, float], art: dict[str, float], unit: str) -> str:
    """One row of the rigid-vs-artefacts table: n, median and worst of each."""
    return (
        f"| {label} | {rigid['n']} / {art['n']} | {_fmt(rigid['median_abs'], unit)} / "
        f"{_fmt(rigid['worst_abs'], unit)} | {_fmt(art['median_abs'], unit)} / "
        f"{_fmt(art['worst_abs'], unit)} |"
    )


def markdown_artefacts(res: dict[str, Any]) -> str:
    """Rigid versus ``Artefacts.real_walk()`` on the same seeds, then the artefact walks in full."""
    art, rigid = res["simulated"], res["rigid"]
    a, r = art["pooled"], rigid["pooled"]
    L = [
        "# Both legs with the simulator's real-walk artefacts",
        "",
        "`simulate_bilateral(..., artefacts=Artefacts.real_walk())` seeds "
        f"{', '.join(map(str, art['seeds']))}, "
        f"{art['duration_s']:g} s each, {_pace_text(art)}realistic noise: heel-strike impacts at "
        "each foot's contacts, "
        "wobbling soft tissue, skin motion, clock offset and jitter, scale and misalignment of all "
        "seven sensors. The same seeds rigid (same placements, walk and noise) alongside; "
        f"scored after {SKIP_S:g} s as `gait.md`.",
        "",
        "## Rigid versus artefacts (n, median abs / worst abs)",
        "",
        "| quantity | n rigid / art | rigid | artefacts |",
        "|---|---|---|---|",
    ]
    for key, unit in (
        ("initial_contact", " ms"),
        ("toe_off", " ms"),
        ("stride_length_pct", " %"),
        ("step_width_mm", " mm"),
        ("step_length_mm", " mm"),
        ("hip_spacing_err_mm", " mm"),
    ):
        L.append(_compare_row(key, r[key], a[key], unit))
    for kind in ("initial_contact", "toe_off"):
        L.append(f"| {kind} missed | | {r[kind]['missed']} | {a[kind]['missed']} |")
    for label in a["joints"]:
        L.append(_compare_row(label, r["joints"][label], a["joints"][label], ""))
    for side in SIDES:
        for name in ANGLES:
            med_r, w_r = (r["angle_rmse_deg"][k][side][name] for k in ("median", "worst"))
            med_a, w_a = (a["angle_rmse_deg"][k][side][name] for k in ("median", "worst"))
            L.append(
                f"| {side} {name} RMSE, deg (median / worst trial) | | {med_r:.2f} / {w_r:.2f} | "
                f"{med_a:.2f} / {w_a:.2f} |"
            )
    n_warn = (sum(tr["warnings"] for tr in rigid["trials"]), sum(tr["warnings"] for tr in art["trials"]))
    L.append(f"| warnings (all trials) | | {n_warn[0]} | {n_warn[1]} |")
    n_ref = [sum(bool(tr.get("side_check_refused")) for tr in x["trials"]) for x in (rigid, art)]
    L.append(f"| trials the side check refused (scored with it off) | | {n_ref[0]} | {n_ref[1]} |")
    n_op = [sum(bool(tr.get("one_pelvis_refused")) for tr in x["trials"]) for x in (rigid, art)]
    L.append(f"| trials whose knees pointed apart (each leg kept its own pelvis) | | {n_op[0]} | {n_op[1]} |")
    L += _per_trial_lines(rigid["trials"], art["trials"])
    L += ["", "## With artefacts, in full", ""]
    L += _simulated_lines(art)
    return "\n".join(L) + "\n"


def _per_trial_lines(rigid: list[dict[str, Any]], art: list[dict[str, Any]]) -> list[str]:
    """Per seed, rigid → artefacts: worst angle RMSE and the knee axis error of each leg."""
    L = [
        "",
        "Per trial, rigid → artefacts (worst angle RMSE of each leg, deg; knee axis error "
        "left / right, deg):",
        "",
        "| seed | worst angle left | worst angle right | knee axis | warnings |",
        "|---|---|---|---|---|",
    ]
    for r, a in zip(rigid, art, strict=True):

        def worst(tr: dict[str, Any], side: str) -> str:
            rm = tr["angle_rmse_deg"][side]
            name = max(rm, key=rm.get)
            return f"{rm[name]:.1f} ({name})"

        def knee(tr: dict[str, Any]) -> str:
            return " / ".join(f"{e:.1f}" for e in tr["joint_err"]["knee axis, deg"])

        L.append(
            f"| {a['seed']} | {worst(r, 'left')} → {worst(a, 'left')} | {worst(r, 'right')} → "
            f"{worst(a, 'right')} | {knee(r)} → {knee(a)} | {r['warnings']} → {a['warnings']} |"
        )
    return L


def _simulated(
    seeds: list[int], duration_s: float, artefacts: Artefacts | None, pace: str = "normal"
) -> dict[str, Any]:
    """Score every seed (with the realism profile ``artefacts``, if any) and pool the results."""
    trials = [score_simulation(seed, duration_s, artefacts, pace=pace) for seed in seeds]
    return {
        "seeds": seeds,
        "duration_s": duration_s,
        "pace": pace,
        "pooled": summarise_simulation(trials),
        "trials": trials,
    }


def _main_artefacts(args: argparse.Namespace) -> None:
    """``--artefacts real``: the same seeds with ``Artefacts.real_walk()`` and rigid."""
    res: dict[str, Any] = {
        "goals": GOALS,
        "profile": Artefacts.real_walk().to_dict(),
        "simulated": _simulated(args.seeds, args.duration, Artefacts.real_walk(), args.pace),
        "rigid": _simulated(args.seeds, args.duration, None, args.pace),
    }
    name = "gait_artefacts" if args.pace == "normal" else f"gait_{args.pace}_artefacts"
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / f"{name}.json").write_text(json.dumps(res, indent=1, default=float) + "\n")
    (args.out / f"{name}.md").write_text(markdown_artefacts(res))
    print(markdown_artefacts(res))


def add_walk_arguments(ap: argparse.ArgumentParser) -> None:
    """``--data``, ``--seeds``, ``--duration`` and ``--out`` of the seven-IMU walk benchmarks."""
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--seeds", type=int, nargs="+", default=[201, 202, 203, 204, 205, 206])
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_walk_arguments(ap)
    ap.add_argument(
        "--artefacts",
        choices=("none", "real"),
        default="none",
        help="real: simulated walks with Artefacts.real_walk(), compared with the same seeds rigid "
        "(writes gait_artefacts.{md,json}; the real walk is not re-run)",
    )
    ap.add_argument(
        "--uniform-field",
        action="store_true",
        help="simulate one uniform magnetic field instead of the lab's (9-axis fusion; writes "
        "gait_uniform_field.{md,json}; the real walk is not re-run)",
    )
    ap.add_argument(
        "--pace",
        choices=PACES,
        default="normal",
        help="the simulated walker's pace; slow (shuffle) writes gait_slow.{md,json} "
        "(gait_slow_artefacts with --artefacts real; the real walk is not re-run)",
    )
    ap.add_argument(
        "--stops",
        type=int,
        default=0,
        help="the walker stops this many times (3 s each) and walks on (writes gait_stops.{md,json}; "
        "the real walk is not re-run)",
    )
    ap.add_argument(
        "--knee-rotation",
        type=float,
        default=0.0,
        help="knees that turn inwards by this many rad per rad of flexion, as real knees do (0.2: "
        "about 11° over a stride; writes gait_knee_rotation.{md,json}; the real walk is not re-run)",
    )
    args = ap.parse_args()
    if args.artefacts == "real":
        _main_artefacts(args)
        return
    trials = [
        score_simulation(
            seed,
            args.duration,
            uniform_field=args.uniform_field,
            pace=args.pace,
            knee_rotation=args.knee_rotation,
            stops=PauseParams(count=args.stops) if args.stops else None,
        )
        for seed in args.seeds
    ]
    res: dict[str, Any] = {
        "goals": GOALS,
        "uniform_field": args.uniform_field,
        "simulated": {
            "seeds": args.seeds,
            "duration_s": args.duration,
            "pace": args.pace,
            "knee_rotation_per_flexion": args.knee_rotation,
            "stops": args.stops,
            "stop_s": PauseParams().pause_s,
            "pooled": summarise_simulation(trials),
            "trials": trials,
        },
    }
    variant = args.uniform_field or args.pace != "normal" or args.knee_rotation != 0.0 or args.stops
    if (args.data / "gait").is_dir() and not variant:
        res["real"] = real(args.data)
    name = "gait_uniform_field" if args.uniform_field else "gait"
    if args.pace != "normal":
        name = f"gait_{args.pace}"
    if args.knee_rotation != 0.0:
        name = "gait_knee_rotation"
    if args.stops:
        name = "gait_stops"
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / f"{name}.json").write_text(json.dumps(res, indent=1, default=float) + "\n")
    (args.out / f"{name}.md").write_text(markdown(res))
    print(markdown(res))


if __name__ == "__main__":
    main()
