"""Joint-centre estimation of a spherical joint from two IMUs (Hu et al. 2021, eq. 1–3, 7–9).

Public entry points:

- :func:`estimate_joint_center` (docs/architecture.md API): returns the two centres;
- :func:`calibrate_spherical_joint`: the same with diagnostics
  (:class:`~lowerlimb.calibration.results.SphericalJointCalibration`).

Pipeline (choices the paper leaves open are written here):

1. gyro bias removed using a still period at the start
   (:mod:`~lowerlimb.stillness`);
2. gyro and accelerometer low-passed at a motion-adaptive cut-off, α by a
   Savitzky–Golay derivative (:mod:`lowerlimb.constraints.prefilter`,
   :mod:`lowerlimb.constraints.angular_acceleration`);
3. ``min Σ e(t)²`` of eq. 7 with e = ‖g_P‖ − ‖g_C‖ (c = −V convention),
   then, with ``noise_correction``, the same cost less its expected
   regressor-noise part (errors in variables,
   :mod:`~lowerlimb.calibration.noise_correction`) and a prior's rows:
   ``casadi`` and ``gn`` start from x = 0 (the sensors themselves; the cost
   is well-behaved there in practice), inside the box ``|c_i| ≤ center_bound_m``;
   the swarms search that box on at most ``swarm_samples`` samples;
   samples near impacts (jerk peaks) are left out first when the caller says so
   (:mod:`~lowerlimb.calibration.impact_window`; a leg's ankle by default);
4. diagnostics from the Jacobian at the solution
   (:mod:`~lowerlimb.calibration.excitation`).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike

import solvers
from lowerlimb.calibration._prepare import check_rate, prepare_pair_bands
from lowerlimb.calibration._rotation import low_rotation_messages
from lowerlimb.calibration._solve import LsqProblem, solve_global, solve_local, subsample_step
from lowerlimb.calibration.excitation import correlation_time, issue_warnings, jacobian_report
from lowerlimb.calibration.geometry import basis_with_first_axis
from lowerlimb.calibration.impact_window import impact_keep_mask
from lowerlimb.calibration.noise_correction import corrected_gauss_newton
from lowerlimb.calibration.options import CalibrationOptions, check_method
from lowerlimb.calibration.pair_band import choose_band
from lowerlimb.calibration.results import SphericalJointCalibration
from lowerlimb.calibration.robust_weights import huber_weights
from lowerlimb.calibration.segment_prior import CenterPrior
from lowerlimb.constraints.spherical import (
    AXIS_GAUGE_MAP,
    SphericalData,
    spherical_axis_gauge_sample_function,
    spherical_jacobian,
    spherical_residual,
    spherical_residual_population,
    spherical_sample_function,
)
from lowerlimb.conventions import FloatArray
from lowerlimb.errors import SolverError
from lowerlimb.upsample import upsample_factor, upsampled

__all__ = ["estimate_joint_center", "calibrate_spherical_joint", "fit_spherical"]


def _spherical_problem(data: SphericalData, options: CalibrationOptions) -> LsqProblem:
    """Eq. 7 in x = (c_P, c_C) ∈ R⁶."""
    sub = data.subsample(subsample_step(data.n_samples, options.swarm_samples))
    b = options.center_bound_m

    def cost_batch(X: FloatArray) -> FloatArray:
        return np.asarray(0.5 * np.mean(spherical_residual_population(X, sub) ** 2, axis=1))

    return LsqProblem(
        lambda x: spherical_residual(x, data),
        lambda x: spherical_jacobian(x, data),
        cost_batch,
        spherical_sample_function(),
        data.data_matrix(),
        np.full(6, -b),
        np.full(6, b),
    )


def _axis_problem(rotated: SphericalData, options: CalibrationOptions) -> LsqProblem:
    """Eq. 7 for a centre on a hinge axis: 5 parameters y, x' = AXIS_GAUGE_MAP y (rotated data)."""
    sub = rotated.subsample(subsample_step(rotated.n_samples, options.swarm_samples))
    b = options.center_bound_m
    E = AXIS_GAUGE_MAP

    def cost_batch(Y: FloatArray) -> FloatArray:
        r = spherical_residual_population(Y @ E.T, sub)
        return np.asarray(0.5 * np.mean(r**2, axis=1))

    return LsqProblem(
        lambda y: spherical_residual(E @ y, rotated),
        lambda y: spherical_jacobian(E @ y, rotated) @ E,
        cost_batch,
        spherical_axis_gauge_sample_function(),
        rotated.data_matrix(),
        np.full(5, -b),
        np.full(5, b),
    )


