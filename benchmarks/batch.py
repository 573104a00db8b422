"""Throughput of ``lowerlimb batch``: trials per minute vs local workers, and through a Dask LocalCluster.

A study of ``--trials`` simulated 1-minute walks (different seeds; every output
written) is processed from scratch (``force``) with 1, 2, … cores local worker
processes, then on a ``dask.distributed.LocalCluster`` of one single-threaded worker
process per core. Reported: wall time (pool start-up included), trials per minute,
speed-up and scaling efficiency against one worker, the mean per-trial wall time
inside the workers, and the peak resident memory of a worker. The machine's load
average is recorded: other work on the machine lowers every figure.

Usage: ``python benchmarks/batch.py [--trials 12] [--minutes 1]``; writes
``benchmarks/results/batch.{md,json}``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import tempfile
import time
from pathlib import Path
from typing import Any

from lowerlimb.batch import BatchParams, run_study


def make_study(folder: Path, n: int, minutes: float) -> Path:
    """``n`` simulated walks (seeds 0..n-1) and their manifest, written once."""
    from lowerlimb.simulation import simulate

    folder.mkdir(parents=True, exist_ok=True)
    rows = ["trial,subject,task"]
    for k in range(n):
        path = folder / f"walk_{minutes:g}min_{k}.csv"
        if not path.exists():
            simulate("walk", 60.0 * minutes, k).trial.to_csv(path)
        rows.append(f"{path.name},s{k % 4},walk")
    manifest = folder / f"manifest_{n}x{minutes:g}min.csv"
    manifest.write_text("\n".join(rows) + "\n")
    return manifest


def run(manifest: Path, out: Path, n: int, **kw: Any) -> dict[str, float]:
    """One study from scratch; its throughput figures."""
    shutil.rmtree(out, ignore_errors=True)
    t = time.perf_counter()
    result = run_study(manifest, out, BatchParams(force=True, workers=kw.pop("workers", None)), **kw)
    wall = time.perf_counter() - t
    ok = [o for o in result.outcomes if o.status != "failed"]
    assert len(ok) == n, [o.reason for o in result.failed]
    return {
        "wall_s": wall,
        "trials_per_min": 60.0 * n / wall,
        "trial_wall_s_mean": sum(o.wall_s for o in ok) / n,
        "trial_cpu_s_mean": sum(o.cpu_s for o in ok) / n,
        "peak_rss_mb": max(o.peak_rss_mb for o in ok),
        "load_avg": os.getloadavg()[0],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=12)
    ap.add_argument("--minutes", type=float, default=1.0)
    ap.add_argument("--max-workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--data", type=Path, default=Path(tempfile.gettempdir()) / "lowerlimb_bench")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    ap.add_argument("--no-dask", action="store_true")
    args = ap.parse_args()
    manifest = make_study(args.data, args.trials, args.minutes)
    scratch = Path(tempfile.mkdtemp(prefix="lowerlimb_batch_bench_"))
    results: dict[str, dict[str, float]] = {}
    try:
        run(manifest, scratch / "warmup", args.trials, workers=args.max_workers)  # numba cache, page cache
        for w in range(1, args.max_workers + 1):
            results[f"local, {w} worker{'s' if w > 1 else ''}"] = run(
                manifest, scratch / f"local{w}", args.trials, workers=w
            )
        if not args.no_dask:
            import dask
            from distributed import LocalCluster

            t = time.perf_counter()
            with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
                with LocalCluster(
                    n_workers=args.max_workers, threads_per_worker=1, processes=True
                ) as cluster:
                    start = time.perf_counter() - t
                    r = run(manifest, scratch / "dask", args.trials, scheduler=cluster.scheduler_address)
            r["cluster_start_s"] = start
            results[f"dask LocalCluster, {args.max_workers} processes"] = r
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    base = results["local, 1 worker"]["trials_per_min"]
    lines = [
        f"# Batch throughput: {args.trials} simulated {args.minutes:g}-minute walks, every output written",
        "",
        f"{os.cpu_count()} cores, shared with other work while measured (load average column: above "
        "the worker count means the workers did not have the cores to themselves). Wall time "
        "includes starting the worker processes (a Dask cluster's start is listed apart). A trial's "
        "CPU time that stays flat while its wall time grows means the workers waited for a core.",
        "",
        "| run | wall (s) | trials/min | speed-up | efficiency | trial wall in worker (s) | "
        "trial CPU in worker (s) | peak RSS per worker (MB) | load avg |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, r in results.items():
        workers = int(name.split(",")[1].split()[0])
        speed = r["trials_per_min"] / base
        lines.append(
            f"| {name} | {r['wall_s']:.1f} | {r['trials_per_min']:.1f} | {speed:.2f}× | "
            f"{speed / workers:.0%} | {r['trial_wall_s_mean']:.2f} | {r['trial_cpu_s_mean']:.2f} | "
            f"{r['peak_rss_mb']:.0f} | "
            f"{r['load_avg']:.1f} |"
        )
    md = "\n".join(lines) + "\n"
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "batch.md").write_text(md)
    (args.out / "batch.json").write_text(
        json.dumps({"trials": args.trials, "minutes": args.minutes, "runs": results}, indent=1)
    )
    print(md)


if __name__ == "__main__":
    main()
