"""Real overground walk (Xsens MTw + Vicon, gait/ in the data folder): calibration, angles, positions.

Each leg of the walk is run as a single-leg trial exactly as a user would:
the Xsens MT Manager exports are read with :func:`lowerlimb.read_xsens`, then
:func:`lowerlimb.process_trial` calibrates and computes the motion. Against the
Vicon Plug-in Gait model of the same frames (same clock):

- thigh length = distance of the calibrated hip centre from the knee axis line
  (thigh sensor frame) vs the median |HJC − KJC|; shank length = ankle centre
  to knee axis line (shank frame) vs the median |KJC − AJC|;
- knee, hip and ankle flexion RMSE, both zeroed on the standing period
  (frames 200–1000), over the authors' walking window (frames 1120–2074) and
  over the two straight passes only (the turn excluded); Vicon's hip and ankle
  flexion are the negated first Euler angle of ``Root_X_Femur`` and
  ``X_Tibia_X_Foot`` (checked by correlation, r ≤ −0.95);
- hip-to-ankle distance RMSE (positions.csv norm vs |HJC − AJC|), mm.

Three configurations: ``default``; ``no rigid band`` (the calibration of the
first release: adaptive prefilter only, which exits "degenerate" in the CLI);
``gravity-pinned hinge`` (``hinge_gravity_rate_rps=10``: the still period's
gravity rows in the knee-axis fit, off by default because it trades angle
accuracy for segment-length accuracy on this walk).
Plug-in Gait's joint centres are themselves regression estimates (hip centre
from pelvis markers, Davis 1991; a centimetre or two of error is typical), so
lengths within about 10–20 mm are at the reference's own accuracy.

Usage: ``python benchmarks/real_gait.py [--data ../shared/data]``; writes
``benchmarks/results/real_gait.{md,json}``.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import lowerlimb as ll
from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import ANGLE_COLUMNS

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _realwalk import STAND, WALK, leg_mapping, load_vicon, raw_dir  # noqa: E402
from _results import real_data_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
GOALS = {"length_mm": 20.0, "knee_deg": 5.0, "hip_deg": 5.0, "ankle_deg": 5.0, "hip_ankle_mm": 25.0}


def load_leg(data: Path, side: str) -> ll.ImuTrial:
    """One leg of the walk as a four-sensor trial, through the library's Xsens reader."""
    return ll.read_xsens(raw_dir(data), leg_mapping(side), side=side)


def straight_passes(vicon: dict, side: str) -> np.ndarray:
    """Frames of the walking window on the two straight passes.

    A frame counts when the sacrum (mean of LPSI/RPSI) moves faster than 0.5 m/s
    within 20° of the heading of the first or the last quarter of the window,
    and lies at least 0.5 s from any frame that does not (Plug-in Gait's hip
    Euler angles pass near gimbal lock in the turn).
    """
    mid = 0.5 * (vicon["LPSI"] + vicon["RPSI"]) / 1000.0
    v = np.gradient(mid[:, :2], axis=0) * 100.0
    speed = np.linalg.norm(v, axis=1)
    heading = np.arctan2(v[:, 1], v[:, 0])
    idx = np.arange(WALK.start, WALK.stop)
    h = heading[idx]
    quarter = len(h) // 4

    def near(ref: float) -> np.ndarray:
        return np.abs(np.angle(np.exp(1j * (h - ref)))) < np.radians(20)

    first = float(np.angle(np.mean(np.exp(1j * h[:quarter]))))
    last = float(np.angle(np.mean(np.exp(1j * h[-quarter:]))))
    ok = (near(first) | near(last)) & (speed[idx] > 0.5)
    bad = np.flatnonzero(~ok)
    keep = np.ones(len(idx), dtype=bool)
    for b in bad:
        keep[max(0, b - 50) : b + 51] = False
    return idx[keep]


def _line_distance(point: np.ndarray, on_line: np.ndarray, axis: np.ndarray) -> float:
    d = point - on_line
    return float(np.linalg.norm(d - (d @ axis) * axis))


def _rmse(a: np.ndarray, b: np.ndarray) -> float:
    e = a - b
    return float(np.sqrt(np.nanmean(e**2)))


