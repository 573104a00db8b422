"""An accelerometer or gyro read with the opposite sign: is it refused, and is a good trial never?

One sensor's ``acc_*`` (or ``gyr_*``) columns are negated, every sensor in turn, and the
trial goes through the pipeline (``lowerlimb.orientation.sign_check`` is on by default):

- simulated two-leg walks (``simulate_bilateral`` seeds 201–206, 60 s, rigid and with the
  real-walk artefact profile), 6-axis, at the normal and at the slow pace;
- simulated one-leg motions (walk, squat, half-squat, knee-lift, sit-to-stand, mixed;
  seeds 1–2, 40 s, rigid and with artefacts);
- the real walk of ``gait/`` (Xsens, both legs, 6-axis);
- unmodified one-leg motions with artefacts over many seeds (``soft_tissue``: false refusals).

Each cell says what happened: ``sign`` (refused by the sign check, naming that sensor),
``sign?`` (refused by it, naming another sensor or two), ``other`` (refused for another
reason: the wrong side, swapped columns, …), ``sign warning`` (calibrated, with the sign
check's ``InvertedSignWarning``), ``warned`` (calibrated, with an ``ImplausibleAnglesWarning``,
``lowerlimb.segments.angle_range``, or two legs' ``OppositeKneesWarning``), ``accepted``
(calibrated without these warnings: a silent wrong result). For the unmodified trials, anything but
``accepted`` is a false refusal (or warning).

Usage: ``python benchmarks/sign_check.py [--data DIR] [--out DIR]``; writes
``benchmarks/results/sign_check.{md,json}``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
import warnings
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lowerlimb.bilateral import process_bilateral_trial
from lowerlimb.bilateral.pelvis import OppositeKneesWarning
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.orientation.sign_check import InvertedSignError, InvertedSignWarning
from lowerlimb.pipeline import process_trial
from lowerlimb.segments.angle_range import ImplausibleAnglesWarning
from lowerlimb.simulation import Artefacts, simulate, simulate_bilateral
from lowerlimb.simulation.treadmill import TreadmillParams

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bilateral_gait as BG  # noqa: E402
from _realwalk import raw_dir  # noqa: E402
from _results import write_results  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SEEDS = (201, 202, 203, 204, 205, 206)
MOTIONS = ("walk", "squat", "half-squat", "knee-lift", "sit-to-stand", "mixed")
SIGNALS = ("acc", "gyr")
OUTCOMES = ("sign", "sign?", "sign warning", "other", "warned", "accepted")
#: Seeds of the unmodified soft-tissue motions (``soft_tissue`` section).
SOFT_SEEDS = tuple(range(3001, 3023))


def _outcome(run: Any, sensor: str | None) -> str:
    """What the pipeline did with the trial (module docstring's cells)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            run()
        except InvertedSignError as e:
            return "sign" if sensor is not None and e.sensors == (sensor.split("_")[-1],) else "sign?"
        except Exception as e:  # noqa: BLE001 — a refusal is a result here
            if isinstance(e.__cause__ or e.__context__, InvertedSignError) or "about the vertical" in str(e):
                named = str(e).split(": the ", 1)[-1].split(" turn", 1)[0]
                same = sensor is not None and named == sensor.split("_", 1)[-1]
                same = same and (sensor == "pelvis" or str(e).startswith(str(sensor).split("_")[0]))
                return "sign" if same else "sign?"
            return "other"
    if any(w.category is InvertedSignWarning for w in caught):
        return "sign warning"
    doubts = (ImplausibleAnglesWarning, OppositeKneesWarning)
    return "warned" if any(w.category in doubts for w in caught) else "accepted"


def _negated(values: dict[str, Any], sensor: str | None) -> dict[str, Any]:
    return {s: (-v if s == sensor else v) for s, v in values.items()}


def _two_leg_rows(trial: BilateralTrial, tag: str, **kw: Any) -> list[dict[str, Any]]:
    rows = [
        {
            "trial": tag,
            "sensor": "-",
            "signal": "-",
            "outcome": _outcome(lambda: process_bilateral_trial(trial, **kw), None),
        }
    ]
    for signal in SIGNALS:
        for sensor in trial.acc:
            t2 = BilateralTrial(
                trial.time_s,
                _negated(trial.acc, sensor if signal == "acc" else None),
                _negated(trial.gyr, sensor if signal == "gyr" else None),
            )
            outcome = _outcome(lambda t2=t2: process_bilateral_trial(t2, **kw), sensor)
            rows.append({"trial": tag, "sensor": sensor, "signal": signal, "outcome": outcome})
    return rows


def _one_leg_rows(trial: Any, tag: str) -> list[dict[str, Any]]:
    rows = [
        {"trial": tag, "sensor": "-", "signal": "-", "outcome": _outcome(lambda: process_trial(trial), None)}
    ]
    for signal in SIGNALS:
        for sensor in trial.acc:
            t2 = dataclasses.replace(trial, **{signal: _negated(getattr(trial, signal), sensor)})
            rows.append(
                {
                    "trial": tag,
                    "sensor": sensor,
                    "signal": signal,
                    "outcome": _outcome(lambda t2=t2: process_trial(t2), sensor),
                }
            )
    return rows


def simulated_two_legs(
    seeds: tuple[int, ...], pace: str = "normal", treadmill: bool = False
) -> list[dict[str, Any]]:
    """Each seed rigid and with artefacts, or rigid only on a treadmill."""
    rows: list[dict[str, Any]] = []
    for art in (None,) if treadmill else (None, Artefacts.real_walk()):
        for seed in seeds:
            tm = TreadmillParams() if treadmill else None
            sim = simulate_bilateral(60.0, seed, artefacts=art, pace=pace, treadmill=tm)
            rows += _two_leg_rows(sim.trial, f"{seed}{' artefacts' if art else ''}", use_mag=False)
    return rows


def simulated_one_leg() -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    for motion in MOTIONS:
        for art in (None, Artefacts.real_walk()):
            for seed in (1, 2):
                sim = simulate(motion, duration_s=40.0, seed=seed, artefacts=art)
                rows += _one_leg_rows(sim.trial, f"{motion} {seed}{' artefacts' if art else ''}")
    return rows


def soft_tissue() -> list[dict[str, Any]]:
    """Unmodified one-leg motions with the real-walk artefacts, many seeds: false refusals only."""
    rows: list[dict[str, Any]] = []
    for motion in MOTIONS:
        for seed in SOFT_SEEDS:
            sim = simulate(motion, duration_s=20.0, seed=seed, artefacts=Artefacts.real_walk())
            outcome = _outcome(lambda sim=sim: process_trial(sim.trial), None)
            rows.append({"trial": f"{motion} {seed}", "motion": motion, "outcome": outcome})
    return rows


def _soft_table(rows: list[dict[str, Any]]) -> list[str]:
    """Per motion, what became of the unmodified trials (anything but ``accepted`` is false)."""
    L = [f"| motion | {' | '.join(OUTCOMES)} |", "|---|" + "---|" * len(OUTCOMES)]
    for motion in dict.fromkeys(r["motion"] for r in rows):
        c = Counter(r["outcome"] for r in rows if r["motion"] == motion)
        L.append(f"| {motion} | {' | '.join(str(c[k]) for k in OUTCOMES)} |")
    return L


def real(data: Path) -> list[dict[str, Any]]:
    if not (raw_dir(data)).is_dir():
        return []
    csv = Path(tempfile.mkdtemp()) / "walk.csv"
    BG.load_xsens(raw_dir(data), BG.IDS).to_csv(csv)
    return _two_leg_rows(BilateralTrial.from_csv(csv), "real walk", use_mag=False)


def _table(rows: list[dict[str, Any]]) -> list[str]:
    """Per signal and sensor, the outcomes' counts over the trials; then the unmodified trials."""
    L = [f"| negated | sensor | {' | '.join(OUTCOMES)} |", "|---|---|" + "---|" * len(OUTCOMES)]
    keys = list(dict.fromkeys((r["signal"], r["sensor"]) for r in rows if r["sensor"] != "-"))
    for signal, sensor in keys:
        c = Counter(r["outcome"] for r in rows if (r["signal"], r["sensor"]) == (signal, sensor))
        cells = " | ".join(str(c[k]) for k in OUTCOMES)
        L.append(f"| {signal} | {sensor} | {cells} |")
    c = Counter(r["outcome"] for r in rows if r["sensor"] == "-")
    L.append(f"| nothing | (false refusals) | {' | '.join(str(c[k]) for k in OUTCOMES)} |")
    return L


def markdown(res: dict[str, list[dict[str, Any]]]) -> str:
    L = [
        "# Inverted accelerometer and gyro signs",
        "",
        "Generated by `benchmarks/sign_check.py`. One sensor's accelerometer (or gyro) columns",
        "negated, every sensor in turn. `sign`: refused by the sign check naming that sensor;",
        "`sign?`: refused by it naming another or two; `sign warning`: calibrated, with the",
        "sign check's warning (a sensor named by a weak axial witness alone, nearer zero than",
        "`SignCheckParams.min_refuse_axial`); `other`: refused for another reason; `warned`:",
        "calibrated with an implausible-angles warning, or with two legs' warning that the knees",
        "point apart (each leg then keeps its own pelvis; such trials were refused before",
        "0.5.13); `accepted`: calibrated without these (a silent wrong result). The last row",
        "counts the unmodified trials, where anything but `accepted` is a false refusal (or",
        "warning).",
        "",
    ]
    titles = {
        "real": "Real walk (`gait/`, both legs, 6-axis; one turn between two passes)",
        "two_legs": "Simulated two-leg walks (seeds 201–206, 60 s, straight; rigid and with artefacts)",
        "two_legs_slow": 'The same walks at the slow pace (`pace="slow"`: 0.55–0.85 m/s)',
        "one_leg": "Simulated one-leg motions (6 motions × seeds 1–2 × rigid / artefacts, 40 s)",
        "treadmill": "Simulated treadmill walks (seeds 201–206, 60 s, rigid; `treadmill=TreadmillParams()`: "
        "straight, no turn at all)",
        "treadmill_slow": 'The same treadmill walks at the slow pace (`pace="slow"`)',
    }
    for key, title in titles.items():
        if res.get(key):
            L += [f"## {title}", "", *_table(res[key]), ""]
    if res.get("soft_tissue"):
        L += [
            f"## Unmodified one-leg motions with soft tissue (seeds {SOFT_SEEDS[0]}–{SOFT_SEEDS[-1]}, "
            "20 s, the real-walk artefacts)",
            "",
            "Nothing negated: anything but `accepted` is false. These motions barely turn, so the",
            "knee's and ankle's axial witnesses decide; soft tissue turns the thigh sensor with the",
            "knee angle and gravity leaks into the knee's small axial acceleration (its correlation",
            "down to −0.83 in squats and sit-to-stands where the gyros fix the axes' direction).",
            "",
            *_soft_table(res["soft_tissue"]),
            "",
        ]
    return "\n".join(L)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument(
        "--sections",
        nargs="+",
        choices=tuple(SECTIONS),
        default=tuple(SECTIONS),
        help="run only these (the others are kept from the JSON already in --out)",
    )
    args = ap.parse_args()
    old = args.out / "sign_check.json"
    res = json.loads(old.read_text()) if old.is_file() else {}
    for name in args.sections:
        res[name] = SECTIONS[name](args.data)
    write_results(args.out, "sign_check", res, markdown(res))


SECTIONS: dict[str, Callable[[Path], list[dict[str, Any]]]] = {
    "real": real,
    "two_legs": lambda _: simulated_two_legs(SEEDS),
    "two_legs_slow": lambda _: simulated_two_legs(SEEDS, pace="slow"),
    "one_leg": lambda _: simulated_one_leg(),
    "treadmill": lambda _: simulated_two_legs(SEEDS, treadmill=True),
    "treadmill_slow": lambda _: simulated_two_legs(SEEDS, pace="slow", treadmill=True),
    "soft_tissue": lambda _: soft_tissue(),
}


if __name__ == "__main__":
    main()
