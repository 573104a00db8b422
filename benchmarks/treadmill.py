"""Treadmill walks: the seven-IMU pipeline on a straight walk whose belt carries the walker back.

Gait labs record on treadmills as often as overground. Each simulated walk (seeds 201–206,
60 s, realistic noise, the lab's magnetic field) is run three ways and scored against its
truth as ``gait.py`` scores it:

- **overground**: the default walk on a gently bending path (``gait.md``'s walks);
- **treadmill**: the same seed on a treadmill (``simulate_bilateral(treadmill=
  TreadmillParams())``: straight, the belt's start-up in the sensors' lab-frame signals, the
  lab's field where the sensors are in the lab, nearly constant in time, and the drive
  motor's dipole; stride length and speed are the belt-frame ones);
- **treadmill, no magnetometer**: the same trial with its magnetometer columns dropped
  (6-axis; ``calibrate --no-mag``).

The heading spread is :attr:`lowerlimb.gait.drift.TrackDrift.heading_spread` (0: every step
one way): on a straight walk the chain's constant bias cannot be told from the standing
anchor's error, and step width carries the calibrated chain's sideways error at standing.

``--pace slow`` (``treadmill_slow``) and ``--artefacts real`` (``treadmill_artefacts``: the
simulator's real-walk artefact profile on all seven sensors) run the same comparison for slow
walkers and for non-rigid sensors.

Usage: ``python benchmarks/treadmill.py [--seeds …] [--duration S] [--pace normal|slow|shuffle]
[--artefacts none|real] [--out DIR]``; writes ``treadmill.{md,json}`` (or the variant's name).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
import gait as G  # noqa: E402
from _results import write_results  # noqa: E402

from lowerlimb.simulation import Artefacts  # noqa: E402
from lowerlimb.simulation.footsteps import PACES  # noqa: E402
from lowerlimb.simulation.treadmill import TreadmillParams  # noqa: E402

VARIANTS = ("overground", "treadmill", "treadmill_no_mag")
LABELS = {
    "overground": "overground",
    "treadmill": "treadmill",
    "treadmill_no_mag": "treadmill, no magnetometer",
}


def _drop_mag(trial: Any) -> Any:
    return replace(trial, mag=None)


def run_variant(
    variant: str, seed: int, duration_s: float, pace: str = "normal", artefacts: Artefacts | None = None
) -> dict[str, Any]:
    """One seed's walk, overground or on the treadmill, scored against its truth."""
    treadmill = None if variant == "overground" else TreadmillParams()
    transform = _drop_mag if variant == "treadmill_no_mag" else None
    return G.score_simulation(
        seed, duration_s, artefacts=artefacts, pace=pace, treadmill=treadmill, transform=transform
    )


def trial_row(tr: dict[str, Any]) -> dict[str, Any]:
    """The per-trial figures of the table."""
    lengths = [abs(e) for k, v in tr["joint_err"].items() if k in G.LENGTH_LABELS for e in v]
    width = G._stats(tr["step_width_mm"])
    return {
        "seed": tr["seed"],
        "ic_ms": G._stats(tr["left_initial_contact_ms"] + tr["right_initial_contact_ms"])["median_abs"],
        "to_ms": G._stats(tr["left_toe_off_ms"] + tr["right_toe_off_ms"])["median_abs"],
        "stride_pct": G._stats(tr["stride_length_pct"])["median_abs"],
        "width_median_mm": width["median_abs"],
        "width_worst_mm": width["worst_abs"],
        "width_bias_mm": width["bias"],
        "length_worst_mm": max(lengths) if lengths else float("nan"),
        "angle_worst_deg": max(max(v.values()) for v in tr["angle_rmse_deg"].values()),
        "heading_spread": tr["heading_spread"],
        "used_mag": tr["used_mag"],
    }


def _walker(res: dict[str, Any]) -> str:
    """``"slow walkers, "`` / ``"the real-walk artefact profile, "`` or ``""``."""
    out = (
        "" if res.get("pace", "normal") == "normal" else f'**{res["pace"]} pace** (`pace="{res["pace"]}"`), '
    )
    if res.get("artefacts"):
        out += "**the real-walk artefact profile** on all seven sensors (`Artefacts.real_walk()`), "
    return out


