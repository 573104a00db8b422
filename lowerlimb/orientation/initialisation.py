"""Initial attitude and gyro bias from the standing-still start of a recording.

A trial should begin with the subject standing still (docs/formats.md). During that
rest the accelerometer measures gravity only, which fixes the inclination; the
magnetometer, when given, fixes the heading; and the mean gyro reading is the
gyro bias. When the start is not still, the first samples still give a rough
attitude, but no bias is estimated (a moving sensor's mean rate is not bias).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from lowerlimb.conventions import GRAVITY_MPS2, FloatArray, quat_from_matrix
from lowerlimb.errors import InputError


@dataclass(frozen=True)
class RestParams:
    """Thresholds of the initial rest detection.

    A window of ``window_s`` is *still* when, over the window, the gyro
    standard deviation (norm of the per-axis std) is below ``gyr_std_rad_s``,
    the mean gyro rate is below ``gyr_mean_rad_s`` (a bias can be at most
    that large), the accelerometer standard deviation is below
    ``acc_std_mps2`` and the mean accelerometer norm is within
    ``acc_norm_tol_mps2`` of :data:`~lowerlimb.conventions.GRAVITY_MPS2`.
    The initial rest is the longest prefix made of still windows; it counts
    only when it lasts at least ``min_rest_s``.

    Attributes:
        window_s: Window length, s.
        gyr_std_rad_s: Gyro noise limit, rad/s (norm of the per-axis std).
        gyr_mean_rad_s: Largest mean gyro rate taken for bias, rad/s.
        acc_std_mps2: Accelerometer noise limit, m/s² (norm of the per-axis std).
        acc_norm_tol_mps2: Allowed |‖mean acc‖ − g|, m/s².
        min_rest_s: Shortest rest that is used for the bias estimate, s
            (after trimming ``trim_s``).
        trim_s: The last ``trim_s`` of the detected rest are not averaged:
            a gentle start of motion passes the window tests for a few samples
            and would bias the mean gyro rate.
        attitude_s: Without a rest, the initial attitude comes from the mean
            of the first ``attitude_s`` seconds.
        warm_start_s: Without a rest, that rough attitude (a foot mid-swing reads
            tens of m/s² besides gravity) is refined by running the filter over the
            first ``warm_start_s`` seconds and back to the first sample
            (:func:`lowerlimb.orientation.estimate.estimate_orientation`); ``0``: not.
            On a seven-IMU walk cut from a longer recording the right foot's strides
            came out 0.47, 0.61, 0.81, 0.99 m long (truth 1.25 m) while its filter
            converged from the swing's attitude.
    """

    window_s: float = 0.5
    gyr_std_rad_s: float = 0.05
    gyr_mean_rad_s: float = 0.1
    acc_std_mps2: float = 0.3
    acc_norm_tol_mps2: float = 1.0
    min_rest_s: float = 0.5
    trim_s: float = 0.25
    attitude_s: float = 0.05
    warm_start_s: float = 10.0


@dataclass(frozen=True)
class InitialState:
    """Initial state of an orientation filter.

    Attributes:
        quat_wxyz: (4,) initial orientation, sensor -> ENU.
        gyr_bias_rad_s: (3,) gyro bias in the sensor frame, rad/s (zeros when
            not estimated).
        rest_samples: Length of the still prefix in samples (0: the start is
            not still).
        bias_estimated: Whether ``gyr_bias_rad_s`` was estimated.
        mag_norm: Norm of the mean magnetic field at the start (unit of the
            magnetometer); NaN without magnetometer.
        mag_dip_rad: Dip of that field below the horizon, rad (positive in the
            northern hemisphere); NaN without magnetometer.
        acc_norm_mps2: Norm of the mean specific force at the start, m/s²
            (the local gravity as this accelerometer measures it).
        lowpass_from_gravity: Start the filters' earth-frame accelerometer low-pass
            at gravity instead of at the first sample rotated by ``quat_wxyz``: the
            attitude is known but the first samples move (a warm start; from a
            foot mid-swing, the first sample's 20 m/s² of motion held in the
            low-pass turned a correct start 40° off within 3 s).
    """

    quat_wxyz: FloatArray
    gyr_bias_rad_s: FloatArray
    rest_samples: int
    bias_estimated: bool
    mag_norm: float = float("nan")
    mag_dip_rad: float = float("nan")
    acc_norm_mps2: float = GRAVITY_MPS2
    lowpass_from_gravity: bool = False

    @classmethod
    def at(cls, quat_wxyz: ArrayLike) -> InitialState:
        """A start at orientation ``quat_wxyz`` (4,), zero bias, no magnetic reference."""
        return cls(
            quat_wxyz=np.asarray(quat_wxyz, dtype=float),
            gyr_bias_rad_s=np.zeros(3),
            rest_samples=0,
            bias_estimated=False,
        )


@njit(cache=True)
def _still_windows(
    gyr: FloatArray,
    acc: FloatArray,
    n: int,
    gyr_std: float,
    gyr_mean: float,
    acc_std: float,
    acc_tol: float,
    g: float,
) -> int:
    """Number of consecutive still windows ``[i, i+n)`` from ``i = 0`` (running sums, O(prefix))."""
    sg = np.zeros(3)
    sg2 = np.zeros(3)
    sa = np.zeros(3)
    sa2 = np.zeros(3)
    for k in range(n):
        for j in range(3):
            sg[j] += gyr[k, j]
            sg2[j] += gyr[k, j] * gyr[k, j]
            sa[j] += acc[k, j]
            sa2[j] += acc[k, j] * acc[k, j]
    n_windows = gyr.shape[0] - n + 1
    for i in range(n_windows):
        if i > 0:
            for j in range(3):
                go = gyr[i - 1, j]
                gi = gyr[i + n - 1, j]
                ao = acc[i - 1, j]
                ai = acc[i + n - 1, j]
                sg[j] += gi - go
                sg2[j] += gi * gi - go * go
                sa[j] += ai - ao
                sa2[j] += ai * ai - ao * ao
        var_g = 0.0
        var_a = 0.0
        mg = 0.0
        ma = 0.0
        for j in range(3):
            m_g = sg[j] / n
            m_a = sa[j] / n
            var_g += max(sg2[j] / n - m_g * m_g, 0.0)
            var_a += max(sa2[j] / n - m_a * m_a, 0.0)
            mg += m_g * m_g
            ma += m_a * m_a
        still = (
            var_g < gyr_std * gyr_std
            and mg < gyr_mean * gyr_mean
            and var_a < acc_std * acc_std
            and abs(np.sqrt(ma) - g) < acc_tol
        )
        if not still:
            return i
    return n_windows


def detect_initial_rest(
    gyr: FloatArray, acc: FloatArray, rate_hz: float, params: RestParams | None = None
) -> int:
    """Length of the still prefix of a recording.

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s².
        rate_hz: Sampling rate, Hz.
        params: Thresholds; :class:`RestParams` defaults when ``None``.

    Returns:
        The number of samples from the start during which the sensor is still,
        0 when the first window already moves (or when the recording is
        shorter than one window, or the rest is shorter than ``min_rest_s``).
    """
    p = params or RestParams()
    n = max(2, int(round(p.window_s * rate_hz)))
    if len(gyr) < n:
        return 0
    n_windows = _still_windows(
        np.ascontiguousarray(gyr, dtype=np.float64),
        np.ascontiguousarray(acc, dtype=np.float64),
        n,
        p.gyr_std_rad_s,
        p.gyr_mean_rad_s,
        p.acc_std_mps2,
        p.acc_norm_tol_mps2,
        GRAVITY_MPS2,
    )
    if n_windows == 0:
        return 0
    rest = n_windows - 1 + n
    return rest if rest >= p.min_rest_s * rate_hz else 0


def attitude_from_gravity(acc: FloatArray, mag: FloatArray | None = None) -> FloatArray:
    """Orientation (sensor -> ENU) from one gravity and, optionally, one magnetic field reading.

    Inclination from ``acc`` (the sensor's up direction). Heading from the
    horizontal part of ``mag`` (pointing north = ENU +y). Without ``mag``,
    heading 0 means the sensor x axis, projected on the horizontal plane,
    points east (ENU +x); when x is within 0.1° of vertical the sensor y axis
    points north instead.

    Args:
        acc: (3,) specific force at rest, sensor frame, m/s² (any scale).
        mag: (3,) magnetic field, sensor frame, any unit, or ``None``.

    Returns:
        (4,) unit quaternion ``w, x, y, z`` with ``w >= 0``.

    Raises:
        InputError: when ``acc`` or ``mag`` is zero or ``mag`` is within 1° of
            parallel to ``acc``.
    """
    up = np.asarray(acc, dtype=float)
    n_up = np.linalg.norm(up)
    if n_up == 0.0:
        raise InputError(
            "the accelerometer reads zero at the start; cannot find the gravity direction "
            "(cut the leading zero samples)"
        )
    up = up / n_up
    if mag is not None:
        north = np.asarray(mag, dtype=float)
        if not np.any(north):
            raise InputError("the magnetometer reads zero at the start; pass mag=None for a 6-axis estimate")
        north = north - np.dot(north, up) * up
        if np.linalg.norm(north) < np.sin(np.radians(1.0)) * float(np.linalg.norm(mag)):
            raise InputError(
                "the magnetic field is parallel to gravity at the start; heading is undefined "
                "(check the magnetometer, or pass mag=None for a 6-axis estimate)"
            )
        north /= np.linalg.norm(north)
        east = np.cross(north, up)
    else:
        east = np.array([1.0, 0.0, 0.0]) - up[0] * up
        if np.linalg.norm(east) < 1.75e-3:
            north = np.array([0.0, 1.0, 0.0]) - up[1] * up
            north /= np.linalg.norm(north)
            east = np.cross(north, up)
        else:
            east /= np.linalg.norm(east)
            north = np.cross(up, east)
    # Rows of R (sensor -> earth) are the earth axes expressed in the sensor frame.
    R = np.stack([east, north, up])
    return quat_from_matrix(R)


def initialise(
    gyr: FloatArray,
    acc: FloatArray,
    mag: FloatArray | None,
    rate_hz: float,
    *,
    estimate_bias: bool = True,
    params: RestParams | None = None,
) -> InitialState:
    """Initial attitude and gyro bias from the still start of a recording.

    Args:
        gyr: (N, 3) angular velocity, sensor frame, rad/s.
        acc: (N, 3) specific force, sensor frame, m/s².
        mag: (N, 3) magnetic field, sensor frame, any unit, or ``None``.
        rate_hz: Sampling rate, Hz.
        estimate_bias: Estimate the gyro bias as the mean rate of the rest.
        params: Rest detection thresholds (:class:`RestParams` defaults).

    Returns:
        The :class:`InitialState`. The attitude is the gravity (and magnetic)
        alignment of the mean readings over the rest (without its last
        ``trim_s``), or over the first ``params.attitude_s`` when the start is
        not still; the bias is the mean gyro rate over the same samples.

    Raises:
        InputError: the accelerometer or magnetometer reads zero over those
            samples, or the magnetic field is within 1° of parallel to gravity.
    """
    p = params or RestParams()
    rest = detect_initial_rest(gyr, acc, rate_hz, p)
    n_avg = rest - int(round(p.trim_s * rate_hz))
    if n_avg < p.min_rest_s * rate_hz:
        n_avg = 0
    n_att = n_avg if n_avg > 0 else max(1, int(round(p.attitude_s * rate_hz)))
    n_att = min(n_att, len(acc))
    acc0 = acc[:n_att].mean(axis=0)
    mag0 = None if mag is None else mag[:n_att].mean(axis=0)
    q0 = attitude_from_gravity(acc0, mag0)
    mag_norm = mag_dip = float("nan")
    if mag0 is not None:
        mag_norm = float(np.linalg.norm(mag0))
        mag_dip = float(np.arcsin(-np.dot(mag0, acc0) / (mag_norm * np.linalg.norm(acc0))))
    if estimate_bias and n_avg > 0:
        bias = np.asarray(gyr[:n_avg].mean(axis=0), dtype=float)
        estimated = True
    else:
        bias = np.zeros(3)
        estimated = False
    return InitialState(
        quat_wxyz=q0,
        gyr_bias_rad_s=bias,
        rest_samples=rest,
        bias_estimated=estimated,
        mag_norm=mag_norm,
        mag_dip_rad=mag_dip,
        acc_norm_mps2=float(np.linalg.norm(acc0)),
    )
