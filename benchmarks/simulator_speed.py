"""Speed of the IMU simulator: a 60 s, 100 Hz, 4-sensor trial per motion (goal: walk < 2 s on one core).

Also the seven-IMU walk (``simulate_bilateral``, with the lab's magnetic field) at 1 and 5
minutes: its cost must grow with the walk's length, not faster.

Usage: ``python benchmarks/simulator_speed.py [--repeats 3]``; writes
``benchmarks/results/simulator_speed.{md,json}``.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from lowerlimb.simulation import MOTIONS, ImuNoise, simulate, simulate_bilateral  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    args = ap.parse_args()
    simulate("walk", 3.0, 0)  # warm-up: imports and first-call costs
    rows = {}
    for motion in MOTIONS:
        for soft in (False, True):
            best = float("inf")
            for r in range(args.repeats):
                t0 = time.perf_counter()
                simulate(motion, args.duration, r, noise=ImuNoise(), soft_tissue=soft)
                best = min(best, time.perf_counter() - t0)
            rows[f"{motion}{' + soft tissue' if soft else ''}"] = best
    bilateral = {}
    for minutes in (1.0, 5.0):
        t0 = time.perf_counter()
        simulate_bilateral(60.0 * minutes, 201)
        bilateral[f"seven-IMU walk, {minutes:g} min"] = (time.perf_counter() - t0, int(6000 * minutes))
    lines = [
        f"# Simulator speed ({args.duration:g} s, 100 Hz, 4 IMUs, realistic noise; best of {args.repeats})",
        "",
        "Goal: walk under 2 s on one core.",
        "",
        "| motion | wall time (s) | samples/s |",
        "|---|---|---|",
    ]
    n = int(args.duration * 100)
    for name, t in rows.items():
        lines.append(f"| {name} | {t:.2f} | {n / t:,.0f} |")
    for name, (t, n7) in bilateral.items():
        lines.append(f"| {name} (7 IMUs, lab field; once) | {t:.2f} | {n7 / t:,.0f} |")
    md = "\n".join(lines) + "\n"
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "simulator_speed.md").write_text(md)
    (args.out / "simulator_speed.json").write_text(
        json.dumps(
            {
                "duration_s": args.duration,
                "wall_s": rows,
                "bilateral_wall_s": {k: v[0] for k, v in bilateral.items()},
            },
            indent=1,
        )
    )
    print(md)


if __name__ == "__main__":
    main()
