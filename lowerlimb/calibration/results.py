"""Result dataclasses of the joint calibration, with ``to_dict``/``from_dict`` in the calibration.json schema.

The required keys of docs/formats.md (``type``, ``parent_sensor``, ``child_sensor``,
``center_in_parent_sensor``, ``center_in_child_sensor``, ``axis_in_*_sensor``
for the knee, ``rms_residual``; metres) come first; the extra keys carry the
diagnostics: standard deviations from the Gauss–Newton covariance, condition
numbers, singular values, excitation warnings and solver statistics.
``from_dict`` accepts both a full dictionary and one with only the required
keys (e.g. the simulator's truth).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lowerlimb.calibration.excitation import ExcitationReport
from lowerlimb.calibration.pair_band import PairBand
from lowerlimb.conventions import FloatArray

__all__ = ["SphericalJointCalibration", "HingeAxisCalibration", "HingeJointCalibration"]


def _vec(v: Any) -> FloatArray:
    return np.asarray(v, dtype=float).reshape(3)


def _list(v: FloatArray) -> list[float]:
    return [float(x) for x in np.asarray(v).ravel()]


def _num(v: float) -> float | None:
    """A JSON-safe number: non-finite values become ``None`` (null)."""
    return float(v) if np.isfinite(v) else None


def _shift(d: dict[str, Any], key_prefix: str, kind: str) -> FloatArray:
    """(6,) a recorded ``center_{kind}_shift_in_*_sensor`` pair, NaN for a frame not recorded."""
    keys = (f"{key_prefix}center_{kind}_shift_in_{f}_sensor" for f in ("parent", "child"))
    return np.concatenate([_vec(d.get(k, [np.nan] * 3)) for k in keys])


def _opt_list(v: FloatArray) -> list[float | None]:
    return [_num(float(x)) for x in np.asarray(v).ravel()]


def _from_num(v: Any) -> float:
    return float("nan") if v is None else float(v)


@dataclass
class SphericalJointCalibration:
    """Joint centre of a spherical joint (or a point on a hinge axis) in both sensor frames.

    Attributes:
        joint: joint name (``"hip"``, ``"ankle"``, ``"knee"`` or a user's name).
        parent_sensor: name of the proximal sensor.
        child_sensor: name of the distal sensor.
        center_in_parent_sensor: (3,) joint centre in the parent sensor frame, m.
        center_in_child_sensor: (3,) joint centre in the child sensor frame, m.
        rms_residual: RMS of the residual of Hu 2021 eq. 3 at the solution, m/s².
        excitation: identifiability report; its ``std`` is (6,) m for
            ``(c_parent, c_child)``. ``None`` when loaded from a minimal dictionary.
        method: calibration method (``"casadi"``, ``"gn"``, ``"dwpso"`` …).
        solver: the solver's own name (e.g. ``"casadi_lsq/gauss_newton"``).
        iterations: solver iterations.
        converged: whether the solver's stopping test was met.
        solve_time_s: wall time of the solve, s.
        warnings: excitation warnings (also issued as :class:`ExcitationWarning`).
        impact_excluded_fraction: fraction of the samples left out of the fit near
            impacts (0–1; :mod:`~lowerlimb.calibration.impact_window`); the residual
            and the excitation report are those of the samples used.
        cutoff_shift: (6,) how far ``(c_parent, c_child)`` move when the fit is
            repeated with every prefilter cut-off widened by half
            (:mod:`~lowerlimb.calibration.cutoff_probe`), m; NaN when not probed. A
            systematic spread that the noise-based ``std`` does not see.
        split_half_shift: (6,) half the difference of ``(c_parent, c_child)`` fitted on
            the recording's second and first half (:mod:`~lowerlimb.calibration.split_half`),
            m; NaN when not probed (in the pelvis sensor when the aligned form places the hip).
        norm_center_in_parent_sensor: (3,) the norm form's parent-frame centre where the
            aligned form replaced it (the hip in the pelvis sensor), m; ``None`` otherwise.
            The clock search compares the joint's acceleration norms at the norm form's
            centres (:func:`~lowerlimb.calibration.clock_sync.estimate_lags`). Not written
            to calibration.json.
        pair_band: a two-IMU fit's band test (:mod:`~lowerlimb.calibration.pair_band`):
            whether it kept the pair's rigid-band cap; ``None`` where no cap applied (and
            in a leg's joints, which are always capped).
    """

    joint: str
    parent_sensor: str
    child_sensor: str
    center_in_parent_sensor: FloatArray
    center_in_child_sensor: FloatArray
    rms_residual: float
    excitation: ExcitationReport | None = None
    method: str = ""
    solver: str = ""
    iterations: int = 0
    converged: bool = True
    solve_time_s: float = 0.0
    warnings: list[str] = field(default_factory=list)
    impact_excluded_fraction: float = 0.0
    cutoff_shift: FloatArray = field(default_factory=lambda: np.full(6, np.nan))
    split_half_shift: FloatArray = field(default_factory=lambda: np.full(6, np.nan))
    norm_center_in_parent_sensor: FloatArray | None = None
    pair_band: PairBand | None = None

    @property
    def center_std_in_parent_sensor(self) -> FloatArray:
        """(3,) standard deviation of the parent-frame centre, m (NaN when unknown)."""
        return self.excitation.std[:3] if self.excitation is not None else np.full(3, np.nan)

    @property
    def center_std_in_child_sensor(self) -> FloatArray:
        """(3,) standard deviation of the child-frame centre, m (NaN when unknown)."""
        return self.excitation.std[3:6] if self.excitation is not None else np.full(3, np.nan)

    def largest_shift(self, shift: FloatArray, above_m: float = 0.0) -> tuple[str, float] | None:
        """The sensor in whose frame a (6,) ``(c_parent, c_child)`` shift is largest, and its length, m.

        A frame whose shift is NaN (not probed) is left out; ``None`` when neither was probed
        or the largest is not above ``above_m``.
        """
        s = np.asarray(shift, dtype=float)
        moved = {
            name: float(np.linalg.norm(part))
            for name, part in ((self.parent_sensor, s[:3]), (self.child_sensor, s[3:6]))
            if np.all(np.isfinite(part))
        }
        if not moved:
            return None
        worst = max(moved, key=lambda k: moved[k])
        return (worst, moved[worst]) if moved[worst] > above_m else None

    def to_dict(self) -> dict[str, Any]:
        """The calibration.json entry of a spherical joint (required keys, then extras)."""
        d: dict[str, Any] = {
            "type": "spherical",
            "parent_sensor": self.parent_sensor,
            "child_sensor": self.child_sensor,
            "center_in_parent_sensor": _list(self.center_in_parent_sensor),
            "center_in_child_sensor": _list(self.center_in_child_sensor),
            "rms_residual": float(self.rms_residual),
        }
        d.update(self._extras())
        return d

    def _extras(self) -> dict[str, Any]:
        d: dict[str, Any] = {"rms_residual_unit": "m/s^2"}
        if self.excitation is not None:
            d["center_std_in_parent_sensor"] = _opt_list(self.center_std_in_parent_sensor)
            d["center_std_in_child_sensor"] = _opt_list(self.center_std_in_child_sensor)
            cn = self.excitation.condition_number
            d["condition_number"] = float(cn) if np.isfinite(cn) else None
            d["excitation"] = self.excitation.to_dict()
        d.update(
            method=self.method,
            solver=self.solver,
            iterations=int(self.iterations),
            converged=bool(self.converged),
            solve_time_s=float(self.solve_time_s),
            warnings=list(self.warnings),
            impact_excluded_fraction=float(self.impact_excluded_fraction),
        )
        if self.pair_band is not None:
            d["pair_band"] = self.pair_band.to_dict()
        for key, shift in (("cutoff", self.cutoff_shift), ("split_half", self.split_half_shift)):
            for frame, part in (("parent", shift[:3]), ("child", shift[3:6])):
                if np.all(np.isfinite(part)):
                    d[f"center_{key}_shift_in_{frame}_sensor"] = _list(part)
        return d

    @classmethod
    def from_dict(
        cls, d: dict[str, Any], joint: str = "", *, key_prefix: str = ""
    ) -> SphericalJointCalibration:
        """Inverse of :meth:`to_dict` (extras optional)."""
        exc = d.get(key_prefix + "excitation")
        band = d.get(key_prefix + "pair_band")
        return cls(
            joint=joint or d.get("joint", ""),
            parent_sensor=d["parent_sensor"],
            child_sensor=d["child_sensor"],
            center_in_parent_sensor=_vec(d["center_in_parent_sensor"]),
            center_in_child_sensor=_vec(d["center_in_child_sensor"]),
            rms_residual=float(d.get(key_prefix + "rms_residual", d.get("rms_residual", 0.0))),
            excitation=ExcitationReport.from_dict(exc) if exc else None,
            method=d.get("method", ""),
            solver=d.get(key_prefix + "solver", d.get("solver", "")),
            iterations=int(d.get(key_prefix + "iterations", d.get("iterations", 0))),
            converged=bool(d.get(key_prefix + "converged", d.get("converged", True))),
            solve_time_s=float(d.get(key_prefix + "solve_time_s", d.get("solve_time_s", 0.0))),
            warnings=list(d.get(key_prefix + "warnings", [])),
            impact_excluded_fraction=float(d.get(key_prefix + "impact_excluded_fraction", 0.0)),
            cutoff_shift=_shift(d, key_prefix, "cutoff"),
            split_half_shift=_shift(d, key_prefix, "split_half"),
            pair_band=PairBand.from_dict(band) if band else None,
        )


def _axis_rms(d: dict[str, Any]) -> float:
    if "axis_fit" in d:
        return _from_num(d["axis_fit"].get("rms_residual"))
    if "rms_residual_axis" in d:
        return _from_num(d["rms_residual_axis"])
    if "center_in_parent_sensor" in d:  # a minimal knee entry: its rms_residual is the centre's
        return float("nan")
    return _from_num(d.get("rms_residual"))


@dataclass
class HingeAxisCalibration:
    """Hinge axis in both sensor frames, unit vectors with the same physical direction.

    Attributes:
        joint: joint name.
        parent_sensor: name of the proximal sensor.
        child_sensor: name of the distal sensor.
        axis_in_parent_sensor: (3,) unit axis in the parent sensor frame.
        axis_in_child_sensor: (3,) unit axis in the child sensor frame.
        rms_residual: RMS of the residual of Hu 2021 eq. 6, rad/s.
        excitation: identifiability report in the local angle parametrisation
            (x = tilts of each axis, rad, about two orthogonal directions).
        axis_std_deg: (2,) standard deviation of the parent and child axis directions, deg.
        sign_coherence: (2,) coherence (0–1) of the relative rotation for the
            chosen and the rejected relative sign (see ``hinge_axis``).
        flexion_sign_margin: how clearly the sign rule chose the overall sign
            (> 0; near 0 means ambiguous), rad.
        acc_sign_correlation: correlation of the joint-centre accelerations
            along the two axes (> 0: consistent signs); NaN when not checked.
        method: calibration method.
        solver: the solver's own name.
        iterations: solver iterations (all starts and the polish).
        converged: whether the final solve met its stopping test.
        solve_time_s: wall time, s.
        warnings: excitation and sign warnings.
    """

    joint: str
    parent_sensor: str
    child_sensor: str
    axis_in_parent_sensor: FloatArray
    axis_in_child_sensor: FloatArray
    rms_residual: float
    excitation: ExcitationReport | None = None
    axis_std_deg: FloatArray = field(default_factory=lambda: np.full(2, np.nan))
    sign_coherence: FloatArray = field(default_factory=lambda: np.full(2, np.nan))
    flexion_sign_margin: float = float("nan")
    acc_sign_correlation: float = float("nan")
    method: str = ""
    solver: str = ""
    iterations: int = 0
    converged: bool = True
    solve_time_s: float = 0.0
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Axis keys of the calibration.json knee entry (plus extras)."""
        d: dict[str, Any] = {
            "axis_in_parent_sensor": _list(self.axis_in_parent_sensor),
            "axis_in_child_sensor": _list(self.axis_in_child_sensor),
            "rms_residual": _num(self.rms_residual),
            "rms_residual_unit": "rad/s",
            "axis_std_deg_in_parent_sensor": _num(self.axis_std_deg[0]),
            "axis_std_deg_in_child_sensor": _num(self.axis_std_deg[1]),
            "sign_coherence": _opt_list(self.sign_coherence),
            "flexion_sign_margin": _num(self.flexion_sign_margin),
            "acc_sign_correlation": _num(self.acc_sign_correlation),
            "method": self.method,
            "solver": self.solver,
            "iterations": int(self.iterations),
            "converged": bool(self.converged),
            "solve_time_s": float(self.solve_time_s),
            "warnings": list(self.warnings),
        }
        if self.excitation is not None:
            cn = self.excitation.condition_number
            d["condition_number"] = float(cn) if np.isfinite(cn) else None
            d["excitation"] = self.excitation.to_dict()
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], joint: str = "") -> HingeAxisCalibration:
        """Inverse of :meth:`to_dict`; also accepts a knee entry of calibration.json."""
        fit = d.get("axis_fit", d)
        exc = fit.get("excitation")
        return cls(
            joint=joint,
            parent_sensor=d.get("parent_sensor", ""),
            child_sensor=d.get("child_sensor", ""),
            axis_in_parent_sensor=_vec(d["axis_in_parent_sensor"]),
            axis_in_child_sensor=_vec(d["axis_in_child_sensor"]),
            rms_residual=_axis_rms(d),
            excitation=ExcitationReport.from_dict(exc) if exc else None,
            axis_std_deg=np.array(
                [
                    _from_num(fit.get("axis_std_deg_in_parent_sensor")),
                    _from_num(fit.get("axis_std_deg_in_child_sensor")),
                ]
            ),
            sign_coherence=np.array([_from_num(v) for v in fit.get("sign_coherence", [None] * 2)]),
            flexion_sign_margin=_from_num(fit.get("flexion_sign_margin")),
            acc_sign_correlation=_from_num(fit.get("acc_sign_correlation")),
            method=fit.get("method", ""),
            solver=fit.get("solver", ""),
            iterations=int(fit.get("iterations", 0)),
            converged=bool(fit.get("converged", True)),
            solve_time_s=float(fit.get("solve_time_s", 0.0)),
            warnings=list(fit.get("warnings", [])),
        )


