"""Sampling rate: seven-IMU walks recorded at 50, 60, 100 and 200 Hz, with and without interpolation.

Many wearable systems record below 100 Hz (Movella DOT: 60 Hz by default; Xsens Awinda
with many sensors: 60 Hz). The joint calibration differentiates the gyros and finds
impacts on samples, and gait events are sample features, so a trial below
``CalibrationOptions.min_fit_rate_hz`` and ``GaitParams.min_event_rate_hz`` (100 Hz) is
interpolated, band-limited, to an integer multiple of its rate for those two stages only
(``lowerlimb.upsample``). This benchmark scores both ways:

- simulated: ``simulate_bilateral`` seeds 201–206, 60 s, at each rate (the simulator
  samples its kinematics at the rate), scored as ``gait.py`` scores them;
- real: the walk of ``gait/`` (Xsens, 100 Hz), resampled to 50 and 60 Hz
  (``scipy.signal.resample_poly``, anti-aliased), against Vicon as ``bilateral_gait.py``.

"interp" is the default (interpolated below 100 Hz); "recorded" calibrates and times the
events on the recorded samples (``min_fit_rate_hz=None``, ``min_event_rate_hz=None``); at
100 Hz and above the two are the same.

Usage: ``python benchmarks/gait_rate.py [--data DIR] [--seeds …] [--quick]``; writes
``benchmarks/results/gait_rate.{md,json}``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from scipy.signal import resample_poly

from lowerlimb.bilateral import process_bilateral_trial
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.gait import GaitParams
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.model.fallback import segment_lengths

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bilateral_gait as BG  # noqa: E402
from _realwalk import load_vicon, raw_dir  # noqa: E402
from _results import write_results  # noqa: E402
from gait import score_simulation, summarise_simulation  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: interpolated (the defaults) or on the recorded samples: (calibration options, gait params)
INTERP = (CalibrationOptions(), GaitParams())
RECORDED = (CalibrationOptions(min_fit_rate_hz=None), GaitParams(min_event_rate_hz=None))
#: (label, rate Hz, (calibration options, gait params))
CONFIGS = (
    ("50 Hz interp", 50.0, INTERP),
    ("50 Hz recorded", 50.0, RECORDED),
    ("60 Hz interp", 60.0, INTERP),
    ("60 Hz recorded", 60.0, RECORDED),
    ("100 Hz", 100.0, INTERP),
    ("200 Hz", 200.0, INTERP),
)
#: resampling of the real 100 Hz walk: (label, up, down, (calibration options, gait params))
REAL = (
    ("100 Hz (recorded)", 1, 1, INTERP),
    ("60 Hz interp", 3, 5, INTERP),
    ("60 Hz recorded", 3, 5, RECORDED),
    ("50 Hz interp", 1, 2, INTERP),
    ("50 Hz recorded", 1, 2, RECORDED),
)
SIM_ROWS = (
    ("initial_contact", "IC ms"),
    ("toe_off", "TO ms"),
    ("stride_length_pct", "stride %"),
    ("step_width_mm", "step width mm"),
    ("step_length_mm", "step length mm"),
)
JOINT_ROWS = (
    ("hip in thigh sensor, mm", "hip in thigh mm"),
    ("ankle in shank sensor, mm", "ankle in shank mm"),
    ("ankle in foot sensor, mm", "ankle in foot mm"),
    ("thigh length (hip to knee axis), mm", "thigh length mm"),
    ("shank length (ankle to knee axis), mm", "shank length mm"),
)


def simulated(seeds: list[int], duration_s: float) -> dict[str, Any]:
    """Each configuration's pooled scores over the seeds (``gait.summarise_simulation``)."""
    out = {}
    for label, rate, (opts, gp) in CONFIGS:
        kw = {"calibration_options": opts, "gait_params": gp, "rate_hz": rate}
        trials = [score_simulation(s, duration_s, **kw) for s in seeds]
        pooled = summarise_simulation(trials)
        worst = max(max(d.values()) for d in pooled["angle_rmse_deg"]["worst"].values())
        out[label] = {"rate_hz": rate, "pooled": pooled, "worst_angle_rmse_deg": worst}
        print(label, "done", flush=True)
    return out


