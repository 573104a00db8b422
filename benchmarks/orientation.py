"""Orientation filters on BROAD and simulated trials, side by side with VQF (issue 4).

For every filter of :mod:`lowerlimb.orientation`, with ONE global parameter
set (the library defaults, chosen by ``benchmarks/tune_orientation.py``):

* BROAD development trials (``DIR/broad/*.mat``; Laidig et al. 2021): RMSE of
  the total, heading and inclination error over the ``movement`` samples
  (NaN truth rows masked), 9-axis and 6-axis (6-axis after removing the best
  constant heading offset, as the BROAD paper does), and the FTECF paper's
  pitch/roll/yaw RMSE and maximum error;
* simulated trials (``lowerlimb.simulation``, realistic noise and gyro bias,
  4 sensors each), scored after the initial still period;
* VQF (Laidig & Seel 2023, ``vqf.VQF``, default parameters) as the
  state-of-the-art reference, and the published BROAD figures (9-axis,
  all 39 trials: Madgwick 4.96°, Mahony 7.49°);
* throughput in samples/s of each filter and of VQF, and the wall time of a
  60 s, 100 Hz trial of 4 sensors through ``estimate_orientation``.

Usage: ``python benchmarks/orientation.py --data DIR [--out benchmarks/results] [--quick]``
Writes ``orientation.md`` and ``orientation.json`` into ``--out`` and prints the Markdown.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io as sio

from lowerlimb.conventions import SENSORS
from lowerlimb.orientation import METHODS, estimate_orientation, orientation_errors
from lowerlimb.orientation.estimate import FILTERS

#: Published BROAD results, 9-axis total RMSE over all 39 trials, one global parameter set.
PUBLISHED_BROAD_9D_DEG = {"Madgwick (BROAD paper)": 4.96, "Mahony (BROAD paper)": 7.49}
#: Published FTECF-paper results (upper arm, Table 2): pitch, roll, yaw RMSE and max error, deg.
PUBLISHED_FTECF_DEG = {
    "FTECF (Zhu & Xu 2018)": (1.80, 1.09, 2.16, 5.38),
    "Madgwick (Zhu & Xu 2018)": (2.23, 1.27, 2.14, 5.80),
    "QUEST+KF (Zhu & Xu 2018)": (1.90, 1.48, 2.59, 9.46),
}
#: Simulated motions: (motion, duration s, seed).
SIM_TRIALS = (("walk", 60.0, 1), ("walk", 60.0, 2), ("squat", 30.0, 3), ("knee-lift", 30.0, 4))
SIM_TRIALS_QUICK = (("walk", 30.0, 1),)
METRICS = ("total_deg", "heading_deg", "inclination_deg", "pitch_deg", "roll_deg", "yaw_deg")


@dataclass
class Trial:
    """One scored recording of one IMU."""

    name: str
    group: str
    gyr: np.ndarray
    acc: np.ndarray
    mag: np.ndarray
    quat_ref: np.ndarray
    mask: np.ndarray
    rate_hz: float
    gyro_timing: str = "instantaneous"


def load_broad(data_dir: Path) -> list[Trial]:
    """The BROAD trials in ``data_dir/broad`` (``.mat``), sorted by name."""
    trials = []
    for f in sorted((data_dir / "broad").glob("*.mat")):
        d = sio.loadmat(f)
        trials.append(
            Trial(
                name=f.stem,
                group="broad",
                gyr=np.ascontiguousarray(d["imu_gyr"], dtype=float),
                acc=np.ascontiguousarray(d["imu_acc"], dtype=float),
                mag=np.ascontiguousarray(d["imu_mag"], dtype=float),
                quat_ref=np.asarray(d["opt_quat"], dtype=float),
                mask=np.asarray(d["movement"]).reshape(-1).astype(bool),
                rate_hz=float(np.squeeze(d["sampling_rate"])),
            )
        )
    return trials


def simulated_trials(spec: tuple[tuple[str, float, int], ...] = SIM_TRIALS) -> list[Trial]:
    """Simulated trials with realistic noise: one :class:`Trial` per sensor."""
    from lowerlimb.simulation import ImuNoise, simulate

    trials = []
    for motion, duration, seed in spec:
        sim = simulate(motion, duration, seed, side="left" if seed % 2 else "right", noise=ImuNoise())
        tr = sim.trial
        mask = tr.time_s - tr.time_s[0] >= 1.5  # score after the initial still period
        for s in SENSORS:
            trials.append(
                Trial(
                    name=f"{motion}-s{seed}-{s}",
                    group="sim",
                    gyr=tr.gyr[s],
                    acc=tr.acc[s],
                    mag=tr.mag[s],
                    quat_ref=sim.quat_wxyz[s],
                    mask=mask,
                    rate_hz=float(tr.rate_hz),
                )
            )
    return trials


def run_method(trial: Trial, method: str, use_mag: bool, params: Any = None) -> np.ndarray:
    """(N, 4) estimate of ``method`` (a library method or ``"vqf"``)."""
    mag = trial.mag if use_mag else None
    if method == "vqf":
        from vqf import VQF

        v = VQF(1.0 / trial.rate_hz)
        if mag is None:
            return v.updateBatch(trial.gyr, trial.acc)["quat6D"]
        return v.updateBatch(trial.gyr, trial.acc, mag)["quat9D"]
    return estimate_orientation(
        trial.gyr,
        trial.acc,
        mag,
        rate_hz=trial.rate_hz,
        method=method,
        params=params,
        gyro_timing=trial.gyro_timing,
    )


def score(trial: Trial, quat: np.ndarray, use_mag: bool) -> dict[str, float]:
    """The metrics of one estimate."""
    e = orientation_errors(quat, trial.quat_ref, trial.mask, remove_heading_offset=not use_mag)
    return e.as_dict()


def evaluate(trials: list[Trial], method: str, use_mag: bool, params: Any = None) -> list[dict[str, float]]:
    """Per-trial metrics of one method on a list of trials."""
    return [score(t, run_method(t, method, use_mag, params), use_mag) for t in trials]


def mean_metrics(rows: list[dict[str, float]]) -> dict[str, float]:
    """Mean of each metric over trials (max error: the largest)."""
    out = {m: float(np.mean([r[m] for r in rows])) for m in METRICS}
    out["max_deg"] = float(np.max([r["max_deg"] for r in rows]))
    return out


def throughput(trial: Trial, fn: Callable[[], object], repeat: int = 3) -> float:
    """Samples per second of ``fn`` on ``trial`` (best of ``repeat`` after a warm-up)."""
    fn()
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return len(trial.gyr) / best


def four_sensor_wall_time(method: str, use_mag: bool) -> float:
    """Wall time (s) of ``estimate_orientation`` on a 60 s, 100 Hz, 4-sensor trial (warm JIT)."""
    from lowerlimb.simulation import ImuNoise, simulate

    tr = simulate("walk", 60.0, 1, noise=ImuNoise()).trial

    def run() -> None:
        for s in SENSORS:
            estimate_orientation(
                tr.gyr[s], tr.acc[s], tr.mag[s] if use_mag else None, rate_hz=tr.rate_hz,
                method=method,
            )  # fmt: skip

    run()
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - t0)
    return float(best)


def _fmt(x: float | None, nd: int = 2) -> str:
    return "–" if x is None or not np.isfinite(x) else f"{x:.{nd}f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, required=True, help="data directory containing broad/")
    ap.add_argument("--out", type=Path, default=Path("benchmarks/results"))
    ap.add_argument("--quick", action="store_true", help="one short simulated trial")
    ap.add_argument(
        "--broad-gyro-timing",
        choices=("instantaneous", "interval_mean"),
        default="instantaneous",
        help="meaning of a BROAD gyro sample (library default: instantaneous; BROAD's IMU "
        "fits interval_mean better)",
    )
    args = ap.parse_args()

    broad = load_broad(args.data)
    for t in broad:
        t.gyro_timing = args.broad_gyro_timing
    sims = simulated_trials(SIM_TRIALS_QUICK if args.quick else SIM_TRIALS)
    methods = [*METHODS, "vqf"]
    results: dict[str, Any] = {"broad": {}, "sim": {}, "per_trial": {}, "throughput": {}}
    for group, trials in (("broad", broad), ("sim", sims)):
        if not trials:
            continue
        for method in methods:
            for use_mag in (True, False):
                key = f"{method}/{'9D' if use_mag else '6D'}"
                rows = evaluate(trials, method, use_mag)
                results[group][key] = mean_metrics(rows)
                results["per_trial"][f"{group}/{key}"] = {
                    t.name: r for t, r in zip(trials, rows, strict=True)
                }
    # throughput on the first BROAD trial (or the first simulated one), 9-axis
    tp_trial = broad[0] if broad else sims[0]
    for method in methods:
        results["throughput"][method] = {
            "samples_per_s_9D": throughput(tp_trial, lambda m=method: run_method(tp_trial, m, True)),
            "samples_per_s_6D": throughput(tp_trial, lambda m=method: run_method(tp_trial, m, False)),
        }
        if method != "vqf":
            results["throughput"][method]["four_sensor_60s_100Hz_s"] = four_sensor_wall_time(method, True)
    results["defaults"] = {m: asdict(FILTERS[m][1]()) for m in METHODS}
    results["published"] = {"broad_9D_total_deg": PUBLISHED_BROAD_9D_DEG, "ftecf": PUBLISHED_FTECF_DEG}
    results["trials"] = {"broad": [t.name for t in broad], "sim": [t.name for t in sims]}
    results["broad_gyro_timing"] = args.broad_gyro_timing

    md = render_markdown(results, len(broad), len(sims))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "orientation.json").write_text(json.dumps(results, indent=2))
    (args.out / "orientation.md").write_text(md)
    print(md)


def goals_markdown(results: dict[str, Any]) -> list[str]:
    """The issue-4 goals, checked on the BROAD development trials (and the simulated ones)."""
    b = results["broad"]
    if not b:
        return []
    best = min(METHODS, key=lambda m: b[f"{m}/9D"]["total_deg"])
    best9, vqf9 = b[f"{best}/9D"]["total_deg"], b["vqf/9D"]["total_deg"]
    best6 = min(METHODS, key=lambda m: b[f"{m}/6D"]["inclination_deg"])
    incl6 = b[f"{best6}/6D"]["inclination_deg"]

    def pry(group: str, m: str) -> tuple[float, float, float]:
        r = results[group][f"{m}/9D"]
        return r["pitch_deg"], r["roll_deg"], r["yaw_deg"]

    def beats(group: str) -> str:
        f = pry(group, "ftecf")
        parts = []
        for other in ("madgwick", "quest_kf"):
            o = pry(group, other)
            won = [n for n, a, c in zip(("pitch", "roll", "yaw"), f, o, strict=True) if a < c]
            parts.append(f"vs {other}: better on {', '.join(won) if won else 'none'}")
        return "; ".join(parts)

    ok = "met" if best9 <= 4.96 and best9 <= 1.3 * vqf9 else "missed"
    lines = [
        "## Goals (issue 4)",
        "",
        f"- BROAD 9-axis, best filter ({best}): {best9:.2f}° mean total RMSE; goal ≤ 4.96° and "
        f"≤ 1.3 × VQF ({1.3 * vqf9:.2f}°): **{ok}** ({best9 / vqf9:.2f} × VQF).",
        f"- BROAD 6-axis inclination, best filter ({best6}): {incl6:.2f}°; goal ≤ 2°: "
        f"**{'met' if incl6 <= 2.0 else 'missed'}**.",
        f"- FTECF pitch/roll/yaw RMSE, BROAD: {beats('broad')}.",
    ]
    if results["sim"]:
        lines.append(f"- FTECF pitch/roll/yaw RMSE, simulated leg trials: {beats('sim')}.")
    lines.append("")
    return lines


def render_markdown(results: dict[str, Any], n_broad: int, n_sim: int) -> str:
    """The Markdown report of :func:`main`."""
    lines = ["# Orientation filters: accuracy and speed", ""]
    names = {"vqf": "VQF (reference)"}
    for group, title in (
        ("broad", f"BROAD development trials ({n_broad}), mean RMSE in degrees"),
        ("sim", f"Simulated trials ({n_sim} sensor recordings), mean RMSE in degrees"),
    ):
        if not results[group]:
            continue
        lines += [
            f"## {title}",
            "",
            "6-axis errors after removing the best constant heading offset. Pitch/roll/yaw: "
            "Euler angles (Z-X-Y) of the earth-frame error, 9-axis; max = largest total error.",
            "",
            "| filter | 9D total | 9D heading | 9D incl. | 6D total | 6D heading | 6D incl. "
            "| pitch | roll | yaw | max |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for method in [*METHODS, "vqf"]:
            a = results[group][f"{method}/9D"]
            b = results[group][f"{method}/6D"]
            lines.append(
                f"| {names.get(method, method)} | {_fmt(a['total_deg'])} | {_fmt(a['heading_deg'])} "
                f"| {_fmt(a['inclination_deg'])} | {_fmt(b['total_deg'])} | {_fmt(b['heading_deg'])} "
                f"| {_fmt(b['inclination_deg'])} | {_fmt(a['pitch_deg'])} | {_fmt(a['roll_deg'])} "
                f"| {_fmt(a['yaw_deg'])} | {_fmt(a['max_deg'], 1)} |"
            )
        if group == "broad":
            for name, val in PUBLISHED_BROAD_9D_DEG.items():
                lines.append(f"| {name}, all 39 trials | {val:.2f} | | | | | | | | | |")
        lines.append("")
    lines += goals_markdown(results)
    lines += [
        "## Published FTECF-paper figures (upper arm vs optical; other data, for scale)",
        "",
        "| method | pitch | roll | yaw | max |",
        "|---|---|---|---|---|",
    ]
    for name, (p, r, y, mx) in PUBLISHED_FTECF_DEG.items():
        lines.append(f"| {name} | {p:.2f} | {r:.2f} | {y:.2f} | {mx:.2f} |")
    lines += [
        "",
        "## Throughput (one core, JIT warm)",
        "",
        "Through ``estimate_orientation`` (input checks, rest detection and initial state "
        "included) on the first BROAD trial; VQF: ``vqf.VQF.updateBatch``.",
        "",
        "| filter | samples/s 9D | samples/s 6D | 60 s × 100 Hz × 4 sensors, 9D (s) |",
        "|---|---|---|---|",
    ]
    for method, tp in results["throughput"].items():
        wall = tp.get("four_sensor_60s_100Hz_s")
        lines.append(
            f"| {names.get(method, method)} | {tp['samples_per_s_9D']:,.0f} "
            f"| {tp['samples_per_s_6D']:,.0f} | {_fmt(wall, 3)} |"
        )
    lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