def _best_start(
    problem: LsqProblem,
    rotated: SphericalData,
    result: solvers.SolverResult,
    accept: Callable[[FloatArray], bool],
    method: str,
    options: CalibrationOptions,
) -> solvers.SolverResult:
    """The hinge centre's fit from zero, or from a better basin (``options.hinge_centre_start_m``).

    Gauss–Newton runs from ± the start distance along each of the five coordinates on a
    subsample (``options.hinge_centre_start_samples``). Ends that ``accept`` (a test of the five
    coordinates) passes come first, then lower cost; the best end is refined on all samples
    and replaces ``result`` when it ranks higher by the same order.
    """
    d = float(options.hinge_centre_start_m or 0.0)
    n = result.x.shape[0]
    step = subsample_step(rotated.n_samples, options.hinge_centre_start_samples)
    sub = _axis_problem(rotated.subsample(step), options)

    def rank(x: FloatArray, cost: float) -> tuple[bool, float]:
        return (not accept(x), cost)

    ends = []
    for x0 in np.vstack([d * np.eye(n), -d * np.eye(n)]):
        try:
            x = np.asarray(solve_local(sub, x0, method, options).x, dtype=float)
        except SolverError:
            continue
        ends.append((rank(x, float(np.sum(sub.residual(x) ** 2))), x))
    if not ends:
        return result
    best = min(ends, key=lambda e: e[0])[1]
    if np.allclose(best, result.x, atol=1e-3):
        return result
    try:
        other = solve_local(problem, best, method, options)
    except SolverError:
        return result
    better = rank(np.asarray(other.x), other.cost) < rank(np.asarray(result.x), result.cost)
    return other if better else result


def _direction_text(v: FloatArray) -> str:
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        return "(none)"
    u = v / n
    return "(" + ", ".join(f"{c:+.2f}" for c in u) + f") [weight {n:.2f}]"


def _refine_weighted(
    data: SphericalData,
    starts: list[FloatArray],
    rows: Callable[[FloatArray], tuple[FloatArray, FloatArray]] | None,
    sqrt_w: FloatArray,
    options: CalibrationOptions,
) -> tuple[FloatArray, FloatArray | None]:
    """A weighted (with ``noise_correction``: corrected) solve from each start; the lowest cost wins."""

    def residual(x: FloatArray) -> FloatArray:
        r = sqrt_w * spherical_residual(x, data)
        return r if rows is None else np.concatenate([r, rows(x)[0]])

    def jacobian(x: FloatArray) -> FloatArray:
        J = sqrt_w[:, None] * spherical_jacobian(x, data)
        return J if rows is None else np.vstack([J, rows(x)[1]])

    b = options.center_bound_m
    correct = options.noise_correction and any(v > 0 for v in data.noise_levels)
    best, best_cost, best_Q = starts[0], float("inf"), None
    for start in starts:
        Q = None
        if correct:
            fit = corrected_gauss_newton(
                residual,
                jacobian,
                data,
                start,
                n_data=data.n_samples,
                weights=sqrt_w**2,
                max_fraction=options.noise_correction_max_fraction,
                bound=b,
                max_iter=options.max_iter,
                tol=options.tol,
            )
            x, Q = fit.x, fit.Q
            cost = float(np.sum(residual(x) ** 2) - x @ Q @ x)
        else:
            try:
                res = solvers.gauss_newton(
                    residual,
                    jacobian,
                    start,
                    max_iter=options.max_iter,
                    tol=options.tol,
                    step="line_search",
                    lower=np.full(6, -b),
                    upper=np.full(6, b),
                )
            except (solvers.SolverError, RuntimeError, ValueError) as e:
                raise SolverError(f"the MAP refinement failed: {e}", method="gn") from e
            x = np.asarray(res.x, dtype=float)
            cost = float(np.sum(residual(x) ** 2))
        if cost < best_cost:
            best, best_cost, best_Q = x, cost, Q
    return best, best_Q


