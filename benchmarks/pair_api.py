"""The two-IMU centre API (``estimate_joint_center``) with and without its band test, rigid and skin-mounted.

``calibrate`` caps every leg joint's cut-offs at the band in which the two accelerometer norms stay
coherent; the pair API, made for any two IMUs, did not (a rigid pair's norms can be incoherent), and
on the real walk's skin-mounted sensors it put the hips 70–150 mm from where ``calibrate`` does.
Since 0.5.14 it fits both bands and keeps the cap where the fits say the sensors move on their
segments (``lowerlimb.calibration.pair_band``). *before* = ``CalibrationOptions(pair_band_test=False)``.

Sources:

- **rigid synthetic**: ``tests/rigid_pair.py`` spherical pairs, 30 s, noise and bias, smooth random
  3D motion with every frequency × 1, 2, 3 (amplitudes ÷ the factor), seeds 0–11; error of both
  centres (6-vector norm), mm;
- **simulated legs**: ``simulate`` one-leg walk / mixed / squat, 40 s, seeds 1–3, rigid sensors, the
  real-walk artefact profile, and that profile with each wobbling mass's own force (``own 3``:
  ``sim_signatures.md``); the hip (pelvis–thigh) and ankle (shank–foot) pairs, error as above;
- **rig**: the mechanical rig (``rig/``, 50 Hz, optical truth; the hinge trial 1D_01 scored by the
  distance to the axis line);
- **RING**: the seg1–seg2 spherical joint, rigid and non-rigid mounting, against the nominal
  geometry (itself a few mm to cm off, ``ring.md``);
- **hinges**: the real walk's knees (as recorded, and from frame 1100 on, without the still start)
  against the leg calibration's axis line, RING's hinges and the rig's hinge trial;
- **real walk**: each leg's hip and ankle pair; the thigh and shank lengths they give with the
  leg calibration's knee, against Plug-in Gait (as ``real_gait.md``), and the distance of the
  centre in the thigh / shank sensor to the leg calibration's.

Usage: ``python benchmarks/pair_api.py [--data ../shared/data] [--out benchmarks/results]``.
"""

from __future__ import annotations

import dataclasses
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import lowerlimb as ll
from lowerlimb.calibration import CalibrationOptions, calibrate_spherical_joint
from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.simulation import Artefacts, simulate, simulate_bilateral

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))  # the synthetic rigid pairs of the unit tests
import rig  # noqa: E402
import ring  # noqa: E402
from _realwalk import leg_mapping, load_vicon, raw_dir  # noqa: E402
from _results import cell, real_data_main  # noqa: E402
from rigid_pair import rigid_pair  # noqa: E402

OFF = CalibrationOptions(pair_band_test=False)
PAIRS = {"hip": ("pelvis", "thigh"), "ankle": ("shank", "foot")}
#: The real walk from this frame on has no still start (walking begins at frame 1120).
NO_STILL_FROM = 1100


def _fit(a1: Any, g1: Any, a2: Any, g2: Any, rate: float, options: CalibrationOptions | None = None) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate_spherical_joint(a1, g1, a2, g2, rate_hz=rate, options=options)


def _x(r: Any) -> np.ndarray:
    return np.r_[r.center_in_parent_sensor, r.center_in_child_sensor]


def _row(source: str, case: str, after: Any, before: Any, err: Any) -> dict[str, Any]:
    """One pair: the errors ``err(result)`` after and before, and the band test's numbers."""
    b = after.pair_band
    return {
        "source": source,
        "case": case,
        "after": err(after),
        "before": err(before),
        "cap_hz": None if b is None else b.cap_hz,
        "gain": None if b is None else b.low_band_gain,
        "cost": None if b is None else b.full_band_cost,
        "capped": bool(b is not None and b.capped),
    }


def _both(signals: tuple[Any, ...], rate: float) -> tuple[Any, Any]:
    return _fit(*signals, rate), _fit(*signals, rate, OFF)


