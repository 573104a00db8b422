"""Gait-lab walks with turns about: the seven-IMU pipeline through a turn, against its truth.

A gait lab's walkway is short, so a walk is straight passes with a 180° turn at each end (the
real walk of ``gait/`` has one). Each seed (201–203, 60 s, realistic noise, the lab's field) is
run twice and scored as ``gait.py`` scores it:

- **bending**: the default walk on a gently bending path (``gait.md``'s walks);
- **turns**: the same walker on straight passes of 6 s with a 180° turn of 2.4 s between them,
  each foot pivoting on the floor while flat (``simulate_bilateral(turns=TurnParams())``).

Strides are the truth's, matched to the pipeline's by their start; a stride whose length or
step width the pipeline leaves out (null in gait.json) is counted as *lost*. Strides are
split by whether the truth's stride touches a turn (starts within a stride time before a
turn's start or inside it).

``--pace slow`` (``turns_slow``) runs the same comparison for slow walkers.

Usage: ``python benchmarks/turns.py [--seeds …] [--duration S] [--pace normal|slow|shuffle]
[--out DIR]``; writes ``turns.{md,json}`` (or ``turns_<pace>``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import gait as G  # noqa: E402
from _results import write_results  # noqa: E402

from lowerlimb.simulation.footsteps import PACES  # noqa: E402
from lowerlimb.simulation.turns import TurnParams  # noqa: E402

VARIANTS = ("bending", "turns")


def _near_turn(starts: list[float], turn_s: float, stride_s: float, t: float) -> bool:
    return any(s - stride_s <= t <= s + turn_s for s in starts)


def run_variant(variant: str, seed: int, duration_s: float, pace: str = "normal") -> dict[str, Any]:
    """One seed's walk scored against its truth, its strides split by the turns."""
    turns = TurnParams() if variant == "turns" else None
    tr = G.score_simulation(seed, duration_s, turns=turns, pace=pace)
    turn_s = turns.turn_s if turns else 0.0
    near = [_near_turn(tr["turn_starts_s"], turn_s, tr["stride_time_s"], s) for s in tr["stride_start_s"]]
    tr["near_turn"] = near
    return tr


def _split(tr: dict[str, Any], key: str, near: bool) -> list[float]:
    return [e for e, n in zip(tr[key], tr["near_turn"], strict=True) if n == near]


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for kind in ("initial_contact", "toe_off"):
        out[kind] = G._stats([e for tr in rows for s in G.SIDES for e in tr[f"{s}_{kind}_ms"]])
        out[kind]["missed"] = sum(tr[f"{s}_{kind}_missed"] for tr in rows for s in G.SIDES)
    for where, near in (("straight", False), ("turn", True)):
        for key in ("stride_length_pct", "step_width_mm"):
            vals = [e for tr in rows for e in _split(tr, key, near)]
            out[f"{key}_{where}"] = G._stats(vals) | {"lost": int(sum(not np.isfinite(v) for v in vals))}
    # what gait.json summarises as straight: the strides and steps the pipeline does not call turning
    for key, flag in (("stride_length_pct", "stride_own_turning"), ("step_width_mm", "stride_turning")):
        vals = [e for tr in rows for e, turn in zip(tr[key], tr[flag], strict=True) if not turn]
        lost = int(sum(not np.isfinite(v) for v in vals))
        out[f"{key}_pipeline_straight"] = G._stats(vals) | {"lost": lost}
    out["angle_worst_deg"] = max(max(v.values()) for tr in rows for v in tr["angle_rmse_deg"].values())
    out["walker_turns"] = _walker_turns(rows)
    return out