def _refine(
    data: SphericalData, x0: FloatArray, prior: CenterPrior | None, options: CalibrationOptions
) -> tuple[FloatArray, FloatArray | None, FloatArray]:
    """The robust, MAP and/or noise-corrected centres, refined from the data-only solution.

    With ``options.robust``: Huber weights of the residual
    (:mod:`~lowerlimb.calibration.robust_weights`), re-computed at each pass's
    solution (iteratively reweighted least squares, at most ``robust_passes``).

    With a prior: eq. 7 plus the prior's rows. The prior rows are scaled by the
    data's noise per independent sample, σ √τ (σ: RMS residual of the data-only
    fit, floored at ``noise_floor_mps2``; τ: its correlation time), so that
    ``Σ e² + σ²τ ‖W (c − μ)‖²`` is (σ²τ times) the negative log posterior.
    Starts: the data-only solution, and the same with the prior's centre put at
    the prior mean; the lower cost wins.

    With ``options.noise_correction``: the expected regressor-noise part of
    ``Σ e²`` is subtracted (:mod:`~lowerlimb.calibration.noise_correction`).

    Args:
        data: the pair's prepared signals (with their regressor noise levels).
        x0: (6,) data-only solution ``(c_P, c_C)``, sensor frames, m.
        prior: the prior on one of the two centres, or ``None``.
        options: calibration options (solver limits, noise floor, search box).

    Returns:
        (6,) refined ``(c_P, c_C)``, m; the (6, 6) noise information subtracted at
        it (``None`` without the correction); the (N,) sample weights (all 1
        without ``robust``).
    """
    rows: Callable[[FloatArray], tuple[FloatArray, FloatArray]] | None = None
    r0 = spherical_residual(x0, data)
    if prior is not None:
        sigma = max(float(np.sqrt(np.mean(r0**2))), options.noise_floor_mps2)
        scale = options.prior_weight * sigma * float(np.sqrt(correlation_time(r0)))
        p = prior

        def rows(x: FloatArray) -> tuple[FloatArray, FloatArray]:
            return p.rows(x, scale)

    b = options.center_bound_m
    starts = [x0]
    if prior is not None:
        x_alt = prior.selector().T @ (prior.mean - prior.selector() @ x0) + x0
        starts.append(np.clip(x_alt, -b, b))
    w = np.ones(data.n_samples)
    x, Q = x0, None
    for _ in range(options.robust_passes if options.robust else 1):
        if options.robust:
            w = huber_weights(spherical_residual(x, data), options.huber_k, floor=options.noise_floor_mps2)
        x_new, Q = _refine_weighted(data, starts, rows, np.sqrt(w), options)
        moved = float(np.linalg.norm(x_new - x))
        x, starts = x_new, [x_new]
        if moved < _ROBUST_TOL_M:
            break
    return x, Q, w


#: The reweighting stops when a pass moves the centres less than this, m.
_ROBUST_TOL_M = 1e-5


def _corrected_jacobian(J: FloatArray, Q: FloatArray | None) -> FloatArray:
    """A Jacobian whose Gauss–Newton covariance is the corrected fit's sandwich covariance.

    The corrected estimator solves ``(H − Q) Δ = …`` with ``H = JᵀJ``; its
    covariance is ``σ² (H − Q)⁻¹ H (H − Q)⁻¹`` (the sandwich of an M-estimator,
    Nakamura 1990), which is ``σ² (J_eᵀ J_e)⁻¹`` for ``J_e = J H⁻¹ (H − Q)``.
    """
    if Q is None:
        return J
    H = J.T @ J
    try:
        return np.asarray(J @ np.linalg.solve(H, H - Q), dtype=float)
    except np.linalg.LinAlgError:
        return J


#: A centre coordinate closer than this to the search box edge counts as on the bound, m.
BOUND_MARGIN_M = 0.001


