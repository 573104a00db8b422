"""Two legs on the real walk (gait/): seven Xsens MTw imported and run through the two-leg ``calibrate``.

The seven MT Manager exports are imported with :func:`lowerlimb.io.load_xsens` into one
two-leg trial CSV, and :func:`lowerlimb.outputs_bilateral.run_calibrate_bilateral` (what
``lowerlimb calibrate TRIAL.csv --out DIR`` runs for a seven-sensor header) writes its
folder. Scored against Vicon (Plug-in Gait, same clock, data/README.md):

- both legs calibrate;
- segment lengths: thigh = distance of the calibrated hip centre from the knee axis line
  (thigh sensor), shank = ankle centre to the knee axis line (shank sensor), vs the
  medians of |HJC − KJC| and |KJC − AJC| (as benchmarks/real_gait.py);
- knee flexion RMSE vs ``L_Femur_L_Tibia`` / ``R_Femur_R_Tibia``, both zeroed on frames
  200–1000 (standing), scored on frames 1120–2074 (the authors' walking window); and, as
  a second reference that no knee axis enters, vs the *joint-centre angle* between Vicon's
  own HJC→KJC and KJC→AJC (zeroed the same way), with the offset and gain of a line fit
  (IMU = gain × reference + offset) against each reference, so that a disagreement that
  is the same on both legs can be told from one that is not;
- stride length and step width (``gait.json``'s strides) vs the Vicon ankle centres
  (LAJC/RAJC) at the marker initial contacts (Zeni et al. 2008), straight strides, with
  the event and stride helpers of benchmarks/gait_events.py; here the inter-foot anchor
  comes from the calibrated chain (not from Vicon as in gait_events.py), and the feet
  are tracked at the calibrated ankle centres;
- hip spacing (the two calibrated hip centres) vs the median |LHJC − RHJC|.

Usage: ``python benchmarks/bilateral_gait.py [--data ../shared/data]``; writes
``benchmarks/results/bilateral_gait.{md,json}``.
"""

from __future__ import annotations

import importlib.util
import json
import sys
import tempfile
import time
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from lowerlimb.bilateral.process import process_bilateral_trial
from lowerlimb.conventions import ANGLE_COLUMNS, SIDES
from lowerlimb.gait.turns import detect_turns
from lowerlimb.io import load_xsens
from lowerlimb.outputs import CalibrateOptions
from lowerlimb.outputs_bilateral import run_calibrate_bilateral

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _realwalk import IDS, STAND, WALK, load_vicon, raw_dir  # noqa: E402
from _results import real_data_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MATCH_S = 0.2
VICON_RATE_HZ = 100.0
GOALS = {"length_mm": 20.0, "stride_length_pct": 3.0, "step_width_mm": 20.0}


def _gait_events_module() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "gait_events_benchmark", ROOT / "benchmarks" / "gait_events.py"
    )
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _line_distance(point: np.ndarray, on_line: np.ndarray, axis: np.ndarray) -> float:
    d = np.asarray(point) - np.asarray(on_line)
    a = np.asarray(axis) / np.linalg.norm(axis)
    return float(np.linalg.norm(d - (d @ a) * a))


def _stats(x: list[float]) -> dict[str, float]:
    a = np.asarray(x, dtype=float)
    a = a[np.isfinite(a)]
    if not a.size:
        return {"n": 0}
    return {
        "n": int(a.size),
        "median_abs": float(np.median(np.abs(a))),
        "worst_abs": float(np.max(np.abs(a))),
        "bias": float(a.mean()),
    }


def joint_centre_knee_deg(vicon: dict, P: str) -> np.ndarray:
    """Knee angle (N,) deg between Vicon's HJC→KJC and KJC→AJC (no knee axis enters)."""
    th = vicon[P + "KJC"] - vicon[P + "HJC"]
    sh = vicon[P + "AJC"] - vicon[P + "KJC"]
    c = np.sum(th * sh, axis=1) / (np.linalg.norm(th, axis=1) * np.linalg.norm(sh, axis=1))
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def _line_fit(est: np.ndarray, ref: np.ndarray) -> dict[str, float]:
    """RMSE, and offset and gain of est = gain × ref + offset (deg), over finite samples."""
    m = np.isfinite(est) & np.isfinite(ref)
    gain, offset = np.polyfit(ref[m], est[m], 1)
    return {
        "rmse_deg": float(np.sqrt(np.mean((est[m] - ref[m]) ** 2))),
        "offset_deg": float(offset),
        "gain": float(gain),
    }


