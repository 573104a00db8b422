"""Which knee axis should set the thigh frame? The real walk's hip flexion against a thigh-twisting simulator.

The thigh frame (:mod:`lowerlimb.segments.frames`) takes its z axis from the knee axis
estimated in the thigh sensor and its y axis from the hip centre, made orthogonal to z
(Hu et al. 2021 eq. 30–33). On the real walk of ``gait/`` that estimate lies 15–20° off
the horizontal at standing, where the shank sensor's estimate of the same axis and
Plug-in Gait's knee axis lie within 9°: the thigh's y axis then leans sideways off the
femur, and the hip's axial rotation in walking swings it forwards and backwards, which
shows as a flexion offset of opposite sign on the two legs (``docs/limits.md``).

Four thigh frames, each built from the same processed trial (heading-corrected sensor
orientations, the same calibration; every other segment frame is the thigh frame at the
standing reference, as in the library), then the Z-X-Y angles:

- ``knee axis`` — the library's frame (z = the thigh sensor's knee axis; reproduces the
  pipeline's angles to 0.01°, checked);
- ``shank's axis`` — z = the shank sensor's knee axis carried into the thigh sensor at
  the standing reference;
- ``mechanical axis`` — ISB's femur (Wu et al. 2002): y from the knee centre to the hip
  centre, the knee centre being the point of the knee axis nearest the hip–ankle line at
  standing; z = the thigh's knee axis made orthogonal to y;
- ``relative rotation`` — z = the principal axis of the shank's angular velocity relative
  to the thigh, in the thigh sensor (gyros and the heading-corrected orientations).

Scored on:

1. the real walk, each leg as a one-leg trial: hip, knee and ankle flexion RMSE on the
   straight passes against Vicon (as ``real_gait.py``), and the knee axis's elevation at
   standing from the thigh sensor, the shank sensor and Plug-in Gait (KJC→KNE);
2. simulated 60 s walks (noise + bias, 6-axis) against the simulator's truth: rigid
   sensors, the real-walk artefact profile, and that profile with the thigh sensor
   twisting internally about the femur by 0.15 or 0.3 rad per rad of knee flexion
   (:attr:`~lowerlimb.simulation.Artefacts.skin_twist_rad_per_rad`; internal on either leg and
   carrying the sensor round the bone since 2026-12-03).

Usage: ``python benchmarks/knee_axis_frames.py [--data ../shared/data] [--out DIR]
[--seeds 6]``; writes ``knee_axis_frames.{md,json}``. Without the data folder the real
rows are left out.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import lowerlimb as ll
from lowerlimb.conventions import ANGLE_COLUMNS, quat_to_matrix
from lowerlimb.model.calibrated import knee_center_pair
from lowerlimb.pipeline import TrialResult
from lowerlimb.segments.angles import compute_joint_angles
from lowerlimb.segments.frames import SegmentFrames, mean_quaternion, thigh_frame_in_sensor
from lowerlimb.simulation import Artefacts, ImuNoise, simulate

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _realwalk import STAND, load_vicon  # noqa: E402
from _results import write_results  # noqa: E402
from real_gait import load_leg, straight_passes  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = ("knee axis", "shank's axis", "mechanical axis", "relative rotation")
NAMES = list(ANGLE_COLUMNS[1:])
TWISTS = (0.15, 0.3)


def _unit(v: np.ndarray) -> np.ndarray:
    return np.asarray(v, dtype=float) / np.linalg.norm(v)


def _reference(result: TrialResult) -> dict[str, np.ndarray]:
    """(3, 3) sensor → earth rotation of each sensor averaged over the standing reference."""
    trial = result.trial
    ref = trial.reference_samples(trial.still_period())
    return {s: quat_to_matrix(mean_quaternion(q[ref])) for s, q in result.motion.sensor_quat_wxyz.items()}


def thigh_axes(result: TrialResult, variant: str) -> np.ndarray:
    """(3, 3) thigh frame in the thigh sensor (columns x, y, z) of one variant."""
    cal, R = result.calibration, _reference(result)
    hip = np.asarray(cal.hip.center_in_child_sensor, dtype=float)
    jt = _unit(cal.knee.axis_in_parent_sensor)
    if variant == "knee axis":
        return thigh_frame_in_sensor(hip, cal.knee.center_in_parent_sensor, cal.knee.axis_in_parent_sensor)
    if variant == "shank's axis":
        js = R["thigh"].T @ R["shank"] @ _unit(cal.knee.axis_in_child_sensor)
        return thigh_frame_in_sensor(hip, cal.knee.center_in_parent_sensor, js)
    if variant == "relative rotation":
        return thigh_frame_in_sensor(hip, cal.knee.center_in_parent_sensor, relative_rotation_axis(result))
    kt, ks = knee_center_pair(cal)
    ankle = kt + R["thigh"].T @ R["shank"] @ (np.asarray(cal.ankle.center_in_parent_sensor, float) - ks)
    d = _unit(ankle - hip)
    # the point kt + s jt nearest the line hip + u d
    w = kt - hip
    b, e, f = jt @ d, jt @ w, d @ w
    knee = kt + (b * f - e) / (1.0 - b * b) * jt
    y = _unit(hip - knee)
    z = _unit(jt - (jt @ y) * y)
    return np.column_stack([np.cross(y, z), y, z])


def relative_rotation_axis(result: TrialResult) -> np.ndarray:
    """(3,) principal axis of the shank's angular velocity relative to the thigh, thigh sensor frame.

    From the gyros (bias removed) and the heading-corrected orientations: ``ω_t − R_tᵀ R_s ω_s``;
    the eigenvector of its largest second moment, signed like the calibrated axis.
    """
    trial, cal, q = result.trial, result.calibration, result.motion.sensor_quat_wxyz
    R_t, R_s = quat_to_matrix(q["thigh"]), quat_to_matrix(q["shank"])
    w_t = trial.gyr["thigh"] - cal.gyro_bias.get("thigh", np.zeros(3))
    w_s = trial.gyr["shank"] - cal.gyro_bias.get("shank", np.zeros(3))
    rel = w_t - np.einsum("nji,njk,nk->ni", R_t, R_s, w_s)
    axis = np.linalg.eigh(rel.T @ rel)[1][:, -1]
    return axis if axis @ cal.knee.axis_in_parent_sensor > 0 else -axis


def angles(result: TrialResult, variant: str) -> np.ndarray:
    """(N, 9) ISB angles (deg) with the variant's thigh frame; every other frame as the library's."""
    R = _reference(result)
    thigh = thigh_axes(result, variant)
    earth_thigh = R["thigh"] @ thigh
    frames = {"thigh": thigh} | {s: R[s].T @ earth_thigh for s in ("pelvis", "shank", "foot")}
    seg = SegmentFrames(frames, result.trial.side).segment_quaternions(result.motion.sensor_quat_wxyz)
    return np.degrees(np.asarray(compute_joint_angles(seg, result.trial.side)))


def elevations(result: TrialResult) -> dict[str, float]:
    """The knee axis's elevation above the horizontal at standing from each sensor, deg."""
    cal, R = result.calibration, _reference(result)
    out = {}
    for name, R_s, j in (
        ("thigh", R["thigh"], cal.knee.axis_in_parent_sensor),
        ("shank", R["shank"], cal.knee.axis_in_child_sensor),
    ):
        out[name] = float(np.degrees(np.arcsin(np.clip((R_s @ _unit(j))[2], -1.0, 1.0))))
    return out


