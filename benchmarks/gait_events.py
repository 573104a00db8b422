"""Gait events, foot-stationary periods and spatio-temporal parameters on the real walk (gait/).

Data: Xsens MTw on both shanks and feet + Vicon, 100 Hz, one clock (data/README.md).
The lowerlimb.gait stages run on the raw IMU files (a small local reader below)
with default :class:`~lowerlimb.gait.GaitParams`, and are scored against:

(a) marker events (Zeni et al. 2008): initial contact where the heel marker (L/RHEE) is
    furthest ahead of the sacrum (mean of L/RPSI) along the local walking direction (the
    sacrum's 2 Hz low-passed horizontal velocity), toe-off where the toe marker (L/RTOE) is
    furthest behind; an event is *straight* when the sacrum moves faster than 0.3 m/s within
    25 deg of the heading of the first or last quarter of the authors' walking window
    (frames 1120-2074) and the footprint that the event ends (toe-off) or begins (initial
    contact) points within 25 deg of that foot's footprints in the same quarter, else it is
    in the *turn* (the footprint test catches the pivot step of a turn: the pelvis has
    already turned, the foot still stands where it was put down at 80 deg). Each marker
    event is matched to the nearest IMU event of its side and type within 0.2 s. As a
    second, physical reference, the heel-marker "heel stop": the first frame after the Zeni
    contact at which the heel marker's horizontal speed falls below 0.3 m/s (reported, not
    a goal);
(b) foot-stationary periods against the per-frame flags of step-detect/ (walking window);
(c) stride length, step length, step width, cadence and speed against the Vicon ankle
    centres (LAJC/RAJC, mm, lab z up) at the marker initial contacts, same definitions as
    lowerlimb.gait.parameters. The IMU side uses the foot *sensor* positions (no calibrated
    ankle offset here). The inter-foot anchor (right minus left foot at the standing
    frame 1000, in walking coordinates) is taken from the Vicon ankle centres, because the
    calibrated chain that should provide it is not part of this module: step length and
    width therefore test the drift and heading alignment of the two ZUPT trajectories over
    the walk, not the anchor.

Usage: ``python benchmarks/gait_events.py [--data ../shared/data]``; writes
``benchmarks/results/gait_events.{md,json}``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import scipy.io as sio
from scipy.signal import butter, filtfilt, find_peaks

from lowerlimb.gait import (
    FootAnchor,
    GaitParams,
    compute_gait_parameters,
    detect_gait_events,
    integrate_foot,
)

ROOT = Path(__file__).resolve().parents[1]
RATE = 100.0
IDS = {"left_shank": "00B40C44", "right_shank": "00B40C47", "left_foot": "00B40C55", "right_foot": "00B40C48"}
WALK = (1120, 2074)
STAND_FRAME = 1000
MATCH_S = 0.2
GOALS = {"event_median_ms": 20.0, "event_worst_ms": 40.0, "stride_length_pct": 3.0, "step_width_mm": 20.0}


def read_xsens_txt(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(acc m/s², gyr rad/s), each (N, 3), from an MT Manager text export."""
    lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.startswith("//")]
    header = lines[0].split(",")
    col = {h: i for i, h in enumerate(header)}
    rows = np.array([[float(x) if x else np.nan for x in ln.split(",")] for ln in lines[1:]])
    pick = [col[f"{q}_{a}"] for q in ("Acc", "Gyr") for a in "XYZ"]
    data = rows[:, pick]
    return data[:, :3], data[:, 3:]


