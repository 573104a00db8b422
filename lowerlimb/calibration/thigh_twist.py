"""A thigh sensor that turns about the femur as the hip flexes: estimated and undone.

On the real walk of ``../shared/data/gait`` the knee axis found from the thigh sensor and the
one found from the shank sensor differ by 17.5 / 18.5° in elevation at the standing start (left
/ right), where a hinge keeps them equal, and the thigh sensor's rate about the femur minus the
shank's about the tibia follows the thigh's sagittal rate (−0.29 / +0.51 rad/rad). The seven-IMU
simulator reproduces both when the thigh sensor turns internally by 0.3 rad per rad of hip
flexion (``Artefacts.skin_twist_driver["thigh"] = "hip"``: 17–19° of mismatch, the left leg's
negative), and no other of its artefacts does (a twist with knee flexion gives 1–6°;
``benchmarks/results/sim_signatures.md``).

Model (thigh sensor frame ``S``; ``F``, the frame fixed to the femur that ``S`` coincides with
at the standing start)::

    S = F · exp(φ ê),   φ(t) = k ψ(t)

* ``ψ``: the thigh's rotation about the knee's flexion axis ``ĵ`` since the standing start (the
  gyro's ``ĵ`` component integrated, high-passed at ``thigh_twist_highpass_hz`` against drift);
* ``ê``: the femur's long axis, the thigh sensor's up at standing;
* the skin carries the sensor round the femur: its place across the axis ``r₀`` (``F``, ⊥ ``ê``)
  turns with it, ``Δp = (cos φ − 1) r₀ + sin φ (ê × r₀)``.

Undone (:func:`untwist_signals`), with ``ω``, ``α`` the femur's rate and its derivative::

    ω_F = exp(φ ê) ω_S − φ̇ ê
    f_F = exp(φ ê) f_S − [α × Δp + ω × (ω × Δp) + 2 ω × Δṗ + Δp̈]

Estimated (:func:`estimate_thigh_twist`): ``k`` is the root of the standing knee axis mismatch
of a calibration on the untwisted trial (secant steps from ``k = 0``); ``r₀`` is the hip centre's
place across ``ê`` in a calibration on the trial untwisted in rotation only. The gyros' own view
of the turn (:func:`gyro_evidence`) is recorded beside it and a twist it does not confirm is
named (:class:`ThighTwistWarning`). On the simulator
that returns the rigid results (``benchmarks/results/thigh_twist.md``); on the real walk it
brings the two legs' pelvis frames together and the knee flexion nearer Vicon's, but puts both
thighs 30–80 mm longer than Plug-in Gait's, so it is off by default
(``CalibrationOptions.thigh_twist``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.signal import butter, sosfiltfilt
from scipy.spatial.transform import Rotation

from ..conventions import FloatArray
from ..errors import InputError
from ..io.trial import ImuTrial
from .knee_line import standing_axis_mismatch
from .options import CalibrationOptions

if TYPE_CHECKING:
    from .leg import LegCalibration

__all__ = [
    "ThighTwist",
    "ThighTwistWarning",
    "estimate_thigh_twist",
    "gyro_evidence",
    "standing_mismatch_deg",
    "untwist_signals",
    "untwist_trial",
]


class ThighTwistWarning(UserWarning):
    """The thigh twist undone is not what the gyros alone see (:meth:`ThighTwist.confirmed`)."""


def unconfirmed_message(twist: ThighTwist) -> str:
    """The warning for a twist the gyros do not confirm (one line)."""
    e = twist.gyro_evidence
    seen = f"{e:+.2f}" if np.isfinite(e) else "nothing (too little knee motion)"
    return (
        f"thigh twist: the knee axes at standing call for a thigh sensor turning {twist.per_flexion:+.2f} "
        f"rad per rad of the thigh's flexion, but its gyro shows {seen}: the mismatch "
        f"may have another cause (a shank sensor that turns, a knee that is no hinge); it was undone all "
        f"the same, compare with a run without --thigh-twist"
    )


@dataclass(frozen=True)
class ThighTwist:
    """How the thigh sensor turns about the femur with the thigh's flexion (module docstring).

    Attributes:
        per_flexion: ``k``, rad of the sensor's turn about ``axis_in_sensor`` per rad of the
            thigh's rotation about ``flexion_axis_in_sensor`` (signed; 0: none).
        axis_in_sensor: (3,) ``ê``, the femur's long axis in the thigh sensor frame (up at standing).
        flexion_axis_in_sensor: (3,) ``ĵ``, the knee's flexion axis made orthogonal to ``ê``.
        offset_from_axis_m: (3,) ``r₀``, the sensor's place across the femur axis, thigh
            sensor frame, m (zeros: the sensor turns in place).
        mismatch_before_deg: the standing knee axis mismatch before, degrees.
        mismatch_after_deg: the same after the twist is undone, degrees.
        highpass_hz: the high-pass of the flexion angle ``ψ``, Hz.
        gyro_evidence: the same turn as the gyros alone see it (:func:`gyro_evidence`),
            rad/rad; near ``per_flexion`` when the mismatch is the thigh sensor's turn.
    """

    per_flexion: float
    axis_in_sensor: FloatArray
    flexion_axis_in_sensor: FloatArray
    offset_from_axis_m: FloatArray
    mismatch_before_deg: float
    mismatch_after_deg: float
    highpass_hz: float
    gyro_evidence: float = float("nan")

    def confirmed(self, min_ratio: float) -> bool:
        """Whether the gyros see a turn of the same sign and at least ``min_ratio`` of ``per_flexion``.

        ``CalibrationOptions.thigh_twist_min_evidence`` (1/3): the simulator's twists give 0.63–0.79
        of the turn found, the real walk's 0.86–0.88.
        """
        return bool(self.gyro_evidence * np.sign(self.per_flexion) >= min_ratio * abs(self.per_flexion))

    def internal_per_flexion(self, side: str) -> float:
        """``k`` as an internal rotation of the sensor per rad of hip flexion (either leg), rad/rad.

        The axis ``ê`` points up and ``ĵ`` right on both legs, so an internal turn is a
        positive ``k`` on the right leg and a negative one on the left.
        """
        return self.per_flexion if side == "right" else -self.per_flexion

    def to_dict(self) -> dict[str, Any]:
        """calibration.json ``thigh_twist``."""
        return {
            "per_flexion_rad_per_rad": float(self.per_flexion),
            "axis_in_sensor": [float(x) for x in self.axis_in_sensor],
            "flexion_axis_in_sensor": [float(x) for x in self.flexion_axis_in_sensor],
            "offset_from_axis_m": [float(x) for x in self.offset_from_axis_m],
            "mismatch_before_deg": float(self.mismatch_before_deg),
            "mismatch_after_deg": float(self.mismatch_after_deg),
            "highpass_hz": float(self.highpass_hz),
            "gyro_evidence_rad_per_rad": float(self.gyro_evidence),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ThighTwist:
        """Inverse of :meth:`to_dict`.

        Raises:
            InputError: a vector that is not three finite numbers (the axes also not zero).
        """

        def vector(key: str, unit: bool) -> FloatArray:
            v = np.asarray(d[key], dtype=float)
            if v.shape != (3,) or not np.all(np.isfinite(v)) or (unit and not np.any(v)):
                raise InputError(
                    f"calibration document: thigh_twist.{key} must be three finite numbers"
                    + (" (not all zero)" if unit else "")
                    + f", got {d[key]!r}"
                )
            return np.asarray(v / np.linalg.norm(v) if unit else v, dtype=float)

        return cls(
            per_flexion=float(d["per_flexion_rad_per_rad"]),
            axis_in_sensor=vector("axis_in_sensor", unit=True),
            flexion_axis_in_sensor=vector("flexion_axis_in_sensor", unit=True),
            offset_from_axis_m=vector("offset_from_axis_m", unit=False),
            mismatch_before_deg=float(d.get("mismatch_before_deg", float("nan"))),
            mismatch_after_deg=float(d.get("mismatch_after_deg", float("nan"))),
            highpass_hz=float(d.get("highpass_hz", 0.1)),
            gyro_evidence=float(d.get("gyro_evidence_rad_per_rad", float("nan"))),
        )


def _unit(v: FloatArray) -> FloatArray:
    return np.asarray(v / np.linalg.norm(v), dtype=float)


def untwist_signals(
    gyr: FloatArray,
    acc: FloatArray,
    phi: FloatArray,
    phi_rate: FloatArray,
    axis: FloatArray,
    offset_m: FloatArray,
    rate_hz: float,
) -> tuple[FloatArray, FloatArray]:
    """The femur-fixed gyro and accelerometer of a sensor turning by ``φ`` about ``axis``.

    Args:
        gyr: (N, 3) the sensor's gyro, rad/s (its bias stays in; it is removed later).
        acc: (N, 3) its specific force, m/s².
        phi: (N,) the sensor's turn about ``axis`` from the femur-fixed frame, rad.
        phi_rate: (N,) its rate, rad/s.
        axis: (3,) the femur's long axis in the sensor frame (unit).
        offset_m: (3,) the sensor's place across that axis, m (zeros: turning in place).
        rate_hz: sampling rate, Hz.

    Returns:
        (N, 3) gyro and (N, 3) specific force of a sensor fixed to the femur where the
        sensor sat at ``φ = 0``, in that frame.
    """
    e = _unit(np.asarray(axis, dtype=float))
    turn = Rotation.from_rotvec(np.outer(phi, e))
    w = turn.apply(gyr) - np.outer(phi_rate, e)
    r0 = np.asarray(offset_m, dtype=float)
    r0 = r0 - (r0 @ e) * e
    if not np.any(r0):
        return w, turn.apply(acc)
    dt = 1.0 / rate_hz
    alpha = np.gradient(w, dt, axis=0)
    phi_acc = np.gradient(phi_rate, dt)
    q = np.cross(e, r0)
    cos, sin = np.cos(phi)[:, None], np.sin(phi)[:, None]
    dp = (cos - 1.0) * r0 + sin * q
    along = -sin * r0 + cos * q  # dΔp/dφ
    dv = phi_rate[:, None] * along
    da = phi_acc[:, None] * along - (phi_rate**2)[:, None] * (cos * r0 + sin * q)
    moving = np.cross(alpha, dp) + np.cross(w, np.cross(w, dp)) + 2.0 * np.cross(w, dv) + da
    return w, turn.apply(acc) - moving


def thigh_flexion(
    gyr: FloatArray, flexion_axis: FloatArray, rate_hz: float, n_still: int, highpass_hz: float
) -> tuple[FloatArray, FloatArray]:
    """The thigh's rotation about ``flexion_axis`` since the standing start, and its rate.

    Args:
        gyr: (N, 3) thigh gyro, rad/s.
        flexion_axis: (3,) the knee's flexion axis in the thigh sensor frame (unit).
        rate_hz: sampling rate, Hz.
        n_still: samples of the still start (their mean rate is the bias; 0: none removed).
        highpass_hz: the angle's high-pass against the drift of the integral, Hz.

    Returns:
        (N,) angle ψ, rad (its mean over the still start is 0), and (N,) its rate, rad/s.
    """
    g = np.asarray(gyr, dtype=float)
    bias = g[:n_still].mean(axis=0) if n_still > 0 else np.zeros(3)
    rate = (g - bias) @ np.asarray(flexion_axis, dtype=float)
    angle = np.cumsum(rate) / rate_hz
    sos = butter(2, highpass_hz, btype="high", fs=rate_hz, output="sos")
    angle = sosfiltfilt(sos, angle)
    ref = angle[:n_still].mean() if n_still > 0 else angle[0]
    return angle - ref, rate


def untwist_trial(trial: ImuTrial, twist: ThighTwist, n_still: int) -> ImuTrial:
    """The trial with its thigh sensor's twist undone (:func:`untwist_signals`); a copy."""
    if twist.per_flexion == 0.0:
        return trial
    gyr, acc, rate = trial.gyr["thigh"], trial.acc["thigh"], trial.rate_hz
    psi, psi_rate = thigh_flexion(gyr, twist.flexion_axis_in_sensor, rate, n_still, twist.highpass_hz)
    k, e, r0 = twist.per_flexion, twist.axis_in_sensor, twist.offset_from_axis_m
    w, f = untwist_signals(gyr, acc, k * psi, k * psi_rate, e, r0, rate)
    return replace(trial, gyr={**trial.gyr, "thigh": w}, acc={**trial.acc, "thigh": f})


