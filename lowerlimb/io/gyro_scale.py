"""Whether a gyro is in rad/s: its turns must carry the accelerometer's gravity from one rest to the next.

The range check (a gyro above 35 rad/s is in deg/s) misses slow motions: a squat whose fastest
turn is 31 deg/s read as rad/s passes it, and the calibration then reports knee flexion of
thousands of degrees with exit status 0. The accelerometer tells the unit. Between two moments at
which a sensor is quasi-static (its specific force near gravity and steady), the gravity it sees
turns by exactly the sensor's own rotation, which the gyro integrates (``u(t+dt) = exp(−ω dt) u(t)``
in the sensor frame). So each such window, integrated at the gyro's scale, must land near the
accelerometer's gravity at its end; a gyro in deg/s read as rad/s turns it 57 times too far.

Measured (``GyroScaleParams`` defaults; the median over windows of 0.5 and 1 s whose two ends
are quasi-static, per sensor): valid recordings land 0.1–15° off (simulated walks, squats,
half-squats, knee lifts, sit-to-stands and the mixed motion, rigid and with the real-walk
artefacts, seven-IMU walks at three paces; the real walk of ``gait/`` 0.4–1.6°, the rig
1.9–3.1°, RING 0.1–0.6°); the same simulated squats, half-squats and sit-to-stands with the gyro
in deg/s read as rad/s land 35–92° off, and 1–9° when scaled by π/180. A gyro 57 times too
small (rad/s data converted as if deg/s) lands where the sensor's tilt change leaves it (5–19°
on those motions) and within 1–7° when scaled back. Walking's quasi-static moments are mostly
its standing start, where a deg/s gyro is caught by the range check anyway.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import uniform_filter1d

from ..conventions import GRAVITY_MPS2, FloatArray
from ..errors import UnitError

__all__ = ["GYRO_SCALE", "GyroScale", "GyroScaleParams", "check_gyro_scale", "gyro_scale"]

_DEG = np.pi / 180.0


@dataclass(frozen=True)
class GyroScaleParams:
    """Thresholds of the gyro unit test.

    Attributes:
        quiet_norm_tol_mps2: a quasi-static sample's specific force (its mean over
            ``quiet_window_s``) is within this of gravity, m/s².
        quiet_std_mps2: ... and varies less than this over ``quiet_window_s`` (RMS), m/s², or
            than ``quiet_noise_factor`` times the sensor's own noise there (the 5th percentile of
            that variation over the trial), whichever is larger: a noisy accelerometer
            (0.25 m/s² per axis) otherwise had no quasi-static moment left.
        quiet_noise_factor: see ``quiet_std_mps2``.
        quiet_window_s: the window of that variation, s.
        window_lengths_s: lengths of the integration windows, s.
        window_step_s: one window starts every this often (at most), s.
        max_windows: at most this many windows of each length (evenly spread).
        min_windows: fewer windows than this decide nothing.
        deg_min_deg: a gyro whose windows land further off than this (median, deg) ...
        deg_ratio: ... and land within this fraction of it when scaled by π/180 is in deg/s.
        small_min_deg: a gyro whose windows land further off than this (median, deg) ...
        small_max_deg: ... and within this (median, deg) when scaled by 180/π ...
        small_ratio: ... and that is within this fraction of the first is 57 times too small.
    """

    quiet_norm_tol_mps2: float = 0.4
    quiet_std_mps2: float = 0.3
    quiet_noise_factor: float = 2.0
    quiet_window_s: float = 0.1
    window_lengths_s: tuple[float, ...] = (0.5, 1.0)
    window_step_s: float = 0.05
    max_windows: int = 300
    min_windows: int = 20
    deg_min_deg: float = 30.0
    deg_ratio: float = 0.25
    small_min_deg: float = 5.0
    small_max_deg: float = 5.0
    small_ratio: float = 0.33


#: The thresholds used unless a caller passes others.
GYRO_SCALE = GyroScaleParams()


@dataclass(frozen=True)
class GyroScale:
    """Where one sensor's quasi-static windows land at three gyro scales (median angles, deg).

    Attributes:
        n_windows: number of windows.
        as_given: the gyro as given (rad/s).
        as_deg: the gyro multiplied by π/180 (it was in deg/s).
        as_small: the gyro multiplied by 180/π (it was 57 times too small).
    """

    n_windows: int
    as_given: float
    as_deg: float
    as_small: float

    def verdict(self, params: GyroScaleParams = GYRO_SCALE) -> str | None:
        """``"deg/s"``, ``"too small"`` or ``None`` (rad/s, or nothing decided)."""
        if self.n_windows < params.min_windows:
            return None
        if self.as_given > params.deg_min_deg and self.as_deg < params.deg_ratio * self.as_given:
            return "deg/s"
        if (
            self.as_given > params.small_min_deg
            and self.as_small < params.small_max_deg
            and self.as_small < params.small_ratio * self.as_given
        ):
            return "too small"
        return None


def _rotate(v: FloatArray, rotvec: FloatArray) -> FloatArray:
    """Each row of ``v`` (M, 3) turned by the matching rotation vector (M, 3), rad (Rodrigues)."""
    th = np.linalg.norm(rotvec, axis=1, keepdims=True)
    k = rotvec / np.maximum(th, 1e-12)
    c, s = np.cos(th), np.sin(th)
    out: FloatArray = v * c + np.cross(k, v) * s + k * np.sum(k * v, axis=1, keepdims=True) * (1.0 - c)
    return out


def _windows(quiet: np.ndarray, n: int, step: int, max_windows: int) -> np.ndarray:
    """Start samples of windows of ``n`` samples whose two ends are quasi-static."""
    starts = np.flatnonzero(quiet[:-n] & quiet[n:])[::step]
    if starts.size > max_windows:
        starts = starts[np.linspace(0, starts.size - 1, max_windows).astype(int)]
    return starts


def _landing_deg(
    up: FloatArray, gyr: FloatArray, windows: list[tuple[int, np.ndarray]], scale: float
) -> float:
    """Median angle between the integrated and the measured gravity at the windows' ends, deg."""
    out = []
    for n, starts in windows:
        v = up[starts]
        for j in range(n):
            v = _rotate(v, -gyr[starts + j] * scale)
        out.append(np.degrees(np.arccos(np.clip(np.sum(v * up[starts + n], axis=1), -1.0, 1.0))))
    return float(np.median(np.concatenate(out)))


