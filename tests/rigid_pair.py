"""Synthetic rigid-body sensor pairs with exact signals, for constraint and calibration unit tests.

Independent of ``lowerlimb.simulation``: two segments joined by a spherical
joint or a hinge, smooth random motion (sums of sinusoids), exact specific
force, angular velocity and angular acceleration in each sensor frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

G_ENU = np.array([0.0, 0.0, -9.81])


@dataclass
class RigidPair:
    rate_hz: float
    acc_parent: np.ndarray
    gyr_parent: np.ndarray
    angacc_parent: np.ndarray
    acc_child: np.ndarray
    gyr_child: np.ndarray
    angacc_child: np.ndarray
    center_parent: np.ndarray
    center_child: np.ndarray
    axis_parent: np.ndarray  # hinge axes (meaningful for kind="hinge" only)
    axis_child: np.ndarray
    R_parent_child: np.ndarray  # (N, 3, 3)


def _smooth_signal(rng: np.random.Generator, n_freq: int, amp: float, fmax: float):
    f = rng.uniform(0.1, fmax, size=(n_freq, 3))
    a = rng.normal(size=(n_freq, 3)) * amp / np.sqrt(n_freq)
    ph = rng.uniform(0, 2 * np.pi, size=(n_freq, 3))

    def s(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t)[..., None, None]
        return np.sum(a * np.sin(2 * np.pi * f * t + ph), axis=-2)

    return s


def rigid_pair(
    kind: str = "spherical",
    *,
    duration_s: float = 20.0,
    rate_hz: float = 100.0,
    seed: int = 0,
    amplitude: float = 1.0,
    parent_amplitude: float = 0.6,
    center_parent=(0.05, -0.2, 0.08),
    center_child=(-0.03, 0.18, 0.06),
    axis_parent=(0.2, 0.1, 0.97),
    axis_child=(-0.1, 0.3, 0.95),
    gyro_noise: float = 0.0,
    acc_noise: float = 0.0,
    gyro_bias: float = 0.0,
    still_s: float = 0.0,
    one_sided: bool = False,
) -> RigidPair:
    """Two segments joined at a spherical joint or a hinge, sampled at ``rate_hz``.

    ``one_sided`` makes the hinge angle q(t) <= 0 about ``axis_parent`` (a knee
    flexing about a right-pointing axis).
    """
    rng = np.random.default_rng(seed)
    cp = np.asarray(center_parent, float)
    cc = np.asarray(center_child, float)
    jp = np.asarray(axis_parent, float)
    jp /= np.linalg.norm(jp)
    jc = np.asarray(axis_child, float)
    jc /= np.linalg.norm(jc)
    # fixed rotation R0 with R0 jc = jp (child-to-parent at zero hinge angle)
    R0 = Rotation.align_vectors(jp[None], jc[None])[0].as_matrix()
    rot_p = _smooth_signal(rng, 4, parent_amplitude, 1.0)
    pos_j = _smooth_signal(rng, 4, 0.3, 0.8)
    rel = _smooth_signal(rng, 4, amplitude, 1.2)
    n_still = int(round(still_s * rate_hz))

    def ramp(t):
        # 0 during the still period, then smoothly 1
        t = np.asarray(t, float)
        s = np.clip((t - still_s) / 1.0, 0.0, 1.0)
        return (s**3 * (10 - 15 * s + 6 * s * s)) if still_s > 0 else np.ones_like(t)

    def R_p(t):
        return Rotation.from_rotvec(rot_p(t) * ramp(t)[..., None]).as_matrix()

    def R_rel(t):
        if kind == "spherical":
            return Rotation.from_rotvec(rel(t) * ramp(t)[..., None]).as_matrix() @ R0
        q = rel(t)[..., 0] * ramp(t)
        if one_sided:  # the child only rotates negatively about the axis (like knee flexion)
            q = -(q**2)
        return Rotation.from_rotvec(q[..., None] * jp).as_matrix() @ R0

    def R_c(t):
        return R_p(t) @ R_rel(t)

    def pj(t):
        return pos_j(t) * ramp(t)[..., None]

    def p_sensor(t, R, c):
        return pj(t) - np.einsum("nij,j->ni", R(t), c)

    t = np.arange(int(round(duration_s * rate_hz))) / rate_hz
    h = 1e-5
    out = {}
    for name, R, c in (("parent", R_p, cp), ("child", R_c, cc)):

        def omega(tt, R=R):
            dR = (R(tt + h) - R(tt - h)) / (2 * h)
            W = np.einsum("nji,njk->nik", R(tt), dR)
            return np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], -1)

        w = omega(t)
        alpha = (omega(t + 1e-4) - omega(t - 1e-4)) / 2e-4
        hp = 1e-3
        acc_w = (p_sensor(t + hp, R, c) - 2 * p_sensor(t, R, c) + p_sensor(t - hp, R, c)) / hp**2
        f = np.einsum("nji,nj->ni", R(t), acc_w - G_ENU)
        if n_still:
            w[:n_still] = 0.0
            alpha[:n_still] = 0.0
        out[name] = (f, w, alpha)
    R_pc = np.einsum("nji,njk->nik", R_p(t), R_c(t))
    if gyro_noise or acc_noise or gyro_bias:
        for name in ("parent", "child"):
            f, w, alpha = out[name]
            b = rng.normal(size=3)
            b *= gyro_bias / np.linalg.norm(b)
            out[name] = (
                f + acc_noise * rng.normal(size=f.shape),
                w + gyro_noise * rng.normal(size=w.shape) + b,
                alpha,
            )
    return RigidPair(
        rate_hz,
        *out["parent"],
        *out["child"],
        cp,
        cc,
        jp,
        jc,
        R_pc,
    )
