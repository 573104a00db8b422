"""The norm form against the aligned 3-D form of the joint constraint, on the same data.

Three configurations, everything else equal (:data:`FORMS`):

- ``norm``: every centre from the norm form (Hu et al. 2021 eq. 3;
  ``CalibrationOptions(hip_in_pelvis_form="norm")``);
- ``default``: the norm form, but the hip centre in the pelvis sensor from the aligned
  form given the norm form's hip in the thigh sensor (``CalibrationOptions()``);
- ``aligned``: the hip and knee centres from the aligned form
  (``CalibrationOptions(centre_form="aligned")``, :mod:`lowerlimb.calibration.aligned_form`);

on:

- simulated seven-IMU walks (``simulate_bilateral`` seeds 201-206, 60 s, the lab's
  magnetic field, 6-axis), rigid and with ``Artefacts.real_walk()``: segment lengths
  (hip or ankle centre to the knee axis line), joint centres, the worst non-flexion
  angle RMSE of each trial, step width (``gait.py``'s scoring);
- the real walk of ``gait/`` (Xsens + Vicon): segment lengths against Vicon's
  HJC-KJC and KJC-AJC, hip spacing, stride length and step width of the straight
  strides, knee flexion RMSE (``bilateral_gait.py``'s scoring);
- the rig of ``rig/`` (exact joint centres): the centre error of both forms at the
  cut-off the calibration uses there (none: the rig's adaptive cut-off leaves the
  signals unfiltered).

Usage: ``python benchmarks/aligned_form.py [--data DIR] [--seeds ...]``; writes
``benchmarks/results/aligned_form.{md,json}``.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from gait import _module, add_walk_arguments, true_leg  # noqa: E402  (benchmarks/gait.py)

from lowerlimb.bilateral import process_bilateral_trial  # noqa: E402
from lowerlimb.calibration._prepare import prepare_signals  # noqa: E402
from lowerlimb.calibration.aligned_form import AlignedSettings, aligned_centres  # noqa: E402
from lowerlimb.calibration.leg import calibrate_leg  # noqa: E402
from lowerlimb.calibration.options import CalibrationOptions  # noqa: E402
from lowerlimb.io import load_xsens  # noqa: E402
from lowerlimb.io.bilateral_trial import BilateralTrial  # noqa: E402
from lowerlimb.model.fallback import segment_lengths  # noqa: E402
from lowerlimb.simulation import Artefacts, simulate  # noqa: E402

#: Configuration name -> its CalibrationOptions keywords (module docstring).
FORMS: dict[str, dict[str, Any]] = {
    "norm": {"hip_in_pelvis_form": "norm"},
    "default": {},
    "aligned": {"centre_form": "aligned"},
}
#: The two forms themselves, where the benchmark calls them directly (RING chain, rig).
PURE_FORMS = ("norm", "aligned")


def simulated(seeds: list[int], duration_s: float, artefacts: Artefacts | None) -> dict[str, Any]:
    """Both forms on the same simulated walks, pooled with ``gait.py``'s summary."""
    g = _module("gait")
    out: dict[str, Any] = {}
    for form in FORMS:
        opts = CalibrationOptions(**FORMS[form])
        trials, failed = [], []
        for seed in seeds:
            try:
                trials.append(g.score_simulation(seed, duration_s, artefacts, calibration_options=opts))
            except Exception as e:  # noqa: BLE001 - a benchmark records any failure
                failed.append(f"seed {seed}: {type(e).__name__}: {e}")
        if not trials:
            out[form] = {"failed": failed}
            continue
        pooled = g.summarise_simulation(trials)
        worst = [
            max(v for side in tr["angle_rmse_deg"].values() for k, v in side.items() if "flexion" not in k)
            for tr in trials
        ]
        out[form] = {
            "joints": pooled["joints"],
            "step_width_mm": pooled["step_width_mm"],
            "stride_length_pct": pooled["stride_length_pct"],
            "worst_other_angle_deg": worst,
            "wall_s": [tr["wall_s"] for tr in trials],
            "seeds": [tr["seed"] for tr in trials],
            "failed": failed,
        }
    return out


