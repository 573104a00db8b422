"""OpenSense IMU inverse kinematics with our orientations and with Xsens's, against Vicon and lowerlimb.

On the real overground walk (gait/ in the data folder: Xsens MTw on both legs, Vicon
on the same clock), each leg is read with :func:`lowerlimb.read_xsens` and processed
by :func:`lowerlimb.process_trial` as a user would. Then OpenSense (OpenSim 4.6,
``Rajagopal_2015.osim`` from opensim/) runs on two orientation sources:

* **ours** — the heading-corrected sensor orientations the pipeline uses for its
  angles (``TrialResult.motion.sensor_quat_wxyz``), one run per leg with its four
  IMUs (the two one-leg runs need not share a pelvis heading), written by
  :func:`lowerlimb.export.opensim.write_orientations_sto` in OpenSim's y-up world;
* **xsens** — Xsens's own on-board orientations (the ``Quat_q0..q3`` columns, sensor
  → Xsens's z-up world), written the same way; one run per leg and one with all
  seven IMUs (the issue's configuration).

Each run: ``IMUPlacer`` with the model's default pose as the standing calibration
(the placer reads the first row of a table holding the mean orientation over the
standing frames 200–1000), ``base_imu_label = pelvis_imu`` and the pelvis sensor axis
closest to lowerlimb's pelvis anterior axis as ``base_heading_axis``; then
``IMUInverseKinematicsTool`` over the whole trial with the default weights.

Knee, hip and ankle flexion of OpenSense-with-ours, OpenSense-with-Xsens and
lowerlimb's own angles are compared with Vicon (knee ``L_Femur_L_Tibia`` /
``R_Femur_R_Tibia``; hip and ankle the negated first Euler angle of ``Root_X_Femur`` /
``X_Tibia_X_Foot``, as in ``real_gait.py``), every series zeroed on its mean over the
standing frames 200–1000 and scored on the walking frames 1120–2074, with
:func:`lowerlimb.agreement.agreement_statistics` (RMSE, bias, 95 % limits of
agreement, Pearson r, CMC). Wall times: lowerlimb's whole ``process_trial`` per leg,
OpenSense's placer and IK inside the OpenSim process (without its start-up).

OpenSim runs in a subprocess: the Python of this process when it imports
``opensim``, else ``$LOWERLIMB_OPENSIM_PYTHON`` (a separate venv with ``pip install
opensim``).

Usage: ``python benchmarks/opensense.py [--data ../shared/data] [--out benchmarks/results]``;
writes ``opensense.{md,json}``.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import lowerlimb as ll
from lowerlimb.agreement import agreement_statistics
from lowerlimb.conventions import ANGLE_COLUMNS, quat_to_matrix
from lowerlimb.export.opensim import write_orientations_sto
from lowerlimb.segments.frames import mean_quaternion

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _realwalk import IDS, STAND, WALK, leg_mapping, load_vicon  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RUNNER = Path(__file__).resolve().parent / "_opensense_run.py"
SIDES = ("left", "right")
#: Joint -> (our angles.csv column, OpenSim coordinate stem).
JOINT_COLUMNS = {
    "knee": ("knee_flexion", "knee_angle"),
    "hip": ("hip_flexion", "hip_flexion"),
    "ankle": ("ankle_dorsiflexion", "ankle_angle"),
}
#: Issue 13's figure for OpenSense with Xsens orientations and a standing calibration.
ISSUE_REFERENCE = {"knee_rmse_deg": [5.8, 7.9], "wall_s": 39.0, "trial_s": 25.0}


def opensim_python() -> str | None:
    """A Python that imports ``opensim``: this one, else ``$LOWERLIMB_OPENSIM_PYTHON``, else None."""
    if importlib.util.find_spec("opensim") is not None:
        return sys.executable
    exe = os.environ.get("LOWERLIMB_OPENSIM_PYTHON")
    return exe if exe and Path(exe).is_file() else None


def load_leg(data: Path, side: str) -> ll.ImuTrial:
    """One leg of the walk as a four-sensor trial, through the library's Xsens reader."""
    mapping = leg_mapping(side)
    return ll.read_xsens(data / "gait" / "rawimu", mapping, side=side)


