"""Walks without a standing start: a two-leg recording cut so that it starts mid-stride.

The trial format asks for 1 s of standing still at the start; a recording cut from a
longer one (or started late) has none, and ``calibrate`` must still calibrate it with one
warning (docs/formats.md). Each walk is scored whole and cut:

- simulated: ``simulate_bilateral`` seeds 201–206, 60 s at 100 Hz; cut at the middle of
  the first right swing after 5 s (the right foot at full speed, the knee flexed). Scored
  against the truth: whether it calibrates, the knee axis error of each leg, stride length
  and events (matched within 0.2 s; whole and cut alike from the cut on), and whether step
  width is given (the simulated walks
  end walking, so a cut one has no standing anchor and its step width is ``null``);
- real: the walk of ``gait/`` (Xsens, 100 Hz, standing start, two passes and a turn,
  standing end) cut 0.3, 0.9 and 1.4 s after walking begins; segment lengths, stride length
  and step width against Vicon, events against the marker events (Zeni et al. 2008) as
  ``bilateral_gait.py`` and ``gait_rate.py`` score them. Cut, the feet are not anchored to
  each other (``UnanchoredFeetWarning``): step width is ``null``. (Anchored at the walk's
  standing end instead, as an earlier fallback did, the step width came out 94-145 mm off.)

Usage: ``python benchmarks/cut_start.py [--data DIR] [--out DIR]``; writes
``benchmarks/results/cut_start.{md,json}``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import warnings
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from lowerlimb.bilateral import UnanchoredFeetWarning, process_bilateral_trial
from lowerlimb.calibration.fit_band import segment_lengths_m
from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.trial import StandingStartWarning
from lowerlimb.model.fallback import segment_lengths
from lowerlimb.simulation import simulate_bilateral

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bilateral_gait as BG  # noqa: E402
from _realwalk import WALK, load_vicon, raw_dir  # noqa: E402
from _results import write_results  # noqa: E402
from gait_rate import _real_events  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SEEDS = (201, 202, 203, 204, 205, 206)
MATCH_S = 0.2
#: the real walk's cuts, s after walking begins (``_realwalk.WALK``)
REAL_CUTS_S = (0.3, 0.9, 1.4)


def _run(trial: BilateralTrial, **kw: Any) -> tuple[Any, dict[str, int]]:
    """The two-leg pipeline and the count of the two warnings of interest (``None`` if refused)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = process_bilateral_trial(trial, **kw)
        except Exception as e:  # noqa: BLE001 — a refusal is a result here
            return f"{type(e).__name__}: {e}", {}
    count = {
        "standing_start": sum(issubclass(w.category, StandingStartWarning) for w in caught),
        "unanchored": sum(issubclass(w.category, UnanchoredFeetWarning) for w in caught),
    }
    return res, count


def _matched(true_s: np.ndarray, est_s: np.ndarray) -> np.ndarray:
    """Signed error (est − true) of the nearest estimate within MATCH_S, ms (unmatched dropped)."""
    out = []
    for t in true_s:
        if est_s.size and np.min(np.abs(est_s - t)) <= MATCH_S:
            out.append(1000.0 * float(est_s[np.argmin(np.abs(est_s - t))] - t))
    return np.asarray(out)


def _stats(x: np.ndarray) -> dict[str, float]:
    a = np.abs(x[np.isfinite(x)])
    return (
        {"n": int(a.size), "median_abs": float(np.median(a)), "worst_abs": float(a.max())}
        if a.size
        else {"n": 0}
    )