def gyro_evidence(trial: ImuTrial, calibration: LegCalibration, n_still: int) -> float:
    """The thigh sensor's turn about the femur per rad of the thigh's flexion, from the gyros alone, rad/rad.

    The thigh's rate about its up at standing minus the shank's about its own, regressed on the
    thigh's rate about the knee axis (made horizontal) and the knee's flexion rate, while the
    shank turns faster than 0.5 rad/s (4 Hz low-pass): the first coefficient. A sensor turning ``k``
    about the femur per rad of the thigh's flexion adds ``k`` (same sign as ``per_flexion``);
    rigid sensors give about ±0.06 on simulated walks (the femur's own rotation).
    """
    n = max(1, n_still)
    sos = butter(4, min(4.0, 0.4 * trial.rate_hz), fs=trial.rate_hz, output="sos")
    axes = {"thigh": calibration.knee.axis_in_parent_sensor, "shank": calibration.knee.axis_in_child_sensor}
    rate: dict[str, tuple[FloatArray, FloatArray]] = {}
    speed: dict[str, FloatArray] = {}
    for s, axis in axes.items():
        g = np.asarray(trial.gyr[s], dtype=float)
        g = sosfiltfilt(sos, g - g[:n].mean(axis=0), axis=0)
        up = _unit(np.asarray(trial.acc[s][:n], dtype=float).mean(axis=0))
        j = np.asarray(axis, dtype=float)
        rate[s] = (g @ up, g @ _unit(j - (j @ up) * up))
        speed[s] = np.linalg.norm(g, axis=1)
    moving = speed["shank"] > 0.5
    if moving.sum() < 10:
        return float("nan")
    x = np.column_stack([rate["thigh"][1], rate["shank"][1] - rate["thigh"][1]])[moving]
    y = (rate["thigh"][0] - rate["shank"][0])[moving]
    return float(np.linalg.lstsq(x, y, rcond=None)[0][0])


