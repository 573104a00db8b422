"""Two input checks that catch wrong columns the range checks cannot.

A gyro's unit from its accelerometer, and one segment's sensors exchanged between the legs:

- **gyro unit** (``lowerlimb.io.gyro_scale``): the median angle by which each sensor's gyro,
  integrated between two quasi-static moments, misses the accelerometer's gravity (as given;
  scaled by π/180). Valid: simulated one-leg motions (walk, squat, half-squat, knee lift,
  sit-to-stand, mixed; seeds 1–3, 30 s; rigid and with the real-walk artefacts), the real walk's
  seven Xsens sensors (``gait/``), the rig's two (``rig/``), RING's five (rigid and non-rigid),
  the BROAD trials (``broad/``). Wrong: the same simulated trials with the gyro in deg/s, played
  1, 2, 3.5 and 5 times slower (the slower, the fewer reach the 35 rad/s range check), and with
  the gyro 57 times too small. A trial counts as caught when any of its sensors is refused.
- **exchanged legs** (``lowerlimb.bilateral.leg_pairing``): simulated seven-IMU walks (seeds
  201–206; normal, slow and shuffling paces, a treadmill, turns, the real-walk artefacts; 40 s)
  and the real walk, each as recorded and with the left and right thigh, shank or foot sensors
  exchanged: the knees' and ankles' crossed / as-given hinge residual ratios and the verdict.

Usage: ``python benchmarks/input_checks.py [--data ../shared/data] [--out benchmarks/results]``.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io as sio

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _realwalk import IDS, raw_dir  # noqa: E402
from _results import cell, real_data_main  # noqa: E402

from lowerlimb.bilateral.leg_pairing import LegPairingParams, leg_pairing  # noqa: E402
from lowerlimb.io import load_xsens  # noqa: E402
from lowerlimb.io.bilateral_trial import BilateralTrial  # noqa: E402
from lowerlimb.io.gyro_scale import gyro_scale  # noqa: E402
from lowerlimb.simulation import Artefacts, simulate, simulate_bilateral  # noqa: E402
from lowerlimb.simulation.bilateral_walk import TreadmillParams, TurnParams  # noqa: E402

MOTIONS = ("walk", "squat", "half-squat", "knee-lift", "sit-to-stand", "mixed")
SEEDS = (1, 2, 3)
SLOWDOWNS = (1.0, 2.0, 3.5, 5.0)
MAX_GYRO_RAD_S = 35.0
WALK_SEEDS = (201, 202, 203, 204, 205, 206)
SEGMENTS = ("thigh", "shank", "foot")
PLURAL = {"thigh": "thighs", "shank": "shanks", "foot": "feet"}


def _sensor_rows(source: str, acc: dict[str, Any], gyr: dict[str, Any], rate: float) -> list[dict[str, Any]]:
    rows = []
    for sensor in acc:
        s = gyro_scale(np.asarray(acc[sensor], float), np.asarray(gyr[sensor], float), rate)
        rows.append({"source": source, "sensor": sensor, "windows": s.n_windows, "as_given": s.as_given,
                     "verdict": s.verdict()})  # fmt: skip
    return rows


def valid_gyros(data: Path) -> list[dict[str, Any]]:
    """Every sensor of the valid recordings: where its gyro lands and the verdict."""
    rows = []
    for motion in MOTIONS:
        for seed in SEEDS:
            for art in ("rigid", "artefacts"):
                t = simulate(
                    motion, 30.0, seed, artefacts=Artefacts.real_walk(seed) if art != "rigid" else None
                )
                rows += _sensor_rows(f"sim {motion} {art}", t.trial.acc, t.trial.gyr, t.trial.rate_hz)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = load_xsens(raw_dir(data), IDS)
    rows += _sensor_rows("real walk", rec.acc, rec.gyr, 1.0 / float(np.median(np.diff(rec.time_s))))
    import rig
    import ring

    for trial in ("1D_01", "2D_01", "3D_01"):
        t = rig.load_trial(data, trial)
        acc, gyr = {"1": t["acc1"], "2": t["acc2"]}, {"1": t["gyr1"], "2": t["gyr2"]}
        rows += _sensor_rows(f"rig {trial}", acc, gyr, t["rate_hz"])
    for mount in ("rigid", "nonrigid"):
        imu = ring.load_imu(data / "ring" / f"trial1_imu_{mount}.csv")
        rows += _sensor_rows(f"RING {mount}", {str(k): v["acc"] for k, v in imu.items()},
                             {str(k): v["gyr"] for k, v in imu.items()}, ring.RATE_HZ)  # fmt: skip
    for f in sorted((data / "broad").glob("*.mat")):
        d = sio.loadmat(f)
        rows += _sensor_rows(f"BROAD {f.stem}", {"imu": d["imu_acc"]}, {"imu": d["imu_gyr"]},
                             float(np.squeeze(d["sampling_rate"])))  # fmt: skip
    return rows


def wrong_gyros() -> list[dict[str, Any]]:
    """Simulated trials with a deg/s gyro (played slower) or a gyro 57 times too small."""
    rows = []
    for case, factor in [*((f"deg/s, {k:g}x slower", k) for k in SLOWDOWNS), ("57x too small", None)]:
        for motion in MOTIONS:
            caught_range = caught_scale = n = 0
            for seed in SEEDS:
                t = simulate(motion, 30.0, seed).trial
                slow = factor or 1.0
                gyr = {k: (np.degrees(g) / slow if factor else np.radians(g)) for k, g in t.gyr.items()}
                rate = t.rate_hz / slow
                n += 1
                if factor and max(float(np.abs(g).max()) for g in gyr.values()) > MAX_GYRO_RAD_S:
                    caught_range += 1
                elif any(gyro_scale(t.acc[k], gyr[k], rate).verdict() is not None for k in gyr):
                    caught_scale += 1
            rows.append({"case": case, "motion": motion, "trials": n, "range_check": caught_range,
                         "gyro_scale": caught_scale})  # fmt: skip
    return rows


def _exchanged(trial: BilateralTrial, segment: str) -> BilateralTrial:
    acc, gyr = dict(trial.acc), dict(trial.gyr)
    for d in (acc, gyr):
        d[f"left_{segment}"], d[f"right_{segment}"] = d[f"right_{segment}"], d[f"left_{segment}"]
    return BilateralTrial(trial.time_s, acc, gyr, None)


def _pairing_row(source: str, trial: BilateralTrial) -> dict[str, Any]:
    p = LegPairingParams()
    found = leg_pairing(trial, p)
    row: dict[str, Any] = {
        "source": source,
        "knee_ratio": found.knees_crossed / found.knees,
        "ankle_ratio": found.ankles_crossed / found.ankles,
        "as_recorded": found.exchanged(p),
    }
    for segment in SEGMENTS:
        row[segment] = leg_pairing(_exchanged(trial, segment), p).exchanged(p)
    return row


def exchanged_legs(data: Path) -> list[dict[str, Any]]:
    """The leg-pairing test on valid walks, as recorded and with each segment exchanged."""
    kinds: dict[str, dict[str, Any]] = {
        "normal": {}, "slow": {"pace": "slow"}, "shuffle": {"pace": "shuffle"},
        "treadmill": {"treadmill": TreadmillParams()}, "turns": {"turns": TurnParams()}, "artefacts": {},
    }  # fmt: skip
    rows = []
    for seed in WALK_SEEDS:
        for kind, kw in kinds.items():
            extra = {"artefacts": Artefacts.real_walk(seed)} if kind == "artefacts" else {}
            rows.append(
                _pairing_row(f"sim {seed} {kind}", simulate_bilateral(40.0, seed, **kw, **extra).trial)
            )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = load_xsens(raw_dir(data), IDS)
    rows.append(_pairing_row("real walk", BilateralTrial(rec.time_s, rec.acc, rec.gyr, None)))
    return rows


def run(data: Path) -> dict[str, Any]:
    return {
        "valid_gyros": valid_gyros(data),
        "wrong_gyros": wrong_gyros(),
        "exchanged_legs": exchanged_legs(data),
    }


def markdown(res: dict[str, Any]) -> str:
    md = [
        "# Input checks: a gyro's unit from its accelerometer, sensors exchanged between the legs",
        "",
        "Generated by `benchmarks/input_checks.py` (sources in its docstring).",
        "",
        "## Gyro unit (`lowerlimb.io.gyro_scale`): valid recordings",
        "",
        "Median angle (deg) by which the gyro, integrated between quasi-static moments, misses the "
        "accelerometer's gravity; a sensor is refused as deg/s beyond 30° (when π/180 lands within a "
        "quarter of it). *refused*: sensors of valid recordings refused (false refusals).",
        "",
        "| source | sensors | decided (≥ 20 windows) | landing deg, median | worst | refused |",
        "|---|---|---|---|---|---|",
    ]
    groups: dict[str, list[dict[str, Any]]] = {}
    for r in res["valid_gyros"]:
        key = r["source"].split(" ")[0] if r["source"].startswith(("BROAD", "rig")) else r["source"]
        groups.setdefault(key, []).append(r)
    for key, rows in groups.items():
        given = np.array([r["as_given"] for r in rows], float)
        ok = given[np.isfinite(given)]
        md.append(
            f"| {key} | {len(rows)} | {ok.size} | {cell(float(np.median(ok)) if ok.size else None)} | "
            f"{cell(float(ok.max()) if ok.size else None)} | {sum(r['verdict'] is not None for r in rows)} |"
        )
    md += [
        "",
        "## Gyro unit: wrong gyros (simulated, 3 seeds per motion)",
        "",
        "Trials caught by the range check (a gyro above 35 rad/s) and, of the rest, by the gyro-scale check.",
        "",
        "| case | motion | trials | range check | gyro scale | missed |",
        "|---|---|---|---|---|---|",
    ]
    for r in res["wrong_gyros"]:
        missed = r["trials"] - r["range_check"] - r["gyro_scale"]
        counts = f"{r['trials']} | {r['range_check']} | {r['gyro_scale']} | {missed}"
        md.append(f"| {r['case']} | {r['motion']} | {counts} |")
    md += [
        "",
        "## Sensors exchanged between the legs (`lowerlimb.bilateral.leg_pairing`)",
        "",
        "Crossed / as-given sum of the two legs' hinge residuals (a thigh or shank exchange is refused "
        "below 0.8 at the knees, a foot exchange below 0.7 at the ankles); the verdict as recorded "
        "(should be none) and with each segment's left and right sensors exchanged (should name it).",
        "",
        "| source | knees ratio | ankles ratio | as recorded | thighs exchanged | shanks exchanged "
        "| feet exchanged |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in res["exchanged_legs"]:
        v = [r[k] or "–" for k in ("as_recorded", *SEGMENTS)]
        md.append(f"| {r['source']} | {r['knee_ratio']:.2f} | {r['ankle_ratio']:.2f} | {' | '.join(v)} |")
    rows = res["exchanged_legs"]
    md += [
        "",
        f"Valid recordings refused: {sum(r['as_recorded'] is not None for r in rows)} of {len(rows)}; "
        + ", ".join(
            f"{PLURAL[s]} named {sum(r[s] == s for r in rows)} of {len(rows)}"
            f" ({sum(r[s] == 'thigh or shank' for r in rows)} as thigh or shank,"
            f" {sum(r[s] not in (None, s, 'thigh or shank') for r in rows)} wrongly)"
            for s in SEGMENTS
        )
        + ". *thigh or shank*: the knees say that one of the two was exchanged and the ankles, within "
        "5 % of 1, cannot tell which (`LegPairingParams.ankle_margin`): the message names both.",
        "",
    ]
    return "\n".join(md)


if __name__ == "__main__":
    real_data_main(__doc__, "input_checks", run, markdown)
