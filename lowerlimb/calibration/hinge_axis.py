"""Hinge-axis estimation from two gyroscopes (Hu et al. 2021, eq. 4–6, 12–15), with sign resolution.

Public entry points:

- :func:`estimate_hinge_axis` (docs/architecture.md API): returns the two unit axes;
- :func:`calibrate_hinge_axis`: the same with diagnostics
  (:class:`~lowerlimb.calibration.results.HingeAxisCalibration`).

Solving (choices the paper leaves open):

- the axes are parametrised by eq. 5 (corrected) in a *rotated basis*
  ``j = Q · j(φ, θ)`` whose first column is the starting axis, so every
  solve starts at (φ, θ) = (0, 0), on the equator, far from the poles where
  eq. 5 is singular (``‖ω × Q j'‖ = ‖Qᵀω × j'‖``: the data are rotated);
- ``casadi``/``gn``: ``hinge_starts`` starting pairs along the sensor axes
  are solved on a subsample (≤ 1000 samples), the best is polished on all
  samples in a basis centred on it;
- swarms: ``φ ∈ [−π/2, π/2]``, ``θ ∈ [−2π, 2π]`` per axis (two turns: the optimum is
  never only on the box edge), identity basis; ``…+casadi`` keeps the better of
  the refined swarm result and the multi-start (on squats the swarm sometimes
  hands a minimum 90° away to the refinement).

Sign resolution (eq. 4/6 cannot see the signs, docs/methods.md):

1. *Relative sign*, from the gyros alone. With consistent signs the joint
   angle ``q(t) = ∫ (ω_C·j_C − ω_P·j_P) dt`` relates the angular-velocity
   components normal to the axis by a rotation: in 2-D coordinates
   ``z_S = ω_S·u_S + i ω_S·v_S`` (``(j_S, u_S, v_S)`` right-handed) one has
   ``z_P = z_C · exp(i(ψ₀ + q(t)))`` with a constant ψ₀. The coherence
   ``|Σ z_P z̄_C e^{−iq}| / Σ |z_P z_C|`` is near 1 for the right relative sign
   and small for the wrong one (then ``z_C`` is mirrored and q is wrong).
2. *Overall sign*: knee flexion is a negative rotation of the shank about a
   right-pointing axis (ISB, both sides). The recording starts standing
   (knee extended), so flexion from the start, ``f(t) = −(q(t) − q₀)``, has a
   large positive and only a small negative excursion. Both axes are
   flipped when ``P99(f) < −P1(f)``. For a generic hinge the same rule makes
   the larger excursion of ``q`` negative.
3. With accelerometers, a centre on the axis is fitted (eq. 16 gauge) and the
   relative sign cross-checked with the sign-sensitive acceleration relation
   ``g_P·j_P = g_C·j_C`` (:func:`check_sign_with_acc`): it decides when the
   gyro coherence is ambiguous (coherence < 0.5 or margin < 0.2) and only
   warns when it contradicts a clear gyro decision.
4. When both leave the relative sign open (|correlation| ≤ 0.5), the candidate whose
   drift-free angle is clearly more one-sided decides (``sign_one_sided_margin``): a
   knee swings to one side of its running mean, a mirrored ``q`` to both
   (:func:`drift_free_one_sidedness`; on a trial too short for it, the angle from the
   standing start or its mean).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.calibration._prepare import (
    check_duration,
    check_rate,
    check_signal,
    pair_data,
    prepare_signals,
)
from lowerlimb.calibration._rotation import low_rotation_messages
from lowerlimb.calibration._solve import LsqProblem, solve_global, solve_local, subsample_step
from lowerlimb.calibration.excitation import ExcitationReport, issue_warnings, jacobian_report
from lowerlimb.calibration.geometry import basis_with_first_axis
from lowerlimb.calibration.hinge_band import axes_disagreement_deg, band_limited_gyros
from lowerlimb.calibration.joint_center import fit_spherical
from lowerlimb.calibration.options import CalibrationOptions, check_method
from lowerlimb.calibration.results import HingeAxisCalibration, SphericalJointCalibration
from lowerlimb.constraints.hinge import (
    axis_from_angles,
    hinge_jacobian,
    hinge_residual,
    hinge_residual_population,
    hinge_sample_function,
)
from lowerlimb.constraints.prefilter import lowpass
from lowerlimb.constraints.spherical import SphericalData, joint_acceleration
from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError

__all__ = [
    "estimate_hinge_axis",
    "calibrate_hinge_axis",
    "fit_hinge_axis",
    "relative_sign_coherence",
    "hinge_angle",
    "check_sign_with_acc",
    "acc_sign_correlation",
]

#: Starting directions (each used for both sensors); the hemisphere suffices (sign symmetry).
_START_AXES = np.array(
    [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [1.0, -1.0, 1.0],
        [-1.0, 1.0, 1.0],
        [1.0, 1.0, -1.0],
    ]
)
_START_SUBSAMPLE = 1000


def _problem(wp: FloatArray, wc: FloatArray, options: CalibrationOptions) -> LsqProblem:
    sub = subsample_step(wp.shape[0], options.swarm_samples)
    wps, wcs = wp[::sub], wc[::sub]
    half = np.pi / 2

    def cost_batch(X: FloatArray) -> FloatArray:
        return np.asarray(0.5 * np.mean(hinge_residual_population(X, wps, wcs) ** 2, axis=1))

    return LsqProblem(
        lambda x: hinge_residual(x, wp, wc),
        lambda x: hinge_jacobian(x, wp, wc),
        cost_batch,
        hinge_sample_function(),
        np.ascontiguousarray(np.hstack([wp, wc]).T),
        # θ spans two turns so that every axis has a representation away from the box edge
        np.array([-half, -2 * np.pi, -half, -2 * np.pi]),
        np.array([half, 2 * np.pi, half, 2 * np.pi]),
        bounded=False,
    )


def _local(
    wp: FloatArray,
    wc: FloatArray,
    dp: FloatArray,
    dc: FloatArray,
    local: str,
    options: CalibrationOptions,
) -> tuple[FloatArray, FloatArray, float, int, bool, str]:
    Qp, Qc = basis_with_first_axis(dp), basis_with_first_axis(dc)
    res = solve_local(_problem(wp @ Qp, wc @ Qc, options), np.zeros(4), local, options)
    jp = Qp @ axis_from_angles(res.x[0], res.x[1])
    jc = Qc @ axis_from_angles(res.x[2], res.x[3])
    return jp, jc, float(res.cost), int(res.iterations), bool(res.converged), res.method


def _principal_axis(w: FloatArray) -> FloatArray:
    """(3,) unit direction of the largest angular-velocity variance of ``w`` (N, 3), rad/s."""
    vals, vecs = np.linalg.eigh(np.asarray(w, dtype=float).T @ np.asarray(w, dtype=float))
    return np.asarray(vecs[:, int(np.argmax(vals))])


def _multistart(
    wp: FloatArray,
    wc: FloatArray,
    local: str,
    options: CalibrationOptions,
    contested: Callable[[FloatArray, FloatArray], bool] | None = None,
) -> tuple[FloatArray, FloatArray, float, int, bool, str]:
    """Local solves on a subsample; two candidates polished on all samples, the better kept.

    The starts: each sensor's principal rotation axis (a hinge's segments rotate mostly
    about it, whatever the sensor's mounting), then ``hinge_starts`` pairs along the
    sensor axes. Without the first, a realistic walk (knee 10–75°, little out-of-plane
    rotation) can settle in a local minimum 8–12° off with the wrong relative sign.
    "Better" is the lower cost among the candidates that ``contested`` does not reject
    (:func:`_sign_cues_disagree`), else the lower cost: with wobbling sensors a walk can
    have a lower minimum 20° off whose gyro coherence and joint angle contradict each
    other on the relative sign. While every polished candidate is contested, the other
    starts are polished too, best subsample cost first.
    """
    step = subsample_step(wp.shape[0], _START_SUBSAMPLE)
    iterations = 0
    starts = [(_principal_axis(wp), _principal_axis(wc))]
    starts += [(d, d) for d in _START_AXES[: options.hinge_starts]]
    sub = []
    for dp, dc in starts:
        jp, jc, cost, it, _, _ = _local(wp[::step], wc[::step], dp, dc, local, options)
        iterations += it
        sub.append((cost, jp, jc))
    # the principal start and the best sensor-axis start are both polished on all samples:
    # on a subsample a soft-tissue recording can prefer a minimum that the whole trial does not
    first = min(range(1, len(sub)), key=lambda i: sub[i][0])
    order = [0, first] + sorted((i for i in range(1, len(sub)) if i != first), key=lambda i: sub[i][0])
    polished: list[tuple[FloatArray, FloatArray, float, int, bool, str]] = []
    fine: list[tuple[FloatArray, FloatArray, float, int, bool, str]] = []
    for n, i in enumerate(order):
        if n >= 2 and (fine or contested is None):
            break  # the rest are polished only while every candidate so far is contested
        res = _local(wp, wc, sub[i][1], sub[i][2], local, options)
        iterations += res[3]
        polished.append(res)
        if contested is None or not contested(res[0], res[1]):
            fine.append(res)
    jp, jc, cost, _, converged, solver = min(fine or polished, key=lambda r: r[2])
    return jp, jc, cost, iterations, converged, solver


def _sign_cues_disagree(
    jp: FloatArray,
    jc: FloatArray,
    wp: FloatArray,
    wc: FloatArray,
    rate_hz: float,
    n_still: int,
    options: CalibrationOptions,
) -> bool:
    """Whether the joint angle's one-sidedness clearly contradicts the gyro coherence's relative sign.

    The coherence (:func:`relative_sign_coherence`) picks a relative sign; the drift-free
    one-sidedness (:func:`drift_free_one_sidedness`) of the other sign is higher by at least
    ``options.sign_one_sided_margin``. Inconclusive one-sidedness (a joint swinging about
    its mean, a short trial) never contradicts.

    Args:
        jp: (3,) unit axis, parent frame.
        jc: (3,) unit axis, child frame.
        wp: (N, 3) parent gyro (no pseudo-samples), rad/s.
        wc: (N, 3) child gyro, rad/s.
        rate_hz: sampling rate, Hz.
        n_still: still samples at the start.
        options: calibration options.
    """
    s = (
        1.0
        if relative_sign_coherence(jp, jc, wp, wc, rate_hz)
        >= relative_sign_coherence(jp, -jc, wp, wc, rate_hz)
        else -1.0
    )
    chosen = drift_free_one_sidedness(jp, s * jc, wp, wc, rate_hz, n_still)
    other = drift_free_one_sidedness(jp, -s * jc, wp, wc, rate_hz, n_still)
    return bool(
        np.isfinite(chosen) and np.isfinite(other) and other - chosen >= options.sign_one_sided_margin
    )


def hinge_angle(
    axis_parent: ArrayLike,
    axis_child: ArrayLike,
    gyr_parent: FloatArray,
    gyr_child: FloatArray,
    rate_hz: float,
) -> FloatArray:
    """Rotation angle q(t) of the child about the axis relative to the parent, from q(0) = 0.

    ``q̇ = ω_C·j_C − ω_P·j_P`` integrated by the trapezoidal rule (drifts with
    gyro bias; use over the recording only for sign decisions).

    Args:
        axis_parent: (3,) axis in the parent frame.
        axis_child: (3,) axis in the child frame, same physical direction.
        gyr_parent: (N, 3) parent gyro, rad/s.
        gyr_child: (N, 3) child gyro, rad/s.
        rate_hz: sampling rate, Hz.

    Returns:
        (N,) angle, rad (right-hand rule about the axis).
    """
    rate = gyr_child @ np.asarray(axis_child) - gyr_parent @ np.asarray(axis_parent)
    q = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]))]) / rate_hz
    return np.asarray(q, dtype=float)


def flexion_sign_margin(
    axis_parent: FloatArray,
    axis_child: FloatArray,
    gyr_parent: FloatArray,
    gyr_child: FloatArray,
    rate_hz: float,
    n_still: int = 0,
    *,
    drift_hz: float = 0.1,
    raw_window_s: float | None = None,
    raw_min_score: float = 0.0,
    drift_free_min_score: float = 0.0,
) -> float:
    """How clearly the axes' sign makes flexion the dominant excursion (> 0: keep, < 0: flip), rad.

    Flexion ``f = −(q − q0)`` from the standing start mostly rises: its 99th
    percentile outweighs its 1st. Over a long trial ``q`` drifts with the gyro
    bias, and a turn leaks into it when the two axes are not exactly the same
    physical line (a 180° turn with a 5° axis error moves q by about 16°). So the
    test is also made on the angle with its slow part removed (zero-phase
    high-pass at ``drift_hz``), in which a flexing joint still shows larger
    positive than negative excursions about its running mean, and the more
    decisive of the two tests (margin over the angle's range) decides. The test
    from the start looks only at the first ``raw_window_s`` after the still
    start: on a 20-minute simulated walk the whole angle drifted by 4.4 rad to
    one side, which made that test the more decisive one, and wrong. A joint flexing from a
    straight standing leg scores near 1 on the test from the start (0.97 on both knees of
    the real walk); below ``raw_min_score`` that angle has swung to both sides by nearly as
    much, so drift, a turn's leakage or a gyro cut at its range has taken it over (the real
    walk's right knee with its gyros cut at ±300 °/s: 0.22, the wrong sign, flexion mirrored),
    and the drift-free test alone decides.

    Args:
        axis_parent: (3,) unit axis, parent frame.
        axis_child: (3,) unit axis, child frame, same physical direction.
        gyr_parent: (N, 3) parent gyro, rad/s.
        gyr_child: (N, 3) child gyro, rad/s.
        rate_hz: sampling rate, Hz.
        n_still: still samples at the start (the angle reference).
        drift_hz: cut-off of the drift removal, Hz.
        raw_window_s: length of the test from the start after the still samples, s
            (``None``: the whole trial).
        raw_min_score: below this score (0–1) the test from a standing start is not used
            when the drift-free test can be made (without a standing start, flexion is taken
            from its mean, about which no knee scores near 1) ...
        drift_free_min_score: ... and scores at least this; below it the drift-free test
            says nothing (pulses as long as the rests between them swing about their
            running mean to both sides alike) and the higher score of the two decides.

    Returns:
        The signed margin ``p99 + p1`` of the deciding test, rad.
    """
    best, best_score = 0.0, -1.0
    tests = _flexion_tests(axis_parent, axis_child, gyr_parent, gyr_child, rate_hz, n_still, drift_hz)
    if raw_window_s is not None:
        tests[0] = tests[0][: n_still + max(1, int(raw_window_s * rate_hz))]
    if (
        n_still >= 1
        and len(tests) > 1
        and _one_sidedness(tests[0])[1] < raw_min_score
        and _one_sidedness(tests[1])[1] >= drift_free_min_score
    ):
        tests = tests[1:]
    for x in tests:
        margin, score = _one_sidedness(x)
        if score > best_score:
            best, best_score = margin, score
    return best


def _flexion_tests(
    axis_parent: FloatArray,
    axis_child: FloatArray,
    gyr_parent: FloatArray,
    gyr_child: FloatArray,
    rate_hz: float,
    n_still: int,
    drift_hz: float,
) -> list[FloatArray]:
    """Flexion from the standing start and, on long enough trials, its drift-free part (rad).

    Without a standing start (``n_still`` < 1) the first sample is any pose of the
    motion (mid-swing, a knee flexed 60°), and flexion from it swings to the wrong side
    as often as not: a walk cut from a longer recording had its right knee axis flipped
    and was refused as mirrored knees. Flexion is then taken from its mean instead,
    about which a knee still swings mostly to the flexed side.
    """
    q = hinge_angle(axis_parent, axis_child, gyr_parent, gyr_child, rate_hz)
    f = -(q - float(np.mean(q[:n_still] if n_still >= 1 else q)))
    tests = [f]
    if f.shape[0] - n_still > rate_hz / drift_hz:
        moving = f[n_still:]
        tests.append(moving - lowpass(moving, rate_hz, drift_hz, order=2))
    return tests


def _one_sidedness(x: FloatArray) -> tuple[float, float]:
    """``(p99 + p1, |p99 + p1| / (p99 − p1))``: signed margin and score of the larger excursion."""
    hi, lo = float(np.percentile(x, 99)), float(np.percentile(x, 1))
    return hi + lo, abs(hi + lo) / max(hi - lo, 1e-12)


def drift_free_one_sidedness(
    axis_parent: FloatArray,
    axis_child: FloatArray,
    gyr_parent: FloatArray,
    gyr_child: FloatArray,
    rate_hz: float,
    n_still: int = 0,
    *,
    drift_hz: float = 0.1,
) -> float:
    """Score (0–1) of how one-sided the drift-free hinge angle is; NaN on too short a trial.

    With the right relative sign a knee's angle swings mostly to one side of its
    running mean (flexion from a nearly straight leg); with the wrong one, ``q``
    mixes the two segments' rotations and swings to both sides. Immune to the
    drift and turn leakage that affect the angle from the start.
    """
    tests = _flexion_tests(axis_parent, axis_child, gyr_parent, gyr_child, rate_hz, n_still, drift_hz)
    return _one_sidedness(tests[1])[1] if len(tests) > 1 else float("nan")


def relative_sign_coherence(
    axis_parent: ArrayLike,
    axis_child: ArrayLike,
    gyr_parent: FloatArray,
    gyr_child: FloatArray,
    rate_hz: float,
) -> float:
    """Coherence (0–1) of the hinge model for the given relative axis sign (module docstring, 1).

    Args:
        axis_parent: (3,) unit axis, parent frame.
        axis_child: (3,) unit axis, child frame (the sign under test).
        gyr_parent: (N, 3) parent gyro, rad/s.
        gyr_child: (N, 3) child gyro, rad/s.
        rate_hz: sampling rate, Hz.

    Returns:
        ``|Σ z_P z̄_C e^{−iq}| / Σ |z_P z_C|``; near 1 for the consistent sign.
    """
    Qp = basis_with_first_axis(axis_parent)
    Qc = basis_with_first_axis(axis_child)
    zp = gyr_parent @ Qp[:, 1] + 1j * (gyr_parent @ Qp[:, 2])
    zc = gyr_child @ Qc[:, 1] + 1j * (gyr_child @ Qc[:, 2])
    q = hinge_angle(Qp[:, 0], Qc[:, 0], gyr_parent, gyr_child, rate_hz)
    m = zp * np.conj(zc) * np.exp(-1j * q)
    den = float(np.sum(np.abs(m)))
    return float(np.abs(np.sum(m)) / den) if den > 0 else 0.0


def check_sign_with_acc(
    axis_parent: ArrayLike,
    axis_child: ArrayLike,
    joint_acc_parent: FloatArray,
    joint_acc_child: FloatArray,
) -> float:
    """Correlation of ``g_P·j_P`` and ``g_C·j_C`` (> 0: the axes point the same way).

    Args:
        axis_parent: (3,) unit axis, parent frame.
        axis_child: (3,) unit axis, child frame.
        joint_acc_parent: (N, 3) acceleration of a point of the axis seen from the parent, m/s².
        joint_acc_child: (N, 3) the same seen from the child, m/s².

    Returns:
        The (uncentred) correlation coefficient in [−1, 1].
    """
    a = joint_acc_parent @ np.asarray(axis_parent)
    b = joint_acc_child @ np.asarray(axis_child)
    den = float(np.sqrt(np.sum(a * a) * np.sum(b * b)))
    return float(np.sum(a * b) / den) if den > 0 else 0.0


def acc_sign_correlation(
    data: SphericalData, axis_parent: FloatArray, axis_child: FloatArray, options: CalibrationOptions
) -> tuple[float, SphericalJointCalibration]:
    """:func:`check_sign_with_acc` at a centre fitted on the axis (gauge of eq. 16), quietly.

    Args:
        data: the pair's prepared signals (with accelerometers).
        axis_parent: (3,) candidate axis, parent frame.
        axis_child: (3,) candidate axis, child frame (the relative sign under test).
        options: calibration options (the fit uses NumPy Gauss–Newton on at most 1000
            samples, without warnings).

    Returns:
        The correlation and the centre fit (reusable while the relative sign holds).
    """
    quiet = replace(options, center_std_tol_m=np.inf, min_rms_rate_rps=0.0)
    data = data.subsample(subsample_step(data.n_samples, _START_SUBSAMPLE))
    center = fit_spherical(data, method="gn", options=quiet, gauge_axes=(axis_parent, axis_child))
    gp = joint_acceleration(
        data.acc_parent, data.gyr_parent, data.angacc_parent, center.center_in_parent_sensor
    )
    gc = joint_acceleration(data.acc_child, data.gyr_child, data.angacc_child, center.center_in_child_sensor)
    return check_sign_with_acc(axis_parent, axis_child, gp, gc), center


def _with_gravity(
    wp: FloatArray,
    wc: FloatArray,
    gravity: tuple[FloatArray, FloatArray] | None,
    n_still: int,
    options: CalibrationOptions,
) -> tuple[FloatArray, FloatArray]:
    """The gyros with the still period's gravity pseudo-samples appended (see :func:`fit_hinge_axis`)."""
    if gravity is None or n_still < 1 or options.hinge_gravity_rate_rps <= 0:
        return wp, wc
    r = options.hinge_gravity_rate_rps
    up, uc = (np.asarray(u, dtype=float) / np.linalg.norm(u) for u in gravity)
    return np.vstack([wp, np.tile(r * up, (n_still, 1))]), np.vstack([wc, np.tile(r * uc, (n_still, 1))])


def _thinned(wp: FloatArray, wc: FloatArray, options: CalibrationOptions) -> tuple[FloatArray, FloatArray]:
    """Every k-th sample of (N, 3) gyros, at most ``options.fit_max_samples`` (gravity rows thin alike)."""
    if options.fit_max_samples is None:
        return wp, wc
    step = subsample_step(wp.shape[0], options.fit_max_samples)
    return wp[::step], wc[::step]


def fit_hinge_axis(
    gyr_parent: FloatArray,
    gyr_child: FloatArray,
    *,
    rate_hz: float,
    method: str,
    options: CalibrationOptions,
    n_still: int = 0,
    joint: str = "joint",
    parent_sensor: str = "parent",
    child_sensor: str = "child",
    acc_check: Callable[[FloatArray, FloatArray], float] | None = None,
    gravity: tuple[FloatArray, FloatArray] | None = None,
) -> HingeAxisCalibration:
    """Solve eq. 12 on prepared gyros, resolve the signs and attach diagnostics.

    A rotation about the hinge keeps the angle between the axis and any vector
    that both segments share; gravity at rest is such a vector, so
    ``|u_P × j_P| = |u_C × j_C|`` for the gravity directions ``u`` of a still
    period: the same form as a gyro sample of eq. 12. ``gravity`` adds it as
    ``n_still`` pseudo-samples ``ω = hinge_gravity_rate_rps · u``. It pins the
    axis's tilt against the segments' long axes, which the gyro residual leaves
    soft when soft tissue rotates a real thigh sensor about the thigh (the
    residual then tilts the axis towards the long axis to absorb it).

    Stages: solve the axes → relative sign (module docstring, 1 and 3) → overall sign (2) →
    diagnostics and warnings.

    Args:
        gyr_parent: (N, 3) bias-corrected, filtered parent gyro, rad/s.
        gyr_child: (N, 3) bias-corrected, filtered child gyro, rad/s.
        rate_hz: sampling rate, Hz.
        method: one of :data:`~lowerlimb.calibration.options.METHODS`.
        options: calibration options.
        n_still: still samples at the start (the angle reference of the sign rule).
        joint: joint name used in messages.
        parent_sensor: parent sensor name used in messages.
        child_sensor: child sensor name used in messages.
        acc_check: optional ``(j_P, j_C) -> correlation`` of the joint-centre
            accelerations along the axes (:func:`acc_sign_correlation`); it decides
            the relative sign when the gyro coherence is ambiguous.
        gravity: optional ``(u_P, u_C)`` (3,) mean accelerometer directions of the
            still period in each frame (unit vectors), see above.

    Returns:
        The axis result; warnings are issued and recorded.

    Raises:
        SolverError: the solver failed.
    """
    t0 = time.perf_counter()
    wp, wc = gyr_parent, gyr_child
    wpf, wcf = _with_gravity(wp, wc, gravity, n_still, options)

    def contested(a: FloatArray, b: FloatArray) -> bool:
        return _sign_cues_disagree(a, b, wp, wc, rate_hz, n_still, options)

    # the axes are solved on every k-th sample of a long trial (options.fit_max_samples);
    # the sign rules and the diagnostics read every sample
    jp, jc, iterations, converged, solver = _solve_axes(
        *_thinned(wpf, wcf, options), method, options, contested
    )
    messages: list[str] = []
    # the sign rules read the gyros the kept axes were fitted on (hinge_band module docstring)
    ws = (wp, wc)
    band = band_limited_gyros(wp, wc, rate_hz, options.hinge_band_hz)
    if band is not None:
        wpb, wcb = band

        def contested_band(a: FloatArray, b: FloatArray) -> bool:
            return _sign_cues_disagree(a, b, wpb, wcb, rate_hz, n_still, options)

        bp, bc, b_it, b_conv, b_solver = _solve_axes(
            *_thinned(*_with_gravity(wpb, wcb, gravity, n_still, options), options),
            method,
            options,
            contested_band,
        )
        iterations += b_it
        apart = axes_disagreement_deg((jp, jc), (bp, bc))
        if apart > options.hinge_band_max_disagreement_deg:
            jp, jc, converged, ws = bp, bc, b_conv, band
            solver = f"{b_solver} (below {options.hinge_band_hz:g} Hz)"
            messages.append(
                f"{joint}: the hinge fit on all frequencies and the one below {options.hinge_band_hz:g} Hz "
                f"disagree by {apart:.0f}°: above it the {parent_sensor} and {child_sensor} sensors do not "
                f"turn as one hinge (soft tissue); kept the axes of the joint's own motion band"
            )
    jc, coherence, corr = _relative_sign(
        jp, jc, *ws, rate_hz, acc_check, joint, child_sensor, messages, n_still=n_still, options=options
    )
    margin = flexion_sign_margin(
        jp,
        jc,
        *ws,
        rate_hz,
        n_still,
        raw_window_s=options.sign_raw_window_s,
        raw_min_score=options.sign_raw_min_score,
        drift_free_min_score=options.sign_drift_free_min_score,
    )
    if margin < 0:
        jp, jc = -jp, -jc
    r, report, std_deg = _axis_diagnostics(
        jp, jc, wp, wc, options, joint, parent_sensor, child_sensor, messages
    )
    messages += low_rotation_messages(
        joint,
        ((parent_sensor, wp), (child_sensor, wc)),
        options.min_rms_rate_rps,
        "the hinge axis cannot be determined; record a trial in which the joint moves",
    )
    report.warnings = list(messages)
    issue_warnings(messages, stacklevel=4)
    return HingeAxisCalibration(
        joint=joint,
        parent_sensor=parent_sensor,
        child_sensor=child_sensor,
        axis_in_parent_sensor=jp,
        axis_in_child_sensor=jc,
        rms_residual=float(np.sqrt(np.mean(r**2))),
        excitation=report,
        axis_std_deg=np.asarray(std_deg, dtype=float),
        sign_coherence=coherence,
        flexion_sign_margin=abs(margin),
        acc_sign_correlation=corr,
        method=method,
        solver=solver,
        iterations=iterations,
        converged=converged,
        solve_time_s=time.perf_counter() - t0,
        warnings=messages,
    )


def _solve_axes(
    wp: FloatArray,
    wc: FloatArray,
    method: str,
    options: CalibrationOptions,
    contested: Callable[[FloatArray, FloatArray], bool] | None = None,
) -> tuple[FloatArray, FloatArray, int, bool, str]:
    """Solve eq. 12 for the axes with ``method`` (signs not yet resolved).

    Args:
        wp: (N, 3) parent gyro (with any gravity pseudo-samples), parent sensor frame, rad/s.
        wc: (N, 3) child gyro, child sensor frame, rad/s.
        method: one of :data:`~lowerlimb.calibration.options.METHODS`.
        options: calibration options.
        contested: rejects a multi-start candidate whose sign cues disagree (:func:`_multistart`).

    Returns:
        ``(j_P, j_C, iterations, converged, solver)``: (3,) unit axes in the parent and child
        sensor frames, and the solver's iterations, convergence flag and name.
    """
    if method in ("casadi", "gn"):
        jp, jc, _, iterations, converged, solver = _multistart(wp, wc, method, options, contested)
    else:
        res = solve_global(_problem(wp, wc, options), method, options)
        jp = axis_from_angles(res.x[0], res.x[1])
        jc = axis_from_angles(res.x[2], res.x[3])
        iterations, converged, solver = int(res.iterations), bool(res.converged), res.method
        if method.endswith("+casadi"):
            # safeguard: the swarm may hand a wrong basin to the refinement (squats:
            # a minimum 90° away); keep the better of it and the default starts
            ms = _multistart(wp, wc, "casadi", options, contested)
            iterations += ms[3]
            if ms[2] < res.cost:
                jp, jc, converged = ms[0], ms[1], ms[4]
                solver = f"{solver} (kept the multi-start {ms[5]})"
    return jp / np.linalg.norm(jp), jc / np.linalg.norm(jc), iterations, converged, solver


def _relative_sign(
    jp: FloatArray,
    jc: FloatArray,
    wp: FloatArray,
    wc: FloatArray,
    rate_hz: float,
    acc_check: Callable[[FloatArray, FloatArray], float] | None,
    joint: str,
    child_sensor: str,
    messages: list[str],
    *,
    n_still: int = 0,
    options: CalibrationOptions | None = None,
) -> tuple[FloatArray, FloatArray, float]:
    """Sign rule 1 (module docstring): gyro coherence, then accelerometers, then one-sidedness.

    When the gyro coherence is ambiguous the accelerometers settle it; when they are
    ambiguous too, the drift-free one-sidedness of the hinge angle does
    (:func:`_one_sided_tiebreak`).

    Args:
        jp: (3,) unit axis, parent sensor frame.
        jc: (3,) unit axis, child sensor frame (flipped here when needed).
        wp: (N, 3) parent gyro, rad/s.
        wc: (N, 3) child gyro, rad/s.
        rate_hz: sampling rate, Hz.
        acc_check: optional ``(j_P, j_C) -> correlation`` (see :func:`fit_hinge_axis`).
        joint: joint name used in messages.
        child_sensor: child sensor name used in messages.
        messages: warnings so far; this stage's are appended.
        n_still: still samples at the start.
        options: calibration options (``sign_one_sided_margin``; defaults when ``None``).

    Returns:
        ``(j_C, [coherence kept, coherence flipped], acceleration correlation or NaN)``.
    """
    coh_keep = relative_sign_coherence(jp, jc, wp, wc, rate_hz)
    coh_flip = relative_sign_coherence(jp, -jc, wp, wc, rate_hz)
    if coh_flip > coh_keep:
        jc = -jc
        coh_keep, coh_flip = coh_flip, coh_keep
    margin_coh = coh_keep - coh_flip
    gyro_clear = coh_keep >= 0.5 and margin_coh >= 0.2
    corr = float("nan")
    if acc_check is not None:
        corr = acc_check(jp, jc)
        if corr < 0 and not gyro_clear:
            jc, corr = -jc, -corr
            coh_keep, coh_flip = coh_flip, coh_keep
            messages.append(
                f"{joint}: the gyro sign test was ambiguous; the {child_sensor} axis was flipped "
                f"after the accelerometer check (correlation {corr:.2f})"
            )
        elif corr < -0.5:
            messages.append(
                f"{joint}: gyro and accelerometer sign tests disagree (coherence margin "
                f"{margin_coh:.2f}, acceleration correlation {corr:.2f}); kept the gyro decision"
            )
    if not gyro_clear and not abs(corr) > 0.5:
        jc, coh_keep, coh_flip = _one_sided_tiebreak(
            jp, jc, wp, wc, rate_hz, n_still, (coh_keep, coh_flip), options or CalibrationOptions(), messages
        )
    if not gyro_clear and not corr > 0.5:
        messages.append(
            f"{joint}: the relative sign of the axes is uncertain (coherence {coh_keep:.2f} vs "
            f"{coh_flip:.2f}); the {child_sensor} axis may point the opposite way"
        )
    return jc, np.array([coh_keep, coh_flip]), corr


def _one_sided_tiebreak(
    jp: FloatArray,
    jc: FloatArray,
    wp: FloatArray,
    wc: FloatArray,
    rate_hz: float,
    n_still: int,
    coherence: tuple[float, float],
    options: CalibrationOptions,
    messages: list[str],
) -> tuple[FloatArray, float, float]:
    """When gyros and accelerometers leave the relative sign open, the more one-sided angle decides.

    The gyro coherence needs the off-axis rotation of both segments, which a walk has
    little of and soft tissue garbles; the accelerometer check needs a well-determined
    centre. The hinge angle's drift-free one-sidedness (:func:`drift_free_one_sidedness`)
    needs only the flexion itself: it flips ``j_C`` when the flipped candidate is more
    one-sided by at least ``options.sign_one_sided_margin``. A trial too short for the
    drift-free test (under ``1 / drift_hz`` = 10 s of motion) is judged on the angle from
    its standing start (or its mean), which drifts little over so short a trial: a real
    walk's last straight pass alone (8 s, no standing start, gyro coherence 0.47 against
    0.18, accelerometer correlation -0.45 from a centre fitted on two strides) otherwise
    kept the accelerometer's wrong sign, mirroring the knee and the hip flexion.

    Returns:
        ``(j_C, coherence kept, coherence flipped)`` after the decision.
    """
    keep = drift_free_one_sidedness(jp, jc, wp, wc, rate_hz, n_still)
    flip = drift_free_one_sidedness(jp, -jc, wp, wc, rate_hz, n_still)
    if not (np.isfinite(keep) and np.isfinite(flip)):
        # too short for the drift-free test (under 1 / drift_hz of motion): over so short a
        # trial the angle from the standing start (or from its mean) drifts little, and its
        # one-sidedness still tells a knee from a mirrored q
        keep, flip = (
            _one_sidedness(_flexion_tests(jp, s * jc, wp, wc, rate_hz, n_still, 0.1)[0])[1]
            for s in (1.0, -1.0)
        )
    if np.isfinite(keep) and np.isfinite(flip) and flip - keep >= options.sign_one_sided_margin:
        messages.append(
            f"the gyro and accelerometer sign tests were ambiguous; the relative axis sign was "
            f"chosen by the one-sidedness of the joint angle ({flip:.2f} against {keep:.2f})"
        )
        return -jc, coherence[1], coherence[0]
    return jc, coherence[0], coherence[1]


def _axis_diagnostics(
    jp: FloatArray,
    jc: FloatArray,
    wp: FloatArray,
    wc: FloatArray,
    options: CalibrationOptions,
    joint: str,
    parent_sensor: str,
    child_sensor: str,
    messages: list[str],
) -> tuple[FloatArray, ExcitationReport, FloatArray]:
    """Residual and excitation of the final axes, in a basis centred on them (x = 0).

    Args:
        jp: (3,) unit axis, parent sensor frame.
        jc: (3,) unit axis, child sensor frame.
        wp: (N, 3) parent gyro, rad/s.
        wc: (N, 3) child gyro, rad/s.
        options: calibration options (noise floor, axis tolerance).
        joint: joint name used in messages.
        parent_sensor: parent sensor name used in messages.
        child_sensor: child sensor name used in messages.
        messages: warnings so far; a poorly determined axis appends one.

    Returns:
        ``(r, report, axis_std_deg)``: the (N,) eq. 12 residual, rad/s; the excitation report;
        the (2,) standard deviation of each axis's direction, degrees.
    """
    Qp, Qc = basis_with_first_axis(jp), basis_with_first_axis(jc)
    wpr, wcr = wp @ Qp, wc @ Qc
    r = hinge_residual(np.zeros(4), wpr, wcr)
    report = jacobian_report(hinge_jacobian(np.zeros(4), wpr, wcr), r, noise_floor=options.noise_floor_rps)
    std_deg = np.degrees([np.hypot(report.std[0], report.std[1]), np.hypot(report.std[2], report.std[3])])
    weak_deg = float(np.degrees(report.weakest_std))
    if weak_deg > options.axis_std_tol_deg:
        v = report.weakest_direction
        tilt_p = v[0] * Qp[:, 2] + v[1] * Qp[:, 1]
        tilt_c = v[2] * Qc[:, 2] + v[3] * Qc[:, 1]
        messages.append(
            f"{joint}: the hinge axis is poorly determined (±{weak_deg:.1f}°), tilting towards "
            f"({', '.join(f'{c:+.2f}' for c in tilt_p)}) in the {parent_sensor} sensor frame and "
            f"({', '.join(f'{c:+.2f}' for c in tilt_c)}) in the {child_sensor} sensor frame; "
            f"record motion in which the {parent_sensor} segment also rotates about other axes"
        )
    return r, report, std_deg


def calibrate_hinge_axis(
    gyr_parent: ArrayLike,
    gyr_child: ArrayLike,
    *,
    rate_hz: float,
    acc_parent: ArrayLike | None = None,
    acc_child: ArrayLike | None = None,
    method: str = "casadi",
    options: CalibrationOptions | None = None,
    joint: str = "joint",
    parent_sensor: str = "parent",
    child_sensor: str = "child",
) -> HingeAxisCalibration:
    """Hinge axis between two IMUs, with diagnostics (see :func:`estimate_hinge_axis`).

    Args:
        gyr_parent: (N, 3) parent gyroscope, parent sensor frame, rad/s.
        gyr_child: (N, 3) child gyroscope, child sensor frame, rad/s.
        rate_hz: common sampling rate, Hz.
        acc_parent: optional (N, 3) parent accelerometer, m/s²: improves the
            still-period detection (gyro bias) and cross-checks the relative sign
            with the joint-centre accelerations.
        acc_child: optional (N, 3) child accelerometer, m/s² (both or neither).
        method: ``"casadi"`` (default), ``"gn"``, ``"dwpso"``, ``"gwo"``,
            ``"dwpso+casadi"`` or ``"gwo+casadi"``.
        options: tuning parameters (defaults: :class:`CalibrationOptions`).
        joint: joint name used in messages.
        parent_sensor: parent sensor name used in messages.
        child_sensor: child sensor name used in messages.

    Returns:
        The axes, residual, excitation report and warnings.

    Raises:
        ShapeError: an array is not (N, 3) or lengths differ.
        NonFiniteValueError: NaN or inf in a signal.
        UnitError: a gyro that looks like deg/s.
        InputError: non-positive rate, too few samples, unknown method, or only
            one of the two accelerometers.
        SolverError: the solver failed.
    """
    opts = options or CalibrationOptions()
    check_method(method)
    rate = check_rate(rate_hz)
    wp = check_signal(gyr_parent, "gyr_parent", "rad/s")
    n = wp.shape[0]
    wc = check_signal(gyr_child, "gyr_child", "rad/s", n)
    if (acc_parent is None) != (acc_child is None):
        raise InputError("pass both acc_parent and acc_child, or neither")
    accs: dict[str, FloatArray] = {}
    if acc_parent is not None and acc_child is not None:
        accs = {
            "p": check_signal(acc_parent, "acc_parent", "m/s²", n),
            "c": check_signal(acc_child, "acc_child", "m/s²", n),
        }
    check_duration(n, rate, opts)
    sig = prepare_signals(accs, {"p": wp, "c": wc}, rate, opts)
    acc_check = None
    if accs:
        data = pair_data(sig)

        def acc_check(jp: FloatArray, jc: FloatArray) -> float:
            return acc_sign_correlation(data, jp, jc, opts)[0]

    res = fit_hinge_axis(
        sig.gyr["p"],
        sig.gyr["c"],
        rate_hz=rate,
        method=method,
        options=opts,
        n_still=sig.n_still,
        joint=joint,
        parent_sensor=parent_sensor,
        child_sensor=child_sensor,
        acc_check=acc_check,
    )
    return res


def estimate_hinge_axis(
    gyr_parent: ArrayLike,
    gyr_child: ArrayLike,
    *,
    rate_hz: float,
    acc_parent: ArrayLike | None = None,
    acc_child: ArrayLike | None = None,
    method: str = "casadi",
    options: CalibrationOptions | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Axis of the hinge between two IMUs, in each sensor's frame (Hu 2021 eq. 4–6).

    Any two IMUs on two segments joined by a (near-)hinge work; the parent
    segment should also rotate about axes other than the hinge (walking does).
    Start the recording with ≥ 0.5 s still (gyro bias) in the extended
    reference posture (sign rule).

    Args:
        gyr_parent: (N, 3) parent gyroscope, parent sensor frame, rad/s.
        gyr_child: (N, 3) child gyroscope, child sensor frame, rad/s.
        rate_hz: common sampling rate, Hz.
        acc_parent: optional (N, 3) parent accelerometer, m/s² (sign cross-check).
        acc_child: optional (N, 3) child accelerometer, m/s².
        method: ``"casadi"`` (default), ``"gn"``, ``"dwpso"``, ``"gwo"``,
            ``"dwpso+casadi"`` or ``"gwo+casadi"``.
        options: tuning parameters (defaults: :class:`CalibrationOptions`).

    Returns:
        ``(axis_in_parent, axis_in_child)``: (3,) unit vectors with the same
        physical direction; for a knee they point to the subject's right
        (flexion positive), see the module docstring.

    Raises:
        ShapeError: an array is not (N, 3) or lengths differ.
        NonFiniteValueError: NaN or inf in a signal.
        UnitError: a gyro that looks like deg/s.
        InputError: non-positive rate, too few samples, unknown method, or only
            one of the two accelerometers.
        SolverError: the solver failed.

    Warns:
        ExcitationWarning: the motion leaves the axis or its sign poorly determined.
    """
    res = calibrate_hinge_axis(
        gyr_parent,
        gyr_child,
        rate_hz=rate_hz,
        acc_parent=acc_parent,
        acc_child=acc_child,
        method=method,
        options=options,
    )
    return res.axis_in_parent_sensor.copy(), res.axis_in_child_sensor.copy()
