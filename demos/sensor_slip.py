"""What does a 3 cm sensor slip do to my knee angle, with and without re-calibration?"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import demo_output, demo_parser, markdown_table, publish

from lowerlimb.conventions import SENSORS, FloatArray, rot_y, rot_z
from lowerlimb.model.calibrated import calibrated_geometry, chain_positions
from lowerlimb.model.geometry import LegGeometry
from lowerlimb.model.leg_model import LegModel
from lowerlimb.pipeline import TrialResult, process_trial
from lowerlimb.segments.angles import compute_joint_angles
from lowerlimb.segments.heading import correct_headings
from lowerlimb.segments.tracking import MAG_HEADING_WEIGHT, track_segments
from lowerlimb.simulation import ImuNoise, Simulation, simulate

#: Angle columns reported (angles.csv index, label).
REPORTED = ((3, "knee flexion"), (4, "knee add."), (5, "knee rot."), (6, "ankle dorsiflexion"))


def slipped(
    geometry: LegGeometry, sensor: str, slide_m: float, twist_deg: float, tilt_deg: float
) -> LegGeometry:
    """The leg with ``sensor`` slid down its segment, twisted about the long axis (y), tilted about z."""
    geo = geometry.copy()
    T = geo.sensor_placements[sensor].copy()
    T[:3, :3] = rot_z(np.deg2rad(tilt_deg)) @ rot_y(np.deg2rad(twist_deg)) @ T[:3, :3]
    T[1, 3] -= slide_m  # segment y is superior: down the limb
    geo.sensor_placements[sensor] = T
    return geo


def with_old_calibration(
    old: TrialResult, new: TrialResult, *, new_reference: bool
) -> tuple[FloatArray, FloatArray]:
    """Angles (N, 9) and positions (N, 6) of ``new``'s trial using ``old``'s joint calibration.

    The orientation filters and the gyro bias of the still start belong to the
    new recording (they do not depend on the calibration). With
    ``new_reference`` the segment frames are rebuilt from the new trial's
    standing start (the subject stood still again after the slip); without
    it the old segment frames are kept too (the sensor slipped mid-recording).
    """
    trial = new.trial
    calib = old.calibration
    gyr = {s: trial.gyr[s] - new.calibration.gyro_bias.get(s, np.zeros(3)) for s in SENSORS}
    weight = MAG_HEADING_WEIGHT if new.used_mag else 0.0
    if new_reference:
        motion = track_segments(
            new.quat_wxyz,
            trial.acc,
            gyr,
            calib,
            rate_hz=trial.rate_hz,
            reference=trial.reference_samples(),
            side=trial.side,
            shared_heading=new.used_mag,
        )
        model = LegModel(calibrated_geometry(calib, motion.frames))
        return motion.angles_rad, chain_positions(model, motion.angles_rad)
    frames = old.motion.frames
    qc, _ = correct_headings(
        new.quat_wxyz,
        trial.acc,
        gyr,
        calib,
        trial.rate_hz,
        R_sensor_segment=frames.R_sensor_segment,
        common_heading_weight=weight,
    )
    angles = np.asarray(compute_joint_angles(frames.segment_quaternions(qc), trial.side))
    return angles, chain_positions(old.model, angles)


def errors(angles: FloatArray, positions: FloatArray, sim: Simulation) -> list[float]:
    """Angle RMSE (deg) of the reported columns, then the pelvis-to-foot RMSE (mm)."""
    rmse = np.rad2deg(np.sqrt(np.mean((angles - sim.angles_rad) ** 2, axis=0)))
    p2f = 1e3 * np.sqrt(np.mean(np.sum((positions[:, :3] - sim.positions_m[:, :3]) ** 2, axis=1)))
    return [float(rmse[k]) for k, _ in REPORTED] + [float(p2f)]


def plot(
    path: Path, sims: dict[str, Simulation], curves: dict[str, dict[str, FloatArray]], sensor: str
) -> None:
    """Knee angles over four seconds of each slipped walk: truth and every calibration."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, len(sims), figsize=(6 * len(sims), 7.5), sharex="col", squeeze=False)
    for col, (slip, sim) in enumerate(sims.items()):
        t = sim.trial.time_s
        window = (t >= 0.5 * t[-1] - 2.0) & (t <= 0.5 * t[-1] + 2.0)
        for ax, (k, name) in zip(axes[:, col], REPORTED[:3], strict=True):
            ax.plot(t[window], np.rad2deg(sim.angles_rad[window, k]), "k-", lw=2.0, label="truth")
            for (label, angles), style in zip(curves[slip].items(), ("--", ":", "-."), strict=False):
                ax.plot(t[window], np.rad2deg(angles[window, k]), style, lw=1.3, label=label)
            ax.set_ylabel(f"{name} (deg)")
            ax.grid(alpha=0.3)
        axes[0, col].set_title(f"{sensor} IMU: {slip}", fontsize=10)
        axes[-1, col].set_xlabel("time (s)")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> dict[str, list[float]]:
    parser = demo_parser(__doc__, "20 s walks instead of 60 s", Path(__file__).parent / "output")
    parser.add_argument("--sensor", choices=("shank", "thigh"), default="shank")
    parser.add_argument("--slide-cm", type=float, default=3.0, help="slip down the segment, cm")
    parser.add_argument(
        "--twist-deg", type=float, default=10.0, help="rotation about the segment's long axis"
    )
    parser.add_argument(
        "--tilt-deg", type=float, default=10.0, help="rotation about the segment's flexion axis"
    )
    parser.add_argument("--seed", type=int, default=4)
    args = parser.parse_args(argv)
    out = demo_output(args, "sensor_slip")
    t0 = time.perf_counter()

    duration = 20.0 if args.quick else 60.0
    before = simulate("walk", duration, args.seed, noise=ImuNoise())
    old = process_trial(before.trial)
    slide = args.slide_cm
    slips = {
        f"{slide:g} cm slide": (slide, 0.0, 0.0),
        f"{slide:g} cm slide + {args.twist_deg:g}° twist": (slide, args.twist_deg, 0.0),
        f"{slide:g} cm slide + {args.tilt_deg:g}° tilt": (slide, 0.0, args.tilt_deg),
    }
    results = {"no slip: own calibration": errors(old.angles_rad, old.positions_m, before)}
    rows = [["no slip", "own calibration", *(f"{v:.1f}" for v in results["no slip: own calibration"])]]
    plotted: dict[str, Simulation] = {}
    curves: dict[str, dict[str, FloatArray]] = {}
    for slip, (slide_cm, twist, tilt) in slips.items():
        geometry = slipped(before.model.geometry, args.sensor, 0.01 * slide_cm, twist, tilt)
        # a later walk of the same subject with the slipped sensor (the same walk for every slip)
        after = simulate("walk", duration, args.seed + 100, noise=ImuNoise(), geometry=geometry)
        new = process_trial(after.trial)
        cases = {
            "old calibration": with_old_calibration(old, new, new_reference=False),
            "old calibration, new standing reference": with_old_calibration(old, new, new_reference=True),
            "re-calibrated": (new.angles_rad, new.positions_m),
        }
        for name, (angles, positions) in cases.items():
            results[f"{slip}: {name}"] = e = errors(angles, positions, after)
            rows.append([slip, name, *(f"{v:.1f}" for v in e)])
        if twist or tilt:
            plotted[slip] = after
            curves[slip] = {name: angles for name, (angles, _) in cases.items()}
    header = ["slip", "calibration", *(f"{label} RMSE deg" for _, label in REPORTED), "pelvis-to-foot mm"]
    table = "\n".join(
        [
            f"# A {slide:g} cm {args.sensor} sensor slip: old calibration vs re-calibration",
            "",
            f"{duration:g} s walks, realistic noise. The {args.sensor} IMU slides {slide:g} cm down the "
            f"segment: alone, with a {args.twist_deg:g}° twist about the segment's long axis, or with a "
            f"{args.tilt_deg:g}° tilt about its flexion axis; a later walk is recorded with it. "
            "'old calibration': the joint calibration and segment frames of the walk before the slip (the "
            "sensor slipped mid-session). 'new standing reference': the old joint calibration, segment "
            "frames rebuilt from the new walk's standing start. 're-calibrated': the new walk calibrated "
            "on its own.",
            "",
            markdown_table(header, rows),
            "",
            f"runtime {time.perf_counter() - t0:.1f} s",
            "",
        ]
    )
    plot(out / "sensor_slip.png", plotted, curves, args.sensor)
    publish(out, "sensor_slip", table)
    return results


if __name__ == "__main__":
    main()
