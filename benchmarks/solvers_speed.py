"""How fast are the solvers on joint-centre-sized problems? Prints a Markdown table.

Problem: :func:`solvers.problems.shared_point_acceleration` (6 unknowns, one residual per
sample; the joint-centre problem of Hu et al. 2021, eq. 1–3). Local solvers run on 12000
residuals from a start 3–5 cm off; the swarms on 6000 residuals with a vectorised
population cost (one numpy call per iteration), then the swarm + CasADi Gauss–Newton
pipeline. Times are medians over ``--repeats`` runs; "cold" includes building the CasADi
functions (and compiling, for JIT), "warm" reuses the cache (new data, same function).

Usage: ``python benchmarks/solvers_speed.py [--repeats 5] [--out DIR]``; with ``--out``,
also writes ``DIR/solvers_speed.{md,json}``. Multithreaded BLAS can slow the tall-skinny
SVDs on a busy machine: compare with ``OPENBLAS_NUM_THREADS=1``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from solvers import SolverResult, casadi_lsq, dwpso, gauss_newton, gwo, swarm_then_refine
from solvers.casadi_lsq import _CACHE
from solvers.problems import LeastSquaresProblem, shared_point_acceleration


def timed(fn: Callable[[], SolverResult], repeats: int) -> tuple[tuple[float, float], SolverResult]:
    """Median wall and CPU time (s) over ``repeats`` calls, and the last result."""
    wall, cpu, result = [], [], None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        result = fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    assert result is not None
    return (statistics.median(wall), statistics.median(cpu)), result


def row(
    name: str, prob: LeastSquaresProblem, t: tuple[float, float], res: SolverResult, note: str = ""
) -> dict:
    return {
        "solver": name,
        "residuals": int(prob.data.shape[1]) if prob.data is not None else 0,
        "time_ms": 1e3 * t[0],
        "cpu_ms": 1e3 * t[1],
        "iterations": res.iterations,
        "error_mm": 1e3 * float(np.abs(res.x - prob.x_true).max()),
        "converged": res.converged,
        "note": note,
    }


def run(repeats: int) -> list[dict]:
    rows = []
    big = shared_point_acceleration(n_samples=12000, noise=0.05, seed=0)
    r, data, x0, lo, hi = big.casadi_residual, big.data, big.x0, big.lower, big.upper

    _CACHE.clear()
    t, res = timed(lambda: casadi_lsq(r, x0, params=data, lower=lo, upper=hi), 1)
    rows.append(row("casadi_lsq gauss_newton (cold)", big, t, res, "builds the functions"))
    t, res = timed(lambda: casadi_lsq(r, x0, params=data, lower=lo, upper=hi), repeats)
    rows.append(row("casadi_lsq gauss_newton (warm)", big, t, res))
    if shutil.which("gcc") or shutil.which("cc"):
        t, res = timed(lambda: casadi_lsq(r, x0, params=data, lower=lo, upper=hi, jit=True), 1)
        rows.append(row("casadi_lsq gauss_newton jit (cold)", big, t, res, "compiles C once"))
        t, res = timed(lambda: casadi_lsq(r, x0, params=data, lower=lo, upper=hi, jit=True), repeats)
        rows.append(row("casadi_lsq gauss_newton jit (warm)", big, t, res))
    t, res = timed(lambda: casadi_lsq(r, x0, params=data, lower=lo, upper=hi, solver="ipopt"), 1)
    rows.append(row("casadi_lsq ipopt (cold)", big, t, res, "builds nlpsol"))
    t, res = timed(lambda: casadi_lsq(r, x0, params=data, lower=lo, upper=hi, solver="ipopt"), repeats)
    rows.append(row("casadi_lsq ipopt (warm)", big, t, res))
    t, res = timed(lambda: gauss_newton(big.residual, big.jacobian, x0, lower=lo, upper=hi), repeats)
    rows.append(row("gauss_newton (numpy residual)", big, t, res, "hand-written Jacobian"))

    mid = shared_point_acceleration(n_samples=6000, noise=0.05, seed=1)
    for name, swarm in (("dwpso", dwpso), ("gwo", gwo)):
        t, res = timed(lambda s=swarm: s(mid.cost_batch, mid.lower, mid.upper, seed=0), repeats)
        pop = 40 if name == "dwpso" else 30
        rows.append(row(f"{name} (P={pop})", mid, t, res, f"{res.iterations + 1} cost calls"))

    def refine(x: np.ndarray) -> SolverResult:
        return casadi_lsq(mid.casadi_residual, x, params=mid.data, lower=mid.lower, upper=mid.upper)

    for name in ("dwpso", "gwo"):
        t, res = timed(
            lambda s=name: swarm_then_refine(
                mid.cost_batch, mid.lower, mid.upper, refine, swarm=s, max_iter=60
            ),
            repeats,
        )
        rows.append(row(f"{name} (60 it) + casadi gauss_newton", mid, t, res))
    return rows


def markdown(rows: list[dict]) -> str:
    lines = [
        "| solver | residuals | wall (ms) | CPU (ms) | iterations | max error (mm) | converged | note |",
        "|---|---:|---:|---:|---:|---:|:-:|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['solver']} | {r['residuals']} | {r['time_ms']:.1f} | {r['cpu_ms']:.1f} | "
            f"{r['iterations']} | "
            f"{r['error_mm']:.3f} | {'yes' if r['converged'] else 'no'} | {r['note']} |"
        )
    blas = os.environ.get("OPENBLAS_NUM_THREADS", "default")
    lines.append("")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines.append(
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, load average "
        f"{load:.1f}, OPENBLAS_NUM_THREADS={blas}; 6 unknowns, local solvers start 3–5 cm "
        "from the truth. CPU time counts all threads of this process."
    )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--out", type=Path, default=None, help="directory for .md and .json")
    args = parser.parse_args()
    rows = run(args.repeats)
    table = markdown(rows)
    print(table)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "solvers_speed.md").write_text(table + "\n")
        (args.out / "solvers_speed.json").write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
