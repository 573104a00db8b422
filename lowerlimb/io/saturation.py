"""Sensors that hit the end of their range: accelerometer or gyro readings cut at a full-scale limit.

Low-cost IMUs often record at a narrow default range (an MPU-6050 at ±2 g and ±250 °/s).
Walking exceeds that: on the simulator's walks the foot reaches 4.8 g and 590 °/s, the shank
3.6 g and 350 °/s; the real walk of the shared data 3.0 g and 460 °/s. A reading beyond the range
is cut at the limit, and everything downstream reads a wrong signal without knowing it: on
simulated walks a ±2 g accelerometer puts the shank 0.1 m off and the step width 0.6 m off, a
±250 °/s gyro puts the angles 8° off (``benchmarks/results/saturation.md``). Nothing in the
rest of the pipeline can tell a cut signal from a true one, so it is found here, at the input,
and said.

A cut signal piles up at its limit. For each sensor, axis and sign, with ``m`` the largest
reading of that sign (``s·x`` for ``s = ±1``), the samples within ``top_band`` of ``m``
(``s·x ≥ (1 − top_band)·m``) are counted against those in the band twice as wide just below.
A true peak thins out towards its maximum (a few samples at the top, more below); a cut one
sits at it (many samples at the top, a few passing through below). The axis-sign is cut when

- at least ``min_samples`` samples sit in the top band and at least ``pile_ratio`` times as
  many as in the band below,
- in at least ``min_episodes`` separate runs (a single long peak is not a limit),
- either all at one value (cut as recorded) or, when a calibration after the cut smeared
  them, at least ``min_samples_smeared`` samples held there for two samples or more in
  ``min_episodes`` of the runs (a periodic signal's peaks come back near one value, but
  neither exactly nor held long: the simulator's one-leg walk repeats its stride),
- and ``m`` is near the sensor's largest reading (``min_level_fraction`` of it; a range is the
  same on every axis) and at least ``min_level_acc_mps2`` or ``min_level_gyr_rps`` (no sensor
  is made with a range below those).

The band is relative, so it tolerates what a vendor's calibration does after the cut (a scale
and a 1 % axis misalignment smear the plateau by less than the band).

A range is the same on the three axes of a sensor, and mostly on every sensor of a trial. So a
limit reached once or twice on one axis-sign still counts when it is held there
(``min_samples`` readings at one value, or ``min_held_samples`` in a row within the band) and
the same limit (within ``top_band``) is reached, held, in ``min_episodes`` places or more over
the sensors of its kind: on the real walk cut at ±350 °/s, the feet reach it four and six times
and each shank once, for 0.1–0.2 s, which moved the right shank's length by 16 mm when it was
not left out. A limit reached once or twice in the whole trial is not reported.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..conventions import GRAVITY_MPS2, FloatArray

__all__ = [
    "longest_run",
    "SATURATION_PARAMS",
    "Saturation",
    "SaturationParams",
    "SaturationWarning",
    "at_limit_samples",
    "find_saturation",
    "trial_saturation",
    "warn_saturation",
]


class SaturationWarning(UserWarning):
    """A sensor's accelerometer or gyro sits at its full-scale limit in several places of the trial."""


