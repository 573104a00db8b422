"""``estimate_orientation``: the one entry point to every orientation filter.

Backends behind one interface (as qpsolvers' ``solve_problem``): each
filter module provides ``<name>_filter(gyr, acc, mag, *, rate_hz, initial,
params)`` and a frozen params dataclass; this module validates the input,
finds the initial state from the still start, and dispatches.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import (
    MAX_GYRO_RAD_S,
    MIN_MEDIAN_ACC_MPS2,
    FloatArray,
    quat_conjugate,
    quat_multiply,
)
from lowerlimb.errors import InputError, NonFiniteValueError, ShapeError, UnitError
from lowerlimb.methods import ORIENTATION_FILTERS
from lowerlimb.orientation.ftecf import FtecfParams, ftecf_filter
from lowerlimb.orientation.initialisation import InitialState, RestParams, initialise
from lowerlimb.orientation.madgwick import MadgwickParams, madgwick_filter
from lowerlimb.orientation.mahony import MahonyParams, mahony_filter
from lowerlimb.orientation.quest_kf import QuestKfParams, quest_kf_filter

OrientationParams = MahonyParams | FtecfParams | MadgwickParams | QuestKfParams

#: method name -> (filter function, its params class)
FILTERS: dict[str, tuple[Callable[..., FloatArray], type]] = {
    "mahony": (mahony_filter, MahonyParams),
    "ftecf": (ftecf_filter, FtecfParams),
    "madgwick": (madgwick_filter, MadgwickParams),
    "quest_kf": (quest_kf_filter, QuestKfParams),
}
#: Valid values of ``method``: the registry :data:`lowerlimb.methods.ORIENTATION_FILTERS`.
METHODS: tuple[str, ...] = tuple(ORIENTATION_FILTERS)


def _as_signal(name: str, x: Any) -> FloatArray:
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name} must be a numeric (N, 3) array; could not convert it: {e}") from e
    if a.ndim != 2 or a.shape[1] != 3:
        hint = " (transpose it: one row per sample)" if a.ndim == 2 and a.shape[0] == 3 else ""
        raise ShapeError(f"{name} must have shape (N, 3) with columns x, y, z; got shape {a.shape}{hint}")
    if a.shape[0] == 0:
        raise ShapeError(f"{name} has no samples; pass at least one row")
    bad = ~np.isfinite(a)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise NonFiniteValueError(f"{name}_{'xyz'[col]}", int(row))
    return a


def _check_inputs(
    gyr: ArrayLike, acc: ArrayLike, mag: ArrayLike | None, rate_hz: Any, method: Any, params: Any
) -> tuple[FloatArray, FloatArray, FloatArray | None, float]:
    if not isinstance(method, str) or method not in FILTERS:
        raise InputError(f"unknown orientation method {method!r}; choose one of {', '.join(METHODS)}")
    if isinstance(rate_hz, bool) or not isinstance(rate_hz, int | float | np.integer | np.floating):
        raise InputError(f"rate_hz must be a number in Hz, got {rate_hz!r}")
    rate = float(rate_hz)
    if not math.isfinite(rate) or rate <= 0.0:
        raise InputError(f"rate_hz must be a positive sampling rate in Hz, got {rate_hz!r}")
    params_cls = FILTERS[method][1]
    if params is not None and not isinstance(params, params_cls):
        raise InputError(
            f"params for method '{method}' must be a {params_cls.__name__}, "
            f"got {type(params).__name__}; pass {params_cls.__name__}(...) or None"
        )
    g = _as_signal("gyr", gyr)
    a = _as_signal("acc", acc)
    m = None if mag is None else _as_signal("mag", mag)
    lengths = {"gyr": len(g), "acc": len(a)} | ({} if m is None else {"mag": len(m)})
    if len(set(lengths.values())) > 1:
        desc = ", ".join(f"{k} {v}" for k, v in lengths.items())
        raise ShapeError(f"gyr, acc and mag must have the same number of samples; got {desc}")
    g_max = float(np.abs(g).max())
    if g_max > MAX_GYRO_RAD_S:
        raise UnitError(
            "gyr",
            g_max,
            f"gyro values up to {g_max:.0f} look like deg/s; estimate_orientation expects "
            f"rad/s (multiply by π/180)",
        )
    step = max(1, len(a) // 2000)  # the median of a subsample is enough to tell g from m/s²
    a_med = float(np.median(np.linalg.norm(a[::step], axis=1)))
    if a_med < MIN_MEDIAN_ACC_MPS2:
        raise UnitError(
            "acc",
            a_med,
            f"accelerometer norms around {a_med:.2f} look like g; estimate_orientation expects "
            f"m/s² (multiply by 9.81)",
        )
    return g, a, m, rate


#: Accepted meanings of a gyro sample (see :func:`estimate_orientation`).
GYRO_TIMINGS = ("instantaneous", "interval_mean")


def estimate_orientation(
    gyr: ArrayLike,
    acc: ArrayLike,
    mag: ArrayLike | None = None,
    *,
    rate_hz: float,
    method: str = "mahony",
    params: OrientationParams | None = None,
    remove_bias: bool = True,
    gyro_timing: str = "instantaneous",
    smooth: bool = False,
) -> FloatArray:
    """Orientation of one IMU over a recording, from gyro + accelerometer (+ magnetometer).

    The initial attitude comes from the still start of the recording (gravity,
    and heading from the magnetometer when given, else heading 0: sensor x
    axis towards east); see :func:`~lowerlimb.orientation.initialisation.initialise`.

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s² (+9.81 along "up" at rest).
        mag: (N, 3) magnetic field, sensor frame, any unit (µT in trial files),
            or ``None`` for a 6-axis estimate (heading then drifts freely).
        rate_hz: Sampling rate, Hz.
        method: ``"mahony"`` (PI complementary filter, Hu et al. 2021),
            ``"ftecf"`` (fuzzy ESOQ-2 complementary filter, Zhu & Xu 2018),
            ``"madgwick"`` (gradient descent) or ``"quest_kf"`` (QUEST +
            Kalman filter, Yun & Bachmann 2006).
        params: The method's params dataclass (:class:`MahonyParams`,
            :class:`FtecfParams`, :class:`MadgwickParams`,
            :class:`QuestKfParams`); ``None`` uses the benchmarked defaults.
        remove_bias: Estimate the gyro bias as the mean rate of the still start
            and subtract it (nothing is subtracted when the start moves).
        gyro_timing: ``"instantaneous"`` (docs/conventions.md: sample k is the angular
            velocity at t_k) or ``"interval_mean"`` (sample k is the mean rate
            over (t_{k-1}, t_k], as many IMUs with internal integration
            deliver). The filters rotate by the mean rate of each interval, so
            instantaneous samples are first averaged pairwise (trapezoid
            rule); without it the estimate leads the motion by half a sample.
        smooth: also run the filter backward in time from the forward run's last
            orientation and take the inclination from the mean of the two passes, the
            heading from the forward pass (:func:`two_pass_inclination`): an offline
            estimate in which the lag of the gravity correction cancels (each sample
            then depends on the whole recording, not only its past). Inclination error
            on the BROAD trials 0.91 → 0.84° (Mahony), on simulated walks 0.70 → 0.47°;
            the two passes' mean heading was worse on BROAD (9-axis 1.76 → 2.24°: real
            fields are disturbed), so the heading stays the forward pass's.

    Returns:
        (N, 4) unit quaternions ``w, x, y, z``, sensor -> earth (ENU), sign
        continuous from sample to sample.

    Raises:
        ShapeError: an array is not (N, 3), is empty, or lengths differ.
        NonFiniteValueError: a NaN or infinite sample (names signal, axis, row).
        UnitError: the gyro looks like deg/s or the accelerometer like g.
        InputError: unknown ``method``, ``rate_hz <= 0``, ``params`` of the
            wrong class, or a start without gravity direction (zero
            accelerometer) or heading (field parallel to gravity).
    """
    passes = estimate_orientation_passes(
        gyr,
        acc,
        mag,
        rate_hz=rate_hz,
        method=method,
        params=params,
        remove_bias=remove_bias,
        gyro_timing=gyro_timing,
        smooth=smooth,
    )
    return passes[1]


def estimate_orientation_passes(
    gyr: ArrayLike,
    acc: ArrayLike,
    mag: ArrayLike | None = None,
    *,
    rate_hz: float,
    method: str = "mahony",
    params: OrientationParams | None = None,
    remove_bias: bool = True,
    gyro_timing: str = "instantaneous",
    smooth: bool = True,
) -> tuple[FloatArray, FloatArray]:
    """(forward, two-pass): :func:`estimate_orientation` without and with ``smooth``, in one run.

    The two-pass estimate reuses the forward pass (what the pipeline needs: the joints'
    heading corrections are found on the forward orientations); with ``smooth=False``, or
    fewer than 2 samples, both are the forward estimate. Arguments, units and errors as
    :func:`estimate_orientation`; each result is (N, 4), ``w, x, y, z``.
    """
    g, a, m, rate = _check_inputs(gyr, acc, mag, rate_hz, method, params)
    if gyro_timing not in GYRO_TIMINGS:
        raise InputError(f"unknown gyro_timing {gyro_timing!r}; use one of {list(GYRO_TIMINGS)}")
    if gyro_timing == "instantaneous" and g.shape[0] > 1:
        g = g.copy()
        g[1:] = 0.5 * (g[1:] + g[:-1])
    initial = initialise(g, a, m, rate, estimate_bias=bool(remove_bias))
    filt = FILTERS[method][0]
    if initial.rest_samples == 0:
        initial = _warm_start(filt, g, a, m, rate, initial, params, RestParams().warm_start_s)
    # Every filter moves its estimate by a small rotation per sample and never
    # flips its sign, so the output is continuous as it is (tested).
    forward = filt(g, a, m, rate_hz=rate, initial=initial, params=params)
    if not smooth or g.shape[0] < 2:
        return forward, forward
    start = replace(initial, quat_wxyz=forward[-1], lowpass_from_gravity=True)
    backward = _backward(filt, g - initial.gyr_bias_rad_s, a, m, rate, start, params)
    weight = forward_weight(g.shape[0], initial.rest_samples, rate)
    return forward, two_pass_inclination(forward, backward, weight)


#: After the still start, the forward pass's weight falls from 1 to ½ over this time, s.
STILL_HANDOVER_S = 1.0


def forward_weight(n: int, rest_samples: int, rate_hz: float) -> FloatArray:
    """(N,) the forward pass's share of each sample's inclination in the two-pass estimate.

    1 over the still start, where the forward pass was just initialised on gravity at rest
    (the angle reference of every joint is taken there; the backward pass arrives with what
    the whole recording left it), then down to ½ within :data:`STILL_HANDOVER_S`, and ½ on.
    """
    t = (np.arange(n) - rest_samples) / rate_hz
    return np.asarray(np.clip(1.0 - 0.5 * t / STILL_HANDOVER_S, 0.5, 1.0), dtype=float)


def _backward(
    filt: Callable[..., FloatArray],
    g: FloatArray,
    a: FloatArray,
    m: FloatArray | None,
    rate: float,
    start: InitialState,
    params: Any,
) -> FloatArray:
    """(N, 4) the filter run from the last sample to the first, in the original sample order.

    ``g`` holds interval means (sample k: the mean rate over (t_{k-1}, t_k], bias removed);
    going back from t_k to t_{k-1} turns by ``-g[k]``, so the reversed run's step j takes
    ``-g[N - j]`` (step 0, the start itself, turns by nothing) and its output j is the
    orientation at t_{N-1-j}.
    """
    rev = np.zeros_like(g)
    rev[1:] = -g[:0:-1]
    return filt(
        np.ascontiguousarray(rev),
        np.ascontiguousarray(a[::-1]),
        None if m is None else np.ascontiguousarray(m[::-1]),
        rate_hz=rate,
        initial=replace(start, gyr_bias_rad_s=np.zeros(3)),
        params=params,
    )[::-1]


def two_pass_inclination(
    forward: ArrayLike, backward: ArrayLike, weight: ArrayLike | float = 0.5
) -> FloatArray:
    """(N, 4) the forward estimate with its inclination replaced by the two passes' mean.

    Both are sensor → earth (ENU) quaternions ``w, x, y, z``; ``weight`` ((N,) or scalar, 0–1)
    is the forward pass's share. The mean is the normalised weighted sum of the two (the
    backward sign matched to the forward's; at ½ the rotation halfway between them). The
    forward heading is put back by turning the mean about the earth's vertical by the
    twist (about +z) of ``forward ⊗ mean⁻¹``, so the result keeps the mean's sensor-frame
    vertical and the forward's heading. Sign continuous as ``forward``.
    """
    f = np.asarray(forward, dtype=float)
    b = np.asarray(backward, dtype=float)
    b = np.where((np.sum(f * b, axis=1) < 0.0)[:, None], -b, b)
    w = np.broadcast_to(np.asarray(weight, dtype=float), (f.shape[0],))[:, None]
    mean = w * f + (1.0 - w) * b
    mean /= np.linalg.norm(mean, axis=1, keepdims=True)
    d = quat_multiply(f, quat_conjugate(mean))  # earth-frame rotation from the mean to forward
    twist = np.stack([d[:, 0], np.zeros(len(d)), np.zeros(len(d)), d[:, 3]], axis=1)
    size = np.linalg.norm(twist, axis=1, keepdims=True)
    # a half-turn swing has no defined twist (the passes never disagree by that much): none
    twist = np.where(size > 1e-12, twist / np.maximum(size, 1e-12), np.array([1.0, 0.0, 0.0, 0.0]))
    out = quat_multiply(twist, mean)
    return np.asarray(np.where((np.sum(out * f, axis=1) < 0.0)[:, None], -out, out), dtype=float)


def _warm_start(
    filt: Callable[..., FloatArray],
    g: FloatArray,
    a: FloatArray,
    m: FloatArray | None,
    rate: float,
    initial: InitialState,
    params: Any,
    warm_s: float,
) -> InitialState:
    """``initial`` with its attitude converged by a run there and back over the first ``warm_s`` s.

    The filter runs forward over the first ``warm_s`` seconds, then backward in time
    (gyro negated) to the first sample.

    Without a still start the first readings include the motion's acceleration; the
    filter's gravity (and magnetic) correction pulls a rough start to the truth within
    seconds, and running it there and back gives that converged attitude at sample 0.
    """
    n = min(g.shape[0], int(round(warm_s * rate)))
    if n < 2:
        return initial
    fwd = filt(g[:n], a[:n], None if m is None else m[:n], rate_hz=rate, initial=initial, params=params)
    back_start = replace(initial, quat_wxyz=fwd[-1], lowpass_from_gravity=True)
    gb, ab = -g[:n][::-1], a[:n][::-1]
    mb = None if m is None else m[:n][::-1]
    back = filt(
        np.ascontiguousarray(gb),
        np.ascontiguousarray(ab),
        None if mb is None else np.ascontiguousarray(mb),
        rate_hz=rate,
        initial=back_start,
        params=params,
    )
    return replace(initial, quat_wxyz=back[-1], lowpass_from_gravity=True)