def resampled(trial: BilateralTrial, up: int, down: int) -> BilateralTrial:
    """The trial at ``rate · up / down``, anti-aliased (``resample_poly``); no magnetometer."""
    if up == down:
        return BilateralTrial(trial.time_s, trial.acc, trial.gyr, None, source="real")

    def r(d: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {k: resample_poly(v, up, down, axis=0, padtype="line") for k, v in d.items()}

    acc, gyr = r(trial.acc), r(trial.gyr)
    n = next(iter(acc.values())).shape[0]
    time_s = trial.time_s[0] + np.arange(n) / (trial.rate_hz * up / down)
    return BilateralTrial(time_s, acc, gyr, None, source="real")


def _real_events(res: Any, vicon: dict, ge: Any) -> dict[str, dict[str, float]]:
    """Straight-pass initial contacts and toe-offs of each side against the marker events, ms.

    The marker events are Zeni et al. 2008's, as ``gait_events.py`` finds them.
    """
    sac, u, straight = ge.sacrum_walk(vicon)
    out = {}
    for side in ("left", "right"):
        ref = ge.zeni_events(vicon, sac, u, side)
        se = getattr(res.gait.events, side)
        for name, est in (("initial_contact", se.initial_contact_s), ("toe_off", se.toe_off_s)):
            fr = ref[name]
            along = straight[fr] & ge.footprint_straight(vicon, side, fr, after=name == "initial_contact")
            out[f"{side}_{name}"] = ge.stats_ms(ge.match(fr / ge.RATE, est)[along])
    return out


def real(data: Path, tmp: Path) -> dict[str, Any]:
    """The real walk at each resampling, scored against Vicon (lengths, stride, step width)."""
    vicon = load_vicon(data)
    ge = BG._gait_events_module()
    csv = tmp / "walk7.csv"
    BG.load_xsens(raw_dir(data), BG.IDS).to_csv(csv)
    full = BilateralTrial.from_csv(csv)
    out = {}
    for label, up, down, (opts, gp) in REAL:
        trial = resampled(full, up, down)
        res = process_bilateral_trial(trial, calibration_options=opts, gait_params=gp, use_mag=False)
        lengths = {}
        for side in ("left", "right"):
            P = side[0].upper()
            cal = res.legs[side].calibration
            thigh, shank = segment_lengths(cal)
            v_thigh = float(np.nanmedian(np.linalg.norm(vicon[P + "HJC"] - vicon[P + "KJC"], axis=1)))
            v_shank = float(np.nanmedian(np.linalg.norm(vicon[P + "KJC"] - vicon[P + "AJC"], axis=1)))
            lengths[side] = {"thigh_err_mm": 1000 * thigh - v_thigh, "shank_err_mm": 1000 * shank - v_shank}
        st = BG.score_strides(res, vicon, ge)
        out[label] = {
            "lengths": lengths,
            "stride_length_err_pct": st["stride_length_err_pct"],
            "step_width_err_mm": st["step_width_err_mm"],
            "events_ms": _real_events(res, vicon, ge),
        }
        print(label, "done", flush=True)
    return out


def _cell(s: dict[str, Any]) -> str:
    return f"{s['median_abs']:.1f} / {s['worst_abs']:.1f}" if s.get("n") else "–"


def _event_cell(e: dict[str, float]) -> str:
    return f"{e['median_abs_ms']:.1f} / {e['worst_abs_ms']:.1f}" if e.get("n") else "–"


def _row(name: str, cells: list[str]) -> str:
    return f"| {name} | " + " | ".join(cells) + " |"


def _head(labels: list[str]) -> list[str]:
    return [_row("quantity", labels), "|---|" + "---|" * len(labels)]


def markdown(res: dict[str, Any]) -> str:
    sim = res["simulated"]
    labels = list(sim)
    L = [
        "# Sampling rate: seven-IMU walks at 50–200 Hz, interpolated for the calibration or not",
        "",
        f"Simulated: `simulate_bilateral` seeds {', '.join(map(str, res['seeds']))}, "
        f"{res['duration_s']:g} s each, sampled at the rate; median / worst absolute error against "
        "the simulator's truth. *interp*: the default, a trial below `min_fit_rate_hz` (100 Hz) "
        "is interpolated (band-limited) to an integer multiple of its rate for the joint "
        "calibration and the gait events; *recorded*: both on the recorded samples "
        "(`min_fit_rate_hz=None`, `min_event_rate_hz=None`).",
        "",
        *_head(labels),
    ]
    L += [_row(name, [_cell(sim[k]["pooled"][key]) for k in labels]) for key, name in SIM_ROWS]
    L += [_row(name, [_cell(sim[k]["pooled"]["joints"][key]) for k in labels]) for key, name in JOINT_ROWS]
    L.append(_row("worst angle RMSE, deg", [f"{sim[k]['worst_angle_rmse_deg']:.2f}" for k in labels]))
    r = res.get("real")
    if r:
        rl = list(r)
        L += [
            "",
            "## Real walk (`gait/`, Xsens at 100 Hz, resampled), against Vicon",
            "",
            "Signed segment-length errors, mm; stride length and step width of the straight strides, "
            "median / worst absolute error; events of the straight passes against the marker events "
            "(Zeni et al. 2008, `gait_events.md`), median / worst absolute error.",
            "",
            *_head(rl),
        ]
        for side in ("left", "right"):
            for seg in ("thigh", "shank"):
                cells = [f"{r[k]['lengths'][side][f'{seg}_err_mm']:+.0f}" for k in rl]
                L.append(_row(f"{side} {seg} mm", cells))
        L.append(_row("stride length %", [_cell(r[k]["stride_length_err_pct"]) for k in rl]))
        L.append(_row("step width mm", [_cell(r[k]["step_width_err_mm"]) for k in rl]))
        for key in ("left_initial_contact", "left_toe_off", "right_initial_contact", "right_toe_off"):
            cells = [_event_cell(r[k]["events_ms"][key]) for k in rl]
            L.append(_row(f"{key.replace('_', ' ')} vs markers, ms", cells))
    return "\n".join(L) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--seeds", type=int, nargs="+", default=[201, 202, 203, 204, 205, 206])
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--quick", action="store_true", help="two seeds, 30 s, no real walk")
    args = ap.parse_args()
    if args.quick:
        args.seeds, args.duration = args.seeds[:2], 30.0
    warnings.simplefilter("ignore")
    res: dict[str, Any] = {"seeds": args.seeds, "duration_s": args.duration}
    res["simulated"] = simulated(args.seeds, args.duration)
    if not args.quick and (args.data / "gait").is_dir():
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            res["real"] = real(args.data, Path(tmp))
    write_results(args.out, "gait_rate", res, markdown(res))


if __name__ == "__main__":
    main()
