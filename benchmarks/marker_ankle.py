"""Where does the real walk's own motion put the ankle? Functional ankle centres from the Vicon markers.

The real walk's shank-length goal (issue 11: within 20 mm of Vicon) is scored against
Plug-in Gait's ankle centre (AJC), which is placed from the lateral malleolus marker
(``*ANK``) and the subject's ankle width: a point between the malleoli, at the height of
the marker. A joint-constraint calibration finds something else, the *functional* centre:
the point of the shank about which the foot turns. Anatomy puts the two apart: the
talocrural axis runs just distal to the malleolar tips (Inman 1976, *The Joints of the
Ankle*; Lundberg et al. 1989, Foot Ankle 9(4):194–200), and a marker sits on the
malleolus's prominence, about a centimetre or more above its tip.

This benchmark measures that offset on the walk itself, with no IMU involved. The shank
markers (``*KNE``, ``*TIB``, ``*ANK``) give a rigid shank frame (Kabsch fit to the standing
average, so its axes are the lab's at standing), and the foot markers (``*HEE``, ``*TOE``)
expressed in it should each move on a sphere about the ankle centre: one centre, one radius
per marker (scipy ``least_squares``), on each straight pass, the turn, the authors' walking
window and both straight passes; with the heel marker, the toe marker, and both.

Per fit: the centre minus AJC in the standing lab axes (forward = heel→toe, lateral =
towards the ``*ANK`` marker, up), its formal SD and RMS, and the shank length
|KJC − centre| minus Plug-in Gait's |KJC − AJC| (mm, mean over the subset's frames).
Walking turns the ankle mostly about one axis, so the centre's position *along* that axis
(here mostly the lateral component) is weakly pinned; the up and forward components, which
decide the shank length, are what the fit determines. For context the summary repeats the
IMU's shank-length errors against Plug-in Gait (``bilateral_gait.json``, the default form;
``aligned_form.json``, ``centre_form="aligned"``) and against the median functional centre.

Usage: ``python benchmarks/marker_ankle.py [--data ../shared/data] [--out DIR]``; writes
``marker_ankle.{md,json}``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _realwalk import STAND, load_vicon  # noqa: E402
from _results import real_data_main  # noqa: E402
from marker_hip import _kabsch, fit_centre, subsets  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SHANK_MARKERS = ("KNE", "TIB", "ANK")
MARKER_SETS = {"heel": ("HEE",), "toe": ("TOE",), "both": ("HEE", "TOE")}
SIDE_NAMES = {"L": "left", "R": "right"}


class ShankFrame:
    """The shank markers' rigid frame, in the lab's axes at standing (mm)."""

    def __init__(self, vicon: dict[str, Any], side: str) -> None:
        markers = np.stack([np.asarray(vicon[f"{side}{k}"], float) for k in SHANK_MARKERS], axis=1)
        ref = markers[STAND].mean(axis=0)
        fits = [_kabsch(ref, m) for m in markers]
        self.rot = np.stack([f[0] for f in fits])
        self.trans = np.stack([f[1] for f in fits])

    def local(self, x: np.ndarray) -> np.ndarray:
        """Lab points (N, 3), mm → the shank frame (N, 3), mm."""
        return np.einsum("nji,nj->ni", self.rot, x - self.trans)


def standing_axes(vicon: dict[str, Any], side: str, frame: ShankFrame, ajc: np.ndarray) -> np.ndarray:
    """(3, 3) rows forward (heel→toe, horizontal), lateral (towards ANK, horizontal), up."""
    names = ("HEE", "TOE", "ANK")
    pt = {k: frame.local(np.asarray(vicon[f"{side}{k}"], float))[STAND].mean(axis=0) for k in names}
    up = np.array([0.0, 0.0, 1.0])
    fwd = pt["TOE"] - pt["HEE"]
    fwd -= (fwd @ up) * up
    fwd /= np.linalg.norm(fwd)
    lat = np.cross(up, fwd)
    if lat @ (pt["ANK"] - ajc) < 0:
        lat = -lat
    return np.stack([fwd, lat, up])


def run(data: Path) -> dict[str, Any]:
    vicon = load_vicon(data)
    rows = []
    for side in "LR":
        frame = ShankFrame(vicon, side)
        ajc = frame.local(np.asarray(vicon[f"{side}AJC"], float))
        kjc = frame.local(np.asarray(vicon[f"{side}KJC"], float))
        pig_len = np.linalg.norm(kjc - ajc, axis=1)
        ajc0 = ajc[STAND].mean(axis=0)
        axes = standing_axes(vicon, side, frame, ajc0)
        ank = frame.local(np.asarray(vicon[f"{side}ANK"], float))[STAND].mean(axis=0)
        for sub, idx in subsets(vicon).items():
            for label, names in MARKER_SETS.items():
                pts = [frame.local(np.asarray(vicon[f"{side}{n}"], float))[idx] for n in names]
                c, sd, rms = fit_centre(pts, ajc0)
                length = float(np.linalg.norm(kjc[idx] - c, axis=1).mean() - pig_len[idx].mean())
                rows.append(
                    {
                        "side": SIDE_NAMES[side],
                        "subset": sub,
                        "markers": label,
                        "frames": len(idx),
                        "centre_minus_ajc_mm": (axes @ (c - ajc[idx].mean(axis=0))).tolist(),
                        "formal_sd_mm": sd.tolist(),
                        "fit_rms_mm": rms,
                        "below_ank_marker_mm": float((ank - c) @ axes[2]),
                        "shank_length_minus_pig_mm": length,
                    }
                )
    return {"rows": rows, "spread": _spread(rows), "imu": _imu_context(rows)}


def _spread(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per side, over the subsets fitted with both foot markers: min / median / max shank offset."""
    out: dict[str, Any] = {}
    for side in SIDE_NAMES.values():
        lens = [r["shank_length_minus_pig_mm"] for r in rows if r["side"] == side and r["markers"] == "both"]
        out[side] = {"min_mm": min(lens), "median_mm": float(np.median(lens)), "max_mm": max(lens)}
    return out