def markdown(res: dict[str, Any]) -> str:
    seeds = res["seeds"]
    L = [
        "# Treadmill walks: the same walkers overground and on a treadmill",
        "",
        f"`simulate_bilateral` seeds {', '.join(map(str, seeds))}, {res['duration_s']:g} s, "
        f"{_walker(res)}realistic noise, the lab's magnetic field (`simulation/magnetic_field.py`), "
        "each seed overground (its "
        "path bends by 17–46°), on a treadmill (`treadmill=TreadmillParams()`: straight; the belt's "
        "start-up in the lab-frame signals; the lab's field where the sensors are in the lab and the "
        "drive motor's, nearly constant in time, so the magnetometer check accepts it and it is "
        "fused) and on the treadmill without the magnetometer columns (6-axis, `calibrate --no-mag`). "
        f"Scored after {G.SKIP_S:g} s against the truth; on the treadmill the truth's strides, "
        "speed and step width are the belt-frame ones.",
        "",
        "| variant | IC ms | TO ms | stride % | step width mm | width bias mm | lengths mm | "
        "angles ° | heading spread |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for v in VARIANTS:
        rows = res["variants"][v]
        p = res["pooled"][v]
        spread = [r["heading_spread"] for r in rows if r["heading_spread"] is not None]
        L.append(
            f"| {LABELS[v]} | {p['initial_contact']['median_abs']:.1f} | {p['toe_off']['median_abs']:.1f} | "
            f"{p['stride_length_pct']['median_abs']:.2f} | {p['step_width_mm']['median_abs']:.1f} / "
            f"{p['step_width_mm']['worst_abs']:.0f} | {p['step_width_mm']['bias']:+.1f} | "
            f"{max(r['length_worst_mm'] for r in rows):.0f} | "
            f"{max(r['angle_worst_deg'] for r in rows):.2f} | "
            f"{min(spread, default=float('nan')):.3f}–{max(spread, default=float('nan')):.3f} |"
        )
    L += [
        "",
        "Pooled over the walks: events and stride length median abs; step width median / worst abs "
        "and mean signed error; lengths: the worst thigh or shank length error; angles: the worst "
        "angle RMSE of any joint and side; heading spread: the range over the walks.",
        "",
        "Per walk (step width median / worst abs, mm; worst angle RMSE, °; magnetometer fused left / right):",
        "",
        "| seed | " + " | ".join(LABELS[v] for v in VARIANTS) + " |",
        "|---|" + "---|" * len(VARIANTS),
    ]
    for i, seed in enumerate(seeds):
        cells = []
        for v in VARIANTS:
            r = res["variants"][v][i]
            mag = "/".join("9" if r["used_mag"][s] else "6" for s in ("left", "right"))
            width = f"{r['width_median_mm']:.1f} / {r['width_worst_mm']:.0f}"
            cells.append(f"{width}; {r['angle_worst_deg']:.2f}°; {mag}-axis")
        L.append(f"| {seed} | " + " | ".join(cells) + " |")
    return "\n".join(L) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    G.add_walk_arguments(ap)
    ap.add_argument("--pace", choices=PACES, default="normal", help="the walkers' pace")
    ap.add_argument("--artefacts", choices=("none", "real"), default="none", help="real: non-rigid sensors")
    args = ap.parse_args()
    art = Artefacts.real_walk() if args.artefacts == "real" else None
    trials = {
        v: [run_variant(v, seed, args.duration, args.pace, art) for seed in args.seeds] for v in VARIANTS
    }
    res: dict[str, Any] = {
        "seeds": args.seeds,
        "duration_s": args.duration,
        "pace": args.pace,
        "artefacts": args.artefacts == "real",
        "treadmill": TreadmillParams().__dict__,
        "pooled": {v: G.summarise_simulation(trials[v]) for v in VARIANTS},
        "variants": {v: [trial_row(tr) for tr in trials[v]] for v in VARIANTS},
        "trials": trials,
    }
    name = "treadmill" + ("" if args.pace == "normal" else f"_{args.pace}")
    name += "_artefacts" if args.artefacts == "real" else ""
    write_results(args.out, name, res, markdown(res))


if __name__ == "__main__":
    main()
