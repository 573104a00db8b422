"""One pelvis for both legs: a shared pelvis segment frame and the two hip centres estimated jointly.

Why (the real walk, gait/): each leg's single-leg calibration finds its hip centre in
the pelvis sensor frame from the pelvis's own rotation, which is small in walking
(mostly yaw, about the vertical): the centre's vertical coordinate is poorly
determined (8 and 22 cm off Vicon there, the two hips 13 cm apart vertically) while
its anterior coordinate is good (2–7 mm). Each leg also builds its own pelvis frame
as its thigh frame at the standing reference, whose z is that leg's knee axis: the
two knee axes were tilted ±21–27° out of the horizontal and turned apart, so the two
legs' pelvis frames were 61° apart (each about 30° from Vicon's ASIS line), while
their mean was within 7°.

What is built here, from the two single-leg calibrations of one trial:

1. **the shared pelvis frame** (:func:`pelvis_frame`): y = up from the pelvis
   sensor's specific force at the standing reference (gravity is the best-measured
   direction); z = to the right, horizontal: the inverse-variance weighted mean, as
   a heading in the horizontal plane, of (a) the horizontal part of the line from
   the left to the right hip centre (its direction depends on the anterior and
   lateral coordinates of the two centres, the well-determined ones; its variance
   from their reported standard deviations plus :attr:`PelvisParams.model_std_m`)
   and (b) the mean of the two knee axes carried into the pelvis sensor at the
   reference (symmetric errors of the two legs, toe-out, cancel; variance
   :attr:`PelvisParams.knee_heading_sd_deg` per leg); x = y × z (anterior);
2. **the joint hip centres** (:func:`joint_hip_centers`): a weighted linear least
   squares in the shared frame, where each leg's calibrated centre is an observation
   with its reported covariance (diagonal, pelvis sensor frame) plus a model error
   (the reported covariance only reflects the noise, not the soft-tissue and
   model errors), and the pelvis adds two priors: mirror symmetry about the
   mid-sagittal plane (equal anterior and vertical coordinates,
   :attr:`PelvisParams.symmetry_sd_m`) and the spacing along z near de Leva's for
   the stature (:attr:`PelvisParams.spacing_sd_m`, the adult spread). The sensor may
   sit off the mid-line: the mid-point's lateral coordinate is free.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..conventions import SIDES, FloatArray
from ..errors import InputError
from ..model.anthropometry import hip_spacing_m

__all__ = [
    "JointHips",
    "OppositeKneesError",
    "OppositeKneesWarning",
    "PelvisParams",
    "SharedPelvis",
    "joint_hip_centers",
    "pelvis_frame",
    "shared_pelvis",
]


@dataclass(frozen=True)
class PelvisParams:
    """Uncertainties of the shared pelvis.

    Attributes:
        model_std_m: Error of a single-leg hip centre beyond its reported standard deviation,
            per axis, m (joint-constraint hip centres carry 1–4 cm of soft-tissue and model
            error; the Gauss–Newton covariance sees only the residual noise).
        symmetry_sd_m: Spread of the difference of the two hip centres' anterior and vertical
            coordinates in the pelvis frame, m (pelvic asymmetry and a few degrees of frame error).
        spacing_sd_m: Spread of the adult hip spacing about de Leva's stature-scaled mean, m.
        knee_heading_sd_deg: Spread of one knee axis's heading about the pelvis's right axis at
            standing, deg (toe-out and the knee-axis fit error).
        max_knee_axes_angle_deg: Largest angle between the two knee axes (both pointing right)
            seen from the pelvis at standing, deg; beyond it one leg's sensors are mirrored or
            belong to the other leg and the pelvis has no right direction.
    """

    model_std_m: float = 0.03
    symmetry_sd_m: float = 0.01
    spacing_sd_m: float = 0.02
    knee_heading_sd_deg: float = 15.0
    max_knee_axes_angle_deg: float = 135.0


def _knees_apart(angle_deg: float, consequence: str) -> str:
    """The message of two knee axes ``angle_deg`` apart, with what became of the trial."""
    return (
        f"the two knee axes point {angle_deg:.0f}° apart seen from the pelvis, but both should point "
        f"to the subject's right{consequence}: a hip centre is undetermined (its warning says so) and "
        f"turned that thigh's heading, one knee barely bends, or one leg's sensors look mirrored or "
        f"belong to the other leg; check the left_* and right_* columns and each sensor's axes"
    )


class OppositeKneesError(InputError):
    """The two knee axes (both meant to point right) point apart; carries their angle (deg)."""

    def __init__(self, angle_deg: float) -> None:
        self.angle_deg = angle_deg
        super().__init__(_knees_apart(angle_deg, ""))


class OppositeKneesWarning(UserWarning):
    """The two-leg pipeline met :class:`OppositeKneesError` and kept each leg's own pelvis."""

    def __init__(self, angle_deg: float) -> None:
        self.angle_deg = angle_deg
        super().__init__(
            _knees_apart(
                angle_deg,
                ", so the legs do not share one pelvis: each keeps its own pelvis frame and hip "
                "centre (as two one-leg trials)",
            )
        )


