"""Does each sensor's accelerometer agree in sign with its gyro? Neighbours turn together.

An accelerometer read with the opposite sign (−9.81 m/s² along up at rest: some devices
report the acceleration of the case rather than the specific force) passes every other
check of a trial. Its gravity still turns the way its gyro says (``−f`` rotates like
``f``), the norm form of the joint constraint cannot tell ``|−f + Kc|`` from ``|f − Kc|``
(the centre comes out mirrored), and the vertical component of a joint's acceleration is
the same either way. A seven-IMU walk simulated with the pelvis's accelerometer negated
was calibrated without a warning, and its hip rotation came out 82° off on average.

What such a sensor gets wrong is *up*: its orientation filter turns the world upside
down about a horizontal axis to put the gravity it reads on +z. The sensor's rate about
the vertical, ``ω_z = (R ω)_z``, then changes sign, while its neighbours' do not. Along
the leg, adjacent segments turn about the vertical together (the joints rotate little
about it, and a walk's turns carry the whole chain), so their turning rates
correlate positively: each vertical rate averaged twice over
:attr:`SignCheckParams.turn_window_s` (longer than a stride, so the stride's oscillation
averages out and the turns stay) correlates with its neighbour's at 0.99–1.0 over the
real walk of ``gait/``, which turns once, and a negated sensor turns its edges to −1. An
edge decides only where both sensors turn (:attr:`SignCheckParams.min_turn_rps`: treadmill
walks 0.005–0.023 rad/s, walks that bend 0.065–0.14, the real walk 0.29). The rates used to
be low-passed at 2 Hz, which kept each stride's rotation about the vertical, and that
oscillation is no turn: its sign between neighbours is the walker's (simulated pelvis–thigh
−0.71 … +0.79 on treadmill walks, slow walkers negative), and a slow treadmill walker was
refused as "pelvis sign inverted". A gyro read with the opposite sign turns
the same correlations negative too (not always beyond the threshold), so the error
names both signals.

The chain's edges that decide (``|r| ≥ min_abs_correlation``) are satisfied by the
fewest sensors whose sign is inverted; a sensor is named when that set is unique, and
the two sensors of a lone negative edge otherwise.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import uniform_filter1d

from lowerlimb.conventions import FloatArray, quat_rotate
from lowerlimb.errors import InputError

__all__ = [
    "InvertedSignError",
    "InvertedSignWarning",
    "SignCheck",
    "SignCheckParams",
    "chain_sign_check",
    "turning_rate",
    "vertical_rate",
]


@dataclass(frozen=True)
class SignCheckParams:
    """Thresholds of the sign check.

    Attributes:
        min_abs_correlation: an edge decides when its correlation is at least this far
            from zero (the real walk's turning rates: 0.99–1.0; a negated sensor turns
            them to −0.99 … −1.0).
        turn_window_s: the vertical rates averaged twice over this window (a triangle
            of twice its length) keep a walk's turns and drop its strides' oscillation
            (a stride lasts at most 2.5 s), s.
        min_turn_rps: both sensors of an edge must turn at least this much at the pace
            of turns (SD of the averaged rate, rad/s): a trial that only oscillates about
            the vertical, as on a treadmill, decides nothing.
        min_abs_axial: an edge's axial-acceleration correlation
            (:mod:`lowerlimb.calibration.axial_sign`) decides when at least this far from
            zero (where the gyros fix the axes: rigid simulated knees +0.89 … +1.0, the real
            walk's knee +0.82 and ankles +0.95, −0.95 with the foot negated; with the
            real-walk artefacts the knee's −0.83 … +1.0 on unmodified squats and
            sit-to-stands).
        min_refuse_axial: a sensor named by axial witnesses alone is refused only when a
            negative one is at least this far from zero; nearer, it is named in an
            :class:`InvertedSignWarning` and the trial goes on. Unmodified one-leg
            squats and sit-to-stands simulated with the real-walk artefacts put the knee's
            witness as low as −0.83 (soft tissue turns the thigh sensor with the knee
            angle, and gravity leaks into the small axial acceleration;
            ``benchmarks/results/sign_check.md``), where rigid knees give +0.89 … +1.0 and
            the real walk's ankles +0.95.
    """

    min_abs_correlation: float = 0.6
    turn_window_s: float = 2.5
    min_turn_rps: float = 0.03
    min_abs_axial: float = 0.5
    min_refuse_axial: float = 0.9


@dataclass(frozen=True)
class SignCheck:
    """The chain's verdict.

    Attributes:
        edges: ``(sensor, sensor)`` neighbour pairs, proximal first.
        correlation: (E,) correlation of each pair's turning rates (:func:`turning_rate`), NaN when
            a sensor barely turns about the vertical.
        axial: (E,) correlation of each pair's accelerations along their joint's axis
            (NaN: not measured, or the gyros left the axes' direction open).
        decided_by: (E,) the witness that decides each edge: ``"vertical"`` (its vertical
            rates), ``"axial"`` (the axial witness, where the rates leave it open) or ``""``.
        inverted: sensors whose sign is inverted (the fewest that explain the deciding
            edges); empty when every deciding edge is positive.
        ambiguous: the inverted set is one of two equally small ones (the sensors named
            are the two ends of the first negative edge).
        firm: some negative deciding edge is decided by the vertical rates, or by an
            axial witness at least :attr:`SignCheckParams.min_refuse_axial` from zero: the
            named sensors are refused (else only warned about).
    """

    edges: tuple[tuple[str, str], ...]
    correlation: FloatArray
    axial: FloatArray
    decided_by: tuple[str, ...]
    inverted: tuple[str, ...]
    ambiguous: bool
    firm: bool = True

    @property
    def decides(self) -> tuple[bool, ...]:
        """(E,) whether each edge decides."""
        return tuple(bool(w) for w in self.decided_by)

    def to_dict(self) -> dict[str, object]:
        """The verdict as JSON-ready values (correlations ``None`` when undecided)."""
        return {
            "vertical_rate_correlation": {
                f"{a}-{b}": None if not np.isfinite(r) else float(r)
                for (a, b), r in zip(self.edges, self.correlation, strict=True)
            },
            "axial_correlation": {
                f"{a}-{b}": None if not np.isfinite(r) else float(r)
                for (a, b), r in zip(self.edges, self.axial, strict=True)
            },
            "inverted": list(self.inverted),
            "firm": self.firm,
        }

    def negative_edges(self) -> list[str]:
        """``"thigh–shank along the joint axis -0.54"`` for each negative deciding edge."""
        rows = zip(self.edges, self.correlation, self.axial, self.decided_by, strict=True)
        named = {"vertical": "about the vertical", "axial": "along the joint axis"}
        return [
            f"{a}–{b} {named[w]} {rv if w == 'vertical' else ra:+.2f}"
            for (a, b), rv, ra, w in rows
            if w and (rv if w == "vertical" else ra) < 0
        ]


class InvertedSignWarning(UserWarning):
    """A sensor's acceleration along a joint axis runs against its neighbour's, too weakly to refuse.

    Only the axial witness names it (nothing turned enough to hear the vertical rates), and
    its correlation is nearer zero than :attr:`SignCheckParams.min_refuse_axial`, which soft
    tissue alone can give.
    """

    def __init__(self, check: SignCheck) -> None:
        self.check = check
        self.sensors = check.inverted
        super().__init__(
            f"the {' or the '.join(check.inverted)} may have its accelerometer or gyro sign inverted "
            f"(correlations {', '.join(check.negative_edges())}; soft tissue alone gives such values "
            f"and no turn confirms it): check that each sensor reads +9.81 m/s² along up at rest"
        )


class InvertedSignError(InputError):
    """A sensor turns against its neighbours (about the vertical, or along a joint axis)."""

    def __init__(self, check: SignCheck) -> None:
        self.check = check
        self.sensors = check.inverted
        neg = check.negative_edges()
        if check.ambiguous:
            what = f"the {' or the '.join(check.inverted)} turns"
            whose = "one of them has its accelerometer or gyro sign inverted (too little turning to tell)"
        elif len(check.inverted) == 1:
            what, whose = f"the {check.inverted[0]} turns", "its accelerometer or gyro sign is inverted"
        else:
            what, whose = (
                f"the {' and the '.join(check.inverted)} turn",
                "their accelerometer or gyro signs are inverted",
            )
        super().__init__(
            f"{what} against the neighbouring segments (correlations {', '.join(neg)}): {whose}; "
            f"negate the acc_* columns (a device that reads -9.81 "
            f"along up at rest) or the gyr_* columns, or pass --no-sign-check if the motion really "
            f"turns these segments against each other"
        )


def vertical_rate(quat_wxyz: FloatArray, gyr: FloatArray) -> FloatArray:
    """(N,) angular rate about the earth's vertical, rad/s.

    Args:
        quat_wxyz: (N, 4) sensor orientations (sensor to earth, z up), ``w, x, y, z``.
        gyr: (N, 3) angular rate, sensor frame, rad/s.
    """
    return np.asarray(quat_rotate(quat_wxyz, gyr)[:, 2], dtype=float)


def turning_rate(rate: FloatArray, rate_hz: float, window_s: float) -> FloatArray:
    """A vertical rate (N,) averaged twice over ``window_s``, rad/s: its turns, without its strides.

    The two moving averages (a triangular window of ``2 window_s``) keep turns, which last
    longer than a stride, and drop a stride's oscillation; the ends, where the average runs
    short, are left out (kept when the trial is shorter than four windows).
    """
    n = max(1, int(round(window_s * rate_hz)))
    x = np.asarray(rate, dtype=float)
    slow = uniform_filter1d(uniform_filter1d(x, n, mode="nearest"), n, mode="nearest")
    return slow[2 * n : -2 * n] if slow.size > 4 * n else slow


def _edge_correlation(a: FloatArray, b: FloatArray, p: SignCheckParams) -> float:
    """Correlation of two sensors' turning rates; NaN when either barely turns."""
    a, b = a - a.mean(), b - b.mean()
    if min(float(np.std(a)), float(np.std(b))) < p.min_turn_rps:
        return float("nan")
    den = float(np.sqrt(np.sum(a * a) * np.sum(b * b)))
    return float(np.sum(a * b) / den) if den > 0 else float("nan")


def _group_signs(root: str, edges: Sequence[tuple[str, str]], sign: Sequence[int]) -> dict[str, int]:
    """Signs (±1) of the sensors joined to ``root`` by deciding edges, relative to ``root``'s +1."""
    value, stack = {root: 1}, [root]
    while stack:
        s = stack.pop()
        for (a, b), e in zip(edges, sign, strict=True):
            other = b if s == a else a if s == b else None
            if e != 0 and other is not None and other not in value:
                value[other] = value[s] * e
                stack.append(other)
    return value


def _fewest_inverted(
    sensors: Sequence[str], edges: Sequence[tuple[str, str]], sign: Sequence[int]
) -> tuple[tuple[str, ...], bool]:
    """The fewest sensors whose inversion explains the deciding edges' signs (±1; 0: undecided).

    Each group of sensors joined by deciding edges gets signs relative to its first
    sensor; of a group's two assignments the one with fewer inverted sensors is taken.
    Returns the inverted sensors and whether some group's choice was a tie.
    """
    seen: set[str] = set()
    inverted: list[str] = []
    ambiguous = False
    for root in sensors:
        if root in seen:
            continue
        value = _group_signs(root, edges, sign)
        seen |= set(value)
        neg = [s for s, v in value.items() if v < 0]
        pos = [s for s, v in value.items() if v > 0]
        if neg and len(neg) == len(pos):
            ambiguous = True
            inverted += _first_negative_edge(edges, sign, list(value))
        else:
            inverted += neg if len(neg) < len(pos) else pos
    return tuple(s for s in sensors if s in inverted), ambiguous


def _first_negative_edge(
    edges: Sequence[tuple[str, str]], sign: Sequence[int], group: list[str]
) -> list[str]:
    """The two sensors of the group's first negative deciding edge (a tie names both)."""
    for (a, b), e in zip(edges, sign, strict=True):
        if e < 0 and a in group:
            return [a, b]
    return []


def chain_sign_check(
    quat_wxyz: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    edges: Sequence[tuple[str, str]],
    rate_hz: float,
    params: SignCheckParams | None = None,
    axial: Mapping[tuple[str, str], float] | None = None,
) -> SignCheck:
    """Correlate neighbours' vertical rates and name the sensors whose sign is inverted.

    Args:
        quat_wxyz: ``{sensor: (N, 4)}`` each sensor's filter orientation (its own gravity).
        gyr: ``{sensor: (N, 3)}`` angular rates, sensor frames, rad/s (bias removed).
        edges: neighbouring sensor pairs (a chain or a tree).
        rate_hz: sampling rate, Hz.
        params: thresholds (defaults when ``None``).
        axial: ``{edge: correlation}`` of the pairs' accelerations along their joint's axis
            (:func:`lowerlimb.calibration.axial_sign.axial_sign_correlation`), a second
            witness that needs no turning, heard on the edges the vertical rates leave open.

    Returns:
        The verdict (nothing inverted when no edge decides).
    """
    p = params or SignCheckParams()
    names = list(dict.fromkeys(s for e in edges for s in e))
    n = min(len(quat_wxyz[s]) for s in names)
    ra = np.asarray([(axial or {}).get((a, b), np.nan) for a, b in edges], dtype=np.float64)
    v = {
        s: turning_rate(vertical_rate(quat_wxyz[s][:n], gyr[s][:n]), rate_hz, p.turn_window_s) for s in names
    }
    r = np.asarray([_edge_correlation(v[a], v[b], p) for a, b in edges], dtype=np.float64)
    votes = [_edge_vote(x, y, p) for x, y in zip(r, ra, strict=True)]
    sign = [v for v, _ in votes]
    inverted, ambiguous = _fewest_inverted(names, edges, sign)
    firm = any(
        e < 0 and (w == "vertical" or abs(x) >= p.min_refuse_axial)
        for (e, w), x in zip(votes, ra, strict=True)
    )
    return SignCheck(tuple(edges), r, ra, tuple(w for _, w in votes), inverted, ambiguous, firm)


def _edge_vote(vertical: float, axial: float, p: SignCheckParams) -> tuple[int, str]:
    """(+1 / −1 / 0, the deciding witness): the vertical rates when they decide, else the axial one.

    The vertical rates come first: the axial witness trusts the gyros to fix the axes'
    direction, which an inverted gyro does not (squats and sit-to-stands with a negated
    shank or foot gyro gave an axial correlation of the wrong sign).
    """
    if abs(vertical) >= p.min_abs_correlation:
        return int(np.sign(vertical)), "vertical"
    if abs(axial) >= p.min_abs_axial:
        return int(np.sign(axial)), "axial"
    return 0, ""
