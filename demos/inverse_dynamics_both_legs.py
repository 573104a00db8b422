"""Both legs in one z-up model: what are the hip, knee and ankle moments through double support?"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pinocchio as pin
from _common import demo_output, demo_parser, markdown_table, publish
from scipy.interpolate import make_interp_spline
from scipy.signal import find_peaks

from lowerlimb.conventions import FloatArray, quat_to_matrix
from lowerlimb.model.geometry import LegGeometry
from lowerlimb.model.leg_model import DOF_NAMES, LegModel
from lowerlimb.model.lower_body import LOWER_BODY_DOF_NAMES, R_BASE_PELVIS, LowerBodyGeometry
from lowerlimb.simulation import ImuNoise, Simulation, simulate
from lowerlimb.viz.gait_curves import symmetry_index_pct

#: The assumption of this demo: over double support the trailing foot's share of the body's ground
#: reaction falls linearly from 1 at the leading foot's initial contact to 0 at its own toe-off (the
#: "linear transfer"; cf. the smooth-transition assumption of Ren, Jones & Howard 2008, J. Biomech.
#: 41:2750). Each foot's force acts through its own ankle centre, the rest of the moment is shared in
#: the same ratio, so the two feet together balance the whole body exactly.
ASSUMPTION = (
    "ground reaction = the wrench that balances the whole body (RNEA of the floating base); over double "
    "support the trailing foot's share falls linearly from 1 at the other foot's initial contact to 0 at "
    "its own toe-off, each foot's force acting through its own ankle centre"
)
FLEXION = ("hip_flexion", "knee_flexion", "ankle_dorsiflexion")


def gait_events(angles_rad: FloatArray, rate_hz: float) -> tuple[FloatArray, FloatArray]:
    """Initial contacts (hip-flexion maxima) and toe-offs (knee flexion rising through 30°), samples."""
    hip, knee = np.rad2deg(angles_rad[:, 0]), np.rad2deg(angles_rad[:, 3])
    ic, _ = find_peaks(hip, distance=int(0.6 * rate_hz))
    peaks, _ = find_peaks(knee, height=40.0, distance=int(0.6 * rate_hz))
    to = []
    for p in peaks:
        start = p
        while start > 0 and knee[start - 1] >= 30.0:
            start -= 1
        if start > 0:
            to.append(start)
    return ic.astype(float), np.array(to, dtype=float)


def stance_share(n: int, events: dict[str, tuple[FloatArray, FloatArray]]) -> FloatArray:
    """(n, 2) share of the ground reaction carried by the left and right foot (the linear transfer)."""
    stance = np.zeros((n, 2), dtype=bool)
    for s, side in enumerate(("left", "right")):
        ic, to = events[side]
        for i in ic:
            later = to[to > i]
            if later.size:
                stance[int(i) : int(later[0]), s] = True
    share = stance.astype(float)
    both = np.flatnonzero(stance.all(axis=1))
    for k in both:
        # the leading foot is the one whose contact began last; the trailing one lifts off at its toe-off
        last_ic = [events[side][0][events[side][0] <= k].max() for side in ("left", "right")]
        lead = int(np.argmax(last_ic))
        trail = 1 - lead
        to_trail = events[("left", "right")[trail]][1]
        t_off = to_trail[to_trail > k].min()
        t_on = last_ic[lead]
        share[k, trail] = (t_off - k) / (t_off - t_on)
        share[k, lead] = 1.0 - share[k, trail]
    return share


def base_motion(sim: Simulation, T_pelvis_sensor: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Free-flyer q (N, 7), v (N, 6), a (N, 6) of the z-up base that moves the pelvis IMU as simulated."""
    t = sim.trial.time_s
    R_ps, p_ps = T_pelvis_sensor[:3, :3], T_pelvis_sensor[:3, 3]
    R_wp = quat_to_matrix(sim.quat_wxyz["pelvis"]) @ R_ps.T
    p = sim.sensor_pos_m["pelvis"] - R_wp @ p_ps
    R_wb = R_wp @ R_BASE_PELVIS.T
    spline = make_interp_spline(t, p, k=5)
    p_dot, p_ddot = spline.derivative(1)(t), spline.derivative(2)(t)
    omega = sim.clean.gyr["pelvis"] @ (R_BASE_PELVIS @ R_ps).T  # in the base frame
    omega_dot = make_interp_spline(t, omega, k=5).derivative(1)(t)
    n = t.shape[0]
    q, v, a = np.empty((n, 7)), np.empty((n, 6)), np.empty((n, 6))
    for k in range(n):
        q[k, :3], q[k, 3:] = p[k], pin.Quaternion(R_wb[k]).coeffs()
        v_lin = R_wb[k].T @ p_dot[k]
        v[k] = np.concatenate([v_lin, omega[k]])
        a[k] = np.concatenate([R_wb[k].T @ p_ddot[k] - np.cross(omega[k], v_lin), omega_dot[k]])
    return q, v, a


