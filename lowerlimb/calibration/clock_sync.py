"""Clock offsets between the sensors of one leg, from the joint constraints.

The calibration assumes the four sensors were sampled at the same instants. Sensors
of one vendor's wireless network are (Xsens Awinda: within microseconds); separate
loggers aligned afterwards on a tap, or a network with buffered clocks, are often
tens of ms apart. At walking speed a 10 ms offset changes a joint centre's
acceleration by a few tenths of m/s² (its jerk times the offset), more than the fit's
residual, and the joint centres go wrong by decimetres (benchmarks/clock_sync.py).

The joints measure the offsets. A point on a joint's axis or at its centre has one
acceleration, seen from either sensor (Hu et al. 2021 eq. 1-3); so does its norm,
which needs no orientation:

``‖a_p(t)‖ = ‖a_c(t + τ)‖``, ``a = f + ω × (ω × c) + α × c``,

with ``τ`` the child sensor's lag behind the parent. Given a first calibration, ``τ``
of each joint minimises the mean squared difference of the two norms, both low-passed
(:attr:`CalibrationOptions.clock_lowpass_hz`), over ``±clock_max_offset_s`` on a 1 ms
grid refined by a parabola, away from impacts (the samples the joint-centre fits leave
out, :func:`~lowerlimb.calibration.impact_window.impact_keep_mask`: a heel strike rings
differently in the shank and the foot sensor, and a wrong lag lines the rings up).
Offsets add down the chain (pelvis → thigh → shank → foot).

A first calibration is wrong where the clocks are, so the first lags fall short; the
signals are re-timed, calibrated again and searched again (``clock_passes``). On a
synchronised real walk (``gait/``, Xsens) the search still finds lags of 2-25 ms at
the hip and knee, but they explain 0-18 % of the norm mismatch (soft tissue and
impacts, not timing), while offsets of 10-30 ms on the simulator explain 40-80 % of it
where the sensors are rigid and 0-80 % under its real-walk artefacts. A lag counts only when it explains at
least :attr:`CalibrationOptions.clock_min_explained` of the mismatch and the two halves
of the trial give the same lag within :attr:`CalibrationOptions.clock_split_tol_s` (a
clock offset is constant over a trial; on the real walk the spurious hip and knee lags
of the two halves were 10-34 ms apart); otherwise the sensors are taken as synchronised.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from ..constraints.angular_acceleration import angular_acceleration
from ..constraints.prefilter import lowpass
from ..constraints.spherical import joint_acceleration
from ..conventions import FloatArray
from .impact_window import impact_keep_mask

if TYPE_CHECKING:
    from .leg import LegCalibration
    from .options import CalibrationOptions


class _Signals(Protocol):
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]

    @property
    def rate_hz(self) -> float: ...


__all__ = [
    "ClockHintWarning",
    "ClockOffsetWarning",
    "ClockOffsets",
    "JointLag",
    "LateSensor",
    "estimate_clock_offsets",
    "joint_residual",
    "late_sensor",
    "retime",
    "synchronise",
    "worse_fits",
]

#: (joint, parent sensor, child sensor), down the chain.
_CHAIN = (("hip", "pelvis", "thigh"), ("knee", "thigh", "shank"), ("ankle", "shank", "foot"))
#: Step of the lag grid, s.
_GRID_S = 0.001


@dataclass(frozen=True)
class JointLag:
    """The lag found at one joint.

    Attributes:
        lag_s: the child sensor's lag behind the parent: ``a_c(t + lag) ≈ a_p(t)``, s.
        explained: share of the mean squared norm mismatch at zero lag that the lag
            removes (0-1).
        split_s: difference of the lags found on the first and the second half of the
            trial, s (a clock offset is constant; a lag that lines up soft-tissue or
            impact features need not be).
        counted: the lag explains enough (:attr:`CalibrationOptions.clock_min_explained`)
            and the halves agree (:attr:`CalibrationOptions.clock_split_tol_s`).
    """

    lag_s: float
    explained: float
    split_s: float
    counted: bool


@dataclass(frozen=True)
class ClockOffsets:
    """Clock offsets of the leg's sensors relative to the pelvis sensor.

    Attributes:
        joints: ``{joint: JointLag}`` of the last pass.
        shift_s: ``{sensor: s}`` applied re-timing: the corrected signal at ``t`` is the
            recorded one at ``t + shift`` (pelvis 0; the sum of the counted lags above it,
            over all passes).
        passes: number of estimation passes run.
        rejected: ``{joint: residual after / before}`` of a re-timing step that was undone
            because it made those joints fit worse (:func:`synchronise`); empty when none was.
        late_sensor: ``{sensor: s}`` a sensor whose uncounted joint lags both said it runs late
            (negative: early) by about this (:func:`late_sensor`), tried as a re-timing step of
            its own (kept where the joints fit no worse, like any step); empty when none did.
    """

    joints: dict[str, JointLag] = field(default_factory=dict)
    shift_s: dict[str, float] = field(default_factory=dict)
    passes: int = 0
    rejected: dict[str, float] = field(default_factory=dict)
    late_sensor: dict[str, float] = field(default_factory=dict)

    @property
    def applied(self) -> bool:
        """Whether any sensor was re-timed."""
        return any(v != 0.0 for v in self.shift_s.values())

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready record (calibration.json ``clock_offsets``)."""
        return {
            "shift_s": {k: float(v) for k, v in self.shift_s.items()},
            "joints": {
                k: {
                    "lag_s": float(v.lag_s),
                    "explained": float(v.explained),
                    "split_s": float(v.split_s),
                    "counted": bool(v.counted),
                }
                for k, v in self.joints.items()
            },
            "passes": int(self.passes),
            "rejected": {k: float(v) for k, v in self.rejected.items()},
            "late_sensor": {k: float(v) for k, v in self.late_sensor.items()},
        }