def score_legs(result: Any, vicon: dict) -> dict[str, dict[str, float]]:
    """Segment lengths and knee flexion RMSE of each leg."""
    out = {}
    names = list(ANGLE_COLUMNS[1:])
    for side in SIDES:
        P = side[0].upper()
        cal = result.legs[side].calibration
        thigh = _line_distance(
            cal.hip.center_in_child_sensor, cal.knee.center_in_parent_sensor, cal.knee.axis_in_parent_sensor
        )
        shank = _line_distance(
            cal.ankle.center_in_parent_sensor, cal.knee.center_in_child_sensor, cal.knee.axis_in_child_sensor
        )
        v_thigh = float(np.nanmedian(np.linalg.norm(vicon[P + "HJC"] - vicon[P + "KJC"], axis=1)))
        v_shank = float(np.nanmedian(np.linalg.norm(vicon[P + "KJC"] - vicon[P + "AJC"], axis=1)))
        knee = np.degrees(result.legs[side].angles_rad[:, names.index("knee_flexion")])
        ref = vicon[f"{P}_Femur_{P}_Tibia"][0].astype(float)
        o, r = knee - np.nanmean(knee[STAND]), ref - np.nanmean(ref[STAND])
        jc = joint_centre_knee_deg(vicon, P)
        jc = jc - np.nanmean(jc[STAND])
        hip = np.degrees(result.legs[side].angles_rad[:, names.index("hip_flexion")])
        href = -vicon[f"Root_{P}_Femur"][:, 0].astype(float)  # as benchmarks/real_gait.py
        ho, hr = hip - np.nanmean(hip[STAND]), href - np.nanmean(href[STAND])
        out[side] = {
            "thigh_mm": 1000 * thigh,
            "thigh_vicon_mm": v_thigh,
            "thigh_err_mm": 1000 * thigh - v_thigh,
            "shank_mm": 1000 * shank,
            "shank_vicon_mm": v_shank,
            "shank_err_mm": 1000 * shank - v_shank,
            "knee_flexion_rmse_deg": float(np.sqrt(np.nanmean((o[WALK] - r[WALK]) ** 2))),
            "hip_flexion_rmse_deg": float(np.sqrt(np.nanmean((ho[WALK] - hr[WALK]) ** 2))),
            "knee_vs_vicon": _line_fit(o[WALK], r[WALK]),
            "knee_vs_joint_centres": _line_fit(o[WALK], jc[WALK]),
            "vicon_knee_vs_joint_centres": _line_fit(r[WALK], jc[WALK]),
        }
    return out


def score_strides(result: Any, vicon: dict, ge: ModuleType) -> dict[str, Any]:
    """Stride length and step width of the straight strides vs the Vicon ankle centres."""
    sac, u, straight = ge.sacrum_walk(vicon)
    ref = {side: ge.zeni_events(vicon, sac, u, side) for side in SIDES}
    vs = ge.vicon_strides(vicon, ref, straight)
    params = result.gait.parameters
    t0 = float(result.trial.time_s[0])
    rows = []
    for s in params.strides if params is not None else []:
        start = s.start_s + t0
        cand = [v for v in vs if v["side"] == s.side and abs(v["start_s"] - start) <= MATCH_S]
        if not cand:
            continue
        v = min(cand, key=lambda r: abs(r["start_s"] - start))
        rows.append(
            {
                "side": s.side,
                "start_s": round(start, 3),
                "straight": bool(v["straight"] and not s.turning),
                "step_straight": bool(v.get("step_straight", False) and not s.step_turning),
                "stride_length_imu_m": s.stride_length_m,
                "stride_length_vicon_m": v["stride_length_m"],
                "step_width_imu_m": s.step_width_m,
                "step_width_vicon_m": v.get("step_width_m", float("nan")),
            }
        )
    sl = [100 * (r["stride_length_imu_m"] / r["stride_length_vicon_m"] - 1) for r in rows if r["straight"]]
    sw = [1000 * (r["step_width_imu_m"] - r["step_width_vicon_m"]) for r in rows if r["step_straight"]]
    return {"stride_length_err_pct": _stats(sl), "step_width_err_mm": _stats(sw), "strides": rows}


