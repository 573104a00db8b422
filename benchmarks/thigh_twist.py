"""Undoing the thigh sensor's twist with hip flexion (``CalibrationOptions.thigh_twist``), simulated and real.

1. **Signature.** The thigh sensor's rate about the femur minus the shank sensor's about the
   tibia (each sensor's up at standing), regressed on the thigh's sagittal rate (about the knee
   axis made horizontal) together with the knee's flexion rate, while the shank moves: the
   coefficient of the thigh's rate, rad/rad. A sensor turning ``k`` about the femur per rad of
   hip flexion adds ``k``. Real walk (each leg) and simulated walks: rigid sensors, knees that
   turn as they flex (``knee_rotation_per_flexion=0.2``), and thigh sensors turning internally
   by 0.15 and 0.3 rad per rad of hip flexion (``Artefacts.skin_twist_driver["thigh"] = "hip"``).
2. **Simulated walks** (``simulate_bilateral(pace="slow")``, the real walk's pace, 60 s, seeds
   201–203, each leg as a one-leg trial through ``process_trial``) with the option off and on:
   the twist found (internal, rad/rad), the standing knee axis mismatch before and after,
   thigh and shank length errors and the angles' RMSE against the truth (after 3 s). Profiles:
   the four above and ``own 3, shared ½`` of ``sim_signatures.py`` with the hip twist 0.3.
3. **Real walk** (``gait/``, Xsens + Vicon): each leg as a one-leg trial (``real_gait.py``'s
   metrics against Plug-in Gait) and both legs through ``calibrate`` (``bilateral_gait.py``'s:
   lengths, knee and hip flexion, the angle between the two legs' pelvis frames, stride length
   and step width), off and on.

Usage: ``python benchmarks/thigh_twist.py [--data ../shared/data] [--seeds 201 202 203]
[--out benchmarks/results]``; writes ``thigh_twist.{md,json}``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import lowerlimb as ll
from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.thigh_twist import gyro_evidence
from lowerlimb.conventions import ANGLE_COLUMNS
from lowerlimb.io.trial import ImuTrial
from lowerlimb.model.fallback import segment_lengths
from lowerlimb.simulation import Artefacts, simulate_bilateral

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bilateral_gait  # noqa: E402
from _realwalk import load_vicon  # noqa: E402
from _results import write_results  # noqa: E402
from gait import true_leg  # noqa: E402
from real_gait import evaluate, load_leg  # noqa: E402
from sim_signatures import _hip_twist, _own  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ANGLES = list(ANGLE_COLUMNS[1:])
SCORED = ("hip_flexion", "hip_adduction", "knee_flexion", "knee_internal_rotation", "ankle_internal_rotation")
ON = CalibrationOptions(thigh_twist=True)
SKIP_S = 3.0


def _quiet(f: Callable[..., Any], *a: Any, **k: Any) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*a, **k)


#: name → (artefact profile of a seed or None, knee rotation per rad of flexion)
PROFILES: dict[str, tuple[Callable[[int], Artefacts] | None, float]] = {
    "rigid": (None, 0.0),
    "knees turning 0.2": (None, 0.2),
    "hip twist 0.15": (_hip_twist(lambda seed: None, 0.15), 0.0),
    "hip twist 0.3": (_hip_twist(lambda seed: None, 0.3), 0.0),
    "own 3, shared ½, hip twist 0.3": (_hip_twist(_own(3.0, 0.5), 0.3), 0.0),
}


def twist_signature(trial: ImuTrial) -> float:
    """The thigh's axial rate minus the shank's, per unit of the thigh's sagittal rate (module docstring)."""
    n = max(1, trial.still_period().samples(0.5))
    return gyro_evidence(trial, _quiet(calibrate_leg, trial), n)