def rigid_rows() -> list[dict[str, Any]]:
    import rigid_pair as module

    smooth = module._smooth_signal
    rows = []
    for speed in (1, 2, 3):

        def faster(rng: Any, n: int, amp: float, fmax: float, s: int = speed) -> Any:
            return smooth(rng, n, amp / s if amp > 0.35 else amp, fmax * s)

        module._smooth_signal = faster
        try:
            for seed in range(12):
                p = rigid_pair(seed=seed, duration_s=30.0, still_s=1.0, gyro_noise=0.01, acc_noise=0.05,
                               gyro_bias=0.01)  # fmt: skip
                true = np.r_[p.center_parent, p.center_child]
                after, before = _both((p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child), p.rate_hz)
                rows.append(_row("rigid synthetic", f"speed x{speed}", after, before,
                                 lambda r, t=true: 1000 * np.linalg.norm(_x(r) - t)))  # fmt: skip
        finally:
            module._smooth_signal = smooth
    return rows


def _own_tissue(seed: int) -> Artefacts:
    base = Artefacts.real_walk(seed)
    half = {k: v * 0.5 for k, v in base.tissue_gain.items()}
    imp = {k: v * 0.5 for k, v in base.impact_mps2.items()}
    contra = {k: v * 0.5 for k, v in base.impact_contra_mps2.items()}
    own = {"pelvis": 3.0, "thigh": 3.0, "shank": 3.0, "foot": 0.0}
    return dataclasses.replace(
        base, tissue_random_mps2=own, tissue_gain=half, impact_mps2=imp, impact_contra_mps2=contra
    )


PROFILES = {"rigid": lambda seed: None, "real-walk artefacts": Artefacts.real_walk, "own 3": _own_tissue}


def _leg_rows(case: str, t: Any, truth: dict[str, Any], prefix: str = "") -> list[dict[str, Any]]:
    """A simulated leg's hip and ankle pairs.

    ``near``: the error of the centre in the sensor on the knee's side (thigh for the hip, shank
    for the ankle), which a segment length uses.
    """
    rows = []
    for joint, (p, c) in PAIRS.items():
        p, c = (p if p == "pelvis" else prefix + p), prefix + c
        tj = truth[joint]
        true = np.r_[tj["center_in_parent_sensor"], tj["center_in_child_sensor"]]
        after, before = _both((t.acc[p], t.gyr[p], t.acc[c], t.gyr[c]), t.rate_hz)
        row = _row("simulated legs", f"{case}, {joint}", after, before,
                   lambda r, tr=true: 1000 * np.linalg.norm(_x(r) - tr))  # fmt: skip
        k = slice(3, 6) if joint == "hip" else slice(0, 3)
        row["near_after"], row["near_before"] = (
            1000 * np.linalg.norm(_x(r)[k] - true[k]) for r in (after, before)
        )
        rows.append(row)
    return rows


def simulated_rows() -> list[dict[str, Any]]:
    rows = []
    for motion in ("walk", "mixed", "squat"):
        for profile, make in PROFILES.items():
            for seed in (1, 2, 3):
                sim = simulate(motion, duration_s=40.0, seed=seed, artefacts=make(seed))
                rows += _leg_rows(f"{motion}, {profile}", sim.trial, sim.truth["joints"])
    for profile in ("rigid", "real-walk artefacts"):
        for seed in range(201, 207):
            art = Artefacts.real_walk(seed) if profile != "rigid" else None
            sim = simulate_bilateral(duration_s=60.0, seed=seed, artefacts=art)
            for side in ("left", "right"):
                truth = sim.truth["legs"][side]["joints"]
                rows += _leg_rows(f"two-leg walk, {profile}", sim.trial, truth, f"{side}_")
    return rows