def score_real_walk(trial: Any, vicon: dict, **options: Any) -> dict[str, Any]:
    """The two-leg pipeline on a (changed) real walk, quietly, scored against Vicon.

    Returns:
        ``length_err_mm`` ({side: [thigh, shank]}), ``stride_length_pct`` and ``step_width_mm``
        (:func:`score_strides`), ``knee_flexion_rmse_deg`` ([left, right]) and ``worst_flexion_rmse_deg``
        (the worst of both legs' knee and hip flexion), and the ``result``.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = process_bilateral_trial(trial, **options)
    legs = score_legs(res, vicon)
    strides = score_strides(res, vicon, _gait_events_module())
    return {
        "length_err_mm": {s: [legs[s]["thigh_err_mm"], legs[s]["shank_err_mm"]] for s in SIDES},
        "stride_length_pct": strides["stride_length_err_pct"],
        "step_width_mm": strides["step_width_err_mm"],
        "knee_flexion_rmse_deg": [legs[s]["knee_flexion_rmse_deg"] for s in SIDES],
        "worst_flexion_rmse_deg": max(
            legs[s][k] for s in SIDES for k in ("knee_flexion_rmse_deg", "hip_flexion_rmse_deg")
        ),
        "result": res,
    }


def vicon_pelvis_rate(vicon: dict) -> np.ndarray:
    """(N,) vertical rate of the pelvis markers' heading (ASIS and PSIS, right minus left), rad/s."""
    lateral = (vicon["RASI"] + vicon["RPSI"] - vicon["LASI"] - vicon["LPSI"])[:, :2].astype(float)
    heading = np.unwrap(np.arctan2(lateral[:, 0], -lateral[:, 1]))  # forward: the right axis turned 90° left
    return np.asarray(np.gradient(heading) * VICON_RATE_HZ)


def score_turns(result: Any, vicon: dict) -> dict[str, Any]:
    """The walker's turns (gait.json's) against the same detector on the Vicon pelvis markers.

    The reference uses the IMU's smoothing window, so the two differ only in the signal.
    """
    turns = result.gait.turns
    if turns is None:
        return {"imu": [], "vicon": []}
    ref = detect_turns(vicon_pelvis_rate(vicon), VICON_RATE_HZ, stride_time_s=turns.window_s)
    return {"imu": [t.to_dict() for t in turns.turns], "vicon": [t.to_dict() for t in ref.turns]}


def run(data: Path, thigh_twist: bool = False) -> dict[str, Any]:
    """Both legs of the real walk through ``calibrate`` (``--thigh-twist`` when ``thigh_twist``), scored."""
    vicon = load_vicon(data)
    ge = _gait_events_module()
    res: dict[str, Any] = {"goals": GOALS}
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "walk7.csv"
        load_xsens(raw_dir(data), IDS).to_csv(csv)
        t = time.perf_counter()
        try:
            options = CalibrateOptions(trial=csv, out=Path(tmp) / "out", thigh_twist=thigh_twist)
            result = run_calibrate_bilateral(options)
        except Exception as e:  # noqa: BLE001 - a benchmark records any failure
            return res | {"both_legs_calibrate": False, "error": f"{type(e).__name__}: {e}"}
        res["wall_s"] = time.perf_counter() - t
        res["gait_json"] = json.loads((Path(tmp) / "out" / "gait.json").read_text())
    res["both_legs_calibrate"] = True
    res["legs"] = score_legs(result, vicon)
    res |= score_strides(result, vicon, ge)
    h = result.hips
    v_sp = float(np.nanmedian(np.linalg.norm(vicon["LHJC"] - vicon["RHJC"], axis=1)))
    res["hips"] = {
        "spacing_mm": 1000 * h.spacing_m,
        "spacing_vicon_mm": v_sp,
        "spacing_err_mm": 1000 * h.spacing_m - v_sp,
        "de_leva_mm": 1000 * h.expected_spacing_m,
        "plausible": h.plausible,
        "pelvis_axes_angle_deg": h.pelvis_axes_angle_deg,
    }
    if result.pelvis is not None:
        pv = result.pelvis
        res["hips"] |= {
            "single_leg_spacing_mm": 1000 * pv.single_leg_spacing_m,
            "legs_own_axes_angle_deg": pv.legs_axes_angle_deg,
            "hip_line_weight": pv.hip_line_weight,
        }
    res["anchor"] = res["gait_json"].get("anchor")
    res["relative_heading_deg"] = (
        result.gait.parameters.relative_heading_deg if result.gait.parameters else None
    )
    res["runtime_s"] = result.runtime_s
    res["turns"] = score_turns(result, vicon)
    return res