def point_acceleration_norm(
    acc: FloatArray, gyr: FloatArray, point: FloatArray, rate_hz: float, cutoff_hz: float
) -> FloatArray:
    """‖f + ω × (ω × c) + α × c‖ (N,), m/s², at ``point`` (3,) m, sensor frame, low-passed.

    The norm of :func:`~lowerlimb.constraints.spherical.joint_acceleration`, through a
    zero-phase 2nd-order Butterworth at ``cutoff_hz`` (none at or above Nyquist).
    """
    a = np.linalg.norm(joint_acceleration(acc, gyr, angular_acceleration(gyr, rate_hz), point), axis=1)
    return lowpass(a, rate_hz, cutoff_hz if cutoff_hz < 0.5 * rate_hz else None, order=2)


def _lag_costs(
    a_parent: FloatArray, a_child: FloatArray, rate_hz: float, max_s: float, masks: list[NDArray[np.bool_]]
) -> tuple[FloatArray, FloatArray]:
    """Lag grid (L,) s and mean (a_p(t) − a_c(t + lag))² over each mask's samples (M, L)."""
    n = a_parent.shape[0]
    t = np.arange(n) / rate_hz
    half = int(round(max_s / _GRID_S))
    lags = np.arange(-half, half + 1, dtype=float) * _GRID_S  # holds 0 exactly
    w = np.asarray(masks, dtype=float)
    count = np.maximum(w.sum(axis=1), 1.0)
    cost = np.array([w @ (a_parent - np.interp(t + g, t, a_child)) ** 2 for g in lags], dtype=float).T
    return lags, cost / count[:, None]


