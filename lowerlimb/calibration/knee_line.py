"""Where along the knee axis the knee sits between the thigh and the shank sensor.

Why: a hinge leaves the common position of its centre along the axis free (the
gauge of Hu 2021 eq. 16), but the *relative* position along the axis of the
knee point in the thigh sensor and in the shank sensor is physical: it decides
how far sideways the chain puts the ankle from the hip, hence step width,
stance width and every pelvis-to-foot position. The data pin it only through
the thigh's rotation about axes other than the knee axis, which walking barely
excites, and the norm residual of eq. 3 is biased by the prefilter when the
two frames rotate against each other fast (the knee in swing): on simulated
seven-IMU walks the estimate moved 5–10 cm with the low-pass cut-off (truth 0
at no cap, 4.7 / −8.4 cm at the 7 Hz cap of the hip's rigid band), and on the
real walk of ``gait/`` it swung over ±25 cm between cut-offs of 3 and 12 Hz.
Its statistical spread (1–3 mm) says nothing of either.

The anatomy knows it better. The hip, knee and ankle centres lie close to one
line, the mechanical axis, which is nearly perpendicular to the knee's flexion
axis: the mechanical axis passes 8 ± 7 mm medial of the knee centre (Moreland,
Bassett & Hanker 1987, J Bone Joint Surg Am 69(5):745–9) and the flexion axis
lies within a few degrees of the joint line, itself about 3° from
perpendicular to the mechanical axis. Vicon's Plug-in-Gait model of the real
walk puts the ankle 20 mm medial of the hip along its knee axis on both legs
(1.4° from perpendicular). So the gauge-invariant quantity

    v = (c_ankle − k_C) · j_C − (c_hip − k_P) · j_P     (m; ankle minus hip along the axis)

has a prior N(:attr:`~CalibrationOptions.knee_line_mean_m`,
:attr:`~CalibrationOptions.knee_line_std_m`) (0 ± 40 mm: 3° over a 0.8 m leg).

The prior is stated for one axis seen from both sensors. At the standing start
a hinge keeps the angle between its axis and gravity, so the axis's elevation
above the horizontal must be the same in the thigh and in the shank sensor; on
the real walk the thigh's estimate is 17–18° off the shank's on both legs (soft
tissue turns a thigh sensor about the femur and the hinge residual absorbs it;
docs/limits.md). ``v`` then mixes the two axes, and the chain's standing stance
width matched Vicon's only with the data's ``v`` (30.7 vs 30.9 cm; with the
prior's it was 52 cm, and a prior whose spread grew with the mismatch still
moved it to 32.9 cm and the step width from 18 to 26 mm median). So the prior
applies only to a hinge whose two axis estimates agree at standing to within
:attr:`~CalibrationOptions.knee_line_max_mismatch_deg` (the simulator: 0.1°);
otherwise the data's ``v`` is kept and the mismatch is recorded.

The data's estimate gets a spread that includes its systematic part: the
larger of its statistical one and how far it moves when the knee centre is
refitted without the low-pass cap and at multiples of it
(:attr:`~CalibrationOptions.knee_line_probe_factors`). The posterior
mean of ``v`` (precision-weighted) is then imposed by moving the two knee
points ±Δ/2 along the axis, which keeps the gauge (their mean along the axis)
and changes no angle and no segment length (both are distances to the axis
line).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration
from lowerlimb.conventions import FloatArray

__all__ = [
    "KneeLine",
    "axis_mismatch_message",
    "knee_line_offset",
    "standing_axis_mismatch",
    "with_knee_line",
]


def knee_line_offset(
    hip_in_thigh: FloatArray, knee: HingeJointCalibration, ankle_in_shank: FloatArray
) -> float:
    """``v``, the ankle minus the hip centre along the knee axis (module docstring), m.

    Args:
        hip_in_thigh: (3,) hip centre in the thigh sensor frame, m.
        knee: the knee (axis and centre in both sensor frames).
        ankle_in_shank: (3,) ankle centre in the shank sensor frame, m.
    """
    jp = np.asarray(knee.axis_in_parent_sensor, dtype=float)
    jc = np.asarray(knee.axis_in_child_sensor, dtype=float)
    a = (np.asarray(ankle_in_shank, dtype=float) - knee.center_in_child_sensor) @ jc
    h = (np.asarray(hip_in_thigh, dtype=float) - knee.center_in_parent_sensor) @ jp
    return float(a - h)


@dataclass(frozen=True)
class KneeLine:
    """The knee's relative position along its axis: data, prior and what was used.

    Attributes:
        data_m: ``v`` from the data's knee fit, m.
        data_std_m: its spread, m: statistical and the cut-off probe's shift, the larger.
        prior_mean_m: the anatomical prior's mean, m.
        prior_std_m: its standard deviation, m.
        posterior_m: the precision-weighted ``v`` imposed on the knee, m (the data's
            when the prior does not apply).
        axis_mismatch_deg: the knee axis's standing elevation in the thigh minus that in
            the shank sensor, deg.
        applied: whether the prior was applied (the two axes agree at standing).
    """

    data_m: float
    data_std_m: float
    prior_mean_m: float
    prior_std_m: float
    posterior_m: float
    axis_mismatch_deg: float = 0.0
    applied: bool = True

    @classmethod
    def combine(
        cls,
        data_m: float,
        data_std_m: float,
        prior_mean_m: float,
        prior_std_m: float,
        mismatch_deg: float = 0.0,
    ) -> KneeLine:
        """The Gaussian posterior of ``v`` from the data and the prior (spreads in m, > 0)."""
        wd, wp = 1.0 / data_std_m**2, 1.0 / prior_std_m**2
        post = (wd * data_m + wp * prior_mean_m) / (wd + wp)
        return cls(data_m, data_std_m, prior_mean_m, prior_std_m, float(post), mismatch_deg)

    def to_dict(self) -> dict[str, Any]:
        """The record written under ``anthropometric_prior.knee_line`` of calibration.json."""
        return {
            "on": "knee centre along the axis (ankle minus hip along the knee axis)",
            "data_m": self.data_m,
            "data_std_m": self.data_std_m,
            "mean_m": self.prior_mean_m,
            "std_m": self.prior_std_m,
            "posterior_m": self.posterior_m,
            "axis_mismatch_deg": self.axis_mismatch_deg,
            "applied": self.applied,
        }


def _shift_along_axis(knee: HingeJointCalibration, delta_m: float) -> HingeJointCalibration:
    """The knee with its thigh point moved ``delta/2`` along the axis and its shank point ``−delta/2``.

    ``v`` grows by ``delta`` (its thigh term loses ``−delta/2``, its shank term gains ``delta/2``).
    """
    jp = np.asarray(knee.axis_in_parent_sensor, dtype=float)
    jc = np.asarray(knee.axis_in_child_sensor, dtype=float)
    center: SphericalJointCalibration = replace(
        knee.center,
        center_in_parent_sensor=knee.center_in_parent_sensor + 0.5 * delta_m * jp,
        center_in_child_sensor=knee.center_in_child_sensor - 0.5 * delta_m * jc,
    )
    return replace(knee, center=center)


def with_knee_line(
    knee: HingeJointCalibration,
    hip_in_thigh: FloatArray,
    ankle_in_shank: FloatArray,
    probes: list[HingeJointCalibration],
    *,
    mean_m: float,
    std_m: float,
    min_data_std_m: float,
    axis_mismatch_rad: float = 0.0,
    max_mismatch_rad: float = np.inf,
) -> tuple[HingeJointCalibration, KneeLine]:
    """The knee moved along its axis to the posterior ``v`` (module docstring).

    Args:
        knee: the data's knee.
        hip_in_thigh: (3,) hip centre in the thigh sensor frame, m.
        ankle_in_shank: (3,) ankle centre in the shank sensor frame, m.
        probes: the knee refitted at other low-pass cut-offs (same axis).
        mean_m: prior mean of ``v``, m.
        std_m: prior standard deviation of ``v``, m.
        min_data_std_m: lower bound of the data's spread, m.
        axis_mismatch_rad: the axis's elevation in the thigh minus that in the shank
            sensor at the standing start, rad (:func:`standing_axis_mismatch`).
        max_mismatch_rad: above this mismatch the prior does not apply (the knee is
            returned unchanged), rad.

    Returns:
        The knee with its centre moved (the axis unchanged) and the record.
    """
    v = knee_line_offset(hip_in_thigh, knee, ankle_in_shank)
    stat = _statistical_std(knee)
    shift = max((abs(knee_line_offset(hip_in_thigh, p, ankle_in_shank) - v) for p in probes), default=0.0)
    spread = max(stat, shift, min_data_std_m)
    mismatch_deg = float(np.degrees(axis_mismatch_rad))
    if abs(axis_mismatch_rad) > max_mismatch_rad:
        return knee, KneeLine(v, spread, mean_m, std_m, v, mismatch_deg, applied=False)
    line = KneeLine.combine(v, spread, mean_m, std_m, mismatch_deg)
    return _shift_along_axis(knee, line.posterior_m - v), line


def standing_axis_mismatch(knee: HingeJointCalibration, up_thigh: FloatArray, up_shank: FloatArray) -> float:
    """The knee axis's elevation above the horizontal in the thigh minus that in the shank sensor, rad.

    Args:
        knee: the knee (axes in both sensor frames).
        up_thigh: (3,) the thigh sensor's mean specific force at the standing start (up).
        up_shank: (3,) the same for the shank sensor.
    """
    e = [
        np.arcsin(
            np.clip(np.asarray(j, dtype=float) @ (np.asarray(u, dtype=float) / np.linalg.norm(u)), -1, 1)
        )
        for j, u in ((knee.axis_in_parent_sensor, up_thigh), (knee.axis_in_child_sensor, up_shank))
    ]
    return float(e[0] - e[1])


def moving_axis_mismatch(
    knee: HingeJointCalibration,
    acc_thigh: FloatArray,
    acc_shank: FloatArray,
    rate_hz: float,
    lowpass_hz: float,
) -> float:
    """:func:`standing_axis_mismatch` without a standing start: its median over the motion, rad.

    A hinge turns the two sensors against each other about its axis only, so the axis keeps
    one angle to any vector both see; gravity dominates each accelerometer once low-passed
    (at ``lowpass_hz``), and a segment's own acceleration along the axis is small where it
    turns about it. The component along the axis is divided by the sensor's median specific
    force (about g), not by the low-passed vector's length, which the filter shortens where
    the sensor turns. The median over the samples of the elevation difference then reads
    what the standing start reads: the real walk's knees −16.8 / +22.3° (at standing
    −17.1 / +22.1°), the rig's hinge 0.4° (1.0°), RING's hinges 0.1–10.0° (0.0–6.7°), rigid
    simulated knees within 0.5° (walks, squats, the mixed motion), knees that turn 0.2 rad per
    rad of flexion 0.6–1.1° (2.4–4.1°), the simulator's real-walk artefacts within 2.5° of
    their standing values (−13.0 … +30.9°).

    Args:
        knee: the hinge (axes in both sensor frames).
        acc_thigh: (N, 3) the parent (thigh) sensor's specific force, sensor frame, m/s².
        acc_shank: (N, 3) the same for the child (shank) sensor.
        rate_hz: sampling rate, Hz.
        lowpass_hz: the low-pass cut-off applied to both accelerometers first, Hz.
    """
    from lowerlimb.constraints.prefilter import lowpass

    e = []
    for j, a in ((knee.axis_in_parent_sensor, acc_thigh), (knee.axis_in_child_sensor, acc_shank)):
        a = np.asarray(a, dtype=float)
        low = lowpass(a, rate_hz, min(lowpass_hz, 0.45 * rate_hz), order=2)
        g = max(float(np.median(np.linalg.norm(a, axis=1))), 1e-9)  # the low-pass shrinks the turning part
        e.append(np.arcsin(np.clip(low @ np.asarray(j, dtype=float) / g, -1.0, 1.0)))
    return float(np.median(e[0] - e[1]))


def axis_mismatch_message(mismatch_deg: float) -> str:
    """The warning for a knee whose two axis estimates disagree at standing (one line)."""
    return (
        f"knee: the knee axis from the thigh sensor and from the shank sensor differ by "
        f"{abs(mismatch_deg):.0f}° in elevation at the standing start (a hinge keeps them equal): a sensor, "
        f"most often the thigh's, turns on soft tissue (typically about the femur as the hip flexes); hip "
        f"flexion (the thigh frame leans with the axis: a few degrees of offset in walking), knee adduction "
        f"and rotation and the ankle's sideways place in the chain are less certain; strap the sensors "
        f"tighter over flat, lean spots, or pass --thigh-twist to undo such a turn (docs/limits.md)"
    )


def _statistical_std(knee: HingeJointCalibration) -> float:
    """The knee fit's own spread of ``v``, m (from its per-coordinate standard deviations)."""
    rep = knee.center.excitation
    if rep is None or not np.all(np.isfinite(rep.std)):
        return float("inf")
    jp = np.asarray(knee.axis_in_parent_sensor, dtype=float)
    jc = np.asarray(knee.axis_in_child_sensor, dtype=float)
    sp = float(np.linalg.norm(rep.std[:3] * jp))
    sc = float(np.linalg.norm(rep.std[3:6] * jc))
    return float(np.hypot(sp, sc))