#: One-leg simulated motions (``simulate``), seeds 0 and 1, 60 s: the milder simulator of issue 1-10.
ONE_LEG_MOTIONS = ("walk", "squat", "knee-lift", "sit-to-stand")


def _mm(a: np.ndarray, b: np.ndarray) -> float:
    return 1000.0 * float(np.linalg.norm(np.asarray(a) - np.asarray(b)))


def one_leg(duration_s: float) -> list[dict[str, Any]]:
    """Both forms on one-leg simulated motions: length errors and hip centre errors, mm."""
    rows = []
    for motion in ONE_LEG_MOTIONS:
        for seed in (0, 1):
            sim = simulate(motion, duration_s, seed)
            truth = true_leg(sim.truth["joints"])
            true_len = np.array(segment_lengths(truth))  # type: ignore[arg-type]
            row: dict[str, Any] = {"motion": motion, "seed": seed}
            for form in FORMS:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    cal = calibrate_leg(sim.trial, options=CalibrationOptions(**FORMS[form]))
                row[form] = {
                    "length_err_mm": list(1000.0 * (np.array(segment_lengths(cal)) - true_len)),
                    "hip_in_pelvis_mm": 1000.0
                    * float(
                        np.linalg.norm(cal.hip.center_in_parent_sensor - truth.hip.center_in_parent_sensor)
                    ),
                    "hip_in_thigh_mm": 1000.0
                    * float(
                        np.linalg.norm(cal.hip.center_in_child_sensor - truth.hip.center_in_child_sensor)
                    ),
                }
            rows.append(row)
    return rows


def real_walk(data: Path) -> dict[str, Any]:
    """Both forms on the real walk, scored as ``bilateral_gait.py`` scores the default."""
    bg = _module("bilateral_gait")
    ge = bg._gait_events_module()
    vicon = bg.load_vicon(data)
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "walk7.csv"
        load_xsens(bg.raw_dir(data), bg.IDS).to_csv(csv)
        trial = BilateralTrial.from_csv(csv)
    out: dict[str, Any] = {}
    for form in FORMS:
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = process_bilateral_trial(trial, calibration_options=CalibrationOptions(**FORMS[form]))
        row: dict[str, Any] = {"wall_s": time.perf_counter() - t}
        row["legs"] = bg.score_legs(res, vicon)
        row |= bg.score_strides(res, vicon, ge)
        row["hip_spacing_err_mm"] = 1000 * res.hips.spacing_m - float(
            np.nanmedian(np.linalg.norm(vicon["LHJC"] - vicon["RHJC"], axis=1))
        )
        out[form] = row
    out["cap_sensitivity"] = cap_sensitivity(trial, vicon, bg)
    return out


#: Multiples of the rigid-band cap the real walk is re-calibrated at (the band's edge is a
#: coherence threshold, not a physical constant: a robust estimate should not hinge on it).
CAP_FACTORS = (1.0, 1.25, 1.5)


def cap_sensitivity(trial: Any, vicon: dict[str, Any], bg: ModuleType) -> dict[str, Any]:
    """Segment length errors against Vicon of both forms with the rigid-band cap widened."""
    out: dict[str, Any] = {}
    for form in ("default", "aligned"):  # the lengths do not depend on the hip in the pelvis
        for f in CAP_FACTORS:
            opts = CalibrationOptions(**FORMS[form], rigid_band_factor=f)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = process_bilateral_trial(trial, calibration_options=opts)
            legs = bg.score_legs(res, vicon)
            out[f"{form} x{f:g}"] = {
                side: {k: legs[side][k] for k in ("thigh_err_mm", "shank_err_mm")} for side in legs
            }
    return out