def _imu_context(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The IMU's shank errors against Plug-in Gait and against the median functional centre."""
    spread = _spread(rows)
    sources = {
        "default": ("bilateral_gait.json", lambda d: d["legs"]),
        "aligned": ("aligned_form.json", lambda d: d["real"]["aligned"]["legs"]),
    }
    out: dict[str, Any] = {}
    for form, (name, legs_of) in sources.items():
        path = ROOT / "benchmarks" / "results" / name
        if not path.is_file():
            continue
        legs = legs_of(json.loads(path.read_text()))
        out[form] = {
            side: {
                "shank_err_vs_pig_mm": legs[side]["shank_err_mm"],
                "shank_err_vs_functional_mm": legs[side]["shank_err_mm"] - spread[side]["median_mm"],
            }
            for side in SIDE_NAMES.values()
        }
    return out


def markdown(res: dict[str, Any]) -> str:
    L = [
        "# Functional ankle centres from the Vicon markers of the real walk",
        "",
        "Generated by `benchmarks/marker_ankle.py` (no IMU involved). The heel and toe markers'",
        "sphere centre in the shank markers' frame, minus Plug-in Gait's AJC in the standing",
        "lab axes (forward, lateral, up), its formal SD, the fit's RMS, how far the centre lies",
        "below the lateral malleolus marker, and the shank length |KJC − centre| minus Plug-in",
        "Gait's |KJC − AJC|; mm.",
        "",
        "| side | subset | markers | frames | centre − AJC (fwd, lat, up) | formal SD | fit RMS "
        "| below ANK | shank − PiG |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        d = ", ".join(f"{v:+.0f}" for v in r["centre_minus_ajc_mm"])
        s = ", ".join(f"{v:.0f}" for v in r["formal_sd_mm"])
        L.append(
            f"| {r['side']} | {r['subset']} | {r['markers']} | {r['frames']} | {d} | {s} | "
            f"{r['fit_rms_mm']:.1f} | {r['below_ank_marker_mm']:.0f} | "
            f"{r['shank_length_minus_pig_mm']:+.0f} |"
        )
    L += [
        "",
        "Both foot markers, over the five subsets:",
        "",
        "| side | functional shank − PiG: min / median / max | IMU shank − PiG, default / aligned "
        "| IMU shank − functional, default / aligned |",
        "|---|---|---|---|",
    ]
    imu = res.get("imu", {})
    for side, sp in res["spread"].items():
        vs_pig = " / ".join(
            f"{imu[f][side]['shank_err_vs_pig_mm']:+.0f}" if f in imu else "–" for f in ("default", "aligned")
        )
        vs_fun = " / ".join(
            f"{imu[f][side]['shank_err_vs_functional_mm']:+.0f}" if f in imu else "–"
            for f in ("default", "aligned")
        )
        L.append(
            f"| {side} | {sp['min_mm']:+.0f} / {sp['median_mm']:+.0f} / {sp['max_mm']:+.0f} "
            f"| {vs_pig} | {vs_fun} |"
        )
    L += [
        "",
        "With both foot markers the functional centre is stable across subsets (a few mm) and",
        "lies below Plug-in Gait's AJC on both legs, as the anatomy says (the talocrural axis",
        "runs distal to the malleolar tips): the functional shank is longer than Plug-in",
        "Gait's. A joint-constraint calibration estimates the functional centre, so its shank",
        "is expected to exceed Plug-in Gait's by about this much; an IMU shank that matches",
        "Plug-in Gait exactly is short of the functional one.",
        "",
    ]
    return "\n".join(L)


def main() -> None:
    real_data_main(__doc__, "marker_ankle", run, markdown)


if __name__ == "__main__":
    main()
