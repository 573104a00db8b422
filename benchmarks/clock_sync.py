"""Clock offsets between sensors: found from the joints, and what re-timing does to the calibration.

Four sources, each processed twice, with ``CalibrationOptions(clock_sync=False)`` and with
the default (``clock_sync=True``, :mod:`lowerlimb.calibration.clock_sync`):

- **clock only**: seven-IMU simulated walks (``simulate_bilateral``, seeds 201-206, 60 s,
  realistic noise) whose only artefact is a clock offset per sensor (σ 10 ms) with 0.5 ms
  jitter: what the re-timing can recover;
- **real-walk artefacts**: the same seeds with :meth:`Artefacts.real_walk` (impacts, soft
  tissue, skin motion, clock, scale, misalignment): whether it still helps when the joints
  are far from rigid;
- **real walk** (``gait/``, Xsens MTw on one clock): it must not re-time anything;
- **real walk with one sensor late** (its right shank or left thigh delayed 30 or 50 ms): the
  segment lengths against the walk as recorded, and the re-timing found.

Scored per leg and joint: the timing error of each joint's sensor pair (child lag
behind the parent, truth minus applied) before and after, and the error of the
calibrated joint centres and knee axis against the simulator's truth.

Usage: ``python benchmarks/clock_sync.py [--data ../shared/data] [--seeds 201 202 ...]``;
writes ``benchmarks/results/clock_sync.{md,json}``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from lowerlimb.bilateral import process_bilateral_trial
from lowerlimb.bilateral.pelvis import OppositeKneesWarning
from lowerlimb.calibration.clock_sync import retime
from lowerlimb.calibration.fit_band import segment_lengths_m
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import SIDES
from lowerlimb.io import load_xsens
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.simulation import Artefacts, simulate_bilateral

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _realwalk import IDS, raw_dir  # noqa: E402
from gait import JOINT_QUANTITIES as QUANTITIES  # noqa: E402
from gait import _joint_errors  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CHAIN = (("hip", "pelvis", "thigh"), ("knee", "thigh", "shank"), ("ankle", "shank", "foot"))


def _pair_lags(off: dict[str, float], side: str) -> dict[str, float]:
    """True lag of each joint's child behind its parent, s (sample stamped t taken at t + offset)."""
    name = {"pelvis": "pelvis", "thigh": f"{side}_thigh", "shank": f"{side}_shank", "foot": f"{side}_foot"}
    return {j: off[name[p]] - off[name[c]] for j, p, c in CHAIN}


def _applied_lags(shift: dict[str, float]) -> dict[str, float]:
    return {j: shift[c] - shift[p] for j, p, c in CHAIN}


def score_seed(seed: int, artefacts: Artefacts) -> dict[str, Any]:
    """One simulated walk processed without and with clock sync."""
    sim = simulate_bilateral(60.0, seed, artefacts=artefacts)
    assert sim.artefacts is not None
    off = sim.artefacts.clock_offset_s
    out: dict[str, Any] = {"seed": seed}
    for on in (False, True):
        t0 = time.perf_counter()
        kw: dict[str, Any] = {"calibration_options": CalibrationOptions(clock_sync=on), "side_check": False}
        key = "sync" if on else "plain"
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = process_bilateral_trial(sim.trial, **kw)
        # the legs' pelvis frames point apart (an undetermined hip turned a thigh's heading):
        # each leg kept its own pelvis, with a warning; counted, as gait.py does
        out[f"{key}_one_pelvis_refused"] = any(w.category is OppositeKneesWarning for w in caught)
        pair_err = []
        for side in SIDES:
            truth = _pair_lags(off, side)
            rec = res.legs[side].calibration.clock_offsets
            applied = _applied_lags(rec["shift_s"]) if rec else dict.fromkeys(truth, 0.0)
            pair_err += [1000.0 * (truth[j] - applied[j]) for j in truth]
        out[key] = {"pair_err_ms": pair_err, "joint_err": _joint_errors(res, sim.truth)}
        out[key]["wall_s"] = time.perf_counter() - t0
    return out