def _walker_turns(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """gait.json's complete turns against the same detector on the true pelvis: counts and errors.

    A found turn matches the true turn of the same direction it overlaps most.
    """
    found = truth = wrong = 0
    err: dict[str, list[float]] = {"angle_deg": [], "start_ms": [], "end_ms": [], "peak_pct": []}
    for tr in rows:
        est = [t for t in tr.get("walker_turns", []) if t["complete"]]
        ref = [t for t in tr.get("walker_turns_truth", []) if t["complete"]]
        found, truth = found + len(est), truth + len(ref)
        for t in est:
            ov = [
                min(t["end_s"], r["end_s"]) - max(t["start_s"], r["start_s"])
                if r["direction"] == t["direction"]
                else 0
                for r in ref
            ]
            if not ov or max(ov) <= 0:
                wrong += 1
                continue
            r = ref[int(np.argmax(ov))]
            err["angle_deg"].append(t["angle_deg"] - r["angle_deg"])
            err["start_ms"].append(1000 * (t["start_s"] - r["start_s"]))
            err["end_ms"].append(1000 * (t["end_s"] - r["end_s"]))
            err["peak_pct"].append(100 * (t["peak_rate_deg_s"] / r["peak_rate_deg_s"] - 1))
    return {"found": found, "true": truth, "unmatched": wrong} | {k: G._stats(v) for k, v in err.items()}


def markdown(res: dict[str, Any]) -> str:
    L = [
        "# Walks with turns about: events, strides and angles through a turn",
        "",
        f"`simulate_bilateral` seeds {', '.join(map(str, res['seeds']))}, {res['duration_s']:g} s, "
        f"{'' if res.get('pace', 'normal') == 'normal' else '**' + res['pace'] + ' pace**, '}realistic "
        "noise, the lab's magnetic field; bending: the default gently bending path; turns: straight "
        "passes of 6 s and 180° turns of 2.4 s, each foot pivoting on the floor while flat "
        f"(`turns=TurnParams()`). Scored after {G.SKIP_S:g} s against the truth.",
        "",
        "| variant | IC ms | TO ms | stride % straight (lost) | stride % at turns (lost) | "
        "step width mm straight (lost) | step width mm at turns (lost) | stride %, gait.json's "
        "straight (lost) | step width mm, gait.json's straight (lost) | angles ° |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for v in VARIANTS:
        p = res["pooled"][v]

        def cell(key: str, p: dict[str, Any] = p) -> str:
            s = p[key]
            return f"{s['median_abs']:.1f} / {s['worst_abs']:.0f} of {s['n']} ({s['lost']})"

        L.append(
            f"| {v} | {p['initial_contact']['median_abs']:.1f} / {p['initial_contact']['worst_abs']:.0f} | "
            f"{p['toe_off']['median_abs']:.1f} / {p['toe_off']['worst_abs']:.0f} | "
            f"{cell('stride_length_pct_straight')} | {cell('stride_length_pct_turn')} | "
            f"{cell('step_width_mm_straight')} | {cell('step_width_mm_turn')} | "
            f"{cell('stride_length_pct_pipeline_straight')} | "
            f"{cell('step_width_mm_pipeline_straight')} | {p['angle_worst_deg']:.2f} |"
        )
    L += [
        "",
        "The walker's turns (gait.json's `turns`: the pelvis sensor's vertical rate smoothed over a "
        "stride, `lowerlimb.gait.turns`) against the same detector on the true pelvis, complete "
        "turns only (median / worst abs error):",
        "",
        "| variant | turns found / true (unmatched) | angle ° | start ms | end ms | peak rate % |",
        "|---|---|---|---|---|---|",
    ]
    for v in VARIANTS:
        w = res["pooled"][v]["walker_turns"]

        def err(key: str, w: dict[str, Any] = w) -> str:
            e = w[key]
            return f"{e['median_abs']:.1f} / {e['worst_abs']:.1f}" if e.get("n") else "–"

        L.append(
            f"| {v} | {w['found']} / {w['true']} ({w['unmatched']}) | {err('angle_deg')} | "
            f"{err('start_ms')} | {err('end_ms')} | {err('peak_pct')} |"
        )
    L += [
        "",
        "Events: median / worst abs error, ms. Strides and step widths: median / worst abs error of "
        "the n the pipeline gives, and in brackets how many more it left out (null in gait.json). "
        "Angles: the worst angle RMSE of any joint and side, °. A stride is at a turn when it "
        "starts within a stride time before a turn or inside it (the truth's turns); gait.json's "
        "straight: the strides and steps the pipeline itself does not call turning (a turning "
        "heading between the contacts, or a foot that pivoted at one), which gait.json summarises.",
        "",
    ]
    return "\n".join(L)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[201, 202, 203])
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--pace", choices=PACES, default="normal")
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "results")
    args = ap.parse_args(argv)
    rows = {v: [run_variant(v, s, args.duration, args.pace) for s in args.seeds] for v in VARIANTS}
    res = {
        "seeds": args.seeds,
        "duration_s": args.duration,
        "pace": args.pace,
        "pooled": {v: summarise(rows[v]) for v in VARIANTS},
        "variants": rows,
    }
    name = "turns" if args.pace == "normal" else f"turns_{args.pace}"
    write_results(args.out, name, res, markdown(res))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
