"""Joint calibration on a real 5-segment chain with known joint types (RING data, issue 3).

Data: ``DIR/ring`` (see ``../shared/data/README.md``; Bachhuber, Weygers,
Seel 2024, trial 1): seg1 free, seg2 on a spherical joint 0.2 m along seg1's
x axis, seg3/seg4/seg5 on hinges about x, y, z of their parent; every IMU
nominally 0.1 m along its segment's x axis and 0.035 m up, axes aligned with
the segment (true misalignment: a few degrees, not given). 40 Hz; "rigid"
IMUs and "nonrigid" ones on foam.

Checks, for both recordings and the methods given:

- hinge axes of seg2–seg3, seg3–seg4, seg4–seg5
  (:func:`~lowerlimb.calibration.calibrate_hinge_joint`): angle between the
  estimated axis and the nominal x / y / z in each IMU frame (unsigned: the
  sign convention of a mechanical hinge is arbitrary), and the distance of
  the estimated centre to the nominal axis line, mm;
- the seg1–seg2 spherical centre (:func:`~lowerlimb.calibration.calibrate_spherical_joint`)
  against the nominal geometry: (0.1, 0, −0.035) m in IMU1 and (−0.1, 0, −0.035) m in IMU2;
- RMS residuals, standard deviations and excitation warnings;
- an IMU-placement-free reference from the optical data (``trial1_omc.csv``):
  the hinge points of seg3–seg4 (about y) and seg4–seg5 (about z) fitted
  functionally from markers and segment orientations give the distance
  between seg4's two joints along its x axis; the IMU estimate of the same
  length is the difference of the x coordinates of the two hinge centres in
  IMU4's frame (x is observable for both hinges).

The "nominal" geometry of ``arm.xml`` is only the RING paper's prior: the
optical data put seg4's joints 0.27 m apart, not 0.2 m, so centre errors
against the nominal values mostly measure the prior, not the estimator.

Usage: ``python benchmarks/ring.py --data DIR [--methods casadi,gn] [--out benchmarks/results]``.
Writes ``ring.{md,json}`` into ``--out`` and prints the Markdown.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from lowerlimb.calibration import calibrate_hinge_joint, calibrate_spherical_joint  # noqa: E402
from lowerlimb.calibration.geometry import angle_between_deg, distance_to_line  # noqa: E402

RATE_HZ = 40.0
#: (parent segment, child segment, hinge axis index in both IMU frames)
HINGES = ((2, 3, 0), (3, 4, 1), (4, 5, 2))
#: Nominal joint point in the parent IMU frame and in the child IMU frame, m.
JOINT_IN_PARENT_IMU = np.array([0.1, 0.0, -0.035])
JOINT_IN_CHILD_IMU = np.array([-0.1, 0.0, -0.035])


def load_imu(path: Path) -> dict[int, dict[str, np.ndarray]]:
    """``{segment: {"acc": (N, 3), "gyr": (N, 3)}}`` from a RING IMU CSV (2 comment lines)."""
    data = np.genfromtxt(path, delimiter=",", names=True, skip_header=2)
    out: dict[int, dict[str, np.ndarray]] = {}
    for seg in range(1, 6):
        out[seg] = {k: np.stack([data[f"seg{seg}_{k}_{a}"] for a in "xyz"], axis=1) for k in ("acc", "gyr")}
    return out


def run(imu: dict[int, dict[str, np.ndarray]], method: str) -> dict[str, Any]:
    """All four joints of one recording with one method."""
    res: dict[str, Any] = {"hinges": [], "method": method}
    for p, c, k in HINGES:
        e = np.eye(3)[k]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            h = calibrate_hinge_joint(
                imu[p]["acc"], imu[p]["gyr"], imu[c]["acc"], imu[c]["gyr"],
                rate_hz=RATE_HZ, method=method, joint=f"seg{p}-seg{c}",
                parent_sensor=f"imu{p}", child_sensor=f"imu{c}",
            )  # fmt: skip
        res["hinges"].append(
            {
                "joint": f"seg{p}-seg{c}",
                "nominal_axis": "xyz"[k],
                "axis_in_parent": h.axis_in_parent_sensor.tolist(),
                "axis_in_child": h.axis_in_child_sensor.tolist(),
                "axis_err_parent_deg": angle_between_deg(h.axis_in_parent_sensor, e, unsigned=True),
                "axis_err_child_deg": angle_between_deg(h.axis_in_child_sensor, e, unsigned=True),
                "axis_std_deg": h.axis.axis_std_deg.tolist(),
                "center_in_parent": h.center_in_parent_sensor.tolist(),
                "center_in_child": h.center_in_child_sensor.tolist(),
                "center_line_parent_mm": 1000
                * distance_to_line(h.center_in_parent_sensor, JOINT_IN_PARENT_IMU, e),
                "center_line_child_mm": 1000
                * distance_to_line(h.center_in_child_sensor, JOINT_IN_CHILD_IMU, e),
                "rms_residual_axis_radps": h.axis.rms_residual,
                "sign_coherence": h.axis.sign_coherence.tolist(),
                "acc_sign_correlation": h.axis.acc_sign_correlation,
                "runtime_s": h.axis.solve_time_s + h.center.solve_time_s,
                "warnings": h.warnings,
            }
        )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = calibrate_spherical_joint(
            imu[1]["acc"], imu[1]["gyr"], imu[2]["acc"], imu[2]["gyr"],
            rate_hz=RATE_HZ, method=method, joint="seg1-seg2",
            parent_sensor="imu1", child_sensor="imu2",
        )  # fmt: skip
    res["spherical"] = {
        "center_in_parent": s.center_in_parent_sensor.tolist(),
        "center_in_child": s.center_in_child_sensor.tolist(),
        "err_parent_mm": 1000 * float(np.linalg.norm(s.center_in_parent_sensor - JOINT_IN_PARENT_IMU)),
        "err_child_mm": 1000 * float(np.linalg.norm(s.center_in_child_sensor - JOINT_IN_CHILD_IMU)),
        "std_parent_mm": (1000 * s.center_std_in_parent_sensor).tolist(),
        "std_child_mm": (1000 * s.center_std_in_child_sensor).tolist(),
        "rms_residual_mps2": s.rms_residual,
        "runtime_s": s.solve_time_s,
        "warnings": s.warnings,
    }
    return res


def omc_seg4_length(path: Path) -> float:
    """Distance between seg4's joints along seg4's x, m, from the optical markers and quaternions.

    For each hinge pair (3, 4) and (4, 5): least squares for the points ``x_P``
    and ``x_C`` (in the segments' optical frames, relative to one marker) with
    ``m_P + R_P x_P = m_C + R_C x_C`` over all valid frames; the coordinates
    along each hinge axis are unobservable, but x is observable for both.
    """
    from lowerlimb.conventions import quat_to_matrix

    d = np.genfromtxt(path, delimiter=",", names=True, skip_header=2)

    def frame(seg: int, marker: int) -> tuple[np.ndarray, np.ndarray]:
        q = np.stack([d[f"seg{seg}_quat_{a}"] for a in "wxyz"], axis=1)
        m = np.stack([d[f"seg{seg}_marker{marker}_{a}"] for a in "xyz"], axis=1)
        return quat_to_matrix(np.where(np.isfinite(q), q, 1.0)), m

    def hinge_point(p: tuple[int, int], c: tuple[int, int]) -> np.ndarray:
        (Rp, mp), (Rc, mc) = frame(*p), frame(*c)
        ok = np.isfinite(mp).all(1) & np.isfinite(mc).all(1)
        ok &= np.isfinite(d[f"seg{p[0]}_quat_w"]) & np.isfinite(d[f"seg{c[0]}_quat_w"])
        A = np.concatenate([Rp[ok], -Rc[ok]], axis=2).reshape(-1, 6)
        x = np.linalg.lstsq(A, (mc[ok] - mp[ok]).reshape(-1), rcond=None)[0]
        return np.asarray(x)

    x34 = hinge_point((3, 1), (4, 2))  # seg4 part relative to seg4 marker 2
    x45 = hinge_point((4, 2), (5, 4))
    return float(x45[0] - x34[3])


def _v(v: list[float], scale: float = 1.0, digits: int = 3) -> str:
    return "(" + ", ".join(f"{scale * x:.{digits}f}" for x in v) + ")"


def seg4_length_imu(r: dict[str, Any]) -> float:
    """seg4's joint-to-joint length along IMU4's x from the two hinge centres, m."""
    h34 = next(h for h in r["hinges"] if h["joint"] == "seg3-seg4")
    h45 = next(h for h in r["hinges"] if h["joint"] == "seg4-seg5")
    return float(h45["center_in_parent"][0] - h34["center_in_child"][0])


def to_markdown(results: dict[str, list[dict[str, Any]]], omc_length: float | None) -> str:
    """Markdown tables of :func:`run` results per recording."""
    md = ["## RING chain (real IMUs, 40 Hz): hinge axes and spherical centre vs nominal geometry\n"]
    md.append(
        "Hinge axes: angle to the nominal segment axis (unsigned), deg; centre: distance to the "
        "nominal axis line, mm. The true IMU misalignment is a few degrees and unknown, so "
        "errors of that size are expected.\n"
    )
    md.append(
        "| recording | method | hinge | axis | err parent ° | err child ° | std ° (p, c) | "
        "centre–line p / c mm | sign coh. | acc corr. | warnings |"
    )
    md.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for rec, runs in results.items():
        for r in runs:
            for h in r["hinges"]:
                md.append(
                    f"| {rec} | {r['method']} | {h['joint']} | {h['nominal_axis']} | "
                    f"{h['axis_err_parent_deg']:.2f} | {h['axis_err_child_deg']:.2f} | "
                    f"{h['axis_std_deg'][0]:.2f}, {h['axis_std_deg'][1]:.2f} | "
                    f"{h['center_line_parent_mm']:.1f} / {h['center_line_child_mm']:.1f} | "
                    f"{h['sign_coherence'][0]:.2f} vs {h['sign_coherence'][1]:.2f} | "
                    f"{h['acc_sign_correlation']:.2f} | {len(h['warnings'])} |"
                )
    md.append(
        "\nSpherical joint seg1–seg2, centre in each IMU frame (m); nominal "
        f"{_v(list(JOINT_IN_PARENT_IMU))} in IMU1 and {_v(list(JOINT_IN_CHILD_IMU))} in IMU2:\n"
    )
    md.append(
        "| recording | method | centre in IMU1 | err mm | centre in IMU2 | err mm | "
        "std IMU1 / IMU2 mm | RMS residual m/s² | warnings |"
    )
    md.append("|---|---|---|---|---|---|---|---|---|")
    for rec, runs in results.items():
        for r in runs:
            s = r["spherical"]
            md.append(
                f"| {rec} | {r['method']} | {_v(s['center_in_parent'])} | {s['err_parent_mm']:.0f} | "
                f"{_v(s['center_in_child'])} | {s['err_child_mm']:.0f} | "
                f"{_v(s['std_parent_mm'], digits=1)} / {_v(s['std_child_mm'], digits=1)} | "
                f"{s['rms_residual_mps2']:.2f} | {len(s['warnings'])} |"
            )
    if omc_length is not None:
        md.append(
            f"\nseg4 joint-to-joint length along x: optical reference {1000 * omc_length:.1f} mm "
            "(nominal arm.xml: 200 mm)\n"
        )
        md.append("| recording | method | from IMU hinge centres, mm | error, mm |")
        md.append("|---|---|---|---|")
        for rec, runs in results.items():
            for r in runs:
                length = seg4_length_imu(r)
                md.append(
                    f"| {rec} | {r['method']} | {1000 * length:.1f} | {1000 * (length - omc_length):+.1f} |"
                )
    warn = [w for runs in results.values() for r in runs for h in r["hinges"] for w in h["warnings"]]
    warn += [w for runs in results.values() for r in runs for w in r["spherical"]["warnings"]]
    if warn:
        md.append("\nWarnings:\n")
        md.extend(f"- {w}" for w in sorted(set(warn)))
    return "\n".join(md) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True, help="folder holding ring/ (e.g. ../shared/data)")
    ap.add_argument("--methods", default="casadi,gn,dwpso+casadi")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results"))
    args = ap.parse_args()
    ring = Path(args.data) / "ring"
    if not ring.is_dir():
        raise SystemExit(f"no ring/ folder in {args.data}; pass --data pointing at the data folder")
    results: dict[str, list[dict[str, Any]]] = {}
    for rec in ("rigid", "nonrigid"):
        imu = load_imu(ring / f"trial1_imu_{rec}.csv")
        results[rec] = [run(imu, m) for m in args.methods.split(",")]
    omc = ring / "trial1_omc.csv"
    omc_length = omc_seg4_length(omc) if omc.is_file() else None
    text = to_markdown(results, omc_length)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ring.md").write_text(text)
    (out / "ring.json").write_text(
        json.dumps({"omc_seg4_length_m": omc_length, "results": results}, indent=1)
    )
    print(text)


if __name__ == "__main__":
    main()
