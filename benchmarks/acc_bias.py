"""Accelerometer bias: how far a constant offset of each accelerometer moves the calibrated leg.

The simulator's noise had no accelerometer bias, but real sensors have one: the real walk's
Xsens MTw read 9.83–9.95 m/s² at rest (local gravity about 9.80), and consumer MEMS parts are
specified at 0.2–0.6 m/s². A constant bias enters the joint constraint (Hu et al. 2021 eq. 3)
beside the centripetal term ``ω×(ω×c)``, which for a slowly turning thigh is small, so the
fitted centre moves by about ``b / ω²``.

Two sources, each with biases of a given norm in a random direction per sensor:

* the real walk (``gait/``, seven Xsens MTw, against Vicon Plug-in Gait), seeds 0–3 of the
  added biases, on top of whatever bias the sensors already have;
* seven-IMU simulated walks (``simulate_bilateral``, seeds 201–203, 60 s) with
  ``ImuNoise(acc_bias_mps2=…)``, against the simulator's truth.

Each is calibrated twice: as by default, and with ``rest_gravity_correction=True``, where the
joint fits take each accelerometer's offset at the standing start off along its standing
vertical (the one component a standing start shows; :mod:`lowerlimb.calibration.rest_gravity`).

    python benchmarks/acc_bias.py --data ../shared/data --out benchmarks/results
"""

from __future__ import annotations

import importlib.util
import sys
import warnings
from dataclasses import replace
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from lowerlimb.bilateral.process import process_bilateral_trial
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import SIDES
from lowerlimb.io import load_xsens
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.simulation import ImuNoise, simulate_bilateral

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _realwalk import IDS, load_vicon, raw_dir  # noqa: E402
from _results import real_data_main  # noqa: E402

#: Norms of the added biases, m/s².
BIASES_MPS2 = (0.0, 0.05, 0.1, 0.2)
REAL_SEEDS = (0, 1, 2, 3)
SIM_SEEDS = (201, 202, 203)


def _module(name: str) -> ModuleType:
    path = Path(__file__).resolve().parent / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"{name}_for_acc_bias", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def with_bias(trial: BilateralTrial, norm_mps2: float, seed: int) -> BilateralTrial:
    """The trial with a constant bias of the given norm, random direction, on every accelerometer."""
    if not norm_mps2:
        return trial
    rng = np.random.default_rng(seed)
    acc = {}
    for s, a in trial.acc.items():
        d = rng.normal(size=3)
        acc[s] = a + norm_mps2 * d / np.linalg.norm(d)
    return replace(trial, acc=acc)


#: The two ways of calibrating: the default, and with the rest offsets removed.
VARIANTS: tuple[tuple[str, CalibrationOptions], ...] = (
    ("default", CalibrationOptions()),
    ("rest offsets removed", CalibrationOptions(rest_gravity_correction=True)),
)


def _process(trial: BilateralTrial, options: CalibrationOptions) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return process_bilateral_trial(trial, calibration_options=options)


def _real_rows(data: Path) -> list[dict[str, Any]]:
    bg = _module("bilateral_gait")
    ge = bg._gait_events_module()
    vicon = load_vicon(data)
    rec = load_xsens(raw_dir(data), IDS)
    base = BilateralTrial(rec.time_s, rec.acc, rec.gyr, rec.mag)
    rows = []
    for norm in BIASES_MPS2:
        for seed in REAL_SEEDS if norm else (0,):
            biased = with_bias(base, norm, seed)
            for variant, options in VARIANTS:
                res = _process(biased, options)
                legs = bg.score_legs(res, vicon)
                strides = bg.score_strides(res, vicon, ge)
                rows.append(
                    {
                        "bias_mps2": norm,
                        "seed": seed,
                        "variant": variant,
                        "length_err_mm": {
                            s: [legs[s]["thigh_err_mm"], legs[s]["shank_err_mm"]] for s in SIDES
                        },
                        "knee_flexion_rmse_deg": {s: legs[s]["knee_flexion_rmse_deg"] for s in SIDES},
                        "step_width_median_mm": strides["step_width_err_mm"].get("median_abs"),
                        "stride_length_median_pct": strides["stride_length_err_pct"].get("median_abs"),
                    }
                )
    return rows


def _sim_rows() -> list[dict[str, Any]]:
    gait = _module("gait")
    rows = []
    for norm in BIASES_MPS2:
        for seed in SIM_SEEDS:
            sim = simulate_bilateral(60.0, seed, noise=ImuNoise(acc_bias_mps2=norm))
            for variant, options in VARIANTS:
                res = _process(sim.trial, options)
                le = gait._length_errors(res, sim.truth)
                rows.append(
                    {
                        "bias_mps2": norm,
                        "seed": seed,
                        "variant": variant,
                        "length_err_mm": {
                            s: [le[gait.LENGTH_LABELS[0]][i], le[gait.LENGTH_LABELS[1]][i]]
                            for i, s in enumerate(SIDES)
                        },
                    }
                )
    return rows


def run(data: Path) -> dict[str, Any]:
    """Both sources, every bias norm and seed, with and without the rest-offset removal."""
    return {"biases_mps2": BIASES_MPS2, "real": _real_rows(data), "simulated": _sim_rows()}


def _spread(rows: list[dict[str, Any]], side: str, k: int) -> str:
    v = np.array([r["length_err_mm"][side][k] for r in rows])
    return f"{np.median(v):+.0f} ({v.min():+.0f} … {v.max():+.0f})" if v.size > 1 else f"{v[0]:+.0f}"


def markdown(res: dict[str, Any]) -> str:
    """Signed thigh / shank length errors, median (range) over the bias seeds."""
    lines = [
        "# Accelerometer bias: how far it moves the calibrated leg",
        "",
        "Each accelerometer gets a constant bias of the given norm in a random direction "
        f"(real walk: seeds {', '.join(map(str, REAL_SEEDS))} of the added biases, on top of the "
        f"sensors' own; simulated seven-IMU walks {', '.join(map(str, SIM_SEEDS))}, 60 s, "
        "`ImuNoise(acc_bias_mps2=…)`). Signed length error (hip or ankle centre to the knee "
        "axis), mm: median (range). *rest offsets removed*: "
        "`CalibrationOptions(rest_gravity_correction=True)`, the joint fits take each "
        "accelerometer's offset at the standing start off along its standing vertical "
        "(`benchmarks/acc_bias.py`).",
        "",
    ]
    for source, ref in (("real", "Vicon Plug-in Gait"), ("simulated", "the simulator's truth")):
        lines += [
            f"## {source.capitalize()} walk, against {ref}",
            "",
            "| bias m/s² | variant | left thigh | right thigh | left shank | right shank |"
            + (" step width mm (median) |" if source == "real" else ""),
            "|---|---|---|---|---|---|" + ("---|" if source == "real" else ""),
        ]
        for norm in res["biases_mps2"]:
            for variant, _ in VARIANTS:
                rows = [r for r in res[source] if r["bias_mps2"] == norm and r["variant"] == variant]
                cells = [_spread(rows, s, k) for k in (0, 1) for s in SIDES]
                extra = ""
                if source == "real":
                    sw = np.array([r["step_width_median_mm"] for r in rows], dtype=float)
                    extra = f" {np.median(sw):.0f} ({sw.min():.0f} … {sw.max():.0f}) |"
                lines.append(f"| {norm:g} | {variant} | " + " | ".join(cells) + " |" + extra)
        lines.append("")
    return "\n".join(lines)


def main() -> None:
    real_data_main(__doc__, "acc_bias", run, markdown)


if __name__ == "__main__":
    main()
