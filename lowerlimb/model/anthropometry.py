"""Segment lengths, masses, centres of mass and inertias scaled from height and mass.

Source: P. de Leva, "Adjustments to Zatsiorsky–Seluyanov's segment inertia
parameters", J. Biomech. 29(9):1223–1230, 1996, Table 4 (male values), with
segment lengths expressed as fractions of the 1.741 m reference stature.
The pelvis is de Leva's "lower trunk" (omphalion to hip-joint-centre level).
Hip-joint spacing, ankle height and heel offset are not in de Leva's table;
they use typical adult proportions (documented on the constants below).

All outputs are SI: m, kg, kg·m². Inertia tensors are expressed in the ISB
segment frame (x anterior, y superior, z right) about the centre of mass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import FloatArray

_REF_STATURE_M = 1.741

#: de Leva 1996 Table 4 (male): length (mm at 1741 mm stature), mass fraction,
#: CoM position from the proximal end (fraction of length), radii of gyration
#: (fraction of length) about the sagittal (x), longitudinal (y) and
#: transverse (z) axes through the CoM.
_DE_LEVA: dict[str, tuple[float, float, float, tuple[float, float, float]]] = {
    # segment: (length_mm, mass_fraction, com_from_proximal, (r_x, r_y, r_z))
    "pelvis": (145.7, 0.1117, 0.6115, (0.615, 0.587, 0.551)),
    "thigh": (422.2, 0.1416, 0.4095, (0.329, 0.149, 0.329)),
    "shank": (434.0, 0.0433, 0.4459, (0.255, 0.103, 0.249)),
    "foot": (258.1, 0.0137, 0.4415, (0.257, 0.245, 0.124)),
}

#: Distance between the two hip-joint centres as a fraction of stature
#: (≈ 0.17 m at 1.75 m; Bell et al. 1990 proportions).
HIP_SPACING_PER_STATURE = 0.098
#: Height of the ankle-joint centre above the sole, fraction of stature.
ANKLE_HEIGHT_PER_STATURE = 0.039
#: Heel-to-ankle horizontal distance, fraction of foot length.
HEEL_OFFSET_PER_FOOT_LENGTH = 0.22


@dataclass(frozen=True)
class SegmentInertia:
    """Mass properties of one segment.

    Attributes:
        length_m: joint-to-joint length (foot: heel to toe tip), m.
        mass_kg: segment mass, kg.
        com_m: (3,) centre of mass in the segment frame (origin at the proximal joint), m.
        inertia_kgm2: (3, 3) inertia tensor about the CoM in the segment frame, kg·m².
    """

    length_m: float
    mass_kg: float
    com_m: FloatArray
    inertia_kgm2: FloatArray


def segment_inertias(height_m: float = 1.75, mass_kg: float = 75.0) -> dict[str, SegmentInertia]:
    """Scale de Leva 1996 parameters to a subject.

    Args:
        height_m: stature, m (``InputBounds.height_m``: 0.5–2.6).
        mass_kg: body mass, kg (5 to ``InputBounds.mass_kg``'s 400).

    Returns:
        ``{"pelvis"|"thigh"|"shank"|"foot": SegmentInertia}``. Frames: thigh and
        shank origins at the proximal joint centre with the segment along −y;
        foot origin at the ankle centre, long axis along +x; pelvis origin at
        the midpoint of the hip centres, CoM above it.

    Raises:
        ValueError: when height or mass is outside the plausible range.
    """
    # the ranges the command line and the batch manifest accept (io.bounds.InputBounds): a
    # height or mass they let through must not fail here as an internal error
    from ..io.bounds import INPUT_BOUNDS

    h_lo, h_hi = INPUT_BOUNDS.height_m
    m_lo, m_hi = min(5.0, INPUT_BOUNDS.mass_kg[0]), INPUT_BOUNDS.mass_kg[1]
    if not h_lo <= height_m <= h_hi:
        raise ValueError(f"height {height_m} m is implausible; give the stature in m ({h_lo:g}–{h_hi:g})")
    if not m_lo <= mass_kg <= m_hi:
        raise ValueError(f"mass {mass_kg} kg is implausible; give the body mass in kg ({m_lo:g}–{m_hi:g})")
    scale = height_m / _REF_STATURE_M
    out: dict[str, SegmentInertia] = {}
    for name, (length_mm, frac, com_frac, radii) in _DE_LEVA.items():
        length = length_mm * 1e-3 * scale
        mass = frac * mass_kg
        if name == "pelvis":
            com = np.array([0.0, (1.0 - com_frac) * length, 0.0])
        elif name == "foot":
            heel = HEEL_OFFSET_PER_FOOT_LENGTH * length
            ankle_h = ANKLE_HEIGHT_PER_STATURE * height_m
            com = np.array([com_frac * length - heel, -0.5 * ankle_h, 0.0])
        else:
            com = np.array([0.0, -com_frac * length, 0.0])
        r = np.array(radii) * length
        if name == "foot":
            # the foot's long axis is x: longitudinal radius belongs to x
            r = np.array([radii[2], radii[0], radii[1]]) * length
        out[name] = SegmentInertia(length, mass, com, np.diag(mass * r**2))
    return out


def hip_spacing_m(height_m: float) -> float:
    """Distance between the hip-joint centres, m."""
    return HIP_SPACING_PER_STATURE * height_m


def ankle_height_m(height_m: float) -> float:
    """Height of the ankle-joint centre above the sole, m."""
    return ANKLE_HEIGHT_PER_STATURE * height_m