def read_xsens_quaternions(rawimu: Path, n_samples: int) -> dict[str, np.ndarray]:
    """Xsens's own orientations (``Quat_q0..q3``, w x y z, sensor → Xsens z-up world) per sensor.

    Rows are aligned on the packets all sensors recorded, as :func:`lowerlimb.read_xsens` does
    (this walk has no counter wrap and no gap: checked against ``n_samples``).
    """
    tables: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for name, sensor_id in IDS.items():
        (path,) = sorted(rawimu.glob(f"*{sensor_id}*.txt"))
        lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if not ln.startswith("//")]
        header = lines[0].split(",")
        cols = [header.index("PacketCounter")] + [header.index(f"Quat_q{k}") for k in range(4)]
        rows = np.array([[float(r.split(",")[c]) for c in cols] for r in lines[1:] if r.strip()])
        tables[name] = (rows[:, 0].astype(int), rows[:, 1:])
    common = sorted(set.intersection(*(set(c.tolist()) for c, _ in tables.values())))
    if len(common) != n_samples:
        raise RuntimeError(f"{len(common)} common Xsens packets, the trial has {n_samples}")
    out = {}
    for name, (counter, q) in tables.items():
        idx = np.searchsorted(counter, common)
        out[name] = q[idx] / np.linalg.norm(q[idx], axis=1, keepdims=True)
    return out


def heading_axis(result: Any) -> str:
    """The pelvis sensor axis (``"x"``, ``"-z"``, …) closest to lowerlimb's pelvis anterior axis."""
    q = result.calibration_dict()["segment_frames"]["pelvis"]["quat_wxyz_segment_in_sensor"]
    anterior = quat_to_matrix(np.asarray(q))[:, 0]
    k = int(np.argmax(np.abs(anterior)))
    return ("-" if anterior[k] < 0 else "") + "xyz"[k]


def write_tables(
    time_s: np.ndarray, quats: dict[str, np.ndarray], directory: Path, stem: str
) -> tuple[Path, Path]:
    """The trial table and the standing-calibration table (mean over STAND, two rows) of one source."""
    trial = directory / f"{stem}.sto"
    write_orientations_sto(trial, time_s, quats, world="opensim")
    standing = {s: np.tile(mean_quaternion(q[STAND]), (2, 1)) for s, q in quats.items()}
    calib = directory / f"{stem}_standing.sto"
    write_orientations_sto(calib, time_s[:2], standing, world="opensim")
    return trial, calib


def run_opensense(
    python: str,
    model: Path,
    trial: Path,
    calib: Path,
    out_dir: Path,
    axis: str,
    time_range: tuple[float, float],
) -> dict[str, Any]:
    """Placer + IK in a subprocess; the runner's JSON plus the subprocess wall time."""
    out_dir = out_dir.resolve()
    config = {
        "model": str(model.resolve()),
        "calibration_sto": str(calib.resolve()),
        "orientations_sto": str(trial.resolve()),
        "out_dir": str(out_dir),
        "base_heading_axis": axis,
        "time_range": list(time_range),
    }
    cfg = out_dir.with_suffix(".json")
    cfg.write_text(json.dumps(config), encoding="utf-8")
    t0 = time.perf_counter()
    out_dir.mkdir(parents=True, exist_ok=True)  # OpenSim writes opensim.log into its working directory
    proc = subprocess.run(
        [python, str(RUNNER), str(cfg)], capture_output=True, text=True, check=False, cwd=out_dir
    )
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"OpenSense failed ({proc.returncode}): {proc.stderr.strip()[-2000:]}")
    res: dict[str, Any] = json.loads(proc.stdout.strip().splitlines()[-1])
    res["subprocess_s"] = wall
    return res