def _minimum(lags: FloatArray, cost: FloatArray, floor: float) -> tuple[float, float]:
    """(lag at the minimum of ``cost`` refined by a parabola, share of the zero-lag cost it removes).

    A zero-lag cost at or below ``floor`` has nothing to explain (share 0).
    """
    k = int(np.argmin(cost))
    lag = float(lags[k])
    if 0 < k < lags.size - 1:
        den = cost[k - 1] - 2.0 * cost[k] + cost[k + 1]
        if den > 0:
            lag += 0.5 * (cost[k - 1] - cost[k + 1]) / den * _GRID_S
    zero = float(cost[lags.size // 2])
    return lag, max(1.0 - float(cost[k]) / zero, 0.0) if zero > floor else 0.0


def joint_lag(
    a_parent: FloatArray,
    a_child: FloatArray,
    rate_hz: float,
    max_s: float,
    keep: NDArray[np.bool_] | None = None,
) -> JointLag:
    """The lag minimising mean (a_p(t) − a_c(t + lag))² over ``±max_s``, on the whole trial and its halves.

    Args:
        a_parent: (N,) the joint point's acceleration norm from the parent sensor, m/s².
        a_child: (N,) the same from the child sensor, m/s².
        rate_hz: sampling rate, Hz.
        max_s: largest lag searched, s.
        keep: (N,) samples to compare (default: all); the ends (``max_s``) are left out.

    Returns:
        The lag and its explained share; ``split_s`` from the two halves; ``counted`` False
        (the caller applies the thresholds).
    """
    n = a_parent.shape[0]
    edge = int(np.ceil(max_s * rate_hz)) + 2
    inner = np.zeros(n, dtype=bool)
    inner[edge : n - edge] = True
    if keep is not None:
        inner &= keep
    first = np.arange(n) < n // 2
    masks = [inner, inner & first, inner & ~first]
    if min(int(m.sum()) for m in masks) < 16:
        return JointLag(0.0, 0.0, np.inf, False)
    lags, cost = _lag_costs(a_parent, a_child, rate_hz, max_s, masks)
    floor = 1e-12 * float(np.mean(a_parent**2))
    lag, explained = _minimum(lags, cost[0], floor)
    (lag1, _), (lag2, _) = _minimum(lags, cost[1], floor), _minimum(lags, cost[2], floor)
    return JointLag(lag, explained, abs(lag1 - lag2), False)


def estimate_lags(
    signals: _Signals, calibration: LegCalibration, options: CalibrationOptions
) -> dict[str, JointLag]:
    """The lag of each joint's child sensor behind its parent (:class:`JointLag`), one pass."""
    rate = signals.rate_hz
    out = {}
    for joint, parent, child in _CHAIN:
        j = calibration.joints[joint]
        keep = impact_keep_mask((signals.acc[parent], signals.acc[child], signals.acc["foot"]), rate, options)
        # the norm form's centre where the aligned form placed the parent side (the hip in the
        # pelvis sensor): the aligned fit absorbs a lag its own way, and at its centre a 25 ms
        # hip lag on a seven-IMU simulated walk explained 23 % of the mismatch (not counted,
        # the hip in the thigh 415 mm off) where the norm form's explained 46 %
        c_parent = getattr(j, "norm_center_in_parent_sensor", None)
        if c_parent is None:
            c_parent = j.center_in_parent_sensor
        a_p, a_c = (
            point_acceleration_norm(signals.acc[s], signals.gyr[s], c, rate, options.clock_lowpass_hz)
            for s, c in ((parent, c_parent), (child, j.center_in_child_sensor))
        )
        found = joint_lag(a_p, a_c, rate, options.clock_max_offset_s, keep)
        counted = (
            found.explained >= options.clock_min_explained and found.split_s <= options.clock_split_tol_s
        )
        out[joint] = replace(found, counted=counted)
    return out


def chain_shifts(lags: dict[str, JointLag]) -> dict[str, float]:
    """``{sensor: s}`` re-timing of each sensor from the counted joint lags (pelvis 0)."""
    shift = {"pelvis": 0.0}
    for joint, parent, child in _CHAIN:
        shift[child] = shift[parent] + (lags[joint].lag_s if lags[joint].counted else 0.0)
    return shift


def retime(signals: Any, shift_s: dict[str, float]) -> Any:
    """A copy of a trial (``time_s``, ``acc``, ``gyr``, optional ``mag``) with sensors re-timed.

    The signal of sensor ``s`` at ``t`` becomes the recorded one at ``t + shift_s[s]``
    (linear interpolation; held at the ends). Sensors with no or zero shift are shared.
    """
    t = np.asarray(signals.time_s, dtype=float)

    def move(d: dict[str, FloatArray] | None) -> dict[str, FloatArray] | None:
        if d is None:
            return None
        out = dict(d)
        for s, dt in shift_s.items():
            if dt != 0.0 and s in d:
                x = np.asarray(d[s], dtype=float)
                out[s] = np.column_stack([np.interp(t + dt, t, x[:, k]) for k in range(x.shape[1])])
        return out

    return replace(
        signals, acc=move(signals.acc), gyr=move(signals.gyr), mag=move(getattr(signals, "mag", None))
    )


def estimate_clock_offsets(
    signals: _Signals, calibration: LegCalibration, options: CalibrationOptions
) -> ClockOffsets:
    """One pass of :func:`estimate_lags` as a :class:`ClockOffsets` (shifts from the counted lags)."""
    lags = estimate_lags(signals, calibration, options)
    return ClockOffsets(joints=lags, shift_s=chain_shifts(lags), passes=1)


class ClockOffsetWarning(UserWarning):
    """The sensors' clocks looked offset and the signals were re-timed before calibrating."""


class ClockHintWarning(UserWarning):
    """One sensor looks late (or early) against both its neighbours, too weakly to re-time it."""


@dataclass(frozen=True)
class LateSensor:
    """A thigh or shank sensor whose two joints' lags both say it runs late (or early).

    Attributes:
        sensor: ``"thigh"`` or ``"shank"``.
        lag_s: how late it looks against its neighbours (the mean of the two joints'), s
            (negative: early).
        joints: ``{joint: its lag as found}`` of the joint above and below it.
    """

    sensor: str
    lag_s: float
    joints: dict[str, JointLag]

    def message(self) -> str:
        """One line for the user."""
        when = "late" if self.lag_s > 0 else "early"
        found = ", ".join(
            f"{j} {1000 * v.lag_s:+.0f} ms explaining {100 * v.explained:.0f} %"
            for j, v in self.joints.items()
        )
        return (
            f"the {self.sensor} sensor's clock looks {1000 * abs(self.lag_s):.0f} ms {when} against both "
            f"its neighbours ({found} of the joint's mismatch), but re-timing it made the joints fit "
            f"worse, so it was not; its segment lengths may come out short; synchronise the sensors, "
            f"or check that sensor's time column"
        )


def late_sensor(lags: Mapping[str, JointLag], options: CalibrationOptions) -> LateSensor | None:
    """The thigh or shank sensor whose two uncounted joint lags agree that it is late or early, if any.

    A sensor's clock offset moves both its joints: the one above by its lag, the one below by
    minus it. Soft tissue and impacts move one joint's lag at a time (synchronised simulated
    walks: hip lags up to +34 ms beside knee lags within ±6 ms).
    """
    for sensor, above, below in (("thigh", "hip", "knee"), ("shank", "knee", "ankle")):
        a, b = lags.get(above), lags.get(below)
        if a is None or b is None or a.counted or b.counted:
            continue
        la, lb = a.lag_s, -b.lag_s  # both: the sensor's lag behind its neighbour
        small, large = sorted((abs(la), abs(lb)))
        if (
            la * lb > 0
            and small >= options.clock_hint_min_lag_s
            and large <= options.clock_hint_max_ratio * small
            and min(a.explained, b.explained) >= options.clock_hint_min_explained
        ):
            return LateSensor(sensor, 0.5 * (la + lb), {above: a, below: b})
    return None


def joint_residual(calibration: LegCalibration, joint: str) -> float:
    """The joint's fit residual that its sensors' relative timing moves.

    The knee's hinge-axis residual (Hu et al. 2021 eq. 6, rad/s: gyros only, so it checks a
    lag found on the accelerometers independently), the hip's and ankle's centre residual
    (eq. 3, m/s²).
    """
    if joint == "knee":
        return float(calibration.knee.axis.rms_residual)
    return float(getattr(calibration, joint).rms_residual)


def worse_fits(
    before: LegCalibration, after: LegCalibration, step: dict[str, float], max_growth: float
) -> dict[str, float]:
    """``{joint: residual after / before}`` of the joints a re-timing step moved, when they fit worse.

    A joint is moved when the step changes its child's timing against its parent's. They fit
    worse when the geometric mean of their residual ratios (:func:`joint_residual`) exceeds
    ``max_growth``; otherwise the result is empty. A real offset removed lowers those
    residuals on the whole (simulated offsets of σ 10 ms: the knee's axis residual
    0.034–0.071 → 0.010–0.014 rad/s; under the simulator's soft-tissue artefacts one knee's
    rose 1.2× while the ankle moved with it fell 3×); a lag that lined up soft tissue or
    impacts on synchronised sensors raises them (a shuffling walk with turns: knee lags of
    45 ms, the axis residual 8×, and both legs' segments 40 % short).
    """
    ratios: dict[str, float] = {}
    for joint, parent, child in _CHAIN:
        if step.get(child, 0.0) == step.get(parent, 0.0):
            continue
        r0, r1 = joint_residual(before, joint), joint_residual(after, joint)
        if np.isfinite(r0) and np.isfinite(r1) and r0 > 0.0 and r1 > 0.0:
            ratios[joint] = r1 / r0
    if not ratios or float(np.exp(np.mean(np.log(list(ratios.values()))))) <= max_growth:
        return {}
    return ratios


def synchronise(
    trial: Any,
    calibration: LegCalibration,
    calibrate: Callable[[Any], LegCalibration],
    options: CalibrationOptions,
) -> tuple[Any, LegCalibration, ClockOffsets]:
    """Estimate the clock offsets, re-time the trial and calibrate again, up to ``clock_passes`` times.

    Args:
        trial: the leg's trial (``time_s``, ``acc``, ``gyr``, optional ``mag``).
        calibration: its first calibration.
        calibrate: calibrates a (re-timed) trial.
        options: ``clock_*`` thresholds.

    A step is undone, and the search stops, when it makes a joint it moved fit worse
    (:func:`worse_fits`, :attr:`CalibrationOptions.clock_max_residual_growth`).

    Returns:
        ``(trial, calibration, offsets)``: the re-timed trial and its calibration (the
        inputs when no lag counted) and the record.

    Warns:
        ClockOffsetWarning: the signals were re-timed.
    """
    total = dict.fromkeys(("pelvis", "thigh", "shank", "foot"), 0.0)
    current, cal = trial, calibration
    lags: dict[str, JointLag] = {}
    rejected: dict[str, float] = {}
    hints: dict[str, float] = {}
    passes = 0
    for _ in range(options.clock_passes):
        passes += 1
        lags = estimate_lags(current, cal, options)
        step = chain_shifts(lags)
        hint = None if any(step.values()) else late_sensor(lags, options)
        if hint is not None:  # one sensor late against both neighbours: tried as a step of its own
            step = dict.fromkeys(step, 0.0) | {hint.sensor: hint.lag_s}
            hints[hint.sensor] = hints.get(hint.sensor, 0.0) + hint.lag_s
        if not any(step.values()):
            break
        tried = {s: total[s] + step[s] for s in total}
        retimed = retime(trial, tried)
        cal_tried = calibrate(retimed)
        rejected = worse_fits(cal, cal_tried, step, options.clock_max_residual_growth)
        if rejected:
            break
        total, current, cal = tried, retimed, cal_tried
    offsets = ClockOffsets(joints=lags, shift_s=total, passes=passes, rejected=rejected, late_sensor=hints)
    if hint is not None and rejected:  # its re-timing made the joints fit worse: said, not done
        warnings.warn(hint.message(), ClockHintWarning, stacklevel=2)
    if offsets.applied:
        moved = ", ".join(f"{s} {1000 * v:+.0f} ms" for s, v in total.items() if v != 0.0)
        warnings.warn(
            f"the sensors' clocks look offset from the pelvis sensor's ({moved}); the signals were "
            f"re-timed before calibrating (calibration.json clock_offsets); synchronise the "
            f"sensors, or pass --no-clock-sync (clock_sync=False) if they are",
            ClockOffsetWarning,
            stacklevel=2,
        )
    return current, cal, offsets
