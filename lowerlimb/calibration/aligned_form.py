"""Joint centres from the 3-D joint constraint in gyro-aligned frames (opt-in: ``centre_form="aligned"``).

Why: the norm form of the spherical-joint constraint (Hu et al. 2021, eq. 3,
:mod:`lowerlimb.constraints.spherical`) compares ``‖g_P‖`` and ``‖g_C‖``, each
computed in its own sensor frame from signals low-passed in that frame. When the
two frames turn against each other within the filter's time constant (a knee in
swing, a thigh against the pelvis) the low-pass of a rotating vector is not the
rotated low-pass, the two norms stop matching where the motion is, and the fit
shortens both lever arms. On the seven-IMU simulator (rigid sensors, the rigid
band capping the knee and hip at 3.9–7 Hz) the thigh and shank came out 21 and
24 mm short on average, 79 mm at worst, and the hip in the pelvis sensor 85 mm
off (median; ``benchmarks/gait.py``). Building the kinematic matrix from the
unfiltered gyro (``filter_regressor``) removes the squaring part of that bias but
not the rotation part.

The form here keeps the three components. Each sensor's gyro (bias removed,
unfiltered) is integrated alone (:mod:`lowerlimb.orientation.strapdown`), which
gives its attitude ``R_S(t)`` in a frame of its own that drifts only slowly. The
joint centre's specific force seen from each sensor, carried into that frame,

    G_S(t) = R_S(t) (a_S(t) + K_S(t) c_S),     K_S = [ω_S]ײ + [α_S]× (eq. 2),

is the same vector in the two integration frames up to one slowly varying rotation
``D(t)`` (the two frames' difference plus their drifts):
``G_P(t) = D(t) G_C(t)``. ``D`` is found per window of
:attr:`~lowerlimb.calibration.options.CalibrationOptions.aligned_window_s` (Wahba's
problem on the window's ``G`` pairs, ``scipy.spatial.transform.Rotation.align_vectors``)
and interpolated between window centres (slerp). Both sides are linear in their
centre, so low-passing ``R_S a_S`` and ``R_S K_S`` (the joint's cut-off) keeps the
equation exact up to ``D``'s slow turn, and the centres are one linear least
squares (three rows per sample)::

    F(R_P a_P) + F(R_P K_P) c_P = D (F(R_C a_C) + F(R_C K_C) c_C).

The windows' ``D`` and the centres are updated in turn
(:attr:`~lowerlimb.calibration.options.CalibrationOptions.aligned_iterations`
passes), starting from the norm form's centres. A hinge's common position along
its axis is not determined by either form; its centre is solved with the
``(j_P, j_C)`` gauge of eq. 16 (the along-axis coordinates sum to zero).

Measured (``benchmarks/aligned_form.py``, same data both ways; the leg applies it
to the hip and the knee, the ankle keeps the norm form): on six rigid simulated
walks the thigh and shank length bias goes from −21 / −24 mm to +0.0 / −1.7 mm
(worst 79 → 15 mm), the hip in the pelvis sensor from 85 to 1.6 mm median and the
hip in the thigh sensor from 5.0 to 0.8 mm; with the simulator's real-walk artefacts
the length bias goes from −60 / −87 to −19 / −58 mm. On the rig (no low-pass
there) it is within 2 mm of the norm form. On the real walk of ``gait/`` the thighs
come to +4 / +11 mm of Vicon (were −10 / +29) but the shanks move from +4 / −5 to
+39 / +34 mm and the step width error from 15 to 26 mm median. So for the thigh and
the knee it is an option; the hip centre in the pelvis sensor, which the norm form
cannot place when the pelvis barely turns, takes it by default with the thigh side
held (``fixed_child``; ``CalibrationOptions.hip_in_pelvis_form``, docs/limits.md).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation, Slerp

from lowerlimb.calibration._solve import subsample_step
from lowerlimb.calibration.geometry import basis_with_first_axis
from lowerlimb.constraints.angular_acceleration import angular_acceleration
from lowerlimb.constraints.prefilter import lowpass
from lowerlimb.constraints.spherical import AXIS_GAUGE_MAP, kinematic_matrix
from lowerlimb.conventions import FloatArray
from lowerlimb.orientation.strapdown import strapdown_matrices

__all__ = ["AlignedFit", "AlignedSettings", "aligned_centres"]


@dataclass(frozen=True)
class AlignedSettings:
    """How one aligned fit runs (taken from :class:`~lowerlimb.calibration.options.CalibrationOptions`).

    Attributes:
        window_s: length of the windows over which ``D`` is taken as constant, s.
        iterations: alternations of the windows' ``D`` and the centres (≥ 1).
        angacc_window_s: Savitzky–Golay window of α, s.
        angacc_polyorder: its polynomial degree.
        max_samples: fit a longer trial on every k-th low-passed sample, at most this many
            (``None``: every sample; ``CalibrationOptions.fit_max_samples``).
    """

    window_s: float
    iterations: int
    angacc_window_s: float
    angacc_polyorder: int
    max_samples: int | None = None


@dataclass(frozen=True)
class AlignedFit:
    """The centres of one joint from the aligned 3-D form.

    Attributes:
        center_in_parent: (3,) joint centre in the parent sensor frame, m.
        center_in_child: (3,) joint centre in the child sensor frame, m.
        rms_residual: RMS of the 3-D residual over the fitted samples and axes, m/s².
        windows: number of windows ``D`` was estimated on.
    """

    center_in_parent: FloatArray
    center_in_child: FloatArray
    rms_residual: float
    windows: int


@dataclass(frozen=True)
class _Side:
    """One sensor's low-passed ``F(R a)`` (N, 3) and ``F(R K)`` (N, 3, 3) in its integration frame."""

    acc: FloatArray
    kin: FloatArray

    def every(self, step: int) -> _Side:
        """Every ``step``-th sample (the signals are already low-passed)."""
        return _Side(self.acc[::step], self.kin[::step])


