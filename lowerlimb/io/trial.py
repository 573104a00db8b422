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
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..conventions import (
    GRAVITY_MPS2,
    MAX_GYRO_RAD_S,
    MIN_MEDIAN_ACC_MPS2,
    SENSORS,
    SIDES,
    FloatArray,
    check_side,
)
from ..errors import (
    InputError,
    MissingColumnError,
    NonFiniteValueError,
    SampleGlitchError,
    TimeAxisError,
    TooShortError,
    UnitError,
)
from ..stillness import StillPeriod, detect_still_period
from .bounds import INPUT_BOUNDS
from .csv_header import RaggedRow, header_line, is_skipped_line, ragged_row, row_fits
from .gyro_scale import check_gyro_scale
from .header_units import check_mag_units, without_own_unit
from .mag_cells import bridged_magnetometer
from .time_axis import TimeAxis, guess_time_unit, require_increasing
from .uneven_clock import CLOCK_PARAMS, refuse_batched_stamps, to_uniform_clock

#: Lowest sampling rate accepted, Hz: below it the time column is taken to be in ms.
MIN_RATE_HZ = 5.0
#: Shortest trial accepted, s.
MIN_DURATION_S = 2.0


class IdenticalSensorsError(InputError):
    """Two sensors hold identical data (one's columns copied into the other's)."""

    def __init__(self, first: str, second: str) -> None:
        self.first, self.second = first, second
        super().__init__(
            f"the {first} and {second} columns hold identical data; each sensor needs its own "
            f"recording (check the column mapping of the export)"
        )


def check_distinct_sensors(
    acc: Mapping[str, FloatArray], gyr: Mapping[str, FloatArray], sensors: Sequence[str]
) -> None:
    """Refuse two sensors with identical data: one sensor's columns copied into another's.

    Args:
        acc: ``{sensor: (N, 3)}`` specific force, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity, rad/s.
        sensors: the names to compare pairwise (the message names the first identical pair).

    Raises:
        IdenticalSensorsError: two sensors agree to the last bit in both signals.
    """
    for i, a in enumerate(sensors):
        for b in sensors[i + 1 :]:
            if np.array_equal(gyr[a], gyr[b]) and np.array_equal(acc[a], acc[b]):
                raise IdenticalSensorsError(a, b)


class ImplausibleAccelerometerError(UnitError):
    """An accelerometer whose median magnitude is far above gravity: its columns are not m/s².

    Attributes:
        sensor: the sensor (as named in the trial).
        median_mps2: its median accelerometer magnitude over the trial, m/s² (also ``value``).
        limit_mps2: the largest plausible median
            (:attr:`~lowerlimb.io.bounds.InputBounds.max_median_acc_mps2`), m/s².
    """

    def __init__(self, sensor: str, median_mps2: float, limit_mps2: float) -> None:
        self.sensor = sensor
        self.median_mps2 = median_mps2
        self.limit_mps2 = limit_mps2
        super().__init__(
            f"{sensor}_acc",
            median_mps2,
            f"the {sensor} accelerometer reads a median magnitude of {median_mps2:.4g} m/s², far above "
            f"gravity ({GRAVITY_MPS2} m/s²; a body-worn sensor's median stays below {limit_mps2:.3g}): "
            f"these columns are not an accelerometer in m/s²; likely the gyro columns are mapped as "
            f"the accelerometer (acc and gyr exchanged), or the unit is cm/s² or mm/s² (divide by 100 "
            f"or 1000); check the column mapping and the units of the export",
        )