@dataclass(frozen=True)
class SaturationParams:
    """Thresholds of the full-scale check (module docstring).

    Attributes:
        top_band: relative width of the band below an axis-sign's largest reading counted as
            "at the limit" (0.01: within 1 %).
        pile_ratio: the top band must hold at least this many times the samples of the band
            below it (relative width ``2·top_band``).
        min_samples: fewest samples at the limit.
        min_samples_smeared: fewest samples at the limit when they are not one value
            (``exact_tolerance``): a few peaks of a near-periodic signal can pile up in the
            band by chance, a signal cut and then calibrated is held there much longer.
        min_episodes: fewest separate runs at the limit; unless every sample at the limit
            has one value (within ``exact_tolerance``, relative), also the fewest runs of two
            samples or more.
        min_held_samples: an axis-sign held at its largest value (within ``top_band``) for this
            many samples in a row, or at one value in ``min_samples``, is cut when that limit
            is reached in ``min_episodes`` places or more over the trial's sensors of its kind
            (the range is shared), though fewer times on this one.
        exact_tolerance: relative spread of the readings at the limit below which they are
            one value (a signal cut as recorded, before any calibration).
        min_level_fraction: an axis-sign's limit must be at least this fraction of the
            sensor's largest reading on any axis.
        min_level_acc_mps2: lowest accelerometer limit considered, m/s² (1.5 g; ±2 g is the
            narrowest range made).
        min_level_gyr_rps: lowest gyro limit considered, rad/s (86 °/s; ±125 °/s is the
            narrowest range made).
        advised_acc_g: accelerometer range the warning advises, g.
        advised_gyr_dps: gyro range the warning advises, °/s.
    """

    top_band: float = 0.01
    pile_ratio: float = 3.0
    min_samples: int = 5
    min_samples_smeared: int = 20
    min_episodes: int = 3
    min_held_samples: int = 3
    exact_tolerance: float = 1e-9
    min_level_fraction: float = 0.8
    min_level_acc_mps2: float = 1.5 * GRAVITY_MPS2
    min_level_gyr_rps: float = 1.5
    advised_acc_g: float = 8.0
    advised_gyr_dps: float = 1000.0


#: The defaults.
SATURATION_PARAMS = SaturationParams()

_NAMES = {"acc": "accelerometer", "gyr": "gyro"}


@dataclass(frozen=True)
class Saturation:
    """One sensor's signal found cut at its range.

    Attributes:
        sensor: the sensor's name as in the trial file (``left_foot``, ``shank``).
        signal: ``"acc"`` or ``"gyr"``.
        level: the limit, m/s² or rad/s (the largest of the cut axis-signs' readings).
        at_limit: (N,) ``True`` where any cut axis-sign sits at its limit.
        episodes: separate runs at the limit.
        axes: (N, 3) ``+1`` where an axis sits at its positive limit, ``-1`` at its negative
            one, ``0`` elsewhere (sensor frame); what a repair needs to know of the cut
            (:mod:`lowerlimb.gait.cut_force`). Empty (0, 3) when not given.
    """

    sensor: str
    signal: str
    level: float
    at_limit: NDArray[np.bool_]
    episodes: int
    axes: NDArray[np.int8] = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int8))

    @property
    def samples(self) -> int:
        """Samples at the limit."""
        return int(self.at_limit.sum())

    @property
    def fraction(self) -> float:
        """Share of the trial's samples at the limit (0–1)."""
        return self.samples / max(1, self.at_limit.size)

    def message(self, params: SaturationParams = SATURATION_PARAMS) -> str:
        """One line naming the sensor, the limit, how often it is reached, what it costs and the fix."""
        if self.signal == "acc":
            level = f"±{self.level:.3g} m/s² ({self.level / GRAVITY_MPS2:.2g} g)"
            fix = f"±{params.advised_acc_g:g} g"
        else:
            level = f"±{self.level:.3g} rad/s ({math.degrees(self.level):.0f} °/s)"
            fix = f"±{params.advised_gyr_dps:g} °/s"
        places = "place" if self.episodes == 1 else "places"
        return (
            f"the {self.sensor} {_NAMES[self.signal]} is cut at its range, {level}: "
            f"{self.samples} samples ({100 * self.fraction:.2g} % of the trial) in {self.episodes} "
            f"{places} sit at that limit, where the joint calibration, the orientation and the foot "
            f"tracks read a wrong signal (lengths, angles and steps may be far off); "
            f"record with the sensor set to a range of {fix} or more"
        )


def _runs(flags: NDArray[np.bool_]) -> int:
    """Number of separate runs of ``True``."""
    f = flags.astype(np.int8)
    return int(np.count_nonzero(np.diff(f) == 1) + f[0]) if f.size else 0