def fit_spherical(
    data: SphericalData,
    *,
    method: str,
    options: CalibrationOptions,
    joint: str = "joint",
    parent_sensor: str = "parent",
    child_sensor: str = "child",
    gauge_axes: tuple[FloatArray, FloatArray] | None = None,
    prior: CenterPrior | None = None,
    keep: ArrayLike | None = None,
    accept: Callable[[FloatArray, FloatArray], bool] | None = None,
) -> SphericalJointCalibration:
    """Solve eq. 7 on prepared signals and attach the excitation diagnostics.

    Args:
        data: bias-corrected, filtered signals of the pair with α.
        method: one of :data:`~lowerlimb.calibration.options.METHODS`.
        options: calibration options.
        joint: joint name used in messages.
        parent_sensor: parent sensor name used in messages.
        child_sensor: child sensor name used in messages.
        gauge_axes: ``(j_P, j_C)`` for a hinge: the solution is pinned to the
            point of the axis nearest the sensors (eq. 16), see
            :func:`~lowerlimb.constraints.spherical.spherical_axis_gauge_sample_function`
            (five parameters; the covariance is mapped back to the six coordinates).
        prior: a weak Gaussian prior on one of the two centres (not with
            ``gauge_axes``): the data-only solution is refined by the MAP problem
            (:func:`_refine`). The excitation report stays the data's own.
        keep: (N,) booleans, the samples to fit (``None``: all); the others are left
            out, e.g. near impacts (:func:`~lowerlimb.calibration.impact_window.impact_keep_mask`).
        accept: with ``gauge_axes`` and a local method, whether a centre ``(c_P, c_C)`` (sensor
            frames, m) is plausible: the fit then also tries other starts
            (``options.hinge_centre_start_m``, :func:`_best_start`) and prefers a plausible
            basin, then a lower cost. ``None``: the start at zero alone.

    Returns:
        The joint result; warnings are issued and recorded.

    Raises:
        SolverError: the solver failed.
    """
    t0 = time.perf_counter()
    excluded = 0.0
    if keep is not None:
        n_all = data.n_samples
        data = data.select(keep)
        excluded = 1.0 - data.n_samples / max(n_all, 1)
    if options.fit_max_samples is not None:
        data = data.subsample(subsample_step(data.n_samples, options.fit_max_samples))
    if gauge_axes is None:
        problem = _spherical_problem(data, options)
        n_par = 6
    else:
        Qp = basis_with_first_axis(gauge_axes[0])
        Qc = basis_with_first_axis(gauge_axes[1])
        rotated = data.rotated(Qp, Qc)
        problem = _axis_problem(rotated, options)
        # y (5) -> x' (rotated frames) -> x = (Q_P c'_P, Q_C c'_C) (sensor frames)
        M = np.zeros((6, 6))
        M[:3, :3], M[3:, 3:] = Qp, Qc
        M = M @ AXIS_GAUGE_MAP
        n_par = 5
    if method in ("casadi", "gn"):
        result = solve_local(problem, np.zeros(n_par), method, options)
        if gauge_axes is not None and accept is not None and options.hinge_centre_start_m is not None:

            def accept_y(y: FloatArray) -> bool:
                x6 = M @ y
                return accept(x6[:3], x6[3:])

            result = _best_start(problem, rotated, result, accept_y, method, options)
    else:
        result = solve_global(problem, method, options)
    if gauge_axes is None:
        x = np.asarray(result.x, dtype=float).copy()
        Q = None
        sqrt_w = np.ones(data.n_samples)
        if prior is not None or options.noise_correction or options.robust:
            x, Q, w = _refine(data, x, prior, options)
            sqrt_w = np.sqrt(w)
        r = spherical_residual(x, data)
        report = jacobian_report(
            _corrected_jacobian(sqrt_w[:, None] * spherical_jacobian(x, data), Q),
            sqrt_w * r,
            noise_floor=options.noise_floor_mps2,
        )
    else:
        x = M @ np.asarray(result.x, dtype=float)
        r = spherical_residual(x, data)
        report = jacobian_report(
            spherical_jacobian(x, data) @ M, r, noise_floor=options.noise_floor_mps2, param_map=M
        )
    messages: list[str] = []
    if np.any(np.abs(x) >= options.center_bound_m - BOUND_MARGIN_M):
        # a solution on the search box is no least-squares optimum: its spread means nothing
        report = replace(report, weakest_std=float("inf"))
        if np.isfinite(options.center_std_tol_m):  # not a quiet internal fit
            messages.append(
                f"{joint}: the joint centre ran into the search box (±{options.center_bound_m:g} m from a "
                f"sensor) and is not determined by the data; record motion that rotates both segments "
                f"about several axes, or check that the {parent_sensor} and {child_sensor} sensors are on "
                f"adjacent segments"
            )
    elif report.weakest_std > options.center_std_tol_m:
        v = report.weakest_direction
        std_text = (
            f"±{report.weakest_std * 1000:.0f} mm"
            if report.weakest_std < 1.0
            else "unobservable: ± more than 1 m"
        )
        messages.append(
            f"{joint}: the joint centre is poorly determined ({std_text})"
            f" along {_direction_text(v[:3])} in the {parent_sensor} sensor frame and "
            f"{_direction_text(v[3:])} in the {child_sensor} sensor frame; record motion that "
            f"rotates both segments about several axes (not only flexion)"
        )
    messages += low_rotation_messages(
        joint,
        ((parent_sensor, data.gyr_parent), (child_sensor, data.gyr_child)),
        options.min_rms_rate_rps,
        "the centre in its frame cannot be determined; record a trial in which this segment moves",
    )
    report.warnings = list(messages)
    issue_warnings(messages, stacklevel=4)
    return SphericalJointCalibration(
        joint=joint,
        parent_sensor=parent_sensor,
        child_sensor=child_sensor,
        center_in_parent_sensor=x[:3],
        center_in_child_sensor=x[3:],
        rms_residual=float(np.sqrt(np.mean(r**2))),
        excitation=report,
        method=method,
        solver=result.method,
        iterations=int(result.iterations),
        converged=bool(result.converged),
        solve_time_s=time.perf_counter() - t0,
        warnings=messages,
        impact_excluded_fraction=excluded,
    )