class NoMotionError(InputError):
    """The trial holds no motion to calibrate the joints from; carries the gyro variation (rad/s)."""

    def __init__(
        self,
        sensor: str,
        gyro_std_rps: float,
        required_rps: float,
        *,
        reusable: bool = True,
        acc_std_mps2: float = 0.0,
    ) -> None:
        self.sensor = sensor
        self.gyro_std_rps = gyro_std_rps
        self.required_rps = required_rps
        self.acc_std_mps2 = acc_std_mps2
        reuse = ", or reuse an earlier calibration with --calibration" if reusable else ""
        if acc_std_mps2 >= INPUT_BOUNDS.moving_acc_std_mps2:
            super().__init__(
                f"the {sensor} gyro barely turns (its angular rate varies by {gyro_std_rps:.3g} rad/s) "
                f"while its accelerometer moves (its magnitude varies by {acc_std_mps2:.2g} m/s²): a gyro "
                f"in the wrong unit (rad/s data converted as if in deg/s?) or the wrong columns; the "
                f"trial format expects rad/s"
            )
            return
        super().__init__(
            f"the trial holds no motion to calibrate from: the {sensor} angular rate varies by "
            f"{gyro_std_rps:.3g} rad/s (at least {required_rps:g} rad/s needed); record a walk or "
            f"the calibration motions{reuse}"
        )


class StandingStartWarning(UserWarning):
    """The trial does not start with ≥ 1 s standing still; the first second is the reference."""


class PartialMagnetometerWarning(UserWarning):
    """Some sensors have magnetometer columns and some do not: none is used (6-axis)."""


def _median_norm(x: FloatArray) -> float:
    """Median magnitude of (N, 3) samples."""
    return float(np.median(np.linalg.norm(x, axis=1)))


def column_names(sensor: str, signal: str) -> list[str]:
    """The three CSV column names of one signal, e.g. ``thigh_gyr_x..z``."""
    return [f"{sensor}_{signal}_{a}" for a in "xyz"]


def mag_columns(header: Sequence[str]) -> set[int]:
    """Indices of a header's magnetometer columns, whose cells may be empty (:mod:`.mag_cells`)."""
    return {i for i, h in enumerate(header) if "_mag_" in h}


def has_all_mag(header: list[str], sensors: tuple[str, ...] | list[str]) -> bool:
    """Whether every sensor has its three magnetometer columns; warn when only some have.

    Warns:
        PartialMagnetometerWarning: some sensors, not all, have magnetometer columns.
    """
    present = [s for s in sensors if all(n in header for n in column_names(s, "mag"))]
    if present and len(present) < len(sensors):
        missing = [s for s in sensors if s not in present]
        warnings.warn(
            f"magnetometer columns for {', '.join(present)} but not for {', '.join(missing)}; "
            f"the orientation filters need every sensor's field, so none is used (6-axis); "
            f"export the magnetometer of all sensors for 9-axis fusion",
            PartialMagnetometerWarning,
            stacklevel=3,
        )
    return len(present) == len(sensors)