def standing_mismatch_deg(calibration: LegCalibration, trial: ImuTrial, n_still: int) -> float:
    """The knee axis's elevation in the thigh minus the shank sensor at standing (coherent band), deg."""
    knee = (calibration.coherent_fit or calibration).knee
    n = max(1, n_still)
    up = [np.asarray(trial.acc[s][:n], dtype=float).mean(axis=0) for s in ("thigh", "shank")]
    return float(np.degrees(standing_axis_mismatch(knee, up[0], up[1])))


def _secant_root(
    mismatch: Callable[[float], float], m0: float, options: CalibrationOptions
) -> tuple[float, float]:
    """``k`` where ``mismatch(k)`` crosses zero, from ``mismatch(0) = m0`` (the one of least |mismatch|)."""
    lim = options.thigh_twist_max
    ks, ms = [0.0], [m0]
    k = float(np.clip(m0 / options.thigh_twist_slope_deg, -lim, lim))
    for _ in range(options.thigh_twist_steps):
        ks.append(k)
        ms.append(mismatch(k))
        if abs(ms[-1]) <= options.thigh_twist_tol_deg or ms[-1] == ms[-2]:
            break
        k = float(np.clip(ks[-1] - ms[-1] * (ks[-1] - ks[-2]) / (ms[-1] - ms[-2]), -lim, lim))
    best = int(np.argmin(np.abs(ms)))
    return ks[best], ms[best]