def _side(
    acc: FloatArray, gyr: FloatArray, rate_hz: float, cutoff_hz: float | None, s: AlignedSettings
) -> _Side:
    R = strapdown_matrices(gyr, rate_hz)
    al = angular_acceleration(gyr, rate_hz, window_s=s.angacc_window_s, polyorder=s.angacc_polyorder)
    n = acc.shape[0]
    RA = np.einsum("nij,nj->ni", R, acc)
    RK = (R @ kinematic_matrix(gyr, al)).reshape(n, 9)
    return _Side(lowpass(RA, rate_hz, cutoff_hz), lowpass(RK, rate_hz, cutoff_hz).reshape(n, 3, 3))


def _window_rotations(
    gp: FloatArray, gc: FloatArray, keep: FloatArray, edges: FloatArray
) -> tuple[Rotation, FloatArray]:
    """Per window, the rotation ``D`` with ``gp ≈ D gc`` (kept samples only); window centres."""
    rots: list[Rotation] = []
    centres: list[float] = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        m = keep[a:b]
        if np.count_nonzero(m) < 3:
            continue
        with warnings.catch_warnings():  # a still window leaves D poorly defined (scipy warns)
            warnings.simplefilter("ignore", UserWarning)
            rots.append(Rotation.align_vectors(gp[a:b][m], gc[a:b][m])[0])
        centres.append(0.5 * (a + b))
    if not rots:
        return Rotation.identity(), np.zeros(0)
    return Rotation.concatenate(rots), np.asarray(centres, dtype=float)


def _rotations_at(rots: Rotation, centres: FloatArray, n: int) -> FloatArray:
    """(n, 3, 3) ``D`` at every sample: slerp between window centres, held beyond the ends."""
    if len(centres) == 1:
        return np.broadcast_to(rots.as_matrix()[0], (n, 3, 3)).copy()
    t = np.clip(np.arange(n, dtype=float), centres[0], centres[-1])
    return np.asarray(Slerp(centres, rots)(t).as_matrix(), dtype=float)