def read_mot(path: Path, n_samples: int, rate_hz: float) -> dict[str, np.ndarray]:
    """An OpenSim .mot (degrees) as column -> (n_samples,) on the trial's frames (NaN where absent)."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    end = next(i for i, ln in enumerate(lines) if ln.strip() == "endheader")
    labels = lines[end + 1].split()
    data = np.array([[float(v) for v in ln.split()] for ln in lines[end + 2 :] if ln.strip()])
    frame = np.rint(data[:, 0] * rate_hz).astype(int)
    out = {}
    for j, name in enumerate(labels[1:], start=1):
        col = np.full(n_samples, np.nan)
        ok = (frame >= 0) & (frame < n_samples)
        col[frame[ok]] = data[ok, j]
        out[name] = col
    return out


def vicon_flexion(vicon: dict, side: str) -> dict[str, np.ndarray]:
    """Vicon knee, hip and ankle flexion (deg, flexion/dorsiflexion positive)."""
    P = side[0].upper()
    return {
        "knee": vicon[f"{P}_Femur_{P}_Tibia"][0].astype(float),
        "hip": -vicon[f"Root_{P}_Femur"][:, 0].astype(float),
        "ankle": -vicon[f"{P}_Tibia_{P}_Foot"][:, 0].astype(float),
    }


def score(series: np.ndarray, reference: np.ndarray, quantity: str) -> dict[str, Any]:
    """Both zeroed on the standing frames, agreement over the walking frames."""
    ours = series - np.nanmean(series[STAND])
    ref = reference - np.nanmean(reference[STAND])
    return agreement_statistics(ours[WALK], ref[WALK], quantity=quantity, unit="deg").to_dict()


def leg_quaternions(quats: dict[str, np.ndarray], side: str) -> dict[str, np.ndarray]:
    """The pelvis and one leg's sensors of a two-leg set (``left_thigh`` …)."""
    return {"pelvis": quats["pelvis"]} | {
        f"{side}_{s}": quats[f"{side}_{s}"] for s in ("thigh", "shank", "foot")
    }


def run(data: Path, python: str, work: Path) -> dict[str, Any]:
    """The whole benchmark; OpenSense's files go to ``work``.

    OpenSense runs once per leg with that leg's four IMUs for each orientation source
    (our two one-leg runs need not share the pelvis heading: one may fuse the
    magnetometer and the other not), and once with all seven Xsens IMUs.
    """
    vicon = load_vicon(data)
    results: dict[str, Any] = {}
    timings: dict[str, float] = {}
    trials = {side: load_leg(data, side) for side in SIDES}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ll.process_trial(trials["left"])  # warm-up: imports, CasADi and Pinocchio set-up
        for side in SIDES:
            t0 = time.perf_counter()
            results[side] = ll.process_trial(trials[side])
            timings[f"lowerlimb_{side}_s"] = time.perf_counter() - t0
    time_s = trials["left"].time_s
    n, rate = time_s.size, trials["left"].rate_hz
    xsens = read_xsens_quaternions(data / "gait" / "rawimu", n)
    axis = heading_axis(results["left"])
    model = data / "opensim" / "Rajagopal_2015.osim"
    runs: dict[str, dict[str, Any]] = {}
    angles: dict[str, dict[str, np.ndarray]] = {}
    jobs: dict[str, dict[str, np.ndarray]] = {"xsens_both": xsens}
    for side in SIDES:
        motion = results[side].motion.sensor_quat_wxyz
        jobs[f"ours_{side}"] = {"pelvis": motion["pelvis"]} | {
            f"{side}_{s}": motion[s] for s in ("thigh", "shank", "foot")
        }
        jobs[f"xsens_{side}"] = leg_quaternions(xsens, side)
    for name, quats in jobs.items():
        sto, calib = write_tables(time_s, quats, work, name)
        t_range = (float(time_s[0]), float(time_s[-1]))
        runs[name] = run_opensense(python, model, sto, calib, work / f"opensense_{name}", axis, t_range)
        angles[name] = read_mot(Path(runs[name]["motion"]), n, rate)
    rows = []
    for side in SIDES:
        ref = vicon_flexion(vicon, side)
        ang = np.degrees(results[side].angles_rad)
        for joint, (column, stem) in JOINT_COLUMNS.items():
            coordinate = f"{stem}_{side[0]}"
            candidates = {
                "OpenSense + our orientations": angles[f"ours_{side}"][coordinate],
                "OpenSense + Xsens orientations": angles[f"xsens_{side}"][coordinate],
                "OpenSense + Xsens orientations, 7 IMUs": angles["xsens_both"][coordinate],
                "lowerlimb angles": ang[:, list(ANGLE_COLUMNS[1:]).index(column)],
            }
            for method, series in candidates.items():
                rows.append(
                    {"side": side, "joint": joint, "method": method} | score(series, ref[joint], column)
                )
    return {
        "trial_s": float(time_s[-1] - time_s[0]),
        "samples": int(n),
        "standing_frames": [STAND.start, STAND.stop],
        "scored_frames": [WALK.start, WALK.stop],
        "base_heading_axis": axis,
        "magnetometer_used": {s: r.used_mag for s, r in results.items()},
        "timings_s": timings
        | {
            f"opensense_{k}_{p}_s": v[f"{p}_s"]
            for k, v in runs.items()
            for p in ("placer", "ik", "subprocess")
        },
        "opensim_version": runs["xsens_both"]["opensim_version"],
        "issue_reference": ISSUE_REFERENCE,
        "rows": rows,
    }