@dataclass(frozen=True)
class JointHips:
    """The two hip centres estimated together.

    Attributes:
        center_in_pelvis_sensor_m: ``{side: (3,)}`` joint estimate, pelvis sensor frame, m.
        std_in_pelvis_m: ``{side: (3,)}`` its standard deviation along the pelvis x, y, z, m.
        spacing_m: Distance between the two joint centres, m.
    """

    center_in_pelvis_sensor_m: dict[str, FloatArray]
    std_in_pelvis_m: dict[str, FloatArray]
    spacing_m: float


@dataclass(frozen=True)
class SharedPelvis:
    """The one pelvis of a two-leg trial.

    Attributes:
        R_sensor_pelvis: (3, 3) pelvis segment frame in the pelvis sensor (columns x anterior,
            y up, z right).
        hips: the joint hip centres.
        single_leg_center_m: ``{side: (3,)}`` each leg's own calibrated hip centre, pelvis sensor, m.
        single_leg_spacing_m: Distance between the single-leg centres, m.
        expected_spacing_m: de Leva's hip spacing for the stature, m.
        legs_axes_angle_deg: Angle between the two legs' own pelvis right axes (knee axes at
            the reference), deg.
        hip_line_weight: Share (0–1) of the hip line in the heading of the right axis.
        hip_line_to_knees_deg: Heading difference of the hip line and the knee-axes mean, deg.
    """

    R_sensor_pelvis: FloatArray
    hips: JointHips
    single_leg_center_m: dict[str, FloatArray]
    single_leg_spacing_m: float
    expected_spacing_m: float
    legs_axes_angle_deg: float
    hip_line_weight: float
    hip_line_to_knees_deg: float

    def to_dict(self) -> dict[str, Any]:
        """The ``pelvis`` entry of the two-leg ``calibration.json``."""
        return {
            "R_sensor_pelvis": np.asarray(self.R_sensor_pelvis).tolist(),
            "hip_center_in_pelvis_sensor_m": {
                s: np.asarray(v).tolist() for s, v in self.hips.center_in_pelvis_sensor_m.items()
            },
            "hip_center_std_in_pelvis_m": {
                s: np.asarray(v).tolist() for s, v in self.hips.std_in_pelvis_m.items()
            },
            "hip_spacing_m": self.hips.spacing_m,
            "single_leg_hip_center_m": {
                s: np.asarray(v).tolist() for s, v in self.single_leg_center_m.items()
            },
            "single_leg_hip_spacing_m": self.single_leg_spacing_m,
            "expected_hip_spacing_m": self.expected_spacing_m,
            "legs_axes_angle_deg": self.legs_axes_angle_deg,
            "hip_line_weight": self.hip_line_weight,
            "hip_line_to_knees_deg": self.hip_line_to_knees_deg,
        }


def _unit(v: FloatArray) -> FloatArray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _finite_or_zero(std: FloatArray) -> FloatArray:
    """Reported standard deviations with unknown (NaN, inf) ones as 0 (the model error remains)."""
    a = np.asarray(std, dtype=float)
    return np.where(np.isfinite(a), a, 0.0)


def _horizontal(v: FloatArray, up: FloatArray) -> FloatArray:
    return _unit(v - (v @ up) * up)


def pelvis_frame(up: FloatArray, right: FloatArray) -> FloatArray:
    """(3, 3) pelvis frame (columns x anterior, y up, z right) from an up and a right direction.

    Args:
        up: (3,) upward direction, pelvis sensor frame (any length).
        right: (3,) a direction to the subject's right, pelvis sensor frame; its vertical
            part is removed.
    """
    y = _unit(up)
    z = _horizontal(np.asarray(right, dtype=float), y)
    return np.column_stack([np.cross(y, z), y, z])