@dataclass
class ImuTrial(TimeAxis):
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
    def has_mag(self) -> bool:
        """True when every sensor has magnetometer data."""
        return self.mag is not None

    # ------------------------------------------------------------ validation

    def validate(self) -> None:
        """Check the recording; raise the first problem found.

        Raises:
            TimeAxisError: non-increasing or uneven time.
            NonFiniteValueError: NaN or inf in any signal.
            SampleGlitchError: an accelerometer or gyro sample beyond any sensor's range
                (:attr:`~lowerlimb.io.bounds.InputBounds.max_sample_abs`).
            UnitError: gyro in deg/s (its values, or its turns against the accelerometer's,
                :mod:`~lowerlimb.io.gyro_scale`) or accelerometer in g;
                :class:`ImplausibleAccelerometerError` for an accelerometer whose median
                magnitude is far above gravity (gyro columns, or cm/s² or mm/s²).
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
                huge = np.argwhere(np.abs(x) > INPUT_BOUNDS.max_sample_abs)
                # a few such samples are glitches; a signal mostly beyond, or an accelerometer whose
                # median is far above gravity, is in another unit (below)
                if (
                    name != "mag"
                    and huge.size
                    and huge.shape[0] < 0.5 * x.shape[0]
                    and not (name == "acc" and _median_norm(x) > INPUT_BOUNDS.max_median_acc_mps2)
                ):
                    r, c = huge[0]
                    raise SampleGlitchError(f"{sensor}_{name}_{'xyz'[c]}", int(r) + 1, float(x[r, c]))
        refuse_batched_stamps(t, [*self.acc.values(), *self.gyr.values()])
        require_increasing(t)
        dt = np.diff(t)
        med = float(np.median(dt))
        if med > 1.0 / MIN_RATE_HZ:
            guess = guess_time_unit(med)
            raise UnitError(
                "time",
                med,
                f"time steps of {med:.4g} look like {guess.text()}; the trial format expects seconds "
                f"(divide the time column by {guess.divisor}"
                f"{'; sample numbers: divide by the rate in Hz' if guess.sample_numbers else ''})"
                if guess is not None
                else f"time steps of {med:.4g} are too long for seconds (a rate of {1.0 / med:.3g} Hz); "
                f"the trial format expects the time in seconds",
            )
        if np.max(np.abs(dt - med)) > CLOCK_PARAMS.jitter_tolerance * med:
            raise TimeAxisError(
                f"time steps vary from {dt.min():.4g} s to {dt.max():.4g} s (median {med:.4g} s); "
                f"resample the trial to a constant rate (lowerlimb.io.trial.on_uniform_clock does it, "
                f"and reading the trial CSV applies it)"
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
            amed = _median_norm(self.acc[sensor])
            if not np.any(self.acc[sensor]):
                raise InputError(
                    f"the {sensor} accelerometer columns are all zero: the sensor recorded nothing; "
                    f"check its columns in the export"
                )
            moving = np.any(np.ptp(self.gyr[sensor], axis=0))  # else it is a still trial (check_motion)
            if moving and not np.any(np.ptp(self.acc[sensor], axis=0)):
                raise InputError(
                    f"the {sensor} accelerometer reads one constant value in every row: the sensor "
                    f"recorded nothing (a real one always has noise); check its columns in the export"
                )
            if amed > INPUT_BOUNDS.max_sample_abs:
                raise UnitError(
                    f"{sensor}_acc",
                    amed,
                    f"{sensor} accelerometer median magnitude {amed:.3g} is beyond any sensor's range "
                    f"in m/s²; the trial format expects m/s² (about {GRAVITY_MPS2} at rest)",
                )
            if amed < MIN_MEDIAN_ACC_MPS2:
                raise UnitError(
                    f"{sensor}_acc",
                    amed,
                    f"{sensor} accelerometer median magnitude {amed:.2f} looks like g; "
                    f"the trial format expects m/s² (multiply by {GRAVITY_MPS2})",
                )
            if amed > INPUT_BOUNDS.max_median_acc_mps2:
                raise ImplausibleAccelerometerError(sensor, amed, INPUT_BOUNDS.max_median_acc_mps2)
        if self.duration_s < MIN_DURATION_S:
            raise TooShortError(self.duration_s, MIN_DURATION_S)
        check_distinct_sensors(self.acc, self.gyr, SENSORS)
        check_gyro_scale(self.acc, self.gyr, self.rate_hz, SENSORS)

    def check_motion(self, min_gyro_std_rps: float) -> None:
        """Refuse a trial with no motion to calibrate from (still, or exactly constant).

        Args:
            min_gyro_std_rps: the least standard deviation of the angular-rate
                magnitude of the thigh, shank and foot, rad/s
                (:attr:`lowerlimb.io.bounds.InputBounds.min_motion_gyro_std_rps`).

        Raises:
            NoMotionError: naming the still sensor.
        """
        for sensor in SENSORS[1:]:
            std = float(np.std(np.linalg.norm(self.gyr[sensor], axis=1)))
            if not std >= min_gyro_std_rps:
                acc_std = float(np.std(np.linalg.norm(self.acc[sensor], axis=1)))
                raise NoMotionError(sensor, std, min_gyro_std_rps, acc_std_mps2=acc_std)

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
    def from_csv(
        cls, path: str | os.PathLike[str], side: str | None = None, *, use_mag: bool = True
    ) -> ImuTrial:
        """Read and validate a trial CSV.

        A header that names one side's sensors with the two-leg prefix (``pelvis``,
        ``left_thigh``, ``left_shank``, ``left_foot``, no ``right_*``) is that leg
        (:func:`one_side_prefix`); messages then name its columns as in the file.

        Args:
            path: the trial CSV (docs/formats.md).
            side: instrumented leg; ``None``: the prefixed side, else ``"left"``.
            use_mag: read the magnetometer columns; when False they are ignored
                (gaps or NaN in them are then no error).

        Raises:
            FileNotFoundError: when ``path`` does not exist.
            InputError: a folder, a binary/compressed/non-UTF-8 file, another
                separator than the comma, a duplicated column, a text cell, a
                ``side`` other than the one the columns name, or any problem of
                :meth:`validate`.
        """
        path = os.fspath(path)
        if os.path.isdir(path):
            raise InputError(f"{path} is a directory, not a trial CSV; give the trial file inside it")
        if os.path.exists(path) and not os.path.isfile(path):
            raise InputError(f"{path} is not a regular file (a device or a pipe); give the trial CSV file")
        if not os.path.isfile(path):
            raise FileNotFoundError(f"trial file not found: {path}")
        header = _read_header(path)
        prefix = leg_side(header, side, path)
        if prefix is None:
            from .bilateral_trial import trial_layout  # it imports this module

            if trial_layout(header) == "two_legs":
                raise InputError(
                    f"{path} is a two-leg trial (left_* and right_* sensors), not one leg; read it with "
                    "lowerlimb.io.bilateral_trial.BilateralTrial.from_csv and process it with "
                    "lowerlimb.bilateral.process_bilateral_trial (or run lowerlimb calibrate on it)"
                )
            return cls._from_csv(path, header, side or "left", use_mag)
        unprefixed = [h.removeprefix(f"{prefix}_") for h in header]
        from .bilateral_trial import with_file_names  # it imports this module

        try:
            return cls._from_csv(path, unprefixed, prefix, use_mag)
        except InputError as e:
            raise with_file_names(e, prefix) from None

    @classmethod
    def _from_csv(cls, path: str, header: list[str], side: str, use_mag: bool) -> ImuTrial:
        """Read the columns of ``header`` (single-leg names) from ``path`` and validate them."""
        col = {name: i for i, name in enumerate(header)}
        names = ["time"]
        for s in SENSORS:
            names += column_names(s, "acc") + column_names(s, "gyr")
        if use_mag:
            check_mag_units(header, path)
        has_mag = use_mag and has_all_mag(header, SENSORS)
        if has_mag:
            names += [n for s in SENSORS for n in column_names(s, "mag")]
        for n in names:
            if n not in col:
                raise MissingColumnError(n, header, path)
        raw = read_numbers(path, header, [col[n] for n in names], blank_ok=mag_columns(header))
        if raw.shape[0] == 0:
            raise TooShortError(0.0, MIN_DURATION_S)
        k = {n: i for i, n in enumerate(names)}

        def block(sensor: str, signal: str) -> FloatArray:
            return np.ascontiguousarray(raw[:, [k[n] for n in column_names(sensor, signal)]])

        acc = {s: block(s, "acc") for s in SENSORS}
        gyr = {s: block(s, "gyr") for s in SENSORS}
        mag = {s: block(s, "mag") for s in SENSORS} if has_mag else None
        mag = bridged_magnetometer(raw[:, 0], mag)
        time_s, acc, gyr, mag = on_uniform_clock(raw[:, 0].copy(), acc, gyr, mag)
        trial = cls(time_s, acc, gyr, mag, side, source=path)
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


def on_uniform_clock(
    time_s: FloatArray,
    acc: dict[str, FloatArray],
    gyr: dict[str, FloatArray],
    mag: dict[str, FloatArray] | None,
) -> tuple[FloatArray, dict[str, FloatArray], dict[str, FloatArray], dict[str, FloatArray] | None]:
    """A trial's (N,) time, s, and ``{sensor: (N, 3)}`` signals, on a constant clock.

    Resampled when the steps vary (:func:`~lowerlimb.io.uneven_clock.to_uniform_clock`, which
    warns), else returned as given.
    """
    groups = [acc, gyr] + ([mag] if mag is not None else [])
    keys = [(g, name) for g, group in enumerate(groups) for name in group]
    t, arrays, repair = to_uniform_clock(time_s, [groups[g][name] for g, name in keys])
    if repair is None:
        return time_s, acc, gyr, mag
    out: list[dict[str, FloatArray]] = [{} for _ in groups]
    for (g, name), x in zip(keys, arrays, strict=True):
        out[g][name] = np.ascontiguousarray(x)
    return t, out[0], out[1], out[2] if mag is not None else None


def one_side_prefix(header: Sequence[str]) -> str | None:
    """The side whose two-leg names (``left_thigh_acc_x`` …) are the header's only leg sensors, or ``None``.

    ``None`` also for a header with both sides, with no side prefix, or with single-leg names.
    """
    names = {side: tuple(f"{side}_{p}_" for p in SENSORS[1:]) for side in SIDES}
    prefixed = {side for side in SIDES for h in header if h.startswith(names[side])}
    single = any(h.startswith(tuple(f"{p}_" for p in SENSORS[1:])) for h in header)
    return prefixed.pop() if len(prefixed) == 1 and not single else None


def leg_side(header: Sequence[str], side: str | None, path: str = "") -> str | None:
    """The side a one-leg header's prefixed columns name (:func:`one_side_prefix`), checked against ``side``.

    Raises:
        InputError: ``side`` is given and is the other side.
    """
    prefix = one_side_prefix(header)
    if prefix is not None and side is not None and check_side(side) != prefix:
        where = f"{path} names" if path else "the columns name"
        raise InputError(
            f"{where} the {prefix} leg's sensors ({prefix}_thigh, {prefix}_shank, {prefix}_foot) "
            f"but the side is {side}; drop --side (or pass --side {prefix})"
        )
    return prefix


def _read_header(path: str) -> list[str]:
    """The trial's header row, stripped; refuses binary, non-UTF-8 and non-comma files.

    Lines before it that are blank, ``#`` comments or Excel's ``sep=`` line are skipped
    (:func:`~lowerlimb.io.csv_header.header_line`).
    """
    head = header_line(path)
    line = head.text
    try:
        header = header_names(next(csv.reader([line])))
    except csv.Error as e:
        raise unreadable_csv(path, e) from None
    if "time" not in header and any("time" in header_names(c.split(",")) for c in head.comments):
        raise InputError(
            f"the header of {path} is a comment line ('# time,…', as numpy.savetxt writes it); "
            f"delete the '#' before it (savetxt: pass comments='')"
        )
    if "time" not in header:
        for sep, name in ((";", "semicolons"), ("\t", "tabs"), ("|", "vertical bars")):
            if sep in line and len(line.split(sep)) > len(header):
                raise InputError(
                    f"{path} separates its columns with {name}, not commas (the decimal mark may be a "
                    f"comma too); save it as a comma-separated CSV with '.' as the decimal mark"
                )
        raise MissingColumnError("time", header, path)
    check_unique_columns(header, path)
    return header


def header_names(cells: Sequence[str]) -> list[str]:
    """A trial CSV's header cells as column names: stripped and in lower case (``Time`` is ``time``)."""
    return [without_own_unit(c.strip().lower()) for c in cells]


