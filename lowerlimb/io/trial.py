"""``ImuTrial``: a four-IMU recording, read from and written to the trial CSV (docs/formats.md).

CSV format: a header row; ``time`` in s; then for each sensor in
``pelvis, thigh, shank, foot``: ``<sensor>_acc_{x,y,z}`` (m/s², specific
force), ``<sensor>_gyr_{x,y,z}`` (rad/s), optionally ``<sensor>_mag_{x,y,z}``
(µT). Validation happens at load time (:meth:`ImuTrial.validate`): every
problem raises one :class:`~lowerlimb.errors.InputError` subclass whose message
names the fix.
"""

from __future__ import annotations

import csv
import os
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..conventions import GRAVITY_MPS2, MAX_GYRO_RAD_S, MIN_MEDIAN_ACC_MPS2, SENSORS, FloatArray, check_side
from ..errors import (
    InputError,
    MissingColumnError,
    NonFiniteValueError,
    TimeAxisError,
    TooShortError,
    UnitError,
)
from ..stillness import StillPeriod, detect_still_period
from .numeric_csv import read_numeric_table

#: Lowest sampling rate accepted, Hz: below it the time column is taken to be in ms.
MIN_RATE_HZ = 5.0
#: Shortest trial accepted, s.
MIN_DURATION_S = 2.0
#: Largest relative deviation of one time step from the median step.
TIME_JITTER_TOLERANCE = 0.25


class StandingStartWarning(UserWarning):
    """The trial does not start with ≥ 1 s standing still; the first second is the reference."""


def column_names(sensor: str, signal: str) -> list[str]:
    """The three CSV column names of one signal, e.g. ``thigh_gyr_x..z``."""
    return [f"{sensor}_{signal}_{a}" for a in "xyz"]