def rig_rows(data: Path) -> list[dict[str, Any]]:
    rows = []
    for trial in rig.TRIALS:
        t = rig.load_trial(data, trial)
        if trial == rig.HINGE_TRIAL:
            j1, j2, _ = rig.true_hinge_axes(t["q1"], t["q2"])

            def err(r: Any, t: Any = t, j1: Any = j1, j2: Any = j2) -> float:
                e1 = rig.distance_to_line(r.center_in_parent_sensor, t["r_12"], j1)
                return 1000 * float(
                    np.hypot(e1, rig.distance_to_line(r.center_in_child_sensor, t["r_21"], j2))
                )
        else:

            def err(r: Any, t: Any = t) -> float:
                return 1000 * float(np.linalg.norm(_x(r) - np.r_[t["r_12"], t["r_21"]]))

        after, before = _both((t["acc1"], t["gyr1"], t["acc2"], t["gyr2"]), t["rate_hz"])
        rows.append(_row("rig", trial, after, before, err))
    return rows


def ring_rows(data: Path) -> list[dict[str, Any]]:
    rows = []
    nominal = np.r_[ring.JOINT_IN_PARENT_IMU, ring.JOINT_IN_CHILD_IMU]
    for rec in ("rigid", "nonrigid"):
        imu = ring.load_imu(data / "ring" / f"trial1_imu_{rec}.csv")
        after, before = _both((imu[1]["acc"], imu[1]["gyr"], imu[2]["acc"], imu[2]["gyr"]), ring.RATE_HZ)
        rows.append(_row("RING", f"{rec} seg1-seg2", after, before,
                         lambda r: 1000 * np.linalg.norm(_x(r) - nominal)))  # fmt: skip
    return rows


def _line_mm(point: np.ndarray, on_line: np.ndarray, axis: np.ndarray) -> float:
    d = point - on_line
    return 1000 * float(np.linalg.norm(d - (d @ axis) * axis))


def _walk_row(side: str, joint: str, t: Any, leg: Any, vicon: dict[str, Any]) -> dict[str, Any]:
    """One real-walk pair: its segment length against Plug-in Gait and its gap to the leg's centre."""
    p, c = PAIRS[joint]
    after, before = _both((t.acc[p], t.gyr[p], t.acc[c], t.gyr[c]), t.rate_hz)
    P, k = side[0].upper(), leg.knee
    a, b = (P + "HJC", P + "KJC") if joint == "hip" else (P + "KJC", P + "AJC")
    ref = float(np.nanmedian(np.linalg.norm(vicon[a] - vicon[b], axis=1)))
    # the centre in the sensor on the knee's side of the segment, and the knee seen from it
    near, own, on, axis = (
        ("child", leg.hip.center_in_child_sensor, k.center_in_parent_sensor, k.axis_in_parent_sensor)
        if joint == "hip"
        else ("parent", leg.ankle.center_in_parent_sensor, k.center_in_child_sensor, k.axis_in_child_sensor)
    )

    def centre(r: Any) -> np.ndarray:
        return np.asarray(getattr(r, f"center_in_{near}_sensor"))

    row = _row("real walk", f"{side} {joint}", after, before, lambda r: _line_mm(centre(r), on, axis) - ref)
    row["leg_gap_after"], row["leg_gap_before"] = (
        1000 * float(np.linalg.norm(centre(r) - own)) for r in (after, before)
    )
    return row


def real_walk_rows(data: Path) -> list[dict[str, Any]]:
    vicon = load_vicon(data)
    rows = []
    for side in ("left", "right"):
        t = ll.read_xsens(raw_dir(data), leg_mapping(side), side=side)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            leg = calibrate_leg(t)
        rows += [_walk_row(side, joint, t, leg, vicon) for joint in PAIRS]
    return rows


def _hinge_row(source: str, case: str, signals: tuple[Any, ...], rate: float, lines: tuple[Any, Any]) -> dict:
    """One hinge through ``calibrate_hinge_joint``: its centre's distance to reference lines, mm."""
    from lowerlimb.calibration import calibrate_hinge_joint

    def fit(o: CalibrationOptions | None) -> Any:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            h = calibrate_hinge_joint(*signals, rate_hz=rate, options=o)
        return h, any("move on their segments" in str(w.message) for w in caught)

    (after, capped), (before, _) = fit(None), fit(OFF)

    def err(h: Any) -> list[float]:
        return [_line_mm(h.center_in_parent_sensor, *lines[0]), _line_mm(h.center_in_child_sensor, *lines[1])]

    return {"source": source, "case": case, "before": err(before), "after": err(after), "capped": capped}


