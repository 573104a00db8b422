"""Two legs end to end: a seven-IMU trial through ``calibrate``, every output written.

The two-leg counterpart of ``pipeline_speed.py``. A simulated seven-IMU walk (seed 201, 1 and 5
minutes) goes through ``run_calibrate_bilateral`` (what ``lowerlimb calibrate`` runs on a
two-leg CSV: read, both legs calibrated and tracked, one pelvis, gait, every output file and
the report) in a fresh process twice: the first run is the cold one (imports included, numba
cache warm), the second the warm one. Per stage: the trial read, each leg's pipeline stages,
the one-pelvis stage, and the rest (gait, files, report) as "gait, files, report".

Usage: ``python benchmarks/bilateral_speed.py [--minutes 1 5] [--repeats 3]``; writes
``benchmarks/results/bilateral_speed.{md,json}``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _results import write_results  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def one_process(trial: Path) -> list[dict[str, float]]:
    """In a fresh process: two end-to-end runs of ``trial``, stage times (s)."""
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")  # as the command line does
    t0 = time.perf_counter()
    from lowerlimb.io.bilateral_trial import BilateralTrial
    from lowerlimb.outputs import CalibrateOptions
    from lowerlimb.outputs_bilateral import run_calibrate_bilateral

    imported = time.perf_counter() - t0
    runs = []
    for r in range(2):
        times = {"import": imported if r == 0 else 0.0}
        t = time.perf_counter()
        BilateralTrial.from_csv(trial)
        times["read"] = time.perf_counter() - t
        with tempfile.TemporaryDirectory() as d, contextlib.redirect_stderr(io.StringIO()):
            t = time.perf_counter()
            result = run_calibrate_bilateral(CalibrateOptions(trial=trial, out=Path(d) / "out"))
            whole = time.perf_counter() - t
        legs = result.timings_s["both legs"]  # wall time: side by side, less than the legs' sum
        times["both legs"] = legs
        times["one pelvis"] = result.timings_s.get("one pelvis", 0.0)
        times["gait, files, report"] = whole - times["read"] - legs - times["one pelvis"]
        times["total"] = times["import"] + whole
        times["duration_s"] = result.trial.duration_s
        runs.append(times)
    return runs


def simulated_walk(minutes: float, folder: Path) -> Path:
    path = folder / f"walk7_{minutes:g}min.csv"
    if not path.exists():
        from lowerlimb.simulation import simulate_bilateral

        simulate_bilateral(60.0 * minutes, 201).trial.to_csv(path)
    return path


def measure(trial: Path, repeats: int) -> dict[str, object]:
    cold, warm = [], []
    for _ in range(repeats):
        out = subprocess.run(
            [sys.executable, __file__, "--one", str(trial)], check=True, capture_output=True, text=True
        ).stdout
        runs = json.loads(out.strip().splitlines()[-1])
        cold.append(runs[0])
        warm.append(runs[1])
    best = {"cold": min(cold, key=lambda r: r["total"]), "warm": min(warm, key=lambda r: r["total"])}
    return best | {"load_avg": os.getloadavg()}


STAGES = ("import", "read", "both legs", "one pelvis", "gait, files, report", "total")


def markdown(results: dict[str, dict[str, object]], repeats: int) -> str:
    L = [
        "# Two legs end to end: a seven-IMU trial through `calibrate`, every output written",
        "",
        f"Best of {repeats} fresh processes; cold = the first run (imports included, numba cache "
        "warm), warm = the second. Simulated seven-IMU walk, seed 201, 100 Hz, 2-core machine. "
        '"read" is counted once more inside the command (the table\'s read is a separate one).',
        "",
        "| stage (s) | " + " | ".join(f"{m} min cold | {m} min warm" for m in results) + " |",
        "|---|" + "---|---|" * len(results),
    ]
    for stage in STAGES:
        cells = [f"{r[kind][stage]:.2f}" for r in results.values() for kind in ("cold", "warm")]  # type: ignore[index]
        L.append(f"| {stage} | " + " | ".join(cells) + " |")
    cells = [
        f"{r[kind]['duration_s'] / r[kind]['total']:.0f}×"  # type: ignore[index]
        for r in results.values()
        for kind in ("cold", "warm")
    ]
    L.append("| **real-time factor** | " + " | ".join(cells) + " |")
    loads = "".join(f" {r['load_avg'][0]:.1f} |  |" for r in results.values())  # type: ignore[index]
    L += [f"| load average (1 min) |{loads}", ""]
    return "\n".join(L)


def main() -> None:
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        print(json.dumps(one_process(Path(sys.argv[2]))))
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, nargs="+", default=[1.0, 5.0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        results = {f"{m:g}": measure(simulated_walk(m, Path(folder)), args.repeats) for m in args.minutes}
    write_results(args.out, "bilateral_speed", results, markdown(results, args.repeats))


if __name__ == "__main__":
    main()