def score_sim(sim: Any, res: Any, t0: float, t_from: float) -> dict[str, Any]:
    """Knee axes, stride lengths and events of a simulated walk whose trial starts at ``t0`` (s).

    Strides and events are scored from ``t_from`` (s, the cut) on, whole or cut alike.
    """
    out: dict[str, Any] = {}
    cal = res.calibration_dict()["legs"]
    for side in ("left", "right"):
        est = np.asarray(cal[side]["joints"]["knee"]["axis_in_parent_sensor"])
        tru = np.asarray(sim.truth["legs"][side]["joints"]["knee"]["axis_in_parent_sensor"])
        out[f"{side}_knee_axis_deg"] = float(np.degrees(np.arccos(np.clip(est @ tru, -1.0, 1.0))))
        j = sim.truth["legs"][side]["joints"]
        true_leg = SimpleNamespace(
            hip=SphericalJointCalibration.from_dict(j["hip"], "hip"),
            knee=HingeJointCalibration.from_dict(j["knee"]),
            ankle=SphericalJointCalibration.from_dict(j["ankle"], "ankle"),
        )
        err = 1000.0 * np.subtract(segment_lengths(res.legs[side].calibration), segment_lengths_m(true_leg))
        out[f"{side}_thigh_err_mm"], out[f"{side}_shank_err_mm"] = (float(e) for e in err)
        out[f"{side}_widened"] = bool(res.legs[side].calibration.fit_band.widened)
    strides = res.gait.parameters.strides if res.gait.parameters is not None else []
    length, width = [], []
    for st in sim.gait.strides:
        c = [s for s in strides if s.side == st.side and abs(s.start_s + t0 - st.start_s) < MATCH_S]
        if c and st.start_s > t_from:
            length.append(100.0 * (c[0].stride_length_m - st.stride_length_m) / st.stride_length_m)
            width.append(1000.0 * (c[0].step_width_m - st.step_width_m))
    out["stride_length_pct"] = _stats(np.asarray(length))
    out["step_width_mm"] = _stats(np.asarray(width))
    out["step_width_given"] = int(np.isfinite(width).sum())
    ic, to = [], []
    for side in ("left", "right"):
        se, truth = getattr(res.gait.events, side), sim.feet[side].events
        keep = lambda x: x[x > t_from + 0.5]  # noqa: E731 — events after the cut
        ic.append(_matched(keep(np.asarray(truth.initial_contact_s)), se.initial_contact_s + t0))
        to.append(_matched(keep(np.asarray(truth.toe_off_s)), se.toe_off_s + t0))
    out["initial_contact_ms"] = _stats(np.concatenate(ic))
    out["toe_off_ms"] = _stats(np.concatenate(to))
    return out


def simulated(seeds: tuple[int, ...]) -> list[dict[str, Any]]:
    """Each seed whole and cut mid-swing."""
    rows = []
    for seed in seeds:
        sim = simulate_bilateral(60.0, seed)
        ev = sim.feet["right"].events
        to = float(ev.toe_off_s[ev.toe_off_s > 5.0][0])
        ic = float(ev.initial_contact_s[ev.initial_contact_s > to][0])
        k0 = int(round(0.5 * (to + ic) * sim.trial.rate_hz))
        for label, trial, t0 in (
            ("whole", sim.trial, 0.0),
            ("cut", sim.trial.from_sample(k0), k0 / sim.trial.rate_hz),
        ):
            res, count = _run(trial)
            row: dict[str, Any] = {"seed": seed, "trial": label, "cut_s": t0, "warnings": count}
            if isinstance(res, str):
                row["refused"] = res
            else:
                row |= score_sim(sim, res, t0, k0 / sim.trial.rate_hz)
            rows.append(row)
            print(seed, label, "done", flush=True)
    return rows


def real(data: Path) -> list[dict[str, Any]]:
    """The real walk whole and cut after walking begins, against Vicon."""
    vicon = load_vicon(data)
    ge = BG._gait_events_module()
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "walk7.csv"
        BG.load_xsens(raw_dir(data), BG.IDS).to_csv(csv)
        full = BilateralTrial.from_csv(csv)
    rows = []
    for after in (None, *REAL_CUTS_S):
        k0 = 0 if after is None else int(WALK.start + round(after * full.rate_hz))
        # the clock is kept: Vicon's events and frames are on it
        trial = BilateralTrial(
            full.time_s[k0:],
            {s: a[k0:] for s, a in full.acc.items()},
            {s: g[k0:] for s, g in full.gyr.items()},
        )
        res, count = _run(trial, use_mag=False)
        row: dict[str, Any] = {"cut_after_walk_start_s": after, "warnings": count}
        if isinstance(res, str):
            row["refused"] = res
            rows.append(row)
            continue
        for side in ("left", "right"):
            P = side[0].upper()
            thigh, shank = segment_lengths(res.legs[side].calibration)
            v_thigh = float(np.nanmedian(np.linalg.norm(vicon[P + "HJC"] - vicon[P + "KJC"], axis=1)))
            v_shank = float(np.nanmedian(np.linalg.norm(vicon[P + "KJC"] - vicon[P + "AJC"], axis=1)))
            row[f"{side}_thigh_err_mm"] = 1000 * thigh - v_thigh
            row[f"{side}_shank_err_mm"] = 1000 * shank - v_shank
        st = BG.score_strides(res, vicon, ge)
        row["stride_length_err_pct"] = st["stride_length_err_pct"]
        row["step_width_err_mm"] = st["step_width_err_mm"]
        row["events_ms"] = _real_events(res, vicon, ge)
        rows.append(row)
        print("real", after, "done", flush=True)
    return rows


