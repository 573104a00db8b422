"""How well does lowerlimb recover a simulated walk? Calibration errors, angle and position RMSE."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import demo_output, demo_parser, markdown_table, publish

from lowerlimb.demo import angle_rmse_deg, compare_with_truth
from lowerlimb.pipeline import process_trial
from lowerlimb.simulation import ImuNoise, simulate
from lowerlimb.viz.plots import plot_angles


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = demo_parser(__doc__, "a 20 s walk instead of 60 s", Path(__file__).parent / "output")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--method", default="casadi", help="calibration method (casadi, gn, dwpso, gwo…)")
    args = parser.parse_args(argv)
    out = demo_output(args, "calibrate_walk")
    t0 = time.perf_counter()

    duration = 20.0 if args.quick else 60.0
    sim = simulate("walk", duration, args.seed, noise=ImuNoise())  # realistic noise and gyro bias
    result = process_trial(sim.trial, method=args.method)
    errors = compare_with_truth(result.calibration_dict(), sim.truth)
    angles = angle_rmse_deg(result.angles_rad, sim.angles_rad)

    calib_rows = []
    for joint, row in errors.items():
        if joint == "knee":
            centre = f"{row['parent_line_mm']:.1f} / {row['child_line_mm']:.1f} (to the axis line)"
            axis = f"{row['axis_deg']:.2f}"
        else:
            centre, axis = f"{row['parent_mm']:.1f} / {row['child_mm']:.1f}", "–"
        calib_rows.append([joint, centre, axis])
    angle_rows = [
        [joint, *(f"{angles[f'{joint}_{dof}']:.2f}" for dof in dofs)]
        for joint, dofs in (
            ("hip", ("flexion", "adduction", "internal_rotation")),
            ("knee", ("flexion", "adduction", "internal_rotation")),
            ("ankle", ("dorsiflexion", "inversion", "internal_rotation")),
        )
    ]
    err = result.positions_m - sim.positions_m
    p2f = 1e3 * float(np.sqrt(np.mean(np.sum(err[:, :3] ** 2, axis=1))))
    h2a = 1e3 * float(np.sqrt(np.mean(np.sum(err[:, 3:] ** 2, axis=1))))
    runtime = time.perf_counter() - t0

    table = "\n".join(
        [
            "# A simulated walk, calibrated by lowerlimb, against the truth",
            "",
            f"{duration:g} s walk, seed {args.seed}, realistic IMU noise and gyro bias, 9-axis Mahony "
            f"filter, calibration method {args.method} "
            f"(joint calibration {result.calibration.runtime_s:.2f} s).",
            "",
            markdown_table(
                ["joint", "centre error in parent / child sensor (mm)", "knee axis error (deg)"], calib_rows
            ),
            "",
            markdown_table(["joint angle RMSE (deg)", "flexion", "ad/abduction", "rotation"], angle_rows),
            "",
            f"Position RMSE (3-D): pelvis-to-foot sensor {p2f:.1f} mm, hip-to-ankle centre {h2a:.1f} mm.",
            "",
            f"runtime {runtime:.1f} s",
            "",
        ]
    )
    plot_angles(
        out / "calibrate_walk.png",
        sim.trial.time_s,
        {"truth": sim.angles_rad, "lowerlimb": result.angles_rad},
        f"Simulated {duration:g} s walk: ISB joint angles, estimated vs true",
    )
    publish(out, "calibrate_walk", table)
    return {**angles, "pelvis_to_foot_mm": p2f, "hip_to_ankle_mm": h2a}


if __name__ == "__main__":
    main()