def _process(trial: ll.ImuTrial) -> TrialResult:
    """The library's pipeline, gyro and accelerometer only (the real walk's field is rejected)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ll.process_trial(trial, use_mag=False)


def _check_default(result: TrialResult) -> None:
    np.testing.assert_allclose(angles(result, "knee axis"), np.degrees(result.angles_rad), atol=0.01)


def real_rows(data: Path) -> list[dict[str, Any]]:
    vicon = load_vicon(data)
    rows = []
    for side in ("left", "right"):
        P = side[0].upper()
        result = _process(load_leg(data, side))
        _check_default(result)
        straight = straight_passes(vicon, side)
        refs = {
            "hip_flexion": -vicon[f"Root_{P}_Femur"][:, 0],
            "knee_flexion": vicon[f"{P}_Femur_{P}_Tibia"][0],
            "ankle_dorsiflexion": -vicon[f"{P}_Tibia_{P}_Foot"][:, 0],
        }
        kne = (vicon[P + "KNE"] - vicon[P + "KJC"])[STAND].mean(axis=0) * (-1.0 if side == "left" else 1.0)
        elev = elevations(result) | {"plug_in_gait": float(np.degrees(np.arcsin(_unit(kne)[2])))}
        for variant in VARIANTS:
            ang = angles(result, variant)
            row: dict[str, Any] = {"side": side, "variant": variant, "elevation_deg": elev}
            for k, ref in refs.items():
                o = ang[:, NAMES.index(k)] - np.nanmean(ang[STAND, NAMES.index(k)])
                r = ref - np.nanmean(ref[STAND])
                row[f"{k}_rmse_deg"] = float(np.sqrt(np.nanmean((o[straight] - r[straight]) ** 2)))
            rows.append(row)
    return rows


def sim_rows(seeds: int) -> list[dict[str, Any]]:
    rows = []
    base = Artefacts.real_walk()
    profiles: dict[str, Artefacts | None] = {"rigid": None, "artefacts": base} | {
        f"artefacts, thigh twist {c}": dataclasses.replace(
            base, skin_twist_rad_per_rad={**base.skin_twist_rad_per_rad, "thigh": c}
        )
        for c in TWISTS
    }
    for label, art in profiles.items():
        errs: dict[str, list[np.ndarray]] = {v: [] for v in VARIANTS}
        mismatch = []
        for k in range(seeds):
            sim = simulate(
                "walk", 60.0, 100 + k, side="left" if k % 2 == 0 else "right", noise=ImuNoise(), artefacts=art
            )
            result = _process(sim.trial)
            _check_default(result)
            e = elevations(result)
            mismatch.append(abs(e["thigh"] - e["shank"]))
            for v in VARIANTS:
                d = angles(result, v) - np.degrees(sim.angles_rad)
                errs[v].append(np.sqrt(np.mean(d**2, axis=0)))
        for v in VARIANTS:
            a = np.array(errs[v])
            rows.append(
                {
                    "sensors": label,
                    "variant": v,
                    "seeds": seeds,
                    "median_rmse_deg": dict(zip(NAMES, np.median(a, axis=0).tolist(), strict=True)),
                    "worst_rmse_deg": dict(zip(NAMES, a.max(axis=0).tolist(), strict=True)),
                    "axis_mismatch_deg_median": float(np.median(mismatch)),
                    "axis_mismatch_deg_max": float(np.max(mismatch)),
                }
            )
    return rows


def markdown(res: dict[str, Any]) -> str:
    L = [
        "# Which knee axis sets the thigh frame: the real walk and a thigh-twisting simulator",
        "",
        "Generated by `benchmarks/knee_axis_frames.py`. Four thigh frames on the same processed",
        "trials (module docstring): `knee axis` (the library's), `shank's axis`, `mechanical axis`",
        "(ISB femur, y primary), `relative rotation` (principal axis of the relative angular velocity).",
        "",
    ]
    if res["real"]:
        L += [
            "## Real walk (one leg at a time; straight passes, zeroed on standing; RMSE deg against Vicon)",
            "",
            "| side | knee axis elevation at standing, deg: thigh / shank / Plug-in Gait | variant "
            "| hip flexion | knee flexion | ankle dorsiflexion |",
            "|---|---|---|---|---|---|",
        ]
        for r in res["real"]:
            e = r["elevation_deg"]
            L.append(
                f"| {r['side']} | {e['thigh']:+.1f} / {e['shank']:+.1f} / {e['plug_in_gait']:+.1f} | "
                f"{r['variant']} | {r['hip_flexion_rmse_deg']:.1f} | {r['knee_flexion_rmse_deg']:.1f} | "
                f"{r['ankle_dorsiflexion_rmse_deg']:.1f} |"
            )
        L.append("")
    L += [
        "## Simulated walks (60 s, 6-axis; median RMSE over seeds, deg; worst in brackets)",
        "",
        "| sensors | thigh−shank elevation mismatch, median / max deg | variant | "
        + " | ".join(n.replace("_", " ") for n in NAMES)
        + " |",
        "|---|---|---|" + "---|" * len(NAMES),
    ]
    for r in res["sim"]:
        cells = " | ".join(f"{r['median_rmse_deg'][n]:.2f} ({r['worst_rmse_deg'][n]:.2f})" for n in NAMES)
        L.append(
            f"| {r['sensors']} | {r['axis_mismatch_deg_median']:.1f} / {r['axis_mismatch_deg_max']:.1f} | "
            f"{r['variant']} | {cells} |"
        )
    L += ["", *res["conclusion"], ""]
    return "\n".join(L)


CONCLUSION = [
    "On the real walk the thigh sensor's knee axis is 15–20° further from the horizontal than",
    "the shank sensor's and Plug-in Gait's; the shank's axis and the mechanical axis lower the",
    "hip flexion RMSE by 1.3–2.5° (and the right ankle's by 4–5°) while the left knee and ankle",
    "lose up to 0.5°. On",
    "the simulator the mechanical axis loses wherever there are artefacts (it measures knee",
    "flexion about an axis that is not the hinge's, so a bending knee shows as adduction and",
    "rotation), and the shank's axis trades hip flexion for knee rotation (thigh twist 0.3: hip",
    "flexion better by ~0.1°, knee rotation worse by ~2°). A twist with knee flexion tilts both",
    "estimates together more often than the thigh's alone (median mismatch 2.5°, not the real",
    "walk's 17–18°); a twist with hip flexion gives the real walk's mismatch (`sim_signatures.md`)",
    "and is undone by `CalibrationOptions.thigh_twist` (`thigh_twist.md`). The principal axis",
    "of the relative rotation gains less on the real walk (hip 6.2 / 6.0°, the left knee and",
    "ankle 0.4–0.6° worse) and trades ankle inversion for knee rotation on the twisting",
    "simulator. The library keeps the knee-axis frame; the real walk's hip-flexion offset is",
    "that frame's lean (docs/limits.md).",
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--seeds", type=int, default=6)
    args = ap.parse_args()
    real = real_rows(args.data) if (args.data / "gait").is_dir() else []
    res = {"real": real, "sim": sim_rows(args.seeds), "conclusion": CONCLUSION}
    write_results(args.out, "knee_axis_frames", res, markdown(res))


if __name__ == "__main__":
    main()