def check_unique_columns(header: list[str], path: str) -> None:
    """Refuse a header that names a column twice (which copy is meant cannot be known).

    Raises:
        InputError: naming the repeated columns.
    """
    dup = sorted({h for h in header if h and header.count(h) > 1})  # empty names: unnamed empty columns
    if dup:
        raise InputError(
            f"{path} has the column {dup[0]!r} {header.count(dup[0])} times"
            f"{' (and ' + ', '.join(repr(d) for d in dup[1:]) + ')' if len(dup) > 1 else ''}; "
            f"each column name must appear once"
        )


def read_numbers(
    path: str, header: list[str], usecols: list[int], blank_ok: Collection[int] = ()
) -> FloatArray:
    """(N, len(usecols)) numbers of the data rows; a bad cell is named by row and column.

    numpy's C reader first; a file it refuses is read again cell by cell, which accepts
    quoted numbers and names the first empty or non-numeric cell, or a row of the wrong
    length. Empty cells of the columns ``blank_ok`` (indices into ``header``) read as NaN,
    and only those: a NaN written out in such a column is refused.

    Raises:
        InputError: naming the bad cell or row.
    """
    head = header_line(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            values = np.loadtxt(
                path,
                delimiter=",",
                skiprows=head.index + 1,
                usecols=usecols,
                dtype=float,
                ndmin=2,
                encoding="utf-8-sig",
                quotechar='"',
            )
        optional = [k for k, c in enumerate(usecols) if c in blank_ok]
        if not np.isnan(values[:, optional]).any() and ragged_row(path, head, header) is None:
            return values  # else the slow path names the written-out NaN or the ragged row
    except UnicodeDecodeError as e:
        raise InputError(
            f"{path} is not UTF-8 text (byte {e.object[e.start]:#04x}); save the trial CSV as UTF-8"
        ) from None
    except ValueError:
        pass
    # the slow path: quoted numbers, or naming the first bad cell
    rows: list[list[float]] = []
    with open(path, newline="", encoding="utf-8-sig") as f:
        lines = [ln for ln in list(f)[head.index + 1 :] if not is_skipped_line(ln)]
    try:
        for row_no, row in enumerate(csv.reader(lines), start=1):
            if not row or all(not c.strip() for c in row):
                continue
            if not row_fits(len(row), not row[-1].strip(), header):
                raise _ragged(path, RaggedRow(row_no, len(row), len(header), row_no == len(lines)))
            rows.append([_cell_value(row[c], header[c], row_no, c in blank_ok) for c in usecols])
    except csv.Error as e:
        raise unreadable_csv(path, e) from None
    return np.asarray(rows, dtype=float).reshape(-1, len(usecols))


def _ragged(path: str, r: RaggedRow) -> InputError:
    """The error for a data row of the wrong length (an interrupted last row named as such)."""
    if r.last and r.n_values < r.n_columns:
        return InputError(
            f"{path}: the last data row ({r.row_no}) has {r.n_values} of {r.n_columns} values, as an "
            f"interrupted recording leaves it; delete that row"
        )
    return InputError(
        f"{path} data row {r.row_no} has {r.n_values} values but the header names {r.n_columns} "
        f"columns; every row needs one value per column (a value added or lost shifts the columns after it)"
    )


def unreadable_csv(path: str, error: csv.Error) -> InputError:
    """The error for a file the csv module refuses (e.g. a cell over its field size limit)."""
    return InputError(f"{path} is not a readable CSV ({error}); export the recording as CSV text again")


def _cell_value(raw: str, column: str, row_no: int, blank_ok: bool = False) -> float:
    """One cell as a number (NaN for an empty cell where ``blank_ok``), or an :class:`InputError`."""
    cell = raw.strip()
    try:
        value = float(cell)
    except ValueError:
        pass
    else:
        if blank_ok and np.isnan(value):
            raise InputError(
                f"column '{column}' has a NaN value ({cell!r}) at data row {row_no}; leave a "
                f"magnetometer cell empty where it has no sample, or drop the magnetometer columns"
            )
        return value
    if not cell and blank_ok:
        return float("nan")
    if not cell:
        raise InputError(
            f"column '{column}' is empty at data row {row_no}; fill or cut the gap before calibrating"
        )
    if "," in cell or _is_comma_decimal(cell):
        raise InputError(
            f"column '{column}' holds {cell!r} at data row {row_no}: a comma as decimal "
            f"mark; save the CSV with '.' as the decimal mark"
        )
    raise InputError(
        f"column '{column}' holds the text {cell[:40]!r} at data row {row_no}, not a "
        f"number; every cell of a trial must be a number"
    )


def _is_comma_decimal(cell: str) -> bool:
    try:
        float(cell.replace(",", "."))
    except ValueError:
        return False
    return True