def joint_hip_centers(
    center_m: dict[str, FloatArray],
    std_m: dict[str, FloatArray],
    R_sensor_pelvis: FloatArray,
    expected_spacing_m: float,
    params: PelvisParams | None = None,
) -> JointHips:
    """The two hip centres estimated together with the pelvis's symmetry and de Leva's spacing.

    Unknowns: the two centres in pelvis-frame coordinates (origin the pelvis sensor).
    Observations: each single-leg centre with covariance ``diag(std²) + model_std²·I``
    (pelvis sensor frame). Priors: equal x and y (``symmetry_sd_m``); right z minus left z
    equal to ``expected_spacing_m`` (``spacing_sd_m``). Linear, solved in closed form.

    Args:
        center_m: ``{side: (3,)}`` single-leg hip centres, pelvis sensor frame, m.
        std_m: ``{side: (3,)}`` their reported standard deviations (NaN/inf: none), m.
        R_sensor_pelvis: (3, 3) the shared pelvis frame in the pelvis sensor.
        expected_spacing_m: prior hip spacing, m.
        params: uncertainties (defaults: :class:`PelvisParams`).
    """
    p = params or PelvisParams()
    R = np.asarray(R_sensor_pelvis, dtype=float)
    rows: list[FloatArray] = []
    rhs: list[float] = []
    for k, side in enumerate(SIDES):
        s = _finite_or_zero(std_m[side])
        cov = R.T @ np.diag(s**2 + p.model_std_m**2) @ R  # pelvis-frame covariance of R^T c
        W = np.linalg.cholesky(np.linalg.inv(cov)).T  # W^T W = cov^-1
        A = np.zeros((3, 6))
        A[:, 3 * k : 3 * k + 3] = np.eye(3)
        obs = R.T @ np.asarray(center_m[side], dtype=float)
        rows.extend(W @ A)
        rhs.extend(W @ obs)
    for axis in (0, 1):  # mirror symmetry: equal anterior and vertical coordinates
        r = np.zeros(6)
        r[axis], r[3 + axis] = 1.0, -1.0
        rows.append(r / p.symmetry_sd_m)
        rhs.append(0.0)
    r = np.zeros(6)
    r[2], r[5] = -1.0, 1.0  # right z − left z (left is SIDES[0])
    rows.append(r / p.spacing_sd_m)
    rhs.append(expected_spacing_m / p.spacing_sd_m)
    A_all, b_all = np.asarray(rows), np.asarray(rhs)
    x, *_ = np.linalg.lstsq(A_all, b_all, rcond=None)
    cov_x = np.linalg.inv(A_all.T @ A_all)
    sd = np.sqrt(np.diag(cov_x))
    centers = {side: R @ x[3 * k : 3 * k + 3] for k, side in enumerate(SIDES)}
    stds = {side: sd[3 * k : 3 * k + 3] for k, side in enumerate(SIDES)}
    spacing = float(np.linalg.norm(centers["right"] - centers["left"]))
    return JointHips(centers, stds, spacing)


def shared_pelvis(
    center_m: dict[str, FloatArray],
    std_m: dict[str, FloatArray],
    knee_axis_in_pelvis: dict[str, FloatArray],
    up_in_pelvis: FloatArray,
    *,
    height_m: float,
    params: PelvisParams | None = None,
) -> SharedPelvis:
    """The one pelvis frame of both legs and the two hip centres estimated with it.

    Args:
        center_m: ``{side: (3,)}`` single-leg hip centres, pelvis sensor frame, m.
        std_m: ``{side: (3,)}`` their reported standard deviations, pelvis sensor frame, m.
        knee_axis_in_pelvis: ``{side: (3,)}`` each knee axis (pointing right) carried into the
            pelvis sensor frame at the standing reference (each leg's own pelvis z).
        up_in_pelvis: (3,) specific force of the pelvis sensor at the standing reference
            (points up), m/s² or any length.
        height_m: subject stature (de Leva's hip spacing), m.
        params: uncertainties (defaults: :class:`PelvisParams`).
    """
    p = params or PelvisParams()
    up = _unit(up_in_pelvis)
    c = {s: np.asarray(center_m[s], dtype=float) for s in SIDES}
    s_rep = {s: _finite_or_zero(std_m[s]) for s in SIDES}
    zl, zr = _unit(knee_axis_in_pelvis["left"]), _unit(knee_axis_in_pelvis["right"])
    apart = float(np.degrees(np.arccos(np.clip(zl @ zr, -1.0, 1.0))))
    if not apart <= p.max_knee_axes_angle_deg:
        raise OppositeKneesError(apart)
    knees = _horizontal(zl + zr, up)
    line = c["right"] - c["left"]
    hline = _horizontal(line, up)
    # heading variance of the hip line: the centres' errors across it, over its horizontal length
    across = np.cross(up, hline)
    var_across = sum(float((across**2) @ (s_rep[s] ** 2)) + p.model_std_m**2 for s in SIDES)
    length = float(np.linalg.norm(line - (line @ up) * up))
    var_line = var_across / max(length, 1e-3) ** 2
    var_knees = np.deg2rad(p.knee_heading_sd_deg) ** 2 / 2.0
    w_line = (1.0 / var_line) / (1.0 / var_line + 1.0 / var_knees) if line @ knees > 0 else 0.0
    # weighted mean heading about "up", measured from the knee-axes mean
    ang = float(np.arctan2(np.cross(knees, hline) @ up, knees @ hline))
    turn = w_line * ang
    right = np.cos(turn) * knees + np.sin(turn) * np.cross(up, knees)
    R = pelvis_frame(up, right)
    expected = hip_spacing_m(height_m)
    hips = joint_hip_centers(c, s_rep, R, expected, p)
    return SharedPelvis(
        R_sensor_pelvis=R,
        hips=hips,
        single_leg_center_m=c,
        single_leg_spacing_m=float(np.linalg.norm(line)),
        expected_spacing_m=expected,
        legs_axes_angle_deg=float(np.degrees(np.arccos(np.clip(zl @ zr, -1.0, 1.0)))),
        hip_line_weight=float(w_line),
        hip_line_to_knees_deg=float(np.degrees(ang)),
    )