def rig(data: Path) -> list[dict[str, Any]]:
    """Centre errors of both forms on the rig's three trials (unfiltered, as the calibration runs there)."""
    import lowerlimb as ll

    r = _module("rig")
    opts = CalibrationOptions()
    settings = AlignedSettings(
        opts.aligned_window_s, opts.aligned_iterations, opts.angacc_window_s, opts.angacc_polyorder
    )
    rows = []
    for trial in ("1D_01", "2D_01", "3D_01"):
        t = r.load_trial(data, trial)
        c1, c2 = ll.estimate_joint_center(t["acc1"], t["gyr1"], t["acc2"], t["gyr2"], rate_hz=t["rate_hz"])
        # the gyro biases the norm form removes (its still period, if any)
        sig = prepare_signals(
            {"p": t["acc1"], "c": t["acc2"]}, {"p": t["gyr1"], "c": t["gyr2"]}, t["rate_hz"], opts
        )
        fit = aligned_centres(
            t["acc1"],
            t["gyr1"] - sig.gyro_bias["p"],
            t["acc2"],
            t["gyr2"] - sig.gyro_bias["c"],
            rate_hz=t["rate_hz"],
            cutoff_hz=None,
            start=np.concatenate([c1, c2]),
            settings=settings,
        )
        rows.append(
            {
                "trial": trial,
                "norm_mm": list(r.centre_errors_mm(t, trial, c1, c2)),
                "aligned_mm": list(r.centre_errors_mm(t, trial, fit.center_in_parent, fit.center_in_child)),
            }
        )
    return rows


#: Cut-offs the RING chain is calibrated at (``None``: the adaptive one, unfiltered at 40 Hz).
RING_CUTOFFS = (None, 5.0)


def _aligned_pair(ctx: dict[str, Any], p: int, c: int, start: np.ndarray, gauge: Any = None) -> Any:
    """The aligned fit of sensors ``p`` (parent) and ``c`` of a chain (``ctx``: signals, biases, settings)."""
    acc, gyr, bias = ctx["acc"], ctx["gyr"], ctx["bias"]
    return aligned_centres(
        acc[str(p)], gyr[str(p)] - bias[str(p)], acc[str(c)], gyr[str(c)] - bias[str(c)],
        rate_hz=ctx["rate"], cutoff_hz=ctx["fc"], start=start, settings=ctx["settings"], gauge_axes=gauge,
    )  # fmt: skip


def ring_chain(data: Path) -> list[dict[str, Any]]:
    """Both forms on the RING chain at the same cut-offs: seg4's joint-to-joint length, the ball joint."""
    from lowerlimb.calibration import calibrate_hinge_joint, calibrate_spherical_joint

    r = _module("ring")
    rows = []
    for rec in ("rigid", "nonrigid"):
        imu = r.load_imu(data / "ring" / f"trial1_imu_{rec}.csv")
        acc = {str(k): v["acc"] for k, v in imu.items()}
        gyr = {str(k): v["gyr"] for k, v in imu.items()}
        for fc in RING_CUTOFFS:
            opts = CalibrationOptions(cutoff_hz=fc)
            sig = prepare_signals(acc, gyr, r.RATE_HZ, opts)
            settings = AlignedSettings(
                opts.aligned_window_s, opts.aligned_iterations, opts.angacc_window_s, opts.angacc_polyorder
            )

            ctx = {
                "acc": acc,
                "gyr": gyr,
                "bias": sig.gyro_bias,
                "fc": fc,
                "settings": settings,
                "rate": r.RATE_HZ,
            }
            row: dict[str, Any] = {"recording": rec, "cutoff_hz": fc}
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                h = {
                    (p, c): calibrate_hinge_joint(
                        imu[p]["acc"],
                        imu[p]["gyr"],
                        imu[c]["acc"],
                        imu[c]["gyr"],
                        rate_hz=r.RATE_HZ,
                        options=opts,
                    )  # fmt: skip
                    for p, c in ((3, 4), (4, 5))
                }
                s = calibrate_spherical_joint(
                    imu[1]["acc"],
                    imu[1]["gyr"],
                    imu[2]["acc"],
                    imu[2]["gyr"],
                    rate_hz=r.RATE_HZ,
                    options=opts,
                )
            a = {
                pc: _aligned_pair(
                    ctx,
                    *pc,
                    np.r_[j.center_in_parent_sensor, j.center_in_child_sensor],
                    (j.axis_in_parent_sensor, j.axis_in_child_sensor),
                )
                for pc, j in h.items()
            }
            b = _aligned_pair(ctx, 1, 2, np.r_[s.center_in_parent_sensor, s.center_in_child_sensor])
            row["seg4_mm"] = {
                "norm": 1000 * (h[4, 5].center_in_parent_sensor[0] - h[3, 4].center_in_child_sensor[0]),
                "aligned": 1000 * (a[4, 5].center_in_parent[0] - a[3, 4].center_in_child[0]),
            }
            row["ball_err_mm"] = {
                "norm": [_mm(s.center_in_parent_sensor, r.JOINT_IN_PARENT_IMU),
                         _mm(s.center_in_child_sensor, r.JOINT_IN_CHILD_IMU)],
                "aligned": [_mm(b.center_in_parent, r.JOINT_IN_PARENT_IMU),
                            _mm(b.center_in_child, r.JOINT_IN_CHILD_IMU)],
            }  # fmt: skip
            row["seg4_optical_mm"] = 1000 * r.omc_seg4_length(data / "ring" / "trial1_omc.csv")
            rows.append(row)
    return rows


