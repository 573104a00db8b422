"""Inverse kinematics of one simulated leg: the joint angles that put the foot where it is planned.

Given the pelvis pose (the root coordinates) and the foot segment's pose in the world,
a leg with a spherical hip, a hinge knee and a spherical ankle has one free
coordinate left, the swivel of the knee about the hip–ankle line; it is fixed by
prescribing the hip internal rotation. The knee flexion follows from the hip–ankle
distance (law of cosines), and the five remaining angles (hip flexion and adduction,
the three ankle angles) solve the six equations of the foot pose in the least-squares
sense, by Gauss–Newton on the SE(3) log error (the closed-loop IK of Pinocchio's
documentation, ``log6`` and ``Jlog6``) with a bounded step, warm-started from the
previous sample. The knee's adduction stays zero; its internal rotation is zero (a hinge) or
coupled to its flexion (``knee_rotation_per_flexion``: the tibia turns inwards as the knee
flexes, as a real knee does), about the shank's long axis, which holds the ankle centre, so
the knee flexion's law of cosines stays exact.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..conventions import FloatArray
from ..model.leg_model import DOF_NAMES, LegModel

__all__ = ["IKError", "solve_leg"]

#: Leg coordinates solved for (indices into the 9 leg DOFs): hip flexion, hip adduction, ankle
#: dorsiflexion, inversion, internal rotation. The knee flexion follows from the hip–ankle
#: distance (law of cosines, exact for collinear hip, knee and ankle centres and a knee
#: axis normal to them, as in the template), which keeps the solve regular near a straight knee.
_SOLVED = np.array([0, 1, 6, 7, 8])
_HIP_ROTATION = 2
_KNEE = 3
_KNEE_ROTATION = 5
#: Largest Gauss–Newton step, rad (keeps each sample on the previous sample's branch).
_MAX_STEP_RAD = 0.2
#: Largest change of any angle between two samples before the solve counts as failed, rad.
_MAX_JUMP_RAD = 0.3


class IKError(RuntimeError):
    """The planned foot pose is out of the leg's reach at some sample.

    Attributes:
        sample: Index of the first failing sample.
        residual: Norm of the SE(3) log error there (m and rad mixed).
    """

    def __init__(self, sample: int, residual: float) -> None:
        super().__init__(f"leg inverse kinematics did not converge at sample {sample} (error {residual:.2e})")
        self.sample = sample
        self.residual = residual


def _segment_lengths(leg: LegModel) -> tuple[float, float]:
    """Hip→knee and knee→ankle distances of the leg, m."""
    g = leg.geometry
    return float(np.linalg.norm(g.joint_origins["knee"][:3, 3])), float(
        np.linalg.norm(g.joint_origins["ankle"][:3, 3])
    )


def _knee_guess(d: float, lengths: tuple[float, float]) -> float:
    """Knee flexion (rad) that puts the ankle ``d`` (m) from the hip, for collinear offsets."""
    L1, L2 = lengths
    c = (d * d - L1 * L1 - L2 * L2) / (2.0 * L1 * L2)
    return float(np.arccos(np.clip(c, -1.0, 1.0)))


def solve_leg(
    leg: LegModel,
    root_q: FloatArray,
    hip_rotation_rad: FloatArray,
    foot_pos_m: FloatArray,
    foot_rot: FloatArray,
    *,
    knee_rotation_per_flexion: float = 0.0,
    tol: float = 1e-10,
    max_iter: int = 30,
) -> FloatArray:
    """Leg joint angles that place the foot segment frame at the planned pose.

    Args:
        leg: The simulation leg on the composite root joint (``leg.n_root_q`` root coordinates).
        root_q: (N, n_root_q) root coordinates at each sample.
        hip_rotation_rad: (N,) prescribed hip internal rotation, rad.
        foot_pos_m: (N, 3) foot segment frame origin (the ankle centre) in the world, m.
        foot_rot: (N, 3, 3) foot segment frame → world.
        knee_rotation_per_flexion: knee internal rotation per unit of knee flexion, rad/rad
            (0: a hinge).
        tol: Convergence threshold on the SE(3) log error norm.
        max_iter: Iterations per sample.

    Returns:
        (N, 9) leg joint angles, angles.csv order, rad.

    Raises:
        IKError: a sample does not converge (the foot is out of reach).
    """
    model, data = leg.model, leg.data
    nr = leg.n_root_q
    fid = leg.frame_id("foot")
    hip_j = model.getJointId(DOF_NAMES[0])
    lengths = _segment_lengths(leg)
    idx = nr + _SOLVED
    n = root_q.shape[0]
    out = np.zeros((n, 9))
    q = np.zeros(model.nq)
    local = pin.ReferenceFrame.LOCAL
    for k in range(n):
        q[:nr] = root_q[k]
        q[nr + _HIP_ROTATION] = hip_rotation_rad[k]
        pin.forwardKinematics(model, data, q)
        q[nr + _KNEE] = _knee_guess(
            float(np.linalg.norm(foot_pos_m[k] - data.oMi[hip_j].translation)), lengths
        )
        q[nr + _KNEE_ROTATION] = knee_rotation_per_flexion * q[nr + _KNEE]
        err = _newton(leg, q, idx, pin.SE3(foot_rot[k], foot_pos_m[k]), fid, local, tol, max_iter)
        if err > max(tol * 1e3, 1e-8) or (k > 0 and np.max(np.abs(q[nr:] - out[k - 1])) > _MAX_JUMP_RAD):
            raise IKError(k, err)
        out[k] = q[nr:]
    return out


def _newton(
    leg: LegModel,
    q: FloatArray,
    idx: FloatArray,
    target: pin.SE3,
    fid: int,
    local: object,
    tol: float,
    max_iter: int,
) -> float:
    """Damped Gauss–Newton on the coordinates ``idx`` of ``q`` (in place); returns the final error norm."""
    model, data = leg.model, leg.data
    err = np.inf
    for _ in range(max_iter):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacement(model, data, fid)
        J = pin.getFrameJacobian(model, data, fid, local)
        dM = target.actInv(data.oMf[fid])
        e = pin.log6(dM).vector
        err = float(np.linalg.norm(e))
        if err < tol:
            break
        Jl = pin.Jlog6(dM) @ J[:, idx]
        step = np.linalg.lstsq(Jl, e, rcond=1e-10)[0]
        norm = float(np.linalg.norm(step))
        q[idx] -= step * min(1.0, _MAX_STEP_RAD / max(norm, 1e-300))
    return err