@dataclass
class ImuTrial:
    """A synchronous recording of the four leg IMUs.

    Attributes:
        time_s: (N,) sample times, s, strictly increasing and evenly spaced.
        acc: ``{sensor: (N, 3)}`` specific force in the sensor frame, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity in the sensor frame, rad/s.
        mag: ``{sensor: (N, 3)}`` magnetic field in the sensor frame, µT, or None.
        side: ``"left"`` or ``"right"``: which leg carries the thigh/shank/foot IMUs.
    """

    time_s: FloatArray
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]
    mag: dict[str, FloatArray] | None = None
    side: str = "left"
    source: str = field(default="", repr=False)

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.time_s.shape[0])

    @property
    def rate_hz(self) -> float:
        """Sampling rate, Hz (from the median time step)."""
        return float(1.0 / np.median(np.diff(self.time_s)))

    @property
    def duration_s(self) -> float:
        """Time span of the recording, s."""
        return float(self.time_s[-1] - self.time_s[0])

    @property
    def has_mag(self) -> bool:
        """True when every sensor has magnetometer data."""
        return self.mag is not None

    # ------------------------------------------------------------ validation

    def validate(self) -> None:
        """Check the recording; raise the first problem found.

        Raises:
            TimeAxisError: non-increasing or uneven time.
            NonFiniteValueError: NaN or inf in any signal.
            UnitError: gyro in deg/s or accelerometer in g.
            TooShortError: fewer than 2 s of data.
            InputError: wrong array shapes or an unknown side.
        """
        try:
            check_side(self.side)
        except ValueError as e:
            raise InputError(f"{e}; pass --side left or --side right") from None
        t = np.asarray(self.time_s, dtype=float)
        if t.ndim != 1 or t.shape[0] < 2:
            raise TooShortError(0.0, MIN_DURATION_S)
        bad_t = np.flatnonzero(~np.isfinite(t))
        if bad_t.size:
            raise NonFiniteValueError("time", int(bad_t[0]) + 1)
        for name, signals in (("acc", self.acc), ("gyr", self.gyr), ("mag", self.mag or {})):
            for sensor in SENSORS if name != "mag" or self.mag else ():
                if sensor not in signals:
                    raise MissingColumnError(f"{sensor}_{name}_x", [], self.source)
                x = np.asarray(signals[sensor])
                if x.shape != (t.shape[0], 3):
                    raise InputError(
                        f"{sensor} {name} has shape {x.shape}, expected ({t.shape[0]}, 3); "
                        f"give one row per time sample"
                    )
                bad = np.argwhere(~np.isfinite(x))
                if bad.size:
                    r, c = bad[0]
                    raise NonFiniteValueError(f"{sensor}_{name}_{'xyz'[c]}", int(r) + 1)
        dt = np.diff(t)
        if np.any(dt <= 0):
            k = int(np.flatnonzero(dt <= 0)[0])
            raise TimeAxisError(
                f"time is not strictly increasing at data row {k + 2} "
                f"({t[k]:.6g} s then {t[k + 1]:.6g} s); sort the rows and drop duplicates"
            )
        med = float(np.median(dt))
        if med > 1.0 / MIN_RATE_HZ:
            raise UnitError(
                "time",
                med,
                f"time steps of {med:.4g} look like milliseconds (a rate of {1.0 / med:.3g} Hz); "
                f"the trial format expects seconds (divide the time column by 1000)",
            )
        if np.max(np.abs(dt - med)) > TIME_JITTER_TOLERANCE * med:
            raise TimeAxisError(
                f"time steps vary from {dt.min():.4g} s to {dt.max():.4g} s (median {med:.4g} s); "
                f"resample the trial to a constant rate"
            )
        for sensor in SENSORS:
            gmax = float(np.max(np.linalg.norm(self.gyr[sensor], axis=1)))
            if gmax > MAX_GYRO_RAD_S:
                raise UnitError(
                    f"{sensor}_gyr",
                    gmax,
                    f"{sensor} gyro values up to {gmax:.0f} look like deg/s; "
                    f"the trial format expects rad/s (multiply by π/180)",
                )
            amed = float(np.median(np.linalg.norm(self.acc[sensor], axis=1)))
            if amed < MIN_MEDIAN_ACC_MPS2:
                raise UnitError(
                    f"{sensor}_acc",
                    amed,
                    f"{sensor} accelerometer median magnitude {amed:.2f} looks like g; "
                    f"the trial format expects m/s² (multiply by {GRAVITY_MPS2})",
                )
        if self.duration_s < MIN_DURATION_S:
            raise TooShortError(self.duration_s, MIN_DURATION_S)

    def still_period(self) -> StillPeriod:
        """Detect the still run at the start of the recording, over every IMU.

        The library's one still-period detector (:func:`lowerlimb.stillness.detect_still_period`);
        :func:`lowerlimb.process_trial` calls it once and hands the result on.
        """
        return detect_still_period(
            [self.gyr[s] for s in SENSORS], [self.acc[s] for s in SENSORS], self.rate_hz
        )

    def standing_samples(self, duration_s: float = 1.0, still: StillPeriod | None = None) -> int:
        """Number of samples at the start in which every IMU is still (0 if under ``duration_s``).

        Args:
            duration_s: shortest accepted still period, s.
            still: the trial's :meth:`still_period` when already detected.
        """
        return (still or self.still_period()).samples(duration_s)

    def has_standing_start(self, duration_s: float = 1.0) -> bool:
        """True when the recording starts with ≥ ``duration_s`` of every IMU still."""
        return self.standing_samples(duration_s) > 0

    def reference_samples(self, still: StillPeriod | None = None) -> slice:
        """Samples of the standing reference posture.

        The detected still period at the start; when there is none, the first
        second, with a one-time :class:`StandingStartWarning`.

        Args:
            still: the trial's :meth:`still_period` when already detected.
        """
        n = self.standing_samples(1.0, still)
        if n > 0:
            # keep clear of the gradual onset of motion
            n = max(int(round(0.8 * self.rate_hz)), n - int(round(0.15 * self.rate_hz)))
        if n == 0:
            warnings.warn(
                "the trial does not start with 1 s of standing still; "
                "the first second is taken as the angle reference",
                StandingStartWarning,
                stacklevel=2,
            )
            n = max(2, int(round(self.rate_hz)))
        return slice(0, n)

    # ------------------------------------------------------------ CSV

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str], side: str = "left") -> ImuTrial:
        """Read and validate a trial CSV.

        Raises:
            FileNotFoundError: when ``path`` does not exist.
            InputError: any problem of :meth:`validate`, or a non-numeric cell.
        """
        path = os.fspath(path)
        if not os.path.isfile(path):
            raise FileNotFoundError(f"trial file not found: {path}")
        with open(path, newline="", encoding="utf-8-sig") as f:
            reader = csv.reader(f)
            try:
                header = [h.strip() for h in next(reader)]
            except StopIteration:
                raise InputError(f"{path} is empty; give a trial CSV with a header row") from None
        if "time" not in header:
            raise MissingColumnError("time", header, path)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                raw = read_numeric_table(path, skip_header=1)
        except ValueError as e:
            raise InputError(f"{path} has rows of unequal length or bad cells ({e}); fix the CSV") from None
        if raw.size == 0:
            raise TooShortError(0.0, MIN_DURATION_S)
        if raw.shape[1] != len(header):
            raise InputError(
                f"{path} has {raw.shape[1]} columns of data but {len(header)} header names; fix the header"
            )
        col = {name: i for i, name in enumerate(header)}

        def block(sensor: str, signal: str) -> FloatArray:
            names = column_names(sensor, signal)
            for n in names:
                if n not in col:
                    raise MissingColumnError(n, header, path)
            return np.ascontiguousarray(raw[:, [col[n] for n in names]])

        acc = {s: block(s, "acc") for s in SENSORS}
        gyr = {s: block(s, "gyr") for s in SENSORS}
        has_mag = all(n in col for s in SENSORS for n in column_names(s, "mag"))
        mag = {s: block(s, "mag") for s in SENSORS} if has_mag else None
        trial = cls(raw[:, col["time"]].copy(), acc, gyr, mag, side, source=path)
        trial.validate()
        return trial

    def header(self) -> list[str]:
        """CSV header of this trial."""
        names = ["time"]
        for s in SENSORS:
            names += column_names(s, "acc") + column_names(s, "gyr")
            if self.mag is not None:
                names += column_names(s, "mag")
        return names

    def to_array(self) -> FloatArray:
        """(N, C) data in the order of :meth:`header`."""
        cols = [self.time_s[:, None]]
        for s in SENSORS:
            cols += [self.acc[s], self.gyr[s]]
            if self.mag is not None:
                cols.append(self.mag[s])
        return np.hstack(cols)

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write the trial CSV (full float precision)."""
        np.savetxt(
            path,
            self.to_array(),
            delimiter=",",
            header=",".join(self.header()),
            comments="",
            fmt="%.9g",
        )