def _cell(st: dict[str, float]) -> str:
    return f"{st['median_abs']:.1f} / {st['worst_abs']:.1f} / {st['bias']:+.1f}"


def _row(label: str, cells: list[str]) -> str:
    return f"| {label} | " + " | ".join(cells) + " |"


_HEAD = " | ".join(FORMS)
_RULE = "|---" * (len(FORMS) + 1) + "|"


def _sim_lines(title: str, sim: dict[str, Any]) -> list[str]:
    runs = [sim[form] for form in FORMS]
    fails = [f"- {form} failed on {f}" for form in FORMS for f in sim[form].get("failed", [])]
    if any("joints" not in r for r in runs):
        return [f"### {title}", "", *fails, ""]
    L = [f"### {title}", "", f"| quantity (median abs / worst abs / bias) | {_HEAD} |", _RULE]
    for label in runs[0]["joints"]:
        L.append(_row(label, [_cell(r["joints"][label]) for r in runs]))
    for key in ("step_width_mm", "stride_length_pct"):
        L.append(_row(key, [_cell(r[key]) for r in runs]))
    worst = [" / ".join(f"{v:.2f}" for v in r["worst_other_angle_deg"]) for r in runs]
    L.append(_row("worst non-flexion angle RMSE per trial, deg", worst))
    wall = [f"{float(np.median(r['wall_s'])):.1f}" for r in runs]
    L.append(_row("pipeline wall time per trial (median), s", wall))
    if fails:
        L += ["", "Trials that failed (left out of the pooled rows above):", "", *fails]
    return L + [""]