@dataclass
class HingeJointCalibration:
    """A hinge joint (the knee): its axis and a centre on the axis, in both sensor frames.

    The centre is the point of the axis nearest the two sensors (Hu 2021
    eq. 16); any point of the axis is an equally valid hinge centre, so
    compare centres by their distance to the axis line.

    Attributes:
        axis: the axis estimate.
        center: the centre estimate (spherical residual with the gauge of eq. 16).
    """

    axis: HingeAxisCalibration
    center: SphericalJointCalibration

    @property
    def joint(self) -> str:
        """Joint name."""
        return self.center.joint

    @property
    def parent_sensor(self) -> str:
        """Name of the proximal sensor."""
        return self.center.parent_sensor

    @property
    def child_sensor(self) -> str:
        """Name of the distal sensor."""
        return self.center.child_sensor

    @property
    def axis_in_parent_sensor(self) -> FloatArray:
        """(3,) unit axis in the parent sensor frame."""
        return self.axis.axis_in_parent_sensor

    @property
    def axis_in_child_sensor(self) -> FloatArray:
        """(3,) unit axis in the child sensor frame."""
        return self.axis.axis_in_child_sensor

    @property
    def center_in_parent_sensor(self) -> FloatArray:
        """(3,) centre in the parent sensor frame, m."""
        return self.center.center_in_parent_sensor

    @property
    def center_in_child_sensor(self) -> FloatArray:
        """(3,) centre in the child sensor frame, m."""
        return self.center.center_in_child_sensor

    @property
    def rms_residual(self) -> float:
        """RMS of the centre's spherical residual, m/s² (the axis's is ``axis.rms_residual``)."""
        return self.center.rms_residual

    @property
    def warnings(self) -> list[str]:
        """Warnings of the axis and the centre fits."""
        return self.axis.warnings + self.center.warnings

    def to_dict(self) -> dict[str, Any]:
        """The calibration.json entry of a hinge joint (required keys, then extras).

        ``rms_residual`` is the centre's spherical residual (m/s², as for the
        other joints); the axis residual (rad/s) is ``rms_residual_axis``.
        """
        d: dict[str, Any] = {
            "type": "hinge",
            "parent_sensor": self.parent_sensor,
            "child_sensor": self.child_sensor,
            "axis_in_parent_sensor": _list(self.axis_in_parent_sensor),
            "axis_in_child_sensor": _list(self.axis_in_child_sensor),
            "center_in_parent_sensor": _list(self.center_in_parent_sensor),
            "center_in_child_sensor": _list(self.center_in_child_sensor),
            "rms_residual": float(self.rms_residual),
            "rms_residual_axis": _num(self.axis.rms_residual),
        }
        d.update(self.center._extras())
        d["axis_std_deg_in_parent_sensor"] = _num(self.axis.axis_std_deg[0])
        d["axis_std_deg_in_child_sensor"] = _num(self.axis.axis_std_deg[1])
        d["warnings"] = self.warnings
        d["axis_fit"] = self.axis.to_dict()
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], joint: str = "knee") -> HingeJointCalibration:
        """Inverse of :meth:`to_dict` (extras optional)."""
        axis = HingeAxisCalibration.from_dict(d, joint)
        center = SphericalJointCalibration.from_dict(d, joint)
        center.warnings = [w for w in center.warnings if w not in axis.warnings]
        return cls(axis=axis, center=center)