def markdown(res: dict[str, Any]) -> str:
    L = ["# Two legs on the real walk (gait/, S02 Walk-1): seven IMUs through `calibrate`", ""]
    if not res.get("both_legs_calibrate"):
        return "\n".join(L + [f"Fails: {res.get('error')}", ""])
    g = res["goals"]
    L += [
        f"Goals (issue 11): both legs calibrate; segment lengths within {g['length_mm']:.0f} mm; "
        f"stride length within {g['stride_length_pct']:.0f} %, step width within "
        f"{g['step_width_mm']:.0f} mm of the Vicon ankle centres. "
        "Knee flexion zeroed on frames 200–1000, RMSE over 1120–2074.",
        "",
        "| side | thigh mm (Vicon, err) | shank mm (Vicon, err) | knee flexion RMSE ° | hip flexion RMSE ° |",
        "|---|---|---|---|---|",
    ]
    for side, s in res["legs"].items():
        L.append(
            f"| {side} | {s['thigh_mm']:.0f} ({s['thigh_vicon_mm']:.0f}, {s['thigh_err_mm']:+.0f}) | "
            f"{s['shank_mm']:.0f} ({s['shank_vicon_mm']:.0f}, {s['shank_err_mm']:+.0f}) | "
            f"{s['knee_flexion_rmse_deg']:.1f} | {s['hip_flexion_rmse_deg']:.1f} |"
        )
    L += [
        "",
        "Knee flexion against two references (walking window, zeroed on standing): Vicon's knee "
        "model, and the joint-centre angle between Vicon's HJC→KJC and KJC→AJC (no knee axis). "
        "RMSE °, and offset ° / gain of the line fit (first = gain × second + offset):",
        "",
        "| side | IMU vs Vicon knee | IMU vs joint-centre angle | Vicon knee vs joint-centre angle |",
        "|---|---|---|---|",
    ]
    for side, s in res["legs"].items():
        cells = [
            f"{f['rmse_deg']:.1f} ({f['offset_deg']:+.1f} / {f['gain']:.2f})"
            for f in (s["knee_vs_vicon"], s["knee_vs_joint_centres"], s["vicon_knee_vs_joint_centres"])
        ]
        L.append(f"| {side} | " + " | ".join(cells) + " |")
    L += ["", "| quantity (straight strides) | n | median abs | worst abs | bias |", "|---|---|---|---|---|"]
    for key, unit in (("stride_length_err_pct", "%"), ("step_width_err_mm", "mm")):
        e = res[key]
        if e.get("n"):
            L.append(
                f"| {key} | {e['n']} | {e['median_abs']:.1f} {unit} | {e['worst_abs']:.1f} {unit} | "
                f"{e['bias']:+.1f} {unit} |"
            )
        else:
            L.append(f"| {key} | 0 | – | – | – |")
    h = res["hips"]
    a = res.get("anchor") or {}
    L += [
        "",
        f"Hip spacing: {h['spacing_mm']:.0f} mm calibrated, {h['spacing_vicon_mm']:.0f} mm Vicon "
        f"({h['spacing_err_mm']:+.0f} mm), de Leva {h['de_leva_mm']:.0f} mm; plausible: {h['plausible']}; "
        f"angle between the two legs' pelvis medio-lateral axes {h['pelvis_axes_angle_deg']:.0f}°"
        + (
            f" (one shared pelvis frame; each leg's own, from its knee axis: "
            f"{h['legs_own_axes_angle_deg']:.0f}° apart; single-leg hip centres "
            f"{h['single_leg_spacing_mm']:.0f} mm apart; hip-line share of the right axis "
            f"{h['hip_line_weight']:.2f})."
            if "legs_own_axes_angle_deg" in h
            else "."
        ),
        f"Chain anchor (right − left ankle centre at {a.get('time_s', float('nan')):.2f} s): forward "
        f"{a.get('forward_m', float('nan')):+.3f} m, left {a.get('left_m', float('nan')):+.3f} m; "
        f"right-to-left heading alignment of the foot trajectories {res['relative_heading_deg']:.1f}°. "
        f"Joint calibration {res['runtime_s']:.2f} s; whole command {res['wall_s']:.1f} s.",
        "",
        "The walker's turns (gait.json's `turns`, from the pelvis sensor's vertical rate smoothed "
        "over a stride, `lowerlimb.gait.turns`) against the same detector on the Vicon pelvis "
        "markers' heading (ASIS and PSIS), with the same window:",
        "",
        "| source | start s | end s | angle ° | peak °/s | steps |",
        "|---|---|---|---|---|---|",
    ]
    for source in ("imu", "vicon"):
        for t in res.get("turns", {}).get(source, []):
            steps = t["steps"] if source == "imu" else "–"
            L.append(
                f"| {source} | {t['start_s']:.2f} | {t['end_s']:.2f} | {t['angle_deg']:+.1f} | "
                f"{t['peak_rate_deg_s']:.0f} | {steps} |"
            )
    L += [
        "",
        "| side | start s | straight | stride IMU/Vicon m | step width IMU/Vicon m |",
        "|---|---|---|---|---|",
    ]
    for r in res["strides"]:
        L.append(
            f"| {r['side']} | {r['start_s']:.2f} | {r['straight']} | {r['stride_length_imu_m']:.3f}/"
            f"{r['stride_length_vicon_m']:.3f} | {r['step_width_imu_m']:.3f}/{r['step_width_vicon_m']:.3f} |"
        )
    return "\n".join(L + [""])


def main() -> None:
    real_data_main(__doc__, "bilateral_gait", run, markdown)


if __name__ == "__main__":
    main()
