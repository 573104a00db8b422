"""One leg's gait: events, stride length and cadence from a four-IMU trial, against the truth and Vicon.

A single-leg trial (pelvis, thigh, shank, foot of one side) gets that leg's ``events.csv``,
``stationary.csv`` and ``gait.json`` (:mod:`lowerlimb.gait.one_leg`): the two-leg stages for one
side, on the calibrated foot orientation and ankle centre. Scored here:

- simulated: each leg of seven-IMU walks (``simulate_bilateral``, seeds 201–203, 60 s) alone
  through ``process_trial`` (what ``lowerlimb calibrate`` runs on a four-sensor CSV): initial
  contact and toe-off against the simulator's events, stride length against its strides
  (matched by start, after the first 3 s), cadence (``120 / stride time``) against the true
  cadence;
- real: each leg of the real walk (``gait/``, Xsens MTw + Vicon) alone: initial contact and
  toe-off against the marker events (Zeni et al. 2008) on the straight passes, stride length
  against the Vicon ankle centres on the straight strides (as ``bilateral_gait.py`` scores the
  two-leg trial, whose figures are given beside).

    python benchmarks/one_leg_gait.py --data ../shared/data --out benchmarks/results
"""

from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from lowerlimb.conventions import SIDES
from lowerlimb.pipeline import process_trial
from lowerlimb.simulation.bilateral_walk import simulate_bilateral

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bilateral_gait  # noqa: E402
import gait as gait_benchmark  # noqa: E402
import real_gait  # noqa: E402
from _realwalk import load_vicon  # noqa: E402
from _results import cell, real_data_main  # noqa: E402

SIM_SEEDS = (201, 202, 203)
EVENTS = ("initial_contact", "toe_off")


def _quiet_leg(trial: Any) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return process_trial(trial)


def _sim() -> dict[str, Any]:
    events: dict[str, list[float]] = {k: [] for k in EVENTS}
    missed = {k: 0 for k in EVENTS}
    lengths, cadence, no_gait = [], [], 0
    for seed in SIM_SEEDS:
        sim = simulate_bilateral(60.0, seed)
        t0 = float(sim.trial.time_s[0])
        for side in SIDES:
            res = _quiet_leg(sim.trial.leg(side))
            if res.gait is None:
                no_gait += 1
                continue
            ev = getattr(res.gait.events, side)
            truth = sim.feet[side].events
            for name, true_s, est in (
                ("initial_contact", truth.initial_contact_s, ev.initial_contact_s - t0),
                ("toe_off", truth.toe_off_s, ev.toe_off_s - t0),
            ):
                errs, miss = gait_benchmark._event_errors(np.asarray(true_s), np.asarray(est))
                events[name] += errs
                missed[name] += miss
            lengths += [
                100.0 * (c.stride_length_m - st.stride_length_m) / st.stride_length_m
                for st, c in gait_benchmark.matched_strides(sim, res)
                if np.isfinite(c.stride_length_m) and not c.turning
            ]
            true_cadence = float(sim.truth["gait"]["cadence_steps_per_min"])
            cadence.append(float(res.gait.to_dict()["cadence_steps_per_min"]) - true_cadence)
    return {
        "events_ms": {k: bilateral_gait._stats(v) | {"missed": missed[k]} for k, v in events.items()},
        "stride_length_pct": bilateral_gait._stats(lengths),
        "cadence_err_steps_per_min": bilateral_gait._stats(cadence),
        "legs_without_gait": no_gait,
    }


def _real(data: Path) -> dict[str, Any]:
    vicon = load_vicon(data)
    ge = bilateral_gait._gait_events_module()
    sac, u, straight = ge.sacrum_walk(vicon)
    out: dict[str, Any] = {}
    for side in SIDES:
        res = _quiet_leg(real_gait.load_leg(data, side))
        if res.gait is None:
            out[side] = None
            continue
        ev = getattr(res.gait.events, side)
        ref = ge.zeni_events(vicon, sac, u, side)
        row: dict[str, Any] = {}
        for name, est in (("initial_contact", ev.initial_contact_s), ("toe_off", ev.toe_off_s)):
            frames = ref[name]
            along = straight[frames] & ge.footprint_straight(
                vicon, side, frames, after=name == "initial_contact"
            )
            row[name] = ge.stats_ms(ge.match(frames / ge.RATE, est)[along])
        strides = bilateral_gait.score_strides(res, vicon, ge)
        row["stride_length_pct"] = strides["stride_length_err_pct"]
        row["cadence_steps_per_min"] = res.gait.to_dict()["cadence_steps_per_min"]
        out[side] = row
    return out


