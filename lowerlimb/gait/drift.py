"""The slow drift of one foot's track against the other, removed with the calibrated chain.

Each foot is integrated on its own (:mod:`lowerlimb.gait.trajectory`); after the
moving foot's track is turned onto the reference one and anchored to it once
(:mod:`lowerlimb.gait.placement`, which does it both ways: right onto left and left onto
right), the two still drift apart: a small difference in the feet's scale or heading errors
grows with the distance walked. On a simulated 10-minute walk the right foot fell behind the
left one by a metre, and step width and step length were lost.

The calibrated chain (pelvis, hips, both legs) gives the moving-minus-reference ankle vector
at every initial contact of the moving foot, in the walking frame of the reference foot's
stance, with no drift at all, but with a bias: on the real walk of ``gait/`` its lateral
part is 20 cm off Vicon's. So the chain is used only for what changes over time. With
``o_i = chain_i − track_i`` the chain-minus-track vectors (earth frame of the reference
track) at the moving foot's contacts ``t_i``, the model is

    o_i = R(ψ_i) b + F(t_i) + e_i,

``b`` the chain's constant bias in the walking frame (forward, left), ``R(ψ_i)`` the
reference stride's walking direction, and ``F`` a piecewise-linear drift with knots every
:attr:`GaitParams.chain_drift_knot_s` from the anchor. Consecutive knots get a Gaussian
prior of :attr:`GaitParams.chain_drift_sd_m`, and the knot at the anchor itself one of
:attr:`GaitParams.chain_anchor_sd_m`: the standing anchor has an error of its own (the
chain's geometry at one instant), which a walk that turns separates from ``b``; walking
straight, ``b`` and a constant ``F`` cannot be told apart and the prior keeps the anchor.
The anchor's prior is narrow (2 cm): on the real walk of ``gait/`` the standing anchor
matched Vicon's stance width within 2 mm, and on straight synthetic walks with a 2°
stride-to-stride wobble the chain's noise moves a free anchor by 19 mm median (34 mm worst;
pinned: 15 / 20 mm from the later knots). Against ``F`` pinned to zero at the anchor
(``chain_anchor_sd_m=None``), on the 60 s simulated seven-IMU walks of
``benchmarks/gait.py`` (seeds 201–206) the step width goes from 15.9 to 12.2 mm median and
from 113 to 46 mm worst (a 5 cm prior: 10.6 / 41 mm); on eight 5- and 10-minute walks,
steady or changing pace, the median of their medians from 9.8 to 9.2 mm and the 10-minute
walk's worst from 129 to 57 mm (one 5-minute walk loses 2 mm: 6.6 → 8.7).
Large residuals (turning steps, a stumble) are down-weighted by Huber weights. The moving
track then moves by ``F(t)``.

**Breaks.** A foot's track jumps where it goes unaided: in a turn about, a foot pivots on the
floor at up to 3 rad/s, no stationary period is found, and its track is integrated through
the turn with no zero-velocity update. On simulated walks of 6 s passes with turns between
them (``benchmarks/results/turns.md``) the step width then changed pass by pass (22.5 / 73 mm
median / worst on the straight passes against 9.9 / 31 on bending walks), which knots 30 s
apart cannot follow. So every gap between a foot's stationary periods longer than
:attr:`GaitParams.chain_drift_gap_s` gets a knot at each end, and the drift's change across
it the prior SD :attr:`GaitParams.chain_drift_break_sd_m` (nearly free). The other knots keep
their random-walk prior, the SD scaled by ``sqrt(Δt / chain_drift_knot_s)`` so that a grid
without breaks is the one above.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lowerlimb.conventions import FloatArray
from lowerlimb.gait.contacts import Contacts, heading_change_rad
from lowerlimb.gait.params import GaitParams

__all__ = ["ChainSteps", "TrackDrift", "fit_track_drift", "heading_spread", "track_drift", "unaided_gaps"]

_MIN_SD_M = 1e-4  # floor of the residual scale (an exact chain in tests), m


@dataclass(frozen=True)
class ChainSteps:
    """The calibrated chain's ankle vector at one foot's initial contacts: that foot minus the other.

    Attributes:
        time_s: (M,) initial-contact times of ``side``, s from sample 0.
        forward_m: (M,) component along the walking direction of the other foot's
            stance (the stance ankle's path under the pelvis), m.
        left_m: (M,) component along up × forward (to the walker's left), m.
        side: the foot making contact (``"right"``: right minus left at right contacts).
    """

    time_s: FloatArray
    forward_m: FloatArray
    left_m: FloatArray
    side: str = "right"


@dataclass(frozen=True)
class TrackDrift:
    """The fitted drift of the moving foot's track against the reference one (``gait.placement``).

    Attributes:
        knot_time_s: (K,) knot times, s from sample 0; the first is the anchor's.
        knot_offset_m: (K, 2) drift ``F`` at the knots, earth frame of the reference track
            (horizontal), m; the first row is the anchor's correction (zero when pinned).
        chain_bias_m: (2,) the chain's constant offset (forward, left) against the
            anchored tracks, m.
        residual_sd_m: robust SD of the chain-minus-track residuals, m.
        steps_used: number of chain steps fitted.
        moving_side: the foot whose track moved (``"right"``: against the left one).
        heading_spread: how much the fitted steps' walking directions differ,
            ``sqrt(1 − |mean u|²)`` of their unit vectors ``u`` (0: one direction, a
            straight walk or a treadmill; about 0.2–0.5 on a walk that bends by 15–45°; 1:
            as many steps one way as back). The chain's bias ``b`` is told from the
            anchor's error only through this spread: near 0, the fit keeps the standing
            anchor and step width carries the chain's sideways error at standing. Pooled
            within the pieces between the drift's breaks (:func:`heading_spread`): straight
            passes joined by unaided turns about give about 0.
    """

    knot_time_s: FloatArray
    knot_offset_m: FloatArray
    chain_bias_m: FloatArray
    residual_sd_m: float
    steps_used: int
    moving_side: str = "right"
    heading_spread: float = 0.0

    def at(self, time_s: FloatArray) -> FloatArray:
        """(N, 2) drift at ``time_s`` (s), m; constant before the anchor and after the last knot."""
        t = np.atleast_1d(np.asarray(time_s, dtype=float))
        return np.column_stack([np.interp(t, self.knot_time_s, self.knot_offset_m[:, j]) for j in range(2)])

    @property
    def max_m(self) -> float:
        """Largest drift removed, m."""
        return float(np.max(np.linalg.norm(self.knot_offset_m, axis=1)))

    def to_dict(self) -> dict[str, object]:
        """``gait.json``'s ``track_drift``: the knots, the chain's bias and the fit's residual."""
        return {
            "moving_side": self.moving_side,
            "max_m": self.max_m,
            "knot_time_s": [float(t) for t in self.knot_time_s],
            "knot_offset_m": [[float(x), float(y)] for x, y in self.knot_offset_m],
            "chain_bias_forward_m": float(self.chain_bias_m[0]),
            "chain_bias_left_m": float(self.chain_bias_m[1]),
            "residual_sd_m": self.residual_sd_m,
            "steps_used": self.steps_used,
            "heading_spread": self.heading_spread,
        }


def _hat_basis(t: FloatArray, knots: FloatArray, pinned: bool) -> FloatArray:
    """(N, K) piecewise-linear basis at ``t`` of the knots; (N, K−1) without the first when ``pinned``."""
    values = np.eye(len(knots))[:, 1 if pinned else 0 :]
    return np.column_stack([np.interp(t, knots, values[:, j]) for j in range(values.shape[1])])


def fit_track_drift(
    time_s: FloatArray,
    offset_m: FloatArray,
    walking_dir: FloatArray,
    anchor_time_s: float,
    params: GaitParams,
    breaks_s: FloatArray | None = None,
) -> TrackDrift | None:
    """Fit ``o_i = R(ψ_i) b + F(t_i)`` (module docstring) by iteratively reweighted least squares.

    Args:
        time_s: (M,) times of the chain steps, s from sample 0.
        offset_m: (M, 2) chain minus track vectors, earth frame of the reference track, m.
        walking_dir: (M, 2) unit walking directions of the reference strides, same frame.
        anchor_time_s: where the drift is pinned to zero, s.
        params: ``chain_drift_knot_s``, ``chain_drift_sd_m``, ``chain_drift_min_steps``,
            ``chain_drift_huber``, ``chain_drift_break_sd_m``.
        breaks_s: (B, 2) start and end of the gaps across which the drift may jump
            (module docstring, "Breaks"), s from sample 0; ``None``: none.

    Returns:
        The fit, or ``None`` when it is switched off or there are fewer than
        ``chain_drift_min_steps`` steps.
    """
    knot_s = params.chain_drift_knot_s
    keep = np.all(np.isfinite(offset_m), axis=1) & np.all(np.isfinite(walking_dir), axis=1)
    keep &= time_s > anchor_time_s
    if knot_s is None or np.count_nonzero(keep) < params.chain_drift_min_steps:
        return None
    t, o, u = time_s[keep], offset_m[keep], walking_dir[keep]
    n_grid = max(2, int(np.ceil((t[-1] - anchor_time_s) / knot_s)) + 1)
    knots = np.asarray(anchor_time_s + knot_s * np.arange(n_grid), dtype=float)
    gaps = np.zeros((0, 2)) if breaks_s is None else np.asarray(breaks_s, dtype=float).reshape(-1, 2)
    gaps = gaps[(gaps[:, 0] > anchor_time_s) & (gaps[:, 1] < t[-1])]
    knots = np.unique(np.concatenate([knots, gaps.ravel()]))
    n_knots = knots.size
    anchor_sd = params.chain_anchor_sd_m
    first = None if anchor_sd is None else params.chain_drift_sd_m / anchor_sd
    M, prior = _design(t, u, knots, first, _interval_scale(knots, gaps, params))
    sol, sd = _irls(M, np.concatenate([o[:, 0], o[:, 1]]), prior, params)
    k = (M.shape[1] - 2) // 2
    F = np.zeros((n_knots, 2))
    F[n_knots - k :, 0], F[n_knots - k :, 1] = sol[2 : 2 + k], sol[2 + k :]
    piece = np.searchsorted(np.sort(gaps.mean(axis=1)), t) if gaps.size else None  # breaks before each step
    spread = heading_spread(u, piece)
    return TrackDrift(knots, F, sol[:2].copy(), sd, len(t), heading_spread=spread)


def heading_spread(walking_dir: FloatArray, piece: np.ndarray | None = None) -> float:
    """``sqrt(1 − |mean u|²)`` of (M, 2) unit walking directions: 0 for one direction, 1 for opposite ones.

    With ``piece`` (M,), the steps' pieces between the drift's breaks, the pooled spread
    within the pieces, ``sqrt(1 − Σ n_k |mean_k u|² / M)``: a free jump at a break takes each
    piece's share of the chain's bias, so only the directions within a piece tell the bias
    from the drift (straight passes joined by turns about: about 0, as for a straight walk).
    """
    u = np.asarray(walking_dir, dtype=float).reshape(-1, 2)
    if u.shape[0] == 0:
        return 0.0
    labels = np.zeros(u.shape[0], dtype=int) if piece is None else np.asarray(piece)
    r2 = sum(
        float(np.sum(labels == k)) * float(np.linalg.norm(u[labels == k].mean(axis=0))) ** 2
        for k in np.unique(labels)
    )
    return float(np.sqrt(max(0.0, 1.0 - min(r2 / u.shape[0], 1.0))))


def _interval_scale(knots: FloatArray, gaps: FloatArray, params: GaitParams) -> FloatArray:
    """(K−1,) prior SD of the drift's change over each knot interval, in ``chain_drift_sd_m``.

    ``sqrt(Δt / chain_drift_knot_s)`` (a random walk: 1 on the regular grid), or
    ``chain_drift_break_sd_m / chain_drift_sd_m`` for an interval inside a gap.
    """
    knot_s = float(params.chain_drift_knot_s or 1.0)
    scale = np.sqrt(np.maximum(np.diff(knots), 1e-9) / knot_s)
    mid = 0.5 * (knots[1:] + knots[:-1])
    inside = np.any((mid[:, None] > gaps[None, :, 0]) & (mid[:, None] < gaps[None, :, 1]), axis=1)
    scale[inside] = params.chain_drift_break_sd_m / params.chain_drift_sd_m
    return np.asarray(scale, dtype=float)


def _design(
    t: FloatArray, u: FloatArray, knots: FloatArray, first: float | None, scale: FloatArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """The model's matrix (2M, 2 + 2k) and the prior's rows (2k, same columns).

    Unknowns: ``b`` (forward, left), then ``F_x`` and ``F_y`` at the k knots: every knot, or
    (``first`` ``None``) those after the anchor's, pinned to zero. Rows: the x components of
    the M steps, then their y components. The prior's rows are the knot-to-knot changes, each
    divided by its interval's ``scale`` (:func:`_interval_scale`; ``None``: all 1); the
    first is the anchor knot's own value scaled by ``first`` (``chain_drift_sd_m`` over
    ``chain_anchor_sd_m``), or, pinned, the change from zero.
    """
    B = _hat_basis(t, knots, first is None)
    k, m = B.shape[1], len(t)
    M = np.zeros((2 * m, 2 + 2 * k))
    M[:m, 0], M[m:, 0] = u[:, 0], u[:, 1]
    M[:m, 1], M[m:, 1] = -u[:, 1], u[:, 0]
    M[:m, 2 : 2 + k] = B
    M[m:, 2 + k :] = B
    D = np.eye(k) - np.eye(k, k=-1)  # knot-to-knot changes, the first from the pinned zero
    if scale is not None:
        # pinned: row j is the change over interval j; free: row 0 is the anchor, row j ≥ 1 interval j − 1
        lead = 0 if first is None else 1
        D[lead:] /= scale[: k - lead, None]
    if first is not None:
        D[0, 0] = first  # the anchor knot itself: N(0, chain_anchor_sd_m²)
    prior = np.zeros((2 * k, 2 + 2 * k))
    prior[:k, 2 : 2 + k] = D
    prior[k:, 2 + k :] = D
    return M, prior


def _irls(M: FloatArray, y: FloatArray, prior: FloatArray, params: GaitParams) -> tuple[FloatArray, float]:
    """Huber-weighted least squares with the prior scaled by the residuals' robust SD.

    Returns:
        ``(solution, robust SD of the residuals in m)``.
    """
    w = np.ones(len(y))
    sd = max(_robust_sd(y - M @ _solve(M, y, w, prior, 1.0)), _MIN_SD_M)  # a first scale
    sol = np.zeros(M.shape[1])
    for _ in range(params.chain_drift_iterations):
        sol = _solve(M, y, w, prior, sd / params.chain_drift_sd_m)
        r = y - M @ sol
        sd = max(_robust_sd(r), _MIN_SD_M)
        w = np.minimum(1.0, params.chain_drift_huber * sd / np.maximum(np.abs(r), 1e-12))
    return sol, sd


def _solve(M: FloatArray, y: FloatArray, w: FloatArray, prior: FloatArray, prior_weight: float) -> FloatArray:
    """Weighted least squares with a stacked prior block (rows ``prior · x ≈ 0``)."""
    sw = np.sqrt(w)
    A = np.vstack([M * sw[:, None], prior_weight * prior])
    rhs = np.concatenate([y * sw, np.zeros(prior.shape[0])])
    return np.asarray(np.linalg.lstsq(A, rhs, rcond=None)[0])


def _robust_sd(r: FloatArray) -> float:
    """1.4826 × the median absolute residual."""
    return float(1.4826 * np.median(np.abs(r)))


def track_drift(
    cl: Contacts,
    cr: Contacts,
    chain: ChainSteps,
    anchor_time_s: float,
    p: GaitParams,
    breaks_s: FloatArray | None = None,
) -> TrackDrift | None:
    """The moving track's drift from the chain steps at its contacts on straight reference strides.

    Args:
        cl: the reference foot's contacts (its track is kept).
        cr: the moving foot's contacts, turned onto the reference track and anchored.
        chain: the chain's moving-minus-reference ankle vectors at the moving foot's contacts.
        anchor_time_s: where the drift is pinned to zero, s from sample 0.
        p: ``turn_heading_deg`` and the ``chain_drift_*`` thresholds.
        breaks_s: (B, 2) gaps across which the drift may jump (:func:`unaided_gaps`), s.

    Returns:
        :func:`fit_track_drift` of the chain-minus-track vectors, or ``None``.
    """
    thr = np.deg2rad(p.turn_heading_deg)
    rows = []
    for t, fwd, lft in zip(chain.time_s, chain.forward_m, chain.left_m, strict=True):
        k = int(np.argmin(np.abs(cr.time_s - t))) if len(cr.time_s) else -1
        before = np.flatnonzero(cl.time_s < t)
        if k < 0 or abs(cr.time_s[k] - t) > 1e-6 or not before.size or before[-1] + 1 >= len(cl.time_s):
            continue
        j = int(before[-1])
        step = cl.position_m[j + 1, :2] - cl.position_m[j, :2]
        length = float(np.linalg.norm(step))
        if not np.isfinite(length) or length == 0.0:
            continue
        if abs(heading_change_rad(cl.R_earth_sensor[j], cl.R_earth_sensor[j + 1])) > thr:
            continue
        u = step / length
        on_chain = fwd * u + lft * np.array([-u[1], u[0]])
        rows.append((t, *(on_chain - (cr.position_m[k, :2] - cl.position_m[j, :2])), *u))
    r = np.asarray(rows, dtype=float).reshape(-1, 5)
    return fit_track_drift(r[:, 0], r[:, 1:3], r[:, 3:5], anchor_time_s, p, breaks_s)


def unaided_gaps(stationary_s: list[FloatArray], p: GaitParams) -> FloatArray:
    """(B, 2) gaps between a foot's stationary periods longer than ``chain_drift_gap_s``, s.

    Args:
        stationary_s: each foot's (K, 2) stationary periods (start, end), s from sample 0.
        p: ``chain_drift_gap_s`` (``None``: no gaps).
    """
    if p.chain_drift_gap_s is None:
        return np.zeros((0, 2))
    out = []
    for iv in stationary_s:
        iv = np.asarray(iv, dtype=float).reshape(-1, 2)
        starts, ends = iv[1:, 0], iv[:-1, 1]
        long = starts - ends > p.chain_drift_gap_s
        out += list(zip(ends[long], starts[long], strict=True))
    return np.asarray(out, dtype=float).reshape(-1, 2)
