"""Segment-to-joint (S2J) vector models M1–M3 of Lee & Lee 2022 (§2.2, §2.4).

- **M1**: constant S2J vectors (the calibration's joint centres).
- **M2**: every S2J component as a Nadaraya–Watson regression on the flexion
  of its joint.
- **M3**: a bivariate regression on two angles — hip: hip flexion and
  adduction (the paper says abduction; the sign does not matter to a
  regression); knee: knee and hip flexion; ankle: ankle dorsiflexion and
  knee flexion.

(M4 of the paper is M3 evaluated with angles and orientations estimated from
the IMUs: same model, different inputs.)

Per joint J the model gives ``s_prox`` (parent sensor -> J, parent sensor
frame) and ``s_dist`` (child sensor -> J, child sensor frame), in metres;
the sensors of each joint are :data:`lowerlimb.conventions.JOINT_SENSORS`.
Joint angles are (N, 9) arrays in radians, columns in the order of
``angles.csv`` (:data:`lowerlimb.conventions.ANGLE_COLUMNS` without
``time``). The model is saved as a JSON sidecar (``to_dict``/``from_dict``)
next to ``calibration.json``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, cast

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import ANGLE_COLUMNS, JOINT_SENSORS, JOINTS, FloatArray
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.s2j.reference_kf import ReferenceKFParams, ReferenceS2J, estimate_reference_s2j
from lowerlimb.s2j.regression import KernelRegression, KernelRegressionParams, fit_kernel_regression
from lowerlimb.s2j.relative_position import (
    reference_relative_position,
    relative_rotation,
    segment_relative_positions,
)

if TYPE_CHECKING:
    from lowerlimb.calibration import LegCalibration

Method = Literal["M1", "M2", "M3"]
METHODS: tuple[str, ...] = ("M1", "M2", "M3")
#: Format tag of :meth:`S2JModel.to_dict`.
FORMAT = "lowerlimb-s2j/1"
#: Joint-angle columns (radians, ``angles.csv`` order) of the (N, 9) input arrays.
ANGLE_NAMES: tuple[str, ...] = ANGLE_COLUMNS[1:]
#: Angles each regression method uses per joint (Lee & Lee 2022, §2.2).
REGRESSION_INPUTS: dict[str, dict[str, tuple[str, ...]]] = {
    "M2": {
        "hip": ("hip_flexion",),
        "knee": ("knee_flexion",),
        "ankle": ("ankle_dorsiflexion",),
    },
    "M3": {
        "hip": ("hip_flexion", "hip_adduction"),
        "knee": ("knee_flexion", "hip_flexion"),
        "ankle": ("ankle_dorsiflexion", "knee_flexion"),
    },
}

S2JPair = tuple[FloatArray, FloatArray]


def _check_method(method: str) -> Method:
    if method not in METHODS:
        raise InputError(f"unknown S2J method {method!r}; use one of {list(METHODS)}")
    return cast(Method, method)


def _angles(joint_angles_rad: ArrayLike) -> FloatArray:
    """Validate an (N, 9) joint-angle array in radians."""
    a = np.asarray(joint_angles_rad, dtype=float)
    if a.ndim != 2 or a.shape[1] != len(ANGLE_NAMES):
        raise ShapeError(
            f"joint_angles_rad must have shape (N, 9), columns {list(ANGLE_NAMES)} in radians, got {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise InputError("joint_angles_rad contains NaN or infinite values; fill the gaps first")
    if np.abs(a).max(initial=0.0) > 2.0 * np.pi:
        raise InputError(
            f"joint angles up to {np.abs(a).max():.0f} look like degrees; the S2J model "
            f"expects radians (multiply by π/180)"
        )
    return a


def _columns(names: Sequence[str]) -> list[int]:
    return [ANGLE_NAMES.index(n) for n in names]


def _constant(constant: Mapping[str, tuple[ArrayLike, ArrayLike]]) -> dict[str, S2JPair]:
    """Validate per-joint constant S2J vectors."""
    out: dict[str, S2JPair] = {}
    for joint in JOINTS:
        if joint not in constant:
            raise InputError(
                f"constant S2J vectors for joint '{joint}' are missing (got {sorted(constant)}); "
                f"pass {{joint: (center_in_parent_sensor, center_in_child_sensor)}} for "
                f"{list(JOINTS)}, e.g. from constant_s2j_from_calibration()"
            )
        sp = np.asarray(constant[joint][0], dtype=float)
        sd = np.asarray(constant[joint][1], dtype=float)
        if sp.shape != (3,) or sd.shape != (3,):
            raise ShapeError(
                f"constant S2J vectors of '{joint}' must have shape (3,) (metres), "
                f"got {sp.shape} and {sd.shape}"
            )
        if not (np.all(np.isfinite(sp)) and np.all(np.isfinite(sd))):
            raise InputError(f"constant S2J vectors of '{joint}' contain NaN or infinite values")
        out[joint] = (sp.copy(), sd.copy())
    return out


def constant_s2j_from_calibration(calibration: LegCalibration | Mapping[str, Any]) -> dict[str, S2JPair]:
    """Constant (M1) S2J vectors from a joint calibration.

    Args:
        calibration: a :class:`~lowerlimb.calibration.LegCalibration`, or the
            parsed ``calibration.json`` (or the simulator's ``truth``) with
            ``joints.<joint>.center_in_parent_sensor`` and
            ``center_in_child_sensor`` in metres (docs/formats.md).

    Returns:
        Joint -> ``(s_prox (3,), s_dist (3,))``, m, parent / child sensor frames.

    Raises:
        InputError: when a joint or centre is missing.
    """
    if not isinstance(calibration, Mapping) and hasattr(calibration, "joints"):
        return _constant(
            {j: (c.center_in_parent_sensor, c.center_in_child_sensor) for j, c in calibration.joints.items()}
        )
    joints = calibration.get("joints") if isinstance(calibration, Mapping) else None
    if not isinstance(joints, Mapping):
        raise InputError("calibration has no 'joints' mapping; pass the parsed calibration.json dictionary")
    out: dict[str, tuple[ArrayLike, ArrayLike]] = {}
    for joint in JOINTS:
        rec = joints.get(joint)
        if not isinstance(rec, Mapping) or not {
            "center_in_parent_sensor",
            "center_in_child_sensor",
        } <= set(rec):
            raise InputError(
                f"calibration joint '{joint}' lacks center_in_parent_sensor / "
                f"center_in_child_sensor; re-run `lowerlimb calibrate`"
            )
        out[joint] = (rec["center_in_parent_sensor"], rec["center_in_child_sensor"])
    return _constant(out)


def reference_s2j_from_poses(
    constant: Mapping[str, tuple[ArrayLike, ArrayLike]],
    quat_wxyz: Mapping[str, ArrayLike],
    sensor_pos_m: Mapping[str, ArrayLike],
    *,
    rate_hz: float,
    params: ReferenceKFParams | None = None,
) -> dict[str, ReferenceS2J]:
    """Reference S2J vectors of the three joints from reference sensor poses (eq. 4–6).

    Args:
        constant: joint -> constant ``(s_prox (3,), s_dist (3,))``, m.
        quat_wxyz: sensor -> (N, 4) reference orientation, w, x, y, z, sensor -> earth.
        sensor_pos_m: sensor -> (N, 3) reference position in the earth frame, m.
        rate_hz: sampling rate, Hz.
        params: Kalman filter noise settings.

    Returns:
        Joint -> per-sample reference S2J vectors.

    Raises:
        InputError: when a sensor is missing or on NaN values.
        ShapeError: on wrong shapes.
    """
    const = _constant(constant)
    out: dict[str, ReferenceS2J] = {}
    for joint in JOINTS:
        parent, child, _ = JOINT_SENSORS[joint]
        for sensor in (parent, child):
            if sensor not in quat_wxyz or sensor not in sensor_pos_m:
                raise InputError(
                    f"reference pose of sensor '{sensor}' is missing; pass orientations and "
                    f"positions for pelvis, thigh, shank and foot"
                )
        R_pd = relative_rotation(quat_wxyz[parent], quat_wxyz[child])
        p_ref = reference_relative_position(sensor_pos_m[parent], quat_wxyz[parent], sensor_pos_m[child])
        out[joint] = estimate_reference_s2j(
            R_pd, p_ref, const[joint][0], const[joint][1], rate_hz=rate_hz, params=params
        )
    return out


@dataclass
class S2JModel:
    """Time-varying (or constant) S2J vectors of the hip, knee and ankle.

    Attributes:
        method: ``"M1"`` (constant), ``"M2"`` (one angle) or ``"M3"`` (two angles).
        constant: joint -> constant ``(s_prox (3,), s_dist (3,))``, m.
        regressions: joint -> fitted regression of ``[s_prox; s_dist]`` (6
            outputs, m) on the angles :data:`REGRESSION_INPUTS` [method][joint];
            empty for M1.
        metadata: free-form JSON-serialisable information (training trials,
            KF settings...).
    """

    method: Method
    constant: dict[str, S2JPair]
    regressions: dict[str, KernelRegression] = field(default_factory=dict)
    metadata: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.method = _check_method(self.method)
        self.constant = _constant(self.constant)
        if self.method != "M1":
            for joint in JOINTS:
                reg = self.regressions.get(joint)
                want = len(REGRESSION_INPUTS[self.method][joint])
                if reg is None or reg.n_inputs != want or reg.n_outputs != 6:
                    raise InputError(
                        f"{self.method} needs a regression for '{joint}' with {want} input(s) "
                        f"and 6 outputs; build the model with S2JModel.fit()"
                    )

    @property
    def inputs(self) -> dict[str, tuple[str, ...]]:
        """Joint -> names of the angles the regression uses (empty for M1)."""
        if self.method == "M1":
            return {j: () for j in JOINTS}
        return dict(REGRESSION_INPUTS[self.method])

    @classmethod
    def fit_reference(
        cls,
        method: str,
        constant: Mapping[str, tuple[ArrayLike, ArrayLike]],
        joint_angles_rad: ArrayLike,
        reference: Mapping[str, tuple[ArrayLike, ArrayLike]],
        *,
        params: KernelRegressionParams | None = None,
    ) -> S2JModel:
        """Fit the regressions to given reference S2J vectors.

        Use this to train on several trials: run
        :func:`reference_s2j_from_poses` per trial and concatenate.

        Args:
            method: ``"M1"``, ``"M2"`` or ``"M3"``.
            constant: joint -> constant ``(s_prox (3,), s_dist (3,))``, m.
            joint_angles_rad: (N, 9) joint angles, rad, ``angles.csv`` order.
            reference: joint -> ``(s_prox (N, 3), s_dist (N, 3))`` reference
                S2J vectors, m (ignored for M1).
            params: kernel-regression settings.

        Returns:
            The fitted model.

        Raises:
            InputError: on an unknown method, missing joints, NaN values or
                angles that look like degrees.
            ShapeError: on wrong shapes.
        """
        m = _check_method(method)
        const = _constant(constant)
        if m == "M1":
            return cls(method=m, constant=const)
        angles = _angles(joint_angles_rad)
        regs: dict[str, KernelRegression] = {}
        for joint in JOINTS:
            if joint not in reference:
                raise InputError(
                    f"reference S2J vectors for joint '{joint}' are missing; pass "
                    f"{{joint: (s_prox (N, 3), s_dist (N, 3))}} for {list(JOINTS)}"
                )
            sp = np.asarray(reference[joint][0], dtype=float)
            sd = np.asarray(reference[joint][1], dtype=float)
            if sp.shape != (angles.shape[0], 3) or sd.shape != sp.shape:
                raise ShapeError(
                    f"reference S2J vectors of '{joint}' must have shape (N, 3) = "
                    f"{(angles.shape[0], 3)} like joint_angles_rad, got {sp.shape}, {sd.shape}"
                )
            x = angles[:, _columns(REGRESSION_INPUTS[m][joint])]
            regs[joint] = fit_kernel_regression(x, np.hstack([sp, sd]), params)
        return cls(method=m, constant=const, regressions=regs)

    @classmethod
    def fit(
        cls,
        method: str,
        constant: Mapping[str, tuple[ArrayLike, ArrayLike]],
        joint_angles_rad: ArrayLike,
        *,
        quat_wxyz: Mapping[str, ArrayLike] | None = None,
        sensor_pos_m: Mapping[str, ArrayLike] | None = None,
        rate_hz: float | None = None,
        kf_params: ReferenceKFParams | None = None,
        params: KernelRegressionParams | None = None,
    ) -> S2JModel:
        """Fit a model to one training trial with reference poses (paper §2.3–2.4).

        Runs the reference Kalman filter (eq. 4–6) on every joint, then the
        kernel regressions. For M1 only ``constant`` is used.

        Args:
            method: ``"M1"``, ``"M2"`` or ``"M3"``.
            constant: joint -> constant ``(s_prox (3,), s_dist (3,))``, m
                (e.g. :func:`constant_s2j_from_calibration`).
            joint_angles_rad: (N, 9) reference joint angles, rad, ``angles.csv`` order.
            quat_wxyz: sensor -> (N, 4) reference orientation, w, x, y, z, sensor -> earth.
            sensor_pos_m: sensor -> (N, 3) reference position, earth frame, m.
            rate_hz: sampling rate, Hz.
            kf_params: reference-KF noise settings.
            params: kernel-regression settings.

        Returns:
            The fitted model; ``metadata`` records the KF settings and the
            constraint residuals.

        Raises:
            InputError: on an unknown method, missing poses or joints, NaN
                values or angles that look like degrees.
            ShapeError: on wrong shapes.
        """
        m = _check_method(method)
        if m == "M1":
            return cls(method=m, constant=_constant(constant))
        if quat_wxyz is None or sensor_pos_m is None or rate_hz is None:
            raise InputError(
                f"{m} learns from reference poses: pass quat_wxyz, sensor_pos_m and rate_hz "
                f"(or use S2JModel.fit_reference with precomputed reference vectors)"
            )
        angles = _angles(joint_angles_rad)
        kf = kf_params if kf_params is not None else ReferenceKFParams()
        ref = reference_s2j_from_poses(constant, quat_wxyz, sensor_pos_m, rate_hz=rate_hz, params=kf)
        for joint in JOINTS:
            if ref[joint].s_prox_m.shape[0] != angles.shape[0]:
                raise ShapeError(
                    f"joint_angles_rad has {angles.shape[0]} samples but the poses have "
                    f"{ref[joint].s_prox_m.shape[0]}; pass the same samples"
                )
        model = cls.fit_reference(
            m,
            constant,
            angles,
            {j: (r.s_prox_m, r.s_dist_m) for j, r in ref.items()},
            params=params,
        )
        model.metadata = {
            "kf_params": {
                "constant_noise_m": kf.constant_noise_m,
                "position_noise_m": kf.position_noise_m,
                "process_noise_m_per_sqrt_s": kf.process_noise_m_per_sqrt_s,
                "smooth": kf.smooth,
            },
            "kf_constraint_rms_m": {j: r.constraint_rms_m for j, r in ref.items()},
            "n_training_samples": int(angles.shape[0]),
        }
        return model

    def predict(self, joint_angles_rad: ArrayLike) -> dict[str, S2JPair]:
        """S2J vectors at every sample.

        Args:
            joint_angles_rad: (N, 9) joint angles, rad, ``angles.csv`` order
                (only the columns of :attr:`inputs` are read; M1 uses only N).

        Returns:
            Joint -> ``(s_prox (N, 3), s_dist (N, 3))``, m, in the parent and
            child sensor frames.

        Raises:
            ShapeError: when the angles are not (N, 9).
            InputError: on NaN values or angles that look like degrees.
        """
        angles = _angles(joint_angles_rad)
        n = angles.shape[0]
        out: dict[str, S2JPair] = {}
        for joint in JOINTS:
            if self.method == "M1":
                sp, sd = self.constant[joint]
                out[joint] = (np.tile(sp, (n, 1)), np.tile(sd, (n, 1)))
            else:
                cols = _columns(REGRESSION_INPUTS[self.method][joint])
                y = self.regressions[joint].predict(angles[:, cols])
                out[joint] = (y[:, :3], y[:, 3:])
        return out

    def relative_positions(
        self, joint_angles_rad: ArrayLike, quat_wxyz: Mapping[str, ArrayLike]
    ) -> dict[str, FloatArray]:
        """Relative sensor positions with this model's S2J vectors (eq. 2–3).

        Args:
            joint_angles_rad: (N, 9) joint angles, rad, ``angles.csv`` order.
            quat_wxyz: sensor -> (N, 4) orientation, w, x, y, z, sensor -> earth.

        Returns:
            ``pelvis_thigh``, ``thigh_shank``, ``shank_foot``, ``pelvis_foot``
            -> (N, 3), m, in the proximal sensor frame
            (:func:`lowerlimb.s2j.relative_position.segment_relative_positions`).

        Raises:
            ShapeError: on wrong shapes or mismatched numbers of samples.
            InputError: on NaN values or missing sensors.
        """
        s2j = self.predict(joint_angles_rad)
        return segment_relative_positions(dict(s2j), quat_wxyz)

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable dictionary (format ``lowerlimb-s2j/1``)."""
        return {
            "format": FORMAT,
            "method": self.method,
            "units": "m, rad",
            "angle_columns": list(ANGLE_NAMES),
            "joints": {
                joint: {
                    "parent_sensor": JOINT_SENSORS[joint][0],
                    "child_sensor": JOINT_SENSORS[joint][1],
                    "center_in_parent_sensor": [float(v) for v in self.constant[joint][0]],
                    "center_in_child_sensor": [float(v) for v in self.constant[joint][1]],
                    "inputs": list(self.inputs[joint]),
                    "regression": (self.regressions[joint].to_dict() if joint in self.regressions else None),
                }
                for joint in JOINTS
            },
            "metadata": self.metadata,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> S2JModel:
        """Inverse of :meth:`to_dict`.

        Raises:
            InputError: when the dictionary is not an S2J model record.
        """
        if not isinstance(data, Mapping) or data.get("format") != FORMAT:
            got = data.get("format") if isinstance(data, Mapping) else type(data).__name__
            raise InputError(
                f"not an S2J model record (format {got!r}, expected {FORMAT!r}); "
                f"write it with S2JModel.to_dict()"
            )
        method = _check_method(str(data.get("method")))
        joints = data.get("joints")
        if not isinstance(joints, Mapping):
            raise InputError("S2J model record has no 'joints' mapping; write it with to_dict()")
        const = constant_s2j_from_calibration({"joints": joints})
        regs: dict[str, KernelRegression] = {}
        if method != "M1":
            for joint in JOINTS:
                rec = joints[joint].get("regression")
                if rec is None:
                    raise InputError(f"{method} record lacks the regression of '{joint}'")
                regs[joint] = KernelRegression.from_dict(rec)
        return cls(
            method=method,
            constant=const,
            regressions=regs,
            metadata=dict(data.get("metadata") or {}),
        )