def _c(s: dict[str, Any], unit: str = "") -> str:
    return f"{s['median_abs']:.1f} / {s['worst_abs']:.1f}{unit}" if s.get("n") else "–"


def _yes(flag: bool) -> str:
    return "yes" if flag else "no"


def markdown(res: dict[str, Any]) -> str:
    L = [
        "# Walks without a standing start (cut mid-stride)",
        "",
        "Generated by `benchmarks/cut_start.py`. A two-leg trial cut so that it starts mid-stride",
        "has no standing start: no gyro bias is removed, the first second is the angle reference",
        "(one `StandingStartWarning`), the orientation filters are warm-started, and the feet are not",
        "anchored to each other (one `UnanchoredFeetWarning`; step length and width `null`).",
        "",
        "## Simulated (seeds 201–206, 60 s, 100 Hz; cut at the middle of the first right swing after 5 s)",
        "",
        "| seed | trial | knee axis L / R deg | thigh L / R mm | shank L / R mm | widened band L / R "
        "| stride length % | IC ms | TO ms | step width mm (given) | warnings: standing / unanchored |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res["simulated"]:
        w = r["warnings"]
        if "refused" in r:
            L.append(f"| {r['seed']} | {r['trial']} | refused: {r['refused'][:80]} | | | | | | | | |")
            continue
        L.append(
            f"| {r['seed']} | {r['trial']} | "
            f"{r['left_knee_axis_deg']:.1f} / {r['right_knee_axis_deg']:.1f} | "
            f"{r['left_thigh_err_mm']:+.0f} / {r['right_thigh_err_mm']:+.0f} | "
            f"{r['left_shank_err_mm']:+.0f} / {r['right_shank_err_mm']:+.0f} | "
            f"{_yes(r['left_widened'])} / {_yes(r['right_widened'])} | "
            f"{_c(r['stride_length_pct'])} | {_c(r['initial_contact_ms'])} | {_c(r['toe_off_ms'])} | "
            f"{_c(r['step_width_mm'])} ({r['step_width_given']}) | "
            f"{w['standing_start']} / {w['unanchored']} |"
        )
    L += [
        "",
        "Cells: median / worst absolute error. Knee axis: angle to the true axis in the thigh sensor. "
        "Lengths: hip and ankle centre to the knee axis line, signed error against the truth. Widened "
        "band: the leg's joints were fitted with the rigid-band caps widened (its knee showed rigid "
        "sensors: at the standing start, or since 0.5.15 over the motion without one).",
        "",
        "## Real walk (`gait/`, against Vicon; cut s after walking begins)",
        "",
        "| cut | thigh L / R mm | shank L / R mm | stride length % | step width mm | IC L / R ms "
        "| TO L / R ms | warnings: standing / unanchored |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in res["real"]:
        name = "whole" if r["cut_after_walk_start_s"] is None else f"+{r['cut_after_walk_start_s']:.1f} s"
        if "refused" in r:
            L.append(f"| {name} | refused: {r['refused'][:80]} | | | | | | |")
            continue
        ev, w = r["events_ms"], r["warnings"]

        def e(k: str, ev: dict[str, Any] = ev) -> str:
            s = ev[k]
            return f"{s['median_abs_ms']:.0f} / {s['worst_abs_ms']:.0f}" if s.get("n") else "–"

        sl, sw = r["stride_length_err_pct"], r["step_width_err_mm"]
        L.append(
            f"| {name} | {r['left_thigh_err_mm']:+.0f} / {r['right_thigh_err_mm']:+.0f} | "
            f"{r['left_shank_err_mm']:+.0f} / {r['right_shank_err_mm']:+.0f} | "
            f"{_c(sl)} | {_c(sw, '') if sw.get('n') else 'null'} | "
            f"{e('left_initial_contact')}; {e('right_initial_contact')} | "
            f"{e('left_toe_off')}; {e('right_toe_off')} | "
            f"{w['standing_start']} / {w['unanchored']} |"
        )
    L += [
        "",
        "Cells: median / worst absolute error; segment lengths signed (IMU − Vicon).",
        "",
    ]
    return "\n".join(L)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--seeds", type=int, nargs="+", default=list(SEEDS))
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args()
    res = {"simulated": simulated(tuple(args.seeds)), "real": real(args.data)}
    write_results(args.out, "cut_start", res, markdown(res))


if __name__ == "__main__":
    main()