def hinge_rows(data: Path) -> list[dict[str, Any]]:
    """Real walk knees (against the leg calibration's knee line), RING hinges (nominal), the rig's hinge."""
    rows = []
    for side in ("left", "right"):
        t = ll.read_xsens(raw_dir(data), leg_mapping(side), side=side)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            k = calibrate_leg(t).knee
        lines = (
            (k.center_in_parent_sensor, k.axis_in_parent_sensor),
            (k.center_in_child_sensor, k.axis_in_child_sensor),
        )
        signals = (t.acc["thigh"], t.gyr["thigh"], t.acc["shank"], t.gyr["shank"])
        rows.append(_hinge_row("real walk (vs calibrate)", f"{side} knee", signals, t.rate_hz, lines))
        cut = tuple(x[NO_STILL_FROM:] for x in signals)  # no still start: the mismatch over the motion
        rows.append(
            _hinge_row("real walk (vs calibrate)", f"{side} knee, no still start", cut, t.rate_hz, lines)
        )
    for rec in ("rigid", "nonrigid"):
        imu = ring.load_imu(data / "ring" / f"trial1_imu_{rec}.csv")
        for p, c, k3 in ring.HINGES:
            e = np.eye(3)[k3]
            signals = (imu[p]["acc"], imu[p]["gyr"], imu[c]["acc"], imu[c]["gyr"])
            nominal = ((ring.JOINT_IN_PARENT_IMU, e), (ring.JOINT_IN_CHILD_IMU, e))
            rows.append(
                _hinge_row("RING (vs nominal)", f"{rec} seg{p}-seg{c}", signals, ring.RATE_HZ, nominal)
            )
    t = rig.load_trial(data, rig.HINGE_TRIAL)
    j1, j2, _ = rig.true_hinge_axes(t["q1"], t["q2"])
    rows.append(_hinge_row("rig (vs optical)", rig.HINGE_TRIAL, (t["acc1"], t["gyr1"], t["acc2"], t["gyr2"]),
                           t["rate_hz"], ((t["r_12"], j1), (t["r_21"], j2))))  # fmt: skip
    return rows


def run(data: Path) -> dict[str, Any]:
    return {
        "hinges": hinge_rows(data),
        "rows": rigid_rows() + simulated_rows() + rig_rows(data) + ring_rows(data) + real_walk_rows(data),
        "margin": CalibrationOptions().pair_band_margin,
        "version": ll.__version__,
    }


def _pooled(rows: list[dict[str, Any]]) -> str:
    """Rows grouped by (source, case without the seed): median / worst of after and before."""
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault((r["source"], r["case"]), []).append(r)
    out = []
    for (source, case), rs in groups.items():
        a, b = np.array([r["after"] for r in rs]), np.array([r["before"] for r in rs])
        na, nb = (np.array([r.get(f"near_{w}", np.nan) for r in rs]) for w in ("after", "before"))
        near = (
            f" | {np.median(nb):.1f} / {np.max(nb):.1f} | {np.median(na):.1f} / {np.max(na):.1f}"
            if np.all(np.isfinite(na))
            else ""
        )
        tested = [r for r in rs if r["cap_hz"] is not None]
        margins = [r["gain"] - r["cost"] for r in tested]
        gains = f"{min(margins):+.2f} … {max(margins):+.2f}" if margins else "–"
        out.append(
            f"| {source} | {case} | {len(rs)} | {len(tested)} | {sum(r['capped'] for r in rs)} | "
            f"{gains} | {np.median(b):.1f} / {np.max(b):.1f} | "
            f"{np.median(a):.1f} / {np.max(a):.1f}{near} |"
        )
    return "\n".join(out)


