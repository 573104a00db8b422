"""Are the calibrated URDF's joint torques usable? Swing-phase hip and knee torques vs the true model."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pinocchio as pin
from _common import demo_output, demo_parser, markdown_table, publish
from scipy.interpolate import make_interp_spline
from scipy.signal import butter, find_peaks, sosfiltfilt

from lowerlimb.conventions import FloatArray, quat_to_matrix
from lowerlimb.model.leg_model import DOF_NAMES
from lowerlimb.pipeline import process_trial
from lowerlimb.simulation import ImuNoise, Simulation, simulate

#: Goal: hip and knee flexion torque RMSE in swing, % of the peak true swing torque.
GOAL_PERCENT = 5.0
#: Low-pass cut-off applied to the estimated angles before differentiating them, Hz.
ANGLE_CUTOFF_HZ = 6.0


def swing_mask(angles_rad: FloatArray, rate_hz: float) -> FloatArray:
    """Swing samples of the simulated gait, from the true joint angles.

    The simulator has no ground contact, so swing is defined from the gait
    cycle: it starts when the knee flexes through 30° on its way to the swing
    peak (toe-off, ≈ 61 % of this simulator's cycle) and ends at the next
    maximum of hip flexion (heel strike, 100 %). Only cycles whose knee peak
    exceeds 40° count (the loading-response bump stays below 25°).
    """
    knee = np.rad2deg(angles_rad[:, 3])
    hip = np.rad2deg(angles_rad[:, 0])
    peaks, _ = find_peaks(knee, height=40.0, distance=int(0.6 * rate_hz))
    mask = np.zeros(knee.shape[0], dtype=bool)
    if len(peaks) < 2:
        return mask
    stride = int(np.median(np.diff(peaks)))
    for p in peaks:
        start = p
        while start > 0 and knee[start - 1] >= 30.0:
            start -= 1
        stop = p + int(0.6 * stride)
        if start == 0 or stop >= knee.shape[0]:
            continue  # incomplete swing at either end of the trial
        end = p + int(np.argmax(hip[p:stop]))
        mask[start : end + 1] = True
    return mask


def spline_derivatives(t: FloatArray, x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """First and second time derivatives of sampled signals (N, k) by quintic interpolation."""
    spline = make_interp_spline(t, x, k=5)
    return spline.derivative(1)(t), spline.derivative(2)(t)


def root_motion(model: pin.Model, sim: Simulation) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Free-flyer q (N, 7), v (N, 6), a (N, 6) that move ``model``'s pelvis IMU as the true pelvis IMU moved.

    Both models are driven by the same physical motion (the pelvis sensor's
    true pose and its clean gyro), each through its own pelvis-to-sensor
    placement.
    """
    t = sim.trial.time_s
    T_pelvis_sensor = model.frames[model.getFrameId("imu_pelvis")].placement
    R_ps, p_ps = T_pelvis_sensor.rotation, T_pelvis_sensor.translation
    R_ws = quat_to_matrix(sim.quat_wxyz["pelvis"])  # (N, 3, 3) sensor -> world
    R_wp = R_ws @ R_ps.T
    p = sim.sensor_pos_m["pelvis"] - R_wp @ p_ps
    p_dot, p_ddot = spline_derivatives(t, p)
    omega = sim.clean.gyr["pelvis"] @ R_ps.T  # pelvis angular velocity in the pelvis frame
    omega_dot, _ = spline_derivatives(t, omega)
    n = t.shape[0]
    q, v, a = np.empty((n, 7)), np.empty((n, 6)), np.empty((n, 6))
    for k in range(n):
        q[k, :3] = p[k]
        q[k, 3:] = pin.Quaternion(R_wp[k]).coeffs()  # x, y, z, w
        v_lin = R_wp[k].T @ p_dot[k]
        v[k] = np.concatenate([v_lin, omega[k]])
        a[k] = np.concatenate([R_wp[k].T @ p_ddot[k] - np.cross(omega[k], v_lin), omega_dot[k]])
    return q, v, a


def flexion_torques(
    model: pin.Model,
    root: tuple[FloatArray, FloatArray, FloatArray],
    angles_rad: FloatArray,
    angles_dot: FloatArray,
    angles_ddot: FloatArray,
) -> FloatArray:
    """Hip and knee flexion torques (N, 2), N·m, by RNEA (no external forces: swing only)."""
    data = model.createData()
    names = ("hip_flexion", "knee_flexion")
    dof_q = [model.joints[model.getJointId(n)].idx_q for n in DOF_NAMES]
    dof_v = [model.joints[model.getJointId(n)].idx_v for n in DOF_NAMES]
    out_v = [model.joints[model.getJointId(n)].idx_v for n in names]
    q_root, v_root, a_root = root
    out = np.empty((angles_rad.shape[0], 2))
    q, v, a = pin.neutral(model), np.zeros(model.nv), np.zeros(model.nv)
    for k in range(angles_rad.shape[0]):
        q[:7], v[:6], a[:6] = q_root[k], v_root[k], a_root[k]
        q[dof_q], v[dof_v], a[dof_v] = angles_rad[k], angles_dot[k], angles_ddot[k]
        tau = pin.rnea(model, data, q, v, a)
        out[k] = tau[out_v]
    return out


def lowpass(x: FloatArray, rate_hz: float, cutoff_hz: float = ANGLE_CUTOFF_HZ) -> FloatArray:
    sos = butter(4, cutoff_hz, fs=rate_hz, output="sos")
    return np.asarray(sosfiltfilt(sos, x, axis=0))


def plot(path: Path, t: FloatArray, swing: FloatArray, curves: dict[str, FloatArray], title: str) -> None:
    """Hip and knee flexion torques over three strides in the middle of the trial."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    window = (t >= 0.5 * t[-1] - 1.75) & (t <= 0.5 * t[-1] + 1.75)
    tw = t[window]
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for j, (ax, name) in enumerate(zip(axes, ("hip flexion", "knee flexion"), strict=True)):
        for (label, tau), style in zip(curves.items(), ("-", "--", ":", "-."), strict=False):
            ax.plot(tw, tau[window, j], style, lw=1.3, label=label)
        ax.fill_between(
            tw, 0, 1, where=swing[window], transform=ax.get_xaxis_transform(), color="0.9", zorder=0
        )
        ax.set_ylabel(f"{name} torque (N·m)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("time (s); shaded: swing")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = demo_parser(__doc__, "a 20 s walk instead of 60 s", Path(__file__).parent / "output")
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args(argv)
    out = demo_output(args, "inverse_dynamics")
    t0 = time.perf_counter()

    duration = 20.0 if args.quick else 60.0
    sim = simulate("walk", duration, args.seed, noise=ImuNoise.none())
    height, mass = float(sim.truth["height_m"]), float(sim.truth["mass_kg"])
    result = process_trial(sim.trial, height_m=height, mass_kg=mass)

    # both legs go through a URDF file and Pinocchio's URDF parser, free-flyer root
    (out / "true.urdf").write_text(sim.truth["urdf"], encoding="utf-8")
    result.model.write_urdf(out / "calibrated.urdf")
    true_m, cal_m = (
        pin.buildModelFromUrdf(str(out / f"{name}.urdf"), pin.JointModelFreeFlyer())
        for name in ("true", "calibrated")
    )

    t, rate = sim.trial.time_s, sim.trial.rate_hz
    swing = swing_mask(sim.angles_rad, rate)
    # true angles: the simulator's own quintic spline, so these derivatives are exact
    true_angles = (sim.angles_rad, *spline_derivatives(t, sim.angles_rad))
    est = lowpass(result.angles_rad, rate)

    tau_true = flexion_torques(true_m, root_motion(true_m, sim), *true_angles)
    root_cal = root_motion(cal_m, sim)
    cases = {
        "calibrated URDF, true angles": flexion_torques(cal_m, root_cal, *true_angles),
        f"calibrated URDF, estimated angles ({ANGLE_CUTOFF_HZ:g} Hz low-pass)": flexion_torques(
            cal_m, root_cal, est, *spline_derivatives(t, est)
        ),
    }
    peak = np.abs(tau_true[swing]).max(axis=0)
    results: dict[str, dict[str, float]] = {}
    rows = []
    for name, tau in cases.items():
        rmse = np.sqrt(np.mean((tau[swing] - tau_true[swing]) ** 2, axis=0))
        pct = 100.0 * rmse / peak
        results[name] = {"hip_percent": float(pct[0]), "knee_percent": float(pct[1])}
        ok = "yes" if pct.max() <= GOAL_PERCENT else "no"
        rows.append([name, f"{rmse[0]:.2f} ({pct[0]:.1f} %)", f"{rmse[1]:.2f} ({pct[1]:.1f} %)", ok])
    knee_err = np.rad2deg(np.sqrt(np.mean((result.angles_rad[swing, 3] - sim.angles_rad[swing, 3]) ** 2)))

    n_cycles = int(np.sum(np.diff(swing.astype(int)) == 1))
    header = ["model, angles", "hip flexion RMSE N·m (% peak)", "knee flexion RMSE N·m (% peak)"]
    table = "\n".join(
        [
            "# Inverse dynamics with the calibrated URDF (noise-free walk)",
            "",
            f"{duration:g} s walk, seed {args.seed}; both models {height:g} m, {mass:g} kg with de Leva "
            f"inertias, loaded from URDF by Pinocchio (free-flyer root) and driven by the true pelvis-IMU "
            f"motion; reference: the true model with the true angles. Swing: {n_cycles} phases, "
            f"{swing.sum()} samples (knee flexion rising through 30° → next hip-flexion maximum). Peak true "
            f"swing torque: hip {peak[0]:.1f} N·m, knee {peak[1]:.1f} N·m.",
            "",
            markdown_table([*header, f"≤ {GOAL_PERCENT:g} %"], rows),
            "",
            f"Estimated knee flexion RMSE in swing: {knee_err:.2f}°.",
            "",
            f"runtime {time.perf_counter() - t0:.1f} s",
            "",
        ]
    )
    plot(
        out / "inverse_dynamics.png",
        t,
        swing,
        {"true model, true angles": tau_true, **dict(list(cases.items())[:2])},
        "Swing-phase flexion torques: calibrated URDF vs the true leg",
    )
    publish(out, "inverse_dynamics", table)
    return results


if __name__ == "__main__":
    main()
