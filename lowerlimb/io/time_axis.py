"""The sample-time properties shared by every recording type (one definition)."""

from __future__ import annotations

import dataclasses
from typing import TypeVar

import numpy as np

from ..conventions import FloatArray
from ..errors import InputError, TimeAxisError

__all__ = ["TimeAxis", "TimeUnitGuess", "guess_time_unit", "rate_from_stamps", "require_increasing"]

#: Time units a column may be in, with the divisor to seconds.
_TIME_UNITS: tuple[tuple[str, float], ...] = (
    ("milliseconds", 1e3),
    ("microseconds", 1e6),
    ("nanoseconds", 1e9),
)
#: Sampling rates a recording may have, Hz (a unit is guessed when it puts the rate in here).
_PLAUSIBLE_RATE_HZ = (5.0, 5000.0)


def rate_from_stamps(time_s: FloatArray) -> float:
    """Sampling rate, Hz, of (N,) sample times, s: the samples over the time span (the mean step).

    Not the median step: stamps rounded to a coarser tick than the period (148 Hz in ms:
    steps of 7 and 6 ms, within the trial's jitter tolerance, so kept as they are) have a
    median step of one tick count, 7 ms, and gave 142.9 Hz, every integrated angle and
    length, the cadence and the stride lengths (+9 %) off with it. On steps that are even
    within a quarter of their median (a checked trial) the span is exact; on an unchecked
    clock with gaps it is not, and the median step is kept.
    """
    t = np.asarray(time_s, dtype=float)
    med = float(np.median(np.diff(t)))
    mean = float(t[-1] - t[0]) / (t.shape[0] - 1)
    return float(1.0 / (mean if abs(mean - med) <= 0.25 * med else med))


def require_increasing(
    time_s: FloatArray, whose: str = "time", fix: str = "sort the rows and drop duplicates"
) -> None:
    """Refuse a (N,) time column, s, that is not strictly increasing, naming the first data row.

    Raises:
        TimeAxisError: ``"<whose> is not strictly increasing at data row k (a s then b s); <fix>"``.
    """
    dt = np.diff(time_s)
    if np.any(dt <= 0):
        k = int(np.flatnonzero(dt <= 0)[0])
        raise TimeAxisError(
            f"{whose} is not strictly increasing at data row {k + 2} ({time_s[k]:.6g} s then "
            f"{time_s[k + 1]:.6g} s); {fix}"
        )


@dataclasses.dataclass(frozen=True)
class TimeUnitGuess:
    """What a time column whose steps are too long for seconds is in.

    Attributes:
        unit: ``"milliseconds"``, ``"microseconds"`` or ``"nanoseconds"``.
        rate_hz: the sampling rate in that unit, Hz.
        divisor: ``"1000"``, ``"1e6"`` or ``"1e9"``: the column divided by it is in seconds.
        sample_numbers: the step is exactly 1, so the column may also hold sample numbers.
    """

    unit: str
    rate_hz: float
    divisor: str
    sample_numbers: bool

    def text(self) -> str:
        """``"milliseconds (a rate of 100 Hz)"``, naming sample numbers where they are possible."""
        samples = " or sample numbers" if self.sample_numbers else ""
        return f"{self.unit}{samples} (a rate of {self.rate_hz:.4g} Hz in {self.unit})"


def guess_time_unit(median_step: float) -> TimeUnitGuess | None:
    """The first of milliseconds, microseconds, nanoseconds that puts the rate within 5–5000 Hz.

    Args:
        median_step: a time column's median step, in its own unit (too long for seconds).

    Returns:
        The guess, or ``None`` when none fits.
    """
    for unit, divisor in _TIME_UNITS:
        rate = divisor / median_step
        if _PLAUSIBLE_RATE_HZ[0] <= rate <= _PLAUSIBLE_RATE_HZ[1]:
            text = "1000" if divisor == 1e3 else f"1e{round(np.log10(divisor))}"
            return TimeUnitGuess(unit, rate, text, median_step == 1.0)
    return None


_T = TypeVar("_T", bound="TimeAxis")


class TimeAxis:
    """Mixin for dataclasses with ``time_s``: (N,) strictly increasing sample times, s."""

    time_s: FloatArray

    def from_sample(self: _T, k0: int) -> _T:
        """The recording from sample ``k0`` on, its clock restarted at zero (as a file cut from it).

        Every ``{name: (N, ...)}`` signal dictionary field (``acc``, ``gyr``, ``mag``) is cut
        alike; other fields are kept.

        Raises:
            InputError: ``k0`` is not a sample index that leaves at least two samples.
        """
        assert dataclasses.is_dataclass(self)
        if isinstance(k0, bool) or not isinstance(k0, (int, np.integer)) or not 0 <= k0 <= self.n_samples - 2:
            raise InputError(
                f"from_sample needs a sample index from 0 to {self.n_samples - 2} (at least two samples "
                f"left), got {k0!r}"
            )
        cut: dict[str, object] = {"time_s": self.time_s[k0:] - self.time_s[k0]}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, dict):
                cut[f.name] = {k: v[k0:] for k, v in value.items()}
        return dataclasses.replace(self, **cut)

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.time_s.shape[0])

    @property
    def rate_hz(self) -> float:
        """Sampling rate, Hz (:func:`rate_from_stamps`)."""
        return rate_from_stamps(self.time_s)

    @property
    def duration_s(self) -> float:
        """Time span of the recording, s."""
        return float(self.time_s[-1] - self.time_s[0])
