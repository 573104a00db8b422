"""ISB joint angles from segment orientations (Hu et al. 2021 eq. 38–42, Z-X-Y)."""

from __future__ import annotations

import numpy as np

from ..conventions import JOINTS, FloatArray, joint_angles_from_matrix, quat_to_matrix

#: (proximal, distal) segment of each joint.
JOINT_SEGMENT_PAIRS: dict[str, tuple[str, str]] = {
    "hip": ("pelvis", "thigh"),
    "knee": ("thigh", "shank"),
    "ankle": ("shank", "foot"),
}


def compute_joint_angles(segment_quat_wxyz: dict[str, FloatArray], side: str) -> FloatArray:
    """Joint angles (N, 9) rad in angles.csv order from segment orientations.

    Args:
        segment_quat_wxyz: ``{segment: (N, 4)}`` orientation of each ISB segment
            frame in one common earth frame (w, x, y, z).
        side: ``"left"`` or ``"right"`` (sets the signs of adduction and rotation).

    Returns:
        (N, 9): for hip, knee, ankle in turn: flexion (dorsiflexion),
        adduction (inversion), internal rotation, rad; clinical signs of
        docs/conventions.md. Each angle is unwrapped in time, so it is continuous.
    """
    R = {seg: quat_to_matrix(q) for seg, q in segment_quat_wxyz.items()}
    out = []
    for joint in JOINTS:
        prox, dist = JOINT_SEGMENT_PAIRS[joint]
        R_rel = np.einsum("nji,njk->nik", R[prox], R[dist])
        out.append(joint_angles_from_matrix(R_rel, joint, side))
    return np.unwrap(np.concatenate(out, axis=1), axis=0)