def estimate_thigh_twist(
    trial: ImuTrial,
    calibration: LegCalibration,
    calibrate: Callable[[ImuTrial], LegCalibration],
    n_still: int,
    options: CalibrationOptions,
) -> ThighTwist | None:
    """The thigh sensor's twist with the thigh's flexion, or ``None`` when the knee axes agree.

    Stages: the standing mismatch of ``calibration`` → ``k`` by secant steps on the mismatch
    of ``calibrate(untwisted trial)`` (rotation only: the knee axes come from the gyros) →
    the sensor's place across the femur axis from that calibration's hip centre.

    Args:
        trial: the trial as recorded (re-timed, if its clocks were).
        calibration: its calibration.
        calibrate: calibrates a trial (the same still start, method and options).
        n_still: samples of the still start.
        options: ``thigh_twist_*``.

    Returns:
        The twist (its ``mismatch_after_deg`` is that of the rotation-only untwisting),
        or ``None`` when the mismatch is under ``thigh_twist_min_mismatch_deg``.
    """
    m0 = standing_mismatch_deg(calibration, trial, n_still)
    if not abs(m0) >= options.thigh_twist_min_mismatch_deg:
        return None
    e = _unit(np.asarray(trial.acc["thigh"][: max(1, n_still)], dtype=float).mean(axis=0))
    jt = np.asarray(calibration.knee.axis_in_parent_sensor, dtype=float)
    base = ThighTwist(0.0, e, _unit(jt - (jt @ e) * e), np.zeros(3), m0, m0, options.thigh_twist_highpass_hz)
    fits: dict[float, LegCalibration] = {}

    def mismatch(k: float) -> float:
        twisted = untwist_trial(trial, replace(base, per_flexion=k), n_still)
        fits[k] = calibrate(twisted)
        return standing_mismatch_deg(fits[k], twisted, n_still)

    k, m = _secant_root(mismatch, m0, options)
    if k == 0.0:
        return None
    centre = np.asarray(fits[k].hip.center_in_child_sensor, dtype=float)
    offset = -(centre - (centre @ e) * e)
    evidence = gyro_evidence(trial, calibration, n_still)
    return replace(
        base, per_flexion=k, offset_from_axis_m=offset, mismatch_after_deg=m, gyro_evidence=evidence
    )