def sacrum_walk(vicon: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sacrum position (N,3) m, unit horizontal walking direction (N,2), straight-walking mask (N,)."""
    sac = 0.5 * (vicon["LPSI"] + vicon["RPSI"]) / 1000.0
    b, a = butter(2, 2.0, fs=RATE)
    v = filtfilt(b, a, np.gradient(sac[:, :2], axis=0) * RATE, axis=0)
    speed = np.linalg.norm(v, axis=1)
    u = v / np.maximum(speed, 1e-9)[:, None]
    q = (WALK[1] - WALK[0]) // 4
    straight = np.zeros(len(sac), dtype=bool)
    for lo, hi in ((WALK[0], WALK[0] + q), (WALK[1] - q, WALK[1])):
        d = v[lo:hi].mean(axis=0)
        d /= np.linalg.norm(d)
        straight |= (u @ d > np.cos(np.deg2rad(25.0))) & (speed > 0.3)
    return sac, u, straight


def footprint_straight(vicon: dict, side: str, frames: np.ndarray, after: bool) -> np.ndarray:
    """Whether each event's footprint (bool per frame of ``frames``) points as in a straight pass.

    The footprint is the foot standing still (heel marker slower than 0.1 m/s): the last
    still frame within 0.8 s before a toe-off (``after=False``), the first within 0.8 s
    after an initial contact (``after=True``); its heading is the heel-to-toe marker
    direction. Each pass's reference is the median footprint heading over the first or
    last quarter of the walking window; a footprint is straight within 25 deg of either.
    """
    s = side[0].upper()
    d = vicon[f"{s}TOE"][:, :2] - vicon[f"{s}HEE"][:, :2]
    h = np.arctan2(d[:, 1], d[:, 0])
    still = np.linalg.norm(np.gradient(vicon[f"{s}HEE"][:, :2] / 1000.0, axis=0) * RATE, axis=1) < 0.1
    q = (WALK[1] - WALK[0]) // 4
    refs = []
    for lo, hi in ((WALK[0], WALK[0] + q), (WALK[1] - q, WALK[1])):
        hh = h[lo:hi][still[lo:hi]]
        refs.append(np.angle(np.median(np.cos(hh)) + 1j * np.median(np.sin(hh))))
    win = int(0.8 * RATE)
    out = np.zeros(len(frames), dtype=bool)
    for k, f in enumerate(frames):
        idx = np.flatnonzero(still[f : f + win]) + f if after else np.flatnonzero(still[max(f - win, 0) : f])
        if not idx.size:
            continue
        fp = idx[0] if after else idx[-1] + max(f - win, 0)
        out[k] = any(np.cos(h[fp] - r) > np.cos(np.deg2rad(25.0)) for r in refs)
    return out


def zeni_events(vicon: dict, sac: np.ndarray, u: np.ndarray, side: str) -> dict[str, np.ndarray]:
    """Marker initial contacts and toe-offs (frames) by Zeni et al. 2008."""
    moving = np.linalg.norm(np.gradient(sac[:, :2], axis=0) * RATE, axis=1) > 0.3
    s = side[0].upper()
    heel = ((vicon[f"{s}HEE"][:, :2] / 1000.0 - sac[:, :2]) * u).sum(axis=1)
    toe = ((vicon[f"{s}TOE"][:, :2] / 1000.0 - sac[:, :2]) * u).sum(axis=1)
    dist = int(0.5 * RATE)
    ic, _ = find_peaks(np.where(moving, heel, -10.0), distance=dist, prominence=0.1)
    to, _ = find_peaks(np.where(moving, -toe, -10.0), distance=dist, prominence=0.1)
    return {"initial_contact": ic, "toe_off": to}


def heel_stop(vicon: dict, side: str, ic: np.ndarray) -> np.ndarray:
    """First frame after each Zeni contact where the heel marker's horizontal speed is < 0.3 m/s."""
    h = vicon[f"{side[0].upper()}HEE"][:, :2] / 1000.0
    sp = np.linalg.norm(np.gradient(h, axis=0) * RATE, axis=1)
    out = []
    for k in ic:
        after = np.flatnonzero(sp[k : k + int(0.3 * RATE)] < 0.3)
        out.append(k + after[0] if after.size else -1)
    return np.asarray(out)


def match(ref_s: np.ndarray, est_s: np.ndarray) -> np.ndarray:
    """Signed error (est - ref), s, of the nearest estimate within MATCH_S; NaN when none."""
    err = np.full(len(ref_s), np.nan)
    for i, t in enumerate(ref_s):
        if len(est_s):
            j = int(np.argmin(np.abs(est_s - t)))
            if abs(est_s[j] - t) <= MATCH_S:
                err[i] = est_s[j] - t
    return err


def stats_ms(err_s: np.ndarray) -> dict[str, float]:
    e = err_s[np.isfinite(err_s)] * 1000.0
    if not e.size:
        return {"n": 0, "missed": int(np.isnan(err_s).sum())}
    return {
        "n": int(e.size),
        "missed": int(np.isnan(err_s).sum()),
        "bias_ms": float(e.mean()),
        "median_abs_ms": float(np.median(np.abs(e))),
        "worst_abs_ms": float(np.max(np.abs(e))),
    }


def stationary_scores(mask: np.ndarray, flags: np.ndarray) -> dict[str, float]:
    """Agreement % and onset/offset errors (detected - flag, ms) over the walking window."""
    lo, hi = WALK
    m, f = mask[lo:hi], flags[lo:hi].astype(bool)

    def edges(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = np.diff(x.astype(int))
        return np.flatnonzero(d == 1) + 1, np.flatnonzero(d == -1) + 1

    on_f, off_f = edges(f)
    on_m, off_m = edges(m)

    def near(ref: np.ndarray, est: np.ndarray) -> np.ndarray:
        return (
            np.array([est[np.argmin(np.abs(est - r))] - r for r in ref]) * 10.0 if est.size else np.array([])
        )

    on_e, off_e = near(on_f, on_m), near(off_f, off_m)
    return {
        "agreement_pct": float(100.0 * np.mean(m == f)),
        "onset_median_ms": float(np.median(on_e)),
        "onset_worst_ms": float(np.max(np.abs(on_e))),
        "offset_median_ms": float(np.median(off_e)),
        "offset_worst_ms": float(np.max(np.abs(off_e))),
        "n_periods_flags": int(on_f.size),
        "n_periods_detected": int(on_m.size),
    }


def marker_temporal(own: dict[str, np.ndarray], other: dict[str, np.ndarray], a: int, b: int) -> dict:
    """Stance and double support (% of the stride a→b) from the marker events, as in lowerlimb.gait."""
    T = b - a
    nan = float("nan")
    to = own["toe_off"][(own["toe_off"] > a) & (own["toe_off"] < b)]
    to_o = other["toe_off"][(other["toe_off"] > a) & (other["toe_off"] < b)]
    out = {"stance_pct": 100.0 * (to[0] - a) / T if to.size else nan, "double_support_pct": nan}
    if to.size and to_o.size:
        ic_o = other["initial_contact"][(other["initial_contact"] > a) & (other["initial_contact"] < to[0])]
        if ic_o.size:
            out["double_support_pct"] = 100.0 * ((to_o[0] - a) + (to[0] - ic_o[-1])) / T
    return out


def vicon_strides(vicon: dict, ev: dict[str, dict[str, np.ndarray]], straight: np.ndarray) -> list[dict]:
    """Reference strides on the ankle centres at the marker initial contacts (lengths m)."""
    out = []
    for side in ("left", "right"):
        other = "right" if side == "left" else "left"
        A = vicon[f"{side[0].upper()}AJC"][:, :2] / 1000.0
        B = vicon[f"{other[0].upper()}AJC"][:, :2] / 1000.0
        ic, ico = ev[side]["initial_contact"], ev[other]["initial_contact"]
        for k in range(len(ic) - 1):
            a, b = ic[k], ic[k + 1]
            if (b - a) / RATE > GaitParams().max_stride_time_s:
                continue
            row = {
                "side": side,
                "start_s": a / RATE,
                **marker_temporal(ev[side], ev[other], a, b),
                "stride_time_s": (b - a) / RATE,
                "stride_length_m": float(np.linalg.norm(A[b] - A[a])),
                "straight": bool(straight[a] and straight[b]),
            }
            prev = ico[ico < a]
            nxt = ico[ico > a]
            if prev.size and nxt.size:
                P, N = B[prev[-1]], B[nxt[0]]
                uu = (N - P) / np.linalg.norm(N - P)
                d = A[a] - P
                row["step_length_m"] = float(d @ uu)
                row["step_width_m"] = float(abs(uu[0] * d[1] - uu[1] * d[0]))
                row["step_time_s"] = (a - prev[-1]) / RATE
                row["step_straight"] = bool(straight[prev[-1]] and straight[nxt[0]] and straight[a])
            out.append(row)
    return out


def vicon_anchor(vicon: dict, ev: dict[str, dict[str, np.ndarray]]) -> FootAnchor:
    """Right minus left ankle centre at the standing frame, in walking coordinates.

    Forward is the mean direction of the two feet's first strides (as :class:`~lowerlimb.gait.FootAnchor`).
    """
    L, R = vicon["LAJC"][:, :2] / 1000.0, vicon["RAJC"][:, :2] / 1000.0
    dirs = []
    for side, P in (("left", L), ("right", R)):
        ic = ev[side]["initial_contact"]
        ic = ic[ic > STAND_FRAME]
        step = P[ic[1]] - P[ic[0]]
        dirs.append(step / np.linalg.norm(step))
    u = dirs[0] + dirs[1]
    u /= np.linalg.norm(u)
    d = R[STAND_FRAME] - L[STAND_FRAME]
    return FootAnchor(
        time_s=STAND_FRAME / RATE, forward_m=float(d @ u), left_m=float(-u[1] * d[0] + u[0] * d[1])
    )


def _temporal_err(rows: list[dict], q: str) -> dict[str, float]:
    """IMU − marker-event value of ``q`` (percentage points of the stride) over ``rows``."""
    e = np.array([r[f"{q}_imu"] - r[f"{q}_vicon"] for r in rows])
    e = e[np.isfinite(e)]
    if not e.size:
        return {"n": 0}
    return {
        "n": int(e.size),
        "median_abs": float(np.median(np.abs(e))),
        "worst_abs": float(np.max(np.abs(e))),
        "bias": float(e.mean()),
    }


def run(data: Path) -> dict:
    folder = data / "gait"
    imu = {k: read_xsens_txt(folder / "rawimu" / f"S02-Trial-Walk-1-000_{v}.txt") for k, v in IDS.items()}
    vicon = sio.loadmat(str(folder / "vicon" / "S02-Trial-Walk-1.mat"))
    flags = np.loadtxt(
        folder / "step-detect" / "S02-Trial-Walk-1-revStepDetect.csv", delimiter=",", skiprows=1
    )
    params = GaitParams()
    events = detect_gait_events(
        RATE,
        left_shank_gyr=imu["left_shank"][1],
        right_shank_gyr=imu["right_shank"][1],
        left_foot_gyr=imu["left_foot"][1],
        left_foot_acc=imu["left_foot"][0],
        right_foot_gyr=imu["right_foot"][1],
        right_foot_acc=imu["right_foot"][0],
        params=params,
    )
    sac, u, straight = sacrum_walk(vicon)
    ref = {side: zeni_events(vicon, sac, u, side) for side in ("left", "right")}
    res: dict = {"events": {}, "stationary": {}, "spatial": {}}
    for side, se in (("left", events.left), ("right", events.right)):
        assert se is not None
        est = {"initial_contact": se.initial_contact_s, "toe_off": se.toe_off_s}
        for name in ("initial_contact", "toe_off"):
            fr = ref[side][name]
            along = straight[fr] & footprint_straight(vicon, side, fr, after=name == "initial_contact")
            err = match(fr / RATE, est[name])
            res["events"][f"{side}_{name}"] = {
                "straight": stats_ms(err[along]),
                "turn": stats_ms(err[~along]),
                "errors_ms": [None if np.isnan(e) else round(1000 * e, 1) for e in err],
                "marker_frames": fr.tolist(),
                "straight_flags": along.tolist(),
            }
        hs = heel_stop(vicon, side, ref[side]["initial_contact"])
        ok = hs >= 0
        err = match(hs[ok] / RATE, se.initial_contact_s)
        res["events"][f"{side}_initial_contact_vs_heel_stop"] = {"straight": stats_ms(err[straight[hs[ok]]])}
        assert se.stationary is not None
        res["stationary"][side] = stationary_scores(se.stationary.mask, flags[:, 0 if side == "left" else 1])
    trajs = {
        side: integrate_foot(
            imu[f"{side}_foot"][1], imu[f"{side}_foot"][0], RATE, se.stationary, params=params
        )
        for side, se in (("left", events.left), ("right", events.right))
        if se is not None and se.stationary is not None
    }
    gp = compute_gait_parameters(
        events, trajs["left"], trajs["right"], anchor=vicon_anchor(vicon, ref), params=params
    )
    vs = vicon_strides(vicon, ref, straight)
    rows = []
    for s in gp.strides:
        cand = [v for v in vs if v["side"] == s.side and abs(v["start_s"] - s.start_s) <= MATCH_S]
        if not cand:
            continue
        v = min(cand, key=lambda r: abs(r["start_s"] - s.start_s))
        rows.append(
            {
                "side": s.side,
                "start_s": round(s.start_s, 3),
                "imu_turning": s.turning,
                "vicon_straight": v["straight"],
                "stride_length_imu_m": s.stride_length_m,
                "stride_length_vicon_m": v["stride_length_m"],
                "step_length_imu_m": s.step_length_m,
                "step_length_vicon_m": v.get("step_length_m", float("nan")),
                "step_width_imu_m": s.step_width_m,
                "step_width_vicon_m": v.get("step_width_m", float("nan")),
                "step_straight": v.get("step_straight", False) and not s.step_turning,
                "stance_pct_imu": s.stance_pct,
                "stance_pct_vicon": v["stance_pct"],
                "double_support_pct_imu": s.double_support_pct,
                "double_support_pct_vicon": v["double_support_pct"],
                "speed_imu_m_s": s.speed_m_s,
                "speed_vicon_m_s": v["stride_length_m"] / v["stride_time_s"],
                "heading_change_deg": s.heading_change_deg,
            }
        )
    res["strides"] = rows
    st = [r for r in rows if r["vicon_straight"] and not r["imu_turning"]]
    sl = np.array([100 * (r["stride_length_imu_m"] / r["stride_length_vicon_m"] - 1) for r in st])
    stp = [r for r in rows if r["step_straight"]]
    sw = np.array([1000 * (r["step_width_imu_m"] - r["step_width_vicon_m"]) for r in stp])
    sle = np.array([1000 * (r["step_length_imu_m"] - r["step_length_vicon_m"]) for r in stp])
    sp = np.array([r["speed_imu_m_s"] - r["speed_vicon_m_s"] for r in st])
    summary = gp.to_dict()
    res["spatial"] = {
        "n_straight_strides": len(st),
        "n_turn_strides_imu": len(gp.select(turning=True)),
        "turn_strides_vicon": sum(not v["straight"] for v in vs),
        "stride_length_err_pct": {
            "median_abs": float(np.median(np.abs(sl))),
            "worst_abs": float(np.max(np.abs(sl))),
            "bias": float(sl.mean()),
        },
        "step_length_err_mm": {
            "median_abs": float(np.median(np.abs(sle))),
            "worst_abs": float(np.max(np.abs(sle))),
            "bias": float(sle.mean()),
        },
        "step_width_err_mm": {
            "median_abs": float(np.median(np.abs(sw))),
            "worst_abs": float(np.max(np.abs(sw))),
            "bias": float(sw.mean()),
        },
        "speed_err_m_s": {"median_abs": float(np.median(np.abs(sp))), "bias": float(sp.mean())},
        **{f"{q}_err_points": _temporal_err(st, q) for q in ("stance_pct", "double_support_pct")},
        "cadence_imu": summary["cadence_steps_per_min"],
        "cadence_vicon": 120.0 / float(np.mean([v["stride_time_s"] for v in vs if v["straight"]])),
        "cadence_imu_from_strides": 120.0 / float(np.mean([s.stride_time_s for s in gp.select()])),
        "speed_imu_m_s": summary["gait_speed_m_s"],
        "speed_vicon_m_s": float(
            np.mean([v["stride_length_m"] / v["stride_time_s"] for v in vs if v["straight"]])
        ),
        "relative_heading_deg": gp.relative_heading_deg,
        "zupt_drift_mps": {side: float(np.median(t.drift_mps)) for side, t in trajs.items()},
    }
    res["gait_json"] = summary
    return res


def markdown(res: dict) -> str:
    L = ["# Gait events and parameters on the real walk (gait/, S02 Walk-1)", ""]
    L += [
        f"Goals: events median ≤ {GOALS['event_median_ms']:.0f} ms, worst ≤ {GOALS['event_worst_ms']:.0f} ms "
        f"(straight walking, vs Zeni marker events); stride length ≤ {GOALS['stride_length_pct']:.0f} %, "
        f"step width ≤ {GOALS['step_width_mm']:.0f} mm vs Vicon ankle centres.",
        "",
    ]
    L += [
        "## (a) Events vs marker events (IMU − marker)",
        "",
        "| event | part | n | missed | bias ms | median abs ms | worst abs ms |",
        "|---|---|---|---|---|---|---|",
    ]
    for k, v in res["events"].items():
        for part in ("straight", "turn"):
            if part not in v:
                continue
            s = v[part]
            if s.get("n"):
                L.append(
                    f"| {k} | {part} | {s['n']} | {s['missed']} | {s['bias_ms']:+.0f} | "
                    f"{s['median_abs_ms']:.0f} | {s['worst_abs_ms']:.0f} |"
                )
            else:
                L.append(f"| {k} | {part} | 0 | {s['missed']} | – | – | – |")
    L += [
        "",
        "## (b) Foot-stationary periods vs step-detect flags (walking window)",
        "",
        "| side | agreement % | onset median ms | onset worst ms | offset median ms | offset worst ms "
        "| periods flags/detected |",
        "|---|---|---|---|---|---|---|",
    ]
    for side, s in res["stationary"].items():
        L.append(
            f"| {side} | {s['agreement_pct']:.1f} | {s['onset_median_ms']:+.0f} | "
            f"{s['onset_worst_ms']:.0f} | "
            f"{s['offset_median_ms']:+.0f} | {s['offset_worst_ms']:.0f} | "
            f"{s['n_periods_flags']}/{s['n_periods_detected']} |"
        )
    sp = res["spatial"]
    L += [
        "",
        "## (c) Spatio-temporal parameters vs Vicon ankle centres and marker events (straight strides)",
        "",
        "| quantity | median abs err | worst abs err | bias |",
        "|---|---|---|---|",
    ]
    for key, unit in (
        ("stride_length_err_pct", "%"),
        ("step_length_err_mm", "mm"),
        ("step_width_err_mm", "mm"),
    ):
        e = sp[key]
        L.append(
            f"| {key.replace('_err_' + unit.replace('%', 'pct'), '')} | {e['median_abs']:.1f} {unit} | "
            f"{e['worst_abs']:.1f} {unit} | {e['bias']:+.1f} {unit} |"
        )
    for key in ("stance_pct", "double_support_pct"):
        e = sp[f"{key}_err_points"]
        if e.get("n"):
            L.append(
                f"| {key} (vs marker events, n={e['n']}) | {e['median_abs']:.1f} pts | "
                f"{e['worst_abs']:.1f} pts | {e['bias']:+.1f} pts |"
            )
    L += [
        "",
        f"Cadence: IMU {sp['cadence_imu']:.1f} (60/step time; 120/stride time: "
        f"{sp['cadence_imu_from_strides']:.1f}), Vicon {sp['cadence_vicon']:.1f} steps/min "
        f"(120/stride time). "
        f"Speed: IMU {sp['speed_imu_m_s']:.3f}, Vicon {sp['speed_vicon_m_s']:.3f} m/s "
        f"(per-stride median abs error {sp['speed_err_m_s']['median_abs']:.3f} m/s). "
        f"Straight strides scored: {sp['n_straight_strides']}; "
        f"IMU turning strides: {sp['n_turn_strides_imu']} "
        f"(Vicon strides touching the turn: {sp['turn_strides_vicon']}). Right-to-left heading alignment "
        f"{sp['relative_heading_deg']:.1f} deg; median ZUPT velocity drift per swing "
        + ", ".join(f"{k} {v:.3f} m/s" for k, v in sp["zupt_drift_mps"].items())
        + ".",
        "",
    ]
    L += [
        "## Strides",
        "",
        "| side | start s | turning (IMU) | straight (Vicon) | stride IMU/Vicon m | step length "
        "IMU/Vicon m | step width IMU/Vicon m | heading change deg |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in res["strides"]:
        L.append(
            f"| {r['side']} | {r['start_s']:.2f} | {r['imu_turning']} | {r['vicon_straight']} | "
            f"{r['stride_length_imu_m']:.3f}/{r['stride_length_vicon_m']:.3f} | "
            f"{r['step_length_imu_m']:.3f}/{r['step_length_vicon_m']:.3f} | "
            f"{r['step_width_imu_m']:.3f}/{r['step_width_vicon_m']:.3f} | {r['heading_change_deg']:.1f} |"
        )
    return "\n".join(L) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    args = ap.parse_args()
    res = run(args.data)
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    (out / "gait_events.json").write_text(json.dumps(res, indent=2, default=float) + "\n")
    md = markdown(res)
    (out / "gait_events.md").write_text(md)
    print(md)


if __name__ == "__main__":
    main()