def gyro_scale(
    acc: FloatArray, gyr: FloatArray, rate_hz: float, params: GyroScaleParams = GYRO_SCALE
) -> GyroScale:
    """How far the gyro carries the accelerometer's gravity between quasi-static moments.

    The two other scales are tried only where the gyro as given lands far enough off to be
    refused (``NaN`` otherwise).

    Args:
        acc: (N, 3) specific force, sensor frame, m/s².
        gyr: (N, 3) angular rate, sensor frame, rad/s (as given).
        rate_hz: sampling rate, Hz.
        params: thresholds.

    Returns:
        The median landing error of the windows at each of three scales.
    """
    acc = np.asarray(acc, dtype=float)
    gyr = np.asarray(gyr, dtype=float)
    w = max(3, int(round(params.quiet_window_s * rate_hz)))
    mean = uniform_filter1d(acc, w, axis=0, mode="nearest")
    spread = np.sqrt(np.maximum(uniform_filter1d(np.sum((acc - mean) ** 2, axis=1), w, mode="nearest"), 0.0))
    tol = max(params.quiet_std_mps2, params.quiet_noise_factor * float(np.percentile(spread, 5)))
    quiet = (np.abs(np.linalg.norm(mean, axis=1) - GRAVITY_MPS2) < params.quiet_norm_tol_mps2) & (
        spread < tol
    )
    up = mean / np.maximum(np.linalg.norm(mean, axis=1), 1e-9)[:, None]
    step = max(1, int(round(params.window_step_s * rate_hz)))
    windows = []
    for length_s in params.window_lengths_s:
        n = int(round(length_s * rate_hz))
        if 2 <= n < len(acc):
            starts = _windows(quiet, n, step, params.max_windows)
            if starts.size:
                windows.append((n, starts))
    m = sum(starts.size for _, starts in windows)
    if m < params.min_windows:
        return GyroScale(m, float("nan"), float("nan"), float("nan"))
    given = _landing_deg(up, gyr, windows, 1.0 / rate_hz)
    as_deg = _landing_deg(up, gyr, windows, _DEG / rate_hz) if given > params.deg_min_deg else float("nan")
    as_small = (
        _landing_deg(up, gyr, windows, 1.0 / (_DEG * rate_hz))
        if given > params.small_min_deg
        else float("nan")
    )
    return GyroScale(m, given, as_deg, as_small)


def check_gyro_scale(
    acc: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    rate_hz: float,
    sensors: Iterable[str],
    params: GyroScaleParams = GYRO_SCALE,
) -> None:
    """Refuse a gyro whose turns do not match its accelerometer's (see the module docstring).

    Raises:
        UnitError: naming the sensor, how far off its windows land and the fix.
    """
    for sensor in sensors:
        scale = gyro_scale(acc[sensor], gyr[sensor], rate_hz, params)
        verdict = scale.verdict(params)
        if verdict == "deg/s":
            raise UnitError(
                f"{sensor}_gyr",
                scale.as_given,
                f"{sensor} gyro looks like deg/s: integrated between moments at rest it turns the "
                f"accelerometer's gravity {scale.as_given:.0f}° away from where the accelerometer "
                f"finds it ({scale.as_deg:.0f}° read as deg/s); the trial format expects rad/s "
                f"(multiply by π/180)",
            )
        if verdict == "too small":
            raise UnitError(
                f"{sensor}_gyr",
                scale.as_given,
                f"{sensor} gyro turns about 57 times too little: integrated between moments at rest "
                f"it leaves the accelerometer's gravity {scale.as_given:.0f}° off "
                f"({scale.as_small:.0f}° multiplied by 180/π); rad/s data converted as if in deg/s? "
                f"the trial format expects rad/s",
            )