def markdown(res: dict[str, Any]) -> str:
    rows = res["rows"]
    sim = [r for r in rows if r["source"] in ("rigid synthetic", "simulated legs")]
    real = [r for r in rows if r["source"] in ("rig", "RING")]
    walk = [r for r in rows if r["source"] == "real walk"]
    md = [
        f"# The two-IMU centre API's band test (lowerlimb {res['version']})",
        "",
        "Generated by `benchmarks/pair_api.py` (sources in its docstring). *before*: "
        "`CalibrationOptions(pair_band_test=False)`, the API as it was (own cut-offs). *tested*: pairs "
        "whose rigid band caps their cut-offs (the others are fitted once, unchanged); *capped*: the "
        "test kept the cap; *gain − cost*: the test's low-band gain less its full-band cost over the "
        f"tested pairs (the cap is kept above {res['margin']:g}).",
        "",
        "## Simulated (error of both centres against the truth, mm: median / worst)",
        "",
        "Rigid synthetic pairs: the 6-vector of both centres. Legs also: *knee side*, the centre in "
        "the thigh sensor (hip) or the shank sensor (ankle) alone, which a segment length uses (a "
        "hip's centre in the pelvis sensor is poorly determined by walking either way).",
        "",
        "| source | case | pairs | tested | capped | gain − cost | before | after |",
        "|---|---|---|---|---|---|---|---|",
        _pooled([r for r in sim if "near_after" not in r]),
        "",
        "| source | case | pairs | tested | capped | gain − cost | before | after | knee side before "
        "| after |",
        "|---|---|---|---|---|---|---|---|---|---|",
        _pooled([r for r in sim if "near_after" in r]),
        "",
        "## Real rigid and non-rigid chains (mm against the optical or nominal centres: median / worst)",
        "",
        "| source | case | pairs | tested | capped | gain − cost | before | after |",
        "|---|---|---|---|---|---|---|---|",
        _pooled(real),
        "",
        "## Real walk (skin-mounted Xsens MTw): segment length against Plug-in Gait, and gap to `calibrate`",
        "",
        "Length: the hip's centre in the thigh sensor (ankle's in the shank sensor) to the leg "
        "calibration's knee axis, less Plug-in Gait's thigh (shank), mm. Gap: that centre's distance "
        "to the leg calibration's own, mm.",
        "",
        "| pair | gain − cost | capped | length error before | after | gap before | after |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in walk:
        margin = None if r["gain"] is None else r["gain"] - r["cost"]
        md.append(
            f"| {r['case']} | {cell(margin, '+.2f')} | {'yes' if r['capped'] else 'no'} | "
            f"{r['before']:+.1f} | {r['after']:+.1f} | {r['leg_gap_before']:.1f} | {r['leg_gap_after']:.1f} |"
        )
    md += [
        "",
        "## The hinge pair API (`calibrate_hinge_joint`): centre to the reference axis line, mm",
        "",
        "Since 0.5.14 a pair whose axis, seen from its two sensors, differs in elevation at rest by more "
        "than 6° (`fit_band_max_mismatch_deg`, the leg calibration's rigidity cue) is fitted again below "
        "its rigid band's cap (*capped*); since 0.5.15 a pair without a still start reads that mismatch "
        "over the motion (*no still start*: the real walk from frame 1100, where walking begins). "
        "Parent / child sensor.",
        "",
        "| source | hinge | capped | before | after |",
        "|---|---|---|---|---|",
    ]
    for h in res["hinges"]:
        b, a = (" / ".join(f"{v:.1f}" for v in h[w]) for w in ("before", "after"))
        md.append(f"| {h['source']} | {h['case']} | {'yes' if h['capped'] else 'no'} | {b} | {a} |")
    return "\n".join(md) + "\n"


if __name__ == "__main__":
    real_data_main(__doc__, "pair_api", run, markdown)