def real_walk(data: Path) -> dict[str, Any]:
    """The real walk's clock record (must apply nothing)."""
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "walk7.csv"
        load_xsens(raw_dir(data), IDS).to_csv(csv)
        trial = BilateralTrial.from_csv(csv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = process_bilateral_trial(trial)
    return {side: res.legs[side].calibration.clock_offsets for side in SIDES}


def late_sensors(data: Path) -> list[dict[str, Any]]:
    """The real walk with one sensor's signals delayed: segment lengths against the walk as recorded."""
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "walk7.csv"
        load_xsens(raw_dir(data), IDS).to_csv(csv)
        trial = BilateralTrial.from_csv(csv)

    def lengths(t: BilateralTrial, sync: bool) -> dict[str, Any]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = process_bilateral_trial(t, calibration_options=CalibrationOptions(clock_sync=sync))
        cals = {side: res.legs[side].calibration for side in SIDES}
        return {
            "lengths_m": {side: list(segment_lengths_m(c)) for side, c in cals.items()},
            "shift_s": {side: c.clock_offsets.get("shift_s", {}) for side, c in cals.items()},
            "late_sensor": {side: c.clock_offsets.get("late_sensor", {}) for side, c in cals.items()},
        }

    base = lengths(trial, True)
    rows = []
    for sensor in ("right_shank", "left_thigh"):
        for delay in (0.03, 0.05):
            late = retime(trial, {sensor: -delay})  # the signal at t is the recorded one at t - delay
            rows.append({"sensor": sensor, "delay_s": delay, "base": base}
                        | {k: lengths(late, k == "sync") for k in ("plain", "sync")})  # fmt: skip
    return rows


def _stats(x: list[float]) -> str:
    a = np.abs(np.asarray(x, dtype=float))
    return f"{np.median(a):.1f} / {np.max(a):.1f}"


def markdown(res: dict[str, Any]) -> str:
    L = [
        "# Clock offsets between sensors, from the joints",
        "",
        "Seven-IMU simulated walks, seeds " + ", ".join(str(s) for s in res["seeds"]) + ", 60 s, "
        "realistic noise; each processed with `clock_sync=False` and with the default "
        "(`lowerlimb/calibration/clock_sync.py`). Pair timing error: each joint's true child-behind-"
        "parent lag minus the re-timing applied, over the 6 joints of both legs. Median / worst "
        "absolute over all seeds.",
        "",
    ]
    for name, label in (("clock_only", "clock offsets only (σ 10 ms)"), ("artefacts", "real-walk artefacts")):
        trials = res[name]
        L += [f"## {label}", "", "| quantity | without | with clock sync |", "|---|---|---|"]
        L.append(
            "| pair timing error, ms | "
            + _stats([e for t in trials for e in t["plain"]["pair_err_ms"]])
            + " | "
            + _stats([e for t in trials for e in t["sync"]["pair_err_ms"]])
            + " |"
        )
        for _, _, q in QUANTITIES:
            L.append(
                f"| {q} | "
                + _stats([e for t in trials for e in t["plain"]["joint_err"][q]])
                + " | "
                + _stats([e for t in trials for e in t["sync"]["joint_err"][q]])
                + " |"
            )
        wall = [t["sync"]["wall_s"] - t["plain"]["wall_s"] for t in trials]
        refused = [
            f"{t['seed']} ({', '.join(k for k in ('plain', 'sync') if t.get(f'{k}_one_pelvis_refused'))})"
            for t in trials
            if t.get("plain_one_pelvis_refused") or t.get("sync_one_pelvis_refused")
        ]
        L += [
            "",
            f"Extra wall time of the two-leg processing with clock sync: median {np.median(wall):.1f} s.",
            "",
        ]
        if refused:
            L += [
                "Refused by the one-pelvis check (opposite knees), scored with each leg's own pelvis: "
                f"seed {'; '.join(refused)}.",
                "",
            ]
    if res.get("real"):
        L += [
            "## Real walk (`gait/`, Xsens MTw, one clock)",
            "",
            "| leg | joint | lag ms | explained | halves apart ms | counted |",
            "|---|---|---|---|---|---|",
        ]
        for side, rec in res["real"].items():
            for j, v in rec["joints"].items():
                L.append(
                    f"| {side} | {j} | {1000 * v['lag_s']:+.1f} | {v['explained']:.2f} | "
                    f"{1000 * v['split_s']:.1f} | {'yes' if v['counted'] else 'no'} |"
                )
        shifted = any(v != 0.0 for rec in res["real"].values() for v in rec["shift_s"].values())
        L += ["", f"Re-timed on the real walk: {'**yes**' if shifted else 'no'}.", ""]
    if res.get("late"):
        L += [
            "## Real walk with one sensor late",
            "",
            "One sensor's signals delayed; its leg's thigh / shank length minus the walk's as recorded "
            "(mm), without and with the clock search, and the re-timing the search applied (a sensor "
            "between two joints whose two uncounted lags agree is tried as a step of its own, "
            "`clock_offsets.late_sensor`).",
            "",
            "| sensor | delay ms | without clock sync | with | re-timed |",
            "|---|---|---|---|---|",
        ]
        for r in res["late"]:
            side = r["sensor"].split("_")[0]
            base = r["base"]["lengths_m"][side]

            def cells(run: dict[str, Any], base: list[float] = base, side: str = side) -> str:
                pairs = zip(run["lengths_m"][side], base, strict=True)
                return " / ".join(f"{1000 * (a - b):+.0f}" for a, b in pairs)

            moved = ", ".join(
                f"{s} {1000 * v:+.0f} ms" for s, v in r["sync"]["shift_s"][side].items() if v != 0.0
            )
            L.append(
                f"| {r['sensor']} | {1000 * r['delay_s']:.0f} | {cells(r['plain'])} | {cells(r['sync'])} | "
                f"{moved or 'no'} |"
            )
        L.append("")
    return "\n".join(L) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--seeds", type=int, nargs="+", default=[201, 202, 203, 204, 205, 206])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args()
    clock = dataclasses.replace(Artefacts(), clock_offset_std_s=0.01, clock_jitter_std_s=0.0005)
    res: dict[str, Any] = {"seeds": args.seeds}
    res["clock_only"] = [score_seed(s, clock) for s in args.seeds]
    res["artefacts"] = [score_seed(s, Artefacts.real_walk()) for s in args.seeds]
    res["real"] = real_walk(args.data) if (args.data / "gait").is_dir() else None
    res["late"] = late_sensors(args.data) if (args.data / "gait").is_dir() else None
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "clock_sync.json").write_text(json.dumps(res, indent=1))
    md = markdown(res)
    (args.out / "clock_sync.md").write_text(md)
    print(md)


if __name__ == "__main__":
    main()