def calibrate_spherical_joint(
    acc_parent: ArrayLike,
    gyr_parent: ArrayLike,
    acc_child: ArrayLike,
    gyr_child: ArrayLike,
    *,
    rate_hz: float,
    method: str = "casadi",
    options: CalibrationOptions | None = None,
    joint: str = "joint",
    parent_sensor: str = "parent",
    child_sensor: str = "child",
) -> SphericalJointCalibration:
    """Joint centre of a spherical joint between two IMUs, with diagnostics.

    With ``options.impact_exclusion`` (default) the samples near jerk peaks of
    either accelerometer are left out
    (:func:`~lowerlimb.calibration.impact_window.impact_keep_mask`); smooth motion
    has none. A pair recorded below ``options.min_fit_rate_hz`` (100 Hz) is fitted on
    its signals interpolated to a multiple of the rate
    (:mod:`~lowerlimb.upsample`; the real rig at 50 Hz: centres 3.1 / 6.4 /
    9.3 → 2.7 / 4.5 / 7.5 mm, ``benchmarks/results/rig.md``).

    Args:
        acc_parent: (N, 3) parent accelerometer (specific force), parent sensor frame, m/s².
        gyr_parent: (N, 3) parent gyroscope, parent sensor frame, rad/s.
        acc_child: (N, 3) child accelerometer, child sensor frame, m/s².
        gyr_child: (N, 3) child gyroscope, child sensor frame, rad/s.
        rate_hz: common sampling rate, Hz.
        method: ``"casadi"`` (default), ``"gn"``, ``"dwpso"``, ``"gwo"``,
            ``"dwpso+casadi"`` or ``"gwo+casadi"``.
        options: tuning parameters (defaults: :class:`CalibrationOptions`).
        joint: joint name used in messages.
        parent_sensor: parent sensor name used in messages.
        child_sensor: child sensor name used in messages.

    Returns:
        The centres (m) in both frames, residual, excitation report and warnings.

    Raises:
        ShapeError: an array is not (N, 3) or lengths differ.
        NonFiniteValueError: NaN or inf in a signal.
        UnitError: a gyro that looks like deg/s.
        InputError: non-positive rate, too few samples, or unknown method.
        SolverError: the solver failed.
    """
    opts = options or CalibrationOptions()
    check_method(method)
    bands = prepare_pair_bands(
        acc_parent, gyr_parent, acc_child, gyr_child, rate_hz, opts, band=opts.pair_band_test
    )
    sig, data, capped = bands.sig, bands.full, bands.capped
    keep = None
    if opts.impact_exclusion:
        k = upsample_factor(check_rate(rate_hz), opts.min_fit_rate_hz)  # as prepare_pair_bands did
        raw = upsampled({"p": np.asarray(acc_parent, float), "c": np.asarray(acc_child, float)}, k)
        keep = impact_keep_mask((raw["p"], raw["c"]), sig.rate_hz, opts)

    def fit(d: SphericalData) -> SphericalJointCalibration:
        return fit_spherical(
            d, method=method, options=opts, joint=joint, parent_sensor=parent_sensor,
            child_sensor=child_sensor, keep=keep,
        )  # fmt: skip

    if capped is None:
        return fit(data)
    return _fit_in_pair_band(fit, data, capped, bands.cap_hz, keep, opts)