def run(data: Path) -> dict[str, Any]:
    """The simulated legs and the real walk's legs, each alone."""
    two_legs = Path(__file__).resolve().parent / "results" / "bilateral_gait.json"
    return {
        "seeds": SIM_SEEDS,
        "simulated": _sim(),
        "real": _real(data),
        "two_legs": json.loads(two_legs.read_text()) if two_legs.is_file() else None,
    }


def markdown(res: dict[str, Any]) -> str:
    """The two tables."""
    s = res["simulated"]
    ev = s["events_ms"]
    lines = [
        "# One leg's gait: events, stride length and cadence from a four-IMU trial",
        "",
        "Generated by `benchmarks/one_leg_gait.py` (definitions in its docstring). Each leg alone "
        "through the single-leg pipeline, which now writes its `events.csv`, `stationary.csv` and "
        "`gait.json` (`lowerlimb.gait.one_leg`; step time, step length, step width and double support "
        "need the other foot and stay null; cadence is 120 / stride time).",
        "",
        f"## Simulated seven-IMU walks, each leg alone (seeds {', '.join(map(str, res['seeds']))}, 60 s)",
        "",
        "| initial contact ms, median (worst) | toe-off ms, median (worst) | missed | stride length %, "
        "median (worst) | cadence error steps/min, median (worst) | legs without gait |",
        "|---|---|---|---|---|---|",
        f"| {cell(ev['initial_contact']['median_abs'])} ({cell(ev['initial_contact']['worst_abs'])}) | "
        f"{cell(ev['toe_off']['median_abs'])} ({cell(ev['toe_off']['worst_abs'])}) | "
        f"{ev['initial_contact']['missed']} / {ev['toe_off']['missed']} | "
        f"{_mw(s['stride_length_pct'])} | {_mw(s['cadence_err_steps_per_min'])} | {s['legs_without_gait']} |",
        "",
        "## Real walk, each leg alone, against Vicon (straight passes)",
        "",
        "| leg | initial contact ms, median (worst) | toe-off ms, median (worst) | stride length %, median "
        "(worst) | strides | cadence steps/min |",
        "|---|---|---|---|---|---|",
    ]
    for side in SIDES:
        r = res["real"][side]
        if r is None:
            lines.append(f"| {side} | no gait | | | | |")
            continue
        ic, to, sl = r["initial_contact"], r["toe_off"], r["stride_length_pct"]
        lines.append(
            f"| {side} | {cell(ic.get('median_abs_ms'))} ({cell(ic.get('worst_abs_ms'))}) | "
            f"{cell(to.get('median_abs_ms'))} ({cell(to.get('worst_abs_ms'))}) | "
            f"{cell(sl.get('median_abs'), '.2f')} ({cell(sl.get('worst_abs'), '.2f')}) | {sl.get('n', 0)} | "
            f"{cell(r['cadence_steps_per_min'])} |"
        )
    two = res.get("two_legs")
    if two:
        lines += ["", f"Two-leg trial of the same walk (`bilateral_gait.md`): {_two_leg_text(two)}."]
    return "\n".join(lines + [""])


def _two_leg_text(two: dict[str, Any]) -> str:
    """The two-leg stride length figures, from ``bilateral_gait.json``, in words."""
    sl = two.get("stride_length_err_pct") or {}
    return f"stride length {_mw(sl)} %, median (worst)"


def _mw(stats: dict[str, Any], fmt: str = ".2f") -> str:
    """``median (worst)`` of absolute values."""
    return f"{cell(stats.get('median_abs'), fmt)} ({cell(stats.get('worst_abs'), fmt)})"


def main() -> None:
    real_data_main(__doc__, "one_leg_gait", run, markdown)


if __name__ == "__main__":
    main()