def evaluate(result, vicon: dict, side: str) -> dict[str, float]:
    """The metrics of the module docstring for one processed leg."""
    P = side[0].upper()
    cal = result.calibration
    j_t, j_s = cal.knee.axis_in_parent_sensor, cal.knee.axis_in_child_sensor
    thigh = _line_distance(cal.hip.center_in_child_sensor, cal.knee.center_in_parent_sensor, j_t)
    shank = _line_distance(cal.ankle.center_in_parent_sensor, cal.knee.center_in_child_sensor, j_s)
    v_thigh = float(np.nanmedian(np.linalg.norm(vicon[P + "HJC"] - vicon[P + "KJC"], axis=1)))
    v_shank = float(np.nanmedian(np.linalg.norm(vicon[P + "KJC"] - vicon[P + "AJC"], axis=1)))
    ang = np.degrees(result.angles_rad)
    names = list(ANGLE_COLUMNS[1:])
    ours = {
        "knee": ang[:, names.index("knee_flexion")],
        "hip": ang[:, names.index("hip_flexion")],
        "ankle": ang[:, names.index("ankle_dorsiflexion")],
    }
    ref = {
        "knee": vicon[f"{P}_Femur_{P}_Tibia"][0],
        "hip": -vicon[f"Root_{P}_Femur"][:, 0],
        "ankle": -vicon[f"{P}_Tibia_{P}_Foot"][:, 0],
    }
    straight = straight_passes(vicon, side)
    out: dict[str, float] = {
        "thigh_length_mm": 1000 * thigh,
        "thigh_length_vicon_mm": v_thigh,
        "thigh_length_error_mm": 1000 * thigh - v_thigh,
        "shank_length_mm": 1000 * shank,
        "shank_length_vicon_mm": v_shank,
        "shank_length_error_mm": 1000 * shank - v_shank,
    }
    for k in ours:
        r = ref[k] - np.nanmean(ref[k][STAND])
        o = ours[k] - np.nanmean(ours[k][STAND])
        out[f"{k}_flexion_rmse_deg"] = _rmse(o[WALK], r[WALK])
        out[f"{k}_flexion_rmse_straight_deg"] = _rmse(o[straight], r[straight])
        out[f"{k}_flexion_bias_deg"] = float(np.nanmean(o[WALK] - r[WALK]))
    h2a = np.linalg.norm(result.positions_m[:, 3:6], axis=1)
    v_h2a = np.linalg.norm(vicon[P + "HJC"] - vicon[P + "AJC"], axis=1) / 1000
    out["hip_ankle_rmse_mm"] = 1000 * _rmse(h2a[WALK], v_h2a[WALK])
    out["knee_axis_std_deg"] = float(np.max(cal.knee.axis.axis_std_deg))
    out["hip_center_std_mm"] = 1000 * float(cal.hip.excitation.weakest_std)
    out["ankle_center_std_mm"] = 1000 * float(cal.ankle.excitation.weakest_std)
    out["calibration_s"] = float(cal.runtime_s)
    return out


def run(data: Path) -> dict:
    vicon = load_vicon(data)
    rows = []
    for config, opts in (
        ("default", CalibrationOptions()),
        ("no rigid band", CalibrationOptions(rigid_band=False)),
        ("gravity-pinned hinge", CalibrationOptions(hinge_gravity_rate_rps=10.0)),
    ):
        for side in ("left", "right"):
            trial = load_leg(data, side)
            t0 = time.perf_counter()
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                try:
                    cal = calibrate_leg(trial, options=opts)
                    result = ll.process_trial(trial, calibration=cal)
                except ll.LowerLimbError as e:
                    rows.append({"config": config, "side": side, "error": str(e)})
                    continue
            row = {"config": config, "side": side, "wall_s": time.perf_counter() - t0}
            row.update(evaluate(result, vicon, side))
            row["calibration_s"] = float(cal.runtime_s)
            row["warnings"] = [str(w.message) for w in caught if "magnetometer" not in str(w.message)]
            rows.append(row)
    return {"rows": rows, "goals": GOALS}


def to_markdown(res: dict) -> str:
    lines = [
        "# Real overground walk (gait/, Xsens MTw + Vicon), each leg as a single-leg trial",
        "",
        "Errors against Vicon Plug-in Gait (a regression model itself). Flexion RMSE over the walking "
        "window (frames 1120–2074) and, in brackets, over the straight passes only; all angles zeroed on "
        "the standing period. Goals (issue 9): lengths ≤ 20 mm, knee/hip/ankle flexion ≤ 5°, "
        "hip-to-ankle ≤ 25 mm.",
        "",
        "| config | side | thigh mm (err) | shank mm (err) | knee ° | hip ° | ankle ° | hip–ankle mm | "
        "knee axis ±° | hip ±mm | calib s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        if "error" in r:
            lines.append(f"| {r['config']} | {r['side']} | fails: {r['error'][:80]} |||||||||")
            continue
        lines.append(
            f"| {r['config']} | {r['side']} | "
            f"{r['thigh_length_mm']:.0f} ({r['thigh_length_error_mm']:+.0f}) | "
            f"{r['shank_length_mm']:.0f} ({r['shank_length_error_mm']:+.0f}) | "
            f"{r['knee_flexion_rmse_deg']:.1f} ({r['knee_flexion_rmse_straight_deg']:.1f}) | "
            f"{r['hip_flexion_rmse_deg']:.1f} ({r['hip_flexion_rmse_straight_deg']:.1f}) | "
            f"{r['ankle_flexion_rmse_deg']:.1f} ({r['ankle_flexion_rmse_straight_deg']:.1f}) | "
            f"{r['hip_ankle_rmse_mm']:.0f} | {r['knee_axis_std_deg']:.1f} | {r['hip_center_std_mm']:.0f} | "
            f"{r['calibration_s']:.2f} |"
        )
    lines += [
        "",
        "Vicon lengths: "
        + ", ".join(
            f"{r['side']} thigh {r['thigh_length_vicon_mm']:.0f} mm, "
            f"shank {r['shank_length_vicon_mm']:.0f} mm"
            for r in res["rows"]
            if r.get("config") == "default" and "error" not in r
        ),
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    real_data_main(__doc__, "real_gait", run, to_markdown)


if __name__ == "__main__":
    main()
