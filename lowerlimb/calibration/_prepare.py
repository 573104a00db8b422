"""Input checks and signal preparation shared by the calibration functions (internal)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.calibration.joint_cutoff import joint_cutoffs_hz
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.constraints.angular_acceleration import angular_acceleration, window_length
from lowerlimb.constraints.prefilter import adaptive_cutoff_hz, lowpass, rigid_band_hz, usable_cutoff_hz
from lowerlimb.constraints.regressor_noise import filter_noise_gains, white_noise_std
from lowerlimb.constraints.spherical import SphericalData, kinematic_matrix
from lowerlimb.conventions import MAX_GYRO_RAD_S as GYRO_DEG_PER_S_THRESHOLD
from lowerlimb.conventions import MIN_MEDIAN_ACC_MPS2, FloatArray
from lowerlimb.errors import InputError, NonFiniteValueError, ShapeError, UnitError
from lowerlimb.stillness import StillPeriod, detect_still_period, gyro_bias
from lowerlimb.upsample import upsample_factor, upsampled

#: Shortest signal accepted by the calibration, s.
MIN_DURATION_S = 1.0


def check_rate(rate_hz: float) -> float:
    """Return ``rate_hz`` as float if it is a positive finite number.

    Raises:
        InputError: naming the fix.
    """
    try:
        r = float(rate_hz)
    except (TypeError, ValueError):
        raise InputError(
            f"rate_hz must be the sampling rate in Hz (a positive number), got {rate_hz!r}"
        ) from None
    if not (np.isfinite(r) and r > 0):
        raise InputError(f"rate_hz must be the sampling rate in Hz (a positive number), got {r}")
    return r


def check_signal(x: ArrayLike, name: str, unit: str, n: int | None = None) -> FloatArray:
    """A finite (N, 3) float array, or an :class:`InputError` that names the fix.

    Raises:
        ShapeError: wrong shape or a length different from ``n``.
        NonFiniteValueError: NaN or inf in the signal.
        UnitError: a gyro that looks like deg/s, an accelerometer that looks like g.
    """
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ShapeError(f"{name} must be a numeric (N, 3) array in {unit}") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        hint = " (transpose it: one row per sample)" if arr.ndim == 2 and arr.shape[0] == 3 else ""
        raise ShapeError(
            f"{name} must have shape (N, 3): one row per sample, columns x, y, z in {unit}; "
            f"got shape {arr.shape}{hint}"
        )
    if n is not None and arr.shape[0] != n:
        raise ShapeError(
            f"{name} has {arr.shape[0]} samples but the first signal has {n}; "
            f"pass synchronised signals of equal length"
        )
    bad = ~np.isfinite(arr)
    if bad.any():
        row = int(np.flatnonzero(bad.any(axis=1))[0])
        raise NonFiniteValueError(name, row)
    if unit == "rad/s":
        peak = float(np.max(np.linalg.norm(arr, axis=1))) if arr.size else 0.0
        if peak > GYRO_DEG_PER_S_THRESHOLD:
            raise UnitError(
                name,
                peak,
                f"{name} values up to {peak:.0f} look like deg/s; the calibration expects "
                f"rad/s (multiply by π/180)",
            )
    if unit == "m/s²" and arr.size:
        step = max(1, arr.shape[0] // 2000)  # a subsample's median tells g from m/s²
        median = float(np.median(np.linalg.norm(arr[::step], axis=1)))
        if median < MIN_MEDIAN_ACC_MPS2:
            raise UnitError(
                name,
                median,
                f"{name} norms around {median:.2f} look like g; the calibration expects "
                f"m/s² specific force, gravity included (multiply by 9.81)",
            )
    return np.ascontiguousarray(arr)


def check_duration(n: int, rate_hz: float, options: CalibrationOptions) -> None:
    """Raise an :class:`InputError` when ``n`` samples are too few to calibrate."""
    need = max(
        int(np.ceil(MIN_DURATION_S * rate_hz)),
        window_length(rate_hz, options.angacc_window_s, options.angacc_polyorder),
        12,
    )
    if n < need:
        raise InputError(
            f"got {n} samples ({n / rate_hz:.2f} s at {rate_hz:g} Hz) but the calibration needs "
            f"at least {need}; record at least {MIN_DURATION_S:g} s of varied motion"
        )


@dataclass(frozen=True)
class PreparedSignals:
    """Bias-corrected gyros and their derivatives, per sensor name.

    Attributes:
        rate_hz: sampling rate, Hz.
        acc: ``{sensor: (N, 3)}`` specific force, sensor frame, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity with the bias removed, rad/s.
        angacc: ``{sensor: (N, 3)}`` angular acceleration, rad/s².
        gyro_bias: ``{sensor: (3,)}`` the bias that was removed, rad/s.
        n_still: number of still samples found at the start (0 = none, no bias removed).
        cutoff_hz: ``{sensor: cut-off}`` of the prefilter, Hz (``None``: unfiltered).
        gyro_noise_std: ``{sensor: σ}`` gyro white noise per axis during the still
            period, rad/s (``None`` without a still period).
        regressor_noise: ``{sensor: (σ_ω, σ_α)}`` white noise per axis of the
            filtered gyro (rad/s) and of α (rad/s²), from the still period's
            first differences through the filter chain
            (:mod:`~lowerlimb.constraints.regressor_noise`; ``(0, 0)`` without a
            still period).
        kin: ``{sensor: (N, 3, 3)}`` with ``options.filter_regressor``: the kinematic
            matrix ``K = [ω]ײ + [α]×`` of the unfiltered gyro, low-passed at the
            sensor's cut-off like its accelerometer, 1/s² (empty otherwise).
    """

    rate_hz: float
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]
    angacc: dict[str, FloatArray]
    gyro_bias: dict[str, FloatArray]
    n_still: int
    cutoff_hz: dict[str, float | None]
    gyro_noise_std: dict[str, float | None]
    regressor_noise: dict[str, tuple[float, float]] = field(default_factory=dict)
    kin: dict[str, FloatArray] = field(default_factory=dict)


def prepare_signals(
    acc: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    rate_hz: float,
    options: CalibrationOptions,
    *,
    still: StillPeriod | None = None,
    n_still: int | None = None,
    set_hz: Mapping[str, float | None] | None = None,
    bias: Mapping[str, FloatArray] | None = None,
) -> PreparedSignals:
    """Remove the gyro bias of a still start, low-pass (adaptively) and differentiate the gyros.

    Args:
        acc: ``{sensor: (N, 3)}`` checked accelerometer signals, m/s² (may be empty).
        gyr: ``{sensor: (N, 3)}`` checked gyro signals, rad/s.
        rate_hz: sampling rate, Hz.
        options: calibration options (window, bias removal).
        still: the still start when already detected on these signals (else detected here).
        n_still: the number of still samples when already decided (a sub-set of
            sensors of prepared signals: the same bias window; overrides ``still``).
        set_hz: ``{sensor: Hz or None}`` cut-offs decided by the caller (a joint's
            cut-offs, :func:`~lowerlimb.calibration.joint_cutoff.joint_cutoffs_hz`;
            ``None``: unfiltered); they replace those sensors' adaptive cut-offs.
        bias: ``{sensor: (3,)}`` gyro biases already measured (a sub-set of sensors of
            prepared signals: the same bias), rad/s; else measured here over the still start.

    Returns:
        The prepared signals.
    """
    quiet = None
    n_end = 0
    if n_still is None:
        n_still = 0
        if options.remove_gyro_bias:
            found = still or detect_still_period(list(gyr.values()), list(acc.values()), rate_hz)
            n_still = found.samples(options.still_min_s)
            quiet = found.quiet
            n_end = found.bias_end(options.still_min_s, options.still_end_min_s)
    if bias is None:
        bias = {k: gyro_bias(g, n_still, quiet, n_end) for k, g in gyr.items()}
    else:
        bias = {k: np.asarray(bias[k], dtype=float) for k in gyr}
    gyr_c = {k: g - bias[k] for k, g in gyr.items()}
    noise: dict[str, float | None] = {
        k: float(np.mean(np.std(g[:n_still], axis=0))) if n_still >= 10 else None for k, g in gyr_c.items()
    }
    cutoff: dict[str, float | None] = {}
    for k, g in gyr_c.items():
        if set_hz is not None and k in set_hz:
            cutoff[k] = usable_cutoff_hz(set_hz[k], rate_hz)
        elif not options.prefilter:
            cutoff[k] = None
        elif options.cutoff_hz is not None:
            cutoff[k] = usable_cutoff_hz(options.cutoff_hz, rate_hz)
        else:
            cutoff[k] = adaptive_cutoff_hz(
                g,
                rate_hz,
                noise_std=noise[k],
                factor=options.cutoff_factor,
                min_hz=options.min_cutoff_hz,
            )
    kin = (
        {k: filtered_regressor(g, rate_hz, cutoff[k], options) for k, g in gyr_c.items()}
        if options.filter_regressor
        else {}
    )
    gyr_c = {k: lowpass(g, rate_hz, cutoff[k]) for k, g in gyr_c.items()}
    acc_f = {k: lowpass(a, rate_hz, cutoff.get(k)) for k, a in acc.items()}
    angacc = {
        k: angular_acceleration(
            g, rate_hz, window_s=options.angacc_window_s, polyorder=options.angacc_polyorder
        )
        for k, g in gyr_c.items()
    }
    regressor: dict[str, tuple[float, float]] = {}
    for k, g in gyr.items():
        white = white_noise_std(g[:n_still]) or 0.0
        gains = filter_noise_gains(
            float(rate_hz), cutoff[k], options.angacc_window_s, options.angacc_polyorder
        )
        regressor[k] = (white * gains[0], white * gains[1])
    if kin:  # the regressor is filtered, not squared after filtering: no noise bias to correct
        regressor = {k: (0.0, 0.0) for k in regressor}
    return PreparedSignals(rate_hz, acc_f, gyr_c, angacc, bias, n_still, cutoff, noise, regressor, kin)


def filtered_regressor(
    gyr: FloatArray, rate_hz: float, cutoff_hz: float | None, options: CalibrationOptions
) -> FloatArray:
    """The kinematic matrix of a bias-corrected, unfiltered gyro, low-passed, (N, 3, 3) 1/s².

    The rigid-body relation ``g = a + K(ω, α) c`` is linear in ``a`` and ``K``, so a
    linear low-pass applied to both keeps it exactly in the sensor's frame; squaring
    a low-passed ω instead (``K(F ω, F α)``) does not, and the difference biases the
    centre when the cut-off is low (module docstring of
    :mod:`~lowerlimb.constraints.spherical`).

    Args:
        gyr: (N, 3) gyro with the bias removed, rad/s.
        rate_hz: sampling rate, Hz.
        cutoff_hz: the sensor's cut-off, Hz (``None``: unfiltered).
        options: the α window (``angacc_window_s``, ``angacc_polyorder``).
    """
    al = angular_acceleration(
        gyr, rate_hz, window_s=options.angacc_window_s, polyorder=options.angacc_polyorder
    )
    K = kinematic_matrix(gyr, al)
    n = K.shape[0]
    return np.asarray(lowpass(K.reshape(n, 9), rate_hz, cutoff_hz), dtype=float).reshape(n, 3, 3)


def rigid_band_cap_hz(
    acc_parent: FloatArray,
    acc_child: FloatArray,
    rate_hz: float,
    options: CalibrationOptions,
    gyr: FloatArray | None = None,
) -> float | None:
    """The cut-off cap of one joint from its rigid band (``None``: no cap), Hz.

    ``gyr``: (N, 6) the two sensors' gyros side by side, rad/s, so that segments of unusual
    rotation are left out (``CalibrationOptions.rigid_band_max_rotation``), or ``None``.
    """
    if not (options.prefilter and options.rigid_band) or options.cutoff_hz is not None:
        return None
    band = rigid_band_hz(
        acc_parent,
        acc_child,
        rate_hz,
        threshold=options.rigid_band_coherence,
        gyr=gyr,
        max_rotation=options.rigid_band_max_rotation,
    )
    if band is None:
        return None
    cap = max(options.rigid_band_min_hz, options.rigid_band_factor * band)
    return usable_cutoff_hz(cap, rate_hz)


def joint_signals(
    acc: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    sig: PreparedSignals,
    parent: str,
    child: str,
    options: CalibrationOptions,
    caps: dict[str, float | None] | None = None,
    cap_hz: float | None = None,
    *,
    own_band: bool = True,
    max_hz: float | None = None,
    capped: set[str] | None = None,
) -> SphericalData:
    """One joint's pair data, filtered at the joint's cut-offs (:mod:`~lowerlimb.calibration.joint_cutoff`).

    A sensor whose adaptive cut-off reaches far above the joint's rigid-band cap
    is capped; then (``options.shared_joint_cutoff``) both sensors take the
    higher of the two cut-offs, so that both see the joint through one filter.

    Args:
        acc: ``{sensor: (N, 3)}`` raw accelerometer signals, m/s².
        gyr: ``{sensor: (N, 3)}`` raw gyro signals, rad/s.
        sig: the signals prepared for every sensor (still period, adaptive cut-offs).
        parent: parent sensor name.
        child: child sensor name.
        options: calibration options.
        caps: when given, receives the cap under the key ``f"{parent}-{child}"``,
            Hz or ``None`` (for the record).
        cap_hz: a cap decided by the caller, Hz, used with (the lower of the two)
            or instead of the pair's own rigid band.
        own_band: also compute the pair's own rigid band. A hinge sets it
            ``False``: its accelerometer norms need not agree, and it takes
            the caps of its neighbouring spherical joints instead.
        max_hz: an upper limit on both sensors' cut-offs after the cap, Hz (an
            unfiltered sensor is filtered at it; ``None``: no limit;
            :func:`~lowerlimb.calibration.impact_window.impact_cutoff_limit_hz`).
        capped: when given, receives ``f"{parent}-{child}"`` if the cap lowered the pair's
            cut-offs (the fit depends on the cap).

    Returns:
        The pair data.
    """
    rot = np.hstack([gyr[parent], gyr[child]])
    own = rigid_band_cap_hz(acc[parent], acc[child], sig.rate_hz, options, rot) if own_band else None
    given = [c for c in (own, cap_hz) if c is not None]
    cap = min(given) if given else None
    if caps is not None:
        caps[f"{parent}-{child}"] = cap
    want = joint_cutoffs_hz(sig.cutoff_hz[parent], sig.cutoff_hz[child], cap, options)
    if capped is not None and want != joint_cutoffs_hz(
        sig.cutoff_hz[parent], sig.cutoff_hz[child], None, options
    ):
        capped.add(f"{parent}-{child}")
    want = (_limited(want[0], max_hz, sig.rate_hz), _limited(want[1], max_hz, sig.rate_hz))
    if want == (sig.cutoff_hz[parent], sig.cutoff_hz[child]):
        return pair_data(sig, parent, child)
    sub = prepare_signals(
        {k: acc[k] for k in (parent, child)},
        {k: gyr[k] for k in (parent, child)},
        sig.rate_hz,
        options,
        n_still=sig.n_still,
        set_hz={parent: want[0], child: want[1]},
        bias={k: sig.gyro_bias[k] for k in (parent, child)},
    )
    return pair_data(sub, parent, child)


def _limited(cutoff_hz: float | None, max_hz: float | None, rate_hz: float) -> float | None:
    """``cutoff_hz`` (``None``: unfiltered) held at or below ``max_hz`` where that can filter."""
    lim = usable_cutoff_hz(max_hz, rate_hz)
    if lim is None:
        return cutoff_hz
    return lim if cutoff_hz is None else min(cutoff_hz, lim)


def pair_data(sig: PreparedSignals, parent: str = "p", child: str = "c") -> SphericalData:
    """The prepared signals of the ``parent`` and ``child`` sensors as a :class:`SphericalData`."""
    return SphericalData(
        sig.acc[parent],
        sig.gyr[parent],
        sig.angacc[parent],
        sig.acc[child],
        sig.gyr[child],
        sig.angacc[child],
        *sig.regressor_noise.get(parent, (0.0, 0.0)),
        *sig.regressor_noise.get(child, (0.0, 0.0)),
        kin_parent=sig.kin.get(parent),
        kin_child=sig.kin.get(child),
    )


def prepare_pair(
    acc_parent: ArrayLike,
    gyr_parent: ArrayLike,
    acc_child: ArrayLike,
    gyr_child: ArrayLike,
    rate_hz: float,
    options: CalibrationOptions,
    *,
    rigid_band: bool = False,
) -> tuple[PreparedSignals, SphericalData]:
    """Check the four signals of a sensor pair and prepare them (sensors ``"p"`` and ``"c"``).

    ``rigid_band`` caps the cut-offs at the pair's rigid band (off by default:
    the coherence of the accelerometer norms is a proxy made for the leg's
    gait-like motion, checked there; an arbitrary pair's motion can make the
    norms incoherent although the chain is rigid). Arguments and errors as
    :func:`prepare_pair_bands`.

    Returns:
        The prepared signals (``rate_hz`` checked) and the pair's :class:`SphericalData`.
    """
    b = prepare_pair_bands(acc_parent, gyr_parent, acc_child, gyr_child, rate_hz, options, band=rigid_band)
    return b.sig, b.full if b.capped is None else b.capped


@dataclass(frozen=True)
class PairBands:
    """A sensor pair prepared at its own cut-offs and, where its rigid band caps them, at the cap.

    Attributes:
        sig: the prepared signals of sensors ``"p"`` and ``"c"`` (rate checked, maybe upsampled).
        full: the pair's data at the sensors' own adaptive cut-offs.
        capped: the pair's data at the cut-offs its rigid band caps
            (:func:`rigid_band_cap_hz`), ``None`` where the cap changes no cut-off.
        cap_hz: the rigid band's cap, Hz (``None``: the norms stay coherent, or no band sought).
    """

    sig: PreparedSignals
    full: SphericalData
    capped: SphericalData | None
    cap_hz: float | None


def prepare_pair_bands(
    acc_parent: ArrayLike,
    gyr_parent: ArrayLike,
    acc_child: ArrayLike,
    gyr_child: ArrayLike,
    rate_hz: float,
    options: CalibrationOptions,
    *,
    band: bool = True,
) -> PairBands:
    """Check the four signals of a sensor pair; prepare them without and (``band``) with the rigid-band cap.

    A pair recorded below ``options.min_fit_rate_hz`` is interpolated first
    (:mod:`~lowerlimb.upsample`); the prepared signals carry the new rate.

    Args:
        acc_parent: (N, 3) parent accelerometer, m/s².
        gyr_parent: (N, 3) parent gyro, rad/s.
        acc_child: (N, 3) child accelerometer, m/s².
        gyr_child: (N, 3) child gyro, rad/s.
        rate_hz: sampling rate, Hz.
        options: calibration options.
        band: also seek the pair's rigid band and prepare the pair at its cap.

    Raises:
        ShapeError: an array is not (N, 3) or lengths differ.
        NonFiniteValueError: NaN or inf in a signal.
        UnitError: a gyro that looks like deg/s.
        InputError: non-positive rate or too few samples.
    """
    rate = check_rate(rate_hz)
    ap = check_signal(acc_parent, "acc_parent", "m/s²")
    n = ap.shape[0]
    wp = check_signal(gyr_parent, "gyr_parent", "rad/s", n)
    ac = check_signal(acc_child, "acc_child", "m/s²", n)
    wc = check_signal(gyr_child, "gyr_child", "rad/s", n)
    check_duration(n, rate, options)
    k = upsample_factor(rate, options.min_fit_rate_hz)
    acc, gyr = upsampled({"p": ap, "c": ac}, k), upsampled({"p": wp, "c": wc}, k)
    sig = prepare_signals(acc, gyr, rate * k, options)
    full = joint_signals(acc, gyr, sig, "p", "c", options, own_band=False)
    if not band:
        return PairBands(sig, full, None, None)
    caps: dict[str, float | None] = {}
    capped: set[str] = set()
    banded = joint_signals(acc, gyr, sig, "p", "c", options, caps, capped=capped)
    return PairBands(sig, full, banded if capped else None, caps["p-c"])