def _leg_scores(sim: Any, side: str, options: CalibrationOptions | None) -> dict[str, Any]:
    trial = sim.trial.leg(side)
    res = _quiet(ll.process_trial, trial, calibration_options=options)
    truth = segment_lengths(true_leg(sim.truth["legs"][side]["joints"]))
    err = [1000.0 * (e - t) for e, t in zip(segment_lengths(res.calibration), truth, strict=True)]
    i = ("left", "right").index(side)
    keep = sim.trial.time_s > SKIP_S
    rmse = np.sqrt(
        np.mean(np.rad2deg(res.angles_rad - sim.angles_rad[:, 9 * i : 9 * i + 9])[keep] ** 2, axis=0)
    )
    tw = res.calibration.thigh_twist
    return {
        "length_err_mm": err,
        "angle_rmse_deg": {a: float(rmse[ANGLES.index(a)]) for a in SCORED},
        "twist": None
        if tw is None
        else {
            "internal_per_flexion": tw.internal_per_flexion(side),
            "mismatch_before_deg": tw.mismatch_before_deg,
            "mismatch_after_deg": tw.mismatch_after_deg,
            "offset_from_axis_mm": 1000.0 * float(np.linalg.norm(tw.offset_from_axis_m)),
        },
    }


def sim_rows(seeds: list[int]) -> list[dict[str, Any]]:
    rows = []
    for name, (make, knee_rotation) in PROFILES.items():
        for seed in seeds:
            art = make(seed) if make is not None else None
            sim = simulate_bilateral(
                60.0, seed, artefacts=art, pace="slow", knee_rotation_per_flexion=knee_rotation
            )
            for side in ("left", "right"):
                row = {"profile": name, "seed": seed, "side": side}
                row["signature"] = twist_signature(sim.trial.leg(side))
                row["off"] = _leg_scores(sim, side, None)
                row["on"] = _leg_scores(sim, side, ON)
                rows.append(row)
                print(name, seed, side, round(row["signature"], 3), row["on"]["twist"], flush=True)
    return rows


REAL_KEYS = (
    "thigh_length_error_mm",
    "shank_length_error_mm",
    "knee_flexion_rmse_deg",
    "knee_flexion_bias_deg",
    "hip_flexion_rmse_straight_deg",
    "ankle_flexion_rmse_deg",
    "hip_ankle_rmse_mm",
)


def real_one_leg(data: Path) -> list[dict[str, Any]]:
    vicon = load_vicon(data)
    rows = []
    for side in ("left", "right"):
        trial = load_leg(data, side)
        row: dict[str, Any] = {"side": side, "signature": twist_signature(trial)}
        for label, options in (("off", None), ("on", ON)):
            res = _quiet(ll.process_trial, trial, calibration_options=options)
            row[label] = {k: evaluate(res, vicon, side)[k] for k in REAL_KEYS}
            tw = res.calibration.thigh_twist
            if tw is not None:
                row["twist"] = {
                    "internal_per_flexion": tw.internal_per_flexion(side),
                    "mismatch_before_deg": tw.mismatch_before_deg,
                    "mismatch_after_deg": tw.mismatch_after_deg,
                    "offset_from_axis_mm": 1000.0 * float(np.linalg.norm(tw.offset_from_axis_m)),
                }
        rows.append(row)
        print("real", side, row, flush=True)
    return rows


def real_two_legs(data: Path) -> dict[str, Any]:
    out = {}
    for label, twist in (("off", False), ("on", True)):
        res = _quiet(bilateral_gait.run, data, thigh_twist=twist)
        legs = res["legs"]
        out[label] = {
            "legs": {
                s: {
                    k: legs[s][k]
                    for k in ("thigh_err_mm", "shank_err_mm", "knee_flexion_rmse_deg", "hip_flexion_rmse_deg")
                }
                for s in legs
            },
            "pelvis_axes_angle_deg": res["hips"]["pelvis_axes_angle_deg"],
            "stride_length_err_pct": res["stride_length_err_pct"],
            "step_width_err_mm": res["step_width_err_mm"],
        }
    return out


def _med(vals: list[float]) -> float:
    return float(np.median(vals)) if vals else float("nan")


