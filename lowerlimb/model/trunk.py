"""The upper body (head, arms, middle and upper trunk) as one rigid body above the pelvis, de Leva 1996.

The lower-body model carries the mass above the pelvis as one fixed ``trunk``
link, so that gravity and the pelvis accelerations load the hips as in a
person. Its mass, centre of mass and inertia are the composite of de Leva's
(1996, J. Biomech. 29:1223, Table 4, male) head, upper trunk, middle trunk,
two upper arms, two forearms and two hands, in the standing reference posture
with the arms hanging at the sides. Choices the table leaves open:

- the segments are stacked along the vertical: the middle trunk starts at the
  omphalion (top of the pelvis, de Leva's lower trunk), the upper trunk on top
  of it and the head on top of the upper trunk (the neck is not a separate
  segment in the table);
- the shoulder joints are at the top of the upper trunk, half the biacromial
  breadth to each side, taken as 0.259 × stature / 2 (Drillis & Contini 1966
  proportions);
- radii of gyration (sagittal, transverse, longitudinal) are about the ISB x,
  z and y axes, as in :mod:`lowerlimb.model.anthropometry`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import FloatArray
from .anthropometry import SegmentInertia

_REF_STATURE_M = 1.741

#: de Leva 1996 Table 4 (male): length (mm at 1741 mm stature), mass fraction, CoM from the
#: proximal (upper) end as a fraction of length, radii of gyration (sagittal, transverse,
#: longitudinal) as fractions of length.
UPPER_BODY_DE_LEVA: dict[str, tuple[float, float, float, tuple[float, float, float]]] = {
    "middle_trunk": (215.5, 0.1633, 0.4502, (0.482, 0.383, 0.468)),
    "upper_trunk": (170.7, 0.1596, 0.5066, (0.505, 0.320, 0.465)),
    "head": (203.3, 0.0694, 0.5976, (0.362, 0.376, 0.312)),
    "upper_arm": (281.7, 0.0271, 0.5772, (0.285, 0.269, 0.158)),
    "forearm": (268.9, 0.0162, 0.4574, (0.276, 0.265, 0.121)),
    "hand": (86.2, 0.0061, 0.7900, (0.628, 0.513, 0.401)),
}
#: Biacromial breadth as a fraction of stature (Drillis & Contini 1966).
BIACROMIAL_PER_STATURE = 0.259


@dataclass(frozen=True)
class TrunkInertia:
    """The lumped upper body.

    Attributes:
        inertia: mass (kg), CoM (3,) and inertia about the CoM (3, 3) in the trunk frame
            (ISB axes, origin at the omphalion, i.e. the top of the pelvis segment), SI.
        mass_fraction: its share of the body mass (de Leva: 0.4911).
        height_m: height of the stacked trunk and head above the omphalion, m.
        shoulder_width_m: biacromial breadth, m.
    """

    inertia: SegmentInertia
    mass_fraction: float
    height_m: float
    shoulder_width_m: float


def _parts(height_m: float) -> list[tuple[str, float, FloatArray, FloatArray]]:
    """(name, mass fraction, CoM (3,) in the trunk frame, m, radii of gyration (3,) about x, y, z, m)."""
    scale = height_m / _REF_STATURE_M
    length = {k: v[0] * 1e-3 * scale for k, v in UPPER_BODY_DE_LEVA.items()}
    top_middle = length["middle_trunk"]
    top_upper = top_middle + length["upper_trunk"]
    half_shoulder = 0.5 * BIACROMIAL_PER_STATURE * height_m
    out: list[tuple[str, float, FloatArray, FloatArray]] = []
    for name, (_, frac, com_frac, (r_sag, r_trans, r_long)) in UPPER_BODY_DE_LEVA.items():
        L = length[name]
        radii = np.array([r_sag, r_long, r_trans]) * L
        if name == "middle_trunk":
            out.append((name, frac, np.array([0.0, top_middle - com_frac * L, 0.0]), radii))
        elif name == "upper_trunk":
            out.append((name, frac, np.array([0.0, top_upper - com_frac * L, 0.0]), radii))
        elif name == "head":
            out.append((name, frac, np.array([0.0, top_upper + (1.0 - com_frac) * L, 0.0]), radii))
        else:
            # arms hang from the shoulders: upper arm, then forearm, then hand
            drop = {"upper_arm": 0.0, "forearm": length["upper_arm"]}
            drop["hand"] = drop["forearm"] + length["forearm"]
            y = top_upper - drop[name] - com_frac * L
            for side in (-1.0, 1.0):
                out.append((f"{name}_{side:+.0f}", frac, np.array([0.0, y, side * half_shoulder]), radii))
    return out


def trunk_inertia(height_m: float, mass_kg: float) -> TrunkInertia:
    """The upper body as one rigid body (see the module docstring), scaled to a subject.

    Args:
        height_m: stature, m.
        mass_kg: body mass, kg.

    Returns:
        The composite :class:`TrunkInertia` (parallel-axis theorem over the parts).
    """
    parts = _parts(height_m)
    masses = np.array([frac * mass_kg for _, frac, _, _ in parts])
    coms = np.array([c for _, _, c, _ in parts])
    total = float(masses.sum())
    com = masses @ coms / total
    inertia = np.zeros((3, 3))
    for m, c, (_, _, _, r) in zip(masses, coms, parts, strict=True):
        d = c - com
        inertia += np.diag(m * r**2) + m * (float(d @ d) * np.eye(3) - np.outer(d, d))
    scale = height_m / _REF_STATURE_M
    stack = (
        UPPER_BODY_DE_LEVA["middle_trunk"][0]
        + UPPER_BODY_DE_LEVA["upper_trunk"][0]
        + UPPER_BODY_DE_LEVA["head"][0]
    )
    return TrunkInertia(
        inertia=SegmentInertia(stack * 1e-3 * scale, total, com, inertia),
        mass_fraction=total / mass_kg,
        height_m=stack * 1e-3 * scale,
        shoulder_width_m=BIACROMIAL_PER_STATURE * height_m,
    )