def aligned_centres(
    acc_parent: ArrayLike,
    gyr_parent: ArrayLike,
    acc_child: ArrayLike,
    gyr_child: ArrayLike,
    *,
    rate_hz: float,
    cutoff_hz: float | None,
    start: ArrayLike,
    settings: AlignedSettings,
    keep: ArrayLike | None = None,
    gauge_axes: tuple[ArrayLike, ArrayLike] | None = None,
    fixed_child: bool = False,
) -> AlignedFit:
    """A joint's centres in both sensor frames from the aligned 3-D form (module docstring).

    Args:
        acc_parent: (N, 3) parent accelerometer, specific force, sensor frame, m/s² (unfiltered).
        gyr_parent: (N, 3) parent gyro with its bias removed, rad/s (unfiltered).
        acc_child: (N, 3) child accelerometer, m/s².
        gyr_child: (N, 3) child gyro with its bias removed, rad/s.
        rate_hz: sampling rate, Hz.
        cutoff_hz: the joint's low-pass cut-off, Hz (``None``: unfiltered).
        start: (6,) ``(c_P, c_C)`` to align the first windows with (the norm form's centres), m.
        settings: windows, passes and the α derivative.
        keep: (N,) booleans, the samples to fit (``None``: all), e.g. without impacts.
        gauge_axes: ``(j_P, j_C)`` of a hinge: the centres are solved in the eq. 16 gauge.
        fixed_child: hold ``c_C`` at its start and solve ``c_P`` alone (the parent's
            centre given the child's, e.g. the hip in a pelvis that barely turns;
            ``gauge_axes`` then does not apply).

    Returns:
        The centres and the fit's RMS residual.
    """
    ap, ac = (np.asarray(a, dtype=float) for a in (acc_parent, acc_child))
    P = _side(ap, np.asarray(gyr_parent, dtype=float), rate_hz, cutoff_hz, settings)
    C = _side(ac, np.asarray(gyr_child, dtype=float), rate_hz, cutoff_hz, settings)
    n = ap.shape[0]
    k = np.ones(n, dtype=bool) if keep is None else np.asarray(keep, dtype=bool)
    step = 1 if settings.max_samples is None else subsample_step(n, settings.max_samples)
    if step > 1:
        P, C, k = P.every(step), C.every(step), k[::step]
        n = P.acc.shape[0]
    M = np.eye(6)  # parameters -> (c_P, c_C)
    if gauge_axes is not None:
        Qp, Qc = (basis_with_first_axis(np.asarray(j, dtype=float)) for j in gauge_axes)
        M = np.zeros((6, 6))
        M[:3, :3], M[3:, 3:] = Qp, Qc
        M = M @ AXIS_GAUGE_MAP
    if fixed_child:
        M = np.eye(6)[:, :3]
    n_win = max(1, int(round(n * step / (settings.window_s * rate_hz))))
    edges = np.linspace(0, n, n_win + 1).astype(int)
    x = np.asarray(start, dtype=float).copy()
    rms = float("nan")
    n_used = 0
    for _ in range(settings.iterations):
        gp = P.acc + P.kin @ x[:3]
        gc = C.acc + C.kin @ x[3:]
        rots, centres = _window_rotations(gp, gc, k, edges)
        n_used = len(centres)
        if n_used == 0:  # nothing kept to align on: the start stands
            break
        D = _rotations_at(rots, centres, n)
        DK = D @ C.kin
        b = (np.einsum("nij,nj->ni", D, C.acc) - P.acc)[k].reshape(-1)
        if fixed_child:
            b = b + (DK @ x[3:])[k].reshape(-1)
        A = (np.concatenate([P.kin, -DK], axis=2)[k].reshape(-1, 6)) @ M
        y = np.linalg.lstsq(A, b, rcond=None)[0]
        x = M @ y + (np.concatenate([np.zeros(3), x[3:]]) if fixed_child else 0.0)
        rms = float(np.sqrt(np.mean((A @ y - b) ** 2)))
    return AlignedFit(x[:3].copy(), x[3:].copy(), rms, n_used)