def _profile_line(name: str, rows: list[dict[str, Any]]) -> str:
    sig = _med([abs(r["signature"]) for r in rows])
    found = [r["on"]["twist"] for r in rows if r["on"]["twist"] is not None]
    k = _med([t["internal_per_flexion"] for t in found]) if found else float("nan")
    before = _med([abs(t["mismatch_before_deg"]) for t in found]) if found else float("nan")
    after = _med([abs(t["mismatch_after_deg"]) for t in found]) if found else float("nan")
    twist = [f"{k:+.2f}", f"{before:.1f} → {after:.1f}"] if found else ["–", "–"]
    cells = [name, f"{sig:.2f}", f"{len(found)}/{len(rows)}", *twist]
    for part in (0, 1):
        off = _med([abs(r["off"]["length_err_mm"][part]) for r in rows])
        on = _med([abs(r["on"]["length_err_mm"][part]) for r in rows])
        cells.append(f"{off:.0f} → {on:.0f}")
    for a in SCORED:
        off = _med([r["off"]["angle_rmse_deg"][a] for r in rows])
        on = _med([r["on"]["angle_rmse_deg"][a] for r in rows])
        cells.append(f"{off:.1f} → {on:.1f}")
    return "| " + " | ".join(cells) + " |"


def markdown(res: dict[str, Any]) -> str:
    lines = [
        "# Undoing the thigh sensor's twist with hip flexion (`CalibrationOptions.thigh_twist`)",
        "",
        "Generated by `benchmarks/thigh_twist.py` (definitions in its docstring).",
        "",
        f"## Simulated walks (seeds {', '.join(map(str, res['seeds']))}, both legs, the real walk's pace; "
        "medians over the legs, off → on)",
        "",
        "| profile | signature, rad/rad (abs) | twist found | internal twist found, rad/rad | "
        "knee axis mismatch, ° | thigh error, mm | shank error, mm | "
        + " | ".join(f"{a.replace('_', ' ')} RMSE, °" for a in SCORED)
        + " |",
        "|" + "---|" * (7 + len(SCORED)),
    ]
    for name in PROFILES:
        lines.append(_profile_line(name, [r for r in res["sim"] if r["profile"] == name]))
    if res.get("real"):
        lines += [
            "",
            "## Real walk (`gait/`), each leg alone, against Vicon Plug-in Gait (off → on)",
            "",
            "| side | signature, rad/rad | internal twist found, rad/rad | knee axis mismatch, ° | "
            "sensor from the femur axis, mm | " + " | ".join(k.replace("_", " ") for k in REAL_KEYS) + " |",
            "|" + "---|" * (5 + len(REAL_KEYS)),
        ]
        for r in res["real"]:
            t = {"internal_per_flexion": np.nan, "mismatch_before_deg": np.nan} | r.get("twist", {})
            t = {"mismatch_after_deg": np.nan, "offset_from_axis_mm": np.nan} | t
            cells = [
                r["side"],
                f"{r['signature']:+.2f}",
                f"{t['internal_per_flexion']:+.2f}",
                f"{t['mismatch_before_deg']:+.1f} → {t['mismatch_after_deg']:+.1f}",
                f"{t['offset_from_axis_mm']:.0f}",
            ]
            cells += [f"{r['off'][k]:+.1f} → {r['on'][k]:+.1f}" for k in REAL_KEYS]
            lines.append("| " + " | ".join(cells) + " |")
        two = res["real_two_legs"]
        lines += [
            "",
            "Both legs through `calibrate` (one shared pelvis), off → on:",
            "",
            "| quantity | left | right |",
            "|---|---|---|",
        ]
        for k in ("thigh_err_mm", "shank_err_mm", "knee_flexion_rmse_deg", "hip_flexion_rmse_deg"):
            cells = [
                f"{two['off']['legs'][s][k]:+.1f} → {two['on']['legs'][s][k]:+.1f}" for s in ("left", "right")
            ]
            lines.append(f"| {k.replace('_', ' ')} | " + " | ".join(cells) + " |")
        lines += [
            "",
            "| quantity | off | on |",
            "|---|---|---|",
            f"| angle between the two legs' pelvis frames, ° | {two['off']['pelvis_axes_angle_deg']:.0f} | "
            f"{two['on']['pelvis_axes_angle_deg']:.0f} |",
        ]
        for k, unit in (("stride_length_err_pct", "%"), ("step_width_err_mm", "mm")):
            o, n = two["off"][k], two["on"][k]
            label = k.replace("_", " ")
            lines.append(
                f"| {label} (median / worst) | {o['median_abs']:.1f} / {o['worst_abs']:.1f} {unit} | "
                f"{n['median_abs']:.1f} / {n['worst_abs']:.1f} {unit} |"
            )
    lines += ["", res.get("conclusion", ""), ""]
    return "\n".join(lines)


