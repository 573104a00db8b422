"""Motion-adaptive low-pass prefilter of the IMU signals before the joint constraints.

Why: gyro noise differentiated into α is noise in the regressors of the
spherical-joint problem and shrinks the estimated joint centres (errors in
variables). Slow motions (squats, sit-to-stand: gyro bandwidth ≈ 2 Hz)
suffer most; walking needs more bandwidth (foot ≈ 12 Hz). A fixed filter
cannot serve both, so each sensor gets its own cut-off (choices the paper
leaves open, tuned on the simulator):

- the gyro's power spectral density (Welch, 5 s segments, summed over axes)
  is compared with the white-noise level, estimated from the standing-still
  period at the start (or, without one, from the median PSD above 0.35·rate);
- the motion bandwidth ``B`` is the highest frequency whose PSD exceeds
  ``snr`` (10) times the noise level;
- the cut-off is ``factor · B`` (the calibration uses factor 1.5), at least
  ``min_hz`` (2.5 Hz); at or above 0.45·rate the signal is left unfiltered;
- gyro and accelerometer of that sensor are filtered by the same zero-phase
  4th-order Butterworth low-pass (``sosfiltfilt``), so that a, ω and α
  share one frequency response.

The cut-off is decided per sensor (walking: the pelvis is slow, the thigh
fast), and a joint's two sensors are then filtered at the higher of their two
cut-offs (:mod:`lowerlimb.calibration.joint_cutoff`): the constraint compares
what both see of the joint, and different filters on the two sides bias it.
The factor is tuned on simulated walks with realistic noise
(``benchmarks/calibration_accuracy.py --option cutoff_factor=…``): lower
factors bias the fast sensors, higher ones let α noise through.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import butter, sosfiltfilt, welch

from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError

__all__ = ["motion_bandwidth_hz", "adaptive_cutoff_hz", "rigid_band_hz", "lowpass", "usable_cutoff_hz"]

_NYQUIST_FRACTION = 0.45
_SEGMENT_S = 5.12


def _psd(gyr: FloatArray, rate_hz: float) -> tuple[FloatArray, FloatArray]:
    nper = int(min(gyr.shape[0], max(16, round(_SEGMENT_S * rate_hz))))
    f, P = welch(gyr, fs=rate_hz, nperseg=nper, axis=0)
    return np.asarray(f, dtype=float), np.asarray(P, dtype=float).sum(axis=1)


def motion_bandwidth_hz(
    gyr: ArrayLike, rate_hz: float, *, noise_std: float | None = None, snr: float = 10.0
) -> float:
    """Highest frequency at which the gyro's power exceeds ``snr`` times its white-noise level.

    Args:
        gyr: (N, 3) angular velocity (bias removed), rad/s.
        rate_hz: sampling rate, Hz.
        noise_std: white-noise standard deviation per axis, rad/s (e.g. from a
            still period); ``None`` estimates it from the top of the spectrum.
        snr: power ratio over the noise level that counts as motion.

    Returns:
        The bandwidth, Hz (0 when nothing rises above the noise).
    """
    g = np.asarray(gyr, dtype=float)
    f, P = _psd(g, rate_hz)
    if noise_std is not None and noise_std > 0:
        level = 3 * 2 * noise_std**2 / rate_hz  # one-sided PSD of white noise, summed over axes
    else:
        level = float(np.median(P[f > 0.35 * rate_hz])) if np.any(f > 0.35 * rate_hz) else 0.0
    above = np.flatnonzero(P > snr * max(level, 1e-30))
    return float(f[above[-1]]) if above.size else 0.0


def adaptive_cutoff_hz(
    gyr: ArrayLike,
    rate_hz: float,
    *,
    noise_std: float | None = None,
    factor: float = 1.5,
    min_hz: float = 2.5,
    snr: float = 10.0,
) -> float | None:
    """Low-pass cut-off for one sensor: ``max(min_hz, factor · bandwidth)``.

    Args:
        gyr: (N, 3) angular velocity (bias removed), rad/s.
        rate_hz: sampling rate, Hz.
        noise_std: gyro white-noise standard deviation per axis, rad/s, or ``None``.
        factor: cut-off over bandwidth.
        min_hz: lowest cut-off, Hz.
        snr: see :func:`motion_bandwidth_hz`.

    Returns:
        The cut-off in Hz, or ``None`` when it would reach 0.45·rate (no filtering).
    """
    fc = max(min_hz, factor * motion_bandwidth_hz(gyr, rate_hz, noise_std=noise_std, snr=snr))
    return None if fc >= _NYQUIST_FRACTION * rate_hz else float(fc)


def rigid_band_hz(
    acc_parent: ArrayLike,
    acc_child: ArrayLike,
    rate_hz: float,
    *,
    threshold: float = 0.3,
    segment_s: float = 1.28,
    start_hz: float = 1.0,
    power_db: float = -15.0,
    gyr: ArrayLike | None = None,
    max_rotation: float | None = None,
) -> float | None:
    """Upper edge of the band in which two sensors of one joint move as a rigid chain.

    Both sensors see the joint centre's acceleration, so the parts of their
    signals that come from the segments' motion are coherent, while soft-tissue
    wobble, strap resonance and impact ringing of each sensor are not. The
    magnitude-squared coherence of the two accelerometer norms (rotation
    invariant; Welch segments of ``segment_s``, smoothed over three bins) is
    followed upwards from ``start_hz``; the band ends at the first frequency
    where it falls below ``threshold`` while either signal still carries
    power (within ``power_db`` of its spectral peak): an incoherent bin with
    next to no power is harmless and is skipped. On clean rigid motion the
    band reaches the motion bandwidth; on real thigh and shank sensors it ends
    a few hertz above the stride harmonics.

    Args:
        acc_parent: (N, 3) parent accelerometer, parent sensor frame, m/s².
        acc_child: (N, 3) child accelerometer, child sensor frame, m/s².
        rate_hz: sampling rate, Hz.
        threshold: coherence (0–1) below which the chain is no longer rigid.
        segment_s: Welch segment length, s (sets the frequency resolution).
        start_hz: lowest frequency inspected, Hz (below it the stride
            fundamental and slow posture changes dominate).
        power_db: a bin counts when either norm's power is within this many dB
            of that norm's peak.
        gyr: (N, k) the two sensors' gyros side by side, rad/s, to leave out the segments
            of unusual rotation (a fast turn: the two norms' centripetal parts differ, which
            is rotation, not soft tissue), or ``None``.
        max_rotation: a segment whose mean squared rate exceeds this many times the moving
            segments' median is left out (``None``: none is).

    Returns:
        The band edge, Hz, or ``None`` when the recording is too short to tell
        or the coherence never falls below ``threshold``.
    """
    a = np.linalg.norm(np.asarray(acc_parent, dtype=float), axis=1)
    b = np.linalg.norm(np.asarray(acc_child, dtype=float), axis=1)
    nper = int(round(segment_s * rate_hz))
    if a.shape[0] < 4 * nper or nper < 8:
        return None
    a, b = a - a.mean(), b - b.mean()
    keep = None if gyr is None or max_rotation is None else _usual_rotation(gyr, nper, max_rotation)
    f, P_aa, P_bb, P_ab = welch_spectra(a, b, rate_hz, nper, keep)
    with np.errstate(divide="ignore", invalid="ignore"):
        C = np.abs(P_ab) ** 2 / P_aa / P_bb
    smooth = np.convolve(np.nan_to_num(C), np.ones(3) / 3.0, mode="same")
    level = 10.0 ** (power_db / 10.0)
    strong = np.zeros(f.shape, dtype=bool)
    for P in (P_aa, P_bb):
        strong |= P >= level * max(float(P.max()), 1e-30)
    start = int(np.searchsorted(f, start_hz))
    below = np.flatnonzero((smooth[start:] < threshold) & strong[start:])
    return float(f[start + below[0]]) if below.size else None


#: A Welch segment counts as moving when its squared rate reaches this share of the 90th percentile.
_MOVING_SHARE = 0.1


def _usual_rotation(gyr: ArrayLike, nper: int, max_rotation: float) -> np.ndarray | None:
    """(segments,) ``True`` for the Welch segments whose mean squared rate is usual; ``None``: all.

    Usual: at most ``max_rotation`` times the median over the moving segments (those reaching
    :data:`_MOVING_SHARE` of the 90th percentile; a standing start is not the reference).
    Fewer than four usual segments keep them all.
    """
    w2 = np.sum(np.asarray(gyr, dtype=float) ** 2, axis=1)
    step = nper - nper // 2
    n_seg = (w2.shape[0] - nper) // step + 1
    seg = np.lib.stride_tricks.sliding_window_view(w2, nper)[::step][:n_seg].mean(axis=1)
    moving = seg[seg >= _MOVING_SHARE * np.percentile(seg, 90)]
    keep = seg <= max_rotation * np.median(moving)
    return keep if np.count_nonzero(keep) >= 4 else None


def welch_spectra(
    a: FloatArray, b: FloatArray, rate_hz: float, nper: int, keep: np.ndarray | None = None
) -> tuple[FloatArray, FloatArray, FloatArray, NDArray[np.complex128]]:
    """Welch auto- and cross-spectra of two signals, as ``scipy.signal.welch``/``csd`` compute them.

    Hann window, half-overlapping segments of ``nper`` samples, each detrended by
    its mean, one-sided power spectral densities: the same numbers (to rounding) as
    ``welch(a)``, ``welch(b)`` and ``csd(a, b)`` with ``nperseg=nper``, in one pass
    over strided segments instead of a Python call per segment.

    Args:
        a: (N,) first signal.
        b: (N,) second signal, same length.
        rate_hz: sampling rate, Hz.
        nper: segment length, samples (≤ N).
        keep: (segments,) ``True`` for the segments to average, or ``None`` (all).

    Returns:
        ``(f, P_aa, P_bb, P_ab)``: frequencies (Hz) and the three spectra (unit²/Hz;
        the cross-spectrum is complex).
    """
    from scipy.signal import get_window

    step = nper - nper // 2
    n_seg = (a.shape[0] - nper) // step + 1
    rows = np.arange(nper)[None, :] + step * np.arange(n_seg)[:, None]
    window = get_window("hann", nper)

    def segments(x: FloatArray) -> NDArray[np.complex128]:
        s = x[rows]
        return np.fft.rfft((s - s.mean(axis=1, keepdims=True)) * window, axis=1)

    A, B = segments(a), segments(b)
    if keep is not None:
        A, B = A[keep], B[keep]
    scale = 1.0 / (rate_hz * float(window @ window))
    doubled = np.full(nper // 2 + 1, 2.0)  # one-sided: every bin but DC (and Nyquist) twice
    doubled[0] = 1.0
    if nper % 2 == 0:
        doubled[-1] = 1.0
    P_aa = np.asarray((A.real**2 + A.imag**2).mean(axis=0) * scale * doubled, dtype=float)
    P_bb = np.asarray((B.real**2 + B.imag**2).mean(axis=0) * scale * doubled, dtype=float)
    P_ab = np.asarray((np.conj(A) * B).mean(axis=0) * scale * doubled, dtype=np.complex128)
    return np.asarray(np.fft.rfftfreq(nper, 1.0 / rate_hz), dtype=float), P_aa, P_bb, P_ab


def usable_cutoff_hz(cutoff_hz: float | None, rate_hz: float) -> float | None:
    """``cutoff_hz``, or ``None`` (no filtering) when it reaches 0.45·rate.

    A cut-off derived from others (a cap times a probe factor, a widened adaptive one)
    can pass the Nyquist frequency; such a filter would keep everything, so the signal
    is left unfiltered rather than refused.
    """
    if cutoff_hz is None or cutoff_hz >= _NYQUIST_FRACTION * rate_hz:
        return None
    return float(cutoff_hz)


def lowpass(x: ArrayLike, rate_hz: float, cutoff_hz: float | None, order: int = 4) -> FloatArray:
    """Zero-phase Butterworth low-pass along axis 0 (``None`` cut-off: returned unchanged).

    Args:
        x: (N, ...) signal, any unit.
        rate_hz: sampling rate, Hz.
        cutoff_hz: -3 dB frequency of each pass, Hz, below 0.5·rate; or ``None``.
        order: Butterworth order (applied forward and backward).

    Returns:
        The filtered signal, same shape and unit.

    Raises:
        InputError: for a cut-off at or above the Nyquist frequency.
    """
    arr = np.asarray(x, dtype=float)
    if cutoff_hz is None:
        return arr
    if not 0 < cutoff_hz < 0.5 * rate_hz:
        raise InputError(
            f"cutoff_hz must be between 0 and half the sampling rate ({0.5 * rate_hz:g} Hz), got {cutoff_hz}"
        )
    sos = butter(order, cutoff_hz, fs=rate_hz, output="sos")
    padlen = min(arr.shape[0] - 1, 3 * (2 * len(sos) + 1))
    return np.asarray(sosfiltfilt(sos, arr, axis=0, padlen=padlen), dtype=float)
