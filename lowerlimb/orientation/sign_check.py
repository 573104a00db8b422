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
about it, and a walk's turns carry the whole chain), so the low-passed vertical rates of
neighbours correlate positively (measured over each whole trial: 0.79–0.98 on the real
walk of ``gait/``, which turns once; 0.4–1.0 on the simulator's one-leg motions, rigid
or with its real-walk artefacts), and a negated accelerometer makes its edges negative
(−0.8 … −0.98 on the real walk). Straight simulated two-leg walks turn too little for a
verdict: their pelvis–thigh and shank–foot correlations lie between −0.4 and +0.8
whether or not a sign is inverted, and a correlation that weak decides nothing
(:attr:`SignCheckParams.min_abs_correlation`). A gyro read with the opposite sign turns
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
from scipy.signal import butter, sosfiltfilt

from lowerlimb.conventions import FloatArray, quat_rotate
from lowerlimb.errors import InputError

__all__ = ["InvertedSignError", "SignCheck", "SignCheckParams", "chain_sign_check", "vertical_rate"]


@dataclass(frozen=True)
class SignCheckParams:
    """Thresholds of the sign check.

    Attributes:
        lowpass_hz: low-pass cut-off of the vertical rates, Hz (a stride's turning is
            about 1 Hz; impacts and filter noise lie above).
        min_abs_correlation: an edge decides when its correlation is at least this far
            from zero (normal data: ≥ −0.4 on straight simulated walks with artefacts;
            a negated sensor on the real walk: ≤ −0.79).
        min_rms_rate_rps: both sensors of an edge must turn about the vertical at least
            this much (RMS of the low-passed rate), rad/s; a trial without turning
            decides nothing.
        min_abs_axial: an edge's axial-acceleration correlation
            (:mod:`lowerlimb.calibration.axial_sign`) decides when at least this far from
            zero (where the gyros fix the axes: rigid simulated knees +0.89 … +1.0, the real
            walk's knee +0.82 and ankles +0.95, −0.95 with the foot negated; with the
            real-walk artefacts −0.14 … +0.78, so mostly no verdict).
    """

    lowpass_hz: float = 2.0
    min_abs_correlation: float = 0.6
    min_rms_rate_rps: float = 0.05
    min_abs_axial: float = 0.5


@dataclass(frozen=True)
class SignCheck:
    """The chain's verdict.

    Attributes:
        edges: ``(sensor, sensor)`` neighbour pairs, proximal first.
        correlation: (E,) correlation of each pair's low-passed vertical rates, NaN when
            a sensor barely turns about the vertical.
        axial: (E,) correlation of each pair's accelerations along their joint's axis
            (NaN: not measured, or the gyros left the axes' direction open).
        decided_by: (E,) the witness that decides each edge: ``"vertical"`` (its vertical
            rates), ``"axial"`` (the axial witness, where the rates leave it open) or ``""``.
        inverted: sensors whose sign is inverted (the fewest that explain the deciding
            edges); empty when every deciding edge is positive.
        ambiguous: the inverted set is one of two equally small ones (the sensors named
            are the two ends of the first negative edge).
    """

    edges: tuple[tuple[str, str], ...]
    correlation: FloatArray
    axial: FloatArray
    decided_by: tuple[str, ...]
    inverted: tuple[str, ...]
    ambiguous: bool

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
        }


class InvertedSignError(InputError):
    """A sensor turns against its neighbours (about the vertical, or along a joint axis)."""

    def __init__(self, check: SignCheck) -> None:
        self.check = check
        self.sensors = check.inverted
        rows = zip(check.edges, check.correlation, check.axial, check.decided_by, strict=True)
        named = {"vertical": "about the vertical", "axial": "along the joint axis"}
        neg = [
            f"{a}–{b} {named[w]} {rv if w == 'vertical' else ra:+.2f}"
            for (a, b), rv, ra, w in rows
            if w and (rv if w == "vertical" else ra) < 0
        ]
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


def _edge_correlation(a: FloatArray, b: FloatArray, p: SignCheckParams) -> float:
    """Correlation of two low-passed vertical rates; NaN when either barely turns."""
    if min(np.sqrt(np.mean(a**2)), np.sqrt(np.mean(b**2))) < p.min_rms_rate_rps:
        return float("nan")
    a, b = a - a.mean(), b - b.mean()
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
    sos = butter(2, min(p.lowpass_hz, 0.45 * rate_hz), fs=rate_hz, output="sos")
    names = list(dict.fromkeys(s for e in edges for s in e))
    n = min(len(quat_wxyz[s]) for s in names)
    ra = np.asarray([(axial or {}).get((a, b), np.nan) for a, b in edges], dtype=np.float64)
    if n <= 27:  # too short to filter (sosfiltfilt's padding)
        r = np.full(len(edges), np.nan, dtype=np.float64)
    else:
        v = {s: sosfiltfilt(sos, vertical_rate(quat_wxyz[s][:n], gyr[s][:n])) for s in names}
        r = np.asarray([_edge_correlation(v[a], v[b], p) for a, b in edges], dtype=np.float64)
    votes = [_edge_vote(x, y, p) for x, y in zip(r, ra, strict=True)]
    sign = [v for v, _ in votes]
    inverted, ambiguous = _fewest_inverted(names, edges, sign)
    return SignCheck(tuple(edges), r, ra, tuple(w for _, w in votes), inverted, ambiguous)


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