def markdown(res: dict[str, Any]) -> str:
    """The report: simulated (rigid, artefacts), real walk, rig."""
    L = [
        "# Norm form against the aligned 3-D form of the joint constraint",
        "",
        "On the same data (benchmarks/aligned_form.py; lowerlimb.calibration.aligned_form): `norm` "
        '= every centre from the norm form (`hip_in_pelvis_form="norm"`); `default` = the norm '
        "form with the hip centre in the pelvis sensor from the aligned form, given the norm "
        "form's hip in the thigh sensor (`CalibrationOptions()`); `aligned` = "
        '`centre_form="aligned"`. Simulated: seeds '
        f"{', '.join(map(str, res['seeds']))}, {res['duration_s']:g} s, scored as gait.md.",
        "",
        "## Simulated seven-IMU walks",
        "",
    ]
    L += _sim_lines("Rigid sensors", res["rigid"])
    L += _sim_lines("With the real-walk artefacts", res["artefacts"])
    if res.get("one_leg"):
        L += [
            "## One-leg simulated motions (`simulate`, 60 s, seeds 0 and 1)",
            "",
            "Thigh / shank length error, hip in the pelvis sensor, hip in the thigh sensor (mm):",
            "",
            f"| motion | seed | {_HEAD} |",
            "|---" + _RULE,
        ]
        for row in res["one_leg"]:
            cells = []
            for form in FORMS:
                r = row[form]
                e = r["length_err_mm"]
                cells.append(
                    f"{e[0]:+.1f} / {e[1]:+.1f}, {r['hip_in_pelvis_mm']:.1f}, {r['hip_in_thigh_mm']:.1f}"
                )
            L.append(f"| {row['motion']} | {row['seed']} | " + " | ".join(cells) + " |")
        L += [""]
    if res.get("real"):
        L += ["## Real walk (gait/, against Vicon Plug-in Gait)", "", f"| quantity | {_HEAD} |", _RULE]
        runs = [res["real"][form] for form in FORMS]
        for side in ("left", "right"):
            for key in ("thigh_err_mm", "shank_err_mm", "knee_flexion_rmse_deg"):
                if key in runs[0]["legs"][side]:
                    L.append(_row(f"{side} {key}", [f"{r['legs'][side][key]:+.1f}" for r in runs]))
        L.append(_row("hip spacing error, mm", [f"{r['hip_spacing_err_mm']:+.1f}" for r in runs]))
        for key in ("stride_length_err_pct", "step_width_err_mm"):
            if runs[0].get(key, {}).get("n"):
                L.append(_row(f"{key} (median abs / worst abs / bias)", [_cell(r[key]) for r in runs]))
        L += [""]
        sens = res["real"].get("cap_sensitivity", {})
        if sens:
            L += [
                "Segment length errors against Vicon, mm (left thigh / shank, right thigh / shank), "
                "with the rigid-band cap at its default and widened:",
                "",
                "| form × cap | left thigh | left shank | right thigh | right shank |",
                "|---|---|---|---|---|",
            ]
            for key, legs in sens.items():
                cells = [
                    f"{legs[s][k]:+.0f}" for s in ("left", "right") for k in ("thigh_err_mm", "shank_err_mm")
                ]
                L.append(f"| {key} | " + " | ".join(cells) + " |")
            L += [""]
    if res.get("ring"):
        opt = res["ring"][0]["seg4_optical_mm"]
        L += [
            f"## RING chain (ring/, real IMUs, 40 Hz; foam-mounted in `nonrigid`): seg4's joint-to-joint "
            f"length (optical {opt:.1f} mm) and the ball joint's centre error (IMU1 / IMU2)",
            "",
            "| recording | cut-off | seg4 norm | seg4 aligned | ball norm | ball aligned |",
            "|---|---|---|---|---|---|",
        ]
        for row in res["ring"]:
            fc = "adaptive" if row["cutoff_hz"] is None else f"{row['cutoff_hz']:g} Hz"
            sn, sa = (row["seg4_mm"][f] for f in PURE_FORMS)
            bn, ba = (" / ".join(f"{v:.0f}" for v in row["ball_err_mm"][f]) for f in PURE_FORMS)
            L.append(f"| {row['recording']} | {fc} | {sn:.1f} | {sa:.1f} | {bn} | {ba} |")
        L += [""]
    if res.get("rig"):
        L += ["## Rig (rig/, exact centres): centre error sensor 1 / sensor 2, mm", ""]
        L += ["| trial | norm | aligned |", "|---|---|---|"]
        for row in res["rig"]:
            n_, a_ = (" / ".join(f"{v:.1f}" for v in row[k]) for k in ("norm_mm", "aligned_mm"))
            L.append(f"| {row['trial']} | {n_} | {a_} |")
        L += [""]
    return "\n".join(L)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_walk_arguments(ap)
    args = ap.parse_args()
    res: dict[str, Any] = {"seeds": args.seeds, "duration_s": args.duration}
    res["rigid"] = simulated(args.seeds, args.duration, None)
    res["artefacts"] = simulated(args.seeds, args.duration, Artefacts.real_walk())
    res["one_leg"] = one_leg(args.duration)
    if (args.data / "gait").is_dir():
        res["real"] = real_walk(args.data)
    if (args.data / "ring").is_dir():
        res["ring"] = ring_chain(args.data)
    if (args.data / "rig").is_dir():
        res["rig"] = rig(args.data)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "aligned_form.json").write_text(json.dumps(res, indent=1, default=float))
    (args.out / "aligned_form.md").write_text(markdown(res))
    print(markdown(res))


if __name__ == "__main__":
    main()