@dataclass(frozen=True)
class _AxisSign:
    """One sensor's axis-sign readings near their largest value (a candidate limit)."""

    sensor: str
    axis: int
    sign: int
    level: float
    top: NDArray[np.bool_]
    alone: bool  # cut by its own evidence (several runs at the limit)
    plateau: bool  # held at the limit, cut if the same limit is reached often enough elsewhere


def longest_run(flags: NDArray[np.bool_]) -> int:
    """Length of the longest run of ``True``."""
    if not flags.any():
        return 0
    edges = np.flatnonzero(np.diff(np.concatenate(([0], flags.astype(np.int8), [0]))))
    return int((edges[1::2] - edges[::2]).max())


def _axis_sign(x: FloatArray, params: SaturationParams) -> tuple[float, NDArray[np.bool_], bool, bool] | None:
    """One axis-sign's readings ``x`` (N,): its largest value, the samples at it, cut alone, held there.

    ``None`` when the readings do not pile up at their largest value (module docstring).
    """
    m = float(x.max())
    if m <= 0:
        return None
    top = x >= (1.0 - params.top_band) * m
    below = (x >= (1.0 - 3.0 * params.top_band) * m) & ~top
    n_top = int(top.sum())
    if n_top < params.min_samples or n_top < params.pile_ratio * int(below.sum()):
        return None
    # cut exactly (one value), or held at the limit for two samples or more in several places;
    # a periodic signal's peaks come back near one value, but neither exactly nor held
    exact = x >= m - params.exact_tolerance * m
    n_exact, runs = int(exact.sum()), _runs(top)
    alone = n_exact >= params.min_samples and _runs(exact) >= params.min_episodes
    if not alone and n_top >= params.min_samples_smeared:
        alone = _runs(top & np.roll(top, 1) & (np.arange(x.size) > 0)) >= params.min_episodes
    plateau = n_exact >= params.min_samples or longest_run(top) >= params.min_held_samples
    return m, top, alone and runs >= params.min_episodes, plateau


def _candidates(signals: Mapping[str, FloatArray], params: SaturationParams, floor: float) -> list[_AxisSign]:
    """Every axis-sign of every sensor that piles up at a value at or above the floor."""
    out = []
    for sensor, x in signals.items():
        level_floor = max(floor, params.min_level_fraction * float(np.abs(x).max()))
        for axis in range(3):
            for sign in (1, -1):
                found = _axis_sign(sign * x[:, axis], params)
                if found is not None and found[0] >= level_floor:
                    out.append(_AxisSign(sensor, axis, sign, *found))
    return out


def _shared_limits(cands: list[_AxisSign], params: SaturationParams) -> list[_AxisSign]:
    """The held axis-signs whose common limit is reached in ``min_episodes`` places or more in all.

    A range is the same on every axis of a sensor, and mostly on every sensor of a trial: a
    shank reaching the gyro's limit once, where the feet reach it again and again, is cut too.
    Levels within ``top_band`` of the largest in a group are one limit.
    """
    held = sorted((c for c in cands if c.plateau), key=lambda c: -c.level)
    out: list[_AxisSign] = []
    while held:
        head = held[0].level
        group = [c for c in held if c.level >= (1.0 - params.top_band) * head]
        held = held[len(group) :]
        per_sensor: dict[str, NDArray[np.bool_]] = {}
        for c in group:
            per_sensor[c.sensor] = per_sensor[c.sensor] | c.top if c.sensor in per_sensor else c.top
        if sum(_runs(t) for t in per_sensor.values()) >= params.min_episodes:
            out += group
    return out