def to_markdown(res: dict[str, Any]) -> str:
    """The results as a Markdown page."""
    t = res["timings_s"]
    lines = [
        "# OpenSense vs lowerlimb on the real walk (gait/, Xsens MTw + Vicon)",
        "",
        f"Trial: {res['trial_s']:.1f} s, {res['samples']} samples at 100 Hz, both legs. Every series is "
        + "zeroed on its mean over the standing frames {}–{} and scored against Vicon over the walking "
        "frames {}–{} ".format(*res["standing_frames"], *res["scored_frames"])
        + "(difference = method − Vicon, deg). OpenSense: OpenSim "
        f"{res['opensim_version']}, Rajagopal 2015, IMUPlacer on the mean standing orientation (default "
        f"pose), base heading axis `{res['base_heading_axis']}` of the pelvis IMU, then "
        "IMUInverseKinematicsTool on the whole trial.",
        "",
        "| side | joint | method | RMSE ° | bias ° | SD ° | 95 % LoA ° | r | CMC |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        lines.append(
            f"| {r['side']} | {r['joint']} | {r['method']} | {r['rmse']:.1f} | {r['bias']:+.1f} | "
            f"{r['sd_diff']:.1f} | "
            f"{r['loa_lower']:+.1f} … {r['loa_upper']:+.1f} | {r['pearson_r']:.3f} | {_f(r['cmc'])} |"
        )
    ref = res["issue_reference"]
    lines += [
        "",
        "Wall time (s; lowerlimb = whole `process_trial`: calibration, filters, angles, positions; "
        "OpenSense = placer + IK inside the OpenSim process, start-up excluded):",
        "",
        "| what | s |",
        "|---|---|",
        f"| lowerlimb, left leg | {t['lowerlimb_left_s']:.1f} |",
        f"| lowerlimb, right leg | {t['lowerlimb_right_s']:.1f} |",
    ]
    for key, label in (
        ("ours_left", "OpenSense + our orientations, left leg (4 IMUs)"),
        ("ours_right", "OpenSense + our orientations, right leg (4 IMUs)"),
        ("xsens_left", "OpenSense + Xsens orientations, left leg (4 IMUs)"),
        ("xsens_right", "OpenSense + Xsens orientations, right leg (4 IMUs)"),
        ("xsens_both", "OpenSense + Xsens orientations, both legs (7 IMUs)"),
    ):
        lines.append(f"| {label} | {t[f'opensense_{key}_placer_s']:.1f} + {t[f'opensense_{key}_ik_s']:.1f} |")
    lines += [
        "",
        "Knee flexion RMSE, left / right: "
        + "; ".join(
            f"{m} {_knee(res, m, 'left'):.1f} / {_knee(res, m, 'right'):.1f}°"
            for m in ("OpenSense + Xsens orientations", "OpenSense + our orientations", "lowerlimb angles")
        )
        + ".",
        "",
        f"Issue 13's reference: OpenSense with Xsens orientations, knee RMSE {ref['knee_rmse_deg'][0]}–"
        f"{ref['knee_rmse_deg'][1]}°, {ref['wall_s']:.0f} s for the {ref['trial_s']:.0f} s trial. "
        f"Magnetometer fused by lowerlimb: {res['magnetometer_used']}.",
        "",
    ]
    return "\n".join(lines)


def _knee(res: dict[str, Any], method: str, side: str) -> float:
    return float(
        next(r["rmse"] for r in res["rows"] if (r["method"], r["side"], r["joint"]) == (method, side, "knee"))
    )


def _f(v: float | None) -> str:
    return "—" if v is None or not np.isfinite(v) else f"{v:.3f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--keep", type=Path, help="keep OpenSense's files in this folder")
    args = ap.parse_args()
    python = opensim_python()
    if python is None:
        sys.exit("opensim is not importable; pip install opensim, or set LOWERLIMB_OPENSIM_PYTHON")
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        res = run(args.data, python, work)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "opensense.json").write_text(json.dumps(res, indent=1), encoding="utf-8")
    md = to_markdown(res)
    (args.out / "opensense.md").write_text(md, encoding="utf-8")
    print(md)


if __name__ == "__main__":
    main()