def _fit_in_pair_band(
    fit: Callable[[SphericalData], SphericalJointCalibration],
    full: SphericalData,
    band: SphericalData,
    cap_hz: float | None,
    keep: ArrayLike | None,
    options: CalibrationOptions,
) -> SphericalJointCalibration:
    """The pair fitted on both bands: the fit :func:`~lowerlimb.calibration.pair_band.choose_band` keeps.

    Only the kept fit's warnings are issued; its ``pair_band`` records the test.
    """
    fits, caught = [], []
    for d in (full, band):
        with warnings.catch_warnings(record=True) as got:
            warnings.simplefilter("always")
            fits.append(fit(d))
        caught.append(got)
    uncapped, capped = (np.r_[f.center_in_parent_sensor, f.center_in_child_sensor] for f in fits)
    choice = choose_band(
        uncapped,
        capped,
        full,
        band,
        cap_hz=float(cap_hz if cap_hz is not None else np.nan),
        margin=options.pair_band_margin,
        keep=keep,
    )
    i = int(choice.capped)
    for w in caught[i]:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return replace(fits[i], pair_band=choice)


def estimate_joint_center(
    acc_parent: ArrayLike,
    gyr_parent: ArrayLike,
    acc_child: ArrayLike,
    gyr_child: ArrayLike,
    *,
    rate_hz: float,
    method: str = "casadi",
    options: CalibrationOptions | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Centre of the spherical joint between two IMUs, in each sensor's frame (Hu 2021 eq. 1–3).

    Any two IMUs on two segments joined by a (near-)spherical joint work;
    the motion should rotate both segments about several axes. Start the
    recording with ≥ 0.5 s still to have the gyro bias removed.

    Args:
        acc_parent: (N, 3) parent accelerometer (specific force), parent sensor frame, m/s².
        gyr_parent: (N, 3) parent gyroscope, parent sensor frame, rad/s.
        acc_child: (N, 3) child accelerometer, child sensor frame, m/s².
        gyr_child: (N, 3) child gyroscope, child sensor frame, rad/s.
        rate_hz: common sampling rate, Hz.
        method: ``"casadi"`` (default), ``"gn"``, ``"dwpso"``, ``"gwo"``,
            ``"dwpso+casadi"`` or ``"gwo+casadi"``.
        options: tuning parameters (defaults: :class:`CalibrationOptions`).

    Returns:
        ``(center_in_parent, center_in_child)``: (3,) vectors from each sensor's
        origin to the joint centre, in that sensor's frame, m.

    Raises:
        ShapeError: an array is not (N, 3) or lengths differ.
        NonFiniteValueError: NaN or inf in a signal.
        UnitError: a gyro that looks like deg/s.
        InputError: non-positive rate, too few samples, or unknown method.
        SolverError: the solver failed.

    Warns:
        ExcitationWarning: the motion leaves a direction of the centre poorly determined.
    """
    res = calibrate_spherical_joint(
        acc_parent,
        gyr_parent,
        acc_child,
        gyr_child,
        rate_hz=rate_hz,
        method=method,
        options=options,
    )
    return res.center_in_parent_sensor.copy(), res.center_in_child_sensor.copy()