def net_moments(
    model: pin.Model,
    base: tuple[FloatArray, FloatArray, FloatArray],
    angles: tuple[FloatArray, ...],
    share: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Joint moments (N, 18) with the split ground reaction, and the base residual (N,) before/after, N."""
    data = model.createData()
    ankles = [model.getJointId(f"{side}_ankle_internal_rotation") for side in ("left", "right")]
    n = share.shape[0]
    tau_out, before, after = np.empty((n, 18)), np.empty(n), np.empty(n)
    q_ang, v_ang, a_ang = angles
    for k in range(n):
        q = np.concatenate([base[0][k], q_ang[k]])
        v = np.concatenate([base[1][k], v_ang[k]])
        a = np.concatenate([base[2][k], a_ang[k]])
        tau = pin.rnea(model, data, q, v, a)
        pin.forwardKinematics(model, data, q)  # rnea does not update data.oMi
        before[k] = np.linalg.norm(tau[:3])
        world = data.oMi[1].act(pin.Force(tau[:6]))  # the balancing wrench, world frame, about the origin
        F, M = world.linear, world.angular
        points = [data.oMi[j].translation for j in ankles]
        free = M - sum(share[k, s] * np.cross(points[s], F) for s in range(2))
        fext = [pin.Force.Zero() for _ in range(model.njoints)]
        for s, j in enumerate(ankles):
            if share[k, s] > 0.0:
                f = pin.Force(share[k, s] * F, share[k, s] * (np.cross(points[s], F) + free))
                fext[j] = data.oMi[j].actInv(f)
        tau = pin.rnea(model, data, q, v, a, fext)
        after[k] = np.linalg.norm(tau[:3])
        tau_out[k] = tau[6:]
    return tau_out, before, after


def standing_hip_torque(model: pin.Model) -> float:
    """Largest hip torque (N·m) of a standing pose under Pinocchio's default gravity."""
    zero = np.zeros(model.nv)
    tau = pin.rnea(model, model.createData(), pin.neutral(model), zero, zero)
    names = [model.names[i] for i in range(2, model.njoints)]
    return float(max(abs(tau[6 + i]) for i, n in enumerate(names) if "hip" in n))


def plot(path: Path, t: FloatArray, tau: FloatArray, share: FloatArray, mass: float) -> None:
    """Flexion moments of both legs over three strides, double support shaded, the left foot's share."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    window = (t >= 0.5 * t[-1] - 1.7) & (t <= 0.5 * t[-1] + 1.7)
    double = (share > 0.0).all(axis=1)
    fig, axes = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
    for ax, dof in zip(axes[:3], FLEXION, strict=True):
        for side, color in (("left", "#d62728"), ("right", "#1f77b4")):
            j = LOWER_BODY_DOF_NAMES.index(f"{side}_{dof}")
            ax.plot(t[window], tau[window, j] / mass, color=color, lw=1.3, label=side)
        ax.set_ylabel(f"{dof.replace('_', ' ')}\n(N·m/kg)", fontsize=9)
    axes[3].plot(t[window], share[window, 0], color="#d62728", label="left foot's share")
    axes[3].set_ylabel("share of GRF")
    for ax in axes:
        ax.fill_between(
            t[window], 0, 1, where=double[window], transform=ax.get_xaxis_transform(), color="0.9"
        )
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("time (s); shaded: double support")
    fig.suptitle("Net joint moments of both legs, linear ground-reaction transfer over double support")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = demo_parser(__doc__, "a 10 s walk instead of 30 s", Path(__file__).parent / "output")
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args(argv)
    out = demo_output(args, "inverse_dynamics_both_legs")
    t0 = time.perf_counter()

    duration = 10.0 if args.quick else 30.0
    sim = simulate("walk", duration, args.seed, noise=ImuNoise.none())
    height, mass = float(sim.truth["height_m"]), float(sim.truth["mass_kg"])
    left = sim.model.geometry.copy()  # the simulator's (left) leg is the left leg
    right = LegGeometry.from_anthropometry("right", height, mass)
    right.sensor_placements["pelvis"] = left.sensor_placements["pelvis"].copy()
    body = LowerBodyGeometry(left, right, height, mass)
    body.write_urdf(out / "lower_body.urdf")
    model = pin.buildModelFromUrdf(str(out / "lower_body.urdf"), pin.JointModelFreeFlyer())

    # the right leg walks the left leg's gait half a stride later (the simulator has one leg)
    t, rate = sim.trial.time_s, sim.trial.rate_hz
    ic, to = gait_events(sim.angles_rad, rate)
    shift = int(np.median(np.diff(ic))) // 2
    keep = np.arange(shift, t.shape[0])
    spline = make_interp_spline(t, sim.angles_rad, k=5)
    derivs = [spline(t), spline.derivative(1)(t), spline.derivative(2)(t)]
    angles = tuple(np.hstack([d[keep], d[keep - shift]]) for d in derivs)
    events = {"left": (ic - shift, to - shift), "right": (ic, to)}
    events = {s: (e[0][e[0] >= 0], e[1][e[1] >= 0]) for s, e in events.items()}
    share = stance_share(keep.shape[0], events)
    base = tuple(x[keep] for x in base_motion(sim, left.sensor_placements["pelvis"]))
    tau, before, after = net_moments(model, base, angles, share)  # type: ignore[arg-type]
    tk = t[keep]

    contact = share.sum(axis=1) > 0.0
    double = (share > 0.0).all(axis=1)
    phantom_before = standing_hip_torque(LegModel.from_template("left", height, mass).model)
    phantom_after = standing_hip_torque(
        pin.buildModelFromUrdf(str(out / "lower_body.urdf"), pin.JointModelFreeFlyer())
    )
    results = {
        "phantom_hip_torque_single_leg_isb_Nm": phantom_before,
        "phantom_hip_torque_lower_body_Nm": phantom_after,
        "base_residual_without_grf_N": float(before[contact].max()),
        "base_residual_with_grf_N": float(after[contact].max()),
        "double_support_pct": float(100.0 * double.mean()),
    }
    rows = []
    for dof in FLEXION:
        peaks = [
            np.abs(tau[:, LOWER_BODY_DOF_NAMES.index(f"{s}_{dof}")]).max() / mass for s in ("left", "right")
        ]
        si = symmetry_index_pct(*peaks)
        results[f"{dof}_si_pct"] = si
        results[f"{dof}_peak_left_Nm_per_kg"] = float(peaks[0])
        rows.append([dof.replace("_", " "), f"{peaks[0]:.2f}", f"{peaks[1]:.2f}", f"{si:.1f}"])
    table = "\n".join(
        [
            "# Inverse dynamics of both legs through double support",
            "",
            f"{duration:g} s simulated walk (seed {args.seed}), {height:g} m, {mass:g} kg; one lower-body "
            "URDF "
            f"(REP 103 z-up base, pelvis, lumped upper body, both legs; {len(DOF_NAMES) * 2} clinical DOFs), "
            "Pinocchio free flyer under its default gravity. The simulator has one leg: the right leg walks "
            "the left leg's gait half a stride later. Events: initial contact at hip-flexion maxima, toe-off "
            f"where knee flexion rises through 30°; double support {results['double_support_pct']:.1f} % of "
            "the samples.",
            "",
            f"**Assumption:** {ASSUMPTION}.",
            "",
            markdown_table(
                ["check", "value"],
                [
                    [
                        "standing, default gravity: largest hip torque, single-leg ISB y-up model",
                        f"{phantom_before:.1f} N·m",
                    ],
                    [
                        "standing, default gravity: largest hip torque, lower-body z-up model",
                        f"{phantom_after:.2f} N·m",
                    ],
                    [
                        "base force to balance, no ground reaction (max in contact)",
                        f"{before[contact].max():.0f} N",
                    ],
                    ["base residual force with the split ground reaction", f"{after[contact].max():.1e} N"],
                ],
            ),
            "",
            markdown_table(["peak net moment (N·m/kg)", "left", "right", "SI (%)"], rows),
            "",
            "The simulated pelvis motion is kinematic: it is not the motion of a body whose feet push on the "
            "ground, so these moments show the method, not normative values.",
            "",
            f"runtime {time.perf_counter() - t0:.1f} s",
            "",
        ]
    )
    plot(out / "inverse_dynamics_both_legs.png", tk, tau, share, mass)
    publish(out, "inverse_dynamics_both_legs", table)
    return results


if __name__ == "__main__":
    main()