def _find(signals: Mapping[str, FloatArray], kind: str, params: SaturationParams) -> list[Saturation]:
    """The cut signals among ``signals`` (``{sensor: (N, 3)}``) of one kind, in their order."""
    floor = params.min_level_acc_mps2 if kind == "acc" else params.min_level_gyr_rps
    cands = _candidates(signals, params, floor)
    accepted = {id(c): c for c in cands if c.alone} | {id(c): c for c in _shared_limits(cands, params)}
    found = []
    for sensor, x in signals.items():
        mine = [c for c in accepted.values() if c.sensor == sensor]
        if not mine:
            continue
        axes = np.zeros(x.shape, dtype=np.int8)
        for c in mine:
            axes[c.top, c.axis] = c.sign
        at_limit: NDArray[np.bool_] = np.asarray(axes.any(axis=1), dtype=bool)
        found.append(Saturation(sensor, kind, max(c.level for c in mine), at_limit, _runs(at_limit), axes))
    return found


def _checked(signal: ArrayLike) -> FloatArray:
    x = np.asarray(signal, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"signal must be (N, 3), got {x.shape}")
    return x


def find_saturation(
    signal: ArrayLike, kind: str, sensor: str = "", params: SaturationParams = SATURATION_PARAMS
) -> Saturation | None:
    """Whether one sensor's accelerometer or gyro is cut at a full-scale limit (module docstring).

    Its three axes share one range; a trial's other sensors are not seen (:func:`trial_saturation`
    sees them all).

    Args:
        signal: (N, 3) readings in the sensor frame, m/s² (``kind="acc"``) or rad/s (``"gyr"``).
        kind: ``"acc"`` or ``"gyr"``.
        sensor: the sensor's name, for the message.
        params: thresholds.

    Returns:
        The cut signal's :class:`Saturation`, or ``None``.

    Raises:
        ValueError: ``kind`` is neither ``"acc"`` nor ``"gyr"``, or ``signal`` is not (N, 3).
    """
    if kind not in _NAMES:
        raise ValueError(f"kind must be 'acc' or 'gyr', got {kind!r}")
    x = _checked(signal)
    if x.shape[0] == 0:
        return None
    found = _find({sensor: x}, kind, params)
    return found[0] if found else None


def trial_saturation(
    acc: Mapping[str, ArrayLike], gyr: Mapping[str, ArrayLike], params: SaturationParams = SATURATION_PARAMS
) -> list[Saturation]:
    """Every cut accelerometer and gyro of a trial, in the order of ``acc``'s sensors (acc, then gyro).

    A limit found on one sensor is sought on the others of its kind too (module docstring).

    Args:
        acc: ``{sensor: (N, 3)}`` specific force, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity, rad/s.
        params: thresholds.
    """
    by_kind: dict[str, list[Saturation]] = {}
    for kind, signals in (("acc", acc), ("gyr", gyr)):
        checked = {s: _checked(signals[s]) for s in acc if s in signals}
        by_kind[kind] = _find({s: x for s, x in checked.items() if x.shape[0]}, kind, params)
    found = []
    for sensor in acc:
        found += [s for kind in ("acc", "gyr") for s in by_kind[kind] if s.sensor == sensor]
    return found


def at_limit_samples(
    acc: Mapping[str, ArrayLike], gyr: Mapping[str, ArrayLike], params: SaturationParams = SATURATION_PARAMS
) -> dict[str, NDArray[np.bool_]]:
    """``{sensor: (N,) booleans}``: where the sensor's accelerometer or gyro sits at a found limit.

    Only the sensors with a cut signal (:func:`trial_saturation`) are keys.
    """
    out: dict[str, NDArray[np.bool_]] = {}
    for s in trial_saturation(acc, gyr, params):
        out[s.sensor] = out[s.sensor] | s.at_limit if s.sensor in out else s.at_limit
    return out


def warn_saturation(found: list[Saturation], params: SaturationParams = SATURATION_PARAMS) -> None:
    """One :class:`SaturationWarning` per cut signal."""
    for s in found:
        warnings.warn(s.message(params), SaturationWarning, stacklevel=3)
