"""Per-stage time of one trial end to end (read → calibrate → … → all output files), cold and warm.

Goal: a 5-minute, 100 Hz, 4-sensor walk with every output at ≥ 100× real time in a warm
process (≤ 3 s) and ≥ 30× from a fresh process (≤ 10 s, interpreter start and imports
included). Each trial length (default 1, 5 and 20 minutes of simulated walking, seed 1)
runs in a fresh process twice: the first run is the cold one (its ``import`` row is the
library's imports; numba's on-disk cache is warm, as after the first use), the second the
warm one. The machine's load average is recorded: other work on the machine slows
every figure.

Usage: ``python benchmarks/pipeline_speed.py [--minutes 1 5 20] [--repeats 3]``; writes
``benchmarks/results/pipeline_speed.{md,json}``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

STAGES = (
    "import",
    "read",
    "joint calibration",
    "orientation filters",
    "segment frames, angles",
    "forward kinematics",
    "write files",
    "report",
)


def one_process(trial: Path, repeats: int) -> list[dict[str, float]]:
    """Run in a fresh process: ``repeats`` end-to-end runs of ``trial``, per-stage times (s)."""
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")  # as the command line does
    t0, cpu0 = time.perf_counter(), time.process_time()
    from lowerlimb.io.trial import ImuTrial
    from lowerlimb.outputs import write_outputs
    from lowerlimb.pipeline import process_trial

    try:
        from lowerlimb.io.result_files import OUTPUT_FILES
    except ImportError:  # a version before --outputs (for the "before" figures): one "write files" row
        OUTPUT_FILES = {}

    imported = time.perf_counter() - t0
    runs = []
    for r in range(repeats):
        cpu = cpu0 if r == 0 else time.process_time()
        times = {"import": imported if r == 0 else 0.0}
        t = time.perf_counter()
        imu = ImuTrial.from_csv(trial)
        times["read"] = time.perf_counter() - t
        result = process_trial(imu)
        times.update(result.timings_s)
        with tempfile.TemporaryDirectory() as d:
            t = time.perf_counter()
            if OUTPUT_FILES:
                write_outputs(result, Path(d), files=[n for n in OUTPUT_FILES if n != "report"])
                times["write files"] = time.perf_counter() - t
                t = time.perf_counter()
                write_outputs(result, Path(d), files=["report"])
                times["report"] = time.perf_counter() - t
            else:
                write_outputs(result, Path(d))
                times["write files"], times["report"] = time.perf_counter() - t, 0.0
        times["duration_s"] = imu.duration_s
        times["cpu"] = time.process_time() - cpu
        times["end_epoch_s"] = time.time()
        runs.append(times)
    return runs


def measure(trial: Path, repeats: int) -> dict[str, object]:
    """Cold (first run of a fresh process, with interpreter start) and warm (best later run) times."""
    cold: list[dict[str, float]] = []
    warm: list[dict[str, float]] = []
    for _ in range(repeats):
        launched = time.time()
        out = subprocess.run(
            [sys.executable, __file__, "--one", str(trial)], check=True, capture_output=True, text=True
        ).stdout
        runs = json.loads(out.strip().splitlines()[-1])
        runs[0]["process wall"] = runs[0]["end_epoch_s"] - launched  # launch to the end of the first trial
        cold.append(runs[0])
        warm.append(runs[1])

    def best(runs: list[dict[str, float]], key: str) -> dict[str, float]:
        return min(runs, key=lambda r: r[key])

    def total(r: dict[str, float]) -> float:
        return sum(r[s] for s in STAGES)

    for r in cold + warm:
        r["total"] = total(r)
    return {
        "cold": best(cold, "process wall"),
        "warm": best(warm, "total"),
        "load_avg": os.getloadavg(),
        "machine_reference_s": machine_reference(),
    }


def machine_reference() -> float:
    """Seconds of a fixed workload (a Python loop and small NumPy solves), best of 3.

    Machines and days differ by up to 2× on the same code: this figure, in every table, says
    how fast the machine was, so that tables from different days can be compared.
    """
    import numpy as np

    rng = np.random.default_rng(0)
    a = rng.standard_normal((200, 200)) + 200 * np.eye(200)
    times = []
    for _ in range(3):
        t = time.perf_counter()
        total = 0
        for i in range(2_000_000):
            total += i & 7
        for _ in range(200):
            np.linalg.solve(a, a[:, 0])
        times.append(time.perf_counter() - t)
    return min(times)


def simulated_walk(minutes: float, folder: Path) -> Path:
    """The simulated walk of ``minutes`` (seed 1), written once into ``folder``."""
    path = folder / f"walk_{minutes:g}min.csv"
    if not path.exists():
        from lowerlimb.simulation import simulate

        simulate("walk", 60.0 * minutes, 1).trial.to_csv(path)
    return path


def report(results: dict[str, dict[str, object]], repeats: int, note: str = "") -> str:
    lines = [
        "# Pipeline speed: one simulated walk end to end, every output written",
        "",
        "Goal: 5 minutes at ≥ 100× real time warm (≤ 3 s), ≥ 30× cold (≤ 10 s). Cold: a fresh "
        "process (interpreter start and imports included, numba cache warm); warm: a later "
        f"trial in the same process. Best of {repeats} processes; 2 cores shared with other "
        "work (load average in the last row), so wall times are inflated: `cpu` is the CPU time "
        "of the same run in this process (the report's second figure grid is drawn in a forked "
        "child beside it, `lowerlimb.side_by_side`, and not counted).",
        "",
        "| stage (s) | " + " | ".join(f"{m} min cold | {m} min warm" for m in results) + " |",
        "|---|" + "---|---|" * len(results),
    ]
    for stage in (*STAGES, "total", "cpu", "process wall"):
        cells = []
        for r in results.values():
            for kind in ("cold", "warm"):
                v = r[kind].get(stage)  # type: ignore[attr-defined]
                cells.append("" if v is None else f"{v:.2f}")
        lines.append(f"| {stage} | " + " | ".join(cells) + " |")
    cells = []
    for r in results.values():
        cold, warm = r["cold"], r["warm"]
        cells.append(f"{cold['duration_s'] / cold['process wall']:.0f}×")  # type: ignore[index]
        cells.append(f"{warm['duration_s'] / warm['total']:.0f}×")  # type: ignore[index]
    lines.append("| **real-time factor (wall)** | " + " | ".join(cells) + " |")
    cells = []
    for r in results.values():
        for kind in ("cold", "warm"):
            cells.append(f"{r[kind]['duration_s'] / r[kind]['cpu']:.0f}×")  # type: ignore[index]
    lines.append("| **real-time factor (cpu)** | " + " | ".join(cells) + " |")
    loads = " | ".join(f"{r['load_avg'][0]:.1f} | " for r in results.values())  # type: ignore[index]
    lines.append(f"| load average (1 min) | {loads}")
    refs = " | ".join(f"{r['machine_reference_s']:.2f} | " for r in results.values())  # type: ignore[index]
    lines.append(f"| machine reference (s, lower is faster) | {refs}")
    if note:
        lines += ["", note]
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, nargs="+", default=[1.0, 5.0, 20.0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--data", type=Path, default=Path(tempfile.gettempdir()) / "lowerlimb_bench")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    ap.add_argument("--name", default="pipeline_speed", help="results file stem")
    ap.add_argument("--note", default="", help="a paragraph written under the table")
    ap.add_argument("--one", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(one_process(args.one, 2)))
        return
    args.data.mkdir(parents=True, exist_ok=True)
    results = {f"{m:g}": measure(simulated_walk(m, args.data), args.repeats) for m in args.minutes}
    md = report(results, args.repeats, args.note)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / f"{args.name}.md").write_text(md)
    (args.out / f"{args.name}.json").write_text(json.dumps(results, indent=1))
    print(md)


if __name__ == "__main__":
    main()