CONCLUSION = """What this says (seeds 201–203; written by hand from the tables):

1. **The real thigh sensors turn with the hip.** The real walk's signature (−0.29 / +0.51
   rad/rad, left / right) and the twist the option finds there (+0.33 / +0.59 internal) are those
   of a simulated thigh sensor turning 0.3 rad per rad of hip flexion (signature 0.26, found
   +0.33), where rigid sensors give 0.06 and knees that turn as they flex 0.07. Both real legs
   turn internally, as a soft-tissue effect of one body would.
2. **On the simulator the option undoes it.** Lengths 33 / 17 → 3 / 1 mm (thigh / shank,
   median), knee rotation 8.3 → 0.7°, knee flexion 1.6 → 0.2°; a twist of 0.15 likewise. Rigid
   walks are left alone (no leg reaches 6° of mismatch). With the sensors' own wobble as well
   (`own 3, shared ½`) the angles gain (knee rotation 7.0 → 1.7°) but not the lengths (thigh
   76 → 74 mm, shank 47 → 83 mm).
3. **Knees that turn as they flex are left alone.** Their 4° of mismatch on rigid sensors stays
   under the 6° at which a twist is sought (with 2°, a twist of 0.08 was found there, the thigh
   went 7 → 15 mm and knee rotation 6.4 → 8.1°); a sensor turning less than about 0.1 rad/rad is
   not undone either.
4. **On the real walk it trades lengths for angles, and the legs differ.** Against Vicon: knee
   flexion 10.5 → 9.5 / 4.7 → 3.6°, hip flexion on the straight passes 7.3 → 5.8 / 3.9 → 4.2°,
   ankle 4.8 → 5.6 / 3.8 → 2.5°; the two legs' pelvis frames 60° → 23° apart. The left thigh
   stays (−10 → −8 mm against Plug-in Gait) and its hip–ankle distance comes within 5 mm RMSE
   (23 without), but the right thigh goes +29 → +62 mm, the shanks to +10 / +20 mm, the right
   hip–ankle distance to 85 mm RMSE and the step width to 48.7 / 88.3 mm (median / worst; 12.9
   / 27.0 without). Before the leg's knee centre was fitted from more starts (0.5.4) the
   untwisted left knee took another basin: thighs +32 / +68 mm, step width 15.5 / 25.9 mm. On
   the simulator the untwisting lengthens the thighs by 30–60 mm and that is the truth; on the
   real walk either Plug-in Gait's right thigh is that short (functional references from the
   walk's own markers put it 27 mm longer, `marker_knee.md`) or the real sensor's motion
   differs from the model's in what the accelerometers see (a turn about a nearer axis, sliding
   as well). One walk cannot tell which, so the option stays off by default."""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--seeds", type=int, nargs="+", default=[201, 202, 203])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args()
    res: dict[str, Any] = {"seeds": args.seeds, "version": ll.__version__}
    if (args.data / "gait").is_dir():
        res["real"] = real_one_leg(args.data)
        res["real_two_legs"] = real_two_legs(args.data)
    res["sim"] = sim_rows(args.seeds)
    res["conclusion"] = CONCLUSION
    write_results(args.out, "thigh_twist", res, markdown(res))


if __name__ == "__main__":
    main()
